"""Speed of the "kalker" plugin, per stage: normal (operator set-up + FFT-preconditioned CG) and tangential
(nested semismooth Newton-GMRES) on the Ertz & Knothe ellipse (a = 5.88 mm, b = 10.54 mm, 100 kN, mu = 0.3,
G = 82 GPa, nu = 0.28) for three cases: combined creepage (xi, eta, phi) = (-2e-3, 1e-3, 0.2 1/m),
longitudinal xi = -5e-4, full slip xi = -0.05; from zero traction, with the Hertz pressure as the normal
solver's start. Grids of 50^2, 100^2, 200^2, 400^2 elements over the potential contact area (46, 92, 184, 368
across 2a and 2b with margins of 2, 4, 8, 16; square cells, as the model's for this ellipse, a/b = 0.56).

``operators = "first"`` starts each solve with empty operator caches (a study's first solve on a grid, set-up
included); ``"cached"`` keeps the grid's operators from an earlier solve, as later solves on the grid do.
``extra_info`` records the CPU time per stage [s] (``normal_setup``, ``normal_solve``, ``tangential``), the total's CPU
and wall time (``total``, ``total_wall``), iteration and product counts, whether the tangential solve ran on one half
(``mirrored``: longitudinal creepage and full slip on this y-symmetric ellipse) and the forces. :func:`compare` alternates two versions of the plugin, :func:`time_public_api`
times ``railtherm.solve`` at level 3, :func:`scaling_exponent` fits a run's ``extra_info``; docs/kalker.md ("Where
the time goes") has the per-stage tables and the scaling with N.
Run: ``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 python -m pytest
benchmarks/test_kalker_benchmark.py -m benchmark --benchmark-enable -p no:cacheprovider -n 0``.
"""
from __future__ import annotations

import importlib
import math
import os
import sys
import time

import numpy as np
import pytest

from railtherm.references.hertz import hertz_from_curvatures, hertz_pressure
from railtherm_kalker import tangential_model
from railtherm_kalker.influence import element_size, normal_operator
from railtherm_kalker.normal_solver import solve_normal
from railtherm_kalker.potential_area import hertz_curvatures, potential_area
from railtherm_kalker.tangential_model import ROLLING_ORDER, rolling_operator
from railtherm_kalker.tangential_solver import solve_tangential_nested

A, B, N, MU, G, NU = 5.88e-3, 10.54e-3, 100e3, 0.3, 82e9, 0.28
CASES = {"combined": (-2e-3, 1e-3, 0.2), "longitudinal": (-5e-4, 0.0, 0.0), "full-slip": (-0.05, 0.0, 0.0)}
#: elements per side of the potential contact area -> (elements across 2a and 2b, margin)
GRIDS = {50: (46, 2), 100: (92, 4), 200: (184, 8), 400: (368, 16)}


def solve_both(n, margin, creepage, order=ROLLING_ORDER, cached=False):
    """Normal and tangential solve; CPU time per stage [s]. ``order``: of the rolling difference (2, the model's
    default; 1, CONTACT's), for before/after pairs in one process. ``cached``: the operators of the grid are kept
    from an earlier solve (a study's later solves on the grid: no set-up) instead of computed (empty caches)."""
    if not cached:
        tangential_model.clear_operator_caches()
    e_star = G / (1 - NU)
    area = potential_area(A, B, n, margin=margin)
    X, Y = area.mesh()
    ca, cb = hertz_curvatures(A, B, N, e_star)
    hz = hertz_from_curvatures(ca, cb, N, e_star)
    w0, t0 = time.perf_counter(), time.process_time()
    conv = normal_operator(*area.shape, element_size(area.x_edges), element_size(area.y_edges), e_star)  # model's key
    t1 = time.process_time()
    ns = solve_normal(conv, ca * X ** 2 + cb * Y ** 2, area.dx * area.dy, force=N,
                      initial=hertz_pressure(X, Y, hz.a, hz.b, hz.max_pressure))
    t2 = time.process_time()
    ts = solve_tangential_nested(lambda xe, ye: rolling_operator(xe, ye, G, NU, order), area.x_edges, area.y_edges,
                                 MU * ns.pressure, creepage)
    t3, w3 = time.process_time(), time.perf_counter()
    dA = area.dx * area.dy
    return {"shape": list(area.shape), "rolling_order": order, "cached_operators": cached, "normal_setup": t1 - t0,
            "normal_solve": t2 - t1, "tangential": t3 - t2, "total": t3 - t0, "total_wall": w3 - w0,
            "mirrored": bool(ts.mirrored), "normal_iterations": ns.iterations, "normal_products": ns.products,
            "newton_steps": ts.iterations, "gmres_iterations": ts.linear_iterations,
            "coarse_newton_steps": [[list(shape), steps] for shape, steps in ts.coarse],
            "tangential_products": ts.products, "residual": ts.residual, "converged": ts.converged,
            "creep_force_x": float(ts.traction[0].sum() * dA), "creep_force_y": float(ts.traction[1].sum() * dA),
            "spin_moment": float((X * ts.traction[1] - Y * ts.traction[0]).sum() * dA),
            "stick_elements": int(ts.stick.sum()), "contact_elements": int((ns.pressure > 0).sum())}


