"""Verdicts on the headline: a run is ok only when its scene's headline quantity is checked against an
independent reference; the scorecard's level holds under refinement; noise and shared stages are not
scored; a non-finite value fails its metric. Each test reproduces a finding on the previous release (where it
failed) and pins the rule of docs/verdicts.md."""
from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.analysis.metrics import run_errors
from studies import steel

CARTER = """
schema_version = 1
[study]
name = "carter"
methods = ["green"]
levels = [0, 1]
reference = "analytic"
tolerance = 0.05
repeat = 1
""" + steel("wheel") + steel("rail") + """[[scene]]
name = "carter-hot"
normal_force = 1.78896e5
contact = { shape = "line", wheel_radius = 0.5 }
speed = 10.0
creepage = { longitudinal = -5e-5 }
friction = 0.3
outputs = ["max_surface_temperature", "creep_force_x", "traction_x", "stick"]
"""


@pytest.fixture(scope="module")
def carter(tmp_path_factory):
    d = tmp_path_factory.mktemp("carter")
    (d / "s.toml").write_text(CARTER)
    return railtherm.run_study(d / "s.toml", d / "out", report=False)


def _row(m, level):
    return int(np.flatnonzero(m["level"].values == level)[0])


# --- 1. ok needs the headline checked ----------------------------------------------------------------
def test_ok_needs_the_headline_checked_against_an_independent_reference(carter):
    """Green on a Carter line contact, headline max. surface temperature: the temperature has no exact value
    (its finest level is its own), the creep force is within 3.2 % of Carter. Every level read "ok" with a NaN
    headline error; now the headline is unchecked, so the runs are unverified and say what was checked."""
    m = carter
    i = _row(m, 1)
    assert str(m["headline"].values[0]) == "max_surface_temperature"
    assert math.isnan(float(m["headline_error"].values[i]))
    assert str(m["status"].values[i]) == "unverified"
    msg = str(m["message"].values[i])
    assert "max_surface_temperature not checked" in msg and "creep_force_x against analytic:carter" in msg, msg
    assert "ok" not in set(map(str, m["status"].values))
    # no level qualifies for the scorecard
    assert str(m["verdict_status"].values[0, 0]) == "" and math.isnan(float(m["verdict_level"].values[0, 0]))


def test_run_status_rule():
    from railtherm.analysis.verdicts import run_status
    tol = 0.05
    head = "max_surface_temperature"
    ok = run_status({head: (0.01, "analytic:moving-source")}, math.nan, "", tol, head)
    assert ok[0] == "ok" and "analytic:moving-source" in ok[1]
    # a self error within tolerance does not check the headline
    assert run_status({head: (0.01, "self:finest")}, math.nan, "", tol, head)[0] == "unverified"
    # another independent error out of tolerance: inaccurate, named
    st, msg = run_status({head: (0.01, "analytic:x"), "creep_force_x": (0.2, "analytic:carter")}, math.nan, "",
                         tol, head)
    assert st == "inaccurate" and "creep_force_x" in msg
    # non-finite where the reference is finite: inaccurate, named
    st, msg = run_status({head: (0.01, "analytic:x"), "peak_temperature": (math.inf, "analytic:jaeger")},
                         math.nan, "", tol, head)
    assert st == "inaccurate" and "peak_temperature" in msg


# --- 2. the converged verdict level ---------------------------------------------------------------------
def _ladder(errors, status=None, times=None):
    return [{"level": k, "status": (status or {}).get(k, "ok" if e <= 0.05 else "inaccurate"),
             "reason_kind": "", "headline_error": e, "wall_time": (times or {}).get(k, 10.0 ** k)}
            for k, e in enumerate(errors)]


def test_a_lucky_level_does_not_qualify_and_the_ladder_is_non_monotone():
    """ek-exact: fastsim-fdm's error went 24 -> 0.17 -> 16 -> 25 % over the levels; the scorecard quoted the
    accidental crossing at level 1."""
    from railtherm.analysis.verdicts import ladder_verdict
    v = ladder_verdict(_ladder([0.24, 0.0017, 0.16, 0.25]), 0.05)
    assert v["level"] == -1 and v["status"] == "" and math.isnan(v["error"])
    assert not v["monotone"] and "non-monotone" in v["message"] and "25 %" in v["message"]


