"""Numba kernels of the finite-difference rail block (seed section 6.3).

* :func:`explicit_step` -- one explicit-Euler step of the 7-point heat equation on a uniform node
  grid (the seed's spreadsheet scheme), parallel over x with ``prange``; :func:`explicit_step_serial`
  is the same body compiled without threads, for small grids;
* :func:`explicit_two_steps` -- two such steps in one pass over memory (temporal blocking), for
  large, memory-bound grids, with the loss sums of both levels (:func:`plane_losses`);
* :func:`explicit_step_2d` -- the explicit step of the 2-D (x-z) block of a line contact;
* :func:`stencil_matvec` (and ``_serial``; operator convention in :func:`_stencil_matvec`),
  :func:`zline_factor`, :func:`sgs_zline` -- a general 7-point operator and its symmetric block
  Gauss-Seidel preconditioner with z-lines as blocks (Thomas algorithm along the depth), used by the
  implicit and moving-frame steady schemes; the BLAS-free vector helpers :func:`vdot`, :func:`vaxpy`.

Array layout: ``T[i, j, k]`` with i along x, j lateral (y), k depth (z, k = 0 the surface); C order,
so the depth index is contiguous.
"""
from __future__ import annotations

import types

import numba
import numpy as np
from numba import prange

__all__ = ["explicit_step", "explicit_step_serial", "explicit_two_steps", "explicit_two_steps_serial",
           "explicit_step_2d", "stencil_matvec", "stencil_matvec_serial", "zline_factor", "sgs_zline", "vdot", "vaxpy", "step_kernel", "matvec_kernel",
           "PARALLEL_MIN_NODES", "compile_twice", "block_kernel_signatures", "compile_block_kernels"]


def compile_twice(func, **options):
    """``(parallel, serial)``: one kernel body compiled with and without numba's threads.

    ``func`` loops with ``prange``, which the parallel build splits over threads and the serial
    build runs as ``range``; both are the same Python code, so they cannot drift apart. The serial
    build compiles a copy of the function named ``<name>_serial``: numba's on-disk cache is keyed by
    the function's qualified name and signature, not by the ``parallel`` flag, and would otherwise
    hand one build the other's machine code.

    Parameters
    ----------
    func : function
        The kernel body (plain Python, numba-compilable).
    **options
        Further ``numba.njit`` options of both builds (``cache``, ``fastmath``, ...).

    Returns
    -------
    parallel, serial : numba dispatchers
    """
    twin = types.FunctionType(func.__code__, func.__globals__, func.__name__ + "_serial", func.__defaults__,
                              func.__closure__)
    twin.__qualname__ = func.__qualname__ + "_serial"
    twin.__doc__ = func.__doc__
    twin.__module__ = func.__module__
    return numba.njit(parallel=True, **options)(func), numba.njit(**options)(twin)


@numba.njit(cache=True, fastmath=True, boundscheck=False, inline="always")
def plane_step(ahead, here, behind, out, r, src, hloss):  # pragma: no cover - compiled
    """The stencil of one x-plane: explicit-Euler update of plane ``here`` into ``out``.

    The one place the 3-D explicit stencil is written; :func:`explicit_step` and both stages of
    :func:`explicit_two_steps` apply it plane by plane.

    Lateral faces j = 0, ny-1 are insulated (seed eq. 57): the half-width dual cell of a boundary
    node is the mirror-image stencil. The surface node k = 0 owns a half-depth dual cell: it
    receives the source increment ``src`` and loses ``hloss * T`` by convection (eqs. 59-60). The
    bottom node k = nz-1 holds the fixed temperature 0 (eq. 58).

    Parameters
    ----------
    ahead, here, behind : ndarray (ny, nz)
        Temperature rise at level n on the planes i+1, i and i-1 [K].
    out : ndarray (ny, nz)
        Output, plane i at level n+1 [K].
    r : float
        kappa dt / d^2 [1].
    src, hloss : ndarray (ny,)
        Source increments [K] and convective loss factors [1] of the plane's surface nodes.
    """
    ny, nz = here.shape
    for j in range(ny):
        jm = j - 1 if j > 0 else 1
        jp = j + 1 if j < ny - 1 else ny - 2
        t = here[j, 0]
        out[j, 0] = (t + r * (ahead[j, 0] + behind[j, 0] + here[jp, 0] + here[jm, 0] + 2.0 * here[j, 1] - 6.0 * t)
                     + src[j] - hloss[j] * t)
        for k in range(1, nz - 1):
            t = here[j, k]
            out[j, k] = t + r * (ahead[j, k] + behind[j, k] + here[jp, k] + here[jm, k]
                                 + here[j, k + 1] + here[j, k - 1] - 6.0 * t)
        out[j, nz - 1] = 0.0


