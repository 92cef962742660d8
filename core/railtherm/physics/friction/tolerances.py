"""When a friction iteration stops: one tolerance on mu (tightened for a plain fixed point) and step limits.

Two iterations solve a friction law whose mu depends on the solution, and both stop on the largest change
of mu over the contact cells:

* the coupled temperature-friction loop (a ``temperature`` law): core's
  :mod:`railtherm.solving.friction_loop` and the FEM's Steps 1-4 loop stop when that change is below
  :data:`LOOP_MU_TOLERANCE`. One step is a whole tangential and thermal solve; the step is mixed (Anderson
  in core, Aitken in the FEM), so the change of the last step is close to the remaining error.
* the slip-velocity iteration (a ``slip-velocity`` or ``polach`` law,
  :func:`railtherm.physics.friction.iterate_slip_law`, used by ``kalker`` and the FEM) stops when it is below
  :data:`SLIP_MU_TOLERANCE`. The iteration is a plain monotone fixed-point map contracting at the rate
  kappa < 1 (:func:`~railtherm.physics.friction.contraction_limit`), whose remaining error is bounded by
  kappa / (1 - kappa) times the last change: 10 times tighter than the loop's keeps that bound below
  :data:`LOOP_MU_TOLERANCE` for kappa up to 0.9, so both iterations deliver mu to the same accuracy.
"""
from __future__ import annotations

__all__ = ["LOOP_MU_TOLERANCE", "LOOP_FORCE_TOLERANCE", "LOOP_MAX_ITERATIONS", "SLIP_MU_TOLERANCE",
           "SLIP_MAX_STEPS"]

#: the coupled temperature-friction loop stops when max |mu_k - mu_{k-1}| over the contact is below this [1]:
#: the traction bound mu p of every cell is then settled to 1e-4 p, the creep force to 1e-4 N
LOOP_MU_TOLERANCE = 1e-4
#: ... and (core's loop) when the creep force changed by less than this times mu_ref N [1]
LOOP_FORCE_TOLERANCE = 1e-4
#: core's loop fails (not converged) after this many tangential solves
LOOP_MAX_ITERATIONS = 30

#: the slip-velocity iteration stops when max |mu_{k+1} - mu_k| over the contact is below this [1]: the one
#: tolerance on mu, tightened for a plain fixed point (remaining error <= kappa / (1 - kappa) x 1e-5 <
#: LOOP_MU_TOLERANCE for kappa <= 0.9)
SLIP_MU_TOLERANCE = LOOP_MU_TOLERANCE / 10
#: ... and fails after this many steps (a solver that did not converge, :class:`railtherm.SolverError`):
#: at kappa = 0.8 the change falls by 0.8 per step, from mu ~ 0.3 to 1e-5 in about 46 steps
SLIP_MAX_STEPS = 60
