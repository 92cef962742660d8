"""The block's fields read off on the patch grid, and the result of one body's block.

:func:`bilinear` and :func:`linear_rows` sample node or cell fields at the patch grid's points;
:func:`surface_from_top_cells` reconstructs the surface temperature of the steady scheme's cell
grid from its two top cells and the surface flux; :class:`BlockResult` holds what one body's run
returns (rises above the bulk temperature).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["BlockResult", "bilinear", "linear_rows", "surface_from_top_cells"]


@dataclass
class BlockResult:
    """Result of one body's block computation (temperature rises).

    Attributes
    ----------
    surface : ndarray (nxp, nyp) or (nxp,)
        Surface rise on the patch grid points [K].
    z : ndarray (nz,)
        Depths of the depth field [m].
    depth : ndarray (nxp, nz)
        Rise at the patch centre line y = 0 against depth [K].
    diagnostics : dict
        Solver diagnostics (scheme, cells, energies, heat balance, iterations, ...).
    """

    surface: np.ndarray
    z: np.ndarray
    depth: np.ndarray
    diagnostics: dict = field(default_factory=dict)


def bilinear(xn, yn, F, xq, yq):
    """Bilinear interpolation of F (len(xn), len(yn)) on a tensor grid at points xq (m,), yq (n,)."""
    ix = np.clip(np.searchsorted(xn, xq) - 1, 0, len(xn) - 2)
    iy = np.clip(np.searchsorted(yn, yq) - 1, 0, len(yn) - 2)
    tx = np.clip((xq - xn[ix]) / (xn[ix + 1] - xn[ix]), 0.0, 1.0)[:, None]
    ty = np.clip((yq - yn[iy]) / (yn[iy + 1] - yn[iy]), 0.0, 1.0)[None, :]
    f00 = F[np.ix_(ix, iy)]
    f10 = F[np.ix_(ix + 1, iy)]
    f01 = F[np.ix_(ix, iy + 1)]
    f11 = F[np.ix_(ix + 1, iy + 1)]
    return (1 - tx) * (1 - ty) * f00 + tx * (1 - ty) * f10 + (1 - tx) * ty * f01 + tx * ty * f11


def linear_rows(xn, F, xq):
    """Linear interpolation along axis 0 of F (len(xn), ...) at xq."""
    ix = np.clip(np.searchsorted(xn, xq) - 1, 0, len(xn) - 2)
    tx = np.clip((xq - xn[ix]) / (xn[ix + 1] - xn[ix]), 0.0, 1.0)
    return (1 - tx)[:, None] * F[ix] + tx[:, None] * F[ix + 1]


def surface_from_top_cells(Q, hA, area, t1, t2, z1, z2, conductivity):
    """Surface rise of a cell-centred grid: the quadratic through the two top cells whose slope at the
    surface is the net surface flux (heat in minus convection) over lambda.

    Parameters
    ----------
    Q, hA, area : ndarray
        Heat into each top cell [W], its convective conductance [W/K] and top face [m^2] (per unit
        width in 2-D).
    t1, t2 : ndarray
        Rises of the first and second cells below the surface [K].
    z1, z2 : float
        Their centre depths [m].
    conductivity : float
        lambda [W/(m K)].

    Returns
    -------
    ndarray
        Surface rise [K].
    """
    slope = -(Q / area - hA / area * t1) / conductivity
    B = ((t2 - t1) - slope * (z2 - z1)) / (z2 ** 2 - z1 ** 2)
    return t1 - slope * z1 - B * z1 ** 2
