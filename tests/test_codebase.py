"""Rules of the code base: small modules, one home for each public function, short module docstrings.

* no module of core or of a built-in plugin is longer than 700 lines;
* no public module-level function is defined in two plugins (shared machinery belongs in core:
  ``railtherm.physics``, ``railtherm.references``); hook implementations (``railtherm_*``) are the
  contract every plugin implements and are exempt;
* no function is over 80 lines without a reason; code text names none of this project's issues;
* no module docstring is over 15 lines (long derivations belong in the function they describe or docs/);
* in the modules of :data:`SCENE_PARTS_MODULES`, only the stage hooks take the scene (and functions that say
  why in a ``# whole scene:`` comment above them).
"""
from __future__ import annotations

import ast
import functools
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 700
SOURCES = sorted((ROOT / "core").rglob("*.py")) + sorted((ROOT / "plugins").rglob("*.py"))


@functools.lru_cache(maxsize=None)
def _text(path: Path) -> str:
    """The text of ``path``, read once per test process (a dozen rules read every module)."""
    return path.read_text(encoding="utf-8")


@functools.lru_cache(maxsize=None)
def _parse(path: Path) -> ast.Module:
    """The parse tree of ``path``, parsed once per test process; the rules only read it."""
    return ast.parse(_text(path))


#: modules of concurrent work over 700 lines, to split; the list only shrinks (an entry at or under the limit
#: fails until it leaves the list)
MODULES_TO_SPLIT: frozenset[str] = frozenset()


@pytest.mark.parametrize("path", SOURCES, ids=[str(p.relative_to(ROOT)) for p in SOURCES])
def test_no_module_over_700_lines(path):
    n = len(_text(path).splitlines())
    if str(path.relative_to(ROOT)) in MODULES_TO_SPLIT:
        assert n > MAX_LINES, f"remove {path.relative_to(ROOT)} from MODULES_TO_SPLIT ({n} lines)"
        return
    assert n <= MAX_LINES, f"{path.relative_to(ROOT)} has {n} lines (> {MAX_LINES}): split it by what it holds"


def test_no_public_function_in_two_plugins():
    homes = defaultdict(set)
    for path in (ROOT / "plugins").rglob("*.py"):
        package = path.relative_to(ROOT / "plugins").parts[0]
        for node in _parse(path).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith(("_", "railtherm_")):
                homes[node.name].add(package)
    twice = {name: sorted(pkgs) for name, pkgs in homes.items() if len(pkgs) > 1}
    assert twice == {}, f"public functions defined in two plugins (move them to core): {twice}"


MAX_FUNCTION_LINES = 80


