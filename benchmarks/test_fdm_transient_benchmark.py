"""Cost of fdm's pass histories (issue 27 targets: a 10-pass history <= 10 passes' worth of steady solves of
the same method and level for fdm; the 1,000-pass case <= 20x one pass): a Hertzian band (2-D, a = 6 mm)
heating the rail at 30 m/s, level 2, through ``railtherm.solve(scene, "fastsim-fdm", level=2)``: the steady
scene (moving-frame steady 2-D block, default outputs) against the transient scene with 1, 10 and 1,000
passes 83 ms apart (history outputs at the surface and 0.1, 0.5 mm; the constant schedule superposes one
pass's response, :func:`railtherm_fdm.history.superposed_history`).

Each case is timed interleaved with the others (best and median in one process); the ratios are recorded
(``extra_info``), not asserted: timings are measured, never test verdicts. Run:
``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fdm_transient_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s -n 0``.
"""
from __future__ import annotations

import statistics
import time

import pytest

import railtherm
from transient_scenes import transient_scene



def scene(passes: int | None) -> dict:
    """The rail heated by a given Hertzian band; ``passes`` None: the steady scene."""
    return transient_scene(f"fdm-band-{passes}", passes)


def interleaved(counts, reps: int = 5) -> dict:
    """Best and median wall time [s] of each case, the cases interleaved in every round."""
    cases = {n: scene(n) for n in counts}
    for sc in cases.values():
        railtherm.solve(sc, "fastsim-fdm", level=2)                 # numba and imports once
    times = {n: [] for n in counts}
    for _ in range(reps):
        for n, sc in cases.items():
            t0 = time.perf_counter()
            railtherm.solve(sc, "fastsim-fdm", level=2)
            times[n].append(time.perf_counter() - t0)
    return {n: (min(v), statistics.median(v)) for n, v in times.items()}


@pytest.mark.benchmark
def test_benchmark_fdm_transient(benchmark):
    benchmark.pedantic(railtherm.solve, args=(scene(10), "fastsim-fdm"), kwargs={"level": 2}, rounds=3,
                       warmup_rounds=1)
    cost = interleaved((None, 1, 10, 1000))
    steady = cost[None][0]
    line = ", ".join(f"{'steady' if n is None else f'{n} passes'} {b:.3f} s (median {m:.3f})"
                     for n, (b, m) in cost.items())
    print(f"\nfastsim-fdm level 2, Hertz band: {line}; 10 passes / steady {cost[10][0] / steady:.1f}, "
          f"1000 passes / 1 pass {cost[1000][0] / cost[1][0]:.1f}")
    benchmark.extra_info.update({f"{'steady' if n is None else n}_best_s": b for n, (b, _) in cost.items()})
    benchmark.extra_info.update(ratio_10_steady=cost[10][0] / steady, ratio_1000_1=cost[1000][0] / cost[1][0])
