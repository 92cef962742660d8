"""Reference curves (references.nc) of a transient scene with a body at rest under the contact: the locked-wheel
slide. The wheel's surface does not move through the contact (V + v_s = 0), so it has no steady moving field
(a band at rest heated since t = -inf rises without bound) and none of the steady curves; the rail, passed at
10 m/s, has Jaeger's moving band. The curves are written without a warning: the rail's as Jaeger's band with the
rail's share of the full-slip heat, the wheel's NaN, and no steady trace (a trace is the steady field's)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from railtherm.analysis.analytic import _thermal_case
from railtherm.analysis.reference_curves import NAME_JAEGER, scene_curves_job
from railtherm.input.materials import Material
from railtherm.input.scene import load_scene
from railtherm.references.jaeger import jaeger_band_temperature

STEEL = {"bulk_temperature": 20.0}
#: the study's locked-wheel slide (studies/transient.toml), with a field as the study's defaults give it
LOCKED = {"name": "locked-wheel-slide", "normal_force": 0.8e6, "contact": {"shape": "line", "wheel_radius": 0.4345},
          "speed": 10.0, "sliding_speed": -10.0, "friction": 0.3, "heat_partition": 0.066, "mode": "transient",
          "rail": STEEL, "wheel": STEEL, "passes": {"count": 1, "interval": 0.1},
          "schedule": {"time": [0.0, 1e-4, 0.05, 0.0501], "factor": [0.0, 1.0, 1.0, 0.0]},
          "field": {"depth": [1e-4, 5e-4, 1e-3], "threshold": 727.0},
          "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]}


def test_locked_wheel_gets_the_rails_curves_without_a_warning():
    """The rail's surface and depth curves equal Jaeger's band at the rail's speed with its share 0.934 of the
    heat (to 1e-12: the same function); the wheel's are NaN; no trace variable; no warning, no problem text."""
    scene = load_scene(LOCKED)
    a, _, shape, q0, speeds, eps = _thermal_case(scene)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds, problem = scene_curves_job((scene, None))
    assert problem == "" and ds is not None
    assert ds.attrs["reference"] == NAME_JAEGER
    assert not any(name.startswith("trace_") for name in ds.data_vars)
    wheel, rail = ds["surface_temperature"].values
    assert np.all(np.isnan(wheel)) and np.all(np.isnan(ds["temperature"].values[0]))
    assert np.isnan(ds["hottest_x"].values[0])
    x = ds["x"].values
    steel = Material(bulk_temperature=20.0)
    exact = 20.0 + jaeger_band_temperature(x, np.zeros_like(x), a, speeds[1], steel, (1.0 - eps) * q0, shape)
    assert rail == pytest.approx(exact, rel=1e-12)
    assert rail.max() - 20.0 > 500.0            # heated: the curve is not a flat bulk temperature
    z = ds["z"].values
    x0 = float(ds["hottest_x"].values[1])
    depth = 20.0 + jaeger_band_temperature(np.full_like(z, x0), z, a, speeds[1], steel, (1.0 - eps) * q0, shape)
    assert ds["temperature"].values[1] == pytest.approx(depth, rel=1e-12)


def test_a_rolling_transient_scene_keeps_both_bodies_curves():
    """The same scene with the wheel rolling through the contact (sliding_speed -5 m/s, the wheel at 5 m/s) has
    both bodies' curves finite: only a body at rest loses its steady curves."""
    ds, problem = scene_curves_job((load_scene({**LOCKED, "sliding_speed": -5.0}), None))
    assert problem == "" and ds is not None
    assert np.all(np.isfinite(ds["surface_temperature"].values))
    assert np.all(np.isfinite(ds["hottest_x"].values))


def test_a_steady_locked_wheel_with_a_field_has_no_trace_and_no_warning():
    """A steady scene with the wheel at rest under the contact and a field: the trace (the steady field's
    thermal trace) does not exist for the wheel, so it is left out, the rail's steady curves kept, no problem."""
    steady = {k: v for k, v in LOCKED.items() if k not in ("mode", "passes", "schedule", "outputs")}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds, problem = scene_curves_job((load_scene({**steady, "field": {"depth": 1e-3, "threshold": 727.0}}), None))
    assert problem == "" and ds is not None
    assert not any(name.startswith("trace_") for name in ds.data_vars)
    assert np.all(np.isnan(ds["surface_temperature"].values[0]))
    assert np.all(np.isfinite(ds["surface_temperature"].values[1]))
