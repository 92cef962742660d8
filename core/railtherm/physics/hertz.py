"""Hertz patch on a surface grid: cell-averaged pressure of given semi-axes and peak pressure, and their
rescaling to another normal force.

The semi-axes and peak pressure of a scene's contact come from the closed forms of
:mod:`railtherm.references.hertz`, applied by :func:`railtherm.models.hertz.hertz_geometry`.
"""
from __future__ import annotations

import math

from ..contract.errors import Refused
from ..contract.grid import BASE_CELLS, surface_grid
from ..contract.results import ContactPatch
from .averaging import GAUSS_POINTS, cell_average

__all__ = ["hertz_patch", "hertz_pressure_grid", "rescale_hertz_patch"]


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
    g = surface_grid(a, b, level, cells)
    return g, p0 * cell_average(g, "hertz", a, b, gauss or GAUSS_POINTS)


def hertz_patch(a: float, b: float | None, p0: float, normal_force: float, level: int, cells: int | None = None,
                *, label: str):
    """A Hertz contact patch (:func:`railtherm.models.hertz.hertz_geometry`'s semi-axes, peak pressure and load) on the surface
    grid of ``level``.

    Parameters
    ----------
    a, b, p0, level
        As :func:`hertz_pressure_grid`: semi-axes [m] (b None for a line contact), peak pressure [Pa],
        grid level k [1].
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
