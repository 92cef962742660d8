"""One pass's response of green's strip at the fixed section: the rise at times after the pass's arrival, as a sum
over the cell edges of the 1-D Duhamel integral F, evaluated by the cheapest exact means per time.

On green's own time axis (the crossings of the cell edges) the edge sum is a discrete convolution on the lattice
of half cell-crossing times; past two contact durations it is the far sum of F' at 25 crossing times, free of the
edge sum's cancellation; elsewhere the direct edge sum; past four, optionally, the tail interpolant of
:mod:`railtherm_green.smooth_tail`. Derivation: docs/NOTES.md, "Green's transient".

References: H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .smooth_tail import chebval_into

__all__ = ["PassResponse", "FAR_DEGREE"]

#: degree of the interpolant in the crossing time of the response past the contact (:meth:`PassResponse.far`)
FAR_DEGREE = 24


@numba.njit(cache=True)
def _f_value(s, c):  # pragma: no cover - compiled
    """F(s) of the module docstring [s^0.5] for one s [s] (0 for s <= 0), depth constant c = z^2/(4 kappa) [s]."""
    if s <= 0.0:
        return 0.0
    rs = math.sqrt(s)
    if c == 0.0:
        return 2.0 * rs
    f = 2.0 * rs * math.exp(-c / s) - 2.0 * math.sqrt(math.pi * c) * math.erfc(math.sqrt(c / s))
    return max(f, 0.0)


@numba.njit(cache=True)
def _edge_sums(theta, c, w, cs):  # pragma: no cover - compiled
    """``sum_k w_k F(theta_i - c_k)`` for the times theta (n,) [s], the crossings c (k,) [s] with weights w (k,)
    and each depth constant of cs (m,), shape (n, m)."""
    out = np.empty((theta.size, cs.size))
    for i in range(theta.size):
        for j in range(cs.size):
            acc = 0.0
            for k in range(c.size):
                acc += w[k] * _f_value(theta[i] - c[k], cs[j])
            out[i, j] = acc
    return out


@numba.njit(cache=True)
def _lattice_response(theta, half, snap, top, w_lead, cs):  # pragma: no cover - compiled
    """The edge sums (n, m) at the times theta (n,) [s], each within ``snap`` [s] of a point of the lattice of
    ``half`` [s] (0 .. top; 0 for a time that is not): ``sum_r w_lead[r] F(theta - r tau)`` (edge r from the lead
    crossed at r tau = 2 r half) as the discrete convolution of the edge weights with F on the lattice, F
    evaluated once per lattice point (on the edges' lattice tau when no time is on a cell centre's crossing)."""
    n = theta.size
    at = np.empty(n, np.int64)
    odd = False
    for i in range(n):
        m = math.floor(theta[i] / half + 0.5)
        if abs(theta[i] - m * half) <= snap and 0 <= m <= top:
            at[i] = m
            odd = odd or m % 2 == 1
        else:
            at[i] = -1
    stride, step = (2, half) if odd else (1, 2.0 * half)
    last = 0
    for i in range(n):
        if at[i] >= 0 and not odd:
            at[i] //= 2
        last = max(last, at[i])
    f = np.empty(last + 1)
    conv = np.empty(last + 1)
    out = np.zeros((n, cs.size))
    for j in range(cs.size):
        for i in range(last + 1):
            f[i] = _f_value(step * i, cs[j])
        # conv[i] = sum_r w_lead[r] f[i - stride r]: one sweep over the lattice per edge
        conv[:] = 0.0
        for r in range(min(w_lead.size, last // stride + 1)):
            wr = w_lead[r]
            shift = stride * r
            for i in range(shift, last + 1):
                conv[i] += wr * f[i - shift]
        for i in range(n):
            if at[i] >= 0:
                out[i, j] = conv[at[i]]
    return out


@numba.njit(cache=True)
def _respond(theta, after, lo, hi, ct, lattice, far, edges, cs, scale):  # pragma: no cover - compiled
    """The unit response (n, m) at the times theta (n,) [s] (:class:`PassResponse`), each by the cheapest exact
    means: from ``after`` on the tail interpolant (ct its coefficients transposed, on [1/hi, 1/lo]; none for
    after = inf); on the lattice (``lattice`` = (half [s], snap [s], last point, edge weights from the lead);
    last point -1: none) the convolution (:func:`_lattice_response`); from 2 D on (``far`` = (2 D, nodes,
    weights)) the far sum (:func:`_g_sums`); else the edge sum (``edges`` = (crossings, weights)); 0 at
    theta <= 0. Every value but the tail's times ``scale``."""
    half, snap, top, w_lead = lattice
    two_d, nodes, weights = far
    c_edge, w_edge = edges
    n = theta.size
    kind = np.zeros(n, np.int64)                        # 0: zero, 1: tail, 2: lattice, 3: far, 4: edge sum
    for i in range(n):
        t = theta[i]
        if t <= 0.0:
            continue
        if t >= after:
            kind[i] = 1
            continue
        m = math.floor(t / half + 0.5)
        if top >= 0 and abs(t - m * half) <= snap and 0 <= m <= top:
            kind[i] = 2
        else:
            kind[i] = 3 if t >= two_d else 4
    out = np.zeros((n, cs.size))
    for k in range(1, 5):
        idx = np.flatnonzero(kind == k)
        if idx.size == 0:
            continue
        sub = theta[idx]
        if k == 1:
            vals = np.empty((idx.size, cs.size))
            chebval_into(sub, lo, hi, ct, vals, 0.5)
        elif k == 2:
            vals = _lattice_response(sub, half, snap, top, w_lead, cs) * scale
        elif k == 3:
            vals = _g_sums(sub, nodes, weights, cs) * scale
        else:
            vals = _edge_sums(sub, c_edge, w_edge, cs) * scale
        for r in range(idx.size):       # element by element: a row assignment compiles numba's shape-error text
            for j in range(cs.size):
                out[idx[r], j] = vals[r, j]
    return out


