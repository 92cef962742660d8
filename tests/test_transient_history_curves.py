"""The exact transient curves of references.nc (railtherm.analysis.transient_curves): a transient scene's group holds
the exact history and per-pass values computed by the same calls metrics.nc scores with (the moving band's
temperature_history and pass_summary with the metrics' quadrature; a locked wheel's FixedSource history and
summary); a steady scene's group has none of them; they survive the write/read round trip of references.nc."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from railtherm.analysis.reference_curves import (read_reference_curves, scene_curves_job, scene_reference_curves,
                                                 write_reference_curves)
from railtherm.analysis.transient_curves import NAME_AT_REST, NAME_BAND, history_time
from railtherm.analysis.transient_metrics import _QUAD, transient_sources
from railtherm.input.scene import load_scene
from railtherm.references.transient import MovingSource, Schedule, pass_summary, temperature_history, time_above
from railtherm.references.transient_spot import FixedSource, fixed_source_history, fixed_source_summary

STEEL = {"bulk_temperature": 20.0}
FIELD = {"depth": [1e-4, 5e-4], "threshold": 727.0}
OUTPUTS = ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]
#: a Hertzian band on the rail passing 3 times, 50 ms apart (studies/transient.toml's train, 3 passes), its surface
#: above the threshold 250 degC in every pass (peaks 283-303 degC)
BAND = {"name": "band-3-passes", "mode": "transient", "speed": 30.0, "heat_partition": 0.0, "convection": 0.0,
        "heat_source": {"flux": 2.0e8, "shape": "hertz", "half_width": 6e-3}, "passes": {"count": 3, "interval": 0.05},
        "field": {**FIELD, "threshold": 250.0}, "outputs": OUTPUTS, "wheel": STEEL, "rail": STEEL}
#: the study's locked-wheel slide: the wheel's spot at rest for 50 ms, the rail passed once at 10 m/s
LOCKED = {"name": "locked-wheel-slide", "normal_force": 0.8e6, "contact": {"shape": "line", "wheel_radius": 0.4345},
          "speed": 10.0, "sliding_speed": -10.0, "friction": 0.3, "heat_partition": 0.066, "mode": "transient",
          "rail": STEEL, "wheel": STEEL, "passes": {"count": 1, "interval": 0.1},
          "schedule": {"time": [0.0, 1e-4, 0.05, 0.0501], "factor": [0.0, 1.0, 1.0, 0.0]},
          "field": FIELD, "outputs": OUTPUTS}
NAMES = ("exact_temperature_history", "exact_pass_peak_temperature", "exact_residual_rise", "exact_time_above")


@pytest.fixture(scope="module")
def band():
    scene = load_scene(BAND)
    ds, problem = scene_curves_job((scene, None))
    assert problem == "" and ds is not None
    return scene, ds


@pytest.fixture(scope="module")
def locked():
    scene = load_scene(LOCKED)
    return scene, scene_reference_curves(scene)


def test_band_history_is_temperature_history(band):
    """The stored rail history equals temperature_history (metrics' quadrature) at sample times, to 1e-12
    relative; the wheel, without heat, is NaN; axes, units and the group's reference as the contract says."""
    scene, ds = band
    tr = scene.transient
    (_, _), (src, bulk) = transient_sources(scene)[0]
    assert isinstance(src, MovingSource) and src.kind == "band"
    t = ds["history_time"].values
    z = ds["history_depth"].values
    assert t[0] == 0.0 and t[-1] == pytest.approx(3 * 0.05, rel=1e-15) and t.size <= 2001
    assert list(z) == [0.0, 1e-4, 5e-4] and list(ds["pass"].values) == [1, 2, 3]
    # about 40 samples per contact duration around each arrival
    d = src.contact_duration
    assert np.count_nonzero((t >= 0.05) & (t < 0.05 + d)) == 40
    pick = [1, 17, 40, 81, 140, t.size - 1]
    exact = bulk + temperature_history(t[pick], z, src, scene.body(1), tr.count, tr.interval, None, **_QUAD)
    got = ds["exact_temperature_history"].values[1, pick]
    assert got == pytest.approx(exact, rel=1e-12, abs=0)
    assert got.max() - bulk > 100.0                                     # heated: not a flat bulk curve
    assert np.all(np.isnan(ds["exact_temperature_history"].values[0]))
    assert ds.attrs["transient_reference"] == NAME_BAND
    assert ds["exact_temperature_history"].attrs["units"] == "degC"
    assert ds["exact_residual_rise"].attrs["units"] == "K"
    assert ds["exact_residual_rise"].attrs["units_metadata"] == "temperature: difference"
    assert ds["exact_time_above"].attrs["units"] == "s" and ds["history_time"].attrs["units"] == "s"


def test_band_per_pass_values_are_pass_summarys(band):
    """Per-pass peaks [degC] = bulk + pass_summary's peak, the residual its surface residual, the time above the
    references' time_above, all at the metrics' quadrature (exact equality: the same calls)."""
    scene, ds = band
    tr = scene.transient
    src, bulk = transient_sources(scene)[0][1]
    z = ds["history_depth"].values
    summary = pass_summary(z, src, scene.body(1), tr.count, tr.interval, None, **_QUAD)
    np.testing.assert_array_equal(ds["exact_pass_peak_temperature"].values[1], bulk + summary.peak)
    np.testing.assert_array_equal(ds["exact_residual_rise"].values[1], summary.residual[:, 0])
    above = time_above(tr.threshold - bulk, z, src, scene.body(1), tr.count, tr.interval, None, **_QUAD)
    np.testing.assert_array_equal(ds["exact_time_above"].values[1], above)
    assert np.all(above[:, 0] > 0)                                      # the surface exceeds it in every pass
    assert np.all(np.diff(ds["exact_residual_rise"].values[1]) > 0)     # the passes accumulate


def test_locked_wheel_gets_the_fixed_source_curves(locked):
    """The wheel's spot at rest: its history is fixed_source_history and its peaks fixed_source_summary's; the rail
    its moving band; the group's reference names both."""
    scene, ds = locked
    tr = scene.transient
    (wsrc, wbulk), (rsrc, _) = transient_sources(scene)[0]
    assert isinstance(wsrc, FixedSource) and isinstance(rsrc, MovingSource)
    assert ds.attrs["transient_reference"] == f"{NAME_AT_REST} (wheel); {NAME_BAND} (rail)"
    t = ds["history_time"].values
    z = ds["history_depth"].values
    assert np.all(np.isin([1e-4, 0.05, 0.0501], t))                    # the schedule's kinks are samples
    pick = [3, 60, int(np.searchsorted(t, 0.05)), t.size - 1]
    sched = Schedule(tr.schedule_time, tr.schedule_factor)
    exact = wbulk + fixed_source_history(t[pick], z, wsrc, scene.body(0), sched)
    assert ds["exact_temperature_history"].values[0, pick] == pytest.approx(exact, rel=1e-12, abs=0)
    summary = fixed_source_summary(z, wsrc, scene.body(0), tr.count, tr.interval, sched)
    np.testing.assert_array_equal(ds["exact_pass_peak_temperature"].values[0], wbulk + summary.peak)
    np.testing.assert_array_equal(ds["exact_residual_rise"].values[0], summary.residual[:, 0])
    assert np.all(np.isfinite(ds["exact_temperature_history"].values))


def test_locked_wheel_time_above_matches_dense_sampling(locked):
    """The spot's surface time above 727 degC (Brent on the exact history) against the fraction of 2,001 equal
    samples of the exact history above it: within two sample steps (the sampled count's resolution)."""
    scene, ds = locked
    tr = scene.transient
    wsrc, wbulk = transient_sources(scene)[0][0]
    sched = Schedule(tr.schedule_time, tr.schedule_factor)
    t = np.linspace(0.0, tr.interval, 2001)
    rise = fixed_source_history(t, [0.0], wsrc, scene.body(0), sched)[:, 0]
    dt = t[1] - t[0]
    sampled = np.count_nonzero(wbulk + rise > 727.0) * dt
    got = float(ds["exact_time_above"].values[0, 0, 0])
    assert sampled > 0.01                                                # the spot exceeds the threshold
    assert abs(got - sampled) <= 2.0 * dt


def test_steady_scene_has_no_transient_curves():
    """A steady band scene (no mode) keeps its steady curves only: no exact_* variable, no history axes."""
    steady = {k: v for k, v in BAND.items() if k not in ("mode", "passes", "outputs", "field")}
    ds = scene_reference_curves(load_scene(steady))
    assert ds is not None and "surface_temperature" in ds
    assert not set(NAMES) & set(ds.data_vars)
    assert not {"history_time", "history_depth", "pass"} & set(ds.dims)
    assert "transient_reference" not in ds.attrs


def test_round_trip_keeps_the_transient_curves(band, locked, tmp_path):
    """write_reference_curves / read_reference_curves keep the variables, values, units and the group attribute."""
    curves = {band[0].name: band[1], locked[0].name: locked[1]}
    path = write_reference_curves(SimpleNamespace(name="transient-curves"), tmp_path, curves=curves)
    back = read_reference_curves(path)
    for name, ds in curves.items():
        got = back[name]
        assert got.attrs["transient_reference"] == ds.attrs["transient_reference"]
        for var in NAMES:
            np.testing.assert_array_equal(got[var].values, ds[var].values)
            assert got[var].attrs["units"] == ds[var].attrs["units"]
        for c in ("history_time", "history_depth", "pass"):
            np.testing.assert_array_equal(got[c].values, ds[c].values)


def test_history_time_is_uniform_beyond_twenty_passes():
    """1,000 passes: uniform samples (the same offsets in every pass), at most 2,001, from 0 to the last pass plus
    one interval; 20 passes stay within 2,001 too."""
    t = history_time(1000, 0.05, 4e-4)
    assert t.size <= 2001 and t[0] == 0.0 and t[-1] == pytest.approx(50.0, rel=1e-15)
    np.testing.assert_allclose(np.diff(t), 0.025, rtol=1e-9)
    assert history_time(20, 0.05, 4e-4).size <= 2001
