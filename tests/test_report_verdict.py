"""The report's verdict, tables and style on synthetic metrics (no solver runs).

metrics.nc is built by hand following docs/verdicts.md (its one layout: each error with its own reference).
"""
from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from studies import steel

STUDY = """
schema_version = 1
[study]
name = "synthetic"
methods = ["fem", "fipy", "green"]
levels = [0, 1, 2, 3]
reference = "analytic"
tolerance = 0.05

[study.published."ek"]
max_surface_temperature = 149.7
source = "seed Table 1"

""" + steel("wheel", thermal=True) + steel("rail", thermal=True) + """
[[scene]]
name = "ek"
normal_force = 100e3
contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
speed = 30.0
sliding_speed = 1.0
friction = 0.3
outputs = ["max_surface_temperature", "surface_temperature"]

[[scene]]
name = "strip"
speed = 30.0
heat_source = { flux = 2.3e8, shape = "hertz", half_width = 5.9e-3 }
outputs = ["max_surface_temperature", "surface_temperature"]
"""

FEM_ELLIPSE = "model 'fem' handles ['line'] contacts, not 'ellipse'"
FIPY_BUDGET = "model 'fipy': 81920 cells > max_cells = 50000 (raise max_cells or use level 2)"
METRICS = ("max_surface_temperature", "creep_force_x", "pressure_l2")

#: (scene, method, level, status, reason_kind, message, wall_time, headline error, reference)
RUNS = [
    ("ek", "green", 0, "ok", "", "", 1.0e-3, 0.004, "analytic:moving-source"),
    ("ek", "green", 1, "ok", "", "", 2.0e-3, 0.001, "analytic:moving-source"),
    ("ek", "green", 2, "ok", "", "", 5.0e-3, 1e-4, "analytic:moving-source"),
    ("ek", "fipy", 0, "inaccurate", "", "relative error 0.08 in max_surface_temperature exceeds the tolerance 0.05",
     0.05, 0.08, "analytic:moving-source"),
    ("ek", "fipy", 1, "ok", "", "", 0.9, 0.012, "analytic:moving-source"),
    ("ek", "fipy", 2, "ok", "", "", 0.4, 0.004, "analytic:moving-source"),  # cheaper than level 1
    ("ek", "fipy", 3, "refused", "budget", FIPY_BUDGET, math.nan, math.nan, ""),
    ("ek", "fem", 0, "refused", "validity", FEM_ELLIPSE, math.nan, math.nan, ""),
    ("ek", "fem", 1, "refused", "validity", FEM_ELLIPSE, math.nan, math.nan, ""),
    ("ek", "fem", 2, "refused", "validity", FEM_ELLIPSE, math.nan, math.nan, ""),
    ("strip", "fem", 0, "unverified", "", "no independent reference", 0.2, 0.03, "self:finest"),
    ("strip", "fem", 1, "unverified", "", "no independent reference", 0.7, 0.01, "self:finest"),
    ("strip", "fem", 2, "unverified", "", "no independent reference", 2.7, 0.0, "self:finest"),
    ("strip", "green", 0, "failed", "timeout", "timed out after 120 s", math.nan, math.nan, ""),
    ("strip", "fipy", 0, "refused", "validity", "model 'fipy' handles ellipses only", math.nan, math.nan, ""),
]


