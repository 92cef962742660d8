"""Green's transient: Duhamel superposition in time of the 1-D strip solution at a fixed material point.

The point at the fixed section, on the centre strip y = 0, at depth z, lies under the contact while
x = x_lead - V (t - t_k) crosses the patch (pass k arrives at t_k = k interval). Each strip is a 1-D
half-space heated only through its surface, so the history is the 1-D Duhamel integral (Carslaw & Jaeger
1959, 2.9): ``T(z, t) = 1/(beta sqrt(pi)) int f(t') q(t') exp(-z^2/(4 kappa (t - t'))) dt' / sqrt(t - t')``,
beta = sqrt(lambda rho c), q the strip's flux (piecewise constant per cell), f the piecewise-linear schedule;
each interval is integrated exactly (:func:`_f_g`); on a 3-D contact the strips weighted by the lateral Gaussian
(:mod:`railtherm_green.lateral`). Neglected: conduction along x (the high-Péclet limit). The problem is linear, so
one pass's response serves every pass (:func:`_unit_pass_sum`); a temperature-dependent flux would break this, and
green refuses such scenes (:func:`railtherm.physics.superposition_limits`). Derivation: docs/NOTES.md, "Green's transient".

References: [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
temperatures in wheel/rail contact, Wear 253 (2002) 498-508 (DOI not verified, see docs/references.md).
[2] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
"""
from __future__ import annotations

import math

import numba
import numpy as np
from railtherm.references.transient import shifted_sum
from scipy.special import erfc

from .lateral import LateralPassResponse, scheduled_lateral
from .pass_response import PassResponse
from .smooth_tail import checked_tail, chebval_into, with_smooth_tail

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
        from scipy.signal import fftconvolve  # scipy.signal: ~1 s to import, for schedules of over 64 passes only
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
                  schedule_factor=None, y_edges=None) -> np.ndarray:
    """Temperature rise history of a material point of one body's centre line under repeated passes.

    Parameters
    ----------
    time : array_like
        Times [s]; 0 when the first pass's leading edge (``x_edges[-1]``) reaches the point.
    depth : array_like
        Depths [m], >= 0.
    x_edges : array_like
        Cell edges of green's grid along x [m], increasing; the leading edge is the last.
    flux : array_like
        The body's heat flux per cell [W/m^2] (the partitioned frictional power density green's steady kernel
        integrates): on the centre strip, one value per cell (nx,) (a line contact: uniform in y), or on every
        strip (nx, ny) with ``y_edges`` (a 3-D contact: the strips' responses weighted by the lateral Gaussian,
        :mod:`railtherm_green.lateral`).
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
    y_edges : array_like or None
        Cell edges across the strips [m], increasing, (ny + 1,), with a flux (nx, ny).

    Returns
    -------
    numpy.ndarray
        Rise above the bulk temperature [K], shape (time.size, depth.size).

    Notes
    -----
    The result is the exact Duhamel integral without conduction along x (on a 3-D contact with the strips'
    lateral Gaussian, :mod:`railtherm_green.lateral`); what separates it from the exact moving band or ellipse is
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
    time, depth, step, duration = _checked_strip(time, depth, x_edges, flux, speed, count, interval, y_edges)
    if not np.asarray(flux).any():
        return np.zeros((time.size, depth.size))
    snap = 1e-12 * max(step, duration) + 1e-15 * duration
    response = (LateralPassResponse(x_edges, y_edges, flux, speed, depth, effusivity, diffusivity, snap)
                if np.ndim(flux) == 2 else PassResponse(x_edges, flux, speed, depth, effusivity, diffusivity, snap))

    def one_pass(theta):
        return with_smooth_tail(response, theta, 4.0 * duration, far=response.far, passes=int(count),
                                power=response.tail_power)
    if schedule_time is None:
        return _unit_pass_sum(time, int(count), interval, response, 4.0 * duration)
    sched = (np.asarray(schedule_time, dtype=float), np.asarray(schedule_factor, dtype=float))
    if np.all(sched[1] == sched[1][0]):
        return float(sched[1][0]) * _unit_pass_sum(time, int(count), interval, response, 4.0 * duration)
    weights = _pass_weights(int(count), step, duration, sched)
    out = _constant_factor_passes(time, depth.size, step, weights, one_pass)
    for k in np.flatnonzero(~np.isfinite(weights)):      # passes whose heating meets a kink: with the schedule
        rows = np.flatnonzero(time - k * step > 0)
        if rows.size:
            out[rows] += _scheduled_history(time[rows] - k * step, depth, x_edges, response, speed, k * step, sched,
                                            effusivity, diffusivity)
    return out


def _scheduled_history(theta, depth, x_edges, response, speed, arrival, sched, effusivity, diffusivity):
    """Rise [K] (theta.size, depth.size) of the pass arriving at ``arrival`` [s] under the schedule at the times
    theta > 0 after it: the centre strip's exact integral (:func:`_scheduled_pass`), on a 3-D contact plus its
    strips' lateral term (:func:`railtherm_green.lateral.scheduled_lateral`)."""
    lateral = isinstance(response, LateralPassResponse)
    centre = response.base_flux if lateral else response.flux
    out = _scheduled_pass(theta, depth, _segments(x_edges, centre, speed), arrival, sched, effusivity, diffusivity)
    if lateral:
        out += scheduled_lateral(theta, response, _lateral_pieces(x_edges, speed, arrival, sched))
    return out


