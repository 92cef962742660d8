"""Plane-strain thermoelastic strip in the frame moving with the wheel (seed eq. 15), scikit-fem.

Weak form of ``div sigma - rho V^2 u_,11 = 0`` with ``sigma = C : eps(u) - alpha (3 lambda + 2 mu) theta I``
(seed eq. 15; the thermal term ``alpha(3 lambda + 2 mu) grad theta`` integrated by parts):

    int sigma_el(u) : eps(v) - rho V^2 int u_,1 . v_,1  =  int alpha (3 lambda + 2 mu) theta div v
                                                            + int_Gamma_C t . v

The moving-frame inertia lowers the stiffness by rho V^2 int u_,1 . v_,1 (for V = 10 m/s,
rho V^2 = 7.8e5 Pa, 1e-5 of G: negligible, kept for fidelity). The boundary term of that integration
by parts vanishes on the surface (n_1 = 0) and on the clamped ends. The strip is clamped on the rigid
foundation y = -H and at the ends x = +-L/2 (seed eq. 17); the top y = 0 carries the contact load.
P1 triangles (``ElementVector(ElementTriP1)``), plane strain with the true Lamé constants.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .condense import CondensedStiffness
from .mesh import StripMesh

__all__ = ["ElasticStrip"]


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
        from skfem import Basis, BilinearForm, ElementTriP1, ElementVector, asm
        from skfem.helpers import ddot, sym_grad, trace, eye

        self.strip = strip
        self.lam, self.mu = float(lame_lambda), float(shear_modulus)
        self.rho, self.speed, self.alpha = float(density), float(speed), float(thermal_expansion)
        mesh = strip.mesh
        self.basis = Basis(mesh, ElementVector(ElementTriP1()), intorder=1)
        lam, mu, rv2 = self.lam, self.mu, self.rho * self.speed ** 2

        @BilinearForm
        def stiffness(u, v, w):
            eu = sym_grad(u)
            sig = 2.0 * mu * eu + lam * eye(trace(eu), 2)
            # moving-frame inertia: - rho V^2 u_,1 . v_,1
            return ddot(sig, sym_grad(v)) - rv2 * (u.grad[0][0] * v.grad[0][0] + u.grad[1][0] * v.grad[1][0])

        self.K = asm(stiffness, self.basis).tocsr()
        self.node_dofs = self.basis.nodal_dofs  # (2, n_nodes)
        edges = mesh.facets
        A = sp.coo_matrix((np.ones(edges.shape[1]), (edges[0], edges[1])),
                          shape=(mesh.nvertices, mesh.nvertices)).tocsr()
        self.adjacency = (A + A.T).tocsr()
        self.condensed = CondensedStiffness(self.K, self.node_dofs, self.adjacency, mesh.p,
                                            strip.fixed_nodes, strip.window)
        self.fixed_dofs = self.node_dofs[:, strip.fixed_nodes].ravel()

    @property
    def ndofs(self) -> int:
        """Number of displacement unknowns (constrained ones included)."""
        return self.K.shape[0]

    @property
    def compliance(self) -> np.ndarray:
        return self.condensed.compliance

    def thermal_load(self, theta, intorder: int = 12, depth: float | None = None) -> np.ndarray:
        """Nodal load ``int alpha (3 lambda + 2 mu) theta div v`` of a temperature rise [N].

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
        from skfem import Basis, ElementTriP1, ElementVector, LinearForm, asm
        mesh = self.strip.mesh
        if depth is None:
            elems = np.arange(mesh.nelements)
        else:
            elems = np.nonzero((-mesh.p[1, mesh.t]).min(axis=0) < depth)[0]
        f = np.zeros(self.ndofs)
        if elems.size == 0 or self.alpha == 0.0:
            return f
        beta = self.alpha * (3.0 * self.lam + 2.0 * self.mu)
        basis = Basis(mesh, ElementVector(ElementTriP1()), elements=elems, intorder=intorder)

        @LinearForm
        def load(v, w):
            th = theta(w.x[0], -w.x[1])
            return beta * th * (v.grad[0][0] + v.grad[1][1])

        f = asm(load, basis)
        f[self.fixed_dofs] = 0.0
        return f

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
        from skfem import MeshTri
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
