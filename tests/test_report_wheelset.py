"""The report's section for wheelsets on profiles (core/railtherm/report/wheelset_section.py). The section is a
reader: its table and key finding hold the run files' and metrics.nc's numbers, which is what is checked, on
a study's data built here (fast), and, opt-in (``-m slow``), on three contacts of the Manchester benchmark
A-2.2 (right wheel at 5 and 6 mm lateral shift, left wheel at 6 mm) run by the exact chain and a Hertz +
FASTSIM chain at level 0 and written by ``railtherm run``.

Run: ``OPENBLAS_NUM_THREADS=1 MPLBACKEND=Agg python -m pytest -q tests/test_report_wheelset.py``
"""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.contract.schema import variable_attrs
from railtherm.report.document import Document
from railtherm.report.load import Run, SceneInfo, StudyData, load
from railtherm.report.wheelset_section import _shapes, wheelset_findings, wheelset_scenes, wheelset_section

DATA = Path(__file__).resolve().parent / "data" / "profiles"

STUDY = """
schema_version = 1
[study]
name = "wheelset-mini"
methods = ["kalker", "hertz-fastsim-green"]
levels = [0]
reference = "kalker"
tolerance = 0.05
repeat = 1
[study.chains.hertz-fastsim-green]
normal = ["wheelset-profile"]
tangential = "fastsim"
temperature = "green"
[defaults]
speed = 2.0
friction = 0.3
outputs = ["normal_force", "creep_force_x", "creep_force_y", "max_pressure", "max_surface_temperature"]
[defaults.wheel]
shear_modulus = 82e9
poisson_ratio = 0.28
[defaults.rail]
shear_modulus = 82e9
poisson_ratio = 0.28
"""
POSITIONS = [("p11-right", 5e-3, 0.012, -3.554e-4, -4.3353637, "right"),
             ("p13-right", 6e-3, 0.0144, -6.272e-4, -4.3293718, "right"),
             ("p13-left", 6e-3, 0.0144, -6.272e-4, -4.3293718, "left")]


def _scene(name, shift, yaw, roll, pitch, side) -> str:
    return (f'[[scene]]\nname = "{name}"\nwheelset = {{ wheel_profile = "{DATA / "MBench_S1002_v3.prw"}", '
            f'rail_profile = "{DATA / "MBench_UIC60_v3.prr"}", nominal_radius = 0.46, lateral_shift = {shift}, '
            f'yaw_angle = {yaw}, roll_angle = {roll}, pitch_velocity = {pitch}, vertical_force = 10000.0, '
            f'side = "{side}" }}\n')


# -- fast: a study's data built here -------------------------------------------------------------------------
#: (scene, side, shift [m], kalker's and the Hertz chain's hotter-body flash temperature [degC], the chain's
#: stored signed error against kalker)
FAKE = [("r0", "right", 0.0, 10.0, 10.2, 0.02), ("r1", "right", 1e-3, 20.0, 23.0, 0.15),
        ("r2", "right", 2e-3, 30.0, 33.0, 0.10), ("r3", "right", 3e-3, 40.0, 40.4, 0.01),
        ("r4", "right", 4e-3, 50.0, 45.0, -0.10), ("l0", "left", 0.0, 5.0, 5.1, 0.02)]


def _result(angle, flash) -> xr.Dataset:
    data = {"contact_position_rail": ((), -0.02 - angle * 1e-2), "contact_angle": ((), angle),
            "max_pressure": ((), 8e8), "creep_force_x": ((), 1e3), "creep_force_y": ((), -2e3),
            "max_surface_temperature": (("body",), [flash, flash - 1.0])}
    ds = xr.Dataset(data, coords={"body": ["wheel", "rail"]})
    for k in ds.data_vars:
        ds[k].attrs.update(variable_attrs(k))
    return ds


