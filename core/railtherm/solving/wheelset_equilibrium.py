"""``pitch_velocity = "free"``: the wheelset's pitch velocity at which the forces of the chain's own solution on
both wheels have no moment about the axle (no traction or braking torque).

For a pitch velocity omega every patch of both wheels (``wheelset.patch = "all"``) is solved with the chain;
the moment about the axle is sum (r x F) . a over the patches, r the patch's reference point from the wheelset
centre, a the axle's direction and F the rail's force on the wheel from the result's normal force N and creep
forces Fx, Fy in the contact plane at contact angle delta: (Fx, Fy cos(delta) + N sin(delta), Fy sin(delta) -
N cos(delta)) in the wheel's axes (z down). The creepages are affine in omega (the rigid slip of the wheel), so
the scenes are built twice and the creepages of any omega interpolated; the secant method finds the root. The
scene is then loaded again with that pitch velocity given and solved: its result is the result of that scene,
with the attributes ``wheelset_pitch_velocity`` [rad/s] and ``wheelset_axle_moment`` [N m] (the moment left);
its ``wall_time`` is the whole search's.
"""
from __future__ import annotations

import copy
import dataclasses
import math
import time

import numpy as np

from ..contract.errors import SolverError
from ..input.scene import load_scene
from ..input.wheelset_profile import patch_scenes

__all__ = ["solve_free_pitch", "axle_moment", "NEED"]

#: what the moment needs of each patch's solve
NEED = ("normal_force", "creep_force_x", "creep_force_y", "contact_angle")
#: the secant stops when the moment is below this fraction of (sum of normal forces) x (nominal radius)
MOMENT_TOL = 1e-7
MAX_STEPS = 30


def axle_moment(pc, normal, creep_x, creep_y, angle) -> float:
    """(r x F) . a [N m] of one patch (module docstring) from its ProfileContact (``arm``, ``axle``) and its
    normal force [N], creep forces on the wheel [N] and contact angle [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    force = np.array([creep_x, creep_y * c + normal * s, creep_y * s - normal * c])
    return float(np.cross(np.asarray(pc.arm), force) @ np.asarray(pc.axle))


def _source(scene, side: str, omega: float, **wheelset) -> dict:
    src = copy.deepcopy(dict(scene.source))
    src["wheelset"] = dict(src["wheelset"], side=side, pitch_velocity=float(omega), **wheelset)
    return src


def _loaded(mapping):
    """The scene of ``mapping``; a wheel of it that finds no contact raises its error (the other wheel's too)."""
    scene = load_scene(mapping)
    if hasattr(scene.profile_contact, "failure"):
        raise scene.profile_contact.failure()
    return scene


def solve_free_pitch(scene, method, level, options, *, solve_one, validate: bool = True, **kw):
    """Solve ``scene`` at the pitch velocity that balances the axle's moment (module docstring)."""
    t0 = time.perf_counter()
    pc = scene.profile_contact
    w0 = float(pc.free_pitch)
    w1 = w0 * (1.0 + 1e-4)
    fixed = {"patch": "all"}
    if pc.balanced_roll is not None:   # balance once: the roll of the scene as loaded, half the axle load per wheel
        fixed.update(roll_angle=pc.balanced_roll, vertical_force=pc.vertical_force)
    wheels = []
    for side in ("right", "left"):
        pair = [patch_scenes(_loaded(dict(_source(scene, side, w, **fixed), outputs=list(NEED))), NEED)
                for w in (w0, w1)]
        if len(pair[0]) != len(pair[1]):
            raise SolverError(f"scene {scene.name!r}: the {side} wheel's patches change with the pitch velocity")
        wheels.extend(zip(*pair))
    load = sum(float(a.profile_contact.normal_force) for a, _ in wheels) * float(pc.rolling_radius)

    def moment(w):
        t = (w - w0) / (w1 - w0)
        total = 0.0
        for a, b in wheels:
            creep = type(a.creepage)(*(u + t * (v - u) for u, v in zip(dataclasses.astuple(a.creepage),
                                                                      dataclasses.astuple(b.creepage))))
            r = solve_one(dataclasses.replace(a, creepage=creep), method, level, options, validate=False, **kw)
            total += axle_moment(a.profile_contact, *(float(r[q]) for q in NEED))
        return total

    x0, x1 = w0, w1
    f0, f1 = moment(x0), moment(x1)
    for _ in range(MAX_STEPS):
        if abs(f1) <= MOMENT_TOL * load or f1 == f0:
            break
        x0, f0, x1 = x1, f1, x1 - f1 * (x1 - x0) / (f1 - f0)
        f1 = moment(x1)
    else:
        raise SolverError(f"scene {scene.name!r}: no pitch velocity balances the axle's moment in {MAX_STEPS} "
                          f"steps (last {x1:.9g} rad/s, moment {f1:.3g} N m)")
    given = {k: v for k, v in fixed.items() if k != "patch"}
    final = load_scene(_source(scene, pc.side, x1, **given))
    out = solve_one(final, method, level, options, validate=validate, **kw)
    # the whole search is the solve's work (its wall time: the loads and every solve of both wheels)
    out.attrs.update({"wheelset_pitch_velocity": float(x1), "wheelset_axle_moment": float(f1),
                      "wall_time": time.perf_counter() - t0})
    if pc.balanced_roll is not None:
        out.attrs.update(wheelset_roll_angle=float(pc.balanced_roll), wheelset_roll_balance=pc.roll_balance)
    return out
