"""Numba kernels of the finite-difference rail block (seed section 6.3).

* :func:`explicit_step` -- one explicit-Euler step of the 7-point heat equation on a uniform node
  grid (the seed's spreadsheet scheme), parallel over the outer (x) index with ``prange``;
  :func:`explicit_step_serial` its serial twin for small grids;
* :func:`explicit_two_steps` -- two such steps in one pass over memory (temporal blocking), for
  large grids where the stencil is memory bound;
* :func:`stencil_matvec` (and ``_serial``), :func:`zline_factor`, :func:`sgs_zline` -- a general
  7-point operator and its symmetric block Gauss-Seidel preconditioner with z-lines as blocks
  (Thomas algorithm along the depth), used by the implicit (backward Euler) and the moving-frame
  steady schemes; :func:`gmres` (right-preconditioned, restarted) and the BLAS-free vector helpers
  :func:`vdot`, :func:`vaxpy`.

Array layout: ``T[i, j, k]`` with i along the rolling direction x, j lateral (y), k depth (z, k = 0 is
the surface); C order, so the depth index is contiguous.

Operator convention of :func:`stencil_matvec`: row (i, j, k) of ``A t`` is ::

    aP t[i,j,k] - aE t[i+1,j,k] - aW t[i-1,j,k] - aN t[i,j+1,k] - aS t[i,j-1,k]
                - aT t[i,j,k-1] - aB t[i,j,k+1]

with coefficients that reach outside the array set to zero (boundary conditions are folded into
``aP`` and the right-hand side).
"""
from __future__ import annotations

import numba
import numpy as np
from numba import prange


@numba.njit(parallel=True, cache=True, fastmath=True, boundscheck=False)
def explicit_step(T, Tn, r, src, hloss):  # pragma: no cover - compiled
    """One explicit-Euler step on a uniform node grid of spacing d (dual-cell finite volumes).

    Nodes i = 0 and i = nx-1 (far faces in x) and k = nz-1 (bottom) hold the fixed temperature 0
    (seed eq. 58) and are not updated. Lateral faces j = 0, ny-1 are insulated (eq. 57): the
    half-width dual cell of a boundary node is the mirror-image stencil. The surface node k = 0 owns
    a half-depth dual cell: it receives the source increment ``src`` and loses ``hloss * T`` by
    convection (eqs. 59-60).

    Parameters
    ----------
    T : ndarray (nx, ny, nz)
        Temperature rise at time level n [K].
    Tn : ndarray (nx, ny, nz)
        Output, temperature rise at level n+1 [K] (fixed nodes must already hold 0).
    r : float
        kappa dt / d^2 [1]; stable for r <= 1/6 (without convection).
    src : ndarray (nx, ny)
        Source increment of each surface node in this step, ``dt Q / (rho c V)`` [K].
    hloss : ndarray (nx, ny)
        Convective loss factor of each surface node, ``dt h A (1 - cover) / (rho c V)`` [1].
    """
    nx, ny, nz = T.shape
    for i in prange(1, nx - 1):
        for j in range(ny):
            jm = j - 1 if j > 0 else 1
            jp = j + 1 if j < ny - 1 else ny - 2
            t = T[i, j, 0]
            Tn[i, j, 0] = (t + r * (T[i + 1, j, 0] + T[i - 1, j, 0] + T[i, jp, 0] + T[i, jm, 0]
                                    + 2.0 * T[i, j, 1] - 6.0 * t)
                           + src[i, j] - hloss[i, j] * t)
            for k in range(1, nz - 1):
                t = T[i, j, k]
                Tn[i, j, k] = t + r * (T[i + 1, j, k] + T[i - 1, j, k] + T[i, jp, k] + T[i, jm, k]
                                       + T[i, j, k + 1] + T[i, j, k - 1] - 6.0 * t)


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def explicit_step_serial(T, Tn, r, src, hloss):  # pragma: no cover - compiled
    """Serial twin of :func:`explicit_step` (small grids: no thread start-up per step).

    One explicit-Euler step on a uniform node grid of spacing d (dual-cell finite volumes).

    Nodes i = 0 and i = nx-1 (far faces in x) and k = nz-1 (bottom) hold the fixed temperature 0
    (seed eq. 58) and are not updated. Lateral faces j = 0, ny-1 are insulated (eq. 57): the
    half-width dual cell of a boundary node is the mirror-image stencil. The surface node k = 0 owns
    a half-depth dual cell: it receives the source increment ``src`` and loses ``hloss * T`` by
    convection (eqs. 59-60).

    Parameters
    ----------
    T : ndarray (nx, ny, nz)
        Temperature rise at time level n [K].
    Tn : ndarray (nx, ny, nz)
        Output, temperature rise at level n+1 [K] (fixed nodes must already hold 0).
    r : float
        kappa dt / d^2 [1]; stable for r <= 1/6 (without convection).
    src : ndarray (nx, ny)
        Source increment of each surface node in this step, ``dt Q / (rho c V)`` [K].
    hloss : ndarray (nx, ny)
        Convective loss factor of each surface node, ``dt h A (1 - cover) / (rho c V)`` [1].
    """
    nx, ny, nz = T.shape
    for i in range(1, nx - 1):
        for j in range(ny):
            jm = j - 1 if j > 0 else 1
            jp = j + 1 if j < ny - 1 else ny - 2
            t = T[i, j, 0]
            Tn[i, j, 0] = (t + r * (T[i + 1, j, 0] + T[i - 1, j, 0] + T[i, jp, 0] + T[i, jm, 0]
                                    + 2.0 * T[i, j, 1] - 6.0 * t)
                           + src[i, j] - hloss[i, j] * t)
            for k in range(1, nz - 1):
                t = T[i, j, k]
                Tn[i, j, k] = t + r * (T[i + 1, j, k] + T[i - 1, j, k] + T[i, jp, k] + T[i, jm, k]
                                       + T[i, j, k + 1] + T[i, j, k - 1] - 6.0 * t)