def _long_functions(path: Path):
    """(name, first line, length) of every function (methods and nested ones too) of ``path`` longer than
    :data:`MAX_FUNCTION_LINES` (from its ``def`` to its last line, docstring included) whose first line
    (its first decorator, else its ``def``) is not directly below a ``#`` comment giving the reason."""
    lines = _text(path).splitlines()
    for node in ast.walk(_parse(path)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        length = node.end_lineno - node.lineno + 1
        if length <= MAX_FUNCTION_LINES:
            continue
        first = min([node.lineno] + [d.lineno for d in node.decorator_list])
        above = lines[first - 2].strip() if first >= 2 else ""
        if not above.startswith("#"):
            yield node.name, first, length


#: functions of concurrent work over 80 lines without a reason, as "path function"; the list only shrinks
LONG_FUNCTIONS_TO_SPLIT = frozenset()


def test_no_function_over_80_lines_without_a_reason(tmp_path):
    """No function of core or of a built-in plugin is over 80 lines unless a ``#`` comment directly above it
    (above its decorators) says why it is long."""
    probe = tmp_path / "probe.py"
    body = "".join(f"    x{i} = {i}\n" for i in range(80))
    probe.write_text(f"def long():\n{body}\n\n# one loop over shared state\ndef reasoned():\n{body}")
    assert [name for name, _, _ in _long_functions(probe)] == ["long"]
    found = {f"{path.relative_to(ROOT)} {name}": f"{path.relative_to(ROOT)}:{line} {name} ({n} lines)"
             for path in SOURCES for name, line, n in _long_functions(path)}
    long = sorted(v for k, v in found.items() if k not in LONG_FUNCTIONS_TO_SPLIT)
    assert long == [], ("functions over 80 lines without a '#' reason directly above them (split them, or "
                        "say why they are long):\n  " + "\n  ".join(long))
    assert sorted(LONG_FUNCTIONS_TO_SPLIT - set(found)) == [], "remove from LONG_FUNCTIONS_TO_SPLIT (split)"


#: test modules of concurrent work whose text still names this project's issues; the list only shrinks
ISSUE_NAMES_TO_REMOVE: frozenset[str] = frozenset()


def _issue_lines(path: Path) -> list[int]:
    """Lines of ``path`` that name an issue of this project ("issue 14", "Issue 3")."""
    import re
    pattern = re.compile(r"\bissue \d+", re.IGNORECASE)
    return [i for i, line in enumerate(_text(path).splitlines(), 1) if pattern.search(line)]


def test_code_text_does_not_narrate_this_project_s_issues(tmp_path):
    """Docstrings and comments of core, plugins, tests and the contract docs say what the code does and why;
    which of this project's issues brought it is history, kept in git. (An upstream bug named with its
    tracker, e.g. "FiPy issue #1223", is a reason.)"""
    probe = tmp_path / "probe.py"
    probe.write_text('"""Thermal trace."""\n# added for Issue 14\nx = 1  # see FiPy issue #1223\n')
    assert _issue_lines(probe) == [2]
    texts = SOURCES + sorted((ROOT / "tests").rglob("*.py")) + [ROOT / "docs" / "DESIGN.md", ROOT / "docs" / "NOTES.md"]
    found = {str(p.relative_to(ROOT)): _issue_lines(p) for p in texts if p != Path(__file__).resolve()}
    found = {k: v for k, v in found.items() if v}
    assert sorted(f"{k}:{v}" for k, v in found.items() if k not in ISSUE_NAMES_TO_REMOVE) == []
    assert sorted(ISSUE_NAMES_TO_REMOVE - set(found)) == [], "remove from ISSUE_NAMES_TO_REMOVE (cleaned)"


MAX_MODULE_DOCSTRING_LINES = 15
# owned by concurrent work; to trim: module docstrings over 15 lines in files others are editing. The list
# only shrinks: a file trimmed to 15 lines or fewer must leave it (the test below fails until it does).
LONG_MODULE_DOCSTRINGS_TO_TRIM: frozenset[str] = frozenset()


def _module_docstring_lines(path: Path) -> int:
    """Lines of the text of ``path``'s module docstring (0 without one)."""
    doc = ast.get_docstring(_parse(path))
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
                       "core/railtherm/physics/pass_history.py",
                       "core/railtherm/physics/partition.py", "core/railtherm/physics/friction/contact_temperature.py",
                       "core/railtherm/physics/thermal_trace.py",
                       "core/railtherm/models/hertz.py", "core/railtherm/models/sliding.py",
                       "core/railtherm/models/core_plugin.py",
                       "core/railtherm/solving/friction_loop.py", "plugins/railtherm_fastsim/*.py",
                       "plugins/railtherm_green/*.py", "plugins/railtherm_fipy/*.py", "plugins/railtherm_fdm/*.py",
                       "core/railtherm/solving/wheelset_*.py",
                       "core/railtherm/analysis/analytic.py", "core/railtherm/analysis/errors.py",
                       "core/railtherm/analysis/metrics.py", "core/railtherm/analysis/patch_metrics.py",
                       "core/railtherm/analysis/rises.py", "core/railtherm/analysis/trace_metrics.py",
                       "core/railtherm/analysis/verdicts.py",
                       "plugins/railtherm_fem/condense.py", "plugins/railtherm_fem/contact.py",
                       "plugins/railtherm_fem/coupled.py", "plugins/railtherm_fem/elastic.py",
                       "plugins/railtherm_fem/friction.py", "plugins/railtherm_fem/history.py", "plugins/railtherm_fem/mesh.py",
                       "plugins/railtherm_fem/model.py", "plugins/railtherm_fem/plugin.py",
                       "plugins/railtherm_fem/thermal.py", "plugins/railtherm_kalker/*.py")


#: the comment directly above a function (above its decorators) that keeps the whole scene says why after this
WHOLE_SCENE = "# whole scene:"


