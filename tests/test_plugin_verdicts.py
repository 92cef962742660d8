"""Verdicts a researcher can trust, the models' part (docs/verdicts.md).

* every stage model reports ``converged`` / ``iterations`` / ``residual``; a coupling loop or a
  Krylov solve that stopped short says so (and core turns it into a failed run);
* budgets: grids and meshes too large for the machine are refused (kind "budget") before anything
  is allocated, naming the level, the cells and the budget;
* the FEM turns what used to be internal errors on valid input into a solution or a refusal;
* the green model says that its default convective surface was fitted to the published table;
* methods declare the theoretical convergence orders they can justify.

Run: python -m pytest tests/test_plugin_verdicts.py -q
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import railtherm
from railtherm.contract.grid import MAX_SURFACE_CELLS, surface_grid

STEEL = {"shear_modulus": 82e9, "poisson_ratio": 0.28, "density": 7850.0, "specific_heat": 450.0,
         "conductivity": 50.0}
#: Ertz & Knothe's ellipse in full sliding (seed Table 1, 30 m/s)
EK = {"name": "ek", "normal_force": 100e3, "contact": {"shape": "ellipse", "semi_axes": [5.88e-3, 10.54e-3]},
      "speed": 30.0, "sliding_speed": 1.0, "friction": 0.3, "heat_partition": 0.5,
      "wheel": dict(STEEL), "rail": dict(STEEL),
      "outputs": ["max_surface_temperature", "mean_contact_temperature", "surface_temperature"]}
#: the FEM scene of the seed (section 4.2) with a normal force on a short strip
FEM_MAT = {"shear_modulus": 8.2e10, "poisson_ratio": 0.2935548841893253, "density": 7800.0,
           "specific_heat": 460.0, "conductivity": 51.6672}
FEM = {"name": "fem-strip", "contact": {"shape": "line", "wheel_radius": 0.46}, "normal_force": 1e6,
       "speed": 10.0, "creepage": {"longitudinal": -2e-3}, "friction": 0.4, "heat_partition": 0.5,
       "strip": {"length": 0.1, "depth": 0.064}, "numerics": {"regularization": 1e-3},
       "wheel": {"rigid": True, **FEM_MAT}, "rail": dict(FEM_MAT),
       "outputs": ["max_pressure", "semi_axis_a", "creep_force_x", "max_surface_temperature"]}
LINE = {"name": "line", "normal_force": 1e6, "contact": {"shape": "line", "wheel_radius": 0.46}, "speed": 10.0,
        "sliding_speed": 1.0, "friction": 0.3, "heat_partition": 0.5, "wheel": dict(STEEL), "rail": dict(STEEL),
        "outputs": ["max_surface_temperature", "mean_contact_temperature"]}
GIVEN = {"name": "given", "speed": 30.0, "heat_partition": 0.5, "wheel": dict(STEEL), "rail": dict(STEEL),
         "heat_source": {"flux": 1e8, "shape": "hertz", "semi_axes": [5.88e-3, 10.54e-3]},
         "outputs": ["max_surface_temperature", "mean_contact_temperature"]}
GIVEN_LINE = {**GIVEN, "name": "given-line", "speed": 10.0,
              "heat_source": {"flux": 1e8, "shape": "hertz", "half_width": 2e-3}}
CREEP = {**EK, "name": "creep", "creepage": {"longitudinal": -1e-3, "lateral": 0.0, "spin": 0.0}}
del CREEP["sliding_speed"]

METRICS = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature_l2", "pressure_l2",
           "max_pressure", "semi_axis_a", "creep_force_x", "frictional_power")


def scene(base, **over):
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    out.update(over)
    return out


def _verdict_keys(ds):
    """{model: (converged, iterations, residual)} of every stage model named in ``ds.attrs['stages']``."""
    out = {}
    for item in ds.attrs["stages"].split():
        model = item.split(":")[1]
        for key in ("converged", "iterations", "residual"):
            assert f"{model}_{key}" in ds.attrs, (model, key, sorted(k for k in ds.attrs if k.startswith(model)))
        out[model] = tuple(ds.attrs[f"{model}_{k}"] for k in ("converged", "iterations", "residual"))
    return out


# ---------------------------------------------------------------------------------------------
# 1. diagnostics vocabulary
# ---------------------------------------------------------------------------------------------
CASES = [
    ("green", EK, 0, {}, {"hertz", "full-sliding", "frictional", "green"}),
    ("green", CREEP, 0, {}, {"hertz", "fastsim", "frictional", "green"}),
    ("green", GIVEN, 0, {}, {"given", "green"}),
    ("fipy", EK, 0, {}, {"hertz", "full-sliding", "frictional", "fipy"}),
    ("fipy", LINE, 0, {}, {"hertz", "full-sliding", "frictional", "fipy"}),
    ("fastsim-fdm", EK, 0, {}, {"hertz", "fastsim", "frictional", "fdm"}),
    ("fastsim-fdm", LINE, 0, {}, {"hertz", "fastsim", "frictional", "fdm"}),
    ("fastsim-fdm", scene(LINE, mode="transient", numerics={"scheme": "implicit"}), 0, {}, {"hertz", "fastsim", "frictional", "fdm"}),
    ("fem", FEM, 0, {}, {"fem"}),
    ("fem", GIVEN_LINE, 0, {}, {"given", "fem"}),   # API 2: the plan's given source is passed to the coupled model
]


@pytest.mark.parametrize("method, base, level, options, models", CASES,
                         ids=[f"{c[0]}-{c[1]['name']}-{i}" for i, c in enumerate(CASES)])
def test_every_stage_reports_converged_iterations_residual(method, base, level, options, models):
    """Each stage's diagnostics carry the three keys: converged (bool -> 0/1), iterations (int >= 0),
    residual (finite float >= 0); a run that returns is converged."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ds = railtherm.solve(base, method, level, options)
    keys = _verdict_keys(ds)
    assert set(keys) == models, keys
    for model, (conv, its, res) in keys.items():
        assert conv in (0, 1) and conv == 1, (model, conv)
        assert isinstance(its, (int, np.integer)) and its >= 0, (model, its)
        assert isinstance(res, (float, np.floating)) and math.isfinite(res) and res >= 0.0, (model, res)
    assert ds.attrs["converged"] == 1


