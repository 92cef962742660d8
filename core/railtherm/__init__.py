"""railtherm: compare numerical methods for thermoelastic wheel-rail rolling contact with friction.

Public API: load_study, solve, run_study, methods, open_results, SceneError, Refused, hookimpl, the
stage interfaces of plugin API 2 (NormalContactModel, TangentialContactModel, HeatSourceModel,
TemperatureModel, CoupledModel, Method, ...), a scene's Hertz patch (hertz_geometry, hertz_patch) and
the section-stepping driver of pass histories (section_history, ImplicitSectionStepper, ...).

Packages, highest first (imports run one way, down; tests/test_import_graph.py checks it): ``cli`` and
``testing`` (command line, plugin conformance kit); ``run/`` (runner, executors, time limits);
``report/``; ``analysis/`` (exact values, metrics, reference curves); ``output/`` (the output folder's one
owner); ``solving/`` (plugin host, stage pipeline); ``input/`` (scenes, studies, materials) and ``models/``
(core's stage models); ``physics/`` (shared formulas) and ``references/`` (exact and published solutions);
``contract/`` (what a plugin implements). docs/DESIGN.md has the full table.

Plugins import ``railtherm`` (this module), ``railtherm.physics`` and ``railtherm.references`` only.
"""
from __future__ import annotations

import importlib

from ._version import __version__

from .contract.errors import PluginError, Refused, SceneError, SolverError
from .contract.grid import SurfaceGrid, surface_grid
from .contract.hookspec import hookimpl
from .input.materials import Material
from .physics import combined_elastic, equal_temperature_partition, scene_partition
from .contract.results import BODIES, BodyTemperature, ContactPatch, HeatSource, TemperatureField
from .contract.options import Option
from .contract.stages import (STAGES, CoupledModel, HeatSourceModel, Method, NormalContactModel, StageModel,
                              TangentialContactModel, TemperatureModel, Upstream)
from .contract.capabilities import Capabilities, asks_history
from .contract.transient import TransientHistory, TransientTemperatureField, with_history

_LAZY = {
    "Scene": "input.scene", "load_scene": "input.scene",
    "Study": "input.study", "load_study": "input.study",
    "solve": "solving.pipeline", "given_heat_source": "solving.pipeline",
    "methods": "solving.plugins", "get_host": "solving.plugins",
    "run_study": "run.runner",
    "open_results": "analysis.results",
    "hertz_geometry": "models.hertz", "hertz_patch": "models.hertz",
    **{name: "solving.section_stepping" for name in (
        "ImplicitSectionStepper", "heating_scheme", "histories_at_section", "section_history",
        "superposed_history", "theta_steps")},
}


def __getattr__(name):  # lazy: keep `railtherm validate` / `methods` fast
    if name in _LAZY:
        mod = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(mod, name)
    raise AttributeError(f"module 'railtherm' has no attribute {name!r}")


__all__ = ["__version__", "PluginError", "Refused", "SceneError", "SolverError", "SurfaceGrid", "surface_grid",
           "hookimpl", "Material", "combined_elastic", "equal_temperature_partition", "scene_partition", "BODIES", "STAGES", "Capabilities", "ContactPatch",
           "CoupledModel", "HeatSource", "HeatSourceModel", "Method", "NormalContactModel", "Option", "StageModel",
           "TangentialContactModel", "Upstream",
           "TemperatureField", "BodyTemperature", "TemperatureModel",
           "TransientHistory", "TransientTemperatureField", "with_history", "asks_history", *_LAZY]