def _lateral_pieces(x_edges, speed, arrival, sched):
    """Every cell's crossing interval after the arrival [s] cut at the schedule's times: (start, end, cell index,
    factor at the start [1], slope [1/s]) for :func:`railtherm_green.lateral.scheduled_lateral`."""
    x_edges = np.asarray(x_edges, dtype=float)
    lead = x_edges[-1]
    cells = np.arange(x_edges.size - 1, dtype=float)
    s, e, idx, f0, slope = _split_by_schedule((lead - x_edges[1:]) / speed, (lead - x_edges[:-1]) / speed, cells,
                                              arrival, *sched)
    return s, e, idx.astype(int), f0, slope


def _checked_strip(time, depth, x_edges, flux, speed, count, interval, y_edges=None):
    """time [s] and depth [m] as 1-D arrays, the time between passes [s] (0 for one pass without interval)
    and the contact duration D [s]; ValueError naming the bad argument of :func:`strip_history`."""
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    depth = np.atleast_1d(np.asarray(depth, dtype=float)).ravel()
    x_edges = np.asarray(x_edges, dtype=float)
    if x_edges.ndim != 1 or np.shape(flux)[:1] != (x_edges.size - 1,) or np.ndim(flux) not in (1, 2):
        raise ValueError(f"flux must have one value per cell along x: {x_edges.size - 1} (and per strip with "
                         f"y_edges), got shape {np.shape(flux)}")
    if np.ndim(flux) == 2 and (y_edges is None or np.shape(y_edges) != (np.shape(flux)[1] + 1,)):
        raise ValueError(f"y_edges must be the {np.shape(flux)[1] + 1} cell edges across the strips of a flux of "
                         f"shape {np.shape(flux)} [m], got {None if y_edges is None else np.shape(y_edges)}")
    if not (x_edges[1:] > x_edges[:-1]).all():
        raise ValueError("x_edges must be strictly increasing [m]")
    if (depth < 0).any():
        raise ValueError(f"depth must be >= 0 [m], got {depth}")
    if not speed > 0:
        raise ValueError(f"speed must be > 0 [m/s], got {speed!r}")
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ValueError(f"count must be an integer >= 1, got {count!r}")
    duration = (x_edges[-1] - x_edges[0]) / speed
    if count > 1 and (interval is None or interval < duration):
        raise ValueError(f"interval must be >= the contact duration {duration:g} s, got {interval!r}")
    return time, depth, 0.0 if interval is None else float(interval), duration


def _unit_pass_sum(time, count, interval, response, after):
    """``sum_k R(t - k interval)``, k = 0 .. count - 1, of one pass's unit response R (:class:`PassResponse`,
    its tail from ``after`` [s] on by :func:`with_smooth_tail`; zero at t <= 0): on an axis whose passes repeat
    one pass's offsets (green's own, :func:`strip_time_axis`) by :func:`_periodic_tail_sum` (every pass but the
    first in the tail) or :func:`_periodic_pass_sum`, else by :func:`railtherm.references.transient.shifted_sum`."""

    def one_pass(theta):
        return with_smooth_tail(response, theta, after, far=response.far, passes=count, power=response.tail_power)
    offsets = None if interval is None else _periodic_offsets(time, count, float(interval))
    if offsets is None:
        return shifted_sum(time, count, interval, one_pass)
    out = _periodic_tail_sum(time, count, float(interval), offsets, response, after) if interval >= after else None
    return _periodic_pass_sum(time, count, float(interval), offsets, one_pass) if out is None else out


