"""Plane-strain thermoelastic strip in the frame moving with the wheel (seed eq. 15).

Weak form of ``div sigma - rho V^2 u_,11 = 0`` with ``sigma = C : eps(u) - alpha (3 lambda + 2 mu) theta I``
(seed eq. 15; the thermal term ``alpha(3 lambda + 2 mu) grad theta`` integrated by parts):

    int sigma_el(u) : eps(v) - rho V^2 int u_,1 . v_,1  =  int alpha (3 lambda + 2 mu) theta div v
                                                            + int_Gamma_C t . v

The moving-frame inertia lowers the stiffness by rho V^2 int u_,1 . v_,1 (for V = 10 m/s,
rho V^2 = 7.8e5 Pa, 1e-5 of G: negligible, kept for fidelity). The boundary term of that integration
by parts vanishes on the surface (n_1 = 0) and on the clamped ends. The strip is clamped on the rigid
foundation y = -H and at the ends x = +-L/2 (seed eq. 17); the top y = 0 carries the contact load.
P1 triangles (``ElementVector(ElementTriP1)``), plane strain with the true Lamé constants. The stiffness
is assembled with array operations (:func:`stiffness_matrix`, equal to scikit-fem's ``asm`` of the form
above to round-off and 10x faster); the thermal load uses scikit-fem's quadrature rules.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import ElementTriP1
from skfem.quadrature import get_quadrature

from .condense import CondensedStiffness
from .mesh import StripMesh
from .thermal import bilinear_weights

__all__ = ["ElasticStrip", "GridThermalLoad", "stiffness_matrix", "node_adjacency"]


class ElasticStrip:
    """Assembled and condensed elastic strip.

    Parameters
    ----------
    strip : StripMesh
        Mesh and window.
    lame_lambda, shear_modulus : float
        Lamé constants lambda and mu [Pa].
    density : float
        Mass density rho [kg/m^3].
    speed : float
        Speed V of the strip relative to the wheel [m/s].
    thermal_expansion : float
        Linear expansion coefficient alpha [1/K].
    """

    def __init__(self, strip: StripMesh, lame_lambda: float, shear_modulus: float, density: float = 0.0,
                 speed: float = 0.0, thermal_expansion: float = 0.0):
        self.strip = strip
        self.lam, self.mu = float(lame_lambda), float(shear_modulus)
        self.rho, self.speed, self.alpha = float(density), float(speed), float(thermal_expansion)
        mesh = strip.mesh
        self.K = stiffness_matrix(mesh.p, mesh.t, self.lam, self.mu, self.rho * self.speed ** 2)
        n = mesh.nvertices
        # unknown numbering of scikit-fem's ElementVector(ElementTriP1()): (x, y) of node i at 2i, 2i+1
        self.node_dofs = np.vstack([2 * np.arange(n), 2 * np.arange(n) + 1])
        self.adjacency = node_adjacency(mesh.t, n)
        self.condensed = CondensedStiffness(self.K, self.node_dofs, self.adjacency, mesh.p,
                                            strip.fixed_nodes, strip.window)
        self.fixed_dofs = self.node_dofs[:, strip.fixed_nodes].ravel()
        self._quadrature = None     # (key, quadrature) of the last heated layer (see _layer_quadrature)

    @property
    def ndofs(self) -> int:
        """Number of displacement unknowns (constrained ones included)."""
        return self.K.shape[0]

    @property
    def nbytes(self) -> int:
        """Estimated memory held [B]: factor fill and stiffness (value and index, 12 B per entry), the
        window compliance and the kept quadrature of the heated layer."""
        quad = self._quadrature[1] if self._quadrature is not None and self._quadrature[1] is not None else {}
        return int(12 * (self.condensed.fill + self.K.nnz) + self.compliance.nbytes
                   + sum(v.nbytes for v in quad.values()))

    @property
    def compliance(self) -> np.ndarray:
        return self.condensed.compliance

    def thermal_load(self, theta, intorder: int = 12, depth: float | None = None) -> np.ndarray:
        """Nodal load ``int alpha (3 lambda + 2 mu) theta div v`` of a temperature rise [N].

        On P1 triangles div v is constant per element, so the load of a node is its hat gradient times
        the element integral of theta, evaluated with scikit-fem's Gauss rule of order ``intorder`` on
        each element. The quadrature points and weights of the elements that meet the heated layer
        depend only on the mesh, ``intorder`` and ``depth``: they are computed once and kept for the
        next call with the same two (the Steps 1-4 loop loads the same layer with a new theta each
        time); each call then costs one evaluation of theta and one sum per element.

        Parameters
        ----------
        theta : callable
            theta(x, z) -> temperature rise [K] at points x [m], depth z = -y [m] (vectorised).
        intorder : int
            Quadrature order on the elements that meet the heated layer (the layer may be thinner
            than the elements: a high order samples it).
        depth : float, optional
            Only elements with a node shallower than this are integrated [m] (theta = 0 below).
        """
        f = np.zeros(self.ndofs)
        if self.alpha == 0.0:
            return f
        q = self._layer_quadrature(int(intorder), None if depth is None else float(depth))
        if q is None:
            return f
        beta = self.alpha * (3.0 * self.lam + 2.0 * self.mu)
        integral = np.sum(np.asarray(theta(q["x"], q["z"]), float) * q["w"], axis=1)      # [K m^2] per element
        f = np.bincount(q["dofs"], weights=(q["grad"] * (beta * integral)).ravel(), minlength=self.ndofs)
        f[self.fixed_dofs] = 0.0
        return f

    def thermal_load_operator(self, grid, intorder: int = 12, depth: float | None = None) -> "GridThermalLoad":
        """The thermal load of a rise given at the nodes of a tensor grid: ``op(theta)`` =
        :meth:`thermal_load` of the bilinear interpolant of ``theta`` (shape (grid.x.size, grid.z.size),
        0 outside the grid).

        The interpolation weights at the Gauss points are computed once: a loop that loads the strip with
        a new temperature field on the same grid then costs a weighted gather and a sum per load.
        """
        q = self._layer_quadrature(int(intorder), None if depth is None else float(depth))
        if q is None or self.alpha == 0.0:
            return GridThermalLoad(None, None, None, None, self.ndofs, self.fixed_dofs)
        nodes, weights = bilinear_weights(grid.x, grid.z, q["x"], q["z"])          # (4, ne nq)
        beta = self.alpha * (3.0 * self.lam + 2.0 * self.mu)
        return GridThermalLoad(nodes, weights * q["w"].ravel(), q["dofs"], beta * q["grad"], self.ndofs,
                               self.fixed_dofs)

    def _layer_quadrature(self, intorder: int, depth: float | None):
        """Quadrature of the elements with a node shallower than ``depth`` (all without it); None if none.

        Returns a dict: ``x``, ``z`` (depth = -y) [m] and ``w`` [m^2] of the Gauss points, shape
        (n_elements, n_points); ``dofs`` (flat) and ``grad`` [1/m], shape (6, n_elements): the x- and
        y-unknowns of the element's three nodes and the matching hat-function gradient components (the
        divergence of each vector basis function). The last one computed is kept (one key: the layer of
        one solve, which the next solve on the same mesh and level finds again).
        """
        key = (intorder, depth)
        if self._quadrature is not None and self._quadrature[0] == key:
            return self._quadrature[1]
        mesh = self.strip.mesh
        t = mesh.t
        elems = np.arange(mesh.nelements) if depth is None else np.nonzero((-mesh.p[1, t]).min(axis=0) < depth)[0]
        out = None
        if elems.size:
            t = t[:, elems]
            x, y = mesh.p[0, t], mesh.p[1, t]                        # (3, ne)
            X, W = get_quadrature(ElementTriP1().refdom, intorder)  # reference points (2, nq), weights (nq,)
            j11, j12, j21, j22 = x[1] - x[0], x[2] - x[0], y[1] - y[0], y[2] - y[0]
            det = j11 * j22 - j12 * j21
            px = x[0][:, None] + j11[:, None] * X[0] + j12[:, None] * X[1]
            py = y[0][:, None] + j21[:, None] * X[0] + j22[:, None] * X[1]
            b = np.stack([y[1] - y[2], y[2] - y[0], y[0] - y[1]]) / det      # dN_i/dx
            c = np.stack([x[2] - x[1], x[0] - x[2], x[1] - x[0]]) / det      # dN_i/dy
            out = dict(x=px, z=-py, w=np.abs(det)[:, None] * W[None, :],
                       dofs=np.concatenate([self.node_dofs[0][t], self.node_dofs[1][t]]).ravel(),
                       grad=np.concatenate([b, c]))
        self._quadrature = (key, out)
        return out

    def solve(self, f: np.ndarray) -> np.ndarray:
        """Displacement field for the nodal load f [m] (constrained unknowns zero)."""
        f = np.array(f, dtype=float)
        f[self.fixed_dofs] = 0.0
        u = self.condensed.solve(f)
        u[self.fixed_dofs] = 0.0
        return u

    def window_load(self, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
        """Global load vector of nodal forces fx, fy [N/m] on the window nodes."""
        f = np.zeros(self.ndofs)
        f[self.node_dofs[0, self.strip.window]] = fx
        f[self.node_dofs[1, self.strip.window]] = fy
        return f

    def stress(self, u: np.ndarray, x, z, theta=None) -> np.ndarray:
        """Stress (sigma_xx, sigma_zz, sigma_xz, sigma_yy) at points (x, z = depth) [Pa].

        ``sigma = C : eps(u) - alpha (3 lambda + 2 mu) theta I`` with eps(u) of the P1 element
        containing each point (plane strain: sigma_yy = lambda tr(eps) - beta theta).
        theta(x, z) gives the temperature rise [K] (None: mechanical stress only).
        """
        mesh = self.strip.mesh
        x = np.asarray(x, float).ravel()
        z = np.asarray(z, float).ravel()
        pts = np.vstack([x, -z])
        elems = mesh.element_finder()(pts[0], pts[1])
        p = mesh.p[:, mesh.t[:, elems]]  # (2, 3, n)
        ux = u[self.node_dofs[0]][mesh.t[:, elems]]
        uy = u[self.node_dofs[1]][mesh.t[:, elems]]
        # P1 gradients
        x1, y1 = p[0, 1] - p[0, 0], p[1, 1] - p[1, 0]
        x2, y2 = p[0, 2] - p[0, 0], p[1, 2] - p[1, 0]
        det = x1 * y2 - x2 * y1
        def grad(f):
            d1, d2 = f[1] - f[0], f[2] - f[0]
            return (d1 * y2 - d2 * y1) / det, (x1 * d2 - x2 * d1) / det
        exx, uxy = grad(ux)
        uyx, eyy = grad(uy)
        exy = 0.5 * (uxy + uyx)
        tr = exx + eyy
        th = np.zeros_like(x) if theta is None else theta(x, z)
        beta = self.alpha * (3.0 * self.lam + 2.0 * self.mu)
        sxx = 2 * self.mu * exx + self.lam * tr - beta * th
        syy = 2 * self.mu * eyy + self.lam * tr - beta * th   # internal y = vertical -> sigma_zz
        sxy = 2 * self.mu * exy                                  # shear; sign flips with z = -y
        szz_out = self.lam * tr - beta * th
        return np.vstack([sxx, syy, -sxy, szz_out])


class GridThermalLoad:
    """Nodal thermal load [N] of a temperature rise given on a tensor grid (:meth:`ElasticStrip.thermal_load_operator`).

    Parameters
    ----------
    nodes, weights : ndarray, shape (4, n_elements n_points) or None
        Grid nodes (flat) of each Gauss point's bilinear interpolant and their weights times the Gauss
        weight [m^2]; None: no heated element (the load is 0).
    dofs : ndarray, shape (6 n_elements,)
        Unknowns of the elements' nodes (x of the three nodes, then y).
    grad : ndarray, shape (6, n_elements)
        alpha (3 lambda + 2 mu) times the matching hat gradients [Pa/(K m)].
    ndofs : int
    fixed_dofs : ndarray
        Constrained unknowns (their load is 0).
    """

    def __init__(self, nodes, weights, dofs, grad, ndofs, fixed_dofs):
        self.nodes, self.weights, self.dofs, self.grad = nodes, weights, dofs, grad
        self.ndofs, self.fixed_dofs = int(ndofs), fixed_dofs

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        """Load vector [N] of the rise ``theta`` [K] on the grid."""
        if self.nodes is None:
            return np.zeros(self.ndofs)
        at_points = np.sum(np.ravel(theta)[self.nodes] * self.weights, axis=0)             # [K m^2]
        integral = at_points.reshape(self.grad.shape[1], -1).sum(axis=1)                     # per element
        f = np.bincount(self.dofs, weights=(self.grad * integral).ravel(), minlength=self.ndofs)
        f[self.fixed_dofs] = 0.0
        return f


def node_adjacency(t: np.ndarray, n_nodes: int) -> sp.csr_matrix:
    """Symmetric node adjacency (nonzero where two nodes share a triangle edge) of a mesh ``t`` (3, n_el)."""
    i = np.concatenate([t[0], t[1], t[2], t[1], t[2], t[0]])
    j = np.concatenate([t[1], t[2], t[0], t[0], t[1], t[2]])
    A = sp.csr_matrix((np.ones(i.size), (i, j)), shape=(n_nodes, n_nodes))
    A.data[:] = 1.0
    return A


def stiffness_matrix(p: np.ndarray, t: np.ndarray, lam: float, mu: float, rv2: float = 0.0) -> sp.csr_matrix:
    """Plane-strain P1 stiffness with the moving-frame term, assembled with array operations.

    The bilinear form ``int sigma(u) : eps(v) - rho V^2 (u_,1 . v_,1)`` on linear triangles (constant
    strain), unknowns numbered as scikit-fem's ``ElementVector(ElementTriP1())`` (x and y of node i at
    2i and 2i+1); equal to ``skfem.asm`` of that form (tests/test_fem_mesh.py), about 5x faster.

    Parameters
    ----------
    p : ndarray, shape (2, n_nodes)
        Node coordinates [m].
    t : ndarray, shape (3, n_elements)
        Triangles (any orientation).
    lam, mu : float
        Lamé constants [Pa].
    rv2 : float
        rho V^2 [Pa] of the moving frame.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (2 n_nodes, 2 n_nodes)
        [N/m] (per unit width).
    """
    x, y = p[0, t], p[1, t]                       # (3, ne)
    # gradients of the hat functions: grad N_i = (b_i, c_i) / (2 A_signed)
    b = np.stack([y[1] - y[2], y[2] - y[0], y[0] - y[1]])
    c = np.stack([x[2] - x[1], x[0] - x[2], x[1] - x[0]])
    two_a = x[0] * b[0] + x[1] * b[1] + x[2] * b[2]
    area = 0.5 * np.abs(two_a)
    b = b / two_a
    c = c / two_a
    bb = b[:, None, :] * b[None, :, :]            # (3, 3, ne): b_i b_j
    cc = c[:, None, :] * c[None, :, :]
    bc = b[:, None, :] * c[None, :, :]            # b_i c_j
    cb = c[:, None, :] * b[None, :, :]            # c_i b_j
    kxx = (lam + 2 * mu - rv2) * bb + mu * cc
    kyy = (lam + 2 * mu) * cc + (mu - rv2) * bb
    kxy = lam * bc + mu * cb                      # row x of node i, column y of node j
    kyx = lam * cb + mu * bc
    ke = np.stack([np.stack([kxx, kxy]), np.stack([kyx, kyy])]) * area  # (2, 2, 3, 3, ne)
    rows = 2 * t[None, None, :, None, :] + np.arange(2)[:, None, None, None, None]
    cols = 2 * t[None, None, None, :, :] + np.arange(2)[None, :, None, None, None]
    rows, cols = np.broadcast_to(rows, ke.shape), np.broadcast_to(cols, ke.shape)
    n = 2 * p.shape[1]
    return sp.csr_matrix((ke.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n))
