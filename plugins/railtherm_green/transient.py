"""Green's transient: Duhamel superposition in time of the 1-D strip solution at a fixed material point.

The point at the fixed section, on the centre strip y = 0, at depth z, lies under the contact while
x = x_lead - V (t - t_k) crosses the patch (pass k arrives at t_k = k interval). Each strip is a 1-D
half-space heated only through its surface, so the history is the 1-D Duhamel integral (Carslaw & Jaeger
1959, 2.9): ``T(z, t) = 1/(beta sqrt(pi)) int f(t') q(t') exp(-z^2/(4 kappa (t - t'))) dt' / sqrt(t - t')``,
beta = sqrt(lambda rho c), q the strip's flux (piecewise constant per cell), f the piecewise-linear schedule;
each interval is integrated exactly (:func:`_f_g`). Neglected: conduction along x and across strips. The
problem is linear, so one pass's response serves every pass (:func:`shifted_sum`); a temperature-dependent
flux would break this, and green refuses such scenes (:func:`railtherm_green.history.limits`). Derivation and
the superposition scheme: docs/NOTES.md, "Green's transient".

References: [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
temperatures in wheel/rail contact, Wear 253 (2002) 498-508 (DOI not verified, see docs/references.md).
[2] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
"""
from __future__ import annotations

import math

import numba
import numpy as np
from numpy.polynomial import chebyshev
from railtherm.references.transient import shifted_sum
from scipy.special import erfc

__all__ = ["strip_history", "strip_time_axis", "scheduled_passes"]


def _f_g(s, c):
    """F(s) and G(s) of the module docstring for s >= 0 (arrays), depth constant c = z^2/(4 kappa) >= 0."""
    s = np.maximum(s, 0.0)
    rs = np.sqrt(s)
    if c == 0.0:
        return 2.0 * rs, (2.0 / 3.0) * s * rs
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        e = np.where(s > 0, np.exp(-c / np.where(s > 0, s, 1.0)), 0.0)
        tail = np.where(s > 0, erfc(np.sqrt(c / np.where(s > 0, s, 1.0))), 0.0)
    f = 2.0 * rs * e - 2.0 * math.sqrt(math.pi * c) * tail
    f = np.maximum(f, 0.0)
    g = (2.0 / 3.0) * (s * rs * e - c * f)
    return f, np.maximum(g, 0.0)


def _segments(x_edges, flux, speed):
    """Crossing interval [start, end] [s] after arrival and flux [W/m^2] of every heated cell."""
    x_edges = np.asarray(x_edges, dtype=float)
    flux = np.asarray(flux, dtype=float)
    if x_edges.ndim != 1 or flux.shape != (x_edges.size - 1,):
        raise ValueError(f"flux must have one value per cell: {x_edges.size - 1}, got shape {flux.shape}")
    if np.any(np.diff(x_edges) <= 0):
        raise ValueError("x_edges must be strictly increasing [m]")
    lead = x_edges[-1]
    start = (lead - x_edges[1:]) / speed
    end = (lead - x_edges[:-1]) / speed
    keep = flux != 0
    return start[keep], end[keep], flux[keep]


def _response(t, z, start, end, q, factor0, slope, effusivity, diffusivity):
    """Rise [K] at times t (n,) of intervals [start, end] (m,) with flux q (factor0 + slope (t' - start))."""
    c = z * z / (4.0 * diffusivity)
    tt = t[:, None]
    s_hi = tt - start[None, :]
    s_lo = np.maximum(tt - end[None, :], 0.0)
    live = s_hi > 0
    f_hi, g_hi = _f_g(np.where(live, s_hi, 0.0), c)
    f_lo, g_lo = _f_g(s_lo, c)
    lin = factor0[None, :] + slope[None, :] * np.where(live, s_hi, 0.0)
    val = q[None, :] * (lin * (f_hi - f_lo) - slope[None, :] * (g_hi - g_lo))
    return np.where(live, val, 0.0).sum(axis=1) / (effusivity * math.sqrt(math.pi))


