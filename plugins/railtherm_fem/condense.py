"""Condensation of the strip stiffness onto its contact window (Schur complement / compliance).

The strip's stiffness K is factorised once with the contact-window unknowns ordered *last*
(after a geometric nested-dissection ordering of all other unknowns, which keeps the fill of a 2-D
mesh at O(n log n)). With ``K = L U`` and the window block trailing, the trailing blocks of the
factors are the factors of the Schur complement

    S = K_ww - K_wi K_ii^{-1} K_iw = L_ww U_ww,

the stiffness of the strip seen from its window. Its inverse, the compliance C = S^{-1} (window
displacements per unit nodal force), is a small dense matrix (2m x 2m for m window nodes) obtained
without a single extra solve with K. The same factorisation then solves full-field load cases
(thermal expansion, the final contact forces) at the cost of one triangular solve each.

SuperLU is called with the natural column order (the ordering is ours), no row pivoting
(``diag_pivot_thresh = 0``, K is symmetric positive definite) and ``SymmetricMode``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["nested_dissection", "CondensedStiffness"]


def nested_dissection(adjacency: sp.csr_matrix, coords: np.ndarray, nodes: np.ndarray, leaf: int = 64) -> np.ndarray:
    """Geometric nested-dissection ordering of ``nodes`` (separators last).

    Parameters
    ----------
    adjacency : scipy.sparse.csr_matrix
        Node adjacency of the mesh (symmetric, nonzero where two nodes share an edge).
    coords : ndarray, shape (2, n_nodes)
        Node coordinates [m].
    nodes : ndarray of int
        Nodes to order.
    leaf : int
        Sets smaller than this are not split further.

    Returns
    -------
    ndarray of int
        The nodes in elimination order.
    """
    if nodes.size <= leaf:
        return nodes
    p = coords[:, nodes]
    ext = p.max(axis=1) - p.min(axis=1)
    ax = int(np.argmax(ext))
    med = np.median(p[ax])
    left = p[ax] <= med
    if left.all() or not left.any():
        return nodes
    L, R = nodes[left], nodes[~left]
    ind = np.zeros(adjacency.shape[0])
    ind[R] = 1.0
    sep = (adjacency[L] @ ind) > 0
    return np.concatenate([nested_dissection(adjacency, coords, L[~sep], leaf),
                           nested_dissection(adjacency, coords, R, leaf), L[sep]])


class CondensedStiffness:
    """Factorised stiffness with the window unknowns last; compliance of the window.

    Parameters
    ----------
    K : scipy.sparse matrix, shape (n, n)
        Stiffness of the strip including the constrained unknowns [N/m].
    node_dofs : ndarray, shape (2, n_nodes)
        Unknown numbers (x, y) of every node.
    adjacency : scipy.sparse.csr_matrix
        Node adjacency.
    coords : ndarray, shape (2, n_nodes)
        Node coordinates [m].
    fixed_nodes : ndarray of int
        Nodes with u = 0 (both components).
    window : ndarray of int
        Window nodes (in the order the compliance is wanted).

    Attributes
    ----------
    compliance : ndarray, shape (2m, 2m)
        Window displacements [ux_1..ux_m, uy_1..uy_m] per unit nodal force in the same order [m/N].
    """

    def __init__(self, K, node_dofs, adjacency, coords, fixed_nodes, window):
        n_nodes = coords.shape[1]
        free = np.ones(n_nodes, bool)
        free[fixed_nodes] = False
        free[window] = False
        order = nested_dissection(adjacency, coords, np.nonzero(free)[0])
        self.window = np.asarray(window)
        m = self.window.size
        wdofs = np.concatenate([node_dofs[0, self.window], node_dofs[1, self.window]])
        self.perm = np.concatenate([node_dofs[:, order].T.ravel(), wdofs])
        self.n = K.shape[0]
        iperm = np.full(K.shape[0], -1)
        iperm[self.perm] = np.arange(self.perm.size)
        Kc = K.tocoo()
        keep = (iperm[Kc.row] >= 0) & (iperm[Kc.col] >= 0)
        nf = self.perm.size
        Kp = sp.csc_matrix((Kc.data[keep], (iperm[Kc.row[keep]], iperm[Kc.col[keep]])), shape=(nf, nf))
        self.lu = spla.splu(Kp, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                            options=dict(SymmetricMode=True))
        if not (np.array_equal(self.lu.perm_c[-2 * m:], np.arange(nf - 2 * m, nf))
                and np.array_equal(self.lu.perm_r[-2 * m:], np.arange(nf - 2 * m, nf))):
            raise RuntimeError("SuperLU reordered the window unknowns; cannot read the Schur complement")
        # K symmetric, no pivoting: K = L U with U = D L^T, so S = U_ww^T D_ww^{-1} U_ww and only the
        # trailing block of U is needed (reading U out of SuperLU costs about as much as its fill)
        U = self.lu.U
        Uw = U[-2 * m:, -2 * m:].toarray()
        from scipy.linalg import solve_triangular
        Uinv = solve_triangular(Uw, np.eye(2 * m), lower=False)
        d = np.diag(Uw)
        # C = S^{-1} = U^{-1} D U^{-T}
        self.compliance = (Uinv * d[None, :]) @ Uinv.T
        self.compliance = 0.5 * (self.compliance + self.compliance.T)
        self.fill = int(2 * U.nnz)

    def solve(self, f: np.ndarray) -> np.ndarray:
        """Displacements for the nodal load vector ``f`` (length n, constrained entries ignored) [m]."""
        f = np.asarray(f, dtype=float)
        x = self.lu.solve(f[self.perm])
        u = np.zeros(self.n if f.ndim == 1 else (self.n, f.shape[1]))
        u[self.perm] = x
        return u
