"""Cost of green's extended field (issue 14): Hertzian sources at Péclet 1000 (a = 5 mm, rail only), level 2
(128 cells along x on the patch), surface and depth temperature, solved through ``railtherm.solve`` (given
heat source, dataset built and validated), patch only against ``field = {behind = 12a, depth}`` with the
thermal trace (the peak at 0.3 mm lies 3.7 a behind the centre, its fastest cooling ~3 times further: 12a
is what the trace at 0.3 mm needs). Cases: the circle at depth 0.3 mm (the issue's case) and an ellipse
a/b = 0.5 at depths 0.3 mm and 2 mm.

Target: extended <= 2 x patch-only. History (this machine, 2 cores, best of 15, interleaved), circle at
0.3 mm: before issue 14's speed work patch only 7.5-8.0 ms, field 24.5 ms (ratio 3.1-3.3); FFT over the heated
rows, depth weights in one numba pass, thermal trace vectorised: 2.2-2.4. Then (profiled, the field's own
cost): the surface sum behind the patch by :func:`railtherm_green.kernel.trail_toeplitz` (far trail by rank-24
Chebyshev interpolation, 3.2 -> 0.8 ms on the ellipse's 896 x 256 cells), the thermal trace in one numba
pass (1.7 -> 0.4 ms), and core's long-grid overheads (``embed`` without ``np.pad``, ``inside()`` on the
patch rows only, ``from_bodies`` without temporaries, ``validate_dataset``'s finiteness by a sum): circle
4.8-4.9 -> 8.5-9.0 ms (1.77-1.84), ellipse 0.3 mm 7.0-7.5 -> 12.9-14.4 ms (1.85-1.93), ellipse 2 mm
7.2-7.6 -> 13.5-14.5 ms (1.87-1.93). Run after other benchmarks in the same process (e.g. this directory's
whole field set) the field takes only 7.0-10.8 ms (ratio 1.43-1.49): the field's arrays (3.7 MB on the ellipse)
are then reused by the allocator instead of fresh pages (glibc raises its mmap threshold after a large block is
freed), i.e. part of the field's cost in a fresh process is page faults. The ratio is recorded
(``extra_info``), not asserted: timings are measured, never test verdicts. Run:
``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_green_field_benchmark.py -m benchmark
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
