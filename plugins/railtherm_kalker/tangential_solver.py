"""Steady rolling with creepage on a given normal pressure: Kalker's exact theory, semismooth Newton.

Unknowns are the tangential tractions p = (p_x, p_y) on body 1 (the wheel) per element of the
potential contact area (zero outside the contact, where the pressure is zero). In the frame of the
contact the material flows in -x (enters at the leading edge +x), so the slip of body 1 relative to
body 2 per unit rolling distance is (Kalker)::

    s = w - d u / d x,     w = (xi - phi y, eta + phi x)

with the rigid slip w of the creepages (xi, eta [1], spin phi [1/m]) and the tangential displacement
difference u = A p (Boussinesq-Cerruti, :mod:`railtherm_kalker.influence`). The derivative is the
steady-state discretisation of CONTACT, the upwind difference (u(x + dx) - u(x)) / dx, so
``s = w - B p`` with the Toeplitz "rolling" influence operator B (one FFT product per evaluation).
Coulomb's law holds element by element: |p| <= g = mu p_n; where |p| < g the element sticks (s = 0);
where it slips, p = -g s / |s|. A positive creepage thus gives a negative force on the wheel
(CONTACT's and :mod:`railtherm.references.kalker`'s sign law).

Solver
------
The law is the fixed point ``p = Proj_g(p - r s(p))`` (projection of each element's traction on the
disc of radius g; r > 0 a scaling, here 1/|B_xx(0)|). Semismooth Newton on
``F(p) = p - Proj_g(p - r s(p)) = 0``: the generalised Jacobian of a sticking element's row is r B,
that of a slipping element ``I - (g/|z|)(I - z z^T/|z|^2)(I + r B)`` (z = p - r s), so each Newton
step is one non-symmetric linear system, solved by GMRES with FFT products in single precision
(inexact Newton: the step only needs a relative accuracy of ~1e-2..1e-4; the residual F itself is
always evaluated in double precision). A backtracking line search on |F| safeguards the first steps.
Starting from zero traction it converges in about 10 Newton steps; diagnostics record the residual
history ``max |F| / max g``.

References
----------
.. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990, ch. 2 and 5.
   doi:10.1007/978-94-015-7889-9
.. [2] E.A.H. Vollebregt, User guide for CONTACT, Vollebregt's rolling and sliding contact model,
   technical report TR09-03 (steady rolling, slip discretisation).
.. [3] P. Alart, A. Curnier, A mixed formulation for frictional contact problems prone to Newton like
   solution methods, Comput. Methods Appl. Mech. Eng. 92 (1991) 353-375.
   doi:10.1016/0045-7825(91)90022-X
.. [4] S. Hueeber, G. Stadler, B.I. Wohlmuth, A primal-dual active set algorithm for three-dimensional
   contact problems with Coulomb friction, SIAM J. Sci. Comput. 30 (2008) 572-596.
   doi:10.1137/060671061
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.linalg import LinearOperator, gmres

__all__ = ["TangentialSolution", "solve_tangential", "solve_tangential_nested", "rigid_slip", "TANGENTIAL_TOLERANCE"]

#: smallest step of the line search (1: plain semismooth Newton)
LINE_SEARCH_MIN = 1.0

#: forcing terms of the inexact Newton steps: GMRES stops at the relative residual
#: min(FORCING_MAX, FORCING |F|)
FORCING, FORCING_MAX = 0.05, 0.1

#: default tolerance on the relative residual max |F| / max(mu p_n)
TANGENTIAL_TOLERANCE = 1e-10


@dataclass
class TangentialSolution:
    """Result of :func:`solve_tangential`.

    Attributes
    ----------
    traction : ndarray (ncomp, nx, ny)
        Tangential traction on body 1 [Pa] (ncomp = 1 for a line contact).
    slip : ndarray (ncomp, nx, ny)
        Slip of body 1 relative to body 2 per unit rolling distance s = w - B p [1] (zero outside
        the contact).
    stick : ndarray (nx, ny) of bool
        Sticking elements (|p| < g in the contact).
    converged : bool
    iterations : int
        Newton steps [1].
    residual : float
        max |F| / max g [1].
    history : list of float
        Residual after each Newton step (the first entry is that of zero traction).
    linear_iterations : int
        GMRES iterations summed over the Newton steps [1].
    products : int
        FFT products of the rolling operator [1].
    """

    traction: np.ndarray
    slip: np.ndarray
    stick: np.ndarray
    converged: bool
    iterations: int
    residual: float
    history: list = field(default_factory=list)
    linear_iterations: int = 0
    products: int = 0


def rigid_slip(X, Y, xi: float, eta: float, phi: float, line: bool = False) -> np.ndarray:
    """Rigid slip w = (xi - phi y, eta + phi x) per unit rolling distance [1], shape (ncomp, nx, ny).

    Parameters
    ----------
    X, Y : ndarray (nx, ny)
        Element centres [m].
    xi, eta : float
        Longitudinal and lateral creepage [1].
    phi : float
        Spin creepage [1/m].
    line : bool
        A line contact (one component, xi only).
    """
    if line:
        return np.full((1,) + np.shape(X), float(xi))
    return np.stack([xi - phi * Y, eta + phi * X]).astype(float)


def _project(z, g):
    """Project each element's traction z (ncomp, ...) on the disc of radius g; returns (proj, |z|)."""
    nz = np.sqrt(np.sum(z * z, axis=0))
    scale = np.where(nz > g, g / np.where(nz > 0, nz, 1.0), 1.0)
    return z * scale, nz


