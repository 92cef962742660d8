"""Finite-difference rail block of seed section 6.3: transient (explicit / implicit) and moving-frame steady.

A heat source (flux ``q(x, y)`` on the heat-source stage's patch grid) moves at the body's speed V over
a block below z = 0. Seed eqs. (56)-(60) in their physically consistent form (theta the rise above bulk):
``d theta/dt = kappa Laplace(theta)`` (56); ``d theta/dy = 0`` on the lateral faces (57); ``theta = 0`` on
the far faces x = 0, L_x and z = L_z (58); ``-lambda d theta/dz = q`` on the patch (59) and ``= -h theta``
outside it (60) (the seed prints (59)-(60) without lambda and with the opposite convection sign).
Schemes: ``explicit`` (the seed's: rail frame, explicit Euler on a uniform node grid, stable for
``dt <= d^2/(6 kappa)`` without convection, steps from :func:`railtherm_fdm.layout.plan_steps`);
``implicit`` (backward Euler, CG with a z-line Gauss-Seidel preconditioner); ``steady`` (moving frame,
graded grid, Allen-Southwell fluxes in x, GMRES: the transient limit, for stiff cases). Details:
docs/NOTES.md, "FDM 3-D block". Layout (:mod:`.layout`), source loading (:mod:`.source_loading`), heat
balance (:mod:`.energy`) and linear solvers (:mod:`.linear_solvers`) are shared with :mod:`.block2d`.
"""
from __future__ import annotations

import math
import time

import numba
import numpy as np

from railtherm import Refused

from . import kernels as K
from .energy import EnergyLedger, quasi_steady_change, steady_heat_balance
from .layout import (Extent, Trail, block_extent, explicit_stability_limit, graded_grid, node_grid, plan_steps,
                     field_note)
from .linear_solvers import CG_RTOL, BackwardEuler, backward_euler_operator, cg, gmres, zero_couplings
from .problem import block_problem
from .sampling import BlockResult, bilinear, linear_rows, surface_from_top_cells
from .source_loading import MovingSource, box_overlap, graded_surface_source

#: the 3-D block solvers and what they return
__all__ = ["transient_block", "steady_block", "BlockResult", "Extent", "block_extent", "explicit_stability_limit",
           "box_overlap"]

#: the conjugate-gradient solver the steady block calls (:func:`railtherm_fdm.linear_solvers.cg`; with
#: ``CG_RTOL``, what tests/test_plugin_verdicts.py patches to starve it)
_cg = cg


