"""Graded finite-volume meshes for the moving-frame heat conduction problem.

Everything is derived from the scene's scales (:func:`railtherm.physics.thermal_scales`), not from
hand-tuned lengths: Péclet number ``Pe = V a / (2 kappa)`` [1]; thermal layer ``delta = a / sqrt(Pe)``
(seed eq. 24); thermal wake length ``ell = 2 kappa / V = a / Pe`` (ahead of the patch the temperature
decays like ``exp(-2 s / ell)``). The surface grid's cells cover the patch; cells grow geometrically to a
margin of a few ``ell`` along x and across, and in depth from ``min(delta, a) / layer_cells`` to three
diffusion lengths of the residence time. Level ``k`` subdivides every level-0 cell into ``2**k`` along the
same geometric map, so meshes are nested and every cell size halves per level -- what the convergence-rate
fits assume (:func:`railtherm.physics.geometric_edges`). Lengths: docs/NOTES.md, "FiPy meshes".
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from railtherm.physics import geometric_edges, thermal_scales

__all__ = ["MovingFrameMesh", "moving_frame_mesh", "subdivide"]


def subdivide(edges: np.ndarray, refine: int) -> np.ndarray:
    """Split every cell of ``edges`` into ``refine`` equal cells."""
    edges = np.asarray(edges, dtype=float)
    if refine == 1:
        return edges.copy()
    t = np.arange(refine) / refine
    inner = (edges[:-1, None] + np.diff(edges)[:, None] * t[None, :]).ravel()
    return np.append(inner, edges[-1])


@dataclass(frozen=True)
class MovingFrameMesh:
    """Cell edges of a moving-frame mesh for one body.

    Attributes
    ----------
    x_edges : ndarray
        Edges along the rolling direction [m], increasing; outflow at ``x_edges[0]``, inflow at
        ``x_edges[-1]``.
    y_edges : ndarray or None
        Lateral edges [m] (None in 2-D).
    z_edges : ndarray
        Depth edges [m], ``z_edges[0] = 0`` is the surface.
    peclet, delta, ell : float
        Scales from :func:`railtherm.physics.thermal_scales` ([1], [m], [m]).
    half : bool
        3-D only: the mesh covers ``y >= 0`` (symmetric source).
    """

    x_edges: np.ndarray
    y_edges: np.ndarray | None
    z_edges: np.ndarray
    peclet: float
    delta: float
    ell: float
    half: bool = False

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of cells along (x, z) or (x, y, z)."""
        if self.y_edges is None:
            return (self.x_edges.size - 1, self.z_edges.size - 1)
        return (self.x_edges.size - 1, self.y_edges.size - 1, self.z_edges.size - 1)

    @property
    def cells(self) -> int:
        return int(np.prod(self.shape))


def moving_frame_mesh(x_patch_edges: np.ndarray, a: float, speed: float, diffusivity: float, level: int, *,
                      y_patch_edges: np.ndarray | None = None, b: float | None = None, refine: int = 1,
                      layer_cells: float = 4.0, ratio: float = 1.3, half: bool = False,
                      min_depth: float | None = None) -> MovingFrameMesh:
    """Build the graded mesh of one body for a patch on ``[-a, a]`` (x [-b, b] in 3-D).

    Parameters
    ----------
    x_patch_edges : ndarray
        Edges of the surface grid along x on ``[-a, a]`` at level ``level`` [m] (uniform).
    a : float
        Semi-axis along the rolling direction [m].
    speed : float
        Speed of the body's surface relative to the contact [m/s].
    diffusivity : float
        Thermal diffusivity kappa [m^2/s].
    level : int
        Refinement level k (the grid's level): the growth ratio of the graded parts is
        ``ratio**(1/2**k)``.
    y_patch_edges : ndarray, optional
        Lateral grid edges on ``[-b, b]`` [m]; given for a 3-D mesh.
    b : float, optional
        Lateral semi-axis [m] (3-D).
    refine : int
        FiPy cells per grid cell along x and y on the patch.
    layer_cells : float
        Cells per ``min(delta, a)`` at the surface at level 0 [1].
    ratio : float
        Growth ratio of neighbouring cells at level 0 [1].
    half : bool
        3-D: mesh only ``y >= 0`` (the caller checked that the source is symmetric and that the
        grid has an edge at y = 0).
    min_depth : float, optional
        Smallest depth of the mesh [m] (the scene's ``field.depth``); the graded z reaches
        ``max(D, min_depth)``.

    ``x_patch_edges`` may also be an *extended* grid (:func:`railtherm.contract.grid.extended_grid`, scene key
    ``field``): uniform cells from ``x_patch_edges[0] < -a`` up to ``a``. The uniform cells then run
    through the whole trail behind the patch and the outflow grading starts at its end; the domain
    length, and with it the depth ``D``, grows with the trail (the grading follows the trail).

    Returns
    -------
    MovingFrameMesh
    """
    sc = thermal_scales(a, speed, diffusivity)
    ell, delta = sc.wake_length, sc.thermal_depth
    xp = subdivide(x_patch_edges, refine)
    dx = float(xp[1] - xp[0])
    dx0 = dx * 2 ** level  # the patch cell of level 0: grading continues it smoothly
    margin = max(4.0 * ell, 0.25 * a)
    out = geometric_edges(margin, dx0, ratio, level)
    # the trailing end of the uniform cells: -a on a patch grid, the extended grid's first edge behind it
    lo = -a if xp[0] >= -a * (1.0 + 1e-9) else float(xp[0])
    x_edges = np.concatenate([lo - out[::-1], xp[1:-1], a + out])
    x_edges[out.size - 1] = lo
    x_edges[-out.size] = a
    length = float(x_edges[-1] - x_edges[0])
    depth = 3.0 * 2.0 * math.sqrt(diffusivity * length / speed)
    first_z = min(delta, a) / layer_cells
    depth = max(depth, 4.0 * first_z)
    if min_depth is not None and min_depth > depth:
        depth = float(min_depth)
    z_edges = geometric_edges(depth, first_z, ratio, level)
    y_edges = None
    if y_patch_edges is not None:
        yp = subdivide(y_patch_edges, refine)
        dy0 = float(yp[1] - yp[0]) * 2 ** level
        lat = max(5.0 * ell, 0.25 * b)
        yout = geometric_edges(lat, dy0, ratio, level)
        if half:
            yin = yp[yp >= -1e-12 * b]
            yin[0] = 0.0
            y_edges = np.concatenate([yin[:-1], b + yout])
        else:
            y_edges = np.concatenate([-b - yout[::-1], yp[1:-1], b + yout])
    return MovingFrameMesh(x_edges, y_edges, z_edges, sc.peclet, delta, ell, half)
