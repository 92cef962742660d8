"""The problem set-up every driver of the finite-difference block shares (the 2-D and 3-D, transient and
steady schemes): material, convection, the patch's semi-axes, the block's extent (with the scene's field)
and the grid the results are sampled on, built once per body and solve."""
from __future__ import annotations

from dataclasses import dataclass

from .layout import Extent, Trail, block_extent, line_extent, trail_extent

__all__ = ["BlockProblem", "block_problem"]


@dataclass(frozen=True)
class BlockProblem:
    """One body's block problem.

    Attributes
    ----------
    conductivity : float
        lambda [W/(m K)].
    capacity : float
        rho c [J/(m^3 K)].
    convection : float
        h [W/(m^2 K)] outside the patch.
    speed : float
        V of the body relative to the contact [m/s].
    a, b : float
        Semi-axes of the patch [m] (b = 0 for a line contact).
    extent : Extent
        The block's size (with the field's trail when the scene asks for one).
    sample_grid : railtherm.SurfaceGrid
        Where the results are sampled (the field's extended grid, else the patch grid).
    """

    conductivity: float
    capacity: float
    convection: float
    speed: float
    a: float
    b: float
    extent: Extent
    sample_grid: object

    @property
    def kappa(self) -> float:
        """Diffusivity lambda / (rho c) [m^2/s]."""
        return self.conductivity / self.capacity


def block_problem(grid, speed, conductivity, density, specific_heat, convection, *, steady: bool,
                  extent: Extent | None = None, out_grid=None, trail: Trail | None = None) -> BlockProblem:
    """The :class:`BlockProblem` of a driver's arguments: the default extent (:func:`block_extent` for an
    ellipse, :func:`line_extent` for a line) unless ``extent`` is given, stretched for ``trail``
    (:func:`trail_extent`; ``steady`` selects the moving-frame stretching)."""
    lam, rc = float(conductivity), float(density) * float(specific_heat)
    kappa = lam / rc
    V = float(speed)
    a = float(grid.x_edges[-1])
    b = 0.0 if grid.line else float(grid.y_edges[-1])
    ext = extent or (line_extent(a, V, kappa) if grid.line else block_extent(a, b, V, kappa))
    if trail is not None:
        ext = trail_extent(ext, trail, a, V, kappa, steady=steady)
    return BlockProblem(lam, rc, float(convection), V, a, b, ext, grid if out_grid is None else out_grid)