def _metrics():
    """A metrics Dataset of RUNS with the columns docs/verdicts.md describes."""
    import xarray as xr
    n = len(RUNS)
    col = lambda i: [r[i] for r in RUNS]
    has = [r[3] in ("ok", "inaccurate", "unverified") for r in RUNS]
    err = np.array([r[7] if h else np.nan for r, h in zip(RUNS, has)])
    data = {"scene": ("run", np.array(col(0), dtype=object)), "method": ("run", np.array(col(1), dtype=object)),
            "level": ("run", np.array(col(2), dtype="int32")), "message": ("run", np.array(col(5), dtype=object)),
            "wall_time": ("run", np.array(col(6), float)),
            "error_max_surface_temperature": ("run", err),
            "error_creep_force_x": ("run", np.where(has, 0.0, np.nan)),  # zero in every run: dropped
            "error_pressure_l2": ("run", np.full(n, np.nan))}  # missing in every run: dropped
    scenes, methods = ["ek", "strip"], ["fem", "fipy", "green"]
    order = np.full((2, 3, len(METRICS)), np.nan)
    order[0, 2, 0], order[0, 1, 0], order[1, 0, 0] = 2.1, -0.4, 1.6
    data.update({
        "status": ("run", np.array(col(3), dtype=object)),
        "reason_kind": ("run", np.array(col(4), dtype=object)),
        "wall_time_median": ("run", np.array(col(6), float) * 1.1),
        "timing_runs": ("run", np.where(has, 5, 0).astype("int32")),
        "peak_rss": ("run", np.where(has, 12e6, np.nan)),
        "energy_balance": ("run", np.where(has, 1e-3, np.nan)),
        "energy_reference": ("run", np.array(["solver" if h else "" for h in has], dtype=object)),
        "reference_max_surface_temperature": ("run", np.array(col(8), dtype=object)),
        "reference_creep_force_x": ("run", np.array(["analytic:full-sliding" if h else "" for h in has],
                                                    dtype=object)),
        "reference_pressure_l2": ("run", np.array([""] * n, dtype=object)),
        "headline_error": ("run", np.array([r[7] if r[8].startswith("analytic") else np.nan for r in RUNS])),
        "headline_reference": ("run", np.array([r[8] if r[8].startswith("analytic") else "" for r in RUNS],
                                               dtype=object)),
        "headline": ("scene_name", np.array(["max_surface_temperature"] * 2, dtype=object)),
        "reference_kind": ("scene_name", np.array(["analytic", "analytic"], dtype=object)),
        "analytic_max_surface_temperature": (("scene_name", "body"), np.array([[149.5, 149.5], [np.nan] * 2])),
    })
    theo = np.full_like(order, np.nan)
    theo[0, 2, 0], theo[0, 1, 0], theo[1, 0, 0] = 2.0, 2.0, 2.0
    oref = np.full(order.shape, "", dtype=object)
    oref[0, 2, 0] = oref[0, 1, 0] = "analytic:moving-source"
    oref[1, 0, 0] = "self:finest"
    rich = np.full_like(order, np.nan)
    rich[1, 0, 0] = 0.003
    unc = np.full_like(order, np.nan)
    unc[1, 0, 0] = 0.001
    data.update({"order_reference": (("scene_name", "method_name", "metric"), oref),
                 "theoretical_order": (("scene_name", "method_name", "metric"), theo),
                 "richardson_error": (("scene_name", "method_name", "metric"), rich),
                 "richardson_uncertainty": (("scene_name", "method_name", "metric"), unc)})
    data["convergence_order"] = (("scene_name", "method_name", "metric"), order)
    data["cross_difference"] = (("scene_name", "quantity", "method_name", "other_method"), np.full((2, 1, 3, 3), np.nan))
    ds = xr.Dataset(data, coords={"run": np.arange(n), "scene_name": np.array(scenes, dtype=object),
                                  "method_name": np.array(methods, dtype=object),
                                  "other_method": np.array(methods, dtype=object),
                                  "metric": np.array(METRICS, dtype=object),
                                  "quantity": np.array(["max_surface_temperature"], dtype=object),
                                  "body": np.array(["wheel", "rail"], dtype=object)})
    ds.attrs.update(study="synthetic", tolerance=0.05)
    return ds


