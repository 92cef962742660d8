"""The report's section for wheelsets on profiles (core/railtherm/report/wheelset_section.py). The section is a
reader: its table, figures and key finding hold the run files' and metrics.nc's numbers patch by patch, which
is what is checked, on a study's data built here (fast), and, opt-in (``-m slow``), on three contacts of the
Manchester benchmark A-2.2 (right wheel at 5 mm lateral shift, two patches, and 6 mm; left wheel at 6 mm; every
patch of each, wheelset.patch = "all", each keeping its pressure field for the patch shapes) run by the exact chain
and a Hertz + FASTSIM chain at level 0 and written by ``railtherm run``.

Run: ``OPENBLAS_NUM_THREADS=1 MPLBACKEND=Agg python -m pytest -q tests/test_report_wheelset.py``
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.contract.schema import variable_attrs
from railtherm.report.document import Document
from railtherm.report.load import Run, SceneInfo, StudyData, load
from railtherm.report import wheelset_figures as WF
from railtherm.report.figures import Palette
from railtherm.report.wheelset_data import (FLASH, QUANTITIES, patch_error, patch_values, role_of, shape_scenes,
                                            wheelset_scenes)
from railtherm.report.wheelset_figures import patch_shapes
from railtherm.report.wheelset_section import wheelset_findings, wheelset_section
from studies import steel

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
""" + steel("wheel") + steel("rail")
POSITIONS = [("p11-right", 5e-3, 0.012, -3.554e-4, -4.3353637, "right"),
             ("p13-right", 6e-3, 0.0144, -6.272e-4, -4.3293718, "right"),
             ("p13-left", 6e-3, 0.0144, -6.272e-4, -4.3293718, "left")]


def _scene(name, shift, yaw, roll, pitch, side) -> str:
    return (f'[[scene]]\nname = "{name}"\nwheelset = {{ wheel_profile = "{DATA / "MBench_S1002_v3.prw"}", '
            f'rail_profile = "{DATA / "MBench_UIC60_v3.prr"}", nominal_radius = 0.46, lateral_shift = {shift}, '
            f'yaw_angle = {yaw}, roll_angle = {roll}, pitch_velocity = {pitch}, vertical_force = 10000.0, '
            f'side = "{side}" }}\n')


# -- fast: a study's data built here -------------------------------------------------------------------------
#: (scene, side, shift [m], kalker's and the Hertz chain's hotter-body flash temperature [degC] per patch, the
#: chain's stored error against kalker per patch [1]); a contact angle of -0.3 rad makes a flange patch
FAKE = [("r0", "right", 0.0, [10.0], [10.2], [0.02]), ("r1", "right", 1e-3, [20.0], [23.0], [0.15]),
        ("r2", "right", 2e-3, [30.0], [33.0], [0.10]), ("r3", "right", 3e-3, [40.0, 8.0], [40.4, 8.1], [0.01, 0.0125]),
        ("r4", "right", 4e-3, [50.0, 9.0], [45.0, 9.9], [0.10, 0.10]), ("l0", "left", 0.0, [5.0], [5.1], [0.02])]
ANGLES = {1: -0.1, 2: -0.3}     # patch 1 on the tread, patch 2 on the flange root [rad]


def _result(flash, patches) -> xr.Dataset:
    """A result: one patch without a patch dimension, several with it (as wheelset.patch = "all" gives)."""
    k = np.arange(1, len(flash) + 1)
    angle = np.array([ANGLES[i] for i in k])
    per = {"contact_position_rail": -0.02 + angle * 1e-2, "contact_angle": angle, "normal_force": 5e3 / k,
           "max_pressure": 8e8 / k, "creep_force_x": 1e3 / k, "creep_force_y": -2e3 / k}
    if patches:
        data = {q: (("patch",), v) for q, v in per.items()}
        data[FLASH] = (("body", "patch"), [flash, [t - 1.0 for t in flash]])
        ds = xr.Dataset(data, coords={"body": ["wheel", "rail"], "patch": k}, attrs={"wheelset_patch": "all"})
    else:
        data = {q: ((), v[0]) for q, v in per.items()}
        data[FLASH] = (("body",), [flash[0], flash[0] - 1.0])
        ds = xr.Dataset(data, coords={"body": ["wheel", "rail"]}, attrs={"wheelset_patch": 1})
    for v in ds.data_vars:
        ds[v].attrs.update(variable_attrs(v))
    return ds


