"""Cost of fastsim-fdm's extended field (issue 14): the Hertzian circle at Péclet 1000 (a = 5 mm, rail
only, given heat source), level 2, surface and depth temperature through ``railtherm.solve``; patch only
against ``field = {behind = 12a, depth = 0.3 mm}`` with the thermal trace (the same case as
benchmarks/test_green_field_benchmark.py).

With the field the 3-D block runs its moving-frame steady scheme on a grid that follows the trail (the
uniform explicit grid of the patch-only ``auto`` run does not resolve the 0.16 mm thermal layer), so two
ratios are measured: against the patch-only steady run (same scheme: the cost of the trail cells) and
against the patch-only ``auto`` run (explicit). Measured (this machine, shared, 2 cores): patch only steady
113 ms (49 x 24 x 54 cells), patch only auto/explicit 46 ms, field 894 ms (141 x 54 x 78 = 5.9e5 cells:
x 3 along x for the trail, x 1.5 in depth, GMRES on the larger grid): ratio 7.9 (same scheme), 19 (auto).
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fdm_field_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -s``.
"""
from __future__ import annotations

import time

import pytest

import railtherm

A = 5e-3
MAT = railtherm.Material()
V = 1000.0 * 2.0 * MAT.diffusivity / A
BASE = dict(name="circle", speed=V, heat_source=dict(flux=1e9, shape="hertz", semi_axes=[A, A]), heat_partition=0.0,
            outputs=["surface_temperature", "temperature", "max_surface_temperature"])
FIELD = dict(BASE, field=dict(behind=12 * A, depth=3e-4, threshold=1000.0),
             outputs=BASE["outputs"] + ["peak_temperature", "cooling_rate", "heated_depth", "time_above"])
LEVEL = 2


def _best(scene, options=None, n=3):
    railtherm.solve(scene, "fastsim-fdm", level=LEVEL, options=options)     # warm-up (numba, caches)
    best = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        railtherm.solve(scene, "fastsim-fdm", level=LEVEL, options=options)
        best = min(best, time.perf_counter() - t0)
    return best


@pytest.mark.benchmark
def test_extended_field_cost_ratio():
    """Measured ratios (printed): 7.9 against the steady patch-only run; bound 15 (shared machine)."""
    steady = _best(BASE, {"scheme": "steady"})
    auto = _best(BASE)
    field = _best(FIELD)
    print(f"fdm patch only steady {steady * 1e3:.0f} ms, patch only auto (explicit) {auto * 1e3:.0f} ms, "
          f"field 12a x 0.3 mm {field * 1e3:.0f} ms: ratio {field / steady:.2f} (same scheme), "
          f"{field / auto:.2f} (auto)")
    assert field < 15 * steady


@pytest.mark.benchmark
def test_extended_field(benchmark):
    railtherm.solve(FIELD, "fastsim-fdm", level=LEVEL)
    ds = benchmark.pedantic(railtherm.solve, args=(FIELD, "fastsim-fdm"), kwargs={"level": LEVEL}, rounds=3,
                            iterations=1)
    assert ds.attrs["fdm_rail_scheme"] == "steady"
