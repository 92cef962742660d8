"""Hostile input to the study parser (hypothesis): every document gives a Study or a SceneError.

Three generators: (1) arbitrary nested documents built from the study vocabulary's keys, unknown keys
and any TOML value (NaN, inf, huge and tiny numbers, empty and odd strings, lists, tables); (2) a
valid scene with one key replaced by such a value (the common typo); (3) valid sweeps, which must
expand to the cartesian product with unique names, and round-trip through TOML text and
``railtherm.load_study``. A SceneError must name what is wrong; any other exception is a bug.
"""
from __future__ import annotations

import math
import os
import string
import warnings

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import railtherm  # noqa: E402
from railtherm.input.scene import MATERIAL_KEYS, SCENE_KEYS, Table, load_scene  # noqa: E402
from railtherm.input.study import STUDY_KEYS, parse_study  # noqa: E402

#: RAILTHERM_HYPOTHESIS_EXAMPLES=5000 runs a longer, random (not derandomized) hunt
HUNT = int(os.environ.get("RAILTHERM_HYPOTHESIS_EXAMPLES", "0"))
SETTINGS = settings(max_examples=HUNT or 150, deadline=None, derandomize=not HUNT, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])

FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, 5e-324, 1e300, -1e300, math.nan, math.inf, -math.inf, 0.5, 1.0, -1.0]),
)
INTS = st.one_of(st.integers(-2 ** 70, 2 ** 70), st.sampled_from([0, 1, -1, 2 ** 63, -2 ** 63 - 1]))
TEXT = st.one_of(st.text(max_size=12), st.sampled_from(["", " ", "/", "a/b", "..", "\\", "ellipse", "line",
                                                        "all", "analytic", "finest", "hertz", "uniform",
                                                        "equal-temperature", "steady", "transient", "nan"]))
SCALARS = st.one_of(FLOATS, INTS, TEXT, st.booleans())
KEYS = st.one_of(st.sampled_from(sorted(SCENE_KEYS) + sorted(MATERIAL_KEYS) + sorted(STUDY_KEYS)
                                 + ["shape", "semi_axes", "curvatures", "wheel_radius", "flux", "half_width",
                                    "longitudinal", "lateral", "spin", "length", "depth", "schema_version"]),
                 st.text(string.ascii_lowercase + "_.", min_size=1, max_size=8))
# TOML values: scalars, (short) lists and tables, nested
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                       st.dictionaries(KEYS, inner, max_size=4)), max_leaves=12)

MAT = {"shear_modulus": 82e9, "poisson_ratio": 0.28, "density": 7850.0, "specific_heat": 450.0,
       "conductivity": 50.0, "thermal_expansion": 12e-6, "bulk_temperature": 0.0}
VALID = {"schema_version": 1,
         "study": {"name": "h", "methods": "all", "levels": [0]},
         "defaults": {"wheel": dict(MAT), "rail": dict(MAT)},
         "scene": [{"name": "s", "normal_force": 100e3, "contact": {"shape": "ellipse", "semi_axes": [5e-3, 8e-3]},
                    "speed": 30.0, "sliding_speed": 1.0, "friction": 0.3, "heat_partition": 0.5}]}


