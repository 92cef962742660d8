"""railtherm.physics: the shared physics of wheel-rail contact, written once.

Plugins and core call these instead of keeping their own copies. Everything is pure (numbers in, numbers
out; a "scene" is any object with the study vocabulary's attributes), in SI units, and importing this
package needs only numpy (the thermal trace's compiled pass loads numba when first called).

Modules: :mod:`.hertz` (cell-averaged Hertz pressure of given semi-axes, rescaled to another load),
:mod:`.averaging` (exact cell averages of the Hertz and uniform distributions), :mod:`.elastic` (Kalker's
combined constants, Hertz's contact modulus), :mod:`.kinematics` (surface speeds), :mod:`.partition` (Blok's
equal-temperature heat partition), :mod:`.scales` (Peclet number, thermal depth, contact time),
:mod:`.grading` (graded cell edges), :mod:`.thermal_trace` (peak, cooling rate, time above and heated depth of
a material point), :mod:`.pass_history` (per-pass peaks of a history), :mod:`.lumped_wheel` (Ertz & Knothe's
long-term wheel temperature), :mod:`.friction` (friction laws and their iterations), :mod:`.profiles` and
:mod:`.contact_search` (wheel and rail profiles). Each function's docstring gives units and references.
"""
from __future__ import annotations

from .averaging import cell_average, exact_total, nodal_cell_average
from .elastic import combined_elastic, contact_modulus
from .grading import geometric_edges
from .hertz import hertz_pressure_grid, rescale_hertz_patch
from .kinematics import body_speeds, creep_speeds
from .lumped_wheel import (CONVECTIVE_AREA, ELLIPSE_SQRT_WIDTH, LumpedWheel, conduction_conductance,
                           convective_area, lumped_wheel)
from .partition import equal_temperature_partition, scene_partition
from .pass_history import pass_peaks_and_residual, pass_time_above, superposition_limits
from .scales import ThermalScales, peclet_number, thermal_scales
from .thermal_trace import Trace, embed_field, extended_grid, field_grid, thermal_trace, with_thermal_trace

__all__ = ["hertz_pressure_grid", "rescale_hertz_patch",
           "cell_average", "exact_total", "nodal_cell_average", "combined_elastic", "contact_modulus",
           "body_speeds", "creep_speeds", "equal_temperature_partition", "scene_partition", "ThermalScales", "thermal_scales",
           "peclet_number", "geometric_edges", "CONVECTIVE_AREA", "ELLIPSE_SQRT_WIDTH", "LumpedWheel",
           "conduction_conductance", "convective_area", "lumped_wheel", "Trace", "thermal_trace", "with_thermal_trace", "field_grid", "extended_grid", "embed_field",
           "pass_peaks_and_residual", "pass_time_above", "superposition_limits"]
