"""Finite differences for a line contact: the 2-D (x-z) rail block of seed section 6.3.

A line contact has no lateral extent: the block is an x-z section per unit width with the equations of
:mod:`.block3d` without y (the 3-D block with a source uniform in y has exactly this solution; the 2-D
solver is some hundred times cheaper): ``d theta/dt = kappa (theta_xx + theta_zz)`` (56), ``theta = 0``
on the far faces (58), ``-lambda d theta/dz = q`` on the patch and ``-h theta`` outside (59)-(60).
Schemes as in 3-D: ``explicit`` (stable for ``dt <= d^2/(4 kappa)`` without convection), ``implicit``
(backward Euler with the 3-D block's CG), ``steady`` (moving frame, graded grid, sparse LU; second-order
upwind ``x_scheme="upwind2"`` or Allen-Southwell fluxes along x; any Péclet number). Details:
docs/NOTES.md, "FDM 2-D block". Layout, source loading, heat balance and implicit solvers are the 3-D
block's (:mod:`.layout`, :mod:`.source_loading`, :mod:`.energy`, :mod:`.linear_solvers`). Per unit width:
energies in [J/m], powers in [W/m].
"""
from __future__ import annotations

import time

import numpy as np
from scipy.sparse import csc_matrix
from scipy.sparse.linalg import splu

from railtherm import Refused

from .energy import EnergyLedger, quasi_steady_change, steady_heat_balance
from .kernels import explicit_step_2d
from .layout import (Extent, Trail, graded_grid, line_extent, line_stability_limit, node_grid, plan_steps, field_note)
from .linear_solvers import BackwardEuler, backward_euler_operator
from .problem import block_problem
from .sampling import BlockResult, linear_rows, surface_from_top_cells
from .source_loading import MovingSource, graded_surface_source

#: the 2-D (line contact) solvers and their limits
__all__ = ["transient_line", "steady_line", "X_SCHEMES", "CG_MIN_CAPACITY_RATIO", "line_stability_limit",
           "line_extent"]

X_SCHEMES = ("exponential", "upwind2")

#: implicit scheme: CG (z-line preconditioned) when rho c d^2 / (lambda dt) reaches this, else sparse LU
CG_MIN_CAPACITY_RATIO = 10.0


def _check_line(grid):
    if not grid.line:
        raise ValueError("the 2-D block needs a line grid (y_edges None)")


