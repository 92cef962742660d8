"""Import FiPy safely and solve its linear systems with a checked SciPy solver.

FiPy chooses its solver suite at import from flags in ``sys.argv`` and from ``FIPY_SOLVERS``; railtherm's
own command line must not be read by FiPy, so :func:`import_fipy` sets ``FIPY_SOLVERS=scipy`` and hides
``sys.argv`` during the import (the SciPy suite is the one this plugin is tested with). Linear solves go
through :func:`solve_checked`, which turns a non-converged or non-finite solve into
:class:`railtherm.SolverError`: in 2-D an LU (:func:`_lu_class`) with the minimum-degree ordering of
``A^T + A`` (less fill than FiPy's default COLAMD), in 3-D GMRES (restart 50) with an incomplete-LU
preconditioner (:func:`_ilu_class`), LU for small 3-D meshes. Details: docs/NOTES.md, "FiPy solvers".
"""
from __future__ import annotations

import os
import sys
import threading
import warnings

import numpy as np
from scipy.sparse.linalg import LinearOperator, spilu, splu

from railtherm import SolverError

_lock = threading.Lock()
_fipy = None

#: solver suite this plugin asks FiPy for
SUITE = "scipy"


def import_fipy():
    """Import and return the ``fipy`` module with the SciPy solver suite.

    ``FIPY_SOLVERS`` is set to ``"scipy"`` before the first import and ``sys.argv`` is replaced by
    ``[sys.argv[0]]`` during the import, so that FiPy's command-line parsing never sees railtherm's
    arguments. If FiPy was already imported by someone else, the module is returned as it is and
    its suite is reported by :func:`solver_suite`.

    Returns
    -------
    module
        ``fipy``.
    """
    global _fipy
    if _fipy is not None:
        return _fipy
    with _lock:
        if _fipy is None:
            if "fipy" not in sys.modules:
                os.environ["FIPY_SOLVERS"] = SUITE
            argv = sys.argv
            sys.argv = [argv[0] if argv else "railtherm"]
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", DeprecationWarning)
                    import fipy  # fipy (heavy, reads sys.argv): on first use, shielded here
            finally:
                sys.argv = argv
            _fipy = fipy
    return _fipy


def solver_suite() -> str:
    """Name of the solver suite FiPy loaded (``"scipy"`` unless FiPy was imported elsewhere first)."""
    return str(import_fipy().solvers.solver_suite)


_classes: dict = {}


def _lu_class():
    if "LU" in _classes:
        return _classes["LU"]
    fp = import_fipy()
    base = fp.solvers.scipy.LinearLUSolver

    class LU(base):
        """FiPy's SciPy LU solver with the ``MMD_AT_PLUS_A`` column ordering.

        Same algorithm as ``fipy.solvers.scipy.LinearLUSolver`` (scale by the largest diagonal,
        factorise, iterative refinement until the residual criterion holds) with a fill-reducing
        ordering suited to the nearly pattern-symmetric finite-volume matrices of this plugin, a
        convergence flag that says whether the criterion was met, and re-use of the last
        factorisation when FiPy assembles an identical matrix again (strips of an ellipse that
        differ only in their flux).
        """

        _cache = None
        #: number of LU factorisations computed / re-used by this solver
        factorisations = 0
        reuses = 0

        def _factor(self, L):
            c = self._cache
            if (c is not None and c[0] == L.shape and np.array_equal(c[1], L.indptr)
                    and np.array_equal(c[2], L.indices) and np.array_equal(c[3], L.data)):
                self.reuses += 1
                return c[4]
            lu = lu_factor(L, getattr(self, "order", None))
            self._cache = (L.shape, L.indptr.copy(), L.indices.copy(), L.data.copy(), lu)
            self.factorisations += 1
            return lu

        def _solve_(self, L, x, b):
            diag = L.diagonal()
            maxdiag = float(np.max(np.abs(diag)))
            L = L * (1.0 / maxdiag)
            b = b * (1.0 / maxdiag)
            tolerance_scale, _ = self._adaptTolerance(L, x, b)
            lu = self._factor(L.tocsr())  # noqa: the cached factorisation of the scaled matrix
            residual = np.inf
            iteration = 0
            for iteration in range(min(self.iterations, 10)):
                residual_vector, residual = self._residualVectorAndNorm(L, x, b)
                if residual <= self.tolerance * tolerance_scale:
                    break
                x[:] = x - lu.solve(residual_vector)
            else:
                residual_vector, residual = self._residualVectorAndNorm(L, x, b)
            ok = bool(np.isfinite(residual) and residual <= self.tolerance * tolerance_scale)
            self._setConvergence(suite="scipy", code=0 if ok else 1, iterations=iteration + 1,
                                 residual=residual, tolerance_scale=tolerance_scale)
            self.convergence.warn()
            return x

    _classes["LU"] = LU
    return LU