def _folder(tmp_path: Path) -> Path:
    """An output folder: study file, study.json, metrics.nc and one run file (green's finest on ek)."""
    import xarray as xr
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "study.toml").write_text(STUDY)
    (out / "study.json").write_text(json.dumps({"study": "synthetic", "path": str(tmp_path / "study.toml"),
                                                "argv": ["railtherm", "run"], "records": []}))
    _metrics().to_netcdf(out / "metrics.nc", engine="netcdf4")
    run = out / "runs" / "ek" / "green"
    run.mkdir(parents=True)
    xr.Dataset({"max_surface_temperature": ("body", [149.1, 149.1])}, coords={"body": ["wheel", "rail"]},
               attrs={"level": 2, "stages": "contact:hertz heat_source:full-sliding temperature:green"}
               ).to_netcdf(run / "level-2.nc", engine="netcdf4")
    return out


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    from railtherm.report import write_report
    out = _folder(tmp_path_factory.mktemp("synthetic"))
    paths = write_report(out)
    return out, paths[0].read_text(), paths[1].read_text()


def _section(md: str, title: str) -> str:
    parts = re.split(r"^## ", md, flags=re.M)
    return next(p for p in parts[1:] if p.startswith(title))


def _scorecard(md: str) -> dict:
    """(scene, method) -> cell text of the scorecard."""
    verdict = _section(md, "Verdict")
    lines = [line for line in verdict.splitlines() if line.startswith("|")]
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    out = {}
    for line in lines[2:]:
        cells = [c.strip() for c in line.strip("|").split("|")]
        scene = re.match(r"\[?([^\]·]+)", cells[0]).group(1).strip()
        out.update({(scene, m): c for m, c in zip(header[1:], cells[1:])})
    return out


def test_verdict_first(report):
    _, md, html = report
    assert re.findall(r"^## (.*)$", md, flags=re.M)[0] == "Verdict"
    body = html.split("<body>", 1)[1]
    assert body.index("<h2") == body.index('<h2 id="verdict">')


def test_scorecard_cheapest_ok_level(report):
    """fipy on ek: level 0 is inaccurate, levels 1 and 2 are ok and level 2 is the cheaper one."""
    _, md, html = report
    card = _scorecard(md)
    assert card[("ek", "fipy")] == "ok · 0.40 % · 0.40 s · level 2"
    assert card[("ek", "green")] == "ok · 0.40 % · 1.0 ms · level 0"
    assert card[("ek", "fem")].startswith("refused")
    assert card[("strip", "fem")].startswith("unverified · headline not checked independently")
    assert card[("strip", "green")].startswith("failed")
    assert '<td class="ok">ok · 0.40 % · 1.0 ms · level 0</td>' in html
    assert '<td class="unverified">unverified' in html


def test_second_release_columns(report):
    _, md, _ = report
    card = _scorecard(md)
    assert card[("ek", "fem")] == "refused (validity)" and card[("strip", "green")] == "failed (timeout)"
    assert "Richardson ≈0.30 %" in card[("strip", "fem")]
    ek = _section(md, "1. Scene `ek`")
    assert "time min / median (n)" in ek and "1.0 ms / 1.1 ms (5)" in ek
    assert "peak RSS" in ek and "12 MB" in ek
    assert "2.1 (th. 2)" in ek and "no convergence (−0.4) (th. 2)" in ek
    strip = _section(md, "2. Scene `strip`")
    assert "1.6 (th. 2) †" in strip and "self-convergence" in strip
    assert "Richardson estimate of the finest level's error 0.30 % ± 0.10 %" in strip


def test_refusals_are_one_line_per_reason(report):
    _, md, _ = report
    ek = _section(md, "1. Scene `ek`")
    assert f"- **fem refused levels 0–2** (validity): {FEM_ELLIPSE}" in ek
    assert f"- **fipy refused level 3** (budget): {FIPY_BUDGET}" in ek
    assert ek.count(FEM_ELLIPSE) == 1
    strip = _section(md, "2. Scene `strip`")
    assert "**green failed level 0**" in strip and "timed out after 120 s" in strip
    assert "| green | 0 | failed" not in strip


