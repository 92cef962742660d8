"""Shared set-up of the extended-field cost benchmarks (benchmarks/test_*_field_benchmark.py):
Hertzian given sources at Péclet 1000 (a = 5 mm, core's default material, all heat into the rail), solved
through ``railtherm.solve`` (dataset built and validated), patch only against ``field`` with the thermal
trace, and the best wall time of a few solves."""
from __future__ import annotations

import time

import railtherm

A = 5e-3                                     # [m]
MAT = railtherm.Material()
V = 1000.0 * 2.0 * MAT.diffusivity / A      # [m s-1]
OUT = ["surface_temperature", "temperature", "max_surface_temperature"]
TRACE = ["peak_temperature", "cooling_rate", "heated_depth", "time_above"]


def scenes(b_over_a: float | None, behind: float, depth: float = 3e-4):
    """(patch only, with field) scene mappings: a band when ``b_over_a`` is None, else an ellipse of
    semi-axes (A, b_over_a A); ``field = {behind [m], depth [m], threshold = 1000 degC}``."""
    src = dict(flux=1e9, shape="hertz",
               **({"half_width": A} if b_over_a is None else {"semi_axes": [A, b_over_a * A]}))
    name = "band" if b_over_a is None else "circle" if b_over_a == 1 else "ellipse"
    base = dict(name=name, speed=V, heat_source=src, heat_partition=0.0, outputs=OUT)
    return base, dict(base, field=dict(behind=behind, depth=depth, threshold=1000.0), outputs=OUT + TRACE)


def best(scene, method: str, level: int, n: int = 3, options=None) -> float:
    """Best wall time [s] of ``n`` solves after one warm-up (imports, numba, caches)."""
    railtherm.solve(scene, method, level=level, options=options)
    out = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        railtherm.solve(scene, method, level=level, options=options)
        out = min(out, time.perf_counter() - t0)
    return out


def best_pair(base, field, method: str, level: int, n: int = 15) -> tuple[float, float]:
    """Best wall times [s] of the patch-only and the field run, interleaved (the machine's load varies)."""
    for sc in (base, field):
        railtherm.solve(sc, method, level=level)
    out = [float("inf"), float("inf")]
    for _ in range(n):
        for i, sc in enumerate((base, field)):
            t0 = time.perf_counter()
            railtherm.solve(sc, method, level=level)
            out[i] = min(out[i], time.perf_counter() - t0)
    return out[0], out[1]