def test_closed_form_stages_report_zero_iterations_and_residual():
    ds = railtherm.solve(EK, "green", 0)
    for model in ("hertz", "full-sliding", "green"):
        assert (ds.attrs[f"{model}_iterations"], ds.attrs[f"{model}_residual"]) == (0, 0.0)


def test_fdm_reports_its_heat_balance_with_the_contract_sign():
    """heat_balance_error = (heat carried out by the field - heat put in) / heat put in: the steady
    block's discrete balance is exact (round-off), and the key is the model's own, not only per body."""
    ds = railtherm.solve(EK, "fastsim-fdm", 0)
    assert abs(ds.attrs["fdm_heat_balance_error"]) < 1e-9
    ds = railtherm.solve(scene(LINE, mode="transient", numerics={"scheme": "explicit"}), "fastsim-fdm", 0)
    hb = ds.attrs["fdm_heat_balance_error"]
    # sign: stored + lost - put in, from the per-body energies
    w = ds.attrs["fdm_rail_energy_in"]
    out = ds.attrs["fdm_rail_energy_stored"] + ds.attrs["fdm_rail_energy_lost_fixed_faces"] \
        + ds.attrs["fdm_rail_energy_lost_convection"]
    assert ds.attrs["fdm_rail_heat_balance_error"] == pytest.approx((out - w) / w, rel=1e-9, abs=1e-15)
    assert abs(hb) < 1e-9


