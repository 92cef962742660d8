"""The compiled loop of the per-pass time above a threshold
(:func:`railtherm.physics.pass_history.pass_time_above`), in its own module: importing :mod:`railtherm.physics` loads
no numba."""
from __future__ import annotations

import numba
import numpy as np

__all__ = ["time_above_sums"]


@numba.njit(cache=True)
def time_above_sums(t, g, edges, count):  # pragma: no cover - compiled
    """Per window [edges[k], edges[k + 1]) and column, the time [s] the sampled g (n, m) is positive: the
    whole step where both ends are, the fraction on the positive side where it crosses (linear between
    samples); each step belongs to the window of its left end. One pass over the samples."""
    n, m = g.shape
    out = np.zeros((count, m))
    w = 0
    for i in range(n - 1):
        while w + 1 < count and t[i] >= edges[w + 1]:
            w += 1
        dt = t[i + 1] - t[i]
        for j in range(m):
            p0 = g[i, j] > 0.0
            p1 = g[i + 1, j] > 0.0
            if p0 and p1:
                out[w, j] += dt
            elif p0 != p1:
                # on a crossing interval the part above is the fraction on the positive side
                num = abs(g[i, j]) if p0 else abs(g[i + 1, j])
                out[w, j] += dt * (num / max(abs(g[i + 1, j] - g[i, j]), 1e-300))
    return out
