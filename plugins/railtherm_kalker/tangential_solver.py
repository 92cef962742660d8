"""Steady rolling with creepage on a given normal pressure: Kalker's exact theory, semismooth Newton.

Unknowns: the tractions p = (p_x, p_y) on body 1 (the wheel) per element of the potential contact area. The
material enters at the leading edge +x, so the slip of body 1 relative to body 2 per unit rolling distance is
``s = w - du/dx = w - B p``: rigid slip ``w = (xi - phi y, eta + phi x)`` (creepages xi, eta [1], spin phi [1/m]),
u = A p (Boussinesq-Cerruti), B the upwind "rolling" operator (:func:`railtherm_kalker.influence.rolling_kernel`).
Coulomb's law per element: |p| <= g = mu p_n, s = 0 where |p| < g, p = -g s/|s| in slip, so a positive creepage
gives a negative force on the wheel (CONTACT's and :mod:`railtherm.references.kalker`'s sign law). Semismooth
Newton-GMRES (:func:`solve_tangential`) on nested grids (:func:`solve_tangential_nested`); costs in docs/kalker.md.

References
----------
.. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990, ch. 2, 5. doi:10.1007/978-94-015-7889-9
.. [2] E.A.H. Vollebregt, User guide for CONTACT, technical report TR09-03 (steady rolling, slip discretisation).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._band import LinePreconditioner
from ._gmres import gmres_single_then_double
from ._sweep import _inverse_blocks, _sweep_nb, newton_blocks, sweep

__all__ = ["TangentialSolution", "solve_tangential", "solve_tangential_nested", "rigid_slip", "TANGENTIAL_TOLERANCE"]

#: smallest step of the line search (1: plain semismooth Newton)
LINE_SEARCH_MIN = 1.0

#: forcing terms of the inexact Newton steps: GMRES stops at the relative residual
#: min(FORCING_MAX, FORCING |F|). The first Newton steps from a prolonged coarse solution only move the
#: stick/slip boundary, for which a loose linear solve suffices: FORCING_MAX 0.5 took 137/143 and 212/199 FFT
#: products (combined/longitudinal creepage, E&K ellipse, 100^2 and 200^2) against 149/189 and 233/282 at 0.1
FORCING, FORCING_MAX = 0.05, 0.5

#: smallest GMRES tolerance, GMRES step limit per Newton step, and the tolerance below which the
#: products and the Krylov basis are in double precision. A float32 product's error (about 1e-7 of the product)
#: bounds what GMRES can reach; the last Newton step's tolerance at the default 1e-10 is 5e-6 - 2e-5 (FINAL_MARGIN),
#: reached in float32 in as many GMRES steps as in float64 (E&K ellipse, 100^2 and 200^2: the same steps, creep
#: forces to 1e-12, 18-25 % less time of the tangential stage than with double precision below 1e-4). The Newton
#: residual is always evaluated in double precision, so the converged traction does not depend on this choice
LINEAR_MIN, LINEAR_MAXITER, SINGLE_BELOW = 1e-8, 200, 2e-6

#: a step whose forcing term would reach the tolerance stops at FINAL_MARGIN tol / res instead (the relative
#: residual of the linearised system predicts the next max |F| to within a factor 2 once the stick/slip division
#: is settled); 0.3 took 203/189 FFT products (combined/longitudinal creepage, E&K ellipse, 200^2) against
#: 212/199 at 0.1
FINAL_MARGIN = 0.3

#: a good start (``good_start``: the full-slip traction beyond saturation, which already has the final slip
#: area) takes its first Newton step with the forcing term GOOD_START_FORCING res instead of FORCING_MAX (full
#: slip, E&K ellipse, 200^2: 2 Newton steps and 10 FFT products against 4 and 13). Not for the prolonged coarse
#: solutions, whose stick/slip boundary still moves (at 400^2 they start at res 0.05 and need 8-9 Newton steps).
GOOD_START_FORCING = 3.0

#: Eisenstat-Walker's gamma (forcing choice 2, exponent 2)
EW_GAMMA = 0.9

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
        Residual after each Newton step (the first entry is that of the initial traction: zero, or in
        :func:`solve_tangential_nested` the coarser grid's solution).
    linear_iterations : int
        GMRES iterations summed over the Newton steps [1].
    products : int
        FFT products of the rolling operator [1].
    mirrored : bool
        Solved on the half y >= 0 of a problem symmetric about the grid's centre line along x (:func:`_y_mirror`).
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
    mirrored: bool = False


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


class LocalPreconditioner:
    """Exact inverse of the Newton Jacobian with the rolling operator B cut to its upwind pair of offsets.

    The rolling kernel ``(A[k + 1] - A[k]) / dx`` is dominated by the offsets 0 and -1 along x (the
    upwind difference of the self-influence, +-2.0 |B(0)| against +-0.5 for the next pair and less
    across), and it is antisymmetric about the offset -1/2. The Jacobian ``D1 + D2 B`` with B cut to
    that balanced pair is block upper triangular along x: element (i, j) couples only to itself and to
    its upstream neighbour (i + 1, j). Its inverse is a backward sweep from the leading edge (FASTSIM's
    integration along the rolling direction, with 2 x 2 blocks per element), O(N) per application.
    (Wider stencils were tried: an unbalanced cut of the antisymmetric kernel, e.g. adding the offsets
    -2 or (-1, +-1) alone, makes GMRES slower.)

    Parameters
    ----------
    conv : railtherm_kalker.influence.Convolution
        The rolling operator (its :attr:`near` kernels are used).
    idx : ndarray
        Flat indices of the unknown elements in the (nx, ny) grid.
    """

    def __init__(self, conv, idx):
        nx, ny = conv.shape
        self.nc = nc = conv.ncomp
        rx, ry = conv.near_radius
        pos = np.full(nx * ny, -1, dtype=np.int64)
        pos[idx] = np.arange(idx.size)
        pos = pos.reshape(nx, ny)
        i, j = np.unravel_index(idx, (nx, ny))
        nb = np.full(idx.size, -1, dtype=np.int64)
        ok = i + 1 < nx
        nb[ok] = pos[i[ok] + 1, j[ok]]
        self.nb = nb
        # sweep order: descending x (the leading edge first), j ascending within a grid column. idx is sorted
        # (row-major), so each column i is a contiguous run: the runs in reverse order (O(N), no sort)
        counts = np.bincount(i, minlength=nx)
        start = np.concatenate([[0], np.cumsum(counts)[:-1]])            # first position of column i in idx
        after = np.concatenate([np.cumsum(counts[::-1])[::-1][1:], [0]])  # elements in the columns beyond i
        order = np.empty(idx.size, dtype=np.int64)
        k = np.arange(idx.size)
        order[after[i] + k - start[i]] = k
        self.order = order
        self._columns = None
        self._column_of = i
        self.K0, self.K1 = np.zeros((nc, nc)), np.zeros((nc, nc))
        for (a, b), k in conv.near.items():
            self.K0[a, b] = k[rx, ry]
            if rx >= 1:
                self.K1[a, b] = k[rx - 1, ry]                     # offset I - J = -1: J = I + (1, 0)
        self.minv = self.coup = None

    def factor(self, D1, D2):
        """Prepare for ``M = D1 + D2 B_near``; D1, D2 of shape (nin, nc, nc) (per-element blocks)."""
        self.minv = np.ascontiguousarray(_inverse_blocks(D1 + D2 @ self.K0))
        self.coup = np.ascontiguousarray(D2 @ self.K1)

    def factor_newton(self, slipping, zh, fac, r):
        """Prepare for the semismooth Newton Jacobian of :func:`solve_tangential`: D2 = -r S, D1 = I - S on
        slipping elements (S = fac (I - zh zh^T)) and D1 = 0, D2 = -r I on sticking ones
        (:func:`railtherm_kalker._sweep.newton_blocks`)."""
        self.minv, self.coup = newton_blocks(slipping, zh, fac, r, self.K0, self.K1)

    @property
    def columns(self):
        """The sweep order grouped by grid column (for the numpy fallback of the sweep), computed when asked."""
        if self._columns is None:
            i = self._column_of[self.order]
            self._columns = np.split(self.order, np.nonzero(np.diff(i))[0] + 1)
        return self._columns

    def solve(self, v):
        """M^{-1} v for v of shape (nc * nin,) in the solver's component-major layout."""
        v = v.reshape(self.nc, -1)
        return sweep(v, self.minv, self.coup, self.order, self.nb, self if _sweep_nb is None else None).ravel()