@numba.njit(cache=True, fastmath=True, boundscheck=False, inline="always")
def _plane(T, i, out, r, src, hloss):  # pragma: no cover - compiled
    """Explicit update of plane i of T into the (ny, nz) array ``out`` (same stencil as explicit_step)."""
    nx, ny, nz = T.shape
    for j in range(ny):
        jm = j - 1 if j > 0 else 1
        jp = j + 1 if j < ny - 1 else ny - 2
        t = T[i, j, 0]
        out[j, 0] = (t + r * (T[i + 1, j, 0] + T[i - 1, j, 0] + T[i, jp, 0] + T[i, jm, 0]
                              + 2.0 * T[i, j, 1] - 6.0 * t)
                     + src[i, j] - hloss[i, j] * t)
        for k in range(1, nz - 1):
            t = T[i, j, k]
            out[j, k] = t + r * (T[i + 1, j, k] + T[i - 1, j, k] + T[i, jp, k] + T[i, jm, k]
                                 + T[i, j, k + 1] + T[i, j, k - 1] - 6.0 * t)
        out[j, nz - 1] = 0.0


@numba.njit(parallel=True, cache=True, fastmath=True, boundscheck=False)
def explicit_two_steps(T, T2, r, src1, hloss1, src2, hloss2, wyz, wy, wtop2, chunk, acc):  # pragma: no cover
    """Two explicit-Euler steps in one pass over memory (temporal blocking), parallel over x-chunks.

    Equivalent to ``explicit_step(T, Tm, r, src1, hloss1); explicit_step(Tm, T2, r, src2, hloss2)``
    without storing the intermediate level Tm: each chunk of ``chunk`` planes keeps three intermediate
    planes in a rolling buffer (its two halo planes are computed twice), halving the memory traffic
    of the memory-bound stencil.

    Parameters
    ----------
    T, T2 : ndarray (nx, ny, nz)
        Level n (input) and level n+2 (output; fixed nodes must hold 0).
    r : float
        kappa dt / d^2.
    src1, hloss1, src2, hloss2 : ndarray (nx, ny)
        Source increments and convective loss factors of the two steps (see :func:`explicit_step`).
    wyz : ndarray (ny, nz)
        Weights of the x-face loss sums (dual-face areas / d^2) [1].
    wy : ndarray (ny,)
        Weights of the bottom loss sums [1].
    wtop2 : ndarray (ny,)
        Heat capacity of the surface nodes per unit rise [J/K] (convective loss of step 2 is
        ``hloss2 * wtop2 * Tm``).
    chunk : int
        Planes per parallel chunk.
    acc : ndarray (nchunks, 3)
        Output: per chunk, the sums at the intermediate level Tm of the x-face losses (planes 1 and
        nx-2, weighted by wyz), the bottom losses (plane k = nz-2, weighted by wy) and the convective
        loss of step 2 [J].
    """
    nx, ny, nz = T.shape
    nint = nx - 2
    nch = (nint + chunk - 1) // chunk
    for c in prange(nch):
        i0 = 1 + c * chunk
        i1 = min(nx - 1, i0 + chunk)
        buf = np.zeros((3, ny, nz))
        a_x = 0.0
        a_b = 0.0
        a_c = 0.0
        for p in range(i0 - 1, i1 + 1):
            slot = p % 3
            if p == 0 or p == nx - 1:
                for j in range(ny):
                    for k in range(nz):
                        buf[slot, j, k] = 0.0
            else:
                _plane(T, p, buf[slot], r, src1, hloss1)
                if p >= i0 and p < i1:
                    if p == 1 or p == nx - 2:
                        for j in range(ny):
                            for k in range(nz):
                                a_x += wyz[j, k] * buf[slot, j, k]
                    for j in range(ny):
                        a_b += wy[j] * buf[slot, j, nz - 2]
                        a_c += hloss2[p, j] * wtop2[j] * buf[slot, j, 0]
            q = p - 1
            if q >= i0 and q < i1:
                bm = buf[(q - 1) % 3]
                b0 = buf[q % 3]
                bp = buf[(q + 1) % 3]
                for j in range(ny):
                    jm = j - 1 if j > 0 else 1
                    jp = j + 1 if j < ny - 1 else ny - 2
                    t = b0[j, 0]
                    T2[q, j, 0] = (t + r * (bp[j, 0] + bm[j, 0] + b0[jp, 0] + b0[jm, 0] + 2.0 * b0[j, 1] - 6.0 * t)
                                   + src2[q, j] - hloss2[q, j] * t)
                    for k in range(1, nz - 1):
                        t = b0[j, k]
                        T2[q, j, k] = t + r * (bp[j, k] + bm[j, k] + b0[jp, k] + b0[jm, k]
                                               + b0[j, k + 1] + b0[j, k - 1] - 6.0 * t)
        acc[c, 0] = a_x
        acc[c, 1] = a_b
        acc[c, 2] = a_c


