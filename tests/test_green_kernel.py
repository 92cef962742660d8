"""Strip quadrature of the "green" plugin against the exact 1-D closed forms (seed eqs. 34, 36, 39).

References: core's ``railtherm.references.flash`` (uniform band: Carslaw & Jaeger 2.9, seed eqs. 34/36
corrected; Hertzian band: exact elliptic-integral form). Run:
``PYTHONPATH=core:plugins python -m pytest tests/test_green_kernel.py -q``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from railtherm import Material
from railtherm.references.flash import (flash_max_hertz_coefficient, flash_max_hertz_location,
                                        flash_temperature_1d, flash_uniform_max_coefficient,
                                        hertz_band_integral)
from railtherm_green import kernel

STEEL = Material()          # lambda 50, rho 7850, c 450 (Ertz & Knothe)
A = 5.88e-3                 # [m]
V = 30.0                    # [m/s]


def _hertz_cell_average(xe):
    """Exact cell averages of sqrt(1 - x^2) (unit half-width), as core's hertz model samples pressure."""
    F = lambda x: 0.5 * (x * np.sqrt(1 - x * x) + np.arcsin(x))  # noqa: E731
    return (F(xe[1:]) - F(xe[:-1])) / np.diff(xe)


def test_weights_are_upper_triangular_toeplitz_and_exact():
    xe = np.linspace(-1.0, 1.0, 11)
    w = kernel.surface_weights(xe)
    h = 0.2
    assert np.allclose(np.tril(w, -1), 0.0)
    assert np.allclose(np.diag(w), math.sqrt(2 * h))              # own cell: upstream half only
    k = np.arange(1, 10)
    assert np.allclose(np.diag(w, 1), 2 * math.sqrt(h) * (math.sqrt(1.5) - math.sqrt(0.5)))
    for d in k:                                                       # Toeplitz
        diag = np.diag(w, d)
        assert np.allclose(diag, diag[0], rtol=1e-13)
    # row sums = int_x^a ds/sqrt(s) = 2 sqrt(a - x)
    xc = 0.5 * (xe[1:] + xe[:-1])
    assert np.allclose(w.sum(axis=1), 2 * np.sqrt(1.0 - xc), rtol=1e-13)
    assert kernel.surface_weights(xe) is w                            # cached


def test_toeplitz_path_equals_full_matrix_and_graded_grid_exact():
    """Uniform grids use the Toeplitz vector, others the full matrix: same numbers; and a graded
    (non-uniform) grid is exact for a uniform flux as well."""
    xe = np.linspace(-1.0, 1.0, 65)
    q = np.random.default_rng(0).random((64, 3))
    np.testing.assert_allclose(kernel.surface_rise(xe, q, 1.0, 1.0),
                               kernel.surface_weights(xe) @ q / math.sqrt(math.pi), rtol=1e-12)
    w = kernel.toeplitz_weights(64, xe[1] - xe[0])
    np.testing.assert_allclose(w, kernel.surface_weights(xe)[0], rtol=1e-12)
    graded = -A + 2 * A * np.linspace(0.0, 1.0, 41) ** 1.7
    xc = 0.5 * (graded[1:] + graded[:-1])
    t = kernel.surface_rise(graded, np.full(40, 1e8), STEEL.effusivity, V)
    np.testing.assert_allclose(t, flash_temperature_1d(xc, 0.0, A, V, STEEL, 1e8, "uniform"), rtol=1e-12)


def test_uniform_flux_surface_exact_inside_and_behind_patch():
    """Uniform flux is piecewise constant on any grid with edges at +-a: the quadrature is exact
    (round-off), in the patch (eq. 34) and behind it (eq. 36), where the flux is zero."""
    q = 2.0e8
    xe = np.linspace(-3 * A, A, 201)           # 50 cells in the patch, 150 behind it
    xc = 0.5 * (xe[1:] + xe[:-1])
    flux = np.where(xc > -A, q, 0.0)
    t = kernel.surface_rise(xe, flux, STEEL.effusivity, V)
    ref = flash_temperature_1d(xc, 0.0, A, V, STEEL, q, "uniform")
    np.testing.assert_allclose(t, ref, rtol=1e-12)
    # eq. 34 at the last cell centre of the patch, x = -a + h/2: 2 sqrt(2/pi) (q/beta) sqrt(a/v) sqrt(1 - h/(4a))
    h = xe[1] - xe[0]
    tmax = flash_uniform_max_coefficient() * q / STEEL.effusivity * math.sqrt(A / V) * math.sqrt(1 - h / (4 * A))
    assert t.max() == pytest.approx(tmax, rel=1e-12)


