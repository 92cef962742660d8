"""green's transient on 3-D contacts (railtherm_green.lateral): each strip's 1-D response weighted by the lateral
Gaussian of the conduction across the strips, against the exact moving ellipse of core (railtherm.references.transient)
on the transient study's train of axles, against a direct quadrature of the same model (with passes and a schedule),
its convergence with the level, and a flux uniform across the strips (the band) unchanged."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import erf

from railtherm.input.materials import Material
from railtherm_green.lateral import LateralPassResponse
from railtherm_green.pass_response import PassResponse
from railtherm_green.transient import strip_history, strip_time_axis

from transient_cases import train_of_axles

STEEL = Material()
BETA, KAP = STEEL.effusivity, STEEL.diffusivity
A, B, V, Q = 6e-3, 4e-3, 30.0, 1e8
D = 2 * A / V


def _train(level, depths):
    """green's pass peaks at ``depths`` and surface residual rises on the study's train-4-axles at ``level``, and
    the exact 3-D moving ellipse's (peaks (passes, depths), surface residual (passes,))."""
    ds, peak, exact = train_of_axles("green", level, (0.0, *depths))
    return (peak[:, 1:], ds["residual_rise"].values[1]), (exact.peak[:, 1:], exact.residual[:, 0])


def test_train_of_axles_pass_peaks_against_the_exact_ellipse():
    """Issue target: against the exact 3-D ellipse at 0.1 and 0.5 mm, every pass's peak within 5 % at level 2
    (the centre strip alone, without the lateral term, is 4.9 % and 15.9 % high at the 4th pass; measured with it:
    8e-5 and 6.4e-4). What is left is conduction along x, of order kappa t / a^2 at the peak's time (at 0.5 mm the
    first pass peaks ~9 ms after the arrival: 3e-3): within 1e-3 here, as the residual rise (measured 1e-4)."""
    (peak, residual), (ref_peak, ref_residual) = _train(2, (1e-4, 5e-4))
    err = peak / ref_peak - 1.0
    assert np.max(np.abs(err)) < 0.05, err
    assert np.max(np.abs(err)) < 1e-3, err
    assert np.max(np.abs(residual / ref_residual - 1.0)) < 1e-3


def test_train_of_axles_converges_with_the_level():
    """Levels 0 .. 3 (32 .. 256 cells along 2a, 21 .. 171 strips): the residual rise of every pass against the
    exact ellipse falls like h^2 (the cell-sampled flux integrated against kernels smooth on the cell scale, the
    midpoint rule's order; the ellipse's square-root edge, met at every offset along the strips, averages out):
    fitted slope within 0.2 of 2 (measured 2.01: 1.6e-3, 3.9e-4, 9.9e-5, 2.4e-5), well above the reference's ~1e-6."""
    hs, errs = [], []
    for level in range(4):
        (_, residual), (_, ref_residual) = _train(level, (1e-4,))
        hs.append(2 * A / (32 * 2 ** level))
        errs.append(np.max(np.abs(residual / ref_residual - 1.0)))
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert slope == pytest.approx(2.0, abs=0.2), errs


def _cells(nx, ny, y_half=B, uniform_y=False):
    xe, ye = np.linspace(-A, A, nx + 1), np.linspace(-y_half, y_half, ny + 1)
    xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
    if uniform_y:
        return xe, ye, Q * np.sqrt(1 - (xc[:, None] / A) ** 2) * np.ones(ny)[None, :]
    return xe, ye, Q * np.sqrt(np.clip(1 - (xc[:, None] / A) ** 2 - (yc[None, :] / B) ** 2, 0.0, None))


def _model_quadrature(theta, z, xe, ye, q, factor=None):
    """The model's rise at theta after one pass's arrival, depth z, by scipy's adaptive quadrature of
    ``sum_k sum_j q_kj int_(cell k) f(c) W_j(theta - c) g_z(theta - c) dc`` (W_j the strips' lateral erf weights),
    in u = sqrt(theta - c) (smooth: ds / sqrt(s) = 2 du)."""
    cz = z * z / (4 * KAP)
    c = (xe[-1] - xe) / V
    total = 0.0
    for k in range(q.shape[0]):
        lo, hi = c[k + 1], min(c[k], theta)
        if hi <= lo:
            continue

        def integrand(u, k=k):
            s = u * u
            if s <= 0:
                return 0.0
            w = 0.5 * (erf(ye[1:] / math.sqrt(4 * KAP * s)) - erf(ye[:-1] / math.sqrt(4 * KAP * s)))
            f = 1.0 if factor is None else factor(theta - s)
            return 2.0 * f * float(q[k] @ w) * math.exp(-cz / s)
        kinks = None if factor is None else [math.sqrt(theta - p) for p in factor.kinks if lo < p < hi] or None
        total += integrate.quad(integrand, math.sqrt(theta - hi), math.sqrt(theta - lo), points=kinks, epsabs=0,
                                epsrel=1e-13, limit=200)[0]
    return total / (BETA * math.sqrt(math.pi))