def test_all_zero_and_missing_columns_dropped(report):
    _, md, _ = report
    ek = _section(md, "1. Scene `ek`")
    table = next(line for line in ek.splitlines() if line.startswith("| method | level |"))
    assert "err max T [%]" in table and "err Fx" not in table and "err p L2" not in table
    note = next(line for line in ek.splitlines() if line.startswith("Columns left out"))
    assert "err Fx [%]" in note  # zero in every run (a metric no run computed is not a column at all)


def test_published_value_printed_exactly(report):
    _, md, _ = report
    ek = _section(md, "1. Scene `ek`")
    row = next(line for line in ek.splitlines() if line.startswith("| `max_surface_temperature` |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "149.7"
    assert cells[2] == "149.1 (Δ −0.40 %)"


def test_findings(report):
    _, md, _ = report
    verdict = _section(md, "Verdict")
    findings = verdict.split("### Key findings")[1].split("\n\n")[1]
    items = [line for line in findings.splitlines() if line.startswith("- ")]
    assert 3 <= len(items) <= 5
    assert any(i.startswith("- 1 run failed: green on `strip`") for i in items)
    assert any("fem is unverified on `strip`" in i for i in items)
    assert any("green reaches 0.40 % error in 1.0 ms; fipy needs" in i for i in items)


def test_method_colours():
    from matplotlib.colors import to_rgb

    from railtherm.report import method_colour
    r, g, b = to_rgb(method_colour("green"))
    assert g > 0.5 and g > r + 0.3 and g > b + 0.3
    r, g, b = to_rgb(method_colour("fipy"))
    assert b > r and b > g
    r, g, b = to_rgb(method_colour("fastsim-fdm"))
    assert r > 0.9 and 0.3 < g < 0.7 and b < 0.2
    r, g, b = to_rgb(method_colour("fem"))
    assert r > g and b > g
    # other methods: a neutral palette in sorted order, independent of the others present
    assert method_colour("zeta", ["zeta", "alpha"]) != method_colour("alpha", ["zeta", "alpha"])
    assert method_colour("green", ["alpha", "green"]) == method_colour("green")


def test_stick_slip_colours_are_neutral():
    from matplotlib.colors import to_rgb

    from railtherm.report.figures import METHOD_COLOURS, SLIP_COLOUR, STICK_COLOUR
    for c in (STICK_COLOUR, SLIP_COLOUR):
        r, g, b = to_rgb(c)
        assert r == g == b  # grey
    assert not {STICK_COLOUR, SLIP_COLOUR} & set(METHOD_COLOURS.values())


def test_number_formats():
    from railtherm.report.format import duration, exact, level_range, memory, pct
    assert exact(149.7) == "149.7" and exact(55.0) == "55.0" and exact(3) == "3"
    assert pct(0.0038) == "0.38 %" and pct(-0.0041) == "−0.41 %" and pct(1e-15, floor=1e-9) == "≈0 %"
    assert duration(7.6e-4) == "760 µs" and duration(0.0123) == "12 ms" and duration(13.76) == "14 s"
    assert memory(1.2e8) == "120 MB" and level_range([0, 1, 2, 5]) == "0–2, 5"


def test_report_imports_no_physics(tmp_path):
    """The report is a pure reader: writing one imports neither railtherm.analysis.analytic, railtherm.references
    nor any stage model beyond what `import railtherm` itself loads."""
    out = _folder(tmp_path)
    code = textwrap.dedent(f"""
        import sys
        import railtherm
        before = {{m for m in sys.modules if m.startswith("railtherm.models")}}
        from railtherm.report import write_report
        write_report({str(out)!r})
        mods = set(sys.modules)
        bad = sorted(m for m in mods if m.startswith(("railtherm.analysis", "railtherm.references"))
                     or m.startswith("railtherm.models") and m not in before)
        print("BAD", bad)
    """)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "MPLBACKEND": "Agg"})
    assert res.returncode == 0, res.stderr
    assert "BAD []" in res.stdout, res.stdout
    src = Path(__import__("railtherm.report", fromlist=["x"]).__file__).parent
    for p in src.glob("*.py"):
        text = p.read_text()
        assert not re.search(r"(from|import)\s+(\.\.|railtherm\.)(analytic|references|models)\b", text), p


