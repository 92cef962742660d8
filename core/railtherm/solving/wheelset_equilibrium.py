"""The wheelset's equilibrium with the chain's own forces, beyond one patch at given motion.

* ``pitch_velocity = "free"`` (:func:`solve_free_pitch`): the pitch velocity at which the forces of the
  chain's own solution on every patch of both wheels have no moment about the axle (no traction or braking
  torque; :func:`axle_moment`), each wheel's normal forces meeting its vertical force with the chain's own creep
  forces at every iterate (:mod:`.wheelset_vertical`); the result carries ``wheelset_pitch_velocity`` [rad/s],
  ``wheelset_axle_moment`` [N m] and ``wheelset_axle_moment_tolerance`` [N m].
* ``roll_angle = "balance"`` (:func:`solve_balanced_roll`): the roll at which both wheels' heights agree
  with the normal approaches of the chain's normal stage; the result carries ``wheelset_roll_angle`` [rad],
  ``wheelset_roll_balance``, ``wheelset_roll_angle_hertz`` [rad] and ``wheelset_roll_height_mismatch`` [m].
"""
from __future__ import annotations

import copy
import math
import time

import numpy as np

from ..contract.errors import SolverError
from ..input.scene import load_scene
from ..input.wheelset_profile import ROLL_BALANCE, roll_height_mismatch
from ..physics.elastic import contact_modulus
from ..references.hertz import hertz_from_curvatures

__all__ = ["solve_free_pitch", "solve_balanced_roll", "axle_moment", "NEED"]

#: what the moment needs of each patch's solve
NEED = ("normal_force", "creep_force_x", "creep_force_y", "contact_angle")
#: the secant stops when the moment is below this fraction of (sum of normal forces) x (the scene's rolling radius)
MOMENT_TOL = 1e-7
MAX_STEPS = 30
#: the roll balanced with the chain's normal stage: the wheels' corrected heights agree to this [m]
HEIGHT_TOL = 1e-10
#: normal models whose patch is the Hertz-equivalent ellipse the loaded roll was balanced with
HERTZ_EQUIVALENT = ("wheelset-profile",)


def axle_moment(pc, normal, creep_x, creep_y, angle) -> float:
    """(r x F) . a [N m] of one patch from its ProfileContact (``arm``, ``axle``) and its normal force [N],
    creep forces on the wheel [N] and contact angle [rad].

    r is the patch's reference point from the wheelset centre, a the axle's direction and F the rail's force
    on the wheel from the result's normal force N and creep forces Fx, Fy in the contact plane at contact
    angle delta: (Fx, Fy cos(delta) + N sin(delta), Fy sin(delta) - N cos(delta)) in the wheel's axes
    (z down)."""
    c, s = math.cos(angle), math.sin(angle)
    force = np.array([creep_x, creep_y * c + normal * s, creep_y * s - normal * c])
    return float(np.cross(np.asarray(pc.arm), force) @ np.asarray(pc.axle))


def _source(source, side: str, omega: float, **wheelset) -> dict:
    """A copy of the scene's table ``source`` with its wheelset's ``side``, ``pitch_velocity`` [rad/s] and the
    keys of ``wheelset`` given."""
    src = copy.deepcopy(dict(source))
    src["wheelset"] = dict(src["wheelset"], side=side, pitch_velocity=float(omega), **wheelset)
    return src


def _loaded(mapping):
    """The scene of ``mapping``; a wheel of it that finds no contact raises its error (the other wheel's too)."""
    scene = load_scene(mapping)
    if hasattr(scene.profile_contact, "failure"):
        raise scene.profile_contact.failure()
    return scene


def _wheel_moment(source, scene_name, side, omega, fixed, method, level, options, solve_one, kw):
    """(moment about the axle [N m], sum of the estimate's normal forces [N]) of wheel ``side`` of the scene of table
    ``source`` at pitch velocity ``omega`` [rad/s]: every patch (``patch = "all"``) solved by ``solve_one`` as a
    scene with that pitch velocity given, so that its normal forces meet the wheel's vertical force with the
    chain's own creep forces where the chain solves the patch's gap (:mod:`.wheelset_vertical`), each patch's
    forces composed at its reference point; ``scene_name`` names the scene in the error."""
    sub = _loaded(dict(_source(source, side, omega, **fixed), outputs=list(NEED)))
    contacts = sub.profile_contact.contacts
    r = solve_one(sub, method, level, options, validate=False, **kw)
    values = [np.atleast_1d(r[q].values) for q in NEED]
    if len(values[0]) != len(contacts):
        raise SolverError(f"scene {scene_name!r}: the {side} wheel's result has {len(values[0])} patches, its scene "
                          f"{len(contacts)}")
    moment = sum(axle_moment(pc, *(float(v[i]) for v in values)) for i, pc in enumerate(contacts))
    return moment, sum(float(pc.normal_force) for pc in contacts)