@numba.njit(parallel=True, cache=True, boundscheck=False)
def stencil_matvec(aP, aE, aW, aN, aS, aT, aB, t, out):  # pragma: no cover - compiled
    """``out = A t`` for the 7-point operator described in the module docstring."""
    nx, ny, nz = t.shape
    for i in prange(nx):
        for j in range(ny):
            for k in range(nz):
                v = aP[i, j, k] * t[i, j, k]
                if i + 1 < nx:
                    v -= aE[i, j, k] * t[i + 1, j, k]
                if i > 0:
                    v -= aW[i, j, k] * t[i - 1, j, k]
                if j + 1 < ny:
                    v -= aN[i, j, k] * t[i, j + 1, k]
                if j > 0:
                    v -= aS[i, j, k] * t[i, j - 1, k]
                if k > 0:
                    v -= aT[i, j, k] * t[i, j, k - 1]
                if k + 1 < nz:
                    v -= aB[i, j, k] * t[i, j, k + 1]
                out[i, j, k] = v


@numba.njit(cache=True, boundscheck=False)
def stencil_matvec_serial(aP, aE, aW, aN, aS, aT, aB, t, out):  # pragma: no cover - compiled
    """Serial twin of :func:`stencil_matvec`."""
    nx, ny, nz = t.shape
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                v = aP[i, j, k] * t[i, j, k]
                if i + 1 < nx:
                    v -= aE[i, j, k] * t[i + 1, j, k]
                if i > 0:
                    v -= aW[i, j, k] * t[i - 1, j, k]
                if j + 1 < ny:
                    v -= aN[i, j, k] * t[i, j + 1, k]
                if j > 0:
                    v -= aS[i, j, k] * t[i, j - 1, k]
                if k > 0:
                    v -= aT[i, j, k] * t[i, j, k - 1]
                if k + 1 < nz:
                    v -= aB[i, j, k] * t[i, j, k + 1]
                out[i, j, k] = v


