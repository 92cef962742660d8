"""Cost of fastsim-fdm's extended field: the Hertzian circle at Péclet 1000 (a = 5 mm, rail only, given heat
source), level 2, surface and depth temperature through ``railtherm.solve``; patch only against
``field = {behind = 12a, depth = 0.3 mm}`` with the thermal trace (the case of
benchmarks/test_green_field_benchmark.py).

With the field the 3-D block runs its moving-frame steady scheme on a grid that follows the trail (the uniform
explicit grid of the patch-only ``auto`` run does not resolve the 0.16 mm thermal layer), so two ratios are
measured: against the patch-only steady run (same scheme: the cost of the trail cells) and against the patch-only
``auto`` run (explicit). The ratios are printed and recorded (``extra_info``), not asserted: timings are
measured, never verdicts (docs/NOTES.md, "Benchmarks", has a measurement). ``test_seed_paper_level3`` times the
main study's two costliest fdm runs.
Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_fdm_field_benchmark.py -m benchmark
--benchmark-enable -p no:cacheprovider -n 0 -s``.
"""
from __future__ import annotations

import pytest

import railtherm
from field_costs import A, best, scenes

BASE, FIELD = scenes(1.0, 12 * A)
LEVEL = 2


@pytest.mark.benchmark
def test_extended_field_cost_ratio(benchmark):
    steady = best(BASE, "fastsim-fdm", LEVEL, options={"scheme": "steady"})
    auto = best(BASE, "fastsim-fdm", LEVEL)
    field = benchmark.pedantic(best, args=(FIELD, "fastsim-fdm", LEVEL), rounds=1, iterations=1)
    print(f"fdm patch only steady {steady * 1e3:.0f} ms, patch only auto (explicit) {auto * 1e3:.0f} ms, "
          f"field 12a x 0.3 mm {field * 1e3:.0f} ms: ratio {field / steady:.2f} (same scheme), "
          f"{field / auto:.2f} (auto)")
    benchmark.extra_info.update(patch_steady_s=steady, patch_auto_s=auto, field_s=field,
                                ratio_same_scheme=field / steady, ratio_auto=field / auto)


@pytest.mark.benchmark
def test_extended_field(benchmark):
    railtherm.solve(FIELD, "fastsim-fdm", level=LEVEL)
    ds = benchmark.pedantic(railtherm.solve, args=(FIELD, "fastsim-fdm"), kwargs={"level": LEVEL}, rounds=3,
                            iterations=1)
    assert ds.attrs["fdm_rail_scheme"] == "steady"


@pytest.mark.benchmark
@pytest.mark.parametrize("name", ["fdm-elliptic-q1", "fdm-circular-q10"])
def test_seed_paper_level3(benchmark, name):
    """The main study's costliest fdm runs: ``fastsim-fdm`` at level 3 on the seed paper's uniform sources
    (1 m/s, field 5 mm behind and 3 mm deep), the explicit block with cells of 78 um. Best of 3 solves
    after a warm-up, with the block's node shape and step count in ``extra_info``.

    Measured (this machine, 2 cores shared with 5 other jobs, load 4-6, one numba thread; CPU time of
    the solve): elliptic 0.46 s (308 x 193 x 44 nodes), circular 0.31 s (308 x 129 x 44 nodes), 256 steps
    each; wall time 1.5-2x that under this load.
    """
    import time
    from pathlib import Path

    scene = railtherm.load_study(Path(__file__).parents[1] / "studies" / "seed_paper.toml").scene(name)
    ds = railtherm.solve(scene, "fastsim-fdm", level=3)
    assert ds.attrs["fdm_rail_scheme"] == "explicit"

    def solve():
        t0 = time.process_time()
        railtherm.solve(scene, "fastsim-fdm", level=3)
        return time.process_time() - t0

    cpu = benchmark.pedantic(solve, rounds=3, iterations=1)          # the last round's CPU time
    print(f"fdm {name} level 3: best wall {benchmark.stats.stats.min:.2f} s, cpu (last) {cpu:.2f} s, "
          f"{ds.attrs['fdm_rail_node_shape']} nodes, {ds.attrs['fdm_rail_steps']} steps")
    benchmark.extra_info.update(node_shape=ds.attrs["fdm_rail_node_shape"], steps=int(ds.attrs["fdm_rail_steps"]),
                                cpu_s_last=cpu)
