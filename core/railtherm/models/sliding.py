"""Core heat-source models: "full-sliding" (mu p v_s on a Hertz patch) and "given" (scene.heat_source)."""
from __future__ import annotations

import numpy as np

from ..errors import Refused
from ..grid import BASE_CELLS, surface_grid
from ..stages import Capabilities, HeatSource, HeatSourceModel, Option
from ..physics.averaging import cell_average, exact_total
from ..physics.kinematics import body_speeds
from ..physics.partition import scene_partition


#: the verdict keys of a closed-form stage (docs/verdicts.md): converged, no iterations, no residual
CLOSED_FORM = {"converged": True, "iterations": 0, "residual": 0.0}


class FullSlidingHeat(HeatSourceModel):
    """Full sliding: the whole patch slips at v_s, power density q = mu p v_s [W/m^2] (seed eq. 37).

    The wheel surface moves at v_w = V + v_s relative to the contact, the rail at v_r = V
    (seed eqs. 32-33); the partition is the scene's number or the equal-temperature fraction.
    ``frictional_power`` is the exact mu v_s N; the grid integral of the cell-averaged density
    equals it to round-off, which the runner's heat-balance check confirms.
    """

    name = "full-sliding"
    exact_reference = "full-sliding"
    description = "full sliding heat source mu p v_s, split by the scene's heat partition"
    capabilities = Capabilities(tangential=frozenset({"full-sliding"}), sources=frozenset({"computed"}),
                                provides=frozenset({"heat_flux", "frictional_power", "heat_partition", "traction_x",
                                                    "slip_velocity_x", "stick", "creep_force_x"}))

    def compute_source(self, scene, patch, level, options):
        vs = scene.sliding_speed
        v_w, v_r = body_speeds(scene)
        q = scene.friction * vs * patch.pressure
        eps = scene_partition(scene, v_w, v_r)
        mu_p = scene.friction * patch.pressure
        # material flows in -x: the wheel surface moves at -(V + v_s), the rail at -V, so the wheel
        # slips at -v_s relative to the rail and friction pushes it forward (+x) for v_s > 0
        patch = patch.with_tangential(
            traction_x=np.sign(vs) * mu_p, slip_velocity_x=np.where(patch.pressure > 0, -vs, 0.0),
            stick=np.where(patch.pressure > 0, 0.0, np.nan),
            creep_force_x=np.sign(vs) * scene.friction * patch.normal_force)
        power = scene.friction * vs * patch.normal_force
        # closed form: converged, no iterations, no residual (docs/verdicts.md)
        return HeatSource(grid=patch.grid, power_density=q, heat_partition=eps, body_speed=(v_w, v_r),
                          frictional_power=power, patch=patch, diagnostics=dict(CLOSED_FORM))


def given_heat_source(scene, level: int, cells: int | None = None) -> HeatSource:
    """The heat source a scene gives (``heat_source = { flux, shape, semi_axes | half_width }``).

    Both bodies move at the scene's speed; the partition is the scene's number or the
    equal-temperature fraction. ``flux`` is the uniform value, or the peak for ``shape = "hertz"``.
    """
    hs = scene.heat_source
    if hs.semi_axes is not None:
        a, b = hs.semi_axes
    else:
        a, b = hs.half_width, None
    try:
        grid = surface_grid(a, b, level, cells or BASE_CELLS)
    except Refused as exc:  # over the cell budget: name the scene
        raise Refused(f"scene {scene.name!r}, given heat source: {exc}", kind=exc.kind) from None
    q = hs.flux * cell_average(grid, hs.shape, a, b)
    v_w, v_r = body_speeds(scene)
    eps = scene_partition(scene, v_w, v_r)
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
        return given_heat_source(scene, level, options.get("cells"))