def _assembler_class():
    if "assembler" in _classes:
        return _classes["assembler"]
    base = _lu_class()

    class Assembler(base):
        """Pseudo-solver that only keeps the linear system FiPy assembled (``self.L``, ``self.b``)."""

        def _solve_(self, L, x, b):
            self.L, self.b = L.tocsr(), np.array(b, dtype=float)
            self._setConvergence(suite="scipy", code=0, iterations=0, residual=0.0)
            return x

    _classes["assembler"] = Assembler
    return Assembler


def assemble(eq, var):
    """The linear system ``A x = b`` FiPy builds for ``eq`` (A as scipy CSR, b as ndarray).

    Uses FiPy's own assembly (``eq.solve`` with a solver that stores the system instead of
    solving it); ``var`` is left unchanged.
    """
    s = _assembler_class()()
    eq.solve(var=var, solver=s)
    return s.L, s.b


class _PermutedLU:
    """LU of ``A[p][:, p]`` that solves systems with ``A`` (the permutation is undone in :meth:`solve`)."""

    def __init__(self, A, order):
        self.p = np.asarray(order)
        A = A.tocsr()
        self.lu = splu(A[self.p][:, self.p].tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=1.0)

    def solve(self, b):
        y = self.lu.solve(np.asarray(b, dtype=float)[self.p])
        x = np.empty_like(y)
        x[self.p] = y
        return x


def lu_factor(A, order=None):
    """Sparse LU of ``A`` (SuperLU, ``MMD_AT_PLUS_A`` column ordering, partial pivoting).

    Parameters
    ----------
    A : scipy.sparse matrix
        Square matrix.
    order : ndarray of int, optional
        Symmetric pre-permutation (new position -> old index) applied before the minimum-degree
        ordering. For the moving-frame meshes, numbering the cells depth-first (z fastest) instead
        of FiPy's x-fastest order leads minimum degree to a factor with 8 % less fill that is
        computed 35 % faster (80 000 cells: 0.51 s instead of 0.82 s on a loaded machine).

    Returns
    -------
    object with ``solve(b)``
    """
    if order is not None:
        return _PermutedLU(A, order)
    return splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=1.0)


def _ilu_class():
    if "ilu" in _classes:
        return _classes["ilu"]
    import_fipy()
    from fipy.solvers.scipy.preconditioners import ILUPreconditioner  # fipy: imported by import_fipy above

    class ILU(ILUPreconditioner):
        """FiPy's ILU preconditioner with a minimum-degree ordering (``MMD_AT_PLUS_A``), drop
        tolerance 1e-3 and fill factor 5.

        SciPy's default COLAMD ordering is poor for these nearly pattern-symmetric matrices. Measured
        on the plugin's 3-D meshes (2 loaded cores): Ertz & Knothe, Pe 6 000, 194 400 cells: ILU
        5.8 s + 57 GMRES iterations with COLAMD (1e-3, 5), 3.4 s + 7 iterations with MMD (default
        FiPy/SciPy settings: 11.4 s + 34 iterations); Pe 0.1, 121 600 cells: 13 s in total
        (227 iterations) against 50 s with COLAMD (1e-5, 20).
        """

        def _applyToMatrix(self, matrix):
            ilu = spilu(matrix.tocsc(), drop_tol=1e-3, fill_factor=5, permc_spec="MMD_AT_PLUS_A")
            return LinearOperator(matrix.shape, ilu.solve), matrix

    _classes["ilu"] = ILU
    return ILU


