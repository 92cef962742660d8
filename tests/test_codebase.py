"""Rules of the code base (issue 12): small modules, one home for each public function.

* no module of core or of a built-in plugin is longer than 700 lines;
* no public module-level function is defined in two plugins (shared machinery belongs in core:
  ``railtherm.physics``, ``railtherm.references``); hook implementations (``railtherm_*``) are the
  contract every plugin implements and are exempt.
"""
from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 700
SOURCES = sorted((ROOT / "core").rglob("*.py")) + sorted((ROOT / "plugins").rglob("*.py"))


@pytest.mark.parametrize("path", SOURCES, ids=[str(p.relative_to(ROOT)) for p in SOURCES])
def test_no_module_over_700_lines(path):
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, f"{path.relative_to(ROOT)} has {n} lines (> {MAX_LINES}): split it by what it holds"


def test_no_public_function_in_two_plugins():
    homes = defaultdict(set)
    for path in (ROOT / "plugins").rglob("*.py"):
        package = path.relative_to(ROOT / "plugins").parts[0]
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith(("_", "railtherm_")):
                homes[node.name].add(package)
    twice = {name: sorted(pkgs) for name, pkgs in homes.items() if len(pkgs) > 1}
    assert twice == {}, f"public functions defined in two plugins (move them to core): {twice}"
