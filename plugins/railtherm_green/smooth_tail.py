"""The cooling tail of green's pass response past the contact: a checked Chebyshev interpolant of the response
over sqrt(time) in 1/time, and its compiled evaluation.

Past 4 contact durations each edge term of the response (:class:`railtherm_green.pass_response.PassResponse`)
is sqrt(theta - c) times a power series in 1/(theta - c), so response/sqrt(theta) is analytic in 1/theta with
its singularities at least 4x beyond the tail's interval: the interpolant's coefficients fall like 13.9^-k
whatever the span of the history (:func:`with_smooth_tail`). Derivation: docs/NOTES.md, "Green's transient".
"""
from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["with_smooth_tail", "checked_tail", "tail_chebval", "chebval_into"]


@numba.njit(cache=True)
def tail_chebval(theta, lo, hi, coef, power=0.5):  # pragma: no cover - compiled
    """theta^power (sqrt(theta) by default) times the Clenshaw sum of the Chebyshev series coef (degree + 1, m) at
    u = 2 (1/theta - lo)/(hi - lo) - 1, shape (theta.size, m) (:func:`chebval_into`)."""
    out = np.empty((theta.size, coef.shape[1]))
    chebval_into(theta, lo, hi, np.ascontiguousarray(coef.T), out, power)
    return out


@numba.njit(cache=True)
def chebval_into(theta, lo, hi, ct, out, power=0.5):  # pragma: no cover - compiled
    """out (theta.size, m) = :func:`tail_chebval` with the coefficients transposed, ct (m, degree + 1). The
    Clenshaw recurrences of all times advance together, one coefficient at a time (independent lanes the
    compiler vectorises: 1.7x faster than four interleaved chains, the same operations per time)."""
    n, m = theta.size, ct.shape[0]
    deg = ct.shape[1] - 1
    u = np.empty(n)
    root = np.empty(n)
    for i in range(n):
        u[i] = 4.0 * (1.0 / theta[i] - lo) / (hi - lo) - 2.0
        root[i] = math.sqrt(theta[i]) if power == 0.5 else theta[i] ** power
    b1 = np.empty(n)
    b2 = np.empty(n)
    for j in range(m):
        c = ct[j]
        b1[:] = 0.0
        b2[:] = 0.0
        for k in range(deg, 0, -1):
            ck = c[k]
            for i in range(n):
                b0 = u[i] * b1[i] - b2[i] + ck
                b2[i] = b1[i]
                b1[i] = b0
        for i in range(n):
            out[i, j] = root[i] * (0.5 * u[i] * b1[i] - b2[i] + c[0])


@numba.njit(cache=True)
def _lobatto_fit(vals, roots, rtol, big):  # pragma: no cover - compiled
    """The check of :func:`checked_tail` at degree d: ``vals`` (2 d + 1, m) are fn at the Chebyshev-Lobatto
    points u_k = cos(pi k / (2 d)) of degree 2 d, ``roots`` (2 d + 1,) sqrt(theta) there. The even points
    interpolate fn/sqrt(theta) at degree d (its Chebyshev coefficients by the points' discrete orthogonality, a
    DCT-I); at the odd points between them it must match fn within ``rtol`` of max|fn| of each column. Returns
    (passed, coefficients (d + 1 - dropped, m)): the trailing coefficients whose absolute sum times ``big``
    (the largest sqrt(theta) times the passes the values are summed over) stays within half the check's margin
    are dropped (cheaper sums, at least 2 kept)."""
    d = (vals.shape[0] - 1) // 2
    m = vals.shape[1]
    coef = np.zeros((d + 1, m))
    for j in range(d + 1):
        for k in range(d + 1):
            e = 0.5 if k == 0 or k == d else 1.0
            c = e * math.cos(math.pi * j * k / d) / roots[2 * k]
            for col in range(m):
                coef[j, col] += c * vals[2 * k, col]
        f = (1.0 if j == 0 or j == d else 2.0) / d
        for col in range(m):
            coef[j, col] *= f
    scale = np.full(m, 1e-300)
    for k in range(vals.shape[0]):
        for col in range(m):
            scale[col] = max(scale[col], abs(vals[k, col]))
    miss = np.zeros(m)
    for i in range(d):
        for col in range(m):
            fit = 0.0
            for j in range(d + 1):
                fit += coef[j, col] * math.cos(math.pi * j * (2 * i + 1) / (2 * d))
            miss[col] = max(miss[col], abs(roots[2 * i + 1] * fit - vals[2 * i + 1, col]))
    for col in range(m):
        if not miss[col] <= rtol * scale[col]:
            return False, coef
    keep = 2
    for col in range(m):
        tail = 0.0
        for j in range(d, -1, -1):                      # tail = sum_(l >= j) |c_l|, from the end
            tail += abs(coef[j, col])
            if tail > 0.5 * (rtol * scale[col] - miss[col]) / big:
                keep = max(keep, j + 1)
                break
    return True, coef[:keep].copy()


