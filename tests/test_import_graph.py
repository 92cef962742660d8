"""Core's import graph (read with :mod:`ast`, function-level imports included): no circle; the layers
import one way (docs/DESIGN.md, lowest first: contract -> references, physics -> input, models -> solving ->
output -> analysis -> report -> run -> cli/testing; a module imports its own layer and lower ones); physics
imports only the contract; the contract imports nothing of railtherm outside itself; the output folder has
one owner (:mod:`railtherm.output.store`); the report reads only through the store; nothing but the cli and
the kit imports the runner; plugins import only the public API (tests/test_physics.py)."""
from functools import cache
from pathlib import Path

import pytest

from import_graphs import cycles, import_graph as _graph

import railtherm

CORE = Path(railtherm.__file__).parent


#: rank of each layer, lowest first (docs/DESIGN.md, "Layout"): a module imports its own layer and layers of
#: lower rank, never a sibling of its rank (so physics imports only the contract)
RANKS = {"contract": 0, "_version": 0, "references": 1, "physics": 1, "input": 2, "models": 2, "solving": 3,
         "output": 4, "analysis": 5, "report": 6, "run": 7, "top": 8}
LAYERS = tuple(RANKS)
#: the flat module paths of 0.1 (removed: each concept has one home in its layer)
OLD_PATHS = {f"railtherm.{n}" for n in ("errors", "grid", "hookspec", "stages", "schema", "options", "scene", "study",
                                        "materials", "store", "plugins", "pipeline", "metrics", "results",
                                        "reference_curves", "analytic", "runner", "executors", "timelimit")}


def layer(mod: str) -> str:
    parts = mod.split(".")
    if len(parts) == 1 or parts[1] in ("cli", "testing"):
        return "top"
    return parts[1]


@cache
def import_graph() -> dict[str, set[str]]:
    """Core module -> core modules it imports (read once per session; the tests only read it)."""
    return _graph(CORE.parent, "railtherm")



def test_graph_sees_function_level_imports():
    graph = import_graph()
    runner = graph["railtherm.run.runner"]
    assert "railtherm.output.store" in runner              # module level
    assert "railtherm.run.executors" in runner             # inside run_tasks
    assert "railtherm.report" in runner                    # inside run_study


def test_every_core_module_is_in_a_layer():
    assert {layer(m) for m in import_graph()} <= set(LAYERS)


def test_core_has_no_import_cycle():
    assert cycles(import_graph()) == []


def _edges_breaking_the_layers(graph) -> list[str]:
    """Edges ``a -> b`` of ``graph`` where b is in another layer than a whose rank is not below a's."""
    return sorted(f"{m} -> {d}" for m, deps in graph.items() for d in deps
                  if layer(d) != layer(m) and RANKS[layer(d)] >= RANKS[layer(m)])


def test_the_layer_check_can_fail():
    graph = {"railtherm.solving.a": {"railtherm.output.store"}, "railtherm.physics.b": {"railtherm.references.c"},
             "railtherm.output.store": {"railtherm.contract.grid"}, "railtherm.references.c": set(),
             "railtherm.models.m": {"railtherm.input.scene"}}
    assert _edges_breaking_the_layers(graph) == ["railtherm.models.m -> railtherm.input.scene",
                                                 "railtherm.physics.b -> railtherm.references.c",
                                                 "railtherm.solving.a -> railtherm.output.store"]


def test_layers_import_one_way():
    bad = _edges_breaking_the_layers(import_graph())
    assert bad == [], bad


def test_contract_imports_nothing_of_railtherm_outside_it():
    """What a plugin implements stands alone: capability enforcement and physics live above it."""
    graph = import_graph()
    contract = [m for m in graph if layer(m) == "contract"]
    assert "railtherm.contract.stages" in contract and "railtherm.contract.results" in contract
    outside = sorted(f"{m} -> {d}" for m in contract for d in graph[m] if layer(d) != "contract")
    assert outside == [], outside


def test_no_alias_modules():
    """No flat 0.1 path is importable and no core or plugin module replaces itself in sys.modules."""
    import importlib
    for old in sorted(OLD_PATHS):
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(old)
    roots = [CORE] + sorted(p for p in (CORE.parent.parent / "plugins").iterdir() if p.is_dir())
    aliases = [str(f) for r in roots for f in r.rglob("*.py") if "sys.modules[__name__]" in f.read_text()]
    assert aliases == []


def test_report_reads_only_through_the_store():
    graph = import_graph()
    outside = {d for m, deps in graph.items() if m.startswith("railtherm.report") for d in deps
               if not d.startswith("railtherm.report")}
    # the store (the output folder), the study file that study.json names and the scorecard rule's numbers
    # (the report applies the rule to metrics written without verdicts); no runner, executors, metrics,
    # physics or reference computations
    assert outside <= {"railtherm.output.store", "railtherm.input.study", "railtherm.contract.verdict_rules"}, outside


def test_store_and_time_limits_import_nothing_above_them():
    graph = import_graph()
    # the store reads the result schema (variables, the sweep attribute, the fields of several patches), nothing more
    assert graph["railtherm.output.store"] <= {"railtherm.contract.schema", "railtherm.contract.patch_grid",
                                               "railtherm.output.zarr_store"}, \
        graph["railtherm.output.store"]
    assert graph["railtherm.run.timelimit"] == set()
    for mod, deps in graph.items():
        if layer(mod) != "top" and mod != "railtherm.run.runner":
            assert "railtherm.run.runner" not in deps, mod


def test_importing_railtherm_and_its_kit_loads_no_numerical_library():
    """``import railtherm.testing`` (a pytest plugin, loaded by every pytest run) loads no numba, scipy,
    xarray or matplotlib: a fresh interpreter shows what the import itself pulls in."""
    import subprocess
    import sys
    code = ("import sys, railtherm, railtherm.testing; "
            "print(sorted(m for m in ('numba', 'scipy', 'xarray', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
