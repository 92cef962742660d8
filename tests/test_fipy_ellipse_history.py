"""fipy's pass histories of an elliptical patch (railtherm_fipy.history3d): the 3-D block of FiPy cells around the
fixed section, its operator separated into 1-D parts and stepped per eigenmode by Crank-Nicolson, through
``railtherm.solve(scene, "fipy", level)`` on the transient study's train-4-axles (4 passes of a Hertz ellipse a = 6,
b = 4 mm, 2e8 W/m^2 into the rail, 30 m/s, 83 ms apart) against core's exact moving ellipse
(railtherm.references.transient).

Checks: (1) the sum of the 1-D parts FiPy assembles is FiPy's assembled 3-D matrix (with surface convection), a
non-separable matrix is recognised; (2) theta steps per mode equal sparse-LU steps of FiPy's matrix, and the
modes the stepper keeps (those the centre column reads) give the same outputs; (3) the
pass peaks at 0.1 and 0.5 mm within 5 % of the exact ellipse (issue target at level 2; level 0 in the fast
suite); (4) the pass peak error converges over levels 0 .. 2 at the scheme's second order; (5) the cell budget
refuses a block too large, naming the option.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from railtherm import Refused
from railtherm.input.materials import Material
from railtherm.input.study import load_study
from railtherm.solving.pipeline import solve
from railtherm_fipy.history3d import fipy_3d_stiffness, fipy_ellipse_block, separate3

from transient_cases import lu_theta_steps, train_of_axles

STUDY = Path(__file__).parent.parent / "studies" / "transient.toml"
STEEL = Material()
A, B, V = 6e-3, 4e-3, 30.0
DEPTHS = (0.0, 1e-4, 5e-4)


@pytest.fixture(scope="module")
def block():
    """The block at level 0 for a history of 1 ms (25 x 17 x 16 cells), depths 0.1 and 0.5 mm, convection
    20 W/(m^2 K)."""
    return fipy_ellipse_block(A, B, V, STEEL.conductivity, STEEL.density * STEEL.specific_heat, 20.0, 0, 1e-3, [1e-4, 5e-4])


def test_block_operator_is_fipys_3d_matrix(block):
    """The sum of the 1-D parts FiPy assembles on Grid1D meshes is FiPy's Grid3D matrix of the block (surface
    convection included) to 1e-12, and :func:`separate3` reads the same parts off the 3-D matrix; a matrix off
    the product form is recognised."""
    dx, dy, dz = block.widths
    K = fipy_3d_stiffness(dx, dy, dz, STEEL.conductivity, STEEL.density * STEEL.specific_heat, 20.0)
    assert abs(K - block.stiffness).max() <= 1e-12 * abs(K).max()
    assert np.allclose(K.diagonal(), block.stiffness.diagonal(), rtol=1e-12, atol=0.0)
    assert block.dt_stab == pytest.approx(float(np.min(block.capacity / K.diagonal())), rel=1e-12)
    Kx, Ky, Kz = separate3(K, dx, dy, dz)
    for got, want in zip(block.parts, (Kx, Ky, Kz)):
        assert np.allclose(got, want, rtol=0.0, atol=1e-12 * np.abs(want).max())
    Kx, Ky, Kz = block.parts
    assert np.allclose(Kx.sum(axis=1), 0.0, atol=1e-12 * np.abs(Kx).max())      # insulated ends
    assert np.allclose(Ky.sum(axis=1), 0.0, atol=1e-12 * np.abs(Ky).max())      # insulated sides
    assert Kz[0].sum() == pytest.approx(20.0, rel=1e-9)        # the top's convection h [W/(m^2 K)]
    assert Kz[-1].sum() > 0.0                                  # the deep face at theta = 0
    nx, ny = dx.size, dy.size
    skewed = K.tolil()
    skewed[3 * nx * ny + 5, 3 * nx * ny + 5] *= 1.001          # one cell's conductance off the product form
    assert separate3(skewed.tocsr(), dx, dy, dz) is None


def test_stepped_modes_are_those_the_centre_column_reads(block):
    """On the block's symmetric widths the odd modes vanish on the centre column and line (to rounding): the
    stepper keeps (nx + 1)/2 x (ny + 1)/2 of them per depth mode, all with a value there."""
    full, kept = block.all_modes(), block.modes
    nz, ny, nx = full.shape
    assert kept.rate.shape == (nz, (ny + 1) // 2, (nx + 1) // 2)
    dropped_x = np.setdiff1d(full.wx, kept.wx)
    assert dropped_x.size == nx // 2
    assert np.max(np.abs(full.vx[block.i0][np.isin(full.wx, dropped_x)])) < 1e-12 * np.max(np.abs(full.vx[block.i0]))


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_steps_per_mode_equal_sparse_lu_steps(block, theta):
    """Theta steps of 1e-7 .. 1 s under a random surface load: per mode and by sparse LU of FiPy's matrix
    ``(C/dt + theta K) T1 = (C/dt - (1 - theta) K) T0 + theta p1 + (1 - theta) p0``, to 1e-11 of the state; the
    stepper's modes (those the centre column reads, stepped in place) give the column's outputs to 1e-11, and
    their compiled step (update and read in one pass) equals the array form to 1e-13."""
    modes, kept, C = block.all_modes(), block.modes, block.capacity
    K = fipy_3d_stiffness(*block.widths, STEEL.conductivity, STEEL.density * STEEL.specific_heat, 20.0)
    T, steps = lu_theta_steps(C, K, modes.dx.size * modes.dy.size, theta, np.random.default_rng(7))
    Y, Yk = modes.of_cells(T), kept.of_cells(T)
    Ys = Yk.copy()
    for dt, load, T in steps:
        a, b = modes.coefficients(dt, theta)
        surface = load.reshape(modes.dy.size, modes.dx.size)
        Y = a * Y + b * modes.load(surface)
        ak, bk = kept.step_coefficients(dt, theta)
        Yk = ak * Yk + bk * kept.project(surface)[None]                               # the array form
        Ys, out = kept.step(Ys, kept.step_coefficients(dt, theta), kept.project(surface))   # compiled, one pass
        assert np.allclose(Ys, Yk, rtol=0.0, atol=1e-13 * np.max(np.abs(Yk)))
        assert np.allclose(out, kept.sample(Yk), rtol=0.0, atol=1e-13 * np.max(np.abs(T)))
        assert np.max(np.abs(modes.to_cells(Y) - T)) <= 1e-11 * np.max(np.abs(T)), dt
        column = T.reshape(modes.shape)[:, block.j0, block.i0]
        expected = np.sum(column[block.rows] * block.weights, axis=1)
        assert np.allclose(modes.sample(Y), expected, rtol=0.0, atol=1e-11 * np.max(np.abs(T)))
        assert np.allclose(kept.sample(Yk), expected, rtol=0.0, atol=1e-11 * np.max(np.abs(T)))
    a, b = modes.coefficients(1e-3, theta)
    Ys, out = kept.step(Ys, kept.step_coefficients(1e-3, theta), None)                # a source-free step
    assert np.allclose(out, modes.sample(a * Y), rtol=0.0, atol=1e-11 * np.max(np.abs(T)))


def test_stepper_power_is_the_flux_integrated_over_the_surface_cells(block):
    """A uniform flux q over a source grid wider than the block: every surface cell takes q times its face's
    area; the state goes to the stepped modes and back (a projection: twice is once) with the centre column's
    outputs kept."""
    xe, ye = np.linspace(-0.1, 0.1, 9), np.linspace(-0.1, 0.1, 5)
    st = block.stepper(xe, ye, np.full((8, 4), 3.0), V, lambda t: 1.0, 0.0)
    p = st._surface_power(0.1 / V, [0.0])          # the source centred on the section
    assert np.allclose(p, 3.0 * np.outer(block.modes.dy, block.modes.dx), rtol=1e-12)
    projected = block.modes.project(p)
    assert np.allclose(st._step_power(0.1 / V, [0.0]), projected, rtol=0.0, atol=1e-12 * np.abs(projected).max())
    T = np.random.default_rng(3).standard_normal(block.capacity.size)
    st.T = T
    column = T.reshape(block.modes.shape)[:, block.j0, block.i0]
    assert np.allclose(block.modes.sample(st.Y), np.sum(column[block.rows] * block.weights, axis=1), rtol=0.0,
                       atol=1e-12 * np.max(np.abs(T)))
    Y = st.Y.copy()
    st.T = st.T.copy()
    assert np.allclose(st.Y, Y, rtol=0.0, atol=1e-12 * np.max(np.abs(Y)))
    side = st.fresh(0.0)
    assert side.cache is st.cache and np.all(side.T == 0.0)


def _train(level):
    """fipy's rail pass peaks (passes, depths) on the study's train-4-axles at ``level`` and their relative
    errors against the exact ellipse at the surface, 0.1 and 0.5 mm; the result."""
    ds, peak, exact = train_of_axles("fipy", level, DEPTHS)
    return np.abs(peak / exact.peak - 1.0), ds


def test_train_of_axles_level_0_within_5_percent_of_the_exact_ellipse():
    """Level 0 (27 x 27 x 31 cells, ~2 s): every pass's peak at 0.1 and 0.5 mm within 5 % of the exact ellipse
    (measured 0.41 % and 0.81 %); the rail's history from the 3-D block, the wheel unheated at its bulk."""
    err, ds = _train(0)
    assert np.max(err[:, 1:]) < 0.05, err
    assert ds.attrs["fipy_dimension"] == 3
    assert ds.attrs["fipy_rail_history_node_shape"].count("x") == 2
    assert np.all(ds.temperature_history.sel(body="wheel").values == 20.0)


