"""Verdicts a researcher can trust: each test reproduces a finding of the issue on the first release
(and failed there), then pins the fix. Numbers are checked against exact identities."""
from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm import Capabilities, Method, TemperatureField, TemperatureModel, hookimpl
from railtherm.analysis.metrics import (compute_metrics, energy_balance, half_space_energy, rel_error, richardson)
from railtherm.physics import body_speeds
from railtherm.run.runner import RunTask, execute_run, run_hash

STUDY = """
schema_version = 1
[study]
name = "verdicts"
methods = {methods}
levels = {levels}
repeat = 1
reference = "{reference}"
{extra}
[defaults.wheel]
shear_modulus = 82e9
poisson_ratio = 0.28
bulk_temperature = {bulk}
[defaults.rail]
shear_modulus = 82e9
bulk_temperature = {bulk}
[[scene]]
name = "ek"
normal_force = 100e3
contact = {{ shape = "ellipse", semi_axes = [5.88e-3, 10.54e-3] }}
speed = 30.0
sliding_speed = 1.0
friction = 0.3
outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "frictional_power"]
"""


def study(tmp_path, methods='["green"]', levels="[0, 1]", reference="analytic", bulk=0.0, extra=""):
    p = tmp_path / "study.toml"
    p.write_text(STUDY.format(methods=methods, levels=levels, reference=reference, bulk=bulk, extra=extra))
    return railtherm.load_study(p)


# --- fixture methods ------------------------------------------------------------------------------
class StuckTemperature(TemperatureModel):
    """Green's temperatures, but its (pretend) iterative solver reports numpy's False for converged."""

    name = "stuck"
    description = "test fixture: never converges"
    capabilities = Capabilities(provides=frozenset({"surface_temperature", "max_surface_temperature",
                                                    "mean_contact_temperature"}))

    def compute_temperature(self, scene, source, level, options):
        bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
        surf = np.stack([source.flux(0), source.flux(1)]) * 0.0 + bulk.reshape(2, 1, 1)
        return TemperatureField.from_surface(source.grid, surf, diagnostics={
            "converged": np.False_, "iterations": 7, "residual": 0.25})


class HotTemperature(StuckTemperature):
    """1e6 degC everywhere: wrong physics, converged."""

    name = "hot"

    def compute_temperature(self, scene, source, level, options):
        f = super().compute_temperature(scene, source, level, options)
        surf = np.full_like(f.surface_temperature, 1e6)
        return TemperatureField.from_surface(source.grid, surf, diagnostics={
            "converged": True, "iterations": 0, "residual": 0.0})


class FixturePlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [StuckTemperature, HotTemperature]

    @hookimpl
    def railtherm_register_methods(self):
        chain = {"normal": ("hertz",), "tangential": ("full-sliding",)}
        return [Method("stuck", {**chain, "temperature": ("stuck",)}),
                Method("hot", {**chain, "temperature": ("hot",)})]


@pytest.fixture
def fixture_host():
    from railtherm.solving import plugins
    saved = plugins._HOST
    host = plugins.new_host([("verdict-fixtures", FixturePlugin())], autoload=True)
    plugins.set_host(host)
    yield host
    plugins.set_host(saved)


def statuses(m):
    return {(str(s), str(me), int(k)): str(st) for s, me, k, st in
            zip(m["scene"].values, m["method"].values, m["level"].values, m["status"].values)}


# --- 1. not converged is failed ------------------------------------------------------------------
def test_a_stage_that_did_not_converge_fails_the_run_with_its_numbers(fixture_host, tmp_path):
    """Finding 1: the pipeline read only a literal ``converged is False`` (numpy's False passed)."""
    with pytest.raises(railtherm.SolverError, match="did not converge.*stuck_iterations=7.*stuck_residual=0.25"):
        railtherm.solve(study(tmp_path).scenes[0], "stuck", 0)
    m = railtherm.run_study(study(tmp_path, methods='["stuck"]', levels="[0]"), tmp_path / "out", report=False)
    assert statuses(m) == {("ek", "stuck", 0): "failed"}
    assert m["reason_kind"].values[0] == "not-converged"


# --- 2. nothing to compare with is unverified ----------------------------------------------------
def test_reference_method_that_did_not_run_leaves_runs_unverified(fixture_host, tmp_path):
    """Finding 2: every run was ``ok`` with all errors NaN when the reference method had no result."""
    st = study(tmp_path, methods='["green", "stuck"]', reference="stuck")
    m = railtherm.run_study(st, tmp_path / "out", report=False)
    s = statuses(m)
    assert s[("ek", "green", 0)] == s[("ek", "green", 1)] == "unverified"
    assert "'stuck' has no successful run" in str(m["message"].values[0])


