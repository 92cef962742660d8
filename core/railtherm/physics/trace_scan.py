"""The per-depth scan behind :func:`railtherm.physics.thermal_trace.thermal_trace`: peak, its position, the
fastest cooling behind it and the time above a threshold, for every depth column of a field at once.

Vectorised numpy over the columns: the study's fields (up to ~1100 x 66 samples) take about a millisecond,
so a compiled kernel would save less per run than its compilation costs a fresh process (about 1 s)."""
from __future__ import annotations

import numpy as np

__all__ = ["trace_columns"]


def _refine_max(x0, x1, x2, f0, f1, f2):
    """(x, value) of the vertex of the parabola through (x0, f0), (x1, f1), (x2, f2) with f1 the largest
    sample, clipped to [x0, x2] and never below f1 (f1 itself where the samples are not curved down);
    elementwise over arrays of equal shape [m], [degC] (or any unit of f)."""
    d01, d12 = (f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1)
    c = (d12 - d01) / (x2 - x0)            # second divided difference (< 0 at a maximum)
    curved = c < 0.0
    c = np.where(curved, c, -1.0)          # any negative value: the flat samples are replaced below
    d = d01 + c * (x1 - x0)                # slope of the parabola at x1
    t = np.minimum(np.maximum(x1 - d / (2.0 * c), x0), x2)
    value = np.maximum(f1 + d * (t - x1) + c * (t - x1) ** 2, f1)
    return np.where(curved, t, x1), np.where(curved, value, f1)


def _cooling_rates(x, T, v):
    """V dT/dx [K s-1] at every sample: second-order central differences on the non-uniform x
    (:func:`numpy.gradient`'s formula), one-sided at the ends."""
    rate = np.empty_like(T)
    h1, h2 = (x[1:-1] - x[:-2])[:, None], (x[2:] - x[1:-1])[:, None]
    rate[1:-1] = v * (-h2 / (h1 * (h1 + h2)) * T[:-2] + (h2 - h1) / (h1 * h2) * T[1:-1]
                      + h1 / (h2 * (h1 + h2)) * T[2:])
    rate[0] = v * (T[1] - T[0]) / (x[1] - x[0])
    rate[-1] = v * (T[-1] - T[-2]) / (x[-1] - x[-2])
    return rate


def _fastest_cooling(x, rate, rows, cols):
    """The fastest cooling behind each column's peak (the largest rate over rows < ``rows``, refined by a
    parabola where it is interior) [K s-1], and whether it lies at the field's first x (then unknown)."""
    behind = np.where(np.arange(x.size)[:, None] < rows[None, :], rate[:, cols], -np.inf)
    j = np.argmax(behind, axis=0)          # the first of equal largest rates
    rj = behind[j, np.arange(cols.size)]
    cool = np.where(rj <= 0.0, 0.0, rj)
    at_end = (rj > 0.0) & (j == 0)
    cool[at_end] = np.nan
    mid = (rj > 0.0) & (j > 0) & (j + 1 < rows)
    if mid.any():
        jm, cm = j[mid], cols[mid]
        cool[mid] = _refine_max(x[jm - 1], x[jm], x[jm + 1], rate[jm - 1, cm], rj[mid], rate[jm + 1, cm])[1]
    return cool, at_end


def _time_above(x, T, v, thr):
    """Measure of {T > thr} along x over V per column [s], T linear between the samples."""
    g0, g1 = T[:-1] - thr, T[1:] - thr
    dx = np.diff(x)[:, None]
    cross = (g0 > 0.0) != (g1 > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        part = np.where((g0 > 0.0) & (g1 > 0.0), dx,
                        np.where(cross, dx * np.maximum(g0, g1) / np.abs(g1 - g0), 0.0))
    return part.sum(axis=0) / v


def trace_columns(x, T, v: float, thr: float):
    """The trace of every column of ``T`` (nx, nz) [degC] on the increasing ``x`` (nx,) [m] at speed ``v``
    [m s-1] and threshold ``thr`` [degC]: (peak [degC], position [m], cooling [K s-1], time above [s]) per
    column, NaN where unknown, and a status per column: bit 1 the peak lies at an end of the field, bit 2 the
    fastest cooling does, bit 4 T is above the threshold at an end (or everywhere, flat)."""
    n, nz = T.shape
    cols = np.arange(nz)
    peak, where, cool, above = (np.full(nz, np.nan) for _ in range(4))
    status = np.zeros(nz, dtype=np.int64)
    i = np.argmax(T, axis=0)               # the first of equal largest samples
    fmax = T[i, cols]
    flat = fmax == T.min(axis=0)           # no heat reached this depth: bulk temperature, no cooling
    peak[flat], cool[flat] = fmax[flat], 0.0
    status[flat & (fmax > thr)] |= 4
    above[flat & ~(fmax > thr)] = 0.0
    at_end = ~flat & ((i == 0) | (i == n - 1))
    status[at_end] |= 1
    inner = cols[~flat & ~at_end]
    if inner.size:
        ii = i[inner]
        where[inner], peak[inner] = _refine_max(x[ii - 1], x[ii], x[ii + 1], T[ii - 1, inner], T[ii, inner],
                                                T[ii + 1, inner])
        cool[inner], cool_at_end = _fastest_cooling(x, _cooling_rates(x, T, v), ii, inner)
        status[inner[cool_at_end]] |= 2
    hot_end = ~flat & ((T[0] > thr) | (T[-1] > thr))
    status[hot_end] |= 4
    measured = ~flat & ~hot_end
    if measured.any():
        above[measured] = _time_above(x, T[:, measured], v, thr)
    return peak, where, cool, above, status
