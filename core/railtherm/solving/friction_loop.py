"""Core's coupled loop for friction that falls with temperature, on a chain's stages: tangential -> heat
source -> temperature -> contact temperature -> friction.

:func:`solve_coupled` runs the chain's own stage models (its temperature model: green by default in the
methods that have it, or any other) as the solve of the one temperature-friction loop,
:func:`railtherm.physics.friction.iterate_temperature_law` (Anderson mixing, stopping rule, step limit):
the tangential model solves with the contact temperature on the patch (first: that of the bulk
temperatures), core's heat source and the chain's temperature model give the surface temperatures and
they the contact temperature of each cell (:func:`railtherm.physics.friction.field_contact_temperature`).

The iteration history goes into the diagnostics: ``friction_loop_iterations``, ``friction_loop_mu_change``
(per iteration, [1]), ``friction_loop_force_change`` (per iteration, [1] relative to mu_ref N; NaN at the
first, which has nothing to compare with), ``friction_loop_mean_mu`` and
``friction_loop_max_contact_temperature`` [degC].
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..physics.friction import LoopStep, contact_temperature, field_contact_temperature, iterate_temperature_law

__all__ = ["needs_loop", "solve_coupled"]


def needs_loop(law, heat_source) -> bool:
    """Whether the friction depends on the temperature and the scene computes its traction.

    Parameters
    ----------
    law : railtherm.physics.friction.FrictionLaw or None
        The scene's friction law.
    heat_source : GivenHeatSource or None
        The scene's given heat source (with one, no traction is computed).
    """
    return heat_source is None and law is not None and law.depends_on_temperature


def _force(patch) -> float:
    fx = float(patch.creep_force_x or 0.0)
    fy = float(patch.creep_force_y or 0.0)
    return float(np.hypot(fx, fy))


def solve_coupled(law, wheel, rail, patch, run_tangential, run_source, run_temperature, *, scene_name=None):
    """Iterate tangential -> heat -> temperature -> friction to convergence.

    Parameters
    ----------
    law : railtherm.physics.friction.FrictionLaw
        A temperature-dependent friction law (its ``nominal`` mu [1] scales the force change).
    wheel, rail : Material
        Their ``bulk_temperature`` [degC] gives the first contact temperature.
    patch : ContactPatch
        The normal stage's patch.
    run_tangential, run_source, run_temperature : callable
        ``run_tangential(patch) -> ContactPatch`` (the chain's tangential model on a patch that carries
        ``contact_temperature``), ``run_source(patch) -> HeatSource``, ``run_temperature(source) ->
        TemperatureField``.
    scene_name : str, optional
        For messages.

    Returns
    -------
    (ContactPatch, HeatSource, TemperatureField, railtherm.physics.friction.LoopHistory)
        The converged stages' results (the patch's ``contact_temperature`` is the one its friction
        used) and the history.

    Raises
    ------
    railtherm.SolverError
        When the loop has not converged after
        :data:`~railtherm.physics.friction.LOOP_MAX_ITERATIONS` solves.
    """
    inside = np.asarray(patch.pressure) > 0
    scale = law.nominal * float(patch.normal_force)

    def solve(t_in):
        p_in = dataclasses.replace(patch, contact_temperature=np.broadcast_to(t_in, patch.grid.shape).copy())
        tang = run_tangential(p_in)
        source = run_source(tang)
        temp = run_temperature(source)
        return LoopStep((tang, source, temp), field_contact_temperature(temp, patch), _force(tang), scale, inside)

    start = float(contact_temperature(wheel.bulk_temperature, rail.bulk_temperature))
    (tang, source, temp), hist = iterate_temperature_law(law, solve, start, what=f"scene {scene_name!r}")
    return tang, source, temp, hist
