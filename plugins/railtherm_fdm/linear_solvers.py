"""Linear solvers of the finite-difference block (3-D and 2-D).

* :func:`backward_euler_operator` -- the implicit scheme's operator on the node grid, and
  :class:`BackwardEuler`, which advances the block one step with it (CG with the z-line Gauss-Seidel
  preconditioner, or a sparse LU factorised once);
* :func:`cg` -- preconditioned conjugate gradients for that SPD operator;
* :func:`gmres` -- right-preconditioned restarted GMRES (the steady 3-D scheme);
* :func:`stencil_matrix` -- the 2-D operator as a sparse matrix (LU); :func:`zero_couplings` -- the
  empty neighbour coefficients an assembly fills.

References
----------
.. [1] Y. Saad, Iterative Methods for Sparse Linear Systems, 2nd ed., SIAM, 2003.
   doi:10.1137/1.9780898718003
"""
from __future__ import annotations

import math

import numpy as np
from scipy.sparse import diags
from scipy.sparse.linalg import splu

from . import kernels as K

__all__ = ["backward_euler_operator", "BackwardEuler", "CG_RTOL", "cg", "gmres", "stencil_matrix", "zero_couplings"]


def zero_couplings(shape) -> tuple[np.ndarray, ...]:
    """The six neighbour coefficients ``aE, aW, aN, aS, aT, aB`` of a 7-point operator (convention of
    :mod:`.kernels`), zero-filled float arrays of ``shape`` (nx, ny, nz) for an assembly to fill [W/K]."""
    return tuple(np.zeros(shape) for _ in range(6))


def backward_euler_operator(nx, ny, nz, d, wy, wz, lam, rc, dt):
    """Backward-Euler operator (rho c V/dt + K) on the node grid; fixed nodes are identity rows.

    The 2-D block uses it with one lateral node of unit width (``ny = 1``, ``wy = [1]``): the 3-D
    operator is then the 2-D one per unit width.

    Parameters
    ----------
    nx, ny, nz : int
        Nodes along x, y and z.
    d : float
        Node spacing [m].
    wy, wz : ndarray
        Lateral and depth widths of the nodes' dual cells [m].
    lam, rc : float
        Conductivity [W/(m K)] and volumetric heat capacity [J/(m^3 K)].
    dt : float
        Time step [s].

    Returns
    -------
    dict
        Coefficient arrays ``aP, aE, aW, aN, aS, aT, aB`` (convention of :mod:`.kernels`) and
        ``mass`` (rho c V / dt) [W/K], shape (nx, ny, nz).
    """
    shape = (nx, ny, nz)
    wx = d
    vol = wx * wy[:, None] * wz[None, :]                             # (ny, nz)
    gx = lam * wy[:, None] * wz[None, :] / d                         # x-conductances (ny, nz)
    gyf = lam * wx * wz[None, :] / d * np.ones((ny - 1, 1))          # between j and j+1 (ny-1, nz)
    gzf = lam * wx * wy[:, None] / d * np.ones((1, nz - 1))          # between k and k+1 (ny, nz-1)
    aE, aW, aN, aS, aT, aB = zero_couplings(shape)
    mass = np.zeros(shape)
    mass[:] = rc * vol[None] / dt
    aE[:] = gx[None]
    aW[:] = gx[None]
    aN[:, :-1, :] = gyf[None]
    aS[:, 1:, :] = gyf[None]
    aB[:, :, :-1] = gzf[None]
    aT[:, :, 1:] = gzf[None]
    aP = mass + aE + aW + aN + aS + aT + aB                          # conductances to fixed nodes included
    fixed = np.zeros(shape, dtype=bool)
    fixed[0] = fixed[-1] = True
    fixed[:, :, -1] = True
    # decouple fixed nodes (value 0): drop couplings to and from them, identity rows
    aE[:-1][fixed[1:]] = 0.0
    aW[1:][fixed[:-1]] = 0.0
    aB[:, :, :-1][fixed[:, :, 1:]] = 0.0
    aE[-1] = 0.0
    aW[0] = 0.0
    for arr in (aE, aW, aN, aS, aT, aB):
        arr[fixed] = 0.0
    aP[fixed] = 1.0
    mass[fixed] = 0.0
    return {"aP": aP, "aE": aE, "aW": aW, "aN": aN, "aS": aS, "aT": aT, "aB": aB, "mass": mass}


#: relative residual ||r|| / ||b|| to which each implicit step's CG solve is iterated [1]; a step that
#: stops above it (after ``maxiter`` iterations) makes the run not converged
CG_RTOL = 1e-12


def cg(coef, rhs, x, work, rtol=CG_RTOL, maxiter=500):
    """Preconditioned conjugate gradients (z-line SGS) for the SPD implicit operator, in place on x.

    Returns (iterations, final relative residual ||rhs - A x|| / ||rhs||); converged when the residual
    is <= ``rtol``.
    """
    r, z, p, Ap = work
    c = (coef["aP"], coef["aE"], coef["aW"], coef["aN"], coef["aS"], coef["aT"], coef["aB"])
    f = lambda arr: arr.reshape(-1)  # noqa: E731
    matvec = K.matvec_kernel(x.size)
    matvec(*c, x, Ap)
    np.subtract(rhs, Ap, out=r)
    bnorm = math.sqrt(K.vdot(f(rhs), f(rhs))) or 1.0
    scratch = np.empty_like(x)
    fac = coef.get("_factors")
    if fac is None:
        fac = coef["_factors"] = K.zline_factor(coef["aP"], coef["aT"], coef["aB"])
    K.sgs_zline(*c, *fac, r, z, scratch)
    p[:] = z
    rz = K.vdot(f(r), f(z))
    res = math.sqrt(K.vdot(f(r), f(r))) / bnorm
    it = 0
    while res > rtol and it < maxiter:
        matvec(*c, p, Ap)
        alpha = rz / K.vdot(f(p), f(Ap))
        K.vaxpy(alpha, f(p), f(x))
        K.vaxpy(-alpha, f(Ap), f(r))
        res = math.sqrt(K.vdot(f(r), f(r))) / bnorm
        it += 1
        if res <= rtol:
            break
        K.sgs_zline(*c, *fac, r, z, scratch)
        rz_new = K.vdot(f(r), f(z))
        p *= rz_new / rz
        p += z
        rz = rz_new
    return it, res