def _fake_data(tmp_path, patch_key="all") -> StudyData:
    """Six contacts, the two at 3 and 4 mm with a flange patch beside the tread patch; the Hertz chain's errors as
    metrics.nc stores them (patch_errors_<metric> for a result with patches, else the signed error)."""
    runs, info, files = [], {}, {}
    for name, side, shift, tk, th, err in FAKE:
        scene = SimpleNamespace(profile_contact=SimpleNamespace(side=side, patch=patch_key),
                                source={"wheelset": {"lateral_shift": shift}},
                                wheel=SimpleNamespace(bulk_temperature=0.0))
        info[name] = SceneInfo(name, reference_kind="kalker", scene=scene)
        several = patch_key == "all"
        runs.append(Run(name, "kalker", 0, "unverified"))
        signed = max(err, key=abs) * (1 if th[err.index(max(err, key=abs))] > tk[err.index(max(err, key=abs))] else -1)
        runs.append(Run(name, "hertz", 0, "inaccurate" if max(err) > 0.05 else "ok",
                        references={FLASH: "method:kalker"}, signed={FLASH: signed},
                        patch_errors={FLASH: dict(enumerate(err, 1))} if several and len(err) > 1 else {}))
        files[name, "kalker", 0] = _result(tk, several and len(tk) > 1)
        files[name, "hertz", 0] = _result(th, several and len(th) > 1)
    data = StudyData(out=tmp_path, name="fake", tolerance=0.05, runs=runs, scenes=[f[0] for f in FAKE],
                     methods=["hertz", "kalker"], levels=[0], info={}, study=None, scene=info, orders={}, cross={},
                     curves=None)
    data._files.update(files)
    return data


def test_patches_are_read_per_patch_and_told_apart_by_the_contact_angle(tmp_path):
    data = _fake_data(tmp_path)
    assert role_of(-0.19) == "tread" and role_of(-0.2) == "flange" and role_of(0.25) == "flange"
    assert role_of(None) == ""
    (tread,) = patch_values(data, "r0", "kalker")
    assert (tread.patch, tread.role, tread.values[FLASH]) == (1, "tread", 10.0)
    tread, flange = patch_values(data, "r4", "hertz")
    assert (flange.patch, flange.role, flange.values[FLASH], flange.values["normal_force"]) == (2, "flange", 9.9,
                                                                                                2.5e3)
    # metrics.nc's per-patch error, signed as the difference of the values
    e = patch_error(data, "r4", "hertz", "kalker", tread, patch_values(data, "r4", "kalker")[0])
    assert (e.error, e.reference, e.stored) == (-0.10, "method:kalker", True)
    e = patch_error(data, "r4", "hertz", "kalker", flange, patch_values(data, "r4", "kalker")[1])
    assert e.error == 0.10


def test_finding_names_the_shifts_per_patch_and_the_reference(tmp_path):
    data = _fake_data(tmp_path)
    assert {k: [s for _, s in v] for k, v in wheelset_scenes(data).items()} == \
        {"right": ["r0", "r1", "r2", "r3", "r4"], "left": ["l0"]}
    (text,) = wheelset_findings(data)
    assert ("more than 5.0 % off the exact chain `kalker` at lateral shifts 1–2, 4 mm (tread patch) and 4 mm "
            "(flange patch) on the right wheel (largest +15 % at 1 mm, right wheel, tread patch, where `kalker` "
            "gives 20 °C; at the hottest contact, 4 mm, right wheel, tread patch, 50 °C, it is −10 %).") in text
    assert ("Reference of the errors: 8 patch errors are metrics.nc's (reference `method:kalker`: `kalker`'s "
            "finest successful level (level 0), each patch against its same patch).") in text
    assert "[`hertz`](#wheelset-on-profiles)" in text and "left" not in text


