"""fdm's transient histories on an elliptical patch: the rail section as a 3-D block under repeated passes.

The 2-D section block of :mod:`.history` with the lateral direction added: node-centred finite volumes on
x in [-W, W] (the same nodes along the rail), y in [0, Y] (the centre line y = 0 a symmetry plane, the
ellipse symmetric about it: half the block, insulated there and at Y = b + 2 sqrt(kappa t_end)), z graded
from the surface as in 2-D; ``C d theta/dt = -K theta + P(t)`` [J/K, W/K, W]. Lateral spacing b/8/2**level
over the patch, growing by ``1.3 ** (1 / 2**level)`` beyond. The source term of a top node is the flux (piecewise
constant on the source grid) integrated exactly over the node's dual cell, at the step's mid-time.

The passes, windows, cooling ladder, residuals and superposition are :func:`.history.section_history`'s;
this block steps them with sparse matrix products (explicit) and conjugate gradients (implicit: theta-scheme
steps of ``C/dt + theta K``, Jacobi-preconditioned, warm-started), no factorisation of the 3-D operator.
What it neglects: conduction beyond the block's ends and its lateral side (insulated).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix, diags

from railtherm import Refused, theta_steps
from railtherm.physics import thermal_scales

from .layout import depth_nodes, rail_nodes

__all__ = ["EllipseBlock", "EllipseSource", "Implicit3D", "ellipse_block", "ellipse_nodes", "check_node_budget", "CG_RTOL", "CG_COST_FACTOR"]

#: relative residual of each implicit step's conjugate gradients
CG_RTOL = 1e-10
#: one implicit (conjugate-gradient) step counted as this many explicit steps of the same block
CG_COST_FACTOR = 30.0


def _graded(first: float, growth: float, uniform_to: float, end: float) -> np.ndarray:
    """Nodes from 0: spacing ``first`` up to ``uniform_to``, then growing by ``growth`` to ``end`` [m]."""
    y = [0.0]
    step = first
    while y[-1] < end:
        if y[-1] >= uniform_to:
            step *= growth
        y.append(y[-1] + step)
    return np.array(y)


def _duals(nodes: np.ndarray) -> np.ndarray:
    """Dual-cell widths of nodes whose end nodes sit on insulated faces (half cells there) [m]."""
    gaps = np.diff(nodes)
    return 0.5 * (np.concatenate([[0.0], gaps]) + np.concatenate([gaps, [0.0]]))


@dataclass(frozen=True)
class EllipseBlock:
    """The x-y-z block around the section and its finite-volume operator (index (i * ny + j) * nz + k).

    Attributes
    ----------
    x, y, z : ndarray
        Node positions [m]: along the rail (section x = 0 at index ``i0``), across from the centre line,
        in depth (theta = 0 one spacing below the last).
    capacity : ndarray (n,)
        C [J/K].
    stiffness : scipy.sparse.csr_matrix
        K [W/K].
    dt_stab : float
        Explicit stability limit min C/K_ii [s].
    depth_index : ndarray of int
        The z nodes of the output depths.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    i0: int
    capacity: np.ndarray
    stiffness: csr_matrix
    dt_stab: float
    depth_index: np.ndarray

    @property
    def node_shape(self) -> str:
        return f"{self.x.size}x{self.y.size}x{self.z.size}"

    def stepper(self, x_edges, y_edges, flux, speed, factor, t0):
        """A :class:`_Stepper3D` of this block under the source ``flux`` (nx, ny) [W/m^2] on the source
        grid's ``x_edges``, ``y_edges`` [m] at ``speed`` [m/s], heat-input factor ``factor(t)``, from t0 [s]."""
        return _Stepper3D(self, EllipseSource(self, x_edges, y_edges, flux, speed), factor, t0)


