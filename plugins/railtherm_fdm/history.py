"""fdm's transient histories on a line contact: the rail section (x-z block) under repeated passes.

The section's material point lies in a 2-D block (rail frame, per unit width) x in [-W, W], z in [0, L_z];
the band source sweeps over its top face once per pass, its flux times the scene's schedule. Node-centred
finite volumes (seed 6.3, as :mod:`.block2d`), fine along x near the section and graded from the surface in
z on the contact-time thermal layer: ``C d theta/dt = -K theta + P(t)``. While a source is over the block
the explicit (forward Euler) or Crank-Nicolson scheme runs, chosen by cost (:func:`heating_scheme`,
:data:`IMPLICIT_COST_FACTOR`); between passes a ladder of growing steps, explicit or Peaceman-Rachford ADI
(:data:`ADI_COST_FACTOR`) after two backward-Euler start steps [2]. Neglected: conduction beyond the
block's insulated x ends (a fraction 1/(4 Pe) of the vertical flow) and the tread's curvature. Grid,
stepping and error: docs/NOTES.md, "FDM pass histories on a line contact".

References: [1] The seed paper, section 6.3 (docs/references.md). [2] R. Rannacher, Finite element
solution of diffusion problems with irregular data, Numer. Math. 43 (1984) 309-327,
doi:10.1007/BF01390130 (backward-Euler start steps before Crank-Nicolson).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy.sparse import diags, csr_matrix
from scipy.sparse.linalg import splu

from railtherm import heating_scheme as core_heating_scheme
from railtherm import histories_at_section, section_history, superposed_history, theta_steps
from railtherm.physics import thermal_scales

from .history3d import ellipse_block
from .layout import depth_nodes, rail_nodes

__all__ = ["SectionBlock", "BandSource", "ImplicitSection", "section_block", "section_history", "superposed_history", "body_histories", "heating_scheme",
           "rail_nodes", "depth_nodes", "IMPLICIT_COST_FACTOR", "ADI_COST_FACTOR"]

#: one implicit (Crank-Nicolson, sparse LU) step counted as this many explicit node updates per node
IMPLICIT_COST_FACTOR = 50.0
#: one alternating-direction step (two tridiagonal sweeps) in explicit steps of the same block
ADI_COST_FACTOR = 4.0


@dataclass(frozen=True)
class SectionBlock:
    """The x-z block around the section and its finite-volume operator.

    Attributes
    ----------
    x : ndarray (nx,)
        Node positions along the rail [m], section x = 0 at index ``i0``.
    z : ndarray (nz,)
        Node depths [m] (unknowns; theta = 0 one spacing below the last).
    capacity : ndarray (nx * nz,)
        C [J/(K m)], index i * nz + j.
    stiffness : scipy.sparse.csr_matrix
        K [W/(K m)].
    top_width : ndarray (nx,)
        Dual-cell widths of the top nodes [m].
    dt_stab : float
        Explicit stability limit min C/K_ii [s].
    depth_index : ndarray of int
        The nodes of the output depths.
    gx : ndarray (nx - 1, nz)
        Conductances between neighbours along x [W/(K m)].
    gz : ndarray (nx, nz)
        Conductances to the node below (the last row: to the fixed bottom) [W/(K m)].
    convection : ndarray (nx,)
        h times the top nodes' dual-cell widths [W/(K m)].
    """

    x: np.ndarray
    z: np.ndarray
    i0: int
    capacity: np.ndarray
    stiffness: csr_matrix
    top_width: np.ndarray
    dt_stab: float
    depth_index: np.ndarray
    gx: np.ndarray
    gz: np.ndarray
    convection: np.ndarray

    @property
    def node_shape(self) -> str:
        return f"{self.x.size}x{self.z.size}"

    def stepper(self, x_edges, y_edges, flux, speed, factor, t0):
        """A :class:`_Stepper` of this block under the band's ``flux`` (nx,) [W/m^2] on ``x_edges`` [m]
        (``y_edges`` None) at ``speed`` [m/s], heat-input factor ``factor(t)``, from t0 [s]."""
        return _Stepper(self, BandSource(self, x_edges, flux, speed), factor, t0)


def section_block(a: float, speed: float, conductivity: float, capacity: float, convection: float, level: int,
                  duration_total: float, depths) -> SectionBlock:
    """The block of the module docstring for a band of half-width ``a`` [m] at ``speed`` [m/s], material
    lambda [W/(m K)] and rho c [J/(m^3 K)], top convection h [W/(m^2 K)], refinement ``level``, a history
    of ``duration_total`` [s] and the output ``depths`` [m]."""
    kappa = conductivity / capacity
    delta = thermal_scales(a, speed, kappa).thermal_depth
    reach = math.sqrt(kappa * duration_total)
    x = rail_nodes(a, reach, level)
    n_half = (x.size - 1) // 2
    bottom = max(8.0 * reach, 10.0 * delta, 1.5 * max(depths))
    z = depth_nodes(delta / 4.0 / 2 ** int(level), 1.3 ** (1.0 / 2 ** int(level)), bottom, depths)
    nx, nz = x.size, z.size
    gx_len = np.diff(x)                                 # (nx - 1,) node gaps
    wx = 0.5 * (np.concatenate([[0.0], gx_len]) + np.concatenate([gx_len, [0.0]]))
    gaps = np.diff(z)                                   # (nz - 1,); theta = 0 at z[-1] + gaps[-1]
    below = np.append(gaps, gaps[-1])
    wz = 0.5 * (below + np.concatenate([[0.0], gaps]))
    cap = (capacity * wx[:, None] * wz[None, :]).ravel()
    idx = np.arange(nx * nz).reshape(nx, nz)
    gx = conductivity * wz[None, :] / gx_len[:, None]
    gz = conductivity * wx[:, None] / below[None, :]    # (nx, nz): to the node below (or the fixed bottom)
    diag = np.zeros((nx, nz))
    diag[:-1] += gx
    diag[1:] += gx
    diag += gz
    diag[:, 1:] += gz[:, :-1]
    diag[:, 0] += convection * wx
    rows = [idx.ravel(), idx[:-1].ravel(), idx[1:].ravel(), idx[:, :-1].ravel(), idx[:, 1:].ravel()]
    cols = [idx.ravel(), idx[1:].ravel(), idx[:-1].ravel(), idx[:, 1:].ravel(), idx[:, :-1].ravel()]
    vals = [diag.ravel(), -gx.ravel(), -gx.ravel(), -gz[:, :-1].ravel(), -gz[:, :-1].ravel()]
    stiff = csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nx * nz,) * 2)
    dt_stab = float(np.min(cap / diag.ravel()))
    nodes = np.array([int(np.argmin(np.abs(z - d))) for d in depths])
    return SectionBlock(x, z, n_half, cap, stiff, wx, dt_stab, nodes,
                        np.ascontiguousarray(gx), np.ascontiguousarray(gz), convection * wx)


class BandSource:
    """The band's flux [W/m^2] as its cumulative integral on the source grid [W/m], and the top nodes' dual
    cells [m]: the power [W/m] of a node is the difference of the cumulative integral over its cell."""

    def __init__(self, block: SectionBlock, x_edges, flux, speed):
        self.xe = np.asarray(x_edges, dtype=float)
        self.cum = np.concatenate([[0.0], np.cumsum(np.asarray(flux, dtype=float) * np.diff(self.xe))])
        mid = 0.5 * (block.x[1:] + block.x[:-1])        # dual cells between the node midpoints
        self.lo = np.concatenate([[block.x[0]], mid])
        self.hi = np.concatenate([mid, [block.x[-1]]])
        self.speed = float(speed)

    def power(self, tau: float) -> np.ndarray:
        """At time tau after the pass's arrival [s]: the node at x meets the contact at xi = x_lead + x - V tau."""
        shift = self.xe[-1] - self.speed * tau
        return np.interp(self.hi + shift, self.xe, self.cum) - np.interp(self.lo + shift, self.xe, self.cum)