def test_one_pass_against_a_quadrature_of_the_model():
    """One pass of a Hertz ellipse (32 x 21 cells) at z = 0, 0.1, 0.5 mm: on the lattice and between its points
    (cubic Hermite), past 2 D (far sums) and 200 D after the arrival, against the adaptive quadrature of the same
    cell integrals: within 1e-9 of the value wherever it is above 1e-6 of the pass's largest rise (measured
    1.3e-10); and below the centre strip's 1-D response once the pass is over (the heat spreads sideways)."""
    xe, ye, q = _cells(32, 21)
    depths = [0.0, 1e-4, 5e-4]
    resp = LateralPassResponse(xe, ye, q, V, depths, BETA, KAP, 1e-18)
    theta = np.array([0.3 * D, 17 * resp.half, 0.999 * D, 1.37 * D, 64 * resp.half, 2.5 * D, 5 * D, 40 * D, 200 * D])
    got = resp(theta)
    ref = np.array([[_model_quadrature(t, z, xe, ye, q) for z in depths] for t in theta])
    big = ref > 1e-6 * ref.max()
    assert np.max(np.abs(got / ref - 1)[big]) < 1e-9
    assert np.all(got[theta > 2 * D] < resp.base(theta[theta > 2 * D]))


class _Ramp:
    """A heat-input factor ramped inside the pass: 0.2 at the arrival, 1 at 0.61 D, 0.7 at D (piecewise linear)."""
    kinks = (0.0, 0.61 * D, D)

    def __call__(self, t):
        return float(np.interp(t, self.kinks, (0.2, 1.0, 0.7)))


def test_passes_with_a_schedule_against_a_quadrature_of_the_model():
    """Three passes 10 D apart, the second heated under a schedule whose kinks fall inside cells (its lateral term
    by Gauss-Legendre on the pieces before 2 D, by the far sums with the schedule's weights after): the history at
    z = 0 and 0.1 mm against the sum over passes of the quadrature of the model, within 1e-9 of the largest rise
    (measured 7e-15)."""
    xe, ye, q = _cells(16, 11)
    step = 10 * D
    ramp = _Ramp()
    st = np.array(ramp.kinks) + step
    sf = np.array([ramp(t - step) for t in st])
    st, sf = np.concatenate([[0.0, step - 1e-9], st, [step + D + 1e-9]]), np.concatenate([[1.0, 1.0], sf, [1.0]])
    sf[2], sf[-1] = ramp(0.0), 1.0
    times = np.array([0.5 * D, 3 * D, step + 0.37 * D, step + 0.9 * D, step + 3 * D, 2 * step + 0.5 * D, 3 * step])
    depths = [0.0, 1e-4]
    got = strip_history(times, depths, xe, q, BETA, KAP, V, 3, step, st, sf, y_edges=ye)
    ref = np.zeros_like(got)
    for i, t in enumerate(times):
        for j, z in enumerate(depths):
            for k in range(3):
                if t - k * step > 0:
                    ref[i, j] += _model_quadrature(t - k * step, z, xe, ye, q, ramp if k == 1 else None)
    assert np.max(np.abs(got - ref)) < 1e-9 * ref.max()


def test_thousand_passes_tail_against_the_direct_response():
    """1,000 passes 83 ms apart (the Hertz ellipse on 32 x 21 cells, z = 0 and 0.5 mm): the periodic sums with the
    tail interpolant of theta R against the sum over passes of the response evaluated without it, at the last pass's
    arrival, its peak and after it: within 1e-10 of the largest rise (measured 2.3e-12)."""
    xe, ye, q = _cells(32, 21)
    depths = [0.0, 5e-4]
    step, count = 0.083, 1000
    t = strip_time_axis(xe, V, count, step)
    got = strip_history(t, depths, xe, q, BETA, KAP, V, count, step, y_edges=ye)
    per = (t.size - 1) // count
    rows = np.array([t.size - 1 - per, t.size - 1 - per + 40, t.size - 1])
    resp = LateralPassResponse(xe, ye, q, V, depths, BETA, KAP, 1e-18)
    direct = sum(resp(np.maximum(t[rows] - k * step, 0.0)) for k in range(count))
    assert np.max(np.abs(got[rows] - direct)) < 1e-10 * got.max()


def test_flux_uniform_across_wide_strips_is_the_band():
    """The lateral kernel integrates to 1: a Hertz band's flux on 9 strips 100 mm wide in all (wider than the
    lateral diffusion length over the 3 passes, sqrt(4 kappa t) = 2.2 mm: erfc(50 / 2.2) = 0) gives the band's
    1-D history (PassResponse) within 1e-12 of its maximum, at z = 0, 0.1, 0.5 mm over 3 passes (measured 1.7e-14)."""
    xe, ye, q = _cells(32, 9, y_half=0.05, uniform_y=True)
    depths = [0.0, 1e-4, 5e-4]
    t = strip_time_axis(xe, V, 3, 0.083)
    got = strip_history(t, depths, xe, q, BETA, KAP, V, 3, 0.083, y_edges=ye)
    band = strip_history(t, depths, xe, q[:, 0], BETA, KAP, V, 3, 0.083)
    assert np.max(np.abs(got - band)) < 1e-12 * band.max()
    resp = LateralPassResponse(xe, ye, q, V, depths, BETA, KAP, 1e-18)
    theta = np.array([0.5 * D, 3 * D, 100 * D])
    base = PassResponse(xe, q[:, 0], V, depths, BETA, KAP, 1e-18)
    assert np.max(np.abs(resp(theta) - base(theta))) < 1e-12 * base(theta).max()


def test_bad_lateral_input_names_the_argument():
    """A flux per strip without its y edges (or of the wrong count) is refused naming y_edges."""
    xe, ye, q = _cells(8, 5)
    with pytest.raises(ValueError, match="y_edges"):
        strip_history([0.001], [0.0], xe, q, BETA, KAP, V)
    with pytest.raises(ValueError, match="y_edges"):
        strip_history([0.001], [0.0], xe, q, BETA, KAP, V, y_edges=ye[:-1])