def ellipse_nodes(a: float, b: float, speed: float, kappa: float, level: int, duration_total: float,
                  depths) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nodes (x, y, z) [m] of the block of the module docstring for an ellipse of semi-axes ``a``, ``b`` [m]
    at ``speed`` [m/s], diffusivity ``kappa`` [m^2/s], refinement ``level``, a history of ``duration_total`` [s]
    and the output ``depths`` [m]: about 8x more a level, and more with the history's reach sqrt(kappa t)."""
    delta = thermal_scales(a, speed, kappa).thermal_depth
    reach = math.sqrt(kappa * duration_total)
    growth = 1.3 ** (1.0 / 2 ** int(level))
    x = rail_nodes(a, reach, level)
    y = _graded(b / 8.0 / 2 ** int(level), growth, b, b + 2.0 * reach)
    bottom = max(8.0 * reach, 10.0 * delta, 1.5 * max(depths))
    z = depth_nodes(delta / 4.0 / 2 ** int(level), growth, bottom, depths)
    return x, y, z


def check_node_budget(nodes, level: int, max_nodes: float, body: str) -> None:
    """Refuse a 3-D history block of more than ``max_nodes`` nodes, naming its shape, the level and the option.

    Raises
    ------
    railtherm.Refused
        kind "budget": the block's memory (its operator and one matrix per implicit step size, ~15 on the cooling
        ladder) and each step's work grow with the node count, 8x a level.
    """
    shape = tuple(int(np.size(n)) for n in nodes)
    total = int(np.prod(shape))
    if total > max_nodes:
        raise Refused(f"model 'fdm' ({body}): the 3-D section block of this history needs {'x'.join(map(str, shape))} "
                      f"= {total:.3g} nodes at level {int(level)}, above the budget max_history_nodes = {max_nodes:.3g} "
                      "(memory: the operator and a matrix per implicit step size; work: every step; both 8x a level "
                      "and growing with the history's length): use a lower level, a shorter history or raise the "
                      "option max_history_nodes", kind="budget")


