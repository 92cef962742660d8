"""Cost of fipy's pass histories against the targets "a 10-pass history <= 10 passes' worth of steady solves
of the same method and level for fipy; the 1,000-pass case <= 20x one pass": a Hertzian band (2-D,
a = 6 mm) heating the rail at 30 m/s, level 2, through ``railtherm.solve(scene, "fipy", level=2)``: the
steady scene (FiPy's moving-frame steady section, default outputs) against the transient scene with 1, 10
and 1,000 passes 83 ms apart (history outputs at the surface and 0.1, 0.5 mm; the constant schedule
superposes one pass's response, :func:`railtherm.solving.section_stepping.superposed_history`), and the
study's 8-pass line contact and its 10 us spike (studies/transient.toml, "train-8-passes-line",
"spike-10us") against their steady scenes.

Measured (the command below, one after the other on 2 loaded cores): with a sparse LU per step size (17
factorisations of the 89x119-cell section, 649 solves: 0.30 + 0.44 s of the 0.99 s history) the 10 passes
cost 14.9x the steady solve (CPU 10.9x), the 8-pass study scene 10.8x, the spike 15.6x (CPU 13.0x); each
Crank-Nicolson step taken per eigenmode of FiPy's separable operator (:mod:`railtherm_fipy.modes`, the same
steps to 7e-13) 1.5x (CPU 1.3x), 2.5x and 2.2x (CPU 2.2x); the 1,000 passes 6.6x one pass (CPU 7.6x).

Each case is timed interleaved with the others (best and median in one process; the 1,000-pass case
once per round, in the first two rounds); the ratios of wall and of process CPU time are recorded
(``extra_info``; a loaded machine stretches wall time, not a single-threaded solve's CPU time), not asserted:
timings are measured, never test verdicts. Run:
``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fipy_transient_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s -n 0``.
"""
from __future__ import annotations

import copy
import statistics
import time
import tomllib
from pathlib import Path

import pytest

import railtherm
from transient_scenes import transient_scene

STUDY = Path(__file__).parent.parent / "studies" / "transient.toml"
HISTORY_KEYS = ("mode", "passes", "schedule", "field", "outputs")


def scene(passes: int | None) -> dict:
    """The rail heated by a given Hertzian band; ``passes`` None: the steady scene."""
    return transient_scene(f"fipy-band-{passes}", passes)


def study_scene(name: str, steady: bool = False) -> dict:
    """A scene of the transient study as a mapping (its [defaults] merged in); ``steady``: without the
    transient keys (the same contact, one steady solve with the default outputs)."""
    doc = tomllib.loads(STUDY.read_text())

    def merge(base, over):
        out = copy.deepcopy(base)
        for k, v in over.items():
            out[k] = merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else copy.deepcopy(v)
        return out
    sc = merge(doc["defaults"], next(s for s in doc["scene"] if s["name"] == name))
    if steady:
        sc = {k: v for k, v in sc.items() if k not in HISTORY_KEYS}
        sc["name"] = f"{name}-steady"
    return sc


def interleaved(cases: dict, reps: int = 3, once=()) -> dict:
    """Best and median wall time [s] and best process CPU time [s] of each case, the cases interleaved in
    every round; the cases in ``once`` only in the first two rounds."""
    for sc in cases.values():
        railtherm.solve(sc, "fipy", level=2)                        # imports and FiPy's first use once
    times = {n: [] for n in cases}
    for rep in range(reps):
        for n, sc in cases.items():
            if n in once and rep >= 2:
                continue
            t0, c0 = time.perf_counter(), time.process_time()
            railtherm.solve(sc, "fipy", level=2)
            times[n].append((time.perf_counter() - t0, time.process_time() - c0))
    return {n: (min(w for w, _ in v), statistics.median(w for w, _ in v), min(c for _, c in v))
            for n, v in times.items()}


@pytest.mark.benchmark
def test_benchmark_fipy_transient(benchmark):
    benchmark.pedantic(railtherm.solve, args=(scene(10), "fipy"), kwargs={"level": 2}, rounds=3, warmup_rounds=1)
    cost = interleaved({n: scene(n) for n in (None, 1, 10, 1000)}, once=(1000,))
    steady = cost[None][0]
    line = ", ".join(f"{'steady' if n is None else f'{n} passes'} {b:.3f} s (median {m:.3f})"
                     for n, (b, m, _) in cost.items())
    print(f"\nfipy level 2, Hertz band: {line}; 10 passes / steady {cost[10][0] / steady:.1f}, "
          f"1000 passes / 1 pass {cost[1000][0] / cost[1][0]:.1f}; CPU time: 10 passes / steady "
          f"{cost[10][2] / cost[None][2]:.1f}, 1000 passes / 1 pass {cost[1000][2] / cost[1][2]:.1f}")
    study = interleaved({"steady": study_scene("train-8-passes-line", steady=True),
                         "8 passes": study_scene("train-8-passes-line")})
    print(f"fipy level 2, study scene train-8-passes-line: steady {study['steady'][0]:.3f} s, 8 passes "
          f"{study['8 passes'][0]:.3f} s; 8 passes / steady {study['8 passes'][0] / study['steady'][0]:.1f}")
    spike = interleaved({"steady": study_scene("spike-10us", steady=True), "spike": study_scene("spike-10us")})
    print(f"fipy level 2, study scene spike-10us (one pass, the schedule's 5 us ramps stepped finer): steady "
          f"{spike['steady'][0]:.3f} s, history {spike['spike'][0]:.3f} s; history / steady "
          f"{spike['spike'][0] / spike['steady'][0]:.1f} (CPU {spike['spike'][2] / spike['steady'][2]:.1f})")
    benchmark.extra_info.update({f"{'steady' if n is None else n}_best_s": b for n, (b, _, _) in cost.items()})
    benchmark.extra_info.update(ratio_10_steady=cost[10][0] / steady, ratio_1000_1=cost[1000][0] / cost[1][0],
                                study_train8_ratio=study["8 passes"][0] / study["steady"][0],
                                study_spike_ratio=spike["spike"][0] / spike["steady"][0],
                                cpu_ratio_10_steady=cost[10][2] / cost[None][2],
                                cpu_ratio_1000_1=cost[1000][2] / cost[1][2])