def test_fipy_reports_its_heat_balance():
    """FiPy's energy balance ((enthalpy out + convective loss) / heat in) as heat_balance_error = balance - 1."""
    ds = railtherm.solve(LINE, "fipy", 0)
    hb = ds.attrs["fipy_heat_balance_error"]
    assert hb == pytest.approx(ds.attrs["fipy_energy_balance_max"] - 1.0, abs=1e-12)
    assert abs(hb) < 0.05


def test_fem_coupling_cut_short_is_not_converged():
    """coupling_max_iterations = 1 with tolerance 0: the Steps 1-4 loop stops after one pass with a
    relative change of 1 (theta from 0), so the model says converged = False with its numbers, and
    railtherm.solve raises SolverError naming them (a study records the run as failed)."""
    from railtherm_fem.model import FemModel
    from railtherm.input.scene import load_scene
    opts = {"coupling_max_iterations": 1, "coupling_tolerance": 0.0}
    model = FemModel()
    sc = load_scene(FEM)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        patch, source, temp = model.compute(sc, 0, {**model.resolve_options(opts)}, ("normal", "tangential", "heat_source",
                                                                                     "temperature"), railtherm.Upstream())
    for obj in (patch, source, temp):
        d = obj.diagnostics
        assert d["converged"] is False and d["iterations"] == 1 and d["residual"] == pytest.approx(1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with pytest.raises(railtherm.SolverError, match="fem_residual=1.0"):
            railtherm.solve(FEM, "fem", 0, opts)
        ok = railtherm.solve(FEM, "fem", 0)   # default options: the loop converges
    assert ok.attrs["fem_converged"] == 1 and ok.attrs["fem_residual"] <= 1e-6
    assert ok.attrs["fem_iterations"] == ok.attrs["fem_coupling_iterations"] >= 2


def test_fdm_cg_cut_short_is_not_converged(monkeypatch):
    """An implicit step whose CG stops above its tolerance CG_RTOL (here: one iteration allowed) makes
    the FDM report converged = False, and solve raises SolverError."""
    from railtherm_fdm import block3d as fdm_solvers
    sc = scene(LINE, mode="transient", numerics={"scheme": "implicit"})
    monkeypatch.setattr(fdm_solvers._cg, "__defaults__", (fdm_solvers.CG_RTOL, 1))
    with pytest.raises(railtherm.SolverError, match="fdm_residual"):
        railtherm.solve(sc, "fastsim-fdm", 0)


# ---------------------------------------------------------------------------------------------
# 2. budgets
# ---------------------------------------------------------------------------------------------
def test_surface_grid_refuses_above_the_cell_budget():
    """Level 8 on the E&K ellipse (32 cells at level 0) is 8192 x 14684 = 1.2e8 cells: refused before
    allocating, naming the level, the cells, the budget and the finest level that fits (5)."""
    with pytest.raises(railtherm.Refused) as err:
        surface_grid(5.88e-3, 10.54e-3, 8, 32)
    assert err.value.kind == "budget"
    msg = str(err.value)
    assert "level 8" in msg and "8192 x 14684" in msg and "MAX_SURFACE_CELLS" in msg and "finest level within it is 5" in msg
    g = surface_grid(5.88e-3, 10.54e-3, 5, 32)
    assert g.x.size * g.y.size <= MAX_SURFACE_CELLS < (2 * g.x.size) * (2 * g.y.size)


@pytest.mark.parametrize("method, base", [("green", EK), ("green", GIVEN), ("fastsim-fdm", EK), ("fipy", EK)])
def test_methods_refuse_a_surface_grid_over_budget(method, base):
    with pytest.raises(railtherm.Refused, match=r"scene '\w+'.*level 8.*MAX_SURFACE_CELLS") as err:
        railtherm.solve(base, method, 8)
    assert err.value.kind == "budget"


def test_fdm_cell_budgets_are_budget_refusals():
    with pytest.raises(railtherm.Refused, match="max_cells|limit") as err:
        railtherm.solve(EK, "fastsim-fdm", 0, {"max_cells": 1000})
    assert err.value.kind == "budget"
    with pytest.raises(railtherm.Refused, match="nodes") as err:
        railtherm.solve(scene(LINE, mode="transient", numerics={"scheme": "explicit"}), "fastsim-fdm", 0,
                        {"max_nodes": 1000})
    assert err.value.kind == "budget"


# ---------------------------------------------------------------------------------------------
# 3. FEM on valid input: a solution or a refusal with the reason
# ---------------------------------------------------------------------------------------------
def test_fem_short_strip_meshes_with_a_uniform_window():
    """A strip of 0.1 m x 0.064 m under 1 MN/m raised 'window nodes are not uniformly spaced' (the
    coarse cell that absorbs the remainder of L/2 held the window): it now solves, with a Hertz-like
    patch (a within 10 % of the half-plane value 1.59 mm: the finite strip is stiffer)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ds = railtherm.solve(FEM, "fem", 0)
    a = float(ds["semi_axis_a"])
    assert 0.9 * 1.59e-3 < a < 1.59e-3 * 1.01
    assert ds.attrs["fem_converged"] == 1


@pytest.mark.parametrize("length, depth, h", [(0.1, 0.064, 1.588e-4), (0.1, 0.2, 1e-4), (0.02, 0.064, 5e-5)])
def test_graded_mesh_window_uniform_on_short_strips(length, depth, h):
    from railtherm_fem.mesh import graded_strip_mesh
    sm = graded_strip_mesh(length, depth, 12.5 * h, h, grading=8.0)
    assert np.allclose(np.diff(sm.x_window), h, rtol=1e-9)
    assert abs(sm.x_window[0] + sm.x_window[-1]) < 1e-12 and sm.x_window[-1] >= 11.5 * h


@pytest.mark.parametrize("strip, limit", [({"length": 0.1, "depth": 0.064}, "strip"),
                                          ({"length": 4.0, "depth": 1.0}, "small-strain")])
def test_fem_refuses_a_load_beyond_its_limits(strip, limit):
    """1e9 N/m: the Hertz half-width (50 mm) exceeds a quarter of a 0.1 m strip, and a/r0 = 0.109 > 0.1
    on the seed's 4 m strip: refused up front (validity), naming the limit and a load that would work."""
    import time
    t0 = time.perf_counter()
    with pytest.raises(railtherm.Refused, match=limit) as err:
        railtherm.solve(scene(FEM, normal_force=1e9, strip=strip), "fem", 0)
    assert time.perf_counter() - t0 < 2.0
    assert err.value.kind == "validity"
    assert "fem-strip" in str(err.value) and "normal_force <=" in str(err.value)


def test_fem_penetration_beyond_the_limit_is_refused():
    with pytest.raises(railtherm.Refused, match="penetration <=") as err:
        sc = scene(FEM, penetration=5e-3)
        del sc["normal_force"]
        railtherm.solve(sc, "fem", 0)
    assert err.value.kind == "validity"


def test_fem_internal_errors_become_solver_errors(monkeypatch):
    """A RuntimeError inside the FEM (mesh, factorisation) is a SolverError naming the scene."""
    import railtherm_fem.model as fm

    def broken(prob):
        raise RuntimeError("quadtree balancing did not finish")
    monkeypatch.setattr(fm, "solve_fem", broken)
    with pytest.raises(railtherm.SolverError, match="fem-strip.*quadtree"):
        railtherm.solve(FEM, "fem", 0)


# ---------------------------------------------------------------------------------------------
# 4. green: the fitted default is said to be fitted
# ---------------------------------------------------------------------------------------------
def test_green_convective_area_says_it_was_fitted_to_table_1():
    from railtherm_green.model import GreenTemperature
    doc = GreenTemperature.options["convective_area"].doc
    for words in ("FITTED", "Table 1", "Ertz & Knothe", "'tread'", "'wheel'"):
        assert words in doc, words
    assert "fitted to that table" in GreenTemperature.__doc__ and '"tread"' in GreenTemperature.__doc__


# ---------------------------------------------------------------------------------------------
# 5. declared convergence orders
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["green", "fipy", "fastsim-fdm", "fem"])
def test_methods_declare_orders(method):
    from railtherm.solving.plugins import get_host
    orders = get_host().method(method).method.orders
    assert orders, method
    assert set(orders) <= set(METRICS), set(orders) - set(METRICS)
    assert all(0.0 < float(v) <= 4.0 for v in orders.values())


