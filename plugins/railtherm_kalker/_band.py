"""Line preconditioner of the steady-rolling Newton systems: the Jacobian with the rolling operator B cut to
four offsets along x, solved exactly per grid line by a block LU (numba; a plain-Python loop without it).

The cut (:class:`LinePreconditioner`) keeps the upwind pair of offsets (0, -1) and the next balanced pair (+1, -2),
so it keeps the kernel's antisymmetry about -1/2; it is factored once per Newton step in O(N) and solved in O(N)
per GMRES step. docs/kalker.md gives the GMRES steps it saves.

References
----------
.. [1] G.H. Golub, C.F. Van Loan, Matrix Computations, 4th ed., Johns Hopkins, 2013, sec. 4.3 and 4.5
   (banded and block LU). ISBN 978-1-4214-0794-4
"""
from __future__ import annotations

import numpy as np

__all__ = ["LinePreconditioner", "LINE_OFFSETS"]

#: x offsets I - J of the cut (the element J = I - o along the grid line)
LINE_OFFSETS = (1, 0, -1, -2)


try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit
except Exception:  # numba missing: a plain-Python loop (correct, slow)
    def njit(*args, **kwargs):
        return (lambda f: f) if not (len(args) == 1 and callable(args[0])) else args[0]


@njit(cache=True, nogil=True)
def invert_block(M, out):
    """Write the inverse of the 1x1 or 2x2 block ``M`` (the traction components of one element) into ``out``."""
    if M.shape[0] == 1:
        out[0, 0] = 1.0 / M[0, 0]
    else:
        det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
        out[0, 0] = M[1, 1] / det
        out[0, 1] = -M[0, 1] / det
        out[1, 0] = -M[1, 0] / det
        out[1, 1] = M[0, 0] / det


@njit(cache=True, nogil=True)
def _assemble(q, nbr, slipping, zh, fac, r, K):
    """Blocks of M = D1 + D2 B_cut per element e: to itself (A0), and to the positions q[e] + 1, - 1, - 2 on
    its line (Asup, As1, As2); q[e] is element e's position on its grid line, the leading edge first."""
    nc, nin = zh.shape
    A0 = np.zeros((nin, nc, nc))
    Asup = np.zeros((nin, nc, nc))
    As1 = np.zeros((nin, nc, nc))
    As2 = np.zeros((nin, nc, nc))
    S = np.empty((nc, nc))
    for e in range(nin):
        for a in range(nc):
            for b in range(nc):
                d = 1.0 if a == b else 0.0
                S[a, b] = fac[e] * (d - zh[a, e] * zh[b, e]) if slipping[e] else d
        for t in range(K.shape[0]):
            f = nbr[e, t]
            if f < 0:
                continue
            dk = q[f] - q[e]
            for a in range(nc):
                for b in range(nc):
                    acc = 0.0
                    for c in range(nc):
                        acc += S[a, c] * K[t, c, b]
                    val = -r * acc
                    if dk == 0:
                        if slipping[e]:
                            val += (1.0 if a == b else 0.0) - S[a, b]
                        A0[e, a, b] += val
                    elif dk == 1:
                        Asup[e, a, b] += val
                    elif dk == -1:
                        As1[e, a, b] += val
                    else:
                        As2[e, a, b] += val
    return A0, Asup, As1, As2


