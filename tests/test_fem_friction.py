"""The FEM under friction laws: mu per contact node from the scene's law.

References and tolerances: a temperature law with no change equals constant friction (rtol 1e-12);
full sliding under the slip law gives mu(v_s) N (the elastic slip is < 1e-4 of v_s here) and every slipping
node carries mu(V |s|) p to the outer iteration's tolerance; the temperature law's fixed point is mu = law(T)
node by node with T the FEM's own contact temperature (to the loop's mu tolerance); friction opposes the slip
at every node (dissipation >= 0) and the frictional power is -V sum(tau s w); identical bodies: F(-xi) = -F(xi).
Small: level 0 (surface spacing a/10), ~1 s per solve.

Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest -q tests/test_fem_friction.py``
"""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm.contract.errors import Refused
from railtherm.input.scene import load_scene
from railtherm.physics import equal_temperature_partition
from railtherm.physics.friction import LOOP_FORCE_TOLERANCE, LOOP_MU_TOLERANCE, SLIP_MU_TOLERANCE, contact_temperature
from railtherm.references.carter import carter_normal_load
from railtherm_fem.coupled import solve_fem
from railtherm_fem.friction import node_surface_temperatures
from railtherm_fem.model import FemModel

G, NU, R, A = 82e9, 0.28, 0.5, 1e-3
MAT = {"shear_modulus": G, "poisson_ratio": NU}
N = carter_normal_load(A, R, G, NU)
V = 30.0
SLIP = {"law": "slip-velocity", "static": 0.36, "kinetic": 0.18, "decay": 0.5}
# the FEM's line contact heats by a few kelvin: a law that falls over 5 K makes the loop do real work
TEMP = {"law": "temperature", "reference": 0.3, "reference_temperature": 0.0, "change": -0.15, "over": 5.0}


def scene(friction, **kw):
    return {"name": "ff", "normal_force": N, "contact": {"shape": "line", "wheel_radius": R}, "speed": V,
            "friction": friction, "wheel": dict(MAT), "rail": dict(MAT),
            "outputs": ["creep_force_x", "max_surface_temperature", "frictional_power"], **kw}


def fem(friction, level=0, **kw):
    sc = load_scene(scene(friction, **kw))
    m = FemModel()
    return solve_fem(m._problem(
        level, m.resolve_options({}), True, wheel=sc.wheel, rail=sc.rail, speed=sc.speed,
        wheel_radius=sc.wheel_radius, normal_force=sc.normal_force, penetration=sc.penetration,
        friction=sc.friction, creepage=sc.creepage, sliding_speed=sc.sliding_speed,
        heat_partition=sc.heat_partition, convection=sc.convection, strip=sc.strip, field=sc.field,
        numerics=sc.numerics))


def mu_slip(v, law=SLIP):
    return law["kinetic"] + (law["static"] - law["kinetic"]) * np.exp(-np.abs(v) / law["decay"])


def test_fem_declares_every_law():
    assert FemModel.capabilities.friction_laws == {"constant", "slip-velocity", "polach", "temperature"}


def test_temperature_law_without_change_equals_constant_friction():
    c = {"longitudinal": -1e-3}
    a = railtherm.solve(scene(0.3, creepage=c), "fem", 0)
    b = railtherm.solve(scene({**TEMP, "change": 0.0}, creepage=c), "fem", 0)
    for v in ("creep_force_x", "max_surface_temperature", "frictional_power"):
        np.testing.assert_allclose(b[v].values, a[v].values, rtol=1e-12, atol=0)


def test_slip_law_in_full_sliding_gives_mu_of_the_sliding_speed():
    for vs in (1.0, 3.0):
        sol = fem(SLIP, sliding_speed=vs)
        c = sol.contact
        on = c.pressure > 0
        assert c.tangential_force == pytest.approx(mu_slip(vs) * c.normal_force, rel=1e-4)
        local = np.abs(c.traction[on]) / c.pressure[on] - mu_slip(V * np.abs(c.slip[on]))
        assert np.max(np.abs(local)) < SLIP_MU_TOLERANCE
        assert sol.diagnostics["friction_law"] == "slip-velocity"


def test_steep_slip_law_converges_monotonically_and_a_steeper_one_is_refused():
    steep = {**SLIP, "decay": 0.01}                       # 50x steeper than the example
    sol = fem(steep, creepage={"longitudinal": -1e-3})
    kappa = sol.diagnostics["friction_contraction"]
    hist = np.array([float(h) for h in sol.diagnostics["friction_mu_change"].split(",")])
    assert 0.1 < kappa < 1
    assert hist[-1] < SLIP_MU_TOLERANCE and np.all(np.diff(np.log(hist)) < 0)
    c = sol.contact
    on = c.pressure > 0
    slipping = on & ~c.stick
    local = np.abs(c.traction[slipping]) / c.pressure[slipping] - mu_slip(V * np.abs(c.slip[slipping]), steep)
    assert np.max(np.abs(local)) < SLIP_MU_TOLERANCE
    with pytest.raises(Refused) as err:
        fem({**SLIP, "decay": 0.1 * kappa * 0.01}, creepage={"longitudinal": -1e-3})    # kappa -> 10 kappa > 1
    assert err.value.kind == "validity" and "kappa" in str(err.value) and "decay >=" in str(err.value)