def _reference_data(status_kalker: str = "inaccurate"):
    """StudyData of one kalker-referenced scene (kalker's coarse levels measured against its own finest)
    and a sweep of two such scenes."""
    from railtherm.report.load import Run, SceneInfo, StudyData
    runs, info = [], {}
    for s in ("ek-exact", "curve--a", "curve--b"):
        info[s] = SceneInfo(s, headline="max_surface_temperature", reference_kind="kalker",
                            sweep={"creepage.longitudinal": -1e-3 if s.endswith("a") else -2e-3} if "--" in s else {},
                            base=s.split("--")[0])
        for lv, t in ((0, 0.5), (1, 2.0), (2, 8.0)):
            st = status_kalker if lv < 2 else "ok"
            runs.append(Run(s, "kalker", lv, st, wall_time=t, headline_error=0.2 if lv < 2 else 0.0,
                            headline_reference="method:kalker"))
            runs.append(Run(s, "green", lv, "inaccurate", wall_time=t / 100, headline_error=0.08,
                            headline_reference="method:kalker"))
    return StudyData(out=Path("."), name="x", tolerance=0.05, runs=runs, scenes=list(info), methods=["green", "kalker"],
                     levels=[0, 1, 2], info={}, study=None, scene=info, orders={}, cross={}, curves=None)


@pytest.mark.parametrize("status", ["inaccurate", "ok"])
def test_reference_method_cell_is_not_a_verdict(status):
    """A scene whose reference is the method kalker: kalker's own cell says "reference" (finest level,
    no error, no status colour) instead of "inaccurate · L0" against its own finest level; the
    other methods keep their verdicts; a sweep of such scenes says "reference" too."""
    from railtherm.report.verdict import cell, choose, rows, scorecard, sweep_groups
    data = _reference_data(status)
    v = choose(data, "ek-exact", "kalker")
    c = cell(v)
    assert v.status == "reference" and v.run.level == 2
    assert c.text.startswith("reference") and "level 2" in c.text and "%" not in c.text
    assert "inaccurate" not in c.text and c.css not in ("ok", "inaccurate", "unverified", "refused", "failed")
    g = choose(data, "ek-exact", "green")
    assert g.status == "inaccurate" and cell(g).text.startswith("inaccurate")
    table_rows = rows(data, sweep_groups(data))
    cards = scorecard(data, table_rows)
    sweep = next(r for r in table_rows if r.group is not None)
    sc = cell(cards[(sweep.label, "kalker")])
    assert sc.text.startswith("reference") and "%" not in sc.text, sc.text
    assert cell(cards[(sweep.label, "green")]).text.startswith("inaccurate")


def test_an_inaccurate_cell_names_its_worst_metric_when_the_headline_is_within_tolerance():
    """A run that is inaccurate on another metric than the headline says which one (e.g. the cooling rate of a
    thermal trace), so that "inaccurate · 0.5 %" does not contradict the tolerance."""
    from railtherm.report.load import Run
    from railtherm.report.verdict import Verdict, cell
    r = Run(scene="s", method="green", level=3, status="inaccurate")
    r.errors = {"max_surface_temperature": 0.005, "cooling_rate": 0.2, "peak_temperature": 0.01}
    r.references = {"max_surface_temperature": "analytic:moving-source", "cooling_rate": "analytic:moving-source",
                    "peak_temperature": "self:finest"}
    text = cell(Verdict("green", "inaccurate", r, 0.005, 0.1)).text
    assert "inaccurate" in text and "cooling rate 20" in text
    r.errors["cooling_rate"] = 0.001
    assert "cooling rate" not in cell(Verdict("green", "inaccurate", r, 0.005, 0.1)).text


