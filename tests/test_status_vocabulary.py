"""Status vocabulary (docs/verdicts.md): a solver that did not converge or broke down on valid input is
``failed`` (railtherm.SolverError, reason not-converged), never ``refused``; ``refused`` is kept for scenes
outside a model's validity or budget. Each test makes a model's solver fail and checks the exception and
how the runner records it."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import railtherm_fastsim.kinematics as kinematics
from railtherm import Material, Refused, SolverError
from railtherm.physics.friction import ConstantFriction
from railtherm.run.runner import _failure
from railtherm_fastsim.wheelset_normal import WheelsetNormal


def _wheelset_scene():
    steel = Material()
    ws = SimpleNamespace(conicity=0.15, lateral_shift=3e-3, yaw_angle=1.5e-3, vertical_load=200e3, wheel_radius=0.46,
                         gauge=1.5, contact=1)
    return SimpleNamespace(name="ws", speed=30.0, friction=ConstantFriction(0.3), creepage=None, sliding_speed=None,
                           wheelset=ws,
                           heat_partition=0.5, wheel=steel, rail=steel, contact_shape="ellipse", heat_source=None,
                           tangential="creepage", semi_axes=(5.88e-3, 10.54e-3), normal_force=100e3,
                           penetration=None, curvatures=None, wheel_radius=0.46)


def test_a_singular_wheelset_equilibrium_is_a_failed_run(monkeypatch):
    def singular(*args, **kw):
        return np.linalg.solve(np.zeros((2, 2)), np.ones(2))
    monkeypatch.setattr(kinematics, "wheelset_contact", singular)
    model = WheelsetNormal()
    with pytest.raises(SolverError, match="normal-force solve failed") as err:
        model.compute_patch(_wheelset_scene(), 0, {"cells": 16, **model.resolve_options({})})
    assert not isinstance(err.value, Refused)
    assert _failure(err.value, 60.0)[:2] == ("failed", "not-converged")


def test_a_wheelset_without_an_equilibrium_contact_stays_refused(monkeypatch):
    def no_contact(*args, **kw):
        raise ValueError("combined elastic constants: both bodies are rigid")
    monkeypatch.setattr(kinematics, "wheelset_contact", no_contact)
    model = WheelsetNormal()
    with pytest.raises(Refused) as err:
        model.compute_patch(_wheelset_scene(), 0, {"cells": 16, **model.resolve_options({})})
    assert _failure(err.value, 60.0)[:2] == ("refused", "validity")