def _periodic_offsets(time, count, step):
    """The offsets (per,) [s] when the first count * per samples of ``time`` are ``count`` passes repeating them
    ``step`` apart, each in [0, step) (the phases :func:`railtherm.references.transient.shifted_sum` merges:
    within 1e-12 step, rounded to it as there), else None."""
    per = time.size // count
    if count < 2 or per == 0 or not _repeats(time, count, per, step):
        return None
    return np.round(time[:per] / step, 12) * step


@numba.njit(cache=True)
def _repeats(time, count, per, step):  # pragma: no cover - compiled
    """Whether time[p per + i] - p step equals time[i] within 1e-12 step for p < count, i < per, with the first
    per times in [0, step (1 - 1e-9)) (the pass index shifted_sum gives them)."""
    for i in range(per):
        if not (time[i] >= 0.0 and time[i] < step * (1.0 - 1e-9)):
            return False
    for p in range(1, count):
        start = step * p
        for i in range(per):
            if abs(time[p * per + i] - start - time[i]) > 1e-12 * step:
                return False
    return True


def _periodic_pass_sum(time, count, step, offsets, curve):
    """``sum_k curve(t - k step)`` on a periodic axis (:func:`_periodic_offsets`): pass p's samples at offset o
    get ``sum_(n <= p) curve(o + n step)``, one cumulative sum over n of the table curve(offsets x passes) (what
    ``shifted_sum`` gathers after sorting the phases out); the samples after the passes (green's: the last
    pass's end) sum their ``count`` terms. One call of ``curve`` for all (one tail interpolant); its times are
    > 0 but at offset 0 of pass 0, whose value is set to 0. The call also takes the last offset plus ``count``
    steps, the end of ``shifted_sum``'s table, so that the tail interpolant spans the same times as there: its
    error (within 1e-11 of the response's maximum, summed over the passes) is then the same in both sums."""
    per = offsets.size
    block = count * per
    rest = time[block:]
    theta = np.empty(block + rest.size * count + 1)
    np.add(offsets[None, :], step * np.arange(count)[:, None], out=theta[:block].reshape(count, per))
    np.subtract(rest[:, None], step * np.arange(count)[None, :], out=theta[block:-1].reshape(rest.size, count))
    theta[-1] = offsets[-1] + step * count
    vals = curve(theta)[:-1]
    vals[theta[:-1] <= 0.0] = 0.0
    out = np.empty((time.size, vals.shape[1]))
    np.cumsum(vals[:block].reshape(count, per, -1), axis=0, out=out[:block].reshape(count, per, -1))
    out[block:] = vals[block:].reshape(rest.size, count, -1).sum(axis=1)
    return out


def _periodic_tail_sum(time, count, step, offsets, response, after, rtol=1e-11):
    """:func:`_periodic_pass_sum` of the unit response when every pass after the first lies in its tail
    (step >= after), without the table: the tail interpolant is fitted once on the same times as there (up to
    the last offset plus ``count`` steps), the first pass's offsets before ``after`` take the response itself,
    and the later passes are interpolated and summed in one compiled loop (:func:`_tail_cumsum`; the same
    values and additions as the table's). None when the tail is not interpolated (then the table)."""
    per = offsets.size
    block = count * per
    rest = time[block:]
    rest_theta, longest, nfar = _table_span(offsets, rest, count, step, after)
    lo, hi = 1.0 / (longest * (1.0 + 1e-12)), 1.0 / after
    if not hi > lo or nfar <= 32:
        return None
    power = response.tail_power
    coef = checked_tail(response.far, lo, hi, nfar, rtol, count, power)
    if coef is None:
        return None
    out = np.empty((time.size, response.cs.size))
    _tail_cumsum(offsets, step, lo, hi, coef, response.with_tail(offsets, after, lo, hi, coef),
                 out[:block].reshape(count, per, -1), power)
    if rest.size:
        tail = response.with_tail(rest_theta, after, lo, hi, coef)
        out[block:] = tail.reshape(rest.size, count, -1).sum(axis=1)
    return out


@numba.njit(cache=True)
def _table_span(offsets, rest, count, step, after):  # pragma: no cover - compiled
    """For :func:`_periodic_tail_sum`: the times (rest.size * count,) [s] after each pass's arrival of the samples
    after the passes, the longest time of the table of :func:`_periodic_pass_sum` (its last offset plus ``count``
    steps, or longer) and how many of its times reach ``after`` [s]."""
    per = offsets.size
    rest_theta = np.empty(rest.size * count)
    longest = max(offsets[per - 1] + step * count, offsets.max() + step * (count - 1))
    nfar = count * per + rest.size * count + 1
    for i in range(per):
        nfar -= offsets[i] < after
    for r in range(rest.size):
        for k in range(count):
            t = rest[r] - step * k
            rest_theta[r * count + k] = t
            longest = max(longest, t)
            nfar -= t < after
    return rest_theta, longest, nfar


