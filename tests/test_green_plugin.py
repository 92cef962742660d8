"""Conformance of the "green" plugin: registration, model class, canonical scenes, options, study file.

Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_green_plugin.py -q``.
"""
from __future__ import annotations

from pathlib import Path

import pytest

import railtherm
from railtherm.testing import check_method, check_model_class
import railtherm_green.plugin as green_plugin
from railtherm_green.model import GreenTemperature

STUDY = Path(__file__).resolve().parents[1] / "studies" / "ertz_knothe_2002.toml"


def test_hooks_register_model_and_method():
    assert green_plugin.railtherm_register_models() == [GreenTemperature]
    (m,) = green_plugin.railtherm_register_methods()
    assert m.name == "green"
    assert m.chain == {"normal": ("wheelset", "hertz"), "tangential": ("full-sliding", "fastsim"),
                       "heat_source": ("frictional",), "temperature": ("green",)}
    assert green_plugin.railtherm_register_models.__doc__ and green_plugin.railtherm_register_methods.__doc__
    check_model_class(GreenTemperature)


def test_conformance_on_canonical_scenes(railtherm_register):
    railtherm_register("green", green_plugin)
    out = check_method("green")
    assert out["ellipse-full-sliding"] == "ok"
    assert out["line-full-sliding"] == "ok"
    assert out["ellipse-given-flux"] == "ok"
    assert out["line-given-flux"] == "ok"
    # creepage needs the FASTSIM heat source, not registered in this host: refused with a reason
    assert out["ellipse-creepage"].startswith("refused")


def test_bad_option_is_a_scene_error():
    scene = railtherm.testing.canonical("ellipse-full-sliding")
    with pytest.raises(railtherm.SceneError, match="convective_area"):
        railtherm.solve(scene, "green", options={"convective_area": "roof"})
    with pytest.raises(railtherm.SceneError, match="depth_points"):
        railtherm.solve(scene, "green", options={"depth_points": 1})


def test_transient_mode_runs_and_its_limits_are_refused():
    """green computes transient scenes (the pass histories, railtherm_green.history); it refuses what
    superposition cannot represent: bodies at different bulk temperatures, and the steady depth field."""
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient")
    assert GreenTemperature().supports(railtherm.load_scene(scene), 0) is None
    warm = railtherm.testing.canonical("ellipse-full-sliding", mode="transient")
    warm["wheel"] = {**warm["wheel"], "bulk_temperature": 50.0}
    why = GreenTemperature().supports(railtherm.load_scene(warm), 0)
    assert why is not None and "bulk temperature" in why
    deep = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", outputs=["temperature"])
    why = GreenTemperature().supports(railtherm.load_scene(deep), 0)
    assert why is not None and "temperature_history" in why


def test_study_file_matches_published_inputs_and_runs():
    import tomllib
    pub_path = Path(__file__).resolve().parent / "data" / "published.toml"
    if not pub_path.exists():
        pytest.skip("published.toml not found")
    with open(pub_path, "rb") as f:
        ek = tomllib.load(f)["ertz_knothe_2002"]
    study = railtherm.load_study(STUDY)
    assert study.reference == "analytic" and "green" in study.methods
    assert len(study.scenes) == 2 * 5                      # two speeds x convection 0, 10, 30, 100, 1000
    assert sorted({s.convection for s in study.scenes}) == [0.0, 10.0, 30.0, 100.0, 1000.0]
    for sc in study.scenes:
        case = ek["low_speed"] if sc.name.startswith("low") else ek["high_speed"]
        assert (sc.speed, sc.sliding_speed, sc.friction.nominal) == (case["speed"], case["sliding_speed"], case["friction"])
        assert sc.normal_force == ek["normal_force"] and list(sc.semi_axes) == ek["semi_axes"]
        for body in (sc.wheel, sc.rail):
            assert (body.density, body.specific_heat, body.conductivity) == (ek["density"], ek["specific_heat"],
                                                                             ek["conductivity"])
        assert sc.wheel_radius == pytest.approx(1 / (2 * ek["curvatures"][0]), rel=1e-4)
        ds = railtherm.solve(sc, "green", level=1, options=study.options.get("green"))
        assert float(ds.max_surface_temperature.max()) == pytest.approx(case["max_surface_temperature"], rel=0.015)
        th, tm = case["steady"][f"{sc.convection:g}"]
        assert float(ds.steady_wheel_temperature) == pytest.approx(th, rel=0.01, abs=0.1)
        assert float(ds.steady_mean_contact_temperature) == pytest.approx(tm, rel=0.01)
