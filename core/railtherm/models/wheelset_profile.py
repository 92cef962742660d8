"""Core normal model "wheelset-profile": the Hertz-equivalent patch of a wheelset on real profiles.

A scene with a ``[scene.wheelset]`` on profiles carries the contact search's patch
(:class:`railtherm.input.wheelset_profile.ProfileContact`): its non-Hertzian gap (for ``kalker``),
its normal force from the wheel's vertical force, and its creepages. Hertz-based chains (Hertz +
FASTSIM with any thermal model) cannot take the non-Hertzian gap; this model gives them the ellipse
that vehicle-dynamics codes use, from the two profiles' curvatures at the contact point (gap
A x^2 + B y^2 with A, B :attr:`ProfileContact.hertz_curvatures`), at the scene's normal force, and says
so in its diagnostics (``patch_shape``). The creepages reach the tangential stage through the scene.
"""
from __future__ import annotations

import dataclasses

from ..contract.grid import BASE_CELLS
from ..contract.capabilities import Capabilities
from ..contract.options import Option
from ..contract.stages import NormalContactModel
from .hertz import hertz_geometry, hertz_patch

__all__ = ["WheelsetProfileHertz"]


class WheelsetProfileHertz(NormalContactModel):
    """Hertz-equivalent ellipse of a profile wheelset's patch (the profiles' curvatures at the contact)."""

    name = "wheelset-profile"
    description = ("wheelset on real profiles: the contact search's patch as the Hertz-equivalent ellipse from "
                   "the profiles' curvatures at the contact point (vehicle-dynamics practice), at the normal "
                   "force from the wheel's vertical force")
    capabilities = Capabilities(contacts=frozenset({"gap", "ellipse"}),
                                provides=frozenset({"pressure", "normal_force", "semi_axis_a", "semi_axis_b",
                                                    "contact_area", "max_pressure"}))
    options = {"cells": Option(BASE_CELLS, "cells along 2a at level 0", minimum=1)}

    def supports(self, scene, level):
        if getattr(scene, "profile_contact", None) is None:
            return "model 'wheelset-profile' needs a [wheelset] table on profiles (wheel_profile, rail_profile, ...)"
        return super().supports(scene, level)

    def compute_patch(self, scene, level, options):
        pc = scene.profile_contact
        geometry = hertz_geometry(scene.wheel, scene.rail, "ellipse", scene.normal_force, penetration=scene.penetration,
                                  curvatures=pc.hertz_curvatures, scene_name=scene.name)
        patch = hertz_patch(*geometry, level, int(options.get("cells") or BASE_CELLS),
                            label=f"scene {scene.name!r}, model {self.name!r}")
        diag = {**patch.diagnostics, "patch_shape": "Hertz-equivalent ellipse from the profiles' curvatures",
                "curvature_A": pc.hertz_curvatures[0], "curvature_B": pc.hertz_curvatures[1],
                "contact_angle": pc.contact_angle, "contact_position_rail": pc.contact_position_rail,
                "patches_found": pc.patches, "patch": pc.patch}
        return dataclasses.replace(patch, diagnostics=diag)
