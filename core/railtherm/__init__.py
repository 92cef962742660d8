"""railtherm: compare numerical methods for thermoelastic wheel-rail rolling contact with friction.

Public API
----------
load_study, solve, run_study, methods, open_results, SceneError, Refused, hookimpl, and the stage
interfaces (ContactModel, HeatSourceModel, TemperatureModel, CoupledModel, Method, ...).
"""
from __future__ import annotations

__version__ = "0.2.0"

from .errors import PluginError, Refused, SceneError, SolverError
from .grid import SurfaceGrid, surface_grid
from .hookspec import hookimpl
from .materials import Material
from .physics import combined_elastic, equal_temperature_partition, scene_partition
from .stages import (BODIES, STAGES, BodyTemperature, Capabilities, ContactModel, ContactPatch, CoupledModel,
                     HeatSource, HeatSourceModel, Method, NormalContactModel, Option, StageModel,
                     TangentialContactModel, TemperatureField, TemperatureModel, Upstream)

_LAZY = {
    "Scene": "scene", "load_scene": "scene",
    "Study": "study", "load_study": "study",
    "solve": "pipeline", "given_heat_source": "pipeline",
    "methods": "plugins", "get_host": "plugins",
    "run_study": "runner",
    "open_results": "results",
}


def __getattr__(name):  # lazy: keep `railtherm validate` / `methods` fast
    if name in _LAZY:
        import importlib
        mod = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(mod, name)
    raise AttributeError(f"module 'railtherm' has no attribute {name!r}")


__all__ = ["__version__", "PluginError", "Refused", "SceneError", "SolverError", "SurfaceGrid", "surface_grid",
           "hookimpl", "Material", "combined_elastic", "equal_temperature_partition", "scene_partition", "BODIES", "STAGES", "Capabilities", "ContactModel", "ContactPatch",
           "CoupledModel", "HeatSource", "HeatSourceModel", "Method", "NormalContactModel", "Option", "StageModel",
           "TangentialContactModel", "Upstream",
           "TemperatureField", "BodyTemperature", "TemperatureModel", *_LAZY]
