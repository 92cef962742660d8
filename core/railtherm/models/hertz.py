"""Core contact model "hertz": the analytic Hertz patch (ellipse or line), and the semi-axes, peak pressure
and load of a scene's contact that it and the other Hertz-based normal models start from (the closed forms of
:mod:`railtherm.references.hertz` applied to the materials, shape and load the models pass from their scene).
"""
from __future__ import annotations

import math

from ..contract.capabilities import Capabilities
from ..contract.errors import Refused
from ..contract.grid import BASE_CELLS
from ..contract.options import Option
from ..contract.results import ContactPatch
from ..contract.stages import NormalContactModel
from ..physics.elastic import contact_modulus
from ..physics.hertz import hertz_pressure_grid

__all__ = ["HertzContact", "hertz_geometry", "hertz_patch", "scene_semi_axis"]


def hertz_geometry(wheel, rail, shape: str, normal_force: float | None, *, penetration: float | None = None,
                   semi_axes: tuple[float, float] | None = None, curvatures: tuple[float, float] | None = None,
                   wheel_radius: float | None = None, scene_name: str | None = None
                   ) -> tuple[float, float | None, float, float]:
    """Semi-axes, peak pressure and normal force of a Hertz patch.

    The patch comes from the ``semi_axes`` (pressure from the load), the gap ``curvatures`` and
    ``normal_force`` or ``penetration`` (complete elliptic integrals), or a line contact's
    ``wheel_radius`` and load per width.

    Parameters
    ----------
    wheel, rail : Material-like
        With ``shear_modulus`` [Pa], ``poisson_ratio`` [1] and ``rigid``.
    shape : {"ellipse", "line"}
        Contact shape.
    normal_force : float or None
        Normal force [N] ([N/m] for a line contact); None when ``penetration`` is given.
    penetration : float, optional
        Approach of the two bodies [m] (an ellipse given by its curvatures).
    semi_axes : (float, float), optional
        Given semi-axes a, b [m].
    curvatures : (float, float), optional
        Gap curvatures A, B [1/m].
    wheel_radius : float, optional
        Wheel radius of a line contact [m].
    scene_name : str, optional
        Name of the scene, for messages.

    Returns
    -------
    a : float
        Semi-axis along rolling [m].
    b : float or None
        Lateral semi-axis [m]; None for a line contact.
    p0 : float
        Peak pressure [Pa].
    normal_force : float
        [N] ([N/m] for a line contact).

    Raises
    ------
    railtherm.Refused
        When Hertz theory gives no patch (zero load, rigid-rigid, penetration on a line contact).

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, sections 4.2-4.3. doi:10.1017/CBO9781139171731
    """
    # here, not at the top: the closed forms load scipy.optimize (about 1 s), which the first Hertz patch
    # needs but registering core's models in a plugin host must not pay
    from ..references.hertz import hertz_from_curvatures, hertz_from_penetration, hertz_from_semi_axes, hertz_line
    e_star = contact_modulus(wheel, rail)
    if normal_force is not None and normal_force <= 0.0:
        raise Refused(f"scene {scene_name!r}: normal_force = {normal_force!r} N gives no contact patch "
                      "(Hertz needs a load > 0); nothing is loaded or heated")
    if not math.isfinite(e_star):
        raise Refused(f"scene {scene_name!r}: both bodies are rigid; Hertz needs at least one elastic body")
    if shape == "line":
        if normal_force is None:
            raise Refused(f"scene {scene_name!r}: a Hertz line contact on a half-plane has no finite approach; "
                          "penetration is defined only for a strip of finite depth: give normal_force [N/m], "
                          "or use method 'fem'")
        a, p0 = hertz_line(normal_force, wheel_radius, e_star)
        return a, None, p0, normal_force
    if semi_axes is not None:
        h = hertz_from_semi_axes(*semi_axes, normal_force)
    elif normal_force is not None:
        h = hertz_from_curvatures(*curvatures, normal_force, e_star)
    else:
        h = hertz_from_penetration(*curvatures, penetration, e_star)
    return h.a, h.b, h.max_pressure, h.normal_force


def scene_semi_axis(heat_source, wheel, rail, shape: str, normal_force: float | None, *,
                    penetration: float | None = None, semi_axes: tuple[float, float] | None = None,
                    curvatures: tuple[float, float] | None = None, wheel_radius: float | None = None
                    ) -> float | None:
    """Semi-axis a along rolling [m] known from a scene before any stage runs, or None.

    A given heat source's ``semi_axes`` or ``half_width``, else the given ``semi_axes``, else the
    Hertz patch (:func:`hertz_geometry`); None when there is no Hertz patch (no load, rigid bodies, a
    line contact given by penetration).

    Parameters
    ----------
    heat_source : GivenHeatSource-like or None
        A given heat source, with ``semi_axes`` [m] or ``half_width`` [m].
    wheel, rail, shape, normal_force, penetration, semi_axes, curvatures, wheel_radius
        As :func:`hertz_geometry` (materials; shape; [N] or [N/m]; [m]; [m]; [1/m]; [m]).

    Returns
    -------
    float or None
        a [m].
    """
    if heat_source is not None:
        if getattr(heat_source, "semi_axes", None) is not None:
            return float(heat_source.semi_axes[0])
        return float(heat_source.half_width)
    if semi_axes is not None:
        return float(semi_axes[0])
    try:
        return float(hertz_geometry(wheel, rail, shape, normal_force, penetration=penetration,
                                    curvatures=curvatures, wheel_radius=wheel_radius)[0])
    except (Refused, ValueError, TypeError, AttributeError, ZeroDivisionError):
        return None


def hertz_patch(a: float, b: float | None, p0: float, normal_force: float, level: int, cells: int | None = None,
                *, label: str):
    """A Hertz contact patch (:func:`hertz_geometry`'s semi-axes, peak pressure and load) on the surface
    grid of ``level``.

    Parameters
    ----------
    a, b, p0, level
        As :func:`railtherm.physics.hertz_pressure_grid`: semi-axes [m] (b None for a line contact), peak
        pressure [Pa], grid level k [1].
    normal_force : float
        Normal force [N] ([N/m] for a line contact).
    cells : int, optional
        Cells along 2a at level 0 [1] (default :data:`railtherm.contract.grid.BASE_CELLS`).
    label : str
        Who asks (scene and model), prefixed to a refusal.

    Returns
    -------
    railtherm.ContactPatch
        Grid, normal force [N], semi-axes [m], peak pressure [Pa] and cell-averaged pressure [Pa].

    Raises
    ------
    railtherm.Refused
        The grid is over the cell budget (kind "budget").
    """
    try:
        grid, pressure = hertz_pressure_grid(a, b, p0, level, int(cells or BASE_CELLS))
    except Refused as exc:  # over the cell budget: name the scene
        raise Refused(f"{label}: {exc}", kind=exc.kind) from None
    # closed form (the eccentricity's root is found to round-off by brentq, which raises otherwise)
    diag = {"converged": True, "iterations": 0, "residual": 0.0}
    return ContactPatch(grid=grid, normal_force=normal_force, a=a, b=b, max_pressure=p0, pressure=pressure,
                        diagnostics=diag)


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