def _takes_the_scene(path: Path):
    """(line, name) of every function of ``path`` but the stage hooks with a parameter ``scene`` and no
    ``# whole scene: <why>`` comment directly above it (a solve driver above the stage hooks, a function that
    returns a scene, or the metrics' entry that reads a dozen parts)."""
    lines = _text(path).splitlines()
    for node in ast.walk(_parse(path)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name not in STAGE_HOOKS:
            args = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            above = lines[first - 2].strip() if first >= 2 else ""
            if any(a.arg == "scene" for a in args) and not (above.startswith(WHOLE_SCENE)
                                                            and above[len(WHOLE_SCENE):].strip()):
                yield node.lineno, node.name


def test_the_scene_parts_check_can_fail(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f(scene):\n    pass\n\n\n# whole scene: it returns a scene\ndef g(scene):\n    pass\n\n\n"
                     "# whole scene:\ndef h(scene):\n    pass\n\n\ndef compute_patch(self, scene):\n    pass\n")
    assert [name for _, name in _takes_the_scene(probe)] == ["f", "h"]


def test_functions_below_the_stage_hooks_take_the_scene_s_parts():
    """In :data:`SCENE_PARTS_MODULES` only the stage hooks, and functions that say why in a ``# whole scene: <why>``
    comment directly above them, have a parameter ``scene``; every other function takes the parts it reads
    (CONTACT's ``calc_temp(ic, mater, kin, cgrid, outpt)`` is the model)."""
    paths = [p for pattern in SCENE_PARTS_MODULES for p in sorted(ROOT.glob(pattern))]
    assert len(paths) >= len(SCENE_PARTS_MODULES)
    takes = [f"{path.relative_to(ROOT)}:{line} {name}" for path in paths for line, name in _takes_the_scene(path)]
    assert takes == [], "functions below the stage hooks that take the whole scene:\n  " + "\n  ".join(takes)


# ---------------------------------------------------------------------------------------------
# no alias module; imports at the top of modules unless a comment says why

def _is_alias_module(tree: ast.Module) -> bool:
    """Whether a module (not a package's ``__init__``) only imports and re-exports: besides its docstring,
    ``__all__`` and ``from __future__``, its body holds imports and nothing else, or it replaces itself in
    ``sys.modules``."""
    body = [n for n in tree.body if not (isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant))]
    body = [n for n in body if not (isinstance(n, ast.ImportFrom) and n.module == "__future__")]
    body = [n for n in body if not (isinstance(n, (ast.Assign, ast.AnnAssign)) and "__all__" in ast.unparse(n))]
    replaces = "sys.modules[__name__]" in ast.unparse(tree)
    return replaces or (bool(body) and all(isinstance(n, (ast.Import, ast.ImportFrom)) for n in body))


def test_the_alias_check_can_fail():
    assert _is_alias_module(ast.parse('"""Moved."""\nfrom .run.runner import *  # noqa\n__all__ = ["x"]\n'))
    assert _is_alias_module(ast.parse("import sys\nfrom .store import store\nsys.modules[__name__] = store\n"))
    assert not _is_alias_module(ast.parse("from .grid import embed\n\ndef f():\n    return embed\n"))


#: alias modules that wait for their users; the list only shrinks
ALIAS_MODULES_TO_REMOVE: frozenset[str] = frozenset()


def test_no_alias_module():
    """A module has one path: no module of core or a plugin (packages' ``__init__`` aside) only re-exports
    another (a deprecation would live in one ``_deprecated.py``, as pytest's ``_pytest/deprecated.py``)."""
    aliases = {str(p.relative_to(ROOT)) for p in SOURCES
               if p.name != "__init__.py" and _is_alias_module(_parse(p))}
    assert sorted(aliases - ALIAS_MODULES_TO_REMOVE) == [], sorted(aliases - ALIAS_MODULES_TO_REMOVE)
    assert sorted(ALIAS_MODULES_TO_REMOVE - aliases) == [], "remove from ALIAS_MODULES_TO_REMOVE (gone)"


def _function_imports_without_reason(path: Path):
    """Line numbers of the imports inside functions of ``path`` that neither end in a ``#`` comment nor stand
    below one (directly, or below a run of imports that starts directly below one)."""
    lines = _text(path).splitlines()
    tree = _parse(path)
    inner = {n.lineno for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
             for n in ast.walk(f) if isinstance(n, (ast.Import, ast.ImportFrom))}
    starts = {n.lineno: n.end_lineno for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))}
    for line in sorted(inner):
        above = line - 1
        while True:                                  # climb over the imports directly above
            prev = next((s for s, e in starts.items() if e == above), None)
            if prev is None or "#" in lines[prev - 1]:
                break
            above = prev - 1
        reason = "#" in lines[line - 1] or (above >= 1 and lines[above - 1].strip().startswith("#")) or (
            prev is not None and "#" in lines[prev - 1])
        if not reason:
            yield line