def _f_only(s, c):
    """F(s) of the module docstring for s >= 0 (arrays), without G (the constant-factor sums need F only)."""
    s = np.maximum(s, 0.0)
    rs = np.sqrt(s)
    if c == 0.0:
        return 2.0 * rs
    pos = s > 0
    safe = np.where(pos, s, 1.0)
    with np.errstate(over="ignore", under="ignore"):
        f = 2.0 * rs * np.exp(-c / safe) - 2.0 * math.sqrt(math.pi * c) * erfc(np.sqrt(c / safe))
    return np.where(pos, np.maximum(f, 0.0), 0.0)


class _PassResponse:
    """One pass's rise [K] at the depths z for a constant factor 1, as a function of the time after arrival.

    Summation by parts turns the cell sum into one over the cell edges: with q_k the flux of cell k (zero
    outside), edge k (crossed at c_k = (x_lead - x_k)/V) carries w_k = q_(k-1) - q_k and

    ``R(theta) = sum_k w_k F(theta - c_k) / (beta sqrt(pi))``   (F(s) = 0 for s <= 0).

    On a uniform grid (c_k = r tau, r = 0 .. n, tau = h/V) and at times on the lattice theta = i tau/2 (green's
    own axis: the crossings of the cell edges) that is a discrete convolution of the upsampled w
    with F on the lattice: F is evaluated once per lattice point instead of once per (time, edge). Times off
    the lattice (another body's axis, a Chebyshev node of the tail) take the direct edge sum. A time within
    ``snap`` [s] of a lattice point is taken on it: green's axis is on the lattice up to the rounding of the
    pass phases (1e-12 of the interval, :func:`shifted_sum`), which the direct sum would see as well.
    """

    def __init__(self, x_edges, flux, speed, depth, effusivity, diffusivity, snap):
        x = np.asarray(x_edges, dtype=float)
        q = np.asarray(flux, dtype=float)
        qp = np.concatenate([[0.0], q, [0.0]])
        self.w = qp[:-1] - qp[1:]                       # edge k: q_(k-1) - q_k
        self.c_edge = (x[-1] - x) / speed               # crossing times [s], decreasing in k
        self.live = self.w != 0
        self.cs = [float(z) * float(z) / (4.0 * diffusivity) for z in depth]
        self.scale = 1.0 / (effusivity * math.sqrt(math.pi))
        n = x.size - 1
        h = (x[-1] - x[0]) / n
        self.uniform = bool(np.all(np.abs(x - (x[0] + h * np.arange(n + 1))) <= 1e-10 * h))
        self.half = 0.5 * h / speed                     # lattice step tau/2 [s]
        self.n = n
        self.snap = float(snap)
        if self.uniform:
            up = np.zeros(2 * n + 1)
            up[::2] = self.w[::-1]                      # edge r from the lead at lattice 2 r
            self.up = up

    def direct(self, theta):
        """The edge sum at arbitrary times theta (m,) [s], shape (m, depths)."""
        theta = np.asarray(theta, dtype=float)
        out = np.zeros((theta.size, len(self.cs)))
        w, ce = self.w[self.live], self.c_edge[self.live]
        for lo in range(0, theta.size, 4096):           # bounded temporaries: (4096, edges)
            s = theta[lo:lo + 4096, None] - ce[None, :]
            for j, c in enumerate(self.cs):
                out[lo:lo + 4096, j] = _f_only(s, c) @ w
        return out * self.scale

    def __call__(self, theta):
        theta = np.asarray(theta, dtype=float)
        if not self.uniform or theta.size == 0:
            return self.direct(theta)
        m = np.rint(theta / self.half)
        on = (np.abs(theta - m * self.half) <= self.snap) & (m >= 0) & (m <= 64 * self.n)
        out = np.empty((theta.size, len(self.cs)))
        if np.any(on):
            mi = m[on].astype(int)
            top = int(mi.max())
            s = self.half * np.arange(top + 1)
            for j, c in enumerate(self.cs):
                out[on, j] = np.convolve(self.up, _f_only(s, c))[mi] * self.scale
        if not np.all(on):
            out[~on] = self.direct(theta[~on])
        return out


