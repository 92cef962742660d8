"""Temperature stage model "fipy": finite-volume heat conduction with FiPy.

Steady mode: each body (wheel at ``v_wheel``, rail at ``v_rail``) is solved in the frame moving with the
contact (:mod:`railtherm_fipy.steady`) on a mesh graded from the scene's scales (:mod:`railtherm_fipy.mesh`):
a line contact as one 2-D (x-z) problem per body; an ellipse as 2-D "strips" (``dimension = 2``, one x-z
problem per row, valid while the thermal layer ``delta = a/sqrt(Pe)`` is thin against b, refused when
``delta / b > max_strip_delta``) or one 3-D problem (``dimension = 3``); ``"auto"`` picks strips where valid,
else 3-D within ``max_cells``. Budgets (cells, estimated seconds, :func:`estimate_seconds_3d`) refuse a
scene before any solve. Transient mode: :mod:`railtherm_fipy.transient` (wheel heating over revolutions); pass
histories: :mod:`railtherm_fipy.history` (a line contact's 2-D section), :mod:`railtherm_fipy.history3d` (an
ellipse's 3-D block). Behind the patch and in depth (scene key ``field``): core's extended grid
(:func:`railtherm.physics.field_grid`) and :func:`railtherm.physics.with_thermal_trace`. The scheme is first
order along the flow wherever the cell Péclet number exceeds ~2 (upwinding), which limits accuracy at high Pe.
Measured accuracy, costs and details: docs/NOTES.md, "FiPy model". Temperatures: absolute (rise plus bulk).
"""
from __future__ import annotations

import math
import time

import numpy as np

from dataclasses import dataclass, field, replace

from railtherm import (BodyTemperature, Capabilities, Option, Refused, TemperatureField, TemperatureModel, asks_history,
                       histories_at_section, with_history)
from railtherm.physics import (embed_field, field_grid, lumped_wheel, superposition_limits, thermal_scales,
                               with_thermal_trace)
from railtherm.physics.thermal_trace import TRACE_OUTPUTS

from .history import fipy_block
from .history3d import MAX_HISTORY_CELLS, fipy_ellipse_block
from .mesh import moving_frame_mesh
from .solvers import solver_suite
from .steady import LU_MAX_CELLS_3D, SCHEMES, MovingFrameSolver
from .transient import wheel_heating

#: Cost model of a 3-D solve per body, calibrated on the development machine (FiPy 4.0.3, SciPy suite,
#: OPENBLAS_NUM_THREADS=1; uniform or Hertz flux on a circle a = 2 mm or ellipses 0.5 x 10 mm, both bodies
#: heated, time per body = solve_time / 2). Measured (cells, Pe, reported iterations, s per body):
#: GMRES + ILU: (28 080, 0.1, 105, 0.77), (53 856, 1, 82, 2.1), (59 972, 0.05, 166, 6.3), (70 560, 0.01, 400,
#: 5.2), (79 920, 0.007, 198, 4.9), (97 344, 0.0035, 129, 4.4), (115 200, 100, 42, 4.1), (152 064, 10, 72,
#: 5.2), (224 640, 0.1, 373, 17.7); i.e. 1.9e-7 .. 8.5e-7 s per cell and iteration. LU (3-D meshes up to
#: LU_MAX_CELLS_3D): (6 732, 1, 0.11), (15 180, 0.3, 0.88), (18 768, 0.2, 0.50): up to 6e-5 s per cell.
#: Commands: /tmp scripts calling ``railtherm.solve(scene, "fipy", level, {"dimension": 3, ...})`` and reading
#: ``fipy_max_cells``, ``fipy_iterations``, ``fipy_solve_time`` (see the report of the verdicts work).
#: The estimate takes the upper ends: it over-predicts by 1.3-2.7x, so it refuses only what is surely slow.
SECONDS_PER_CELL_ITERATION = 5e-7
SECONDS_PER_CELL_LU = 6e-5


def expected_iterations(peclet: float) -> int:
    """Envelope of the GMRES + ILU iterations measured above [1]: up to 82 at Pe >= 1, up to 400 below."""
    return 100 if peclet >= 1.0 else 400


def estimate_seconds_3d(cells: int, peclet: float, bodies: int) -> float:
    """Estimated wall time [s] of the 3-D solves: ``bodies`` meshes of ``cells`` cells at Péclet number ``peclet``.

    LU up to :data:`railtherm_fipy.steady.LU_MAX_CELLS_3D` cells (``SECONDS_PER_CELL_LU`` x cells), else
    GMRES + ILU (``SECONDS_PER_CELL_ITERATION`` x cells x :func:`expected_iterations`).
    """
    if cells <= LU_MAX_CELLS_3D:
        per_body = SECONDS_PER_CELL_LU * cells
    else:
        per_body = SECONDS_PER_CELL_ITERATION * cells * expected_iterations(peclet)
    return float(bodies) * per_body


