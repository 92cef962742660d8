"""The scenes of a wheelset's patches: what a scene of several patches (``wheelset.patch = "all"``) may ask, and
one scene per loaded patch (its gap, normal force and creepages) for the chain to solve
(:mod:`railtherm.solving.wheelset_patches`)."""
from __future__ import annotations

import dataclasses

from .checks import gap_powers, quadratic_curvatures
from .wheelset_profile import ProfileContacts, _fail

__all__ = ["PATCH_DEFAULT_OUTPUTS", "TOTALS_NEED", "check_patch_outputs", "patch_scenes"]

#: the outputs a scene of several patches gives by default (per patch, and the wheel's totals)
PATCH_DEFAULT_OUTPUTS = ("contact_position_rail", "contact_angle", "normal_force", "max_pressure", "contact_area",
                         "creep_force_x", "creep_force_y", "wheel_force_x", "wheel_force_y", "wheel_force_z",
                         "max_surface_temperature")
#: what the wheel's totals need of each patch
TOTALS_NEED = ("normal_force", "creep_force_x", "creep_force_y", "contact_angle")


def check_patch_outputs(scene_name: str, outputs, pc, dims_of) -> None:
    """SceneError unless ``outputs`` suit the scene's wheelset: the wheel's totals (``wheel_force_x/y/z``) need
    ``patch = "all"``, and a scene of several patches asks only quantities over the body and the patch's grid
    (``dims_of(name)`` within ("body", "x", "y", "z"): each patch's field is kept on its own grid,
    :mod:`railtherm.contract.patch_grid`), no pass history."""
    totals = [o for o in outputs if o.startswith("wheel_force_")]
    if not isinstance(pc, ProfileContacts):
        if totals:
            _fail(scene_name, "outputs", totals[0], "the wheel's total force over its patches only with "
                  "wheelset.patch = \"all\" (a scene of one patch: its normal_force, creep_force_x/y)")
        return
    other = [o for o in outputs if set(dims_of(o)) - {"body", "x", "y", "z"}]
    if other:
        _fail(scene_name, "outputs", other[0], "a quantity over the body and the patch's grid in a scene of several "
              "patches (wheelset.patch = \"all\"), e.g. " + ", ".join(PATCH_DEFAULT_OUTPUTS)
              + ", pressure; ask a pass history of one patch with wheelset.patch = 1, 2 or 3")


def patch_scenes(scene, outputs) -> list:
    """One scene per loaded patch of a ``patch = "all"`` scene: the patch's gap, normal force (its share) and
    creepages, asking ``outputs``; its source names the patch, so each has a hash of its own."""
    creepage = type(scene.creepage)   # the scene's Creepage (the first patch's)
    out = []
    for pc in scene.profile_contact.contacts:
        gap = gap_powers(pc.gap_coefficients)
        quad = quadratic_curvatures(gap)
        source = dict(scene.source, wheelset=dict(scene.source.get("wheelset", {}), patch=pc.patch))
        out.append(dataclasses.replace(scene, profile_contact=pc, contact_shape="ellipse" if quad else "gap",
                                       curvatures=quad, gap_coefficients=gap, normal_force=pc.normal_force,
                                       kinematics=dataclasses.replace(scene.kinematics, creepage=creepage(*pc.creepage)),
                                       outputs=tuple(outputs), source=source))
    return out
