"""The compiled integrand of the Hertzian band (railtherm.references.transient_pass._band_hertz_depth), which the
transient scenes' exact histories spend their time in, against the window quadrature it compiles
(_band_hertz times the depth factor), node by node: the same sums to 1e-13 of the largest value, at the surface
and at depth, over emissions ahead of, under and behind the band, at lags from 1e-12 s to 1 s."""
from __future__ import annotations

import math

import numpy as np
import pytest

from railtherm.input.materials import Material
from railtherm.references import transient_pass as tp

STEEL = Material()


def _numpy_integrand(u, theta_e, z, src, kappa, nx):
    """The integrand by the numpy window quadrature (the uncompiled path of _integrand_u)."""
    s = 2.0 * math.sqrt(kappa) * u
    xi = src.half_width - src.speed * theta_e
    out = np.zeros(u.shape)
    ok = s > 0
    inner = tp._band_hertz(xi[ok], s[ok], src, nx)
    with np.errstate(under="ignore"):
        depth = np.exp(-(np.broadcast_to(z, u.shape)[ok] / s[ok]) ** 2)
    out[ok] = 2.0 / (math.pi * math.sqrt(kappa)) * inner * depth
    return out


def test_compiled_band_hertz_integrand_equals_the_window_quadrature():
    src = tp.MovingSource("band", 6e-3, 30.0, 1e8, "hertz")
    kappa = STEEL.diffusivity
    rng = np.random.default_rng(7)
    n = 20000
    u = np.sqrt(10.0 ** rng.uniform(-12, 0, n))                       # lags 1e-12 .. 1 s
    u[:50] = 0.0                                                     # no lag: no contribution
    theta_e = rng.uniform(-2.0, 3.0, n) * src.contact_duration       # ahead of, under and behind the band
    for z in (0.0, 1e-4, 1e-3):
        for nx in (24, 48):
            got = tp._integrand_u(u, theta_e, z, src, kappa, nx)
            want = _numpy_integrand(u, theta_e, z, src, kappa, nx)
            scale = np.max(np.abs(want))
            assert scale > 0 and np.all(got[:50] == 0.0)
            assert np.max(np.abs(got - want)) <= 1e-13 * scale, (z, nx)
            assert np.count_nonzero(want) > n // 10                  # the comparison covers heated nodes


def test_graded_pair_rule_grades_each_end_as_asked():
    """Both ends to 1e-16: the two-sided rule itself. For 1/sqrt(t + d) on (0, 1), a singularity d outside the
    end t = 0, the rule graded there only to 10 % of d gives the fully graded rule's integral to 1e-15 (grading
    beyond the singularity's distance adds nothing), with fewer nodes the farther the singularity (d from 1e-12
    to 1); with 16 points per panel both are within 1e-12 of the exact 2 (sqrt(1 + d) - sqrt(d)); graded only to
    0.1 when d = 1e-8, it misses by far more (the grading is what carries the accuracy)."""
    from railtherm.references._quadrature import graded_pair_rule, two_sided_rule
    t, w = graded_pair_rule(8, -16, -16)
    t2, w2 = two_sided_rule(8)
    np.testing.assert_array_equal(t, t2)
    np.testing.assert_array_equal(w, w2)
    for n in (8, 16):
        tf, wf = graded_pair_rule(n, -16, -16)
        sizes = []
        for d in (1e-12, 1e-8, 1e-4, 1e-2, 1.0):
            e = int(math.floor(math.log10(max(0.1 * d, 1e-16))))
            t, w = graded_pair_rule(n, e, -1)
            exact = 2.0 * (math.sqrt(1.0 + d) - math.sqrt(d))
            got = w @ (1.0 / np.sqrt(t + d))
            assert abs(got - wf @ (1.0 / np.sqrt(tf + d))) < 1e-15 * exact, (n, d)
            if n == 16:
                assert abs(got - exact) < 1e-12 * exact, d
            sizes.append(t.size)
        assert sizes == sorted(sizes, reverse=True) and sizes[-1] < sizes[0] / 3
    t, w = graded_pair_rule(16, -1, -1)
    assert abs(w @ (1.0 / np.sqrt(t + 1e-8)) / (2.0 * (math.sqrt(1.0 + 1e-8) - 1e-4)) - 1.0) > 1e-4


@pytest.mark.parametrize("shape", ["uniform", "hertz"])
def test_time_integrals_graded_to_their_singularities_equal_the_fully_graded_ones(shape, monkeypatch):
    """The schedule's time integrals (a slip event on the second of 3 passes, a ramp of the heat over the first)
    at 300 times and 4 depths: graded toward each end only as far as _grading finds its nearest singularity, the
    history equals the one by rules graded fully (to 1e-16) at both ends of every panel, to 1e-12 of its largest
    value at each depth."""
    from railtherm.references.transient import Schedule, temperature_history
    src = tp.MovingSource("band", 6e-3, 30.0, 1e8, shape)
    d = src.contact_duration
    sched = Schedule((0.0, 0.3 * d, 10.0 * d, 10.2 * d, 10.6 * d, 10.8 * d), (0.0, 1.0, 1.0, 2.0, 2.0, 1.0))
    z = [0.0, 1e-4, 5e-4, 1e-3]
    t = np.sort(np.random.default_rng(3).uniform(0.0, 30.0 * d, 300))
    opts = dict(quad_points=8, inner_points=24)
    graded = temperature_history(t, z, src, STEEL, 3, 10.0 * d, sched, **opts)
    monkeypatch.setattr(tp, "_grading", lambda u1, u2, s, k: (np.full(u1.shape, -16), np.full(u1.shape, -16)))
    full = temperature_history(t, z, src, STEEL, 3, 10.0 * d, sched, **opts)
    scale = np.max(np.abs(full), axis=0)
    assert np.all(scale > 0)
    assert np.all(np.max(np.abs(graded - full), axis=0) <= 1e-12 * scale)


def test_source_at_rest_graded_to_u_equals_the_fully_graded_history(monkeypatch):
    """The history under a band at rest (the locked wheel's spot, Hertzian, switched on for 50 ms) at 200 times
    and 4 depths: each panel graded toward its ends only as far as its distance from u = 0 needs equals the
    history by fully graded panels to 1e-12 of its largest value at each depth."""
    from railtherm.references import transient_spot as ts
    from railtherm.references.transient import Schedule
    src = ts.FixedSource("band", 1.97e-3, 2e7, "hertz")
    sched = Schedule((0.0, 1e-4, 0.05, 0.0501), (0.0, 1.0, 1.0, 0.0))
    z = [0.0, 1e-4, 5e-4, 1e-3]
    t = np.sort(np.concatenate([np.random.default_rng(5).uniform(0.0, 0.1, 200), [1e-4, 0.05, 0.0501]]))
    graded = ts.fixed_source_history(t, z, src, STEEL, sched, quad_points=8, inner_points=24)
    monkeypatch.setattr(ts, "_grade_exponent", lambda distance, width: -16)
    full = ts.fixed_source_history(t, z, src, STEEL, sched, quad_points=8, inner_points=24)
    scale = np.max(np.abs(full), axis=0)
    assert np.all(scale > 0)
    assert np.all(np.max(np.abs(graded - full), axis=0) <= 1e-12 * scale)
