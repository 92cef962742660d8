"""The report shows each metric as metrics.nc stores it: an infinite error (a value that is not finite where
its reference is) as "not finite", a metric that is not scored as "—" with the reason of ``not_scored``,
signed errors with their sign, the cooling rate named with the depths it is scored at and its all-depths
variant beside it, and levels in words ("level 2", never "L2")."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

#: (method, level, status, max T error, its sign, cooling-rate error, all depths, not_scored)
RUNS = [
    ("green", 0, "inaccurate", 0.012, -1, 0.11, 0.37, "creep force x: zero by symmetry (no longitudinal creepage)"),
    ("green", 1, "ok", 0.004, -1, 0.02, 0.25, "creep force x: zero by symmetry (no longitudinal creepage)"),
    ("fipy", 0, "inaccurate", math.inf, 0, 0.03, 0.14, "creep force x: zero by symmetry (no longitudinal creepage)"),
]
DEPTH = 26.4e-6


def _metrics():
    import xarray as xr
    n = len(RUNS)
    col = lambda i: [r[i] for r in RUNS]  # noqa: E731
    obj = lambda v: ("run", np.array(v, dtype=object))  # noqa: E731
    signed = [e * s if math.isfinite(e) else np.nan for e, s in zip(col(3), col(4))]
    data = {"scene": obj(["band"] * n), "method": obj(col(0)), "level": ("run", np.array(col(1), "int32")),
            "status": obj(col(2)), "message": obj([""] * n), "reason_kind": obj([""] * n),
            "wall_time": ("run", np.array([1e-3, 4e-3, 0.5])),
            "error_max_surface_temperature": ("run", np.array(col(3), float)),
            "signed_error_max_surface_temperature": ("run", np.array(signed, float)),
            "reference_max_surface_temperature": obj(["analytic:jaeger"] * n),
            "error_cooling_rate": ("run", np.array(col(5), float)),
            "reference_cooling_rate": obj(["analytic:jaeger"] * n),
            "error_cooling_rate_all_depths": ("run", np.array(col(6), float)),
            "reference_cooling_rate_all_depths": obj(["analytic:jaeger"] * n),
            "error_creep_force_x": ("run", np.full(n, np.nan)),
            "reference_creep_force_x": obj(["analytic:full-sliding"] * n),
            "not_scored": obj(col(7)), "cooling_rate_depth": ("run", np.full(n, DEPTH)),
            "headline_error": ("run", np.array(col(3), float)),
            "headline_signed_error": ("run", np.array(signed, float)),
            "headline_reference": obj(["analytic:jaeger"] * n),
            "headline": ("scene_name", np.array(["max_surface_temperature"], dtype=object)),
            "reference_kind": ("scene_name", np.array(["analytic"], dtype=object))}
    ds = xr.Dataset(data, coords={"run": np.arange(n), "scene_name": np.array(["band"], dtype=object)})
    ds.attrs.update(study="metrics-table", tolerance=0.05)
    return ds


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    from railtherm.report import write_report
    out = tmp_path_factory.mktemp("metrics-table") / "out"
    out.mkdir()
    (out / "study.json").write_text(json.dumps({"study": "metrics-table", "records": []}))
    _metrics().to_netcdf(out / "metrics.nc", engine="netcdf4")
    paths = write_report(out)
    return out, paths[0].read_text(), paths[1].read_text()


def _runs_table(md: str) -> tuple[list[str], list[list[str]]]:
    scene = re.split(r"^## \d+\. Scene `band`", md, flags=re.M)[1].split("\n## ")[0]
    lines = [ln for ln in scene.splitlines() if ln.startswith("| method | level")]
    assert lines, scene
    start = scene.splitlines().index(lines[0])
    body = []
    for ln in scene.splitlines()[start + 2:]:
        if not ln.startswith("|"):
            break
        body.append([c.strip() for c in ln.strip("|").split("|")])
    return [c.strip() for c in lines[0].strip("|").split("|")], body


def test_an_infinite_error_is_kept_and_shown_as_not_finite(out):
    from railtherm.report.load import load
    data = load(out[0])
    fipy = next(r for r in data.runs if r.method == "fipy")
    assert fipy.errors["max_surface_temperature"] == math.inf
    header, rows = _runs_table(out[1])
    col = header.index("err max T [%]")
    assert next(r for r in rows if r[0] == "fipy")[col] == "not finite"


def test_a_metric_not_scored_shows_a_dash_and_its_reason(out):
    header, rows = _runs_table(out[1])
    col = header.index("err Fx [%]")
    assert {r[col] for r in rows} == {"—"}
    assert "Fx not scored: zero by symmetry (no longitudinal creepage)" in out[1]


def test_signed_errors_keep_their_sign(out):
    header, rows = _runs_table(out[1])
    col = header.index("err max T [%]")
    assert next(r for r in rows if r[0] == "green" and r[1] == "0")[col] == "−1.2"


def test_cooling_rate_named_with_its_depths_and_all_depths_beside_it(out):
    header, rows = _runs_table(out[1])
    i = header.index("err cooling rate, z ≥ 26.4 µm [%]")
    assert header[i + 1] == "err cooling rate, all depths (not used by the verdict) [%]"
    assert next(r for r in rows if r[0] == "green" and r[1] == "0")[i + 1] == "37"


def test_no_level_is_called_l_and_a_digit(out):
    html = out[2]
    text = re.sub(r"<[^>]+>", " ", html.split("<body", 1)[1])
    hit = re.search(r".{0,40}\bL\d\b(?! norm).{0,40}", text)
    assert not hit, hit.group(0)
    assert "level 1" in text


def test_an_inaccurate_cell_says_which_metric_is_not_finite():
    from railtherm.report.load import Run
    from railtherm.report.verdict import Verdict, cell
    r = Run(scene="s", method="fipy", level=1, status="inaccurate")
    r.errors = {"max_surface_temperature": 0.005, "surface_temperature_l2": math.inf}
    r.references = {k: "analytic:moving-source" for k in r.errors}
    text = cell(Verdict("fipy", "inaccurate", r, 0.005, 0.1)).text
    assert "surface temperature (L2 norm) not finite" in text and "level 1" in text, text


def test_findings_quote_signed_headline_errors():
    from types import SimpleNamespace
    from railtherm.report.load import Run
    from railtherm.report.verdict import Row, Verdict, findings
    runs = [Run(scene="s", method=m, level=0, status="ok") for m in ("fast", "slow")]
    data = SimpleNamespace(tolerance=0.05, methods=["fast", "slow"], runs=runs, stages=lambda *a: {})
    cards = {("s", "fast"): Verdict("fast", "ok", runs[0], 0.012, 1e-3, signed=-0.012),
             ("s", "slow"): Verdict("slow", "ok", runs[1], 0.004, 1.0, signed=0.004)}
    out = findings(data, [Row("s", "scene-s", ["s"], "max_surface_temperature")], cards)
    text = next(t for t in out if t.startswith("For `s`"))
    assert "reaches −1.2 % error" in text and "for +0.40 %" in text and "1,000× the time of fast" in text, text


def test_a_finding_on_a_headline_that_is_not_finite_says_so():
    from types import SimpleNamespace
    from railtherm.report.load import Run
    from railtherm.report.verdict import Row, Verdict, findings
    r = Run(scene="s", method="fipy", level=0, status="inaccurate")
    r.errors = {"max_surface_temperature": math.inf}
    r.references = {"max_surface_temperature": "analytic:moving-source"}
    data = SimpleNamespace(tolerance=0.05, methods=["fipy"], runs=[r], stages=lambda *a: {})
    out = findings(data, [Row("s", "scene-s", ["s"], "max_surface_temperature")],
                   {("s", "fipy"): Verdict("fipy", "inaccurate", r, math.inf, 0.5)})
    miss = next(t for t in out if t.startswith("No level of fipy"))
    assert "worst max. surface temperature error not finite" in miss, miss
