"""A wheel on profiles carrying its prescribed vertical force with the chain's own creep forces.

A scene on profiles is loaded with normal forces that balance the wheel's vertical force Fz with an estimated lateral
creep force (Kalker's linear theory, saturated; :mod:`railtherm.input.wheelset_profile_vertical`): sum over the
patches of N cos(delta) - Fy sin(delta) = Fz (Fy on the wheel in the patch's contact plane, delta its contact angle;
:func:`railtherm.solving.wheelset_patches.wheel_totals`). At a flange the estimate's Fy is 5-7 % above kalker's, whose
own forces then carry 9.80-9.86 kN of A-2.2's 10 kN (positions 14-21 right). The CONTACT program prescribes the total
vertical force and meets it with its own creep forces; :func:`solve_vertical_force` does the same for a chain whose
normal stage solves the patch's own gap, moving the estimate's vertical force u (the patches' split at one common
approach kept) until the chain's own sum meets Fz to :data:`VERTICAL_TOL`. Hertz-equivalent chains keep the estimate.
Result attributes: ``wheelset_vertical_balance`` (whose Fy), ``wheelset_vertical_force_iterations`` (corrections of
the normal forces), ``wheelset_vertical_force_residual`` [N] (the chain's sum minus Fz),
``wheelset_vertical_force_tolerance`` [N] (the residual's bound, :data:`VERTICAL_TOL` Fz) and
``wheelset_vertical_force_at_estimate`` [N] (the chain's sum at the estimate's normal forces).
"""
from __future__ import annotations

import dataclasses
import time

from ..contract.errors import Refused, SolverError
from ..contract.schema import WHEELSET_VARIABLES
from ..input.wheelset_profile import VERTICAL_ESTIMATE, ProfileContacts
from ..input.wheelset_profile_vertical import estimated_normal_forces, patch_contacts, with_normal_forces
from .wheelset_equilibrium import HERTZ_EQUIVALENT
from .wheelset_patches import solve_patches, wheel_totals

__all__ = ["solve_vertical_force", "vertical_force", "VERTICAL_TOL", "VERTICAL_NEED"]

#: the chain's vertical force meets Fz to this fraction of it: |sum N cos(delta) - Fy sin(delta) - Fz| <= tol Fz
VERTICAL_TOL = 1e-4
#: what the vertical force needs of each patch's solve
VERTICAL_NEED = ("normal_force", "creep_force_y", "contact_angle")
MAX_STEPS = 12


class _Recorder:
    """``solve_one`` asking each solve for :data:`VERTICAL_NEED` as well (the patch quantities a wheelset's result
    always has aside), keeping those numbers of the solves since the last :meth:`take`. Each result is returned
    with the scene's own ``outputs`` attribute; the variables of the stages the added outputs ran stay (a result
    carries what its stages computed, as any solve)."""

    def __init__(self, solve_one):
        self.solve_one, self.patches = solve_one, []

    # whole scene: the pipeline's single-patch solve, wrapped
    def __call__(self, scene, method, level, options, **kw):
        extra = tuple(q for q in VERTICAL_NEED if q not in scene.outputs and q not in WHEELSET_VARIABLES)
        r = self.solve_one(dataclasses.replace(scene, outputs=tuple(scene.outputs) + extra), method, level, options,
                           **kw)
        self.patches.append(tuple(float(r[q]) for q in VERTICAL_NEED))
        r.attrs["outputs"] = " ".join(scene.outputs)
        return r

    def take(self) -> list:
        """(normal force [N], lateral creep force on the wheel [N], contact angle [rad]) of each patch solved since
        the last call."""
        out, self.patches = self.patches, []
        return out


def vertical_force(patches) -> float:
    """The vertical force [N] of the rail on the wheel (z up) from its patches' (normal force [N], lateral creep
    force on the wheel [N], contact angle [rad]): sum N cos(delta) - Fy sin(delta)."""
    normal, creep_y, angle = zip(*patches)
    return wheel_totals(normal, [0.0] * len(normal), creep_y, angle)[2]


def _model_slope(pc, fz, chain, wheel, rail, mu) -> float:
    """d(vertical force)/du [1] of the chain modelled by the estimate: the patches' normal forces the estimate gives
    for a vertical force u (:func:`railtherm.input.wheelset_profile_vertical.estimated_normal_forces`), each
    patch's estimated Fy scaled by the chain's own over the estimate's at u = Fz (``chain``: the chain's patches
    there, as :func:`vertical_force` takes them) and composed at the chain's contact angles; central difference
    over 1e-4 Fz. The secant's first step, where the chain has been solved once."""
    _, _, estimate = estimated_normal_forces(pc, fz, wheel, rail, mu)
    ratio = [f / e if e != 0.0 else 1.0 for (_, f, _), e in zip(chain, estimate)]

    def model(u):
        _, normal, lateral = estimated_normal_forces(pc, u, wheel, rail, mu)
        return vertical_force([(n, r * f, d) for n, f, r, (_, _, d) in zip(normal, lateral, ratio, chain)])

    h = 1e-4 * fz
    return (model(fz + h) - model(fz - h)) / (2.0 * h)


# whole scene: it returns the scene with its patches' normal forces replaced
def _at(scene, normal_forces, approach, balance):
    """``scene`` with its patches' normal forces [N] (and common approach [m]) replaced, balanced by ``balance``."""
    pc = with_normal_forces(scene.profile_contact, normal_forces, approach, balance)
    return dataclasses.replace(scene, profile_contact=pc, normal_force=float(patch_contacts(pc)[0].normal_force))


