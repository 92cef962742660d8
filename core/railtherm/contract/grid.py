"""The surface grid on which every stage reports its fields.

One grid per (scene, level): cell-centred, covering the bounding box of the contact patch,
x in [-a, a] (rolling direction, leading edge at +a), y in [-b, b]. Line contacts have no y.
Level k has ``cells * 2**k`` cells along x; y gets a count in proportion to b/a.

A scene with ``field = {behind = d}`` reports its temperatures on the *extended* grid
(:func:`extended_grid`): the patch grid with whole cells of the same size added behind the trailing
edge until x reaches -a - d; y is unchanged. Contact and heat-source fields are put on it with
:func:`embed` (zero outside the patch; ``stick`` NaN).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import Refused

#: cells along 2a at level 0
BASE_CELLS = 8

#: Budget of the surface grid [cells]: :func:`surface_grid` refuses (``Refused``, kind "budget") a
#: grid with more cells, before anything is allocated. One float64 field on it is 32 MB; a run holds
#: about 20 such fields at once (pressure, tractions, slips, stick, power density, fluxes, the two
#: surface temperatures, coordinates, masks and the result Dataset's copies), i.e. ~0.7 GB, and the
#: temperature models add their own work arrays on top. At level 8 the Ertz & Knothe ellipse
#: (a = 5.88 mm, b = 10.54 mm, 32 cells at level 0) would need 8192 x 14684 = 1.2e8 cells (~1 GB per
#: field) and the process was killed by the OOM killer; within this budget its finest level is 5
#: (1024 x 1836 = 1.9e6 cells).
MAX_SURFACE_CELLS = 4_000_000


@dataclass(frozen=True)
class SurfaceGrid:
    """Cell-centred grid on the patch bounding box.

    Attributes
    ----------
    x_edges : ndarray, shape (nx+1,)
        Cell edges along the rolling direction [m].
    y_edges : ndarray, shape (ny+1,) or None
        Cell edges across [m]; None for a line contact.
    a, b : float
        Semi-axes of the patch [m]; b is None for a line contact. For a patch that is not an ellipse,
        half its extent along x and y.
    contact : ndarray of bool, optional
        The cells in contact, shape ``self.shape``, for a patch that is not the ellipse (or band) of
        its semi-axes (a non-Hertzian gap's, computed by a normal model); None: the ellipse.
    """

    x_edges: np.ndarray
    y_edges: np.ndarray | None
    a: float
    b: float | None
    contact: np.ndarray | None = None

    @property
    def line(self) -> bool:
        return self.y_edges is None

    @property
    def x(self) -> np.ndarray:
        """Cell centres along x [m]."""
        return 0.5 * (self.x_edges[1:] + self.x_edges[:-1])

    @property
    def y(self) -> np.ndarray | None:
        """Cell centres along y [m] (None for a line contact)."""
        if self.y_edges is None:
            return None
        return 0.5 * (self.y_edges[1:] + self.y_edges[:-1])

    @property
    def dx(self) -> float:
        return float(self.x_edges[1] - self.x_edges[0])

    @property
    def dy(self) -> float:
        """Cell width across [m]; 1.0 for a line contact (per unit width)."""
        return 1.0 if self.y_edges is None else float(self.y_edges[1] - self.y_edges[0])

    @property
    def shape(self) -> tuple[int, ...]:
        return (self.x.size,) if self.line else (self.x.size, self.y.size)

    @property
    def cell_area(self) -> float:
        """Area of one cell [m^2] (per unit width [m] for a line contact)."""
        return self.dx * self.dy

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """X, Y arrays of shape (nx, ny) (indexing 'ij'); Y is zeros for a line contact."""
        if self.line:
            return self.x[:, None], np.zeros((1, 1))
        return np.meshgrid(self.x, self.y, indexing="ij")

    def inside(self) -> np.ndarray:
        """Boolean mask of the cells whose centre lies inside the patch, shape ``self.shape`` (the
        ``contact`` cells when the grid carries them)."""
        if self.contact is not None:
            return np.asarray(self.contact, dtype=bool).reshape(self.shape)
        if self.line:
            return np.abs(self.x) < self.a
        # only the rows with |x| < a can hold patch cells (a long field grid has many rows behind the patch);
        # broadcast (rows, 1) + (1, ny): the same values as on the mesh without its two (nx, ny) arrays
        rows = np.flatnonzero(np.abs(self.x) < self.a)
        out = np.zeros(self.shape, dtype=bool)
        if rows.size:
            r = slice(int(rows[0]), int(rows[-1]) + 1)
            out[r] = (self.x[r, None] / self.a) ** 2 + (self.y[None, :] / self.b) ** 2 < 1.0
        return out

    def integrate(self, field: np.ndarray) -> float:
        """Midpoint-rule integral of a cell field over the grid [field units x m^2]."""
        return float(np.sum(field) * self.cell_area)


def surface_grid(a: float, b: float | None, level: int, cells: int | None = None) -> SurfaceGrid:
    """Build the grid of level ``level`` for a patch with semi-axes a, b [m].

    Parameters
    ----------
    a : float
        Semi-axis along the rolling direction [m].
    b : float or None
        Lateral semi-axis [m]; None for a line contact.
    level : int
        Resolution level k >= 0: ``cells * 2**k`` cells along x.
    cells : int, optional
        Cells along x at level 0 (default :data:`BASE_CELLS`).

    Raises
    ------
    railtherm.Refused
        (kind "budget") when the grid would have more than :data:`MAX_SURFACE_CELLS` cells.
    """
    base = int(cells or BASE_CELLS)
    n = base * 2 ** int(level)
    ny = None if b is None else min(max(4, int(round(n * b / a))), 4 * n)
    total = n * (ny or 1)
    if total > MAX_SURFACE_CELLS:
        finest = min(int(level), 64)
        while finest > 0 and _cells(base * 2 ** finest, a, b) > MAX_SURFACE_CELLS:
            finest -= 1
        within = (f"the finest level within it is {finest}" if _cells(base * 2 ** finest, a, b) <= MAX_SURFACE_CELLS
                  else "no level is within it: use fewer cells at level 0")
        raise Refused(
            f"the surface grid of level {level} needs {_shape(n, ny)} = {total:.3g} cells "
            f"({base} cells along 2a at level 0, a = {a:.4g} m" + (f", b = {b:.4g} m" if b is not None else "")
            + f"), above the budget railtherm.contract.grid.MAX_SURFACE_CELLS = {MAX_SURFACE_CELLS:.3g} cells "
            f"({8 * total / 1e6:.0f} MB per field, about 20 fields per run); {within} with {base} cells at "
            "level 0", kind="budget")
    x_edges = np.linspace(-a, a, n + 1)
    if b is None:
        return SurfaceGrid(x_edges, None, float(a), None)
    y_edges = np.linspace(-b, b, ny + 1)
    return SurfaceGrid(x_edges, y_edges, float(a), float(b))


def extended_grid(grid: SurfaceGrid, behind: float) -> SurfaceGrid:
    """The grid of ``grid`` extended by ``behind`` [m] beyond the trailing edge (x = -a).

    Parameters
    ----------
    grid : SurfaceGrid
        The patch grid (uniform along x).
    behind : float
        Distance [m] beyond the trailing edge, >= 0; rounded up to whole cells of width ``grid.dx``
        (so the extended grid's first edge is at or below -a - behind, and its cells inside the patch
        are exactly the patch grid's).

    Returns
    -------
    SurfaceGrid
        Same ``a``, ``b``, ``y_edges``; ``x_edges`` with ``ceil(behind / dx)`` cells prepended;
        ``contact`` (if any) padded with False. ``grid`` itself when no cell is added.

    Raises
    ------
    railtherm.Refused
        (kind "budget") when the extended grid has more than :data:`MAX_SURFACE_CELLS` cells.
    """
    behind = float(behind)
    if not behind >= 0.0:
        raise ValueError(f"behind must be >= 0, got {behind!r} [m]")
    dx = grid.dx
    n = int(math.ceil(behind / dx - 1e-9)) if behind > 0 else 0
    if n == 0:
        return grid
    nx = grid.x.size + n
    ny = 1 if grid.line else grid.y.size
    if nx * ny > MAX_SURFACE_CELLS:
        raise Refused(f"the surface grid extended {behind:.4g} m behind the patch (field.behind) needs "
                      f"{_shape(nx, None if grid.line else ny)} = {nx * ny:.3g} cells of {dx:.3g} m, above the "
                      f"budget railtherm.contract.grid.MAX_SURFACE_CELLS = {MAX_SURFACE_CELLS:.3g}: use a lower level or a "
                      "shorter field.behind", kind="budget")
    x0 = float(grid.x_edges[0])
    x_edges = np.concatenate([x0 - dx * np.arange(n, 0, -1), np.asarray(grid.x_edges, dtype=float)])
    contact = None
    if grid.contact is not None:
        contact = embed(np.asarray(grid.contact, dtype=bool), grid, SurfaceGrid(x_edges, grid.y_edges, grid.a, grid.b),
                        fill=False)
    return SurfaceGrid(x_edges, grid.y_edges, grid.a, grid.b, contact)


def behind_cells(grid: SurfaceGrid, target: SurfaceGrid) -> int:
    """Number of cells ``target`` (an :func:`extended_grid` of ``grid``) adds behind the trailing edge."""
    n = target.x.size - grid.x.size
    if n < 0 or not np.allclose(target.x_edges[n:], grid.x_edges, rtol=0.0, atol=1e-9 * grid.dx):
        raise ValueError("target is not an extension of grid behind the trailing edge")
    return n


def embed(field: np.ndarray, grid: SurfaceGrid, target: SurfaceGrid, fill=0.0) -> np.ndarray:
    """A field on ``grid`` put on its :func:`extended_grid` ``target`` (``fill`` behind the patch).

    Parameters
    ----------
    field : ndarray, shape (..., *grid.shape)
        Cell values on the patch grid (leading axes, e.g. the body, are kept).
    grid, target : SurfaceGrid
        The patch grid and its extension.
    fill : scalar
        Value of the added cells (0 for pressure, traction and heat flux; NaN for ``stick``).

    Returns
    -------
    ndarray, shape (..., *target.shape)
    """
    field = np.asarray(field)
    n = behind_cells(grid, target)
    if n == 0:
        return field
    lead = field.ndim - len(grid.shape)
    shape = list(field.shape)
    shape[lead] += n
    # zeros are calloc'ed pages that stay untouched behind the patch (np.pad writes all of them: 2-3x slower
    # on a long field grid, measured)
    out = np.zeros(shape, dtype=field.dtype) if fill == 0 else np.full(shape, fill, dtype=field.dtype)
    out[(slice(None),) * lead + (slice(n, None),)] = field
    return out


def _cells(n: int, a: float, b: float | None) -> int:
    """Cells of a grid with n cells along x (as :func:`surface_grid` lays them out)."""
    return n if b is None else n * min(max(4, int(round(n * b / a))), 4 * n)


def _shape(n: int, ny: int | None) -> str:
    return f"{n}" if ny is None else f"{n} x {ny}"