#: GMRES gives up when STALL_CYCLES restart cycles have not reduced the residual below STALL_FACTOR of what
#: it was before them: at that rate it could not reach its tolerance within ``maxiter`` anyway (a hostile
#: scene -- conductivity 1e4 W/mK on a 100:1 patch -- took 400 steps and 31 s to fail; now 3 cycles)
STALL_CYCLES = 2
STALL_FACTOR = 0.9


def gmres(matvec, precond, b, x0, *, rtol=1e-11, restart=30, maxiter=2000):
    """Right-preconditioned restarted GMRES with modified Gram-Schmidt.

    Solves ``A x = b`` for flat float arrays; ``matvec(v)`` returns ``A v`` and ``precond(v)`` an
    approximation of ``A^{-1} v`` (both new flat arrays). Stops when ``||b - A x|| <= rtol ||b||``, or
    (not converged) when :data:`STALL_CYCLES` restart cycles have reduced the residual by less than
    :data:`STALL_FACTOR`.

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
    bnorm = np.sqrt(K.vdot(b, b)) or 1.0
    r = b - matvec(x)
    beta = np.sqrt(K.vdot(r, r))
    its = 0
    V = np.empty((restart + 1, n))
    cycles = [beta]
    while beta > rtol * bnorm and its < maxiter:
        if len(cycles) > STALL_CYCLES and cycles[-1] > STALL_FACTOR * cycles[-1 - STALL_CYCLES]:
            break                                   # stagnated: report the residual, not converged
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
                hij = K.vdot(w, V[i])
                H[i, j] = hij
                K.vaxpy(-hij, V[i], w)
            hn = np.sqrt(K.vdot(w, w))
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
            K.vaxpy(y[i], V[i], u)
        x += precond(u)
        r = b - matvec(x)
        beta = np.sqrt(K.vdot(r, r))
        cycles.append(beta)
    return x, its, beta / bnorm


def stencil_matrix(coef, shape):
    """The 5-point operator of ``coef`` (3-D layout with one lateral node) as a CSC matrix."""
    nx, nz = shape
    n = nx * nz
    f = lambda k: coef[k].reshape(-1)  # noqa: E731
    east = f("aE")[:-nz]          # row (i, k) -> (i+1, k)
    west = f("aW")[nz:]           # row (i, k) -> (i-1, k)
    bot = f("aB")[:-1].copy()     # row (i, k) -> (i, k+1)
    top = f("aT")[1:].copy()      # row (i, k) -> (i, k-1)
    bot[nz - 1::nz] = 0.0         # no coupling across columns
    top[nz - 1::nz] = 0.0
    return diags([f("aP"), -east, -west, -bot, -top], [0, nz, -nz, 1, -1], shape=(n, n), format="csc")


class BackwardEuler:
    """Backward-Euler steps of a transient block on its node grid (convection lagged).

    Parameters
    ----------
    coef : dict
        :func:`backward_euler_operator` of the node grid.
    capacity : float or ndarray (ny,)
        Heat capacity of a surface node per unit rise [J/K].
    dt : float
        Time step [s].
    lu : bool
        Solve each step with a sparse LU factorised once (2-D block) instead of CG.
    """

    def __init__(self, coef, capacity, dt, *, lu=False):
        self.coef, self.capacity, self.dt = coef, capacity, dt
        self.iterations, self.worst, self.failed = 0, 0.0, 0
        shape = coef["aP"].shape
        if lu:
            self._lu = splu(stencil_matrix(coef, (shape[0], shape[2])), permc_spec="MMD_AT_PLUS_A")
        else:
            self._lu = None
            self._work = [np.zeros(shape) for _ in range(4)]

    def step(self, T, src, hloss) -> None:
        """Advance the rises ``T`` (nx, ny, nz) in place by one step with the surface source increments
        ``src`` [K] and loss factors ``hloss`` [1] of shape (nx, ny)."""
        rhs = self.coef["mass"] * T
        rhs[:, :, 0] += self.capacity * (src - hloss * T[:, :, 0]) / self.dt
        rhs[0] = rhs[-1] = 0.0
        rhs[:, :, -1] = 0.0
        if self._lu is not None:
            T[:] = self._lu.solve(rhs.reshape(-1)).reshape(T.shape)
            return
        it, res = cg(self.coef, rhs, T, self._work)
        self.iterations += it
        self.worst = max(self.worst, res)
        self.failed += res > CG_RTOL

    def diagnostics(self) -> dict:
        """``linear_solver`` and the CG counts; ``converged`` when every step's CG met :data:`CG_RTOL`
        (an LU solve is direct: 0 iterations)."""
        return {"linear_solver": "lu" if self._lu is not None else "cg", "cg_iterations": self.iterations,
                "cg_worst_residual": self.worst, "cg_tolerance": CG_RTOL, "cg_failed_steps": int(self.failed),
                "converged": bool(self.failed == 0), "iterations": int(self.iterations),
                "residual": float(self.worst)}
