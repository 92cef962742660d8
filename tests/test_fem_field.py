"""fem behind the patch and in depth (scene key ``field``) against the exact 2-D reference:
Jaeger's Hertzian band at depth, Péclet 1000, rail only (heat_partition 0: the rail carries the whole
flux), a = 5 mm, behind = 30a, depth 0.3 mm, threshold 1100 degC (the FEM is 2-D: line contacts only).

The FEM computes the trace on its strip's thermal layer (moving-frame conduction, P1 in depth, BDF2
upstream along x): the layer reaches 32a behind the centre (the default strip, lengthened when the field
asks for more), 2 x field.depth deep at least, and its x-spacing grows by 1 + 0.02/2^level only behind
the patch.

Measured (``OPENBLAS_NUM_THREADS=1 python -m pytest tests/test_fem_field.py -s``; max over the depths of
the error / exact rise, cooling rate from z = 0.1 mm):

* peak temperature at depth, levels 0, 1, 2: 1.18e-2, 3.3e-3, 8.5e-4 (fitted order 1.9: second order);
* cooling rate: 1.1e-2, 1.9e-3, 8.2e-4; heated depth: 7.7e-3, 2.8e-3, 2.0e-3;
* the depth field behind the patch (x = -25a .. 0.5a, surface, middle and field.depth) against Jaeger's
  band, max error / max: 1.0e-2, 4.8e-3, 2.3e-3, 1.1e-3 at levels 0..3 (first order: linear
  interpolation along the graded trail); level 3 takes ~3 s (267k thermal unknowns), level 2 0.6 s.

The tolerances are these numbers with a margin of ~1.5.
"""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm import Refused
from railtherm.analysis.analytic import trace_reference
from railtherm.input.scene import load_scene
from field_cases import A, V, BULK, TRACE, PLAIN, band_field_errors



def _band(behind=30 * A, depth=3e-4, threshold=1100.0, outputs=TRACE, **over):
    sc = dict(name="band", speed=V, contact={"shape": "line", "wheel_radius": 0.46}, normal_force=1e6,
              heat_source=dict(flux=1e9, shape="hertz", half_width=A), heat_partition=0.0, outputs=outputs)
    if behind is not None:
        sc["field"] = dict(behind=behind, threshold=threshold, **({} if depth is None else {"depth": depth}))
    sc.update(over)
    return sc


def _errors(ds, ref):
    rail = {k: ds[k].values[1] for k in ("peak_temperature", "cooling_rate")}
    peak = np.max(np.abs(rail["peak_temperature"] - ref["peak_temperature"][1])
                  / (ref["peak_temperature"][1] - BULK))
    ok = np.isfinite(ref["cooling_rate"][1]) & (ds["z"].values >= 1e-4)   # near the surface: log-singular
    cool = np.max(np.abs(rail["cooling_rate"] - ref["cooling_rate"][1])[ok] / ref["cooling_rate"][1][ok])
    depth = abs(float(ds["heated_depth"].values[1]) - ref["heated_depth"][1]) / ref["heated_depth"][1]
    return {"peak": float(peak), "cool": float(cool), "depth": float(depth)}


def test_fem_declares_the_field():
    from railtherm_fem.model import FemModel
    assert FemModel.capabilities.field
    assert {"peak_temperature", "cooling_rate", "heated_depth", "time_above"} <= FemModel.capabilities.provides


def test_band_pe1000_trace_against_jaeger_with_order():
    """Peak temperature at depth behind the patch, cooling rate and heated depth against the exact band,
    levels 0..2: second order in the peak."""
    sc = _band()
    levels = (0, 1, 2)
    errs = []
    for level in levels:
        ds = railtherm.solve(sc, "fem", level=level)
        assert ds["z"].values[-1] == pytest.approx(3e-4, rel=1e-12)          # reaches field.depth
        x = ds["x"].values
        assert x[0] - 0.5 * (x[1] - x[0]) < -31 * A * (1 - 1e-12)             # reaches field.behind
        ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("fem band Pe 1000, levels 0-2:", errs)
    peak = [e["peak"] for e in errs]
    assert peak[0] < 1.8e-2 and peak[-1] < 1.3e-3
    assert all(b < a for a, b in zip(peak, peak[1:]))
    order = float(-np.polyfit(np.asarray(levels, float), np.log2(peak), 1)[0])
    print("fitted order of the peak temperature:", order)
    assert 1.5 < order < 2.5
    assert errs[-1]["cool"] < 1.3e-3 and errs[-1]["depth"] < 3e-3
    # the exact peak at 0.3 mm lies behind the trailing edge: the field had to reach it
    assert np.all(np.isfinite(ds["peak_temperature"].values[1]))
    # the depth field behind the patch against Jaeger's band (level 2)
    rel, surface = band_field_errors(ds)
    print("fem band depth field behind the patch, max error / max:", rel)
    assert rel < 3.5e-3
    assert surface < 3.5e-3