def test_temperature_law_loop_converges_to_mu_of_the_fems_own_contact_temperature():
    sol = fem(TEMP, creepage={"longitudinal": -1e-2})
    d = sol.diagnostics
    dmu = np.array([float(h) for h in d["friction_loop_mu_change"].split(",")])
    steps = [int(n) for n in d["friction_loop_coupling_iterations"].split(",")]
    assert d["friction_loop_iterations"] == dmu.size == len(steps) and sol.coupling_converged
    assert dmu[-1] < LOOP_MU_TOLERANCE and np.all(np.diff(np.log(dmu)) < 0)
    assert float(d["friction_loop_force_change"].split(",")[-1]) < LOOP_FORCE_TOLERANCE
    c = sol.contact
    T = contact_temperature(*node_surface_temperatures(c.x, sol.thermal_grid, sol.theta, 0.0, 0.0))
    law = np.clip(0.3 - 0.15 * T / 5.0, 0.15, 0.3)
    slipping = (c.pressure > 0) & ~c.stick
    assert slipping.sum() >= 5
    assert np.max(np.abs(np.abs(c.traction[slipping]) / c.pressure[slipping] - law[slipping])) < LOOP_MU_TOLERANCE
    mean_mu = float(d["friction_loop_mean_mu"].split(",")[-1])
    assert 0.15 < mean_mu < 0.3 and c.tangential_force / c.normal_force < 0.3
    # energy: friction opposes the slip at every node; the heat is the traction's power
    assert np.all(c.traction * np.nan_to_num(c.slip) <= 0)
    w = np.gradient(c.x)
    assert sol.frictional_power == pytest.approx(-V * float(np.sum(c.traction * np.nan_to_num(c.slip) * w)), rel=1e-12)


def test_the_fems_temperature_law_runs_cores_loop(monkeypatch):
    """The FEM's Steps 1-4 solve is the solve of core's temperature-friction loop: core's step limit stops it
    with core's message (a failed run, not converged), and with the limit restored the loop converges in the
    steps its history records."""
    from railtherm.contract.errors import SolverError
    from railtherm.physics.friction import temperature_loop
    monkeypatch.setattr(temperature_loop, "LOOP_MAX_ITERATIONS", 2)
    with pytest.raises(SolverError, match=r"model 'fem': the temperature-friction loop did not converge in 2 "
                                          r"iterations .*history: 1: dmu"):
        fem(TEMP, creepage={"longitudinal": -1e-2})
    monkeypatch.undo()
    assert fem(TEMP, creepage={"longitudinal": -1e-2}).diagnostics["friction_loop_iterations"] > 2


def test_slip_law_is_odd_in_the_creepage():
    """Identical bodies: F(-xi) = -F(xi), to the outer iteration's tolerance on mu (the two runs stop at
    different iterates; measured 6e-10 relative)."""
    f = [fem(SLIP, creepage={"longitudinal": x}).contact.tangential_force for x in (-1e-3, 1e-3)]
    assert f[0] > 0 > f[1] and f[0] == pytest.approx(-f[1], rel=SLIP_MU_TOLERANCE)


def test_heat_partition_keys_each_have_one_meaning_on_the_fem():
    """"equal-temperature" is Blok's fraction at the FEM's own body speeds, exactly as every other method
    computes it (physics.equal_temperature_partition, rtol 1e-15); "equal-mean-temperature" is the FEM's own
    rule: the wheel's and the rail's mean surface temperatures over the patch come out equal (to 1e-9 of the
    rise, the coupling's own tolerance is 1e-6). With a wheel 2 K warmer than the rail the two differ
    (measured 0.504 against 0.422): one key, one meaning."""
    warm = {**MAT, "bulk_temperature": 2.0}
    blok = fem(0.3, sliding_speed=1.0, heat_partition="equal-temperature", wheel=warm)
    sc = load_scene(scene(0.3, sliding_speed=1.0, wheel=warm))
    assert blok.heat_partition == pytest.approx(equal_temperature_partition(sc.wheel, sc.rail, *blok.body_speed),
                                                rel=1e-15)
    mean = fem(0.3, sliding_speed=1.0, heat_partition="equal-mean-temperature", wheel=warm)
    g = mean.thermal_grid
    on = (g.x >= mean.centre - mean.half_width) & (g.x <= mean.centre + mean.half_width)
    t_wheel, t_rail = 2.0 + mean.theta[0][on, 0].mean(), mean.theta[1][on, 0].mean()
    assert mean.coupling_converged and abs(t_wheel - t_rail) < 1e-9 * t_rail
    assert blok.heat_partition - mean.heat_partition > 0.05