#: result variables this model fills
PROVIDES = frozenset({"surface_temperature", "max_surface_temperature", "mean_contact_temperature", "temperature"})
#: the thermal trace (scenes with ``field``: :func:`railtherm.physics.with_thermal_trace` of the depth field)
TRACE = frozenset(TRACE_OUTPUTS)


class FipyTemperature(TemperatureModel):
    """Flash temperatures of wheel and rail by finite volumes (FiPy), steady in the contact frame.

    Solves ``kappa laplace(T) - div(u T) = 0`` with ``u = (-V, 0, 0)`` for each body: the frictional
    flux on the patch, convection ``h`` outside it, bulk temperature at the inflow, zero gradient at
    the outflow, insulated elsewhere (see :mod:`railtherm_fipy.steady`). Verified against Jaeger's
    moving band (2-D) and the moving surface source (3-D) of ``railtherm.references`` for Péclet
    numbers 0.1 to 1e4, and against Table 1 of Ertz & Knothe [1]_.

    Options
    -------
    scheme : {"power-law", "upwind", "exponential", "hybrid", "central"}
        FiPy convection scheme (default "power-law"; "central" oscillates at high cell Péclet
        number and is offered for demonstration only).
    dimension : {"auto", 2, 3}
        See the module docstring.
    refine : int
        FiPy cells per surface-grid cell along x (and y in 3-D) on the patch.
    layer_cells : float
        Cells per ``min(delta, a)`` at the surface at level 0.
    growth : float
        Growth ratio of the graded cells at level 0 (``growth**(1/2**level)`` at level k).
    max_cells : int
        Largest 3-D mesh (cells per body) this model will solve.
    max_cells_low_peclet : int
        Largest 3-D mesh when the Péclet number is below 1 (slow Krylov convergence there).
    max_strip_delta : float
        Largest ``delta / b`` for which strip-wise 2-D solves of an ellipse are accepted.
    max_history_cells : int
        Largest 3-D block (cells per body) of an ellipse's pass histories (:mod:`railtherm_fipy.history3d`).

    References
    ----------
    .. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation
       of temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
       (DOI not verified, see docs/references.md)
    .. [2] J.E. Guyer, D. Wheeler, J.A. Warren, FiPy: Partial differential equations with Python,
       Computing in Science & Engineering 11(3) (2009) 6-15. doi:10.1109/MCSE.2009.52
    .. [3] S.V. Patankar, Numerical Heat Transfer and Fluid Flow, Hemisphere, 1980 (power-law
       scheme). ISBN 978-0891165224
    """

    name = "fipy"
    description = ("finite-volume heat conduction with FiPy: steady moving frame (2-D/3-D), wheel heating and pass "
                   "histories (2-D section of a line contact, 3-D block of an ellipse)")
    capabilities = Capabilities(convection=True, modes=frozenset({"steady", "transient"}), moving_surface=True,
                                field=True, histories=True,
                                advice={"moving_surface": "e.g. a locked wheel v0 + v_s = 0; use a method with a static "
                                                          "source"},
                                provides=PROVIDES | TRACE | {"steady_wheel_temperature", "steady_mean_contact_temperature",
                                                             "temperature_history", "pass_peak_temperature",
                                                             "residual_rise"})
    options = {
        "scheme": Option("power-law", "convection scheme", choices=tuple(SCHEMES)),
        "dimension": Option("auto", "2 (x-z, strips of an ellipse), 3 (x-y-z) or auto", choices=("auto", 2, 3)),
        "refine": Option(1, "FiPy cells per surface-grid cell on the patch", minimum=1),
        "layer_cells": Option(4.0, "cells per min(delta, a) at the surface at level 0", minimum=0.5),
        "growth": Option(1.3, "growth ratio of graded cells at level 0", minimum=1.01),
        "max_cells": Option(400_000, "largest 3-D mesh per body [cells]", minimum=1000),
        "max_history_cells": Option(MAX_HISTORY_CELLS, "largest 3-D block of an ellipse's pass histories per body "
                                    "[cells]", minimum=1000),
        "max_cells_low_peclet": Option(100_000, "largest 3-D mesh per body when Pe < 1 [cells]", minimum=1000),
        "max_strip_delta": Option(0.02, "largest delta/b accepted for strip-wise 2-D solves", minimum=0.0),
        "max_seconds": Option(60.0, "largest estimated wall time [s] of the 3-D solves of both bodies "
                                    "(estimate_seconds_3d: cells x expected iterations, calibrated; it over-predicts "
                                    "up to 2.7x) or of a fixed-step transient (steps x 4e-5 s); refused above",
                              minimum=0.0),
    }

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def choose_dimension(bodies, field_depth, source, level, options, grid=None) -> tuple[int, str]:
        """Return (2 or 3, how) for the materials ``bodies`` (wheel, rail) and the source; raise
        :class:`railtherm.Refused` when neither works.

        ``how`` is "line", "strips" or "3-D". ``field_depth``: the scene's ``field.depth`` [m] or None (the mesh
        reaches it). ``grid``: the grid reported on (default ``source.grid``; the extended grid of the scene's
        ``field``, whose 3-D mesh is counted against the budgets).
        """
        grid = source.grid if grid is None else grid
        dim = options["dimension"]
        if grid.line:
            if dim == 3:
                raise Refused("model 'fipy': dimension 3 needs an elliptical patch; a line contact is solved in 2-D "
                              "(x-z): use dimension 'auto' or 2")
            return 2, "line"
        strip_why = FipyTemperature.strip_limit(bodies, source, options)
        cells = FipyTemperature.cells_3d(bodies, field_depth, source, level, options, grid)
        pe = min(thermal_scales(grid.a, source.body_speed[i], bodies[i].diffusivity).peclet for i in (0, 1))
        size_why = None
        bodies = sum(bool(np.any(np.asarray(source.flux(i)) != 0)) for i in (0, 1))
        seconds = estimate_seconds_3d(cells, pe, bodies)
        limit = float(options["max_seconds"])
        trail = "" if grid is source.grid else f" reaching {float(-grid.a - grid.x_edges[0]):.4g} m behind the patch (field)"
        if cells > options["max_cells"]:
            size_why = (f"a 3-D mesh{trail} would need {cells} cells per body > max_cells = {options['max_cells']} "
                        f"(lower the level{', shorten field.behind' if trail else ''} or raise the option max_cells)")
        elif pe < 1.0 and cells > options["max_cells_low_peclet"]:
            size_why = (f"a 3-D mesh{trail} would need {cells} cells per body > max_cells_low_peclet = "
                        f"{options['max_cells_low_peclet']} at Peclet number {pe:.3g} < 1 (diffusion-dominated: "
                        f"GMRES + ILU needs hundreds of iterations; lower the level or raise the option)")
        elif seconds > limit:
            size_why = (f"a 3-D solve{trail} of {bodies} bod{'y' if bodies == 1 else 'ies'} with {cells} cells each at Peclet "
                        f"number {pe:.3g} is estimated at {seconds:.3g} s ({expected_iterations(pe)} GMRES iterations "
                        f"expected) > max_seconds = {limit:g} s (lower the level or raise the option max_seconds)")
        if dim == 2:
            if strip_why:
                raise Refused(f"model 'fipy', dimension 2: {strip_why}; use dimension 3 or 'auto'")
            return 2, "strips"
        if dim == 3:
            if size_why:
                raise Refused(f"model 'fipy', dimension 3: {size_why}", kind="budget")
            return 3, "3-D"
        if strip_why is None:
            return 2, "strips"
        if size_why is None:
            return 3, "3-D"
        # the strips are invalid, the 3-D mesh is valid but over the budget: a budget refusal
        raise Refused(f"model 'fipy': {strip_why}, and {size_why}", kind="budget")

    @staticmethod
    def strip_limit(bodies, source, options) -> str | None:
        """Reason why strip-wise 2-D solves of an ellipse of the materials ``bodies`` (wheel, rail) are not valid,
        or None."""
        grid = source.grid
        worst = 0.0
        for i in (0, 1):
            v = source.body_speed[i]
            sc = thermal_scales(grid.a, v, bodies[i].diffusivity)
            worst = max(worst, sc.thermal_depth / grid.b)
        lim = options["max_strip_delta"]
        if worst > lim:
            pe = min(thermal_scales(grid.a, source.body_speed[i], bodies[i].diffusivity).peclet for i in (0, 1))
            return (f"strip-wise 2-D solves neglect lateral conduction, valid only for a thin thermal layer: "
                    f"delta/b = a/(b sqrt(Pe)) = {worst:.3g} > max_strip_delta = {lim:g} (Peclet number {pe:.3g})")
        return None

    @staticmethod
    def cells_3d(bodies, field_depth, source, level, options, grid=None) -> int:
        """Cells per body of the 3-D mesh (the larger of wheel and rail, materials ``bodies``) on ``grid`` (default
        ``source.grid``) reaching ``field_depth`` [m] (None: the mesh's own depth)."""
        grid = source.grid if grid is None else grid
        n = 0
        for i in (0, 1):
            m = moving_frame_mesh(grid.x_edges, grid.a, source.body_speed[i], bodies[i].diffusivity, level,
                                  y_patch_edges=grid.y_edges, b=grid.b, refine=options["refine"],
                                  layer_cells=options["layer_cells"], ratio=options["growth"],
                                  half=FipyTemperature._half(source), min_depth=field_depth)
            n = max(n, m.cells)
        return n

    @staticmethod
    def _half(source) -> bool:
        grid = source.grid
        if grid.line or grid.y.size % 2:
            return False
        q = np.asarray(source.power_density, dtype=float)
        eps = np.broadcast_to(np.asarray(source.heat_partition, dtype=float), q.shape)
        return bool(np.allclose(q, q[:, ::-1], rtol=1e-12, atol=0.0) and np.allclose(eps, eps[:, ::-1]))

    # ------------------------------------------------------------------ compute
    def supports(self, scene, level):
        """fipy's pass histories: line contacts (its 2-D FiPy section) and elliptical patches (its 3-D block),
        under the superposition's limits."""
        why = super().supports(scene, level)
        if why or not asks_history(scene):
            return why
        return superposition_limits(scene.friction, scene.heat_source, scene.wheel, scene.rail, scene.outputs, "fipy")

    def compute_temperature(self, scene, source, level, options):
        """Surface (and depth at y = 0) temperatures of wheel and rail [degC], absolute; in a transient scene
        with passes, the pass histories (:meth:`_histories`)."""
        opts = {**options, "refine": int(options["refine"])}   # resolved by core (pipeline)
        bodies = (scene.wheel, scene.rail)
        fld = getattr(scene, "field", None)
        depth = _field_depth(fld)
        radius = float(getattr(scene, "wheel_radius", None) or scene.wheel.radius)
        if asks_history(scene):
            outputs = tuple(getattr(scene, "outputs", ()) or ())
            return self._histories(scene.transient, bodies, scene.convection, outputs, depth, radius, source, level,
                                   opts)
        grid = field_grid(source.grid, fld)                     # the patch grid, or its extension (field)
        flash = self._steady(bodies, depth, scene.convection, source, level, opts, grid)
        if getattr(scene, "mode", "steady") != "transient":
            result = self._lumped_steady(bodies, scene.convection, radius, source, flash, grid)
        else:
            heating = dict(convection=scene.convection, wheel_radius=radius,
                           numerics=getattr(scene, "numerics", {}), name=getattr(scene, "name", "?"))
            result = self._transient(bodies, heating, source, level, opts, flash, grid)
        if fld is None:
            return result
        return with_thermal_trace(result, fld, source)

    def _histories(self, transient, bodies, convection, outputs, field_depth, radius, source, level, opts):
        """The pass histories of both bodies (materials ``bodies``) on the FiPy section under the scene's
        ``transient`` passes and schedule (:mod:`railtherm_fipy.history`, stepped by
        :func:`railtherm.solving.section_stepping.histories_at_section`), with the steady one-pass fields of the
        moving frame when ``outputs`` (empty: the defaults) ask them; ``convection`` [W/(m^2 K)], ``field_depth``
        [m] or None, wheel ``radius`` [m]."""
        grid = source.grid
        fluxes = [np.asarray(source.flux(i), dtype=float).reshape(-1) for i in range(2)]
        for i, q in enumerate(fluxes):
            if np.any(q != 0) and not float(source.body_speed[i]) > 0.0:
                raise Refused(f"model 'fipy' ({('wheel', 'rail')[i]}): its surface moves at "
                              f"{float(source.body_speed[i]):g} m/s relative to the contact; the section's passes "
                              "need a body moving through it")
        bulk = (float(bodies[0].bulk_temperature), float(bodies[1].bulk_temperature))

        def make_block(v, m, convection, duration, z):
            args = (v, m.conductivity, m.density * m.specific_heat, convection, level, duration, z,
                    transient.schedule_time, transient.schedule_factor)
            if grid.line:
                return fipy_block(float(grid.a), *args)
            return fipy_ellipse_block(float(grid.a), float(grid.b), *args, max_cells=opts["max_history_cells"],
                                 body="wheel" if m is bodies[0] else "rail")
        section = ("the fixed section (x-z)" if grid.line else
                   "a 3-D block (x-y-z) around the fixed section, the centre line's column sampled")
        hist, diag = histories_at_section(
            transient, convection, grid.x_edges, grid.y_edges,
            [q if np.any(q != 0) else None for q in fluxes], tuple(float(v) for v in source.body_speed),
            tuple(bodies), bulk, int(level), "implicit", make_block,
            f"FiPy cell-centred finite volumes of {section}, Crank-Nicolson steps per eigenmode of the separable "
            "operator (FiPy has no explicit stepping)",
            "conduction along the rail beyond the block's ends" + ("" if grid.line else " and sides")
            + "; the wheel's curvature")
        diag.update({"converged": True, "iterations": 0, "residual": 0.0, "dimension": 2 if grid.line else 3,
                     "scheme": "transient FiPy section (Crank-Nicolson)"})
        one_pass = ("surface_temperature", "max_surface_temperature", "mean_contact_temperature")
        if not outputs or any(o in outputs for o in one_pass):
            flash = self._steady(bodies, field_depth, convection, source, level, opts, grid)
            result = self._lumped_steady(bodies, convection, radius, source, flash, grid)
            # the one-pass depth field lies on another depth axis than the histories: not returned
            result = replace(result, z=None, temperature=None,
                             diagnostics={**dict(result.diagnostics or {}), **diag})
        else:
            result = TemperatureField.from_bodies(grid, bulk, diagnostics=diag)
        return with_history(result, hist)

    @staticmethod
    def _lumped_steady(bodies, convection, radius, source, flash, grid=None):
        """Steady mode: the long-term values of Ertz & Knothe's lumped wheel (no time integration) of the materials
        ``bodies`` (wheel, rail), surface ``convection`` [W/(m^2 K)] and wheel ``radius`` [m].

        ``T_inf = eps P / (G_cond + alpha A)`` and ``T_mean_inf = T_mean + eps_c T_inf`` (seed eqs.
        50-54), with core's :func:`railtherm.physics.lumped_wheel` and its documented convective area
        A (the same as the "green" method's default); the state the transient mode converges to.
        """
        patch = source.grid
        grid = patch if grid is None else grid
        v_w, v_r = (float(v) for v in source.body_speed)
        power = float(patch.integrate(np.asarray(source.flux(0), dtype=float) * np.ones(patch.shape)))
        wheel, rail = bodies
        st = lumped_wheel(power, 0.0, wheel=wheel, rail=rail, speed_wheel=v_w, speed_rail=v_r,
                          a=grid.a, b=None if grid.line else grid.b, radius=float(radius),
                          heat_transfer=float(convection or 0.0))
        return flash.field(grid, steady_wheel_temperature=wheel.bulk_temperature + st.wheel_rise,
                           steady_mean_contact_temperature=flash.mean_wheel(grid)
                           + st.contact_fraction * st.wheel_rise)

    def _transient(self, bodies, heating, source, level, opts, flash, grid=None):
        """Wheel heating over many revolutions on top of the cold-wheel flash field (seed eq. 54): the materials
        ``bodies`` (wheel, rail), ``heating`` the keywords of :func:`railtherm_fipy.transient.wheel_heating`
        (``convection``, ``wheel_radius``, ``numerics``, ``name``).

        Superposition (seed eqs. 41, 44, 54): with the tread rise T_s at the end of the simulated time,
        in the patch both surfaces rise by eps_c T_s; outside it the wheel is at T_s, and the wheel's
        depth profile rises by T_s. The radial history itself is summarised in the ``transient_*``
        diagnostics.
        """
        h = wheel_heating(bodies, source=source, level=level, options=opts, **heating)
        ts = float(h["tread"][-1])                      # tread rise at the end of the simulated time
        eps_c = h["eps_c"]
        grid = source.grid if grid is None else grid
        inside = grid.inside()
        diag = dict(flash.diagnostics)
        diag.update({"transient_" + k: v for k, v in h.items() if np.isscalar(v)})
        diag["transient_tread_fraction_of_steady"] = ts / h["t_inf"] if h["t_inf"] > 0 else 1.0
        diag["transient_mean_fraction_of_steady"] = float(h["mean"][-1]) / h["t_inf"] if h["t_inf"] > 0 else 1.0
        bulk_w = bodies[0].bulk_temperature
        warm = flash.warmed(np.where(inside, eps_c * ts, ts), np.where(inside, eps_c * ts, 0.0), ts)
        return warm.field(grid, steady_wheel_temperature=bulk_w + ts,
                          steady_mean_contact_temperature=bulk_w + (flash.mean_wheel(grid) - bulk_w) + eps_c * ts,
                          diagnostics=diag)

    def _steady(self, bodies, field_depth, convection, source, level, opts, grid=None) -> "_Flash":
        """Steady moving-frame flash temperature rises of both bodies (materials ``bodies``, surface ``convection``
        [W/(m^2 K)]) on ``grid`` (default ``source.grid``; the extended grid of the scene's ``field``: zero flux and
        convection behind the patch, the mesh's uniform cells running through the trail and its depth reaching
        ``field_depth`` [m])."""
        patch = source.grid
        grid = patch if grid is None else grid
        extended = grid is not patch
        dim, how = self.choose_dimension(bodies, field_depth, source, level, opts, grid)
        min_depth = field_depth
        t0 = time.perf_counter()
        surface, body_diag = [None, None], [None, None]      # rises of the heated bodies and their diagnostics
        depth_T, depth_z = [], []
        diag = {"dimension": dim, "mode": how, "scheme": opts["scheme"], "refine": opts["refine"]}
        if extended or min_depth is not None:
            diag.update(field_behind=float(patch.x_edges[0] - grid.x_edges[0]),
                        field_cells_behind=int(grid.x.size - patch.x.size))
        tally = _Tally()
        contact = grid.inside()
        for i in (0, 1):
            mat = bodies[i]
            v = float(source.body_speed[i])
            q = np.asarray(source.flux(i), dtype=float) * np.ones(patch.shape)
            if extended:
                q = embed_field(q, patch, grid)                  # zero flux behind the patch
            mesh = moving_frame_mesh(grid.x_edges, grid.a, v, mat.diffusivity, level,
                                     y_patch_edges=None if dim == 2 else grid.y_edges,
                                     b=grid.b, refine=opts["refine"], layer_cells=opts["layer_cells"],
                                     ratio=opts["growth"], half=(dim == 3 and self._half(source)),
                                     min_depth=min_depth)
            if extended and dim == 2 and mesh.cells > opts["max_cells"]:
                raise Refused(f"model 'fipy': the 2-D mesh reaching {float(-grid.a - grid.x_edges[0]):.4g} m behind "
                              f"the patch and {float(mesh.z_edges[-1]):.4g} m deep (field) would need {mesh.cells} cells "
                              f"per {'strip' if how == 'strips' else 'body'} > max_cells = {opts['max_cells']} (lower the "
                              "level, shorten field.behind or raise the option max_cells)", kind="budget")
            bd = {"peclet": mesh.peclet}
            if not np.any(q != 0):  # no heat enters this body (partition 0 or 1): rise 0
                diag[f"{('wheel', 'rail')[i]}_peclet"] = mesh.peclet
                depth_T.append(np.zeros((grid.x.size, mesh.z_edges.size - 1)))
                depth_z.append(0.5 * (mesh.z_edges[1:] + mesh.z_edges[:-1]))
                continue
            solver = MovingFrameSolver(mesh, v, mat, scheme=opts["scheme"])
            rows = _PatchRows.of(grid, mesh, solver, extended, opts["refine"])
            if dim == 2 and grid.line:
                surface[i], T, z = _solve_line(solver, rows, grid, q, contact, convection, tally)
            elif dim == 2:
                surface[i], T, z = _solve_strip_rows(solver, rows, grid, q, contact, convection, tally, bd)
            else:
                surface[i], T, z = _solve_3d(solver, mesh, rows, grid, q, contact, convection, tally)
            depth_T.append(T)
            depth_z.append(z)
            bd.update(first_cell=float(mesh.z_edges[1]), depth=float(mesh.z_edges[-1]), cells=int(mesh.cells))
            body_diag[i] = bd
        if min_depth is not None:           # the depth field down to field.depth exactly
            for i in (0, 1):
                depth_z[i], depth_T[i] = _to_depth(depth_z[i], depth_T[i], min_depth)
        diag.update(tally.diagnostics(), solve_time=time.perf_counter() - t0)
        diag["solver_suite"] = solver_suite()
        bulk = (bodies[0].bulk_temperature, bodies[1].bulk_temperature)
        return _Flash(bulk, tuple(surface), tuple(depth_T), tuple(depth_z), tuple(body_diag), diag)