def test_finest_level_of_a_self_referenced_ladder_is_unverified(tmp_path):
    m = railtherm.run_study(study(tmp_path, reference="finest", levels="[0, 1, 2]"), tmp_path / "out", report=False)
    s = statuses(m)
    assert s[("ek", "green", 2)] == "unverified"
    # coarser levels are compared with the finest only: self-convergence, never ok
    assert s[("ek", "green", 0)] in ("unverified", "inaccurate") and s[("ek", "green", 1)] in ("unverified", "inaccurate")
    assert set(m["reference_max_surface_temperature"].values[:2]) == {"self:finest"}
    k = list(m["metric"].values).index("max_surface_temperature")
    assert m["order_reference"].values[0, 0, k] == "self:finest"


def test_ok_needs_an_independent_reference_and_names_it(tmp_path):
    m = railtherm.run_study(study(tmp_path), tmp_path / "out", report=False)
    assert set(m["status"].values) == {"ok"}
    assert set(m["reference_max_surface_temperature"].values) == {"analytic:moving-source"}
    # the Hertz patch and full-sliding power are the reference itself: not counted as checks
    assert set(m["reference_frictional_power"].values) == {""}
    assert np.all(np.isnan(m["error_frictional_power"].values))
    assert set(m["headline_reference"].values) == {"analytic:moving-source"}
    assert m["headline"].values.tolist() == ["max_surface_temperature"]


# --- 3. errors on the rise -----------------------------------------------------------------------
def test_temperature_errors_do_not_depend_on_the_bulk_temperature(tmp_path):
    """Finding 3: the same solution had error 1.2e-3 at bulk 0 degC and 2.8e-4 at bulk 500 degC."""
    errs = []
    for bulk in (0.0, 500.0):
        d = tmp_path / f"b{bulk:g}"
        d.mkdir()
        m = railtherm.run_study(study(d, bulk=bulk, levels="[0]"), d / "out", report=False)
        errs.append(float(m["error_max_surface_temperature"].values[0]))
    assert errs[0] > 1e-4
    assert errs[1] == pytest.approx(errs[0], rel=1e-6)
    assert rel_error(None, "max_pressure", 2.0, 1.0) == 1.0


# --- 6. resume keys on options and versions ------------------------------------------------------
def test_resume_recomputes_a_result_of_other_options(tmp_path):
    """Finding 6: resumed with cells = 16 over a cells = 4 result, the study kept 4."""
    sc = study(tmp_path).scenes[0]
    t4 = RunTask(sc, "green", 0, {"cells": 4}, str(tmp_path / "out"), repeat=1)
    assert execute_run(t4).status == "ok"
    t16 = RunTask(sc, "green", 0, {"cells": 16}, str(tmp_path / "out"), repeat=1)
    assert t16.run_hash != t4.run_hash
    rec = execute_run(t16, resume=True)
    assert not rec.resumed
    with xr.open_dataset(t16.path) as ds:
        assert ds.sizes["x"] == 16 and ds.attrs["run_hash"] == t16.run_hash
    again = execute_run(t16, resume=True)
    assert again.resumed and again.path == str(t16.path) and again.timing_runs == rec.timing_runs >= 1
    assert again.wall_time == rec.wall_time and again.peak_rss == rec.peak_rss
    assert run_hash(sc, "green", 0, {"cells": 16}) == t16.run_hash


# --- 7. timing and memory ------------------------------------------------------------------------
def test_fast_runs_are_timed_up_to_three_times_after_a_warm_up_and_memory_is_native(tmp_path, monkeypatch):
    """A short solve (green level 1: milliseconds) is timed ``repeat`` = 3 times after the process's
    warm-up of the method; the memory is the process's (interpreter included)."""
    from railtherm.run import runner
    monkeypatch.setattr(runner, "_WARM", set())
    sc = study(tmp_path).scenes[0]
    rec = execute_run(RunTask(sc, "green", 1, {}, str(tmp_path / "out"), repeat=3))
    assert rec.timing_runs == 3 and rec.wall_time <= rec.wall_time_median
    assert rec.phases["warmup"] > 0 and rec.peak_rss > 50e6 and rec.rss_growth >= 0  # interpreter included