def solve_tangential(conv, bound: np.ndarray, w: np.ndarray, *, tol: float = TANGENTIAL_TOLERANCE,
                     maxiter: int = 60, initial: np.ndarray | None = None, rscale: float = 1.0) -> TangentialSolution:
    """Solve Kalker's steady rolling problem with semismooth Newton-GMRES.

    Parameters
    ----------
    conv : railtherm_kalker.influence.Convolution
        Rolling influence operator B (kernels ``(A[k+1] - A[k]) / dx``, see
        :func:`railtherm_kalker.influence.rolling_kernel`) [1/Pa].
    bound : ndarray (nx, ny)
        Traction bound g = mu p_n per element [Pa]; elements with g <= 0 are outside the contact.
    w : ndarray (ncomp, nx, ny)
        Rigid slip [1] (:func:`rigid_slip`).
    tol : float
        Stop when max |F| <= tol max g [1].
    maxiter : int
        Newton step limit [1].
    initial : ndarray (ncomp, nx, ny), optional
        Initial traction [Pa] (default zero).

    Returns
    -------
    TangentialSolution
    """
    g = np.asarray(bound, dtype=float)
    w = np.asarray(w, dtype=float)
    nc = w.shape[0]
    inside = g > 0
    gmax = float(g.max()) if inside.any() else 1.0
    idx = np.nonzero(inside.ravel())[0]
    nin = idx.size
    full_shape = w.shape
    n0 = conv.products
    r = rscale / abs(float(conv.self_coefficient))     # inverse of the self-influence |B_xx(0)|

    def slip_of(p, single=False):
        return w - conv.apply(p, single=single)

    def embed(v):
        out = np.zeros((nc, g.size), dtype=v.dtype)
        out[:, idx] = v.reshape(nc, nin)
        return out.reshape(full_shape)

    def restrict(a):
        return a.reshape(nc, -1)[:, idx]

    gin = g.ravel()[idx]
    p = np.zeros(full_shape) if initial is None else np.where(inside, np.asarray(initial, dtype=float), 0.0)
    s = slip_of(p)

    def residual_of(p, s):
        z = restrict(p) - r * restrict(s)
        proj, nz = _project(z, gin)
        return restrict(p) - proj, z, nz

    F, z, nz = residual_of(p, s)
    # no element can carry traction (friction 0, or no contact): the zero traction is exact
    res = float(np.max(np.sqrt(np.sum(F * F, axis=0)))) / gmax if nin else 0.0
    history = [res]
    lin_total = 0
    converged = res <= tol
    it = 0
    while not converged and it < maxiter:
        it += 1
        slipping = nz > gin
        zh = np.where(slipping, z / np.where(nz > 0, nz, 1.0), 0.0)        # unit z on slipping elements
        fac = np.where(slipping, gin / np.where(nz > 0, nz, 1.0), 0.0)    # g/|z|

        def jac(v):
            v = v.reshape(nc, nin)
            bv = restrict(conv.apply(embed(v.astype(np.float32)), single=True)).astype(float)
            stick_row = -r * bv                                          # F = r s, s = w - B p
            q = v + r * bv                                               # (I + r B) v
            proj_q = q - zh * np.sum(zh * q, axis=0)                     # (I - zz^T) q
            slip_row = v - fac * proj_q
            return np.where(slipping, slip_row, stick_row).ravel()

        # Newton: J d = -F, with J = -r B (stick) / I - fac P (I + r B) (slip)
        op = LinearOperator((nc * nin, nc * nin), matvec=jac, dtype=float)
        eta_k = min(FORCING_MAX, max(1e-8, FORCING * res))
        counter = [0]

        def cb(_):
            counter[0] += 1

        d, info = gmres(op, -F.ravel(), rtol=eta_k, restart=60, maxiter=4, callback=cb,
                        callback_type="pr_norm")
        lin_total += counter[0]
        d = d.reshape(nc, nin)
        # line search on max |F|
        step = 1.0
        for _ in range(8):
            p_try = p + step * embed(d)
            s_try = slip_of(p_try)
            F_try, z_try, nz_try = residual_of(p_try, s_try)
            res_try = float(np.max(np.sqrt(np.sum(F_try * F_try, axis=0)))) / gmax
            if res_try < res or step < 0.9 * LINE_SEARCH_MIN:
                break
            step *= 0.5
        p, s, F, z, nz, res = p_try, s_try, F_try, z_try, nz_try, res_try
        history.append(res)
        converged = res <= tol
    stick = np.zeros(g.shape, dtype=bool)
    stick.ravel()[idx] = nz <= gin
    # tractions exactly on the bound where slipping; zero slip outside the contact
    s_out = np.where(inside[None], s, 0.0)
    return TangentialSolution(traction=p, slip=s_out, stick=stick, converged=converged, iterations=it,
                              residual=res, history=history, linear_iterations=lin_total,
                              products=conv.products - n0)


