"""Jaeger's moving band (railtherm.references.jaeger) graded toward each field point only as far as its nearest
singularity or steepest scale needs (jaeger._grading): the same temperatures as the rules graded fully (to 1e-16)
for every point, from Péclet 0.01 to 1e5, uniform and Hertzian flux, on the band's surface, ahead of it, under it
and far behind at depth; and the grading does carry the accuracy where the point sits on the band."""
from __future__ import annotations

import numpy as np
import pytest

from railtherm.input.materials import Material
from railtherm.references import jaeger as J

STEEL = Material()
A = 6e-3


def _points(rng, n=3000):
    x = A * np.concatenate([rng.uniform(-200.0, 3.0, n), rng.uniform(-1.02, 1.02, n), [-1.0, 1.0, 0.0]])
    z = A * np.concatenate([10.0 ** rng.uniform(-6.0, 1.3, n), np.zeros(n + 3)])
    rng.shuffle(z)
    return x, z


@pytest.mark.parametrize("shape", ["uniform", "hertz"])
@pytest.mark.parametrize("pe", [0.01, 1.0, 10.0, 300.0, 7000.0, 1e5])
def test_graded_to_the_singularity_equals_the_fully_graded_band(pe, shape, monkeypatch):
    """Pointwise within 1e-14 (relative, where the rise is above 1e-8 of its largest) and within 1e-15 of the
    largest rise everywhere."""
    speed = pe * 2.0 * STEEL.diffusivity / A
    x, z = _points(np.random.default_rng(int(pe * 100) + len(shape)))
    got = J.jaeger_band_temperature(x, z, A, speed, STEEL, 1e8, shape)
    monkeypatch.setattr(J, "_grading", lambda xi, zeta, p: [np.full(xi.shape, -16), np.full(xi.shape, -16)])
    full = J.jaeger_band_temperature(x, z, A, speed, STEEL, 1e8, shape)
    scale = np.max(np.abs(full))
    assert np.max(np.abs(got - full)) <= 1e-15 * scale
    big = np.abs(full) > 1e-8 * scale
    assert np.max(np.abs(got[big] / full[big] - 1.0)) <= 1e-14


def test_grading_follows_the_distance_and_is_full_on_the_band():
    """On the band's surface (zeta = 0, |xi| <= 1) both sides are graded to 1e-16; far behind at depth only a few
    panels; 1e-1 (no grading) to 1e-16 the only exponents."""
    lo, hi = J._grading(np.array([0.3, -1.0, -50.0, 0.3]), np.array([0.0, 0.0, 2.0, 1e-3]), 7000.0)
    assert lo[0] == hi[0] == -16 and lo[1] == hi[1] == -16
    assert lo[2] >= -6 and hi[2] >= -6
    assert -16 < lo[3] < -5
    for e in (lo, hi):
        assert np.all((e <= -1) & (e >= -16))


def test_coarse_grading_on_the_band_would_miss(monkeypatch):
    """The grading carries the accuracy: graded to only 1e-2 at the pivot, points on the band's surface miss
    the fully graded temperatures by more than 1e-6 of the largest (the log singularity of K0 there)."""
    x = A * np.linspace(-0.95, 0.95, 41)
    z = np.zeros_like(x)
    full = J.jaeger_band_temperature(x, z, A, 30.0, STEEL, 1e8, "uniform")
    monkeypatch.setattr(J, "_grading", lambda xi, zeta, p: [np.full(xi.shape, -2), np.full(xi.shape, -2)])
    coarse = J.jaeger_band_temperature(x, z, A, 30.0, STEEL, 1e8, "uniform")
    assert np.max(np.abs(coarse - full)) > 1e-6 * np.max(np.abs(full))
