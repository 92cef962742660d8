"""Cost of fipy's extended field, through ``railtherm.solve`` (given heat source, dataset built
and validated), rail only, a = 5 mm, Péclet 1000, Hertzian flux: patch only against ``field`` with the
thermal trace.

* 2-D, Jaeger's band, level 2: patch only against ``behind = 30a, depth = 0.3 mm`` (the mesh's uniform
  cells run through the trail: 1 024 instead of 32 cells along x; LU);
* 3-D, the circle, level 1: patch only against ``behind = 16a, depth = 0.3 mm`` (about 6x the cells;
  GMRES + ILU).

No target is set for fipy (only what it costs is asked). Measured (this machine, shared, 2
cores, best of 3): 2-D band level 2: patch only 52 ms, field 519 ms (ratio 10: 32x the cells along x,
one LU); 3-D circle level 1: patch only 0.76 s, field 3.9 s (ratio 5.1). At load ~1 (session 4): band 49 ->
407 ms (8.3), circle 0.45 -> 3.1 s (6.9).
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fipy_field_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s``.
"""
from __future__ import annotations

import pytest

import railtherm
from field_costs import A, best, scenes


@pytest.mark.benchmark
@pytest.mark.parametrize("line, behind, level", [(True, 30 * A, 2), (False, 16 * A, 1)], ids=["band-2d", "circle-3d"])
def test_benchmark_fipy_extended_field(benchmark, line, behind, level):
    base, field = scenes(None if line else 1.0, behind)
    benchmark.pedantic(railtherm.solve, args=(field, "fipy", level), rounds=1, iterations=1)
    patch, extended = best(base, "fipy", level), best(field, "fipy", level)
    print(f"fipy {'2-D band' if line else '3-D circle'} level {level}: patch only {patch * 1e3:.0f} ms, field "
          f"behind = {behind / A:g}a, depth 0.3 mm {extended * 1e3:.0f} ms, ratio {extended / patch:.2f}")
    benchmark.extra_info.update(patch_only_s=patch, field_s=extended, ratio=extended / patch)
