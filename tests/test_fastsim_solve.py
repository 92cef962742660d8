"""Method "fastsim-fdm" through ``railtherm.solve``: conformance, scenes of the seed, end-to-end numbers.

The plugin is registered inline (``railtherm_register`` fixture of ``railtherm.testing``), so these
tests do not depend on the installed entry points. Run:
``PYTHONPATH=core:plugins python -m pytest tests/test_fastsim_solve.py -q``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import railtherm
import railtherm_fastsim.plugin as fastsim_plugin
import railtherm_fdm.plugin as fdm_plugin
from railtherm import Material, Refused, SceneError
from railtherm.references.moving_source import moving_source_temperature
from railtherm.testing import canonical, check_method

RAIL = {"density": 7680.0, "conductivity": 54.0, "specific_heat": 460.0, "bulk_temperature": 20.0}
SEED = {"name": "seed-circular-q1", "speed": 1.0, "heat_partition": 0.0, "wheel": RAIL, "rail": RAIL,
        "heat_source": {"flux": 1e6, "shape": "uniform", "semi_axes": [2.5e-3, 2.5e-3]},
        "outputs": ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "temperature",
                    "heat_flux", "frictional_power"]}


@pytest.fixture
def host(railtherm_register):
    """A strict host with the two plugins of method fastsim-fdm: fastsim (normal and tangential models,
    the method) and fdm (the temperature model)."""
    host = railtherm_register("fdm", fdm_plugin)          # the model first: the method names it
    host.add_plugin(fastsim_plugin, "fastsim")
    return host.build()


def test_conformance(host):
    out = check_method("fastsim-fdm")
    assert out["ellipse-full-sliding"] == "ok" and out["ellipse-creepage"] == "ok"
    assert out["ellipse-given-flux"] == "ok"
    assert out["line-full-sliding"] == "ok" and out["line-given-flux"] == "ok"       # 2-D FASTSIM and FDM


def test_seed_scene_against_exact_moving_source(host):
    """The seed's circular source (r = 2.5 mm chosen), steady scheme at level 3: within 2 %."""
    ds = railtherm.solve(SEED, "fastsim-fdm", level=3, options={"cell_size": 1e-3, "scheme": "steady"})
    X, Y = np.meshgrid(ds.x.values, ds.y.values, indexing="ij")
    rail = Material(**RAIL)
    ref = moving_source_temperature(X, Y, 0 * X, (2.5e-3, 2.5e-3), 1.0, rail, flux=1e6) + 20.0
    got = ds.surface_temperature.sel(body="rail").values
    assert float(ds.max_surface_temperature.sel(body="rail")) - 20 == pytest.approx(ref.max() - 20, rel=0.02)
    assert np.sqrt(np.mean((got - ref) ** 2)) / (ref.max() - 20) < 0.02
    assert float(ds.max_surface_temperature.sel(body="wheel")) == 20.0                # eps = 0
    assert ds.temperature.dims == ("body", "x", "z") and float(ds.z[0]) == 0.0
    assert abs(ds.attrs["fdm_rail_heat_balance_error"]) < 1e-9
    assert ds.attrs["fdm_rail_scheme"] == "steady"


def test_seed_scene_explicit_and_scaling(host):
    opts = {"cell_size": 1e-3, "scheme": "explicit"}
    t1 = railtherm.solve(SEED, "fastsim-fdm", level=2, options=opts)
    t10 = railtherm.solve({**SEED, "heat_source": {**SEED["heat_source"], "flux": 1e7}}, "fastsim-fdm", level=2,
                          options=opts)
    r1 = t1.surface_temperature.sel(body="rail").values - 20
    r10 = t10.surface_temperature.sel(body="rail").values - 20
    assert np.max(np.abs(r10 - 10 * r1)) <= 1e-12 * np.max(r10)
    assert t1.attrs["fdm_rail_scheme"] == "explicit" and t1.attrs["fdm_rail_quasi_steady"] == 1


def test_creepage_scene_forces_and_power(host):
    """CONTACT's FASTSIM example as a scene (exact-edge discretisation, core's Hertz patch)."""
    sc = canonical("ellipse-creepage", creepage={"longitudinal": 0.0, "lateral": -0.000625, "spin": 0.625},
                   outputs=["creep_force_x", "creep_force_y", "spin_moment", "frictional_power", "heat_flux",
                            "traction_x", "stick"])
    ds = railtherm.solve(sc, "fastsim-fdm", level=3)
    assert "surface_temperature" not in ds                                       # no thermal stage asked
    fy = float(ds.creep_force_y) / (0.3 * 82e3)
    assert fy == pytest.approx(-0.5956, rel=0.02)           # CONTACT elliptic 200x200 (its discretisation)
    flux = ds.heat_flux.values.sum(axis=0)
    area = float((ds.x[1] - ds.x[0]) * (ds.y[1] - ds.y[0]))
    assert flux.sum() * area == pytest.approx(float(ds.frictional_power), rel=1e-12)
    glob = ds.attrs["fastsim_global_power"]
    assert glob == pytest.approx(-30.0 * (-0.000625 * float(ds.creep_force_y) + 0.625 * float(ds.spin_moment)))
    assert 0.2 < float(ds.frictional_power) / glob - 1 < 0.5                       # local p.s vs global


def test_full_sliding_high_speed_runs_the_steady_scheme(host):
    """Ertz & Knothe, 30 m/s: auto picks the moving-frame scheme; maxima within 2 % of the exact
    moving Hertz source mu p v_s (FASTSIM's p.s differs from it by the small adhesion zone and the
    elastic slip), local frictional power within 1 % of mu N v_s."""
    sc = canonical("ellipse-full-sliding", outputs=["max_surface_temperature", "frictional_power"])
    ds = railtherm.solve(sc, "fastsim-fdm", level=2)
    assert ds.attrs["fdm_rail_scheme"] == "steady" and ds.attrs["fdm_wheel_scheme"] == "steady"
    assert float(ds.frictional_power) == pytest.approx(0.3 * 1.0 * 100e3, rel=0.01)
    a, b = 5.88e-3, 10.54e-3
    q0 = 0.3 * 1.0 * 3 * 100e3 / (2 * math.pi * a * b)
    steel = Material()
    x = np.linspace(-a, 0, 200)
    for body, v in (("wheel", 31.0), ("rail", 30.0)):
        ref = moving_source_temperature(x, 0 * x, 0 * x, (a, b), v, steel, flux=0.5 * q0, shape="hertz").max()
        assert float(ds.max_surface_temperature.sel(body=body)) == pytest.approx(ref, rel=0.02)


def test_bad_option_and_lateral_creepage_on_a_line(host):
    with pytest.raises(SceneError, match="bound"):
        railtherm.solve(canonical("ellipse-creepage"), "fastsim-fdm", options={"bound": "square"})
    line = canonical("line-full-sliding")
    del line["sliding_speed"]
    with pytest.raises(Refused):
        railtherm.solve({**line, "creepage": {"longitudinal": -1e-4, "lateral": 1e-3}}, "fastsim-fdm")


def test_steady_block_refuses_diffusion_dominated_scenes(host):
    """Péclet 0.02: the steady 3-D block's GMRES does not converge there; refused with the number."""
    with pytest.raises(Refused, match=r"Péclet number .* = 0.0198 < 0.1"):
        railtherm.solve(canonical("ellipse-given-flux", speed=1.4e-4), "fastsim-fdm", 0)
