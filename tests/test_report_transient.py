"""The report's transient part of a scene section on a small study (green at level 0, a uniform band passing
the rail section three times, and one steady scene): the per-pass figure, the temperature history and the
error table appear for the transient scene only, name the exact reference the errors are taken against,
and a scene without exact history curves in ``references.nc`` is drawn without them."""
from __future__ import annotations

import re
import textwrap

import numpy as np
import pytest

from studies import green_analytic_study, run_with_report

STUDY = green_analytic_study("transient-small") + textwrap.dedent("""
    [[scene]]
    name = "band-passes"
    speed = 30.0
    heat_source = { flux = 1e8, shape = "uniform", half_width = 6e-3 }
    heat_partition = 0.0
    mode = "transient"
    passes = { count = 3, interval = 0.083 }
    field = { depth = [1e-4, 5e-4, 1e-3], threshold = 727.0 }
    outputs = ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]
    [[scene]]
    name = "steady"
    speed = 30.0
    heat_source = { flux = 1e8, shape = "uniform", half_width = 6e-3 }
    heat_partition = 0.0
    outputs = ["max_surface_temperature", "surface_temperature"]
""")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    study, out, _ = run_with_report(tmp_path_factory.mktemp("transient-report"), STUDY)
    return study, out


def _scene_text(md: str, scene: str) -> str:
    return re.split(rf"^## \d+\. Scene `{scene}`", md, flags=re.M)[1].split("\n## ")[0]


