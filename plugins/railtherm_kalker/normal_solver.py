"""The normal contact problem on the potential contact area: Polonsky & Keer's conjugate gradients.

Find the pressure p >= 0 per element and the approach delta such that the deformed gap
``e = h + A p - delta`` is >= 0, zero where p > 0 (complementarity), with the total force
``sum p dA = N`` prescribed (or delta prescribed). A is Love's influence matrix
(:func:`railtherm_kalker.influence.normal_kernel`), applied by FFT.

The iteration is Polonsky & Keer's (1999) constrained conjugate gradients: CG on the current
contact set with the mean gap as the approach estimate, projection on p >= 0, re-entry of elements
that penetrate (which restarts the conjugate directions), and rescaling to the prescribed force. It
converges from a uniform pressure in a few tens of iterations, each with one or two FFT products
(the displacement is updated from the search direction's when the contact set did not change).

References
----------
.. [1] I.A. Polonsky, L.M. Keer, A numerical method for solving rough contact problems based on the
   multi-level multi-summation and conjugate gradient techniques, Wear 231 (1999) 206-219.
   doi:10.1016/S0043-1648(99)00113-1
.. [2] E.A.H. Vollebregt, A new solver for the elastic normal contact problem using conjugate
   gradients, deflation, and an FFT-based preconditioner, J. Comput. Phys. 257 (2014) 333-351.
   doi:10.1016/j.jcp.2013.10.005
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

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


def solve_normal(conv, gap: np.ndarray, cell_area: float, *, force: float | None = None,
                 approach: float | None = None, initial: np.ndarray | None = None, tol: float = NORMAL_TOLERANCE,
                 maxiter: int = 500) -> NormalSolution:
    """Solve the normal contact problem with Polonsky & Keer's constrained conjugate gradients.

    Parameters
    ----------
    conv : railtherm_kalker.influence.Convolution
        Love's influence operator (one component) on the element grid [m/Pa].
    gap : ndarray (nx, ny)
        Undeformed gap h at the element centres [m].
    cell_area : float
        Element area [m^2] (element length [m] for a line contact).
    force : float, optional
        Prescribed normal force N [N] ([N/m] for a line contact).
    approach : float, optional
        Prescribed approach delta [m] (instead of the force).
    initial : ndarray (nx, ny), optional
        Initial pressure [Pa] (e.g. the Hertz pressure of the gap's quadratic part); default a
        uniform pressure (force prescribed) or a unit pressure on the geometric overlap.
    tol : float
        Stop when the relative pressure change and the complementarity residual are below tol [1].
    maxiter : int
        Iteration limit [1].

    Returns
    -------
    NormalSolution
    """
    if (force is None) == (approach is None):
        raise ValueError("give exactly one of force [N] and approach [m]")
    h = np.asarray(gap, dtype=float)
    shape = h.shape

    def A(v):
        return conv.apply(v[None])[0]

    n0 = conv.products
    if initial is not None and np.any(np.asarray(initial) > 0):
        p = np.clip(np.asarray(initial, dtype=float).reshape(shape), 0.0, None)
        if force is not None:
            p = p * (force / (float(p.sum()) * cell_area))
    elif force is not None:
        p = np.full(shape, force / (cell_area * h.size))
    else:
        p = np.where(h < approach, 1.0, 0.0)   # unit pressure on the geometric overlap
    u = A(p)
    t = np.zeros(shape)
    g_old, restart = 1.0, True
    history = []
    converged = False
    it = 0
    res = np.inf
    for it in range(1, maxiter + 1):
        contact = p > 0
        if not contact.any():
            contact = h <= h.min()
        e = h + u
        if force is not None:
            e = e - e[contact].mean()
        else:
            e = e - approach
        G = float(np.sum(e[contact] ** 2))
        if restart:
            t = np.where(contact, e, 0.0)
        else:
            t = np.where(contact, e + (G / g_old) * t, 0.0)
        g_old = G
        r = A(t)
        rc = r - r[contact].mean() if force is not None else r
        den = float(np.sum(rc[contact] * t[contact]))
        tau = float(np.sum(e[contact] * t[contact])) / den if den != 0.0 else 0.0
        p_old = p
        p = p - tau * t
        clipped = p < 0.0
        p = np.where(clipped, 0.0, p)
        overlap = (p == 0.0) & (e < 0.0) & ~contact
        restart = bool(overlap.any())
        if restart:
            p = np.where(overlap, p - tau * e, p)
        if force is not None:
            total = float(p.sum()) * cell_area
            scale = force / total if total > 0 else 1.0
            p = p * scale
        else:
            scale = 1.0
        # displacement: incremental when nothing was clipped or re-entered (exact), else recomputed
        if restart or bool((clipped & contact).any()):
            u = A(p)
        else:
            u = scale * (u - tau * r)
        change = float(np.sum(np.abs(p - p_old))) / max(float(np.sum(np.abs(p))), 1e-300)
        history.append(change)
        if change < tol:
            u = A(p)
            e = h + u
            contact = p > 0
            delta = float(e[contact].mean()) if force is not None else float(approach)
            res = _complementarity(p, e - delta, u)
            if res < max(tol, 1e-12) * 10.0 or change == 0.0:
                converged = True
                break
    e = h + u
    contact = p > 0
    delta = float(e[contact].mean()) if (force is not None and contact.any()) else float(approach or 0.0)
    res = _complementarity(p, e - delta, u)
    return NormalSolution(pressure=p, approach=delta, displacement=u, force=float(p.sum()) * cell_area,
                          converged=converged, iterations=it, residual=res, history=history,
                          products=conv.products - n0)