def test_the_cheapest_level_among_those_that_hold_under_refinement():
    from railtherm.analysis.verdicts import ladder_verdict
    v = ladder_verdict(_ladder([0.08, 0.03, 0.01, 0.004]), 0.05)
    assert (v["level"], v["status"], v["error"], v["monotone"]) == (1, "ok", 0.03, True)
    # level 0 is cheap and within tolerance, but level 1 is not: only levels 2 and 3 qualify
    v = ladder_verdict(_ladder([0.01, 0.06, 0.02, 0.01]), 0.05)
    assert v["level"] == 2 and not v["monotone"]
    # a finer level that failed ran and is not within tolerance; one refused did not run
    v = ladder_verdict(_ladder([0.03, 0.02, 0.01], status={2: "failed"}), 0.05)
    assert v["level"] == -1
    v = ladder_verdict(_ladder([0.03, 0.02, 0.01], status={2: "refused"}), 0.05)
    assert v["level"] == 0


def test_levels_whose_times_tie_give_the_lowest_level():
    """Two runs of one study time a short solve tens of per cent apart: qualifying levels within TIME_TIE (1.5)
    of the cheapest cost the same and the lowest is quoted, in the stored verdict and in the report's rule;
    a finer level clearly cheaper (more than 1.5 times) is still taken."""
    from railtherm.analysis.verdicts import ladder_verdict
    from railtherm.contract.verdict_rules import TIME_TIE
    from railtherm.report.load import Run
    from railtherm.report.verdict import ladder_rule
    assert TIME_TIE == 1.5
    errors = [0.01, 0.005, 0.002]
    for times, level in (({0: 0.012, 1: 0.010, 2: 0.5}, 0), ({0: 0.010, 1: 0.012, 2: 0.5}, 0),
                         ({0: 0.030, 1: 0.010, 2: 0.5}, 1), ({0: math.inf, 1: 0.2, 2: 0.29}, 1)):
        ladder = _ladder(errors, times=times)
        assert ladder_verdict(ladder, 0.05)["level"] == level, times
        runs = [Run("s", "m", r["level"], r["status"], wall_time=r["wall_time"], headline_error=r["headline_error"])
                for r in ladder]
        assert ladder_rule(runs, 0.05)["level"] == level, times


def test_metrics_store_the_scorecard(carter):
    """verdict_* on scene_name x method_name; every qualifying level's finer levels are within tolerance."""
    m = carter
    for v in ("verdict_level", "verdict_error", "verdict_time", "verdict_status", "verdict_message"):
        assert m[v].dims == ("scene_name", "method_name"), v
    assert "non-monotone" not in str(m["verdict_message"].values[0, 0]) or True
    assert "no level qualifies" in str(m["verdict_message"].values[0, 0])


# --- 3. no score on noise -----------------------------------------------------------------------------
def _scene(**kw):
    base = dict(name="lat", normal_force=100e3, contact={"shape": "ellipse", "curvatures": [1.015, 0.4215]},
                speed=30.0, creepage={"lateral": 1e-3}, friction=0.3,
                outputs=["max_surface_temperature", "creep_force_x"])
    base.update(kw)
    return railtherm.load_scene(base)


def _result(stages, **values):
    ds = xr.Dataset({k: ((("body",), np.asarray(v, float)) if np.ndim(v) else ((), float(v)))
                     for k, v in values.items()}, coords={"body": ["wheel", "rail"]})
    ds.attrs["stages"] = stages
    return ds


FASTSIM = "normal:hertz tangential:fastsim heat_source:frictional temperature:green"
KALKER = "normal:kalker tangential:kalker heat_source:frictional temperature:green"


