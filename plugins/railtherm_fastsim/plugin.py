"""Hook implementations of the fastsim plugin (registration only; the models do the work).

Method ``fastsim-fdm`` names the temperature model ``fdm`` of plugin ``fdm`` (``railtherm_fdm``); the plugin
host resolves model names across plugins, so a host needs both plugins to run the method.
"""
from __future__ import annotations

from railtherm import Method, hookimpl

from .tangential import FastsimTangential
from .wheelset_normal import WheelsetNormal


@hookimpl
def railtherm_register_models():
    """The tangential model ``fastsim`` and the normal model ``wheelset`` (the temperature model ``fdm`` that
    method ``fastsim-fdm`` names is plugin ``fdm``'s)."""
    return [FastsimTangential, WheelsetNormal]


@hookimpl
def railtherm_register_methods():
    """Method ``fastsim-fdm``: Hertz patch (or a wheelset's) -> FASTSIM tractions -> core's frictional heat
    -p.s -> finite-difference block (3-D for an ellipse, 2-D for a line contact)."""
    return [Method("fastsim-fdm", {"normal": ("wheelset", "hertz"), "tangential": ("fastsim",),
                                   "heat_source": ("frictional",), "temperature": ("fdm",)},
                   description="Kalker's FASTSIM power density (seed 6.2) and the finite-difference "
                               "rail block (seed 6.3; 3-D, or 2-D for line contacts)",
                   default_cells=16,
                   orders={
                       # FASTSIM: the traction has a kink at the slip onset of every strip, located to within a
                       # cell: first order (tests/test_fastsim.py measures 1.0-1.8 for the creep force, 0.85 for
                       # the local power, whose error is the last slip cell of each strip)
                       "creep_force_x": 1.0,
                       "frictional_power": 1.0,
                       # FDM: the moving-frame block uses exponential (upwind-like) fluxes along x at cell
                       # Péclet numbers >> 2 and the transient schemes are first order in time: first order for
                       # the surface field, its maximum and its patch mean (a staircase on an ellipse, O(h))
                       "max_surface_temperature": 1.0,
                       "mean_contact_temperature": 1.0,
                       "surface_temperature_l2": 1.0,
                   })]
