"""The report's thermal-trace section on a small study (green at level 0): the exact trace reaches the
report through references.nc, the figures and the table exist, and the table's values are the run
files' and references.nc's."""
from __future__ import annotations

import re
import textwrap

import numpy as np
import pytest

from studies import green_analytic_study, run_with_report

STUDY = green_analytic_study("trace-small") + textwrap.dedent("""
    [[scene]]
    name = "locked"
    speed = 10.0
    heat_source = { flux = 7.7053e8, shape = "hertz", semi_axes = [5.8789e-3, 10.540e-3] }
    heat_partition = 0.0
    field = { behind = 12e-3, depth = 0.6e-3, threshold = 727.0 }
    outputs = ["surface_temperature", "temperature", "peak_temperature", "cooling_rate", "heated_depth",
               "time_above", "max_surface_temperature"]
    [[scene]]
    name = "band"
    speed = 30.0
    heat_source = { flux = 2.3116e8, shape = "hertz", half_width = 5.8789e-3 }
    field = { behind = 12e-3, depth = 0.3e-3, threshold = 50.0 }
    outputs = ["surface_temperature", "temperature", "peak_temperature", "cooling_rate", "heated_depth",
               "time_above", "max_surface_temperature"]
    [[scene]]
    name = "plain"
    speed = 30.0
    heat_source = { flux = 2.3116e8, shape = "hertz", half_width = 5.8789e-3 }
    outputs = ["max_surface_temperature", "surface_temperature"]
""")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    return run_with_report(tmp_path_factory.mktemp("trace"), STUDY)


def test_reference_curves_hold_the_exact_trace(small):
    """references.nc holds the exact trace of the field scenes (values of analytic.trace_reference on
    its own depths), none for a scene without field."""
    from railtherm.analysis.analytic import trace_reference
    from railtherm.analysis.reference_curves import read_reference_curves
    study, out, _ = small
    curves = read_reference_curves(out / "references.nc")
    assert "trace_peak_temperature" not in curves["plain"]
    for name in ("locked", "band"):
        c = curves[name]
        sc = next(s for s in study.scenes if s.name == name)
        zt = c["z_trace"].values
        assert zt[0] == 0.0 and zt[-1] == pytest.approx(sc.field.depth)
        tr = trace_reference(sc, zt)
        np.testing.assert_allclose(c["trace_peak_temperature"].values, tr["peak_temperature"], rtol=1e-12)
        np.testing.assert_allclose(c["trace_heated_depth"].values, tr["heated_depth"], rtol=1e-12)
        # the surface curve reaches behind the trailing edge; the depth curve reaches field.depth
        a = float(c["x"].values.max())
        assert c["x"].values.min() == pytest.approx(-a - sc.field.behind)
        assert c["z"].values.max() == pytest.approx(sc.field.depth)
        zs = float(c["trace_depth"].values)
        star = trace_reference(sc, [zs])
        np.testing.assert_allclose(c["trace_depth_cooling_rate"].values, star["cooling_rate"][:, 0], rtol=1e-12)
        # the shallowest depth at which metrics.nc scores the cooling rate (the figure shades above it)
        from railtherm.analysis.analytic import _thermal_case
        from railtherm.analysis.trace_metrics import cooling_rate_depth
        z_c = c["trace_cooling_depth"].values
        case = _thermal_case(sc)
        np.testing.assert_allclose(z_c, cooling_rate_depth(case[0], case[4], sc.wheel, sc.rail), rtol=1e-12)
        assert np.all(z_c > 0) and np.all(z_c < sc.field.depth)
        assert ("surface_map" in c) == (name == "locked")
    # the locked wheel: all heat into the rail, the 727 degC isotherm inside the field: z* is its depth
    c = curves["locked"]
    hd = c["trace_heated_depth"].values
    assert hd[0] == 0.0 and 0 < hd[1] < 0.6e-3
    assert float(c["trace_depth"].values) == pytest.approx(hd[1], rel=1e-12)
    # trace_temperature at z* = heated depth peaks at the threshold (exact: within the x sampling)
    assert c["trace_temperature"].values[1].max() == pytest.approx(727.0, rel=5e-3)


def test_section_figures_and_table(small):
    _, out, paths = small
    md = (out / "report.md").read_text()
    assert "## Thermal trace: behind the patch and in depth" in md
    trace = md.split("## Thermal trace")[1].split("\n## ")[0]
    for name in ("trace-locked-rail", "trace-map-locked-rail", "trace-band-wheel", "trace-band-rail"):
        assert f"figures/{name}.png" in trace, name
        assert (out / "figures" / f"{name}.png").stat().st_size > 10_000
    assert "trace-map-band" not in trace   # a line contact has no map
    assert "trace-locked-wheel" not in trace   # the locked wheel takes no heat
    # the maps are behind a closed box; the scene's own section links here instead of repeating figures
    assert trace.index("<details><summary>Surface map of the trace of `locked`") < trace.index("trace-map-locked-rail")
    scene = re.split(r"^## \d+\. Scene `locked`", md, flags=re.M)[1].split("\n## ")[0]
    assert "figures/" not in scene and "(#trace-locked)" in scene
    assert "could not be drawn" not in md
    # the section comes after the verdict and before the scenes' own sections
    assert md.index("## Verdict") < md.index("## Thermal trace") < re.search(r"^## \d+\. Scene `plain`", md, re.M).start()


