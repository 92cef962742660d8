"""Hertz patch of a scene: semi-axes, peak pressure and cell-averaged pressure, and its rescaling
to another normal force.

The closed forms (complete elliptic integrals, line contact) are core's exact references in
:mod:`railtherm.references.hertz`; this module applies them to a scene.
"""
from __future__ import annotations

import math

__all__ = ["hertz_geometry", "hertz_patch", "hertz_pressure_grid", "rescale_hertz_patch", "scene_semi_axis"]


def hertz_geometry(scene) -> tuple[float, float | None, float, float]:
    """Semi-axes, peak pressure and normal force of a scene's Hertz patch.

    The patch comes from the scene's ``semi_axes`` (pressure from the load), its gap ``curvatures``
    and ``normal_force`` or ``penetration`` (complete elliptic integrals), or a line contact's
    ``wheel_radius`` and load per width.

    Parameters
    ----------
    scene : Scene-like
        With ``wheel``, ``rail`` (``shear_modulus`` [Pa], ``poisson_ratio`` [1], ``rigid``),
        ``contact_shape`` ("ellipse" or "line"), ``normal_force`` [N] ([N/m] for a line) or
        ``penetration`` [m], and ``semi_axes`` [m] or ``curvatures`` [1/m] or ``wheel_radius`` [m].

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
    from ..contract.errors import Refused
    from ..references.hertz import (contact_modulus, hertz_from_curvatures, hertz_from_penetration,
                                    hertz_from_semi_axes, hertz_line)
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


def scene_semi_axis(scene) -> float | None:
    """Semi-axis a along rolling [m] known from the scene before any stage runs, or None.

    A given heat source's ``semi_axes`` or ``half_width``, else the scene's Hertz patch
    (:func:`hertz_geometry`); None when the scene has no Hertz patch (no load, rigid bodies, a line
    contact given by penetration).

    Parameters
    ----------
    scene : Scene-like
        As :func:`hertz_geometry`, optionally with ``heat_source`` (``semi_axes`` or ``half_width`` [m]).

    Returns
    -------
    float or None
        a [m].
    """
    from ..contract.errors import Refused
    hs = getattr(scene, "heat_source", None)
    if hs is not None:
        if getattr(hs, "semi_axes", None) is not None:
            return float(hs.semi_axes[0])
        return float(hs.half_width)
    if getattr(scene, "semi_axes", None) is not None:
        return float(scene.semi_axes[0])
    try:
        return float(hertz_geometry(scene)[0])
    except (Refused, ValueError, TypeError, AttributeError, ZeroDivisionError):
        return None


def rescale_hertz_patch(normal_force: float, ref_normal_force: float, ref_a: float, ref_b: float | None,
                        scaling: str = "curvatures") -> tuple[float, float | None, float]:
    """Semi-axes and peak pressure of a Hertz patch at another normal force.

    Parameters
    ----------
    normal_force : float
        New normal force N [N].
    ref_normal_force : float
        Normal force N_ref at which the reference semi-axes hold [N].
    ref_a, ref_b : float
        Reference semi-axes [m] (``ref_b`` None for a line contact, loads then per width [N/m]).
    scaling : {"curvatures", "semi_axes"}
        ``"curvatures"``: fixed gap curvatures, a, b ~ N^(1/3) (a ~ N^(1/2) on a line);
        ``"semi_axes"``: a, b fixed (the scene gives them).

    Returns
    -------
    a, b : float
        Semi-axes [m].
    p0 : float
        Peak pressure [Pa]: ``3 N / (2 pi a b)`` (``2 N / (pi a)`` on a line).

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, eqs. (4.32), (4.45). doi:10.1017/CBO9781139171731
    """
    if ref_b is None:
        s = math.sqrt(normal_force / ref_normal_force) if scaling == "curvatures" else 1.0
        a = ref_a * s
        return a, None, 2.0 * normal_force / (math.pi * a)
    s = (normal_force / ref_normal_force) ** (1.0 / 3.0) if scaling == "curvatures" else 1.0
    a, b = ref_a * s, ref_b * s
    return a, b, 3.0 * normal_force / (2.0 * math.pi * a * b)


def hertz_pressure_grid(a: float, b: float | None, p0: float, level: int = 0, cells: int | None = None,
                        gauss: int | None = None):
    """Patch grid and cell-averaged Hertz pressure for given semi-axes and peak pressure.

    Parameters
    ----------
    a, b : float
        Semi-axes [m] (b None for a line contact).
    p0 : float
        Peak pressure [Pa].
    level : int
        Grid level k [1] (:func:`railtherm.surface_grid`).
    cells : int, optional
        Cells along 2a at level 0 [1].
    gauss : int, optional
        Gauss-Legendre points across each cell in y [1] (default
        :data:`railtherm.physics.averaging.GAUSS_POINTS`).

    Returns
    -------
    grid : railtherm.SurfaceGrid
    pressure : ndarray
        Cell-averaged pressure [Pa].
    """
    from ..contract.grid import surface_grid
    from .averaging import GAUSS_POINTS, cell_average
    g = surface_grid(a, b, level, cells)
    return g, p0 * cell_average(g, "hertz", a, b, gauss or GAUSS_POINTS)


def hertz_patch(scene, level: int, cells: int | None = None, *, model: str = "hertz"):
    """The scene's Hertz contact patch on the surface grid of ``level``.

    Parameters
    ----------
    scene : Scene-like
        As :func:`hertz_geometry`.
    level : int
        Grid level k [1].
    cells : int, optional
        Cells along 2a at level 0 [1] (default :data:`railtherm.contract.grid.BASE_CELLS`).
    model : str
        Name of the model asking, for messages.

    Returns
    -------
    railtherm.ContactPatch
        Grid, normal force [N], semi-axes [m], peak pressure [Pa] and cell-averaged pressure [Pa].

    Raises
    ------
    railtherm.Refused
        No Hertz patch (see :func:`hertz_geometry`), or the grid is over the cell budget (kind
        "budget").
    """
    from ..contract.errors import Refused
    from ..contract.grid import BASE_CELLS
    from ..contract.results import ContactPatch
    a, b, p0, n = hertz_geometry(scene)
    try:
        grid, pressure = hertz_pressure_grid(a, b, p0, level, int(cells or BASE_CELLS))
    except Refused as exc:  # over the cell budget: name the scene
        raise Refused(f"scene {scene.name!r}, model {model!r}: {exc}", kind=exc.kind) from None
    # closed form (the eccentricity's root is found to round-off by brentq, which raises otherwise)
    diag = {"converged": True, "iterations": 0, "residual": 0.0}
    return ContactPatch(grid=grid, normal_force=n, a=a, b=b, max_pressure=p0, pressure=pressure, diagnostics=diag)