def test_a_finding_on_a_method_that_misses_names_the_failing_metric():
    """"No level of fipy is within 5 % (worst 0.074 %)" contradicted itself when the headline was fine and the
    cooling rate was not: the finding names the headline's worst error and the metric that fails."""
    from types import SimpleNamespace
    from railtherm.report.load import Run
    from railtherm.report.verdict import Row, Verdict, findings
    r = Run(scene="s", method="fipy", level=1, status="inaccurate")
    r.errors = {"max_surface_temperature": 0.00074, "cooling_rate": 0.11}
    r.references = {"max_surface_temperature": "analytic:moving-source", "cooling_rate": "analytic:moving-source"}
    data = SimpleNamespace(tolerance=0.05, methods=["fipy"], runs=[r], stages=lambda *a: {})
    row = Row("s", "scene-s", ["s"], "max_surface_temperature")
    out = findings(data, [row], {("s", "fipy"): Verdict("fipy", "inaccurate", r, 0.00074, 0.5)})
    miss = next(t for t in out if t.startswith("No level of fipy"))
    assert "worst max. surface temperature error 0.074 %" in miss and "fipy: cooling rate 11 %" in miss, miss


def test_a_finding_credits_the_model_that_ran_on_a_given_heat_source():
    """On a scene with a given heat source only a chain's temperature stage runs: "kalker reaches 0.12 %" would
    credit a contact model that never ran, so the finding names the temperature model."""
    from types import SimpleNamespace
    from railtherm.report.load import Run
    from railtherm.report.verdict import Row, Verdict, acting, findings
    stages = {"kalker": {"heat_source": "given", "temperature": "green"},
              "fipy": {"heat_source": "given", "temperature": "fipy"}}
    runs = [Run(scene="s", method=m, level=1, status="ok") for m in stages]
    data = SimpleNamespace(tolerance=0.05, methods=list(stages), runs=runs, stages=lambda sc, m: stages[m])
    assert acting(data, "s", "fipy") == "fipy"
    assert acting(data, "s", "kalker") == "kalker (green's temperatures; the heat source is given)"
    cards = {("s", "kalker"): Verdict("kalker", "ok", runs[0], 0.0012, 0.0019),
             ("s", "fipy"): Verdict("fipy", "ok", runs[1], 0.0002, 1.1)}
    out = findings(data, [Row("s", "scene-s", ["s"], "max_surface_temperature")], cards)
    assert any(t.startswith("For `s` (max. surface temperature), kalker (green's temperatures; the heat source is "
                            "given) reaches 0.12 % error") and "; fipy needs" in t for t in out), out


def _ladder_data(errors, stages=None, signed=None, scenes=("ek-exact",), reference="kalker"):
    """StudyData of green's ladder (headline errors per level) on kalker-referenced scenes, with stored
    verdicts left to the rule (no metrics.nc) unless ``signed`` gives metrics.nc's signed headline errors."""
    from railtherm.report.load import Run, SceneInfo, StudyData
    runs, info = [], {}
    methods = sorted((stages or {"green": {}, "kalker": {}}).keys())
    for s in scenes:
        info[s] = SceneInfo(s, headline="max_surface_temperature", reference_kind=reference)
        for m in methods:
            for lv, e in enumerate(errors if m != reference else [math.nan] * len(errors)):
                st = "unverified" if m == reference else ("ok" if e <= 0.05 else "inaccurate")
                runs.append(Run(s, m, lv, st, wall_time=10.0 ** lv * 1e-3, headline_error=e,
                                headline_reference="" if m == reference else f"method:{reference}"))
    data = StudyData(out=Path("."), name="x", tolerance=0.05, runs=runs, scenes=list(scenes), methods=methods,
                     levels=list(range(len(errors))), info={}, study=None, scene=info, orders={}, cross={},
                     curves=None)
    if stages:
        data.stages = lambda sc, m: stages[m]
    if signed is not None:
        data._stored_verdicts = signed
    return data


