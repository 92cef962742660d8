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
Rerun with the 3-D cases below: 1.3x, 2.3x, 2.4x; 1,000 passes 7.1x one pass.

The 3-D block of an ellipse (:mod:`railtherm_fipy.history3d`, :func:`test_benchmark_fipy_transient_ellipse`):
the Hertz ellipse a = 6, b = 4 mm of :func:`transient_scenes.transient_scene` (steady: FiPy's moving-frame strips,
0.15 s) against 1, 10 and 1,000 passes 83 ms apart, and the study's train-4-axles against its steady scene.
With FiPy's Grid3D assembly of the block (85..133 x 101..175 x 121..155 cells) and every mode stepped, separate
processes: 1 pass 14.5 s (2.4 GB peak RSS), 10 passes 38 s (3.7 GB): 160x the steady solve; train-4-axles 22 s
(3.3 GB); 1,000 passes refused (3.6e6 cells over the budget 1.5e6); cProfile: 26 of 30 s in FiPy's Grid3D mesh
and matrix. With the block's operator from FiPy's three 1-D parts, only the modes the centre column reads
stepped (a quarter), each step compiled (update and read in one pass over the modes) and the source's heat
projected on the modes strip by strip: 1 pass 0.22 s, 10 passes 0.35 s: 2.3x the steady solve (CPU 2.2x;
target 10x), 1,000 passes 3.3 s: 14.7x one pass (CPU 14.5x; target 20x); train-4-axles 0.48 s, 3.5x its
steady 0.14 s; peak RSS (separate processes, /usr/bin/time) 10 passes 0.32 GB, train-4-axles 0.36 GB, 1,000
passes 0.85 GB. The 1,000 passes cost more than the 10 per pass stepped because the block grows with the
history (sqrt(kappa t_end): 3.6e6 cells against 1.2e6) and the source crosses it in steps of h/V (2,059 steps
of the 1,000-pass case's one pass: 2.9 of its 6 s under cProfile in the compiled steps, memory-bound).

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


def interleaved(cases: dict, reps: int = 3, once=(), level: int = 2) -> dict:
    """Best and median wall time [s] and best process CPU time [s] of each case at ``level``, the cases
    interleaved in every round; the cases in ``once`` only in the first two rounds."""
    for sc in cases.values():
        railtherm.solve(sc, "fipy", level=level)                    # imports and FiPy's first use once
    times = {n: [] for n in cases}
    for rep in range(reps):
        for n, sc in cases.items():
            if n in once and rep >= 2:
                continue
            t0, c0 = time.perf_counter(), time.process_time()
            railtherm.solve(sc, "fipy", level=level)
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


@pytest.mark.benchmark
def test_benchmark_fipy_transient_ellipse(benchmark):
    """The 3-D block (:mod:`railtherm_fipy.history3d`): the Hertz ellipse a = 6, b = 4 mm of
    :func:`transient_scenes.transient_scene` steady (FiPy's moving-frame strips) against 1, 10 and 1,000 passes,
    and the study's train-4-axles (its outputs ask the one-pass steady fields too) against its steady scene."""
    benchmark.pedantic(railtherm.solve, args=(transient_scene("fipy-ellipse-10", 10, "ellipse"), "fipy"),
                       kwargs={"level": 2}, rounds=3, warmup_rounds=1)
    cases = {n: transient_scene(f"fipy-ellipse-{n}", n, "ellipse") for n in (None, 1, 10, 1000)}
    cost = interleaved(cases, once=(1000,))
    study = interleaved({"steady": study_scene("train-4-axles", steady=True), "4 passes": study_scene("train-4-axles")})
    line = ", ".join(f"{'steady' if n is None else f'{n} passes'} {b:.3f} s (median {m:.3f}, CPU {c:.3f})"
                     for n, (b, m, c) in cost.items())
    ratios = {"ratio_10_steady": cost[10][0] / cost[None][0], "cpu_ratio_10_steady": cost[10][2] / cost[None][2],
              "ratio_1000_1": cost[1000][0] / cost[1][0], "cpu_ratio_1000_1": cost[1000][2] / cost[1][2],
              "study_train4_ratio": study["4 passes"][0] / study["steady"][0],
              "study_train4_cpu_ratio": study["4 passes"][2] / study["steady"][2]}
    print(f"\nfipy level 2, Hertz ellipse (3-D block): {line}; " + ", ".join(f"{k} {v:.1f}" for k, v in ratios.items())
          + f"; train-4-axles steady {study['steady'][0]:.3f} s, 4 passes {study['4 passes'][0]:.3f} s")
    benchmark.extra_info.update({f"ellipse_{'steady' if n is None else n}_best_s": b for n, (b, _, _) in cost.items()})
    benchmark.extra_info.update({f"ellipse_{'steady' if n is None else n}_cpu_s": c for n, (_, _, c) in cost.items()})
    benchmark.extra_info.update(ratios, study_train4_steady_s=study["steady"][0], study_train4_s=study["4 passes"][0])
