"""The exact history a transient scene's runs are scored against (railtherm.analysis.transient_metrics) is
computed once per time for all the scene's runs: the cached values equal a fresh computation bit for bit, and
only the times not asked before are computed."""
from __future__ import annotations

import numpy as np

from railtherm.analysis.transient_metrics import _cached_history
from railtherm.input.materials import Material
from railtherm.references.transient import MovingSource, Schedule, temperature_history

STEEL = Material()


def test_cached_history_equals_a_fresh_one_and_computes_each_time_once():
    src = MovingSource("band", 6e-3, 30.0, 1e8, "hertz")
    d = src.contact_duration
    sched = Schedule((1.0 * d, 1.2 * d, 1.6 * d), (1.0, 2.0, 1.0))
    z = np.array([0.0, 1e-4])
    asked = []

    def compute(times):
        asked.append(np.array(times))
        return temperature_history(times, z, src, STEEL, 2, 3 * d, sched, quad_points=8, inner_points=24)
    cache: dict = {}
    first = np.linspace(0.0, 6 * d, 41)
    second = np.linspace(0.0, 6 * d, 61)               # shares 21 of its times with the first axis
    a = _cached_history(cache, "k", first, compute)
    b = _cached_history(cache, "k", second, compute)
    np.testing.assert_array_equal(a, compute(first))
    np.testing.assert_array_equal(b, compute(second))
    assert asked[0].size == 41 and asked[1].size == 61 - np.intersect1d(first, second).size
    assert _cached_history(None, "k", first, compute).shape == (41, 2)
