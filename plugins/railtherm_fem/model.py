"""CoupledModel "fem": 2-D quasistatic thermoelastic FEM rolling contact (seed section 4).

A rigid wheel (``wheel = { rigid = true }``, as in the paper) or an elastic wheel rolls on an elastic
strip lying on a rigid foundation, in the frame moving with the wheel; see :mod:`railtherm_fem.coupled`
for the operator splitting and the heat flux, :mod:`.contact` for the contact law, :mod:`.thermal` for
the conduction, :mod:`.elastic` and :mod:`.condense` for the strip. Results are on the patch grid of the
computed half-width a, centred on the computed patch (a rigid wheel's tangential-normal coupling may shift
it: diagnostics ``patch_centre``); nodal fields are mapped as cell averages of their piecewise-linear
interpolant, stick is the state of the nearest node in contact.

Temperatures: the rail from the strip's conduction problem; the wheel -- rigid or not -- from the same
solver applied to the wheel's material moving at V + v_s, with the wheel's share eps of the heat (and the
contact conductance, when given); for a rigid wheel that temperature is a report only. Fields behind the
patch and in depth (``field``): :class:`FemModel`. Transient scenes (passes over the section or wheel
revolutions): one pass's heat source stepped in time on the FE section, :mod:`railtherm_fem.history`.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from railtherm import (BodyTemperature, Capabilities, ContactPatch, CoupledModel, HeatSource, Option, Refused,
                       SolverError, TemperatureField, asks_history, surface_grid, with_history)
from railtherm.physics import field_grid, nodal_cell_average, with_thermal_trace
from railtherm.physics.friction import LAW_KINDS
from railtherm.physics.pass_history import superposition_limits
from railtherm.physics.thermal_trace import TRACE_OUTPUTS

from .coupled import FIELD_MARGIN, FIELD_TRAIL_RATIO, FemProblem, _interpolator, fem_limits, solve_fem
from .history import section_histories
from .thermal import ThermalBody, ThermalSolver, hat_load, thermal_grid

__all__ = ["FemModel"]

TEMPERATURE_OUTPUTS = frozenset({"surface_temperature", "temperature", "max_surface_temperature",
                                 "mean_contact_temperature"}) | frozenset(TRACE_OUTPUTS)
PROVIDES = frozenset({
    "pressure", "traction_x", "slip_velocity_x", "stick", "normal_force", "semi_axis_a", "contact_area", "max_pressure",
    "creep_force_x", "heat_flux", "frictional_power", "heat_partition", "surface_temperature", "temperature",
    "max_surface_temperature", "mean_contact_temperature",
    "temperature_history", "pass_peak_temperature", "residual_rise",
}) | frozenset(TRACE_OUTPUTS)
#: one pass's surface outputs a transient scene may ask beside the histories (the steady moving-frame solve)
ONE_PASS_SURFACE = ("surface_temperature", "max_surface_temperature", "mean_contact_temperature")


#: a direct (LU) thermal solve whose relative residual ||A theta - b|| / ||b|| exceeds this is reported as
#: not converged [1] (round-off of a sound factorisation is ~1e-14; a singular or ill-conditioned one is not)
THERMAL_RESIDUAL_LIMIT = 1e-8


def verdict_diagnostics(sol, thermal: bool) -> dict:
    """``converged``, ``iterations`` and ``residual`` of a FEM solve (docs/verdicts.md).

    With the thermal part, the outer solver is the Steps 1-4 coupling loop: its iterations and its last
    relative change max|theta^{k+1} - theta^k| / max|theta^{k+1}| [1]; it has converged when that met the
    ``coupling_tolerance`` (or when nothing couples back: no thermal expansion) *and* the last contact
    solve converged *and* the thermal LU solves are sound. Without it, the outer solver is the contact
    problem's semismooth Newton: its iterations and its residual relative to the mean pressure [1].
    """
    c = sol.contact
    contact_ok = bool(c.converged)
    if thermal:
        tres = float(sol.diagnostics.get("thermal_residual", 0.0))
        residual = float(sol.diagnostics.get("coupling_residual", 0.0))
        return dict(converged=bool(sol.coupling_converged and contact_ok and tres < THERMAL_RESIDUAL_LIMIT),
                    iterations=int(sol.coupling_iterations), residual=residual)
    return dict(converged=contact_ok, iterations=int(c.iterations), residual=float(c.residual))


class FemModel(CoupledModel):
    """Quasistatic thermoelastic FEM of a wheel rolling on an elastic strip (line contacts).

    Behind the patch and in depth (scene key ``field``; ``Capabilities(field=True)``): the
    temperatures are sampled from the strip's thermal layer on core's extended grid
    (:func:`railtherm.physics.field_grid`) down to ``field.depth`` exactly (linear in z between the
    layer's nodes, as its P1 elements), and the thermal trace is :func:`railtherm.physics.with_thermal_trace`.
    The layer's outflow end (-L/2) must lie 2a beyond -a - behind, and the layer must be 2 x field.depth
    deep: a default strip is lengthened/deepened to that, a given one that is too short or shallow is
    refused with the limit. Behind the patch the x-spacing then grows by 1 + 0.02/2^level only. Against
    Jaeger's band at Pe 1000 (tests/test_fem_field.py): peak temperature at 0..0.3 mm to 8.5e-4 of the
    rise at level 2 (second order). Without ``field`` the grids and results are those of the patch alone.

    Transient scenes (``mode = "transient"`` with passes, a schedule or a transient output; line contacts):
    one pass's heat source (the scene's, or the contact's) heats the fixed section of each body, a Q1 FE
    heat equation stepped by Crank-Nicolson (:func:`railtherm_fem.history.section_histories`); the outputs
    ``temperature_history``, ``pass_peak_temperature``, ``residual_rise`` and ``time_above``, beside one
    pass's steady surface temperatures when asked. Against the exact moving band
    (tests/test_fem_transient.py, tests/test_fem_wheel_spin.py): second order in the section's spacing. The
    contact's own heat is tau . s with the elastic creep in the slip (full sliding of equal bodies: s = -v_s +
    V mu x / R), 0.089 mm behind the patch centre on the study's wheel spin, where the exact band's full-sliding
    heat mu p v_s is centred: under a schedule that ramps the heat up through the first pass, that pass's
    peaks are 1.5-2.5 % above the band's at any level (the later passes' within 1 %).
    """

    name = "fem"
    description = ("2-D plane-strain FEM strip (graded P1 mesh, condensed onto the contact), Signorini + "
                   "regularised Coulomb by semismooth Newton, moving-frame conduction, Steps 1-4 coupling (seed section 4)")
    capabilities = Capabilities(contacts=frozenset({"line"}), sources=frozenset({"computed", "given"}),
                                tangential=frozenset({"full-sliding", "creepage"}), convection=True, field=True,
                                modes=frozenset({"steady", "transient"}), histories=True, moving_surface=True,
                                provides=PROVIDES,
                                friction_laws=LAW_KINDS,
                                advice={"moving_surface": "it needs a positive rolling speed (steady moving frame)"})
    options = {
        "thermal_model": Option("2d", "conduction along x included ('2d') or dropped (seed eq. 16, '1d')",
                                choices=("2d", "1d")),
        "thermal_resistance": Option(0.0, "r [K s/m] of the contact conductance p/r (seed: 1000); 0 = none",
                                     minimum=0.0),
        "coupling_tolerance": Option(1e-6, "eta: stop when max|theta^{k+1}-theta^k| <= eta max|theta| [1]",
                                     minimum=0.0),
        "coupling_max_iterations": Option(30, "limit of the Steps 1-4 loop", minimum=1),
        "grading": Option(8.0, "mesh grading: element size ~ distance / grading", minimum=1.0),
        "regularization": Option(None, "friction regularisation eps [1] (default: scene numerics, else 0 = exact "
                                       "Coulomb; eps biases the creep force by about eps/|creepage|)"),
        "cells": Option(None, "cells of the patch grid at level 0"),
    }

    def supports(self, scene, level):
        why = super().supports(scene, level)
        if why:
            return why
        cr = getattr(scene, "creepage", None)
        if cr is not None and (cr.lateral or cr.spin):
            return (f"model 'fem' is 2-D (longitudinal creepage only); lateral={cr.lateral!r}, spin={cr.spin!r} "
                    "need a 3-D method (e.g. fastsim-fdm)")
        if scene.heat_source is None:
            if getattr(scene.rail, "rigid", False):
                return "model 'fem' needs an elastic rail strip"
            if scene.friction is None:
                return "model 'fem' needs a friction coefficient"
            if scene.normal_force is not None and not scene.normal_force > 0:
                return (f"model 'fem': normal_force = {scene.normal_force!r} N/m presses nothing into the strip "
                        "(no contact, no heat); give a load > 0 or a penetration")
        if getattr(scene, "transient", None) is not None:     # a transient scene
            if not asks_history(scene):
                return ("model 'fem' computes the pass histories of a transient scene (passes, schedule or a transient "
                        "output: temperature_history, pass_peak_temperature, residual_rise, time_above); this scene "
                        "asks none (a wheel warming over revolutions is model 'fipy''s transient mode)")
            return superposition_limits(scene.friction, scene.heat_source, scene.wheel, scene.rail, scene.outputs,
                                        "fem")
        return None

    # ------------------------------------------------------------------------------------------
    @staticmethod
    def _problem(level, options, thermal, *, wheel, rail, speed, wheel_radius, normal_force, penetration, friction,
                 creepage, sliding_speed, heat_partition, convection, strip, field, numerics):
        """The FEM problem of a scene's parts at ``level`` with the model's ``options``.

        Parameters
        ----------
        level : int
            Mesh level k [1].
        options : dict
            The model's resolved options.
        thermal : bool
            Whether the thermal part runs.
        wheel, rail : Material
            Elastic and thermal constants of both bodies (SI).
        speed : float
            Rolling speed V [m/s].
        wheel_radius : float
            Wheel radius r0 [m].
        normal_force, penetration : float or None
            Load per width [N/m], or the wheel's penetration [m] when no load is given.
        friction : FrictionLaw or None
            The scene's law (its ``nominal`` [1] where one coefficient is needed); None: frictionless.
        creepage : Creepage or None
            Creepages (only ``longitudinal`` [1] applies in 2-D); None for full sliding.
        sliding_speed : float or None
            Sliding speed v_s [m/s] (full sliding).
        heat_partition : HeatPartition, float or str
            The scene's ``heat_partition``: the wheel's fraction [1] or the rule (resolved by
            :meth:`railtherm.physics.partition.HeatPartition.of` in :class:`FemProblem`).
        convection : float
            Heat transfer coefficient [W m-2 K-1].
        strip : Strip or None
            Strip ``length`` and ``depth`` [m].
        field : Field or None
            ``behind`` and ``depth`` [m] of the scene's field.
        numerics : mapping
            The scene's numerics (``regularization`` [1]).
        """
        eps = options.get("regularization")
        if eps is None:
            # exact Coulomb unless asked: the seed's eps = 1e-3 is a relative micro-slip as large as the
            # creepages of rolling (1e-4 .. 1e-3) and would turn the stick zone viscous (Fx ~ mu N |xi| / eps)
            eps = (numerics or {}).get("regularization", 0.0)
        creep = None
        sliding = None
        if creepage is not None:
            creep = float(creepage.longitudinal)
        else:
            sliding = float(sliding_speed or 0.0)
        behind, field_depth = _field(field)
        return FemProblem(
            radius=float(wheel_radius), rail=rail, wheel=wheel, speed=float(speed),
            normal_force=normal_force, penetration=penetration if normal_force is None else None,
            friction=friction,
            creepage=creep, sliding_speed=sliding,
            regularization=float(eps), heat_partition=heat_partition,
            convection=float(convection or 0.0),
            thermal_resistance=float(options.get("thermal_resistance") or 0.0),
            strip_length=getattr(strip, "length", None) if strip else None,
            strip_depth=getattr(strip, "depth", None) if strip else None,
            level=int(level), thermal=thermal, two_d=options.get("thermal_model", "2d") == "2d",
            grading=float(options.get("grading") or 8.0),
            coupling_tolerance=float(options.get("coupling_tolerance", 1e-6)),
            coupling_max_iterations=int(options.get("coupling_max_iterations", 30)),
            field_behind=behind, field_depth=field_depth)

    def compute(self, scene, level, options, stages, upstream):
        why = self.supports(scene, level)
        if why:
            raise Refused(why)
        cells = options.get("cells")
        bulk = (scene.wheel.bulk_temperature, scene.rail.bulk_temperature)
        transient = asks_history(scene)
        if transient:
            # the pass histories, beside one pass's steady surface temperatures when the scene asks them (or no
            # outputs); no field behind the patch (a transient scene's field gives the histories' depths)
            outputs = tuple(scene.outputs or ())
            thermal = not outputs or any(o in ONE_PASS_SURFACE for o in outputs)
            fld = None
        else:
            # the pipeline may plan only ("normal",) for a coupled model (docs/DESIGN.md, "Stages"): run the
            # thermal part whenever the scene asks for a temperature output
            thermal = "temperature" in stages or any(o in TEMPERATURE_OUTPUTS for o in scene.outputs)
            fld = getattr(scene, "field", None)
        if upstream.source is not None:   # a given heat source (core's "given", run by the plan)
            given = self._given(level, options, upstream.source, wheel=scene.wheel, rail=scene.rail,
                                convection=scene.convection, strip=getattr(scene, "strip", None),
                                field=fld, scene_name=scene.name) if thermal else None
            if transient:
                hist = section_histories(scene.transient, scene.convection, (scene.wheel, scene.rail), upstream.source,
                                         level, scene.name)
                given = self._with_histories(given, *hist, bulk)
            return None, None, given
        prob = self._problem(
            level, options, thermal, wheel=scene.wheel, rail=scene.rail, speed=scene.speed,
            wheel_radius=scene.wheel_radius, normal_force=scene.normal_force, penetration=scene.penetration,
            friction=scene.friction, creepage=scene.creepage,
            sliding_speed=scene.sliding_speed, heat_partition=scene.partition, convection=scene.convection,
            strip=getattr(scene, "strip", None), field=fld, numerics=getattr(scene, "numerics", None))
        if transient and prob.heat_partition.needs_temperatures and not prob.thermal:
            # the partition rule's fraction is found with the steady pass's temperatures (Step 3)
            prob = replace(prob, thermal=True)
        why = fem_limits(prob)
        if why:
            raise Refused(f"scene {scene.name!r}: {why}", kind="validity")
        sol = self._solve(prob, scene.name, level)
        patch, source, grid, xc, diag = self._patch_and_source(sol, prob, level, cells)
        temp = None
        if thermal:
            temp = self._temperature_from(sol.thermal_grid, sol.theta, grid, xc, fld, bulk,
                                          {**diag, **self._stresses(sol, grid, xc)}, source, scene_name=scene.name)
        if transient:
            hist = section_histories(scene.transient, scene.convection, (scene.wheel, scene.rail), source, level,
                                     scene.name)
            temp = self._with_histories(temp, *hist, bulk)
        return (patch if {"normal", "tangential"} & set(stages) else None,
                source if "heat_source" in stages or thermal or transient else None, temp)

    @staticmethod
    def _with_histories(one_pass, history, diag, grid, bulk):
        """The transient result: one pass's steady surface temperatures ``one_pass`` (a
        :class:`TemperatureField`, or None: bulk temperatures on ``grid``) without their depth field (on
        another depth axis than the histories), with ``history`` (a
        :class:`~railtherm.contract.transient.TransientHistory`) and its diagnostics ``diag``; ``bulk``: the
        bulk temperatures of wheel and rail [degC]."""
        if one_pass is None:
            return with_history(TemperatureField.from_bodies(grid, bulk, diagnostics=diag), history)
        return with_history(replace(one_pass, z=None, temperature=None,
                                    diagnostics={**dict(one_pass.diagnostics or {}), **diag}), history)

    @staticmethod
    def _solve(prob, scene_name, level):
        """:func:`solve_fem` of ``prob``; an internal failure on valid input (mesh, factorisation) raises
        :class:`railtherm.SolverError` with the solver's words (``scene_name``, ``level`` [1] for the message)."""
        try:
            return solve_fem(prob)
        except (RuntimeError, ValueError, np.linalg.LinAlgError) as exc:
            raise SolverError(f"scene {scene_name!r}, level {level}: model 'fem' failed: "
                              f"{type(exc).__name__}: {exc}") from exc

    @staticmethod
    def _patch_and_source(sol, prob, level, cells):
        """The contact patch and heat source of a FEM solution on the patch grid ``surface_grid(a, None, level,
        cells)`` centred on the computed patch: (patch, source, grid, patch centre xc [m], diagnostics).

        Parameters
        ----------
        sol : FemSolution
            The solution of :func:`railtherm_fem.coupled.solve_fem`.
        prob : FemProblem
            Its problem (``speed`` [m/s], ``mu`` [1] (its law's nominal), ``creepage`` [1], ``sliding_speed`` [m/s]).
        level : int
            Mesh level k [1].
        cells : int or None
            Cells of the patch grid at level 0 (the model's option).
        """
        c = sol.contact
        a, xc = sol.half_width, sol.centre
        grid = surface_grid(a, None, level, cells)
        edges = grid.x_edges + xc
        V = prob.speed
        pressure = nodal_cell_average(c.x, c.pressure, edges)
        traction = nodal_cell_average(c.x, c.traction, edges)
        slip = nodal_cell_average(c.x, V * np.nan_to_num(c.slip), edges)
        # stick: the state of the nearest node in contact (the patch edges lie between the outermost
        # contact nodes and the next, open ones, whose state would read "slip")
        loaded = np.nonzero(c.pressure > 0)[0]
        loaded = loaded if loaded.size else np.arange(c.x.size)
        near = loaded[np.argmin(np.abs(c.x[loaded][None, :] - (grid.x + xc)[:, None]), axis=1)]
        stick = np.where(grid.inside(), c.stick[near].astype(float), np.nan)
        diag = dict(sol.diagnostics)
        diag.update(verdict_diagnostics(sol, prob.thermal))
        diag.update(patch_centre=float(xc), coupling_iterations=int(sol.coupling_iterations),
                    coupling_converged=bool(sol.coupling_converged),
                    coupling_history=",".join(f"{h:.3e}" for h in sol.history),
                    coupling_relaxation=",".join(f"{w:.3g}" for w in sol.omegas),
                    nodal_frictional_power=float(sol.frictional_power))
        if not prob.mu > 0:
            # frictionless: no traction and no stick anywhere; every point slips at the rigid slip V xi (the
            # limit mu -> 0 of the frictional solution; the contact solver computes no slip without friction)
            xi = prob.creepage if prob.creepage is not None else -(prob.sliding_speed or 0.0) / V
            traction, slip = np.zeros_like(pressure), np.full_like(pressure, V * xi)
            stick = np.where(grid.inside(), 0.0, np.nan)
        patch = ContactPatch(grid=grid, normal_force=float(c.normal_force), a=float(a), b=None,
                             max_pressure=float(c.pressure.max()), pressure=pressure, traction_x=traction,
                             slip_velocity_x=slip, stick=stick,
                             creep_force_x=float(c.tangential_force) if prob.mu > 0 else 0.0,
                             diagnostics=diag)
        power = nodal_cell_average(c.x, sol.heat_power_density, edges)
        source = HeatSource(grid=grid, power_density=power, heat_partition=float(sol.heat_partition),
                            body_speed=tuple(float(v) for v in sol.body_speed),
                            frictional_power=float(sol.frictional_power), patch=patch, diagnostics=diag)
        return patch, source, grid, xc, diag

    # ------------------------------------------------------------------------------------------
    @staticmethod
    def _temperature_from(tgrid, theta, grid, xc, fld, bulk_temperature, diag, source=None, *, scene_name=None):
        """The temperature field of the thermal solution ``theta`` on the patch grid, or on the field's extended
        grid with the thermal trace.

        Parameters
        ----------
        tgrid : ThermalGrid
            The thermal grid: ``x`` [m] along the strip, ``z`` [m] in depth.
        theta : sequence of ndarray
            Temperature rise of wheel and rail on ``tgrid`` [K], shape (nx, nz) each.
        grid : SurfaceGrid
            The patch grid (centred on the patch).
        xc : float
            Patch centre on the strip [m].
        fld : Field or None
            The scene's ``field``: ``behind`` [m], ``depth`` [m] and ``threshold`` [degC].
        bulk_temperature : (float, float)
            Bulk temperatures of wheel and rail [degC].
        diag : dict
            Diagnostics to report.
        source : HeatSource, optional
            Its ``body_speed`` [m/s] for the thermal trace.
        scene_name : str, optional
            For messages.
        """
        if fld is None:
            xs = grid.x + xc
            bodies = [BodyTemperature(np.interp(xs, tgrid.x, theta[j][:, 0]), z=tgrid.z,
                                      depth_rise=np.stack([np.interp(xs, tgrid.x, theta[j][:, k])
                                                           for k in range(tgrid.z.size)], axis=1))
                      for j in range(2)]
            return TemperatureField.from_bodies(grid, bulk_temperature, *bodies, z=tgrid.z, diagnostics=diag)
        # the scene's field: core's extended grid, sampled on the thermal layer of the strip
        out = field_grid(grid, fld)
        xs = out.x + xc
        reach = float(xc - tgrid.x[0])           # how far behind the patch centre the thermal layer reaches
        if tgrid.x[0] > out.x_edges[0] + xc:
            raise Refused(f"scene {scene_name!r}: model 'fem': the strip's thermal layer reaches {reach:.4g} m "
                          f"behind the patch centre, less than the field's {float(-out.x_edges[0]):.4g} m "
                          f"(a + field.behind); lengthen the strip (strip.length) or shorten field.behind",
                          kind="validity")
        z = np.asarray(tgrid.z, float)
        depth = getattr(fld, "depth", None)
        if depth is not None:
            depth = float(depth)
            if z[-1] < depth:
                raise Refused(f"scene {scene_name!r}: model 'fem': the strip's thermal layer is {z[-1]:.4g} m "
                              f"deep, less than field.depth = {depth:g} m; deepen the strip (strip.depth)",
                              kind="validity")
        bodies = []
        for j in range(2):
            rise = np.stack([np.interp(xs, tgrid.x, theta[j][:, k]) for k in range(z.size)], axis=1)
            zb = z
            if depth is not None:              # the depth field down to field.depth exactly (P1 in z)
                keep = z < depth * (1.0 - 1e-12)
                k = int(np.clip(np.searchsorted(z, depth), 1, z.size - 1))
                w = (depth - z[k - 1]) / (z[k] - z[k - 1])
                last = (1.0 - w) * rise[:, k - 1] + w * rise[:, k]
                zb = np.append(z[keep], depth)
                rise = np.concatenate([rise[:, keep], last[:, None]], axis=1)
            bodies.append(BodyTemperature(rise[:, 0].copy(), z=zb, depth_rise=rise))
        diag = {**diag, "field_behind": float(grid.x_edges[0] - out.x_edges[0]),
                "field_cells_behind": int(out.x.size - grid.x.size), "field_thermal_reach": reach,
                "field_thermal_nodes_behind": int(np.sum(tgrid.x < grid.x_edges[0] + xc))}
        result = TemperatureField.from_bodies(out, bulk_temperature, *bodies, z=bodies[0].z, diagnostics=diag)
        return with_thermal_trace(result, fld, source)

    @staticmethod
    def _stresses(sol, grid, xc):
        """Surface stress diagnostics: FE sigma_xx with thermal part, and the thin-layer limit."""
        strip = sol.strip
        th = sol.rail_theta()
        xs = grid.x + xc
        z = np.full(xs.shape, 1e-3 * (sol.contact.x[1] - sol.contact.x[0]))
        s = strip.stress(sol.displacement, xs, z, th)
        s_mech = strip.stress(sol.displacement, xs, z, None)
        E = strip.mu * (3 * strip.lam + 2 * strip.mu) / (strip.lam + strip.mu)
        nu = strip.lam / (2 * (strip.lam + strip.mu))
        tmax = float(np.max(th(xs, 0 * xs))) if sol.theta is not None else 0.0
        return dict(surface_stress_xx_min=float(s[0].min()), surface_stress_xx_max=float(s[0].max()),
                    thermal_stress_xx_min=float((s[0] - s_mech[0]).min()),
                    thin_layer_thermal_stress=float(-E * strip.alpha * tmax / (1 - nu)))

    def _given(self, level, options, source, *, wheel, rail, convection, strip, field, scene_name=None):
        """Thermal part only, for a heat flux the scene gives (both bodies at their body_speed).

        Parameters
        ----------
        level, options : int, dict
            Mesh level k [1] and the model's resolved options, as in :meth:`_problem`.
        source : HeatSource
            The given heat source: ``shape``, ``peak_flux`` [W/m^2] or ``power_density`` [W/m^2] on its grid,
            ``heat_partition`` [1] and ``body_speed`` [m/s].
        wheel, rail : Material
            Thermal constants of both bodies (SI) and their ``bulk_temperature`` [degC].
        convection : float or None
            Heat transfer coefficient [W m-2 K-1].
        strip : Strip or None
            Strip ``length`` and ``depth`` [m].
        field : Field or None
            The scene's ``field``: ``behind`` and ``depth`` [m], ``threshold`` [degC].
        scene_name : str, optional
            For messages.
        """
        grid = source.grid
        a = grid.a
        level = int(level)
        shape, q0 = source.shape, source.peak_flux
        if shape == "uniform":
            qf = lambda s: np.where(np.abs(s) <= a, q0, 0.0)
        elif shape == "hertz":
            qf = lambda s: q0 * np.sqrt(np.clip(1 - (s / a) ** 2, 0.0, None))
        else:
            edges, pd = grid.x_edges, source.power_density
            qf = lambda s: np.where((s >= edges[0]) & (s < edges[-1]),
                                    pd[np.clip(np.searchsorted(edges, s) - 1, 0, pd.size - 1)], 0.0)
        two_d = options.get("thermal_model", "2d") == "2d"
        vw, vr = source.body_speed
        conv = float(convection or 0.0)
        bodies = [ThermalBody(m.conductivity, m.density * m.specific_heat, v, conv)
                  for m, v in ((wheel, vw), (rail, vr))]
        behind, fdepth = _field(field)
        length, sdepth = getattr(strip, "length", None), getattr(strip, "depth", None)
        if behind is not None and length and 0.5 * length < behind + (1.0 + FIELD_MARGIN) * a:
            raise Refused(f"scene {scene_name!r}: model 'fem': field.behind = {behind:g} m does not fit on the strip "
                          f"(length L = {length:g} m): its outflow end -L/2 must lie {FIELD_MARGIN:g} a beyond -a - behind "
                          f"(a = {a:g} m); use strip length >= {2.0 * (behind + (1.0 + FIELD_MARGIN) * a):.4g} m or leave "
                          "strip.length out", kind="validity")
        if fdepth is not None and sdepth and sdepth < 2.0 * fdepth:
            raise Refused(f"scene {scene_name!r}: model 'fem': field.depth = {fdepth:g} m is too deep for the strip "
                          f"(depth {sdepth:g} m; its thermal layer must reach 2 x field.depth); use strip depth >= "
                          f"{2.0 * fdepth:.4g} m or leave strip.depth out", kind="validity")
        tgrid = given_grid(a, bodies, level, two_d, length, behind, fdepth)
        load = hat_load(tgrid.x, qf, breaks=np.concatenate([[-a, a], grid.x_edges]), order=4)
        eps = source.heat_partition
        eps = float(np.mean(eps)) if np.ndim(eps) else float(eps)
        solver = ThermalSolver(tgrid, bodies, two_d)
        theta = solver.solve([eps * load, (1 - eps) * load])
        # one direct solve (banded LU per depth mode): 0 iterations, its relative residual ||A theta - b|| / ||b||
        diag = dict(converged=bool(np.isfinite(solver.residual) and solver.residual < THERMAL_RESIDUAL_LIMIT),
                    iterations=0, residual=float(solver.residual),
                    thermal_unknowns=int(solver.unknowns), thermal_model="2d" if two_d else "1d")
        return self._temperature_from(tgrid, theta, grid, 0.0, field, (wheel.bulk_temperature, rail.bulk_temperature),
                                      diag, source, scene_name=scene_name)


