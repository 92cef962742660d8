"""The CONTACT program's contact reference point (railtherm.physics.contact_reference): the interpenetration's
centre of gravity weighted by the squared interpenetration, on analytic gaps against quadrature, its convergence in
the section's sample spacing (where results report it: tests/test_manchester.py)."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad

from railtherm.physics.contact_reference import interpenetration_centre, interpenetration_weights
from railtherm.physics.contact_search import GapSection

#: an asymmetric lateral gap h(y) = B y^2 + C y^3 [m] with a wheel curvature along x of 1 / 0.46 m
B, C, KX, APPROACH = 40.0, 4000.0, 1.0 / 0.46, 20e-6


def _gap(y):
    return B * y ** 2 + C * y ** 3


def _edges():
    """The interpenetration stretch's ends around y = 0 (roots of APPROACH - h)."""
    r = np.roots([C, B, 0.0, -APPROACH])
    r = np.sort(r[np.abs(r.imag) < 1e-12].real)
    return float(r[r < 0].max()), float(r[r > 0].min())


def _exact_centre():
    """sum w y / sum w with w(y) = (16/15) c^(5/2) / sqrt(k_x / 2), c = APPROACH - h(y), by adaptive quadrature."""
    lo, hi = _edges()
    f = lambda y: (APPROACH - _gap(y)) ** 2.5   # noqa: E731 (the common factor cancels)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        return quad(lambda y: y * f(y), lo, hi, epsabs=0, epsrel=1e-13, limit=200)[0] / \
            quad(f, lo, hi, epsabs=0, epsrel=1e-13, limit=200)[0]


def _section(eta, h=None, kx=None):
    eta = np.asarray(eta, dtype=float)
    return GapSection(eta, _gap(eta) if h is None else h, np.zeros(eta.size),
                      np.full(eta.size, KX) if kx is None else kx)


def test_slice_weight_is_the_integral_of_the_squared_interpenetration():
    """Each slice's weight is int (d - h(x, y))^2 dx over the interpenetration along x, h = h_lat + k_x x^2 / 2
    (closed form (16/15) c^(5/2) / sqrt(k_x / 2)), against quadrature to 1e-12 relative, for slices of different
    depth and curvature along x."""
    eta = np.array([-0.3e-3, 0.0, 0.2e-3, 0.5e-3])
    kx = np.array([2.0, 2.2, 1.5, 3.0])
    s = _section(eta, kx=kx)
    got_eta, w = interpenetration_weights(s, APPROACH)
    assert np.array_equal(got_eta, eta)
    for y, k, wi in zip(eta, kx, w):
        c = APPROACH - _gap(y)
        t0 = math.sqrt(2.0 * c / k)
        exact = quad(lambda x: (c - 0.5 * k * x * x) ** 2, -t0, t0, epsabs=0, epsrel=1e-13)[0]
        assert wi == pytest.approx(exact, rel=1e-12)


def test_centre_of_a_symmetric_gap_is_its_minimum_and_the_origin_is_subtracted():
    """A gap even in y has its centre at y = 0 (to 1e-18 m on a symmetric sampling); ``origin`` is subtracted
    from the samples (a section whose samples are 5 um higher with origin 5 um gives the same centre, to the
    rounding of the subtraction, 1e-12 relative; 10 um higher without origin, at a 5 um larger approach, moves it
    by 25 %)."""
    eta = np.linspace(-3e-3, 3e-3, 601)
    h = B * eta ** 2
    assert abs(interpenetration_centre(_section(eta, h=h), APPROACH)) < 1e-18
    lifted = GapSection(eta, _gap(eta) + 5e-6, np.zeros(eta.size), np.full(eta.size, KX), origin=5e-6)
    plain = interpenetration_centre(_section(eta), APPROACH)
    assert interpenetration_centre(lifted, APPROACH) == pytest.approx(plain, rel=1e-12)
    higher = GapSection(eta, _gap(eta) + 10e-6, np.zeros(eta.size), np.full(eta.size, KX))
    assert abs(interpenetration_centre(higher, APPROACH + 5e-6) / plain - 1.0) > 0.2


def test_centre_converges_at_order_seven_halves_in_the_sample_spacing():
    """The weights vanish like (y - y_edge)^(5/2) at the stretch's ends, so the sums over uniform samples (the
    stretch's ends on samples) converge as dy^(7/2): the slope fitted on dy = (hi - lo) / N, N = 25 .. 800, is
    3.5 within 0.15 (measured 3.46), and the finest error is below 1e-13 m of a centre at -9.4 um."""
    lo, hi = _edges()
    exact = _exact_centre()
    steps, errors = [], []
    for n in (25, 50, 100, 200, 400, 800):
        dy = (hi - lo) / n
        eta = lo + dy * np.arange(-5, n + 6)
        steps.append(dy)
        errors.append(abs(interpenetration_centre(_section(eta), APPROACH) - exact))
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert slope == pytest.approx(3.5, abs=0.15)
    assert errors[-1] < 1e-13
    assert exact == pytest.approx(-9.43e-6, rel=1e-3)


def test_only_the_stretch_around_the_origin_counts():
    """A second interpenetration region beyond a rise of the gap (another patch) is left out: a copy of the gap
    10 mm away changes nothing."""
    eta = np.linspace(-4e-3, 14e-3, 3601)
    h = np.minimum(_gap(eta), B * (eta - 10e-3) ** 2)
    near = (eta > -4e-3) & (eta < 4e-3)
    got_eta, _ = interpenetration_weights(_section(eta, h=h), APPROACH)
    assert got_eta.max() < 1e-3
    assert interpenetration_centre(_section(eta, h=h), APPROACH) == interpenetration_centre(
        _section(eta[near], h=h[near]), APPROACH)


def test_no_interpenetration_at_the_origin_is_an_error():
    eta = np.linspace(-3e-3, 3e-3, 601)
    with pytest.raises(ValueError, match="approach = 0.0 m does not reach the gap at the plane's origin"):
        interpenetration_weights(_section(eta), 0.0)
