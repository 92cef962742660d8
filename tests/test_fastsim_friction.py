"""FASTSIM under friction laws: mu cell by cell from the scene's law.

References and tolerances:

* constant law: the model's fields equal a direct call of :func:`fastsim` with the float mu bit for bit
  (and the previous release's code, checked when the change was made: 168 grids/options, 0 differences);
* a temperature law with no change equals constant friction (rtol 1e-12);
* the local equation of a slipping cell, g = mu(keff (|h| - g)) p, against a brute-force root count on a
  fine grid of g (exact number of roots; the root to 1e-12 relative);
* full slip: every traction sits on its bound mu(|v|) p with v the cell's own slip speed (1e-12), and the
  force tends to mu(V |xi|) N (the slip becomes uniform) with an error that falls with |xi|;
* reversing every creepage reverses every force exactly (the sweep is odd in the creepages);
* energy balance: frictional power = -integral of traction . slip velocity (rtol 1e-12), every law;
* core's coupled temperature loop on the green chain (hertz -> fastsim -> frictional -> green) converges
  to its tolerances at 30 and 90 m/s and its fixed point satisfies mu = law(T) cell by cell.

Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest -q tests/test_fastsim_friction.py``
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import railtherm
from railtherm.contract.errors import Refused
from railtherm.physics.friction import LOOP_FORCE_TOLERANCE, LOOP_MU_TOLERANCE
from railtherm_fastsim.fastsim_kernel import slip_law_bound

SLIP = {"law": "slip-velocity", "static": 0.36, "kinetic": 0.18, "decay": 0.5}
POLACH = {"law": "polach", "mu0": 0.36, "A": 0.5, "B": 2.0}          # the same exponential as SLIP
TEMP = {"law": "temperature", "reference": 0.3, "reference_temperature": 0.0, "change": -0.15, "over": 400.0}
N = 100e3
BASE = {"name": "ff", "speed": 30.0, "normal_force": N, "contact": {"shape": "ellipse", "curvatures": [1.015, 0.4215]},
        "heat_partition": "equal-temperature"}
FIELDS = ("creep_force_x", "creep_force_y", "spin_moment", "traction_x", "traction_y", "slip_velocity_x",
          "slip_velocity_y", "frictional_power", "pressure", "stick")


def solve(friction, creepage, outputs=FIELDS, level=0, **kw):
    sc = {**BASE, "friction": friction, "creepage": creepage, "outputs": list(outputs), **kw}
    return railtherm.solve(sc, "green", level=level)


def mu_slip(v, law=SLIP):
    return law["kinetic"] + (law["static"] - law["kinetic"]) * np.exp(-np.abs(v) / law["decay"])


# --- constant law: today's results ------------------------------------------------------------------------

def _model_patch(friction, creep, temperature=None, level=1):
    """The scene, a Hertz patch (cell-averaged pressure, as core's Hertz model gives it) and FASTSIM's result."""
    from railtherm import ContactPatch, surface_grid
    from railtherm.input.scene import load_scene
    from railtherm.physics import cell_average
    from railtherm_fastsim.tangential import FastsimTangential
    sc = load_scene({**BASE, "friction": friction, "creepage": creep, "outputs": ["creep_force_x"]})
    a, b = 5.88e-3, 10.54e-3
    p0 = 1.5 * N / (math.pi * a * b)
    grid = surface_grid(a, b, level)
    patch = ContactPatch(grid=grid, normal_force=N, a=a, b=b, max_pressure=p0,
                         pressure=p0 * cell_average(grid, "hertz", a, b))
    if temperature is not None:
        patch = dataclasses.replace(patch, contact_temperature=temperature(grid))
    model = FastsimTangential()
    return sc, patch, model.compute_tangential(sc, patch, level, model.resolve_options({}))


@pytest.mark.parametrize("creep", [{"longitudinal": -1e-3}, {"longitudinal": -2e-3, "lateral": 1e-3, "spin": 0.3},
                                   {"longitudinal": -0.05}])
def test_constant_law_is_the_float_path_bit_for_bit(creep):
    """The model with ``friction = 0.3`` equals fastsim() called with the float mu."""
    from railtherm import combined_elastic
    from railtherm_fastsim.simplified_theory import fastsim
    sc, patch, pt = _model_patch(0.3, creep)
    G, nu = combined_elastic(sc.wheel, sc.rail)
    r = fastsim(patch.grid, patch.pressure, a=patch.a, b=patch.b, normal_force=N, friction=0.3, shear_modulus=G,
                poisson_ratio=nu, xi=creep.get("longitudinal", 0.0), eta=creep.get("lateral", 0.0),
                phi=creep.get("spin", 0.0), speed=30.0)
    for f in ("traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y"):
        assert np.array_equal(np.asarray(getattr(pt, f)), getattr(r, f))
    assert pt.creep_force_x == r.creep_force_x and pt.creep_force_y == r.creep_force_y


def test_temperature_law_is_mu_of_the_contact_temperature_cell_by_cell():
    """A patch carrying a contact temperature that varies across the patch: every slipping cell's traction
    is law(T) p (the bound), and reversing every creepage reverses every force exactly."""
    def hot(grid):
        X, Y = grid.mesh()
        return 300.0 * (1.0 - X / grid.a) + 50.0 * Y / grid.b            # 0 .. 650 degC
    creep = {"longitudinal": -0.02, "lateral": 0.01, "spin": 0.5}
    _, patch, pt = _model_patch(TEMP, creep, hot)
    T = hot(patch.grid)
    mu = np.clip(0.3 - 0.15 * T / 400.0, 0.15, 0.3)
    st = np.asarray(pt.stick)
    slip = st == 0
    from railtherm_fastsim.simplified_theory import ellipse_cell_integrals
    frac, _ = ellipse_cell_integrals(patch.grid, patch.a, patch.b)
    t = np.hypot(pt.traction_x, pt.traction_y)
    np.testing.assert_allclose(t[slip], mu[slip] * np.asarray(patch.pressure)[slip], rtol=1e-12)
    assert np.all(frac[slip] > 0)
    _, _, back = _model_patch(TEMP, {k: -v for k, v in creep.items()}, hot)
    assert (back.creep_force_x, back.creep_force_y, back.spin_moment) == \
        (-pt.creep_force_x, -pt.creep_force_y, -pt.spin_moment)


def test_temperature_law_without_change_equals_constant_friction():
    c = {"longitudinal": -2e-3, "lateral": 5e-4, "spin": 0.2}
    out = FIELDS + ("max_surface_temperature",)
    a = solve(0.3, c, out)
    b = solve({**TEMP, "change": 0.0}, c, out)
    for v in out:
        np.testing.assert_allclose(b[v].values, a[v].values, rtol=1e-12, atol=1e-9)


def test_polach_equals_the_same_exponential_slip_law():
    a = solve(SLIP, {"longitudinal": -0.05})
    b = solve(POLACH, {"longitudinal": -0.05})
    for v in FIELDS:
        np.testing.assert_array_equal(a[v].values, b[v].values)


# --- the local equation ----------------------------------------------------------------------------------

def _roots(habs, pc, keff, kin=0.18, dmu=0.18, decay=0.5, n=400001):
    """Brute force: sign changes of F(g) = g - pc mu(keff (|h| - g)) on g in [kin pc, min(|h|, (kin+dmu) pc)]."""
    g = np.linspace(kin * pc, min(habs, (kin + dmu) * pc), n)
    F = g - pc * (kin + dmu * np.exp(-keff * (habs - g) / decay))
    return g[:-1][np.sign(F[:-1]) != np.sign(F[1:])]


@pytest.mark.parametrize("kappa", [0.5, 0.99, 3.0, 30.0])
def test_a_cell_that_cannot_stick_has_one_root_and_the_kernel_finds_it(kappa):
    """|h| > mu_st p: F is concave, negative at mu_kin p, positive at mu_st p: exactly one root, whatever kappa."""
    pc = 1e9
    keff = kappa * 0.5 / (0.18 * pc)
    habs = 0.4 * pc
    roots = _roots(habs, pc, keff)
    assert roots.size == 1
    g, it, flag, kap = slip_law_bound(habs, pc, keff, 0.18, 0.18, 0.5)
    assert flag == 0 and kap == pytest.approx(kappa, rel=1e-12) and it <= 20
    assert g == pytest.approx(roots[0], abs=2 * (0.18 * pc) / 400000)
    assert abs(g - pc * mu_slip(keff * (habs - g))) <= 1e-12 * pc           # the law, to round-off


@pytest.mark.parametrize("kappa, habs_rel, expect", [(0.9, 0.3599, 1), (3.0, 0.2, 1), (3.0, 0.35, 2), (1.2, 0.3599, 2)])
def test_a_cell_that_can_stick_sticks_and_is_flagged_exactly_when_it_also_has_slip_roots(kappa, habs_rel, expect):
    """|h| <= mu_st p: stick is a solution (taken: static friction holds); two more (slip) roots exist iff
    kappa > 1 and F(g*) >= 0, and only then is the cell flagged (flag 2)."""
    pc = 1e9
    keff = kappa * 0.5 / (0.18 * pc)
    habs = habs_rel * pc
    _, _, flag, _ = slip_law_bound(habs, pc, keff, 0.18, 0.18, 0.5)
    assert flag == expect
    assert _roots(habs, pc, keff).size == (2 if expect == 2 else 0)


# --- full slip ----------------------------------------------------------------------------------------

def test_full_slip_tends_to_mu_of_the_rigid_slip_speed():
    """Each slipping cell's traction is mu(|v|) p with its own slip speed; the force is their integral and tends
    to mu(V |xi|) N as the slip becomes uniform (the elastic part V L dg/dx stays bounded while V |xi| grows)."""
    errs = []
    for xi in (-0.05, -0.1, -0.2):
        ds = solve(SLIP, {"longitudinal": xi}, level=1)
        p, t, s, st = (ds[v].values for v in ("pressure", "traction_x", "slip_velocity_x", "stick"))
        slip = st == 0
        assert np.max(np.abs(np.abs(t[slip]) - mu_slip(s[slip]) * p[slip])) <= 1e-12 * p.max()
        area = np.prod([float(np.diff(ds[c].values[:2])[0]) for c in ("x", "y")])
        assert float(ds.creep_force_x) == pytest.approx(float(t.sum()) * area, rel=1e-12)
        ref = mu_slip(30.0 * abs(xi)) * N
        errs.append(abs(abs(float(ds.creep_force_x)) - ref) / ref)
    assert errs[1] < 2e-3 and errs[2] < errs[1] < errs[0]


# --- the slip law where it falls steeply, and the refusal ----------------------------------------------

def test_steep_law_converges_and_cells_that_could_stick_or_slip_stick():
    """decay 0.05 m/s: in full slip every cell's root is unique; in partial slip some cells could stick or slip
    (kappa > 1): they stick (static friction holds, the solution of least slip) and are counted, never refused."""
    steep = {**SLIP, "decay": 0.05}                        # 10x steeper than the example
    ds = solve(steep, {"longitudinal": -0.05}, level=0)
    kappa = float(ds.attrs["fastsim_friction_contraction"])
    assert kappa > 1                                       # steeper than the traction can follow near v = 0 ...
    assert int(ds.attrs["fastsim_friction_nonunique_cells"]) == 0   # ... but every cell's root is unique
    assert int(ds.attrs["fastsim_friction_iterations"]) <= 30
    p, t, s, st = (ds[v].values for v in ("pressure", "traction_x", "slip_velocity_x", "stick"))
    slip = st == 0
    assert np.max(np.abs(np.abs(t[slip]) - mu_slip(s[slip], steep) * p[slip])) <= 1e-12 * p.max()
    ds = solve(steep, {"longitudinal": -4e-3}, level=0)
    assert int(ds.attrs["fastsim_friction_nonunique_cells"]) > 0
    assert float(ds.attrs["fastsim_friction_nonunique_kappa"]) > 1
    p, t, s, st = (ds[v].values for v in ("pressure", "traction_x", "slip_velocity_x", "stick"))
    stuck = st == 1
    assert stuck.any() and np.all(np.abs(t[stuck]) <= 0.36 * p[stuck] * (1 + 1e-12))   # within static friction
    assert np.all(s[stuck] == 0)


def test_a_law_with_kappa_below_one_everywhere_has_a_unique_solution():
    """decay chosen so that kappa_max < 1 on level 0: unique at every creepage (F monotone in every cell)."""
    gentle = {**SLIP, "decay": 0.7}
    for xi in (-5e-4, -2e-3, -4e-3, -8e-3, -3.2e-2):
        ds = solve(gentle, {"longitudinal": xi}, level=0)
        assert float(ds.attrs["fastsim_friction_contraction"]) < 1
        assert int(ds.attrs["fastsim_friction_nonunique_cells"]) == 0


# --- symmetry, creep curve, energy ---------------------------------------------------------------------

@pytest.mark.parametrize("law", [0.3, SLIP, POLACH])
def test_reversing_every_creepage_reverses_every_force(law):
    """Exact for laws of the slip speed. (A temperature law through the chain is not exactly odd: the wheel's
    surface speed V (1 - xi) changes with the sign of xi, and with it the temperature; the tangential model
    itself is, see test_temperature_law_is_mu_of_the_contact_temperature_cell_by_cell.)"""
    c = {"longitudinal": -0.02, "lateral": 0.01, "spin": 0.5}
    out = ("creep_force_x", "creep_force_y", "spin_moment", "frictional_power")
    a = solve(law, c, out)
    b = solve(law, {k: -v for k, v in c.items()}, out)
    for v in out[:3]:
        assert float(b[v]) == -float(a[v])
    assert float(b.frictional_power) == float(a.frictional_power)


@pytest.mark.parametrize("law, speed, level", [(SLIP, 30.0, 0), (TEMP, 90.0, 1)])
def test_creep_curve_with_falling_friction_has_a_maximum_and_falls_after_it(law, speed, level):
    xis = [5e-4, 1e-3, 2e-3, 4e-3, 8e-3, 1.6e-2, 3.2e-2, 6.4e-2, 1.28e-1]
    f = np.array([abs(float(solve(law, {"longitudinal": -x}, ("creep_force_x",), level=level, speed=speed)
                               .creep_force_x)) / N for x in xis])
    k = int(np.argmax(f))
    assert 0 < k < len(xis) - 1                            # an interior maximum ...
    assert np.all(np.diff(f[k:]) < 0) and np.all(np.diff(f[:k + 1]) > 0)    # ... falling after it
    # the peak lies where the constant-friction curve saturates (xi ~ 3 mu N / (G c^2 C11) ~ 4e-3 .. 1.6e-2)
    assert 2e-3 <= xis[k] <= 1.6e-2
    assert f[k] < (0.36 if law is SLIP else 0.3)
    if law is SLIP:                                         # the tail tends to mu(V |xi|)
        assert f[-1] == pytest.approx(mu_slip(speed * xis[-1]), rel=3e-3)


@pytest.mark.parametrize("law", [0.3, SLIP, POLACH, TEMP])
def test_energy_balance_frictional_power_is_minus_traction_dot_slip(law):
    ds = solve(law, {"longitudinal": -0.05, "lateral": 2e-3, "spin": 0.3}, level=0)
    area = np.prod([float(np.diff(ds[c].values[:2])[0]) for c in ("x", "y")])
    power = -float(np.sum(ds.traction_x.values * ds.slip_velocity_x.values
                          + ds.traction_y.values * ds.slip_velocity_y.values)) * area
    assert power > 0
    assert float(ds.frictional_power) == pytest.approx(power, rel=1e-12)


# --- core's coupled temperature loop on the green chain ------------------------------------------------

@pytest.mark.parametrize("speed", [30.0, 90.0])
def test_coupled_temperature_loop_converges_and_its_fixed_point_is_the_law(speed):
    out = ("creep_force_x", "traction_x", "pressure", "stick", "surface_temperature")
    ds = solve(TEMP, {"longitudinal": -0.1}, out, level=1, speed=speed)
    h = {k.split("friction_loop_")[1]: v for k, v in ds.attrs.items() if "friction_loop_" in k}
    n = int(h["iterations"])
    dmu, df = np.asarray(h["mu_change"]), np.asarray(h["force_change"])
    assert 2 <= n <= 10 and dmu.size == n
    assert dmu[-1] < LOOP_MU_TOLERANCE and df[-1] < LOOP_FORCE_TOLERANCE
    assert np.all(np.diff(np.log(dmu)) < 0)                # each step shrinks the residual
    p, t, st = ds.pressure.values, ds.traction_x.values, ds.stick.values
    T = 0.5 * (ds.surface_temperature.sel(body="wheel").values + ds.surface_temperature.sel(body="rail").values)
    slip = (st == 0) & (p > 0)
    law_mu = np.clip(0.3 - 0.15 * T[slip] / 400.0, 0.15, 0.3)
    assert np.max(np.abs(np.abs(t[slip]) / p[slip] - law_mu)) < 2 * LOOP_MU_TOLERANCE
    mu_mean = float(np.asarray(h["mean_mu"])[-1])
    assert 0.15 < mu_mean < 0.3 and abs(float(ds.creep_force_x)) / N < 0.3


# --- line contacts (one strip: the sweep runs whenever mu varies) ------------------------------------------

def test_line_contact_applies_the_laws_in_the_sweep():
    from railtherm import surface_grid
    from railtherm.physics.friction import friction_law
    from railtherm_fastsim.fastsim_line import fastsim_line
    a, n_line = 1e-3, 1e6
    grid = surface_grid(a, None, 0, 64)
    p0 = 2 * n_line / (math.pi * a)
    lo, hi = np.clip(grid.x_edges[:-1], -a, a), np.clip(grid.x_edges[1:], -a, a)
    anti = lambda u: 0.5 * (u * np.sqrt(1 - u * u) + np.arcsin(u))    # noqa: E731
    p = p0 * a * (anti(hi / a) - anti(lo / a)) / grid.dx                  # cell averages of the Hertz pressure
    kw = dict(a=a, normal_force=n_line, shear_modulus=82e9, poisson_ratio=0.28, xi=-0.05, speed=30.0)
    r = fastsim_line(grid, p, friction=0.3, slip_law=friction_law(SLIP), **kw)
    slip = r.stick == 0
    assert r.diagnostics["integration"] == "sweep" and slip.sum() > 50
    np.testing.assert_allclose(np.abs(r.traction_x[slip]), mu_slip(r.slip_velocity_x[slip]) * p[slip], rtol=1e-12)
    mu = np.linspace(0.3, 0.2, p.size)                                    # a temperature law's mu per cell
    r = fastsim_line(grid, p, friction=mu, **kw)
    slip = r.stick == 0
    np.testing.assert_allclose(np.abs(r.traction_x[slip]), mu[slip] * p[slip], rtol=1e-12)


def test_the_wheelset_equilibrium_refuses_a_friction_law():
    """The section 6.1 equilibrium runs FASTSIM with one coefficient: a law would make it inconsistent with the
    tangential stage, so the normal model refuses it, naming the law and what works instead."""
    sc = {"name": "ws", "speed": 30.0, "contact": {"shape": "ellipse", "curvatures": [1.015, 0.4215]},
          "wheelset": {"conicity": 0.15, "lateral_shift": 3e-3, "yaw_angle": 1.5e-3, "vertical_load": 200e3},
          "friction": SLIP, "outputs": ["creep_force_x"]}
    with pytest.raises(Refused, match=r"'wheelset'.*slip-velocity.*prescribe the creepages"):
        railtherm.solve(sc, {"normal": "wheelset", "tangential": "fastsim"}, level=0)