@dataclass
class _Tally:
    """The solves' iterations, residuals, energy balances and cells, and the heat put in and carried out
    (advected + convected) [W, or W/m], summed over both bodies."""

    iters: list = field(default_factory=list)
    resid: list = field(default_factory=list)
    balance: list = field(default_factory=list)
    cells: list = field(default_factory=list)
    heat_in: float = 0.0
    heat_out: float = 0.0

    def add(self, res, balance=None) -> None:
        self.iters.append(res["iterations"]), self.resid.append(res["residual"])
        if balance is None:
            self.balance.append(res["energy_balance"])
        else:
            self.balance.extend(balance)
        self.cells.append(res["cells"])

    def diagnostics(self) -> dict:
        iters, resid, balance, cells = self.iters, self.resid, self.balance, self.cells
        heat_in, heat_out = self.heat_in, self.heat_out
        return dict(iterations=int(max(iters) if iters else 0), residual=float(max(resid) if resid else 0.0),
                    converged=True, solves=len(iters), max_cells=int(max(cells) if cells else 0),
                    energy_balance_min=float(min(balance) if balance else 1.0),
                    energy_balance_max=float(max(balance) if balance else 1.0),
                    # (heat carried out of the mesh by the field - heat put in) / heat put in (docs/verdicts.md)
                    heat_balance_error=float(heat_out / heat_in - 1.0) if heat_in > 0 else 0.0)


