"""Registration of the "fem" coupled model and method (entry point ``railtherm.plugins: fem``)."""
from __future__ import annotations

from railtherm import Method, hookimpl


@hookimpl
def railtherm_register_models():
    from .model import FemModel
    return [FemModel]


@hookimpl
def railtherm_register_methods():
    return [Method("fem", {"contact": ("fem",), "heat_source": ("fem",), "temperature": ("fem",)},
                   description="2-D quasistatic thermoelastic FEM rolling contact (seed section 4)")]
