"""Transient scenes end to end: ``railtherm.solve(scene, "green", level=2)`` on scenes with passes and a
schedule against core's exact transient references (the moving band, 2-D, and the moving ellipse, 3-D),
and the bad input of the transient vocabulary as SceneErrors naming the key.

Targets (docs/DESIGN.md "Result schema", transient): against the exact band at level 2, pass peaks and
residual rise within 2 %, the history's max-norm within 3 % of its maximum rise; against the exact
ellipse at 0.1 and 0.5 mm, pass peaks within 5 %."""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm import Refused, SceneError
from railtherm.input.materials import Material
from railtherm.references.transient import MovingSource, Schedule, pass_summary, temperature_history

A, B, V, Q = 6e-3, 4e-3, 30.0, 1e8
INTERVAL = 0.083
SLIP = {"time": [0.0, 0.083, 0.0832, 0.0836, 0.0838, 0.2], "factor": [1.0, 1.0, 2.0, 2.0, 1.0, 1.0]}
DEPTHS = [1e-4, 5e-4]
STEEL = {"bulk_temperature": 20.0}
CHEAP = dict(quad_points=8, inner_points=24)    # the references at ~1e-5 of their maximum


def _scene(source: dict, **kw) -> dict:
    """A given heat source into the rail only (heat_partition 0), transient."""
    scene = {"name": "rail-section", "speed": V, "heat_source": {"flux": Q, **source}, "heat_partition": 0.0,
             "rail": STEEL, "wheel": STEEL, "mode": "transient",
             "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]}
    scene.update(kw)
    return scene


# the Hertzian flux costs the exact reference 4x the uniform one's time integrals: opt-in (-m slow)
@pytest.mark.parametrize("shape", ["uniform", pytest.param("hertz", marks=pytest.mark.slow)])
def test_band_history_against_the_exact_2d_band(shape):
    """4 passes 83 ms apart with a slip event on the second pass, at the surface and 0.1, 0.5 mm: the rail's
    (body 2) pass peaks, residual rise and history from railtherm.solve against the exact moving band."""
    scene = _scene({"shape": shape, "half_width": A}, passes={"count": 4, "interval": INTERVAL}, schedule=SLIP,
                   field={"depth": DEPTHS, "threshold": 400.0})
    ds = railtherm.solve(scene, "green", level=2)
    for name, units in (("temperature_history", "degC"), ("pass_peak_temperature", "degC"), ("residual_rise", "K"),
                        ("time_above", "s")):
        assert ds[name].attrs["units"] == units
    assert ds["residual_rise"].attrs["units_metadata"] == "temperature: difference"
    assert ds.time.attrs["units"] == "s" and list(ds["pass"].values) == [1, 2, 3, 4]
    depths = ds.z.values
    assert list(depths) == [0.0, *DEPTHS]
    src = MovingSource("band", A, V, Q, shape)
    sched = Schedule(tuple(SLIP["time"]), tuple(SLIP["factor"]))
    t = ds.time.values
    got = ds.temperature_history.sel(body="rail").values - 20.0
    exact = temperature_history(t, depths, src, Material(), 4, INTERVAL, sched, **CHEAP)
    ref = pass_summary(depths, src, Material(), 4, INTERVAL, sched, **CHEAP)
    peak = ds.pass_peak_temperature.sel(body="rail").values - 20.0
    assert np.max(np.abs(peak / ref.peak - 1)) < 0.02
    assert np.max(np.abs(ds.residual_rise.sel(body="rail").values / ref.residual[:, 0] - 1)) < 0.02
    assert np.max(np.abs(got - exact).max(axis=0) / exact.max(axis=0)) < 0.03
    # the wheel gets no heat (heat_partition 0): it stays at its bulk temperature
    assert np.all(ds.temperature_history.sel(body="wheel").values == 20.0)
    # at least 20 samples per contact duration around each pass
    d = 2 * A / V
    assert np.sum((t >= INTERVAL) & (t < INTERVAL + d)) >= 20


def test_ellipse_pass_peaks_in_depth_against_the_exact_3d_ellipse():
    """One pass of a Hertzian ellipse (a = 6, b = 4 mm): the rail's peaks at 0.1 and 0.5 mm within 5 % of the
    exact moving ellipse (green's centre strip neglects the lateral conduction)."""
    scene = _scene({"shape": "hertz", "semi_axes": [A, B]}, passes={"count": 1, "interval": INTERVAL},
                   field={"depth": DEPTHS})
    ds = railtherm.solve(scene, "green", level=2)
    peak = ds.pass_peak_temperature.sel(body="rail").values[0, 1:] - 20.0
    ref = pass_summary(DEPTHS, MovingSource("ellipse", A, V, Q, "hertz", B), Material(), 1, INTERVAL)
    assert np.max(np.abs(peak / ref.peak[0] - 1)) < 0.05


def test_wheel_interval_defaults_to_its_revolution():
    """Without passes.interval a pass is one revolution of the wheel: 2 pi wheel.radius / speed."""
    scene = railtherm.load_scene(_scene({"half_width": A}, passes={"count": 3}, wheel={**STEEL, "radius": 0.46}))
    assert scene.transient.interval == pytest.approx(2 * np.pi * 0.46 / V, rel=1e-12)
    assert scene.transient.count == 3


def test_computed_contact_runs_and_steady_methods_refuse():
    """A computed Hertz patch (full sliding) runs through green (and fastsim-fdm, its 3-D section block: opt-in,
    below) and fipy (its 3-D block: tests/test_fipy_ellipse_history.py); fem (line contacts only) refuses the ellipse
    instead of returning a steady answer."""
    import railtherm.testing
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", passes={"count": 3, "interval": 0.05},
                                        outputs=["temperature_history", "residual_rise"])
    ds = railtherm.solve(scene, "green", level=0)
    assert ds.residual_rise.shape == (2, 3) and np.all(ds.residual_rise.values > 0)
    with pytest.raises(Refused, match="contacts, not 'ellipse'"):
        railtherm.solve(scene, "fem", level=0)