@dataclass(frozen=True)
class _PatchRows:
    """Where the grid's cells lie among the solver's fine surface faces: from face ``i0``, ``refine`` faces per
    grid cell (``nxp`` in all, at ``fine_x``)."""

    x: np.ndarray                 # grid x centres [m]
    size: int                     # solver.x.size
    i0: int
    nxp: int
    refine: int
    fine_x: np.ndarray

    @classmethod
    def of(cls, grid, mesh, solver, extended, refine):
        lo = float(grid.x_edges[0]) if extended else -grid.a    # the grid's first edge on the mesh
        i0 = int(np.searchsorted(mesh.x_edges, lo - 1e-12 * grid.a))
        nxp = grid.x.size * refine
        return cls(grid.x, solver.x.size, i0, nxp, refine, solver.x[i0:i0 + nxp])

    def to_grid(self, values):
        """Fine patch values -> grid x centres."""
        return values if self.refine == 1 else np.interp(self.x, self.fine_x, values)

    def on_mesh(self, row):
        """Grid row -> fine surface faces (piecewise constant)."""
        full = np.zeros(self.size)
        full[self.i0:self.i0 + self.nxp] = np.repeat(row, self.refine)
        return full

    def depth(self, T, nz):
        """The depth field (nx, nz) on the grid of a fine field T (faces, nz)."""
        i0, nxp = self.i0, self.nxp
        return np.array([self.to_grid(T[i0:i0 + nxp, k]) for k in range(nz)]).T