def test_a_force_zero_by_symmetry_is_not_scored():
    """ek-exact-lateral: FASTSIM's Fx is exactly 0, the exact contact's is round-off; "creep force x 100 %" made
    the scene inaccurate."""
    sc = _scene()
    run = _result(FASTSIM, creep_force_x=0.0, max_surface_temperature=[80.0, 80.0])
    ref = _result(KALKER, creep_force_x=3e-5, max_surface_temperature=[81.0, 81.0])
    err = run_errors(sc, run, {}, ref, ref_tag="method:kalker")
    assert math.isnan(err["creep_force_x"][0])
    notes = {}
    run_errors(sc, run, {}, ref, ref_tag="method:kalker", notes=notes)
    assert "symmetry" in notes["creep_force_x"]
    # with longitudinal creepage the same force is scored
    lon = _scene(creepage={"longitudinal": -1e-3})
    assert run_errors(lon, run, {}, ref, ref_tag="method:kalker")["creep_force_x"][0] == pytest.approx(1.0)


def test_a_reference_below_the_noise_floor_is_not_scored():
    from railtherm.analysis.verdicts import unscored
    assert "noise floor" in unscored("creep_force_x", 5e-10)         # 0.5e-3 µN < 1e-3 µN
    assert unscored("creep_force_x", 2e-9) == ""
    assert unscored("max_surface_temperature", [20.0, 20.0 + 1e-8], 20.0) != ""
    assert unscored("creep_force_x", 0.0) == "the reference is zero"
    # a metric zero by symmetry on the scene (verdicts.zero_by_symmetry) is not scored, whatever its reference
    assert unscored("creep_force_x", 1.0, zero={"creep_force_x": "zero by symmetry"}) == "zero by symmetry"
    assert unscored("max_pressure", 1.0, zero={"creep_force_x": "zero by symmetry"}) == ""


# --- 7. non-finite values fail their metric ------------------------------------------------------------
def test_a_nan_against_a_finite_reference_fails_the_metric():
    sc = _scene(creepage={"longitudinal": -1e-3})
    run = _result(FASTSIM, creep_force_x=-2000.0, max_surface_temperature=[np.nan, 80.0])
    ref = _result(KALKER, creep_force_x=-2010.0, max_surface_temperature=[81.0, 81.0])
    err = run_errors(sc, run, {}, ref, ref_tag="method:kalker")
    assert err["max_surface_temperature"][0] == math.inf
    assert err["creep_force_x"][0] == pytest.approx(10 / 2010)


def test_nan_trace_depths_fail_the_trace_metric():
    from railtherm.analysis.rises import rel_error
    ref = np.array([[np.nan, np.nan], [10.0, 5.0]])
    assert rel_error(None, "time_above", np.array([[1.0, 1.0], [10.0, 5.0]]), ref) == 0.0
    assert rel_error(None, "time_above", np.array([[1.0, 1.0], [10.0, np.nan]]), ref) == math.inf


# --- 9. shared stages are not checks; references must be converged ---------------------------------------
def test_a_quantity_of_a_shared_stage_model_is_not_an_independent_check():
    """wheelset_curve: semi_axis_a comes from the wheelset model in every chain; its zero error against
    method:wheelset-kalker counted as a check."""
    sc = _scene(creepage={"longitudinal": -1e-3})
    run = _result("normal:wheelset tangential:fastsim heat_source:frictional temperature:green",
                  semi_axis_a=5.88e-3, creep_force_x=-2000.0)
    ref = _result("normal:wheelset tangential:kalker heat_source:frictional temperature:green",
                  semi_axis_a=5.88e-3, creep_force_x=-2100.0)
    err = run_errors(sc, run, {}, ref, ref_tag="method:wheelset-kalker")
    assert "semi_axis_a" not in err
    assert err["creep_force_x"][0] == pytest.approx(100 / 2100)


