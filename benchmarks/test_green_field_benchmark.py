"""Cost of green's extended field: Hertzian sources at Péclet 1000 (a = 5 mm, rail only), level 2 (128 cells
along x on the patch), surface and depth temperature, solved through ``railtherm.solve`` (given heat source,
dataset built and validated), patch only against ``field = {behind = 12a, depth}`` with the thermal trace (the
peak at 0.3 mm lies 3.7 a behind the centre, its fastest cooling ~3 times further: 12a is what the trace at
0.3 mm needs). Cases: the circle at depth 0.3 mm and an ellipse a/b = 0.5 at depths 0.3 mm and 2 mm.

Target: extended <= 2 x patch-only. The ratio is recorded (``extra_info``), not asserted: timings are measured,
never test verdicts. Run after other benchmarks in the same process, the field costs less (its arrays reuse
freed pages instead of faulting in fresh ones): time it in a fresh process. docs/NOTES.md, "Benchmarks", has a
measurement.
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_green_field_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s``.
"""
from __future__ import annotations

import pytest

import railtherm
from field_costs import A, best_pair, scenes


@pytest.mark.benchmark
@pytest.mark.parametrize("b_over_a, depth", [(1.0, 3e-4), (2.0, 3e-4), (2.0, 2e-3)],
                         ids=["circle-0.3mm", "ellipse-0.3mm", "ellipse-2mm"])
def test_benchmark_green_extended_field(benchmark, b_over_a, depth):
    base, field = scenes(b_over_a, 12 * A, depth)
    benchmark(railtherm.solve, field, "green", level=2)
    patch, extended = best_pair(base, field, "green", 2)
    print(f"green level 2, b/a = {b_over_a:g}, depth {depth * 1e3:g} mm: patch only {patch * 1e3:.1f} ms, field "
          f"behind = 12a {extended * 1e3:.1f} ms, ratio {extended / patch:.2f}")
    benchmark.extra_info.update(patch_only_s=patch, field_s=extended, ratio=extended / patch)