@numba.njit(cache=True)
def _tail_chebval(theta, lo, hi, coef):  # pragma: no cover - compiled
    """sqrt(theta) times the Clenshaw sum of the Chebyshev series coef (degree + 1, m) at
    u = 2 (1/theta - lo)/(hi - lo) - 1, shape (theta.size, m). Per column, four times' recurrences run
    interleaved (independent chains: 2.5x faster than one at a time, the same operations in the same order)."""
    n, m = theta.size, coef.shape[1]
    deg = coef.shape[0] - 1
    out = np.empty((n, m))
    u = np.empty(n)
    root = np.empty(n)
    for i in range(n):
        u[i] = 4.0 * (1.0 / theta[i] - lo) / (hi - lo) - 2.0
        root[i] = math.sqrt(theta[i])
    ct = np.ascontiguousarray(coef.T)
    for j in range(m):
        c = ct[j]
        i = 0
        while i + 4 <= n:
            ua, ub, uc, ud = u[i], u[i + 1], u[i + 2], u[i + 3]
            a1 = a2 = b1 = b2 = c1 = c2 = d1 = d2 = 0.0
            for k in range(deg, 0, -1):
                ck = c[k]
                a0 = ua * a1 - a2 + ck
                a2, a1 = a1, a0
                b0 = ub * b1 - b2 + ck
                b2, b1 = b1, b0
                c0 = uc * c1 - c2 + ck
                c2, c1 = c1, c0
                d0 = ud * d1 - d2 + ck
                d2, d1 = d1, d0
            out[i, j] = root[i] * (0.5 * ua * a1 - a2 + c[0])
            out[i + 1, j] = root[i + 1] * (0.5 * ub * b1 - b2 + c[0])
            out[i + 2, j] = root[i + 2] * (0.5 * uc * c1 - c2 + c[0])
            out[i + 3, j] = root[i + 3] * (0.5 * ud * d1 - d2 + c[0])
            i += 4
        while i < n:
            u2 = u[i]
            b1 = b2 = 0.0
            for k in range(deg, 0, -1):
                b0 = u2 * b1 - b2 + c[k]
                b2, b1 = b1, b0
            out[i, j] = root[i] * (0.5 * u2 * b1 - b2 + c[0])
            i += 1
    return out


def _chop(coef, tol):
    """The Chebyshev coefficients (degree + 1, m) without the trailing ones whose absolute sum (a bound on
    what dropping them changes) stays within tol (m,)."""
    tail = np.cumsum(np.abs(coef[::-1]), axis=0)[::-1]          # tail[k] = sum_(l >= k) |c_l|
    keep = coef.shape[0]
    while keep > 2 and np.all(tail[keep - 1] <= tol):
        keep -= 1
    return coef[:keep]


