"""Steady heat conduction in the frame moving with the contact (seed eq. 16 and its 2-D form).

In the contact frame the body material flows in -x with speed V; the steady temperature rise theta
satisfies (rho c) V theta_,x + lambda (theta_,xx + theta_,zz) = 0 (2-D form), or, dropping the
conduction along x (seed eq. 16, valid at high Péclet numbers), (rho c) V theta_,x + lambda theta_,zz = 0,
with the heat flux q entering at the surface z = 0: ``-lambda theta_,z = q - h theta`` (h: convection
outside the contact, and the contact conductance where one is given), theta = 0 upstream (the
leading side) and at the bottom of the layer, and no conduction through the outflow end.

Discretisation (method of lines on a tensor grid x_i, z_k):

* depth: P1 finite elements on a geometrically graded z-grid (scikit-fem, ``MeshLine``): stiffness
  K_z and consistent mass M_z; the surface flux is the natural boundary term of the z-weak form.
* along x: P1 elements with lumped mass for the conduction along x (scikit-fem), and second-order
  one-sided (upstream) differences for the convection term, i.e. BDF2 in the "time" t = -x / V
  that a material point has spent under the source. The 1-D form is then exactly a BDF2 marching
  scheme; the 2-D form adds the (central) x-conduction.

The assembled system ``[lambda (K_x x M_z) + lambda (M_x x K_z) - rho c V (M_x D_x x M_z) + H] theta = b``
is solved with one sparse LU factorisation. Second order in dx and dz (the tests fit the rate).

References
----------
.. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, section 10.7.
.. [2] J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts, J. Proc. Roy. Soc.
   New South Wales 76 (1942) 203-224.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["ThermalGrid", "thermal_grid", "hat_load", "solve_thermal", "ThermalSolver", "ThermalBody"]


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
    from skfem import Basis, BilinearForm, ElementLineP1, MeshLine, asm

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
    """

    def __init__(self, grid: ThermalGrid, bodies, two_d: bool = True, conductance=None):
        self.grid, self.nb = grid, len(bodies)
        nx, nz = grid.shape
        Kx, Mx = _fe_1d(grid.x)
        Kz, Mz = _fe_1d(grid.z)
        mx = np.asarray(Mx.sum(axis=1)).ravel()  # lumped x-mass
        MxL = sp.diags(mx)
        Dx = _upstream_matrix(grid.x)
        e0 = sp.csr_matrix(([1.0], ([0], [0])), shape=(nz, nz))
        blocks = []
        for b in bodies:
            if not b.speed > 0:
                raise ValueError(f"body speed must be positive for a steady moving-frame solution, got {b.speed!r}")
            A = b.conductivity * sp.kron(MxL, Kz) - b.volumetric_heat * b.speed * sp.kron(MxL @ Dx, Mz)
            if two_d:
                A = A + b.conductivity * sp.kron(Kx, Mz)
            if b.convection:
                A = A + b.convection * sp.kron(MxL, e0)
            blocks.append(A.tocsr())
        N = nx * nz
        A = blocks[0] if self.nb == 1 else sp.block_diag(blocks).tocsr()
        if conductance is not None and self.nb == 2:
            hc = np.asarray(conductance, float) * mx
            surf = np.arange(nx) * nz
            H = sp.csr_matrix((hc, (surf, surf)), shape=(N, N))
            A = A + sp.bmat([[H, -H], [-H, H]])
        fixed = np.zeros((nx, nz), bool)
        fixed[-1, :] = True   # inflow end: bulk temperature
        fixed[:, -1] = True   # bottom of the layer: bulk temperature
        self.free = ~np.tile(fixed.ravel(), self.nb)
        A = A.tocsr()
        self.A = A[self.free][:, self.free].tocsc()
        self.lu = spla.splu(self.A, permc_spec="COLAMD")
        self.N = N
        self.unknowns = int(self.free.sum())
        #: relative residual ||A theta - b|| / ||b|| of the last :meth:`solve` (worst over its loads) [1]
        self.residual = 0.0

    def solve(self, loads):
        """theta of each body, shape (nx, nz) [K], for the nodal surface heat inputs ``loads`` [W/m]."""
        nx, nz = self.grid.shape
        b = np.zeros(self.nb * self.N)
        for j, load in enumerate(loads):
            b[j * self.N + np.arange(nx) * nz] = load
        theta = np.zeros(self.nb * self.N)
        bf = b[self.free]
        theta[self.free] = self.lu.solve(bf)
        nb = float(np.linalg.norm(bf))
        self.residual = float(np.linalg.norm(self.A @ theta[self.free] - bf) / nb) if nb > 0 else 0.0
        return [theta[j * self.N:(j + 1) * self.N].reshape(nx, nz) for j in range(self.nb)]


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
