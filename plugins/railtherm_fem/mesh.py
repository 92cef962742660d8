"""Graded triangular mesh of the elastic strip, built directly as a balanced quadtree.

The strip occupies ``-L/2 <= x <= L/2``, ``-H <= y <= 0`` (internal coordinates: y points up, the
contact surface is y = 0; depth is z = -y). A coarse tensor grid of rectangles is subdivided into
quadrants (a quadtree) wherever a cell is closer to the contact window than ``grading`` times its own
diagonal, until the surface cells in the window have the width h. The element size therefore grows about
linearly with the distance from the window (a geometric grading), which is what the 1/r decay of the
contact fields needs; the node count grows only like ``(window / h) * grading + grading^2 log(H / h)``.
The tree is 2:1 balanced (neighbouring leaves differ by at most one level). Each leaf is split into two
triangles along its (lower-left to upper-right) diagonal or, where a finer neighbour puts a node on its
edge, into a fan of triangles about its centre, so the mesh is conforming (:func:`graded_strip_mesh`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from skfem import MeshTri

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


def _uniform_half(half: float, s0: float) -> float:
    """Half-length [m] covered by the coarse cells of exactly s0 in :func:`_coarse_nodes` (half, s0 in m)."""
    n = max(1, int(math.floor(half / s0 + 1e-9)))
    if half - s0 * n > 0.25 * s0:
        return s0 * n
    return s0 * (n - 1) if abs(half - s0 * n) > 1e-9 * s0 else half


def _balance_violations(ix, iy, lev, kmax, keys):
    """Leaves with a node of the tree at a quarter point of one of their edges (2:1 balance broken)."""
    size = (1 << (kmax - lev)).astype(np.int64)
    q = size // 4
    bad = np.zeros(ix.size, bool)
    ok = q > 0
    for fx, fy in ((1, 0), (3, 0), (1, 4), (3, 4), (0, 1), (0, 3), (4, 1), (4, 3)):
        kx = ix + fx * q
        ky = iy + fy * q
        bad |= ok & _member(keys, _key(kx, ky))
    return bad


def _key(kx, ky):
    return kx.astype(np.int64) * (1 << 31) + ky.astype(np.int64)


def _sorted_unique(a):
    a = np.sort(a)
    return a[np.concatenate([[True], a[1:] != a[:-1]])] if a.size else a


def _member(keys, q):
    """q in keys (keys sorted and unique)."""
    pos = np.minimum(np.searchsorted(keys, q), keys.size - 1)
    return keys[pos] == q


def graded_strip_mesh(length: float, depth: float, window: float, spacing: float,
                      grading: float = 4.0, core: float | None = None) -> StripMesh:
    """Build the graded triangular mesh of the strip.

    Built with array operations only (no element-by-element refinement): 0.07 s for 5e4 nodes
    (scikit-fem's red-green-blue refinement of the same grading took 0.38 s). The coarse cell width is
    ``h * 2**K`` so that repeated halving lands exactly on the spacing h in the window: the window's
    surface nodes are uniformly spaced, ``x = j h``, symmetric about x = 0.

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
        A cell is subdivided while its distance to the window is below ``grading`` times its
        diagonal [1]; larger values give a smoother (and larger) mesh.
    core : float, optional
        Depth of a region below the window meshed with cells of width h [m] (default: h * 4).

    Returns
    -------
    StripMesh
    """
    if not (length > 0 and depth > 0 and window > 0 and spacing > 0):
        raise ValueError("length, depth, window and spacing must be positive")
    if window >= 0.5 * length:
        raise ValueError(f"contact window {window:g} m does not fit in the strip of length {length:g} m")
    h = float(spacing)
    k, s0 = _coarse_size(length, depth, window, h)
    xs = _coarse_nodes(0.5 * length, s0)
    ny = max(1, int(round(depth / s0)))
    ys = np.linspace(-depth, 0.0, ny + 1)
    core = 4.0 * h if core is None else float(core)
    tree = _Quadtree(xs, ys, k + 1)   # deepest level allowed (the balance may need one level below the window's)
    ix, iy, lev = tree.graded(window, h, grading, core)
    ix, iy, lev = tree.balanced(ix, iy, lev)
    p, t = tree.triangulate(ix, iy, lev)
    m = MeshTri(p, t)
    tol = 1e-9 * h
    top = np.nonzero((np.abs(p[1]) < tol) & (np.abs(p[0]) <= window + tol))[0]
    top = top[np.argsort(p[0, top])]
    xw = p[0, top]
    dd = np.diff(xw)
    if dd.size and not np.allclose(dd, h, rtol=1e-6, atol=0):
        raise RuntimeError(f"window nodes are not uniformly spaced: spacing {dd.min():g}..{dd.max():g} m, wanted {h:g}")
    return StripMesh(m, float(length), float(depth), h, top, xw)


def _coarse_size(length: float, depth: float, window: float, h: float) -> tuple[int, float]:
    """(k, s0): the coarse cell s0 = h 2^k, about half the depth, in which the window lies whole."""
    k = max(0, int(math.ceil(math.log2(max(depth, h) / h))) - 1)
    s0 = h * 2.0 ** k  # coarse cell: about half the depth, an exact power-of-two multiple of h
    # the window must lie in coarse cells of exactly s0 (the last cell on each side absorbs the remainder
    # of L/2 and is not a power-of-two multiple of h): on a short strip (L/2 < 1.25 s0) halve s0 until
    # it does, else the window's surface nodes would not have the spacing h
    while k > 0 and _uniform_half(0.5 * length, s0) < window * (1.0 + 1e-9):
        k -= 1
        s0 = h * 2.0 ** k
    if _uniform_half(0.5 * length, s0) < window * (1.0 + 1e-9):
        raise ValueError(f"contact window {window:g} m and spacing {h:g} m do not fit in the strip of length "
                         f"{length:g} m")
    return k, s0


@dataclass(frozen=True)
class _Quadtree:
    """The strip's coarse cells (node coordinates ``xs``, ``ys``) subdivided as a quadtree down to level ``kmax``.

    Cells are (ix, iy, lev) in integer coordinates: coarse cell (I, J) spans [I, I+1] x [J, J+1] * 2**kmax.
    """

    xs: np.ndarray
    ys: np.ndarray
    kmax: int

    @property
    def nxc(self) -> int:
        return self.xs.size - 1

    @property
    def nyc(self) -> int:
        return self.ys.size - 1

    def phys(self, kx, ky):
        """Physical coordinates [m] of integer points."""
        kmax, xs, ys = self.kmax, self.xs, self.ys
        cx = np.minimum(kx >> kmax, self.nxc - 1)
        cy = np.minimum(ky >> kmax, self.nyc - 1)
        fx = (kx - (cx << kmax)) / float(1 << kmax)
        fy = (ky - (cy << kmax)) / float(1 << kmax)
        return xs[cx] + fx * (xs[cx + 1] - xs[cx]), ys[cy] + fy * (ys[cy + 1] - ys[cy])

    def split(self, ix, iy, lev, mark):
        """The cells with the ``mark``-ed ones replaced by their four children."""
        half = (1 << (self.kmax - lev[mark] - 1)).astype(np.int64)
        cx, cy, cl = ix[mark], iy[mark], lev[mark] + 1
        kids_x = np.concatenate([cx, cx + half, cx, cx + half])
        kids_y = np.concatenate([cy, cy, cy + half, cy + half])
        keep = ~mark
        return (np.concatenate([ix[keep], kids_x]), np.concatenate([iy[keep], kids_y]),
                np.concatenate([lev[keep], np.tile(cl, 4)]))

    def graded(self, window, h, grading, core):
        """The coarse cells subdivided by the grading criterion, level by level (a cell left alone once stays a
        leaf: the criterion depends on its geometry only)."""
        kmax = self.kmax
        I, J = np.meshgrid(np.arange(self.nxc), np.arange(self.nyc), indexing="ij")
        ix = (I.ravel() << kmax).astype(np.int64)
        iy = (J.ravel() << kmax).astype(np.int64)
        lev = np.zeros(ix.size, np.int64)
        for _ in range(kmax):
            size = (1 << (kmax - lev)).astype(np.int64)
            x0, y0 = self.phys(ix, iy)
            x1, y1 = self.phys(ix + size, iy + size)
            cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
            width = x1 - x0
            diam = np.hypot(width, y1 - y0)
            dist = np.hypot(np.maximum(np.abs(cx) - window, 0.0), cy)
            fine_enough = width <= 1.01 * h
            mark = ((dist < grading * diam) | ((np.abs(cx) < window) & (-cy < core))) & ~fine_enough & (lev < kmax)
            if not mark.any():
                break
            ix, iy, lev = self.split(ix, iy, lev, mark)
        return ix, iy, lev

    def balanced(self, ix, iy, lev):
        """The cells subdivided until neighbours differ by one level at most (2:1 balance)."""
        kmax = self.kmax
        for _ in range(kmax + 1):
            size = (1 << (kmax - lev)).astype(np.int64)
            corners = np.concatenate([_key(ix, iy), _key(ix + size, iy), _key(ix, iy + size), _key(ix + size, iy + size)])
            keys = _sorted_unique(corners)
            bad = _balance_violations(ix, iy, lev, kmax, keys)
            if not bad.any():
                break
            ix, iy, lev = self.split(ix, iy, lev, bad)
        else:
            raise RuntimeError("quadtree balancing did not finish")
        return ix, iy, lev

    def triangulate(self, ix, iy, lev):
        """Nodes (2, n) [m] and triangles (3, m) of the balanced cells: cell corners, plus a centre for cells
        with a hanging node on an edge."""
        size = (1 << (self.kmax - lev)).astype(np.int64)
        hs = size // 2
        c00, c10 = _key(ix, iy), _key(ix + size, iy)
        c01, c11 = _key(ix, iy + size), _key(ix + size, iy + size)
        keys = _sorted_unique(np.concatenate([c00, c10, c01, c11]))
        mids = [_key(ix + hs, iy), _key(ix + size, iy + hs), _key(ix + hs, iy + size), _key(ix, iy + hs)]
        has = [_member(keys, mk) & (hs > 0) for mk in mids]  # bottom, right, top, left
        hanging = has[0] | has[1] | has[2] | has[3]
        ncorner = keys.size
        idx = lambda kk: np.searchsorted(keys, kk)
        n00, n10, n01, n11 = idx(c00), idx(c10), idx(c01), idx(c11)
        nm = [np.where(hm, idx(np.where(hm, mk, keys[0])), -1) for hm, mk in zip(has, mids)]
        hang = np.nonzero(hanging)[0]
        centre = np.full(ix.size, -1)
        centre[hang] = ncorner + np.arange(hang.size)
        kx_all, ky_all = keys // (1 << 31), keys % (1 << 31)
        px, py = self.phys(kx_all, ky_all)
        ccx, ccy = self.phys(ix[hang] + hs[hang], iy[hang] + hs[hang])
        p = np.vstack([np.concatenate([px, ccx]), np.concatenate([py, ccy])])
        tris = []
        # plain cells: two triangles, all with the same diagonal (as scikit-fem's init_tensor and its red
        # refinement; a diagonal mirrored about x = 0 leaves the centre node in two triangles only and
        # measurably worsened the Hertz peak pressure: 0.9 % instead of 0.1 % at level 3)
        plain = np.nonzero(~hanging)[0]
        a, b, c, d = n00[plain], n10[plain], n11[plain], n01[plain]
        tris.append(np.vstack([a, b, c]))
        tris.append(np.vstack([a, c, d]))
        # cells with hanging nodes: fan about the centre over the boundary points in ccw order
        ring = np.vstack([n00[hang], nm[0][hang], n10[hang], nm[1][hang], n11[hang], nm[2][hang], n01[hang], nm[3][hang]])
        cen = centre[hang]
        for j in range(8):
            sel = ring[j] >= 0                       # corners (even j) always, edge midpoints where present
            nxt = ring[(j + 1) % 8].copy()           # next boundary point: the midpoint, else the corner
            nxt[nxt < 0] = ring[(j + 2) % 8][nxt < 0]
            tris.append(np.vstack([ring[j][sel], nxt[sel], cen[sel]]))
        t = np.hstack(tris)
        return p, t
