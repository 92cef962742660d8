"""green's transient sums (railtherm_green.transient): the far sum of one pass's response past the contact against
quadrature of its cell integrals, the sums over passes on green's periodic axis against the generic sum over the
passes' phases, the tail interpolant's error over a thousand passes, and the time above a threshold the history
never reaches."""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate

from railtherm.input.materials import Material
from railtherm.physics import pass_time_above
from railtherm.references.transient import shifted_sum
from railtherm.solving.pipeline import solve
from railtherm_green import transient as gt
from railtherm_green.pass_response import PassResponse
from railtherm_green.smooth_tail import with_smooth_tail

STEEL = Material()
BETA, KAP = STEEL.effusivity, STEEL.diffusivity
A, V, Q = 6e-3, 30.0, 1e8
D = 2 * A / V                   # contact duration [s]


def _hertz(n):
    xe = np.linspace(-A, A, n + 1)
    xc = 0.5 * (xe[1:] + xe[:-1])
    return xe, Q * np.sqrt(1 - (xc / A) ** 2)


def _cell_quadrature(theta, z, xe, fl):
    """The unit response at theta [s], depth z [m] as the sum over cells of q_k int g(theta - c) dc over the
    cell's crossing times (g = F' = exp(-c_z/s)/sqrt(s) > 0: no cancellation), by scipy's adaptive quadrature."""
    cz = z * z / (4 * KAP)
    c_hi, c_lo = (xe[-1] - xe[:-1]) / V, (xe[-1] - xe[1:]) / V
    total = 0.0
    for q, lo, hi in zip(fl, c_lo, c_hi):
        val, _ = integrate.quad(lambda c: math.exp(-cz / (theta - c)) / math.sqrt(theta - c), lo, hi,
                                epsabs=0.0, epsrel=1e-13)
        total += q * val
    return total / (BETA * math.sqrt(math.pi))


def test_far_sum_against_the_cell_quadrature():
    """Past two contact durations the response is the far sum: g = F' interpolated in the crossing time at 25
    Chebyshev nodes and integrated to each edge, with the weights' zero sum taken out exactly. Against the
    quadrature of the cell integrals (Hertz flux, 32 cells, 12 times from 2 D to 100 s, z = 0, 0.1, 0.5 mm):
    within 1e-14 relative (measured 7e-16). The direct edge sum differs from the same reference by up to 1e-10
    relative past 20 s (its terms are ~theta/D times the result; measured 9.7e-11 at 46 s): what the far sum
    removes."""
    xe, fl = _hertz(32)
    depths = [0.0, 1e-4, 5e-4]
    theta = np.geomspace(2 * D, 100.0, 12)
    resp = PassResponse(xe, fl, V, depths, BETA, KAP, 1e-18)
    ref = np.array([[_cell_quadrature(t, z, xe, fl) for z in depths] for t in theta])
    far = resp.far(theta)
    assert np.max(np.abs(far / ref - 1)) < 1e-14
    direct = resp.direct(theta)
    assert np.max(np.abs(direct[-1] / ref[-1] - 1)) > 100 * np.max(np.abs(far[-1] / ref[-1] - 1))


def _away_from_crossings(t, xe, count, step):
    """Times more than 1e-9 s from every pass's cell-edge crossings (where sqrt(t - c) amplifies rounding)."""
    crossings = (xe[-1] - xe) / V
    gap = np.abs(t[:, None, None] - step * np.arange(count)[None, :, None] - crossings[None, None, :])
    return gap.min(axis=(1, 2)) > 1e-9


def test_periodic_sums_equal_the_sum_over_the_phases():
    """On green's own axis (the passes repeat one pass's offsets) the passes after the first, all in the tail,
    are interpolated and summed in one compiled loop: equal bit for bit to the cumulative sums of the table of
    the response over (offsets x passes), and to the generic sum over the passes' rounded phases
    (railtherm.references.transient.shifted_sum) within 1e-12 of the maximum away from the cell-edge crossings
    and 1e-7 at them (there the phases' rounding to 1e-12 of the interval, which shifted_sum does pass by pass,
    meets sqrt(t - c)). An axis that does not repeat takes the generic sum."""
    depths = [0.0, 1e-4, 5e-4]
    for n, count, step in ((64, 3, 0.02), (32, 40, 0.05)):
        xe, fl = _hertz(n)
        t = gt.strip_time_axis(xe, V, count, step)
        resp = PassResponse(xe, fl, V, depths, BETA, KAP, 1e-12 * step + 1e-15 * D)

        def one_pass(theta):
            return with_smooth_tail(resp, theta, 4 * D, far=resp.far, passes=count)
        got = gt.strip_history(t, depths, xe, fl, BETA, KAP, V, count, step)
        offsets = gt._periodic_offsets(t, count, step)
        assert offsets is not None and offsets.size == (t.size - 1) // count
        assert np.array_equal(got, gt._periodic_pass_sum(t, count, step, offsets, one_pass))
        generic = shifted_sum(t, count, step, one_pass)
        smooth = _away_from_crossings(t, xe, count, step)
        assert np.max(np.abs(got - generic)[smooth]) < 1e-12 * generic.max()
        assert np.max(np.abs(got - generic)) < 1e-7 * generic.max()
    assert gt._periodic_offsets(np.sort(np.random.default_rng(1).uniform(0, 0.06, 300)), 3, 0.02) is None


def test_thousand_passes_keep_the_tail_error_of_one():
    """1,000 passes 50 ms apart (Hertz band, 128 cells, z = 0, 0.1, 0.5 mm), against the same sum of the response
    evaluated exactly at every time (the lattice convolution, the far sum, the edge sums: no tail interpolant):
    within 2e-11 of the maximum (measured 3e-12). The interpolant's dropped trailing coefficients change each
    pass's tail by one sign along it, so what they may change is shared among the passes summed (dropped
    against one pass's margin, they left 9.5e-11 of the maximum at 0.5 mm over the benchmark's 1,000 passes)."""
    xe, fl = _hertz(128)
    count, step, depths = 1000, 0.05, [0.0, 1e-4, 5e-4]
    t = gt.strip_time_axis(xe, V, count, step)
    resp = PassResponse(xe, fl, V, depths, BETA, KAP, 1e-12 * step + 1e-15 * D)
    exact = gt._periodic_pass_sum(t, count, step, gt._periodic_offsets(t, count, step), resp)
    got = gt.strip_history(t, depths, xe, fl, BETA, KAP, V, count, step)
    assert np.max(np.abs(got - exact)) < 2e-11 * exact.max()


def test_time_above_a_threshold_never_reached_is_zero():
    """A history below the threshold spends no time above it: green's time above is 0 without the per-pass
    crossing search, as that search gives on the same history; with a threshold the surface reaches, green's
    time above is that search's."""
    for threshold, reached in ((400.0, False), (60.0, True)):
        scene = {"name": "band", "speed": V, "heat_source": {"flux": Q, "shape": "hertz", "half_width": A},
                 "heat_partition": 0.0, "rail": {"bulk_temperature": 20.0}, "wheel": {"bulk_temperature": 20.0},
                 "mode": "transient", "passes": {"count": 3, "interval": 0.05},
                 "field": {"depth": [1e-4], "threshold": threshold},
                 "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]}
        ds = solve(scene, "green", level=1)
        rise = ds["temperature_history"].values[1] - 20.0
        search = pass_time_above(ds["time"].values, rise, 3, 0.05, threshold - 20.0)
        assert np.array_equal(ds["time_above"].values[1], search)
        assert bool(np.any(search > 0)) == reached