def test_without_field_nothing_changes_on_the_patch():
    """The field run's patch values agree closely with the patch-only run (the thermal grid behind the
    patch is finer with the field; the patch-only run is unchanged by the field code)."""
    plain = railtherm.solve(_band(behind=None, outputs=PLAIN), "fem", level=1)
    ext = railtherm.solve(_band(behind=4 * A, depth=None, outputs=PLAIN), "fem", level=1)
    n = ext.sizes["x"] - plain.sizes["x"]
    assert n > 0 and np.allclose(ext["x"].values[n:], plain["x"].values, rtol=0, atol=1e-15)
    a, b = plain["surface_temperature"].values - BULK, ext["surface_temperature"].values[:, n:] - BULK
    assert np.max(np.abs(a - b)) / np.max(a) < 1e-3
    assert ext.attrs["fem_field_cells_behind"] == n


def test_coupled_sliding_case_reports_behind_the_patch():
    """The coupled solve (rigid wheel sliding): the field reaches behind the patch, contact and heat flux
    are zero there, the trace is filled (a too-deep peak flagged, not reported)."""
    sc = dict(name="slide", speed=10.0, contact={"shape": "line", "wheel_radius": 0.46}, normal_force=2e6,
              sliding_speed=1.0, friction=0.3, heat_partition=0.5, wheel={"rigid": True},
              outputs=TRACE + ["heat_flux", "pressure"], field=dict(behind=0.02, depth=1e-3, threshold=60.0))
    ds = railtherm.solve(sc, "fem", level=0)
    x = ds["x"].values
    a = ds.attrs["fem_field_behind"]
    assert a >= 0.02 and x[0] < -0.02
    # cell centres behind the patch: the patch's first centre is x[0] + field_behind (equal up to round-off),
    # so the cut lies half a cell before it
    behind = x < x[0] + ds.attrs["fem_field_behind"] - 0.5 * (x[1] - x[0])
    assert behind.sum() == round(ds.attrs["fem_field_behind"] / (x[1] - x[0]))
    assert np.all(ds["heat_flux"].values[:, behind] == 0) and np.all(ds["pressure"].values[behind] == 0)
    assert ds["z"].values[-1] == pytest.approx(1e-3, rel=1e-12)
    peak = ds["peak_temperature"].values[1]
    assert np.isfinite(peak[0]) and peak[0] > BULK
    assert float(ds["heated_depth"].values[1]) > 0


def test_too_short_a_strip_is_refused_with_the_limit():
    with pytest.raises(Refused) as info:
        railtherm.solve(_band(strip={"length": 0.2, "depth": 0.1}), "fem", level=0)
    assert "field.behind" in str(info.value) and "strip length >=" in str(info.value)
    with pytest.raises(Refused) as info:
        railtherm.solve(_band(behind=10 * A, depth=0.06, strip={"length": 0.5, "depth": 0.1}), "fem", level=0)
    assert "field.depth" in str(info.value) and "strip depth >=" in str(info.value)


def test_a_longer_field_lengthens_the_default_strip():
    """behind = 60a exceeds the default 40a wake: the thermal layer is extended to reach it."""
    ds = railtherm.solve(_band(behind=60 * A, depth=3e-4), "fem", level=0)
    x = ds["x"].values
    assert x[0] - 0.5 * (x[1] - x[0]) < -61 * A * (1 - 1e-12)
    assert ds.attrs["fem_field_thermal_reach"] >= 61 * A + 2 * A
    assert np.all(np.isfinite(ds["surface_temperature"].values))
