"""Friction laws in the FEM's contact (:mod:`railtherm.physics.friction`): mu per window node.

The FEM's friction is local (one Coulomb bound mu p per window node, :mod:`.contact`); a law gives that mu
node by node:
* a temperature law: mu at the node's contact temperature (:func:`railtherm.physics.friction.contact_temperature`
  of the wheel's and the rail's surface temperature, bulk + rise of the FEM's thermal layer at z = 0,
  interpolated to the node: :func:`node_surface_temperatures`), iterated by core's temperature-friction
  loop around the Steps 1-4 solve of :mod:`.coupled` (:func:`railtherm.physics.friction.iterate_temperature_law`);
* a slip-velocity law (exponential or Polach's): mu(v) with v = V |s| the node's own slip speed, by core's
  monotone outer iteration around the contact solve (:func:`railtherm.physics.friction.iterate_slip_law`,
  tolerance :data:`~railtherm.physics.friction.SLIP_MU_TOLERANCE`). It contracts when kappa = |dmu/dv(0)|
  p V |(D A_tt)_ii| < 1 (the law's slope against the slip the node's own traction drives through the
  condensed compliance A_tt and the upstream derivative D;
  :func:`~railtherm.physics.friction.contraction_limit`); kappa >= 1 is refused.
"""
from __future__ import annotations

import numpy as np

from railtherm.physics.friction import contraction_limit, iterate_slip_law

__all__ = ["node_surface_temperatures", "solve_with_slip_law"]


def node_surface_temperatures(x, grid, theta, wheel_bulk, rail_bulk):
    """Surface temperatures of wheel and rail at the window nodes [degC]: bulk + the thermal layer's rise.

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

    Returns
    -------
    (ndarray, ndarray)
        Wheel and rail surface temperature at ``x`` [degC].
    """
    bulk = (float(wheel_bulk), float(rail_bulk))
    if grid is None or theta is None:
        return tuple(np.full(np.shape(x), b) for b in bulk)
    return tuple(b + np.interp(x, grid.x, np.asarray(th)[:, 0], left=0.0, right=0.0) for b, th in zip(bulk, theta))


def solve_with_slip_law(law, solve, speed, self_slip):
    """The contact solve under a slip-velocity law, mu per node: core's monotone outer iteration
    (:func:`railtherm.physics.friction.iterate_slip_law`) with the FEM's own slip response.

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
        As :func:`~railtherm.physics.friction.iterate_slip_law`.
    """
    V = abs(float(speed))

    def kappa_of(sol):
        inside = sol.pressure > 0
        kappa = max((contraction_limit(law, float(pi), 1.0 / (V * float(si))) for pi, si
                     in zip(sol.pressure[inside], self_slip[inside])), default=0.0)
        return kappa, inside

    return iterate_slip_law(law, solve, lambda sol: V * np.abs(np.nan_to_num(sol.slip)), np.shape(self_slip),
                            kappa_of, model="fem", speed=V)