# whole scene: a solve driver above the stage hooks; it reloads the scene from its table and solves it
def solve_free_pitch(scene, method, level, options, *, solve_one, validate: bool = True, **kw):
    """Solve ``scene`` at the pitch velocity that balances the axle's moment.

    For a pitch velocity omega both wheels are loaded with it given and every patch (``wheelset.patch = "all"``)
    solved through the pipeline, whose normal forces then meet each wheel's vertical force with the chain's own
    creep forces where the chain solves the patch's gap (:mod:`.wheelset_vertical`); the moment about the axle is
    the sum of :func:`axle_moment` over the patches of both wheels (:func:`_wheel_moment`). The secant method finds
    its root to :data:`MOMENT_TOL` of (sum of both wheels' normal forces at the iterate) x (the scene's rolling
    radius). The scene is then loaded again
    with that pitch velocity given and solved: its result is the result of that scene, with the attributes
    ``wheelset_pitch_velocity`` [rad/s], ``wheelset_axle_moment`` [N m] (the moment left, of the forces of the
    last iterate's solves) and ``wheelset_axle_moment_tolerance`` [N m]; its ``wall_time`` is the whole
    search's."""
    t0 = time.perf_counter()
    pc = scene.profile_contact
    w0 = float(pc.free_pitch)
    w1 = w0 * (1.0 + 1e-4)
    fixed = {"patch": "all"}
    if pc.balanced_roll is not None:   # balance once: the roll of the scene as loaded, half the axle load per wheel
        fixed.update(roll_angle=pc.balanced_roll, vertical_force=pc.vertical_force)
    inner = dict(method=method, level=level, options=options, solve_one=solve_one, kw=kw)
    loads = {}

    def moment(w):
        total = 0.0
        for side in ("right", "left"):
            m, loads[side] = _wheel_moment(scene.source, scene.name, side, w, fixed, **inner)
            total += m
        return total

    def tolerance():   # the normal forces of the last iterate (the estimate's move with the creepages)
        return MOMENT_TOL * sum(loads.values()) * float(pc.rolling_radius)

    x0, x1 = w0, w1
    f0, f1 = moment(x0), moment(x1)
    for _ in range(MAX_STEPS):
        if abs(f1) <= tolerance() or f1 == f0:
            break
        x0, f0, x1 = x1, f1, x1 - f1 * (x1 - x0) / (f1 - f0)
        f1 = moment(x1)
    else:
        raise SolverError(f"scene {scene.name!r}: no pitch velocity balances the axle's moment in {MAX_STEPS} "
                          f"steps (last {x1:.9g} rad/s, moment {f1:.3g} N m)")
    given = {k: v for k, v in fixed.items() if k != "patch"}
    final = load_scene(_source(scene.source, pc.side, x1, **given))
    out = solve_one(final, method, level, options, validate=validate, **kw)
    # the whole search is the solve's work (its wall time: the loads and every solve of both wheels)
    out.attrs.update({"wheelset_pitch_velocity": float(x1), "wheelset_axle_moment": float(f1),
                      "wheelset_axle_moment_tolerance": float(tolerance()), "wall_time": time.perf_counter() - t0})
    if pc.balanced_roll is not None:
        out.attrs.update(wheelset_roll_angle=float(pc.balanced_roll), wheelset_roll_balance=pc.roll_balance)
    return out