def _with_smooth_tail(fn, theta, after, rtol=1e-11):
    """fn(theta) (shape (theta.size, m)), with the long tail theta >= ``after`` (past the contact: the smooth
    1-D cooling) taken from a Chebyshev interpolant when that is cheaper.

    The interpolant is of fn(theta)/sqrt(theta) in w = 1/theta: each edge term F(theta - c) of
    :class:`_PassResponse` is sqrt(theta - c) times a power series in 1/(theta - c) plus a constant (which
    the edge weights' zero sum cancels), so fn/sqrt(theta) is analytic in w with its singularities at
    w = 1/c >= 1/D, at least 4x the interval's end 1/after (after = 4 D): Chebyshev coefficients fall like
    (7 + sqrt 48)^-k = 13.9^-k whatever the span of theta (a series in log(theta) needs several times the
    degree over long histories). On the Chebyshev-Lobatto points of degree d (from 16, doubling) the
    interpolant is checked at the d points the degree 2d adds between them and used once it matches fn there
    within ``rtol`` of max|fn| of each column; above degree 512 fn is evaluated directly."""
    theta = np.asarray(theta, dtype=float)
    far = theta >= after
    nfar = int(far.sum())
    near = fn(theta[~far])
    out = np.empty((theta.size, near.shape[1]))
    out[~far] = near
    if nfar == 0:
        return out
    lo, hi = 1.0 / (float(theta[far].max()) * (1.0 + 1e-12)), 1.0 / after
    if not hi > lo:
        out[far] = fn(theta[far])
        return out

    def at(u):
        th = 1.0 / (lo + (hi - lo) * (u + 1.0) / 2.0)
        return fn(th), np.sqrt(th)[:, None]
    degree = 16
    u = np.cos(math.pi * np.arange(degree + 1) / degree)
    vals, roots = at(u)
    while 2 * degree < nfar and degree <= 512:
        mid = np.cos(math.pi * (2 * np.arange(degree) + 1) / (2 * degree))
        exact, mid_roots = at(mid)
        coef = chebyshev.chebfit(u, vals / roots, degree)
        scale = np.maximum(np.maximum(np.abs(vals).max(axis=0), np.abs(exact).max(axis=0)), 1e-300)
        miss = np.abs(mid_roots * chebyshev.chebval(mid, coef).T - exact).max(axis=0)
        if np.all(miss <= rtol * scale):
            # trailing coefficients whose sum (times the largest sqrt(theta)) stays within the check's margin
            # are dropped (cheaper sums)
            big = math.sqrt(1.0 / lo)
            coef = _chop(coef.reshape(degree + 1, -1), 0.5 * (rtol * scale - miss) / big)
            out[far] = _tail_chebval(theta[far], lo, hi, np.ascontiguousarray(coef))
            return out
        u = np.concatenate([u, mid])
        vals = np.concatenate([vals, exact])
        roots = np.concatenate([roots, mid_roots])
        order = np.argsort(-u)
        u, vals, roots = u[order], vals[order], roots[order]
        degree *= 2
    out[far] = fn(theta[far])
    return out


def _pass_weights(count, step, duration, sched):
    """Per pass, the schedule's factor when it is constant over the pass's heating [k step, k step + D]
    (then that pass is the factor times the unit pass response), else NaN (integrated pass by pass)."""
    st, sf = sched
    w = np.empty(count)
    for k in range(count):
        t0, t1 = k * step, k * step + duration
        inside = (st > t0) & (st < t1)
        f0, f1 = np.interp([t0, t1], st, sf)
        flat = f0 == f1 and not np.any(inside & (sf != f0))
        w[k] = f0 if flat else np.nan
    return w


def scheduled_passes(count: int, interval: float | None, duration: float, schedule_time=None,
                     schedule_factor=None) -> np.ndarray:
    """Indices of the passes whose heating [k interval, k interval + duration] [s] meets a kink of the
    schedule (the factor not constant over it): the passes :func:`strip_history` integrates with the schedule
    rather than as a multiple of one pass's response. None of them without a schedule."""
    if schedule_time is None:
        return np.zeros(0, dtype=int)
    sched = (np.asarray(schedule_time, dtype=float), np.asarray(schedule_factor, dtype=float))
    return np.flatnonzero(~np.isfinite(_pass_weights(int(count), float(interval or 0.0), float(duration), sched)))


def _weighted_pass_sum(time, step, weights, curve):
    """``sum_k weights[k] curve(t - k step)`` over passes k with a finite weight: per distinct phase the
    pass-index table of one pass's response convolved with the weights (FFT above 64 passes)."""
    count = weights.size
    k = np.floor(time / step + 1e-9).astype(int)
    phase = np.maximum(time - k * step, 0.0)
    uph, inv = np.unique(np.round(phase / step, 12), return_inverse=True)
    uph = uph * step
    ns = np.arange(0, max(int(k.max()), 0) + 1)
    theta = (uph[:, None] + step * ns[None, :])
    vals = curve(theta.ravel())
    table = vals.reshape(theta.shape + (vals.shape[-1],))
    w = np.where(np.isfinite(weights), weights, 0.0)
    if count > 64:
        from scipy.signal import fftconvolve
        conv = fftconvolve(table, w[None, :, None], axes=1)[:, :ns.size]
    else:
        conv = np.zeros_like(table)
        for j in range(count):
            if w[j] != 0.0 and j < ns.size:
                conv[:, j:] += w[j] * table[:, :ns.size - j]
    live = k >= 0
    out = np.zeros((time.size, table.shape[-1]))
    out[live] = conv[inv.ravel()[live], np.clip(k[live], 0, ns.size - 1)]
    return out