def ellipse_block(a: float, b: float, speed: float, conductivity: float, capacity: float, convection: float,
                  level: int, duration_total: float, depths, max_nodes: float = math.inf,
                  body: str = "rail") -> EllipseBlock:
    """The block of the module docstring for an ellipse of semi-axes ``a``, ``b`` [m] at ``speed`` [m/s],
    material lambda [W/(m K)] and rho c [J/(m^3 K)], top convection h [W/(m^2 K)], refinement ``level``, a
    history of ``duration_total`` [s] and the output ``depths`` [m]; refused above ``max_nodes`` nodes
    (:func:`check_node_budget`, ``body`` named)."""
    kappa = conductivity / capacity
    x, y, z = ellipse_nodes(a, b, speed, kappa, level, duration_total, depths)
    check_node_budget((x, y, z), level, max_nodes, body)
    nx, ny, nz = x.size, y.size, z.size
    wx, wy = _duals(x), _duals(y)
    gaps = np.diff(z)
    below = np.append(gaps, gaps[-1])
    wz = 0.5 * (below + np.concatenate([[0.0], gaps]))
    cap = (capacity * wx[:, None, None] * wy[None, :, None] * wz[None, None, :]).ravel()
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    gx = conductivity * (wy[:, None] * wz[None, :])[None] / np.diff(x)[:, None, None]
    gy = conductivity * (wx[:, None] * wz[None, :])[:, None, :] / np.diff(y)[None, :, None]
    gz = conductivity * (wx[:, None] * wy[None, :])[:, :, None] / below[None, None, :]
    diag = np.zeros((nx, ny, nz))
    diag[:-1] += gx
    diag[1:] += gx
    diag[:, :-1] += gy
    diag[:, 1:] += gy
    diag += gz                                          # the last layer's gz: to the fixed bottom
    diag[:, :, 1:] += gz[:, :, :-1]
    diag[:, :, 0] += convection * wx[:, None] * wy[None, :]
    pairs = [(idx[:-1], idx[1:], gx), (idx[:, :-1], idx[:, 1:], gy), (idx[:, :, :-1], idx[:, :, 1:], gz[:, :, :-1])]
    rows = [idx.ravel()] + [p.ravel() for p, q, _ in pairs] + [q.ravel() for p, q, _ in pairs]
    cols = [idx.ravel()] + [q.ravel() for p, q, _ in pairs] + [p.ravel() for p, q, _ in pairs]
    vals = [diag.ravel()] + [-g.ravel() for *_, g in pairs] * 2
    n = nx * ny * nz
    stiff = csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    nodes = np.array([int(np.argmin(np.abs(z - d))) for d in depths])
    return EllipseBlock(x, y, z, (nx - 1) // 2, cap, stiff, float(np.min(cap / diag.ravel())), nodes)


class EllipseSource:
    """The flux on the source grid as each strip's cumulative integral along x [W/m], and the overlaps
    [m] of the top nodes' lateral dual cells with the strips: the power [W] of a top node is the sum over
    strips of overlap x (difference of the cumulative integral over the node's x dual cell). The half block
    takes the flux symmetrised about y = 0, (q(y) + q(-y)) / 2: the centre line's temperature under any flux
    is the one under its symmetrised part (the half-space is symmetric about the plane y = 0)."""

    def __init__(self, block: EllipseBlock, x_edges, y_edges, flux, speed):
        xe = np.asarray(x_edges, dtype=float)
        ye = np.asarray(y_edges, dtype=float)
        q = np.asarray(flux, dtype=float).reshape(xe.size - 1, ye.size - 1)
        self.xe = xe
        self.cum = np.concatenate([np.zeros((1, q.shape[1])), np.cumsum(q * np.diff(xe)[:, None], axis=0)])
        mid = 0.5 * (block.x[1:] + block.x[:-1])
        self.lo = np.concatenate([[block.x[0]], mid])
        self.hi = np.concatenate([mid, [block.x[-1]]])
        ymid = 0.5 * (block.y[1:] + block.y[:-1])
        ylo = np.concatenate([[0.0], ymid])
        yhi = np.concatenate([ymid, [block.y[-1]]])
        # overlap of [ylo, yhi] (and its mirror [-yhi, -ylo]) with each strip [ye[s], ye[s + 1]]
        over = np.zeros((block.y.size, q.shape[1]))
        for lo, hi in ((ylo, yhi), (-yhi, -ylo)):
            over += np.clip(np.minimum(hi[:, None], ye[None, 1:]) - np.maximum(lo[:, None], ye[None, :-1]), 0.0, None)
        self.over = 0.5 * over                     # the half block carries half the symmetrised flux
        self.speed = float(speed)
        self.nz = block.z.size

    def power(self, tau: float) -> np.ndarray:
        """Top nodes' power (nx, ny) [W] at time tau after the pass's arrival [s]."""
        shift = self.xe[-1] - self.speed * tau
        if self.hi[-1] + shift <= self.xe[0] or self.lo[0] + shift >= self.xe[-1]:
            return np.zeros((self.lo.size, self.over.shape[0]))
        strips = np.stack([np.interp(self.hi + shift, self.xe, c) - np.interp(self.lo + shift, self.xe, c)
                           for c in self.cum.T], axis=1)
        return strips @ self.over.T


class Implicit3D:
    """theta-scheme steps by conjugate gradients (the matrix C/dt + theta K is symmetric positive definite),
    Jacobi-preconditioned and warm-started from the last state; ``cache`` holds the matrices per (dt, theta)."""

    def __init__(self, block: EllipseBlock):
        self.C = block.capacity
        self.K = block.stiffness
        self.cache = {}
        self.solves = 0
        self.iterations = 0

    def step(self, T, dt, theta, p_old, p_new):
        key = (float(dt), float(theta))
        if key not in self.cache:
            A = (diags(self.C / dt) + theta * self.K).tocsr()
            self.cache[key] = (A, 1.0 / A.diagonal())
        A, minv = self.cache[key]
        rhs = self.C / dt * T - (1.0 - theta) * (self.K @ T) + theta * p_new + (1.0 - theta) * p_old
        out, its = _pcg(A, minv, rhs, T)
        self.solves += 1
        self.iterations += its
        return out


def _dot(u, v) -> float:
    """Inner product without BLAS (a multithreaded BLAS dot of 1e4-1e5 entries is ~60x slower on a loaded
    machine than the sum of the product)."""
    return float(np.add.reduce(u * v))


def _pcg(A, minv, b, x0, rtol: float = CG_RTOL, maxiter: int = 5000):
    """Jacobi-preconditioned conjugate gradients for the symmetric positive definite A, from x0, to
    ||b - A x|| <= rtol ||b||: (x, iterations)."""
    x = x0.copy()
    r = b - A @ x
    stop = rtol * math.sqrt(_dot(b, b))
    z = minv * r
    p = z.copy()
    rz = _dot(r, z)
    for it in range(maxiter):
        if math.sqrt(_dot(r, r)) <= stop:
            return x, it
        q = A @ p
        alpha = rz / _dot(p, q)
        x += alpha * p
        r -= alpha * q
        z = minv * r
        rz, rz_old = _dot(r, z), rz
        p = z + (rz / rz_old) * p
    raise RuntimeError(f"fdm 3-D history: conjugate gradients did not reach {rtol:g} in {maxiter} iterations")


class _Stepper3D:
    """The 3-D block's state, clock and recorded samples (the section's centre-line column at the output
    depths), with the interface of :class:`railtherm_fdm.history._Stepper`."""

    heating_cost = CG_COST_FACTOR
    implicit_cost = CG_COST_FACTOR
    cooling_implicit = "Crank-Nicolson steps by conjugate gradients (two backward-Euler start steps)"

    def __init__(self, block: EllipseBlock, source: EllipseSource, factor, t0: float):
        self.b = block
        self.src = source
        self.factor = factor
        self.shape = (block.x.size, block.y.size, block.z.size)
        self.T = np.zeros(block.capacity.size)
        self.t = t0
        self.cinv = 1.0 / block.capacity
        self.implicit = Implicit3D(block)
        self.times, self.rows = [], []
        self.explicit_steps = 0
        self.adi_steps = 0
        nx, ny, nz = self.shape
        self.top = (np.arange(nx)[:, None] * ny + np.arange(ny)[None, :]) * nz          # (nx, ny)
        self.out = (block.i0 * ny) * nz + block.depth_index                                 # y = 0 column

    def fresh(self, t0: float) -> "_Stepper3D":
        """A stepper of the same block and source from t0 [s], state zero."""
        return _Stepper3D(self.b, self.src, self.factor, t0)

    def _power(self, t, arrivals, f):
        p = np.zeros(self.T.size)
        if f != 0.0:
            for arr in arrivals:
                p[self.top] += self.src.power(t - arr)
            p *= f
        return p

    def explicit(self, dt: float, m: int, arrivals, heated: bool = True):
        """m forward-Euler steps of dt; the source at each step's mid-time; all steps recorded."""
        K, cinv, T = self.b.stiffness, self.cinv, self.T
        out = np.empty((m, self.out.size))
        for s in range(m):
            tm = self.t + (s + 0.5) * dt
            f = float(self.factor(tm)) if heated else 0.0
            T = T + dt * cinv * (self._power(tm, arrivals, f) - K @ T)
            out[s] = T[self.out]
        self.T = T
        self.times.append(self.t + dt * np.arange(1, m + 1))
        self.rows.append(out)
        self.t += m * dt
        self.explicit_steps += m

    def adi(self, dt: float, m: int, start: int = 0):
        """m source-free implicit steps of dt (Crank-Nicolson, the first ``start`` backward Euler)."""
        self.implicit_steps(dt, m, (), 0.5, start)
        self.adi_steps += m

    def implicit_steps(self, dt: float, m: int, arrivals=(), theta: float = 0.5, start: int = 0):
        """m theta-scheme steps of dt (the first ``start`` backward Euler); source of ``arrivals``."""
        def power(t):
            return self._power(t, arrivals, float(self.factor(t))) if len(arrivals) else np.zeros(self.T.size)
        self.T, self.t, out, times = theta_steps(self.T, self.t, dt, m, power, self.implicit.step,
                                                 lambda T: T[self.out], self.out.size, theta, start)
        self.times.append(times)
        self.rows.append(out)
