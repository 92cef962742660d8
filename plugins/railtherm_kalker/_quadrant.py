"""Kernels of uniform loads on rectangular elements from one quadrant of offsets.

The influence coefficients at all element offsets are second differences of corner functions on the lattice of
element corners (:mod:`railtherm_kalker.influence`). The kernels are even in x and y (Love's 1/r, the
Boussinesq-Cerruti xx and yy) or odd in both (xy), so the corners of one quadrant give them all: a quarter of the
logarithms, and the full kernels, the rolling differences and the circulant placements are built from the quadrant
without full-size intermediates (:func:`railtherm_kalker.tangential_model.rolling_operator_kernels`,
:func:`railtherm_kalker.influence.normal_operator`).
"""
from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["quadrant_differences", "mirror_quadrant", "place_even", "tangential_quadrants", "place_rolling",
           "ROLLING_EXTRA"]

#: offsets beyond the element grid along x that the rolling differences need (up to the second order) [1]
ROLLING_EXTRA = 2


def _second_difference(F: np.ndarray) -> np.ndarray:
    """Corner sum F(x+, y+) - F(x-, y+) - F(x+, y-) + F(x-, y-) over each element of the lattice."""
    return F[1:, 1:] - F[:-1, 1:] - F[1:, :-1] + F[:-1, :-1]


@functools.lru_cache(maxsize=4)
def _quadrant_differences_cached(nx: int, ny: int, dx: float, dy: float) -> tuple:
    """:func:`quadrant_differences`, kept for the grid: the normal and the rolling operator of a grid share it (its
    logarithms are a third of their set-up). Read-only arrays."""
    out = quadrant_differences(nx, ny, dx, dy)
    for a in out:
        a.flags.writeable = False
    return out


def quadrant_differences(nx: int, ny: int, dx: float, dy: float) -> tuple:
    """Second differences of the corner functions ``x asinh(y/x)``, ``y asinh(x/y)`` and ``-r`` over the elements at
    the offsets i = 0 ... nx - 1, j = 0 ... ny - 1 (one quadrant) [m].

    The first two are odd in x and in y and their differences even; ``-r`` is even and its difference odd in each
    (zero at i = 0 or j = 0). The corners (m + 1/2) dx, (l + 1/2) dy are evaluated once, the row and column at
    -1/2 by the symmetry: the kernels at all offsets are these mirrored (:func:`mirror_quadrant`), from a quarter of
    the corners and without full-size intermediates. Love's 1/r is the sum of the first two; the Boussinesq-Cerruti
    kernels combine all three (:func:`railtherm_kalker.influence.tangential_kernels`).
    """
    xs = (np.arange(nx) + 0.5) * dx
    ys = (np.arange(ny) + 0.5) * dy
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    R = np.hypot(X, Y)
    out = []
    for F, sign in ((X * np.log((Y + R) / X), -1.0), (Y * np.log((X + R) / Y), -1.0), (-R, 1.0)):
        E = np.empty((nx + 1, ny + 1))
        E[1:, 1:] = F
        E[0, 1:] = sign * F[0]
        E[1:, 0] = sign * F[:, 0]
        E[0, 0] = F[0, 0]                       # sign * sign
        out.append(_second_difference(E))
    return tuple(out)


def mirror_quadrant(q: np.ndarray, hx: int, hy: int, odd: bool = False) -> np.ndarray:
    """The kernel over the offsets -(hx - 1) ... hx - 1, -(hy - 1) ... hy - 1 from its quadrant q (offsets >= 0),
    even in x and y, or odd in both (``odd``)."""
    s = -1.0 if odd else 1.0
    top = np.concatenate([s * q[hx - 1:0:-1, :hy], q[:hx, :hy]], axis=0)
    return np.concatenate([s * top[:, hy - 1:0:-1], top], axis=1)


def place_even(q: np.ndarray, hx: int, hy: int, mx: int, my: int) -> np.ndarray:
    """The even kernel of quadrant q over the offsets -(hx - 1) ... hx - 1 (and y likewise) placed circulantly on an
    (mx, my) grid (offset o at o mod M; with 2 h - 2 = M the offsets +-M/2 coincide and hold one value)."""
    emb = np.zeros((mx, my))
    emb[:hx, :hy] = q[:hx, :hy]
    emb[mx - hx + 1:, :hy] = q[hx - 1:0:-1, :hy]
    emb[:, my - hy + 1:] = emb[:, hy - 1:0:-1]
    return emb


def tangential_quadrants(nx: int, ny: int, dx: float, dy: float, shear_modulus: float, poisson_ratio: float,
                         differences: tuple | None = None) -> dict:
    """The Boussinesq-Cerruti kernels of :func:`railtherm_kalker.influence.tangential_kernels` at the offsets
    i = 0 ... nx - 1, j = 0 ... ny - 1 [m/Pa]: ``xx`` and ``yy`` even in x and y, ``xy`` odd in both
    (:func:`mirror_quadrant`). ``differences``: the corner differences (:func:`quadrant_differences`) of at least
    this quadrant, when already computed."""
    nu, c = float(poisson_ratio), 1.0 / (math.pi * shear_modulus)
    if differences is None:
        xa, ya, mr = quadrant_differences(nx, ny, dx, dy)
    else:
        xa, ya, mr = (a[:nx, :ny] for a in differences)
    inv_r = xa + ya
    return {"xx": c * ((1.0 - nu) * inv_r + nu * ya), "xy": c * nu * mr, "yy": c * ((1.0 - nu) * inv_r + nu * xa)}


def place_rolling(qxx, qxy, qyy, nx, ny, order, dx, out):
    """The rolling kernels (xx, xy, yy; :func:`railtherm_kalker.influence.rolling_kernel`) at the offsets
    -(nx - 1) ... nx - 1 (and y likewise) from the Boussinesq-Cerruti quadrants (offsets 0 ... nx - 1 + order),
    placed at o mod M in out (3, M_x, M_y), which is zero elsewhere (M_y >= 2 ny - 1: the y offsets do not
    overlap). Vectorised numpy: called once per grid (the operator is cached), a compiled pass would cost more to
    compile than it saves; each value is the difference's terms summed from 0 in the order s = 0, 1, 2.

    Parameters
    ----------
    qxx, qxy, qyy : ndarray (>= nx + order, >= ny)
        Quadrants of the Boussinesq-Cerruti kernels [1/Pa] (:func:`tangential_quadrants`).
    nx, ny : int
        Elements along x and y.
    order : {1, 2}
        Order of the rolling difference.
    dx : float
        Element length along x [m].
    out : ndarray (3, M_x, M_y)
        Zeroed output, filled in place [1/Pa/m]."""
    mx, my = out.shape[1], out.shape[2]
    if order == 1:
        w = (-1.0 / dx, 1.0 / dx)
    else:
        w = (-3.0 / (2.0 * dx), 4.0 / (2.0 * dx), -1.0 / (2.0 * dx))
    ox = np.arange(-(nx - 1), nx)
    vxx, vxy, vyy = (np.zeros((ox.size, ny)) for _ in range(3))
    for s, ws in enumerate(w):
        o = ox + s
        a = np.abs(o)
        vxx += ws * qxx[a, :ny]
        vxy += (ws * np.sign(o).astype(float))[:, None] * qxy[a, :ny]
        vyy += ws * qyy[a, :ny]
    ix = ox % mx
    for c, v, odd in ((0, vxx, False), (1, vxy, True), (2, vyy, False)):
        out[c, ix, :ny] = v
        out[c, ix[:, None], my - np.arange(1, ny)] = -v[:, 1:] if odd else v[:, 1:]
