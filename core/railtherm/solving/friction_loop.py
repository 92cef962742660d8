"""Core's coupled loop for friction that falls with temperature: tangential -> heat source -> temperature
-> contact temperature -> friction, iterated to a stated tolerance on mu and on the creep force.

A scene whose ``friction`` is a ``temperature`` law (:class:`railtherm.physics.friction.TemperatureFriction`)
makes the friction of each cell depend on the surface temperature there, which depends on the heat the
friction makes. :func:`solve_coupled` runs the chain's own stage models around that loop (the temperature
model of the chain, green by default in the methods that have it, or any other):

1. the tangential model solves with the contact temperature on the patch (first: the bulk temperature);
2. core's heat source and the chain's temperature model give the surface temperatures, and they the contact
   temperature of each cell (:func:`railtherm.physics.friction.field_contact_temperature`) [degC];
3. the next contact temperature is an Anderson-mixed update (depth 2) of the last ones, so that the
   negative feedback (hotter -> less friction -> less heat) converges in a few steps instead of
   oscillating;
4. stop when the largest change of mu over the contact cells is below
   :data:`~railtherm.physics.friction.LOOP_MU_TOLERANCE` and the change of the creep force below
   :data:`~railtherm.physics.friction.LOOP_FORCE_TOLERANCE` x mu_ref N; after
   :data:`~railtherm.physics.friction.LOOP_MAX_ITERATIONS` the run fails (``SolverError``: not converged),
   naming the history.

The iteration history goes into the diagnostics: ``friction_loop_iterations``, ``friction_loop_mu_change``
(per iteration, [1]), ``friction_loop_force_change`` (per iteration, [1] relative to mu_ref N),
(NaN at the first, which has nothing to compare with), ``friction_loop_mean_mu`` and ``friction_loop_max_contact_temperature`` [degC].
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..contract.errors import SolverError
from ..physics.friction import (LOOP_FORCE_TOLERANCE, LOOP_MAX_ITERATIONS, LOOP_MU_TOLERANCE, contact_temperature,
                                field_contact_temperature)

__all__ = ["LoopHistory", "needs_loop", "solve_coupled"]

#: depth of the Anderson mixing (number of earlier residuals used)
ANDERSON_DEPTH = 2


def needs_loop(scene) -> bool:
    """Whether the scene's friction depends on the temperature (and the scene computes its traction)."""
    law = scene.friction_law
    return scene.heat_source is None and law is not None and law.depends_on_temperature


@dataclass
class LoopHistory:
    """The iteration history of the coupled loop."""

    mu_change: list = field(default_factory=list)
    force_change: list = field(default_factory=list)
    mean_mu: list = field(default_factory=list)
    max_temperature: list = field(default_factory=list)

    def diagnostics(self) -> dict:
        return {"friction_loop_iterations": len(self.mu_change),
                "friction_loop_mu_change": np.asarray(self.mu_change, dtype=float),
                "friction_loop_force_change": np.asarray(self.force_change, dtype=float),
                "friction_loop_mean_mu": np.asarray(self.mean_mu, dtype=float),
                "friction_loop_max_contact_temperature": np.asarray(self.max_temperature, dtype=float)}

    def text(self) -> str:
        return "; ".join(f"{k + 1}: dmu {m:.2e}, dF {f:.2e}" for k, (m, f) in
                         enumerate(zip(self.mu_change, self.force_change)))


def _force(patch) -> float:
    fx = float(patch.creep_force_x or 0.0)
    fy = float(patch.creep_force_y or 0.0)
    return float(np.hypot(fx, fy))


class _Anderson:
    """Anderson mixing (type II, depth m) for the fixed point t = G(t) on the contact temperature."""

    def __init__(self, depth: int):
        self.depth = depth
        self.ts: list[np.ndarray] = []
        self.fs: list[np.ndarray] = []

    def next(self, t: np.ndarray, g: np.ndarray) -> np.ndarray:
        f = g - t
        self.ts.append(t.ravel().copy())
        self.fs.append(f.ravel().copy())
        self.ts, self.fs = self.ts[-(self.depth + 1):], self.fs[-(self.depth + 1):]
        if len(self.fs) == 1:
            return g
        dF = np.stack([self.fs[i + 1] - self.fs[i] for i in range(len(self.fs) - 1)], axis=1)
        dT = np.stack([self.ts[i + 1] - self.ts[i] for i in range(len(self.ts) - 1)], axis=1)
        gamma, *_ = np.linalg.lstsq(dF, f.ravel(), rcond=None)
        new = t.ravel() + f.ravel() - (dT + dF) @ gamma
        return new.reshape(t.shape)


def solve_coupled(scene, patch, run_tangential, run_source, run_temperature):
    """Iterate tangential -> heat -> temperature -> friction to convergence.

    Parameters
    ----------
    scene : Scene
        With a temperature-dependent friction law.
    patch : ContactPatch
        The normal stage's patch.
    run_tangential, run_source, run_temperature : callable
        ``run_tangential(patch) -> ContactPatch`` (the chain's tangential model on a patch that carries
        ``contact_temperature``), ``run_source(patch) -> HeatSource``, ``run_temperature(source) ->
        TemperatureField``.

    Returns
    -------
    (ContactPatch, HeatSource, TemperatureField, LoopHistory)
        The converged stages' results (the patch's ``contact_temperature`` is the one its friction
        used) and the history.

    Raises
    ------
    railtherm.SolverError
        When the loop has not converged after
        :data:`~railtherm.physics.friction.LOOP_MAX_ITERATIONS` solves.
    """
    law = scene.friction_law
    inside = np.asarray(patch.pressure) > 0
    scale = law.nominal * float(patch.normal_force)
    bulk = float(contact_temperature(scene.wheel.bulk_temperature, scene.rail.bulk_temperature))
    t_in = np.full(patch.grid.shape, bulk)
    mix = _Anderson(ANDERSON_DEPTH)
    hist = LoopHistory()
    mu_old = f_old = None
    for _ in range(LOOP_MAX_ITERATIONS):
        p_in = dataclasses.replace(patch, contact_temperature=t_in)
        tang = run_tangential(p_in)
        source = run_source(tang)
        temp = run_temperature(source)
        mu = np.asarray(law.mu(0.0, t_in), dtype=float)
        force = _force(tang)
        t_out = field_contact_temperature(temp, patch)
        hist.mean_mu.append(float(mu[inside].mean()) if inside.any() else float(law.nominal))
        hist.max_temperature.append(float(t_out[inside].max()) if inside.any() else bulk)
        mu_next = np.asarray(law.mu(0.0, t_out), dtype=float)
        dmu = float(np.abs(mu_next - mu)[inside].max()) if inside.any() else 0.0
        df = abs(force - f_old) / scale if f_old is not None and scale > 0 else (np.nan if scale > 0 else 0.0)
        hist.mu_change.append(dmu)
        hist.force_change.append(float(df))
        if dmu < LOOP_MU_TOLERANCE and df < LOOP_FORCE_TOLERANCE:
            return tang, source, temp, hist
        mu_old, f_old = mu, force
        t_in = mix.next(t_in, t_out)
    raise SolverError(f"scene {scene.name!r}: the temperature-friction loop did not converge in {LOOP_MAX_ITERATIONS} "
                      f"iterations (tolerances: mu {LOOP_MU_TOLERANCE:g}, creep force {LOOP_FORCE_TOLERANCE:g} mu N); "
                      f"history: {hist.text()}")