def _approach_correction(source, vertical_force, side, roll, method, level, options, solve_one, host):
    """(height correction [m], normal model, patches) of wheel ``side`` of the scene of table ``source`` at ``roll``
    [rad] and the wheel's ``vertical_force`` [N]: (delta - delta_Hertz) /
    cos(contact angle), delta the chain's normal approach (result attribute ``<normal model>_approach``) at the
    normal force the solve settled on (its own creep forces balancing the vertical force,
    :mod:`.wheelset_vertical`) and delta_Hertz the Hertz-equivalent one at the estimate's normal force, the one
    the Hertz-equivalent heights (:func:`railtherm.input.wheelset_profile.roll_height_mismatch`) take; None for
    the correction when the chain's normal model is Hertz-equivalent or reports no approach."""
    src = _source(source, side, float(source["wheelset"]["pitch_velocity"]), roll_angle=float(roll),
                  vertical_force=float(vertical_force))
    sub = _loaded(dict(src, outputs=["normal_force"]))
    r = solve_one(sub, method, level, options, validate=False, host=host)
    model = dict(part.split(":", 1) for part in str(r.attrs.get("stages", "")).split()).get("normal", "")
    delta = r.attrs.get(f"{model}_approach")
    if model in HERTZ_EQUIVALENT or delta is None:
        return None, model, sub.profile_contact.patches
    q = sub.profile_contact
    hertz = hertz_from_curvatures(*q.hertz_curvatures, float(q.normal_force), contact_modulus(sub.wheel, sub.rail))
    return (float(delta) - hertz.approach) / math.cos(q.contact_angle), model, q.patches


# whole scene: a solve driver above the stage hooks; it reloads the scene from its table and solves it
def solve_balanced_roll(scene, method, level, options, *, solve_one, validate: bool = True, host=None, peers=None,
                        **kw):
    """Solve ``scene`` (``roll_angle = "balance"``) at the roll that balances the wheels' heights with the
    chain's own normal approaches.

    One patch per scene, pitch velocity given: the scene comes loaded with the roll at which both wheels'
    Hertz-equivalent heights agree (:func:`railtherm.input.wheelset_profile.balance_roll`). A chain whose
    normal stage solves the patch's own gap (kalker) reports its normal approach delta at the normal force its
    own creep forces balance the wheel's vertical force with (:mod:`.wheelset_vertical`); each wheel's height
    is then corrected by (delta - delta_Hertz) / cos(contact angle), delta_Hertz at the estimate's normal force
    (:func:`_approach_correction`), and the roll is moved until the corrected heights agree (chord steps with
    the Hertz heights' slope). A chain on the Hertz-equivalent ellipse keeps the loaded roll. The result's attributes ``wheelset_roll_angle``
    [rad], ``wheelset_roll_balance`` (whose forces), ``wheelset_roll_angle_hertz`` [rad] and
    ``wheelset_roll_height_mismatch`` [m] say which."""
    t0 = time.perf_counter()
    pc = scene.profile_contact
    hertz_roll = roll = float(pc.balanced_roll)
    balance, mismatch = ROLL_BALANCE, 0.0
    inner = dict(method=method, level=level, options=options, solve_one=solve_one, host=host)
    loaded = (scene.source, pc.vertical_force)
    right, model, n_right = _approach_correction(*loaded, "right", roll, **inner)
    if right is not None:
        left, _, n_left = _approach_correction(*loaded, "left", roll, **inner)
        if max(n_right, n_left) > 1:
            balance = (f"{ROLL_BALANCE}; the chain's normal stage ({model}) is not used: a wheel has "
                       f"{max(n_right, n_left)} patches, and one scene carries one")
        else:
            slope = (roll_height_mismatch(scene, roll + 1e-6) - roll_height_mismatch(scene, roll - 1e-6)) / 2e-6
            for _ in range(MAX_STEPS):
                mismatch = roll_height_mismatch(scene, roll) + right - left
                if abs(mismatch) <= HEIGHT_TOL:
                    break
                roll -= mismatch / slope
                right = _approach_correction(*loaded, "right", roll, **inner)[0]
                left = _approach_correction(*loaded, "left", roll, **inner)[0]
            else:
                raise SolverError(f"scene {scene.name!r}: key 'wheelset.roll_angle' = 'balance': no roll balances "
                                  f"the wheels' heights with {model}'s approaches in {MAX_STEPS} steps (last "
                                  f"{roll:.9g} rad, mismatch {mismatch:.3g} m)")
            balance = (f"the chain's normal stage ({model}): each wheel's Hertz-equivalent height corrected by "
                       f"({model}'s normal approach at the normal force its own creep forces balance the vertical "
                       f"force with - Hertz's at the estimate's) / cos(contact angle)")
    final = load_scene(_source(scene.source, pc.side, float(scene.source["wheelset"]["pitch_velocity"]),
                               roll_angle=roll, vertical_force=float(pc.vertical_force)))
    out = solve_one(final, method, level, options, validate=validate, host=host, peers=peers, **kw)
    out.attrs.update({"wheelset_roll_angle": roll, "wheelset_roll_balance": balance,
                      "wheelset_roll_angle_hertz": hertz_roll, "wheelset_roll_height_mismatch": float(mismatch),
                      "wall_time": time.perf_counter() - t0})
    return out