@numba.njit(cache=True)
def far_weights_columns(c_edge, w, duration, degree):  # pragma: no cover - compiled
    """The nodes c_l (degree + 1,) [s] (Chebyshev-Lobatto on [0, D]) and weights K_l (degree + 1, P) [W/m^2 s] of
    :meth:`PassResponse.far` for the edge weights of every column of w (edges, P): ``K_l = -sum_k w_k int_0^(c_k)
    l_l(c) dc`` with l_l the Lagrange basis of the nodes, from the integrated Chebyshev polynomials
    ``P_j(u) = int_(-1)^u T_j`` at the edges' u_k = 2 c_k/D - 1: ``m_j = sum_k w_k P_j(u_k)``, then
    K = -(D/2) C^T m with C the nodes' values -> coefficients matrix (DCT-I). One column: a strip's own response;
    P columns: the lateral distances of :mod:`railtherm_green.lateral`."""
    p = degree
    ncol = w.shape[1]
    m = np.zeros((p + 1, ncol))
    t = np.empty(p + 2)
    pj = np.empty(p + 1)
    for k in range(c_edge.size):
        u = min(max(2.0 * c_edge[k] / duration - 1.0, -1.0), 1.0)
        t[0], t[1] = 1.0, u
        for j in range(1, p + 1):
            t[j + 1] = 2.0 * u * t[j] - t[j - 1]
        pj[0] = u + 1.0
        pj[1] = 0.5 * (u * u - 1.0)
        for j in range(2, p + 1):
            sign = 1.0 if j % 2 == 0 else -1.0
            pj[j] = 0.5 * (t[j + 1] / (j + 1) - t[j - 1] / (j - 1)) - sign / (j * j - 1.0)
        for col in range(ncol):
            wk = w[k, col]
            if wk != 0.0:
                for j in range(p + 1):
                    m[j, col] += wk * pj[j]
    nodes = np.empty(p + 1)
    weights = np.zeros((p + 1, ncol))
    for i in range(p + 1):
        u = math.cos(math.pi * i / p)
        nodes[i] = 0.5 * duration * (1.0 + u)
        f = -0.5 * duration * (2.0 / p) * (0.5 if i == 0 or i == p else 1.0)
        t0, t1 = 1.0, u
        for col in range(ncol):
            weights[i, col] = 0.5 * m[0, col]
        for j in range(1, p + 1):
            e = (0.5 if j == p else 1.0) * t1
            for col in range(ncol):
                weights[i, col] += e * m[j, col]
            t0, t1 = t1, 2.0 * u * t1 - t0
        for col in range(ncol):
            weights[i, col] *= f
    return nodes, weights


