"""Hook implementations of the fastsim plugin (registration only; the models do the work)."""
from __future__ import annotations

from railtherm import Method, hookimpl

from .fastsim_model import FastsimHeatSource
from .fdm_model import FDMTemperature


@hookimpl
def railtherm_register_models():
    """The heat-source model ``fastsim`` and the temperature model ``fdm``."""
    return [FastsimHeatSource, FDMTemperature]


@hookimpl
def railtherm_register_methods():
    """Method ``fastsim-fdm``: Hertz patch -> FASTSIM power density -> finite-difference block
    (3-D for an ellipse, 2-D for a line contact)."""
    return [Method("fastsim-fdm", {"contact": ("hertz",), "heat_source": ("fastsim",), "temperature": ("fdm",)},
                   description="Kalker's FASTSIM power density (seed 6.2) and the finite-difference "
                               "rail block (seed 6.3; 3-D, or 2-D for line contacts)",
                   default_cells=16)]
