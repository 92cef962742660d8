"""FiPy plumbing of the "fipy" plugin: safe import, FiPy's exponential1D example, solver checks, meshes.

Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_fipy_solvers.py -q``.
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from railtherm import SolverError
from railtherm.physics import geometric_edges, thermal_scales
from railtherm_fipy.mesh import moving_frame_mesh
from railtherm_fipy.solvers import import_fipy, make_solver, solve_checked, solver_suite
from railtherm_fipy.steady import SCHEMES, convection_term

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED = Path(__file__).parent / "data" / "published.toml"


def _published(name):
    with open(PUBLISHED, "rb") as f:
        return tomllib.load(f)[name]


# ------------------------------------------------------------------ import guard
@pytest.mark.parametrize("first_use", [
    "from railtherm_fipy.solvers import import_fipy; import_fipy()",
    # the pass-history block may be the first code of a process to need FiPy: it goes through the guard too
    "from railtherm_fipy.history import fipy_block; fipy_block(1e-3, 30.0, 50.0, 3.8e6, 0.0, 0, 0.01, [0.0])",
], ids=["import_fipy", "section-history"])
def test_import_ignores_our_command_line_and_uses_scipy(first_use):
    """FiPy reads sys.argv at import: railtherm's CLI arguments (even a stray --petsc) must not reach it, and the
    suite is SciPy's, whichever fipy module is the first to need FiPy."""
    code = ("import sys; sys.argv = ['railtherm', 'run', 'study.toml', '--out', 'x', '--petsc', '--inline'];"
            f"{first_use}; from railtherm_fipy.solvers import solver_suite;"
            "assert sys.argv[1:3] == ['run', 'study.toml'], sys.argv; print(solver_suite())")
    env = dict(os.environ)
    env.pop("FIPY_SOLVERS", None)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "core"), str(ROOT / "plugins"), env.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "scipy"


def test_suite_in_process():
    import_fipy()
    assert solver_suite() == "scipy"
    assert os.environ.get("FIPY_SOLVERS") == "scipy"


# ------------------------------------------------------------------ FiPy's exponential1D example
def _exponential1d(scheme: str, ours: bool):
    """FiPy examples/convection/exponential1D/mesh1D.py: D phi'' + (u phi)' = 0, phi(0)=0, phi(L)=1."""
    fp = import_fipy()
    p = _published("fipy_exponential1d")
    D, u, L = p["diffusion"], p["velocity"], p["length"]
    nx = 10
    mesh = fp.Grid1D(dx=L / nx, nx=nx)
    var = fp.CellVariable(mesh=mesh, name="variable")
    var.constrain(0.0, mesh.facesLeft)
    var.constrain(1.0, mesh.facesRight)
    if ours:
        # the form used by railtherm_fipy.steady: material flowing towards -x with speed u
        eq = fp.DiffusionTerm(coeff=D) - convection_term(scheme)(coeff=(-u,)) == 0
    else:  # the example verbatim
        eq = fp.DiffusionTerm(coeff=D) + fp.ExponentialConvectionTerm(coeff=(u,)) == 0
    diag = solve_checked(eq, var, make_solver("lu"))
    x = mesh.cellCenters[0].value
    exact = (1.0 - np.exp(-u * x / D)) / (1.0 - np.exp(-u * L / D))
    return np.asarray(var.value), exact, diag


def test_exponential1d_example_verbatim():
    """FiPy's own check: ``var.allclose(analyticalArray)`` (rtol 1e-5, atol 1e-8)."""
    phi, exact, diag = _exponential1d("exponential", ours=False)
    assert np.allclose(phi, exact, rtol=1e-5, atol=1e-8)
    assert diag["converged"] and diag["residual"] < 1e-10


def test_exponential1d_with_our_sign_convention():
    """``DiffusionTerm(D) - Term(coeff=(-u,))`` (material moving to -x) is the same equation."""
    phi, exact, _ = _exponential1d("exponential", ours=True)
    assert np.allclose(phi, exact, rtol=1e-5, atol=1e-8)


@pytest.mark.parametrize("scheme,tol", [("power-law", 0.02), ("upwind", 0.25), ("hybrid", 0.25)])
def test_exponential1d_other_schemes(scheme, tol):
    """Cell Péclet number u dx / D = 10 here: power law tracks the exponential scheme (Patankar: within
    a few per cent), upwind/hybrid are first order with an error of order 1/(cell Pe)."""
    phi, exact, _ = _exponential1d(scheme, ours=True)
    err = np.max(np.abs(phi - exact))
    assert err < tol
    assert np.all(phi >= -1e-12) and np.all(phi <= 1 + 1e-12)  # monotone schemes: no over/undershoot


