"""What a worker of the main study (studies/seed_paper.toml) pays the first time, measured in this process:
run as ``python benchmarks/cold_start.py KIND`` by benchmarks/test_cold_start_benchmark.py, it prints one JSON
object.

* ``compile``: with the caller's ``NUMBA_CACHE_DIR`` (an empty directory: a fresh install), the warm-up of
  fastsim-fdm on the study's first scene (ek-low, level 0: FASTSIM and the FDM's steady scheme), then two
  solves of fdm-circular-q10 at level 3, the first level whose scheme is explicit (the fused kernel must come
  from the warm-up: :func:`railtherm_fdm.kernels.compile_block_kernels`). Wall and CPU time [s] of each solve
  and the numba compilations in it (top level: a kernel's compilation includes the functions it calls).
* ``fem``: the FEM's first solve of a geometry against its repeat, for the runs whose first timed solve was
  slowest in a study: each cold solve follows a warm-up on another scene and an emptied mechanics cache
  (:func:`railtherm_fem.coupled.clear_cache`), so it builds the mesh, stiffness and factorisation; the repeat
  finds them kept.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from numba.core import event

import railtherm
import railtherm.solving.pipeline  # noqa: F401 - imports are not part of the first solve's cost
import railtherm_fastsim.plugin  # noqa: F401
import railtherm_fdm.model  # noqa: F401
from railtherm_fem.coupled import clear_cache

STUDY = Path(__file__).resolve().parents[1] / "studies" / "seed_paper.toml"
#: (scene, level) of the FEM's slowest first timed solves
FEM_RUNS = (("fem-seed", 0), ("fem-seed", 1), ("ek-strip-contact", 2), ("carter--creepage.longitudinal=-0.00024", 3))


def _timed(scene, method: str, level: int) -> dict:
    """One solve: wall and CPU time [s] and the numba kernels compiled in it (name, wall seconds)."""
    w0, c0 = time.perf_counter(), time.process_time()
    with event.install_recorder("numba:compile") as rec:
        railtherm.solve(scene, method, level, validate=False)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    starts, depth, top = {}, 0, []
    for ts, ev in rec.buffer:
        key = (id(ev.data["dispatcher"]), str(ev.data["args"]))
        if ev.is_start:
            starts[key] = (ts, depth)
            depth += 1
            continue
        depth -= 1
        t0, d = starts[key]
        if d == 0:
            top.append((ev.data["dispatcher"].py_func.__qualname__, ts - t0))
    return {"wall": wall, "cpu": cpu, "compiled": top}


def compile_costs() -> dict:
    """fastsim-fdm: the warm-up and the level-3 explicit solve on an empty numba cache (module docstring)."""
    study = railtherm.load_study(STUDY)
    return {"warmup": _timed(study.scene("ek-low"), "fastsim-fdm", 0),
            "explicit_first": _timed(study.scene("fdm-circular-q10"), "fastsim-fdm", 3),
            "explicit_repeat": _timed(study.scene("fdm-circular-q10"), "fastsim-fdm", 3)}


def fem_costs() -> dict:
    """The FEM: cold (mechanics built) and warm (mechanics kept) solve of each of :data:`FEM_RUNS` [s]."""
    study = railtherm.load_study(STUDY)
    railtherm.solve(study.scene("trace-band"), "fem", 0, validate=False)    # imports and first touch
    out = {}
    for name, level in FEM_RUNS:
        clear_cache()
        cold = _timed(study.scene(name), "fem", level)
        warm = _timed(study.scene(name), "fem", level)
        out[f"{name} L{level}"] = {"cold": cold["wall"], "cold_cpu": cold["cpu"], "warm": warm["wall"],
                                   "warm_cpu": warm["cpu"]}
    return out


if __name__ == "__main__":
    print(json.dumps(compile_costs() if sys.argv[1] == "compile" else fem_costs()))