# fdm's 3-D block for both bodies (~6 s): opt-in (-m slow)
@pytest.mark.slow
def test_computed_ellipse_histories_through_fdm():
    """The computed Hertz patch above (FASTSIM's heat, both bodies) through fastsim-fdm's 3-D section block:
    every residual rise positive, the wheel's and the rail's history returned, and the one-pass surface
    maximum asked beside them (the 3-D steady block on the patch's flux) within 5 % of green's."""
    import railtherm.testing
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", passes={"count": 3, "interval": 0.05},
                                        outputs=["temperature_history", "residual_rise", "max_surface_temperature"])
    ds = railtherm.solve(scene, "fastsim-fdm", level=0)
    assert ds.residual_rise.shape == (2, 3) and np.all(ds.residual_rise.values > 0)
    green = railtherm.solve(scene, "green", level=0).max_surface_temperature.values
    np.testing.assert_allclose(ds.max_surface_temperature.values, green, rtol=0.05)


@pytest.mark.parametrize("change, key", [
    ({"schedule": {"time": [0.0, 0.01, 0.01], "factor": [0.0, 1.0, 0.0]}}, "schedule.time"),
    ({"schedule": {"time": [0.0, 0.01, 0.005], "factor": [0.0, 1.0, 0.0]}}, "schedule.time"),
    ({"schedule": {"time": [0.0, 0.01], "factor": [1.0, -0.5]}}, "schedule.factor"),
    ({"passes": {"count": 2, "interval": 1e-4}}, "passes.interval"),
    ({"passes": {"count": 0, "interval": 0.1}}, "passes.count"),
    ({"mode": "steady", "passes": {"count": 2, "interval": 0.1}, "outputs": ["max_surface_temperature"]}, "passes"),
    ({"mode": "steady", "schedule": {"time": [0.0], "factor": [1.0]}, "outputs": ["max_surface_temperature"]},
     "schedule"),
    ({"mode": "steady", "outputs": ["residual_rise"]}, "outputs"),
    ({"field": {"depth": [1e-4], "behind": 0.01}}, "field.behind"),
])
def test_bad_input_names_the_key(change, key):
    with pytest.raises(SceneError) as err:
        railtherm.load_scene(_scene({"half_width": A}, **change))
    assert err.value.key == key
    assert key in str(err.value)


