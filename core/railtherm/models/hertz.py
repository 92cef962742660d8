"""Core contact model "hertz": the analytic Hertz patch (ellipse or line)."""
from __future__ import annotations

import math

from ..errors import Refused
from ..grid import BASE_CELLS, surface_grid
from ..references.hertz import (contact_modulus, hertz_from_curvatures, hertz_from_penetration,
                                hertz_from_semi_axes, hertz_line)
from ..stages import Capabilities, ContactModel, ContactPatch, Option
from .shapes import cell_average


def hertz_geometry(scene) -> tuple[float, float | None, float, float]:
    """Semi-axes a, b [m], peak pressure p0 [Pa] and normal force [N or N/m] of a scene's Hertz patch.

    Raises :class:`railtherm.Refused` when Hertz theory gives no patch (zero load, rigid-rigid,
    penetration on a line contact).
    """
    e_star = contact_modulus(scene.wheel, scene.rail)
    if scene.normal_force is not None and scene.normal_force <= 0.0:
        raise Refused(f"scene {scene.name!r}: normal_force = {scene.normal_force!r} N gives no contact patch "
                      "(Hertz needs a load > 0); nothing is loaded or heated")
    if not math.isfinite(e_star):
        raise Refused(f"scene {scene.name!r}: both bodies are rigid; Hertz needs at least one elastic body")
    if scene.contact_shape == "line":
        if scene.normal_force is None:
            raise Refused(f"scene {scene.name!r}: a Hertz line contact on a half-plane has no finite approach; "
                          "penetration is defined only for a strip of finite depth: give normal_force [N/m], "
                          "or use method 'fem'")
        a, p0 = hertz_line(scene.normal_force, scene.wheel_radius, e_star)
        return a, None, p0, scene.normal_force
    if scene.semi_axes is not None:
        h = hertz_from_semi_axes(*scene.semi_axes, scene.normal_force)
    elif scene.normal_force is not None:
        h = hertz_from_curvatures(*scene.curvatures, scene.normal_force, e_star)
    else:
        h = hertz_from_penetration(*scene.curvatures, scene.penetration, e_star)
    return h.a, h.b, h.max_pressure, h.normal_force


class HertzContact(ContactModel):
    """Hertz's elastic half-space patch: semi-axes from the scene or from the gap curvatures
    (complete elliptic integrals), pressure p0 sqrt(1 - x²/a² - y²/b²) averaged exactly over each cell.

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, ch. 4. doi:10.1017/CBO9781139171731
    """

    name = "hertz"
    exact_reference = "hertz"
    description = "analytic Hertz contact patch (ellipse from semi-axes or curvatures; line contact)"
    capabilities = Capabilities(provides=frozenset({"pressure", "normal_force", "semi_axis_a", "semi_axis_b",
                                                    "max_pressure"}))
    options = {"cells": Option(BASE_CELLS, "cells along 2a at level 0", minimum=1)}

    def compute_patch(self, scene, level, options):
        a, b, p0, n = hertz_geometry(scene)
        try:
            grid = surface_grid(a, b, level, int(options.get("cells") or BASE_CELLS))
        except Refused as exc:  # over the cell budget: name the scene
            raise Refused(f"scene {scene.name!r}, model 'hertz': {exc}", kind=exc.kind) from None
        pressure = p0 * cell_average(grid, "hertz", a, b)
        # closed form (the eccentricity's root is found to round-off by brentq, which raises otherwise)
        diag = {"converged": True, "iterations": 0, "residual": 0.0}
        return ContactPatch(grid=grid, normal_force=n, a=a, b=b, max_pressure=p0, pressure=pressure,
                            diagnostics=diag)
