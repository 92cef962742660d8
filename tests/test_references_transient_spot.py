"""The exact history under a surface source at rest (railtherm.references.transient_spot) against closed forms
(Carslaw & Jaeger 1959: the uniform disc on its axis, 10.5 (6); the 1-D half-space under a constant flux,
2.9 (7)) and against independent adaptive quadratures (scipy.integrate.quad / nquad) of the instantaneous
source integrals (Hertzian band and ellipse, a schedule switching the source on and off)."""
import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import integrate
from scipy.special import erf, erfc

from railtherm.references.transient import Schedule
from railtherm.references.transient_spot import FixedSource, fixed_source_history, fixed_source_summary, heating_window

LAM, RHO, C = 50.0, 7850.0, 460.0
STEEL = SimpleNamespace(conductivity=LAM, density=RHO, specific_heat=C, diffusivity=LAM / (RHO * C))
KAPPA = LAM / (RHO * C)
Q = 1e8
#: switched on at t = 0 (a 1e-12 s ramp: its missing heat is 5e-13 s of flux, < 1e-8 of the rise from 1e-4 s on)
STEP = Schedule((0.0, 1e-12), (0.0, 1.0))
TIMES = np.array([1e-4, 1e-3, 0.01, 0.05, 0.3])
DEPTHS = np.array([0.0, 1e-4, 5e-4, 1e-3])


def _ierfc(x):
    return np.exp(-x * x) / math.sqrt(math.pi) - x * erfc(x)


def _relative_to_peak(got, exact):
    """Largest error over the history relative to the largest exact rise at each depth."""
    return float(np.max(np.abs(got - exact) / np.max(np.abs(exact), axis=0)))


def test_uniform_disc_on_its_axis_matches_carslaw_jaeger_10_5():
    a = 2e-3
    got = fixed_source_history(TIMES, DEPTHS, FixedSource("ellipse", a, Q, "uniform", a), STEEL, STEP)
    t, z = np.meshgrid(TIMES, DEPTHS, indexing="ij")
    r = 2.0 * np.sqrt(KAPPA * t)
    exact = 2.0 * Q * np.sqrt(KAPPA * t) / LAM * (_ierfc(z / r) - _ierfc(np.sqrt(z * z + a * a) / r))
    assert _relative_to_peak(got, exact) < 1e-8


def test_wide_band_is_the_1d_half_space_carslaw_jaeger_2_9():
    # a = 1 m against sqrt(kappa t) <= 2 mm: the band's edges add erfc(250) ~ 0
    got = fixed_source_history(TIMES, DEPTHS, FixedSource("band", 1.0, Q, "uniform"), STEEL, STEP)
    t, z = np.meshgrid(TIMES, DEPTHS, indexing="ij")
    exact = 2.0 * Q * np.sqrt(KAPPA * t) / LAM * _ierfc(z / (2.0 * np.sqrt(KAPPA * t)))
    assert _relative_to_peak(got, exact) < 1e-8


def _band_kernel(tau, z, a):
    """(rho c / q) K of a uniform band of half-width a at its centre, depth z, after tau [1/s]."""
    s = 2.0 * math.sqrt(KAPPA * tau)
    return math.exp(-(z / s) ** 2) / math.sqrt(math.pi * KAPPA * tau) * erf(a / s)


def test_scheduled_band_matches_an_adaptive_duhamel_integral():
    """On for 50 ms with 0.1 ms ramps: quad over the emission time of f(t') K(t - t') in closed form."""
    a = 5.88e-3
    sched = Schedule((0.0, 1e-4, 0.05, 0.0501), (0.0, 1.0, 1.0, 0.0))
    times = np.array([5e-5, 2e-3, 0.0499, 0.0502, 0.06, 0.1])
    depths = np.array([0.0, 5e-4])
    got = fixed_source_history(times, depths, FixedSource("band", a, Q, "uniform"), STEEL, sched)
    exact = np.empty_like(got)
    for i, t in enumerate(times):
        for j, z in enumerate(depths):
            # u = sqrt(t - t') removes the 1/sqrt(tau) singularity at t' = t; pieces between the kinks
            def g(u, t=t, z=z):
                return 2.0 * u * float(sched(t - u * u)) * _band_kernel(u * u, z, a)
            edges = sorted(math.sqrt(t - p) for p in (0.0, 1e-4, 0.05, 0.0501) if p < t)
            if t <= 0.0501:
                edges = [0.0] + edges
            exact[i, j] = Q / (RHO * C) * sum(integrate.quad(g, e0, e1, epsabs=0, epsrel=1e-12, limit=200)[0]
                                              for e0, e1 in zip(edges[:-1], edges[1:]))
    assert _relative_to_peak(got, exact) < 1e-8