@numba.njit(cache=True)
def _interp(x, xp, fp):  # pragma: no cover - compiled
    """``numpy.interp(x, xp, fp)`` for one x (xp increasing), by the same formula: numba's own np.interp
    costs each process about 7 s of compilation (its broadcasting and error-message paths)."""
    n = xp.size
    if x > xp[n - 1]:
        return fp[n - 1]
    if x < xp[0]:
        return fp[0]
    lo, hi = 0, n                          # the last j with xp[j] <= x
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xp[mid] <= x:
            lo = mid
        else:
            hi = mid
    if lo == n - 1 or xp[lo] == x:
        return fp[lo]
    slope = (fp[lo + 1] - fp[lo]) / (xp[lo + 1] - xp[lo])
    return slope * (x - xp[lo]) + fp[lo]


@numba.njit(cache=True)
def _explicit_steps(T, cinv, gx, gz, hconv, dt, t0, factors, arrivals, lo, hi, xe, cum, speed, i0, jd,
                    out):  # pragma: no cover - compiled
    """``factors.size`` forward-Euler steps of the block from time t0 [s] (T (nx, nz) updated in place); the
    source of the passes arriving at ``arrivals`` [s] at each step's mid-time times ``factors`` (0: none);
    the section's rise at the depth nodes ``jd`` after each step into out (steps, depths)."""
    nx, nz = T.shape
    tn = np.empty_like(T)
    p = np.zeros(nx)
    lead = xe[-1]
    for s in range(factors.size):
        f = factors[s]
        p[:] = 0.0
        if f != 0.0:
            tm = t0 + (s + 0.5) * dt
            for k in range(arrivals.size):
                shift = lead - speed * (tm - arrivals[k])
                if hi[-1] + shift <= xe[0] or lo[0] + shift >= lead:
                    continue
                for i in range(nx):
                    p[i] += f * (_interp(hi[i] + shift, xe, cum) - _interp(lo[i] + shift, xe, cum))
        for i in range(nx):
            for j in range(nz):
                tij = T[i, j]
                flow = gz[i, j] * ((T[i, j + 1] if j < nz - 1 else 0.0) - tij)
                if i > 0:
                    flow += gx[i - 1, j] * (T[i - 1, j] - tij)
                if i < nx - 1:
                    flow += gx[i, j] * (T[i + 1, j] - tij)
                if j > 0:
                    flow += gz[i, j - 1] * (T[i, j - 1] - tij)
                else:
                    flow += p[i] - hconv[i] * tij
                tn[i, j] = tij + dt * cinv[i, j] * flow
        T[:, :] = tn
        for d in range(jd.size):
            out[s, d] = T[i0, jd[d]]


