"""Core contact model "hertz": the analytic Hertz patch (ellipse or line)."""
from __future__ import annotations

from ..contract.grid import BASE_CELLS
from ..physics.hertz import hertz_geometry, hertz_patch
from ..contract.capabilities import Capabilities
from ..contract.options import Option
from ..contract.stages import NormalContactModel

__all__ = ["HertzContact"]


class HertzContact(NormalContactModel):
    """Hertz's elastic half-space patch: semi-axes from the scene or from the gap curvatures
    (complete elliptic integrals), pressure p0 sqrt(1 - x²/a² - y²/b²) averaged exactly over each cell.

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, ch. 4. doi:10.1017/CBO9781139171731
    """

    name = "hertz"
    exact_reference = "hertz"
    description = "analytic Hertz contact patch (ellipse from semi-axes or curvatures; line contact)"
    capabilities = Capabilities(provides=frozenset({"pressure", "normal_force", "semi_axis_a", "semi_axis_b", "contact_area",
                                                    "max_pressure"}))
    options = {"cells": Option(BASE_CELLS, "cells along 2a at level 0", minimum=1)}

    def compute_patch(self, scene, level, options):
        geometry = hertz_geometry(scene.wheel, scene.rail, scene.contact_shape, scene.normal_force,
                                  penetration=scene.penetration, semi_axes=scene.semi_axes,
                                  curvatures=scene.curvatures, wheel_radius=scene.wheel_radius,
                                  scene_name=scene.name)
        return hertz_patch(*geometry, level, int(options.get("cells") or BASE_CELLS),
                           label=f"scene {scene.name!r}, model {self.name!r}")
