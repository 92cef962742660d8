"""Hook implementations of the "fipy" plugin (registration only; the work is in model.py)."""
from __future__ import annotations

from railtherm import Method, hookimpl


@hookimpl
def railtherm_register_models():
    from .model import FipyTemperature
    return [FipyTemperature]


@hookimpl
def railtherm_register_methods():
    return [Method("fipy", {"contact": ("hertz",), "heat_source": ("full-sliding", "fastsim"),
                            "temperature": ("fipy",)},
                   description="Hertz patch, full-sliding (or FASTSIM) heat, FiPy finite-volume temperatures "
                               "(steady moving frame 2-D/3-D; transient wheel heating)",
                   default_cells=16)]
