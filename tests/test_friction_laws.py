"""Friction laws: the scene vocabulary, the laws' formulas, core's full-sliding model under each
law, and core's coupled temperature-friction loop (railtherm.solving.friction_loop) on the green chain.

References: the laws' own definitions (Polach 2005, doi:10.1016/j.wear.2004.03.046, eq. 6; CONTACT's
piecewise-linear temperature law); full sliding gives mu(|v_s|) N exactly; a law with no change equals
constant friction; the coupled loop's fixed point satisfies mu = law(T) cell by cell.

Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest -q tests/test_friction_laws.py``
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import railtherm
from railtherm.contract.errors import Refused, SceneError
from railtherm.input.scene import load_scene
from railtherm.physics.friction import (LOOP_FORCE_TOLERANCE, LOOP_MU_TOLERANCE, ConstantFriction, PolachFriction,
                                        SlipVelocityFriction, TemperatureFriction, friction_law)

SLIP = {"law": "slip-velocity", "static": 0.36, "kinetic": 0.18, "decay": 0.5}
TEMP = {"law": "temperature", "reference": 0.3, "reference_temperature": 0.0, "change": -0.15, "over": 400.0}
POLACH = {"law": "polach", "mu0": 0.36, "A": 0.5, "B": 2.0}

BASE = {"name": "sl", "speed": 30.0, "normal_force": 100e3,
        "contact": {"shape": "ellipse", "curvatures": [1.015, 0.4215]}, "sliding_speed": 1.0,
        "heat_partition": "equal-temperature",
        "outputs": ["max_surface_temperature", "creep_force_x", "frictional_power", "heat_flux", "surface_temperature"]}


def scene(friction, **kw):
    return {**BASE, "friction": friction, **kw}


# --- vocabulary ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("bad, key", [
    ({"law": "coulomb"}, "friction.law"),
    ({**SLIP, "kinetic": 0.0}, "friction.kinetic"),
    ({**SLIP, "static": -0.1}, "friction.static"),
    ({**SLIP, "decay": 0.0}, "friction.decay"),
    ({**TEMP, "over": 0.0}, "friction.over"),
    ({**TEMP, "over": -5.0}, "friction.over"),
    ({**TEMP, "change": -0.3}, "friction.change"),        # mu_ref + change = 0: friction would vanish
    ({**TEMP, "reference": 0.0}, "friction.reference"),
    ({**POLACH, "A": 0.0}, "friction.A"),
    ({"law": "polach", "mu0": 0.3, "A": 0.4}, "friction.B"),  # missing
    ({**SLIP, "over": 3.0}, "friction.over"),              # a key of another law
])
def test_invalid_law_parameters_are_scene_errors_naming_the_key(bad, key):
    with pytest.raises(SceneError) as err:
        load_scene(scene(bad))
    assert err.value.key == key
    assert key in str(err.value) and "'sl'" in str(err.value)


def test_scene_keeps_the_law_and_a_nominal_coefficient():
    s = load_scene(scene(SLIP))
    assert s.friction.nominal == 0.36 and s.friction == SlipVelocityFriction(0.36, 0.18, 0.5)
    assert load_scene(scene(TEMP)).friction.nominal == 0.3
    c = load_scene(scene(0.3))
    assert c.friction.nominal == 0.3 and c.friction == ConstantFriction(0.3)
    assert load_scene(scene(0.3)).hash == load_scene(scene(0.3)).hash


def test_the_scene_validator_takes_each_laws_parameters_from_the_law():
    """One declaration per law: the validator's keys, units and lower bounds are the law's Parameter list
    (in its order), the DESIGN scene table names every key with its unit, and a declared (open) lower bound
    is refused at the bound itself, naming the key."""
    from pathlib import Path

    from railtherm.input.scene import Friction
    from railtherm.physics.friction import LAWS
    design = (Path(__file__).parents[1] / "docs" / "DESIGN.md").read_text()
    row = next(line for line in design.splitlines() if line.startswith("| `friction` |"))
    valid = {"slip-velocity": SLIP, "polach": POLACH, "temperature": TEMP}
    assert set(LAWS) == set(Friction.PARAMETER_CHECKS) == set(valid)
    for kind, law in LAWS.items():
        checks = Friction.PARAMETER_CHECKS[kind]
        assert list(checks) == [p.name for p in law.PARAMETERS] == [k for k in valid[kind] if k != "law"]
        assert f'law = "{kind}", ' + ", ".join(p.label for p in law.PARAMETERS) in row
        for p in law.PARAMETERS:
            assert (checks[p.name].unit, checks[p.name].lo, checks[p.name].lo_open) == (p.unit, p.lower, p.lower_open)
            if p.lower > -math.inf:
                assert p.lower_open
                with pytest.raises(SceneError) as err:
                    load_scene(scene({**valid[kind], p.name: p.lower}))
                assert err.value.key == f"friction.{p.name}"
        assert friction_law(valid[kind]).kind == kind


# --- the laws -------------------------------------------------------------------------------------------

def test_slip_velocity_law_is_the_exponential():
    law = friction_law(SLIP)
    v = np.array([0.0, 0.5, 1.0, 10.0])
    assert np.allclose(law.mu(v), 0.18 + 0.18 * np.exp(-v / 0.5), rtol=0, atol=1e-15)
    assert law.mu(0.0) == 0.36 and law.mu(-1.0) == law.mu(1.0)          # the slip speed is a magnitude
    h = 1e-6
    assert law.dmu_dslip(0.7) == pytest.approx((law.mu(0.7 + h) - law.mu(0.7 - h)) / (2 * h), rel=1e-7)


def test_polach_law_is_polachs_eq_6():
    law = friction_law(POLACH)
    assert isinstance(law, PolachFriction)
    w = np.linspace(0, 5, 11)
    assert np.allclose(law.mu(w), 0.36 * ((1 - 0.5) * np.exp(-2.0 * w) + 0.5), rtol=0, atol=1e-15)


def test_temperature_law_is_piecewise_linear():
    law = friction_law(TEMP)
    assert isinstance(law, TemperatureFriction)
    t = np.array([-50.0, 0.0, 100.0, 200.0, 400.0, 900.0])
    assert np.allclose(law.mu(0.0, t), [0.3, 0.3, 0.2625, 0.225, 0.15, 0.15], rtol=0, atol=1e-15)
    assert law.bounds == (0.15, 0.3)


# --- full sliding under each law -------------------------------------------------------------------------

def test_slip_law_in_full_sliding_gives_mu_of_the_sliding_speed_times_n():
    for vs in (0.2, 1.0, 3.0):
        ds = railtherm.solve(scene(SLIP, sliding_speed=vs, outputs=["creep_force_x", "frictional_power"]),
                             "green", level=1)
        mu = 0.18 + 0.18 * math.exp(-vs / 0.5)
        assert float(ds.creep_force_x) == pytest.approx(mu * 100e3, rel=1e-12)
        assert float(ds.frictional_power) == pytest.approx(mu * 100e3 * vs, rel=1e-12)   # energy balance


def test_polach_in_full_sliding_is_verified_against_the_closed_form():
    ds = railtherm.solve(scene(POLACH, outputs=["creep_force_x", "max_surface_temperature"]), "green", level=1)
    mu = 0.36 * (0.5 * math.exp(-2.0) + 0.5)
    assert float(ds.creep_force_x) == pytest.approx(mu * 100e3, rel=1e-12)


def test_temperature_law_without_change_equals_constant_friction():
    const = railtherm.solve(scene(0.3), "green", level=1)
    flat = railtherm.solve(scene({**TEMP, "change": 0.0}), "green", level=1)
    for v in ("creep_force_x", "frictional_power", "max_surface_temperature", "heat_flux", "surface_temperature"):
        np.testing.assert_allclose(flat[v].values, const[v].values, rtol=1e-12, atol=1e-9)


def test_sign_of_the_sliding_direction_only_reverses_the_force():
    ds = railtherm.solve(scene(TEMP), "green", level=1)
    back = railtherm.solve(scene(TEMP, sliding_speed=1.0, speed=30.0), "green", level=1)
    assert float(back.creep_force_x) == float(ds.creep_force_x)
    # core's full sliding: v_s >= 0 by the vocabulary; the traction opposes the slip
    assert float(ds.creep_force_x) > 0


# --- the coupled loop ------------------------------------------------------------------------------------

def _loop(ds):
    return {k.split("friction_loop_")[1]: v for k, v in ds.attrs.items() if "friction_loop_" in k}


def test_coupled_loop_converges_as_a_contraction_and_its_history_is_recorded():
    ds = railtherm.solve(scene(TEMP), "green", level=1)
    h = _loop(ds)
    n = int(h["iterations"])
    assert 2 <= n <= 8
    dmu = np.asarray(h["mu_change"])
    assert dmu[-1] < LOOP_MU_TOLERANCE and np.asarray(h["force_change"])[-1] < LOOP_FORCE_TOLERANCE
    assert np.all(np.diff(np.log(dmu[dmu > 0])) < 0)           # each step shrinks the residual (contraction)
    # hotter -> less friction: the converged mean mu lies between the law's bounds and below mu_ref
    assert 0.15 < h["mean_mu"][-1] < 0.3


def test_coupled_loop_fixed_point_satisfies_the_law_cell_by_cell():
    """Independent check of the converged state: the traction is mu(T) p with T the contact temperature the
    temperature model gives for that very traction, to the loop's tolerance."""
    sc = load_scene(scene(TEMP, outputs=["traction_x", "surface_temperature", "frictional_power", "creep_force_x",
                                         "pressure"]))
    ds = railtherm.solve(sc, "green", level=1)
    p = ds.pressure.values
    inside = p > 0
    t_contact = 0.5 * (ds.surface_temperature.sel(body="wheel").values + ds.surface_temperature.sel(body="rail").values)
    mu_used = ds.traction_x.values[inside] / p[inside]
    mu_law = friction_law(TEMP).mu(0.0, t_contact[inside])
    assert np.max(np.abs(mu_used - mu_law)) < 2 * LOOP_MU_TOLERANCE
    # energy balance: the heat is the traction's power, mu(T) p |v_s| integrated
    assert float(ds.frictional_power) == pytest.approx(float(ds.creep_force_x) * 1.0, rel=1e-12)


