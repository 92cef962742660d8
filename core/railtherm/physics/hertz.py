"""Hertz pressure on a surface grid: cell-averaged pressure of given semi-axes and peak pressure, and their
rescaling to another normal force.

The semi-axes and peak pressure of a scene's contact come from the closed forms of
:mod:`railtherm.references.hertz`, applied by :func:`railtherm.models.hertz.hertz_geometry`;
:func:`railtherm.models.hertz.hertz_patch` makes the contact patch of them.
"""
from __future__ import annotations

import math

from ..contract.grid import surface_grid
from .averaging import GAUSS_POINTS, cell_average

__all__ = ["hertz_pressure_grid", "rescale_hertz_patch"]


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