def test_finding_reads_the_run_files_where_metrics_has_no_error_against_the_reference(tmp_path):
    data = _fake_data(tmp_path)
    for r in data.runs:
        r.references, r.signed, r.patch_errors = {}, {}, {}
    (text,) = wheelset_findings(data)
    # (45 - 50) / 50 on r4's tread patch, (23 - 20) / 20 on r1's
    assert "largest +15 % at 1 mm" in text and "and 4 mm (flange patch) on the right wheel" in text
    assert "8 are taken from the run files' values (metrics.nc has no error against `kalker` for them)" in text


def _ctx(data, drawn, tmp_path):
    def draw(doc, name, caption, fn, *args):
        drawn[name] = (caption, args, fn(*args, path=tmp_path / f"{name}.png"))
    return SimpleNamespace(data=data, palette=Palette(data.methods), draw=draw)


def test_section_table_figures_and_key_finding(tmp_path, monkeypatch):
    data = _fake_data(tmp_path)
    figs = {}
    monkeypatch.setattr(WF, "save", lambda fig, path: figs.setdefault(path.stem, fig) and (path, 900))
    drawn = {}
    doc = Document()
    wheelset_section(doc, _ctx(data, drawn, tmp_path))
    md = doc.markdown()
    assert "## Wheelset on profiles" in md and "**Key finding:** On the wheelset on profiles" in md
    assert "Reference of the errors:" in md
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in md.splitlines()
            if line.startswith("| right | 4 |")]
    # kalker first (the reference): patch, y [mm], angle, N [kN], p0 [MPa], T_max; then the chain's and its error
    assert rows == [["right", "4", "1 tread", "-21", "-0.1", "5", "800", "50", "800", "45", "−10 %"],
                    ["right", "4", "2 flange", "-23", "-0.3", "2.5", "400", "9", "400", "9.9", "+10 %"]]
    caption, (panels, methods, _), _ = drawn["wheelset-against-shift"]
    assert methods == ["kalker", "hertz"]
    assert panels["right"][FLASH][("hertz", "tread")] == [(0.0, 10.2), (1.0, 23.0), (2.0, 33.0), (3.0, 40.4),
                                                         (4.0, 45.0)]
    assert panels["right"][FLASH][("hertz", "flange")] == [(3.0, 8.1), (4.0, 9.9)]
    assert "tread: solid lines" in caption and "flange: dashed" in caption
    # every panel has its quantity and unit on the y axis, the bottom row the lateral shift in mm
    fig = figs["wheelset-against-shift"]
    axes = fig.axes
    assert len(axes) == 2 * len(QUANTITIES)
    for ax in axes:
        assert re.search(r"\[(mm|rad|kN|MPa|°C)\]", ax.get_ylabel()), ax.get_ylabel()
    assert sum(ax.get_xlabel() == "lateral shift of the wheelset [mm]" for ax in axes) == 2
    styles = {(line.get_color(), line.get_linestyle()) for ax in axes for line in ax.get_lines()}
    assert {ls for _, ls in styles} == {"-", "--"}
    # no pressure fields in a result with patches: the shapes are not drawn, and the section says why
    assert "wheelset-patch-shapes" not in drawn and "The patch shapes are not drawn" in md


def test_no_section_without_a_wheelset_on_profiles(tmp_path):
    data = _fake_data(tmp_path)
    for si in data.scene.values():
        si.scene = SimpleNamespace(source={})
    doc = Document()
    wheelset_section(doc, SimpleNamespace(data=data, palette=None, draw=None))
    assert "Wheelset" not in doc.markdown() and wheelset_findings(data) == []


def _with_fields(data):
    """Scenes of one patch at 0 mm whose runs keep a pressure field on a 5 x 3 grid (6 cells in contact for
    kalker, 3 for the Hertz chain), on a contact plane at y0 = -10 mm and -0.5 rad."""
    x, y = np.linspace(-2e-3, 2e-3, 5), np.linspace(-1e-3, 1e-3, 3)
    for name, side, shift, *_ in FAKE:
        si = data.scene[name]
        si.scene.profile_contact = SimpleNamespace(side=side, patch=1, plane_position_rail=-0.01, plane_angle=-0.5,
                                                   contact_position_rail=-0.011, contact_height_rail=2e-4,
                                                   contact_angle=-0.1, normal_force=1e4,
                                                   rail_section=((-0.03, 0.0, 0.03), (1e-3, 0.0, 1e-3)))
        for m, cells in (("kalker", (slice(1, 4), slice(1, None))), ("hertz", (slice(1, 4), 1))):
            p = np.zeros((5, 3))
            p[cells] = 1e8
            ds = data._files[name, m, 0]
            data._files[name, m, 0] = ds.assign(pressure=(("x", "y"), p)).assign_coords(x=x, y=y)
    return x, y


