"""Speed of the Manchester benchmark A-2.2 on real profiles: all 42 contacts (21 wheelset positions x both wheels)
from the scene keys, each one contact search and the exact chain (``kalker`` normal and tangential, frictional
heat, ``green`` temperatures), on two worker processes; and the contact search alone per wheel.

Targets: the 42 contacts in <= 20 s on 2 cores (exact normal + tangential at a 0.2 mm grid, green temperatures);
the contact search <= 5 ms per wheel. The contacts are solved at level 2, the level tests/test_manchester.py checks
against CONTACT's published results; its grids are finer than CONTACT's 0.2 mm (more elements in contact at the
three published contacts), so the timing is an upper bound for a 0.2 mm grid. Records (``extra_info``): the wall
time of the 42 contacts after one warm-up contact per worker, the warm-up's time, the sum of the contacts' own wall
and CPU times (the CPU time tells the machine's load apart), the slowest contact, the load average; and the best
time per wheel [ms] of :func:`railtherm.physics.contact_search.contact_search` and of the whole scene set-up
(:func:`railtherm.input.scene.load_scene`). docs/NOTES.md, "Benchmarks", has a measurement.
Run: ``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 python -m pytest
benchmarks/test_manchester_benchmark.py -m benchmark --benchmark-enable -p no:cacheprovider -n 0``.
"""
from __future__ import annotations

import multiprocessing as mp
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parents[1] / "tests"
sys.path.insert(0, str(TESTS))  # the shared cases (spawned workers inherit the path)
import manchester_cases  # noqa: E402

WORKERS = 2
LEVEL = 2
OUTPUTS = ["normal_force", "creep_force_x", "creep_force_y", "max_pressure", "max_surface_temperature"]


def a22_scene(position: int, side: str) -> dict:
    """The benchmark's wheel ``side`` at ``position`` (tests/manchester_cases.py) with green's material
    constants and the outputs timed here."""
    return dict(manchester_cases.a22_scene(position, side, density=7850.0, specific_heat=450.0, conductivity=50.0,
                                           bulk_temperature=0.0), outputs=OUTPUTS)


CONTACTS = [(p, side) for p in range(1, 22) for side in ("right", "left")]


def _contact(case) -> tuple[float, float, float]:
    """One contact from its scene keys: (wall and CPU seconds for search + solve, max surface temperature
    [degC])."""
    import railtherm
    from railtherm.input.scene import load_scene
    t0, c0 = time.perf_counter(), time.process_time()
    ds = railtherm.solve(load_scene(a22_scene(*case)), "kalker", level=LEVEL)
    return time.perf_counter() - t0, time.process_time() - c0, float(ds["max_surface_temperature"].max())


def _warm(_) -> float:
    return _contact((13, "right"))[0]


@pytest.mark.benchmark
def test_a22_all_contacts_two_workers(benchmark):
    for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ.setdefault(k, "1")    # the workers share two cores: one thread each
    with ProcessPoolExecutor(WORKERS, mp_context=mp.get_context("spawn")) as pool:
        warm = list(pool.map(_warm, range(WORKERS)))

        def run():
            return list(pool.map(_contact, CONTACTS))
        t0 = time.perf_counter()
        results = benchmark.pedantic(run, rounds=1, iterations=1)
        wall = time.perf_counter() - t0
    own = [r[0] for r in results]
    benchmark.extra_info.update({"contacts": len(results), "workers": WORKERS, "level": LEVEL, "wall_time": wall,
                                 "warm_up": max(warm), "sum_contact_time": sum(own), "slowest_contact": max(own),
                                 "sum_contact_cpu": sum(r[1] for r in results),
                                 "load_average": os.getloadavg()[0]})
    assert len(results) == 42 and all(r[2] > 0.0 for r in results)


@pytest.mark.benchmark
def test_a22_contact_search_per_wheel(benchmark):
    from railtherm.input.profiles import wheelset_geometry_from_table
    from railtherm.input.scene import load_scene
    from railtherm.input.wheelset_profile import SECTION_HALF_WIDTH
    from railtherm.physics.contact_search import contact_search
    maps = [a22_scene(*c) for c in CONTACTS]
    geos = [wheelset_geometry_from_table(m["name"], m["wheelset"]).on_track() for m in maps]
    sides = [m["wheelset"]["side"] for m in maps]

    def search_all():
        for g, side in zip(geos, sides):
            contact_search(g, side, speed=2.0, section_half_width=SECTION_HALF_WIDTH)
    benchmark.pedantic(search_all, rounds=5, iterations=1, warmup_rounds=1)
    search = benchmark.stats.stats.min / len(geos)
    c0 = time.process_time()
    search_all()
    search_cpu = (time.process_time() - c0) / len(geos)
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        for m in maps:
            load_scene(m)
        best = min(best, (time.perf_counter() - t0) / len(maps))
    benchmark.extra_info.update({"search_ms_per_wheel": search * 1e3, "search_cpu_ms_per_wheel": search_cpu * 1e3,
                                 "scene_setup_ms_per_wheel": best * 1e3, "load_average": os.getloadavg()[0]})
    assert search > 0.0