def _fake_data(tmp_path) -> StudyData:
    runs, info, files = [], {}, {}
    for name, side, shift, tk, th, err in FAKE:
        scene = SimpleNamespace(profile_contact=SimpleNamespace(side=side), source={"wheelset": {"lateral_shift": shift}},
                                wheel=SimpleNamespace(bulk_temperature=0.0))
        info[name] = SceneInfo(name, reference_kind="kalker", scene=scene)
        runs.append(Run(name, "kalker", 0, "ok"))
        runs.append(Run(name, "hertz", 0, "inaccurate" if abs(err) > 0.05 else "ok",
                        references={"max_surface_temperature": "method:kalker"},
                        signed={"max_surface_temperature": err}))
        files[name, "kalker", 0] = _result(-0.1 * shift * 1e3, tk)
        files[name, "hertz", 0] = _result(-0.1 * shift * 1e3, th)
    data = StudyData(out=tmp_path, name="fake", tolerance=0.05, runs=runs, scenes=[f[0] for f in FAKE],
                     methods=["hertz", "kalker"], levels=[0], info={}, study=None, scene=info, orders={}, cross={},
                     curves=None)
    data._files.update(files)
    return data


def test_finding_names_the_shifts_off_by_more_than_the_tolerance(tmp_path):
    data = _fake_data(tmp_path)
    assert {k: [s for _, s in v] for k, v in wheelset_scenes(data).items()} == \
        {"right": ["r0", "r1", "r2", "r3", "r4"], "left": ["l0"]}
    (text,) = wheelset_findings(data)
    assert ("more than 5.0 % off the exact chain `kalker` at lateral shifts 1–2, 4 mm on the right wheel (largest "
            "+15 % at 1 mm, right wheel, where `kalker` gives 20 °C)") in text
    assert "[`hertz`](#wheelset-on-profiles)" in text and "left" not in text


def test_section_table_and_figure_call(tmp_path):
    data = _fake_data(tmp_path)
    drawn = []
    ctx = SimpleNamespace(data=data, palette=None, draw=lambda doc, name, caption, fn, *a: drawn.append((name, a)))
    doc = Document()
    wheelset_section(doc, ctx)
    md = doc.markdown()
    assert "## Wheelset on profiles" in md and "**Key finding:** " in md
    row = next(line for line in md.splitlines() if line.startswith("| right | 4 |"))
    # kalker first (the reference): y [mm], angle, p0 [MPa], T_max; then the chain's p0, T_max and error
    assert [c.strip() for c in row.strip("|").split("|")] == ["right", "4", "-16", "-0.4", "800", "50", "800",
                                                              "45", "−10 %"]
    (name, (panels, methods, _)), = drawn
    assert name == "wheelset-against-shift" and methods == ["kalker", "hertz"]
    assert panels["right"]["max_surface_temperature"]["hertz"] == [(0.0, 10.2), (1.0, 23.0), (2.0, 33.0),
                                                                   (3.0, 40.4), (4.0, 45.0)]


def test_no_section_without_a_wheelset_on_profiles(tmp_path):
    data = _fake_data(tmp_path)
    for si in data.scene.values():
        si.scene = SimpleNamespace(source={})
    doc = Document()
    wheelset_section(doc, SimpleNamespace(data=data, palette=None, draw=None))
    assert "Wheelset" not in doc.markdown() and wheelset_findings(data) == []


def test_patch_shapes_are_placed_on_the_rail_by_the_contact_plane(tmp_path):
    """The shapes figure's data: the reference method's cells with pressure, at y = y0 + s cos(delta0) on the
    rail (s across the contact plane), at the shift 0 mm the study has (5 and 6.5 mm it has not)."""
    data = _fake_data(tmp_path)
    for name, side, shift, *_ in FAKE:
        si = data.scene[name]
        si.scene.profile_contact = SimpleNamespace(side=side, plane_position_rail=-0.01, plane_angle=-0.5,
                                                   contact_position_rail=-0.011, contact_height_rail=2e-4)
        ds = data._files[name, "kalker", 0]
        x, y = np.linspace(-2e-3, 2e-3, 5), np.linspace(-1e-3, 1e-3, 3)
        p = np.zeros((5, 3))
        p[1:4, 1:] = 1e8
        data._files[name, "kalker", 0] = ds.assign(pressure=(("x", "y"), p)).assign_coords(x=x, y=y)
    shapes = _shapes(data, wheelset_scenes(data), "kalker")
    assert [s[0] for s in shapes["right"]] == [0.0] and [s[0] for s in shapes["left"]] == [0.0]
    (shift, ref, (yr, xr, inside)), = shapes["right"]
    assert ref == (-0.011, 2e-4)
    assert np.allclose(yr, -0.01 + y * np.cos(-0.5)) and np.array_equal(xr, x)
    assert inside.sum() == 6 and inside[1:4, 1:].all()


