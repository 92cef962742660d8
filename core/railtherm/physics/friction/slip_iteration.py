"""The slip-velocity iteration: mu of each slipping cell at the slip speed its own traction bound drives.

The traction bound of a slipping cell, mu(v) p, depends on its own slip speed v, which depends on the bound.
:func:`iterate_slip_law` solves that by a monotone outer iteration around a method's tangential solve (``kalker``
and the FEM); :func:`contraction_limit` is the rate it contracts at, and says when no unique local solution
exists. FASTSIM solves the same local equation cell by cell in its sweep.
"""
from __future__ import annotations

import math

import numpy as np

from ...contract.errors import Refused, SolverError
from .laws import FrictionLaw
from .tolerances import SLIP_MAX_STEPS, SLIP_MU_TOLERANCE

__all__ = ["contraction_limit", "iterate_slip_law"]


def contraction_limit(law: FrictionLaw, pressure: float, stiffness: float) -> float:
    """The steepest slope of ``mu(v_slip) p`` against the slip the traction drives, at one cell [1].

    In a slipping cell the traction bound g = mu(v) p and the slip speed v are tied by the elastic
    (or, for FASTSIM, the flexibility) relation v = (|p_candidate| - g) / stiffness; the fixed point
    g = mu((|p_c| - g) / stiffness) p is unique and the monotone iteration on it converges when
    ``|d mu/dv| p / stiffness < 1`` (the law falls slower than the traction can follow).
    Returns that number at v = 0 (the steepest point of the exponential laws); >= 1 means no unique
    local solution.

    Parameters
    ----------
    law : FrictionLaw
    pressure : float
        Local pressure p [Pa].
    stiffness : float
        Traction drop per unit slip speed in the cell, -dp_t/dv [Pa s/m].
    """
    return float(abs(law.dmu_dslip(0.0)) * pressure / stiffness) if stiffness > 0 else math.inf


def iterate_slip_law(law: FrictionLaw, solve, slip_speed, shape, kappa_of, *, model: str, speed: float,
                     tol: float | None = None, max_outer: int | None = None):
    """Solve a tangential problem under a slip-velocity law by the monotone outer iteration on mu.

    The traction bound of a slipping cell, mu(v) p, depends on its own slip speed v, which depends on the
    bound. The map mu -> law(v(mu)) is monotone increasing (a higher bound gives less slip, and the law
    falls with slip), so the iteration started at the law's maximum (mu at zero slip) decreases
    monotonically to the largest fixed point, the solution of least slip. It contracts at the rate kappa =
    max |dmu/dv| p V s_self (the law's slope against the slip a cell's own traction drives,
    :func:`contraction_limit`); kappa >= 1 (no unique local solution: outside the model's validity) is
    refused before the iteration goes on; an iteration with kappa < 1 that has not met ``tol`` after
    ``max_outer`` steps is a solver that did not converge, a failed run. Used by the exact
    (``kalker``) and the FEM tangential problems; FASTSIM solves its local equation in its sweep.

    Parameters
    ----------
    law : FrictionLaw
        A law that depends on the slip speed.
    solve : callable
        ``solve(mu, previous) -> solution`` with mu per cell (``shape``) [1] and the previous solution (None
        at the first step; a warm start where the solver takes one).
    slip_speed : callable
        ``slip_speed(solution) -> ndarray`` (``shape``): |v_slip| per cell [m/s].
    shape : tuple
        Shape of mu.
    kappa_of : callable
        ``kappa_of(solution) -> (kappa, inside)``: the contraction number [1] and the contact mask, from the
        first solution.
    model : str
        Model name for the messages.
    speed : float
        Rolling speed V [m/s] (the refusal says which speed would work).
    tol, max_outer : float, int, optional
        Stop when max |mu_{k+1} - mu_k| over the contact < ``tol`` [1]; fail after ``max_outer`` steps
        (default :data:`~railtherm.physics.friction.SLIP_MU_TOLERANCE`,
        :data:`~railtherm.physics.friction.SLIP_MAX_STEPS`).

    Returns
    -------
    solution, mu, history, kappa
        The last solve (it used ``mu``, which the law reproduces within ``tol``), mu per cell [1], the
        change of mu at each step [1], and kappa [1].

    Raises
    ------
    railtherm.Refused
        (validity) kappa >= 1.
    railtherm.SolverError
        No convergence in ``max_outer`` steps (the run is ``failed``, reason not-converged).
    """
    tol = SLIP_MU_TOLERANCE if tol is None else tol
    max_outer = SLIP_MAX_STEPS if max_outer is None else max_outer
    mu = np.full(shape, float(law.mu(0.0)))
    sol, kappa, inside, history = None, None, None, []
    for _ in range(max_outer):
        sol = solve(mu, sol)
        if kappa is None:
            kappa, inside = kappa_of(sol)
            if not kappa < 1.0:
                decay = getattr(law, "decay", None)
                raise Refused(
                    f"model {model!r}: the friction law ({law.describe()}) falls too steeply for a unique local "
                    f"solution: kappa = |dmu/dv| p V s_self = {kappa:.3g} >= 1 at the most loaded cell (its slip "
                    f"cannot follow its falling traction bound); use a slower decay"
                    + (f" (decay >= {kappa * decay:.3g} m/s)" if decay else "")
                    + f", a speed <= {abs(float(speed)) / kappa:.3g} m/s or a lower load", kind="validity")
        new = np.asarray(law.mu(np.nan_to_num(slip_speed(sol))), dtype=float).reshape(shape)
        change = float(np.max(np.abs(new - mu)[inside], initial=0.0))
        history.append(change)
        if change < tol:
            return sol, mu, history, kappa
        mu = new
    raise SolverError(f"model {model!r}: the slip-velocity friction iteration did not converge in {max_outer} "
                      f"steps (last change of mu {history[-1]:.2e}, tolerance {tol:g}; kappa = {kappa:.3g})")