def _split_by_schedule(start, end, q, arrival, sched_t, sched_f):
    """Cut the cells' intervals at the schedule's times; the factor (value at the start, slope) of each piece."""
    cuts = np.asarray(sched_t, dtype=float) - arrival
    s_out, e_out, q_out = [], [], []
    for s, e, qq in zip(start, end, q):
        inner = cuts[(cuts > s) & (cuts < e)]
        pts = np.concatenate([[s], inner, [e]])
        s_out.append(pts[:-1])
        e_out.append(pts[1:])
        q_out.append(np.full(pts.size - 1, qq))
    s_all, e_all, q_all = (np.concatenate(v) for v in (s_out, e_out, q_out))
    f0 = np.interp(s_all + arrival, sched_t, sched_f)
    f1 = np.interp(e_all + arrival, sched_t, sched_f)
    slope = (f1 - f0) / (e_all - s_all)
    return s_all, e_all, q_all, f0, slope


def strip_history(time, depth, x_edges, flux, effusivity: float, diffusivity: float, speed: float,
                  count: int = 1, interval: float | None = None, schedule_time=None,
                  schedule_factor=None) -> np.ndarray:
    """Temperature rise history of a material point of one body's centre strip under repeated passes.

    Parameters
    ----------
    time : array_like
        Times [s]; 0 when the first pass's leading edge (``x_edges[-1]``) reaches the point.
    depth : array_like
        Depths [m], >= 0.
    x_edges : array_like
        Cell edges of green's grid along x [m], increasing; the leading edge is the last.
    flux : array_like
        The body's heat flux per cell on the centre strip [W/m^2] (the partitioned frictional power
        density green's steady kernel integrates), one value per cell.
    effusivity : float
        beta = sqrt(lambda rho c) of the body [W s^0.5 / (m^2 K)].
    diffusivity : float
        kappa of the body [m^2/s].
    speed : float
        Speed of the body's surface through the contact [m/s], > 0.
    count : int
        Passes (revolutions for the wheel) [1].
    interval : float or None
        Time between passes [s], >= the contact duration; needed when count > 1.
    schedule_time, schedule_factor : array_like or None
        Heat-input factor f [1] at strictly increasing times [s], piecewise linear, constant ends; None:
        f = 1.

    Returns
    -------
    numpy.ndarray
        Rise above the bulk temperature [K], shape (time.size, depth.size).

    Notes
    -----
    The result is the strip's exact 1-D Duhamel integral; what separates it from the exact moving band is
    conduction along x. It is small where every pass lays down the same heat along the rail, and shows where
    the schedule varies on the scale of one pass: a heat input ramped from zero over a few contact durations
    leaves a deposit that grows across the first pass (material reached later gets more), and by the next
    pass conduction along x has carried heat from the more heated material ahead into the section. On the
    study's wheel spin (ramp 0 -> 1 over 5 ms, contact duration 0.37 ms, residual at one revolution, 91 ms)
    the first residual rise is 0.535 % below the exact band at every level, of the order kappa t / (2a)^2
    = 0.8 %, while it equals the exact 1-D integral within 1e-7; the later passes, heated under a constant
    factor, are within 0.04 % (tests/test_green_transient.py).

    References
    ----------
    .. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
    """
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    depth = np.atleast_1d(np.asarray(depth, dtype=float)).ravel()
    if np.any(depth < 0):
        raise ValueError(f"depth must be >= 0 [m], got {depth}")
    if not speed > 0:
        raise ValueError(f"speed must be > 0 [m/s], got {speed!r}")
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ValueError(f"count must be an integer >= 1, got {count!r}")
    start, end, q = _segments(x_edges, flux, speed)
    duration = (x_edges[-1] - x_edges[0]) / speed
    if count > 1 and (interval is None or interval < duration):
        raise ValueError(f"interval must be >= the contact duration {duration:g} s, got {interval!r}")
    step = 0.0 if interval is None else float(interval)
    out = np.zeros((time.size, depth.size))
    if q.size == 0:
        return out
    snap = 1e-12 * max(step, duration) + 1e-15 * duration
    response = _PassResponse(x_edges, flux, speed, depth, effusivity, diffusivity, snap)

    def one_pass(theta):
        return _with_smooth_tail(response, theta, 4.0 * duration)
    if schedule_time is None:
        return shifted_sum(time, int(count), interval, one_pass)
    sched = (np.asarray(schedule_time, dtype=float), np.asarray(schedule_factor, dtype=float))
    if np.all(sched[1] == sched[1][0]):
        return float(sched[1][0]) * shifted_sum(time, int(count), interval, one_pass)
    # passes heated under a constant factor: that factor times one pass's response (weighted sum over the
    # passes); passes whose heating meets a kink of the schedule: integrated pass by pass
    weights = _pass_weights(int(count), step, duration, sched)
    if count == 1 or interval is None:
        out = weights[0] * one_pass(time) if np.isfinite(weights[0]) else out
    else:
        out = _weighted_pass_sum(time, step, weights, one_pass)
    for k in np.nonzero(~np.isfinite(weights))[0]:
        rows = np.nonzero(time - k * step > 0)[0]
        if rows.size == 0:
            continue
        s, e, qq, f0, slope = _split_by_schedule(start, end, q, k * step, *sched)
        for j, z in enumerate(depth):
            out[rows, j] += _response(time[rows] - k * step, z, s, e, qq, f0, slope, effusivity, diffusivity)
    return out


