"""Wheelset kinematics of plugin "fastsim" (seed 6.1): creepages and normal forces of both contacts.

Checks: the equilibrium equations hold at convergence (vertical force, roll moment, axle moment),
the classical linear results (centred symmetric wheelset: no longitudinal creepage, equal loads;
lateral shift y: xi_1,2 = -/+ gamma y / r0 to first order; yaw psi: eta = -psi / cos(delta)), and the
model's use of the kinematics when a scene gives a wheelset instead of creepages. Run:
``PYTHONPATH=core:plugins python -m pytest tests/test_fastsim_kinematics.py -q``.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from railtherm import ContactPatch, Material
from railtherm.physics.friction import ConstantFriction
import railtherm_fastsim.wheelset_normal as wheelset_normal
from railtherm.models.sliding import FrictionalHeat
from railtherm_fastsim.tangential import FastsimTangential
from railtherm_fastsim.wheelset_normal import WheelsetNormal
from railtherm.physics import hertz_pressure_grid, rescale_hertz_patch
from railtherm.physics.partition import HeatPartition
from railtherm_fastsim.kinematics import PRESSURE_GAUSS, wheelset_contacts

BASE = dict(conicity=0.05, lateral_shift=0.0, yaw_angle=0.0, vertical_load=200e3, wheel_radius=0.46, gauge=1.5,
            speed=30.0, friction=0.3, shear_modulus=82e9, poisson_ratio=0.28, ref_normal_force=100e3,
            ref_semi_axes=(5.88e-3, 10.54e-3))


def solve(**changes):
    kw = dict(BASE)
    kw.update(changes)
    return wheelset_contacts(**kw)


def test_centred_wheelset_is_symmetric():
    s = solve()
    assert s.converged and s.iterations <= 5
    delta = math.atan(BASE["conicity"])
    assert s.normal_force[0] == pytest.approx(s.normal_force[1], rel=1e-12)
    assert abs(s.theta) < 1e-12 and np.all(np.abs(s.xi) < 1e-12)
    assert s.phi[0] == pytest.approx(math.sin(delta) / 0.46) and s.phi[1] == pytest.approx(-s.phi[0])
    # opposite spins give opposite lateral forces: vertical balance with the lateral forces' share
    fz = s.normal_force * math.cos(delta) + s.creep_force_y * np.sin([delta, -delta])
    assert fz.sum() == pytest.approx(BASE["vertical_load"], rel=1e-12)


@pytest.mark.parametrize("y", [1e-3, 3e-3, -2e-3])
def test_lateral_shift_gives_rolling_radius_difference_creepage(y):
    s = solve(lateral_shift=y)
    lin = BASE["conicity"] * y / BASE["wheel_radius"]
    assert s.xi[0] == pytest.approx(-lin, rel=2e-3) and s.xi[1] == pytest.approx(lin, rel=2e-3)
    assert s.creep_force_x[0] * s.radii[0] + s.creep_force_x[1] * s.radii[1] == pytest.approx(0.0, abs=1e-6)


def test_yaw_gives_lateral_creepage_and_load_transfer():
    psi = 2e-3
    s = solve(yaw_angle=psi)
    delta = math.atan(BASE["conicity"])
    assert s.eta == pytest.approx(np.full(2, -psi / math.cos(delta)))
    assert s.normal_force[0] != pytest.approx(s.normal_force[1], rel=1e-3)      # roll moment of Fy r


@pytest.mark.parametrize("changes", [{}, {"lateral_shift": 3e-3}, {"yaw_angle": 2e-3},
                                     {"lateral_shift": 3e-3, "yaw_angle": -1e-3}])
def test_equilibrium_residuals_vanish(changes):
    s = solve(**changes)
    assert s.converged
    assert all(abs(v) < 1e-9 for v in s.residuals.values())


def test_patch_scaling():
    a, b, p0 = rescale_hertz_patch(800.0, 100.0, 2e-3, 3e-3, "curvatures")
    assert (a, b) == (pytest.approx(4e-3), pytest.approx(6e-3))
    g, p = hertz_pressure_grid(a, b, p0, 0, 32, gauss=PRESSURE_GAUSS)
    assert g.integrate(p) == pytest.approx(800.0, rel=1e-4)
    assert rescale_hertz_patch(800.0, 100.0, 2e-3, 3e-3, "semi_axes")[:2] == (2e-3, 3e-3)


def test_model_uses_the_kinematics_for_a_wheelset_scene(monkeypatch):
    """Normal model "wheelset" finds the contact's normal force and creepages; FASTSIM (tangential)
    then uses the patch's creepages; neither changes the other's result."""
    steel = Material()
    ws = SimpleNamespace(conicity=0.05, lateral_shift=3e-3, yaw_angle=1e-3, vertical_load=200e3,
                         wheel_radius=0.46, gauge=1.5)
    scene = SimpleNamespace(name="ws", speed=30.0, friction=ConstantFriction(0.3), creepage=None, sliding_speed=None, wheelset=ws,
                            heat_partition=0.5, wheel=steel, rail=steel, contact_shape="ellipse", heat_source=None,
                            tangential="creepage", semi_axes=None, normal_force=100e3, penetration=None,
                            curvatures=None, wheel_radius=0.46, partition=HeatPartition.of(0.5))
    a, b, p0 = rescale_hertz_patch(100e3, 100e3, 5.88e-3, 10.54e-3)
    g, p = hertz_pressure_grid(a, b, p0, 0, 16, gauss=PRESSURE_GAUSS)
    ref = ContactPatch(grid=g, normal_force=100e3, a=a, b=b, max_pressure=p0, pressure=p)
    monkeypatch.setattr(wheelset_normal, "hertz_geometry", lambda *args, **kw: (a, b, p0, 100e3))
    monkeypatch.setattr(wheelset_normal, "hertz_patch", lambda *args, **kw: ref)
    model = WheelsetNormal()
    patch = model.compute_patch(scene, 0, {"cells": 16, **model.resolve_options({})})
    sol = wheelset_contacts(**{**BASE, "lateral_shift": 3e-3, "yaw_angle": 1e-3})
    assert patch.diagnostics["converged"] and patch.normal_force == pytest.approx(sol.normal_force[0], rel=1e-9)
    assert patch.creepage == pytest.approx((sol.xi[0], sol.eta[0], sol.phi[0]), rel=1e-9)
    assert patch.a == pytest.approx(5.88e-3 * (sol.normal_force[0] / 100e3) ** (1 / 3))
    tang = FastsimTangential()
    pt = tang.compute_tangential(scene, patch, 0, tang.resolve_options({}))
    d = pt.diagnostics
    assert d["creepage_longitudinal"] == pytest.approx(sol.xi[0], rel=1e-9)
    assert d["creepage_lateral"] == pytest.approx(sol.eta[0]) and d["creepage_spin"] == pytest.approx(sol.phi[0])
    assert pt.creep_force_x == pytest.approx(sol.creep_force_x[0], rel=1e-6)
    assert pt.pressure is patch.pressure and pt.normal_force == patch.normal_force
    src = FrictionalHeat().compute_source(scene, pt, 0, {})
    assert src.body_speed == (pytest.approx(30.0 * (1 - sol.xi[0])), 30.0)
