"""Graded one-dimensional cell edges, nested by refinement level."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["geometric_edges"]


def geometric_edges(length: float, first: float, ratio: float, level: int) -> np.ndarray:
    """Edges ``0 = e_0 < ... < e_n = length`` of cells growing geometrically from ``first``.

    Level 0 has ``n0 = ceil(log(1 + length (ratio - 1) / first) / log(ratio))`` cells along the map
    ``e(s) = length (ratio**s - 1) / (ratio**n0 - 1)`` at ``s = 0, 1, ..., n0`` (so the first cell is
    at most ``first``); level k samples the same map at ``s = j / 2**k``. The meshes are nested
    (every edge of level k - 1 is an edge of level k), every cell halves per level and the growth
    ratio of level k is ``ratio**(1/2**k)``: what convergence-rate fits assume.

    Parameters
    ----------
    length : float
        Total length [m], > 0.
    first : float
        Largest admissible first cell at level 0 [m], > 0.
    ratio : float
        Growth ratio of neighbouring cells at level 0 [1], > 1.
    level : int
        Refinement level k >= 0 [1].

    Returns
    -------
    ndarray, shape (n0 * 2**k + 1,)
        Edges [m].

    Raises
    ------
    ValueError
        For ``length <= 0``, ``first <= 0`` or ``ratio <= 1``.
    """
    if length <= 0 or first <= 0 or ratio <= 1.0:
        raise ValueError(f"geometric_edges needs length > 0, first > 0, ratio > 1; got {length}, {first}, {ratio}")
    if first >= length:
        n0 = 1
    else:
        n0 = max(1, math.ceil(math.log(1.0 + length * (ratio - 1.0) / first) / math.log(ratio) - 1e-9))
    s = np.arange(n0 * 2 ** level + 1) / 2 ** level
    e = length * (ratio ** s - 1.0) / (ratio ** n0 - 1.0)
    e[-1] = length
    return e
