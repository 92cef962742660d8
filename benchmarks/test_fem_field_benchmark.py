"""Cost of the FEM's extended field: Jaeger's Hertzian band at Péclet 1000 (a = 5 mm, rail
only, given heat source; the FEM is 2-D: line contacts only), through ``railtherm.solve``, patch only
against ``field = {behind = 30a, depth = 0.3 mm}`` with the thermal trace (the case of
tests/test_fem_field.py). The FEM's thermal layer always reaches 32a behind the centre (its default
strip), so the field adds the depth resolution the trace asks for and the trace itself, not a longer
domain. Measured as process CPU time (this machine, 2 cores, OPENBLAS_NUM_THREADS=1; the wall time at a load
of 5 was 3-40x that): level 1 patch only and field about 14 ms each; level 2 13 -> 24 ms (ratio 1.8). The
ratios are printed and recorded in
``extra_info`` (not asserted: timings are measured, never verdicts).
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fem_field_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s``.
"""
from __future__ import annotations

import pytest

import railtherm
from field_costs import A, best, scenes


@pytest.mark.benchmark
@pytest.mark.parametrize("level", [1, 2])
def test_benchmark_fem_extended_field(benchmark, level):
    base, field = scenes(None, 30 * A)
    benchmark.pedantic(railtherm.solve, args=(field, "fem", level), rounds=1, iterations=1)
    patch, extended = best(base, "fem", level), best(field, "fem", level)
    print(f"fem 2-D band level {level}: patch only {patch * 1e3:.0f} ms, field behind = 30a, depth 0.3 mm "
          f"{extended * 1e3:.0f} ms, ratio {extended / patch:.2f}")
    benchmark.extra_info.update(patch_only_s=patch, field_s=extended, ratio=extended / patch)