def test_patch_shapes_are_placed_on_the_rail_by_the_contact_plane(tmp_path):
    """The shapes figure's data: each method's cells with pressure at y = y0 + s cos(delta0) on the rail (s
    across the contact plane), at the shift 0 mm the study has (5 and 6.5 mm it has not)."""
    data = _fake_data(tmp_path, patch_key=1)
    x, y = _with_fields(data)
    shapes = patch_shapes(data, shape_scenes(data), ["kalker", "hertz"])
    assert [(s.shift, s.method) for s in shapes["right"]] == [(0.0, "kalker"), (0.0, "hertz")]
    kalker, hertz = shapes["right"]
    assert (kalker.point, kalker.role, kalker.patch, kalker.normal_force) == ((-0.011, 2e-4), "tread", 1, 5e3)
    assert np.allclose(kalker.y, -0.01 + y * np.cos(-0.5)) and np.array_equal(kalker.x, x)
    assert kalker.inside.sum() == 6 and kalker.inside[1:4, 1:].all() and hertz.inside.sum() == 3


def test_shapes_figure_is_drawn_with_units(tmp_path, monkeypatch):
    data = _fake_data(tmp_path, patch_key=1)
    _with_fields(data)
    figs, drawn = {}, {}
    monkeypatch.setattr(WF, "save", lambda fig, path: figs.setdefault(path.stem, fig) and (path, 900))
    doc = Document()
    wheelset_section(doc, _ctx(data, drawn, tmp_path))
    caption = drawn["wheelset-patch-shapes"][0]
    assert "`kalker` filled, `hertz` outlined dashed" in caption and "share it" not in caption
    for ax in figs["wheelset-patch-shapes"].axes:
        assert re.search(r"\[mm\]", ax.get_xlabel()) and re.search(r"\[mm\]", ax.get_ylabel())


def _with_patch_fields(data):
    """The 0 mm right contact as a result of two patches (wheelset.patch = "all") keeping each patch's pressure on
    its own grid, padded with NaN (contract.patch_grid): patch 1 on the tread (5 x 3 cells, contact plane at
    y0 = -10 mm, -0.05 rad), patch 2 on the flange root (4 x 2 cells, y0 = -35 mm, -0.3 rad), 6 and 2 cells in
    contact for kalker (1 and 2 for the Hertz chain), 8 and 2 kN."""
    grids = {1: (np.linspace(-2e-3, 2e-3, 5), np.linspace(-1e-3, 1e-3, 3)),
             2: (np.linspace(-1.5e-3, 1.5e-3, 4), np.linspace(-0.5e-3, 0.5e-3, 2))}
    planes = {1: (-0.01, -0.05), 2: (-0.035, -0.3)}
    contacts = tuple(SimpleNamespace(patch=k, plane_position_rail=planes[k][0], plane_angle=planes[k][1],
                                     contact_position_rail=planes[k][0] - 1e-3, contact_height_rail=1e-3 * k,
                                     contact_angle=planes[k][1], normal_force=math.nan) for k in (1, 2))
    si = data.scene["r0"]
    si.scene.profile_contact = SimpleNamespace(side="right", patch="all", contacts=contacts,
                                               rail_section=((-0.05, 0.0, 0.03), (2e-2, 0.0, 1e-3)))
    cells = {"kalker": {1: (slice(1, 4), slice(1, None)), 2: (slice(1, 3), 0)},
             "hertz": {1: (2, 1), 2: (slice(1, 3), 1)}}
    for m in ("kalker", "hertz"):
        p = np.full((5, 3, 2), np.nan)
        px, py = np.full((5, 2), np.nan), np.full((3, 2), np.nan)
        for k, (x, y) in grids.items():
            p[:x.size, :y.size, k - 1] = 0.0
            p[(*cells[m][k], k - 1)] = 1e8
            px[:x.size, k - 1], py[:y.size, k - 1] = x, y
        ds = _result([10.0, 3.0], True).assign(normal_force=("patch", [8e3, 2e3], variable_attrs("normal_force")),
                                                  pressure=(("x", "y", "patch"), p, variable_attrs("pressure")))
        data._files["r0", m, 0] = ds.assign_coords(patch_x=(("x", "patch"), px), patch_y=(("y", "patch"), py))
    return grids, planes