def test_uniform_flux_depth_exact():
    """Depth field (eq. 34 with exp(-zeta^2/(2(xi+1))), the seed prints xi) is exact per cell."""
    q = 1.0e8
    xe = np.linspace(-2 * A, A, 61)
    xc = 0.5 * (xe[1:] + xe[:-1])
    z = np.array([0.0, 5e-6, 2e-5, 7.5e-5, 2e-4])
    flux = np.where(xc > -A, q, 0.0)
    t = kernel.depth_rise(xe, flux, z, STEEL.effusivity, V, STEEL.diffusivity)
    X, Z = np.meshgrid(xc, z, indexing="ij")
    ref = flash_temperature_1d(X, Z, A, V, STEEL, q, "uniform")
    np.testing.assert_allclose(t, ref, rtol=1e-10, atol=1e-12 * ref.max())
    np.testing.assert_allclose(t[:, 0], kernel.surface_rise(xe, flux, STEEL.effusivity, V), rtol=1e-13)
    # graded grid (full-matrix path)
    graded = np.concatenate([-2 * A + A * np.linspace(0.0, 1.0, 21)[:-1] ** 2,
                             -A + 2 * A * np.linspace(0.0, 1.0, 41) ** 1.5])       # edge at -a
    xg = 0.5 * (graded[1:] + graded[:-1])
    tg = kernel.depth_rise(graded, np.where(xg > -A, q, 0.0), z, STEEL.effusivity, V, STEEL.diffusivity)
    Xg, Zg = np.meshgrid(xg, z, indexing="ij")
    refg = flash_temperature_1d(Xg, Zg, A, V, STEEL, q, "uniform")
    np.testing.assert_allclose(tg, refg, rtol=1e-9, atol=1e-12 * refg.max())


def test_two_bodies_one_matmul_equals_separate():
    rng = np.random.default_rng(1)
    xe = np.linspace(-A, A, 33)
    q = rng.random((2, 32, 7)) * 1e8
    both = kernel.surface_rise(xe, q, (1.3e4, 1.1e4), (31.0, 30.0))
    np.testing.assert_allclose(both[0], kernel.surface_rise(xe, q[0], 1.3e4, 31.0), rtol=1e-13)
    np.testing.assert_allclose(both[1], kernel.surface_rise(xe, q[1], 1.1e4, 30.0), rtol=1e-13)


def test_hertz_band_maximum_coefficient_and_eq39():
    """The Hertzian maximum 1.2346 (q0/beta) sqrt(a/v) at x = -0.652 a (trailing half);
    the seed's eq. 39 quotes 1.253 (= sqrt(pi/2), 1.5 % high)."""
    xe = np.linspace(-1.0, 1.0, 4097)
    t = kernel.surface_rise(xe, _hertz_cell_average(xe), 1.0, 1.0)
    c = flash_max_hertz_coefficient()
    assert t.max() == pytest.approx(c, rel=1e-6)
    xc = 0.5 * (xe[1:] + xe[:-1])
    assert xc[np.argmax(t)] == pytest.approx(flash_max_hertz_location(), abs=1e-3)
    assert c == pytest.approx(1.2346, abs=1e-4)
    assert 1.253 / c - 1 == pytest.approx(0.0149, abs=5e-4)


LADDER = [16, 32, 64, 128, 256, 512, 1024, 2048]


def _ladder_errors():
    c = flash_max_hertz_coefficient()
    h, err_max, err_sampled = [], [], []
    for n in LADDER:
        xe = np.linspace(-1.0, 1.0, n + 1)
        xc = 0.5 * (xe[1:] + xe[:-1])
        t = kernel.surface_rise(xe, _hertz_cell_average(xe), 1.0, 1.0)
        exact = hertz_band_integral(xc) / math.sqrt(math.pi)
        h.append(2.0 / n)
        err_max.append(abs(t.max() - c) / c)
        err_sampled.append(abs(t.max() - exact.max()) / c)
    return np.array(h), np.array(err_max), np.array(err_sampled)