def test_central_scheme_oscillates_at_high_cell_peclet():
    """Central differencing at cell Péclet number 10 over- and undershoots (docs/NOTES.md): values leave [0, 1]
    and the profile is not monotone."""
    phi, exact, _ = _exponential1d("central", ours=True)
    assert phi.max() > 1.0 + 1e-3 or phi.min() < -1e-3
    assert np.any(np.diff(phi) < 0)


# ------------------------------------------------------------------ solver checks
def test_non_converged_solve_raises_solver_error():
    """A Krylov solve stopped after 1 iteration returns garbage with only a warning in FiPy: we raise."""
    fp = import_fipy()
    mesh = fp.Grid2D(nx=60, ny=60, dx=1.0, dy=1.0)
    var = fp.CellVariable(mesh=mesh, value=0.0)
    var.constrain(1.0, mesh.facesLeft)
    var.constrain(0.0, mesh.facesRight)
    eq = fp.DiffusionTerm(1.0) == 0
    solver = fp.solvers.scipy.LinearGMRESSolver(tolerance=1e-12, iterations=1, criterion="RHS")
    with pytest.raises(SolverError, match="did not converge"):
        solve_checked(eq, var, solver, what="test")


def test_lu_reports_residual_and_iterations():
    fp = import_fipy()
    mesh = fp.Grid1D(nx=50, dx=0.02)
    var = fp.CellVariable(mesh=mesh, value=0.0)
    var.constrain(0.0, mesh.facesLeft)
    var.constrain(1.0, mesh.facesRight)
    diag = solve_checked(fp.DiffusionTerm(1.0) == 0, var, make_solver("lu"))
    assert diag["converged"] is True and diag["iterations"] >= 1 and diag["residual"] < 1e-12
    assert np.allclose(var.value, mesh.cellCenters[0].value, atol=1e-12)  # linear profile, exact


def test_schemes_known():
    assert {"power-law", "upwind", "exponential"} <= set(SCHEMES)
    with pytest.raises(ValueError):
        convection_term("quick")


# ------------------------------------------------------------------ meshes
def test_thermal_scales_ertz_knothe():
    """Péclet ~ 6 200 at 30 m/s (docs/NOTES.md), delta = a / sqrt(Pe) ~ 75 um."""
    kappa = 50.0 / (7850.0 * 450.0)
    sc = thermal_scales(5.88e-3, 30.0, kappa)
    assert sc.peclet == pytest.approx(30.0 * 5.88e-3 / (2 * kappa))
    assert 6000 < sc.peclet < 6400
    assert sc.thermal_depth == pytest.approx(5.88e-3 / math.sqrt(sc.peclet))
    assert 70e-6 < sc.thermal_depth < 80e-6
    assert sc.wake_length == pytest.approx(2 * kappa / 30.0)


def test_geometric_edges_nested_and_graded():
    for level in range(4):
        e = geometric_edges(1.0, 0.01, 1.3, level)
        assert e[0] == 0.0 and e[-1] == 1.0 and np.all(np.diff(e) > 0)
        r = np.diff(e)[1:] / np.diff(e)[:-1]
        assert np.allclose(r, 1.3 ** (1.0 / 2 ** level))
        if level:
            coarse = geometric_edges(1.0, 0.01, 1.3, level - 1)
            assert np.allclose(e[::2], coarse)  # nested: every level halves every cell
    assert np.diff(geometric_edges(1.0, 0.01, 1.3, 0))[0] <= 0.01


@pytest.mark.parametrize("pe", [0.1, 10.0, 1e3, 1e4])
def test_mesh_follows_the_scene_scales(pe):
    kappa, a = 1.4e-5, 1e-3
    v = 2 * kappa * pe / a
    xp = np.linspace(-a, a, 17)
    m0 = moving_frame_mesh(xp, a, v, kappa, 0)
    sc = thermal_scales(a, v, kappa)
    dz = np.diff(m0.z_edges)
    assert dz[0] <= min(sc.thermal_depth, a) / 4.0 * (1 + 1e-12)        # first cell resolves delta
    length = m0.x_edges[-1] - m0.x_edges[0]
    assert m0.z_edges[-1] == pytest.approx(max(6.0 * math.sqrt(kappa * length / v), dz[0] * 4))
    assert m0.x_edges[-1] - a == pytest.approx(max(4 * sc.wake_length, a / 4))   # inflow margin
    assert np.allclose(m0.x_edges[(m0.x_edges >= -a) & (m0.x_edges <= a)], xp)  # patch cells = grid cells
    m1 = moving_frame_mesh(np.linspace(-a, a, 33), a, v, kappa, 1)
    assert np.diff(m1.z_edges)[0] == pytest.approx(dz[0] * (1.3 ** 0.5 - 1) / (1.3 - 1), rel=1e-9)
    assert m1.cells == pytest.approx(4 * m0.cells, rel=0.01)