def test_a_lucky_level_is_not_the_scorecard_verdict():
    """ek-exact: green's error went 24 -> 0.17 -> 16 -> 25 % over the levels; the cell read "ok · 0.17 % · L1"."""
    from railtherm.report.verdict import cell, choose, findings, rows, scorecard, sweep_groups
    data = _ladder_data([0.24, 0.0017, 0.16, 0.25])
    v = choose(data, "ek-exact", "green")
    text = cell(v).text
    assert v.status == "inaccurate" and v.run.level == 3 and "25 %" in text and "non-monotone" in text, text
    assert not text.startswith("ok")
    table_rows = rows(data, sweep_groups(data))
    out = findings(data, table_rows, scorecard(data, table_rows))
    assert any("non-monotone" in t and "green" in t for t in out), out
    # a ladder that holds from level 1 on quotes level 1
    v = choose(_ladder_data([0.24, 0.03, 0.01, 0.004]), "ek-exact", "green")
    assert (v.status, v.run.level) == ("ok", 1)


def test_scorecard_reads_the_verdict_stored_in_metrics():
    """The cell shows metrics.nc's verdict_* (here a level the run table alone would not give) with the headline
    error's sign (headline_signed_error), and its message's "reference not converged" beside it."""
    from railtherm.report.verdict import cell, choose
    data = _ladder_data([0.24, 0.03, 0.01, 0.004], signed={
        ("ek-exact", "green"): {"level": 2, "error": 0.01, "time": 0.1, "status": "ok",
                                "message": "reference not converged: kalker's own finest-level error is 2.9 %"},
        ("ek-exact", "green", 2): -0.01})
    text = cell(choose(data, "ek-exact", "green")).text
    assert text.startswith("ok · −1.0 %") and "level 2" in text and "reference not converged" in text, text


def test_key_findings_split_the_contact_model_from_the_thermal_model():
    """On the kalker-referenced scenes green (FASTSIM -> green) differs from kalker only in the contact model and
    fastsim-fdm (FASTSIM -> fdm) from green only in the thermal model: a key finding says what each costs, from
    metrics.nc's signed headline errors at the finest levels."""
    from railtherm.report.verdict import findings, rows, scorecard, sweep_groups
    stages = {"kalker": {"normal": "kalker", "tangential": "kalker", "temperature": "green"},
              "green": {"normal": "hertz", "tangential": "fastsim", "temperature": "green"},
              "fastsim-fdm": {"normal": "hertz", "tangential": "fastsim", "temperature": "fdm"}}
    scenes = ("ek-exact-longitudinal", "ek-exact-lateral", "ek-exact-spin")
    signed = {}
    for s, e_c, e_t in zip(scenes, (0.27, 0.29, 0.31), (0.26, 0.30, 0.33)):
        signed[(s, "green", 3)], signed[(s, "fastsim-fdm", 3)] = e_c, e_t
    data = _ladder_data([0.3, 0.3, 0.3, 0.3], stages=stages, signed=signed, scenes=scenes)
    table_rows = rows(data, sweep_groups(data))
    out = findings(data, table_rows, scorecard(data, table_rows))
    split = next((t for t in out if "contact model alone" in t), "")
    assert "the fastsim contact model alone costs +27 to +31 % in max. surface temperature" in split, out
    assert "`ek-exact-*` (3 scenes)" in split and "the fdm thermal model adds" in split, split
    assert "−0.79 to +1.5 %" in split, split           # (1.26 / 1.27 - 1, 1.33 / 1.31 - 1)