def _pe_scene(pe, a=2e-3):
    kappa = STEEL["conductivity"] / (STEEL["density"] * STEEL["specific_heat"])
    return {"name": "pe", "speed": 2.0 * kappa * pe / a, "heat_partition": 0.5, "wheel": dict(STEEL),
            "rail": dict(STEEL), "heat_source": {"flux": 1e6, "shape": "uniform", "semi_axes": [a, a]},
            "outputs": ["max_surface_temperature"]}


def test_fipy_refuses_a_3d_solve_estimated_over_its_time_budget():
    """Pe 0.1 on a circle at level 1: two 3-D meshes of 224 640 cells (measured 35 s for both, 373 GMRES
    iterations); the estimate 2 x 224 640 x 400 x 5e-7 s = 90 s exceeds max_seconds = 60 s: refused
    (budget) before any mesh is solved, naming cells, Péclet number, estimate and option."""
    import time
    from railtherm_fipy.model import estimate_seconds_3d
    assert estimate_seconds_3d(224_640, 0.1, 2) == pytest.approx(89.856)
    t0 = time.perf_counter()
    with pytest.raises(railtherm.Refused, match=r"224640 cells.*estimated at 89.9 s.*max_seconds = 60") as err:
        railtherm.solve(_pe_scene(0.1), "fipy", 1, {"dimension": 3, "max_cells_low_peclet": 300_000})
    assert time.perf_counter() - t0 < 5.0
    assert err.value.kind == "budget"
    with pytest.raises(railtherm.Refused, match="max_cells") as err:   # the cell caps are budgets too
        railtherm.solve(_pe_scene(0.1), "fipy", 1, {"dimension": 3})
    assert err.value.kind == "budget"