def test_patch_shapes_of_several_patches_come_from_each_patch_field(tmp_path):
    """A result of every patch: one shape per patch and method, each from its own field on its own grid (padding
    dropped), placed by its own contact plane, with its own share of the load and its role."""
    data = _fake_data(tmp_path)
    grids, planes = _with_patch_fields(data)
    shapes = patch_shapes(data, shape_scenes(data), ["kalker", "hertz"])
    assert [(s.shift, s.patch, s.method, s.role, s.shared) for s in shapes["right"]] == [
        (0.0, 1, "kalker", "tread", True), (0.0, 1, "hertz", "tread", True),
        (0.0, 2, "kalker", "flange", True), (0.0, 2, "hertz", "flange", True)]
    k1, h1, k2, h2 = shapes["right"]
    assert (k1.normal_force, k2.normal_force) == (8e3, 2e3)
    assert k2.point == (planes[2][0] - 1e-3, 2e-3) and np.array_equal(k2.x, grids[2][0])
    assert np.allclose(k2.y, planes[2][0] + grids[2][1] * np.cos(planes[2][1]))
    assert k2.inside.shape == (4, 2) and k2.inside.sum() == 2 and k1.inside.sum() == 6
    assert (h1.inside.sum(), h2.inside.sum()) == (1, 2)


def test_shapes_caption_says_each_patch_carries_its_share(tmp_path, monkeypatch):
    data = _fake_data(tmp_path)
    _with_patch_fields(data)
    figs, drawn = {}, {}
    monkeypatch.setattr(WF, "save", lambda fig, path: figs.setdefault(path.stem, fig) and (path, 900))
    doc = Document()
    wheelset_section(doc, _ctx(data, drawn, tmp_path))
    caption, (rails, shapes, reference), _ = drawn["wheelset-patch-shapes"]
    assert "its own pressure field" in caption and "its own share of the wheel's vertical force" in caption
    assert "whole vertical force" not in caption and reference == "kalker"
    labels = [t.get_text() for ax in figs["wheelset-patch-shapes"].axes for t in
              (ax.get_legend().get_texts() if ax.get_legend() else [])]
    assert "0 mm, tread 1, N = 8 kN" in labels and "0 mm, flange 2, N = 2 kN" in labels


