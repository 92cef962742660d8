"""The backward sweep of :class:`railtherm_kalker.tangential_solver.LocalPreconditioner` (compiled by numba
when available; a column-by-column numpy loop otherwise)."""
from __future__ import annotations

import numpy as np

__all__ = ["sweep"]


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
    columns : list of ndarray
        The same order grouped by grid column (for the numpy fallback).

    Returns
    -------
    ndarray (nc, nin)
    """
    if _sweep_nb is not None:
        return _sweep_nb(np.ascontiguousarray(v), minv, coup, order, nb)
    return _sweep_py(v, minv, coup, order, nb, columns)
