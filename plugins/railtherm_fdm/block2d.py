"""Finite differences for a line contact: the 2-D (x-z) rail block of seed section 6.3.

A line contact has no lateral extent: the block is a half-plane section x-z, per unit width, with
the same equations as :mod:`railtherm_fastsim.fdm_solvers` without the y direction (the 3-D block
with insulated lateral faces and a source uniform in y has exactly this solution; a dedicated 2-D
solver is used because it is some hundred times cheaper):

* ``d theta/dt = kappa (theta_xx + theta_zz)`` in the block                                   (56)
* fixed far faces ``theta = 0`` (x = 0, x = L_x, z = L_z)                                    (58)
* ``-lambda d theta/dz = q`` on the surface inside the patch, ``= -h theta`` outside        (59)-(60)

Schemes (as for the 3-D block):

``explicit``
    Rail frame, the source moves over the top face; explicit Euler on a uniform node grid of
    spacing d (dual-cell finite volumes, surface nodes on z = 0). Stable for
    ``dt <= 1 / (4 kappa/d^2 + 2 h/(rho c d))`` (d^2/(4 kappa) without convection).
``implicit``
    Same grid and moving source, backward Euler (convection lagged), each step solved by the 3-D
    block's conjugate gradients with the z-line Gauss-Seidel preconditioner (one lateral node).
``steady``
    Moving frame: ``-V d theta/dx = kappa (theta_xx + theta_zz)`` on a cell-centred grid graded
    towards the surface and the patch, solved directly (sparse LU). Fluxes along x by default with
    the second-order upwind face value (``x_scheme="upwind2"``: the BDF2 of the marching problem at
    high Péclet number) plus central diffusion, or by the exponential (Allen-Southwell) scheme of
    the 3-D block (first order at high cell Péclet number); central diffusion in z. Inflow
    theta = 0, outflow zero diffusive flux, bottom theta = 0. Direct solves work at any Péclet
    number (measured within 0.012 % of Jaeger at Pe 0.01 and 1e5, level 3).

The source is applied conservatively: the power of each patch cell is split over the nodes
(cells) by the exact length of overlap, averaged over the distance the source travels in a step;
every run reports its heat balance (energy in = stored + lost through the fixed faces + convected,
+ carried out of the outflow face for the steady scheme). Per unit width: energies in [J/m],
powers in [W/m].
"""
from __future__ import annotations

import math
import time

import numba
import numpy as np

from railtherm import Refused
from railtherm.physics import thermal_scales

from .block3d import (CG_RTOL, BlockResult, _cg, _graded, _graded_depth, _implicit_coefficients, _linear_rows,
                          block_extent, box_overlap)

__all__ = ["line_stability_limit", "line_extent", "transient_line", "steady_line", "X_SCHEMES"]

X_SCHEMES = ("exponential", "upwind2")

#: implicit scheme: CG (z-line preconditioned) when rho c d^2 / (lambda dt) reaches this, else sparse LU
CG_MIN_CAPACITY_RATIO = 10.0


def line_stability_limit(d: float, kappa: float, h: float, rho_c: float) -> float:
    """Largest stable explicit step of the 2-D block [s]: ``1 / (4 kappa/d^2 + 2 h/(rho c d))``.

    Parameters
    ----------
    d : float
        Node spacing [m].
    kappa : float
        Diffusivity [m^2/s].
    h : float
        Convection coefficient [W/(m^2 K)].
    rho_c : float
        Volumetric heat capacity [J/(m^3 K)].
    """
    return 1.0 / (4.0 * kappa / d ** 2 + 2.0 * h / (rho_c * d))


def line_extent(a: float, speed: float, kappa: float, *, scale: float = 1.0):
    """Block size around a band of half-width a [m] (:func:`railtherm_fastsim.fdm_solvers.block_extent`
    without the lateral margin)."""
    return block_extent(a, a, speed, kappa, scale=scale)