def _solve_line(solver, rows, grid, q, contact, convection, tally):
    """One body of a line contact (2-D): surface rise on the grid, depth field and depth axis."""
    i0, nxp = rows.i0, rows.nxp
    res = solver.solve(rows.on_mesh(q), convection=convection, contact=rows.on_mesh(contact.astype(float)) > 0)
    tally.add(res)
    w = grid.integrate(q)
    tally.heat_in, tally.heat_out = tally.heat_in + w, tally.heat_out + res["energy_balance"] * w
    return rows.to_grid(res["surface"][i0:i0 + nxp]), rows.depth(res["T"], res["z"].size), res["z"]


def _solve_strip_rows(solver, rows, grid, q, contact, convection, tally, bd):
    """One body of an ellipse strip by strip (2-D, one strip per grid row in y): surface rise, the depth field
    of the centre strip and its depth axis."""
    i0, nxp = rows.i0, rows.nxp
    centre = int(np.argmin(np.abs(grid.y)))
    Q = np.array([rows.on_mesh(q[:, j]) for j in range(grid.y.size)])
    C = np.array([rows.on_mesh(contact[:, j].astype(float)) > 0 for j in range(grid.y.size)])
    res = solver.solve_strips(Q, C, convection=convection, keep=centre)
    tally.add(res, balance=res["energy_balance"][np.any(Q > 0, axis=1)])
    w = q.sum(axis=0) * grid.cell_area                        # heat into each strip [W]
    tally.heat_in, tally.heat_out = tally.heat_in + w.sum(), tally.heat_out + float(np.sum(res["energy_balance"] * w))
    bd["factorisations"] = int(res["factorisations"])
    surface = np.array([rows.to_grid(row[i0:i0 + nxp]) for row in res["surface"]]).T
    return surface, rows.depth(res["T"], res["z"].size), res["z"]


