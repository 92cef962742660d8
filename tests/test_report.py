"""The study report of a small study run end to end: report.md, report.html and figures/*.png.

A small study is run with inline dummy methods (registered through the plugin host exactly like a
plugin): one that computes, one that fails and one that refuses on the finer level, and one that gives
Carter's traction (perturbed by level) on a creepage sweep, so that every part of the report is drawn.
The report's pieces on synthetic metrics are tested in tests/test_report_verdict.py.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import railtherm
from railtherm import ContactPatch, TangentialContactModel, TemperatureField, TemperatureModel
from railtherm.solving.plugins import get_host, new_host, set_host
from studies import steel

STUDY = """
schema_version = 1
[study]
name = "report-test"
methods = ["alpha", "broken", "picky", "creep"]
levels = [0, 1]
reference = "analytic"
repeat = 1
warmup = false

""" + steel("wheel", thermal=True, bulk_temperature=20.0) + steel("rail", thermal=True, bulk_temperature=10.0) + """
[[scene]]
name = "line-sliding"
normal_force = 1e6
contact = { shape = "line", wheel_radius = 0.46 }
speed = 30.0
sliding_speed = 1.0
friction = 0.3
heat_partition = 0.5
outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "temperature",
           "heat_flux", "frictional_power", "pressure"]

[[scene]]
name = "ellipse-convective"
normal_force = 100e3
contact = { shape = "ellipse", semi_axes = [5.88e-3, 10.54e-3] }
speed = 30.0
sliding_speed = 1.0
friction = 0.3
heat_partition = 0.5
convection = 10.0
outputs = ["max_surface_temperature", "surface_temperature", "heat_flux", "frictional_power", "pressure",
           "traction_x", "stick"]

[[scene]]
name = "carter"
normal_force = 2.0e5
contact = { shape = "line", wheel_radius = 0.5 }
speed = 30.0
creepage = { longitudinal = [-1e-3, -4e-4, 0.0, 4e-4, 1e-3], lateral = 0.0, spin = 0.0 }
friction = 0.3
wheel = { bulk_temperature = 10.0 }
outputs = ["creep_force_x", "traction_x", "stick", "pressure"]
"""


def _delta(level: int) -> float:
    """Relative perturbation of the dummy results: first order in h = 2^-level."""
    return 0.2 * 2.0 ** (-level)


class DummyTemperature(TemperatureModel):
    """Jaeger-like 1-D flash profile, scaled by (1 + factor * delta(level)); depth decay exp(-z / d)."""

    name = "report-dummy-temperature"
    description = "test stand-in: a 1-D flash temperature with a level-dependent error"
    # convection declared so that core lets the stand-in run the scene "ellipse-convective" (it ignores it)
    capabilities = railtherm.Capabilities(convection=True,
                                          provides=frozenset({"surface_temperature", "max_surface_temperature",
                                                              "mean_contact_temperature", "temperature"}))
    factor = 1.0

    def compute_temperature(self, scene, source, level, options):
        grid = source.grid
        rises = []
        for body in (0, 1):
            mat = scene.body(body)
            v = source.body_speed[body]
            q = source.flux(body)
            # 1-D flash temperature: running integral of q along the material path (from +a to -a)
            dx = grid.dx
            acc = np.flip(np.cumsum(np.flip(q, axis=0), axis=0), axis=0) * dx
            xi = (grid.a - grid.x) if grid.line else (grid.a - grid.x)[:, None]
            t = 2.0 * acc / (mat.effusivity * np.sqrt(np.pi * v * np.maximum(xi, dx)))
            rises.append(mat.bulk_temperature + t * (1.0 + self.factor * _delta(level)))
        surface = np.stack(rises)
        z = np.linspace(0.0, 3e-4, 31)
        depth = np.sqrt(scene.body(0).diffusivity * 2 * grid.a / scene.speed)
        centre = surface if grid.line else surface[:, :, surface.shape[2] // 2]
        bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])[:, None, None]
        temp = bulk + (centre[:, :, None] - bulk) * np.exp(-z / depth)[None, None, :]
        return TemperatureField.from_surface(grid, surface, z=z, temperature=temp)


class BrokenTemperature(DummyTemperature):
    name = "report-broken-temperature"

    def compute_temperature(self, scene, source, level, options):
        if level >= 1:
            raise RuntimeError("dummy solver diverged on purpose")
        return super().compute_temperature(scene, source, level, options)


class PickyTemperature(DummyTemperature):
    name = "report-picky-temperature"

    def supports(self, scene, level):
        if level >= 1:
            return f"level {level} > 0: this dummy refuses fine grids (use level 0)"
        return super().supports(scene, level)


class CarterContact(TangentialContactModel):
    """Carter's traction on the Hertz line patch, creep force off by delta(level)."""

    name = "report-carter-contact"
    description = "test stand-in: Carter's 2-D traction with a level-dependent error"
    capabilities = railtherm.Capabilities(contacts=frozenset({"line"}), tangential=frozenset({"creepage"}),
                                          provides=frozenset({"traction_x", "stick", "creep_force_x"}))

    def compute_tangential(self, scene, patch, level, options):
        from railtherm.references.carter import carter_2d
        c = carter_2d(scene.creepage.longitudinal, patch.a, scene.friction.nominal, scene.wheel_radius,
                      max_pressure=patch.max_pressure)
        x = patch.grid.x
        inside = patch.pressure > 0
        return patch.with_tangential(traction_x=c.traction(x) * (1 + _delta(level)),
                                     stick=np.where(inside, c.stick(x).astype(float), np.nan),
                                     creep_force_x=c.force_ratio * scene.friction.nominal * patch.normal_force
                                     * (1 + _delta(level)))


