"""The eigenmodes of fipy's section (railtherm_fipy.modes): FiPy's operator separated and stepped per mode.

Checks: (1) the separated conductances rebuild FiPy's assembled matrix of the section (with surface convection)
and a non-separable matrix is recognised (the section refuses it with a SolverError); (2) theta-scheme steps taken per mode equal the same steps solved by
sparse LU with FiPy's matrix, ``(C/dt + theta K) T1 = (C/dt - (1 - theta) K) T0 + theta p1 + (1 - theta) p0``, to
1e-11 of the state's size (Crank-Nicolson and backward Euler, steps from 1e-7 to 1 s, a surface load); (3) the
change of basis and the section's stepper state go both ways.
"""
from __future__ import annotations

import numpy as np
import pytest

from railtherm import SolverError
from railtherm.input.materials import Material
from railtherm_fipy.history import FipyBlock, fipy_block
from railtherm_fipy.modes import separate

from transient_cases import lu_theta_steps

STEEL = Material()
A, V = 6e-3, 30.0


@pytest.fixture(scope="module")
def block():
    """The section at level 1 for 4 passes 20 ms apart, depths 0.1 and 0.5 mm, convection 20 W/(m^2 K)."""
    return fipy_block(A, V, STEEL.conductivity, STEEL.density * STEEL.specific_heat, 20.0, 1, 0.08, [1e-4, 5e-4])


def test_separated_conductances_rebuild_fipys_matrix(block):
    dx, dz = np.diff(block.faces_x), block.modes.dz
    Kx, Kz = separate(block.stiffness, dx, dz)
    nx = dx.size
    assert np.allclose(Kx.sum(axis=1), 0.0, atol=1e-12 * np.abs(Kx).max())      # insulated ends
    rebuilt = np.kron(np.diag(dz), Kx) + np.kron(Kz, np.diag(dx))
    K = block.stiffness.toarray()
    assert np.max(np.abs(K - rebuilt)) <= 1e-12 * np.max(np.abs(K))
    assert Kz[0, 0] * dx[0] - K[0, 0] + Kx[0, 0] * dz[0] == pytest.approx(0.0, abs=1e-9 * K[0, 0])
    skewed = block.stiffness.tolil()
    skewed[3 * nx + 5, 3 * nx + 5] *= 1.001                    # one cell's conductance off the product form
    assert separate(skewed.tocsr(), dx, dz) is None
    faces_z = np.concatenate([[0.0], np.cumsum(dz)])
    with pytest.raises(SolverError, match="not the separable sum"):
        FipyBlock(block.faces_x, faces_z, block.capacity, skewed.tocsr(), [1e-4])


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_steps_per_mode_equal_sparse_lu_steps(block, theta):
    modes = block.modes
    T, steps = lu_theta_steps(block.capacity, block.stiffness, modes.dx.size, theta, np.random.default_rng(7))
    Y = modes.of_cells(T)
    for dt, load, T in steps:
        a, b = modes.coefficients(dt, theta)
        Y = a * Y + b * modes.load(load)
        assert np.max(np.abs(modes.to_cells(Y) - T)) <= 1e-11 * np.max(np.abs(T)), dt
        expected = np.sum(T[block.rows] * block.weights, axis=1)
        assert np.allclose(modes.sample(Y), expected, rtol=0.0, atol=1e-11 * np.max(np.abs(T)))


def test_cells_and_modes_go_both_ways(block):
    T = np.random.default_rng(3).standard_normal(block.capacity.size)
    assert np.allclose(block.modes.to_cells(block.modes.of_cells(T)), T, rtol=0.0, atol=1e-12)
    st = block.stepper(np.linspace(-A, A, 33), None, np.ones(32), V, lambda t: 1.0, 0.0)
    assert np.all(st.T == 0.0)
    st.T = T
    assert np.allclose(st.T, T, rtol=0.0, atol=1e-12)
    side = st.fresh(0.0)
    assert side.cache is st.cache and np.all(side.T == 0.0)
