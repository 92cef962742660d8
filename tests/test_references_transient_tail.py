"""The cheap evaluation of exact transient histories (railtherm.references.checked_interpolant and its use in
railtherm.references.transient): checked Chebyshev pieces against closed forms and their convergence rate, the
interpolated tail of many passes against the exact sum, each pass's steady-sweep level against the pure time
integral, and the vectorised peak search against scipy's bounded scalar minimiser.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize

from railtherm.input.materials import Material
from railtherm.references import transient as tr
from railtherm.references.checked_interpolant import CheckedInterpolant, _barycentric, _chebyshev_points
from railtherm.references.transient import MovingSource, Schedule, pass_summary, temperature_history

STEEL = Material()


def _two_columns(x):
    return np.column_stack([1.0 / np.sqrt(x), np.exp(-x) * np.sin(3.0 * x)])


def test_checked_pieces_hold_their_tolerance_between_the_checks():
    """On analytic curves every accepted piece agrees with the curve to its tolerance at 20,000 points spread
    over the interval, not only at its check points (measured: 0.02 of the tolerance)."""
    tol = np.array([1e-11, 1e-12])
    fit = CheckedInterpolant(_two_columns, 1e-3, 30.0, tol)
    x = np.geomspace(1e-3, 30.0, 20000)
    err = np.max(np.abs(fit(x) - _two_columns(x)), axis=0)
    assert np.all(err <= tol)
    assert all(p.values is not None for p in fit.pieces)
    assert fit.evaluations < 2000


def test_chebyshev_interpolation_converges_at_the_bernstein_ellipse_rate():
    """Degree-n interpolation in Chebyshev points of f(x) = 1/(x - x0), x0 = 1.5, on [-1, 1] converges like
    rho^-n, rho = x0 + sqrt(x0^2 - 1) = 2.618 (Trefethen 2013, theorem 8.2): fitted rate within 2 %."""
    x0 = 1.5
    rho = x0 + math.sqrt(x0 * x0 - 1.0)
    xs = np.linspace(-1.0, 1.0, 4001)
    ns = np.arange(8, 33, 4)
    errs = []
    for n in ns:
        nodes, w, _ = _chebyshev_points(int(n))
        got = _barycentric(xs, nodes, w, (1.0 / (nodes - x0))[:, None])[:, 0]
        errs.append(np.max(np.abs(got - 1.0 / (xs - x0))))
    rate = -np.polyfit(ns, np.log(errs), 1)[0]
    assert rate == pytest.approx(math.log(rho), rel=0.02)


def test_a_curve_too_rough_to_check_is_evaluated_exactly():
    """Pieces whose check fails down to the smallest width are left to the curve: there the interpolant returns
    the curve's own values, bit for bit."""
    def rough(x):
        return np.abs(np.sin(1e4 * x))[:, None]
    fit = CheckedInterpolant(rough, 1.0, 2.0, 1e-12)
    assert all(p.values is None for p in fit.pieces)
    x = np.linspace(1.0, 2.0, 101)
    np.testing.assert_array_equal(fit(x), rough(x))


@pytest.mark.parametrize("kwargs,key", [(dict(lo=0.0, hi=1.0), "lo"), (dict(lo=2.0, hi=1.0), "hi"),
                                        (dict(lo=1.0, hi=2.0, ratio=1.0), "ratio"),
                                        (dict(lo=1.0, hi=2.0, tolerance=0.0), "tolerance")])
def test_checked_interpolant_rejects_bad_input(kwargs, key):
    args = dict(tolerance=1e-9) | kwargs
    with pytest.raises(ValueError, match=key):
        CheckedInterpolant(_two_columns, **args)


def test_outside_the_interval_is_an_error():
    fit = CheckedInterpolant(_two_columns, 1.0, 2.0, 1e-9)
    with pytest.raises(ValueError, match="x must lie in"):
        fit([0.5])


def test_many_passes_with_the_interpolated_tail_equal_the_exact_sum(monkeypatch):
    """30 passes of a Hertzian band (1.2 D apart, a history asked at 400 times: 12,000 delays, more than the
    threshold) with the interpolated tail equal the history from exact steady sweeps to 1e-8 of its largest rise
    at each depth (the bound: max(1e-7 / 30, 1e-8) = 1e-8; measured 4e-12), and the tail was interpolated (not
    bit-identical)."""
    src = MovingSource("band", 6e-3, 30.0, 1e8, "hertz")
    d = src.contact_duration
    t = np.linspace(0.0, 30 * 1.2 * d, 400)
    z = [0.0, 2e-4, 1e-3]
    fast = temperature_history(t, z, src, STEEL, 30, 1.2 * d)
    monkeypatch.setattr(tr, "TAIL_MIN_DELAYS", 10 ** 9)
    exact = temperature_history(t, z, src, STEEL, 30, 1.2 * d)
    err = np.max(np.abs(fast - exact), axis=0) / np.max(np.abs(exact), axis=0)
    assert not np.array_equal(fast, exact)
    assert np.all(err <= max(tr.TAIL_TOLERANCE / 30, tr.TAIL_FLOOR)), err