@numba.njit(cache=True, boundscheck=False)
def zline_factor(aP, aT, aB):  # pragma: no cover - compiled
    """LU factors of every z-line block ``aP x_k - aT x_{k-1} - aB x_{k+1}`` (Thomas algorithm).

    Returns ``cp`` (the modified super-diagonal) and ``inv`` (inverse pivots), shape (nx, ny, nz),
    for :func:`sgs_zline`.
    """
    nx, ny, nz = aP.shape
    cp = np.empty((nx, ny, nz))
    inv = np.empty((nx, ny, nz))
    for i in range(nx):
        for j in range(ny):
            den = aP[i, j, 0]
            inv[i, j, 0] = 1.0 / den
            cp[i, j, 0] = -aB[i, j, 0] / den
            for k in range(1, nz):
                den = aP[i, j, k] + aT[i, j, k] * cp[i, j, k - 1]
                inv[i, j, k] = 1.0 / den
                cp[i, j, k] = -aB[i, j, k] / den
    return cp, inv


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def sgs_zline(aP, aE, aW, aN, aS, aT, aB, cp, inv, r, out, work):  # pragma: no cover - compiled
    """Symmetric block Gauss-Seidel preconditioner with z-lines as blocks: ``out = M^{-1} r``.

    ``M = (D + L) D^{-1} (D + U)`` where D holds the z-line (tridiagonal) blocks, L the couplings to
    the neighbours at (i+1, j) and (i, j-1) -- the upstream side for material flowing in -x -- and U
    those to (i-1, j) and (i, j+1). M is symmetric positive definite when A is (implicit scheme),
    and close to A for flow-dominated steady problems swept from upstream (steady scheme).

    Parameters
    ----------
    cp, inv : ndarray (nx, ny, nz)
        Factors of the z-line blocks from :func:`zline_factor`.
    r : ndarray (nx, ny, nz)
        Right-hand side.
    out : ndarray (nx, ny, nz)
        Result.
    work : ndarray (nx, ny, nz)
        Scratch array of the same shape.
    """
    nx, ny, nz = r.shape
    rhs = np.empty(nz)
    v = work
    # forward sweep: (D + L) v = r, upstream (large i) first
    for ii in range(nx):
        i = nx - 1 - ii
        for j in range(ny):
            for k in range(nz):
                rhs[k] = r[i, j, k]
            if i + 1 < nx:
                for k in range(nz):
                    rhs[k] += aE[i, j, k] * v[i + 1, j, k]
            if j > 0:
                for k in range(nz):
                    rhs[k] += aS[i, j, k] * v[i, j - 1, k]
            # Thomas: forward substitution then back substitution
            d = rhs[0] * inv[i, j, 0]
            rhs[0] = d
            for k in range(1, nz):
                d = (rhs[k] + aT[i, j, k] * d) * inv[i, j, k]
                rhs[k] = d
            x = rhs[nz - 1]
            v[i, j, nz - 1] = x
            for k in range(nz - 2, -1, -1):
                x = rhs[k] - cp[i, j, k] * x
                v[i, j, k] = x
    # backward sweep: (D + U) out = D v
    for i in range(nx):
        for jj in range(ny):
            j = ny - 1 - jj
            for k in range(nz):
                s = aP[i, j, k] * v[i, j, k]
                if k > 0:
                    s -= aT[i, j, k] * v[i, j, k - 1]
                if k + 1 < nz:
                    s -= aB[i, j, k] * v[i, j, k + 1]
                rhs[k] = s
            if i > 0:
                for k in range(nz):
                    rhs[k] += aW[i, j, k] * out[i - 1, j, k]
            if j + 1 < ny:
                for k in range(nz):
                    rhs[k] += aN[i, j, k] * out[i, j + 1, k]
            d = rhs[0] * inv[i, j, 0]
            rhs[0] = d
            for k in range(1, nz):
                d = (rhs[k] + aT[i, j, k] * d) * inv[i, j, k]
                rhs[k] = d
            x = rhs[nz - 1]
            out[i, j, nz - 1] = x
            for k in range(nz - 2, -1, -1):
                x = rhs[k] - cp[i, j, k] * x
                out[i, j, k] = x


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def vdot(a, b):  # pragma: no cover - compiled
    """Dot product of two flat arrays (serial; avoids BLAS thread contention)."""
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def vaxpy(alpha, x, y):  # pragma: no cover - compiled
    """In place ``y += alpha * x`` on flat arrays."""
    for i in range(x.shape[0]):
        y[i] += alpha * x[i]