def test_fipy_estimate_accepts_what_it_measured_fast():
    """Pe 0.01 at level 0 (70 560 cells, measured 10 s for both bodies) is estimated at 28 s, Pe 0.1 at
    level 1 on a = 1 mm (121 600 cells, ~17 s) at 49 s: accepted under the default max_seconds = 60 s."""
    from railtherm_fipy.model import FipyTemperature, estimate_seconds_3d
    limit = FipyTemperature.options["max_seconds"].default
    assert estimate_seconds_3d(70_560, 0.01, 2) < limit and estimate_seconds_3d(121_600, 0.1, 2) < limit
    assert estimate_seconds_3d(6_732, 1.0, 2) < 1.0        # LU: measured 0.22 s


def test_fipy_refuses_a_transient_with_too_many_fixed_steps():
    """A fixed time step of 1 ms over 8 lumped time constants is millions of implicit steps (35 us each
    measured): refused as a budget before the first step, naming the steps and a step that would fit."""
    import time
    sc = scene(EK, mode="transient", numerics={"time_step": 1e-3}, outputs=["steady_wheel_temperature"])
    t0 = time.perf_counter()
    with pytest.raises(railtherm.Refused, match=r"implicit steps, estimated at .* > max_seconds = 60 s; use "
                                                 r"time_step >=") as err:
        railtherm.solve(sc, "fipy", 0)
    assert time.perf_counter() - t0 < 5.0 and err.value.kind == "budget"
    ok = railtherm.solve(scene(sc, numerics={"time_step": 0.01, "duration": 20.0}), "fipy", 0)
    assert ok.attrs["fipy_transient_steps"] == 2000 and ok.attrs["fipy_converged"] == 1
