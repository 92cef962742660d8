"""Exact transient histories of a half-space under repeated passes of a moving surface source.

The same source (:class:`MovingSource`: band or ellipse, uniform or Hertz flux) passes the fixed
section ``count`` times, ``interval`` apart, with a heat-input schedule in the history's time
(:class:`Schedule`). The problem is linear: the history is the sum of the passes' responses
(:func:`~railtherm.references.transient_pass.pass_response`; derivation in docs/NOTES.md, "Exact pass
response"). The response to the schedule's first value (held since t = -inf) is the same curve for
every pass, summed by :func:`shifted_sum`; the schedule's departure from it is integrated pass by pass.
:func:`pass_summary` gives per-pass peaks and residual rises, :func:`time_above` the time above a rise.

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959,
sections 10.2, 10.3 and 10.7. ISBN 978-0198533689. [2] J.C. Jaeger, Moving sources of heat and the
temperature at sliding contacts, J. Proc. Roy. Soc. New South Wales 76 (1942) 203-224.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from .checked_interpolant import CheckedInterpolant
from .flash import thermal_properties
from .transient_pass import (MovingSource, Schedule, _as_depth, _constant_part, _schedule_part, _split,
                             pass_level, pass_response, upstream_reach)

__all__ = ["MovingSource", "Schedule", "PassSummary", "history_time_axis", "pass_response",
           "temperature_history", "pass_summary", "shifted_sum", "time_above"]


@dataclass(frozen=True)
class PassSummary:
    """Per-pass results: ``peak`` [K] and ``peak_time`` [s] of shape (count, depths), the maximum rise
    over [k interval, (k + 1) interval); ``residual`` [K] of shape (count, depths), the rise at
    (k + 1) interval left by passes 0 .. k (just before the next pass, without the conduction ahead of
    the arriving contact, which a 1-D model cannot have; after the last pass, one interval after it)."""

    peak: np.ndarray
    peak_time: np.ndarray
    residual: np.ndarray


# ------------------------------------------------------------------------------------------------
# passes
# ------------------------------------------------------------------------------------------------
def _check_passes(count, interval, source):
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ValueError(f"count must be an integer >= 1, got {count!r}")
    if count > 1 or interval is not None:
        if interval is None or not (interval >= source.contact_duration and math.isfinite(interval)):
            raise ValueError(f"interval must be >= the contact duration {source.contact_duration:g} s, "
                             f"got {interval!r} [s]")


def history_time_axis(source: MovingSource, count: int = 1, interval: float | None = None,
                      samples_per_contact: int = 20, tail_samples: int = 40) -> np.ndarray:
    """Time axis of a history [s]: for each pass the same offsets, ``samples_per_contact`` per contact
    duration D over [0, 2 D], then ``tail_samples`` geometrically spaced up to the next pass (the last
    pass: one interval after it; a single pass without interval: up to 100 D). The common offsets let
    :func:`temperature_history` reuse one pass's response for all passes.

    Parameters
    ----------
    source : MovingSource
        The source.
    count : int
        Number of passes [1].
    interval : float or None
        Time between passes [s], >= D.
    samples_per_contact : int
        Samples per contact duration near each pass [1].
    tail_samples : int
        Samples between 2 D and the next pass [1].

    Returns
    -------
    numpy.ndarray
        Increasing times [s] from 0 to count * interval.
    """
    _check_passes(count, interval, source)
    d = source.contact_duration
    span = interval if interval is not None else 100.0 * d
    offsets = np.linspace(0.0, min(2.0 * d, span), int(2 * samples_per_contact) + 1)
    if span > 2.0 * d:
        offsets = np.concatenate([offsets, np.geomspace(2.0 * d, span, int(tail_samples) + 1)[1:]])
    return np.concatenate([k * span + offsets[:-1] for k in range(count)] + [[count * span]])


def shifted_sum(time, count: int, interval: float | None, curve, reach: float = 0.0,
                through_pass=None) -> np.ndarray:
    """Sum of one pass's response over passes: ``out(t) = sum_k curve(t - k interval)``, k = 0 .. count - 1.

    Each time is split into its pass index n and phase t - n interval; ``curve`` is evaluated once per
    (distinct phase, n) and the passes are summed by cumulative sums over n. On an axis whose passes share
    their offsets (:func:`history_time_axis`) that is (offsets) x (count) evaluations and no
    (samples) x (count) work at all.

    Parameters
    ----------
    time : array_like
        Times [s].
    count : int
        Passes [1].
    interval : float or None
        Time between passes [s] (None: one pass).
    curve : callable
        Response of one pass arriving at 0, ``curve(theta) -> array (theta.size, m)`` [any unit].
    reach : float
        A pass contributes only where t - k interval > -reach [s] (its response ahead of arrival).
    through_pass : array_like of int or None
        Per time, the last pass counted [1]; None: all.

    Returns
    -------
    numpy.ndarray
        Shape (time.size, m).
    """
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    last = np.full(time.size, count - 1) if through_pass is None else \
        np.minimum(np.asarray(through_pass, dtype=int).ravel(), count - 1)
    if interval is None or count == 1:
        live = (time > -reach) & (last >= 0)
        first = curve(time[live]) if np.any(live) else np.zeros((0, 1))
        out = np.zeros((time.size, first.shape[1]))
        out[live] = first
        return out
    step = float(interval)
    k = np.floor(time / step + 1e-9).astype(int)
    phase = np.maximum(time - k * step, 0.0)
    uph, inv = np.unique(np.round(phase / step, 12), return_inverse=True)
    inv = inv.ravel()
    uph = uph * step
    n_lo = -int(math.ceil(reach / step)) - 1
    n_hi = max(int(k.max()), n_lo)
    ns = np.arange(n_lo, n_hi + 1)
    theta = (uph[:, None] + step * ns[None, :]).ravel()
    live = np.flatnonzero(theta > -reach)
    vals = curve(theta[live])
    m = vals.shape[1]
    table = np.zeros((theta.size, m))
    table[live] = vals                                  # rows (phase, n) of one pass's response
    # cumulative sums over n, a zero row first; flat rows (phase, n) index the gathers below
    cum = np.zeros((uph.size, ns.size + 1, m))
    np.cumsum(table.reshape(uph.size, ns.size, m), axis=1, out=cum[:, 1:])
    cum = cum.reshape(-1, m)
    # passes j = 0 .. last: n = k - j from k - last to k, within the table's n range
    hi = np.clip(k - n_lo + 1, 0, ns.size)
    lo = np.clip(k - last - n_lo, 0, ns.size)
    lo = np.minimum(lo, hi)
    row = inv * (ns.size + 1)
    # np.take along the rows: the same copies as cum[index], several times faster on long axes
    if n_lo != -1:
        return np.take(cum, row + hi, axis=0) - np.take(cum, row + lo, axis=0)
    # nothing ahead of arrival (reach <= 0): the row n = -1 is zero, so is every lower sum up to it
    out = np.take(cum, row + hi, axis=0)
    below = np.flatnonzero(lo > 1)
    out[below] -= np.take(cum, row[below] + lo[below], axis=0)
    return out


#: the sum over passes of one pass's tail (2 D after its arrival on) is interpolated to this fraction of the
#: largest rise of one pass at each depth (:func:`_with_checked_tail`), divided among the passes ...
TAIL_TOLERANCE = 1e-7
#: ... but each pass's tail to no less than this fraction: the steady sweep's own quadrature scatters by up to
#: about 4e-9 of its largest value far behind the source at depth (railtherm.references.jaeger), and no check
#: resolves less; with 1,000 passes the bound is 1e-5 of the largest rise (their errors have both signs:
#: tests/test_references_transient_tail.py measures the sum), with 10 passes 1e-8
TAIL_FLOOR = 1e-8
#: ... when the tail is asked at more delays than this (below, its exact values cost less than the fit)
TAIL_MIN_DELAYS = 2000


def _with_checked_tail(curve, duration: float, count: int):
    """``curve`` (one pass's response to a constant factor) with its tail theta >= 2 D replaced by a
    :class:`~.checked_interpolant.CheckedInterpolant` of it when asked at more than :data:`TAIL_MIN_DELAYS`
    delays there: behind the source the response is smooth and decays slowly, and a history of many passes asks
    it at (samples per pass) x (passes) delays. Each piece is checked to max(:data:`TAIL_TOLERANCE` / ``count``,
    :data:`TAIL_FLOOR`) of the response's largest value at each depth (sampled over [0, 2 D] and geometrically
    over the tail; at depth it peaks long after the pass), so that the passes' errors add up to at most
    ``count`` times that fraction of it, and of the history, which is at least as large."""
    start = 2.0 * duration

    def with_tail(theta):
        tail = theta >= start
        if np.count_nonzero(tail) <= TAIL_MIN_DELAYS:
            return curve(theta)
        hi = max(float(theta[tail].max()), 1.001 * start)
        head = curve(theta[~tail]) if np.any(~tail) else None
        probe = np.concatenate([np.linspace(0.0, start, 81), np.geomspace(start, hi, 161)[1:]])
        scale = np.max(np.abs(curve(probe)), axis=0)
        rtol = max(TAIL_TOLERANCE / count, TAIL_FLOOR)
        fit = CheckedInterpolant(curve, start, hi, np.maximum(scale, np.finfo(float).tiny) * rtol)
        vals = fit(theta[tail])
        out = np.empty((theta.size, vals.shape[1]))
        out[tail] = vals
        if head is not None:
            out[~tail] = head
        return out
    return with_tail


def temperature_history(time, depth, source: MovingSource, material, count: int = 1,
                        interval: float | None = None, schedule: Schedule | None = None,
                        quad_points: int = 12, inner_points: int = 48,
                        via_time_integral: bool = False, through_pass=None) -> np.ndarray:
    """Temperature rise history of the fixed material point under ``count`` passes.

    The response to the schedule's first value (held from t = -inf) is one curve for every pass,
    shifted: it is evaluated once per distinct shift, so a time axis from :func:`history_time_axis`
    costs (offsets per pass) x (count) evaluations whatever the schedule. The schedule's departure
    from that value is integrated in time for each pass.

    Parameters
    ----------
    time : array_like
        Times [s] (time 0: the first pass's leading edge reaches the section).
    depth : array_like
        Depths [m], >= 0.
    source : MovingSource
        The source.
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density and specific_heat).
    count : int
        Number of passes [1].
    interval : float or None
        Time between passes [s], >= the contact duration (needed when count > 1).
    schedule : Schedule or None
        Heat-input factor [1]; None: 1.
    quad_points, inner_points : int
        See :func:`pass_response`.
    via_time_integral : bool
        See :func:`pass_response`.
    through_pass : array_like of int or None
        Per time, the last pass counted [1] (passes after it left out); None: all.

    Returns
    -------
    numpy.ndarray
        Rise [K], shape (time.size, depth.size).
    """
    _check_passes(count, interval, source)
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    depth = _as_depth(depth)
    lam, kappa = thermal_properties(material)
    step = 0.0 if interval is None else float(interval)
    reach = upstream_reach(0.0, source, kappa) + source.contact_duration
    opts = dict(quad_points=quad_points, inner_points=inner_points)
    const, sched, minus = _split(schedule, via_time_integral)
    out = np.zeros((time.size, depth.size))
    def curve(th):
        return _constant_part(th, depth, source, material, via_time_integral, **opts)
    if not via_time_integral and count > 1:
        # one pass's steady sweep, its tail from a checked interpolant when asked at many delays: the passes'
        # constant part and the schedule's levels below read the same curve
        curve = _with_checked_tail(curve, source.contact_duration, count)
    if const != 0.0:
        # a pass still further ahead than its upstream reach adds less than e^-45 of its rise: skipped
        out += const * shifted_sum(time, count, interval, curve, reach=reach, through_pass=through_pass)
    if sched is not None:
        last = np.full(time.size, count - 1) if through_pass is None else np.asarray(through_pass).ravel()
        swept: list[tuple[np.ndarray, np.ndarray, float]] = []      # (rows, delays, level - minus) per pass
        for k in range(count):
            rows = np.nonzero((time - k * step > -reach) & (k <= last))[0]
            if not rows.size:
                continue
            # pass k: level * (steady sweep) + the time integral of f - level (see pass_level)
            level = pass_level(sched, k * step, minus, via_time_integral)
            if level != minus:
                swept.append((rows, time[rows] - k * step, level - minus))
            out[rows] += _schedule_part(time[rows] - k * step, depth, source, material, sched, level, k * step,
                                        **opts)
        if swept:                                   # every pass's sweep in one call of the curve
            vals = curve(np.concatenate([th for _, th, _ in swept]))
            start = 0
            for rows, th, weight in swept:
                out[rows] += weight * vals[start:start + th.size]
                start += th.size
    return out


def _own_pass(t, k, step, depth_j, source, material, schedule, opts):
    """Rise [K] at time t due to pass k alone, at one depth."""
    return float(pass_response([t - k * step], [depth_j], source, material, schedule, arrival=k * step,
                               **opts)[0, 0])


def _local_rise(axis, hist, i, j, k, interval, depth, source, material, schedule, opts):
    """The rise near sample i (depth j) as pass k's own exact response plus the other passes' contribution,
    smooth there (it varies on the scale of the interval, not of D), interpolated quadratically through
    samples i - 1, i, i + 1."""
    three = axis[i - 1:i + 2]
    own = [_own_pass(t, k, interval, depth[j], source, material, schedule, opts) for t in three]
    rest = np.polyfit(three, hist[i - 1:i + 2, j] - own, 2)

    def rise(t):
        return _own_pass(t, k, interval, depth[j], source, material, schedule, opts) + np.polyval(rest, t)
    return rise


def _own_at(t, depth, source, material, interval, schedule, opts):
    """Pass k's own rise [K] at time t[k, j] [s] and depth j, shape (count, depths): with a constant factor
    every pass has the same response (one call per depth), else each pass its own (one call per pass)."""
    count = t.shape[0]
    theta = t - interval * np.arange(count)[:, None]
    out = np.empty(t.shape)
    if schedule is None or schedule.is_constant:
        for j, z in enumerate(depth):
            out[:, j] = pass_response(theta[:, j], [z], source, material, schedule, **opts)[:, 0]
        return out
    for k in range(count):
        out[k] = np.diagonal(pass_response(theta[k], depth, source, material, schedule, arrival=k * interval, **opts))
    return out


#: golden-section ratio (3 - sqrt(5)) / 2
_GOLDEN = 0.3819660112501051


def _refine_peaks(axis, hist, idx, depth, source, material, interval, schedule, opts):
    """The largest rise near each pass's largest sample idx[k, j] (depth j) and where: the rise as the pass's
    own exact response plus the other passes' contribution (smooth there: it varies on the scale of the
    interval, not of D) interpolated quadratically through samples i - 1, i, i + 1, maximised over
    [axis[i - 1], axis[i + 1]] by golden-section search (to 1e-7 D) for all passes and depths at once.
    Entries with idx 0 are returned but meaningless. Returns (time [s], rise [K]), each (count, depths)."""
    i = np.maximum(idx, 1)
    cols = np.arange(depth.size)
    three = [axis[i - 1], axis[i], axis[i + 1]]
    rest = [hist[i + s, cols] - _own_at(t, depth, source, material, interval, schedule, opts)
            for s, t in zip((-1, 0, 1), three)]

    def rise(t):
        x0, x1, x2 = three
        quad = (rest[0] * (t - x1) * (t - x2) / ((x0 - x1) * (x0 - x2))
                + rest[1] * (t - x0) * (t - x2) / ((x1 - x0) * (x1 - x2))
                + rest[2] * (t - x0) * (t - x1) / ((x2 - x0) * (x2 - x1)))
        return _own_at(t, depth, source, material, interval, schedule, opts) + quad
    a, b = three[0].copy(), three[2].copy()
    c, e = a + _GOLDEN * (b - a), b - _GOLDEN * (b - a)
    fc, fe = rise(c), rise(e)
    xtol = 1e-7 * source.contact_duration
    while np.max(b - a) > xtol:
        left = fc >= fe                                  # the maximum lies in [a, e]
        b = np.where(left, e, b)
        a = np.where(left, a, c)
        e_new = np.where(left, c, a + (1.0 - _GOLDEN) * (b - a))
        c_new = np.where(left, a + _GOLDEN * (b - a), e)
        f_new = rise(np.where(left, c_new, e_new))
        fe, fc = np.where(left, fc, f_new), np.where(left, f_new, fe)
        c, e = c_new, e_new
    best = np.where(fc >= fe, c, e)
    return best, np.maximum(fc, fe)


def time_above(rise, depth, source: MovingSource, material, count: int = 1, interval: float | None = None,
               schedule: Schedule | None = None, samples_per_contact: int = 40, tail_samples: int = 40,
               quad_points: int = 12, inner_points: int = 48) -> np.ndarray:
    """Time each pass keeps the fixed material point above a given rise.

    Within [k interval, (k + 1) interval) the history is sampled on :func:`history_time_axis`; every sign
    change of (history - rise) between two samples is located by Brent's method (to 1e-9 D) on the
    pass's own exact response plus the others' interpolated contribution (as in :func:`pass_summary`).
    Excursions shorter than the sampling (two crossings between neighbouring samples) are not seen:
    ``samples_per_contact`` sets that resolution.

    Parameters
    ----------
    rise : float
        Threshold rise above the bulk temperature [K] (threshold minus bulk temperature).
    depth, source, material, count, schedule, quad_points, inner_points
        As in :func:`temperature_history` (depths [m], passes [1], heat-input factor [1]).
    interval : float
        Time between passes [s] (the last pass's window ends one interval after it).
    samples_per_contact, tail_samples : int
        Sampling of :func:`history_time_axis` [1].

    Returns
    -------
    numpy.ndarray
        Time above [s], shape (count, depth.size).
    """
    if interval is None:
        raise ValueError("interval is needed: each pass's window is one interval long [s]")
    depth, axis, hist, opts = _sampled_history(depth, source, material, count, interval, schedule,
                                               samples_per_contact, tail_samples, quad_points, inner_points)
    per = (axis.size - 1) // count
    tol = 1e-9 * source.contact_duration
    out = np.zeros((count, depth.size))
    for k in range(count):
        rows = np.arange(k * per, (k + 1) * per + 1)
        for j in range(depth.size):
            above = hist[rows, j] > rise
            total = 0.0
            since = axis[rows[0]] if above[0] else None
            for m in np.nonzero(above[1:] != above[:-1])[0]:
                i = rows[m] if rows[m] > 0 else rows[m] + 1
                local = _local_rise(axis, hist, i, j, k, interval, depth, source, material, schedule, opts)
                t = optimize.brentq(lambda t: local(t) - rise, axis[rows[m]], axis[rows[m] + 1], xtol=tol)
                if above[m + 1]:
                    since = t
                else:
                    total += t - since
                    since = None
            if since is not None:
                total += axis[rows[-1]] - since
            out[k, j] = total
    return out


def _sampled_history(depth, source, material, count, interval, schedule, samples_per_contact, tail_samples,
                     quad_points, inner_points):
    """(depths [m], the :func:`history_time_axis` [s], the exact history on it [K], the quadrature options) that
    :func:`time_above` and :func:`pass_summary` read their passes from."""
    depth = _as_depth(depth)
    axis = history_time_axis(source, count, interval, samples_per_contact, tail_samples)
    opts = dict(quad_points=quad_points, inner_points=inner_points)
    return depth, axis, temperature_history(axis, depth, source, material, count, interval, schedule, **opts), opts


def pass_summary(depth, source: MovingSource, material, count: int = 1, interval: float | None = None,
                 schedule: Schedule | None = None, samples_per_contact: int = 40, tail_samples: int = 40,
                 quad_points: int = 12, inner_points: int = 48, refine: bool = True) -> PassSummary:
    """Per-pass peak rise and residual rise of the fixed material point (see :class:`PassSummary`).

    The history is sampled on :func:`history_time_axis`; each pass's largest sample is then refined
    by a golden-section search (to 1e-7 D) over the two neighbouring sample intervals, with the
    pass's own response evaluated exactly and the other passes' (smooth there: they vary on the scale
    of the interval, not of D) interpolated quadratically through the three samples (:func:`_refine_peaks`).

    Parameters
    ----------
    depth, source, material, count, schedule, samples_per_contact, tail_samples, quad_points, inner_points
        As in :func:`time_above` (depths [m], passes [1], heat-input factor [1], samples [1]).
    interval : float
        Time between passes [s], >= the contact duration (also for one pass: the residual is taken
        one interval after it).
    refine : bool
        Refine the peaks by the scalar search (False: the largest sample).

    Returns
    -------
    PassSummary
        peak [K], peak_time [s], residual [K].
    """
    if interval is None:
        raise ValueError("interval is needed for the residual rise (one interval after the last pass) [s]")
    depth, axis, hist, opts = _sampled_history(depth, source, material, count, interval, schedule,
                                               samples_per_contact, tail_samples, quad_points, inner_points)
    per = (axis.size - 1) // count
    # the passes up to k at the next arrival: the arriving pass's forerunning conduction left out
    residual = temperature_history(interval * np.arange(1, count + 1), depth, source, material, count, interval,
                                   schedule, **opts, through_pass=np.arange(count))
    cols = np.arange(depth.size)
    idx = np.array([k * per + np.argmax(hist[k * per:(k + 1) * per], axis=0) for k in range(count)])
    peak, when = hist[idx, cols], axis[idx]
    if refine:
        found_t, found_v = _refine_peaks(axis, hist, idx, depth, source, material, interval, schedule, opts)
        better = (idx > 0) & (found_v > peak)
        peak[better], when[better] = found_v[better], found_t[better]
    return PassSummary(peak=peak, peak_time=when, residual=residual)