# -- slow: the benchmark's contacts through railtherm run --------------------------------------------------------
@pytest.fixture(scope="module")
def out(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheelset")
    path = tmp / "wheelset.toml"
    path.write_text(STUDY + "".join(_scene(*p) for p in POSITIONS))
    out = tmp / "out"
    railtherm.run_study(path, out=out, executor="serial")   # writes the report
    return out


def _run(out, scene, method) -> xr.Dataset:
    return xr.open_dataset(out / "runs" / scene / method / "level-0.nc")


@pytest.mark.slow
def test_study_section_table_holds_the_run_files_numbers(out):
    md = (out / "report.md").read_text()
    assert "## Wheelset on profiles: the patch and its flash temperature against lateral shift" in md
    assert (out / "figures" / "wheelset-against-shift.png").exists()
    assert (out / "figures" / "wheelset-patch-shapes.png").exists()       # the 5 mm patch, right wheel
    for name, shift, *_, side in POSITIONS:
        k, h = _run(out, name, "kalker"), _run(out, name, "hertz-fastsim-green")
        row = next(line for line in md.splitlines() if line.startswith(f"| {side} | {shift * 1e3:g} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert float(cells[2]) == pytest.approx(float(k["contact_position_rail"]) * 1e3, abs=5e-3)
        assert float(cells[3]) == pytest.approx(float(k["contact_angle"]), rel=5e-3)
        assert float(cells[5]) == pytest.approx(float(k["max_surface_temperature"].max()), rel=5e-4)
        assert float(cells[7]) == pytest.approx(float(h["max_surface_temperature"].max()), rel=5e-4)
        # position and angle are the contact search's: the same numbers in both chains' results
        assert float(h["contact_angle"]) == float(k["contact_angle"])


@pytest.mark.slow
def test_study_key_finding_names_the_shifts_off_by_more_than_the_tolerance(out):
    data = load(out)
    assert {side: [s for _, s in g] for side, g in wheelset_scenes(data).items()} == \
        {"right": ["p11-right", "p13-right"], "left": ["p13-left"]}
    m = xr.open_dataset(out / "metrics.nc")
    off = {}
    for i in range(m.sizes["run"]):
        if str(m["method"].values[i]) == "hertz-fastsim-green":
            e = float(m["error_max_surface_temperature"].values[i])
            assert str(m["reference_max_surface_temperature"].values[i]) == "method:kalker"
            off[str(m["scene"].values[i])] = math.isfinite(e) and e > 0.05
    (text,) = wheelset_findings(data)
    assert "`hertz-fastsim-green`" in text and "`kalker`" in text
    named = {"p11-right": "5 mm on the right", "p13-right": "6 mm on the right", "p13-left": "6 mm on the left"}
    if not any(off.values()):
        assert "within 5.0 %" in text
    for scene, miss in off.items():
        assert (named[scene] in text) == miss or (scene == "p11-right" and miss and "5–6 mm on the right" in text)
    md = (out / "report.md").read_text()
    verdict = md.split("### Key findings", 1)[1].split("\n\n", 2)[1]
    assert "flash temperature of [`hertz-fastsim-green`](#wheelset-on-profiles)" in verdict
    assert np.isfinite(list(off.values())).all()


@pytest.mark.slow
def test_profile_patches_are_not_reported_as_typed_in_gaps(out):
    """The exact-contact section's paragraph and table for a typed-in non-Hertzian gap ("only kalker runs it",
    "beside the Hertzian ellipse ...") are not written for the wheelset's patches: other chains run them with
    the equivalent ellipse, and they have their own section."""
    md = (out / "report.md").read_text()
    assert "Non-Hertzian contact" not in md and "beside the Hertzian ellipse" not in md