# one time loop (explicit or implicit steps) sharing the energy ledger, the source and the quasi-steady check;
# half of its length is the docstring of its eleven parameters
def transient_line(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                   scheme="explicit", time_step=None, courant=1.0, extent: Extent | None = None, checkpoint=None,
                   max_nodes=2e7, out_grid=None, trail: Trail | None = None):
    """Seed 6.3 in 2-D: the band source moves over the top face of the block; transient run.

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Line grid of the band (x along rolling, leading edge +a).
    flux : ndarray (nx,)
        Heat flux into this body [W/m^2].
    cover : ndarray (nx,)
        1 where the patch cell is in contact (no convection), else 0 [1].
    speed, conductivity, density, specific_heat, convection, cell : float
        As :func:`railtherm_fdm.block3d.transient_block`: speed V of the body relative to the contact
        [m/s], lambda [W/(m K)], rho [kg/m^3], c [J/(kg K)], h [W/(m^2 K)] outside the patch, node spacing d [m].
    scheme : {"explicit", "implicit"}
    time_step : float, optional
        Forced step [s] (explicit: the caller refuses steps beyond the stability limit).
    courant : float
        Default step = courant d / V (capped by stability for explicit) [1].
    extent : Extent, optional
        Block size (default :func:`line_extent`).
    checkpoint : float, optional
        Travel before the end at which the patch-frame field is sampled again for the
        quasi-steady check [m] (default a).
    max_nodes : float
        Largest node count [1].
    out_grid, trail
        As :func:`railtherm_fdm.block3d.transient_block`.

    Returns
    -------
    BlockResult
        ``surface`` (nxp,), ``depth`` (nxp, nz) [K]; energies per unit width in the diagnostics.
    """
    _check_line(grid)
    if scheme not in ("explicit", "implicit"):
        raise ValueError(f"scheme must be 'explicit' or 'implicit', got {scheme!r}")
    t0 = time.perf_counter()
    pb = block_problem(grid, speed, conductivity, density, specific_heat, convection, steady=False, extent=extent,
                       out_grid=out_grid, trail=trail)
    lam, rc, kappa, h, a, ext, sg = (pb.conductivity, pb.capacity, pb.kappa, pb.convection, pb.a, pb.extent,
                                     pb.sample_grid)
    d = float(cell)
    ng = node_grid(a, ext, d)
    nx, nz, X0 = ng.nx, ng.nz, ng.start
    if nx * nz > max_nodes:
        raise Refused(f"model 'fdm' ({scheme}, line): the 2-D block needs {nx}x{nz} = {nx * nz:.3g} nodes at "
                      f"d = {d:.3g} m, above the limit {max_nodes:.3g}; use a lower level, a larger cell_size or "
                      "scheme 'steady'" + field_note(trail), kind="budget")
    xn, zn = ng.x, ng.z
    wz = np.full(nz, d)
    wz[0] = 0.5 * d
    cap_top = rc * d * wz[0]                                     # [J/(K m)]
    dt_stab = line_stability_limit(d, kappa, h, rc)
    plan = plan_steps(d, speed, ext.travel, dt_stab, scheme=scheme, courant=courant, time_step=time_step,
                      checkpoint=checkpoint, a=a)
    dt, nsteps, ncheck = plan.dt, plan.steps, plan.check_step
    source = MovingSource(xn, d, grid.x_edges, np.asarray(flux, dtype=float).reshape(-1),
                          np.asarray(cover, dtype=float).reshape(-1), d, cap_top, dt * h * d / cap_top, h, X0,
                          speed, dt, period=plan.period,
                          period_cells=plan.period_cells)
    src, hloss = source.src[0], source.hloss[0]
    ledger = EnergyLedger(dt, lam, d, wz, d, cap_top)
    r = kappa * dt / d ** 2
    T = np.zeros((nx, nz))
    Tn = np.zeros((nx, nz))
    if scheme == "implicit":
        # the 3-D operator with one lateral node of unit width is the 2-D one (per unit width).
        # Solver: when the capacity term dominates (rho c d^2/(lambda dt) >= 10: high Péclet
        # number, dt ~ d/V) the z-line preconditioned CG of the 3-D block needs about two
        # iterations a step and beats a sparse LU (7.7 s against 18 s for 635 steps on 190k nodes);
        # otherwise the LU factorised once wins (5.4 s against 14 s at Pe = 1, 75k nodes).
        use_cg = rc * d * d / (lam * dt) >= CG_MIN_CAPACITY_RATIO
        implicit = BackwardEuler(backward_euler_operator(nx, 1, nz, d, np.ones(1), wz, lam, rc, dt), cap_top, dt,
                                 lu=not use_cg)
        T3, src3, hloss3 = T.reshape(nx, 1, nz), src.reshape(nx, 1), hloss.reshape(nx, 1)

    def patch_field(Tarr, xs):
        return np.interp(sg.x, xn - xs, Tarr[:, 0]), linear_rows(xn - xs, Tarr, sg.x)

    check = None
    n = 0
    while n < nsteps:
        ledger.energy_in += source.load(n)
        if h > 0:
            ledger.convection += ledger.convective_loss(T, hloss)
        if scheme == "explicit":
            ledger.fixed_faces += ledger.fixed_face_loss(T)
            explicit_step_2d(T, Tn, r, src, hloss)
            T, Tn = Tn, T
        else:
            implicit.step(T3, src3, hloss3)
            ledger.fixed_faces += ledger.fixed_face_loss(T)
        n += 1
        if n == ncheck:
            check = patch_field(T, X0 + speed * dt * n)[0]
    surf, dep = patch_field(T, X0 + plan.travel)
    qs_change = quasi_steady_change(surf, check)
    diag = {
        "scheme": scheme, "dimension": 2, "cell_size": d, "time_step": dt, "stability_limit": dt_stab,
        "steps": nsteps, "nodes": int(nx * nz), "node_shape": f"{nx}x{nz}",
        "cell_updates": int((nx - 2) * (nz - 1) * nsteps), "travel": plan.travel,
        "block_length": float(xn[-1]), "block_depth": float(zn[-1]),
        **ledger.summary(rc * d * float((wz[None, :] * T).sum())),
        "quasi_steady_change": qs_change, "quasi_steady": bool(qs_change < 2e-3), "fourier_number": r,
        "wall_time_solver": time.perf_counter() - t0,
    }
    # implicit: CG to CG_RTOL at every step (converged when every step met it) or one LU (direct);
    # explicit time stepping: no iterative solve (0 iterations, residual 0)
    diag.update(implicit.diagnostics() if scheme == "implicit" else {"converged": True, "iterations": 0,
                                                                     "residual": 0.0})
    return BlockResult(surf, zn.copy(), dep, diag)


