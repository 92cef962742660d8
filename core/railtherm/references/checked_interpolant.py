"""Piecewise Chebyshev interpolation of a smooth curve, each piece checked against the curve itself.

A history of many passes sums one pass's response at many delays; long after the source has left it is a
smooth, slowly varying tail. :class:`CheckedInterpolant` replaces the curve on an interval by
polynomials of degree ``degree`` through Chebyshev points on geometrically growing pieces (the tail varies on
the scale of the delay itself). Every piece is accepted only after the interpolant agrees with the curve at
the ``degree`` points halfway (in angle) between its nodes, where the interpolation error of a smooth
function peaks, to an absolute tolerance per column; a piece that fails is halved, and a piece still failing
at the smallest width is left to the curve itself (evaluated exactly there at every call). The interpolant
is evaluated in the barycentric form (stable for any degree).

References: [1] L.N. Trefethen, Approximation Theory and Approximation Practice, SIAM, 2013, chapters 2-5
(Chebyshev points of the second kind, barycentric interpolation, convergence for analytic functions).
ISBN 978-1611972399. [2] J.-P. Berrut, L.N. Trefethen, Barycentric Lagrange interpolation, SIAM Review 46
(2004) 501-517. doi:10.1137/S0036144502417715
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CheckedInterpolant"]


def _chebyshev_points(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes x_j = cos(pi j / n) on [-1, 1], their barycentric weights, the n check points cos(pi (j + 1/2) / n))."""
    j = np.arange(n + 1)
    nodes = np.cos(math.pi * j / n)
    weights = (-1.0) ** j
    weights[[0, -1]] *= 0.5
    checks = np.cos(math.pi * (np.arange(n) + 0.5) / n)
    return nodes, weights, checks


def _barycentric(x, nodes, weights, values):
    """Barycentric interpolation at x (1-D, in [-1, 1]) through ``values`` (nodes, m) [Berrut & Trefethen (4.2)]."""
    diff = x[:, None] - nodes[None, :]
    hit = diff == 0.0
    diff[hit] = 1.0
    c = weights[None, :] / diff
    out = (c @ values) / c.sum(axis=1)[:, None]
    rows, cols = np.nonzero(hit)
    out[rows] = values[cols]
    return out


@dataclass
class _Piece:
    lo: float
    hi: float
    values: np.ndarray | None      # at the nodes, shape (degree + 1, m); None: evaluated exactly


class CheckedInterpolant:
    """The curve ``f`` on [lo, hi] as checked Chebyshev pieces (see the module docstring).

    Parameters
    ----------
    f : callable
        ``f(x) -> array (x.size, m)``, x a 1-D array of abscissae [any unit].
    lo, hi : float
        The interval, 0 < lo < hi [unit of x].
    tolerance : array_like
        Largest accepted interpolation error per column of f, shape (m,) or scalar [unit of f], > 0.
    degree : int
        Polynomial degree per piece [1].
    ratio : float
        The first pieces grow geometrically by this ratio from lo [1], > 1.
    min_width : float
        Relative width (to its left end) below which a failing piece is not halved again [1].
    """

    def __init__(self, f, lo: float, hi: float, tolerance, degree: int = 16, ratio: float = 2.0,
                 min_width: float = 1.0 / 64.0):
        if not (0.0 < lo < hi and math.isfinite(hi)):
            raise ValueError(f"need 0 < lo < hi < inf, got lo={lo!r}, hi={hi!r}")
        if not ratio > 1.0:
            raise ValueError(f"ratio must be > 1, got {ratio!r}")
        self.f, self.lo, self.hi = f, float(lo), float(hi)
        self.tolerance = np.asarray(tolerance, dtype=float)
        if not np.all(self.tolerance > 0):
            raise ValueError(f"tolerance must be > 0, got {tolerance!r}")
        self.nodes, self.weights, self._checks = _chebyshev_points(int(degree))
        self.min_width = float(min_width)
        self.evaluations = 0
        #: largest error found at the check points of the accepted pieces, relative to the tolerance [1]
        self.worst = 0.0
        edges = [self.lo]
        while edges[-1] * ratio < self.hi:
            edges.append(edges[-1] * ratio)
        edges.append(self.hi)
        self.pieces: list[_Piece] = []
        for a, b in zip(edges[:-1], edges[1:]):
            self._fit(a, b)
        self.edges = np.array([p.lo for p in self.pieces] + [self.hi])

    def _fit(self, a: float, b: float) -> None:
        """Accept [a, b] as one piece if its check passes, else halve it (or leave it exact)."""
        half, mid = 0.5 * (b - a), 0.5 * (a + b)
        x = np.concatenate([mid + half * self.nodes, mid + half * self._checks])
        vals = np.asarray(self.f(x), dtype=float)
        self.evaluations += x.size
        at_nodes, at_checks = vals[:self.nodes.size], vals[self.nodes.size:]
        err = np.max(np.abs(_barycentric(self._checks, self.nodes, self.weights, at_nodes) - at_checks), axis=0)
        if np.all(err <= self.tolerance):
            self.worst = max(self.worst, float(np.max(err / self.tolerance)))
            self.pieces.append(_Piece(a, b, at_nodes))
        elif (b - a) > self.min_width * a:
            self._fit(a, mid)
            self._fit(mid, b)
        else:
            self.pieces.append(_Piece(a, b, None))

    def __call__(self, x) -> np.ndarray:
        """The interpolant at x in [lo, hi], shape (x.size, m) (exact values in pieces left to the curve)."""
        x = np.asarray(x, dtype=float).ravel()
        if x.size and (x.min() < self.lo or x.max() > self.hi):
            raise ValueError(f"x must lie in [{self.lo:g}, {self.hi:g}], got [{x.min():g}, {x.max():g}]")
        which = np.clip(np.searchsorted(self.edges, x, side="right") - 1, 0, len(self.pieces) - 1)
        out = None
        for k in np.unique(which):
            rows = np.nonzero(which == k)[0]
            piece = self.pieces[k]
            if piece.values is None:
                vals = np.asarray(self.f(x[rows]), dtype=float)
            else:
                s = (2.0 * x[rows] - (piece.lo + piece.hi)) / (piece.hi - piece.lo)
                vals = _barycentric(np.clip(s, -1.0, 1.0), self.nodes, self.weights, piece.values)
            if out is None:
                out = np.empty((x.size, vals.shape[1]))
            out[rows] = vals
        return np.zeros((0, self.tolerance.size)) if out is None else out