def test_convergence_rate_of_tmax():
    """Theory: piecewise-constant flux under the one-sided kernel 1/sqrt(x' - x) has a local error
    O(h^1.5) where the flux is smooth (own half cell: q' int_0^{h/2} s^{1/2} ds; upstream cells:
    q' h^3 sum (k h)^{-3/2}); sampling the maximum at cell centres adds O(h^2).
    Measured (cells 16..2048): slope 1.59 for T_max against the sampled exact maximum, 1.61
    against the continuous maximum 1.2346; local slopes approach 1.5 from above (2.98 -> 2.88 per halving)."""
    h, err_max, err_sampled = _ladder_errors()
    slope_sampled = np.polyfit(np.log(h), np.log(err_sampled), 1)[0]
    slope_max = np.polyfit(np.log(h), np.log(err_max), 1)[0]
    assert 1.45 <= slope_sampled <= 1.7, slope_sampled
    assert 1.45 <= slope_max <= 1.75, slope_max
    # asymptotic local rate -> 1.5
    local = np.log2(err_sampled[-4:-1] / err_sampled[-3:])
    assert np.all(np.abs(local - 1.5) < 0.12), local
    # accuracy at the CONTACT grid spacing (dx = 0.2 mm on 2a = 11.76 mm: ~59 cells): < 0.1 %
    assert err_max[LADDER.index(64)] < 1e-3


def test_contact_double_count_bias_is_not_present():
    """CONTACT's strip sum appears to add a cell's own heat twice (docs/NOTES.md): counting the own-cell
    weight sqrt(2 dx) twice makes the maximum 9.4 % high at dx = 0.2 mm; ours is within 0.1 % of
    the exact maximum on that grid (59 cells along 2a)."""
    n = int(round(2 * A / 0.2e-3))
    xe = np.linspace(-A, A, n + 1)
    q0 = 1.0e8
    t = kernel.surface_rise(xe, q0 * _hertz_cell_average(xe / A), STEEL.effusivity, V)
    exact = flash_max_hertz_coefficient() * q0 / STEEL.effusivity * math.sqrt(A / V)
    assert t.max() == pytest.approx(exact, rel=1e-3)
    # the double-counted variant (own cell's full weight added again) is ~10 % high
    w = kernel.surface_weights(xe)
    w2 = w + np.diag(np.diag(w))
    biased = (w2 @ (q0 * _hertz_cell_average(xe / A))).max() * kernel.strip_prefactor(STEEL.effusivity, V)
    assert 0.05 < biased / exact - 1 < 0.2


def test_extended_paths_equal_the_direct_sums_on_an_extended_grid():
    """The sums of a ``field`` grid (zero flux behind the patch: the surface by
    :func:`kernel.trail_toeplitz`, the depth by FFT over the patch rows) equal the direct O(nx^2) Toeplitz
    sums to 1e-13 of the maximum: surface (two bodies, some strips cold, one body cold, a gap between
    heated strips), depth (all depths in one transform), and the 1-D and per-column forms of
    :func:`kernel.fft_toeplitz`."""
    rng = np.random.default_rng(3)
    n_patch, n_behind, ny = 40, 250, 12
    h = 2 * A / n_patch
    xe = -A - n_behind * h + h * np.arange(n_patch + n_behind + 1)
    nx = xe.size - 1
    q = np.zeros((2, nx, ny))
    q[1, n_behind:, 2:6] = rng.random((n_patch, 4)) * 1e9
    q[1, n_behind:, 8:11] = rng.random((n_patch, 3)) * 1e9               # a second run of heated strips
    beta, v = (STEEL.effusivity, 1.1 * STEEL.effusivity), (V, 0.9 * V)
    fast = kernel.surface_rise(xe, q, beta, v, extended=True)
    slow = kernel.surface_rise(xe, q, beta, v)
    assert np.all(fast[0] == 0.0) and np.all(fast[1][:, [0, 1, 6, 7, 11]] == 0.0)
    assert np.max(np.abs(fast - slow)) < 1e-13 * np.max(np.abs(slow))
    z = 4e-4 * np.linspace(0.0, 1.0, 9) ** 2
    dfast = kernel.depth_rise(xe, q[1, :, 3], z, STEEL.effusivity, V, STEEL.diffusivity, extended=True)
    dslow = kernel.depth_rise(xe, q[1, :, 3], z, STEEL.effusivity, V, STEEL.diffusivity)
    assert np.max(np.abs(dfast - dslow)) < 1e-13 * np.max(np.abs(dslow))
    per_depth = np.stack([kernel.depth_rise(xe, q[1, :, 3], [zk], STEEL.effusivity, V, STEEL.diffusivity)[:, 0]
                          for zk in z], axis=1)                           # one depth at a time
    assert np.max(np.abs(dslow - per_depth)) < 1e-14 * np.max(np.abs(dslow))
    w = kernel.toeplitz_weights(nx, h)
    x1 = np.zeros(nx)
    x1[100:140] = rng.random(40)                                           # support inside the grid
    direct = kernel.toeplitz_matmul(w, x1[:, None])[:, 0]
    assert np.max(np.abs(kernel.fft_toeplitz(w, x1) - direct)) < 1e-13 * np.max(direct)
    assert np.all(kernel.fft_toeplitz(w, x1)[140:] == 0.0)                 # upstream of the heat: nothing
    assert np.all(kernel.fft_toeplitz(w, np.zeros(nx)) == 0.0)


