"""Registration of the "fem" coupled model and method (entry point ``railtherm.plugins: fem``)."""
from __future__ import annotations

from railtherm import Method, hookimpl


@hookimpl
def railtherm_register_models():
    # lazy: the model loads scikit-fem and builds its forms; plugin discovery (every `import railtherm`
    # session that lists the plugins) must not pay for that
    from .model import FemModel
    return [FemModel]


@hookimpl
def railtherm_register_methods():
    return [Method("fem", {"normal": ("fem",), "tangential": ("fem",), "heat_source": ("fem",), "temperature": ("fem",)},
                   description="2-D quasistatic thermoelastic FEM rolling contact (seed section 4)",
                   orders={
                       # P1 pressures on uniform surface nodes: the square-root edge of the pressure costs
                       # O(h) in L2 (int_0^h (sqrt(x))^2 dx ~ h^2 in the edge cells; O(h^2) inside); measured
                       # 1.3 (tests/test_fem_contact.py::test_hertz_mesh_convergence_rate)
                       "pressure_l2": 1.0,
                       # the stick-slip boundary is a kink of the traction located to within a node spacing
                       # (measured 1.3-2.2 on Carter's case, levels 0-3)
                       "creep_force_x": 1.0,
                       # not declared: max_pressure and semi_axis_a approach the finite strip's values, not
                       # Hertz's (1e-3 bias at 80 a x 40 a); the conduction is second order (BDF2 x P1, tests/
                       # test_fem_thermal.py) but the coupled heat source inherits the contact's first order
                   })]