@numba.njit(cache=True)
def _thomas(lower, diag, upper, rhs, out, work):  # pragma: no cover - compiled
    """Solve the tridiagonal system (lower[i] x[i-1] + diag[i] x[i] + upper[i] x[i+1] = rhs[i]) into out."""
    n = diag.size
    work[0] = upper[0] / diag[0]
    out[0] = rhs[0] / diag[0]
    for i in range(1, n):
        m = diag[i] - lower[i] * work[i - 1]
        work[i] = upper[i] / m
        out[i] = (rhs[i] - lower[i] * out[i - 1]) / m
    for i in range(n - 2, -1, -1):
        out[i] -= work[i] * out[i + 1]


@numba.njit(cache=True)
def _adi_steps(T, cap, gx, gz, hconv, dt, m, lie, jd, i0, out):  # pragma: no cover - compiled
    """m source-free steps of dt of ``C dT/dt = -(Kx + Kz) T`` (T (nx, nz) in place): Peaceman-Rachford
    (second order) or, ``lie`` True, backward Euler in x then in z (first order, damps the stiff modes);
    tridiagonal solves along x per depth and along z per column. Kz holds the convection of the top row and
    the fixed bottom. The section's rise at the depth nodes jd after each step into out."""
    nx, nz = T.shape
    half = dt if lie else 0.5 * dt
    ts = np.empty_like(T)
    bx = np.empty((6, nx))
    bz = np.empty((6, nz))
    lo_x, di_x, up_x, r_x, o_x, w_x = bx[0], bx[1], bx[2], bx[3], bx[4], bx[5]
    lo_z, di_z, up_z, r_z, o_z, w_z = bz[0], bz[1], bz[2], bz[3], bz[4], bz[5]
    for s in range(m):
        # x sweep: (C/half + Kx) T* = (C/half - Kz) T   (lie: C/half T)
        for j in range(nz):
            for i in range(nx):
                c = cap[i, j] / half
                kd = 0.0
                lo_x[i] = 0.0
                up_x[i] = 0.0
                if i > 0:
                    kd += gx[i - 1, j]
                    lo_x[i] = -gx[i - 1, j]
                if i < nx - 1:
                    kd += gx[i, j]
                    up_x[i] = -gx[i, j]
                di_x[i] = c + kd
                r = c * T[i, j]
                if not lie:
                    kz = gz[i, j] * (T[i, j] - (T[i, j + 1] if j < nz - 1 else 0.0))
                    if j > 0:
                        kz += gz[i, j - 1] * (T[i, j] - T[i, j - 1])
                    else:
                        kz += hconv[i] * T[i, j]
                    r -= kz
                r_x[i] = r
            _thomas(lo_x, di_x, up_x, r_x, o_x, w_x)
            for i in range(nx):
                ts[i, j] = o_x[i]
        # z sweep: (C/half + Kz) T' = (C/half - Kx) T*   (lie: C/half T*)
        for i in range(nx):
            for j in range(nz):
                c = cap[i, j] / half
                kd = gz[i, j]
                lo_z[j] = 0.0
                up_z[j] = -gz[i, j] if j < nz - 1 else 0.0
                if j > 0:
                    kd += gz[i, j - 1]
                    lo_z[j] = -gz[i, j - 1]
                else:
                    kd += hconv[i]
                di_z[j] = c + kd
                r = c * ts[i, j]
                if not lie:
                    kx = 0.0
                    if i > 0:
                        kx += gx[i - 1, j] * (ts[i, j] - ts[i - 1, j])
                    if i < nx - 1:
                        kx += gx[i, j] * (ts[i, j] - ts[i + 1, j])
                    r -= kx
                r_z[j] = r
            _thomas(lo_z, di_z, up_z, r_z, o_z, w_z)
            for j in range(nz):
                T[i, j] = o_z[j]
        for d in range(jd.size):
            out[s, d] = T[i0, jd[d]]


