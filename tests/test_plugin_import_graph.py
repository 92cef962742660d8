"""Each plugin package's import graph (read with :mod:`ast`, function-level imports included) has no
circle, and no plugin module is over 700 lines (issue 12, "checked by")."""
import ast
from pathlib import Path

import pytest

PLUGINS = Path(__file__).resolve().parents[1] / "plugins"
PACKAGES = sorted(p.name for p in PLUGINS.iterdir() if (p / "__init__.py").is_file())
MAX_LINES = 700


def _module_name(package: str, path: Path) -> str:
    parts = [package, *path.relative_to(PLUGINS / package).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _type_checking_only(tree) -> set:
    """Nodes under ``if TYPE_CHECKING:`` (never executed at run time)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                out.update(id(n) for n in ast.walk(sub))
    return out


def import_graph(package: str) -> dict[str, set[str]]:
    """Module -> modules of the same package it imports (module level and inside functions)."""
    files = {_module_name(package, p): p for p in (PLUGINS / package).rglob("*.py")}
    graph = {}
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skip = _type_checking_only(tree)
        parent = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = parent.split(".")[:len(parent.split(".")) - node.level + 1]
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


def test_graph_sees_relative_and_function_level_imports():
    graph = import_graph("railtherm_fdm")
    assert "railtherm_fdm.kernels" in graph["railtherm_fdm.block3d"]          # from . import kernels as K
    assert "railtherm_fdm.layout" in graph["railtherm_fdm.block2d"]           # from .layout import ...
    assert "railtherm_fdm.block3d" in graph["railtherm_fdm.model"]            # inside a method
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == [["a", "b", "c"]]


@pytest.mark.parametrize("package", PACKAGES)
def test_plugin_has_no_import_cycle(package):
    assert cycles(import_graph(package)) == []


def test_fdm_shares_its_pieces_instead_of_importing_privately():
    """The 2-D block imports the shared modules, not the 3-D block (which once exported five private
    names to it), and nothing imports a private name of another module of the package."""
    graph = import_graph("railtherm_fdm")
    assert "railtherm_fdm.block3d" not in graph["railtherm_fdm.block2d"]
    for path in (PLUGINS / "railtherm_fdm").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level:
                private = [a.name for a in node.names if a.name.startswith("_")]
                assert not private, f"{path.name} imports private names {private}"


@pytest.mark.parametrize("package", PACKAGES)
def test_no_plugin_module_over_the_line_limit(package):
    long = {p.name: n for p in (PLUGINS / package).rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"{package}: modules over {MAX_LINES} lines: {long}"