class DummyPlugin:
    @railtherm.hookimpl
    def railtherm_register_models(self):
        return [DummyTemperature, BrokenTemperature, PickyTemperature, CarterContact]

    @railtherm.hookimpl
    def railtherm_register_methods(self):
        chain = lambda t: {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": (t,)}
        return [railtherm.Method("alpha", chain("report-dummy-temperature"), default_cells=16),
                railtherm.Method("broken", chain("report-broken-temperature"), default_cells=16),
                railtherm.Method("picky", chain("report-picky-temperature"), default_cells=16),
                railtherm.Method("creep", {"normal": ("hertz",), "tangential": ("report-carter-contact",)}, default_cells=16)]


@pytest.fixture(scope="module")
def study_out(tmp_path_factory):
    """Run the dummy study once, write its reference curves and its report."""
    import railtherm.report as report
    from railtherm.analysis.reference_curves import write_reference_curves
    from railtherm.input.study import load_study
    tmp = tmp_path_factory.mktemp("report")
    path = tmp / "study.toml"
    path.write_text(STUDY)
    old = get_host()
    set_host(new_host([("report-dummy", DummyPlugin())], autoload=False, strict=True))
    try:
        out = tmp / "out"
        railtherm.run_study(str(path), out, report=False)
        write_reference_curves(load_study(path), out)
        bench = {"datetime": "2026-01-01T00:00:00", "machine_info": {"cpu": {"brand_raw": "Test CPU"}},
                 "benchmarks": [{"name": "test_green_speed", "stats": {"mean": 0.0123, "min": 0.0101, "stddev": 1e-4,
                                                                       "rounds": 7},
                                 "extra_info": {"error_max_surface_temperature": 1.234e-3}}]}
        (out / "benchmarks.json").write_text(json.dumps(bench))
        paths = report.write_report(out)
        yield out, paths
    finally:
        set_host(old)


def _sections(md: str) -> dict[str, str]:
    parts = re.split(r"^## ", md, flags=re.M)
    return {p.splitlines()[0]: p for p in parts[1:]}


def test_files_written_and_listed(study_out):
    out, paths = study_out
    assert paths[0] == out / "report.md" and paths[1] == out / "report.html"
    figs = paths[2:]
    assert figs and all(p.parent == out / "figures" and p.suffix == ".png" for p in figs)
    assert sorted(figs) == sorted((out / "figures").glob("*.png")), "stale or unlisted figures"
    for p in figs:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 5000, p


def test_verdict_comes_first(study_out):
    out, _ = study_out
    md = (out / "report.md").read_text()
    assert "could not be drawn" not in md and "not drawn" not in md
    assert re.findall(r"^## (.*)$", md, flags=re.M)[0] == "Verdict"
    verdict = _sections(md)["Verdict"]
    assert "**Table 1.** Scorecard" in verdict
    assert "Key findings" in verdict and "**Figure 1.** Work-precision" in verdict
    header = next(line for line in verdict.splitlines() if line.startswith("| scene"))
    assert [c.strip() for c in header.strip("|").split("|")] == ["scene · headline", "alpha", "broken", "creep",
                                                                 "picky"]
    text = (out / "report.html").read_text()
    body = text.split("<body>", 1)[1]
    assert body.index("<h2") == body.index('<h2 id="verdict">')
    assert body.index("<table") > body.index('<h2 id="verdict">')
    assert "Table 1.</b> Scorecard" in body.split("</table>")[0]


def test_scorecard_cells(study_out):
    """line-sliding: the dummies' errors (20 % and 10 %) exceed the 5 % tolerance, so each cell shows the status
    of the finest level that ran (alpha: level 1 inaccurate; broken: level 1 failed; picky: level 0, the only one
    it ran); creep is refused (its contact model needs creepage)."""
    out, _ = study_out
    verdict = _sections((out / "report.md").read_text())["Verdict"]
    row = next(line for line in verdict.splitlines() if line.startswith("| [line-sliding]"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[0] == "[line-sliding](#scene-line-sliding) · max T"
    assert cells[1].startswith("inaccurate · ") and cells[1].endswith("· level 1")
    assert cells[2].startswith("failed")
    assert cells[4].startswith("inaccurate · ") and cells[4].endswith("· level 0")
    assert cells[3].startswith("refused")
    sweep = next(line for line in verdict.splitlines() if line.startswith("| [carter]"))
    assert "(5 scenes) · Fx" in sweep


def test_scene_sections(study_out):
    out, _ = study_out
    sec = _sections((out / "report.md").read_text())
    assert "1. Scene `line-sliding`" in sec and "2. Scene `ellipse-convective`" in sec
    line = sec["1. Scene `line-sliding`"]
    assert "Headline quantity: **max. surface temperature**" in line and "jaeger" in line.lower()
    # refused and failed runs are one line each, not table rows
    assert "**broken failed level 1**" in line and "dummy solver diverged on purpose" in line
    assert "**picky refused level 1**" in line and "refuses fine grids" in line
    assert "**creep refused levels 0–1**" in line
    assert "| broken | 1 |" not in line and "| creep |" not in line
    assert re.search(r"<details><summary>Details of `line-sliding`: the \d+ runs with a result", line)
    assert "Fitted convergence order" in line
    for kind in ("surface", "depth"):
        assert f"figures/001-line-sliding-{kind}.png" in line, kind
    assert "Exact reference curves are not drawn" not in line
    ell = sec["2. Scene `ellipse-convective`"]
    assert "figures/002-ellipse-convective-traction.png" in ell
    assert "convection 10 W/(m² K)" in ell


def test_sweep_is_one_section(study_out):
    out, paths = study_out
    md = (out / "report.md").read_text()
    sec = _sections(md)
    assert not any(t.startswith(tuple(f"{i}. Scene `carter" for i in range(10))) for t in sec)
    title = next(t for t in sec if "Sweep `carter`" in t)
    assert "over longitudinal creepage (5 scenes)" in title
    body = sec[title]
    assert body.count("**Table ") == 1 and body.count("**Figure ") == 1
    assert any(p.name.startswith("003-sweep-carter") for p in paths)
    # Fx/(mu N) of the finest level: Carter's ratio times (1 + delta(1)), beside the exact ratio
    from railtherm.models.hertz import hertz_geometry
    from railtherm.references.carter import carter_2d
    from railtherm.input.study import load_study
    sc = load_study(out.parent / "study.toml").scene("carter--creepage.longitudinal=-0.0004")
    a = hertz_geometry(sc.wheel, sc.rail, sc.contact_shape, sc.normal_force, penetration=sc.penetration,
                       semi_axes=sc.semi_axes, curvatures=sc.curvatures, wheel_radius=sc.wheel_radius)[0]
    ratio = carter_2d(-4e-4, a, sc.friction.nominal, sc.wheel_radius).force_ratio
    assert 0.3 < ratio < 0.95  # partial slip: the curve is not trivially saturated here
    header = next(line for line in body.splitlines() if line.startswith("| longitudinal creepage |"))
    header = [c.strip() for c in header.strip("|").split("|")]
    row = next(line for line in body.splitlines() if line.startswith("| -0.0004 |"))
    cells = dict(zip(header, (c.strip() for c in row.strip("|").split("|"))))
    assert float(cells["exact"]) == pytest.approx(ratio, rel=1e-3)
    assert float(cells["creep"].split()[0]) == pytest.approx(ratio * (1 + _delta(1)), rel=2e-3)
    assert cells["alpha"] == "refused"
    assert "Creep force computed by: creep ← report-carter-contact (tangential stage)" in body


def test_convergence_order_in_report(study_out):
    """The dummies' errors are first order in h, so the fitted order must be close to 1."""
    out, _ = study_out
    sec = _sections((out / "report.md").read_text())["1. Scene `line-sliding`"]
    table = sec.split("Fitted convergence order")[1]
    header = next(line for line in table.splitlines() if line.startswith("| method |"))
    row = next(line for line in table.splitlines() if line.startswith("| alpha |"))
    col = [c.strip() for c in header.split("|")].index("max T")
    assert float(row.split("|")[col].split()[0]) == pytest.approx(1.0, abs=0.15)


def test_markdown_tables_are_rectangular(study_out):
    out, _ = study_out
    md = (out / "report.md").read_text()
    tables = re.findall(r"((?:^\|.*\|\n)+)", md, flags=re.M)
    assert len(tables) >= 6
    for block in tables:
        rows = block.strip("\n").split("\n")
        assert re.fullmatch(r"\|(---\|)+", rows[1]), rows[1]
        widths = {len(re.split(r"(?<!\\)\|", r)) for r in rows}
        assert len(widths) == 1, rows[0]
    numbers = [int(n) for n in re.findall(r"\*\*Table (\d+)\.\*\*", md)]
    assert numbers == list(range(1, len(numbers) + 1)) and len(numbers) == len(tables)
    figures = [int(n) for n in re.findall(r"\*\*Figure (\d+)\.\*\*", md)]
    assert figures == list(range(1, len(figures) + 1))


def test_benchmarks_and_footer(study_out):
    out, _ = study_out
    sec = _sections((out / "report.md").read_text())
    assert "| test_green_speed | 12 ms | 10 ms |" in sec["Benchmarks"]
    assert "error_max_surface_temperature=0.001234" in sec["Benchmarks"]
    env = sec["Environment and code"]
    for word in ("numpy", "scipy", "xarray", "numba", "fipy", "scikit-fem", "OMP_NUM_THREADS",
                 "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS", "os.cpu_count()", "CPU:", "Command line of the run"):
        assert word in env, word


def test_html_self_contained(study_out):
    out, paths = study_out
    text = (out / "report.html").read_text()
    assert text.startswith("<!DOCTYPE html>") and text.rstrip().endswith("</html>")
    imgs = re.findall(r'<img src="([^"]+)" width="(\d+)"', text)
    assert sorted(s for s, _ in imgs) == sorted(f"figures/{p.name}" for p in paths[2:])
    assert all((out / s).exists() for s, _ in imgs)
    from PIL import Image
    for src, width in imgs:  # HiDPI: the PNG holds twice the CSS width, which fits the page
        assert Image.open(out / src).size[0] == pytest.approx(2 * int(width), abs=2)
        assert int(width) <= 980
    assert text.count("<table") == (out / "report.md").read_text().count("\n|---")
    assert "<script" not in text and "http" not in text.split("<body>")[1].split("Environment")[0]


def test_report_without_study_or_curves(study_out, tmp_path):
    """`railtherm report DIR` re-loads the study from study.json; without it, and without
    references.nc, the report is still written (overlays left out with a note)."""
    import shutil

    import railtherm.report as report
    out, _ = study_out
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    info = json.loads((copy / "study.json").read_text())
    info["path"] = str(tmp_path / "missing.toml")
    (copy / "study.json").write_text(json.dumps(info))
    (copy / "benchmarks.json").unlink()
    (copy / "references.nc").unlink()
    paths = report.write_report(copy)
    md = paths[0].read_text()
    assert "missing.toml" in md and "not found" in md
    assert "Benchmarks" not in md
    assert "Exact reference curves are not drawn: `references.nc` is missing" in md
    # the sweep is still one section (from the run records), without the exact curve
    assert "Sweep `carter` over longitudinal creepage (5 scenes)" in md and "could not be drawn" not in md


def test_missing_metrics(tmp_path):
    from railtherm.report import write_report
    with pytest.raises(FileNotFoundError, match="metrics.nc"):
        write_report(tmp_path)


def test_report_groups_a_sweep_from_the_run_files_json_not_the_name(study_out, tmp_path):
    """Without the study and without the run records' sweeps, the report reads each run file's
    ``sweep`` attribute (JSON with dotted study keys); the scene name is never parsed for values."""
    import shutil

    import netCDF4

    from railtherm.report.load import load
    from railtherm.report.verdict import sweep_groups
    out, _ = study_out
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    info = json.loads((copy / "study.json").read_text())
    info["path"] = str(tmp_path / "missing.toml")
    for rec in info.get("records", []):
        rec.pop("sweep", None)
    (copy / "study.json").write_text(json.dumps(info))
    # the JSON says 10x the creepage the scene name says: the report must follow the JSON
    for f in copy.glob("runs/carter--*/*/level-*.nc"):
        with netCDF4.Dataset(f, "a") as nc:
            sw = json.loads(nc.getncattr("sweep"))
            assert list(sw) == ["creepage.longitudinal"]
            nc.setncattr("sweep", json.dumps({"creepage.longitudinal": 10 * sw["creepage.longitudinal"]}))
    data = load(copy)
    assert data.study is None
    groups = [g for g in sweep_groups(data) if g.base == "carter"]
    assert len(groups) == 1 and groups[0].key == "creepage.longitudinal"
    values = [v for v, _ in groups[0].members]
    assert len(values) == 5 and -4e-3 in values          # the name says -0.0004
    for v, nm in groups[0].members:
        assert data.scene[nm].sweep == {"creepage.longitudinal": v}


def test_cell_reasons_list_a_sweeps_messages_in_member_order():
    """The lines of refused cells follow the members' order (a set of messages followed the string hash, which
    differs per process: two reports of one folder differed)."""
    from types import SimpleNamespace as N

    from railtherm.report.sections import _cell_reasons
    members = [N(message=f"scene 'sw--k={k}': refused because {k}") for k in ("c", "a", "b", "a")]
    card = N(status="refused", reason_kind="validity", members=members, message="")
    data = N(methods=["fipy"])
    lines = _cell_reasons(data, [N(label="sw", scenes=["sw"])], {("sw", "fipy"): card})
    assert [re.search(r"because (\w)", ln).group(1) for ln in lines] == ["c", "a", "b"]


def test_per_scene_arrays_equal_xarray_selections():
    """The report reads metrics.nc's per-scene variables by the scene's position in arrays transposed once
    (a selection per scene and variable made a 10 000-scene report take minutes): each value equals
    ``m[var].sel(scene_name=...)`` with the dimensions asked for."""
    import xarray as xr

    from railtherm.report.load import _PerScene
    rng = np.random.default_rng(3)
    scenes, methods, metrics = ["a", "b--k=1", "c"], ["fem", "green"], ["max_pressure", "creep_force_x"]
    m = xr.Dataset({
        "convergence_order": (("method_name", "scene_name", "metric"), rng.normal(size=(2, 3, 2))),
        "headline": (("scene_name",), np.array(["x", "", "y"], dtype=object)),
        "flat": (("method_name",), np.ones(2))},
        coords={"scene_name": scenes, "method_name": methods, "metric": metrics})
    ps = _PerScene(m)
    for s in scenes:
        want = m["convergence_order"].sel(scene_name=s).transpose("method_name", "metric").values
        np.testing.assert_array_equal(ps.get("convergence_order", s, ("method_name", "metric")), want)
        assert ps.get("headline", s) == m["headline"].sel(scene_name=s).item()
    assert ps.get("convergence_order", "missing") is None and ps.get("flat", "a") is None
    assert ps.get("absent", "a") is None and ps.coord("metric") == metrics


def test_runs_of_equals_a_filter_of_the_runs():
    from types import SimpleNamespace as N

    from railtherm.report.load import StudyData
    runs = [N(scene=s, method=m, level=k) for k in range(2) for s in ("a", "b") for m in ("fem", "green")]
    data = StudyData(out=Path("."), name="t", tolerance=0.05, runs=runs, scenes=["a", "b"], methods=["fem", "green"],
                     levels=[0, 1], info={}, study=None, scene={}, orders={}, cross={}, curves=None)
    for s in ("a", "b", "missing"):
        for m in (None, "fem", "green"):
            assert data.runs_of(s, m) == [r for r in runs if r.scene == s and (m is None or r.method == m)]
