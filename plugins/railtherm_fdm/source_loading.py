"""The patch's heat flux put onto the block's surface, conservatively (3-D and 2-D blocks).

The power of each patch cell is split over the block's surface nodes (transient schemes,
:class:`MovingSource`) or cells (steady scheme, :func:`graded_surface_source`) by the exact area of
overlap -- averaged over the distance the source travels in a step for the moving source -- so the
energy put into the block equals the integral of the flux to rounding. The same overlaps give the
covered fraction of each node, which sets where the surface convects (outside the patch, seed
eq. 60).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["box_overlap", "MovingSource", "graded_surface_source"]


def box_overlap(c0, c1, e0, e1, s0=0.0, s1=None):
    """Overlap length of intervals [c0, c1] and [e0 + s, e1 + s], averaged over s in [s0, s1].

    Uses ``|[c0,c1] ∩ [e0+s,e1+s]| = R(c1-e0-s) - R(c0-e0-s) - R(c1-e1-s) + R(c0-e1-s)`` with
    R(u) = max(u, 0) (valid for c1 >= c0, e1 >= e0), whose integral over s is exact with
    R2(u) = max(u, 0)^2 / 2. Broadcasts its arguments.

    Parameters
    ----------
    c0, c1 : array_like
        Target interval ends [m].
    e0, e1 : array_like
        Source interval ends before the shift [m].
    s0, s1 : float
        Shift range [m]; ``s1=None`` (or s1 == s0) gives the overlap at shift s0.

    Returns
    -------
    ndarray
        Mean overlap length [m].
    """
    c0, c1, e0, e1 = (np.asarray(v, dtype=float) for v in (c0, c1, e0, e1))
    if s1 is None or s1 == s0:
        R = lambda u: np.maximum(u, 0.0)  # noqa: E731
        s = s0
        return R(c1 - e0 - s) - R(c0 - e0 - s) - R(c1 - e1 - s) + R(c0 - e1 - s)
    R2 = lambda u: 0.5 * np.maximum(u, 0.0) ** 2  # noqa: E731

    def integ(k):
        return R2(k - s0) - R2(k - s1)

    return (integ(c1 - e0) - integ(c0 - e0) - integ(c1 - e1) + integ(c0 - e1)) / (s1 - s0)


class MovingSource:
    """The patch's flux moving over the top face of a node grid, one step at a time (body frame).

    Each step puts the heat that the patch brings while it travels V dt into the surface nodes it
    overlaps (:meth:`load`): a source increment ``src`` [K] per node, and a convective loss factor
    ``hloss`` [1] that is ``base_loss`` where the surface is free and falls with the covered fraction.
    Arrays have the node grid's surface shape: (nx,) for the 2-D block, (nx, ny) for the 3-D block,
    whose lateral overlap the caller folds into ``flux`` and ``cover`` beforehand.

    Parameters
    ----------
    x_nodes : ndarray (nx,)
        Node x coordinates [m] (spacing d).
    d : float
        Node spacing [m].
    x_edges : ndarray (nxp + 1,)
        Patch cell edges along x, relative to the patch centre [m].
    flux : ndarray (nxp,) or (nxp, ny)
        Flux per patch cell along x (3-D: already integrated over each node's lateral width) [W/m^2]
        ([W/m] in 3-D).
    cover : ndarray like ``flux`` or None
        Covered width (1 per unit width in 2-D) of each patch cell; None without convection.
    cover_width : float or ndarray (ny,)
        Width that ``Wx @ cover`` is divided by to give the covered fraction of a node [m] ([m^2]).
    capacity : float or ndarray (ny,)
        Heat capacity of a surface node per unit rise [J/K] ([J/(K m)] in 2-D).
    base_loss : float or ndarray (ny,)
        Convective loss factor of a fully exposed surface node in one step [1].
    convection : float
        h [W/(m^2 K)]; 0 leaves ``hloss`` at zero.
    start : float
        x of the patch centre at step 0 [m].
    speed, dt : float
        Body speed relative to the contact [m/s] and time step [s].
    buffers : int
        Independent (src, hloss) buffer pairs (the fused explicit kernel loads two steps at once).
    period : int, optional
        Steps after which the source has moved exactly ``period_cells`` node spacings
        (``V dt period = period_cells d``): step n then loads what step ``n mod period`` loads, shifted
        by ``period_cells (n // period)`` nodes, and the overlaps are computed once per phase instead of
        once per step (equal to rounding).
    period_cells : int
        Node spacings travelled in ``period`` steps [1].
    """

    def __init__(self, x_nodes, d, x_edges, flux, cover, cover_width, capacity, base_loss, convection, start,
                 speed, dt, buffers=1, period=None, period_cells=1):
        self.x, self.d, self.pxe = x_nodes, float(d), np.asarray(x_edges, dtype=float)
        self.flux, self.cover, self.cover_width = flux, cover, cover_width
        self.capacity, self.base_loss, self.h = capacity, base_loss, float(convection)
        self.start, self.speed, self.dt = float(start), float(speed), float(dt)
        shape = (x_nodes.size,) + np.shape(flux)[1:]
        self.src = [np.zeros(shape) for _ in range(buffers)]
        self.hloss = [np.zeros(shape) for _ in range(buffers)]
        if self.h > 0:
            for hl in self.hloss:
                hl[1:-1] = base_loss
        self._prev = [(1, 1)] * buffers
        self.period = int(period) if period else None
        self.period_cells = int(period_cells)
        self._phases = {}

    def load(self, n: int, slot: int = 0) -> float:
        """Put the source of step ``n`` into buffer ``slot``; returns the energy it brings [J] ([J/m])."""
        src, hloss = self.src[slot], self.hloss[slot]
        lo_prev, hi_prev = self._prev[slot]
        src[lo_prev:hi_prev] = 0.0
        if self.h > 0:
            hloss[lo_prev:hi_prev] = self.base_loss
        shift, phase = (0, n) if self.period is None else divmod(n, self.period)
        shift *= self.period_cells
        lo, hi, s, hl, energy = self._phase(phase) if self.period is not None else self._step(n)
        lo, hi = lo + shift, hi + shift
        if lo < 1 or hi > self.x.size - 1:          # the block's end cuts the footprint: load it directly
            lo, hi, s, hl, energy = self._step(n)
        src[lo:hi] = s
        if self.h > 0:
            hloss[lo:hi] = hl
        self._prev[slot] = (lo, hi)
        return energy

    def _phase(self, phase: int):
        """:meth:`_step` of step ``phase`` (< period), computed once."""
        if phase not in self._phases:
            self._phases[phase] = self._step(phase, clip=False)
        return self._phases[phase]

    def _step(self, n: int, clip: bool = True):
        """Footprint of step ``n``: first and end node (clipped to the block's inner nodes when ``clip``),
        source increments [K], loss factors [1] (None without convection) and energy [J] ([J/m])."""
        d, dt, pxe = self.d, self.dt, self.pxe
        s0 = self.start + self.speed * dt * n
        s1 = s0 + self.speed * dt
        lo = int(math.floor((s0 + pxe[0]) / d)) - 1
        hi = int(math.ceil((s1 + pxe[-1]) / d)) + 2
        if clip:
            lo, hi = max(1, lo), min(self.x.size - 1, hi)
        xi_ = d * np.arange(lo, hi)
        # overlap in x averaged over the step, coordinates relative to s0 for accuracy
        Wx = box_overlap((xi_ - 0.5 * d - s0)[:, None], (xi_ + 0.5 * d - s0)[:, None], pxe[:-1][None, :],
                         pxe[1:][None, :], 0.0, s1 - s0)          # (m, nxp) [m]
        Q = Wx @ self.flux
        hl = None
        if self.h > 0:
            C = (Wx @ self.cover) / self.cover_width              # covered fraction of each node
            hl = self.base_loss * (1.0 - np.clip(C, 0.0, 1.0))
        return lo, hi, dt * Q / self.capacity, hl, dt * float(Q.sum())

    def reach(self, slot: int = 0) -> int:
        """Last node index the source of buffer ``slot`` may heat (its increments are 0 beyond it)."""
        return self._prev[slot][1] - 1


def graded_surface_source(x_edges, patch_x_edges, flux, cover, convection, y_edges=None, patch_y_edges=None):
    """Heat input, face areas and convective conductance of the top cells of a graded grid.

    Parameters
    ----------
    x_edges, y_edges : ndarray
        Cell edges of the graded grid [m] (``y_edges`` None for the 2-D block).
    patch_x_edges, patch_y_edges : ndarray
        Edges of the patch grid [m].
    flux : ndarray (nxp,) or (nxp, nyp)
        Heat flux into the body on the patch grid [W/m^2].
    cover : ndarray like ``flux``
        1 where the patch cell is in contact, else 0 [1].
    convection : float
        h [W/(m^2 K)] outside the patch.

    Returns
    -------
    Q : ndarray (nx,) or (nx, ny)
        Heat into each top cell [W/m] or [W].
    area : ndarray like ``Q``
        Top face of each cell [m] or [m^2].
    hA : ndarray like ``Q``
        Convective conductance h A (1 - covered fraction) [W/(m K)] or [W/K].
    """
    dx = np.diff(x_edges)
    Wx = box_overlap(x_edges[:-1, None], x_edges[1:, None], patch_x_edges[None, :-1], patch_x_edges[None, 1:])
    if y_edges is None:
        Q = Wx @ np.asarray(flux, dtype=float).reshape(-1)
        area = dx
        cov = np.clip(Wx @ np.asarray(cover, dtype=float).reshape(-1) / area, 0.0, 1.0)
    else:
        Wy = box_overlap(y_edges[:-1, None], y_edges[1:, None], patch_y_edges[None, :-1], patch_y_edges[None, 1:])
        Q = Wx @ np.asarray(flux, dtype=float) @ Wy.T
        area = dx[:, None] * np.diff(y_edges)[None, :]
        cov = np.clip(Wx @ np.asarray(cover, dtype=float) @ Wy.T / area, 0.0, 1.0)
    return Q, area, convection * area * (1.0 - cov)