def test_the_function_import_check_can_fail(tmp_path):
    p = tmp_path / "m.py"
    p.write_text("import os\n\ndef f():\n    import json\n    return json\n\n\ndef g():\n"
                 "    # numba: compiled on first use only\n    import numba\n    import math\n    return numba\n\n"
                 "def h():\n    import re  # 40 ms, only for messages\n    return re\n")
    assert list(_function_imports_without_reason(p)) == [4]


def test_imports_inside_functions_say_why():
    """Imports stand at the top of a module; one inside a function carries a ``#`` comment saying why
    (a heavy library a plain ``import railtherm`` must not load, a cycle, an optional dependency)."""
    found = sorted(f"{p.relative_to(ROOT)}:{line}" for p in SOURCES for line in _function_imports_without_reason(p))
    assert found == [], "imports inside functions without a '#' reason (move them to the top):\n  " + "\n  ".join(found)


# ---------------------------------------------------------------------------------------------
# one home for friction and for the heat partition

FRICTION = "core/railtherm/physics/friction/"
#: the scene's friction law keys
LAW_KINDS = frozenset({"constant", "slip-velocity", "polach", "temperature"})
#: files of concurrent work whose capabilities still spell out every law key instead of
#: ``railtherm.physics.friction.LAW_KINDS``; the list only shrinks
LAW_KEYS_TO_REPLACE: frozenset[str] = frozenset()


def _trees():
    for p in SOURCES:
        yield str(p.relative_to(ROOT)), _parse(p)


def _law_key_collections(rel: str, tree) -> list[str]:
    """Tuples, lists, sets and dicts of ``tree`` that hold two or more friction law keys as strings."""
    out = []
    for node in ast.walk(tree):
        items = node.keys if isinstance(node, ast.Dict) else getattr(node, "elts", None)
        if isinstance(node, (ast.Tuple, ast.List, ast.Set, ast.Dict)) and items:
            words = {n.value for n in items if isinstance(n, ast.Constant) and isinstance(n.value, str)}
            if len(words & LAW_KINDS) >= 2:
                out.append(f"{rel}:{node.lineno}")
    return out


def test_friction_law_keys_are_defined_once():
    """The law keys of the scene's ``friction`` table are listed in one place, the laws of
    ``physics/friction/laws.py`` (each law's ``kind``); the scene validator reads them from there."""
    from railtherm.physics.friction import LAW_KINDS as KINDS
    assert KINDS == LAW_KINDS
    assert _law_key_collections("x", ast.parse('LAWS = ("constant", "polach")')) == ["x:1"]
    found = [where for rel, tree in _trees() if not rel.startswith(FRICTION) for where in _law_key_collections(rel, tree)]
    found = [where for where in found if where.split(":")[0] not in LAW_KEYS_TO_REPLACE]
    assert found == [], f"friction law keys listed outside {FRICTION} (use railtherm.physics.friction.LAW_KINDS): {found}"
    listed = {where.split(":")[0] for rel, tree in _trees() for where in _law_key_collections(rel, tree)}
    assert LAW_KEYS_TO_REPLACE <= listed, f"remove from LAW_KEYS_TO_REPLACE: {sorted(LAW_KEYS_TO_REPLACE - listed)}"


