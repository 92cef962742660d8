"""Method "fem" through railtherm.solve: given heat source, refusals, the coupled seed case.

Run: PYTHONPATH=core:plugins python -m pytest tests/test_fem_model.py -q  (seed ladders: -m slow)
"""
from __future__ import annotations

import copy
import pathlib
import tomllib

import numpy as np
import pytest

import railtherm
from railtherm.references.jaeger import jaeger_band_temperature

ROOT = pathlib.Path(__file__).resolve().parents[1]
STEEL = dict(shear_modulus=82e9, poisson_ratio=0.28, density=7850.0, specific_heat=450.0, conductivity=50.0,
             thermal_expansion=12e-6, bulk_temperature=0.0)


def seed_scene(name="seed-sliding", **over):
    study = tomllib.loads((ROOT / "studies" / "seed_fem.toml").read_text())
    sc = next(s for s in study["scene"] if s["name"] == name)
    sc = {**copy.deepcopy(sc), "wheel": dict(study["defaults"]["wheel"]), "rail": dict(study["defaults"]["rail"])}
    sc.update(over)
    return sc


def test_given_heat_source_runs_thermal_part_only():
    """A scene that gives its flux: no contact stage; rail surface temperature against Jaeger within 2 %."""
    a, q0, V = 3e-3, 2e8, 10.0
    scene = dict(name="given-band", speed=V, contact={"shape": "line", "wheel_radius": 0.46}, normal_force=1e6,
                 heat_source={"flux": q0, "shape": "hertz", "half_width": a}, heat_partition=0.5,
                 wheel=dict(STEEL), rail=dict(STEEL), outputs=["surface_temperature", "max_surface_temperature"])
    ds = railtherm.solve(scene, "fem", level=2)
    assert "pressure" not in ds and "normal_force" not in ds
    x = ds["x"].values
    ref = 0.5 * jaeger_band_temperature(x, 0 * x, a, V, railtherm.Material(**STEEL), q0, "hertz")
    T = ds["surface_temperature"].sel(body="rail").values
    assert abs(T.max() / ref.max() - 1) < 0.02
    assert np.sqrt(np.sum((T - ref) ** 2) / np.sum(ref ** 2)) < 0.02


def test_refuses_ellipse_with_reason():
    scene = dict(name="ellipse", speed=30.0, normal_force=1e5, contact={"shape": "ellipse", "semi_axes": [5e-3, 8e-3]},
                 sliding_speed=1.0, friction=0.3, wheel=dict(STEEL), rail=dict(STEEL), outputs=["max_pressure"])
    with pytest.raises(railtherm.Refused, match="line"):
        railtherm.solve(scene, "fem", level=0)


def test_small_coupled_case_converges_and_conserves_energy():
    """Rigid wheel sliding on a small strip: the Steps 1-4 loop contracts; heat on the grid = nodal power."""
    scene = dict(name="small", speed=10.0, contact={"shape": "line", "wheel_radius": 0.46}, normal_force=2e6,
                 sliding_speed=1.0, friction=0.3, heat_partition=0.5, strip={"length": 0.2, "depth": 0.1},
                 wheel={**STEEL, "rigid": True}, rail=dict(STEEL),
                 outputs=["pressure", "heat_flux", "frictional_power", "max_surface_temperature", "temperature"])
    ds = railtherm.solve(scene, "fem", level=0)
    assert ds.attrs["fem_coupling_converged"] == 1
    assert 1 <= ds.attrs["fem_coupling_iterations"] <= 15
    assert ds["temperature"].dims[0] == "body"
    hist = [float(v) for v in ds.attrs["fem_coupling_history"].split(",")]
    assert hist[-1] <= 1e-6
    # heat: mu p v_s integrated equals the reported frictional power (P1 cell averages are conservative)
    dx = float(ds["x"][1] - ds["x"][0])
    grid_power = float(ds["heat_flux"].sum("body").sum()) * dx
    assert abs(grid_power / float(ds["frictional_power"]) - 1) < 0.02


@pytest.mark.slow
def test_seed_case_converges_within_15_iterations():
    ds = railtherm.solve(seed_scene(), "fem", level=1, options={"thermal_resistance": 1000.0})
    assert ds.attrs["fem_coupling_converged"] == 1
    assert ds.attrs["fem_coupling_iterations"] <= 15


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:friction regularisation:RuntimeWarning")  # eps up to 50 |xi| on purpose
@pytest.mark.parametrize("eps", [1e-1, 1e-3, 1e-5, 1e-7, 1e-9])
@pytest.mark.parametrize("name", ["seed-sliding", "seed-rolling"])
def test_seed_case_converges_for_eps(name, eps):
    sc = seed_scene(name, numerics={"regularization": eps})
    ds = railtherm.solve(sc, "fem", level=0, options={"thermal_resistance": 1000.0})
    assert ds.attrs["fem_coupling_converged"] == 1
    assert ds.attrs["fem_coupling_iterations"] <= 15
    assert ds.attrs["fem_contact_converged"] == 1
