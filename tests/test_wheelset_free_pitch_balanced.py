"""``pitch_velocity = "free"`` with the exact chain: at the pitch velocity found, the forces of the chain's own
solves of both wheels (each wheel's normal forces meeting its vertical force with the chain's own creep forces,
:mod:`railtherm.solving.wheelset_vertical`) have no moment about the axle.

The moment is rebuilt from results alone: the free result's per-patch forces of the asked wheel and those of the
other wheel solved at the pitch velocity the free result reports (a given pitch velocity; the pipeline balances its
vertical force the same way), composed with :func:`railtherm.solving.wheelset_equilibrium.axle_moment` at each
patch's reference point. Tolerance: the pitch secant's, :data:`MOMENT_TOL` of (sum of normal forces) x (the asked
wheel's rolling radius), with a factor 10 for the last bits of two independent solves.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

import railtherm
from railtherm.input.scene import load_scene
from railtherm.solving.wheelset_equilibrium import MOMENT_TOL, NEED, axle_moment
from railtherm.solving.wheelset_vertical import VERTICAL_TOL

from manchester_cases import A22, a22_scene

FZ = A22["setup"]["vertical_force"]


def _scene(position, side, pitch_velocity):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(pitch_velocity=pitch_velocity, patch="all")
    return load_scene(dict(s, outputs=list(NEED)))


def _moment(scene, r) -> float:
    """sum over the result's patches of the moment about the axle [N m] at the scene's patch reference points."""
    return sum(axle_moment(pc, *(float(r[q].values[i]) for q in NEED))
               for i, pc in enumerate(scene.profile_contact.contacts))


def _vertical(r) -> float:
    """sum N cos(delta) - Fy sin(delta) [N] over the result's patches."""
    n, fy, d = (np.atleast_1d(r[q].values) for q in ("normal_force", "creep_force_y", "contact_angle"))
    return float(np.sum(n * np.cos(d) - fy * np.sin(d)))


@pytest.mark.parametrize("position", [14])
def test_the_free_pitch_balances_the_axle_with_the_chains_balanced_forces(position):
    """A-2.2 flange contact of the right wheel, kalker level 0: both wheels' own forces (vertical force met to
    :data:`VERTICAL_TOL`) have no moment about the axle to :data:`MOMENT_TOL`, and the result's attributes say
    both residuals."""
    free = _scene(position, "right", "free")
    r = railtherm.solve(free, "kalker", level=0)
    w = float(r.attrs["wheelset_pitch_velocity"])
    right = _scene(position, "right", w)
    left = _scene(position, "left", w)
    rl = railtherm.solve(left, "kalker", level=0)
    assert abs(_vertical(r) - FZ) <= VERTICAL_TOL * FZ
    assert abs(_vertical(rl) - FZ) <= VERTICAL_TOL * FZ
    load = (sum(c.normal_force for c in right.profile_contact.contacts)
            + sum(c.normal_force for c in left.profile_contact.contacts)) * right.profile_contact.rolling_radius
    moment = _moment(right, r) + _moment(left, rl)
    assert abs(moment) <= 10 * MOMENT_TOL * load, (moment, load)
    assert abs(float(r.attrs["wheelset_axle_moment"])) <= MOMENT_TOL * load
    assert float(r.attrs["wheelset_axle_moment"]) == pytest.approx(moment, abs=10 * MOMENT_TOL * load)
    assert abs(float(r.attrs["wheelset_vertical_force_residual"])) <= VERTICAL_TOL * FZ
    assert float(r.attrs["wheelset_vertical_force_tolerance"]) == pytest.approx(VERTICAL_TOL * FZ, rel=1e-12)
    assert float(r.attrs["wheelset_axle_moment_tolerance"]) == pytest.approx(MOMENT_TOL * load, rel=1e-9)
