"""Normal-contact model "kalker": the exact half-space pressure for the scene's undeformed gap.

The gap (:func:`railtherm_kalker.potential_area.scene_gap`) is solved on a rectangular grid of elements over the
potential contact area (Love's influence coefficients, FFT products, Vollebregt's FFT-preconditioned active-set
conjugate gradients; :mod:`railtherm_kalker.normal_solver`). An elliptical or line contact's gap is the scene's
Hertz quadratic, so the result converges to the Hertz patch; ``contact = { shape = "gap", ... }`` gives another.
The returned patch's grid is the potential contact area (zero pressure outside the contact); its ``a`` and
``b`` are the contact's half-extents along x and y, located within an element (:func:`contact_extent`).

References
----------
.. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990, ch. 5. doi:10.1007/978-94-015-7889-9
.. [2] E.A.H. Vollebregt, J. Comput. Phys. 257 (2014) 333-351. doi:10.1016/j.jcp.2013.10.005
"""
from __future__ import annotations

import math

import numpy as np
from railtherm import Capabilities, ContactPatch, NormalContactModel, Option, Refused, SurfaceGrid
from railtherm.physics import contact_modulus
from railtherm.references.hertz import hertz_from_curvatures, hertz_pressure

from ._precompile import compile_kernels
from .influence import element_size, normal_operator
from .normal_solver import NORMAL_TOLERANCE, solve_normal
from .potential_area import SampledGap, check_border, potential_area, rolling_refinement, scene_gap

__all__ = ["KalkerNormal", "solve_scene_normal", "contact_extent", "DEFAULT_CELLS", "ROLLING_REFINEMENTS"]

#: elements across 2b (and 2a) at level 0; level k has DEFAULT_CELLS 2^k (128 at level 3), times the
#: rolling refinement m (:func:`railtherm_kalker.potential_area.rolling_refinement`) across 2a
DEFAULT_CELLS = 16


def _edge_positions(coord: np.ndarray, p_line: np.ndarray, h: float) -> tuple[float, float] | None:
    """Leading and trailing contact edges along one grid line [m] (p^2 extrapolated to zero)."""
    idx = np.nonzero(p_line > 0)[0]
    if idx.size == 0:
        return None
    lo, hi = idx[0], idx[-1]

    def ext(i, j):      # edge beyond element i, j its inner neighbour
        pi, pj = p_line[i] ** 2, (p_line[j] ** 2 if 0 <= j < p_line.size else 0.0)
        if pj > pi:
            return min(pi / (pj - pi), 1.0) * h
        return 0.5 * h

    up = coord[hi] + (ext(hi, hi - 1) if hi > lo else 0.5 * h)
    down = coord[lo] - (ext(lo, lo + 1) if hi > lo else 0.5 * h)
    return down, up


def contact_extent(x, y, pressure, dx: float, dy: float) -> tuple[float, float, float, float]:
    """Extent of the loaded region: (x_min, x_max, y_min, y_max) [m] (y's 0 for a line contact).

    Each edge is located to within a fraction of an element by extrapolating p^2 (linear in the distance from a
    Hertz-like edge) from the last two loaded elements of each grid line.

    Parameters
    ----------
    x, y : ndarray
        Element centres [m] (y None for a line contact).
    pressure : ndarray (nx, ny)
        Pressure [Pa].
    dx, dy : float
        Element sides [m].
    """
    p = np.asarray(pressure).reshape(x.size, -1)
    x0, x1 = _extent_along(np.asarray(x, dtype=float), p, dx)
    if y is None:
        return x0, x1, 0.0, 0.0
    y0, y1 = _extent_along(np.asarray(y, dtype=float), p.T, dy)
    return x0, x1, y0, y1