@numba.njit(cache=True, fastmath=True, boundscheck=False)
def explicit_step_2d(T, Tn, r, src, hloss):  # pragma: no cover - compiled
    """One explicit-Euler step of the 2-D block (node grid, spacing d).

    Nodes i = 0, nx-1 and k = nz-1 are fixed (0). The surface node k = 0 owns a half-depth dual
    cell: it receives ``src`` [K] and loses ``hloss * T`` by convection.

    Parameters
    ----------
    T, Tn : ndarray (nx, nz)
        Rise at level n and output at level n+1 [K].
    r : float
        kappa dt / d^2 [1]; stable for r <= 1/4 without convection.
    src, hloss : ndarray (nx,)
        Source increment [K] and convective loss factor [1] of each surface node.
    """
    nx, nz = T.shape
    for i in range(1, nx - 1):
        t = T[i, 0]
        Tn[i, 0] = t + r * (T[i + 1, 0] + T[i - 1, 0] + 2.0 * T[i, 1] - 4.0 * t) + src[i] - hloss[i] * t
        for k in range(1, nz - 1):
            t = T[i, k]
            Tn[i, k] = t + r * (T[i + 1, k] + T[i - 1, k] + T[i, k + 1] + T[i, k - 1] - 4.0 * t)


def _check_line(grid):
    if not grid.line:
        raise ValueError("the 2-D block needs a line grid (y_edges None)")


