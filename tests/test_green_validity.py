"""Validity of the 1-D model of the "green" plugin against core's exact moving-source references.

* Péclet >= 1000: within 1 % of references.moving_source (3-D half-space, any Péclet) for the
  Ertz & Knothe ellipse, max and patch mean (the model run through ``railtherm.solve`` on its grid).
* Péclet 10..1000: the model's measured error (validity.ERROR_TABLE) is what the diagnostics report;
  the slow test recomputes rows of the table from the references.

Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_green_validity.py -q`` (add ``-m slow`` for
the slow ones).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import railtherm
from railtherm import Material
from railtherm.references.moving_source import moving_source_temperature
from railtherm_green import validity

A, B = validity.ERROR_ELLIPSE


def _exact_max_mean(v, m):
    """Max (on y = 0, refined) and ellipse mean of the exact moving Hertzian source, peak flux 1."""
    from scipy import optimize
    f = lambda x: moving_source_temperature(np.atleast_1d(x), 0.0, 0.0, (A, B), v, m, 1.0, "hertz")  # noqa: E731
    xs = np.linspace(-A, A, 81)
    i = int(np.argmax(f(xs)))
    res = optimize.minimize_scalar(lambda s: -float(f(s)[0]), bounds=(xs[i - 1], xs[i + 1]), method="bounded",
                                   options={"xatol": 1e-9 * A})
    u, wu = np.polynomial.legendre.leggauss(16)
    u, wu = 0.5 * (u + 1), 0.5 * wu
    r, wr = 1 - u * u, 2 * u * wu
    th = np.arange(48) * 2 * math.pi / 48
    R, TH = np.meshgrid(r, th, indexing="ij")
    t = moving_source_temperature(A * R * np.cos(TH), B * R * np.sin(TH), 0.0, (A, B), v, m, 1.0, "hertz")
    return -res.fun, float(np.sum(t * R * wr[:, None]) * (2 * math.pi / 48) / math.pi)


def _model(v, level=3):
    scene = {"name": "hertz-ellipse", "heat_source": {"flux": 1.0, "shape": "hertz", "semi_axes": [A, B]},
             "speed": v, "heat_partition": 1.0, "outputs": ["max_surface_temperature", "mean_contact_temperature"]}
    ds = railtherm.solve(scene, "green", level=level)
    return float(ds.max_surface_temperature[0]), float(ds.mean_contact_temperature[0])


def _check(pe, tol):
    m = Material()
    v = 2 * m.diffusivity * pe / A
    tmax, tmean = _exact_max_mean(v, m)
    gmax, gmean = _model(v)
    assert gmax == pytest.approx(tmax, rel=tol)
    assert gmean == pytest.approx(tmean, rel=tol)
    return gmax / tmax - 1, gmean / tmean - 1


def test_within_one_percent_of_moving_source_at_peclet_1000():
    """Measured (grid level 3 included): max +0.012 %, mean -0.012 %; the same check gives
    +1.66 % / -0.40 % at L = 10, +0.52 % / -0.19 % at 30, +0.15 % / -0.069 % at 100, +0.046 % / -0.028 % at 300."""
    emax, emean = _check(1000.0, 0.01)
    assert abs(emax) < 1e-3 and abs(emean) < 2e-3


@pytest.mark.slow
@pytest.mark.parametrize("pe", [3000.0, 6231.0, 18694.0])
def test_within_one_percent_of_moving_source_high_peclet(pe):
    """Péclet numbers of the Ertz & Knothe rail (30 and 90 m/s) and between."""
    _check(pe, 0.01)


def test_model_error_estimate_from_table():
    e10 = validity.model_error(10.0)
    assert e10["max_surface_temperature"] == pytest.approx(validity.ERROR_TABLE[("ellipse", "hertz", "max")][0])
    e300 = validity.model_error(300.0, shape="uniform", line=True)
    assert e300["mean_contact_temperature"] == pytest.approx(validity.ERROR_TABLE[("line", "uniform", "mean")][3])
    seq = [validity.model_error(p)["max_surface_temperature"] for p in (10, 20, 50, 200, 999)]
    assert np.all(np.diff(seq) < 0) and seq[0] > 0.015 and seq[-1] < 2e-4
    assert validity.model_error(1000.0) == {"max_surface_temperature": 0.0, "mean_contact_temperature": 0.0}
    # magnitude law of the Hertzian ellipse maximum: ~0.16/L over the whole range
    pe = np.array(validity.ERROR_TABLE["peclet"])
    e = np.array(validity.ERROR_TABLE[("ellipse", "hertz", "max")])
    slope = np.polyfit(np.log(pe), np.log(e), 1)[0]
    assert slope == pytest.approx(-1.0, abs=0.05)


def test_refusal_message_names_numbers():
    # the refusal comes from core (the declared Péclet range) with green's advice appended
    from types import SimpleNamespace
    from railtherm_green.model import GreenTemperature
    m = Material()
    scene = SimpleNamespace(wheel=m, rail=m)

    def source(speeds):
        return SimpleNamespace(grid=SimpleNamespace(a=1e-3), body_speed=speeds)

    from railtherm.solving.capabilities_check import source_refusal
    why = source_refusal(GreenTemperature(), scene, source((30.0, 0.1)))
    assert why is not None and "rail" in why and "3.53" in why and "fipy" in why
    assert source_refusal(GreenTemperature(), scene, source((30.0, 30.0))) is None


@pytest.mark.slow
@pytest.mark.parametrize("geometry,shape,pe", [("ellipse", "hertz", 10.0), ("ellipse", "hertz", 1000.0),
                                               ("ellipse", "uniform", 30.0), ("line", "hertz", 100.0),
                                               ("line", "uniform", 300.0)])
def test_error_table_regenerates(geometry, shape, pe):
    got = validity.measure_model_error(pe, geometry, shape)
    i = validity.ERROR_TABLE["peclet"].index(pe)
    for key in ("max", "mean"):
        assert got[key] == pytest.approx(validity.ERROR_TABLE[(geometry, shape, key)][i], rel=0.01)