def test_hertz_band_and_ellipse_match_adaptive_space_time_integrals():
    """Hertzian flux on a band and an ellipse, on from 0, at 2 ms and 50 ms, surface and 0.5 mm: scipy's nquad of
    the instantaneous-source integral over the source and the time (relative 1e-9 requested)."""
    a, b = 5.88e-3, 4e-3
    times, depths = np.array([2e-3, 0.05]), np.array([0.0, 5e-4])
    band = fixed_source_history(times, depths, FixedSource("band", a, Q, "hertz"), STEEL, STEP)
    ell = fixed_source_history(times, depths, FixedSource("ellipse", a, Q, "hertz", b), STEEL, STEP)
    for i, t in enumerate(times):
        for j, z in enumerate(depths):
            def band_in(x, u, z=z):          # tau = u^2, dtau = 2 u du; x' = a sin(phi) on the band
                tau = u * u
                s2 = 4.0 * KAPPA * tau
                return (2.0 * u * 2.0 / math.sqrt(math.pi * s2) * math.exp(-z * z / s2) / math.sqrt(math.pi * s2)
                        * math.sqrt(max(1.0 - x * x / (a * a), 0.0)) * math.exp(-x * x / s2))
            exact_band = 2.0 * Q / (RHO * C) * integrate.nquad(
                band_in, [[0.0, a], [0.0, math.sqrt(t)]], opts={"epsrel": 1e-10, "epsabs": 0, "limit": 200})[0]
            assert band[i, j] == pytest.approx(exact_band, rel=1e-7)

            def ell_in(r, phi, u, z=z):        # x = a r cos(phi), y = b r sin(phi), dA = a b r dr dphi
                tau = u * u
                s2 = 4.0 * KAPPA * tau
                x, y = a * r * math.cos(phi), b * r * math.sin(phi)
                return (2.0 * u * 2.0 * (math.pi * s2) ** -1.5 * math.exp(-(z * z + x * x + y * y) / s2)
                        * math.sqrt(max(1.0 - r * r, 0.0)) * a * b * r)
            exact_ell = 4.0 * Q / (RHO * C) * integrate.nquad(
                ell_in, [[0.0, 1.0], [0.0, 0.5 * math.pi], [0.0, math.sqrt(t)]],
                opts={"epsrel": 1e-9, "epsabs": 0, "limit": 100})[0]
            assert ell[i, j] == pytest.approx(exact_ell, rel=1e-6)


def test_summary_peaks_at_the_end_of_heating_and_residual_one_window_later():
    """Surface: the rise grows while heated, so the window's peak is at the schedule's last full-factor time
    or within its ramp down; below the surface the peak comes later; the residual is the rise at the window's end."""
    a = 5.88e-3
    sched = Schedule((0.0, 1e-4, 0.05, 0.0501), (0.0, 1.0, 1.0, 0.0))
    src = FixedSource("band", a, Q, "hertz")
    s = fixed_source_summary([0.0, 5e-4], src, STEEL, 1, 0.1, sched, samples=100)
    assert 0.05 <= s.peak_time[0, 0] <= 0.0501
    assert s.peak_time[0, 1] > s.peak_time[0, 0]
    dense = fixed_source_history(np.linspace(0.04, 0.07, 301), [0.0, 5e-4], src, STEEL, sched)
    assert np.all(s.peak[0] >= dense.max(axis=0) * (1.0 - 1e-12))
    assert s.peak[0] == pytest.approx(dense.max(axis=0), rel=1e-4)        # the dense sampling's own spacing
    assert s.residual[0] == pytest.approx(fixed_source_history([0.1], [0.0, 5e-4], src, STEEL, sched)[0], rel=1e-14)


@pytest.mark.parametrize("factor, key", [((1.0, 1.0), "first factor"), ((0.5, 0.0), "first factor")])
def test_a_source_heated_since_minus_infinity_is_refused(factor, key):
    with pytest.raises(ValueError, match=key):
        heating_window(Schedule((0.0, 1.0), factor))
    with pytest.raises(ValueError, match=key):
        heating_window(None)
    assert heating_window(Schedule((0.0, 1e-4, 0.05, 0.0501), (0.0, 1.0, 1.0, 0.0))) == (0.0, 0.0501)
    assert heating_window(Schedule((-1.0, 0.0, 2.0), (0.0, 0.0, 3.0))) == (0.0, math.inf)