def test_interval_shorter_than_a_computed_patch():
    """The interval against the contact duration of a patch known only after the contact stage: green's
    SceneError names passes.interval."""
    import railtherm.testing
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", passes={"count": 2, "interval": 1e-4})
    with pytest.raises(SceneError) as err:
        railtherm.solve(scene, "green", level=0)
    assert err.value.key == "passes.interval"


def test_metrics_score_the_histories_against_the_exact_band():
    """metrics.nc's transient errors (railtherm.analysis.transient_metrics) on a uniform band with passes and
    a slip event at level 2: the issue's targets (2 %, 2 %, 3 %; measured 0.25 %, 0.44 %, 0.37 %)."""
    from railtherm.analysis.transient_metrics import transient_errors
    scene = railtherm.load_scene(_scene({"shape": "uniform", "half_width": A},
                                        passes={"count": 4, "interval": INTERVAL}, schedule=SLIP,
                                        field={"depth": DEPTHS}))
    ds = railtherm.solve(scene, "green", level=2)
    notes = {}
    err = transient_errors(scene, ds, notes, {})
    assert set(err) == {"pass_peak_temperature", "residual_rise", "temperature_history"} and not notes
    assert all(tag == "analytic:transient-band" for _, tag in err.values())   # every body moves
    assert err["pass_peak_temperature"][0] < 0.02 and err["residual_rise"][0] < 0.02
    assert err["temperature_history"][0] < 0.03


def test_green_refuses_a_temperature_dependent_friction_law_in_a_transient_scene():
    """Superposition of one pass's response needs a heat input independent of the temperature."""
    import railtherm.testing
    scene = railtherm.testing.canonical("ellipse-full-sliding", mode="transient", passes={"count": 2, "interval": 0.05},
                                        friction={"law": "temperature", "reference": 0.3, "reference_temperature": 200.0,
                                                  "change": -0.1, "over": 300.0})
    with pytest.raises(Refused, match="temperature-dependent friction law"):
        railtherm.solve(scene, "green", level=0)


def test_history_is_scored_over_the_same_passes_at_every_level():
    """A history longer than MAX_HISTORY_SAMPLES is thinned to every k-th sample while MIN_PER_CONTACT
    remain per contact duration, so a finer level is scored over the same passes with the same scale (3
    passes of 12,256 samples, 570 per contact duration: every 3rd, all passes); only what is still too long
    is cut to its first whole passes (1,000 passes at 25 samples per contact duration)."""
    from railtherm.analysis.transient_metrics import MAX_HISTORY_SAMPLES, MIN_PER_CONTACT, history_samples
    d, interval = 4e-4, 0.091
    dense = np.sort(np.concatenate([k * interval + np.linspace(0.0, 2.5 * d, 1425, endpoint=False)
                                    for k in range(3)] + [np.linspace(0.0, 3 * interval, 7981)]))
    notes = {}
    every, n, thin = history_samples(dense, 3, interval, d, notes)
    assert every == 3 and n == thin.size <= MAX_HISTORY_SAMPLES and thin[-1] > 2.9 * interval
    assert np.count_nonzero(thin[:n] < d) >= MIN_PER_CONTACT and "one in 3 " in notes["temperature_history"]
    long = np.sort(np.concatenate([k * 0.05 + np.linspace(0.0, 0.05, 500, endpoint=False) for k in range(1000)]))
    notes = {}
    every, n, thin = history_samples(long, 1000, 0.05, 1e-4, notes)
    assert every == 1 and thin[n - 1] == pytest.approx(9 * 0.05)
    assert "first 9 of 1000 passes" in notes["temperature_history"]
    notes = {}
    assert history_samples(np.linspace(0.0, 0.3, 3000), 3, 0.1, 4e-4, notes)[:2] == (1, 3000) and not notes