def test_flux_given_on_the_patch_of_an_extended_grid():
    """``behind`` (zero flux in the first cells, the flux given on the patch only) equals the flux padded
    with zeros, by the extended-grid sums and by the direct sums, surface (1-, 2- and 3-D flux) and depth."""
    rng = np.random.default_rng(5)
    n_patch, n_behind = 30, 170
    h = 2 * A / n_patch
    xe = -A - n_behind * h + h * np.arange(n_patch + n_behind + 1)
    q = rng.random((2, n_patch, 5)) * 1e9
    q[0, :, 0] = 0.0
    full = np.concatenate([np.zeros((2, n_behind, 5)), q], axis=1)
    ref = kernel.surface_rise(xe, full, STEEL.effusivity, V)
    for extended in (False, True):
        got = kernel.surface_rise(xe, q, STEEL.effusivity, V, extended=extended, behind=n_behind)
        assert got.shape == full.shape
        assert np.max(np.abs(got - ref)) < 1e-13 * np.max(ref)
        got2 = kernel.surface_rise(xe, q[1], STEEL.effusivity, V, extended=extended, behind=n_behind)
        assert np.max(np.abs(got2 - ref[1])) < 1e-13 * np.max(ref)
        got1 = kernel.surface_rise(xe, q[1, :, 2], STEEL.effusivity, V, extended=extended, behind=n_behind)
        assert np.max(np.abs(got1 - ref[1, :, 2])) < 1e-13 * np.max(ref)
    z = np.array([0.0, 5e-5, 2e-4])
    dref = kernel.depth_rise(xe, full[1, :, 2], z, STEEL.effusivity, V, STEEL.diffusivity)
    for extended in (False, True):
        d = kernel.depth_rise(xe, q[1, :, 2], z, STEEL.effusivity, V, STEEL.diffusivity, extended=extended,
                              behind=n_behind)
        assert np.max(np.abs(d - dref)) < 1e-13 * np.max(dref)


@pytest.mark.parametrize("n_heat, n_behind, start", [(128, 768, 0), (60, 900, 7), (47, 40, 3), (30, 500, 0), (8, 50, 0)],
                         ids=["field-ellipse", "gap-before-heat", "short-trail", "few-nodes", "dense-only"])
def test_trail_sum_equals_the_exact_sum_far_behind_the_patch(n_heat, n_behind, start):
    """:func:`kernel.trail_toeplitz` (rows far behind the heat by rank-24 Chebyshev interpolation of the
    smooth weight, the rest exactly) equals the exact sum :func:`kernel.toeplitz_matmul` to 1e-13 of the
    maximum in every row, also relative to each far row's own size (1e-12: the trail decays like 1/sqrt(d));
    rows upstream of the heat are exactly 0, ``scale`` and ``out`` as documented."""
    rng = np.random.default_rng(n_heat)
    h = 2 * A / max(n_heat, 1)
    n_patch = n_heat + start + 5
    q = np.zeros((n_patch, 6))
    q[start:start + n_heat] = rng.random((n_heat, 6)) * 1e9
    q[start:start + n_heat, 4] = 0.0                                       # a cold strip
    nx = n_patch + n_behind
    full = np.concatenate([np.zeros((n_behind, 6)), q])
    exact = kernel.toeplitz_matmul(kernel.toeplitz_weights(nx, h), full)
    got = kernel.trail_toeplitz(h, q, behind=n_behind)
    assert got.shape == (nx, 6)
    assert np.max(np.abs(got - exact)) < 1e-13 * np.max(exact)
    far = slice(0, n_behind - n_heat)
    rel = np.abs(got[far] - exact[far]) / np.where(exact[far] > 0, exact[far], 1.0)
    assert rel.size == 0 or np.max(rel) < 1e-12
    assert np.all(got[n_behind + start + n_heat:] == 0.0) and np.all(got[:, 4] == 0.0)
    out = np.full((nx, 6), np.nan)
    kernel.trail_toeplitz(h, q, 2.5, out=out, behind=n_behind)
    assert np.max(np.abs(out - 2.5 * exact)) < 2.5e-13 * np.max(exact)
    one = kernel.trail_toeplitz(h, q[:, 0], behind=n_behind)
    assert one.shape == (nx,) and np.max(np.abs(one - exact[:, 0])) < 1e-13 * np.max(exact)
    assert np.all(kernel.trail_toeplitz(h, np.zeros(n_patch), behind=n_behind) == 0.0)