def test_one_contact_temperature_and_one_mu_tolerance():
    """The contact temperature a temperature law reads is computed by the functions of
    ``physics/friction/contact_temperature.py`` only, and the tolerances on mu of the friction iterations
    are defined in ``physics/friction/tolerances.py`` only."""
    temps, tolerances = [], []
    for rel, tree in _trees():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and "contact_temperature" in node.name \
                    and rel != FRICTION + "contact_temperature.py":
                temps.append(f"{rel}:{node.lineno} {node.name}")
            targets = node.targets if isinstance(node, ast.Assign) else [node.target] \
                if isinstance(node, ast.AnnAssign) else []
            for t in targets:
                name = getattr(t, "id", getattr(t, "attr", ""))
                if "MU" in name.upper().split("_") and "TOLERANCE" in name.upper() \
                        and rel != FRICTION + "tolerances.py":
                    tolerances.append(f"{rel}:{node.lineno} {name}")
    assert temps == [], f"contact temperatures computed outside {FRICTION}contact_temperature.py: {temps}"
    assert tolerances == [], f"mu tolerances defined outside {FRICTION}tolerances.py: {tolerances}"
    # ... and there, one tolerance: every other bound on mu is derived from LOOP_MU_TOLERANCE
    tree = dict(_trees())[FRICTION + "tolerances.py"]
    own = [n for n in tree.body if isinstance(n, ast.Assign) and "MU" in n.targets[0].id.split("_")
           and "TOLERANCE" in n.targets[0].id]
    assert [n.targets[0].id for n in own][:1] == ["LOOP_MU_TOLERANCE"], "LOOP_MU_TOLERANCE comes first"
    free = [n.targets[0].id for n in own[1:] if "LOOP_MU_TOLERANCE" not in ast.unparse(n.value)]
    assert free == [], f"mu tolerances not derived from LOOP_MU_TOLERANCE: {free}"


def _calls(tree, name: str) -> bool:
    return any(isinstance(n, ast.Call) and name in (getattr(n.func, "id", None), getattr(n.func, "attr", None))
               for n in ast.walk(tree))


def test_one_coupled_temperature_friction_loop():
    """Core's chains and the FEM run the one temperature-friction loop,
    :func:`railtherm.physics.friction.iterate_temperature_law`; no module defines another."""
    trees = dict(_trees())
    for user in ("core/railtherm/solving/friction_loop.py", "plugins/railtherm_fem/coupled.py"):
        assert _calls(trees[user], "iterate_temperature_law"), user
    import re
    loop = re.compile(r"(temperature|friction)_loop|iterate_\w*law|fixed_point")
    others = [f"{rel}:{n.lineno} {n.name}" for rel, tree in trees.items() if not rel.startswith(FRICTION)
              for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and loop.search(n.name)
              and not (_calls(n, "iterate_temperature_law") or _calls(n, "solve_coupled"))]
    assert others == [], f"temperature-friction loops outside {FRICTION}: {others}"


def test_each_heat_partition_rule_has_one_meaning():
    """The rule words of ``heat_partition`` are listed once (:attr:`railtherm.physics.partition.HeatPartition.RULES`),
    and a function that tests a value for ``"equal-temperature"`` means Blok's fraction: it computes
    :func:`railtherm.physics.equal_temperature_partition` (the FEM's rule that equalises mean temperatures is
    ``"equal-mean-temperature"``)."""
    lists, meanings = [], []
    for rel, tree in _trees():
        for node in ast.walk(tree):
            if isinstance(node, (ast.Tuple, ast.List, ast.Set)) and rel != "core/railtherm/physics/partition.py":
                words = {n.value for n in node.elts if isinstance(n, ast.Constant)}
                if "equal-mean-temperature" in words:
                    lists.append(f"{rel}:{node.lineno}")
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                tests = [c for c in ast.walk(node) if isinstance(c, ast.Compare)
                         and any(isinstance(x, ast.Constant) and x.value == "equal-temperature"
                                 for x in [c.left, *c.comparators])]
                if tests and not _calls(node, "equal_temperature_partition"):
                    meanings.append(f"{rel}:{node.lineno} {node.name}")
    assert lists == [], f"heat partition rules listed outside physics/partition.py: {lists}"
    assert meanings == [], f"'equal-temperature' taken to mean something else than Blok's fraction: {meanings}"


def test_the_scene_is_resolved_once():
    """Only ``core/railtherm/input/`` reads the scene's raw table (``scene.source[...]``) for the friction law
    and the heat partition; everything else reads the typed parts ``scene.friction`` and
    ``scene.partition`` resolved at load time."""
    raw = []
    for rel, tree in _trees():
        if rel.startswith("core/railtherm/input/"):
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) \
                    and node.slice.value in ("friction", "heat_partition") and "source" in ast.unparse(node.value):
                raw.append(f"{rel}:{node.lineno} {ast.unparse(node)}")
            if isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "get" and node.args \
                    and isinstance(node.args[0], ast.Constant) and node.args[0].value in ("friction", "heat_partition") \
                    and "source" in ast.unparse(node.func.value):
                raw.append(f"{rel}:{node.lineno} {ast.unparse(node)}")
    assert raw == [], f"the scene's friction or heat partition re-read from its source: {raw}"