def _gmres_class():
    if "gmres" in _classes:
        return _classes["gmres"]
    fp = import_fipy()

    class GMRES(fp.solvers.scipy.LinearGMRESSolver):
        """FiPy's SciPy GMRES with a restart length of 50 (SciPy's default 20 stalls at low Péclet)."""

        def _doSolve(self, *args, **kwargs):
            return self.solveFnc(*args, **kwargs, restart=50, callback_type="pr_norm")

    _classes["gmres"] = GMRES
    return GMRES


def make_solver(kind: str, tolerance: float | None = None, iterations: int | None = None):
    """A FiPy solver object.

    Parameters
    ----------
    kind : {"lu", "gmres"}
        ``"lu"``: :class:`LU` (direct, for 2-D); ``"gmres"``: GMRES with ILU preconditioning (3-D).
    tolerance : float, optional
        Relative residual tolerance ``||A x - b|| / ||b||`` [1] (default 1e-10 for LU, 1e-9 for GMRES).
    iterations : int, optional
        Maximum iterations (LU refinement steps are capped at 10 by FiPy's algorithm).
    """
    fp = import_fipy()
    if kind == "lu":
        return _lu_class()(tolerance=tolerance or 1e-10, iterations=iterations or 10, criterion="RHS")
    if kind == "gmres":
        return _gmres_class()(tolerance=tolerance or 1e-9, iterations=iterations or 100,
                              criterion="RHS", precon=_ilu_class()())
    raise ValueError(f"unknown solver kind {kind!r}: 'lu' or 'gmres'")


def solve_checked(eq, var, solver, what: str = "FiPy solve", dt: float | None = None) -> dict:
    """Solve ``eq`` for ``var`` with ``solver``; raise :class:`railtherm.SolverError` unless converged.

    Parameters
    ----------
    eq : fipy term
        The equation (``... == 0``), freshly built (FiPy issue #1223: a cached convection stencil
        is not rebuilt when coefficients change, so never re-use an equation after changing them).
    var : fipy.CellVariable
        Unknown; overwritten with the solution.
    solver : fipy solver
        From :func:`make_solver`.
    what : str
        Names the solve in the error message.
    dt : float, optional
        Time step [s] for equations with a ``TransientTerm``.

    Returns
    -------
    dict
        ``iterations``, ``residual`` (relative to ``||b||``), ``converged`` (True), ``solver``.
    """
    eq.cacheMatrix()
    eq.cacheRHSvector()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # FiPy warns on non-convergence; we raise instead
        eq.solve(var=var, solver=solver, dt=dt)
    conv = solver.convergence
    status = int(getattr(conv, "status_code", 0) or 0)
    iterations = int(getattr(conv, "iterations", 0) or 0)
    x = np.asarray(var.value, dtype=float)
    A = eq.matrix.matrix
    b = np.asarray(eq.RHSvector, dtype=float)
    bnorm = float(np.linalg.norm(b))
    rel = float(np.linalg.norm(A @ x - b)) / (bnorm if bnorm > 0 else 1.0)
    finite = bool(np.all(np.isfinite(x)))
    if status != 0 or not finite or not np.isfinite(rel) or rel > 10 * solver.tolerance:
        raise SolverError(f"{what}: {type(solver).__name__} did not converge (status "
                          f"{getattr(conv, 'status_name', status)}, iterations {iterations}, relative residual "
                          f"{rel:.3g} > tolerance {solver.tolerance:g}, finite solution: {finite})")
    return {"iterations": iterations, "residual": rel, "converged": True, "solver": type(solver).__name__}
