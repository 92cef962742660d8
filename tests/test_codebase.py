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


MAX_FUNCTION_LINES = 80


def _long_functions(path: Path):
    """(name, first line, length) of every function (methods and nested ones too) of ``path`` longer than
    :data:`MAX_FUNCTION_LINES` (from its ``def`` to its last line, docstring included) whose first line
    (its first decorator, else its ``def``) is not directly below a ``#`` comment giving the reason."""
    lines = path.read_text(encoding="utf-8").splitlines()
    for node in ast.walk(ast.parse("\n".join(lines))):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        length = node.end_lineno - node.lineno + 1
        if length <= MAX_FUNCTION_LINES:
            continue
        first = min([node.lineno] + [d.lineno for d in node.decorator_list])
        above = lines[first - 2].strip() if first >= 2 else ""
        if not above.startswith("#"):
            yield node.name, first, length


def test_no_function_over_80_lines_without_a_reason():
    """Issue 25: no function of core or of a built-in plugin is over 80 lines unless a ``#`` comment directly
    above it (above its decorators) says why it is long."""
    long = [f"{path.relative_to(ROOT)}:{line} {name} ({n} lines)"
            for path in SOURCES for name, line, n in _long_functions(path)]
    assert long == [], ("functions over 80 lines without a '#' reason directly above them (split them, or "
                        "say why they are long):\n  " + "\n  ".join(long))


def test_code_text_does_not_narrate_this_project_s_issues():
    """Docstrings and comments say what the code does and why; which of this project's issues brought it is
    history, kept in git. (An upstream bug named with its tracker, e.g. "FiPy issue #1223", is a reason.)"""
    import re
    pattern = re.compile(r"\bissue \d+", re.IGNORECASE)
    found = [f"{p.relative_to(ROOT)}:{i}" for p in SOURCES
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if pattern.search(line)]
    assert found == [], found