def with_smooth_tail(fn, theta, after, rtol=1e-11, far=None, passes=1, power=0.5):
    """fn(theta) (shape (theta.size, m)), with the long tail theta >= ``after`` (past the contact: the smooth
    1-D cooling) taken from a Chebyshev interpolant when that is cheaper; ``far`` (default fn): fn for times
    >= ``after``, by which the tail is interpolated.

    The interpolant is of fn(theta)/sqrt(theta) in w = 1/theta: each edge term F(theta - c) of
    :class:`railtherm_green.pass_response.PassResponse` is sqrt(theta - c) times a power series in 1/(theta - c)
    plus a constant (which the edge weights' zero sum cancels), so fn/sqrt(theta) is analytic in w with its
    singularities at w = 1/c >= 1/D, at least 4x the interval's end 1/after (after = 4 D): Chebyshev coefficients
    fall like (7 + sqrt 48)^-k = 13.9^-k whatever the span of theta (a series in log(theta) needs several times
    the degree over long histories). On the Chebyshev-Lobatto points of degree d (from 16, doubling) the
    interpolant is checked at the d points the degree 2d adds between them and used once it matches fn there
    within ``rtol`` of max|fn| of each column; above degree 512 fn is evaluated directly. The trailing
    coefficients dropped to cheapen the sums change the values by at most half the check's margin over the
    ``passes`` whose values are summed (that change has one sign along the tail: it adds up pass by pass).
    ``power``: the interpolant is of fn/theta^power (0.5 above; -1 for the laterally spread response of
    :class:`railtherm_green.lateral.LateralPassResponse`, which is 1/theta times a function analytic in w)."""
    far = fn if far is None else far
    theta = np.asarray(theta, dtype=float)
    beyond = theta >= after
    nfar = int(beyond.sum())
    near = fn(theta[~beyond])
    out = np.empty((theta.size, near.shape[1]))
    out[~beyond] = near
    if nfar == 0:
        return out
    lo, hi = 1.0 / (float(theta[beyond].max()) * (1.0 + 1e-12)), 1.0 / after
    if not hi > lo or nfar <= 32:
        out[beyond] = far(theta[beyond])
        return out
    coef = checked_tail(far, lo, hi, nfar, rtol, passes, power)
    out[beyond] = far(theta[beyond]) if coef is None else tail_chebval(theta[beyond], lo, hi, coef, power)
    return out


def checked_tail(far, lo, hi, nfar, rtol, passes=1, power=0.5):
    """The Chebyshev coefficients (degree + 1, m) of far(theta)/theta^power in u = 2 (1/theta - lo)/(hi - lo) - 1
    (:func:`with_smooth_tail`), or None when no degree up to 512 and below nfar / 2 passes the check. The
    values at the Lobatto points of degree 2d are evaluated once: the even ones interpolate at degree d, the odd
    ones (the points between them) check it; a failed check doubles d and adds the new points between."""

    degree = 16                                         # nfar > 2 degree (the caller's)
    theta = _lobatto_times(lo, hi, 2 * degree, 1)       # the Lobatto points of degree 2d
    vals, roots = far(theta), _scaling(theta, power)
    big = (math.sqrt(1.0 / lo) if power == 0.5 else max(lo ** -power, hi ** -power)) * passes
    while True:
        passed, coef = _lobatto_fit(vals, roots, rtol, big)
        if passed:
            return coef
        degree *= 2
        if not (2 * degree < nfar and degree <= 512):
            return None
        theta = _lobatto_times(lo, hi, 2 * degree, 2)   # the new points between them
        vals, roots = _interleave(vals, far(theta)), _interleave(roots, _scaling(theta, power))


def _scaling(theta, power):
    """theta^power [s^power], sqrt(theta) for power 0.5 (the interpolated function is fn / theta^power)."""
    return np.sqrt(theta) if power == 0.5 else theta ** power


@numba.njit(cache=True)
def _lobatto_times(lo, hi, d, every):  # pragma: no cover - compiled
    """The times [s] of the Chebyshev-Lobatto points u_k = cos(pi k / d) (every ``every``-th from k = every - 1)
    of the tail's variable u = 2 (1/theta - lo)/(hi - lo) - 1."""
    k = np.arange(every - 1, d + 1, every)
    out = np.empty(k.size)
    for i in range(k.size):
        out[i] = 1.0 / (lo + (hi - lo) * (math.cos(math.pi * k[i] / d) + 1.0) / 2.0)
    return out


def _interleave(even, odd):
    """Rows even[0], odd[0], even[1], ..., even[-1]: the Lobatto values of degree 2d from those of degree d
    and the d points between them."""
    out = np.empty((even.shape[0] + odd.shape[0],) + even.shape[1:])
    out[0::2] = even
    out[1::2] = odd
    return out
