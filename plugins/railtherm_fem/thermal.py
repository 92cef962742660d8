"""Steady heat conduction in the frame moving with the contact (seed eq. 16 and its 2-D form).

In the contact frame the body material flows in -x with speed V; the steady temperature rise theta
satisfies (rho c) V theta_,x + lambda (theta_,xx + theta_,zz) = 0 (2-D form), or, dropping the
conduction along x (seed eq. 16, valid at high Péclet numbers), (rho c) V theta_,x + lambda theta_,zz = 0,
with the heat flux q entering at the surface z = 0: ``-lambda theta_,z = q - h theta`` (h: convection
outside the contact, and the contact conductance where one is given), theta = 0 upstream and at the
bottom of the layer, and no conduction through the outflow end. P1 elements in depth, upstream BDF2 along
x (:class:`ThermalSolver`); the operator is a sum of Kronecker products of 1-D matrices, solved exactly
through the eigenvectors of the depth problem (one banded x-system per mode, factorised once); a contact
conductance between two bodies breaks that structure and is solved by one sparse LU instead.

References: H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, section 10.7.
J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts, J. Proc. Roy. Soc. New South
Wales 76 (1942) 203-224.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import eigh
from scipy.linalg.lapack import dgbtrf, dgbtrs
from skfem import Basis, BilinearForm, ElementLineP1, MeshLine, asm

__all__ = ["ThermalGrid", "thermal_grid", "bilinear_weights", "hat_load", "solve_thermal", "ThermalSolver", "ThermalBody"]


@dataclass
class ThermalGrid:
    """Tensor grid of the thermal layer.

    Attributes
    ----------
    x : ndarray
        Nodes along the rolling direction, increasing [m]; the last node is the inflow (upstream) end.
    z : ndarray
        Depth nodes, z[0] = 0 (surface) [m].
    """

    x: np.ndarray
    z: np.ndarray

    @property
    def shape(self):
        return (self.x.size, self.z.size)


@dataclass
class ThermalBody:
    """Thermal properties and speed of one body.

    Attributes
    ----------
    conductivity : float
        lambda [W/(m K)].
    volumetric_heat : float
        rho c [J/(m^3 K)].
    speed : float
        Speed of the body's material relative to the contact [m/s], > 0 (flowing in -x).
    convection : float
        Heat transfer coefficient on the free surface [W/(m^2 K)].
    """

    conductivity: float
    volumetric_heat: float
    speed: float
    convection: float = 0.0

    @property
    def diffusivity(self) -> float:
        return self.conductivity / self.volumetric_heat


def _graded(x0: float, x1: float, h0: float, ratio: float) -> np.ndarray:
    """Nodes from x0 towards x1 (either direction) starting with spacing h0, growing by ratio."""
    L = abs(x1 - x0)
    out = [0.0]
    h = h0
    while out[-1] + h < L:
        out.append(out[-1] + h)
        h *= ratio
    if L - out[-1] < 0.3 * (out[-1] - out[-2] if len(out) > 1 else h0):
        out[-1] = L
    else:
        out.append(L)
    out = np.array(out)
    return x0 + np.sign(x1 - x0) * out


def thermal_grid(heated: float, dx: float, x_min: float, x_max: float, dz0: float, depth: float,
                 ratio_x: float = 1.15, ratio_z: float = 1.1, ratio_trail: float | None = None) -> ThermalGrid:
    """Grid with uniform spacing dx on [-heated, heated], geometric growth outside, graded depth.

    Parameters
    ----------
    heated : float
        Half-length of the uniformly resolved heated zone [m].
    dx : float
        Spacing in the heated zone [m].
    x_min, x_max : float
        Outflow (wake) end and inflow end [m], x_min < -heated, x_max > heated.
    dz0 : float
        Depth spacing at the surface [m].
    depth : float
        Depth of the layer [m] (theta = 0 below).
    ratio_x, ratio_z : float
        Growth ratios of the spacing away from the heated zone and from the surface.
    ratio_trail : float, optional
        Growth ratio behind the heated zone (x < -heated, the trail; default ``ratio_x``): a gentler one
        resolves the temperatures behind the patch (scene key ``field``).
    """
    n = max(2, int(round(2 * heated / dx)))
    mid = np.linspace(-heated, heated, n + 1)
    h = mid[1] - mid[0]
    right = _graded(heated, x_max, h * ratio_x, ratio_x)[1:] if x_max > heated else np.empty(0)
    rt = ratio_x if ratio_trail is None else ratio_trail
    left = _graded(-heated, x_min, h * rt, rt)[1:][::-1] if x_min < -heated else np.empty(0)
    x = np.concatenate([left, mid, right])
    z = _graded(0.0, depth, dz0, ratio_z)
    return ThermalGrid(x, z)


def bilinear_weights(x: np.ndarray, z: np.ndarray, xs: np.ndarray, zs: np.ndarray):
    """Nodes and weights of the bilinear (P1 x P1) interpolant on the tensor grid (x, z) at points (xs, zs).

    Returns ``(nodes, weights)``, both shape (4, n): flat indices into values of shape (x.size, z.size)
    (C order) and their weights [1]; a point outside the grid gets weight 0 (the interpolant is 0 there).
    The interpolant at the points is ``(values.ravel()[nodes] * weights).sum(axis=0)``.
    """
    def locate(g, s):
        i = np.clip(np.searchsorted(g, s, side="right") - 1, 0, g.size - 2)
        return i, (s - g[i]) / (g[i + 1] - g[i])

    xs, zs = np.asarray(xs, float).ravel(), np.asarray(zs, float).ravel()
    i, tx = locate(x, xs)
    k, tz = locate(z, zs)
    nz = z.size
    nodes = np.stack([i * nz + k, i * nz + k + 1, (i + 1) * nz + k, (i + 1) * nz + k + 1])
    weights = np.stack([(1.0 - tx) * (1.0 - tz), (1.0 - tx) * tz, tx * (1.0 - tz), tx * tz])
    weights[:, (xs < x[0]) | (xs > x[-1]) | (zs < z[0]) | (zs > z[-1])] = 0.0
    return nodes, weights


def hat_load(x: np.ndarray, q, breaks=None, order: int = 4) -> np.ndarray:
    """Integrals int q(s) phi_i(s) ds of a surface flux against the P1 hat functions of the x-nodes.

    Parameters
    ----------
    x : ndarray
        Increasing nodes [m].
    q : callable
        Vectorised flux q(s) [W/m^2].
    breaks : array_like, optional
        Points where q has a kink or jump [m]; each element is split there (exact for piecewise
        polynomials of degree < 2 order - 1 between breaks).
    order : int
        Gauss-Legendre points per piece.

    Returns
    -------
    ndarray
        Nodal loads [W/m].
    """
    t, wq = np.polynomial.legendre.leggauss(order)
    pts = np.unique(np.concatenate([x, np.asarray([] if breaks is None else breaks, float)]))
    pts = pts[(pts >= x[0]) & (pts <= x[-1])]
    lo, hi = pts[:-1], pts[1:]
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    s = mid[:, None] + half[:, None] * t[None, :]  # (pieces, order)
    qs = q(s.ravel()).reshape(s.shape) * (half[:, None] * wq[None, :])
    j = np.clip(np.searchsorted(x, mid) - 1, 0, x.size - 2)  # element of each piece
    xl, xr = x[j], x[j + 1]
    phi_r = (s - xl[:, None]) / (xr - xl)[:, None]
    load = np.zeros(x.size)
    np.add.at(load, j, np.sum(qs * (1.0 - phi_r), axis=1))
    np.add.at(load, j + 1, np.sum(qs * phi_r, axis=1))
    return load


def _upstream_matrix(x: np.ndarray) -> sp.csr_matrix:
    """d/dx at node i from nodes i, i+1, i+2 (second order, nonuniform); first order at n-2."""
    n = x.size
    rows, cols, vals = [], [], []
    for i in range(n - 1):
        if i + 2 < n:
            h1, h2 = x[i + 1] - x[i], x[i + 2] - x[i + 1]
            c1 = (h1 + h2) / (h1 * h2)
            c2 = -h1 / (h2 * (h1 + h2))
            rows += [i, i, i]
            cols += [i, i + 1, i + 2]
            vals += [-(c1 + c2), c1, c2]
        else:
            h1 = x[i + 1] - x[i]
            rows += [i, i]
            cols += [i, i + 1]
            vals += [-1.0 / h1, 1.0 / h1]
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def _fe_1d(nodes: np.ndarray):
    """P1 stiffness and mass on 1-D nodes (scikit-fem)."""
    mesh = MeshLine(np.asarray(nodes, float))
    basis = Basis(mesh, ElementLineP1())

    @BilinearForm
    def stiff(u, v, w):
        return u.grad[0] * v.grad[0]

    @BilinearForm
    def mass(u, v, w):
        return u * v

    return asm(stiff, basis).tocsr(), asm(mass, basis).tocsr()


class ThermalSolver:
    """Factorised steady moving-frame conduction operator of one or two bodies on the same grid.

    Discretisation (method of lines on a tensor grid x_i, z_k): in depth P1 finite elements on a
    geometrically graded z-grid (scikit-fem, ``MeshLine``), stiffness K_z and consistent mass M_z, the
    surface flux the natural boundary term of the z-weak form; along x P1 elements with lumped mass for
    the conduction along x, and second-order one-sided (upstream) differences for the convection term,
    i.e. BDF2 in the "time" t = -x / V that a material point has spent under the source (the 1-D form is
    exactly a BDF2 marching scheme; the 2-D form adds the central x-conduction). Second order in dx and
    dz (the tests fit the rate).

    The operator of one body is a sum of Kronecker products of 1-D matrices (x outer, z inner):
    ``A = M_x (x) Kz' + G_x (x) M_z`` with ``Kz' = lambda K_z + h e_0 e_0^T`` (conduction in depth and the
    convection at the surface node), ``G_x = lambda K_x - rho c V M_x D_x`` (conduction along x, dropped in
    the 1-D form, and the upstream convection) and M_x the lumped x-mass. Without a contact conductance
    the bodies are uncoupled and each is solved exactly through the generalised eigenvectors of
    (Kz', M_z) (``Phi^T Kz' Phi = diag(mu)``, ``Phi^T M_z Phi = I``, on the nodes above the bottom): in
    that basis the system splits into one banded x-system ``(mu_j M_x + G_x) eta_j = Phi[0, j] load``
    per depth mode (bandwidths 1 below, 2 above), all factorised once at construction (a dense
    eigenproblem of size nz and LAPACK ``gbtrf`` on nx nz rows: O(nz^3 + nx nz), against O((nx nz)^1.5)
    for a sparse LU of the 2-D system; two bodies with equal properties and speed share theirs); each
    :meth:`solve` is then one banded back-substitution and two dense products, O(nx nz^2). Same discrete
    solution as the assembled sparse system (to round-off; tests/test_fem_thermal.py compares them).
    With a contact conductance h_c(x) the surface nodes of the two bodies couple, the Kronecker
    structure is lost, and the assembled system is factorised once by sparse LU.

    Parameters
    ----------
    grid : ThermalGrid
    bodies : sequence of ThermalBody
        One or two bodies (two when a contact conductance couples them).
    two_d : bool
        Include the conduction along x (2-D form); False gives the seed's eq. 16.
    conductance : ndarray, optional
        Contact conductance h_c(x_i) at the surface nodes [W/(m^2 K)] coupling body 0 and body 1:
        body 0 receives h_c (theta_1 - theta_0), body 1 the opposite.

    Attributes
    ----------
    unknowns : int
        Free temperatures of all bodies (the inflow end x = x_max and the bottom z = depth are fixed at 0).
    residual : float
        Relative residual ||A theta - b|| / ||b|| of the last :meth:`solve` over all its loads [1].
    """

    def __init__(self, grid: ThermalGrid, bodies, two_d: bool = True, conductance=None):
        self.grid, self.nb = grid, len(bodies)
        for b in bodies:
            if not b.speed > 0:
                raise ValueError(f"body speed must be positive for a steady moving-frame solution, got {b.speed!r}")
        nx, nz = grid.shape
        Kx, Mx = _fe_1d(grid.x)
        Kz, Mz = _fe_1d(grid.z)
        self._mx = np.asarray(Mx.sum(axis=1)).ravel()      # lumped x-mass [m]
        Dx = _upstream_matrix(grid.x)
        fx, fz = slice(0, nx - 1), slice(0, nz - 1)         # free: all but the inflow end and the bottom
        self._Mz = Mz[fz, fz].toarray()
        self._G, self._Kz = [], []
        for b in bodies:
            G = -b.volumetric_heat * b.speed * (sp.diags(self._mx) @ Dx)
            if two_d:
                G = G + b.conductivity * Kx
            Kzb = b.conductivity * Kz[fz, fz].toarray()
            Kzb[0, 0] += b.convection
            self._G.append(sp.csr_matrix(G)[fx, fx])
            self._Kz.append(Kzb)
        self.N = nx * nz
        self.unknowns = self.nb * (nx - 1) * (nz - 1)
        self.residual = 0.0
        coupled = conductance is not None and self.nb == 2
        self._lu = _SparseCoupled(self, conductance) if coupled else None
        self._modes = None
        if not coupled:
            self._modes = []
            for j, b in enumerate(bodies):
                same = next((k for k in range(j) if bodies[k] == b), None)
                self._modes.append(self._modes[same] if same is not None
                                   else _ModalFactor(self._G[j], self._Kz[j], self._Mz, self._mx[fx]))

    def _apply(self, j: int, theta: np.ndarray) -> np.ndarray:
        """A_j theta of body j on the free nodes, theta shape (nx-1, nz-1) [W/m]."""
        mx = self._mx[:-1]
        return (mx[:, None] * theta) @ self._Kz[j] + (self._G[j] @ theta) @ self._Mz

    def solve(self, loads):
        """theta of each body, shape (nx, nz) [K], for the nodal surface heat inputs ``loads`` [W/m]."""
        nx, nz = self.grid.shape
        loads = [np.asarray(q, float)[:-1] for q in loads]
        out = [np.zeros((nx, nz)) for _ in range(self.nb)]
        if self._lu is not None:
            free = self._lu.solve(np.concatenate([_surface_rhs(q, nz - 1) for q in loads]))
            for j in range(self.nb):
                out[j][:-1, :-1] = free[j * (nx - 1) * (nz - 1):(j + 1) * (nx - 1) * (nz - 1)].reshape(nx - 1, nz - 1)
        else:
            for j in range(self.nb):
                out[j][:-1, :-1] = self._modes[j].solve(loads[j])
        res, rhs = 0.0, 0.0
        for j in range(self.nb):
            r = self._apply(j, out[j][:-1, :-1])
            r[:, 0] -= loads[j]
            if self._lu is not None:
                r[:, 0] += self._lu.coupling(out, j)
            res += float(np.sum(r * r))
            rhs += float(np.sum(loads[j] ** 2))
        self.residual = math.sqrt(res / rhs) if rhs > 0 else 0.0
        return out


class _ModalFactor:
    """Banded LU of every depth mode of one body: ``(mu_j M_x + G_x) eta_j = Phi[0, j] load`` (see
    :class:`ThermalSolver`), the modes stacked one after the other in one banded matrix."""

    def __init__(self, G, Kz, Mz, mx):
        self.mu, self.phi = eigh(Kz, Mz)                 # Phi^T Kz Phi = diag(mu), Phi^T Mz Phi = I
        n, m = G.shape[0], self.mu.size
        band = np.zeros((4, n))                          # LAPACK band storage: band[2 + i - j, j] = G[i, j]
        Gd = sp.dia_matrix(G)
        for off, d in zip(Gd.offsets, Gd.data):
            if not -1 <= off <= 2:
                raise ValueError(f"x-operator has a diagonal at offset {off}, outside the band (-1, 2)")
            band[2 - off] += d
        ab = np.tile(band, (1, m))
        ab[2] += np.repeat(self.mu, n) * np.tile(mx, m)
        for off in (1, 2):                               # no coupling between consecutive modes
            for s in range(off):
                ab[2 - off, s::n] = 0.0
        ab[3, n - 1::n] = 0.0
        self.n, self.m = n, m
        lu, piv, info = dgbtrf(np.vstack([np.zeros((1, ab.shape[1])), ab]), 1, 2)
        if info != 0:
            raise np.linalg.LinAlgError(f"banded LU of the thermal x-operator failed (info = {info})")
        self.lu, self.piv = lu, piv

    def solve(self, load: np.ndarray) -> np.ndarray:
        """Free temperatures, shape (n, m) [K], for the surface load of the free x-nodes [W/m]."""
        rhs = (self.phi[0][:, None] * load[None, :]).ravel()
        eta, info = dgbtrs(self.lu, 1, 2, rhs, self.piv)
        if info != 0:
            raise np.linalg.LinAlgError(f"banded solve of the thermal x-operator failed (info = {info})")
        return eta.reshape(self.m, self.n).T @ self.phi.T


def _surface_rhs(load: np.ndarray, m: int) -> np.ndarray:
    """Right-hand side of one body on its free nodes (x outer, z inner): ``load`` at the surface node."""
    b = np.zeros((load.size, m))
    b[:, 0] = load
    return b.ravel()


class _SparseCoupled:
    """Sparse LU of two bodies coupled by a contact conductance at their surface nodes."""

    def __init__(self, solver: "ThermalSolver", conductance):
        n, m = solver._G[0].shape[0], solver._Mz.shape[0]
        self.hc = np.asarray(conductance, float)[:-1] * solver._mx[:-1]      # [W/(m K)]
        blocks = [sp.kron(sp.diags(solver._mx[:-1]), sp.csr_matrix(Kz)) + sp.kron(G, sp.csr_matrix(solver._Mz))
                  for G, Kz in zip(solver._G, solver._Kz)]
        surf = np.arange(n) * m
        H = sp.csr_matrix((self.hc, (surf, surf)), shape=(n * m, n * m))
        A = sp.block_diag(blocks).tocsr() + sp.bmat([[H, -H], [-H, H]])
        self.lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A")

    def solve(self, b):
        return self.lu.solve(b)

    def coupling(self, theta, j: int) -> np.ndarray:
        """Conductance flux into the surface row of body j's residual [W/m]."""
        d = theta[j][:-1, 0] - theta[1 - j][:-1, 0]
        return self.hc * d


def solve_thermal(grid: ThermalGrid, bodies, loads, *, two_d: bool = True, conductance=None):
    """Steady temperature rise of one or two bodies on the same grid (see :class:`ThermalSolver`).

    Parameters
    ----------
    grid : ThermalGrid
    bodies : sequence of ThermalBody
    loads : sequence of ndarray
        Nodal surface heat inputs of each body (:func:`hat_load` of its flux) [W/m].
    two_d : bool
        2-D form (True) or the seed's 1-D-in-depth eq. 16 (False).
    conductance : ndarray, optional
        Contact conductance at the surface nodes [W/(m^2 K)].

    Returns
    -------
    list of ndarray
        theta of each body, shape (nx, nz) [K].
    """
    return ThermalSolver(grid, bodies, two_d, conductance).solve(loads)
