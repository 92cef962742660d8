"""Cell averages on a surface grid: analytic patch distributions and piecewise-linear nodal fields.

The Hertz semi-ellipsoid and the uniform ellipse are integrated exactly along x in each cell and with
Gauss-Legendre points across y, so the sampled field integrates to the exact total (the square-root
edge of the Hertz pressure would otherwise cost a first-order error at the patch boundary).
"""
from __future__ import annotations

import numpy as np

__all__ = ["cell_average", "exact_total", "nodal_cell_average", "GAUSS_POINTS"]

#: Gauss-Legendre points across each cell in y used by :func:`cell_average` by default [1]
GAUSS_POINTS = 8


def _hertz_x_integral(x0, x1, c, a):
    """Integral of sqrt(c^2 - (x/a)^2) dx over [x0, x1] ∩ [-c a, c a] (c >= 0), vectorised."""
    lim = c * a
    lo = np.clip(x0, -lim, lim)
    hi = np.clip(x1, -lim, lim)

    def F(x):
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.where(lim > 0, x / np.where(lim > 0, lim, 1.0), 0.0)
            s = np.clip(s, -1.0, 1.0)
            return 0.5 * a * c ** 2 * (s * np.sqrt(1.0 - s ** 2) + np.arcsin(s))

    return F(hi) - F(lo)


def _uniform_x_integral(x0, x1, c, a):
    lim = c * a
    return np.clip(np.minimum(x1, lim) - np.maximum(x0, -lim), 0.0, None)


def cell_average(grid, shape: str, a: float, b: float | None, gauss: int = GAUSS_POINTS) -> np.ndarray:
    """Cell averages of the unit-peak distribution ``shape`` on a surface grid [1].

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Surface grid (cell edges ``x_edges`` [m], ``y_edges`` [m] unless a line contact).
    shape : {"hertz", "uniform"}
        ``sqrt(1 - x^2/a^2 - y^2/b^2)`` or 1 on the ellipse (interval for a line contact).
    a, b : float
        Semi-axes [m] (b None for a line contact).
    gauss : int
        Gauss-Legendre points across each cell in y [1] (x is integrated exactly).

    Returns
    -------
    ndarray, shape ``grid.shape``
        Cell averages [1].

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, ch. 4 (Hertz pressure). doi:10.1017/CBO9781139171731
    """
    fx = _hertz_x_integral if shape == "hertz" else _uniform_x_integral
    x0, x1 = grid.x_edges[:-1], grid.x_edges[1:]
    if grid.line:
        return fx(x0, x1, np.ones_like(x0), a) / grid.dx
    g, w = np.polynomial.legendre.leggauss(int(gauss))
    y0, y1 = grid.y_edges[:-1], grid.y_edges[1:]
    out = np.zeros(grid.shape)
    for gi, wi in zip(g, w):
        yy = 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * gi  # (ny,)
        c = np.sqrt(np.clip(1.0 - (yy / b) ** 2, 0.0, None))  # (ny,)
        out += 0.5 * wi * fx(x0[:, None], x1[:, None], c[None, :], a)
    return out / grid.dx


def exact_total(shape: str, a: float, b: float | None) -> float:
    """Integral of the unit-peak distribution over the patch [m^2] ([m] for a line contact).

    Parameters
    ----------
    shape : {"hertz", "uniform"}
        Distribution, as in :func:`cell_average`.
    a, b : float
        Semi-axes [m] (b None for a line contact).

    Returns
    -------
    float
        ``2 pi a b / 3`` (Hertz) or ``pi a b`` (uniform); ``pi a / 2`` or ``2 a`` on a line.
    """
    if b is None:
        return np.pi * a / 2.0 if shape == "hertz" else 2.0 * a
    return 2.0 * np.pi * a * b / 3.0 if shape == "hertz" else np.pi * a * b


def nodal_cell_average(x_nodes, values, edges) -> np.ndarray:
    """Cell averages over ``edges`` of the piecewise-linear interpolant of nodal values.

    Beyond the first and last node the interpolant runs linearly to 0 at the next cell edge (the
    values at edges outside the nodes are 0).

    Parameters
    ----------
    x_nodes : array_like, shape (n,)
        Increasing node positions [m].
    values : array_like, shape (n,)
        Nodal values [any unit].
    edges : array_like, shape (m + 1,)
        Increasing cell edges [m].

    Returns
    -------
    ndarray, shape (m,)
        Exact cell averages of the interpolant [unit of ``values``].
    """
    x_nodes = np.asarray(x_nodes, float)
    v = np.asarray(values, float)
    xs = np.unique(np.concatenate([x_nodes, edges]))
    vs = np.interp(xs, x_nodes, v, left=0.0, right=0.0)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (vs[1:] + vs[:-1]) * np.diff(xs))])
    F = np.interp(edges, xs, cum)
    return np.diff(F) / np.diff(edges)
