"""Friction laws in the FEM's contact (issue 15; :mod:`railtherm.physics.friction`): mu per window node.

The FEM's friction is already local (one Coulomb bound mu p per window node, :mod:`.contact`); a law gives
that mu node by node:

* a temperature law: mu at the node's contact temperature, the mean of the wheel's and the rail's surface
  temperature (bulk + rise of the FEM's own thermal layer at z = 0, interpolated to the node), updated in the
  Steps 1-4 loop of :mod:`.coupled` after every thermal solve, which then also stops on the change of mu
  (:data:`MU_TOLERANCE`) and records its history;
* a slip-velocity law (exponential or Polach's): mu(v) with v = V |s| the node's own slip speed, by a
  monotone outer iteration around the contact solve started at the law's value at zero slip (the slip each
  bound produces gives the next bound), stopped when max |mu_{k+1} - mu_k| over the contact nodes is below
  :data:`SLIP_MU_TOLERANCE`. The local equation g = mu(V |s(g)|) p of a slipping node has one solution and the
  iteration contracts when kappa = |dmu/dv(0)| p V |(D A_tt)_ii| < 1 (the law's slope against the slip the
  node's own traction drives through the condensed compliance A_tt and the upstream derivative D; core's
  :func:`~railtherm.physics.friction.contraction_limit`); kappa >= 1 is refused.
"""
from __future__ import annotations

import numpy as np

from railtherm import Refused
from railtherm.physics.friction import contraction_limit

__all__ = ["MU_TOLERANCE", "SLIP_MU_TOLERANCE", "MAX_OUTER", "node_contact_temperature", "solve_with_slip_law"]

#: the Steps 1-4 loop under a temperature law also stops only when mu changes by less than this [1]
MU_TOLERANCE = 1e-4
#: the slip-velocity outer iteration stops when mu changes by less than this over the contact nodes [1]
SLIP_MU_TOLERANCE = 1e-5
#: refuse after this many outer iterations (not converged)
MAX_OUTER = 60


def node_contact_temperature(x, grid, theta, wheel_bulk, rail_bulk):
    """Contact temperature at the window nodes [degC]: mean of wheel and rail surface temperatures.

    Parameters
    ----------
    x : ndarray (m,)
        Window node coordinates [m].
    grid : ThermalGrid or None
        The thermal layer's grid (None, or ``theta`` None: no rise yet).
    theta : list of two ndarrays or None
        Temperature rises (wheel, rail) on ``grid`` [K]; row 0 along z is the surface.
    wheel_bulk, rail_bulk : float
        Bulk temperatures [degC].
    """
    t = np.full(np.shape(x), 0.5 * (float(wheel_bulk) + float(rail_bulk)))
    if grid is None or theta is None:
        return t
    rise = [np.interp(x, grid.x, np.asarray(th)[:, 0], left=0.0, right=0.0) for th in theta]
    return t + 0.5 * (rise[0] + rise[1])


def solve_with_slip_law(law, solve, speed, self_slip):
    """The contact solve under a slip-velocity law, mu per node.

    Parameters
    ----------
    law : SlipVelocityFriction
    solve : callable
        ``solve(mu, initial) -> ContactSolution`` with mu per node (m,) [1] and a warm start (or None).
    speed : float
        Rolling speed V [m/s] (slip velocity = V s).
    self_slip : ndarray (m,)
        |(D A_tt)_ii|: slip per unit traction of each node on itself [1/Pa].

    Returns
    -------
    solution, mu, history, kappa
        The converged solve, mu per node [1], the change of mu at every outer step [1], and the largest
        kappa over the contact nodes [1].

    Raises
    ------
    railtherm.Refused
        (validity) kappa >= 1 (the law falls faster than a node's slip can follow), or no convergence.
    """
    V = abs(float(speed))
    sol = None
    mu = None
    history = []
    kappa = None
    for _ in range(MAX_OUTER):
        if mu is None:
            mu = np.full(np.shape(self_slip), float(law.mu(0.0)))      # the law at zero slip: its maximum
        sol = solve(mu, sol)
        p = sol.pressure
        inside = p > 0
        if kappa is None:
            kappa = max((contraction_limit(law, float(pi), 1.0 / (V * float(si))) for pi, si
                         in zip(p[inside], self_slip[inside])), default=0.0)
            if not kappa < 1.0:
                raise Refused(
                    f"model 'fem': the friction law ({law.describe()}) falls too steeply for a unique local "
                    f"solution: kappa = |dmu/dv| p V |(D A_tt)_ii| = {kappa:.3g} >= 1 at the most loaded node (the "
                    f"slip of a node cannot follow its falling traction bound); use a slower decay (decay >= "
                    f"{kappa * law.decay:.3g} m/s), or a speed <= {V / kappa:.3g} m/s, or a lower load",
                    kind="validity")
        new = np.asarray(law.mu(V * np.abs(np.nan_to_num(sol.slip))), dtype=float)
        change = float(np.max(np.abs(new - mu)[inside], initial=0.0))
        history.append(change)
        if change < SLIP_MU_TOLERANCE:
            return sol, mu, history, kappa
        mu = new
    raise Refused(f"model 'fem': the slip-velocity friction iteration did not converge in {MAX_OUTER} steps (last "
                  f"change of mu {history[-1]:.2e}, tolerance {SLIP_MU_TOLERANCE:g}; kappa = {kappa:.3g})",
                  kind="validity")