def _line_operator(xe, ze, lam, rc, V, hA, x_scheme):
    """:func:`steady_line`'s operator on the graded cells (edges ``xe``, ``ze`` [m]), top convection ``hA``:
    (A (csc) [W/(m K)], capacity flow rho c V dz (nz,), inflow coefficients (nz,), bottom conductances (nx,))."""
    dx, dz = np.diff(xe), np.diff(ze)
    xc, zc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ze[1:] + ze[:-1])
    nx, nz = dx.size, dz.size
    n = nx * nz
    idx = np.arange(n).reshape(nx, nz)
    rows, cols, vals = [], [], []
    aP = np.zeros((nx, nz))

    def couple(i_rows, j_cols, coef):
        """Add ``-coef`` at (row, col) (a neighbour contribution)."""
        rows.append(i_rows.reshape(-1))
        cols.append(j_cols.reshape(-1))
        vals.append(-coef.reshape(-1))

    F = rc * V * dz                                                    # (nz,) capacity flow [W/(m K)]
    dxc = np.diff(xc)                                                  # (nx-1,)
    Dx = lam * dz[None, :] / dxc[:, None]                              # (nx-1, nz)
    if x_scheme == "exponential":
        Pf = F[None, :] / Dx
        with np.errstate(over="ignore"):
            alpha = F[None, :] / np.expm1(Pf)
        beta = F[None, :] / (-np.expm1(-Pf))
        # face between i (downstream) and i+1 (upstream)
        aP[:-1] += alpha
        couple(idx[:-1], idx[1:], beta)
        aP[1:] += beta
        couple(idx[1:], idx[:-1], alpha)
        # inflow face (x max): theta = 0 at dx/2
        Db = lam * dz / (0.5 * dx[-1])
        with np.errstate(over="ignore"):
            ab = F / np.expm1(F / Db)
        aP[-1] += ab
        inflow_coef = ab
    else:
        # diffusion: central
        aP[:-1] += Dx
        aP[1:] += Dx
        couple(idx[:-1], idx[1:], Dx)
        couple(idx[1:], idx[:-1], Dx)
        Db = lam * dz / (0.5 * dx[-1])
        aP[-1] += Db
        inflow_coef = Db
        # advection: the face between i and U = i+1 carries F theta_f from U into i, with the
        # linear upwind value theta_f = wU theta_U + wUU theta_UU (UU = i+2); first-order upwind at
        # the face next to the inflow, where UU does not exist
        i = np.arange(nx - 1)
        U = i + 1
        c1 = np.zeros(nx - 1)
        has = U + 1 < nx
        c1[has] = (xe[U[has]] - xc[U[has]]) / (xc[U[has]] - xc[U[has] + 1])     # 1/2 on a uniform grid
        wU, wUU = 1.0 + c1, -c1
        Fi = F[None, :]
        couple(idx[i], idx[U], Fi * wU[:, None])            # cell i gains F theta_f
        aP[U] += Fi * wU[:, None]                           # cell U loses it
        ih = i[has]
        couple(idx[ih], idx[ih + 2], Fi * wUU[has][:, None])
        rows.append(idx[ih + 1].reshape(-1))
        cols.append(idx[ih + 2].reshape(-1))
        vals.append((Fi * wUU[has][:, None]).reshape(-1))
    # outflow face (x min): advective outflow F theta_0, zero diffusive flux
    aP[0] += F
    # z faces: central
    Dz = lam * dx[:, None] / np.diff(zc)[None, :]                      # (nx, nz-1)
    aP[:, :-1] += Dz
    aP[:, 1:] += Dz
    couple(idx[:, :-1], idx[:, 1:], Dz)
    couple(idx[:, 1:], idx[:, :-1], Dz)
    Dbot = lam * dx / (0.5 * dz[-1])
    aP[:, -1] += Dbot
    aP[:, 0] += hA
    rows.append(idx.reshape(-1))
    cols.append(idx.reshape(-1))
    vals.append(aP.reshape(-1))
    A = csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    return A, F, inflow_coef, Dbot


