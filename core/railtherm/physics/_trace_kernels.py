"""The compiled pass of :func:`railtherm.physics.thermal_trace.thermal_trace`: peak, its position, the
fastest cooling behind it and the time above a threshold, for every depth column at once (numba)."""
from __future__ import annotations

import numba
import numpy as np

__all__ = ["trace_columns"]


@numba.njit(cache=True)
def _refine_max(x0, x1, x2, f0, f1, f2):  # pragma: no cover - compiled
    """(x, value) of the vertex of the parabola through (x0, f0), (x1, f1), (x2, f2) with f1 the largest
    sample, clipped to [x0, x2] and never below f1 (f1 itself where the samples are not curved down)."""
    d01, d12 = (f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1)
    c = (d12 - d01) / (x2 - x0)            # second divided difference (< 0 at a maximum)
    if not c < 0.0:
        return x1, f1
    d = d01 + c * (x1 - x0)                # slope of the parabola at x1
    t = min(max(x1 - d / (2.0 * c), x0), x2)
    return t, max(f1 + d * (t - x1) + c * (t - x1) ** 2, f1)


@numba.njit(cache=True)
def _rate(x, T, v, r, c):  # pragma: no cover - compiled
    """V dT/dx at sample r of column c: second-order central differences on the non-uniform x
    (:func:`numpy.gradient`'s formula), one-sided at the ends."""
    n = x.size
    if r == 0:
        return v * (T[1, c] - T[0, c]) / (x[1] - x[0])
    if r == n - 1:
        return v * (T[n - 1, c] - T[n - 2, c]) / (x[n - 1] - x[n - 2])
    h1, h2 = x[r] - x[r - 1], x[r + 1] - x[r]
    return v * (-h2 / (h1 * (h1 + h2)) * T[r - 1, c] + (h2 - h1) / (h1 * h2) * T[r, c]
                + h1 / (h2 * (h1 + h2)) * T[r + 1, c])


@numba.njit(cache=True)
def trace_columns(x, T, v, thr):  # pragma: no cover - compiled
    """The trace of every column of T (nx, nz) in one pass: (peak, position, cooling, time above) per
    column, NaN where unknown, and a status per column: bit 1 the peak lies at an end of the field,
    bit 2 the fastest cooling does, bit 4 T is above the threshold at an end (or everywhere, flat)."""
    n, nz = T.shape
    peak = np.full(nz, np.nan)
    where = np.full(nz, np.nan)
    cool = np.full(nz, np.nan)
    above = np.full(nz, np.nan)
    status = np.zeros(nz, dtype=np.int64)
    for c in range(nz):
        i, fmax, fmin = 0, T[0, c], T[0, c]
        for r in range(1, n):
            t = T[r, c]
            if t > fmax:
                i, fmax = r, t
            if t < fmin:
                fmin = t
        if fmax == fmin:                   # no heat reached this depth: bulk temperature, no cooling
            peak[c], cool[c] = fmax, 0.0
            if fmax > thr:
                status[c] |= 4
            else:
                above[c] = 0.0
            continue
        if i == 0 or i == n - 1:
            status[c] |= 1
        else:
            where[c], peak[c] = _refine_max(x[i - 1], x[i], x[i + 1], T[i - 1, c], T[i, c], T[i + 1, c])
            j = 0                                  # fastest cooling behind the peak (rows < i)
            rj = _rate(x, T, v, np.int64(j), c)    # an int64, not the literal 0: one compiled _rate
            for r in range(1, i):
                rr = _rate(x, T, v, r, c)
                if rr > rj:
                    j, rj = r, rr
            if rj <= 0.0:
                cool[c] = 0.0
            elif j == 0:
                status[c] |= 2
            elif j + 1 < i:
                cool[c] = _refine_max(x[j - 1], x[j], x[j + 1], _rate(x, T, v, j - 1, c), rj,
                                      _rate(x, T, v, j + 1, c))[1]
            else:
                cool[c] = rj
        if T[0, c] > thr or T[n - 1, c] > thr:
            status[c] |= 4
            continue
        length = 0.0                       # measure of {T > thr}, T linear between the samples
        for r in range(n - 1):
            g0, g1 = T[r, c] - thr, T[r + 1, c] - thr
            if g0 > 0.0 and g1 > 0.0:
                length += x[r + 1] - x[r]
            elif (g0 > 0.0) != (g1 > 0.0):
                length += (x[r + 1] - x[r]) * max(g0, g1) / abs(g1 - g0)
        above[c] = length / v
    return peak, where, cool, above, status
