"""Friction laws in Kalker's exact tangential problem: mu per element from the scene's law
(:mod:`railtherm.physics.friction`), cell by cell.

* A temperature law: mu of each element at its contact temperature (core's coupled loop puts it on the
  patch), one tangential solve.
* A slip-velocity law (exponential or Polach's): the traction bound of a slipping element, mu(v) p, depends
  on its own slip speed v = V |s|, which depends on the bound. The map mu -> law(V |s(mu)|) is monotone
  increasing (a higher bound gives less slip, and the law falls with slip), so the iteration started at the
  law's maximum (mu at zero slip) decreases monotonically to the largest fixed point. It converges at the rate
  kappa = max |dmu/dv| p V |B_xx(0)| (the law's slope against the traction's own slip response, with
  B_xx(0) the rolling operator's self-coefficient): kappa >= 1 means the law falls faster than the traction
  can follow, no unique local solution, and the run is refused naming kappa
  (:func:`railtherm.physics.friction.contraction_limit`). The iteration and its stopping rule are core's,
  shared with the FEM (:func:`railtherm.physics.friction.iterate_slip_law`).
"""
from __future__ import annotations

import numpy as np
from railtherm.physics.friction import contraction_limit, iterate_slip_law, local_friction

__all__ = ["solve_with_law"]


def _mu_of(law, patch, wheel_bulk, rail_bulk, shape, slip_speed=0.0):
    return local_friction(law, patch, wheel_bulk, rail_bulk, np.asarray(slip_speed).reshape(np.shape(patch.pressure))
                          if np.ndim(slip_speed) else slip_speed).reshape(shape)


def solve_with_law(law, patch, wheel_bulk: float, rail_bulk: float, solve, self_coefficient: float, speed: float):
    """Solve the tangential problem under a friction law (the scene's ``friction``).

    Parameters
    ----------
    law : railtherm.physics.friction.FrictionLaw
        The scene's friction law (``scene.friction``).
    patch : ContactPatch
        Grid, pressure [Pa] and (for a temperature law) ``contact_temperature`` [degC].
    wheel_bulk, rail_bulk : float
        Bulk temperatures of the wheel and the rail [degC] (``scene.wheel.bulk_temperature``,
        ``scene.rail.bulk_temperature``): a temperature law's contact temperature where the patch has none
        (:func:`railtherm.physics.friction.local_friction`).
    solve : callable
        ``solve(mu, previous=None) -> (solution, X, Y)``: the tangential solve with mu per element (nx, ny) [1],
        warm-started from ``previous`` (the last such tuple) when given.
    self_coefficient : float
        |B_xx(0)| of the rolling operator on this grid [1/Pa].
    speed : float
        Rolling speed V [m/s] (slip velocity = V s).

    Returns
    -------
    solution, X, Y, mu, diagnostics
        The converged solve, mu per element [1] and ``{"friction_iterations", "friction_mu_change",
        "friction_contraction"}`` for a slip law.

    Raises
    ------
    railtherm.Refused
        (validity) when the slip law falls too steeply (kappa >= 1).
    railtherm.SolverError
        When the slip-law iteration does not converge (:func:`railtherm.physics.friction.iterate_slip_law`).
    """
    p = np.clip(np.asarray(patch.pressure, dtype=float), 0.0, None)
    shape = p.reshape(p.shape[0], -1).shape
    if not law.depends_on_slip:
        mu = _mu_of(law, patch, wheel_bulk, rail_bulk, shape)
        sol, X, Y = solve(mu)
        return sol, X, Y, mu, {}
    V = abs(float(speed))
    kappa = contraction_limit(law, float(p.max()), 1.0 / (V * self_coefficient))
    inside = p.reshape(shape) > 0
    (sol, X, Y), mu, history, kappa = iterate_slip_law(
        law, solve,
        lambda out: V * np.sqrt(np.sum(np.asarray(out[0].slip) ** 2, axis=0)), shape,
        lambda _out: (kappa, inside), model="kalker", speed=V)
    return sol, X, Y, mu, {"friction_iterations": len(history), "friction_mu_change": np.asarray(history),
                           "friction_contraction": kappa}