#: GMRES's right preconditioner in :func:`solve_tangential` (except from a good start, see GOOD_START_FORCING):
#: 20-27 % fewer GMRES steps than the upwind sweep :class:`LocalPreconditioner` at 1.5 times its cost per
#: application and 4 times per factorisation (both small against an FFT product)
PRECONDITIONER = LinePreconditioner


try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit

    @njit(cache=True, nogil=True)
    def _jacobian_rows(v, bv, slipping, zh, fac, r):
        """The Newton Jacobian's rows J v from v and B v in one pass: -r B v on sticking elements,
        v - fac (I - zh zh^T)(v + r B v) on slipping ones (the numpy expression of :func:`solve_tangential`),
        evaluated in double precision and returned in v's precision (GMRES's basis)."""
        nc, nin = v.shape
        out = np.empty((nc, nin), dtype=v.dtype)
        for e in range(nin):
            if slipping[e]:
                dot = 0.0
                for c in range(nc):
                    dot += zh[c, e] * (float(v[c, e]) + r * float(bv[c, e]))
                for c in range(nc):
                    q = float(v[c, e]) + r * float(bv[c, e])
                    out[c, e] = float(v[c, e]) - fac[e] * (q - zh[c, e] * dot)
            else:
                for c in range(nc):
                    out[c, e] = -r * float(bv[c, e])
        return out
