"""Cost of core's coupled temperature-friction loop against the uncoupled solve, and its loop iterations.

Scene: a circular Hertz contact (100 kN, both curvatures 1.015 1/m) on 100 x 100 surface cells (level 0,
``cells = 100``), longitudinal creepage -0.01 (partial slip near saturation) and -0.1 (large slip, hot), at 30
and 90 m/s. Uncoupled: ``friction = 0.3`` (one pass of the chain). Coupled: the temperature law
mu = 0.3 at 0 degC falling to 0.15 at 400 degC (core's loop, railtherm.solving.friction_loop, tolerances
1e-4 on mu and on the force). Both through ``railtherm.solve`` (dataset built and validated), best of 5 after a
warm-up. Parametrized by method (``METHODS``): ``green`` runs hertz -> fastsim -> frictional -> green,
``kalker`` kalker -> kalker -> frictional -> green (``cells`` elements across 2a, plus the potential area's margin).

``extra_info``: both times, their ratio (the target: coupled <= 5 x uncoupled, read there, not asserted: no timed
assertions) and the loop's iterations.
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_friction_loop_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s``.
"""
from __future__ import annotations

import time

import pytest

import railtherm

METHODS = ["green", "kalker"]
CELLS = 100
TEMP = {"law": "temperature", "reference": 0.3, "reference_temperature": 0.0, "change": -0.15, "over": 400.0}
BASE = {"name": "loop", "normal_force": 100e3, "contact": {"shape": "ellipse", "curvatures": [1.015, 1.015]},
        "heat_partition": "equal-temperature",
        "outputs": ["creep_force_x", "frictional_power", "max_surface_temperature", "pressure"]}


def _best(scene, method, n=5):
    ds = railtherm.solve(scene, method, level=0, options={"cells": CELLS})        # warm-up (numba, caches)
    best = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        railtherm.solve(scene, method, level=0, options={"cells": CELLS})
        best = min(best, time.perf_counter() - t0)
    return best, ds


@pytest.mark.benchmark
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("speed, creepage", [(30.0, -0.01), (30.0, -0.1), (90.0, -0.01), (90.0, -0.1)])
def test_benchmark_coupled_temperature_loop(benchmark, method, speed, creepage):
    scene = {**BASE, "speed": speed, "creepage": {"longitudinal": creepage}}
    coupled_scene = {**scene, "friction": TEMP}
    uncoupled, ds0 = _best({**scene, "friction": 0.3}, method)
    coupled, ds = _best(coupled_scene, method)
    assert min(ds.pressure.shape) >= CELLS       # kalker's potential area adds a margin around the patch
    n = int(next(v for k, v in ds.attrs.items() if k.endswith("friction_loop_iterations")))
    ratio = coupled / uncoupled
    benchmark.extra_info.update({"method": method, "speed": speed, "creepage": creepage, "uncoupled_s": uncoupled,
                                 "coupled_s": coupled, "ratio": ratio, "loop_iterations": n,
                                 "creep_force_ratio": float(ds.creep_force_x) / float(ds0.creep_force_x)})
    benchmark(railtherm.solve, coupled_scene, method, level=0, options={"cells": CELLS})
    print(f"{method} V={speed:g} xi={creepage:g}: uncoupled {uncoupled * 1e3:.1f} ms, coupled {coupled * 1e3:.1f} ms, "
          f"ratio {ratio:.2f}, {n} loop iterations, Fx coupled/constant {float(ds.creep_force_x) / float(ds0.creep_force_x):.3f}")