def test_rss_peak_sees_native_allocations():
    from railtherm.run.runner import RSSPeak
    with RSSPeak() as mem:
        a = np.ones(50_000_000 // 8)  # 50 MB, touched
        del a
    assert mem.growth > 40e6 and mem.peak > mem.growth


# --- 8. a real energy balance --------------------------------------------------------------------
def test_half_space_energy_is_exact_for_a_piecewise_constant_flux():
    """A flux spike in the last cell (FASTSIM's slip power at small creepage): exact, not 11 % off."""
    beta, q0, T, n = 1.3e4, 1e8, 4e-4, 32
    t = np.linspace(0.0, T, n + 1)
    tc = 0.5 * (t[1:] + t[:-1])
    # theta at the centres for a flux q0 in the last cell only (exact 1-D solution)
    theta = np.where(tc > t[-2], 2 * q0 * np.sqrt(np.clip(tc - t[-2], 0, None)), 0.0) / (beta * math.sqrt(math.pi))
    e = half_space_energy(theta, t) * beta / math.sqrt(math.pi)
    assert e == pytest.approx(q0 * (T / n), rel=1e-12)


def test_half_space_energy_of_a_ramp_converges_at_order_one_and_a_half():
    """Flux q = c t on a 1-D half-space: theta(t) = 4 c t^1.5 / (3 beta sqrt(pi)); E(T) = c T^2 / 2.

    Midpoint collocation of the Abel equation (kernel (t - tau)^-1/2) with piecewise-constant flux:
    the integrated flux converges as h^(1 + 1/2) (local ratios 3.05, 3.00, 2.96, 2.93: 1.6 -> 1.55,
    approaching 1.5; the same for q = t^2 and t^3, so it is the scheme's order, not the data's)."""
    beta, c, T = 1.3e4, 1e11, 4e-4
    errors, hs = [], []
    for n in (8, 16, 32, 64, 128):
        t = np.linspace(0.0, T, n + 1)
        tc = 0.5 * (t[1:] + t[:-1])
        theta = 4 * c * tc ** 1.5 / (3 * beta * math.sqrt(math.pi))
        e = half_space_energy(theta, t) * beta / math.sqrt(math.pi)
        errors.append(abs(e - c * T ** 2 / 2) / (c * T ** 2 / 2))
        hs.append(T / n)
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert errors[-1] < 2e-4
    assert 1.4 < slope < 1.7, (slope, errors)


def test_energy_balance_of_the_exact_field_and_of_wrong_physics(fixture_host, tmp_path):
    """Finding 8: heat_balance compared the heat source with itself (1e-16 for every run)."""
    from railtherm.analysis.analytic import reference_fields
    sc = study(tmp_path).scenes[0]
    ds = railtherm.solve(sc, "green", 1)
    exact = ds.copy(deep=True)
    exact["surface_temperature"].values[...] = reference_fields(sc, ds)["surface_temperature"]
    parts = (body_speeds(sc.speed, sc.sliding_speed, sc.tangential), sc.wheel, sc.rail)
    e, ref = energy_balance(exact, *parts)
    assert ref == "analytic:half-space-1d" and abs(e) < 3e-3  # Péclet about 6000: the identity's own error
    hot = railtherm.solve(sc, "hot", 0)
    e_hot, _ = energy_balance(hot, *parts)
    assert e_hot > 100
    m = railtherm.run_study(study(tmp_path, methods='["hot"]', levels="[0]"), tmp_path / "out", report=False)
    assert statuses(m) == {("ek", "hot", 0): "inaccurate"}


# --- 9. the API rejects bad levels and methods ---------------------------------------------------
@pytest.mark.parametrize("level", [-1, 1.7, "1", True])
def test_solve_rejects_a_level_that_is_not_a_non_negative_integer(tmp_path, level):
    with pytest.raises(railtherm.SceneError, match="level"):
        railtherm.solve(study(tmp_path).scenes[0], "green", level)


def test_solve_rejects_an_unknown_method_and_option(tmp_path):
    sc = study(tmp_path).scenes[0]
    with pytest.raises(railtherm.SceneError, match="unknown method 'gren'"):
        railtherm.solve(sc, "gren", 0)
    with pytest.raises(railtherm.SceneError, match="foo"):
        railtherm.solve(sc, "green", 0, {"foo": 1})


# --- Richardson ----------------------------------------------------------------------------------
def test_richardson_recovers_the_error_of_a_second_order_ladder():
    levels = [0, 1, 2, 3]
    exact = 10.0
    q = [exact + 3.0 * 2.0 ** (-2 * k) for k in levels]
    est, unc, p = richardson(levels, q, theoretical=2.0)
    assert p == pytest.approx(2.0, abs=1e-9)
    assert est == pytest.approx(abs(q[-1] - exact), rel=1e-9) and unc < 1e-9
    assert math.isnan(richardson([0, 1], q[:2])[0])