def gmres(matvec, precond, b, x0, *, rtol=1e-11, restart=30, maxiter=2000):
    """Right-preconditioned restarted GMRES with modified Gram-Schmidt.

    Solves ``A x = b`` for flat float arrays; ``matvec(v)`` returns ``A v`` and ``precond(v)`` an
    approximation of ``A^{-1} v`` (both new flat arrays). Stops when ``||b - A x|| <= rtol ||b||``.

    Returns
    -------
    x : ndarray
    iterations : int
        Arnoldi steps taken.
    relres : float
        Final true relative residual.
    """
    n = b.shape[0]
    x = x0.copy()
    bnorm = np.sqrt(vdot(b, b)) or 1.0
    r = b - matvec(x)
    beta = np.sqrt(vdot(r, r))
    its = 0
    V = np.empty((restart + 1, n))
    while beta > rtol * bnorm and its < maxiter:
        H = np.zeros((restart + 1, restart))
        cs = np.zeros(restart)
        sn = np.zeros(restart)
        g = np.zeros(restart + 1)
        g[0] = beta
        V[0] = r / beta
        k = 0
        for j in range(restart):
            w = matvec(precond(V[j]))
            for i in range(j + 1):
                hij = vdot(w, V[i])
                H[i, j] = hij
                vaxpy(-hij, V[i], w)
            hn = np.sqrt(vdot(w, w))
            H[j + 1, j] = hn
            if hn > 0:
                V[j + 1] = w / hn
            for i in range(j):
                t = cs[i] * H[i, j] + sn[i] * H[i + 1, j]
                H[i + 1, j] = -sn[i] * H[i, j] + cs[i] * H[i + 1, j]
                H[i, j] = t
            den = np.hypot(H[j, j], H[j + 1, j])
            cs[j] = H[j, j] / den if den > 0 else 1.0
            sn[j] = H[j + 1, j] / den if den > 0 else 0.0
            H[j, j] = den
            H[j + 1, j] = 0.0
            g[j + 1] = -sn[j] * g[j]
            g[j] = cs[j] * g[j]
            k = j + 1
            its += 1
            if abs(g[j + 1]) <= rtol * bnorm or hn == 0 or its >= maxiter:
                break
        y = np.linalg.solve(np.triu(H[:k, :k]), g[:k]) if k > 0 else np.zeros(0)
        u = np.zeros(n)
        for i in range(k):
            vaxpy(y[i], V[i], u)
        x += precond(u)
        r = b - matvec(x)
        beta = np.sqrt(vdot(r, r))
    return x, its, beta / bnorm


#: grids with fewer nodes than this use the serial kernels (thread start-up dominates below)
PARALLEL_MIN_NODES = 400_000


def step_kernel(nodes):
    """The explicit-step kernel for a grid of ``nodes`` nodes (parallel for large grids)."""
    return explicit_step if nodes >= PARALLEL_MIN_NODES else explicit_step_serial


def matvec_kernel(nodes):
    """The 7-point operator kernel for a grid of ``nodes`` nodes (parallel for large grids)."""
    return stencil_matvec if nodes >= PARALLEL_MIN_NODES else stencil_matvec_serial