@numba.njit(cache=True)
def _tail_cumsum(offsets, step, lo, hi, coef, first, out, power):  # pragma: no cover - compiled
    """out[p, i] = sum_(n <= p) R(offsets[i] + n step) (count, per, m): ``first`` (per, m) the first pass
    (n = 0), the later ones from the tail interpolant by :func:`chebval_into` (as :func:`tail_chebval`),
    added in order of n as a cumulative sum does."""
    count, per, m = out.shape
    ct = np.ascontiguousarray(coef.T)
    theta = np.empty(per)
    row = np.empty((per, m))
    for i in range(per):                # element by element: a block assignment compiles numba's shape-error text
        for j in range(m):
            out[0, i, j] = first[i, j]
    for p in range(1, count):
        shift = step * p
        for i in range(per):
            theta[i] = offsets[i] + shift
        chebval_into(theta, lo, hi, ct, row, power)
        for i in range(per):
            for j in range(m):
                out[p, i, j] = out[p - 1, i, j] + row[i, j]
    return out


def _constant_factor_passes(time, depths, step, weights, one_pass):
    """The passes heated under a constant factor of the schedule (``weights``: per pass the factor, NaN where a
    kink of the schedule meets the pass's heating, :func:`_pass_weights`): that factor times one pass's
    response, summed over them (:func:`_weighted_pass_sum`), shape (time.size, depths)."""
    if weights.size == 1 or step == 0.0:
        if np.isfinite(weights[0]):
            return weights[0] * one_pass(time)
        return np.zeros((time.size, depths))
    return _weighted_pass_sum(time, step, weights, one_pass)


def _scheduled_pass(theta, depth, segments, arrival, sched, effusivity, diffusivity):
    """Rise [K] (theta.size, depth.size) of the pass arriving at ``arrival`` [s] at the times theta > 0 after its
    arrival, its cells' intervals cut at the schedule's times and each piece integrated exactly with the
    factor linear on it (:func:`_response`)."""
    s, e, qq, f0, slope = _split_by_schedule(*segments, arrival, *sched)
    out = np.empty((theta.size, depth.size))
    for j, z in enumerate(depth):
        out[:, j] = _response(theta, z, s, e, qq, f0, slope, effusivity, diffusivity)
    return out


def _linspace(start, stop, num):
    """np.linspace(start, stop, num)'s values (start + i (stop - start)/(num - 1), the last set to stop) without its
    argument handling: the axis is built once per body and solve."""
    out = np.arange(num, dtype=float)
    if num > 1:
        out *= (stop - start) / (num - 1)
        out += start
        out[-1] = stop
    else:
        out[:] = start
    return out


def strip_time_axis(x_edges, speed: float, count: int = 1, interval: float | None = None,
                    tail_samples: int = 40, per_cell: int = 1, dense=()) -> np.ndarray:
    """Green's own time axis [s]: in every pass the crossing times of the cell edges (``per_cell`` = 1: one
    sample per cell, >= 20 per contact duration from 20 cells on, 32 at level 0; 2: the edges and the
    centres), then the same times after the contact (cooling, over one more contact duration), then
    ``tail_samples`` geometrically spaced to the next pass (the last: one interval after it; one pass without
    interval: to 100 contact durations). Every sample lies on the lattice of :class:`PassResponse`. One
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
        out = _linspace(0.0, min(2.0 * d, span), 2 * n + 1)
        if span > 2.0 * d:                              # np.geomspace's values (10 ** linspace of the logs) but
            tail = np.power(10.0, _linspace(np.log10(2.0 * d), np.log10(span), int(tail_samples) + 1))
            out = np.concatenate([out, tail[1:]])       # its end, set to span there: dropped here
        return out[:-1]
    offsets = pass_offsets(int(per_cell))
    dense = sorted({int(k) for k in dense if 0 <= int(k) < int(count)}) if int(per_cell) == 1 and len(dense) else []
    if not dense:
        out = np.empty(int(count) * offsets.size + 1)
        np.add(np.arange(int(count))[:, None] * span, offsets[None, :],
               out=out[:-1].reshape(int(count), offsets.size))
        out[-1] = int(count) * span
        return out
    fine = pass_offsets(2)
    per_pass = [k * span + (fine if k in dense else offsets) for k in range(int(count))]
    return np.concatenate(per_pass + [[int(count) * span]])