def _explicit_step(T, Tn, r, src, hloss):  # pragma: no cover - compiled
    """One explicit-Euler step on a uniform node grid of spacing d (dual-cell finite volumes).

    Compiled twice (:func:`compile_twice`): :func:`explicit_step` (parallel over x) and
    :func:`explicit_step_serial`.

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
    nx = T.shape[0]
    for i in prange(1, nx - 1):
        plane_step(T[i + 1], T[i], T[i - 1], Tn[i], r, src[i], hloss[i])


explicit_step, explicit_step_serial = compile_twice(_explicit_step, cache=True, fastmath=True,
                                                   boundscheck=False)


def _explicit_two_steps(T, T2, r, src1, hloss1, src2, hloss2, wyz, wy, wtop2, chunk, acc, stop):  # pragma: no cover
    """Two explicit-Euler steps in one pass over memory (temporal blocking), parallel over x-chunks.

    Compiled twice (:func:`compile_twice`): :func:`explicit_two_steps` (parallel over the chunks) and
    :func:`explicit_two_steps_serial` (for one thread: the parallel build takes about 7 s to compile).

    Equivalent to ``explicit_step(T, Tm, r, src1, hloss1); explicit_step(Tm, T2, r, src2, hloss2)``
    without storing the intermediate level Tm: each chunk of ``chunk`` planes keeps three intermediate
    planes in a rolling buffer (its two halo planes are computed twice), halving the memory traffic
    of the memory-bound stencil.

    Planes ``i >= stop`` are not visited: the caller guarantees that they are zero in ``T`` and ``T2``
    and stay zero over the two steps (no heat has reached them: the explicit stencil moves a
    disturbance by one plane per step). Skipping them gives the same field bit for bit and saves the
    planes ahead of the heat while the source starts out on a cold block; the chunks split the planes
    below ``stop`` (so that threads share the work evenly), which orders the loss sums differently
    (rounding only).

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
        ``hloss2 * wtop2 * Tm``, of step 1 ``hloss1 * wtop2 * T``).
    chunk : int
        Planes per parallel chunk (chunks start at plane 1).
    acc : ndarray (at least ceil((nx - 2) / chunk), 6)
        Output: per chunk (rows beyond the chunks below ``stop`` are zeroed), the sums at the
        intermediate level Tm of the x-face losses (planes 1 and nx-2, weighted by wyz), the bottom
        losses (plane k = nz-2, weighted by wy) and the convective loss of step 2 [J]
        (:func:`plane_losses`); then the same three at level n (input ``T``, the convective loss of
        step 1 with ``hloss1``).
    stop : int
        First plane known to be zero at both levels (``nx - 1``: every plane is updated).
    """
    nx, ny, nz = T.shape
    end = min(nx - 1, max(stop, 1))
    nch = (end - 1 + chunk - 1) // chunk
    for c in range(nch, acc.shape[0]):
        for m in range(6):
            acc[c, m] = 0.0
    for c in prange(nch):
        i0 = 1 + c * chunk
        i1 = min(end, i0 + chunk)
        for m in range(6):
            acc[c, m] = 0.0
        buf = np.zeros((3, ny, nz))
        for p in range(i0 - 1, i1 + 1):
            slot = p % 3
            if p == 0 or p == nx - 1:
                for j in range(ny):
                    for k in range(nz):
                        buf[slot, j, k] = 0.0
            else:
                plane_step(T[p + 1], T[p], T[p - 1], buf[slot], r, src1[p], hloss1[p])
                if p >= i0 and p < i1:
                    edge = p == 1 or p == nx - 2
                    plane_losses(buf[slot], wyz, wy, wtop2, hloss2[p], edge, acc[c], 0)
                    plane_losses(T[p], wyz, wy, wtop2, hloss1[p], edge, acc[c], 3)
            q = p - 1
            if q >= i0 and q < i1:
                plane_step(buf[(q + 1) % 3], buf[q % 3], buf[(q - 1) % 3], T2[q], r, src2[q], hloss2[q])


explicit_two_steps, explicit_two_steps_serial = compile_twice(_explicit_two_steps, cache=True, fastmath=True,
                                                           boundscheck=False)


@numba.njit(cache=True, fastmath=True, boundscheck=False, inline="always")
def plane_losses(plane, wyz, wy, wtop, hloss, edge, out, at):  # pragma: no cover - compiled
    """Add the loss sums of one x-plane to ``out[at:at + 3]``: its x-face sum (``wyz``-weighted, only
    when ``edge``: planes 1 and nx-2 face the fixed x faces), its bottom sum (plane row k = nz-2,
    ``wy``-weighted) and its convective loss ``hloss * wtop * T[:, 0]`` [J].

    Parameters
    ----------
    plane : ndarray (ny, nz)
        Rises of the plane [K].
    wyz : ndarray (ny, nz)
        Weights of the x-face sum [m^2].
    wy : ndarray (ny,)
        Weights of the bottom sum [m^2].
    wtop : ndarray (ny,)
        Heat capacity of the surface nodes [J/K].
    hloss : ndarray (ny,)
        Convective loss factors of the step [1].
    """
    ny, nz = plane.shape
    if edge:
        s = 0.0
        for j in range(ny):
            for k in range(nz):
                s += wyz[j, k] * plane[j, k]
        out[at] += s
    b = 0.0
    cv = 0.0
    for j in range(ny):
        b += wy[j] * plane[j, nz - 2]
        cv += hloss[j] * wtop[j] * plane[j, 0]
    out[at + 1] += b
    out[at + 2] += cv


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def explicit_step_2d(T, Tn, r, src, hloss):  # pragma: no cover - compiled
    """One explicit-Euler step of the 2-D block (node grid, spacing d).

    Nodes i = 0, nx-1 and k = nz-1 are fixed (0). The surface node k = 0 owns a half-depth dual
    cell: it receives ``src`` [K] and loses ``hloss * T`` by convection.

    Parameters
    ----------
    T, Tn : ndarray (nx, nz)
        Rise at level n and output at level n+1 [K].
    r : float
        kappa dt / d^2 [1]; stable for r <= 1/4 without convection.
    src, hloss : ndarray (nx,)
        Source increment [K] and convective loss factor [1] of each surface node.
    """
    nx, nz = T.shape
    for i in range(1, nx - 1):
        t = T[i, 0]
        Tn[i, 0] = t + r * (T[i + 1, 0] + T[i - 1, 0] + 2.0 * T[i, 1] - 4.0 * t) + src[i] - hloss[i] * t
        for k in range(1, nz - 1):
            t = T[i, k]
            Tn[i, k] = t + r * (T[i + 1, k] + T[i - 1, k] + T[i, k + 1] + T[i, k - 1] - 4.0 * t)


def _stencil_matvec(aP, aE, aW, aN, aS, aT, aB, t, out):  # pragma: no cover - compiled
    """``out = A t`` for the general 7-point operator: row (i, j, k) of ``A t`` is ::

        aP t[i,j,k] - aE t[i+1,j,k] - aW t[i-1,j,k] - aN t[i,j+1,k] - aS t[i,j-1,k]
                    - aT t[i,j,k-1] - aB t[i,j,k+1]

    with coefficients that reach outside the array set to zero (boundary conditions are folded into
    ``aP`` and the right-hand side).

    Compiled twice (:func:`compile_twice`): :func:`stencil_matvec` (parallel over x) and
    :func:`stencil_matvec_serial`.
    """
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


stencil_matvec, stencil_matvec_serial = compile_twice(_stencil_matvec, cache=True, boundscheck=False)


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


@numba.njit(cache=True, fastmath=True, boundscheck=False, inline="always")
def zline_solve(rhs, aT, cp, inv, i, j, dst):  # pragma: no cover - compiled
    """``dst[i, j, :]`` = the z-line block at (i, j) solved for ``rhs`` with the factors of
    :func:`zline_factor` (Thomas algorithm: forward then back substitution; ``rhs`` is overwritten).
    Inlined into :func:`sgs_zline`, which calls it in both sweeps."""
    nz = rhs.shape[0]
    d = rhs[0] * inv[i, j, 0]
    rhs[0] = d
    for k in range(1, nz):
        d = (rhs[k] + aT[i, j, k] * d) * inv[i, j, k]
        rhs[k] = d
    x = rhs[nz - 1]
    dst[i, j, nz - 1] = x
    for k in range(nz - 2, -1, -1):
        x = rhs[k] - cp[i, j, k] * x
        dst[i, j, k] = x


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
            zline_solve(rhs, aT, cp, inv, i, j, v)
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
            zline_solve(rhs, aT, cp, inv, i, j, out)


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


#: grids with fewer nodes than this use the serial kernels (thread start-up dominates below)
PARALLEL_MIN_NODES = 400_000


def _threaded(nodes: int) -> bool:
    """Whether a grid of ``nodes`` nodes takes the parallel build: only when it is large and numba has more
    than one thread (a worker process of a study runs one; its parallel build would only add seconds of
    compilation)."""
    return nodes >= PARALLEL_MIN_NODES and numba.get_num_threads() > 1


def step_kernel(nodes):
    """The explicit-step kernel for a grid of ``nodes`` nodes (parallel for large grids and several threads)."""
    return explicit_step if _threaded(nodes) else explicit_step_serial


def matvec_kernel(nodes):
    """The 7-point operator kernel for a grid of ``nodes`` nodes (parallel for large grids and several
    threads)."""
    return stencil_matvec if _threaded(nodes) else stencil_matvec_serial


def block_kernel_signatures() -> list:
    """(kernel, argument types) of what the 3-D block (:mod:`railtherm_fdm.block3d`) calls with one numba
    thread: the steady and implicit schemes' operator, preconditioner and vector helpers, and the fused
    explicit kernel of large grids. All float64, C-contiguous; counts and plane indices int64."""
    f8, i8 = numba.types.float64, numba.types.int64

    def a(nd):
        return numba.types.Array(f8, nd, "C")

    return [(zline_factor, (a(3),) * 3), (sgs_zline, (a(3),) * 12), (stencil_matvec_serial, (a(3),) * 9),
            (vdot, (a(1), a(1))), (vaxpy, (f8, a(1), a(1))),
            (explicit_two_steps_serial, (a(3), a(3), f8, a(2), a(2), a(2), a(2), a(2), a(1), a(1), i8, a(2), i8))]


_BLOCK_KERNELS_READY = []


def compile_block_kernels() -> None:
    """Compile (or load from numba's disk cache) the 3-D block's kernels (:func:`block_kernel_signatures`) in a
    process's first 3-D solve, when numba runs one thread (a study's worker): the scheme a scene takes depends on
    its level (the main study's circular sources: steady up to level 2, explicit at level 3), so a warm-up at the
    coarsest level would otherwise leave the fused explicit kernel (about 2.5 s on an empty cache) to compile in
    a timed level-3 solve. With a filled cache they load in milliseconds. Several threads: the kernels compile on
    first use (their parallel builds take seconds that a solve which never needs them should not pay).
    A compilation that fails is left to the kernel's first call, which raises it where it matters."""
    if _BLOCK_KERNELS_READY or numba.get_num_threads() > 1:
        return
    for kernel, sig in block_kernel_signatures():
        try:
            kernel.compile(sig)
        except Exception:  # noqa: BLE001 - the kernel's own call reports it in the solve that needs it
            pass
    _BLOCK_KERNELS_READY.append(True)
