"""Each plugin package's import graph (read with :mod:`ast`, function-level imports included) has no
circle (the 700-line limit is tests/test_codebase.py's)."""
import ast
from pathlib import Path

import pytest
from import_graphs import cycles, import_graph as _graph

PLUGINS = Path(__file__).resolve().parents[1] / "plugins"
PACKAGES = sorted(p.name for p in PLUGINS.iterdir() if (p / "__init__.py").is_file())


def import_graph(package: str) -> dict[str, set[str]]:
    """Module -> modules of the same plugin package it imports."""
    return _graph(PLUGINS, package)


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