def test_transient_scene_has_figures_and_error_table(small):
    _, out = small
    md = (out / "report.md").read_text()
    assert "could not be drawn" not in md
    part = _scene_text(md, "band-passes")
    assert "### `band-passes` over time" in part
    for name in ("001-band-passes-per-pass", "001-band-passes-history-rail"):
        assert f"figures/{name}.png" in part, name
        assert (out / "figures" / f"{name}.png").stat().st_size > 10_000
    assert "history-wheel" not in part          # heat_partition 0: the wheel takes no heat
    # references.nc holds the scene's exact history: both figures draw it as the grey band
    assert part.count("grey band: exact transient band (`references.nc`)") == 2
    # the error table: green's level, its three transient errors (metrics.nc's) and the reference named
    from railtherm.report.load import load
    data = load(out)
    run = data.finest_result("band-passes", "green")
    row = next(ln for ln in part.splitlines() if ln.startswith("| green (level 0)"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[4] == "exact transient band"
    for cell, metric in zip(cells[1:4], ("pass_peak_temperature", "residual_rise", "temperature_history")):
        assert run.references[metric] == "analytic:transient-band"
        if cell == "< 0.001":   # the report's floor of printed percentages
            assert abs(run.errors[metric]) < 1e-5, metric
        else:
            assert float(cell.replace("−", "-").lstrip("+")) == pytest.approx(
                abs(run.errors[metric]) * 100, rel=0.05), metric


def test_steady_scene_has_no_transient_part(small):
    _, out = small
    md = (out / "report.md").read_text()
    part = _scene_text(md, "steady")
    assert "over time" not in part and "per-pass" not in part and "history" not in part


def _section(out, curve):
    """The transient part of ``band-passes`` written alone, with ``curve`` as its references.nc group."""
    from railtherm.report.document import Document
    from railtherm.report.figures import Palette
    from railtherm.report.load import load
    from railtherm.report.sections import Context, _finest
    from railtherm.report.transient_section import transient_section
    data = load(out)
    data.curves = {"band-passes": curve}
    ctx = Context(data, out / "alone", Palette(data.methods))
    doc = Document()
    with _no_warning():
        transient_section(doc, ctx, 1, "band-passes", _finest(data, "band-passes"))
    return doc.markdown(), ctx


class _no_warning:
    """Fails on a RuntimeWarning (a figure that could not be drawn becomes one)."""

    def __enter__(self):
        import warnings
        self._w = warnings.catch_warnings(record=True)
        self.log = self._w.__enter__()
        warnings.simplefilter("always")
        return self

    def __exit__(self, *exc):
        self._w.__exit__(*exc)
        assert not [w for w in self.log if issubclass(w.category, RuntimeWarning)], [str(w.message) for w in self.log]


def test_missing_exact_curves_are_not_drawn(small):
    """No exact history in references.nc (or no references.nc): the figures are drawn without it, and say so."""
    import xarray as xr
    _, out = small
    for curve in (None, xr.Dataset()):
        md, ctx = _section(out, curve)
        assert len(ctx.figures) == 2 and all(p.stat().st_size > 10_000 for p in ctx.figures)
        assert "no exact history is drawn" in md and "could not be drawn" not in md


def test_exact_curves_are_drawn_when_present(small):
    """references.nc's exact history curves (their contract: ``exact_temperature_history(body, history_time,
    history_depth)``, per-pass curves on ``pass``, attribute ``transient_reference``) are drawn and named."""
    import xarray as xr
    _, out = small
    from railtherm.report.load import load
    data = load(out)
    ds = data.run_file("band-passes", "green", 0)
    hist = ds["temperature_history"].rename(time="history_time", z="history_depth")
    curve = xr.Dataset({"exact_temperature_history": hist,
                        "exact_pass_peak_temperature": ds["pass_peak_temperature"].rename(z="history_depth"),
                        "exact_residual_rise": ds["residual_rise"],
                        "exact_time_above": ds["time_above"].rename(z="history_depth")},
                       attrs={"transient_reference": "exact transient band"})
    md, ctx = _section(out, curve)
    assert len(ctx.figures) == 2
    assert "grey band: exact transient band (`references.nc`)" in md and "no exact history" not in md


def test_many_passes_draw_first_and_last_windows_and_thinning_keeps_peaks():
    from railtherm.report.transient_figures import FEW_PASSES, thin, windows
    assert len(windows(0.3, 3)) == 1 and windows(0.3, 3)[0][:2] == (0.0, 0.3)
    w = windows(50.0, 1000)
    assert [x[:2] for x in w] == [(0.0, pytest.approx(0.15)), (pytest.approx(49.9), 50.0)]
    assert len(windows(1.0, FEW_PASSES + 1)) == 2
    t = np.linspace(0.0, 1.0, 300_001)
    y = np.sin(40 * t) + (np.abs(t - 0.123457) < 2e-6) * 5.0   # a spike one sample wide
    tt, yy = thin(t, y)
    assert tt.size <= 5000 and yy.max() == y.max() and yy.min() == y.min()
    assert np.all(np.diff(tt) > 0)


def test_a_coarse_exact_history_is_drawn_as_points_and_a_fine_one_as_a_band():
    """The exact history is joined by a line only where its time axis is within 20x the methods' median step:
    a uniform axis of half a pass over 1,000 passes would cut every peak."""
    import xarray as xr
    from railtherm.report.transient_figures import exact_joined
    run = xr.Dataset({"temperature_history": (("body", "time", "z"), np.zeros((2, 1001, 1)))},
                     coords={"time": np.linspace(0.0, 1e-3, 1001)})          # step 1 us
    def curve(n):
        return xr.Dataset({"exact_temperature_history": (("body", "history_time", "history_depth"),
                                                        np.zeros((2, n, 1)))},
                          coords={"history_time": np.linspace(0.0, 1e-3, n)})
    assert exact_joined({"m": run}, curve(101)) is True        # 10 us: joined
    assert exact_joined({"m": run}, curve(21)) is False        # 50 us: points
    assert exact_joined({"m": run}, None) is None and exact_joined({"m": run}, xr.Dataset()) is None


@pytest.mark.parametrize("passes", [1, 3])
def test_per_pass_figure_of_one_and_of_several_passes(tmp_path, passes):
    """The per-pass figure draws for one pass (a single tick) as for several, both bodies heated, with the
    time above the threshold and the exact values."""
    import xarray as xr
    from railtherm.report.figures import Palette
    from railtherm.report.transient_figures import per_pass
    n = np.arange(1, passes + 1)
    peak = 800.0 + np.zeros((2, passes, 2))
    run = xr.Dataset({"pass_peak_temperature": (("body", "pass", "z"), peak),
                      "residual_rise": (("body", "pass"), np.ones((2, passes))),
                      "time_above": (("body", "pass", "z"), 1e-3 * np.ones((2, passes, 2)))},
                     coords={"pass": n, "z": [0.0, 1e-4]})
    curve = xr.Dataset({"exact_pass_peak_temperature": (("body", "pass", "history_depth"), peak),
                        "exact_residual_rise": (("body", "pass"), np.ones((2, passes))),
                        "exact_time_above": (("body", "pass", "history_depth"), 1e-3 * np.ones((2, passes, 2)))},
                       coords={"pass": n, "history_depth": [0.0, 1e-4]})
    path, width = per_pass({"green": run}, curve, [1, 0], 727.0, Palette(["green"]), "t", path=tmp_path / "p.png")
    assert path.stat().st_size > 10_000 and width <= 1024
