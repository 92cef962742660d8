"""Plugin "kalker": every numba kernel compiled in a process's first solve (:mod:`railtherm_kalker._precompile`).

The runner's warm-up is one coarse solve of the first scene a worker sees (the timing protocol in docs/DESIGN.md,
"Scene vocabulary"); a kernel it did not reach compiled in a later solve. These tests check that the table of kernel signatures covers
every kernel of the plugin and the argument types the solvers really pass: after :func:`compile_kernels`, solves
that reach every kernel leave no kernel with a signature outside the table (a kernel whose call types drifted
from the table would compile a new specialisation there).
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest -n 0 -q tests/test_kalker_precompile.py``.
"""
from __future__ import annotations

import importlib
import json
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import railtherm
import railtherm_kalker
from railtherm import load_scene
from railtherm.testing import canonical
from railtherm_kalker import _precompile

numba = pytest.importorskip("numba")
from numba.core.registry import CPUDispatcher  # noqa: E402 - after the skip without numba

#: creepage sets that, with the line contact below, reach every kernel at level 1: the line contact's partial and
#: (at xi = -6e-4) nearly full slip (one-component sweep blocks), the ellipse's longitudinal creepage (mirrored
#: product), lateral creepage (two-component products and line factorisation) and large lateral creepage (a
#: full-slip start: the two-component sweep blocks)
ELLIPSE_CREEPAGES = ({"longitudinal": -1e-3}, {"lateral": 1e-3}, {"lateral": 5e-3})


def _plugin_kernels():
    """The numba kernels defined in the plugin's modules: {(module, name): dispatcher}."""
    out = {}
    for info in pkgutil.iter_modules(railtherm_kalker.__path__):
        mod = importlib.import_module(f"railtherm_kalker.{info.name}")
        for name, obj in vars(mod).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == mod.__name__:
                out[(mod.__name__, obj.py_func.__name__)] = obj
    return out


def _scene(base, name, **changes):
    doc = canonical(base, **changes)
    doc["name"] = name
    doc.pop("sliding_speed", None)
    return load_scene(doc)


def _scenes():
    """Carter's line contact of the main study at xi = -5e-5 and -6e-4 and the E&K ellipse at ELLIPSE_CREEPAGES."""
    line = [_scene("line-full-sliding", f"carter-{xi:g}", normal_force=1.78896e5,
                   contact={"shape": "line", "wheel_radius": 0.5}, speed=10.0, creepage={"longitudinal": xi},
                   friction=0.3, outputs=["creep_force_x"]) for xi in (-5e-5, -6e-4)]
    ellipse = [_scene("ellipse-creepage", f"ek-{i}", normal_force=100e3,
                      contact={"shape": "ellipse", "semi_axes": [5.88e-3, 10.54e-3]},
                      creepage={"longitudinal": 0.0, "lateral": 0.0, "spin": 0.0, **c},
                      outputs=["creep_force_x", "creep_force_y"]) for i, c in enumerate(ELLIPSE_CREEPAGES)]
    return line + ellipse


def test_every_kernel_is_in_the_table():
    """Each kernel of the plugin is compiled by compile_kernels (or is a callee compiled into its callers), and the
    table names no kernel twice with one signature."""
    table = _precompile.kernel_signatures()
    listed = {k.py_func.__name__ for k, _ in table}
    kernels = _plugin_kernels()
    missing = sorted(f"{m}.{n}" for (m, n) in kernels if n not in listed and n not in _precompile.CALLEES)
    assert not missing, f"numba kernels not compiled by compile_kernels: {missing}"
    assert len({(id(k), tuple(s)) for k, s in table}) == len(table)
    assert len(table) == 13   # 11 kernels; _combine and _mac2 in 2 precisions


def test_compile_kernels_compiles_the_whole_table():
    """After compile_kernels every kernel holds every signature of its table entries, none failed."""
    _precompile.compile_kernels()
    assert _precompile.FAILED == []
    for kernel, sig in _precompile.kernel_signatures():
        assert tuple(sig) in {tuple(s) for s in kernel.signatures}, (kernel.py_func.__name__, sig)


def extra_signatures() -> dict:
    """In this process: compile_kernels, then the solves of :func:`_scenes` at level 1 (the models' own path through
    railtherm.solve); the signatures of the plugin's kernels outside compile_kernels' table, {name: [str]}."""
    _precompile.compile_kernels()
    for scene in _scenes():
        railtherm.solve(scene, "kalker", 1)
    table = {}
    for kernel, sig in _precompile.kernel_signatures():
        table.setdefault(id(kernel), set()).add(tuple(sig))
    extra = {name: [str(s) for s in k.signatures if tuple(s) not in table.get(id(k), set())]
             for (_, name), k in _plugin_kernels().items() if name not in _precompile.CALLEES}
    return {name: sigs for name, sigs in extra.items() if sigs}


def test_solves_need_no_other_signature():
    """Solves reaching every kernel (two line contacts and three ellipse creepages) leave each kernel with the
    table's signatures only, so that no solve after the first compiles. In a child process: the kernels of this one
    may hold the signatures of other tests' direct calls."""
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import test_kalker_precompile as t; "
            "print(json.dumps(t.extra_signatures()))")
    out = subprocess.run([sys.executable, "-c", code, str(Path(__file__).parent)], capture_output=True, text=True,
                         check=True)
    extra = json.loads(out.stdout.strip().splitlines()[-1])
    assert not extra, f"kernels compiled for signatures outside compile_kernels' table: {extra}"