# ---------------------------------------------------------------------------------------------
# transient schemes (rail frame, uniform node grid)
# ---------------------------------------------------------------------------------------------
# one time loop (fused two-step explicit kernel, single explicit or implicit steps) sharing the energy ledger,
# the moving source's buffers and the quasi-steady check; a third of its length is the parameters' docstring
def transient_block(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                    scheme="explicit", time_step=None, courant=1.0, extent: Extent | None = None, checkpoint=None,
                    max_nodes=5e7, out_grid=None, trail: Trail | None = None):
    """Seed section 6.3: the source moves over the top face of a rail block; transient run.

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Patch grid (x along rolling, leading edge +a).
    flux : ndarray (nx, ny)
        Heat flux into this body on the patch grid [W/m^2].
    cover : ndarray (nx, ny)
        1 where the patch cell is in contact (no convection there), else 0 [1].
    speed : float
        Speed V of the body's material relative to the contact [m/s].
    conductivity, density, specific_heat : float
        lambda [W/(m K)], rho [kg/m^3], c [J/(kg K)].
    convection : float
        h [W/(m^2 K)] outside the patch.
    cell : float
        Node spacing d [m].
    scheme : {"explicit", "implicit"}
    time_step : float, optional
        Forced step [s] (explicit: must not exceed the stability limit; the caller refuses).
    courant : float
        Default step = courant * d / V (capped by stability for explicit) [1].
    extent : Extent, optional
        Block size (default :func:`block_extent`).
    checkpoint : float, optional
        Source travel before the end at which the patch-frame field is sampled a second time to
        judge whether it is quasi-steady [m] (default: a).
    max_nodes : float
        Largest node count (two float64 arrays of this size are held) [1].
    out_grid : railtherm.SurfaceGrid, optional
        Grid the fields are sampled on (a scene's extended field grid); default ``grid``.
    trail : Trail, optional
        A scene's ``field``: the source travels ``trail.behind`` further and the block reaches
        ``trail.depth`` (:func:`railtherm_fdm.layout.trail_extent`).

    Returns
    -------
    BlockResult
        ``surface`` (nxp, nyp) on the sample grid and ``depth`` (nxp, nz) at the node depths [K] at the
        end of the run; energies, steps and the quasi-steady check in the diagnostics.

    Raises
    ------
    railtherm.Refused
        When the block needs more than ``max_nodes`` nodes.
    """
    t0 = time.perf_counter()
    pb = block_problem(grid, speed, conductivity, density, specific_heat, convection, steady=False, extent=extent,
                       out_grid=out_grid, trail=trail)
    lam, rc, kappa, h, a, b, ext, sg = (pb.conductivity, pb.capacity, pb.kappa, pb.convection, pb.a, pb.b, pb.extent,
                                        pb.sample_grid)
    d = float(cell)
    # node grid: x in [0, Lx], y in [0, Ly], z in [0, Lz]
    ng = node_grid(a, ext, d)
    nx, nz, X0 = ng.nx, ng.nz, ng.start
    nyh = int(math.ceil((b + ext.lateral) / d))
    ny = 2 * nyh + 1
    if nx * ny * nz > max_nodes:
        raise Refused(f"model 'fdm' ({scheme}): the rail block needs {nx}x{ny}x{nz} = {nx * ny * nz:.3g} nodes "
                      f"at d = {d:.3g} m, above the limit {max_nodes:.3g} ({16 * nx * ny * nz / 1e9:.1f} GB); "
                      "use a lower level, a larger cell_size, or scheme 'steady' (graded moving-frame grid)"
                      + field_note(trail), kind="budget")
    xn, zn = ng.x, ng.z
    yn = d * np.arange(ny)
    Yc = yn[nyh]
    # dual-cell widths
    wy = np.full(ny, d)
    wy[0] = wy[-1] = 0.5 * d
    wz = np.full(nz, d)
    wz[0] = 0.5 * d
    vol_top = d * wy * wz[0]                              # (ny,) surface-node volumes [m^3]
    dt_stab = explicit_stability_limit(d, kappa, h, rc)
    plan = plan_steps(d, speed, ext.travel, dt_stab, scheme=scheme, courant=courant, time_step=time_step,
                      checkpoint=checkpoint, a=a)
    dt, nsteps, ncheck = plan.dt, plan.steps, plan.check_step

    # lateral overlap weights (fixed): node dual intervals vs patch cells shifted by Yc
    pye = grid.y_edges
    q = np.asarray(flux, dtype=float)
    cov = np.asarray(cover, dtype=float)
    yl = np.maximum(yn - 0.5 * d, 0.0)
    yh = np.minimum(yn + 0.5 * d, yn[-1])
    Wy = box_overlap(yl[:, None], yh[:, None], (pye[:-1] + Yc)[None, :], (pye[1:] + Yc)[None, :])  # (ny, nyp)
    cap_top = rc * vol_top                                # heat capacity of the surface nodes [J/K]
    Ayz = np.ascontiguousarray(wy[:, None] * wz[None, :])  # x-face areas of nodes [m^2]
    Axy_b = d * wy                                        # bottom-adjacent face areas per (i, j) [m^2]
    # two source/loss buffers (the fused explicit kernel advances two steps at once)
    source = MovingSource(xn, d, grid.x_edges, q @ Wy.T, cov @ Wy.T if h > 0 else None, d * wy, cap_top,
                          dt * h * d * wy / (rc * vol_top), h, X0, speed, dt, buffers=2, period=plan.period,
                          period_cells=plan.period_cells)
    (src, src2), (hls, hls2) = source.src, source.hloss
    ledger = EnergyLedger(dt, lam, d, Ayz, Axy_b, cap_top)

    T = np.zeros((nx, ny, nz))
    Tn = np.zeros((nx, ny, nz))
    step = K.step_kernel(T.size)
    fused = scheme == "explicit" and T.size >= K.PARALLEL_MIN_NODES
    if fused:
        split = 4 * numba.get_num_threads()        # chunks of the active planes per call
        # one thread (a study's worker): the serial build, the same chunks (hence the same sums)
        two_steps = K.explicit_two_steps if numba.get_num_threads() > 1 else K.explicit_two_steps_serial
        acc = np.zeros((((nx - 2) + 3) // 4, 6))
    r = kappa * dt / d ** 2
    if scheme == "implicit":
        implicit = BackwardEuler(backward_euler_operator(nx, ny, nz, d, wy, wz, lam, rc, dt), cap_top[None, :], dt)

    def patch_field(Tarr, xs):
        surf = bilinear(xn - xs, yn - Yc, Tarr[:, :, 0], sg.x, sg.y)
        dep = linear_rows(xn - xs, Tarr[:, nyh, :], sg.x) if sg.y is not None else None
        return surf, dep

    check = None
    n = 0
    front = 0             # last x-plane that may hold heat (the stencil moves it one plane per step)
    while n < nsteps:
        if fused and n + 2 <= nsteps and not (n < ncheck < n + 2):
            ledger.energy_in += source.load(n, 0) + source.load(n + 1, 1)
            front = max(front + 1, source.reach(0)) + 1
            front = max(front, source.reach(1))
            stop = min(nx - 1, front + 1)
            chunk = max(4, -(-(stop - 1) // split))
            two_steps(T, Tn, r, src, hls, src2, hls2, Ayz, Axy_b, cap_top, chunk, acc, stop)
            tot = acc.sum(axis=0)         # losses at levels n+1 and n (the kernel sums both)
            ledger.fixed_faces += ledger.g * (tot[3] + tot[4]) + ledger.g * (tot[0] + tot[1])
            ledger.convection += (tot[5] + tot[2]) if h > 0 else 0.0
            T, Tn = Tn, T
            n += 2
        else:
            ledger.energy_in += source.load(n)
            front = max(front + 1, source.reach(0))
            ledger.convection += ledger.convective_loss(T, hls) if h > 0 else 0.0
            if scheme == "explicit":
                ledger.fixed_faces += ledger.fixed_face_loss(T)   # losses at level n (explicit update uses T^n)
                step(T, Tn, r, src, hls)
                T, Tn = Tn, T
            else:
                implicit.step(T, src, hls)
                ledger.fixed_faces += ledger.fixed_face_loss(T)   # implicit: fixed-face losses at level n+1
            n += 1
        if n == ncheck:
            check = patch_field(T, X0 + speed * dt * n)[0]
    surf, dep = patch_field(T, X0 + plan.travel)
    vol = d * wy[:, None] * wz[None, :]
    qs_change = quasi_steady_change(surf, check)
    diag = {
        "scheme": scheme, "cell_size": d, "time_step": dt, "stability_limit": dt_stab,
        "steps": nsteps, "nodes": int(nx * ny * nz), "node_shape": f"{nx}x{ny}x{nz}",
        "cell_updates": int((nx - 2) * ny * (nz - 1) * nsteps),
        "travel": plan.travel, "block_length": float(xn[-1]), "block_width": float(yn[-1]),
        "block_depth": float(zn[-1]), **ledger.summary(rc * float((vol[None, :, :] * T).sum())),
        "quasi_steady_change": qs_change, "quasi_steady": bool(qs_change < 2e-3), "fused_steps": bool(fused),
        "fourier_number": r, "wall_time_solver": time.perf_counter() - t0,
    }
    # implicit: one CG solve per step, each to its own tolerance; explicit stepping: no iterative
    # solve (0 iterations, residual 0)
    diag.update(implicit.diagnostics() if scheme == "implicit" else {"converged": True, "iterations": 0,
                                                                     "residual": 0.0})
    return BlockResult(surf, zn.copy(), dep, diag)


# ---------------------------------------------------------------------------------------------
# moving-frame steady scheme (graded cell-centred grid)
# ---------------------------------------------------------------------------------------------
# the 3-D operator is assembled in place (no per-face helper: its arrays are the block's largest, ~350 bytes
# a cell) and solved by preconditioned GMRES in the same frame; a third of its length is the docstring
def steady_block(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                 level=0, ratio=1.3, surface_layers=4, extent: Extent | None = None, rtol=1e-11, maxiter=400,
                 max_cells=4e6, out_grid=None, trail: Trail | None = None):
    """Moving-frame steady state of the rail block (the transient schemes' quasi-steady limit).

    Parameters
    ----------
    grid, flux, cover, speed, conductivity, density, specific_heat, convection
        As :func:`transient_block`.
    cell : float
        Cell size in x and y over the patch [m]; the depth grid starts at
        ``min(cell, delta / surface_layers)`` with delta = sqrt(2 a kappa / V).
    level : int
        Refinement level: the growth ratio outside the patch is ``ratio ** (1 / 2**level)`` so that
        halving ``cell`` level by level refines the whole graded grid consistently.
    ratio : float
        Growth ratio of the graded cells at level 0 [1].
    surface_layers : int
        Cells across the penetration depth delta at the given ``cell`` [1].
    extent : Extent, optional
        Block size around the patch (default :func:`block_extent`).
    rtol : float
        GMRES relative tolerance.
    max_cells : float
        Largest cell count (about 350 bytes per cell are held) [1].
    out_grid : railtherm.SurfaceGrid, optional
        Grid the fields are sampled on (a scene's extended field grid); default ``grid``.
    trail : Trail, optional
        A scene's ``field``: the grid reaches ``trail.behind`` beyond the trailing edge and
        ``trail.depth`` deep with cells that follow the trail (:func:`railtherm_fdm.layout.graded_grid`).

    Returns
    -------
    BlockResult
        Steady ``surface`` (nxp, nyp) on the sample grid and ``depth`` (nxp, nz) at the cell-centre depths
        (the surface first) [K]; the GMRES iterations and heat balance in the diagnostics.

    Raises
    ------
    railtherm.Refused
        When the grid needs more than ``max_cells`` cells.
    """
    t0 = time.perf_counter()
    pb = block_problem(grid, speed, conductivity, density, specific_heat, convection, steady=True, extent=extent,
                       out_grid=out_grid, trail=trail)
    lam, rc, kappa, h, V, a, b, ext, sg = (pb.conductivity, pb.capacity, pb.kappa, pb.convection, pb.speed, pb.a, pb.b,
                                           pb.extent, pb.sample_grid)
    gg = graded_grid(a, ext, cell, V, kappa, level, b=b, ratio=ratio, surface_layers=surface_layers, trail=trail)
    xe, ye, ze, rk = gg.x_edges, gg.y_edges, gg.z_edges, gg.growth
    dx, dy, dz = np.diff(xe), np.diff(ye), np.diff(ze)
    xc, yc, zc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1]), 0.5 * (ze[1:] + ze[:-1])
    nx, ny, nz = len(dx), len(dy), len(dz)
    shape = (nx, ny, nz)
    if nx * ny * nz > max_cells:
        raise Refused(f"model 'fdm' (steady): the graded grid needs {nx}x{ny}x{nz} = {nx * ny * nz:.3g} cells at "
                      f"level {level} (cell {cell:.3g} m), above the limit {max_cells:.3g} "
                      f"(~{350 * nx * ny * nz / 1e9:.1f} GB); use a lower level or a larger cell_size"
                      + field_note(trail),
                      kind="budget")

    # source on the top faces: exact overlap of the FV cells with the patch cells
    Q, Az, hA = graded_surface_source(xe, grid.x_edges, flux, cover, h, ye, grid.y_edges)   # [W], [m^2], [W/K]

    # coefficients
    Ax = dy[:, None] * dz[None, :]                                  # (ny, nz)
    F = rc * V * Ax                                                 # advective capacity flow [W/K]
    aE, aW, aN, aS, aT, aB = zero_couplings(shape)
    aP = np.zeros(shape)

    def exp_coeffs(delta_x):
        D = lam * Ax[None] / delta_x[:, None, None]
        P = F[None] / D
        with np.errstate(over="ignore"):
            alpha = F[None] / np.expm1(P)                           # downstream-side coefficient
        beta = F[None] / (-np.expm1(-P))                            # upstream-side coefficient
        return alpha, beta

    alpha, beta = exp_coeffs(np.diff(xc))                           # faces between i and i+1 (nx-1)
    aE[:-1] = beta
    aP[:-1] += alpha
    aW[1:] = alpha
    aP[1:] += beta
    # inflow face (x max): theta = 0 at distance dx/2
    ab, _ = exp_coeffs(np.array([0.5 * dx[-1]]))
    aP[-1] += ab[0]
    # outflow face (x min): advective outflow, zero diffusive flux
    aP[0] += F
    # y faces
    Dy = lam * (dx[:, None] * dz[None, :])[:, None, :] / np.diff(yc)[None, :, None]   # (nx, ny-1, nz)
    aN[:, :-1] = Dy
    aS[:, 1:] = Dy
    aP[:, :-1] += Dy
    aP[:, 1:] += Dy
    # z faces
    Dz = lam * Az[:, :, None] / np.diff(zc)[None, None, :]                             # (nx, ny, nz-1)
    aB[:, :, :-1] = Dz
    aT[:, :, 1:] = Dz
    aP[:, :, :-1] += Dz
    aP[:, :, 1:] += Dz
    # bottom theta = 0, top convection
    Dbot = lam * Az / (0.5 * dz[-1])
    aP[:, :, -1] += Dbot
    aP[:, :, 0] += hA
    rhs = np.zeros(shape)
    rhs[:, :, 0] = Q

    c = tuple(np.ascontiguousarray(v) for v in (aP, aE, aW, aN, aS, aT, aB))
    n = nx * ny * nz
    tmp = np.empty(shape)
    out = np.empty(shape)
    scratch = np.empty(shape)

    matvec = K.matvec_kernel(n)

    def mv(v):
        matvec(*c, v.reshape(shape), tmp)
        return tmp.reshape(-1).copy()

    fac = K.zline_factor(aP, aT, aB)

    def pc(v):
        K.sgs_zline(*c, *fac, np.ascontiguousarray(v.reshape(shape)), out, scratch)
        return out.reshape(-1).copy()

    x0 = pc(rhs.reshape(-1))
    sol, its, resid = gmres(mv, pc, rhs.reshape(-1), x0, rtol=rtol, restart=30, maxiter=maxiter)
    info = 0 if resid <= rtol * 10 else 1
    T = sol.reshape(shape)

    # energy balance (exact for the discrete equations)
    balance = steady_heat_balance(Q, F, T, ab[0], Dbot, hA)
    # surface temperature: quadratic through the two top cells with the surface flux as slope
    ts = surface_from_top_cells(Q, hA, Az, T[:, :, 0], T[:, :, 1], zc[0], zc[1], lam)
    surf = bilinear(xc, yc, ts, sg.x, sg.y)
    jc = int(np.argmin(np.abs(yc)))
    prof = np.concatenate([ts[:, jc][:, None], T[:, jc, :]], axis=1)   # (nx, nz+1)
    zout = np.concatenate([[0.0], zc])
    dep = linear_rows(xc, prof, sg.x)
    diag = {
        "scheme": "steady", "cell_size": float(cell), "first_depth_cell": float(dz[0]),
        "growth_ratio": rk, "cells": int(n), "cell_shape": f"{nx}x{ny}x{nz}",
        "gmres_iterations": int(its), "iterations": int(its), "residual": float(resid), "gmres_tolerance": rtol,
        "converged": bool(info == 0),
        **balance,
        "block_length": float(xe[-1] - xe[0]), "block_width": float(ye[-1] - ye[0]), "block_depth": float(ze[-1]),
        "wall_time_solver": time.perf_counter() - t0,
    }
    return BlockResult(surf, zout, dep, diag)