#: the study's locked-wheel slide: sliding_speed = -speed, the wheel's surface at rest under the contact
LOCKED = {"name": "locked-wheel-slide", "normal_force": 0.8e6, "contact": {"shape": "line", "wheel_radius": 0.4345},
          "speed": 10.0, "sliding_speed": -10.0, "friction": 0.3, "heat_partition": 0.066, "mode": "transient",
          "rail": STEEL, "wheel": STEEL, "passes": {"count": 1, "interval": 0.1},
          "schedule": {"time": [0.0, 1e-4, 0.05, 0.0501], "factor": [0.0, 1.0, 1.0, 0.0]},
          "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]}


@pytest.mark.parametrize("method", ["green", "fipy", "fem"])
def test_locked_wheel_is_refused_by_the_moving_frame_methods(method):
    """green, FiPy and the FEM work in the frame moving with the contact: the wheel's spot at rest is refused with
    the reason (core's moving-surface check), never answered with a steady field."""
    with pytest.raises(Refused, match="wheel moves at 0 m/s"):
        railtherm.solve(LOCKED, method, level=0)


def test_locked_wheel_heat_and_exact_sources():
    """sliding_speed = -speed: full-slip heat mu p |v_s| (the analytic frictional power positive), the rail's exact
    reference the moving band at 10 m/s, the wheel's the band at rest (references.transient_spot), each with its
    share of the heat; a wheel moving backwards through the contact (sliding_speed < -speed) is a SceneError."""
    from railtherm.analysis.analytic import _thermal_case
    from railtherm.analysis.transient_metrics import transient_sources
    from railtherm.input.scene import load_scene
    from railtherm.references.transient_spot import FixedSource
    scene = load_scene(LOCKED)
    a, b, shape, q0, speeds, eps = _thermal_case(scene)
    assert q0 > 0 and speeds == (0.0, 10.0) and eps == 0.066 and b is None
    (wheel, _), (rail, _) = transient_sources(scene)[0]
    assert isinstance(wheel, FixedSource) and wheel.flux == pytest.approx(0.066 * q0, rel=1e-14)
    assert isinstance(rail, MovingSource) and rail.speed == 10.0 and rail.flux == pytest.approx(0.934 * q0, rel=1e-14)
    with pytest.raises(SceneError) as err:
        load_scene({**LOCKED, "sliding_speed": -10.5})
    assert err.value.key == "sliding_speed" and "locked wheel" in str(err.value)


def test_study_scores_the_locked_wheel_at_its_finest_level(tmp_path):
    """metrics.nc scores a transient scene's histories against the exact ones at every level, the finest too,
    where neither a finer level nor the steady references exist (a wheel at rest has none): fdm's locked wheel
    at level 0 alone, 40 ms of the 50 ms slide (the exact scheduled rail pass costs per sample)."""
    from railtherm.input.study import parse_study
    scene = {**LOCKED, "passes": {"count": 1, "interval": 0.06},
             "schedule": {"time": [0.0, 1e-4, 0.04, 0.0401], "factor": [0.0, 1.0, 1.0, 0.0]}}
    study = parse_study({"schema_version": 1, "study": {
        "name": "locked", "methods": ["fdm"], "levels": [0], "reference": "analytic",
        "chains": {"fdm": {"normal": ["wheelset", "hertz"], "tangential": ["full-sliding", "fastsim"],
                           "heat_source": "frictional", "temperature": "fdm"}}}, "scene": [scene]})
    m = railtherm.run_study(study, tmp_path, report=False)
    # a scene asking histories only has a headline: the peak of each pass (scored, so not "unverified")
    assert str(m["status"].values[0]) in ("ok", "inaccurate")
    for metric in ("pass_peak_temperature", "residual_rise", "temperature_history"):
        assert 0.0 < float(m[f"error_{metric}"].values[0]) < 0.1, metric
        assert str(m[f"reference_{metric}"].values[0]) == "analytic:transient-band-moving-and-at-rest", metric
