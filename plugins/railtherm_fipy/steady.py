"""Steady heat conduction in the frame moving with the contact, solved with FiPy.

In the frame of the contact the material flows with velocity ``u = (-V, 0, 0)`` (entering at ``x = +a``).
The rise ``T`` above the bulk temperature obeys

    kappa laplace(T) - div(u T) = 0                                     (1)

with the frictional flux on the patch, convection ``h`` outside it, ``T = 0`` at the inflow, zero
gradient at the outflow and insulated lateral and deep boundaries (so the outflow carries the heat put in,
which :meth:`MovingFrameSolver.solve` reports as ``energy_balance``). FiPy's sign convention (checked
against its ``exponential1D`` example in the tests): ``DiffusionTerm(kappa) - ConvectionTerm(u) == 0`` is
(1). The surface temperature is the face value of the finite-volume solution. Boundary terms and face
values: docs/NOTES.md, "FiPy steady solve".
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from railtherm import SolverError

from .mesh import MovingFrameMesh
from .solvers import assemble, import_fipy, lu_factor, make_solver, solve_checked

#: 3-D meshes up to this size are solved by sparse LU, larger ones by GMRES + ILU. Measured (2 loaded
#: cores): Pe 0.1, 15 200 cells: LU 1.1 s, GMRES + ILU 0.5 s; Pe 6 000, 49 680 cells: LU 4.8 s,
#: GMRES + ILU 2.1 s.
LU_MAX_CELLS_3D = 20_000

#: convection schemes (option ``scheme``) -> FiPy term class name
SCHEMES = {
    "power-law": "PowerLawConvectionTerm",
    "upwind": "UpwindConvectionTerm",
    "exponential": "ExponentialConvectionTerm",
    "hybrid": "HybridConvectionTerm",
    "central": "CentralDifferenceConvectionTerm",
}


def convection_term(scheme: str):
    """FiPy convection term class of ``scheme`` (a key of :data:`SCHEMES`)."""
    fp = import_fipy()
    try:
        return getattr(fp, SCHEMES[scheme])
    except KeyError:
        raise ValueError(f"unknown convection scheme {scheme!r}: one of {sorted(SCHEMES)}") from None


class MovingFrameSolver:
    """FiPy mesh, unknown and linear solver of one body's moving-frame problem (1).

    Build once per body and call :meth:`solve` for each surface flux (e.g. each strip of an
    ellipse): the FiPy mesh, the constrained unknown and the solver are re-used; the equation is
    rebuilt on every call (FiPy issue #1223: a cached convection stencil is not rebuilt when
    coefficients change). The LU solver re-uses its factorisation when FiPy assembles an identical
    matrix (same mesh, speed and convection mask), so many strips cost one factorisation.

    Parameters
    ----------
    mesh : MovingFrameMesh
        From :func:`railtherm_fipy.mesh.moving_frame_mesh` (2-D when ``mesh.y_edges`` is None).
    speed : float
        Speed of the body's surface relative to the contact [m/s] (material flows towards -x).
    material : railtherm.Material
        ``conductivity`` [W/(m K)], ``density`` [kg/m^3], ``specific_heat`` [J/(kg K)].
    scheme : str
        Convection scheme, a key of :data:`SCHEMES`.
    solver : {"lu", "gmres"}, optional
        Default LU in 2-D and for 3-D meshes up to :data:`LU_MAX_CELLS_3D` cells, else GMRES + ILU.
    tolerance : float, optional
        Relative residual tolerance of the linear solve [1].
    """

    def __init__(self, mesh: MovingFrameMesh, speed: float, material, *, scheme: str = "power-law",
                 solver: str | None = None, tolerance: float | None = None):
        fp = import_fipy()
        self.mesh, self.speed, self.material, self.scheme = mesh, float(speed), material, scheme
        self.three_d = mesh.y_edges is not None
        self.Term = convection_term(scheme)
        self.dxs, self.dzs = np.diff(mesh.x_edges), np.diff(mesh.z_edges)
        nx, nz = self.dxs.size, self.dzs.size
        if self.three_d:
            self.dys = np.diff(mesh.y_edges)
            m = fp.Grid3D(dx=self.dxs, dy=self.dys, dz=self.dzs)
            surface = m.facesFront.value          # z-min (FiPy's z = depth)
            self.velocity = (-self.speed, 0.0, 0.0)
            self.surface_shape = (nx, self.dys.size)
        else:
            self.dys = None
            m = fp.Grid2D(dx=self.dxs, dy=self.dzs)
            surface = m.facesBottom.value         # y-min (FiPy's y = depth)
            self.velocity = (-self.speed, 0.0)
            self.surface_shape = (nx,)
        self.fipy_mesh = m
        # surface faces are numbered like the cells below them (x fastest, then y)
        self.surface_ids = np.flatnonzero(surface)
        self.T = fp.CellVariable(mesh=m, value=0.0)
        self.T.constrain(0.0, where=m.facesRight)            # inflow at x = a + margin: bulk
        self.T.faceGrad.constrain(0.0, where=m.facesLeft)    # outflow: zero gradient
        if solver is None:  # LU where its fill stays small (all 2-D, small 3-D), else GMRES + ILU
            solver = "gmres" if (self.three_d and mesh.cells > LU_MAX_CELLS_3D) else "lu"
        self.solver = make_solver(solver, tolerance)
        # depth-first cell numbering for the LU's minimum-degree ordering (see solvers.lu_factor)
        ids = np.arange(int(np.prod([d.size for d in (self.dxs, self.dys, self.dzs) if d is not None])))
        self.order = ids.reshape(-1, nx).T.ravel() if not self.three_d else \
            ids.reshape(nz, self.dys.size, nx).transpose(2, 1, 0).ravel()
        if solver == "lu":
            self.solver.order = self.order
        self.x = 0.5 * (mesh.x_edges[1:] + mesh.x_edges[:-1])
        self.y = None if not self.three_d else 0.5 * (mesh.y_edges[1:] + mesh.y_edges[:-1])
        self.z = 0.5 * (mesh.z_edges[1:] + mesh.z_edges[:-1])

    def _faces(self, values: np.ndarray) -> np.ndarray:
        out = np.zeros(self.fipy_mesh.numberOfFaces)
        out[self.surface_ids] = values.T.ravel() if self.three_d else values
        return out

    def equation(self, flux: np.ndarray, convection: float, contact: np.ndarray):
        """A fresh FiPy equation for this flux and convection (FiPy issue #1223: never re-used)."""
        fp = import_fipy()
        m = self.fipy_mesh
        mat = self.material
        lam, rho_c = mat.conductivity, mat.density * mat.specific_heat
        kappa = lam / rho_c
        n = m.faceNormals
        eq = (fp.DiffusionTerm(coeff=kappa) - self.Term(coeff=self.velocity)
              + (fp.FaceVariable(mesh=m, value=self._faces(flux) / rho_c) * n).divergence)
        if convection > 0:
            h_eff = 1.0 / (1.0 / convection + self.dzs[0] / (2.0 * lam))
            conv = self._faces(np.where(contact, 0.0, h_eff))
            eq = eq - fp.ImplicitSourceTerm(coeff=(fp.FaceVariable(mesh=m, value=conv / rho_c) * n).divergence)
        return eq == 0

    def solve_strips(self, fluxes: np.ndarray, contacts: np.ndarray, *, convection: float = 0.0,
                     keep: int | None = None, tolerance: float = 1e-10) -> dict:
        """Solve many 2-D problems that differ only in their surface flux (strips of an ellipse).

        FiPy assembles the system three times: the matrix ``A0`` and right-hand side ``b0`` for
        zero flux, the right-hand side for a unit flux on every surface face (the difference ``d``
        is the diagonal map from a surface flux to its cell) and, when ``convection > 0``, the
        matrix with convection on every surface face (its diagonal difference is the convective
        term of each surface cell). Every strip's system is then ``A0 + diag(h (1 - contact_j))``
        and ``b0 + d q_j``; one sparse LU factorisation per distinct contact mask (one when
        ``convection`` is 0) solves all strips with that mask (plus one step of iterative
        refinement), and the relative residual of every strip is checked.

        Parameters
        ----------
        fluxes : ndarray, shape (ns, nx)
            Flux into the body on the surface faces of each strip [W/m^2].
        contacts : ndarray of bool, shape (ns, nx)
            Faces in contact (no convection there).
        convection : float
            Heat transfer coefficient outside the contact [W/(m^2 K)].
        keep : int, optional
            Index of the strip whose whole field ``T`` is returned (e.g. the centre strip).
        tolerance : float
            Largest accepted relative residual ``||A x - b|| / ||b||`` [1].

        Returns
        -------
        dict
            ``surface`` (ns, nx) [K rise], ``T`` (nx, nz) of strip ``keep`` (or None), ``z``,
            ``iterations`` (1 + refinement steps), ``residual`` (largest over the strips),
            ``converged``, ``factorisations``, ``energy_balance`` (ns,) [1], ``cells``.
        """
        if self.three_d:
            raise ValueError("solve_strips is for 2-D meshes")
        fluxes = np.atleast_2d(np.asarray(fluxes, dtype=float))
        contacts = np.atleast_2d(np.asarray(contacts, dtype=bool))
        ns, nx = fluxes.shape
        nz = self.dzs.size
        # identical strips (e.g. y and -y of a symmetric source) are solved once
        rows = {}
        first = np.array([rows.setdefault(fluxes[j].tobytes() + contacts[j].tobytes(), j) for j in range(ns)])
        unique = np.unique(first)
        keys = {j: contacts[j].tobytes() if convection > 0 else b"" for j in unique}   # one LU per contact mask
        X = np.zeros((nx * nz, ns))
        residual, factorisations = 0.0, 0
        # FiPy assembles: A0, b0 (no flux, no convection), b1 (unit flux), A_h (convection on every
        # surface face). Assembly is linear in the flux and in the convection coefficient and both
        # act on the surface cells only (the first nx cells), so every strip's system follows exactly.
        no_contact = np.zeros(nx, dtype=bool)
        A0, b0 = assemble(self.equation(np.zeros(nx), 0.0, no_contact), self.T)
        _, b1 = assemble(self.equation(np.ones(nx), 0.0, no_contact), self.T)
        d = (b1 - b0)[:nx]
        if convection > 0:
            Ah, _ = assemble(self.equation(np.zeros(nx), convection, no_contact), self.T)
            h_diag = (Ah - A0).diagonal()[:nx]
        for key in dict.fromkeys(keys.values()):
            cols = [j for j in unique if keys[j] == key]
            A = A0
            if convection > 0:
                A = (A0 + sp.diags(np.r_[np.where(contacts[cols[0]], 0.0, h_diag), np.zeros(nx * (nz - 1))])).tocsr()
            B = np.repeat(b0[:, None], len(cols), axis=1)
            B[:nx] += d[:, None] * fluxes[cols].T
            Xg, r = self._refined_solve(A, B)
            factorisations += 1
            residual = max(residual, float(r.max()))
            X[:, cols] = Xg
        X = X[:, first]
        if not (np.all(np.isfinite(X)) and residual <= tolerance):
            raise SolverError(f"FiPy 2-D strip solves: relative residual {residual:.3g} > {tolerance:g} "
                              f"or non-finite solution")
        T = X.reshape(nz, nx, ns)
        surface, balance = self._strip_surfaces(T, fluxes, contacts, convection)
        return {"surface": surface, "T": None if keep is None else T[:, :, keep].T, "x": self.x, "z": self.z,
                "iterations": 2, "residual": residual, "converged": True, "factorisations": factorisations,
                "energy_balance": balance, "cells": nx * nz}

    def _refined_solve(self, A, B):
        """Solve A X = B for the columns of B with one sparse LU factorisation and one step of iterative
        refinement: X and each column's relative residual."""
        lu = lu_factor(A, self.order)
        # column by column: SciPy's SuperLU solve of a 2-D right-hand side is ~10x slower
        Xg = np.column_stack([lu.solve(B[:, k]) for k in range(B.shape[1])])
        R = A @ Xg - B
        Xg -= np.column_stack([lu.solve(R[:, k]) for k in range(B.shape[1])])
        bn = np.linalg.norm(B, axis=0)
        return Xg, np.linalg.norm(A @ Xg - B, axis=0) / np.where(bn > 0, bn, 1.0)

    def _strip_surfaces(self, T, fluxes, contacts, convection):
        """Surface rise (ns, nx) of every strip from its cell values T (nz, nx, ns), and its energy balance
        (heat advected and convected out / heat put in) [1]."""
        lam = self.material.conductivity
        rho_c = self.material.density * self.material.specific_heat
        top = T[0].T                                   # (ns, nx)
        dz1 = self.dzs[0]
        surface = np.where(contacts, top + fluxes * dz1 / (2.0 * lam), top / (1.0 + convection * dz1 / (2.0 * lam)))
        q_in = np.sum(fluxes * self.dxs[None, :], axis=1)
        out = rho_c * self.speed * np.einsum("zs,z->s", T[:, 0, :], self.dzs)
        loss = np.sum(np.where(contacts, 0.0, convection * surface) * self.dxs[None, :], axis=1)
        balance = np.where(q_in > 0, (out + loss) / np.where(q_in > 0, q_in, 1.0), 1.0)
        return surface, balance

    def solve(self, flux: np.ndarray, *, convection: float = 0.0, contact: np.ndarray | None = None) -> dict:
        """Solve (1) for a surface flux given on the mesh's surface cells.

        Parameters
        ----------
        flux : ndarray, shape (nx,) or (nx, ny)
            Heat flux entering the body through each surface face [W/m^2].
        convection : float
            Heat transfer coefficient outside the contact [W/(m^2 K)].
        contact : ndarray of bool, optional
            Surface faces in contact (no convection there); default ``flux > 0``.

        Returns
        -------
        dict
            ``T`` (cell values, shape ``mesh.shape``) [K rise], ``surface`` (face values at z = 0,
            shape ``mesh.shape[:-1]``) [K rise], ``x``, ``y``, ``z`` cell centres [m], and
            diagnostics: ``iterations``, ``residual``, ``converged``, ``cells``, ``energy_balance``
            (outflow enthalpy flux + convective loss over heat input [1]; 1 when the domain holds
            the heat), ``peclet``, ``first_cell``, ``depth``, ``scheme``.
        """
        mesh = self.mesh
        lam = self.material.conductivity
        rho_c = self.material.density * self.material.specific_heat
        flux = np.asarray(flux, dtype=float)
        if flux.shape != self.surface_shape:
            raise ValueError(f"flux has shape {flux.shape}, the mesh surface has {self.surface_shape}")
        contact = flux > 0 if contact is None else np.asarray(contact, dtype=bool)
        dz1 = self.dzs[0]
        eq = self.equation(flux, convection, contact)
        diag = solve_checked(eq, self.T, self.solver,
                             what=f"FiPy {'3-D' if self.three_d else '2-D'} steady moving-frame solve")
        vals = np.asarray(self.T.value, dtype=float)
        nx, nz = self.dxs.size, self.dzs.size
        if self.three_d:
            Tc = vals.reshape(nz, self.dys.size, nx).transpose(2, 1, 0)
        else:
            Tc = vals.reshape(nz, nx).T
        top = Tc[..., 0]
        surface = np.where(contact, top + flux * dz1 / (2.0 * lam), top / (1.0 + convection * dz1 / (2.0 * lam)))
        # energy balance: heat in = enthalpy carried out through the outflow + convective loss
        if self.three_d:
            area = self.dxs[:, None] * self.dys[None, :]
            section = self.dys[:, None] * self.dzs[None, :]
        else:
            area, section = self.dxs, self.dzs
        q_in = float(np.sum(flux * area))
        out = float(rho_c * self.speed * np.sum(Tc[0] * section))
        loss = float(np.sum(np.where(contact, 0.0, convection * surface) * area))
        balance = (out + loss) / q_in if q_in > 0 else 1.0
        diag.update(cells=int(Tc.size), energy_balance=balance, peclet=mesh.peclet, first_cell=float(dz1),
                    depth=float(mesh.z_edges[-1]), scheme=self.scheme)
        return {"T": Tc, "surface": surface, "x": self.x, "y": self.y, "z": self.z, **diag}


def solve_moving(mesh: MovingFrameMesh, flux: np.ndarray, speed: float, material, *, convection: float = 0.0,
                 contact: np.ndarray | None = None, scheme: str = "power-law", solver: str | None = None,
                 tolerance: float | None = None) -> dict:
    """Solve (1) once: ``MovingFrameSolver(mesh, speed, material, ...).solve(flux, ...)``.

    See :class:`MovingFrameSolver` for the parameters and the returned dict.
    """
    return MovingFrameSolver(mesh, speed, material, scheme=scheme, solver=solver,
                             tolerance=tolerance).solve(flux, convection=convection, contact=contact)