def _solve_3d(solver, mesh, rows, grid, q, contact, convection, tally):
    """One body in 3-D (the half y >= 0 on a symmetric mesh): surface rise on the grid, the depth field at y = 0
    and its depth axis."""
    from scipy.interpolate import RegularGridInterpolator  # scipy.interpolate (~80 ms): 3-D solves only

    i0, nxp, r_ = rows.i0, rows.nxp, rows.refine
    j0 = int(np.searchsorted(mesh.y_edges, -grid.b - 1e-12 * grid.b)) if not mesh.half else 0
    nyp = grid.y.size * r_
    ycells = np.repeat(np.arange(grid.y.size), r_)
    qf = np.zeros((solver.x.size, solver.y.size))
    cf = np.zeros_like(qf, dtype=bool)
    if mesh.half:
        jh = np.flatnonzero(grid.y > 0)
        yrep = np.repeat(jh, r_)
        qf[i0:i0 + nxp, :yrep.size] = np.repeat(q[:, yrep], r_, axis=0)
        cf[i0:i0 + nxp, :yrep.size] = np.repeat(contact[:, yrep], r_, axis=0)
    else:
        qf[i0:i0 + nxp, j0:j0 + nyp] = np.repeat(q[:, ycells], r_, axis=0)
        cf[i0:i0 + nxp, j0:j0 + nyp] = np.repeat(contact[:, ycells], r_, axis=0)
    res = solver.solve(qf, convection=convection, contact=cf)
    tally.add(res)
    w = grid.integrate(q)
    tally.heat_in, tally.heat_out = tally.heat_in + w, tally.heat_out + res["energy_balance"] * w
    S = res["surface"][i0:i0 + nxp]
    yy = solver.y if not mesh.half else np.concatenate([-solver.y[::-1], solver.y])
    SS = S if not mesh.half else np.concatenate([S[:, ::-1], S], axis=1)
    interp = RegularGridInterpolator((rows.fine_x, yy), SS, bounds_error=False, fill_value=None)
    X, Y = grid.mesh()
    surface = interp(np.stack([X.ravel(), Y.ravel()], axis=1)).reshape(grid.shape)
    Tyz = res["T"][i0:i0 + nxp]
    ys = solver.y
    if mesh.half:
        k0 = 0  # y = 0 is a symmetry plane: the first cell row is the nearest
        Tc = Tyz[:, k0, :]
    else:
        kk = np.argsort(np.abs(ys))[:2]
        w = np.abs(ys[kk[::-1]]) / np.abs(ys[kk]).sum()
        Tc = w[0] * Tyz[:, kk[0], :] + w[1] * Tyz[:, kk[1], :]
    return surface, np.array([rows.to_grid(Tc[:, k]) for k in range(res["z"].size)]).T, res["z"]


