"""The normal contact problem on the potential contact area: FFT-preconditioned conjugate gradients.

Find the pressure p >= 0 per element and the approach delta such that the deformed gap ``e = h + A p - delta`` is
>= 0, zero where p > 0, with the force ``sum p dA = N`` (or delta) prescribed; A is Love's influence matrix
(:func:`railtherm_kalker.influence.normal_kernel`), applied by FFT. The iteration is Vollebregt's active-set CG
(CONTACT's NormCG): the constant vector deflated when the force is prescribed, Polak-Ribiere's beta >= 0 (so
active-set changes need no restart), elements with p < 0 moved out and penetrating ones in after every step. The
inverse of A's Strang circulant on the periodic element grid (:meth:`railtherm_kalker.influence.Convolution.precondition`)
preconditions it, making the iteration count almost independent of the grid (docs/kalker.md, "Normal stage").

References
----------
.. [1] E.A.H. Vollebregt, A new solver for the elastic normal contact problem using conjugate gradients, deflation,
   and an FFT-based preconditioner, J. Comput. Phys. 257 (2014) 333-351. doi:10.1016/j.jcp.2013.10.005
.. [2] I.A. Polonsky, L.M. Keer, Wear 231 (1999) 206-219 (CG for rough contact). doi:10.1016/S0043-1648(99)00113-1
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import _cg, _fold

__all__ = ["NormalSolution", "solve_normal", "NORMAL_TOLERANCE"]

#: default tolerance on the relative complementarity residual (see :class:`NormalSolution`)
NORMAL_TOLERANCE = 1e-10


@dataclass
class NormalSolution:
    """Result of :func:`solve_normal`.

    Attributes
    ----------
    pressure : ndarray (nx, ny)
        Element pressures [Pa].
    approach : float
        Approach delta [m] (in 2-D relative to the kernel's logarithm unit).
    displacement : ndarray (nx, ny)
        Normal displacement difference A p [m].
    force : float
        Sum p dA [N] ([N/m] for a line contact).
    converged : bool
    iterations : int
        CG iterations [1].
    residual : float
        Relative complementarity residual: max over the elements of |e| where p > 0 and of max(-e, 0)
        elsewhere, divided by max |A p| [1].
    history : list of float
        Residual after each iteration (the relative pressure change ``sum |p - p_old| / sum p``).
    products : int
        FFT convolution products [1].
    """

    pressure: np.ndarray
    approach: float
    displacement: np.ndarray
    force: float
    converged: bool
    iterations: int
    residual: float
    history: list = field(default_factory=list)
    products: int = 0


def _complementarity(p, e, u) -> float:
    scale = float(np.max(np.abs(u))) or 1.0
    inside = p > 0
    r1 = float(np.max(np.abs(e[inside]))) if inside.any() else 0.0
    r2 = float(np.max(np.clip(-e[~inside], 0.0, None))) if (~inside).any() else 0.0
    return max(r1, r2) / scale


def _initial_pressure(h, cell_area, force, approach, initial):
    """Starting pressure [Pa]: the given one (scaled to the force), uniform, or unit on the overlap."""
    if initial is not None and np.any(np.asarray(initial) > 0):
        p = np.clip(np.asarray(initial, dtype=float).reshape(h.shape), 0.0, None)
        return p * (force / (float(p.sum()) * cell_area)) if force is not None else p
    if force is not None:
        return np.full(h.shape, force / (cell_area * h.size))
    return np.where(h < approach, 1.0, 0.0)


# over 80 lines with its docstring: one loop whose state (p, u, the contact set, the direction) every step
# shares, and the dispatch of a symmetric gap to the same loop on one quadrant; the element-wise work is in ._cg
def solve_normal(conv, gap: np.ndarray, cell_area: float, *, force: float | None = None,
                 approach: float | None = None, initial: np.ndarray | None = None,
                 tol: float = NORMAL_TOLERANCE, maxiter: int = 500, precondition: bool = True,
                 fold: bool = True) -> NormalSolution:
    """Solve the normal contact problem by active-set preconditioned conjugate gradients.

    Parameters
    ----------
    conv : railtherm_kalker.influence.Convolution
        Normal influence operator (one component) [m/Pa]; with a circulant
        (:func:`railtherm_kalker.influence.normal_operator`) for the preconditioner.
    gap : ndarray (nx, ny)
        Undeformed gap h at the element centres [m].
    cell_area : float
        Element area [m^2] ([m] for a line contact).
    force : float, optional
        Prescribed total force [N] ([N/m] for a line contact).
    approach : float, optional
        Prescribed approach delta [m] (exactly one of force and approach).
    initial : ndarray (nx, ny), optional
        Initial pressure (e.g. Hertz's) [Pa].
    tol : float
        Stop when the relative pressure update ``sum |p - p_old| / sum p`` and the complementarity
        residual are below tol [1].
    maxiter : int
        Iteration limit [1].
    precondition : bool
        Use the circulant preconditioner when the operator has one (False: plain CG, for comparison).
    fold : bool
        Solve a gap symmetric in x and y (and a symmetric initial pressure) on one quadrant when the operator
        allows it (:func:`railtherm_kalker._fold.folded_operator`; False: always the whole grid).

    Returns
    -------
    NormalSolution
    """
    if (force is None) == (approach is None):
        raise ValueError("give exactly one of force [N] and approach [m]")
    h = np.asarray(gap, dtype=float)
    folded = _fold.folded_operator(conv, h, initial) if fold else None
    if folded is not None:      # a gap symmetric in x and y: the same iteration on one quadrant (:mod:`._fold`)
        q = solve_normal(folded, _fold.fold(h), 4.0 * cell_area, force=force, approach=approach,
                         initial=_fold.fold(initial), tol=tol, maxiter=maxiter, precondition=precondition, fold=False)
        p = _fold.unfold(q.pressure)
        return NormalSolution(pressure=p, approach=q.approach, displacement=_fold.unfold(q.displacement),
                              force=float(p.sum()) * cell_area, converged=q.converged, iterations=q.iterations,
                              residual=q.residual, history=q.history, products=q.products)
    use_m = precondition and getattr(conv, "_inverse32", None) is not None

    def A(v):
        return conv.apply(v.reshape((1,) + h.shape))[0].ravel()

    n0 = conv.products
    fm = force is not None
    a0 = 0.0 if fm else float(approach)
    shape = h.shape
    h = np.ascontiguousarray(h).ravel()
    p = np.ascontiguousarray(_initial_pressure(h.reshape(shape), cell_area, force, approach, initial), dtype=float).ravel()
    u = A(p)
    C = p > 0
    if not C.any():
        C = h <= h.min()
    v, r, r_prev = np.zeros_like(h), np.zeros_like(h), np.zeros_like(h)
    rz_old = 0.0
    history, converged, it, res = [], False, 0, np.inf
    # one FFT product, one preconditioner application and four fused element-wise passes (:mod:`._cg`) per step
    for it in range(1, maxiter + 1):
        _cg.residual(h, u, C, fm, a0, r)                     # residual of A_CC p = delta - h (mean-free)
        z = np.ascontiguousarray(conv.precondition(r.reshape(shape)).ravel()) if use_m else r.copy()
        rz = _cg.direction(z, r, r_prev, v, C, fm, rz_old, it == 1)
        q = A(v)
        alpha, change, nneg = _cg.step(q, v, r, C, fm, p, u)
        r, r_prev, rz_old = r_prev, r, rz
        # active set: negative pressures leave (force rescaled), penetrating exterior elements enter
        changed = nneg > 0
        if changed:
            neg = C & (p < 0.0)
            p[neg] = 0.0
            if fm:
                total = float(p.sum()) * cell_area
                p = p * (force / total) if total > 0 else np.where(h <= h.min(), 1.0, 0.0)
            u = A(p)
            C = C & ~neg
            if not C.any():
                C = h <= h.min()
        delta, nnew = _cg.enter(h, u, C, fm, a0)
        changed = changed or nnew > 0
        history.append(change)
        if not changed and change < tol:
            res = _complementarity(p, h + u - delta, u)
            if res < max(tol, 1e-12) * 10.0 or change == 0.0:
                converged = True
                break
    # u is A p: updated with every step's product, recomputed after every change of the active set
    e = h + u
    contact = p > 0
    delta = float(e[contact].mean()) if (fm and contact.any()) else float(approach or 0.0)
    res = _complementarity(p, e - delta, u)
    p, u = p.reshape(shape), u.reshape(shape)
    return NormalSolution(pressure=p, approach=delta, displacement=u, force=float(p.sum()) * cell_area,
                          converged=converged, iterations=it, residual=res, history=history,
                          products=conv.products - n0)