def test_a_reference_method_that_is_not_converged_is_named_beside_every_verdict():
    """friction study: kalker's frictional power moved 2.9 % between its two levels against a 5 % tolerance."""
    from railtherm.analysis.scorecard import verdict_vars
    tol, h = 0.05, "frictional_power"
    rows = [{"scene": "s", "method": "kalker", "level": 1, "status": "unverified", "headline_error": math.nan,
             "wall_time": 1.0, f"error_{h}": 0.029, f"reference_{h}": "self:finest"},
            {"scene": "s", "method": "kalker", "level": 2, "status": "unverified", "headline_error": math.nan,
             "wall_time": 4.0},
            {"scene": "s", "method": "fastsim-green", "level": 2, "status": "ok", "headline_error": 0.01,
             "wall_time": 0.1, f"error_{h}": 0.01, f"reference_{h}": "method:kalker"}]
    ds = xr.Dataset(coords={"scene_name": ["s"], "method_name": ["fastsim-green", "kalker"], "metric": [h]})
    ds["headline"] = ("scene_name", np.array([h], dtype=object))
    ds["reference_kind"] = ("scene_name", np.array(["kalker"], dtype=object))
    ds = verdict_vars(ds, rows, ["s"], ["fastsim-green", "kalker"], tol)
    assert float(ds["reference_convergence_error"].values[0, 0]) == pytest.approx(0.029)
    assert str(ds["verdict_status"].values[0, 0]) == "ok"
    assert "reference not converged" in str(ds["verdict_message"].values[0, 0])
    rows[0][f"error_{h}"] = 0.01                          # below a quarter of the tolerance
    ds = verdict_vars(ds, rows, ["s"], ["fastsim-green", "kalker"], tol)
    assert "reference not converged" not in str(ds["verdict_message"].values[0, 0])


def test_the_report_applies_the_stored_rule_to_metrics_without_it():
    """The report reads only the output folder (it may not import analysis): for metrics.nc files without
    verdict_* it applies docs/verdicts.md's rule itself; both implementations agree on random ladders."""
    from railtherm.analysis.verdicts import ladder_verdict
    from railtherm.report.load import Run
    from railtherm.report.verdict import ladder_rule
    rng = np.random.default_rng(7)
    for _ in range(400):
        n = int(rng.integers(1, 5))
        ladder = []
        for k in range(n):
            st = str(rng.choice(["ok", "inaccurate", "unverified", "failed", "refused"]))
            kind = str(rng.choice(["", "timeout", "error"])) if st == "failed" else ""
            e = float(rng.choice([math.nan, rng.uniform(0, 0.1)])) if st in ("ok", "inaccurate") else math.nan
            ladder.append({"level": k, "status": st, "reason_kind": kind, "headline_error": e,
                           "wall_time": float(rng.uniform(0, 1))})
        a = ladder_verdict(ladder, 0.05)
        b = ladder_rule([Run("s", "m", r["level"], r["status"], reason_kind=r["reason_kind"],
                             wall_time=r["wall_time"], headline_error=r["headline_error"]) for r in ladder], 0.05)
        assert (a["level"], a["status"]) == (b["level"], b["status"]), ladder
        assert ("non-monotone" in a["message"]) == ("non-monotone" in b["message"]), ladder


def test_the_cooling_rate_at_all_depths_is_stored_but_never_decides_a_status(monkeypatch):
    """error_cooling_rate_all_depths is shown beside the scored cooling rate (z >= z_c) and used by no status."""
    from railtherm.analysis import metrics
    from railtherm.analysis.metrics import UNSCORED_BY_STATUS
    assert UNSCORED_BY_STATUS == ("cooling_rate_all_depths",)
    sc = railtherm.load_scene(dict(name="src", speed=1.0, heat_partition=0.0,
                                   heat_source={"flux": 1e6, "shape": "uniform", "semi_axes": [2.5e-3, 2.5e-3]},
                                   field={"behind": 5e-3, "depth": 1e-3, "threshold": 2.0},
                                   outputs=["max_surface_temperature", "cooling_rate"]))
    monkeypatch.setattr(metrics, "run_errors", lambda *a, **k: {
        "max_surface_temperature": (0.01, "analytic:moving-source"),
        "cooling_rate": (0.02, "analytic:moving-source"),
        "cooling_rate_all_depths": (0.4, "analytic:moving-source")})
    monkeypatch.setattr(metrics, "_cooling_depth", lambda z_c: 26e-6)

    class Rec:
        scene, method, level, status, message, wall_time, path = sc.name, "green", 0, "ok", "", 0.1, "x"
        summary, energy_balance, energy_reference, values = True, float("nan"), "", {}

    class Study:
        scenes, reference, tolerance, name = [sc], "analytic", 0.05, "s"
    ctx = metrics._Study(Study(), [Rec()], 0.05)
    ctx.cache["x"] = xr.Dataset()
    ctx.exact[sc.name] = {"max_surface_temperature": 1.0}
    row = metrics._score(ctx, Rec())
    assert row["status"] == "ok" and row["error_cooling_rate_all_depths"] == 0.4, row["message"]
    assert row["cooling_rate_depth"] == 26e-6
    from railtherm.analysis.verdicts import label
    assert label("cooling_rate", 26e-6) == "cooling rate, z ≥ 26 µm"


