"""The "kalker" method's cold level-3 solve after a level-0 warm-up, as a study's worker runs it.

The runner warms a method up once per process with a level-0 solve (the timing protocol in docs/DESIGN.md); a run's
first timed solve at level 3 is then the first on its grid. Scene: the main study's carter line contact at
xi = -6e-4 (``studies/seed_paper.toml``; at level 0 it slips fully, so its warm-up reaches none of the tangential
solver's kernels). Two settings:

``cache = "filled"``
    In this process, numba's disk cache filled: the kalker operator caches (normal and rolling operators, the
    corner differences of their kernels, the FFT work arrays) are emptied, the scene solved at level 0, then the
    level-3 solve is timed: the set-up of the level-3 grid (influence coefficients, spectra) and the solve.
``cache = "empty"``
    A fresh install: a child process with an empty numba cache directory (``NUMBA_CACHE_DIR``) solves level 0,
    then level 3 twice. The benchmark's time is the child's whole run (imports, compilation, three solves);
    ``extra_info`` holds the level-0 warm-up, the cold and the warm level-3 solves [s] and whether numba compiled
    during the cold one (the runner solves such a run again and does not time it, but the seconds are spent).

Run: ``OPENBLAS_NUM_THREADS=1 NUMBA_NUM_THREADS=1 python -m pytest benchmarks/test_kalker_cold_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -n 0``. Before / after of the plugin: ``python
benchmarks/test_kalker_cold_benchmark.py [DIR]`` prints the empty-cache child's numbers, DIR (optional) holding a
copy of ``plugins/railtherm_kalker`` put first on the child's path.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

STUDY = Path(__file__).resolve().parents[1] / "studies" / "seed_paper.toml"
SCENE = "carter--creepage.longitudinal=-0.0006"
CHILD_FLAG = "--child"


def _scene(name: str = SCENE):
    """The main study's scene ``name``."""
    from railtherm.input.study import load_study  # here: the child's imports are part of what it times
    return {s.name: s for s in load_study(STUDY).scenes}[name]


def _timed_solve(scene, level: int) -> tuple[float, bool]:
    """Wall time of one kalker solve [s] and whether numba compiled during it."""
    import railtherm
    from railtherm.run.timing import compile_watch
    with compile_watch() as compiled:
        t0 = time.perf_counter()
        railtherm.solve(scene, "kalker", level)
        took = time.perf_counter() - t0
    return took, bool(compiled)


def warm_then_cold(name: str = SCENE) -> dict:
    """Level-0 warm-up, then two level-3 solves of the scene: their wall times [s] and compilations."""
    scene = _scene(name)
    warmup, _ = _timed_solve(scene, 0)
    cold, compiled = _timed_solve(scene, 3)
    warm, _ = _timed_solve(scene, 3)
    return {"warmup_level0": warmup, "cold_level3": cold, "warm_level3": warm, "compiled_in_cold": compiled}


def run_child(plugin_dir: str | None = None) -> dict:
    """:func:`warm_then_cold` in a child process with an empty numba cache: its numbers and its wall time [s]."""
    with tempfile.TemporaryDirectory(prefix="kalker-numba-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        if plugin_dir:
            env["PYTHONPATH"] = os.pathsep.join([plugin_dir, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, __file__, CHILD_FLAG], env=env, capture_output=True, text=True,
                             check=True)
        took = time.perf_counter() - t0
    result = json.loads(out.stdout.strip().splitlines()[-1])
    result["child_wall"] = took
    return result


def _clear_kalker_caches() -> None:
    """Empty the plugin's grid caches: the next solve on a grid sets it up as a process's first does."""
    from railtherm_kalker import _work
    from railtherm_kalker.tangential_model import clear_operator_caches
    clear_operator_caches()
    _work._work_arrays.cache_clear()
    _work._periodic_work_arrays.cache_clear()


@pytest.mark.benchmark
def test_benchmark_kalker_cold_level3_filled_cache(benchmark):
    """The cold level-3 solve in this process (kernels loaded): grid set-up and solve."""
    scene = _scene()
    _timed_solve(scene, 0)                                    # the process's first solve: kernels, imports

    def setup():
        _clear_kalker_caches()
        _timed_solve(scene, 0)

    compiled = []

    def cold():
        took, c = _timed_solve(scene, 3)
        compiled.append(c)
        return took

    benchmark.pedantic(cold, setup=setup, rounds=5, iterations=1)
    warm = min(_timed_solve(scene, 3)[0] for _ in range(3))
    benchmark.extra_info.update({"scene": SCENE, "warm_level3": warm, "compiled_in_cold": any(compiled)})
    assert not any(compiled)


@pytest.mark.benchmark
def test_benchmark_kalker_cold_level3_empty_cache(benchmark):
    """A fresh install's child process: warm-up, cold and warm level-3 solves; the cold one compiles nothing."""
    result = {}
    benchmark.pedantic(lambda: result.update(run_child()), rounds=1, iterations=1)
    benchmark.extra_info.update({"scene": SCENE, **result})
    assert not result["compiled_in_cold"]
    assert result["cold_level3"] < 0.5 + 10 * result["warm_level3"]


if __name__ == "__main__":
    if sys.argv[1:] == [CHILD_FLAG]:
        print(json.dumps(warm_then_cold()))
    else:
        print(json.dumps(run_child(sys.argv[1] if len(sys.argv) > 1 else None)))
