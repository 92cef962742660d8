"""The backward sweep of :class:`railtherm_kalker.tangential_solver.LocalPreconditioner` and its per-element
blocks from the Newton Jacobian: the sweep compiled by numba when available (numpy otherwise), the blocks in
vectorised numpy."""
from __future__ import annotations

import numpy as np

__all__ = ["sweep", "newton_blocks"]


def _sweep_py(v, minv, coup, order, nb, columns):
    """z_e = Minv_e (v_e - C_e z_nb(e)) for the elements in ``order`` (downstream after upstream)."""
    nc, nin = v.shape
    z = np.zeros((nc, nin))
    for cols in columns:                      # element indices of one grid column, leading edge first
        rhs = v[:, cols].T.copy()             # (m, nc)
        up = nb[cols]
        has = up >= 0
        if has.any():
            rhs[has] -= np.einsum("mab,mb->ma", coup[cols[has]], z[:, up[has]].T)
        z[:, cols] = np.einsum("mab,mb->ma", minv[cols], rhs).T
    return z


try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit

    @njit(cache=True, nogil=True)
    def _sweep_nb(v, minv, coup, order, nb):
        nc, nin = v.shape
        z = np.zeros((nc, nin))
        rhs = np.zeros(nc)
        for k in range(nin):
            e = order[k]
            for a in range(nc):
                rhs[a] = v[a, e]
            u = nb[e]
            if u >= 0:
                for a in range(nc):
                    acc = 0.0
                    for b in range(nc):
                        acc += coup[e, a, b] * z[b, u]
                    rhs[a] -= acc
            for a in range(nc):
                acc = 0.0
                for b in range(nc):
                    acc += minv[e, a, b] * rhs[b]
                z[a, e] = acc
        return z
except Exception:  # numba missing or unusable
    _sweep_nb = None


def _inverse_blocks(M):
    """Inverses of the 1 x 1 or 2 x 2 blocks M (n, nc, nc) by the explicit formula (vectorised)."""
    if M.shape[1] == 1:
        return 1.0 / M
    a, b, c, d = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    det = a * d - b * c
    return np.stack([np.stack([d, -b], axis=-1), np.stack([-c, a], axis=-1)], axis=1) / det[:, None, None]


def newton_blocks(slipping, zh, fac, r, K0, K1):
    """Diagonal-block inverses and upstream coupling blocks of the cut Newton Jacobian ``D1 + D2 B_near``.

    Per element, with S = fac (I - zh zh^T) where slipping and S = I where sticking: D2 = -r S, and
    D1 = I - S (slipping) or 0 (sticking); the blocks are ``(D1 + D2 K0)^{-1}`` and ``D2 K1``, with K0 and K1
    the rolling kernel at the offsets 0 and -1 along x (nc x nc). Vectorised numpy: it runs once per Newton step
    (the main study's kalker runs: 52 calls, 0.03-0.05 s in all), where a compiled one-pass build (ten times faster
    at 200^2 elements) would cost a process 1.4 s of compilation.

    Parameters
    ----------
    slipping : ndarray (nin,) of bool
    zh : ndarray (nc, nin)
        Unit vector of z = p - r s on slipping elements [1].
    fac : ndarray (nin,)
        g / |z| on slipping elements [1].
    r : float
        Scaling of the slip in the projection form [Pa].
    K0, K1 : ndarray (nc, nc)
        Near kernels [1/Pa].

    Returns
    -------
    (minv, coup) : ndarrays (nin, nc, nc)
    """
    slipping = np.ascontiguousarray(slipping, dtype=np.bool_)
    zh = np.ascontiguousarray(zh, dtype=float)
    fac = np.ascontiguousarray(fac, dtype=float)
    nc = zh.shape[0]
    eye = np.eye(nc)
    sl = slipping[:, None, None]
    S = np.where(sl, fac[:, None, None] * (eye[None] - zh.T[:, :, None] * zh.T[:, None, :]), eye[None])
    minv = _inverse_blocks(np.where(sl, eye[None] - S, 0.0) - r * (S @ K0))
    return minv, -r * (S @ K1)


def sweep(v, minv, coup, order, nb, columns):
    """Solve the block upper-triangular (along x) system of the local preconditioner.

    Parameters
    ----------
    v : ndarray (nc, nin)
        Right-hand side.
    minv : ndarray (nin, nc, nc)
        Inverses of the diagonal blocks.
    coup : ndarray (nin, nc, nc)
        Coupling blocks to the upstream neighbour ``nb`` (the element at x + dx).
    order : ndarray (nin,)
        Elements in sweep order (descending x).
    nb : ndarray (nin,)
        Upstream neighbour of each element, -1 when outside the unknowns.
    columns : list of ndarray, or an object with the attribute ``columns``
        The same order grouped by grid column (for the numpy fallback; None with numba).

    Returns
    -------
    ndarray (nc, nin)
    """
    if _sweep_nb is not None:
        return _sweep_nb(np.ascontiguousarray(v), minv, coup, order, nb)
    return _sweep_py(v, minv, coup, order, nb, getattr(columns, "columns", columns))
