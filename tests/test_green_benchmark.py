"""Speed of the "green" temperature model: the full Ertz & Knothe patch at 216 x 45 cells, both bodies.

Target: <= 1 ms per call (surface temperature of wheel and rail, max and mean; no depth field, no
steady state). The product runs in a numba loop (single-threaded); compile time is excluded by a
warm-up call. Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_green_benchmark.py -m benchmark
--benchmark-enable``. Measured on the project machine (2 cores, load average ~8 from other jobs,
OPENBLAS_NUM_THREADS=1): min 0.31 ms, median 0.33 ms (mean 0.74 ms: preemption outliers).
"""
from __future__ import annotations

import math
import os
from types import SimpleNamespace

import numpy as np
import pytest

from railtherm import HeatSource, Material, SurfaceGrid
from railtherm.references.flash import flash_max_hertz_coefficient
from railtherm_green.model import GreenTemperature
from railtherm.physics import equal_temperature_partition


@pytest.mark.benchmark
def test_benchmark_ertz_knothe_patch_216x45(benchmark):
    a, b, n = 5.88e-3, 10.54e-3, 100e3
    p0 = 3 * n / (2 * math.pi * a * b)
    grid = SurfaceGrid(np.linspace(-a, a, 217), np.linspace(-b, b, 46), a, b)
    X, Y = grid.mesh()
    q = 0.3 * 1.0 * p0 * np.sqrt(np.clip(1 - (X / a) ** 2 - (Y / b) ** 2, 0, None))
    steel = Material()
    eps = equal_temperature_partition(steel, steel, 31.0, 30.0)
    source = HeatSource(grid, q, eps, (31.0, 30.0), 0.3 * n)
    scene = SimpleNamespace(name="ek", wheel=steel, rail=steel, convection=0.0, wheel_radius=0.46,
                            outputs=("max_surface_temperature", "mean_contact_temperature", "surface_temperature"))
    model = GreenTemperature()
    opts = model.resolve_options({})
    model.compute_temperature(scene, source, 0, opts)        # warm-up: numba compile / cache load
    field = benchmark(model.compute_temperature, scene, source, 0, opts)
    assert field.surface_temperature.shape == (2, 216, 45)
    exact = flash_max_hertz_coefficient() * eps * q.max() / steel.effusivity * math.sqrt(a / 31.0)
    err = abs(float(field.max_surface_temperature.max()) - exact) / exact
    benchmark.extra_info.update({"max_surface_temperature": float(field.max_surface_temperature.max()),
                                 "rel_error_max_vs_closed_form": err, "cells": "216x45x2",
                                 "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
                                 "NUMBA_NUM_THREADS": os.environ.get("NUMBA_NUM_THREADS", "unset")})
    assert err < 1e-3
