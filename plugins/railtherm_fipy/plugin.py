"""Hook implementations of the "fipy" plugin (registration only; the work is in model.py)."""
from __future__ import annotations

from railtherm import Method, hookimpl

from .model import FipyTemperature


@hookimpl
def railtherm_register_models():
    return [FipyTemperature]


@hookimpl
def railtherm_register_methods():
    return [Method("fipy", {"normal": ("wheelset", "hertz"), "tangential": ("full-sliding", "fastsim"),
                            "heat_source": ("frictional",),
                            "temperature": ("fipy",)},
                   description="Hertz patch, full-sliding (or FASTSIM) heat, FiPy finite-volume temperatures "
                               "(steady moving frame 2-D/3-D; transient wheel heating)",
                   default_cells=16,
                   orders={
                       # along the flow FiPy's power-law scheme is upwinding wherever the cell Péclet number
                       # exceeds ~2, which it does by orders of magnitude at rolling speeds (NOTES: cell Péclet in
                       # the hundreds): first order in dx for the surface field, its maximum and its mean (the
                       # mean also over a staircase of cells inside an ellipse, O(h))
                       "max_surface_temperature": 1.0,
                       "mean_contact_temperature": 1.0,
                       "surface_temperature_l2": 1.0,
                   })]