@njit(cache=True, nogil=True)
def _factor(q, nbr, line, sweep_order, slipping, zh, fac, r, K):
    """Block LU (no pivoting between blocks) of M = D1 + D2 B_cut along each grid line, the leading edge first.

    The cut couples element e to the positions q[e] + d, d in {-2, -1, 0, +1} on its line (its line neighbours
    line[e] = (k - 2, k - 1, k + 1, k + 2) as elements, -1 where none). The lines are factored together in
    ``sweep_order`` (descending x, y inner: memory order). Returns Uinv (diagonal-block inverses), Usup (block
    to k + 1), L1, L2 (blocks to k - 1, k - 2 of the unit lower factor), per element."""
    nc, nin = zh.shape
    A0, Asup, As1, As2 = _assemble(q, nbr, slipping, zh, fac, r, K)
    Uinv = np.zeros((nin, nc, nc))
    L1 = np.zeros((nin, nc, nc))
    L2 = np.zeros((nin, nc, nc))
    M = np.empty((nc, nc))
    for e in sweep_order:
        p1, n1, n2 = line[e, 1], line[e, 2], line[e, 3]
        for a in range(nc):
            for b in range(nc):
                acc = A0[e, a, b]
                if p1 >= 0:
                    for c in range(nc):
                        acc -= L1[e, a, c] * Asup[p1, c, b]
                M[a, b] = acc
        invert_block(M, Uinv[e])
        if n1 >= 0:                              # L_{k+1,k} = (A_{k+1,k} - L_{k+1,k-1} U_{k-1,k}) U_kk^-1
            for a in range(nc):
                for b in range(nc):
                    acc = As1[n1, a, b]
                    if p1 >= 0:
                        for c in range(nc):
                            acc -= L2[n1, a, c] * Asup[p1, c, b]
                    M[a, b] = acc
            for a in range(nc):
                for b in range(nc):
                    acc = 0.0
                    for c in range(nc):
                        acc += M[a, c] * Uinv[e, c, b]
                    L1[n1, a, b] = acc
        if n2 >= 0:                              # L_{k+2,k} = A_{k+2,k} U_kk^-1
            for a in range(nc):
                for b in range(nc):
                    acc = 0.0
                    for c in range(nc):
                        acc += As2[n2, a, c] * Uinv[e, c, b]
                    L2[n2, a, b] = acc
    return Uinv, Asup, L1, L2


@njit(cache=True, nogil=True)
def _solve(v, line, sweep_order, Uinv, Usup, L1, L2):
    """x = (L U)^{-1} v, v and x (nc, nin) indexed by element."""
    nc, nin = v.shape
    y = np.empty((nin, nc))
    for e in sweep_order:
        p2, p1 = line[e, 0], line[e, 1]
        for a in range(nc):
            acc = v[a, e]
            if p1 >= 0:
                for c in range(nc):
                    acc -= L1[e, a, c] * y[p1, c]
            if p2 >= 0:
                for c in range(nc):
                    acc -= L2[e, a, c] * y[p2, c]
            y[e, a] = acc
    x = np.empty((nin, nc))
    t = np.empty(nc)
    for m in range(nin - 1, -1, -1):
        e = sweep_order[m]
        n1 = line[e, 2]
        for a in range(nc):
            acc = y[e, a]
            if n1 >= 0:
                for c in range(nc):
                    acc -= Usup[e, a, c] * x[n1, c]
            t[a] = acc
        for a in range(nc):
            acc = 0.0
            for c in range(nc):
                acc += Uinv[e, a, c] * t[c]
            x[e, a] = acc
    return x.T.copy()


@njit(cache=True, nogil=True)
def _solve2(v, line, sweep_order, Uinv, Usup, L1, L2):
    """:func:`_solve` for two components with the 2 x 2 block products written out (2-3 times faster)."""
    nin = v.shape[1]
    y0, y1 = np.empty(nin), np.empty(nin)
    for e in sweep_order:
        p2, p1 = line[e, 0], line[e, 1]
        a0, a1 = v[0, e], v[1, e]
        if p1 >= 0:
            b0, b1 = y0[p1], y1[p1]
            a0 -= L1[e, 0, 0] * b0 + L1[e, 0, 1] * b1
            a1 -= L1[e, 1, 0] * b0 + L1[e, 1, 1] * b1
        if p2 >= 0:
            b0, b1 = y0[p2], y1[p2]
            a0 -= L2[e, 0, 0] * b0 + L2[e, 0, 1] * b1
            a1 -= L2[e, 1, 0] * b0 + L2[e, 1, 1] * b1
        y0[e], y1[e] = a0, a1
    x = np.empty((2, nin))
    for m in range(nin - 1, -1, -1):
        e = sweep_order[m]
        n1 = line[e, 2]
        a0, a1 = y0[e], y1[e]
        if n1 >= 0:
            b0, b1 = x[0, n1], x[1, n1]
            a0 -= Usup[e, 0, 0] * b0 + Usup[e, 0, 1] * b1
            a1 -= Usup[e, 1, 0] * b0 + Usup[e, 1, 1] * b1
        x[0, e] = Uinv[e, 0, 0] * a0 + Uinv[e, 0, 1] * a1
        x[1, e] = Uinv[e, 1, 0] * a0 + Uinv[e, 1, 1] * a1
    return x


