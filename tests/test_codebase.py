"""Rules of the code base: small modules, one home for each public function, short module docstrings.

* no module of core or of a built-in plugin is longer than 700 lines;
* no public module-level function is defined in two plugins (shared machinery belongs in core:
  ``railtherm.physics``, ``railtherm.references``); hook implementations (``railtherm_*``) are the
  contract every plugin implements and are exempt;
* no function is over 80 lines without a reason; code text names none of this project's issues;
* no module docstring is over 15 lines (long derivations belong in the function they describe or docs/);
* in the modules of :data:`SCENE_PARTS_MODULES`, only the stage hooks take the scene.
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
    """No function of core or of a built-in plugin is over 80 lines unless a ``#`` comment directly above it
    (above its decorators) says why it is long."""
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


MAX_MODULE_DOCSTRING_LINES = 15
# owned by concurrent work; to trim: module docstrings over 15 lines in files others are editing. The list
# only shrinks: a file trimmed to 15 lines or fewer must leave it (the test below fails until it does).
LONG_MODULE_DOCSTRINGS_TO_TRIM: frozenset[str] = frozenset()


def _module_docstring_lines(path: Path) -> int:
    """Lines of the text of ``path``'s module docstring (0 without one)."""
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    return len(doc.splitlines()) if doc else 0


def test_module_docstrings_at_most_15_lines():
    """A module docstring says what the module holds, its key equations and choices and why, and its
    references in at most 15 lines; derivations go in the docstring of the function they belong to or
    in docs/. The files of :data:`LONG_MODULE_DOCSTRINGS_TO_TRIM` are exempt until trimmed, and each of
    them must still exceed (so the list stays exact and cannot grow silently)."""
    counts = {str(p.relative_to(ROOT)): _module_docstring_lines(p) for p in SOURCES}
    long = sorted(f"{rel} ({n} lines)" for rel, n in counts.items()
                  if n > MAX_MODULE_DOCSTRING_LINES and rel not in LONG_MODULE_DOCSTRINGS_TO_TRIM)
    assert long == [], ("module docstrings over 15 lines (move derivations into the function they belong "
                        "to or into docs/):\n  " + "\n  ".join(long))
    trimmed = sorted(rel for rel in LONG_MODULE_DOCSTRINGS_TO_TRIM
                     if counts.get(rel, 0) <= MAX_MODULE_DOCSTRING_LINES)
    assert trimmed == [], f"remove from LONG_MODULE_DOCSTRINGS_TO_TRIM (trimmed or gone): {trimmed}"


#: the stage hooks of the plugin API (docs/DESIGN.md): they take the scene and hand its parts on
STAGE_HOOKS = frozenset({"supports", "compute_patch", "compute_tangential", "compute_source", "compute_temperature",
                         "compute"})

#: modules whose functions below the stage hooks take the scene's parts (materials, heat partition, friction
#: law, creepage, ...) instead of the Scene, so that each function's inputs show in its signature
SCENE_PARTS_MODULES = ("core/railtherm/physics/hertz.py", "core/railtherm/physics/kinematics.py",
                       "core/railtherm/physics/partition.py", "core/railtherm/physics/friction/contact_temperature.py",
                       "core/railtherm/physics/thermal_trace.py",
                       "core/railtherm/models/hertz.py", "core/railtherm/models/sliding.py",
                       "core/railtherm/models/core_plugin.py", "core/railtherm/models/shapes.py",
                       "core/railtherm/solving/friction_loop.py", "plugins/railtherm_fastsim/*.py",
                       "plugins/railtherm_green/model.py", "plugins/railtherm_green/steady.py",
                       "plugins/railtherm_green/kernel.py", "plugins/railtherm_green/validity.py",
                       "plugins/railtherm_fem/condense.py", "plugins/railtherm_fem/contact.py",
                       "plugins/railtherm_fem/coupled.py", "plugins/railtherm_fem/elastic.py",
                       "plugins/railtherm_fem/friction.py", "plugins/railtherm_fem/mesh.py",
                       "plugins/railtherm_fem/model.py", "plugins/railtherm_fem/plugin.py",
                       "plugins/railtherm_fem/thermal.py", "plugins/railtherm_kalker/friction_laws.py")


def test_functions_below_the_stage_hooks_take_the_scene_s_parts():
    """In :data:`SCENE_PARTS_MODULES` only the stage hooks have a parameter ``scene``; every other function
    takes the parts it reads (CONTACT's ``calc_temp(ic, mater, kin, cgrid, outpt)`` is the model)."""
    paths = [p for pattern in SCENE_PARTS_MODULES for p in sorted(ROOT.glob(pattern))]
    assert len(paths) >= len(SCENE_PARTS_MODULES)
    takes = []
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name not in STAGE_HOOKS:
                args = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
                if any(a.arg == "scene" for a in args):
                    takes.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}")
    assert takes == [], "functions below the stage hooks that take the whole scene:\n  " + "\n  ".join(takes)
