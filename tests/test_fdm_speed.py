"""What makes the transient 3-D block of plugin "fdm" cheap, and that it changes no answer.

* the fused explicit kernel visits only the x-planes that heat can have reached (the stencil moves a
  disturbance by one plane per step): the same field, bit for bit, as updating every plane;
* the moving source computes its overlaps once per phase of its cadence (p steps per q node spacings) and
  shifts them: the same increments as computing them step by step, to rounding;
* the default explicit step is the largest of that cadence within 0.9 of the stability limit (q <= 8),
  not the largest whole fraction of d/V: 4 steps per 3 cells instead of 2 per cell at the seed paper's
  level 3;
* with a scene's ``field`` the uniform transient grid reaches six penetration depths of the trail's end
  (or one contact penetration depth below ``field.depth``), not ``field.depth`` plus six: the fixed bottom
  face then changes the trace by less than 1e-6 of its maximum against the deeper block.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from railtherm import Material, surface_grid
from railtherm.physics import cell_average
from railtherm.physics import thermal_scales
from railtherm_fdm import kernels as K
from railtherm_fdm.block3d import transient_block
from railtherm_fdm.layout import (STABLE_FRACTION, Extent, Trail, block_extent, explicit_stability_limit,
                                  plan_steps, steps_per_cells, trail_extent)
from railtherm_fdm.source_loading import MovingSource

RAIL = Material(density=7680.0, conductivity=54.0, specific_heat=460.0)
KAPPA = RAIL.diffusivity
R = 2.5e-3            # contact radius [m]
Q = 1e6               # flux [W/m^2]


def _run(cell, h=0.0, **kw):
    g = surface_grid(R, R, 0, cells=16)
    q = Q * cell_average(g, "uniform", R, R)
    return transient_block(g, q, g.inside().astype(float), 1.0, RAIL.conductivity, RAIL.density,
                           RAIL.specific_heat, h, cell, scheme="explicit", **kw)


@pytest.mark.parametrize("h", [0.0, 2e4])
def test_fused_kernel_skips_only_planes_without_heat(monkeypatch, h):
    """Stops the kernel is given lie below the last plane while the source starts on a cold block, and
    the field equals the run that updates every plane (stop = nx - 1) bit for bit."""
    monkeypatch.setattr(K, "PARALLEL_MIN_NODES", 0)
    # the serial build: the parallel one is the same Python body compiled with prange (bit-identical,
    # tests/test_fdm_package.py) and costs ~15 s to compile on an empty numba cache
    fused = K.explicit_two_steps_serial
    stops = []

    def record(*args):
        stops.append((args[-1], args[0].shape[0] - 1))
        fused(*args)

    def full(*args):
        fused(*args[:-1], args[0].shape[0] - 1)

    for build in ("explicit_two_steps", "explicit_two_steps_serial"):   # the one this process's threads pick
        monkeypatch.setattr(K, build, record)
    skipped = _run(R / 4, h=h)
    for build in ("explicit_two_steps", "explicit_two_steps_serial"):
        monkeypatch.setattr(K, build, full)
    every = _run(R / 4, h=h)
    assert skipped.diagnostics["fused_steps"]
    assert stops[0][0] < stops[0][1] and sum(stop < end for stop, end in stops) >= 3
    assert stops[-1][0] == stops[-1][1]
    assert np.array_equal(skipped.surface, every.surface) and np.array_equal(skipped.depth, every.depth)
    for key in ("energy_lost_fixed_faces", "energy_lost_convection", "energy_stored"):
        assert skipped.diagnostics[key] == pytest.approx(every.diagnostics[key], rel=1e-12, abs=1e-300)
    assert abs(skipped.diagnostics["heat_balance_error"]) < 1e-12


@pytest.mark.parametrize("h, steps, cells", [(0.0, 3, 1), (2e4, 3, 1), (2e4, 4, 3)])
def test_moving_source_phases_match_step_by_step_loading(h, steps, cells):
    """Source increments, loss factors and energies of every step, up to where the block's end cuts the
    footprint, against the overlaps computed afresh each step (``steps`` steps per ``cells`` spacings)."""
    d, speed = 1e-4, 1.0
    dt = cells * d / (steps * speed)
    x = d * np.arange(120)
    pxe = np.linspace(-R, R, 17)
    flux = np.linspace(1.0, 2.0, 16) * Q
    cover = np.ones(16)
    args = (x, d, pxe, flux, cover, d, 3.5e3, 0.01, h, 30 * d + R, speed, dt)
    phased, direct = MovingSource(*args, period=steps, period_cells=cells), MovingSource(*args)
    last = int((x[-1] - 30 * d) / (speed * dt))                       # the footprint runs off the block's end
    for n in range(last):
        e1, e2 = phased.load(n), direct.load(n)
        assert e1 == pytest.approx(e2, rel=1e-12)
        # rounding: the step-averaged overlap divides differences of squared lengths (~d^2) by the
        # travel of one step (d/3), so both ways carry errors of ~1e-13 of the largest increment
        assert np.max(np.abs(phased.src[0] - direct.src[0])) <= 1e-12 * direct.src[0].max()
        assert np.max(np.abs(phased.hloss[0] - direct.hloss[0])) <= 1e-12 * direct.hloss[0].max()
        # the footprints may differ by a node of their zero margin (a ceil at a node, rounded either way)
        assert abs(phased.reach() - direct.reach()) <= 1
        assert not phased.src[0][phased.reach() + 1:].any() and not direct.src[0][direct.reach() + 1:].any()
    assert direct.reach() == x.size - 2 and len(phased._phases) == steps


def test_steps_per_cells_is_the_least_ratio_above_the_need():
    """p/q >= need with no smaller such ratio for any q <= 8; one step per cell when that is stable."""
    assert steps_per_cells(0.7) == (1, 1) and steps_per_cells(1.0) == (1, 1)
    assert steps_per_cells(2.0) == (2, 1) and steps_per_cells(1.2) == (6, 5)
    for need in np.linspace(1.01, 9.7, 97):
        p, q = steps_per_cells(need)
        assert p / q >= need * (1 - 1e-12) and q <= 8
        assert all(math.ceil(need * k * (1 - 1e-12)) / k >= p / q for k in range(1, 9))


def test_explicit_plan_at_the_seed_papers_level_3():
    """Cells of 78 um at 1 m/s (d/V is 1.17 stability limits): 4 steps per 3 cells at 0.88 of the limit (the
    whole-fraction cadence took 2 per cell), the quasi-steady checkpoint a whole cadence before the end."""
    d, V, travel = R / 32, 1.0, 6 * R
    lim = explicit_stability_limit(d, KAPPA)
    plan = plan_steps(d, V, travel, lim, a=R)
    assert (plan.period, plan.period_cells) == (4, 3)
    assert 0.85 * lim < plan.dt <= STABLE_FRACTION * lim
    assert plan.steps == math.ceil(travel / d * 4 / 3 - 1e-9) and plan.travel >= travel
    assert (plan.steps - plan.check_step) % plan.period == 0
    assert (plan.steps - plan.check_step) * V * plan.dt == pytest.approx(R, rel=0.1)
    fast = plan_steps(d, 4 * V, travel, lim, a=R)                  # stable at one step per cell: the seed's
    assert (fast.period, fast.period_cells) == (1, 1) and fast.dt == pytest.approx(d / (4 * V))
    implicit = plan_steps(d, V, travel, lim, scheme="implicit", a=R)
    assert (implicit.period, implicit.period_cells) == (1, 1) and implicit.dt == pytest.approx(d / V)


def test_transient_trail_depth_is_six_penetration_depths_of_the_trail():
    """The uniform transient grid reaches max(6 s, field.depth + delta), the graded steady grid
    field.depth + 6 s (s the trail end's penetration depth, delta the contact's)."""
    a, V, behind, depth = R, 1.0, 2 * R, 3e-3
    ext = block_extent(a, a, V, KAPPA)
    s = math.sqrt(2 * KAPPA * (2 * a + behind) / V)
    delta = thermal_scales(a, V, KAPPA).thermal_depth
    tr = trail_extent(ext, Trail(behind, depth), a, V, KAPPA, steady=False)
    st = trail_extent(ext, Trail(behind, depth), a, V, KAPPA, steady=True)
    assert tr.depth == pytest.approx(max(6 * s, depth + delta, ext.depth), rel=1e-12)
    assert st.depth == pytest.approx(depth + 6 * s, rel=1e-12)
    assert tr.travel == pytest.approx(ext.travel + behind) and st.behind == pytest.approx(ext.behind + behind)
    shallow = trail_extent(ext, Trail(behind, 1e-4), a, V, KAPPA, steady=False)
    assert shallow.depth == pytest.approx(max(6 * s, ext.depth), rel=1e-12)


def test_transient_trail_depth_changes_the_trace_by_less_than_1e_6():
    """The explicit block with a field 2a behind and 1.5 mm deep, against the same block 6 s deeper:
    surface and depth field (y = 0) agree to 1e-6 of their maximum; the shallower block has fewer nodes."""
    g = surface_grid(R, R, 0, cells=16)
    trail = Trail(2 * R, 1.5e-3)
    base = block_extent(R, R, 1.0, KAPPA)
    s = math.sqrt(2 * KAPPA * (2 * R + trail.behind) / 1.0)
    deep = Extent(base.ahead, base.behind, base.lateral, trail.depth + 12 * s, base.travel)
    short = _run(R / 8, out_grid=g, trail=trail)
    ref = _run(R / 8, out_grid=g, trail=trail, extent=deep)
    assert short.diagnostics["nodes"] < 0.75 * ref.diagnostics["nodes"]
    assert short.z[-1] >= trail.depth
    assert np.max(np.abs(short.surface - ref.surface)) < 1e-6 * ref.surface.max()
    k = short.z.size
    assert np.array_equal(short.z, ref.z[:k])
    assert np.max(np.abs(short.depth - ref.depth[:, :k])) < 1e-6 * ref.depth.max()


def test_serial_build_of_the_fused_kernel_equals_the_parallel_one():
    """explicit_two_steps_serial (what a one-thread process runs) gives the parallel build's planes and
    loss sums for the same chunks."""
    rng = np.random.default_rng(1)
    n = 18
    T = rng.random((n, n, n))
    T[0] = T[-1] = 0.0
    z, ones = np.zeros((n, n)), np.ones(n)
    out = []
    for fn in (K.explicit_two_steps, K.explicit_two_steps_serial):
        T2, acc = np.zeros_like(T), np.zeros((4, 6))
        fn(T.copy(), T2, 1 / 6, z + 0.01, z + 1e-3, z + 0.02, z + 1e-3, np.ones((n, n)), ones, ones, 4, acc, n - 1)
        out.append((T2, acc))
    assert out[0][0].tobytes() == out[1][0].tobytes() and out[0][1].tobytes() == out[1][1].tobytes()