class ImplicitSection:
    """theta-scheme steps (1: backward Euler, 0.5: Crank-Nicolson) with one LU per (dt, theta)."""

    def __init__(self, block: SectionBlock):
        self.C = block.capacity
        self.K = block.stiffness
        self.cache = {}
        self.solves = 0

    def step(self, T, dt, theta, p_old, p_new):
        key = (float(dt), float(theta))
        lu = self.cache.get(key)
        if lu is None:
            lu = splu((diags(self.C / dt) + theta * self.K).tocsc())
            self.cache[key] = lu
        rhs = self.C / dt * T - (1.0 - theta) * (self.K @ T) + theta * p_new + (1.0 - theta) * p_old
        self.solves += 1
        return lu.solve(rhs)


class _Stepper:
    """The block's state, clock and recorded samples, stepped explicitly (numba) or implicitly (LU); an
    implicit heating step costs :data:`IMPLICIT_COST_FACTOR` explicit node updates, a cooling step
    :data:`ADI_COST_FACTOR` explicit steps."""

    heating_cost = IMPLICIT_COST_FACTOR
    implicit_cost = ADI_COST_FACTOR
    cooling_implicit = "alternating-direction steps (Peaceman-Rachford, two backward-Euler start steps)"

    def fresh(self, t0: float) -> "_Stepper":
        """A stepper of the same block and source from t0 [s], state zero."""
        return _Stepper(self.b, self.src, self.factor, t0)

    def __init__(self, block: SectionBlock, source: BandSource, factor, t0: float):
        self.b = block
        self.src = source
        self.factor = factor
        nx, nz = block.x.size, block.z.size
        self.shape = (nx, nz)
        self.T = np.zeros((nx, nz))
        self.t = t0
        self.cinv = (1.0 / block.capacity).reshape(nx, nz)
        self.implicit = ImplicitSection(block)
        self.times, self.rows = [], []
        self.explicit_steps = 0
        self.adi_steps = 0

    def explicit(self, dt: float, m: int, arrivals, heated: bool = True):
        """m forward-Euler steps of dt; all steps recorded."""
        b = self.b
        mids = self.t + (np.arange(m) + 0.5) * dt
        f = np.asarray(self.factor(mids), dtype=float) if heated else np.zeros(m)
        out = np.empty((m, b.depth_index.size))
        _explicit_steps(self.T, self.cinv, b.gx, b.gz, b.convection, float(dt), float(self.t), f,
                        np.asarray(arrivals, dtype=float), self.src.lo, self.src.hi, self.src.xe, self.src.cum,
                        self.src.speed, int(b.i0), b.depth_index, out)
        self.times.append(self.t + dt * np.arange(1, m + 1))
        self.rows.append(out)
        self.t += m * dt
        self.explicit_steps += m

    def adi(self, dt: float, m: int, start: int = 0):
        """m source-free alternating-direction steps of dt, the first ``start`` backward Euler (Lie)."""
        b = self.b
        cap = b.capacity.reshape(self.shape)
        out = np.empty((m, b.depth_index.size))
        for lo, hi, lie in ((0, min(start, m), True), (min(start, m), m, False)):
            if hi > lo:
                _adi_steps(self.T, cap, b.gx, b.gz, b.convection, float(dt), hi - lo, lie, b.depth_index,
                           int(b.i0), out[lo:hi])
        self.times.append(self.t + dt * np.arange(1, m + 1))
        self.rows.append(out)
        self.t += m * dt
        self.adi_steps += m

    def implicit_steps(self, dt: float, m: int, arrivals=(), theta: float = 0.5, start: int = 0):
        """m theta-scheme steps of dt (the first ``start`` backward Euler); source of ``arrivals``."""
        b = self.b
        nx, nz = self.shape
        top = np.arange(nx) * nz

        def power(t):
            p = np.zeros(nx * nz)
            for arr in arrivals:
                p[top] += self.src.power(t - arr)
            return p * float(self.factor(t)) if len(arrivals) else p
        T, self.t, out, times = theta_steps(
            self.T.reshape(-1), self.t, dt, m, power, self.implicit.step,
            lambda T: T.reshape(nx, nz)[b.i0, b.depth_index], b.depth_index.size, theta, start)
        self.T = T.reshape(nx, nz)
        self.times.append(times)
        self.rows.append(out)


