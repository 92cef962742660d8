"""The study report: report.md, report.html and figures/*.png from a study output folder.

A small study is run with inline dummy methods (registered through the plugin host exactly like a
plugin): one that computes, one that fails and one that refuses on the finer level, and one that gives Carter's traction
(perturbed by level) on a creepage sweep, so that every part of the report is drawn.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import railtherm
from railtherm import ContactModel, ContactPatch, TemperatureField, TemperatureModel
from railtherm.plugins import get_host, new_host, set_host

STUDY = """
schema_version = 1
[study]
name = "report-test"
methods = ["alpha", "broken", "picky", "creep"]
levels = [0, 1]
reference = "analytic"
repeat = 1
warmup = false

[defaults.wheel]
shear_modulus = 82e9
poisson_ratio = 0.28
density = 7850.0
specific_heat = 450.0
conductivity = 50.0
bulk_temperature = 20.0
[defaults.rail]
shear_modulus = 82e9
poisson_ratio = 0.28
density = 7850.0
specific_heat = 450.0
conductivity = 50.0
bulk_temperature = 10.0

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
    capabilities = railtherm.Capabilities(provides=frozenset({"surface_temperature", "max_surface_temperature",
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


class CarterContact(ContactModel):
    """Hertz line patch with Carter's traction, creep force off by delta(level)."""

    name = "report-carter-contact"
    description = "test stand-in: Carter's 2-D traction with a level-dependent error"
    capabilities = railtherm.Capabilities(contacts=frozenset({"line"}), tangential=frozenset({"creepage"}),
                                          provides=frozenset({"pressure", "normal_force", "semi_axis_a",
                                                              "max_pressure", "traction_x", "stick",
                                                              "creep_force_x"}))

    def compute_patch(self, scene, level, options):
        from railtherm.models.hertz import HertzContact
        from railtherm.references.carter import carter_2d
        patch = HertzContact().compute_patch(scene, level, options)
        c = carter_2d(scene.creepage.longitudinal, patch.a, scene.friction, scene.wheel_radius,
                      max_pressure=patch.max_pressure)
        x = patch.grid.x
        inside = patch.pressure > 0
        return patch.with_tangential(traction_x=c.traction(x) * (1 + _delta(level)),
                                     stick=np.where(inside, c.stick(x).astype(float), np.nan),
                                     creep_force_x=c.force_ratio * scene.friction * patch.normal_force
                                     * (1 + _delta(level)))


class DummyPlugin:
    @railtherm.hookimpl
    def railtherm_register_models(self):
        return [DummyTemperature, BrokenTemperature, PickyTemperature, CarterContact]

    @railtherm.hookimpl
    def railtherm_register_methods(self):
        chain = lambda t: {"contact": ("hertz",), "heat_source": ("full-sliding",), "temperature": (t,)}
        return [railtherm.Method("alpha", chain("report-dummy-temperature"), default_cells=16),
                railtherm.Method("broken", chain("report-broken-temperature"), default_cells=16),
                railtherm.Method("picky", chain("report-picky-temperature"), default_cells=16),
                railtherm.Method("creep", {"contact": ("report-carter-contact",)}, default_cells=16)]


@pytest.fixture(scope="module")
def study_out(tmp_path_factory):
    """Run the dummy study once (report written by run_study with a section limit of 3)."""
    import railtherm.report as report
    tmp = tmp_path_factory.mktemp("report")
    path = tmp / "study.toml"
    path.write_text(STUDY)
    old = get_host()
    set_host(new_host([("report-dummy", DummyPlugin())], autoload=False, strict=True))
    limit = report.MAX_SCENE_SECTIONS
    report.MAX_SCENE_SECTIONS = 3
    try:
        out = tmp / "out"
        railtherm.run_study(str(path), out, report=False)
        bench = {"datetime": "2026-01-01T00:00:00", "machine_info": {"cpu": {"brand_raw": "Test CPU"}},
                 "benchmarks": [{"name": "test_green_speed", "stats": {"mean": 0.0123, "min": 0.0101, "stddev": 1e-4,
                                                                       "rounds": 7},
                                 "extra_info": {"error_max_surface_temperature": 1.234e-3}}]}
        (out / "benchmarks.json").write_text(json.dumps(bench))
        paths = report.write_report(out)
        yield out, paths
    finally:
        report.MAX_SCENE_SECTIONS = limit
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


def test_report_sections(study_out):
    out, _ = study_out
    md = (out / "report.md").read_text()
    assert "could not be drawn" not in md and "not drawn" not in md
    sec = _sections(md)
    # one section per scene (first 3), then the summary of the others
    assert "1. Scene `line-sliding`" in sec and "2. Scene `ellipse-convective`" in sec
    assert "3. Scene `carter--creepage.longitudinal=-0.001`" in sec
    assert "Summary of further scenes" in sec
    assert "carter--creepage.longitudinal=0.001" in sec["Summary of further scenes"]
    line = sec["1. Scene `line-sliding`"]
    # reference named, every status shown with its message, heat balance, errors, convergence orders
    assert "Reference: " in line and "Jaeger" in line and "Hertz" in line
    assert "| broken | 1 | failed |" in line and "dummy solver diverged on purpose" in line
    assert "| picky | 1 | refused |" in line and "refuses fine grids" in line
    assert "| creep | 0–1 | refused |" in line  # levels refused for the same reason share a row
    assert "heat balance [1]" in line and "err max_surface_temperature" in line
    assert "Fitted convergence order" in line
    assert "max_surface_temperature: method \\ compared with" in line  # cross-method matrix
    for kind in ("work-precision", "cross", "surface", "depth", "traction"):
        assert f"figures/001-line-sliding-{kind}.png" in line, kind
    ell = sec["2. Scene `ellipse-convective`"]
    assert "figures/002-ellipse-convective-traction.png" in ell
    assert "convection 10 W/(m² K)" in ell


def test_markdown_tables_are_rectangular(study_out):
    out, _ = study_out
    md = (out / "report.md").read_text()
    tables = re.findall(r"((?:^\|.*\|\n)+)", md, flags=re.M)
    assert len(tables) >= 8
    for block in tables:
        rows = block.strip("\n").split("\n")
        assert re.fullmatch(r"\|(---\|)+", rows[1]), rows[1]
        widths = {len(re.split(r"(?<!\\)\|", r)) for r in rows}
        assert len(widths) == 1, rows[0]


def test_convergence_order_in_report(study_out):
    """The dummies' errors are first order in h, so the fitted orders must be close to 1."""
    out, _ = study_out
    import xarray as xr
    with xr.open_dataset(out / "metrics.nc") as m:
        order = float(m["convergence_order"].sel(scene_name="carter--creepage.longitudinal=-0.001",
                                                 method_name="creep", metric="creep_force_x"))
    assert order == pytest.approx(1.0, abs=0.05)
    sec = _sections((out / "report.md").read_text())["3. Scene `carter--creepage.longitudinal=-0.001`"]
    table = sec.split("Fitted convergence order")[1]
    header = next(line for line in table.splitlines() if line.startswith("| method |"))
    row = next(line for line in table.splitlines() if line.startswith("| creep |"))
    col = [c.strip() for c in header.split("|")].index("creep_force_x")
    assert float(row.split("|")[col]) == pytest.approx(order, rel=1e-3)


def test_creep_force_curves(study_out):
    out, paths = study_out
    sec = _sections((out / "report.md").read_text())["Creep-force curves"]
    assert "`carter`: creep force against creepage.longitudinal" in sec
    assert any(p.name.startswith("creep-01-carter") for p in paths)
    # the table holds Fx/(mu N) of the finest level: Carter's ratio times (1 + delta(1))
    from railtherm.references.carter import carter_2d
    from railtherm.study import load_study
    st = load_study(out.parent / "study.toml")
    sc = st.scene("carter--creepage.longitudinal=-0.0004")
    from railtherm.models.hertz import hertz_geometry
    a = hertz_geometry(sc)[0]
    ratio = carter_2d(-4e-4, a, sc.friction, sc.wheel_radius).force_ratio
    assert 0.3 < ratio < 0.95  # partial slip: the curve is not trivially saturated here
    want = ratio * (1 + _delta(1))
    row = next(line for line in sec.splitlines() if line.startswith("| -0.0004 |"))
    assert float(row.split("|")[2]) == pytest.approx(want, rel=2e-3)


def test_benchmarks_and_footer(study_out):
    out, _ = study_out
    md = (out / "report.md").read_text()
    sec = _sections(md)
    assert "| test_green_speed | 0.0123 | 0.0101 |" in sec["Benchmarks"]
    assert "error_max_surface_temperature=0.001234" in sec["Benchmarks"]
    env = sec["Environment"]
    for word in ("numpy", "scipy", "xarray", "numba", "fipy", "scikit-fem", "OMP_NUM_THREADS",
                 "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS", "os.cpu_count()", "CPU:", "Command line of the run"):
        assert word in env, word


def test_html_self_contained(study_out):
    out, paths = study_out
    text = (out / "report.html").read_text()
    assert text.startswith("<!DOCTYPE html>") and text.rstrip().endswith("</html>")
    srcs = re.findall(r'<img src="([^"]+)"', text)
    assert sorted(srcs) == sorted(f"figures/{p.name}" for p in paths[2:])
    assert all((out / s).exists() for s in srcs)
    assert text.count("<table>") == (out / "report.md").read_text().count("\n|---")
    assert "<script" not in text and "http" not in text.split("<body>")[1].split("Environment")[0]


def test_report_without_study(study_out, tmp_path):
    """`railtherm report DIR` re-loads the study from study.json; without it the report still works."""
    import shutil

    import railtherm.report as report
    out, _ = study_out
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    info = json.loads((copy / "study.json").read_text())
    info["path"] = str(tmp_path / "missing.toml")
    (copy / "study.json").write_text(json.dumps(info))
    (copy / "benchmarks.json").unlink()
    report.MAX_SCENE_SECTIONS, limit = 0, report.MAX_SCENE_SECTIONS
    try:
        paths = report.write_report(copy)
    finally:
        report.MAX_SCENE_SECTIONS = limit
    md = paths[0].read_text()
    assert "missing.toml" in md and "not found" in md
    assert "Benchmarks" not in md
    # scene sweep parsed from the names: the creep-force curves are still drawn (without Carter)
    assert "Creep-force curves" in md and "could not be drawn" not in md


def test_missing_metrics(tmp_path):
    from railtherm.report import write_report
    with pytest.raises(FileNotFoundError, match="metrics.nc"):
        write_report(tmp_path)