def check(doc):
    """parse_study(doc) returns a Study, or raises a SceneError that says what is wrong."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            study = parse_study(doc)
        except railtherm.SceneError as exc:
            msg = str(exc)
            assert msg.strip(), "empty SceneError message"
            assert exc.key is not None or any(w in msg for w in ("scene", "study", "key", "name")), msg
            return None
    assert isinstance(study, railtherm.Study) and study.scenes
    for sc in study.scenes:
        assert isinstance(sc, railtherm.Scene)
        assert math.isfinite(sc.speed) and sc.speed > 0
        mu = None if sc.friction is None else sc.friction.nominal
        for v in (sc.normal_force, sc.penetration, mu, sc.sliding_speed, sc.convection):
            assert v is None or (isinstance(v, float) and math.isfinite(v) and v >= 0)
        # the scene round-trips through its mapping
        assert load_scene(sc.to_dict()).hash == sc.hash
    return study


@SETTINGS
@given(st.dictionaries(st.one_of(st.sampled_from(["schema_version", "study", "defaults", "scene"]), KEYS),
                       VALUES, max_size=5))
def test_arbitrary_documents(doc):
    check(doc)


@SETTINGS
@given(st.sampled_from(sorted(SCENE_KEYS)), VALUES)
def test_one_scene_key_replaced(key, value):
    doc = {**VALID, "scene": [{**VALID["scene"][0], key: value}]}
    if key == "name" and isinstance(value, list):
        value = value[:1]
    check(doc)


NESTED = [(k, sub) for k, c in SCENE_KEYS.items() if isinstance(c, Table) for sub in c.keys]


@SETTINGS
@given(st.sampled_from(NESTED), VALUES)
def test_one_nested_key_replaced(path, value):
    key, sub = path
    scene = dict(VALID["scene"][0])
    base = dict(scene.get(key, {})) if isinstance(scene.get(key), dict) else {}
    base[sub] = value
    scene[key] = base
    check({**VALID, "scene": [scene]})


@SETTINGS
@given(st.sampled_from(sorted(STUDY_KEYS)), VALUES)
def test_one_study_key_replaced(key, value):
    check({**VALID, "study": {**VALID["study"], key: value}})


@SETTINGS
@given(st.sampled_from(["wheel", "rail"]), st.sampled_from(sorted(MATERIAL_KEYS)), VALUES)
def test_one_material_key_replaced(body, key, value):
    check({**VALID, "defaults": {**VALID["defaults"], body: {**MAT, key: value}}})


POSITIVE = st.floats(1e-3, 1e3, allow_nan=False)


@settings(max_examples=HUNT or 60, deadline=None, derandomize=not HUNT, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(POSITIVE, min_size=1, max_size=4, unique=True),
       st.lists(st.floats(0.0, 2.0, allow_nan=False), min_size=1, max_size=3, unique=True),
       st.lists(st.floats(0.0, 1.0, allow_nan=False), min_size=1, max_size=3, unique=True))
def test_sweeps_expand_and_round_trip(tmp_path_factory, speeds, frictions, partitions):
    import tomli_w
    scene = {**VALID["scene"][0], "speed": speeds, "friction": frictions,
             "wheel": {"bulk_temperature": partitions}}
    doc = {**VALID, "scene": [scene]}
    study = check(doc)
    n = len(speeds) * len(frictions) * len(partitions)
    if study is None:  # names that collide after formatting (e.g. 1e-3 and 0.001000001 both print as 0.001)
        from railtherm.input.study import _fmt
        labels = {(_fmt(s), _fmt(f), _fmt(p)) for s in speeds for f in frictions for p in partitions}
        assert len(labels) < n
        return
    assert len(study.scenes) == n
    assert len({s.name for s in study.scenes}) == n
    assert {(s.speed, s.friction.nominal, s.wheel.bulk_temperature) for s in study.scenes} == \
           {(float(a), float(b), float(c)) for a in speeds for b in frictions for c in partitions}
    for s in study.scenes:
        assert set(s.sweep) == {"speed", "friction", "wheel.bulk_temperature"}
    p = tmp_path_factory.mktemp("toml") / "study.toml"
    p.write_text(tomli_w.dumps(doc))
    again = railtherm.load_study(p)
    assert [s.hash for s in again.scenes] == [s.hash for s in study.scenes]


def test_toml_syntax_error_and_missing_file_are_scene_errors(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[study\nname = 1")
    with pytest.raises(railtherm.SceneError, match="not valid TOML"):
        railtherm.load_study(p)
    with pytest.raises(railtherm.SceneError, match="does not exist"):
        railtherm.load_study(tmp_path / "missing.toml")


def test_a_sweep_of_millions_of_scenes_is_refused_before_expanding():
    """5 swept keys of 20 values (3.2 million scenes) is an error at once, not an hour of parsing."""
    import time
    vals = [float(v) for v in range(1, 21)]
    scene = {**VALID["scene"][0], "speed": vals, "friction": vals, "sliding_speed": vals, "convection": vals,
             "normal_force": [v * 1e3 for v in vals]}
    t0 = time.perf_counter()
    with pytest.raises(railtherm.SceneError, match="3200000 scenes"):
        parse_study({**VALID, "scene": [scene]})
    assert time.perf_counter() - t0 < 1.0


@pytest.mark.parametrize("output", ["semi_axis_b", "traction_y", "slip_velocity_y", "creep_force_y", "spin_moment"])
def test_a_line_contact_cannot_ask_lateral_outputs(output):
    """Found by the method hypothesis test: a line contact has no lateral direction, so asking for a
    lateral output is invalid input (before: the result came back without it and no error)."""
    from railtherm.testing import canonical
    with pytest.raises(railtherm.SceneError, match=output):
        load_scene(canonical("line-full-sliding", outputs=["max_pressure", output]))