except Exception:  # numba missing or unusable
    _jacobian_rows = None


def _forcing_term(history, eta_prev, tol, forcing, good_start):
    """Relative GMRES tolerance of the next inexact Newton step [1] from the residual history max |F| / max g.

    Eisenstat & Walker's choice 2, eta = 0.9 (res / res_prev)^2 (loose while the stick/slip division still
    moves and Newton converges only linearly), at most FORCING_MAX and at least FORCING res (superlinear at
    the end), but never tighter than needed to reach tol in this step (FINAL_MARGIN tol / res); the first
    step FORCING_MAX, or GOOD_START_FORCING res from a good start. ``forcing`` other than "ew": FORCING res.
    (S.C. Eisenstat, H.F. Walker, SIAM J. Sci. Comput. 17 (1996) 16-32, doi:10.1137/0917003.)
    """
    res = history[-1]
    if forcing == "ew" and len(history) > 1:
        eta_k = EW_GAMMA * (res / history[-2]) ** 2
        if EW_GAMMA * eta_prev ** 2 > 0.1:
            eta_k = max(eta_k, EW_GAMMA * eta_prev ** 2)
        eta_k = min(FORCING_MAX, max(eta_k, FORCING * res))
    elif forcing == "ew":
        eta_k = min(FORCING_MAX, GOOD_START_FORCING * res) if good_start else FORCING_MAX
    else:
        eta_k = min(FORCING_MAX, FORCING * res)
    return max(eta_k, LINEAR_MIN, FINAL_MARGIN * tol / max(res, 1e-300))


#: a problem is solved on the half j >= ny/2 of its grid when its traction bound equals its mirror image about the
#: grid's centre line along x to this fraction of its largest value [1] (the bound is then averaged with the image)
MIRROR_TOLERANCE = 1e-13


def _y_mirror(g, w) -> bool:
    """Whether steady rolling on bound g and rigid slip w is symmetric about the centre line along x of its grid
    (an even number of elements across): w = (xi, 0) (no lateral creepage, no spin: w_x even and w_y odd in y, as
    compared) and g(x, -y) = g(x, y) to :data:`MIRROR_TOLERANCE`. The traction then has an even x and an odd y
    component (the solution is unique and B keeps that symmetry: its kernels B_xx, B_yy are even in y, B_xy odd),
    and :func:`solve_tangential` solves on one half: the Krylov spaces from a symmetric start stay in the symmetric
    subspace, whose inner product is twice the half's, so Newton and GMRES take the same steps with half the
    orthogonalisation, preconditioner and element-wise work (the FFT products stay those of the whole grid)."""
    if w.shape[0] != 2 or g.ndim != 2 or g.shape[1] < 2 or g.shape[1] % 2:
        return False
    wmax = float(np.abs(w).max())
    if np.any(np.abs(w[0] - w[0][:, ::-1]) > MIRROR_TOLERANCE * wmax) or np.any(np.abs(w[1]) > 0.0):
        return False
    return bool(np.all(np.abs(g - g[:, ::-1]) <= MIRROR_TOLERANCE * float(np.abs(g).max())))


