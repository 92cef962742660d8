"""railtherm.physics: the shared physics of wheel-rail contact, written once.

Plugins and core use these functions instead of keeping their own copies. Everything is pure
(numbers in, numbers out; a "scene" is any object with the study vocabulary's attributes), in SI
units, and importing this package needs only numpy.

Contact patch (:mod:`railtherm.physics.hertz`)
    hertz_geometry(scene) -> (a, b, p0, N)
        Semi-axes [m], peak pressure [Pa] and normal force [N] of a scene's Hertz patch.
    hertz_patch(scene, level, cells) -> ContactPatch
        The scene's Hertz patch with cell-averaged pressure on the surface grid of a level.
    hertz_pressure_grid(a, b, p0, level, cells) -> (grid, pressure)
        Surface grid and cell-averaged Hertz pressure [Pa] for given semi-axes.
    rescale_hertz_patch(N, N_ref, a_ref, b_ref, scaling) -> (a, b, p0)
        The patch at another normal force (a, b ~ N^(1/3) for fixed curvatures, or fixed).
    scene_semi_axis(scene) -> a or None
        Semi-axis along rolling [m] known before any stage runs.
Cell averaging (:mod:`railtherm.physics.averaging`)
    cell_average(grid, shape, a, b), exact_total(shape, a, b)
        Exact cell averages and totals of the unit Hertz / uniform distributions.
    nodal_cell_average(x_nodes, values, edges)
        Cell averages of a piecewise-linear nodal field.
Elastic constants (:mod:`railtherm.physics.elastic`)
    combined_elastic(wheel, rail) -> (G, nu)
        Kalker's combined shear modulus [Pa] and Poisson's ratio [1].
    contact_modulus(wheel, rail) -> E*
        Hertz's plane-strain contact modulus [Pa].
Kinematics (:mod:`railtherm.physics.kinematics`)
    body_speeds(scene) -> (v_wheel, v_rail)
    creep_speeds(V, xi) -> (V (1 - xi), V)
        Surface speeds through the patch [m/s].
Heat partition (:mod:`railtherm.physics.partition`)
    equal_temperature_partition(wheel, rail, v_wheel, v_rail) -> eps
        Blok's equal-temperature fraction into the wheel [1]; robust to zero and negative speeds.
    scene_partition(scene, v_wheel, v_rail) -> eps
        The scene's number or the equal-temperature fraction.
Thermal scales (:mod:`railtherm.physics.scales`)
    thermal_scales(a, V, kappa) -> ThermalScales(peclet, thermal_depth, contact_time, wake_length)
        Pe = V a/(2 kappa) [1], delta = sqrt(2 kappa a/V) [m], t_c = 2a/V [s], ell = 2 kappa/V [m].
    peclet_number(V, a, kappa) -> Pe
Graded edges (:mod:`railtherm.physics.grading`)
    geometric_edges(length, first, ratio, level)
        Geometrically graded cell edges, nested by refinement level.
Thermal trace (:mod:`railtherm.physics.thermal_trace`)
    thermal_trace(x, z, T, V, threshold) -> Trace
        Peak temperature, cooling rate, time above a threshold per depth and the heated depth of a
        material point on the centre line (NaN where the field is too short).
    with_thermal_trace(field, scene, source) -> TemperatureField
        The same for both bodies of a temperature result (one implementation for every method).
    field_grid(grid, scene), extended_grid(grid, behind), embed_field(field, grid, target)
        The grid reaching ``field.behind`` beyond the trailing edge, and a patch field put on it.
Pass histories (:mod:`railtherm.physics.pass_history`)
    pass_peaks_and_residual(time, history, count, interval) -> (peak, residual)
        Per-pass peak rise and the rise at the next pass's arrival [K] of a sampled history.
    pass_time_above(time, history, count, interval, rise) -> time above [s] per pass.
    superposition_limits(scene, model) -> why one pass's response cannot be superposed, or None.
Lumped wheel (:mod:`railtherm.physics.lumped_wheel`)
    lumped_wheel(eps P, theta_mean, ...) -> LumpedWheel
        Ertz & Knothe's long-term wheel temperature with the documented convective area
        (:data:`CONVECTIVE_AREA` = "wheel"); conduction_conductance, convective_area.

References
----------
.. [1] K.L. Johnson, Contact Mechanics, Cambridge University Press, 1985. doi:10.1017/CBO9781139171731
.. [2] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
   temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
.. [3] J.J. Kalker, Three-dimensional elastic bodies in rolling contact, Kluwer 1990.
   doi:10.1007/978-94-015-7889-9
"""
from __future__ import annotations

from .averaging import cell_average, exact_total, nodal_cell_average
from .elastic import combined_elastic, contact_modulus
from .grading import geometric_edges
from .hertz import hertz_geometry, hertz_patch, hertz_pressure_grid, rescale_hertz_patch, scene_semi_axis
from .kinematics import body_speeds, creep_speeds
from .lumped_wheel import (CONVECTIVE_AREA, ELLIPSE_SQRT_WIDTH, LumpedWheel, conduction_conductance,
                           convective_area, lumped_wheel)
from .partition import equal_temperature_partition, scene_partition
from .pass_history import pass_peaks_and_residual, pass_time_above, superposition_limits
from .scales import ThermalScales, peclet_number, thermal_scales
from .thermal_trace import Trace, embed_field, extended_grid, field_grid, thermal_trace, with_thermal_trace

__all__ = ["hertz_geometry", "hertz_patch", "hertz_pressure_grid", "rescale_hertz_patch", "scene_semi_axis",
           "cell_average", "exact_total", "nodal_cell_average", "combined_elastic", "contact_modulus",
           "body_speeds", "creep_speeds", "equal_temperature_partition", "scene_partition", "ThermalScales", "thermal_scales",
           "peclet_number", "geometric_edges", "CONVECTIVE_AREA", "ELLIPSE_SQRT_WIDTH", "LumpedWheel",
           "conduction_conductance", "convective_area", "lumped_wheel", "Trace", "thermal_trace", "with_thermal_trace", "field_grid", "extended_grid", "embed_field",
           "pass_peaks_and_residual", "pass_time_above", "superposition_limits"]