def test_a_pass_held_at_its_arrival_level_is_the_swept_field_plus_the_schedule_departures():
    """Each pass takes the schedule's value at its arrival as its steady-sweep level and integrates only the
    departures from it in time. Three passes under a ramp up, a plateau and a ramp down (the second pass on the
    plateau: a steady sweep and nothing else) against the whole schedule integrated in time, both with the same
    fine rules: equal to 1e-7 of the largest rise at each depth."""
    src = MovingSource("band", 6e-3, 30.0, 1e8, "hertz")
    d = src.contact_duration
    interval = 20 * d
    sched = Schedule((0.0, 5 * d, 45 * d, 50 * d), (0.0, 1.0, 1.0, 0.0))
    t = np.concatenate([k * interval + np.linspace(0.0, 3 * d, 13) for k in range(3)] + [[3 * interval]])
    z = [0.0, 1e-4, 5e-4]
    opts = dict(quad_points=12, inner_points=48)
    split = temperature_history(t, z, src, STEEL, 3, interval, sched, **opts)
    whole = temperature_history(t, z, src, STEEL, 3, interval, sched, **opts, via_time_integral=True)
    err = np.max(np.abs(split - whole), axis=0) / np.max(np.abs(whole), axis=0)
    assert np.all(err < 1e-7)


def test_vectorised_peak_search_finds_the_bounded_scalar_maximum():
    """The golden-section search of every pass's peak (all passes and depths at once) against scipy's bounded
    Brent search of each, on the same local model (the pass's own response plus the others' quadratic), under a
    slip event and with a constant factor: where the maximum is inside the bracket the peaks agree to 1e-9
    relative (measured 1e-11); where the model still rises at the bracket's end (a depth that peaks later) both
    stop within 2e-7 D of it and the golden search's value is at least Brent's, above it by at most 1e-6."""
    src = MovingSource("band", 6e-3, 30.0, 1e8, "hertz")
    d = src.contact_duration
    z = np.array([0.0, 1e-4, 5e-4])
    for sched in (None, Schedule((2.0 * d, 2.2 * d, 2.6 * d, 2.8 * d), (1.0, 2.0, 2.0, 1.0))):
        got = pass_summary(z, src, STEEL, 3, 2.0 * d, sched, quad_points=8, inner_points=24)
        axis = tr.history_time_axis(src, 3, 2.0 * d, 40, 40)
        opts = dict(quad_points=8, inner_points=24)
        hist = temperature_history(axis, z, src, STEEL, 3, 2.0 * d, sched, **opts)
        per = (axis.size - 1) // 3
        for k in range(3):
            for j in range(z.size):
                i = k * per + int(np.argmax(hist[k * per:(k + 1) * per, j]))
                rise = tr._local_rise(axis, hist, i, j, k, 2.0 * d, z, src, STEEL, sched, opts)
                res = optimize.minimize_scalar(lambda t: -rise(t), bounds=(axis[i - 1], axis[i + 1]),
                                               method="bounded", options={"xatol": 1e-7 * d})
                brent = max(hist[i, j], -res.fun)
                if axis[i + 1] - res.x > 2e-7 * d:
                    assert got.peak[k, j] == pytest.approx(brent, rel=1e-9)
                else:
                    assert axis[i + 1] - got.peak_time[k, j] <= 2e-7 * d
                    assert brent * (1 - 1e-12) <= got.peak[k, j] <= brent * (1 + 1e-6)


def test_schedule_levels_read_the_interpolated_sweep_within_its_tolerance(monkeypatch):
    """A heat ramp held over 3 revolutions (the study's wheel spin: f from 0 to 1 in 5 ms, back to 0 at 0.2 s)
    asked at 6,000 times: the passes after the first take their level's steady sweep from the checked tail (more
    than TAIL_MIN_DELAYS delays behind 2 D); the history equals the one from exact sweeps (the tail switched off)
    to count x TAIL_TOLERANCE / count of the largest rise at each depth, and the tail was used (the histories
    are not bit-identical)."""
    src = MovingSource("band", 5.88e-3, 30.0, 1e8, "hertz")
    sched = Schedule((0.0, 0.005, 0.195, 0.2), (0.0, 1.0, 1.0, 0.0))
    interval, count = 0.091, 3
    t = np.sort(np.random.default_rng(11).uniform(0.0, count * interval, 6000))
    z = [0.0, 1e-4, 1e-3]
    opts = dict(quad_points=8, inner_points=24)
    got = temperature_history(t, z, src, STEEL, count, interval, sched, **opts)
    monkeypatch.setattr(tr, "TAIL_MIN_DELAYS", 10 ** 9)
    exact = temperature_history(t, z, src, STEEL, count, interval, sched, **opts)
    scale = np.max(np.abs(exact), axis=0)
    err = np.max(np.abs(got - exact), axis=0)
    assert np.all(err <= tr.TAIL_TOLERANCE * scale)
    assert np.any(err > 0)
