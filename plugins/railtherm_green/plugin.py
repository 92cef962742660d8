"""Hook implementations of the "green" plugin (registration only; the work is in the model classes)."""
from __future__ import annotations

from railtherm import Method, hookimpl

from .model import GreenTemperature


@hookimpl
def railtherm_register_models():
    """The temperature model ``green``."""
    return [GreenTemperature]


@hookimpl
def railtherm_register_methods():
    """Method ``green``: Hertz patch, full-sliding (or FASTSIM) heat source, 1-D Green temperatures."""
    return [Method("green", {"normal": ("wheelset", "hertz"), "tangential": ("full-sliding", "fastsim"),
                            "heat_source": ("frictional",),
                             "temperature": ("green",)},
                   description="Ertz & Knothe (2002) analytic flash temperatures: Hertz patch, full-sliding or "
                               "FASTSIM heat, 1-D moving Green function strip by strip (Péclet >= 10)",
                   default_cells=32,
                   orders={
                       # the strip quadrature of the one-sided 1/sqrt(x' - x) kernel with a piecewise-constant
                       # flux has a local error O(h^1.5) where the flux is smooth, i.e. where the maximum lies
                       # (model docstring; self-convergence on the E&K ellipse, levels 0-4 against 5: 1.4-1.8)
                       "max_surface_temperature": 1.5,
                       # the patch mean is over the cells whose centre lies inside the ellipse: the staircase
                       # misses an area O(h) of the ellipse (the fitted rate scatters around 1 from level to level)
                       "mean_contact_temperature": 1.0,
                   })]