def _coarsen(a: np.ndarray, line: bool) -> np.ndarray:
    """Average over blocks of 2 x 2 elements (2 x 1 for a line contact); last two axes (nx, ny)."""
    nx, ny = a.shape[-2:]
    if line:
        return 0.5 * (a[..., 0::2, :] + a[..., 1::2, :])
    return 0.25 * (a[..., 0::2, 0::2] + a[..., 1::2, 0::2] + a[..., 0::2, 1::2] + a[..., 1::2, 1::2])


def _refine(a: np.ndarray, line: bool) -> np.ndarray:
    """Piecewise-constant prolongation of a coarse field to the elements twice as fine."""
    a = np.repeat(a, 2, axis=-2)
    return a if line else np.repeat(a, 2, axis=-1)


def solve_tangential_nested(conv_for, x_edges, y_edges, bound, creepage, *, min_elements: int = 12,
                            tol: float = TANGENTIAL_TOLERANCE, maxiter: int = 60) -> TangentialSolution:
    """Nested iteration: solve on grids of 2, 4, ... times larger elements first, starting from zero
    traction on the coarsest, and start each finer solve from the coarser solution.

    The coarse problems cover the same potential contact area (elements merged 2 x 2; pressure and
    traction bound averaged over the merged elements, rigid slip at the coarse centres). Only the
    finest solve's tolerance matters: the coarse ones give its initial traction (projected on the
    fine traction bound), which leaves it a few Newton steps to adjust the stick/slip boundary.

    Parameters
    ----------
    conv_for : callable
        ``conv_for(x_edges, y_edges) -> Convolution`` of the rolling operator B on that grid.
    x_edges, y_edges : ndarray
        Element edges [m] (y_edges None for a line contact).
    bound : ndarray (nx, ny)
        Traction bound mu p_n [Pa].
    creepage : (float, float, float)
        xi [1], eta [1], phi [1/m].
    min_elements : int
        Stop coarsening when a side would have fewer elements than this [1].
    tol, maxiter
        As :func:`solve_tangential` (finest grid).

    Returns
    -------
    TangentialSolution
        Of the finest grid; ``iterations`` and ``history`` are the finest solve's, ``products`` and
        ``linear_iterations`` are summed over all grids, ``coarse`` (attribute set on the result)
        lists the coarse solves' (shape, Newton steps).
    """
    line = y_edges is None
    levels = [(np.asarray(x_edges, dtype=float), None if line else np.asarray(y_edges, dtype=float),
               np.asarray(bound, dtype=float))]
    while True:
        xe, ye, g = levels[-1]
        nx, ny = g.shape
        can = nx % 2 == 0 and nx // 2 >= min_elements and (line or (ny % 2 == 0 and ny // 2 >= min_elements))
        if not can:
            break
        levels.append((xe[::2], None if line else ye[::2], _coarsen(g, line)))
    p = None
    coarse = []
    products = linear = 0
    sol = None
    for k in range(len(levels) - 1, -1, -1):
        xe, ye, g = levels[k]
        xc = 0.5 * (xe[1:] + xe[:-1])
        if line:
            X, Y = xc[:, None], np.zeros((xc.size, 1))
        else:
            X, Y = np.meshgrid(xc, 0.5 * (ye[1:] + ye[:-1]), indexing="ij")
        w = rigid_slip(X, Y, *creepage, line=line)
        conv = conv_for(xe, ye)
        init = None
        if p is not None:
            init, _ = _project(_refine(p, line), g)
        last = k == 0
        sol = solve_tangential(conv, g, w, tol=tol if last else max(tol, 1e-6), maxiter=maxiter, initial=init)
        products += sol.products
        linear += sol.linear_iterations
        if not last:
            coarse.append((g.shape, sol.iterations))
        p = sol.traction
    sol.products = products
    sol.linear_iterations = linear
    sol.coarse = coarse
    return sol
