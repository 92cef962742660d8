"""Right-preconditioned GMRES for the Newton steps of :func:`railtherm_kalker.tangential_solver.solve_tangential`.

No restart, classical Gram-Schmidt repeated on cancellation (Daniel et al.), a Krylov basis grown in blocks, in single
precision for the loose solves (float32 products and basis) and, when a float32 basis stalls at its floor, continued
in double precision on the linear residual (:func:`gmres_single_then_double`).

References
----------
.. [1] Y. Saad, Iterative Methods for Sparse Linear Systems, 2nd ed., SIAM, 2003, sec. 6.5 and 9.3 (right-
   preconditioned GMRES). doi:10.1137/1.9780898718003
.. [2] J.W. Daniel, W.B. Gragg, L. Kaufman, G.W. Stewart, Reorthogonalization and stable algorithms for
   updating the Gram-Schmidt QR factorization, Math. Comp. 30 (1976) 772-795.
   doi:10.1090/S0025-5718-1976-0431641-8
"""
from __future__ import annotations

import numpy as np

__all__ = ["krylov_gmres", "gmres_single_then_double"]

#: Gram-Schmidt is repeated when the new Krylov vector keeps less than this fraction of its norm [1]. At 1/sqrt(2)
#: (Daniel et al.'s choice [2]) 90 % of the steps were repeated, at 0.3 fewer than 8 %, with the same GMRES steps and
#: creep forces to 1e-12 (E&K ellipse, 100^2 and 200^2): the loss of orthogonality between 0.3 and 0.7 does not
#: slow GMRES down here, and the halved orthogonalisation is about 7 % of the tangential stage
REORTHOGONALISE = 0.3

#: rows of the first block of GMRES's Krylov basis (doubled when full) [1]
GMRES_BLOCK = 16

#: GMRES with a float32 basis has stalled when, below STALL_BELOW of the initial residual and after STALL_WINDOW
#: steps at least, its residual estimate fell by less than STALL_RATIO over the last STALL_WINDOW steps: it then
#: continues in double precision from its solution (restarted on the linear residual). At 200^2 longitudinal creepage
#: the last Newton step's GMRES (tolerance 1.2e-5) took 55 or 145 float32 steps depending on round-off in the
#: pressure (1e-12): the estimate crawled from 5e-5 to 1.2e-5 over 95 steps (the float32 basis's orthogonality), where
#: a float64 basis took 50 steps; a double-precision basis in every final step cost 6-9 % of the tangential stage at
#: 100^2
STALL_BELOW, STALL_WINDOW, STALL_RATIO = 1e-3, 10, 0.5

def krylov_gmres(matvec, psolve, b, rtol, maxiter, dtype=np.float64, stall=False):
    """Right-preconditioned GMRES (no restart; classical Gram-Schmidt, repeated when the new vector lost
    more than 1 - :data:`REORTHOGONALISE` of its norm: Kahan-Parlett's "twice is enough").

    ``dtype`` is that of the Krylov basis: float32 for the loose solves whose products are float32 anyway
    (halves the memory traffic of the orthogonalisation, a fifth of a GMRES step's time at 200^2).

    Returns the solution, the iterations and whether it stalled; stops when ``|b - A x| <= rtol |b|`` (true
    residual of the unpreconditioned system, up to round-off), after ``maxiter`` steps, or with ``stall`` when the
    residual estimate stalls (:data:`STALL_BELOW`).
    """
    n = b.size
    beta = float(np.linalg.norm(b))
    if beta == 0.0:
        return np.zeros(n), 0, False
    # the Krylov basis grows in blocks: allocating (and releasing) maxiter rows for the few steps of most solves
    # cost as much as the steps (1.5 ms at 26,700 unknowns for 201 rows against 0.1 ms for 8)
    rows = min(maxiter, GMRES_BLOCK)
    V = np.empty((rows + 1, n), dtype=dtype)
    Z = np.empty((rows, n), dtype=dtype)
    H = np.zeros((maxiter + 1, maxiter))
    cs, sn = np.zeros(maxiter), np.zeros(maxiter)
    g = np.zeros(maxiter + 1)
    g[0] = beta
    V[0] = b / beta
    k = 0
    stalled = False
    for k in range(maxiter):
        if k == Z.shape[0]:
            grow = min(maxiter, 2 * k) - k
            V = np.concatenate([V, np.empty((grow, n), dtype=dtype)])
            Z = np.concatenate([Z, np.empty((grow, n), dtype=dtype)])
        Z[k] = psolve(V[k].astype(float))
        w = matvec(Z[k]).astype(dtype, copy=False)
        wn = float(np.linalg.norm(w))
        h = V[:k + 1] @ w
        w = w - h @ V[:k + 1]
        hn = float(np.linalg.norm(w))
        if hn < REORTHOGONALISE * wn:            # cancellation: orthogonalise once more ("twice is enough")
            h2 = V[:k + 1] @ w
            w = w - h2 @ V[:k + 1]
            h = h + h2
            hn = float(np.linalg.norm(w))
        col = np.append(h.astype(float), hn)     # the Hessenberg column and its rotations in double precision
        for m in range(k):                       # earlier rotations
            t = cs[m] * col[m] + sn[m] * col[m + 1]
            col[m + 1] = -sn[m] * col[m] + cs[m] * col[m + 1]
            col[m] = t
        den = float(np.hypot(col[k], col[k + 1]))
        cs[k], sn[k] = (col[k] / den, col[k + 1] / den) if den > 0 else (1.0, 0.0)
        col[k] = den
        col[k + 1] = 0.0
        H[:k + 2, k] = col
        g[k + 1] = -sn[k] * g[k]
        g[k] = cs[k] * g[k]
        if hn > 0:
            V[k + 1] = w / hn
        if abs(g[k + 1]) <= rtol * beta or hn == 0.0:
            break
        if (stall and k >= 2 * STALL_WINDOW and abs(g[k + 1]) < STALL_BELOW * beta
                and abs(g[k + 1]) > STALL_RATIO * abs(g[k + 1 - STALL_WINDOW])):
            stalled = True
            break
    k += 1
    y = np.linalg.solve(np.triu(H[:k, :k]) + np.diag(np.where(np.diag(H[:k, :k]) == 0, 1.0, 0.0)), g[:k])
    return (y.astype(dtype) @ Z[:k]).astype(float), k, stalled


def gmres_single_then_double(matvec, psolve, b, rtol, maxiter, single):
    """GMRES to ``|b - A x| <= rtol |b|``: with a float32 basis when ``single`` and, if that stalls at its floor,
    continued in double precision on the linear residual (one more product); the solution and the steps (the
    residual's product counted as one)."""
    x, steps, stalled = krylov_gmres(matvec, psolve, b, rtol, maxiter, np.float32 if single else np.float64,
                                     stall=single)
    if not stalled:
        return x, steps
    rest = b - matvec(x)
    nrest = float(np.linalg.norm(rest))
    if nrest == 0.0:
        return x, steps + 1
    dx, more, _ = krylov_gmres(matvec, psolve, rest, rtol * float(np.linalg.norm(b)) / nrest,
                               max(maxiter - steps, 1))
    return x + dx, steps + more + 1
