"""Cost of green's transient histories against the cost target "a 10-pass history <= 2x one steady solve of the
same method and level for green" (and a 1,000-pass history far below 1,000 passes' worth): a Hertzian band
(2-D) and a Hertzian ellipse (a = 6, b = 4 mm) heating the rail at 30 m/s, level 2 (128 cells along 2a), solved through
``railtherm.solve`` (dataset built and validated): the steady scene (default outputs) against the
transient scene with 1, 10 and 1,000 passes 83 ms apart (outputs temperature_history, pass peaks, residual
rise and time above at the surface and 0.1, 0.5 mm; green's own axis, 552 samples per pass).

Each case is timed interleaved with the others (best and median of ``REPS`` in one process, the pytest-
benchmark statistics for the case itself); the ratios to the steady solve are recorded (``extra_info``),
not asserted: timings are measured, never test verdicts; the process CPU times' ratios beside the wall
times' (a loaded machine stretches wall time, not a single-threaded solve's CPU time). Recorded beside them: the time of green's
histories alone (:func:`railtherm_green.history.histories`, the best of the same rounds) and the rest of the
transient solve (the steady pass's kernel, the result's dataset and its checks), which the history's cost
is compared against. Run:
``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_green_transient_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s -n 0``.
"""
from __future__ import annotations

import statistics
import time

import pytest

import railtherm
from railtherm_green import history as green_history
from transient_scenes import transient_scene

REPS = 9


def scene(kind: str, passes: int | None) -> dict:
    """The rail heated by a given Hertzian source; ``passes`` None: the steady scene."""
    return transient_scene(f"green-{kind}-{passes}", passes, kind)


def interleaved(kind: str, counts, reps: int = REPS, history_times: dict | None = None,
                cpu_times: dict | None = None) -> dict:
    """Best and median wall time [s] of each case, the cases interleaved in every round; ``history_times``
    (filled when given): the best time [s] of green's histories within each transient case; ``cpu_times``:
    the best process CPU time [s] of each case (steadier than wall time on a shared machine)."""
    cases = {n: scene(kind, n) for n in counts}
    for sc in cases.values():
        railtherm.solve(sc, "green", level=2)                       # compile / import once
    times = {n: [] for n in counts}
    cpu = {n: [] for n in counts}
    spent = []
    original = green_history.histories

    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        out = original(*args, **kwargs)
        spent.append(time.perf_counter() - t0)
        return out
    green_history.histories = timed          # the model calls it through the module
    try:
        for rep in range(reps):
            for n, sc in cases.items():
                if n is not None and n >= 1000 and rep >= 3:
                    continue
                spent.clear()
                t0, c0 = time.perf_counter(), time.process_time()
                railtherm.solve(sc, "green", level=2)
                times[n].append(time.perf_counter() - t0)
                cpu[n].append(time.process_time() - c0)
                if history_times is not None and spent:
                    history_times[n] = min(history_times.get(n, float("inf")), sum(spent))
    finally:
        green_history.histories = original
    if cpu_times is not None:
        cpu_times.update({n: min(v) for n, v in cpu.items()})
    return {n: (min(v), statistics.median(v)) for n, v in times.items()}


@pytest.mark.benchmark
@pytest.mark.parametrize("kind", ["band", "ellipse"])
@pytest.mark.parametrize("passes", [None, 10, 1000], ids=["steady", "10-pass", "1000-pass"])
def test_benchmark_green_transient(benchmark, kind, passes):
    sc = scene(kind, passes)
    benchmark.pedantic(railtherm.solve, args=(sc, "green"), kwargs={"level": 2}, rounds=3 if passes == 1000 else 15,
                       warmup_rounds=1)
    if passes != 10:
        return
    hist, cpu = {}, {}
    cost = interleaved(kind, (None, 1, 10, 1000), history_times=hist, cpu_times=cpu)
    steady = cost[None][0]
    line = ", ".join(f"{'steady' if n is None else f'{n} passes'} {b * 1e3:.1f} ms (median {m * 1e3:.1f})"
                     for n, (b, m) in cost.items())
    print(f"\ngreen level 2, {kind}: {line}; 10 passes / steady {cost[10][0] / steady:.2f}, "
          f"1000 passes / 1 pass {cost[1000][0] / cost[1][0]:.1f}; histories alone: "
          + ", ".join(f"{n} passes {t * 1e3:.1f} ms" for n, t in hist.items())
          + f"; the 10-pass solve without its histories {(cost[10][0] - hist[10]) / steady:.2f} steady solves; "
          f"CPU time: 10 passes / steady {cpu[10] / cpu[None]:.2f}, 1000 passes / 1 pass {cpu[1000] / cpu[1]:.1f}")
    benchmark.extra_info.update({f"{'steady' if n is None else n}_best_s": b for n, (b, _) in cost.items()})
    benchmark.extra_info.update({f"{n}_histories_best_s": t for n, t in hist.items()})
    benchmark.extra_info.update(ratio_10_steady=cost[10][0] / steady, ratio_1000_1=cost[1000][0] / cost[1][0],
                                ratio_10_without_histories_steady=(cost[10][0] - hist[10]) / steady,
                                cpu_ratio_10_steady=cpu[10] / cpu[None], cpu_ratio_1000_1=cpu[1000] / cpu[1])