# -- slow: the benchmark's contacts through railtherm run --------------------------------------------------------
@pytest.fixture(scope="module")
def out(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheelset")
    path = tmp / "wheelset.toml"
    scenes = [_scene(*p).replace('" }', '", patch = "all" }') for p in POSITIONS]
    path.write_text(STUDY.replace('"max_pressure", "max_surface_temperature"]',
                                  '"max_pressure", "contact_position_rail", "contact_angle", '
                                  '"max_surface_temperature", "pressure"]') + "".join(scenes))
    out = tmp / "out"
    railtherm.run_study(path, out=out, executor="serial")   # writes the report
    return out


def _run(out, scene, method) -> xr.Dataset:
    return xr.open_dataset(out / "runs" / scene / method / "level-0.nc")


@pytest.mark.slow
def test_study_section_table_holds_the_run_files_numbers_per_patch(out):
    md = (out / "report.md").read_text()
    assert "## Wheelset on profiles: the patches and their flash temperature against lateral shift" in md
    assert (out / "figures" / "wheelset-against-shift.png").exists()
    assert (out / "figures" / "wheelset-patch-shapes.png").exists()       # the 5 mm patches, right wheel
    seen = 0
    for name, shift, *_, side in POSITIONS:
        k, h = _run(out, name, "kalker"), _run(out, name, "hertz-fastsim-green")
        assert "patch" in k.dims
        for p in k["patch"].values:
            row = next(line for line in md.splitlines()
                       if line.startswith(f"| {side} | {shift * 1e3:g} | {p} "))
            cells = [c.strip() for c in row.strip("|").split("|")]
            kp, hp = k.sel(patch=p), h.sel(patch=p)
            assert cells[2] == f"{p} {'flange' if abs(float(kp['contact_angle'])) >= 0.2 else 'tread'}"
            assert float(cells[3]) == pytest.approx(float(kp["contact_position_rail"]) * 1e3, abs=5e-3)
            assert float(cells[4]) == pytest.approx(float(kp["contact_angle"]), rel=5e-3)
            assert float(cells[5]) == pytest.approx(float(kp["normal_force"]) * 1e-3, rel=5e-3)
            assert float(cells[7]) == pytest.approx(float(kp["max_surface_temperature"].max()), rel=5e-4)
            assert float(cells[9]) == pytest.approx(float(hp["max_surface_temperature"].max()), rel=5e-4)
            # each chain reports its own patch's reference point (attribute wheelset_reference_point): the exact
            # chain the CONTACT program's at kalker's approach, the Hertz chain the contact search's (measured here:
            # angles 0.0015 rad apart at most)
            assert float(hp["contact_angle"]) == pytest.approx(float(kp["contact_angle"]), abs=0.005)
            assert h.attrs["wheelset_reference_point"] != k.attrs["wheelset_reference_point"]
            seen += 1
    assert seen == 4          # 5 mm right has a tread and a flange-root patch
    assert "| right | 5 | 1 flange |" in md and "| right | 5 | 2 tread |" in md


@pytest.mark.slow
def test_study_key_finding_names_the_shifts_off_by_more_than_the_tolerance(out):
    data = load(out)
    assert {side: [s for _, s in g] for side, g in wheelset_scenes(data).items()} == \
        {"right": ["p11-right", "p13-right"], "left": ["p13-left"]}
    m = xr.open_dataset(out / "metrics.nc")
    off = {}
    for i in range(m.sizes["run"]):
        if str(m["method"].values[i]) == "hertz-fastsim-green" and str(m["scene"].values[i]) in \
                ("p11-right", "p13-right", "p13-left"):
            assert str(m["reference_max_surface_temperature"].values[i]) == "method:kalker"
            errs = str(m["patch_errors_max_surface_temperature"].values[i])
            for part in errs.split("; "):
                p, e = part.split(": ")
                off[str(m["scene"].values[i]), int(p)] = float(e) > 0.05
    assert len(off) == 4
    (text,) = wheelset_findings(data)
    assert "`hertz-fastsim-green`" in text and "`kalker`" in text
    assert "Reference of the errors: 4 patch errors are metrics.nc's (reference `method:kalker`" in text
    if not any(off.values()):
        assert "within 5.0 %" in text
    right = text.split(" on the right wheel")[0] if " on the right wheel" in text else ""
    assert bool(re.search(r"\b5(–6)? mm \(flange patch\)", right)) == off["p11-right", 1]
    assert bool(re.search(r"\b5 mm \(tread patch\)", right)) == off["p11-right", 2]
    assert ("6 mm (tread patch) on the left wheel" in text) == off["p13-left", 1]
    md = (out / "report.md").read_text()
    verdict = md.split("### Key findings", 1)[1].split("\n\n", 2)[1]
    assert "flash temperature of [`hertz-fastsim-green`](#wheelset-on-profiles)" in verdict


@pytest.mark.slow
def test_profile_patches_are_not_reported_as_typed_in_gaps(out):
    """The exact-contact section's paragraph and table for a typed-in non-Hertzian gap ("only kalker runs it",
    "beside the Hertzian ellipse ...") are not written for the wheelset's patches: other chains run them with
    the equivalent ellipse, and they have their own section."""
    md = (out / "report.md").read_text()
    assert "Non-Hertzian contact" not in md and "beside the Hertzian ellipse" not in md