def strip_time_axis(x_edges, speed: float, count: int = 1, interval: float | None = None,
                    tail_samples: int = 40, per_cell: int = 1, dense=()) -> np.ndarray:
    """Green's own time axis [s]: in every pass the crossing times of the cell edges (``per_cell`` = 1: one
    sample per cell, >= 20 per contact duration from 20 cells on, 32 at level 0; 2: the edges and the
    centres), then the same times after the contact (cooling, over one more contact duration), then
    ``tail_samples`` geometrically spaced to the next pass (the last: one interval after it; one pass without
    interval: to 100 contact durations). Every sample lies on the lattice of :class:`_PassResponse`. One
    sample per cell keeps the sampled peak's error (h^2) below the strip's own (h^1.5) and time above a
    threshold within 0.05 % of the contact duration at level 0 (tests/test_green_transient.py), at half the
    samples of every pass (the cost of long histories is their samples). The passes in ``dense`` (those a
    schedule's kink meets, :func:`scheduled_passes`: a short spike peaks between two edge crossings) take
    the edges and the centres.

    Parameters
    ----------
    x_edges : array_like
        Cell edges along x [m].
    speed : float
        Surface speed [m/s].
    count : int
        Passes [1].
    interval : float or None
        Time between passes [s].
    tail_samples : int
        Samples between two contact durations after the arrival and the next pass [1].
    per_cell : int
        Samples per cell crossing over the two contact durations after each arrival, 1 or 2 [1].
    dense : sequence of int
        Passes sampled at 2 per cell crossing whatever ``per_cell``.

    Returns
    -------
    numpy.ndarray
        Increasing times [s] from 0 to count * interval.
    """
    x_edges = np.asarray(x_edges, dtype=float)
    d = (x_edges[-1] - x_edges[0]) / speed
    span = interval if interval is not None else 100.0 * d
    if per_cell not in (1, 2):
        raise ValueError(f"per_cell must be 1 or 2 (samples per cell crossing), got {per_cell!r}")

    def pass_offsets(per):
        n = per * (x_edges.size - 1)
        out = np.linspace(0.0, min(2.0 * d, span), 2 * n + 1)
        if span > 2.0 * d:
            out = np.concatenate([out, np.geomspace(2.0 * d, span, int(tail_samples) + 1)[1:]])
        return out[:-1]
    offsets = pass_offsets(int(per_cell))
    passes = (np.arange(int(count))[:, None] * span + offsets[None, :]).ravel()
    dense = sorted({int(k) for k in dense if 0 <= int(k) < int(count)}) if int(per_cell) == 1 else []
    if not dense:
        return np.concatenate([passes, [int(count) * span]])
    fine = pass_offsets(2)
    per_pass = [k * span + (fine if k in dense else offsets) for k in range(int(count))]
    return np.concatenate(per_pass + [[int(count) * span]])