def _extent_along(coord: np.ndarray, p: np.ndarray, h: float) -> tuple[float, float]:
    """The smallest trailing and the largest leading edge over the grid lines along axis 0 of p [m]:
    :func:`_edge_positions` of every line at once (the same arithmetic, no loop over the lines)."""
    loaded = p > 0
    has = loaded.any(axis=0)
    n = p.shape[0]
    lo = np.argmax(loaded, axis=0)[has]
    hi = (n - 1 - np.argmax(loaded[::-1], axis=0))[has]
    cols = np.nonzero(has)[0]
    single = hi == lo

    def ext(i, j):      # edge beyond element i, j its inner neighbour (in range where not single)
        pi = p[i, cols] ** 2
        pj = np.where(single, 0.0, p[np.clip(j, 0, n - 1), cols] ** 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            e = np.where(pj > pi, np.minimum(pi / (pj - pi), 1.0) * h, 0.5 * h)
        return np.where(single, 0.5 * h, e)

    up = coord[hi] + ext(hi, hi - 1)
    down = coord[lo] - ext(lo, lo + 1)
    return float(down.min()), float(up.max())


def _normal_operator(area, e_star):
    nx, ny = area.shape
    dy = None if area.y_edges is None else element_size(area.y_edges)
    return normal_operator(nx, ny, element_size(area.x_edges), dy, float(e_star))


def _estimate_area(scene_name, gap, e_star, load):
    """Centre and half-extents of the contact of a non-Hertzian gap from a coarse solve (32 elements);
    ``scene_name`` names the scene in the refusal."""
    A, B = gap.quadratic
    force, approach = load
    if force is not None:
        h0 = hertz_from_curvatures(A, B, force, e_star)
        half = (1.6 * h0.a, 1.6 * h0.b)
    else:
        half = (1.6 * math.sqrt(approach / A), 1.6 * math.sqrt(approach / B))
    for _ in range(6):
        area = potential_area(half[0], half[1], 32, margin=0, name=scene_name)
        X, Y = area.mesh()
        sol = solve_normal(_normal_operator(area, e_star), gap(X, Y), area.dx * area.dy, force=force,
                           approach=approach, tol=1e-8)
        p = sol.pressure
        if not (p[0].any() or p[-1].any() or p[:, 0].any() or p[:, -1].any()):
            loaded = np.nonzero(p > 0)
            x0, x1 = area.x_edges[loaded[0].min()], area.x_edges[loaded[0].max() + 1]
            y0, y1 = area.y_edges[loaded[1].min()], area.y_edges[loaded[1].max() + 1]
            return (0.5 * (x0 + x1), 0.5 * (y0 + y1)), (0.5 * (x1 - x0), 0.5 * (y1 - y0))
        half = (1.5 * half[0], 1.5 * half[1])
    raise Refused(f"scene {scene_name!r}, model 'kalker': the contact of the gap {gap.coefficients} does not stay "
                  f"within {half[0]:.3g} x {half[1]:.3g} m; check the gap coefficients", kind="validity")


#: allowed values of the option ``rolling_refinement`` ("auto": :func:`rolling_refinement` of the contact)
ROLLING_REFINEMENTS = ("auto", 1, 2, 4, 8, 16, 32)


# whole scene: the gap is built from the scene's geometry (scene_gap), then loaded by its force or approach
def solve_scene_normal(scene, level: int, cells: int = DEFAULT_CELLS, tol: float = NORMAL_TOLERANCE,
                       refine_x="auto"):
    """Solve the normal problem of a scene on the potential contact area of ``level``.

    Parameters
    ----------
    scene : Scene-like
        See :func:`railtherm_kalker.potential_area.scene_gap`.
    level : int
        Level k: ``cells 2^k`` elements across the expected contact in y, ``m cells 2^k`` in x with
        the rolling refinement m = :func:`railtherm_kalker.potential_area.rolling_refinement` [1].
    cells : int
        Elements at level 0 [1].
    tol : float
        Tolerance of the normal solver [1].
    refine_x : "auto" or int
        Elements along x per element along y [1]; "auto" (default) is
        :func:`railtherm_kalker.potential_area.rolling_refinement` of the expected contact.

    Returns
    -------
    area : PotentialArea
    gap : Gap
    solution : NormalSolution
    """
    gap = scene_gap(scene)
    e_star = contact_modulus(scene.wheel, scene.rail)
    force = scene.normal_force
    approach = None if force is not None else float(scene.penetration)
    n = int(cells) * 2 ** int(level)
    if gap.hertz is not None:
        a0, b0, _ = gap.hertz
        centre = (0.0, 0.0)
    else:
        centre, (a0, b0) = _estimate_area(scene.name, gap, e_star, (force, approach))
    m = rolling_refinement(a0, b0) if refine_x == "auto" else int(refine_x)
    area = potential_area(a0, b0, n, centre=centre, name=scene.name, refine_x=m)
    X, Y = area.mesh()
    h = gap(X) if area.y_edges is None else gap(X, Y)
    initial = None
    A, B = gap.quadratic
    if force is not None and A > 0 and (area.y_edges is None or B > 0):
        if area.y_edges is None:
            initial = np.sqrt(np.clip(1.0 - (X / a0) ** 2, 0.0, None))
        else:
            hz = hertz_from_curvatures(A, B, force, e_star)
            initial = hertz_pressure(X - centre[0], Y - centre[1], hz.a, hz.b, hz.max_pressure)
    sol = solve_normal(_normal_operator(area, e_star), h, area.dx * area.dy, force=force, approach=approach,
                       initial=initial, tol=tol)
    return area, gap, sol


class KalkerNormal(NormalContactModel):
    """Kalker's exact normal contact on the elastic half-space: the pressure of the scene's undeformed
    gap on a grid of elements over the potential contact area (Love's influence coefficients applied
    by FFT, FFT-preconditioned conjugate gradients). A Hertzian scene's gap is its Hertz quadratic
    (the solution converges to the Hertz patch); a ``shape = "gap"`` scene gives a non-Hertzian one.

    References
    ----------
    .. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990.
       doi:10.1007/978-94-015-7889-9
    """

    name = "kalker"
    description = ("Kalker's exact normal contact on the half-space: pressure of the undeformed gap (Hertz "
                   "quadratic or non-Hertzian) by FFT influence coefficients and FFT-preconditioned CG")
    capabilities = Capabilities(contacts=frozenset({"ellipse", "line", "gap"}),
                                provides=frozenset({"pressure", "normal_force", "semi_axis_a", "semi_axis_b",
                                                    "max_pressure", "contact_area"}))
    options = {"cells": Option(DEFAULT_CELLS, "elements across the contact (2b; 2a m times more, m = 1 for a < 0.71 b, "
                              "2 up to a circle, 4 for a > b: rolling_refinement) at level 0 [1]", minimum=2),
               "rolling_refinement": Option("auto", "elements along x per element along y; 'auto': "
                                            "2^ceil(log2(2 (a/b)^2)) between 1 and 4 (the upwind rolling slip's "
                                            "error is first order in dx) [1]",
                                            choices=ROLLING_REFINEMENTS),
               "normal_tolerance": Option(NORMAL_TOLERANCE, "tolerance of the normal solver (relative "
                                          "pressure change and complementarity residual) [1]", minimum=0.0)}

    def supports(self, scene, level):
        why = super().supports(scene, level)
        if why:
            return why
        if getattr(scene.wheel, "rigid", False) and getattr(scene.rail, "rigid", False):
            return "model 'kalker' needs at least one elastic body (both are rigid)"
        return None

    def compute_patch(self, scene, level, options):
        compile_kernels()           # all of the plugin's kernels in the process's first solve (the runner's warm-up)
        cells = int(options.get("cells") or DEFAULT_CELLS)
        area, gap, sol = solve_scene_normal(scene, level, cells, float(options.get("normal_tolerance", NORMAL_TOLERANCE)),
                                            options.get("rolling_refinement", "auto"))
        line = area.y_edges is None
        check_border(area, sol.pressure, scene.name)
        x0, x1, y0, y1 = contact_extent(area.x, area.y, sol.pressure, area.dx, area.dy)
        a = 0.5 * (x1 - x0)
        b = None if line else 0.5 * (y1 - y0)
        p = sol.pressure[:, 0] if line else sol.pressure
        # the cells in contact: the patch of a non-Hertzian gap is no ellipse (grid.inside() returns them)
        grid = SurfaceGrid(area.x_edges, area.y_edges, float(a), None if b is None else float(b), contact=p > 0)
        nx, ny = area.shape
        diag = {"converged": bool(sol.converged), "iterations": int(sol.iterations), "residual": float(sol.residual),
                "approach": float(sol.approach), "products": int(sol.products),
                "elements_x": int(nx), "elements_y": int(ny), "rolling_refinement": int(area.refine_x),
                "elements_in_contact": int(np.count_nonzero(sol.pressure > 0)),
                # loaded elements x element area (a line contact: x element length, the contact length)
                "contact_area": float(np.count_nonzero(sol.pressure > 0)) * area.dx * area.dy,
                "gap": "hertz" if gap.hertz is not None else "non-hertzian",
                # 1: the gap solved is a profile wheelset's as the contact search samples it, so that the result
                # reports the CONTACT program's reference point at this approach (ProfileContact.reported_reference)
                "sampled_gap": int(isinstance(gap, SampledGap)),
                "residual_history": np.asarray(sol.history, dtype=float)}
        return ContactPatch(grid=grid, normal_force=float(scene.normal_force if scene.normal_force is not None
                                                          else sol.force),
                            a=float(a), b=None if b is None else float(b), max_pressure=float(p.max()),
                            pressure=np.array(p), contact_area=diag["contact_area"], diagnostics=diag)
