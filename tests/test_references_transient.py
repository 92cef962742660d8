"""Exact transient references (railtherm.references.transient): the fixed-frame history of a half-space
under moving bands and ellipses, with passes and a heat-input schedule.

Independent checks: the 1-D half-space solution (high Péclet limit), the steady moving-source fields
of railtherm.references.jaeger / moving_source (a different representation: space integrals of the
steady kernel, no time), the heat content against the heat put in, a direct scipy quadrature of a
multi-band source against the superposition of passes, and the convergence rates of the quadratures.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize
from scipy.special import erf

from railtherm.input.materials import Material
from railtherm.references import transient as tr
from railtherm.references.jaeger import jaeger_band_temperature
from railtherm.references.moving_source import moving_source_temperature
from railtherm.references.transient import (MovingSource, Schedule, history_time_axis, pass_response, pass_summary,
                                            temperature_history)

STEEL = Material()
LAM = STEEL.conductivity
KAP = STEEL.diffusivity
RHOC = STEEL.density * STEEL.specific_heat
A = 6e-3        # half-width [m]
B = 4e-3        # lateral semi-axis [m]
V = 30.0        # speed [m/s]
Q = 1e8         # flux [W/m^2]


def _source(kind, shape, a=A, v=V):
    return MovingSource(kind, a, v, Q, shape, B if kind == "ellipse" else None)


# ------------------------------------------------------------------------------------------------
# (i) the 1-D limit
# ------------------------------------------------------------------------------------------------
def test_band_under_the_source_tends_to_the_1d_half_space_like_one_over_peclet():
    """While the band covers the point, T -> 2 q sqrt(kappa t/pi)/lambda (Carslaw & Jaeger 2.9) as the
    Péclet number L = V a/(2 kappa) grows; lateral conduction is a relative correction O(1/L). Measured:
    the deviation times L is 0.62 at t = 0.1 D for L = 1e3 .. 7e4; fitted slope of log(dev) on log(L)
    within 0.02 of -1; below 6e-4 for L >= 1000 over 0.1 .. 0.9 D."""
    devs, pes = [], []
    for a in (1e-3, 4e-3, 16e-3):
        src = _source("band", "uniform", a=a)
        d = src.contact_duration
        th = np.array([0.1, 0.25, 0.5, 0.75, 0.9]) * d
        got = temperature_history(th, [0.0], src, STEEL, via_time_integral=True)[:, 0]
        exact = 2 * Q * np.sqrt(KAP * th / math.pi) / LAM
        dev = np.abs(got / exact - 1)
        assert dev.max() < 6e-4
        devs.append(dev[0])
        pes.append(V * a / (2 * KAP))
    slope = np.polyfit(np.log(pes), np.log(devs), 1)[0]
    assert slope == pytest.approx(-1.0, abs=0.02)


# ------------------------------------------------------------------------------------------------
# (ii) the steady moving field, swept past the point
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind,shape", [("band", "uniform"), ("band", "hertz"),
                                        ("ellipse", "uniform"), ("ellipse", "hertz")])
def test_time_integral_of_a_source_on_for_ever_is_the_steady_field_swept_past(kind, shape):
    """A source on for all times gives T(t) = T_steady(a - V t, 0, z) exactly. The time integral (instantaneous
    sources, no steady kernel) against Jaeger's K0 band / the Rosenthal point-source ellipse at their tight
    settings, before, under and long after the source, at z = 0, 0.1 and 0.5 mm: within 1e-7 of the maximum
    (measured <= 6e-9)."""
    src = _source(kind, shape)
    d = src.contact_duration
    th = np.array([-0.05, 0.1, 0.5, 0.9, 1.0, 1.3, 3.0, 30.0]) * d
    x = A - V * th
    for z in (0.0, 1e-4, 5e-4):
        got = pass_response(th, [z], src, STEEL, via_time_integral=True)[:, 0]
        if kind == "band":
            ref = jaeger_band_temperature(x, z, A, V, STEEL, Q, shape, quad_points=24)
        else:
            ref = moving_source_temperature(x, 0.0, z, (A, B), V, STEEL, Q, shape, quad_points=14, adaptive=False)
        assert np.max(np.abs(got - ref)) < 1e-7 * ref.max()


@pytest.mark.parametrize("kind,shape", [("band", "uniform"), ("band", "hertz"), ("ellipse", "hertz")])
def test_single_pass_peak_is_the_steady_maximum_along_the_line(kind, shape):
    """The refined pass peak of one pass equals the maximum of the steady field along x (a bounded scalar
    search on the steady reference itself) at each depth, within 1e-7 relative; the peak time is a - V t =
    x_max within 1e-5 max(a, |x_max|) (measured 3e-6 for the peak 0.26 m behind the patch at 0.5 mm; the
    steady field searched on its own: 400 samples over 100 D, then Brent)."""
    src = _source(kind, shape)
    depths = [0.0, 1e-4, 5e-4]
    d = src.contact_duration
    got = pass_summary(depths, src, STEEL, count=1, interval=100 * d)
    for j, z in enumerate(depths):
        if kind == "band":
            def f(x):
                return -float(jaeger_band_temperature(x, z, A, V, STEEL, Q, shape))
        else:
            def f(x):
                return -float(moving_source_temperature(x, 0.0, z, (A, B), V, STEEL, Q, shape, quad_points=12))
        xs = A - V * np.concatenate([np.linspace(0, 2 * d, 201), np.geomspace(2 * d, 100 * d, 200)[1:]])[::-1]
        i = int(np.argmin([f(x) for x in xs]))
        res = optimize.minimize_scalar(f, bounds=(xs[max(i - 1, 0)], xs[i + 1]), method="bounded",
                                       options={"xatol": 1e-9 * A})
        assert got.peak[0, j] == pytest.approx(-res.fun, rel=1e-7)
        # a flat maximum (at depth, far behind the patch) fixes its place only to ~sqrt(value error)
        assert A - V * got.peak_time[0, j] == pytest.approx(res.x, abs=1e-5 * max(A, abs(res.x)))


# ------------------------------------------------------------------------------------------------
# (iii) energy
# ------------------------------------------------------------------------------------------------
def test_heat_content_of_a_slip_event_equals_the_heat_put_in():
    """A band switched on and off by the schedule (f = 0 at both ends): after the heat input stops, the
    heat content int int rho c T dx dz per unit length equals int f(t) q 2a dt (insulated surface). The
    field at section X is the history of a point whose pass arrives at X/V (the schedule seen from it
    shifted). Composite Gauss-Legendre in x (panels split at the swept band's ends) and in z; within
    2e-6 relative (measured 7e-10). Péclet number 3.6: lateral conduction matters."""
    a, v = 1e-3, 0.1
    src = MovingSource("band", a, v, Q)
    d = src.contact_duration
    sched = Schedule((0.0, 0.25 * d, d, 1.5 * d), (0.0, 1.0, 1.0, 0.0))
    t_obs = 2.0 * d
    put_in = Q * 2 * a * (0.125 + 0.75 + 0.25) * d
    ell = math.sqrt(4 * KAP * t_obs)
    xe = [-2 * a - 12 * ell, -2 * a, -a, 0.0, v * 1.5 * d, v * 1.5 * d + 12 * ell]
    xg, wg = np.polynomial.legendre.leggauss(24)
    zs, wz = np.polynomial.legendre.leggauss(32)
    zmax = 12 * ell
    zz = zmax * (zs + 1) / 2
    wzz = zmax * wz / 2
    total = 0.0
    for lo, hi in zip(xe[:-1], xe[1:]):
        xs = lo + (hi - lo) * (xg + 1) / 2
        for x, w in zip(xs, (hi - lo) * wg / 2):
            # the point at section x: the leading edge reaches it at x / v
            col = pass_response([t_obs - x / v], zz, src, STEEL, sched, arrival=x / v)[0]
            total += w * RHOC * float(col @ wzz)
    assert abs(total / put_in - 1) < 2e-6, total / put_in - 1


# ------------------------------------------------------------------------------------------------
# (iv) passes: superposition against a direct multi-band source
# ------------------------------------------------------------------------------------------------
def _direct_multiband(t, z, count, interval, sched, a, v):
    """int f(t') sum_k (1/(rho c sqrt(pi) s)) exp(-z^2/s^2) [erf((xi_k + a)/s) - erf((xi_k - a)/s)] dt' by
    scipy.integrate.quad (QUADPACK), s = 2 sqrt(kappa (t - t')), xi_k = a - v (t' - k interval); split at the
    kinks, at the surface the last piece with the weight (t - t')^(-1/2) (QAWS)."""
    def g(tp, weighted):
        s = 2 * math.sqrt(KAP * max(t - tp, 1e-30))  # QAWS samples the end t' = t itself
        tot = 0.0
        for k in range(count):
            xi = a - v * (tp - k * interval)
            tot += erf((xi + a) / s) - erf((xi - a) / s)
        # weighted: the factor 1/sqrt(t - t') of 1/s is the quadrature's weight
        scale = 2 * math.sqrt(KAP) if weighted else s
        return float(sched(tp)) * tot * math.exp(-(z / s) ** 2) / (RHOC * math.sqrt(math.pi) * scale)
    edges = sorted({*sched.time, *(k * interval for k in range(count)),
                    *(k * interval + 2 * a / v for k in range(count))})
    pts = [-0.05] + [e for e in edges if -0.05 < e < t - 1e-9 * interval] + [t]  # no sliver at t
    val = 0.0
    plain = pts if z > 0 else pts[:-1]  # below the surface exp(-z^2/s^2) removes the singularity
    for lo, hi in zip(plain[:-1], plain[1:]):
        val += integrate.quad(g, lo, hi, args=(False,), limit=500, epsabs=0, epsrel=1e-12)[0]
    if z == 0:
        val += integrate.quad(g, pts[-2], t, args=(True,), weight="alg", wvar=(0.0, -0.5), limit=500, epsabs=0,
                              epsrel=1e-12)[0]
    return Q * val


def test_superposed_passes_equal_the_direct_multiband_source():
    """Three passes of a uniform band (Péclet 214, interval 3 D) with a schedule that starts at 0.3, rises to 1
    and ends at 0.5 (so both the swept steady part and the per-pass schedule part are exercised), against an
    adaptive scipy quadrature of a source made of the three bands at once: within 1e-7 relative to the
    maximum at z = 0 and 0.2 mm."""
    a, v = 1e-3, 6.0
    src = MovingSource("band", a, v, Q)
    d = src.contact_duration
    sched = Schedule((0.5 * d, 2.0 * d, 4.5 * d, 7.5 * d), (0.3, 1.0, 1.0, 0.5))
    times = np.array([0.4, 1.05, 2.5, 3.3, 4.0, 6.2, 7.1, 9.0]) * d  # off the edges: QAWS wants g smooth at t
    for z in (0.0, 2e-4):
        got = temperature_history(times, [z], src, STEEL, count=3, interval=3 * d, schedule=sched)[:, 0]
        ref = np.array([_direct_multiband(t, z, 3, 3 * d, sched, a, v) for t in times])
        assert np.max(np.abs(got - ref)) < 1e-7 * ref.max()


def test_one_pass_response_serves_every_pass():
    """On the common time axis the constant-factor response is evaluated once per distinct shift:
    (offsets per pass) x (passes) values, not (samples) x (passes); 60 passes need <= 2 x 81 x 60."""
    src = _source("band", "uniform")
    calls = []
    real = tr._constant_part

    def counting(theta, *args, **kw):
        calls.append(theta.size)
        return real(theta, *args, **kw)
    axis = history_time_axis(src, 60, 0.05)
    try:
        tr._constant_part = counting
        temperature_history(axis, [0.0], src, STEEL, count=60, interval=0.05)
    finally:
        tr._constant_part = real
    assert axis.size == 60 * 80 + 1
    assert sum(calls) <= 2 * 81 * 60
    assert sum(calls) < axis.size * 60 / 20


# ------------------------------------------------------------------------------------------------
# (v) schedules
# ------------------------------------------------------------------------------------------------
def test_constant_schedule_of_one_equals_no_schedule_and_scales_linearly():
    """f = 1 at every schedule time is no schedule; f = 2.5 doubles and a half the rise; a schedule that is 1
    on all passes but given with kinks (f = 1 everywhere, yet integrated in time as a departure of 0) also:
    within 1e-12 relative."""
    src = _source("band", "hertz")
    d = src.contact_duration
    t = history_time_axis(src, 3, 4 * d, samples_per_contact=5, tail_samples=5)
    base = temperature_history(t, [0.0, 1e-4], src, STEEL, count=3, interval=4 * d)
    one = temperature_history(t, [0.0, 1e-4], src, STEEL, count=3, interval=4 * d,
                              schedule=Schedule((0.0, d, 3 * d), (1.0, 1.0, 1.0)))
    np.testing.assert_allclose(one, base, rtol=1e-12, atol=0)
    two = temperature_history(t, [0.0, 1e-4], src, STEEL, count=3, interval=4 * d,
                              schedule=Schedule((0.0,), (2.5,)))
    np.testing.assert_allclose(two, 2.5 * base, rtol=1e-12, atol=0)


def test_schedule_linearity_split_in_two_ramps():
    """The history of f1 + f2 is the sum of the histories of f1 and f2 (both non-constant, f1 nonzero at
    -inf): within 1e-10 of the maximum."""
    src = _source("band", "uniform")
    d = src.contact_duration
    t = np.array([0.2, 0.9, 1.5, 3.0, 4.4, 6.0]) * d
    f1 = Schedule((0.0, d, 4 * d), (0.5, 0.2, 0.7))
    f2 = Schedule((0.0, d, 4 * d), (0.0, 1.0, 0.1))
    f12 = Schedule((0.0, d, 4 * d), (0.5, 1.2, 0.8))
    h = [temperature_history(t, [0.0, 1e-4], src, STEEL, count=2, interval=4 * d, schedule=f)
         for f in (f1, f2, f12)]
    assert np.max(np.abs(h[0] + h[1] - h[2])) < 1e-10 * h[2].max()


def test_schedule_rejects_bad_input():
    with pytest.raises(ValueError, match="strictly increasing"):
        Schedule((0.0, 0.0), (1.0, 1.0))
    with pytest.raises(ValueError, match=">= 0"):
        Schedule((0.0, 1.0), (1.0, -0.1))
    with pytest.raises(ValueError, match="interval"):
        temperature_history([0.0], [0.0], _source("band", "uniform"), STEEL, count=2, interval=1e-5)
    with pytest.raises(ValueError, match="count"):
        temperature_history([0.0], [0.0], _source("band", "uniform"), STEEL, count=0, interval=1.0)
    with pytest.raises(ValueError, match="depth"):
        pass_response([0.0], [-1e-3], _source("band", "uniform"), STEEL)


# ------------------------------------------------------------------------------------------------
# (vi) convergence rates
# ------------------------------------------------------------------------------------------------
def test_time_quadrature_converges_geometrically_at_the_hp_rate():
    """Error of the time integral against n = 20 points per graded panel, n = 2 .. 7, Hertz band at z = 0
    and 0.1 mm, under and behind the source. Theory for the geometric mesh with ratio 0.15: each panel
    sees the singular end at 1.353 half-widths from its centre, Bernstein ellipse rho = 2.26, error
    ~ rho^(-2 n) = 0.195^n (log10 slope -0.71 per point). Fitted slope within 10 % of that or steeper:
    <= -0.64 (measured -0.85; 8e-8 at n = 7)."""
    src = _source("band", "hertz")
    d = src.contact_duration
    th = np.array([0.3, 0.95, 1.4, 6.0]) * d
    ref = pass_response(th, [0.0, 1e-4], src, STEEL, via_time_integral=True, quad_points=20, inner_points=64)
    ns = np.arange(2, 8)
    err = [np.max(np.abs(pass_response(th, [0.0, 1e-4], src, STEEL, via_time_integral=True, quad_points=n,
                                       inner_points=64) - ref)) / ref.max() for n in ns]
    slope = np.polyfit(ns, np.log10(err), 1)[0]
    assert slope <= -0.64, (slope, err)
    assert err[-1] < 1e-7


def test_inner_window_quadrature_converges_faster_than_geometrically():
    """The Hertz inner integral (Gauss-Legendre over the Gaussian window |x' - xi| <= 6.5 s; the integrand is
    entire in phi apart from the band's ends, which the substitution x' = -a cos(phi) makes smooth): error
    against 96 points for 8, 16, 24, 32, 48 points. An entire integrand gives super-geometric decay: the
    fitted log10 slope per point is < -0.15 and the error at 48 points < 1e-9 (measured: slope -0.35, the
    local rate steepening from -0.26 to -0.36 per point; 4e-9 at 32 points, 6e-15 at 48)."""
    src = _source("ellipse", "hertz")
    d = src.contact_duration
    th = np.array([0.3, 0.95, 1.4]) * d
    ref = pass_response(th, [0.0, 1e-4], src, STEEL, via_time_integral=True, quad_points=10, inner_points=96)
    ns = np.array([8, 16, 24, 32, 48])
    err = np.array([np.max(np.abs(pass_response(th, [0.0, 1e-4], src, STEEL, via_time_integral=True,
                                                quad_points=10, inner_points=n) - ref)) / ref.max() for n in ns])
    slope = np.polyfit(ns, np.log10(err), 1)[0]
    assert slope < -0.15, (slope, err)
    assert err[-1] < 1e-9, err


def test_shifted_sum_equals_the_direct_sum_over_passes():
    """The phase/cumulative-sum bookkeeping against the plain double loop, on an irregular axis with
    negative times, a reach ahead of arrival and a per-time last pass: equal to 1e-12 relative."""
    rng = np.random.default_rng(7)
    time = np.sort(np.concatenate([rng.uniform(-0.3, 5.2, 200), np.arange(0, 6) * 1.0]))
    last = rng.integers(-1, 5, time.size)

    def curve(th):
        th = np.asarray(th)
        return np.stack([np.where(th > -0.4, np.exp(-np.abs(th)) * (1 + th), 0.0), np.cos(th) * (th > -0.4)], 1)
    got = tr.shifted_sum(time, 5, 1.0, curve, reach=0.4, through_pass=last)
    ref = np.zeros((time.size, 2))
    for i, t in enumerate(time):
        for k in range(5):
            if k <= last[i] and t - k > -0.4:
                ref[i] += curve(np.array([t - k]))[0]
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)


def test_residual_counts_the_passes_so_far():
    """Residual of pass k = sum over passes j <= k of the steady sweep at (k + 1 - j) interval (Jaeger's band
    directly; the arriving pass left out): within 1e-9 relative."""
    src = _source("band", "uniform")
    d = src.contact_duration
    got = pass_summary([0.0, 1e-4], src, STEEL, count=3, interval=5 * d, refine=False)
    for j, z in enumerate((0.0, 1e-4)):
        one = jaeger_band_temperature(A - V * 5 * d * np.arange(1, 4), z, A, V, STEEL, Q)
        np.testing.assert_allclose(got.residual[:, j], np.cumsum(one), rtol=1e-9)


def test_time_above_of_one_pass_is_the_steady_field_above_the_rise():
    """One pass, source on for ever: the time above a rise is the length of {x: T_steady(x, z) > rise} / V.
    The crossings searched on Jaeger's band directly (400 samples, then Brent) against time_above (the
    history's samples, Brent on the pass's exact response): within 1e-6 D, at z = 0 and 0.1 mm, for
    rises of 30 % and 70 % of the surface maximum. With three passes the later passes start warmer and
    stay above longer."""
    src = _source("band", "hertz")
    d = src.contact_duration
    tmax = float(jaeger_band_temperature(np.linspace(-A, A, 401), 0.0, A, V, STEEL, Q, "hertz").max())
    for frac in (0.3, 0.7):
        got = tr.time_above(frac * tmax, [0.0, 1e-4], src, STEEL, 1, 50 * d)[0]
        for j, z in enumerate((0.0, 1e-4)):
            def g(x):
                return float(jaeger_band_temperature(x, z, A, V, STEEL, Q, "hertz")) - frac * tmax
            xs = A - V * np.concatenate([np.linspace(0, 2 * d, 201), np.geomspace(2 * d, 50 * d, 200)[1:]])
            vals = np.array([g(x) for x in xs])
            cross = [optimize.brentq(g, xs[i + 1], xs[i], xtol=1e-12 * A)
                     for i in np.nonzero(np.sign(vals[1:]) != np.sign(vals[:-1]))[0]]
            length = sum(cross[i] - cross[i + 1] for i in range(0, len(cross) - 1, 2))
            assert got[j] == pytest.approx(length / V, abs=1e-6 * d)
    three = tr.time_above(0.5 * tmax, [0.0], src, STEEL, 3, 10 * d)[:, 0]
    assert three[0] > 0 and np.all(np.diff(three) > 0)


@pytest.mark.parametrize("kind,shape", [("band", "hertz"), ("ellipse", "uniform"), ("ellipse", "hertz")])
def test_two_routes_agree_with_a_schedule_and_passes(kind, shape):
    """Swept steady field + per-pass time integral of the schedule's departure, against the whole schedule
    integrated in time for every pass (no steady kernel), two passes, at z = 0 and 0.2 mm: within 1e-7 of
    the maximum."""
    src = _source(kind, shape)
    d = src.contact_duration
    sched = Schedule((0.5 * d, 2.0 * d, 4.5 * d, 6.5 * d), (0.3, 1.0, 1.0, 0.5))
    t = np.array([0.3, 1.0, 2.5, 4.2, 4.9, 8.0]) * d
    a = temperature_history(t, [0.0, 2e-4], src, STEEL, 2, 4 * d, sched)
    b = temperature_history(t, [0.0, 2e-4], src, STEEL, 2, 4 * d, sched, via_time_integral=True)
    assert np.max(np.abs(a - b)) < 1e-7 * a.max()