def transient_line(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                   scheme="explicit", time_step=None, courant=1.0, extent=None, checkpoint=None, max_nodes=2e7):
    """Seed 6.3 in 2-D: the band source moves over the top face of the block; transient run.

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Line grid of the band (x along rolling, leading edge +a).
    flux : ndarray (nx,)
        Heat flux into this body [W/m^2].
    cover : ndarray (nx,)
        1 where the patch cell is in contact (no convection), else 0 [1].
    speed : float
        Speed V of the body relative to the contact [m/s].
    conductivity, density, specific_heat : float
        lambda [W/(m K)], rho [kg/m^3], c [J/(kg K)].
    convection : float
        h [W/(m^2 K)] outside the patch.
    cell : float
        Node spacing d [m].
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

    Returns
    -------
    BlockResult
        ``surface`` (nxp,), ``depth`` (nxp, nz) [K]; energies per unit width in the diagnostics.
    """
    _check_line(grid)
    t0 = time.perf_counter()
    lam, rc = float(conductivity), float(density) * float(specific_heat)
    kappa = lam / rc
    h = float(convection)
    a = float(grid.x_edges[-1])
    ext = extent or line_extent(a, speed, kappa)
    d = float(cell)
    nb = int(math.ceil((ext.behind + 0.5 * d) / d)) + 1
    X0 = nb * d + a
    nx = int(math.ceil((X0 + ext.travel + a + ext.ahead) / d)) + 1
    nz = max(3, int(math.ceil(ext.depth / d)) + 1)
    if nx * nz > max_nodes:
        raise Refused(f"model 'fdm' ({scheme}, line): the 2-D block needs {nx}x{nz} = {nx * nz:.3g} nodes at "
                      f"d = {d:.3g} m, above the limit {max_nodes:.3g}; use a lower level, a larger cell_size or "
                      "scheme 'steady'", kind="budget")
    xn = d * np.arange(nx)
    zn = d * np.arange(nz)
    wz = np.full(nz, d)
    wz[0] = 0.5 * d
    cap_top = rc * d * wz[0]                                     # [J/(K m)]
    dt_stab = line_stability_limit(d, kappa, h, rc)
    if time_step is not None:
        dt = float(time_step)
        per_cell = None
    else:
        target = min(dt_stab, courant * d / speed) if scheme == "explicit" else courant * d / speed
        per_cell = max(1, int(math.ceil(d / (speed * target) * (1.0 - 1e-12))))
        dt = d / (per_cell * speed)
    nsteps = max(2, int(math.ceil(ext.travel / (speed * dt) - 1e-9)))
    travel = nsteps * speed * dt
    back = checkpoint if checkpoint is not None else a
    nback = per_cell * max(1, int(round(back / d))) if per_cell is not None else max(1, int(round(back / (speed * dt))))
    ncheck = max(1, nsteps - nback)

    pxe = grid.x_edges
    q = np.asarray(flux, dtype=float).reshape(-1)
    cov = np.asarray(cover, dtype=float).reshape(-1)
    base_h = dt * h * d / cap_top
    src = np.zeros(nx)
    hloss = np.zeros(nx)
    if h > 0:
        hloss[1:-1] = base_h
    prev = [1, 1]
    r = kappa * dt / d ** 2
    T = np.zeros((nx, nz))
    Tn = np.zeros((nx, nz))
    e_in = e_dir = e_conv = 0.0
    fields = {}

    if scheme == "implicit":
        # the 3-D operator with one lateral node of unit width is the 2-D one (per unit width).
        # Solver: when the capacity term dominates (rho c d^2/(lambda dt) >= 10: high Péclet
        # number, dt ~ d/V) the z-line preconditioned CG of the 3-D block needs about two
        # iterations a step and beats a sparse LU (7.7 s against 18 s for 635 steps on 190k nodes);
        # otherwise the LU factorised once wins (5.4 s against 14 s at Pe = 1, 75k nodes).
        coef = _implicit_coefficients(nx, 1, nz, d, np.ones(1), wz, lam, rc, dt)
        T3 = T.reshape(nx, 1, nz)
        cg_iters, cg_worst, cg_failed = 0, 0.0, 0
        use_cg = rc * d * d / (lam * dt) >= CG_MIN_CAPACITY_RATIO
        if use_cg:
            work = [np.zeros((nx, 1, nz)) for _ in range(4)]
        else:
            from scipy.sparse.linalg import splu
            lu = splu(_stencil_matrix(coef, (nx, nz)), permc_spec="MMD_AT_PLUS_A")
    elif scheme != "explicit":
        raise ValueError(f"scheme must be 'explicit' or 'implicit', got {scheme!r}")

    def patch_field(Tarr, xs):
        surf = np.interp(grid.x, xn - xs, Tarr[:, 0])
        dep = _linear_rows(xn - xs, Tarr, grid.x)
        return surf, dep

    def load(n):
        lo_prev, hi_prev = prev
        s0 = X0 + speed * dt * n
        s1 = s0 + speed * dt
        lo = max(1, int(math.floor((s0 + pxe[0]) / d)) - 1)
        hi = min(nx - 1, int(math.ceil((s1 + pxe[-1]) / d)) + 2)
        src[lo_prev:hi_prev] = 0.0
        if h > 0:
            hloss[lo_prev:hi_prev] = base_h
        xi_ = xn[lo:hi]
        Wx = box_overlap((xi_ - 0.5 * d - s0)[:, None], (xi_ + 0.5 * d - s0)[:, None], pxe[:-1][None, :],
                         pxe[1:][None, :], 0.0, s1 - s0)          # (m, nxp) [m]
        Q = Wx @ q                                                # [W/m]
        src[lo:hi] = dt * Q / cap_top
        if h > 0:
            C = (Wx @ cov) / d
            hloss[lo:hi] = base_h * (1.0 - np.clip(C, 0.0, 1.0))
        prev[0], prev[1] = lo, hi
        return dt * float(Q.sum())

    def fixed_losses(Tarr):
        return dt * lam / d * (float((wz * Tarr[1]).sum()) + float((wz * Tarr[-2]).sum())
                               + d * float(Tarr[1:-1, -2].sum()))

    n = 0
    while n < nsteps:
        e_in += load(n)
        if h > 0:
            e_conv += float((hloss[1:-1] * cap_top * T[1:-1, 0]).sum())
        if scheme == "explicit":
            e_dir += fixed_losses(T)
            explicit_step_2d(T, Tn, r, src, hloss)
            T, Tn = Tn, T
        else:
            rhs = coef["mass"] * T3
            rhs[:, 0, 0] += cap_top * (src - hloss * T[:, 0]) / dt
            rhs[0] = rhs[-1] = 0.0
            rhs[:, :, -1] = 0.0
            if use_cg:
                it, res = _cg(coef, rhs, T3, work)
                cg_iters += it
                cg_worst = max(cg_worst, res)
                cg_failed += res > CG_RTOL
            else:
                T[:] = lu.solve(rhs.reshape(-1)).reshape(nx, nz)
            e_dir += fixed_losses(T)
        n += 1
        if n == ncheck:
            fields["check"] = patch_field(T, X0 + speed * dt * n)[0]
    surf, dep = patch_field(T, X0 + travel)
    stored = rc * d * float((wz[None, :] * T).sum())
    # (heat carried by the field: stored + lost - heat put in) / heat put in (docs/verdicts.md)
    balance = (stored + e_dir + e_conv - e_in) / e_in if e_in > 0 else 0.0
    smax = float(np.max(np.abs(surf))) or 1.0
    qs_change = float(np.max(np.abs(surf - fields.get("check", surf)))) / smax
    diag = {
        "scheme": scheme, "dimension": 2, "cell_size": d, "time_step": dt, "stability_limit": dt_stab,
        "steps": nsteps, "nodes": int(nx * nz), "node_shape": f"{nx}x{nz}",
        "cell_updates": int((nx - 2) * (nz - 1) * nsteps), "travel": travel,
        "block_length": float(xn[-1]), "block_depth": float(zn[-1]),
        "energy_in": e_in, "energy_stored": stored, "energy_lost_fixed_faces": e_dir,
        "energy_lost_convection": e_conv, "heat_balance_error": balance,
        "quasi_steady_change": qs_change, "quasi_steady": bool(qs_change < 2e-3), "fourier_number": r,
        "wall_time_solver": time.perf_counter() - t0,
    }
    if scheme == "implicit":
        # CG: each step to its own tolerance CG_RTOL, converged when every step met it; LU: direct
        diag.update({"linear_solver": "cg" if use_cg else "lu", "cg_iterations": cg_iters,
                     "cg_worst_residual": cg_worst, "cg_tolerance": CG_RTOL, "cg_failed_steps": int(cg_failed),
                     "converged": bool(cg_failed == 0), "iterations": int(cg_iters), "residual": float(cg_worst)})
    else:
        # explicit time stepping: no iterative solve (0 iterations, residual 0)
        diag.update({"converged": True, "iterations": 0, "residual": 0.0})
    return BlockResult(surf, zn.copy(), dep, diag)


