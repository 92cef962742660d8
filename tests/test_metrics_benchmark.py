"""Speed of the verdict machinery: the energy balance of one result and the metrics of a study.

Run: ``python -m pytest tests/test_metrics_benchmark.py -m benchmark --benchmark-enable``.
The energy balance is on the run's hot path (the worker computes it for every run), so it must stay
well below the solve it checks: a level-3 green result of the Ertz & Knothe ellipse has 64 x 115
cells per body at level 1 and 256 x 459 at level 3.
"""
from __future__ import annotations

import pytest

import railtherm
from railtherm.analysis.metrics import energy_balance
from railtherm.physics import body_speeds
from studies import ellipse_scene


def _scene(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text("""
schema_version = 1
[study]
name = "bench"
[defaults.wheel]
shear_modulus = 82e9
poisson_ratio = 0.28
""" + ellipse_scene() + """outputs = ["max_surface_temperature", "surface_temperature", "frictional_power"]
""")
    return railtherm.load_study(p).scenes[0]


@pytest.mark.benchmark
@pytest.mark.parametrize("level", [1, 3])
def test_benchmark_energy_balance(benchmark, tmp_path, level):
    sc = _scene(tmp_path)
    ds = railtherm.solve(sc, "green", level)
    speeds = body_speeds(sc.speed, sc.sliding_speed, sc.tangential)
    e, ref = benchmark(energy_balance, ds, speeds, sc.wheel, sc.rail)
    benchmark.extra_info.update(energy_balance=e, reference=ref, cells=int(ds.sizes["x"] * ds.sizes["y"]))
    assert ref == "analytic:half-space-1d" and abs(e) < 2e-3
