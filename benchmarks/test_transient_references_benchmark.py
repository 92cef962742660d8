"""Cost of core's exact transient references per history sample, the work of a transient study's metrics phase
(railtherm.analysis.transient_metrics scores every run's history against them at the run's own times): the
study's wheel spin (Hertzian band, a = 5.88 mm, 30 m/s, 3 revolutions 91 ms apart, the heat ramped up over 5 ms
and down at 0.2 s) and slip event (a = 6 mm, 4 passes 83 ms apart, the heat doubled for 0.4 ms on the second),
at the surface and 0.1, 0.5, 1 mm, 1,000 sample times each, with the metrics' quadrature (8 points per graded
panel, 24 inner points); and Jaeger's steady band on 10,000 points behind and under it (the passes' steady
sweeps). Recorded (``extra_info``): milliseconds per sample, not asserted (timings are measured, never test
verdicts). Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest benchmarks/test_transient_references_benchmark.py
-m benchmark --benchmark-enable -p no:cacheprovider -s -n 0``.
"""
from __future__ import annotations

import numpy as np
import pytest

from railtherm.input.materials import Material
from railtherm.references.jaeger import jaeger_band_temperature
from railtherm.references.transient import MovingSource, Schedule, temperature_history

STEEL = Material()
DEPTHS = [0.0, 1e-4, 5e-4, 1e-3]
QUAD = dict(quad_points=8, inner_points=24)
SAMPLES = 1000
CASES = {
    "wheel-spin": (MovingSource("band", 5.88e-3, 30.0, 1e8, "hertz"), 3, 0.091,
                   Schedule((0.0, 0.005, 0.195, 0.2), (0.0, 1.0, 1.0, 0.0))),
    "slip-event": (MovingSource("band", 6e-3, 30.0, 1e8, "hertz"), 4, 0.083,
                   Schedule((0.0, 0.083, 0.0832, 0.0836, 0.0838), (1.0, 1.0, 2.0, 2.0, 1.0))),
}


@pytest.mark.benchmark
@pytest.mark.parametrize("case", list(CASES))
def test_benchmark_exact_history_per_sample(benchmark, case):
    src, count, interval, sched = CASES[case]
    t = np.sort(np.random.default_rng(0).uniform(0.0, count * interval, SAMPLES))
    temperature_history(t[:5], DEPTHS, src, STEEL, count, interval, sched, **QUAD)      # numba compiled/loaded
    out = benchmark.pedantic(temperature_history, args=(t, DEPTHS, src, STEEL, count, interval, sched),
                             kwargs=QUAD, rounds=3, iterations=1)
    assert out.shape == (SAMPLES, len(DEPTHS)) and np.all(np.isfinite(out))
    benchmark.extra_info.update(ms_per_sample=1e3 * benchmark.stats.stats.min / SAMPLES, samples=SAMPLES,
                                depths=len(DEPTHS))


@pytest.mark.benchmark
def test_benchmark_jaeger_sweep(benchmark):
    a = 5.88e-3
    x = a * np.concatenate([np.linspace(-40.0, -1.0, 8000), np.linspace(-1.0, 1.0, 2000)])
    z = np.resize(np.array(DEPTHS), x.size)
    out = benchmark.pedantic(jaeger_band_temperature, args=(x, z, a, 30.0, STEEL, 1e8, "hertz"), rounds=3,
                             iterations=1)
    assert np.all(np.isfinite(out))
    benchmark.extra_info.update(us_per_point=1e6 * benchmark.stats.stats.min / x.size)