def scaling_exponent(sizes, times) -> float:
    """Least-squares slope of log(time) against log(elements per side) [1]."""
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


@pytest.mark.benchmark
@pytest.mark.parametrize("operators", ["first", "cached"])
@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("side", list(GRIDS), ids=[f"{s}x{s}" for s in GRIDS])
def test_benchmark_kalker_ertz_knothe(benchmark, side, case, operators):
    """One solve on the grid: ``first`` computes the operators (kernels, spectra, work arrays), ``cached`` reuses
    them (a study's later solves, a friction loop, a wheelset's patches on the grid)."""
    n, margin = GRIDS[side]
    best = {}
    cached = operators == "cached"

    def run():
        out = solve_both(n, margin, CASES[case], cached=cached)
        if not best or out["total"] < best["total"]:
            best.update(out)

    solve_both(max(8, n // 4), 2, CASES[case])          # compile the sweep before timing
    if cached:
        solve_both(n, margin, CASES[case])              # the grid's operators
    benchmark.pedantic(run, rounds=3 if side <= 100 else (2 if side <= 200 else 1), iterations=1)
    assert best["shape"] == [side, side] and best["converged"]
    benchmark.extra_info.update(best)
    benchmark.extra_info["OPENBLAS_NUM_THREADS"] = os.environ.get("OPENBLAS_NUM_THREADS", "unset")
    assert math.hypot(best["creep_force_x"], best["creep_force_y"]) < MU * N * (1 + 1e-9)


def _plugin_modules(package):
    """The modules of a copy of the plugin imported as ``package`` (a directory on sys.path): influence,
    normal_solver, tangential_model, tangential_solver, potential_area."""
    return [importlib.import_module(f"{package}.{m}") for m in
            ("influence", "normal_solver", "tangential_model", "tangential_solver", "potential_area")]


def _solve_with(mods, n, margin, creepage, cached):
    """solve_both's first or cached solve with the given plugin modules: CPU times (total, normal, tangential) [s],
    forces, tangential products, total wall time [s]."""
    inf, nsm, tm, tsm, pa = mods
    if not cached:
        inf.normal_operator.cache_clear()
        tm._rolling_operator.cache_clear()
        getattr(tm, "clear_operator_caches", lambda: None)()
    e_star = G / (1 - NU)
    area = pa.potential_area(A, B, n, margin=margin)
    X, Y = area.mesh()
    ca, cb = pa.hertz_curvatures(A, B, N, e_star)
    hz = hertz_from_curvatures(ca, cb, N, e_star)
    w0, t0 = time.perf_counter(), time.process_time()
    conv = inf.normal_operator(*area.shape, inf.element_size(area.x_edges), inf.element_size(area.y_edges), e_star)
    ns = nsm.solve_normal(conv, ca * X ** 2 + cb * Y ** 2, area.dx * area.dy, force=N,
                          initial=hertz_pressure(X, Y, hz.a, hz.b, hz.max_pressure))
    t1 = time.process_time()
    ts = tsm.solve_tangential_nested(lambda xe, ye: tm.rolling_operator(xe, ye, G, NU), area.x_edges, area.y_edges,
                                     MU * ns.pressure, creepage)
    t2, w2 = time.process_time(), time.perf_counter()
    dA = area.dx * area.dy
    forces = (float(ts.traction[0].sum() * dA), float(ts.traction[1].sum() * dA),
              float((X * ts.traction[1] - Y * ts.traction[0]).sum() * dA))
    return t2 - t0, t1 - t0, t2 - t1, forces, ts.products, w2 - w0


def compare(before_package, sides, cases, repetitions, cached=False):
    """Before / after pairs alternated in one process: the plugin copy importable as ``before_package`` against the
    installed plugin, best CPU time of ``repetitions`` per version (and the best wall time), printed with the
    forces' largest difference (relative to |F|, the spin moment to |F| a)."""
    versions = {"before": _plugin_modules(before_package), "after": _plugin_modules("railtherm_kalker")}
    for side in sides:
        n, margin = GRIDS[side]
        for case in cases:
            for mods in versions.values():                       # compile and warm up
                _solve_with(mods, max(8, n // 4), 2, CASES[case], False)
                _solve_with(mods, n, margin, CASES[case], False)
            runs = {k: [] for k in versions}
            for _ in range(repetitions):
                for k, mods in versions.items():
                    runs[k].append(_solve_with(mods, n, margin, CASES[case], cached))
            b, a = min(runs["before"]), min(runs["after"])
            bw, aw = (min(r[5] for r in runs[k]) for k in ("before", "after"))
            scale = math.hypot(b[3][0], b[3][1])
            diff = max(abs(a[3][0] - b[3][0]), abs(a[3][1] - b[3][1]), abs(a[3][2] - b[3][2]) / A) / scale
            print(f"{side}^2 {case:12s} before {b[0]:.4f} ({b[1]:.4f} / {b[2]:.4f}) after {a[0]:.4f} ({a[1]:.4f} / "
                  f"{a[2]:.4f}) ratio {a[0] / b[0]:.2f}, wall {bw:.4f} -> {aw:.4f}, products {b[4]} -> {a[4]}, "
                  f"forces {diff:.1e}", flush=True)


def time_public_api(cases, repetitions):
    """``railtherm.solve(scene, "kalker", 3)`` on the E&K ellipse (144 x 144 elements), creep forces and spin moment
    only, the operator caches emptied before each solve: best CPU (and wall) time [s] of ``repetitions`` per case,
    printed with the forces. The plugin is the one first on the path (a copy named railtherm_kalker on PYTHONPATH for "before")."""
    import railtherm  # here: the benchmarks above need only the plugin's modules
    from railtherm import load_scene
    from railtherm.testing import canonical
    from railtherm_kalker import influence
    for case in cases:
        xi, eta, phi = CASES[case]
        scene = load_scene(canonical("ellipse-creepage", normal_force=N,
                                     contact={"shape": "ellipse", "semi_axes": [A, B]},
                                     creepage={"longitudinal": xi, "lateral": eta, "spin": phi},
                                     outputs=["creep_force_x", "creep_force_y", "spin_moment"]))
        railtherm.solve(scene, "kalker", 3)
        best = best_wall = math.inf
        for _ in range(repetitions):
            influence.normal_operator.cache_clear()
            tangential_model._rolling_operator.cache_clear()
            getattr(tangential_model, "clear_operator_caches", lambda: None)()
            w0, t0 = time.perf_counter(), time.process_time()
            ds = railtherm.solve(scene, "kalker", 3)
            best = min(best, time.process_time() - t0)
            best_wall = min(best_wall, time.perf_counter() - w0)
        print(f"{case:12s} best {best:.4f} s (wall {best_wall:.4f} s), Fx {float(ds['creep_force_x']):.9e} Fy {float(ds['creep_force_y']):.9e} "
              f"Mz {float(ds['spin_moment']):.9e}", flush=True)


if __name__ == "__main__":
    # before / after pairs: python benchmarks/test_kalker_benchmark.py DIR PACKAGE SIDES CASES REPETITIONS [cached],
    # DIR holding a copy of plugins/railtherm_kalker renamed PACKAGE (e.g. /tmp/k railtherm_kalker_before 100,200
    # full-slip,combined 9); the public API: python benchmarks/test_kalker_benchmark.py --api CASES REPETITIONS
    if sys.argv[1] == "--api":
        time_public_api(sys.argv[2].split(","), int(sys.argv[3]))
    else:
        sys.path.insert(0, sys.argv[1])
        compare(sys.argv[2], [int(x) for x in sys.argv[3].split(",")], sys.argv[4].split(","), int(sys.argv[5]),
                cached=len(sys.argv) > 6 and sys.argv[6] == "cached")