def _far_weights(c_edge, w, duration, degree):
    """:func:`far_weights_columns` of the one column ``w`` (edges,): nodes (degree + 1,) [s], weights
    (degree + 1,) [W/m^2 s]."""
    nodes, weights = far_weights_columns(c_edge, np.ascontiguousarray(w, dtype=float).reshape(-1, 1), duration,
                                         degree)
    return nodes, weights[:, 0]


@numba.njit(cache=True)
def _g_sums(theta, nodes, weights, cs):  # pragma: no cover - compiled
    """``sum_l K_l g(theta_i - c_l)`` with g(s) = exp(-c/s)/sqrt(s) = F'(s) for the times theta (n,) [s] (past
    the nodes c_l) and each depth constant c of cs (m,), shape (n, m)."""
    out = np.empty((theta.size, cs.size))
    for i in range(theta.size):
        for j in range(cs.size):
            acc = 0.0
            for k in range(nodes.size):
                s = theta[i] - nodes[k]
                if s > 0.0:
                    acc += weights[k] * math.exp(-cs[j] / s) / math.sqrt(s)
            out[i, j] = acc
    return out


@numba.njit(cache=True)
def _edges(x, flux, speed):  # pragma: no cover - compiled
    """The edges of the cells x (n + 1,) [m] with the flux (n,) [W/m^2] crossing at ``speed`` [m/s]: their weights
    w_k = q_(k-1) - q_k (q = 0 outside), crossing times (x_lead - x_k)/speed [s], both for the edges whose weight
    is not 0, the weights from the lead, and whether the cells are equal (within 1e-10 of their mean)."""
    n = x.size - 1
    w = np.zeros(n + 1)
    c = np.empty(n + 1)
    h = (x[n] - x[0]) / n
    uniform = True
    live = 0
    for k in range(n + 1):
        if k < n:
            w[k + 1] += flux[k]
            w[k] -= flux[k]
        c[k] = (x[n] - x[k]) / speed
        uniform = uniform and abs(x[k] - (x[0] + h * k)) <= 1e-10 * h
    for k in range(n + 1):
        live += w[k] != 0.0
    c_live, w_live = np.empty(live), np.empty(live)
    j = 0
    for k in range(n + 1):
        if w[k] != 0.0:
            c_live[j], w_live[j] = c[k], w[k]
            j += 1
    return w, c, c_live, w_live, w[::-1].copy(), uniform