def _field_depth(fld) -> float | None:
    """The depth [m] of the scene's ``field`` (a :class:`railtherm.input.scene.Field` or None), or None (no field,
    or the model's own depth)."""
    depth = None if fld is None else getattr(fld, "depth", None)
    return None if depth is None else float(depth)


def _to_depth(z: np.ndarray, T: np.ndarray, depth: float) -> tuple[np.ndarray, np.ndarray]:
    """The depth field (nx, nz) on the cell centres ``z`` cut at ``depth`` [m]: the centres above it and
    ``depth`` itself (linear interpolation between the two centres around it; the mesh reaches it)."""
    z = np.asarray(z, dtype=float)
    keep = z < depth * (1.0 - 1e-12)
    k = int(np.clip(np.searchsorted(z, depth), 1, z.size - 1))
    w = (depth - z[k - 1]) / (z[k] - z[k - 1])
    last = (1.0 - w) * T[:, k - 1] + w * T[:, k]
    return np.append(z[keep], depth), np.concatenate([T[:, keep], last[:, None]], axis=1)


@dataclass(frozen=True)
class _Flash:
    """The steady flash rises of both bodies before they are assembled into the result.

    Attributes
    ----------
    bulk : (float, float)
        Bulk temperatures of wheel and rail [degC].
    surface : (ndarray or None, ndarray or None)
        Surface rise of each body on the patch grid [K]; None for a body without heat.
    depth : (ndarray, ndarray)
        Rise at y = 0 against depth, (nx, nz_i) [K] (zeros for a body without heat).
    z : (ndarray, ndarray)
        Each body's depth axis [m]; the wheel's is the result's common axis.
    body_diagnostics : (dict or None, dict or None)
        Each heated body's diagnostics (prefixed with its name in the result).
    diagnostics : dict
        The model's diagnostics.
    depth_offset : float
        Rise added to the wheel's depth profile [K] (the warmed wheel of the transient mode).
    """

    bulk: tuple
    surface: tuple
    depth: tuple
    z: tuple
    body_diagnostics: tuple
    diagnostics: dict
    depth_offset: float = 0.0

    def mean_wheel(self, grid) -> float:
        """Mean wheel surface temperature over the patch [degC] (as the result's ``mean_contact_temperature``)."""
        rise = 0.0 if self.surface[0] is None else self.surface[0]
        return float((self.bulk[0] + rise * np.ones(grid.shape))[grid.inside()].mean())

    def warmed(self, wheel_rise, rail_rise, wheel_depth_rise) -> "_Flash":
        """The flash field on top of a warmed wheel: surface rises added per body [K] (a body without heat
        that now warms gets a surface rise and no depth profile) and ``wheel_depth_rise`` [K] added to the
        wheel's depth profile."""
        surface = tuple(extra if s is None and np.any(extra != 0) else (s if s is None else s + extra)
                        for s, extra in zip(self.surface, (wheel_rise, rail_rise)))
        return _Flash(self.bulk, surface, self.depth, self.z, self.body_diagnostics, self.diagnostics,
                      self.depth_offset + wheel_depth_rise)

    def field(self, grid, *, steady_wheel_temperature, steady_mean_contact_temperature, diagnostics=None):
        """The result: :meth:`railtherm.TemperatureField.from_bodies` on the wheel's depth axis (the rail
        interpolated onto it, zero rise below its mesh)."""
        bodies = []
        for i, rise in enumerate(self.surface):
            if rise is None:
                bodies.append(None)
                continue
            heated = self.body_diagnostics[i] is not None
            offset = self.depth_offset if i == 0 else 0.0
            bodies.append(BodyTemperature(rise, z=self.z[i] if heated else None,
                                          depth_rise=(self.depth[i] + offset if offset else self.depth[i])
                                          if heated else None,
                                          diagnostics=self.body_diagnostics[i] or {}))
        return TemperatureField.from_bodies(grid, self.bulk, *bodies, z=self.z[0],
                                            steady_wheel_temperature=steady_wheel_temperature,
                                            steady_mean_contact_temperature=steady_mean_contact_temperature,
                                            diagnostics=self.diagnostics if diagnostics is None else diagnostics)