def heating_scheme(requested: str, dt_stab: float, dt_source: float,
                   implicit_cost: float = IMPLICIT_COST_FACTOR) -> tuple[str, float, str]:
    """:func:`railtherm.solving.section_stepping.heating_scheme` with the 2-D block's implicit cost
    (a Crank-Nicolson LU solve: :data:`IMPLICIT_COST_FACTOR` explicit node updates) by default."""
    return core_heating_scheme(requested, dt_stab, dt_source, implicit_cost)


def body_histories(transient, convection, grid, fluxes, bodies, speeds, bulk, level: int, requested: str = "auto",
                   max_nodes: float = math.inf):
    """:func:`railtherm.solving.section_stepping.histories_at_section` on fdm's blocks: the 2-D section block of a
    line contact, the 3-D block (:mod:`.history3d`) of a patch, refused above ``max_nodes`` nodes.

    ``transient``: the scene's passes (count, interval [s], schedule, history depths [m]); ``convection``: the
    surface heat transfer coefficient [W/(m^2 K)] (None: 0); ``grid``: the source's grid; ``fluxes``: each body's
    flux [W/m^2] on it (None: not heated); ``bodies``: the wheel's and the rail's materials; ``speeds``: their
    surface speeds through the contact [m/s]; ``bulk``: their bulk temperatures [degC]."""
    def make_block(v, m, convection, duration, z):
        args = (v, m.conductivity, m.density * m.specific_heat, convection, level, duration, z)
        if grid.line:
            return section_block(float(grid.a), *args)
        return ellipse_block(float(grid.a), float(grid.b), *args, max_nodes=max_nodes,
                             body="wheel" if m is bodies[0] else "rail")
    what = ("finite-volume block around the section (2-D for a line contact, 3-D for a patch), explicit while a "
            "source is over it and implicit between passes, chosen by cost")
    return histories_at_section(transient, convection, grid.x_edges, grid.y_edges, fluxes,
                                speeds, bodies, bulk, level, requested, make_block, what,
                                "conduction along the rail beyond the block's ends; the wheel's curvature")
