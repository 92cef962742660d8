"""Geometrically graded composite Gauss-Legendre rules (hp-quadrature) for endpoint singularities.

A rule on (0, 1] graded toward 0: panels [s^(k+1), s^k], k = 0 .. K-1, and [0, s^K], each with n
Gauss-Legendre points. For integrands analytic on (0, 1] with an integrable algebraic or logarithmic
singularity (or a boundary layer of any width) at 0, the error decays exponentially in n, down to the
innermost panel's share (|f| integrated over [0, s^K], about s^K |log s^K| for a log singularity).

References
----------
.. [1] C. Schwab, p- and hp-Finite Element Methods, Oxford, 1998, section 3.3 (geometric meshes).
.. [2] P.J. Davis, P. Rabinowitz, Methods of Numerical Integration, 2nd ed., Academic Press, 1984,
   section 2.12.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

GRADING_RATIO = 0.15  # near-optimal ratio for geometric meshes (Schwab 1998)
INNERMOST = 1e-16     # size of the innermost panel relative to the interval


@lru_cache(maxsize=64)
def graded_rule(n: int, ratio: float = GRADING_RATIO, innermost: float = INNERMOST
                ) -> tuple[np.ndarray, np.ndarray]:
    """Nodes t in (0, 1) and weights of a composite Gauss-Legendre rule graded toward t = 0.

    Parameters
    ----------
    n : int
        Gauss-Legendre points per panel [1].
    ratio : float
        Geometric grading ratio s, 0 < s < 1 [1].
    innermost : float
        Upper bound of the innermost panel [1].

    Returns
    -------
    t, w : numpy.ndarray
        Nodes and weights (sum of weights = 1).
    """
    if n < 1:
        raise ValueError("n must be >= 1")
    k = max(1, int(math.ceil(math.log(innermost) / math.log(ratio))))
    edges = np.concatenate([[0.0], ratio ** np.arange(k, -1, -1)])
    x, w = np.polynomial.legendre.leggauss(int(n))
    lo, hi = edges[:-1, None], edges[1:, None]
    t = (lo + (hi - lo) * (x + 1.0) / 2.0).ravel()
    wt = ((hi - lo) * w / 2.0).ravel()
    t.setflags(write=False)
    wt.setflags(write=False)
    return t, wt


@lru_cache(maxsize=64)
def two_sided_rule(n: int, ratio: float = GRADING_RATIO, innermost: float = INNERMOST
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Rule on (0, 1) graded toward both ends (halves graded toward 0 and toward 1)."""
    t, w = graded_rule(n, ratio, innermost)
    tt = np.concatenate([0.5 * t, 1.0 - 0.5 * t[::-1]])
    ww = np.concatenate([0.5 * w, 0.5 * w[::-1]])
    tt.setflags(write=False)
    ww.setflags(write=False)
    return tt, ww


@lru_cache(maxsize=512)
def graded_pair_rule(n: int, low_exponent: int, high_exponent: int, ratio: float = GRADING_RATIO
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Rule on (0, 1) graded toward 0 down to 10**low_exponent and toward 1 down to 10**high_exponent (each
    half as :func:`graded_rule` with that innermost panel): an integrand whose nearest singularity lies a
    distance d outside an end needs its panels graded only down to about d there (Schwab 1998, 3.3), so an end
    far from any singularity takes few panels. With both exponents -16 it is :func:`two_sided_rule`."""
    t0, w0 = graded_rule(n, ratio, 10.0 ** int(low_exponent))
    t1, w1 = graded_rule(n, ratio, 10.0 ** int(high_exponent))
    tt = np.concatenate([0.5 * t0, 1.0 - 0.5 * t1[::-1]])
    ww = np.concatenate([0.5 * w0, 0.5 * w1[::-1]])
    tt.setflags(write=False)
    ww.setflags(write=False)
    return tt, ww