def _mirror_average(a, sign):
    """The part of a (ncomp, nx, ny) with the symmetry of :func:`_y_mirror` (component c times sign[c] mirrored)."""
    a = np.asarray(a, dtype=float)
    return 0.5 * (a + np.asarray(sign, dtype=float)[:, None, None] * a[:, :, ::-1])


# over 80 lines: the Newton loop, its Jacobian and line search share the unknowns' layout (idx, restrict,
# embed) and the step's state; split, they would pass a dozen arrays around
def solve_tangential(conv, bound: np.ndarray, w: np.ndarray, *, tol: float = TANGENTIAL_TOLERANCE,
                     maxiter: int = 60, initial: np.ndarray | None = None, rscale: float = 1.0,
                     precondition: bool = True, forcing: str = "ew",
                     initial_slip: np.ndarray | None = None, good_start: bool = False,
                     mirror: bool = True) -> TangentialSolution:
    """Solve Kalker's steady rolling problem with semismooth Newton-GMRES.

    Coulomb's law is the fixed point ``p = Proj_g(p - r s(p))`` (each element's traction projected on the disc of
    radius g; r = 1/|B_xx(0)| a scaling). Newton on ``F(p) = p - Proj_g(p - r s(p)) = 0`` uses the generalised
    Jacobian: r B for a sticking element's row, ``I - (g/|z|)(I - z z^T/|z|^2)(I + r B)`` (z = p - r s) for a
    slipping one's, so each step solves ``(D1 + D2 B) d = -F`` (2 x 2 blocks D1, D2 per element) by GMRES with FFT
    products on the unknown elements only, in single precision while the step's tolerance is above
    :data:`SINGLE_BELOW`, to the forcing term of :func:`_forcing_term`. GMRES is right-preconditioned by the
    Jacobian with B cut to a few offsets along x: :class:`railtherm_kalker._band.LinePreconditioner` from a coarse
    or zero start, :class:`LocalPreconditioner` (one sweep, cheaper) from a good start, which needs few GMRES steps.
    References: P. Alart, A. Curnier, Comput. Methods Appl. Mech. Eng. 92 (1991) 353-375,
    doi:10.1016/0045-7825(91)90022-X; S. Hueeber, G. Stadler, B.I. Wohlmuth, SIAM J. Sci. Comput. 30 (2008)
    572-596, doi:10.1137/060671061.

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
    initial_slip : ndarray (ncomp, nx, ny), optional
        The slip w - B p of ``initial`` when the caller has computed it [1] (saves one product).
    good_start : bool
        ``initial`` already has the final stick/slip division (the full-slip start): a tight first Newton step
        (:data:`GOOD_START_FORCING`) and the cheaper sweep preconditioner (few GMRES steps in all).
    precondition : bool
        Precondition GMRES with :class:`LocalPreconditioner` (False: plain GMRES, for comparison).
    mirror : bool
        Solve a problem symmetric about the grid's centre line along x on one half (:func:`_y_mirror`; False: on
        the whole grid, for comparison).

    Returns
    -------
    TangentialSolution
    """
    g = np.asarray(bound, dtype=float)
    w = np.asarray(w, dtype=float)
    nc = w.shape[0]
    mirrored = mirror and _y_mirror(g, w)
    sign = np.array([1.0, -1.0])
    if mirrored:        # the symmetric parts (the bound's to MIRROR_TOLERANCE; a coarse grid's start to its tolerance)
        g = 0.5 * (g + g[:, ::-1])
        initial = None if initial is None else _mirror_average(initial, sign)
        initial_slip = None if initial_slip is None else _mirror_average(initial_slip, sign)
    inside = g > 0
    gmax = float(g.max()) if inside.any() else 1.0
    idx = np.nonzero(inside.ravel())[0]
    if mirrored:        # the unknowns j >= ny/2; their mirror images j' = ny - 1 - j follow with the sign
        ny = g.shape[1]
        idx = idx[idx % ny >= ny // 2]
        twin = idx - 2 * (idx % ny) + ny - 1
    nin = idx.size
    full_shape = w.shape
    n0 = conv.products
    r = rscale / abs(float(conv.self_coefficient))     # inverse of the self-influence |B_xx(0)|

    def product(v, single=False):
        """B v on the unknown elements for v (nc, nin) on them (and, mirrored, its image on the twins)."""
        if mirrored:
            return conv.apply_at(v, idx, single=single, mirrored=True)
        return conv.apply_at(v, idx, single=single)

    def slip_of(p):
        """Slip s = w - B p on the unknown elements (nc, nin) of a traction p (nc, nx, ny) zero outside them."""
        return w_in - product(restrict(p))

    def embed(v):
        out = np.zeros((nc, g.size), dtype=v.dtype)
        vv = v.reshape(nc, nin)
        for c in range(nc):                     # np.put: about twice as fast as fancy assignment
            np.put(out[c], idx, vv[c])
            if mirrored:
                np.put(out[c], twin, sign[c] * vv[c])
        return out.reshape(full_shape)

    def restrict(a):
        return np.take(a.reshape(nc, -1), idx, axis=1)

    gin = g.ravel()[idx]
    w_in = restrict(w)
    p = np.zeros(full_shape) if initial is None else np.where(inside, np.asarray(initial, dtype=float), 0.0)
    s = slip_of(p) if initial_slip is None else restrict(np.asarray(initial_slip, dtype=float))

    def residual_of(p, s):
        z = restrict(p) - r * s
        proj, nz = _project(z, gin)
        return restrict(p) - proj, z, nz

    F, z, nz = residual_of(p, s)
    # no element can carry traction (friction 0, or no contact): the zero traction is exact
    res = float(np.max(np.sqrt(np.sum(F * F, axis=0)))) / gmax if nin else 0.0
    history = [res]
    lin_total = 0
    converged = res <= tol
    it = 0
    # a good start needs a few GMRES steps in all: the sweep's cheaper factorisation then wins
    kind = LocalPreconditioner if good_start else PRECONDITIONER
    pre = kind(conv, idx) if (precondition and nin) else None
    eta_prev = FORCING_MAX
    while not converged and it < maxiter:
        it += 1
        slipping = nz > gin
        zh = np.where(slipping, z / np.where(nz > 0, nz, 1.0), 0.0)        # unit z on slipping elements
        fac = np.where(slipping, gin / np.where(nz > 0, nz, 1.0), 0.0)    # g/|z|
        eta_k = _forcing_term(history, eta_prev, tol, forcing, good_start)
        eta_prev = eta_k
        single = eta_k > SINGLE_BELOW

        def jac(v):
            v = v.reshape(nc, nin)
            if single:      # a float32 product, the rows in the basis's precision: no conversions of the product
                bv = product(v.astype(np.float32, copy=False), single=True)
            else:
                bv = product(v)
            if _jacobian_rows is not None:   # one compiled signature (float64): float32 in exactly, out rounded
                rows = _jacobian_rows(v.astype(float, copy=False), bv.astype(float, copy=False), slipping, zh, fac, r)
                return rows.astype(v.dtype, copy=False).ravel()
            bv = bv.astype(float, copy=False)
            stick_row = -r * bv                                          # F = r s, s = w - B p
            q = v + r * bv                                               # (I + r B) v
            proj_q = q - zh * np.sum(zh * q, axis=0)                     # (I - zz^T) q
            slip_row = v - fac * proj_q
            return np.where(slipping, slip_row, stick_row).ravel()

        # Newton: J d = -F, with J = -r B (stick) / I - fac P (I + r B) (slip) = D1 + D2 B
        if pre is not None:
            pre.factor_newton(slipping, zh, fac, r)
            psolve = pre.solve
        else:
            def psolve(v):
                return v
        d, nlin = gmres_single_then_double(jac, psolve, -F.ravel(), eta_k, LINEAR_MAXITER, single)
        lin_total += nlin
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
    if mirrored:
        stick.ravel()[twin] = nz <= gin
    # tractions exactly on the bound where slipping; zero slip outside the contact
    s_out = embed(s)
    return TangentialSolution(traction=p, slip=s_out, stick=stick, converged=converged, iterations=it,
                              residual=res, history=history, linear_iterations=lin_total,
                              products=conv.products - n0, mirrored=mirrored)


def _coarsen(a: np.ndarray, line: bool) -> np.ndarray:
    """Average over blocks of 2 x 2 elements (2 x 1 for a line contact); last two axes (nx, ny)."""
    nx, ny = a.shape[-2:]
    if line:
        return 0.5 * (a[..., 0::2, :] + a[..., 1::2, :])
    return 0.25 * (a[..., 0::2, 0::2] + a[..., 1::2, 0::2] + a[..., 0::2, 1::2] + a[..., 1::2, 1::2])


def _interpolate2(a: np.ndarray, axis: int) -> np.ndarray:
    """Linear interpolation to the element centres twice as fine along ``axis`` (weights 3/4, 1/4; the
    outermost values held)."""
    a = np.moveaxis(a, axis, -1)
    lo = np.concatenate([a[..., :1], a[..., :-1]], axis=-1)
    hi = np.concatenate([a[..., 1:], a[..., -1:]], axis=-1)
    out = np.empty(a.shape[:-1] + (2 * a.shape[-1],))
    out[..., 0::2] = 0.75 * a + 0.25 * lo
    out[..., 1::2] = 0.75 * a + 0.25 * hi
    return np.moveaxis(out, -1, axis)


def _refine(p: np.ndarray, g_coarse: np.ndarray, g_fine: np.ndarray, line: bool) -> np.ndarray:
    """Prolongation of a coarse traction (ncomp, nx, ny) to the elements twice as fine.

    The traction's ratio to the coarse bound, p / g (length <= 1, = 1 in slip), is interpolated
    linearly over the loaded coarse elements (weights renormalised at the contact edge) and
    multiplied by the fine bound: the slip zone stays on the bound, the stick zone's traction is
    smooth. Elements without a loaded coarse neighbour get the piecewise-constant value.
    """
    inside = g_coarse > 0
    q = np.where(inside, p / np.where(inside, g_coarse, 1.0), 0.0)
    w = inside.astype(float)
    axes = (1,) if line else (1, 2)
    for ax in axes:
        q = _interpolate2(q, ax)
        w = _interpolate2(w, ax - 1)
    const = np.repeat(p / np.where(inside, g_coarse, 1.0), 2, axis=-2)
    const = const if line else np.repeat(const, 2, axis=-1)
    q = np.where(w > 0, q / np.where(w > 0, w, 1.0), const)
    return q * g_fine


#: the full-slip traction -g w/|w| starts the finest grid directly (no coarse grids) when its residual
#: max |F| / max g is below this [1] (the prolonged coarse solutions start at 0.1-0.2)
FULL_SLIP_START = 0.05


def _centres(xe, ye, offset, line):
    """Element centres (X, Y) [m], x shifted by ``offset`` elements."""
    xc = 0.5 * (xe[1:] + xe[:-1]) + offset * (xe[1] - xe[0])
    if line:
        return xc[:, None], np.zeros((xc.size, 1))
    return np.meshgrid(xc, 0.5 * (ye[1:] + ye[:-1]), indexing="ij")


def _full_slip_start(conv_for, level, creepage, offset, line):
    """The full-slip traction -g w/|w| of the rigid slip w on the finest grid when its residual is below
    :data:`FULL_SLIP_START` (creepages beyond saturation: the elastic slip is a small part of w, so the
    coarse grids would only reproduce it), else None; its slip w - B p (handed to the solve, which then
    needs no product for its first residual; on the contact's elements only when the problem is mirrored, see
    :func:`_y_mirror`); and the products spent [1]."""
    xe, ye, g = level
    w = rigid_slip(*_centres(xe, ye, offset, line), *creepage, line=line)
    nw = np.sqrt(np.sum(w * w, axis=0))
    if not (g > 0).any() or np.any((g > 0) & (nw == 0)):
        return None, None, 0
    conv = conv_for(xe, ye)
    p, _ = _project(-g * w / np.where(nw > 0, nw, 1.0), g)
    r = 1.0 / abs(float(conv.self_coefficient))
    if _y_mirror(g, w):     # the product on the contact's half j >= ny/2 (solve_tangential solves there)
        ny = g.shape[1]
        idx = np.nonzero((g > 0).ravel())[0]
        idx = idx[idx % ny >= ny // 2]
        twin = idx - 2 * (idx % ny) + ny - 1
        s = w.copy()
        bp = conv.apply_at(np.take(p.reshape(2, -1), idx, axis=1), idx, mirrored=True)
        for c, sign in ((0, 1.0), (1, -1.0)):
            sc = s[c].reshape(-1)
            sc[idx] -= bp[c]
            sc[twin] = sign * sc[idx]
    else:
        s = w - conv.apply(p)
    proj, _ = _project(p - r * s, g)
    F = np.where(g > 0, p - proj, 0.0)
    res = float(np.max(np.sqrt(np.sum(F * F, axis=0)))) / float(g.max())
    return (p, s, 1) if res < FULL_SLIP_START else (None, None, 1)


def _add_coarse_levels(levels, min_elements, line):
    """Append to ``levels`` (edges x, edges y, bound) the grids of 2, 4, ... times larger elements while
    each side keeps at least ``min_elements`` elements (and an even count to merge)."""
    while True:
        xe, ye, g = levels[-1]
        nx, ny = g.shape
        can = nx % 2 == 0 and nx // 2 >= min_elements and (line or (ny % 2 == 0 and ny // 2 >= min_elements))
        if not can:
            return
        levels.append((xe[::2], None if line else ye[::2], _coarsen(g, line)))


def _level_start(p, slip0, levels, k, line):
    """Initial traction of the solve on ``levels[k]``: none (coarsest, no warm start); the full-slip start
    as it is (already projected, its slip known: ``slip0``); else the coarser solution (or the warm start)
    refined to this grid and projected on its traction bound."""
    if slip0 is not None:
        return p
    if p is None:
        return None
    g = levels[k][2]
    init, _ = _project(p if p.shape[1:] == g.shape else _refine(p, levels[k + 1][2], g, line), g)
    return init


def solve_tangential_nested(conv_for, x_edges, y_edges, bound, creepage, *, min_elements: int = 12,
                            tol: float = TANGENTIAL_TOLERANCE, maxiter: int = 60,
                            coarse_tol: float = 1e-2, offset: float = 0.0,
                            initial: np.ndarray | None = None, mirror: bool = True) -> TangentialSolution:
    """Nested iteration: solve on grids of 2, 4, ... times larger elements first, starting from zero
    traction on the coarsest, and start each finer solve from the coarser solution. With ``initial`` (a
    traction on this grid, e.g. the previous solve of a friction-law or temperature loop) only this grid is
    solved, from ``initial`` projected on the traction bound.

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
    initial : ndarray (ncomp, nx, ny), optional
        A warm start on this grid [Pa]: no coarse solves.
    mirror : bool
        As :func:`solve_tangential` (every grid).
    offset : float
        Rigid slip evaluated at x + offset dx instead of the element centre [elements] (default 0; 1/6 with the
        first-order operator is CONTACT's discretisation). No offset makes the first-order operator a
        second-order scheme: ``offset = 1/4`` with the moment arm at
        x - dx/4 keeps the exact reciprocity C23(Fy) = C23(Mz) and moves the first-order error of the spin
        moment into C23 by about as much (measured at 128 elements across 2a on a = 8, b = 4 mm:
        C33 +4.8 % -> +1.1 %, C23 +0.15 % -> +1.2 %; see tests/test_kalker_solver.py), so it is no default.
        (It is the discrete-vortex "1/4-3/4 rule", second order in 1-D only when the contact's edges
        lie on element edges, which a uniform grid on an ellipse cannot give; the model's default is the
        second-order operator, :func:`railtherm_kalker.tangential_model.rolling_operator`.)

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
    products, slip0 = 0, None
    if initial is None:
        initial, slip0, products = _full_slip_start(conv_for, levels[0], creepage, offset, line)
    if initial is None:
        _add_coarse_levels(levels, min_elements, line)
    p = None if initial is None else np.asarray(initial, dtype=float)
    coarse = []
    linear = 0
    sol = None
    for k in range(len(levels) - 1, -1, -1):
        xe, ye, g = levels[k]
        w = rigid_slip(*_centres(xe, ye, offset, line), *creepage, line=line)
        conv = conv_for(xe, ye)
        init = _level_start(p, slip0, levels, k, line)
        last = k == 0
        sol = solve_tangential(conv, g, w, tol=tol if last else max(tol, coarse_tol), maxiter=maxiter, initial=init,
                               initial_slip=slip0, good_start=slip0 is not None, mirror=mirror)
        products += sol.products
        linear += sol.linear_iterations
        if not last:
            coarse.append((g.shape, sol.iterations))
        p = sol.traction
    sol.products = products
    sol.linear_iterations = linear
    sol.coarse = coarse
    return sol
