"""Transient heating of the wheel over many revolutions (FiPy, implicit Euler in time).

One contact lasts ``2a / V`` (0.4 ms at 30 m/s); the wheel warms up over minutes to hours (seed §5.3). After
one revolution the flash layer has diffused into the rim, so on the warm-up's time scale the tread sees the
revolution-averaged heat balance of seed §5.1-5.3: frictional heat ``eps P`` in, conduction into the cold
rail ``G_cond T_s`` (Blok fraction ``eps_c``, seed eqs. 40-43) and convection ``alpha A_c T_s``
(:func:`railtherm.physics.convective_area`, seed eqs. 45-48) out. FiPy solves the radial conduction
``rho c dT/dt = (1/r) d/dr (lambda r dT/dr)`` in a disc of the rolling radius and the running band's width,
with that balance as tread flux; its steady state is :func:`railtherm.physics.lumped_wheel` (seed eq. 52).
Reported: the tread temperature at the end and the steady flash fields shifted by superposition (seed
eq. 54). Time steps: ``numerics.time_step`` if given, else growing from ``tau / 1e4`` (:func:`time_steps`);
duration ``numerics.duration`` or ``numerics.revolutions`` turns, default ``8 tau``. Derivation of
``G_cond`` and the reported fields: docs/NOTES.md, "FiPy transient".
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from railtherm import Refused, SolverError
from railtherm.physics import (conduction_conductance, convective_area, equal_temperature_partition,
                               geometric_edges)

from .solvers import assemble, import_fipy, lu_factor

#: wall time of one implicit step of the radial wheel problem [s]: measured 35 us per step at 28 radial
#: cells (E&K scene, transient mode, numerics.time_step = 0.01 s over 200 s: 20 000 steps in 0.71 s,
#: OPENBLAS_NUM_THREADS=1); the estimate takes 4e-5 s. Used to refuse fixed-step runs over the
#: ``max_seconds`` budget before they start (1e6 steps would take ~40 s).
SECONDS_PER_STEP = 4e-5


def time_steps(duration: float, tau: float, level: int, fixed: float | None = None) -> list[float]:
    """Implicit-Euler time steps [s] covering ``duration``.

    ``fixed`` (``numerics.time_step``) gives constant steps; otherwise steps grow by 10 % from
    ``tau / 1e4`` (the sqrt(t) start of a suddenly heated surface) up to ``max(tau / 20, t / 50)``
    (the late approach is governed by the slow radial conduction, time scale R^2 / kappa >> tau).
    Level k divides every step by ``2**k``.
    """
    k = 2 ** int(level)
    if fixed is not None:
        n = max(1, int(math.ceil(duration * k / float(fixed) - 1e-9)))
        return [duration / n] * n
    dts, t, dt = [], 0.0, tau / 1e4 / k
    growth = 1.1 ** (1.0 / k)
    while t < duration * (1 - 1e-12):
        step = min(dt, duration - t)
        dts.append(step)
        t += step
        dt = min(dt * growth, max(tau / 20.0, t / 50.0) / k)
    return dts


def wheel_heating(bodies, convection: float | None, wheel_radius: float | None, numerics, source, level: int,
                  options: dict, flash=None, name: str = "?") -> dict:
    """Integrate the wheel's warm-up with FiPy (see the module docstring).

    Parameters
    ----------
    bodies : (Material, Material)
        Wheel and rail.
    convection : float or None
        Heat transfer coefficient of the tread [W/(m^2 K)] (None: 0).
    wheel_radius : float or None
        Rolling radius [m] (None: the wheel's ``radius``).
    numerics : mapping or None
        The scene's ``numerics``: ``time_step`` [s], ``duration`` [s], ``revolutions`` [1].
    source : railtherm.HeatSource
        Heat source (grid, power density, partition, body speeds).
    level : int
        Refinement level: radial cells and time steps double per level.
    options : dict
        Model options (unused keys ignored).
    flash : TemperatureField, optional
        Unused; kept for symmetry with the steady path.
    name : str
        The scene's name (in a refusal's message).

    Returns
    -------
    dict
        ``t`` [s], ``tread`` [K rise], ``mean`` [K rise] (volume mean of the disc) histories,
        ``t_inf`` [K] (lumped steady state), ``tau`` [s], ``eps_c`` [1], ``g_cond`` [W/K],
        ``power`` [W] into the wheel, diagnostics ``iterations``, ``residual``, ``converged``, ``steps``.
    """
    fp = import_fipy()
    grid = source.grid
    wheel, rail = bodies
    v_w, v_r = (float(v) for v in source.body_speed)
    R = float(wheel_radius or wheel.radius)
    width = 1.0 if grid.line else 2.0 * grid.b
    area = 2.0 * math.pi * R * width
    b = None if grid.line else grid.b
    power = float(grid.integrate(np.asarray(source.flux(0), dtype=float) * np.ones(grid.shape)))
    eps_c = equal_temperature_partition(wheel, rail, v_w, v_r)
    g_cond = conduction_conductance(rail.effusivity, v_r, eps_c, grid.a, b)
    alpha = float(convection or 0.0)
    area_c = convective_area(R, b)
    g_tot = g_cond + alpha * area_c
    t_inf = power / g_tot
    rho_c = wheel.density * wheel.specific_heat
    lam = wheel.conductivity
    tau = rho_c * math.pi * R * R * width / g_tot
    num = dict(numerics or {})
    duration = _duration(num, R, v_w, tau)
    if num.get("time_step") is not None:
        _check_budget(name, num, level, duration, tau, options)
    # radial mesh graded towards the tread: first cell resolves the diffusion length of the first step
    dt0 = float(num.get("time_step", tau / 1e4))
    first = min(0.25 * math.sqrt(wheel.diffusivity * dt0), R / 20.0)
    mesh, T, L, b, dr1, c_half = _radial_operator(fp, R, first, level, lam, g_tot / area, power / area)
    vol = np.asarray(mesh.cellVolumes, dtype=float)
    cap = rho_c * vol
    dts = time_steps(duration, tau, level, num.get("time_step"))
    lift = power / area * dr1 / (2.0 * lam)          # tread surface: T_s = (T_P + lift) / (1 + c)
    ts, tr, mean, res, t, x = _march(L, b, cap, vol, dts, lambda x: (float(x[-1]) + lift) / (1.0 + c_half))
    T.value = x
    return {"t": np.array(ts), "tread": np.array(tr), "mean": np.array(mean), "t_inf": t_inf, "tau": tau,
            "eps_c": eps_c, "g_cond": g_cond, "power": power, "convective_area": area_c,
            "iterations": 1, "residual": res, "converged": True, "steps": len(dts), "duration": t,
            "radial_cells": int(mesh.numberOfCells), "first_cell": float(dr1), "area": area}


def _radial_operator(fp, R: float, first: float, level: int, lam: float, H: float, flux: float):
    """FiPy's radial conduction in a disc of radius ``R`` [m] (conductivity ``lam`` [W/(m K)]) with the tread's
    heat balance (``flux`` P/A [W/m^2] in, ``H`` G/A [W/(m^2 K)] out), cells graded towards the tread from
    ``first`` [m] by 1.3 at level 0: (mesh, the cell variable, the operator L and right side b of
    ``L T = b``, the tread cell's width dr [m], c = H dr / (2 lambda))."""
    e = R - geometric_edges(R, first, 1.3, level)[::-1]
    e[0] = 0.0
    mesh = fp.CylindricalGrid1D(dx=np.diff(e))
    T = fp.CellVariable(mesh=mesh, value=0.0, hasOld=True)
    dr1 = e[-1] - e[-2]
    tread = mesh.facesRight.value
    n = mesh.faceNormals
    # tread face: lambda (T_s - T_P) / (dr/2) = P/A - H T_s with H = G/A gives
    # T_s = (T_P + P/A dr/(2 lambda)) / (1 + c), c = H dr / (2 lambda); the flux into the cell is
    # (P/A) / (1 + c) - H_eff T_P with H_eff = H / (1 + c): exact steady state P / G.
    c_half = H * dr1 / (2.0 * lam)
    h_eff = H / (1.0 + c_half)
    q_in = fp.FaceVariable(mesh=mesh, value=np.where(tread, flux / (1.0 + c_half), 0.0))
    h_face = fp.FaceVariable(mesh=mesh, value=np.where(tread, h_eff, 0.0))
    # FiPy assembles the spatial operator once: L T = b for  div(lambda grad T) + flux - H_eff T = 0.
    # Implicit Euler, exactly what FiPy's TransientTerm(rho c) adds (rho c V / dt on the diagonal):
    #   (rho c V / dt - L) T_new = rho c V / dt T_old - b
    # The coefficients never change, so one assembly serves every step (and FiPy issue #1223 cannot bite).
    steady_eq = (fp.DiffusionTerm(coeff=lam) + (q_in * n).divergence
                 - fp.ImplicitSourceTerm(coeff=(h_face * n).divergence)) == 0
    L, b = assemble(steady_eq, T)
    return mesh, T, L, b, dr1, c_half


def _duration(num: dict, R: float, v_w: float, tau: float) -> float:
    """The time integrated [s]: ``numerics.duration``, or ``numerics.revolutions`` of the wheel, or 8 tau."""
    if "duration" in num:
        return float(num["duration"])
    if "revolutions" in num:
        return float(num["revolutions"]) * 2.0 * math.pi * R / v_w
    return 8.0 * tau


def _check_budget(name: str, num: dict, level: int, duration: float, tau: float, options: dict) -> None:
    """Refuse fixed time steps whose number is estimated to take more than ``max_seconds`` (known before
    anything is built; growing steps stay ~100s); ``name``: the scene's, for the message."""
    k = 2 ** int(level)
    n_steps = max(1, int(math.ceil(duration * k / float(num["time_step"]) - 1e-9)))
    seconds = n_steps * SECONDS_PER_STEP
    limit = float((options or {}).get("max_seconds", 60.0))
    if seconds > limit:
        raise Refused(
            f"scene {name!r}, model 'fipy' (transient wheel heating): numerics.time_step = "
            f"{float(num['time_step']):g} s over a duration of {duration:.4g} s (lumped time constant tau = "
            f"{tau:.4g} s) at level {level} is {n_steps:.3g} implicit steps, estimated at {seconds:.3g} s "
            f"({SECONDS_PER_STEP:g} s per step) > max_seconds = {limit:g} s; use time_step >= "
            f"{duration * k * SECONDS_PER_STEP / limit:.3g} s, a shorter numerics.duration, or no time_step "
            "(growing steps)", kind="budget")


def _march(L, b, cap, vol, dts, tread_of):
    """Implicit Euler steps ``(cap/dt - L) x_new = cap/dt x_old - b`` from x = 0 (one LU factorisation per
    distinct dt): times, tread rises (``tread_of(x)``), volume-mean rises, the largest relative residual,
    the final time and the final cell values."""
    ts, tr, mean = [0.0], [0.0], [0.0]
    res = 0.0
    t = 0.0
    x = np.zeros(vol.size)
    lu, lu_dt = None, None
    for dt in dts:
        if lu is None or dt != lu_dt:
            M = (sp.diags(cap / dt) - L).tocsc()
            lu, lu_dt = lu_factor(M), dt
        rhs = cap / dt * x - b
        x = lu.solve(rhs)
        rel = float(np.linalg.norm(M @ x - rhs) / max(np.linalg.norm(rhs), 1e-300))
        if not (np.all(np.isfinite(x)) and rel < 1e-9):
            raise SolverError(f"FiPy transient wheel heating: relative residual {rel:.3g} at t = {t:.4g} s")
        res = max(res, rel)
        t += dt
        ts.append(t)
        tr.append(tread_of(x))
        mean.append(float(np.sum(x * vol) / np.sum(vol)))
    return ts, tr, mean, res, t, x
