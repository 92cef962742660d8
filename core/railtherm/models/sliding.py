"""Core models of the tangential and heat-source stages: "full-sliding" (traction mu p against the slip v_s),
"frictional" (heat = -traction . slip) and "given" (the scene's own heat source)."""
from __future__ import annotations

import numpy as np

from ..contract.errors import Refused
from ..contract.grid import BASE_CELLS, surface_grid
from ..contract.capabilities import Capabilities
from ..contract.options import Option
from ..contract.results import HeatSource
from ..contract.stages import HeatSourceModel, TangentialContactModel
from ..physics.averaging import cell_average, exact_total
from ..physics.friction import LAW_KINDS, local_friction
from ..physics.kinematics import body_speeds
from ..physics.partition import scene_partition


#: the verdict keys of a closed-form stage (docs/verdicts.md): converged, no iterations, no residual
CLOSED_FORM = {"converged": True, "iterations": 0, "residual": 0.0}


class FullSlidingTangential(TangentialContactModel):
    """Full sliding: the whole patch slips at v_s, traction mu p against the slip (seed eq. 37).

    The wheel surface moves at v_w = V + v_s relative to the contact, the rail at v_r = V
    (seed eqs. 32-33). The local dissipation -(traction . slip) = mu p |v_s| is exact per cell (the
    pressure is cell-averaged and mu |v_s| constant), so core's heat source integrates it to
    mu |v_s| N to round-off.

    Every friction law applies: the slip speed is |v_s| in every cell, so a slip-velocity law gives
    mu(|v_s|) N exactly; a temperature law takes each cell's contact temperature (core's coupled loop).
    """

    name = "full-sliding"
    exact_reference = "full-sliding"
    description = "full sliding: traction mu p opposing the slip v_s over the whole patch"
    capabilities = Capabilities(contacts=frozenset({"ellipse", "line", "gap"}),
                                tangential=frozenset({"full-sliding"}), sources=frozenset({"computed"}),
                                provides=frozenset({"traction_x", "slip_velocity_x", "stick", "creep_force_x"}),
                                friction_laws=LAW_KINDS)

    def compute_tangential(self, scene, patch, level, options):
        vs = scene.sliding_speed
        speeds = body_speeds(scene.speed, vs, scene.tangential)
        if scene.friction.kind != "constant":
            return self._with_law(scene.friction, scene.wheel.bulk_temperature, scene.rail.bulk_temperature,
                                  patch, vs, speeds)
        mu = scene.friction.nominal
        mu_p = mu * patch.pressure
        # material flows in -x: the wheel surface moves at -(V + v_s), the rail at -V, so the wheel
        # slips at -v_s relative to the rail and friction pushes it forward (+x) for v_s > 0
        return patch.with_tangential(
            traction_x=np.sign(vs) * mu_p, slip_velocity_x=np.where(patch.pressure > 0, -vs, 0.0),
            stick=np.where(patch.pressure > 0, 0.0, np.nan),
            creep_force_x=np.sign(vs) * mu * patch.normal_force,
            body_speed=speeds, dissipation=mu * abs(vs) * patch.pressure,
            diagnostics=dict(CLOSED_FORM))

    @staticmethod
    def _with_law(law, wheel_bulk, rail_bulk, patch, vs, body_speed):
        """Full sliding under a friction law: mu of each cell at |v_s| and its contact temperature.

        Parameters
        ----------
        law : railtherm.physics.friction.FrictionLaw
            The scene's friction law.
        wheel_bulk, rail_bulk : float
            Bulk temperatures of wheel and rail [degC] (the contact temperature when the patch carries none).
        patch : ContactPatch
            The normal stage's patch (pressure [Pa], optionally ``contact_temperature`` [degC]).
        vs : float
            Sliding speed v_s [m/s].
        body_speed : (float, float)
            Surface speeds of wheel and rail through the patch [m/s].
        """
        mu = local_friction(law, patch, wheel_bulk, rail_bulk, abs(vs))
        mu_p = mu * patch.pressure
        return patch.with_tangential(
            traction_x=np.sign(vs) * mu_p, slip_velocity_x=np.where(patch.pressure > 0, -vs, 0.0),
            stick=np.where(patch.pressure > 0, 0.0, np.nan),
            creep_force_x=float(np.sign(vs) * patch.grid.integrate(mu_p)),
            body_speed=body_speed, dissipation=abs(vs) * mu_p,
            diagnostics={**CLOSED_FORM, "friction_min": float(mu[patch.pressure > 0].min()),
                         "friction_max": float(mu[patch.pressure > 0].max())})