def _field(fld):
    """``field.behind`` and ``field.depth`` [m] of the scene's ``field`` (a :class:`~railtherm.input.scene.Field`
    or None): (None, None without a field; depth None: the model's default)."""
    if fld is None:
        return None, None
    depth = getattr(fld, "depth", None)
    return float(fld.behind), (None if depth is None else float(depth))


def given_grid(a, bodies, level, two_d, length=None, behind=None, field_depth=None):
    """Thermal grid for a band of half-width a (spacing a/(10 2^level), wake 40 a or the strip).

    With the scene's ``field`` (``behind`` and/or ``field_depth`` [m] not None): the wake reaches at least
    ``behind + (1 + FIELD_MARGIN) a`` (when no strip length is given), the layer at least 2 ``field_depth``,
    and the x-spacing behind the patch grows by 1 + 0.02 / 2^level only."""
    dx = a / (10.0 * 2 ** level)
    kap = min(b.diffusivity / b.speed for b in bodies)
    kmax = max(b.diffusivity / b.speed for b in bodies)
    x_min = -(0.5 * length if length else 40.0 * a)
    x_max = a + (max(30 * kap, 4 * dx) if two_d else dx)
    depth = 8.0 * math.sqrt(kmax * (x_max - x_min)) + 4 * kmax
    rz = 1.0 + 0.2 / 2 ** level
    if behind is None and field_depth is None:
        return thermal_grid(a, dx, x_min, x_max, 0.5 * min(math.sqrt(kap * dx), dx), depth, rz, rz)
    if behind is not None and not length:
        x_min = min(x_min, -(behind + (1.0 + FIELD_MARGIN) * a))
        depth = 8.0 * math.sqrt(kmax * (x_max - x_min)) + 4 * kmax
    if field_depth is not None:
        depth = max(depth, 2.0 * field_depth)
    return thermal_grid(a, dx, x_min, x_max, 0.5 * min(math.sqrt(kap * dx), dx), depth, rz, rz,
                        ratio_trail=1.0 + FIELD_TRAIL_RATIO / 2 ** level)
