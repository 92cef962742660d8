"""Hook implementations of the "green" plugin (registration only; the work is in the model classes)."""
from __future__ import annotations

from railtherm import Method, hookimpl


@hookimpl
def railtherm_register_models():
    """The temperature model ``green``."""
    from .model import GreenTemperature
    return [GreenTemperature]


@hookimpl
def railtherm_register_methods():
    """Method ``green``: Hertz patch, full-sliding (or FASTSIM) heat source, 1-D Green temperatures."""
    return [Method("green", {"contact": ("hertz",), "heat_source": ("full-sliding", "fastsim"),
                             "temperature": ("green",)},
                   description="Ertz & Knothe (2002) analytic flash temperatures: Hertz patch, full-sliding or "
                               "FASTSIM heat, 1-D moving Green function strip by strip (Péclet >= 10)",
                   default_cells=32)]
