"""Core's import graph (read with :mod:`ast`, function-level imports included): no circle; the layers
import one way (cli/testing -> run -> report -> analysis -> solve -> output -> input -> models ->
physics -> contract -> references); the output folder has one owner (:mod:`railtherm.output.store`)
that imports nothing above it; the report reads only through the store; nothing but the cli and the
kit imports the runner; plugins import only the public API (tests/test_physics.py)."""
import ast
from pathlib import Path

import railtherm

CORE = Path(railtherm.__file__).parent


#: bottom to top; a module imports only its own layer and layers below it
LAYERS = ("_version", "references", "contract", "physics", "models", "input", "output", "solving", "analysis",
          "report", "run", "top")
#: the one upward edge: the contract's capability checks (StageModel.supports) use the Péclet number and
#: the body speeds, from physics modules that import nothing of railtherm themselves
EXCEPTIONS = {("railtherm.contract.stages", "railtherm.physics.kinematics"),
              ("railtherm.contract.stages", "railtherm.physics.scales")}
#: the flat module paths of 0.1, kept for one release as aliases of the moved modules
SHIMS = {f"railtherm.{n}" for n in ("errors", "grid", "hookspec", "stages", "schema", "options", "scene", "study",
                                    "materials", "store", "plugins", "pipeline", "metrics", "results",
                                    "reference_curves", "analytic", "runner", "executors", "timelimit")}


def layer(mod: str) -> str:
    parts = mod.split(".")
    if len(parts) == 1 or parts[1] in ("cli", "testing"):
        return "top"
    return parts[1]


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(CORE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _type_checking_only(tree) -> set:
    """Import nodes under ``if TYPE_CHECKING:`` (never executed at run time)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                out.update(id(n) for n in ast.walk(sub))
    return out


def import_graph() -> dict[str, set[str]]:
    """Module -> railtherm modules it imports (module level and inside functions)."""
    files = {_module_name(p): p for p in CORE.rglob("*.py") if _module_name(p) not in SHIMS}
    graph = {}
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skip = _type_checking_only(tree)
        package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[:len(package.split(".")) - node.level + 1]
                    base = ".".join(base + ([node.module] if node.module else []))
                else:
                    base = node.module or ""
                # ``from pkg import sub`` imports the submodule ``pkg.sub``; else a name of ``pkg``
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]
            else:
                continue
            deps.update(n for n in names if n in files and n != mod)
        graph[mod] = deps
    return graph


def cycles(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


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


def test_layers_import_one_way():
    graph = import_graph()
    rank = {name: i for i, name in enumerate(LAYERS)}
    upward = sorted(f"{m} -> {d}" for m, deps in graph.items() for d in deps
                    if rank[layer(d)] > rank[layer(m)] and (m, d) not in EXCEPTIONS)
    assert upward == [], upward


def test_the_exceptions_import_nothing_of_railtherm():
    graph = import_graph()
    for _, target in EXCEPTIONS:
        assert graph[target] == set(), target


def test_shims_alias_the_moved_modules():
    import importlib
    for old in sorted(SHIMS):
        mod = importlib.import_module(old)
        assert mod.__name__ != old and mod.__name__.endswith(old.rsplit(".", 1)[1]), old
        assert importlib.import_module(mod.__name__) is mod


def test_report_reads_only_through_the_store():
    graph = import_graph()
    outside = {d for m, deps in graph.items() if m.startswith("railtherm.report") for d in deps
               if not d.startswith("railtherm.report")}
    # the store (the output folder) and the study file that study.json names; no runner, executors,
    # metrics, physics or reference computations
    assert outside <= {"railtherm.output.store", "railtherm.input.study"}, outside


def test_store_and_time_limits_import_nothing_above_them():
    graph = import_graph()
    # the store decodes railtherm 0.1's sweep attributes against the scene vocabulary, nothing more
    assert graph["railtherm.output.store"] <= {"railtherm.input.scene"}, graph["railtherm.output.store"]
    assert graph["railtherm.run.timelimit"] == set()
    for mod, deps in graph.items():
        if layer(mod) != "top" and mod != "railtherm.run.runner":
            assert "railtherm.run.runner" not in deps, mod