class LinePreconditioner:
    """Exact inverse of the Newton Jacobian with B cut to the x offsets :data:`LINE_OFFSETS`.

    The rolling kernel ``(A[k + 1] - A[k]) / dx`` is antisymmetric about the x offset -1/2. The upwind pair
    (offsets 0 and -1) gives a block-triangular cut, inverted by one sweep
    (:class:`railtherm_kalker.tangential_solver.LocalPreconditioner`); the next balanced pair (+1 and -2) adds the
    next largest coefficients and keeps the cut's antisymmetry. The cut couples each element to its neighbours at
    i - 1, i + 1 and i + 2 on its grid line along x: a block-banded system per line (2 x 2 blocks, ordered from the
    leading edge, two blocks below the diagonal, one above), factored by block LU without pivoting between blocks
    (the diagonal blocks are those of the sweep, and the +1 and -2 offsets are a quarter of the upwind pair). Adding
    the lateral offsets (0, +-1), (-1, +-1) to the upwind pair made GMRES slower.

    Parameters
    ----------
    conv : railtherm_kalker.influence.Convolution
        The rolling operator (its :attr:`near` kernels are used).
    idx : ndarray
        Flat indices of the unknown elements in the (nx, ny) grid (row-major: i along x, j along y).
    """

    def __init__(self, conv, idx):
        nx, ny = conv.shape
        self.nc = nc = conv.ncomp
        rx, ry = conv.near_radius
        nin = idx.size
        pos = np.full(nx * ny, -1, dtype=np.int64)
        pos[idx] = np.arange(nin)
        pos = pos.reshape(nx, ny)
        i, j = np.unravel_index(idx, (nx, ny))
        order = np.lexsort((-i, j))                               # lines along x, each from the leading edge
        self.q = np.empty(nin, dtype=np.int64)
        self.q[order] = np.arange(nin)
        same = j[order]
        self.line = np.full((nin, 4), -1, dtype=np.int64)        # line neighbours at k - 2, k - 1, k + 1, k + 2
        for col, d in enumerate((-2, -1, 1, 2)):
            k = np.arange(nin) + d
            ok = (k >= 0) & (k < nin)
            ok[ok] = same[k[ok]] == same[ok]
            self.line[order[ok], col] = order[k[ok]]
        self.sweep_order = np.lexsort((j, -i)).astype(np.int64)  # descending x, y inner (memory order)
        self.nbr = np.full((nin, len(LINE_OFFSETS)), -1, dtype=np.int64)
        self.K = np.zeros((len(LINE_OFFSETS), nc, nc))
        for t, o in enumerate(LINE_OFFSETS):
            if abs(o) > rx:
                continue
            ii = i - o
            ok = (ii >= 0) & (ii < nx)
            self.nbr[ok, t] = pos[ii[ok], j[ok]]
            for (a, b), k in conv.near.items():
                self.K[t, a, b] = k[rx + o, ry]
        self.factors = None

    def factor_newton(self, slipping, zh, fac, r):
        """Factor M = D1 + D2 B_cut with D2 = -r S, D1 = I - S on slipping elements (S = fac (I - zh zh^T))
        and D1 = 0, D2 = -r I on sticking ones; zh (nc, nin), fac and slipping (nin,)."""
        self.factors = _factor(self.q, self.nbr, self.line, self.sweep_order, np.ascontiguousarray(slipping, dtype=np.bool_),
                               np.ascontiguousarray(zh, dtype=float), np.ascontiguousarray(fac, dtype=float),
                               float(r), self.K)

    def solve(self, v):
        """M^{-1} v for v of shape (nc * nin,) in the solver's component-major layout."""
        v = np.ascontiguousarray(v, dtype=float).reshape(self.nc, -1)
        solve = _solve2 if self.nc == 2 else _solve
        return solve(v, self.line, self.sweep_order, *self.factors).ravel()