# whole scene: a solve driver above the stage hooks (every patch stacked, or its one)
def _solve(scene, method, level, options, solve_one, **kw):
    """The scene solved as the pipeline does once its balance is settled: every patch stacked, or its one."""
    if isinstance(scene.profile_contact, ProfileContacts):
        return solve_patches(scene, method, level, options, solve_one=solve_one, **kw)
    return solve_one(scene, method, level, options, **kw)


def _own_stages(ds) -> dict:
    return dict(part.split(":", 1) for part in str(ds.attrs.get("stages", "")).split())


# whole scene: a solve driver above the stage hooks; it solves the scene at trial normal forces by solve_one
def solve_vertical_force(scene, method, level, options, *, solve_one, validate: bool = True, host=None, peers=None,
                         **kw):
    """Solve ``scene`` (a wheel on profiles, its normal forces the estimate's) with its normal forces balancing
    the wheel's vertical force with the chain's own creep forces (module docstring).

    Each trial solves the scene as asked (every patch stacked, or its one; :data:`VERTICAL_NEED` added), at the
    estimate's normal forces for a vertical force u: first u = Fz, then the step of the chain's own vertical
    force's miss over the estimate's slope with the chain's Fy (:func:`_model_slope`), then secant steps. The
    result is the last trial's, with the attributes ``wheelset_vertical_*`` and the whole search's
    ``wall_time``. A chain on the Hertz-equivalent ellipse or without a lateral creep force keeps the first."""
    t0 = time.perf_counter()
    pc = scene.profile_contact
    fz = float(pc.vertical_force)
    mu = None if scene.friction is None else scene.friction.nominal
    kept = dict(method=method, level=level, options=options, validate=validate, host=host, peers=peers, **kw)
    record = _Recorder(solve_one)
    estimate = [c.normal_force for c in patch_contacts(pc)]
    own = _at(scene, estimate, getattr(pc, "approach", None), "the chain's own creep forces")
    try:
        out = _solve(own, solve_one=record, **kept)
    except Refused:   # a chain without a lateral creep force: the estimate is all there is
        out = None
    stages = _own_stages(out) if out is not None else {}
    if out is None or stages.get("normal") in HERTZ_EQUIVALENT or "tangential" not in stages:
        why = ("its normal stage is the Hertz-equivalent ellipse" if out is not None and "tangential" in stages
               else "the chain computes no lateral creep force")
        held = _at(scene, estimate, getattr(pc, "approach", None), f"{VERTICAL_ESTIMATE}; not the chain's own ({why})")
        at_estimate = vertical_force(record.take()) if out is not None else None
        out = out if out is not None else _solve(held, solve_one=solve_one, **kept)
        return _attributes(out, held.profile_contact.vertical_balance, 0, at_estimate, at_estimate, fz, t0)
    tangential = stages["tangential"]
    balance = (f"the chain's own lateral creep forces ({tangential}): sum N cos(delta) - Fy sin(delta) over the "
               f"patches meets the vertical force to {VERTICAL_TOL:g} of it, at the contact angles the chain reports")
    chain = record.take()
    at_estimate = vertical = vertical_force(chain)
    u0, g0, steps = fz, at_estimate - fz, 0
    if abs(g0) > VERTICAL_TOL * fz:
        u1 = fz - g0 / _model_slope(pc, fz, chain, scene.wheel, scene.rail, mu)
        for steps in range(1, MAX_STEPS + 1):
            approach, normal, _ = estimated_normal_forces(pc, u1, scene.wheel, scene.rail, mu)
            if min(normal) <= 0.0:
                raise SolverError(f"scene {scene.name!r}: balancing the wheel's vertical force with {tangential}'s "
                                  f"creep forces unloads a patch (normal forces {normal} N)")
            out = _solve(_at(scene, normal, approach, balance), solve_one=record, **kept)
            vertical = vertical_force(record.take())
            g1 = vertical - fz
            if abs(g1) <= VERTICAL_TOL * fz:
                break
            if g1 == g0:
                raise SolverError(f"scene {scene.name!r}: the chain's vertical force does not move with the normal "
                                  f"forces ({vertical:.6g} N against {fz:.6g} N)")
            u0, g0, u1 = u1, g1, u1 - g1 * (u1 - u0) / (g1 - g0)
        else:
            raise SolverError(f"scene {scene.name!r}: the chain's own creep forces do not meet the wheel's vertical "
                              f"force {fz:.6g} N in {MAX_STEPS} steps (last {vertical:.6g} N)")
    return _attributes(out, balance, steps, vertical, at_estimate, fz, t0)


def _attributes(out, balance, steps, vertical, at_estimate, fz, t0):
    """``out`` with the attributes of its vertical balance (module docstring) and the whole search's wall time."""
    out.attrs.update({"wheelset_vertical_balance": balance, "wheelset_vertical_force_iterations": int(steps),
                      "wall_time": time.perf_counter() - t0})
    if vertical is not None:
        out.attrs.update({"wheelset_vertical_force_residual": float(vertical - fz),
                          "wheelset_vertical_force_tolerance": float(VERTICAL_TOL * fz),
                          "wheelset_vertical_force_at_estimate": float(at_estimate)})
    return out