def frictional_heat_source(patch, partition, wheel, rail, body_speed, *, scene_name=None) -> HeatSource:
    """The heat source of a tangential patch: power density -(traction . slip velocity) [W/m^2].

    Uses the patch's ``dissipation`` when the tangential model integrated it exactly over each cell,
    else the product of the traction and slip fields (a missing component counts as zero). The
    bodies move at the patch's ``body_speed``, else at ``body_speed``.

    Parameters
    ----------
    patch : ContactPatch
        The tangential stage's patch.
    partition : railtherm.physics.partition.HeatPartition
        The scene's heat partition (a fraction, or Blok's equal-temperature rule).
    wheel, rail : Material
        Their ``effusivity`` [W s^0.5 m^-2 K^-1] for Blok's rule.
    body_speed : (float, float)
        Surface speeds of wheel and rail through the patch [m/s] when the patch has none
        (:func:`railtherm.physics.body_speeds`).
    scene_name : str, optional
        For messages.

    Returns
    -------
    HeatSource
        ``frictional_power`` is the grid integral of the power density [W] ([W/m] for a line).
    """
    if patch.dissipation is not None:
        q = np.asarray(patch.dissipation, dtype=float)
    else:
        if patch.traction_x is None and patch.traction_y is None:
            raise Refused(f"scene {scene_name!r}: the heat source needs the tangential traction and slip; "
                          "the method's chain has no tangential stage")
        q = np.zeros(patch.pressure.shape)
        for t, s in ((patch.traction_x, patch.slip_velocity_x), (patch.traction_y, patch.slip_velocity_y)):
            if t is not None and s is not None:
                q = q - np.asarray(t, dtype=float) * np.asarray(s, dtype=float)
    v_w, v_r = patch.body_speed if patch.body_speed is not None else body_speed
    eps = scene_partition(partition, wheel, rail, v_w, v_r, scene_name=scene_name)
    return HeatSource(grid=patch.grid, power_density=q, heat_partition=eps, body_speed=(float(v_w), float(v_r)),
                      frictional_power=patch.grid.integrate(q), patch=patch, diagnostics=dict(CLOSED_FORM))


class FrictionalHeat(HeatSourceModel):
    """Core's heat source: the local frictional power -(traction . slip) of the tangential stage.

    Full sliding gives mu p v_s (seed eq. 37); FASTSIM gives the "modified FASTSIM" power density
    -p . s of seed section 6.2. See :func:`frictional_heat_source`.
    """

    name = "frictional"
    description = "frictional heat: power density -(traction . slip velocity), split by the heat partition"
    capabilities = Capabilities(contacts=frozenset({"ellipse", "line", "gap"}), sources=frozenset({"computed"}),
                                provides=frozenset({"heat_flux", "frictional_power", "heat_partition"}))

    def compute_source(self, scene, patch, level, options):
        return frictional_heat_source(patch, scene.partition, scene.wheel, scene.rail,
                                      body_speeds(scene.speed, scene.sliding_speed, scene.tangential),
                                      scene_name=scene.name)


def given_heat_source(heat_source, partition, wheel, rail, body_speed, level: int, cells: int | None = None, *,
                      scene_name=None) -> HeatSource:
    """The heat source a scene gives (``heat_source = { flux, shape, semi_axes | half_width }``).

    ``flux`` is the uniform value, or the peak for ``shape = "hertz"``.

    Parameters
    ----------
    heat_source : railtherm.input.scene.GivenHeatSource
        ``flux`` [W/m^2], ``shape`` ("uniform" or "hertz"), ``semi_axes`` [m] or ``half_width`` [m].
    partition : railtherm.physics.partition.HeatPartition
        The scene's heat partition.
    wheel, rail : Material
        Their ``effusivity`` [W s^0.5 m^-2 K^-1] for Blok's rule.
    body_speed : (float, float)
        Surface speeds of wheel and rail [m/s] (both the rolling speed for a given source).
    level : int
        Grid level k [1].
    cells : int, optional
        Cells along 2a at level 0 [1].
    scene_name : str, optional
        For messages.
    """
    hs = heat_source
    if hs.semi_axes is not None:
        a, b = hs.semi_axes
    else:
        a, b = hs.half_width, None
    try:
        grid = surface_grid(a, b, level, cells or BASE_CELLS)
    except Refused as exc:  # over the cell budget: name the scene
        raise Refused(f"scene {scene_name!r}, given heat source: {exc}", kind=exc.kind) from None
    q = hs.flux * cell_average(grid, hs.shape, a, b)
    v_w, v_r = body_speed
    eps = scene_partition(partition, wheel, rail, v_w, v_r, scene_name=scene_name)
    return HeatSource(grid=grid, power_density=q, heat_partition=eps, body_speed=(v_w, v_r),
                      frictional_power=hs.flux * exact_total(hs.shape, a, b), shape=hs.shape, peak_flux=hs.flux,
                      diagnostics=dict(CLOSED_FORM))


class GivenHeat(HeatSourceModel):
    """The scene's own heat source (paper section 6.4); run automatically when a scene gives one."""

    name = "given"
    exact_reference = "given-source"
    description = "heat source given by the scene (uniform or Hertz-shaped flux on an ellipse or band)"
    capabilities = Capabilities(sources=frozenset({"given"}),
                                provides=frozenset({"heat_flux", "frictional_power", "heat_partition"}))
    options = {"cells": Option(BASE_CELLS, "cells along 2a at level 0", minimum=1)}

    def supports(self, scene, level):
        if scene.heat_source is None:
            return "model 'given' needs a scene with a heat_source table"
        return None

    def compute_source(self, scene, patch, level, options):
        return given_heat_source(scene.heat_source, scene.partition, scene.wheel, scene.rail,
                                 body_speeds(scene.speed, scene.sliding_speed, scene.tangential),
                                 level, options.get("cells"), scene_name=scene.name)
