"""Temperature model "fdm": the finite-difference rail block of seed section 6.3.

Each body (wheel and rail) is a block whose top face carries its share of the heat source moving at the
body's speed relative to the contact. An elliptical patch runs the 3-D block (:mod:`.block3d`), a line
contact the 2-D (x-z) block (:mod:`.block2d`; exactly the 3-D block with a laterally uniform source). The
schemes (``explicit``, the seed's; ``implicit``; the moving-frame ``steady`` one for stiff cases) are
described in :mod:`.block3d`; :mod:`.scheme_choice` picks one per body. The result is the surface field in
the patch frame once the source has travelled ``travel`` (:func:`railtherm_fdm.layout.block_extent`),
flagged quasi-steady when it changed by less than 0.2 % over the last semi-axis. Scene key ``field``
stretches the block to hold the trail (:func:`railtherm_fdm.layout.trail_extent`). Pass histories of
transient scenes come from :mod:`.history` (line contact) and :mod:`.history3d` (patch); what they refuse:
:func:`history_limits`. Details: docs/NOTES.md, "FDM model".

References: [1] The seed paper, section 6.3: "Comparison of Numerical Methods for Solution of
Thermoelastic Wheel-Rail Contact Problems with Friction" (docs/references.md).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from railtherm import (BodyTemperature, Capabilities, Option, Refused, TemperatureField, TemperatureModel, asks_history,
                       with_history)
from railtherm.physics import field_grid, peclet_number, superposition_limits, thermal_scales, with_thermal_trace

from .layout import Trail
from .scheme_choice import (SCHEMES, check_explicit_step, choose_line_scheme, choose_scheme, explicit_cost,
                            requested_scheme)

#: the model and its scheme choice
__all__ = ["FDMTemperature", "choose_scheme", "explicit_cost"]

BODY_NAMES = ("wheel", "rail")


class FDMTemperature(TemperatureModel):
    """Finite differences in a rail block with a moving surface heat source (seed 6.3): 3-D for an
    elliptical patch, 2-D (x-z, per unit width) for a line contact.

    Cells: ``cell_size`` (default 2 min(a, b)/8 for an ellipse, 2a/16 for a line) halved per level.
    The 3-D transient schemes use cubic cells of that size; the 2-D ones a node spacing
    ``min(cell_size, delta/2) / 2**level`` that resolves the contact-time penetration depth
    delta = sqrt(2 a kappa / V) from level 0 on; the steady schemes grade their grids from it
    (:func:`railtherm_fdm.layout.graded_grid`).

    Diagnostics: per body (prefixed ``wheel_`` / ``rail_``) the scheme, Péclet number, heat put in
    (``power`` [W] or [W/m]) and the solver's own (energies, heat balance, iterations, ...); overall
    ``scheme`` (the rail's, else the wheel's), ``converged`` (every heated body's solve), ``iterations``
    (their sum), ``residual`` (the worst) and ``heat_balance_error`` (the bodies' balances weighted by
    the heat put into each) -- docs/verdicts.md.
    """

    name = "fdm"
    description = ("finite-difference block per body (seed 6.3; 3-D, or 2-D for line contacts): explicit "
                   "transient as the paper, implicit, or moving-frame steady for stiff cases; insulated sides, "
                   "fixed far faces, convection")
    capabilities = Capabilities(
        contacts=frozenset({"ellipse", "line"}), sources=frozenset({"computed", "given"}),
        tangential=frozenset({"full-sliding", "creepage"}), convection=True,
        modes=frozenset({"steady", "transient"}), field=True, histories=True,
        provides=frozenset({"surface_temperature", "max_surface_temperature", "mean_contact_temperature",
                            "temperature", "peak_temperature", "cooling_rate", "heated_depth", "time_above",
                            "temperature_history", "pass_peak_temperature", "residual_rise"}))
    options = {
        "scheme": Option("auto", "'explicit' (seed), 'implicit', 'steady' (moving frame) or 'auto'",
                         choices=SCHEMES),
        "cell_size": Option(0.0, "cell size d at level 0 [m]; 0: 2 min(a, b)/8", minimum=0.0),
        "courant": Option(1.0, "transient schemes: source advance per step in cells (capped by stability)",
                          minimum=1e-6),
        "budget": Option(4e9, "'auto': largest explicit cost in node updates", minimum=0.0),
        "threads": Option(0, "numba threads for the explicit stencil (0: numba's default)", minimum=0),
        "max_nodes": Option(5e7, "transient schemes: largest node count of the block (refused above)", minimum=1),
        "max_history_nodes": Option(1e6, "pass histories on a patch: largest node count of the 3-D section block "
                                         "(refused above; at 1e6 each sparse matrix, the operator and one per implicit step size, ~90 MB)",
                                    minimum=1),
        "max_cells": Option(4e6, "steady scheme: largest cell count of the graded grid (refused above)", minimum=1),
        "line_x_scheme": Option("upwind2", "line contacts, steady scheme: fluxes along x 'upwind2' (second-order "
                                           "upwind, default) or 'exponential' (as the 3-D block)",
                                choices=("upwind2", "exponential")),
    }

    #: below this Péclet number the steady 3-D block's iterative solve does not converge
    STEADY_PECLET_MIN = 0.1

    # -- compute -------------------------------------------------------------------------------
    def supports(self, scene, level):
        """What fdm's pass histories cover (:func:`history_limits`); core has checked the declared capabilities."""
        why = super().supports(scene, level)
        if why or not asks_history(scene):
            return why
        return history_limits(scene.friction, scene.heat_source, scene.wheel, scene.rail, scene.outputs)

    def compute_temperature(self, scene, source, level, options):
        """Surface (and, when asked for, depth at y = 0) temperatures of wheel and rail [degC]; in a
        transient scene that asks for them, the pass histories of the section (:mod:`.history`)."""
        bodies_m = (scene.wheel, scene.rail)
        convection, mode = scene.convection, getattr(scene, "mode", "steady")
        outputs = tuple(getattr(scene, "outputs", ()) or ())
        ts = _forced_step(scene.numerics)
        requested = requested_scheme(scene.numerics, options)
        if asks_history(scene):
            return self._histories(scene.transient, bodies_m, convection, mode, ts, outputs, requested, source,
                                   level, options)
        grid = source.grid
        fld = getattr(scene, "field", None)
        out = field_grid(grid, scene.field)
        extra = {}
        if fld is not None:       # without a field the blocks are called exactly as before
            behind = float(grid.x_edges[0] - out.x_edges[0])
            extra = {"out_grid": out, "trail": Trail(behind, None if fld.depth is None else float(fld.depth))}
        if grid.line:
            cell0 = float(options["cell_size"]) or 2.0 * float(grid.a) / 16.0
            diag = {"cell_size": cell0 / 2 ** int(level), "requested_scheme": requested, "dimension": 2}
        else:
            if int(options["threads"]) > 0:
                import numba  # numba on first use
                numba.set_num_threads(min(int(options["threads"]), numba.config.NUMBA_NUM_THREADS))
            cell0 = float(options["cell_size"]) or 2.0 * min(float(grid.a), float(grid.b)) / 8.0
            diag = {"cell_size": cell0 / 2 ** int(level), "requested_scheme": requested}
        depth = "temperature" in outputs or fld is not None
        bodies, solved = [], {}
        for i, body in enumerate(BODY_NAMES):
            q = np.asarray(source.flux(i), dtype=float)
            if not np.any(q > 0):
                diag[f"{body}_scheme"] = "none (no heat)"
                bodies.append(None)
                continue
            run = self._run_line if grid.line else self._run_block
            m = bodies_m[i]
            scheme, res = run(m, convection, mode, ts, source, level, options, i, q, cell0, requested, extra)
            body_diag = {"peclet": peclet_number(float(source.body_speed[i]), float(grid.a), m.diffusivity),
                         "power": float(grid.integrate(q)), "scheme": scheme,
                         **{k: v for k, v in res.diagnostics.items() if k != "scheme"}}
            solved[body] = body_diag
            zb, rise = res.z, res.depth
            if fld is not None and fld.depth is not None:
                zb, rise = _clip_depth(zb, rise, float(fld.depth))
            bodies.append(BodyTemperature(res.surface, z=zb if depth else None,
                                          depth_rise=rise if depth else None, diagnostics=body_diag))
        diag.update(_summary(diag, solved))
        # a depth field with no heated body: the bulk temperatures at the surface (down to field.depth)
        z = None
        if depth and not solved:
            z = np.zeros(1) if fld is None or fld.depth is None else np.array([0.0, float(fld.depth)])
        if fld is not None:
            diag.update({"field_behind": float(grid.x_edges[0] - out.x_edges[0]),
                         "field_cells_behind": int(out.x.size - grid.x.size)})
        result = TemperatureField.from_bodies(out, (bodies_m[0].bulk_temperature, bodies_m[1].bulk_temperature),
                                              *bodies, z=z, diagnostics=diag)
        return result if fld is None else with_thermal_trace(result, scene.field, source)

    def _histories(self, transient, bodies_m, convection, mode, time_step, outputs, requested, source, level,
                   options):
        """The pass histories of both bodies (:func:`railtherm_fdm.history.body_histories`; a body at rest under
        the contact, a locked wheel: :mod:`railtherm_fdm.spot`), with the steady one-pass surface (the
        moving-frame steady block) when ``outputs`` (empty: the defaults) ask for it.

        The scene's parts: ``transient`` (passes, schedule, history depths), ``bodies_m`` the wheel's and the
        rail's materials, ``convection`` [W/(m^2 K)] (None: 0), ``mode`` ("steady" or "transient"), the forced
        ``time_step`` [s] or None, and the ``requested`` scheme (:func:`railtherm_fdm.scheme_choice.requested_scheme`)."""
        from .history import body_histories                  # numba on first use
        from .spot import resting_body_history, with_resting_body
        grid = source.grid
        fluxes = [np.asarray(source.flux(i), dtype=float).reshape(grid.shape) for i in range(2)]
        # a body whose surface does not move through the contact (a locked wheel): its spot heated in place
        resting = [i for i, q in enumerate(fluxes) if np.any(q != 0) and not float(source.body_speed[i]) > 0.0]
        one_pass = not outputs or any(o in outputs for o in _ONE_PASS)
        if resting and one_pass:
            raise Refused(f"model 'fdm' ({BODY_NAMES[resting[0]]}): its surface does not move through the contact "
                          f"(speed {float(source.body_speed[resting[0]]):g} m/s), so it has no one-pass surface field "
                          f"in the contact's frame ({', '.join(_ONE_PASS)}); ask only the histories "
                          "(temperature_history, pass_peak_temperature, residual_rise, time_above)", kind="validity")
        bulk = (float(bodies_m[0].bulk_temperature), float(bodies_m[1].bulk_temperature))
        if requested == "steady":
            raise Refused("model 'fdm': scheme 'steady' (the moving frame) has no history at a fixed section; use "
                          "'auto', 'explicit' or 'implicit' for the pass histories", kind="validity")
        moving = [q if np.any(q != 0) and i not in resting else None for i, q in enumerate(fluxes)]
        hist, diag = body_histories(transient, convection, grid, moving, bodies_m,
                                    tuple(float(v) for v in source.body_speed), bulk, int(level), requested,
                                    max_nodes=float(options["max_history_nodes"]))
        for i in resting:
            t, rise, d = resting_body_history(transient, grid, fluxes[i], bodies_m[i],
                                              float(convection or 0.0), int(level), BODY_NAMES[i],
                                              max_nodes=float(options["max_history_nodes"]))
            hist = with_resting_body(hist, i, t, rise, transient, bulk[i])
            diag.update({f"{BODY_NAMES[i]}_history_{k}": v for k, v in d.items()})
        bodies = [None, None]
        if one_pass:
            cell0 = float(options["cell_size"]) or 2.0 * float(grid.a) / 16.0
            for i, q in enumerate(fluxes):
                if np.any(q > 0):
                    run = self._run_line if grid.line else self._run_block
                    scheme, res = run(bodies_m[i], convection, mode, time_step, source, level, options, i, q, cell0,
                                      "steady")
                    bodies[i] = BodyTemperature(res.surface, diagnostics={"scheme": scheme, **res.diagnostics})
                    diag[f"{BODY_NAMES[i]}_one_pass_scheme"] = scheme
        diag.update({"converged": True, "iterations": 0, "residual": 0.0, "dimension": 2,
                     "scheme": "transient section block (explicit/implicit by cost)"})
        result = TemperatureField.from_bodies(grid, bulk, *bodies, diagnostics=diag)
        if not one_pass:   # not computed: no one-pass field in the result (bulk would read as "not heated")
            result = dataclasses.replace(result, surface_temperature=None, max_surface_temperature=None,
                                         mean_contact_temperature=None)
        return with_history(result, hist)

    def _run_block(self, m, convection, mode, time_step, source, level, options, i, q, cell0, requested, extra=None):
        """Body ``i`` (material ``m``) on the 3-D block with cells ``cell0 / 2**level``: (scheme, BlockResult).

        The scene's parts: surface ``convection`` [W/(m^2 K)] (None: 0), ``mode`` ("steady" or "transient") and
        the forced ``time_step`` [s] or None (the scene's ``numerics.time_step``)."""
        from .block3d import explicit_stability_limit, steady_block, transient_block   # numba on first use
        from .kernels import compile_block_kernels      # numba on first use
        compile_block_kernels()                   # every level's kernels in the process's first solve (warm-up)
        grid = source.grid
        a, b = float(grid.a), float(grid.b)
        body = BODY_NAMES[i]
        d = cell0 / 2 ** int(level)
        ts = time_step
        h = float(convection or 0.0)
        V = float(source.body_speed[i])
        rc = m.density * m.specific_heat
        kappa = m.conductivity / rc
        lim = explicit_stability_limit(d, kappa, h, rc)
        scheme = choose_scheme(requested, mode, a, b, V, kappa, d,
                               float(options["budget"]), time_step=ts, dt_limit=lim, courant=float(options["courant"]))
        check_explicit_step(scheme, ts, lim, d=d, kappa=kappa, h=h, body=body)
        pe = peclet_number(V, a, kappa)
        if scheme == "steady" and pe < self.STEADY_PECLET_MIN:
            raise Refused(
                f"model 'fdm' ({body}): Péclet number V a/(2 kappa) = {pe:.3g} < {self.STEADY_PECLET_MIN:g}: the "
                "moving-frame steady block is diffusion-dominated there and its GMRES+ILU solve does not "
                "converge (stability study: 400 iterations, residual 0.05 at Péclet 0.01); use method 'fipy' "
                "or the exact railtherm.references.moving_source")
        delta = thermal_scales(a, V, kappa).thermal_depth
        if extra and scheme != "steady" and d > 0.5 * delta:
            # a field asks for temperatures in depth: the uniform transient grid must resolve the thermal layer
            if requested == "auto" and pe >= self.STEADY_PECLET_MIN:
                scheme = "steady"
            else:
                raise Refused(
                    f"model 'fdm' ({body}): the scene's field asks for temperatures in depth, but the {scheme} "
                    f"block's uniform node spacing d = {d:.3g} m is coarser than half the thermal layer "
                    f"sqrt(2 a kappa / V) = {delta:.3g} m in which the trace lies; use scheme 'steady' or 'auto' "
                    "(graded moving-frame grid) or a cell_size below that", kind="validity")
        args = (grid, q, grid.inside().astype(float), V, m.conductivity, m.density, m.specific_heat, h, d)
        if scheme == "steady":
            return scheme, steady_block(*args, level=level, max_cells=float(options["max_cells"]), **(extra or {}))
        return scheme, transient_block(*args, scheme=scheme, time_step=ts, courant=float(options["courant"]),
                                       max_nodes=float(options["max_nodes"]), **(extra or {}))

    def _run_line(self, m, convection, mode, time_step, source, level, options, i, q, cell0, requested, extra=None):
        """Body ``i`` (material ``m``) on the 2-D (x-z) block of a line contact: (scheme, BlockResult); the
        scene's parts ``convection``, ``mode`` and ``time_step`` as in :meth:`_run_block`.

        The steady scheme takes cells ``cell0 / 2**level`` along x over the band (its depth grid
        starts at ``min(cell, delta/4/2**level)``); the transient schemes a node spacing
        ``min(cell0, delta/2) / 2**level`` that resolves the flash layer from level 0 on.
        """
        from .block2d import line_stability_limit, steady_line, transient_line   # numba on first use
        grid = source.grid
        a = float(grid.a)
        body = BODY_NAMES[i]
        V = float(source.body_speed[i])
        if not V > 0.0:
            raise Refused(f"model 'fdm' ({body}, line): the {body} surface moves at {V:g} m/s relative to the "
                          "contact; the 2-D block needs a body moving through the contact (speed > 0): a "
                          "line source at rest on a half-plane has no steady state")
        ts = time_step
        h = float(convection or 0.0)
        rc = m.density * m.specific_heat
        kappa = m.conductivity / rc
        delta = thermal_scales(a, V, kappa).thermal_depth
        d = min(cell0, 0.5 * delta) / 2 ** int(level)
        lim = line_stability_limit(d, kappa, h, rc)
        scheme = choose_line_scheme(requested, mode, a, V, kappa, d,
                                    float(options["budget"]), time_step=ts, dt_limit=lim,
                                    courant=float(options["courant"]), body=body, level=level)
        check_explicit_step(scheme, ts, lim, d=d, kappa=kappa, h=h, body=body, line=True)
        args = (grid, q, grid.inside().astype(float), V, m.conductivity, m.density, m.specific_heat, h)
        if scheme == "steady":
            return scheme, steady_line(*args, cell0 / 2 ** int(level), level=level, x_scheme=options["line_x_scheme"],
                                       max_cells=float(options["max_cells"]), **(extra or {}))
        return scheme, transient_line(*args, d, scheme=scheme, time_step=ts, courant=float(options["courant"]),
                                      max_nodes=float(options["max_nodes"]), **(extra or {}))


#: the one-pass outputs fdm adds to a transient scene's histories (the moving-frame steady surface)
_ONE_PASS = ("surface_temperature", "max_surface_temperature", "mean_contact_temperature")


def history_limits(friction, heat_source, wheel, rail, outputs) -> str | None:
    """Why fdm cannot superpose the pass histories of a transient scene that asks for them, or None: the scene's
    friction law, heat source, wheel and rail materials and outputs checked by
    :func:`railtherm.physics.superposition_limits`."""
    return superposition_limits(friction, heat_source, wheel, rail, outputs, "fdm")


def _clip_depth(z, rise, depth: float):
    """The depth field down to exactly ``depth`` [m]: the block's depths above it and ``depth`` itself
    (rise interpolated linearly between the two block depths around it)."""
    z = np.asarray(z, dtype=float)
    rise = np.asarray(rise, dtype=float)
    keep = z < depth * (1.0 - 1e-12)
    if not keep.any() or z[-1] < depth:
        return z, rise
    at = np.array([np.interp(depth, z, r) for r in rise])
    return np.append(z[keep], depth), np.concatenate([rise[:, keep], at[:, None]], axis=1)


def _forced_step(numerics) -> float | None:
    """``numerics["time_step"]`` [s] of the scene's ``numerics`` mapping (or None), or None."""
    ts = dict(numerics or {}).get("time_step")
    return float(ts) if ts is not None else None


def _summary(diag, solved) -> dict:
    """Overall scheme and the verdict keys (docs/verdicts.md) from the heated bodies' diagnostics.

    ``converged``: every heated body's solve converged (GMRES / every implicit step's CG to its own
    tolerance; LU and explicit stepping are direct); ``iterations``: their sum (0 when direct);
    ``residual``: the worst relative residual [1]; ``heat_balance_error``: the bodies' balances weighted
    by the heat put into each, (heat carried out or stored by the field - heat put in) / heat put in [1].
    A model run with no heated body did nothing iterative: converged, 0 iterations, residual 0.
    """
    out = {"scheme": solved["rail"]["scheme"] if "rail" in solved else diag["rail_scheme"],
           "converged": bool(all(d["converged"] for d in solved.values())),
           "iterations": int(sum(int(d.get("iterations", 0)) for d in solved.values())),
           "residual": float(max([float(d.get("residual", 0.0)) for d in solved.values()] or [0.0]))}
    pairs = [(float(d.get("power", 0.0)), float(d["heat_balance_error"]))
             for d in solved.values() if "heat_balance_error" in d]
    total = sum(p for p, _ in pairs)
    if pairs and total > 0:
        out["heat_balance_error"] = float(sum(p * e for p, e in pairs) / total)
    return out
