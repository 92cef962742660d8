"""Graded triangular mesh of the elastic strip, refined towards the contact window.

The strip occupies ``-L/2 <= x <= L/2``, ``-H <= y <= 0`` (internal coordinates: y points up, the
contact surface is y = 0; depth is z = -y). A coarse tensor mesh of right triangles is refined
locally (red-green-blue refinement of scikit-fem) wherever an element is closer to the contact
window than ``grading`` times its own diameter, until the surface node spacing in the window is h.
The element size therefore grows about linearly with the distance from the window (a geometric
grading), which is what the 1/r decay of the contact fields needs; the node count grows only like
``(window / h) * grading + grading^2 log(H / h)``.

The coarse cell size is ``h * 2**K`` so that repeated bisection lands exactly on the spacing h in the
window: the window's surface nodes are uniformly spaced, ``x = j h``, symmetric about x = 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["StripMesh", "graded_strip_mesh"]


@dataclass
class StripMesh:
    """A graded strip mesh and the nodes of its contact window.

    Attributes
    ----------
    mesh : skfem.MeshTri
        Triangular mesh of the strip [m].
    length, depth : float
        Strip length L and depth H [m].
    spacing : float
        Surface node spacing h in the window [m].
    window : ndarray of int
        Surface nodes with |x| <= window half-length, sorted by x.
    x_window : ndarray
        Their x coordinates [m] (uniform, spacing h).
    """

    mesh: object
    length: float
    depth: float
    spacing: float
    window: np.ndarray
    x_window: np.ndarray

    @property
    def fixed_nodes(self) -> np.ndarray:
        """Nodes on the rigid foundation (y = -H) and on the clamped ends (x = +-L/2) (seed eq. 17)."""
        p = self.mesh.p
        tol = 1e-9 * max(self.length, self.depth)
        return np.nonzero((p[1] < -self.depth + tol) | (np.abs(p[0]) > 0.5 * self.length - tol))[0]

    @property
    def surface_nodes(self) -> np.ndarray:
        """All nodes on y = 0, sorted by x."""
        p = self.mesh.p
        s = np.nonzero(np.abs(p[1]) < 1e-12 * max(self.length, self.depth))[0]
        return s[np.argsort(p[0, s])]


def _coarse_nodes(half: float, s0: float) -> np.ndarray:
    """Nodes 0, +-s0, +-2 s0 ... up to +-half; the last cell on each side absorbs the remainder."""
    n = max(1, int(math.floor(half / s0 + 1e-9)))
    pos = s0 * np.arange(n + 1, dtype=float)
    if half - pos[-1] > 0.25 * s0:
        pos = np.append(pos, half)
    else:
        pos[-1] = half
    return np.concatenate([-pos[:0:-1], pos])


def graded_strip_mesh(length: float, depth: float, window: float, spacing: float,
                      grading: float = 4.0, core: float | None = None) -> StripMesh:
    """Build the graded triangular mesh of the strip.

    Parameters
    ----------
    length : float
        Strip length L [m] (x from -L/2 to L/2).
    depth : float
        Strip depth H [m].
    window : float
        Half-length of the contact window on the surface [m]; its surface nodes get spacing h.
    spacing : float
        Surface node spacing h in the window [m].
    grading : float
        An element is refined while its distance to the window is below ``grading`` times its
        diameter [1]; larger values give a smoother (and larger) mesh.
    core : float, optional
        Depth of a region below the window meshed uniformly with spacing h [m] (default: h * 4).

    Returns
    -------
    StripMesh
    """
    from skfem import MeshTri

    if not (length > 0 and depth > 0 and window > 0 and spacing > 0):
        raise ValueError("length, depth, window and spacing must be positive")
    if window >= 0.5 * length:
        raise ValueError(f"contact window {window:g} m does not fit in the strip of length {length:g} m")
    h = float(spacing)
    k = max(0, int(math.ceil(math.log2(max(depth, h) / h))) - 1)
    s0 = h * 2.0 ** k  # coarse cell: about half the depth, an exact power-of-two multiple of h
    xs = _coarse_nodes(0.5 * length, s0)
    ny = max(1, int(round(depth / s0)))
    ys = np.linspace(-depth, 0.0, ny + 1)
    m = MeshTri.init_tensor(xs, ys)
    core = 4.0 * h if core is None else float(core)
    for _ in range(k + 8):
        pts = m.p[:, m.t]
        c = pts.mean(axis=1)
        edges = np.linalg.norm(pts - np.roll(pts, 1, axis=1), axis=0)
        diam = edges.max(axis=0)
        leg = edges.min(axis=0)
        dx = np.maximum(np.abs(c[0]) - window, 0.0)
        dist = np.hypot(dx, c[1])
        mark = (dist < grading * diam) & (leg > 1.01 * h)
        mark |= (np.abs(c[0]) < window) & (-c[1] < core) & (leg > 1.01 * h)
        if not mark.any():
            break
        m = m.refined(np.nonzero(mark)[0])
    p = m.p
    tol = 1e-9 * h
    top = np.nonzero((np.abs(p[1]) < tol) & (np.abs(p[0]) <= window + tol))[0]
    top = top[np.argsort(p[0, top])]
    xw = p[0, top]
    d = np.diff(xw)
    if d.size and not np.allclose(d, h, rtol=1e-6, atol=0):
        raise RuntimeError(f"window nodes are not uniformly spaced: spacing {d.min():g}..{d.max():g} m, wanted {h:g}")
    return StripMesh(m, float(length), float(depth), h, top, xw)