def test_the_friction_study_reference_is_converged_where_the_issue_found_it_was_not():
    """friction.toml's reference kalker at xi = -2e-3 (constant friction, 30 m/s): level 2 was -2.9 % off the exact
    power and its finest step 2.2 % (frictional power) and 2.6 % (mean temperature) against a 5 % tolerance. With
    the study's own kalker options its finest step is below a quarter of the tolerance on every compared quantity."""
    from pathlib import Path
    st = railtherm.load_study(Path(__file__).resolve().parents[1] / "studies" / "friction.toml")
    sc = next(s for s in st.scenes if s.name == "constant-30--creepage.longitudinal=-0.002")
    opts = st.options.get("kalker", {})
    lo, hi = (railtherm.solve(sc, "kalker", k, options=opts) for k in st.levels[-2:])
    for q in ("creep_force_x", "frictional_power", "max_surface_temperature", "mean_contact_temperature"):
        a, b = float(np.ravel(lo[q].values)[0]), float(np.ravel(hi[q].values)[0])
        assert abs(a - b) / abs(b) < 0.25 * st.tolerance, (q, a, b)


def test_a_reference_field_that_cannot_be_put_on_the_run_grid_fails_the_metric():
    """An interpolation that raised (or gave another shape) dropped the field error silently."""
    sc = _scene(creepage={"longitudinal": -1e-3})
    x = np.linspace(-1e-3, 1e-3, 5)
    run = _result(FASTSIM, creep_force_x=-2000.0)
    run["surface_temperature"] = (("body", "x"), np.ones((2, 5)))
    run = run.assign_coords(x=x)
    ref = _result(KALKER, creep_force_x=-2010.0)
    ref["surface_temperature"] = (("body", "x", "y"), np.ones((2, 5, 3)))
    ref = ref.assign_coords(x=x, y=np.linspace(-1e-3, 1e-3, 3))
    notes = {}
    err = run_errors(sc, run, {}, ref, ref_tag="method:kalker", notes=notes)
    assert err["surface_temperature_l2"][0] == math.inf and "grid" in notes["surface_temperature_l2"]
    from railtherm.analysis.verdicts import run_status
    st, msg = run_status(err, math.nan, "", 0.05, "creep_force_x", notes=notes)
    assert st == "inaccurate" and "surface_temperature_l2" in msg and "grid" in msg


def test_a_transient_scene_is_judged_on_its_pass_peaks():
    """A transient scene's headline is the peak of each pass even when it also asks for the one-pass field
    (the same in every pass: it would hide what accumulates between passes); a steady scene's stays the
    maximum surface temperature (docs/verdicts.md)."""
    from railtherm.analysis.metrics import headline
    steady = ("max_surface_temperature", "mean_contact_temperature", "heat_flux")
    assert headline(steady) == "max_surface_temperature"
    assert headline(steady + ("temperature_history", "pass_peak_temperature", "residual_rise")) == \
        "pass_peak_temperature"
    assert headline(("creep_force_x", "traction_x")) == "creep_force_x"
    assert headline(("heat_flux",)) == ""