def _stencil_matrix(coef, shape):
    """The 5-point operator of ``coef`` (3-D layout with one lateral node) as a CSC matrix."""
    from scipy.sparse import diags
    nx, nz = shape
    n = nx * nz
    f = lambda k: coef[k].reshape(-1)  # noqa: E731
    east = f("aE")[:-nz]          # row (i, k) -> (i+1, k)
    west = f("aW")[nz:]           # row (i, k) -> (i-1, k)
    bot = f("aB")[:-1].copy()     # row (i, k) -> (i, k+1)
    top = f("aT")[1:].copy()      # row (i, k) -> (i, k-1)
    bot[nz - 1::nz] = 0.0         # no coupling across columns
    top[nz - 1::nz] = 0.0
    return diags([f("aP"), -east, -west, -bot, -top], [0, nz, -nz, 1, -1], shape=(n, n), format="csc")


def steady_line(grid, flux, cover, speed, conductivity, density, specific_heat, convection, cell, *,
                level=0, ratio=1.3, surface_layers=4, extent=None, x_scheme="upwind2", max_cells=4e6):
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

    Returns
    -------
    BlockResult
    """
    _check_line(grid)
    if x_scheme not in X_SCHEMES:
        raise ValueError(f"x_scheme must be one of {X_SCHEMES}, got {x_scheme!r}")
    from scipy.sparse import csc_matrix
    from scipy.sparse.linalg import splu

    t0 = time.perf_counter()
    lam, rc = float(conductivity), float(density) * float(specific_heat)
    kappa = lam / rc
    h = float(convection)
    V = float(speed)
    a = float(grid.x_edges[-1])
    ext = extent or line_extent(a, V, kappa)
    rk = ratio ** (1.0 / 2 ** level)
    nxa = max(2, int(round(2 * a / cell)))
    xe = _graded(-a, a, nxa, -a - ext.behind, a + ext.ahead, rk)
    delta = thermal_scales(a, V, kappa).thermal_depth
    dz1 = min(cell, delta / surface_layers / 2 ** level)
    ze = _graded_depth(dz1, ext.depth, rk)
    dx, dz = np.diff(xe), np.diff(ze)
    xc, zc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ze[1:] + ze[:-1])
    nx, nz = dx.size, dz.size
    n = nx * nz
    if n > max_cells:
        raise Refused(f"model 'fdm' (steady, line): the graded grid needs {nx}x{nz} = {n:.3g} cells at level "
                      f"{level}, above the limit {max_cells:.3g}; use a lower level or a larger cell_size", kind="budget")
    Wx = box_overlap(xe[:-1, None], xe[1:, None], grid.x_edges[None, :-1], grid.x_edges[None, 1:])
    Q = Wx @ np.asarray(flux, dtype=float).reshape(-1)                 # [W/m]
    cov = np.clip(Wx @ np.asarray(cover, dtype=float).reshape(-1) / dx, 0.0, 1.0)
    hA = h * dx * (1.0 - cov)                                          # [W/(m K)]

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
    rhs = np.zeros((nx, nz))
    rhs[:, 0] = Q
    # orderings measured on 2-D grids: minimum degree on A^T + A for the (diagonally dominant)
    # exponential matrix; column AMD for the second-order upwind one, whose off-diagonal pivots make
    # the symmetric ordering fill in ten times more
    lu = splu(A, permc_spec="MMD_AT_PLUS_A" if x_scheme == "exponential" else "COLAMD")
    T = lu.solve(rhs.reshape(-1)).reshape(nx, nz)
    resid = float(np.linalg.norm(A @ T.reshape(-1) - rhs.reshape(-1)) / (np.linalg.norm(rhs) or 1.0))

    e_in = float(Q.sum())
    out_adv = float((F * T[0]).sum())
    out_inflow = float((inflow_coef * T[-1]).sum())
    out_bottom = float((Dbot * T[:, -1]).sum())
    out_conv = float((hA * T[:, 0]).sum())
    # (heat carried out by the field - heat put in) / heat put in (docs/verdicts.md)
    balance = (out_adv + out_inflow + out_bottom + out_conv - e_in) / e_in if e_in > 0 else 0.0

    qcell = Q / dx
    z1, z2 = zc[0], zc[1]
    t1, t2 = T[:, 0], T[:, 1]
    slope = -(qcell - hA / dx * t1) / lam
    B = ((t2 - t1) - slope * (z2 - z1)) / (z2 ** 2 - z1 ** 2)
    ts = t1 - slope * z1 - B * z1 ** 2
    surf = np.interp(grid.x, xc, ts)
    prof = np.concatenate([ts[:, None], T], axis=1)
    dep = _linear_rows(xc, prof, grid.x)
    diag = {
        "scheme": "steady", "dimension": 2, "x_scheme": x_scheme, "cell_size": float(cell),
        "first_depth_cell": float(dz[0]), "growth_ratio": rk, "cells": int(n), "cell_shape": f"{nx}x{nz}",
        # one sparse LU solve (direct: 0 iterations); its relative residual ||A T - b|| / ||b||
        "iterations": 0, "residual": resid, "converged": bool(resid < 1e-8),
        "energy_in": e_in, "energy_out_advected": out_adv, "energy_lost_fixed_faces": out_inflow + out_bottom,
        "energy_lost_convection": out_conv, "heat_balance_error": balance,
        "block_length": float(xe[-1] - xe[0]), "block_depth": float(ze[-1]),
        "wall_time_solver": time.perf_counter() - t0,
    }
    return BlockResult(surf, np.concatenate([[0.0], zc]), dep, diag)
