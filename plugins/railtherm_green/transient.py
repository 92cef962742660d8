"""Green's transient: Duhamel superposition in time of the 1-D strip solution at a fixed material point.

The material point at the fixed section, on the centre strip y = 0, at depth z, lies under the contact
while its position relative to the contact, x = x_lead - V (t - t_k), crosses the patch (pass k arrives,
leading edge first, at t_k = k interval). In green's model each strip is a 1-D half-space heated only
through its surface (no conduction along x or y), so the point's history is the 1-D Duhamel integral of
the flux it meets (Carslaw & Jaeger 1959, 2.9):

``T(z, t) = 1/(beta sqrt(pi)) int f(t') q(t') exp(-z^2/(4 kappa (t - t'))) dt' / sqrt(t - t')``,

beta = sqrt(lambda rho c) the effusivity, q(t') the strip's flux at the point's position (piecewise
constant per cell of green's grid, as in the steady kernel), f the heat-input schedule (piecewise
linear). Each (cell, schedule piece) interval is integrated exactly: with s = t - t', c = z^2/(4 kappa),

``F(s) = int_0^s exp(-c/u) du/sqrt(u) = 2 sqrt(s) exp(-c/s) - 2 sqrt(pi c) erfc(sqrt(c/s))``,
``G(s) = int_0^s sqrt(u) exp(-c/u) du = (2/3) (s^(3/2) exp(-c/s) - c F(s))``,

and a factor f_p + m (t' - p) on [p, r] contributes ``(f_p + m (t - p)) [F] - m [G]`` between
s = t - min(r, t) and t - p. The 1-D Green function is exact in time; what the model neglects is
conduction along x (in the patch and, between passes, along the rail) and across the strips (y): the
heat a 3-D contact's centre strip loses sideways while it cools between passes.

Superposition: the problem is linear, so with a constant factor one pass's response serves every pass
(evaluated once per distinct shift t - t_k; on a time axis with the same offsets in every pass, a
1,000-pass history costs (offsets) x (passes) evaluations of the cell sums); a schedule that is not
constant is integrated pass by pass. Where the flux itself depends on temperature (a temperature-
dependent friction law) the passes are no longer independent and this superposition does not hold.

References
----------
.. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
   temperatures in wheel/rail contact, Wear 253 (2002) 498-508 (DOI not verified, see docs/references.md)
.. [2] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
"""
from __future__ import annotations

import math

import numpy as np
from numpy.polynomial import chebyshev
from railtherm.references.transient import shifted_sum
from scipy.special import erfc

__all__ = ["strip_history", "strip_time_axis"]


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


def _with_smooth_tail(fn, theta, after, rtol=1e-11):
    """fn(theta), with the long tail theta >= ``after`` (past the contact: the smooth 1-D cooling) taken
    from a Chebyshev interpolant in log(theta) when that is cheaper. The degree doubles from 32 until the
    interpolant matches fn at 257 log-spaced check points within ``rtol`` of max|fn| there (measured:
    degree 48 reaches 1e-12 for z <= 1 mm over 4 D .. 50 s); above degree 512 fn is evaluated directly."""
    theta = np.asarray(theta, dtype=float)
    far = theta >= after
    out = np.empty(theta.shape)
    out[~far] = fn(theta[~far])
    nfar = int(far.sum())
    if nfar == 0:
        return out
    lo, hi = math.log(after), math.log(float(theta[far].max()) * (1.0 + 1e-12))
    check = np.exp(np.linspace(lo, hi, 257))
    exact = fn(check)
    degree = 32
    while 2 * degree + check.size < nfar and degree <= 512:
        u = np.cos(math.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
        coef = chebyshev.chebfit(u, fn(np.exp(lo + (hi - lo) * (u + 1.0) / 2.0)), degree)

        def interp(t):
            return chebyshev.chebval(2.0 * (np.log(t) - lo) / (hi - lo) - 1.0, coef)
        if np.max(np.abs(interp(check) - exact)) <= rtol * max(np.max(np.abs(exact)), 1e-300):
            out[far] = interp(theta[far])
            return out
        degree *= 2
    out[far] = fn(theta[far])
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
    sched = None
    const = 1.0
    if schedule_time is not None:
        sched = (np.asarray(schedule_time, dtype=float), np.asarray(schedule_factor, dtype=float))
        if np.all(sched[1] == sched[1][0]):
            const, sched = float(sched[1][0]), None
    if sched is None:
        # one pass's response for every pass: evaluated per (phase, pass index), summed by cumulative sums
        ones, flat = np.ones(q.size), np.zeros(q.size)

        def one_pass(theta):
            return np.stack([_with_smooth_tail(
                lambda th, z=z: _response(th, z, start, end, q, ones, flat, effusivity, diffusivity),
                theta, 4.0 * duration) for z in depth], axis=1)
        return const * shifted_sum(time, int(count), interval, one_pass)
    for k in range(int(count)):
        rows = np.nonzero(time - k * step > 0)[0]
        if rows.size == 0:
            continue
        s, e, qq, f0, slope = _split_by_schedule(start, end, q, k * step, *sched)
        for j, z in enumerate(depth):
            out[rows, j] += _response(time[rows] - k * step, z, s, e, qq, f0, slope, effusivity, diffusivity)
    return out


def strip_time_axis(x_edges, speed: float, count: int = 1, interval: float | None = None,
                    tail_samples: int = 40) -> np.ndarray:
    """Green's own time axis [s]: in every pass the crossing times of the cell edges and centres (2 samples
    per cell: >= 20 per contact duration from 10 cells on), then the same times after the contact
    (cooling, over one more contact duration), then ``tail_samples`` geometrically spaced to the next pass
    (the last: one interval after it; one pass without interval: to 100 contact durations).

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

    Returns
    -------
    numpy.ndarray
        Increasing times [s] from 0 to count * interval.
    """
    x_edges = np.asarray(x_edges, dtype=float)
    d = (x_edges[-1] - x_edges[0]) / speed
    span = interval if interval is not None else 100.0 * d
    n = 2 * (x_edges.size - 1)
    offsets = np.linspace(0.0, min(2.0 * d, span), 2 * n + 1)
    if span > 2.0 * d:
        offsets = np.concatenate([offsets, np.geomspace(2.0 * d, span, int(tail_samples) + 1)[1:]])
    return np.concatenate([k * span + offsets[:-1] for k in range(int(count))] + [[int(count) * span]])
