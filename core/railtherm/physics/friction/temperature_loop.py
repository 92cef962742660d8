"""The coupled temperature-friction loop: the one iteration every method runs for a ``temperature`` law.

Friction that falls with temperature makes each cell's mu depend on the contact temperature there, which
depends on the heat the friction makes. :func:`iterate_temperature_law` iterates on the contact
temperature T_c (on the points a method solves on: core's patch cells, the FEM's window nodes):
1. ``solve(T_c)``: the method's solve with mu = law(T_c) per point; it returns the contact temperature its
   own heat produces, the creep force and the contact mask (a :class:`LoopStep`);
2. the next T_c is an Anderson-mixed update (depth :data:`ANDERSON_DEPTH`) of the last ones, so that the
   negative feedback (hotter -> less friction -> less heat) converges in a few steps instead of oscillating;
3. stop when max |law(T_out) - law(T_c)| over the contact is below :data:`.tolerances.LOOP_MU_TOLERANCE`
   and the creep force changed by less than :data:`.tolerances.LOOP_FORCE_TOLERANCE` x mu_ref N; after
   :data:`.tolerances.LOOP_MAX_ITERATIONS` solves the run fails (``SolverError``: not converged).
Core's :func:`railtherm.solving.friction_loop.solve_coupled` drives a chain's stages with it; the FEM
drives its Steps 1-4 solve (at fixed mu per node) with it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...contract.errors import SolverError
from .laws import FrictionLaw
from .tolerances import LOOP_FORCE_TOLERANCE, LOOP_MAX_ITERATIONS, LOOP_MU_TOLERANCE

__all__ = ["ANDERSON_DEPTH", "LoopStep", "LoopHistory", "iterate_temperature_law"]

#: depth of the Anderson mixing (number of earlier residuals used)
ANDERSON_DEPTH = 2


@dataclass
class LoopStep:
    """What one solve of the loop returns.

    Attributes
    ----------
    result : object
        The method's solution (returned by the loop when it converges).
    contact_temperature : ndarray
        The contact temperature the solution's heat produces at the loop's points [degC].
    force : float
        Creep force magnitude [N] ([N/m] for a line contact).
    force_scale : float
        mu_ref N [N]: the force change is measured against it.
    inside : ndarray of bool
        The points in contact (same shape as ``contact_temperature``).
    """

    result: object
    contact_temperature: np.ndarray
    force: float
    force_scale: float
    inside: np.ndarray


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


def iterate_temperature_law(law: FrictionLaw, solve, start: float, *, what: str):
    """Iterate ``solve`` on the contact temperature until mu and the creep force settle.

    Parameters
    ----------
    law : FrictionLaw
        A law that depends on the temperature.
    solve : callable
        ``solve(t_in) -> LoopStep``: the method's solve with mu = law(0, t_in) at its points; ``t_in`` is the
        scalar ``start`` at the first call, then an array on the points of the first step's
        ``contact_temperature``.
    start : float
        The first contact temperature [degC] (that of the bulk temperatures).
    what : str
        Who iterates, for the message (``"scene 'x'"``, ``"model 'fem'"``).

    Returns
    -------
    (result, LoopHistory)
        The last step's ``result`` (its mu is law(t_in) of the t_in it was given) and the history.

    Raises
    ------
    railtherm.SolverError
        When the loop has not converged after :data:`~railtherm.physics.friction.LOOP_MAX_ITERATIONS` solves.
    """
    t_in = start
    mix = _Anderson(ANDERSON_DEPTH)
    hist = LoopHistory()
    f_old = None
    for _ in range(LOOP_MAX_ITERATIONS):
        step = solve(t_in)
        t_out, inside, scale = step.contact_temperature, step.inside, step.force_scale
        t_in = np.broadcast_to(np.asarray(t_in, dtype=float), t_out.shape).copy()
        mu = np.asarray(law.mu(0.0, t_in), dtype=float)
        hist.mean_mu.append(float(mu[inside].mean()) if inside.any() else float(law.nominal))
        hist.max_temperature.append(float(t_out[inside].max()) if inside.any() else float(start))
        mu_next = np.asarray(law.mu(0.0, t_out), dtype=float)
        dmu = float(np.abs(mu_next - mu)[inside].max()) if inside.any() else 0.0
        df = abs(step.force - f_old) / scale if f_old is not None and scale > 0 else (np.nan if scale > 0 else 0.0)
        hist.mu_change.append(dmu)
        hist.force_change.append(float(df))
        if dmu < LOOP_MU_TOLERANCE and df < LOOP_FORCE_TOLERANCE:
            return step.result, hist
        f_old = step.force
        t_in = mix.next(t_in, t_out)
    raise SolverError(f"{what}: the temperature-friction loop did not converge in {LOOP_MAX_ITERATIONS} "
                      f"iterations (tolerances: mu {LOOP_MU_TOLERANCE:g}, creep force {LOOP_FORCE_TOLERANCE:g} mu N); "
                      f"history: {hist.text()}")