class PassResponse:
    """One pass's rise [K] at the depths z for a constant factor 1, as a function of the time after arrival.

    Summation by parts turns the cell sum into one over the cell edges: with q_k the flux of cell k (zero
    outside), edge k (crossed at c_k = (x_lead - x_k)/V) carries w_k = q_(k-1) - q_k and

    ``R(theta) = sum_k w_k F(theta - c_k) / (beta sqrt(pi))``   (F(s) = 0 for s <= 0).

    On a uniform grid (c_k = r tau, r = 0 .. n, tau = h/V) and at times on the lattice theta = i tau/2 (green's
    own axis: the crossings of the cell edges) that is a discrete convolution of the edge weights with F on
    the lattice: F is evaluated once per lattice point instead of once per (time, edge). Times off the lattice
    (another body's axis, a Chebyshev node of the tail) take the far sum (:meth:`far`) from 2 D on, else the
    direct edge sum (:meth:`direct`); :meth:`with_tail` adds the tail interpolant of
    :func:`railtherm_green.smooth_tail.with_smooth_tail`.
    A time within ``snap`` [s] of a lattice point is taken on it: green's axis is on the lattice up to the
    rounding of the pass phases (1e-12 of the interval, :func:`shifted_sum`), which the direct sum would see
    as well.
    """

    #: the tail interpolant is of R / theta^tail_power (:func:`railtherm_green.smooth_tail.with_smooth_tail`)
    tail_power = 0.5

    def __init__(self, x_edges, flux, speed, depth, effusivity, diffusivity, snap):
        x = np.ascontiguousarray(x_edges, dtype=float)
        self.flux = np.asarray(flux, dtype=float)
        # edge k: w_k = q_(k-1) - q_k, crossed at c_k [s] (decreasing in k); those whose weight is not 0; the
        # weights from the lead (edge r at lattice point 2 r); whether the cells are equal
        self.w, self.c_edge, self.c_live, self.w_live, self.w_lead, self.uniform = _edges(
            x, np.ascontiguousarray(flux, dtype=float), float(speed))
        self.cs = np.square(np.asarray(depth, dtype=float)) / (4.0 * diffusivity)
        self.scale = 1.0 / (effusivity * math.sqrt(math.pi))
        n = x.size - 1
        h = (x[-1] - x[0]) / n
        self.half = 0.5 * h / speed                     # lattice step tau/2 [s]
        self.n = n
        self.snap = float(snap)
        self.duration = float((x[-1] - x[0]) / speed)
        self._far = None                                # (crossing nodes, their weights), on first use

    def direct(self, theta):
        """The edge sum at arbitrary times theta (m,) [s], shape (m, depths)."""
        theta = np.asarray(theta, dtype=float)
        return _edge_sums(theta, self.c_live, self.w_live, self.cs) * self.scale

    def far(self, theta):
        """The edge sum at times theta (m,) >= 2 D [s] (D the contact duration), shape (m, depths), from g = F' at
        FAR_DEGREE + 1 crossing times instead of F at every edge, and without the edge sum's cancellation.

        The edge weights sum to zero (w_k = q_(k-1) - q_k), so ``R = sum_k w_k (F(theta - c_k) - F(theta))
        = -sum_k w_k int_0^(c_k) g(theta - c) dc`` with g(s) = F'(s) = exp(-c_z/s)/sqrt(s) [s^-0.5]: no longer a
        difference of terms ~theta/D times the result (the direct sum's rounding: 2e-10 relative at 100 s on a
        0.4 ms contact against 40-digit sums, this sum's 7e-16). For theta >= 2 D, c -> g(theta - c) is analytic
        on the crossings' span [0, D] and beyond it up to c = theta (where Re(theta - c) > 0, exp(-c_z/(theta - c))
        stays bounded), so its interpolant at the Chebyshev-Lobatto nodes of [0, D] converges like rho^-p with
        rho = xi + sqrt(xi^2 - 1), xi = 2 theta/D - 1: 5.8^-24 = 5e-19 at 2 D, 13.9^-24 = 4e-28 at 4 D (the
        tail's start). Integrated from 0 to each crossing, it makes R = sum_l K_l g(theta - c_l)
        (:func:`_far_weights`).
        """
        theta = np.asarray(theta, dtype=float)
        nodes, weights = self._far_sum()
        return _g_sums(theta, nodes, weights, self.cs) * self.scale

    def _far_sum(self):
        """The nodes and weights of :meth:`far` (:func:`_far_weights`), computed on first use."""
        if self._far is None:
            self._far = _far_weights(self.c_edge, self.w, self.duration, FAR_DEGREE)
        return self._far

    def __call__(self, theta):
        return self.with_tail(theta, math.inf, 0.0, 1.0, np.zeros((1, self.cs.size)))

    def with_tail(self, theta, after, lo, hi, coef):
        """The response at the times theta (n,) [s], shape (n, depths), from ``after`` [s] on by the tail
        interpolant coef (degree + 1, depths) on [1/hi, 1/lo] (:mod:`railtherm_green.smooth_tail`; after = inf: none);
        before it on the lattice by the convolution, from 2 D on by :meth:`far`, else by :meth:`direct`
        (one compiled pass, :func:`_respond`); 0 at theta <= 0."""
        theta = np.ascontiguousarray(theta, dtype=float)
        lattice = (self.half, self.snap, 64 * self.n if self.uniform else -1, self.w_lead)
        far = (2.0 * self.duration,) + tuple(self._far_sum())
        return _respond(theta, float(after), float(lo), float(hi), np.ascontiguousarray(coef.T), lattice, far,
                        (self.c_live, self.w_live), self.cs, self.scale)