@pytest.fixture(scope="module")
def ladder():
    """The errors (levels, passes, depths) of levels 0 .. 2 (level 2: 85 x 101 x 121 cells, ~3 s)."""
    return [_train(level)[0] for level in range(3)]


def test_train_of_axles_level_2_within_5_percent_of_the_exact_ellipse(ladder):
    """Issue target: at level 2 every pass's peak at 0.1 and 0.5 mm within 5 % of the exact ellipse (measured
    0.047 % and 0.032 %)."""
    assert np.max(ladder[2][:, 1:]) < 0.05, ladder[2]


def test_pass_peak_error_converges_at_second_order(ladder):
    """Levels 0 .. 2 (cells h = 2a/32/2**level along x, b/8/2**level across, delta/4/2**level at the surface,
    steps h/V: second order in space and time): the largest pass peak error over the surface, 0.1 and 0.5 mm
    falls like h^2 (fitted slope within 0.3 of 2; measured 0.81, 0.14, 0.047 %: slope 2.05), and at every
    depth each level at least halves it (at 0.1 mm more slowly than h^2: measured 0.41, 0.13, 0.047 %)."""
    worst = [float(np.max(e)) for e in ladder]
    hs = [2 * A / 32 / 2 ** level for level in range(3)]
    assert np.polyfit(np.log(hs), np.log(worst), 1)[0] == pytest.approx(2.0, abs=0.3), worst
    by_depth = np.array([np.max(e, axis=0) for e in ladder])
    assert np.all(by_depth[1:] < 0.5 * by_depth[:-1]), by_depth


def test_computed_patch_through_fipy_agrees_with_green():
    """A computed Hertz patch (full sliding, heat into both bodies), 3 passes 50 ms apart, level 0: fipy's 3-D
    blocks of both bodies (the wheel's and the rail's) separate (FiPy's deep face alone constrained) and their
    residual rises agree with green's (exact in time, its lateral conduction approximate) within 1 % (measured
    0.24 %)."""
    import railtherm.testing
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", passes={"count": 3, "interval": 0.05},
                                        outputs=["temperature_history", "residual_rise"])
    ds = solve(scene, "fipy", level=0)
    green = solve(scene, "green", level=0)
    assert ds.attrs["fipy_wheel_history_node_shape"].count("x") == 2
    assert np.max(np.abs(ds.residual_rise.values / green.residual_rise.values - 1.0)) < 0.01


def test_block_over_the_cell_budget_is_refused():
    """A level whose block exceeds ``max_history_cells`` is refused before FiPy assembles it, naming the shape,
    the level and the option."""
    scene = load_study(STUDY).scene("train-4-axles")
    with pytest.raises(Refused, match=r"max_history_cells = 1e\+04.*raise the option max_history_cells"):
        solve(scene, "fipy", level=0, options={"max_history_cells": 10_000})