def steady_line(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                level=0, ratio=1.3, surface_layers=4, extent=None, x_scheme="upwind2", max_cells=4e6,
                out_grid=None, trail: Trail | None = None):
    """Moving-frame steady state of the 2-D block (the transient schemes' quasi-steady limit).

    Parameters
    ----------
    grid, flux, cover, speed, conductivity, density, specific_heat, convection
        As :func:`transient_line`.
    cell : float
        Cell size along x over the band [m]; the depth grid starts at
        ``min(cell, delta / surface_layers / 2**level)``, delta = sqrt(2 a kappa / V).
    level : int
        Refinement level: growth ratio ``ratio ** (1 / 2**level)`` outside the band and in depth.
    ratio : float
        Growth ratio of the graded cells at level 0 [1].
    surface_layers : int
        Cells across the penetration depth delta at level 0 [1].
    extent : Extent, optional
        Block size (default :func:`line_extent`).
    x_scheme : {"upwind2", "exponential"}
        Fluxes along x: second-order upwind advection with central diffusion (default; measured
        order ~1.8 against Jaeger), or exponential (Allen-Southwell, as the 3-D block; first order
        at high cell Péclet number, its LU is about twice as cheap).
    max_cells : float
        Largest cell count [1].
    out_grid, trail
        As :func:`railtherm_fdm.block3d.steady_block`.

    Returns
    -------
    BlockResult
    """
    _check_line(grid)
    if x_scheme not in X_SCHEMES:
        raise ValueError(f"x_scheme must be one of {X_SCHEMES}, got {x_scheme!r}")
    t0 = time.perf_counter()
    pb = block_problem(grid, speed, conductivity, density, specific_heat, convection, steady=True, extent=extent,
                       out_grid=out_grid, trail=trail)
    lam, rc, kappa, h, V, a, ext, sg = (pb.conductivity, pb.capacity, pb.kappa, pb.convection, pb.speed, pb.a,
                                        pb.extent, pb.sample_grid)
    gg = graded_grid(a, ext, cell, V, kappa, level, ratio=ratio, surface_layers=surface_layers, trail=trail)
    xe, ze, rk = gg.x_edges, gg.z_edges, gg.growth
    dx, dz = np.diff(xe), np.diff(ze)
    xc, zc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ze[1:] + ze[:-1])
    nx, nz = dx.size, dz.size
    n = nx * nz
    if n > max_cells:
        raise Refused(f"model 'fdm' (steady, line): the graded grid needs {nx}x{nz} = {n:.3g} cells at level "
                      f"{level}, above the limit {max_cells:.3g}; use a lower level or a larger cell_size"
                      + field_note(trail), kind="budget")
    Q, _, hA = graded_surface_source(xe, grid.x_edges, flux, cover, h)    # [W/m], [W/(m K)]
    A, F, inflow_coef, Dbot = _line_operator(xe, ze, lam, rc, V, hA, x_scheme)
    rhs = np.zeros((nx, nz))
    rhs[:, 0] = Q
    # orderings measured on 2-D grids: minimum degree on A^T + A for the (diagonally dominant)
    # exponential matrix; column AMD for the second-order upwind one, whose off-diagonal pivots make
    # the symmetric ordering fill in ten times more
    lu = splu(A, permc_spec="MMD_AT_PLUS_A" if x_scheme == "exponential" else "COLAMD")
    T = lu.solve(rhs.reshape(-1)).reshape(nx, nz)
    resid = float(np.linalg.norm(A @ T.reshape(-1) - rhs.reshape(-1)) / (np.linalg.norm(rhs) or 1.0))

    balance = steady_heat_balance(Q, F, T, inflow_coef, Dbot, hA)
    ts = surface_from_top_cells(Q, hA, dx, T[:, 0], T[:, 1], zc[0], zc[1], lam)
    surf = np.interp(sg.x, xc, ts)
    prof = np.concatenate([ts[:, None], T], axis=1)
    dep = linear_rows(xc, prof, sg.x)
    diag = {
        "scheme": "steady", "dimension": 2, "x_scheme": x_scheme, "cell_size": float(cell),
        "first_depth_cell": float(dz[0]), "growth_ratio": rk, "cells": int(n), "cell_shape": f"{nx}x{nz}",
        # one sparse LU solve (direct: 0 iterations); its relative residual ||A T - b|| / ||b||
        "iterations": 0, "residual": resid, "converged": bool(resid < 1e-8),
        **balance,
        "block_length": float(xe[-1] - xe[0]), "block_depth": float(ze[-1]),
        "wall_time_solver": time.perf_counter() - t0,
    }
    return BlockResult(surf, np.concatenate([[0.0], zc]), dep, diag)