def _table_rows(md: str) -> list[list[str]]:
    trace = md.split("## Thermal trace")[1].split("\n## ")[0]
    lines = [ln for ln in trace.splitlines() if ln.startswith("|")]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines[2:]]


def test_table_values_match_the_store(small):
    """Each table value is the run file's (green's level 0), metrics.nc's or references.nc's; each error of a
    metric is metrics.nc's; each difference at a point is (value - exact) / |exact| of those."""
    import xarray as xr
    from railtherm.analysis.reference_curves import read_reference_curves
    _, out, _ = small
    rows = _table_rows((out / "report.md").read_text())
    curves = read_reference_curves(out / "references.nc")
    ds = xr.open_dataset(out / "runs" / "locked" / "green" / "level-0.nc")
    m = xr.open_dataset(out / "metrics.nc")
    c = curves["locked"]
    i = next(k for k, r in enumerate(rows) if r[0].startswith("`locked`"))
    exact, green = rows[i], rows[i + 1]
    assert exact[1] == "rail" and exact[2] == "**exact**" and green[2] == "green (level 0)"
    # the table prints three significant digits
    num = lambda s: float(re.sub(r"[^0-9eE+.\-]", "", s.replace("−", "-")))
    exact_peak = float(m["analytic_max_surface_temperature"].sel(scene_name="locked").values[1])
    assert num(exact[3]) == pytest.approx(exact_peak, rel=5e-3)
    assert num(exact[5]) == pytest.approx(1e3 * float(c["trace_heated_depth"][1]), rel=5e-3)
    assert num(exact[7]) == pytest.approx(1e3 * float(c["trace_time_above"][1, 0]), rel=5e-3)
    assert num(exact[9]) == pytest.approx(float(c["trace_depth_cooling_rate"][1]), rel=5e-3)
    run = int(np.flatnonzero((m["scene"].values == "locked") & (m["method"].values == "green"))[0])
    assert num(green[3]) == pytest.approx(float(ds["max_surface_temperature"][1]), rel=5e-3)
    assert num(green[4]) == pytest.approx(100 * float(m["signed_error_max_surface_temperature"][run]), rel=0.051)
    assert num(green[5]) == pytest.approx(1e3 * float(ds["heated_depth"][1]), rel=5e-3)
    assert num(green[6]) == pytest.approx(100 * float(m["error_heated_depth"][run]), rel=0.051)
    zs = float(c["trace_depth"])
    cool = np.asarray(ds["cooling_rate"].isel(body=1).values, float)
    ok = np.isfinite(cool)
    assert num(green[9]) == pytest.approx(np.interp(zs, ds["z"].values[ok], cool[ok]), rel=5e-3)
    assert num(green[11]) == pytest.approx(100 * float(m["error_cooling_rate"][run]), rel=0.051)
    assert num(green[12]) == pytest.approx(100 * float(m["error_cooling_rate_all_depths"][run]), rel=0.051)
    # the band scene lists both bodies (each takes part of the heat)
    bodies = [r[1] for r in rows if r[2] == "**exact**"]
    assert bodies.count("wheel") == 1 and bodies.count("rail") == 2


def _run_table(md: str, scene: str) -> tuple[list[str], list[list[str]]]:
    part = re.split(rf"^## \d+\. Scene `{scene}`", md, flags=re.M)[1].split("\n## ")[0]
    lines = [ln for ln in part.splitlines() if ln.startswith("| method | level")]
    start = part.splitlines().index(lines[0])
    body = []
    for ln in part.splitlines()[start + 2:]:
        if not ln.startswith("|"):
            break
        body.append([c.strip() for c in ln.strip("|").split("|")])
    return [c.strip() for c in lines[0].strip("|").split("|")], body


def test_one_metric_one_number(small):
    """The cooling-rate error and the maximum surface temperature read the same in the trace table, the scene's
    run table and the published/scene values: one number per metric (the trace table once printed the cooling
    rate at z* and the surface peak of the trace profile under the metrics' names)."""
    _, out, _ = small
    md = (out / "report.md").read_text()
    rows = _table_rows(md)
    header = [c.strip() for c in [ln for ln in md.split("## Thermal trace")[1].splitlines()
                                  if ln.startswith("| scene")][0].strip("|").split("|")]
    depth_name = next(h for h in header if h.startswith("error of cooling rate, z ≥"))
    for scene in ("locked", "band"):
        i = next(k for k, r in enumerate(rows) if r[0].startswith(f"`{scene}`"))
        trace = rows[i + 1]
        run_head, run_rows = _run_table(md, scene)
        green = next(r for r in run_rows if r[0] == "green")
        scored = next(h for h in run_head if h.startswith("err cooling rate, z ≥"))   # e.g. "z ≥ 45.6 µm"
        assert scored[len("err "):-len(" [%]")] + " scored" in rows[i][0], (scored, rows[i][0])
        assert trace[header.index(depth_name)].removesuffix(" %") == green[run_head.index(scored)]
        assert trace[4].removesuffix(" %") == green[run_head.index("err max T [%]")]
    assert "cooling rate at z* [K/s]" in header and "difference at z* [%]" in header