def test_loop_refuses_a_chain_without_a_temperature_model():
    with pytest.raises(Refused, match="depends on the surface temperature"):
        railtherm.solve(scene(TEMP, outputs=["creep_force_x"]), {"normal": "hertz", "tangential": "full-sliding"})


def test_temperature_friction_has_no_closed_form_reference():
    from railtherm.analysis.analytic import uniform_friction

    def mu(sc):
        return uniform_friction(sc.friction, sc.tangential, sc.sliding_speed)
    assert mu(load_scene(scene(TEMP))) is None
    assert mu(load_scene(scene(SLIP, sliding_speed=0.5))) == pytest.approx(0.18 + 0.18 * math.exp(-1))
    assert mu(load_scene(scene(0.25))) == 0.25


def test_slip_law_iteration_past_its_step_limit_raises_solver_error_and_too_steep_refuses():
    """core's outer iteration (shared by kalker and the FEM): a contraction kappa < 1 that has not met the
    tolerance after max_outer steps did not converge (SolverError: a failed run); kappa >= 1 is outside the
    law's validity (Refused, kind validity)."""
    from railtherm.contract.errors import SolverError
    from railtherm.physics.friction import iterate_slip_law
    law = SlipVelocityFriction(static=0.36, kinetic=0.18, decay=0.5)
    inside = np.ones(3, dtype=bool)

    def slip(mu):          # a linear slip response: v = 10 (0.4 - mu) m/s per cell, mu of the last solve
        return 10.0 * (0.4 - np.asarray(mu))

    def run(kappa, max_outer):
        return iterate_slip_law(law, lambda mu, prev: mu, slip, (3,), lambda sol: (kappa, inside), model="m",
                                speed=30.0, max_outer=max_outer)

    sol, mu, history, _ = run(0.5, 60)            # converges: mu reproduces the law within the tolerance
    assert history[-1] < 1e-5 and np.allclose(mu, law.mu(slip(mu)), atol=1e-5)
    with pytest.raises(SolverError, match="did not converge in 2 steps") as err:
        run(0.5, 2)
    assert not isinstance(err.value, Refused)
    with pytest.raises(Refused, match="falls too steeply") as err:
        run(1.5, 60)
    assert err.value.kind == "validity"
