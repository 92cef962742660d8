"""The transient scene vocabulary (railtherm.input.transient): parsed values and clear SceneErrors."""
from __future__ import annotations

import pytest

from railtherm import SceneError
from railtherm.input.transient import DEFAULT_THRESHOLD, Transient, transient_from_table

D = 4e-4  # contact duration 2a/V [s]

ISSUE_EXAMPLE = {
    "mode": "transient",
    "passes": {"count": 4, "interval": 0.083},
    "schedule": {"time": [0.0, 0.002, 0.010, 0.012], "factor": [0.0, 1.0, 1.0, 0.0]},
    "field": {"depth": 2e-3, "threshold": 727.0},
    "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "max_surface_temperature"],
}


def _error(table, contact_duration=D) -> SceneError:
    with pytest.raises(SceneError) as exc:
        transient_from_table("train", table, contact_duration)
    assert "scene 'train'" in str(exc.value)
    return exc.value


def test_the_issue_example_parses():
    got = transient_from_table("train", ISSUE_EXAMPLE, D)
    assert got == Transient(count=4, interval=0.083, schedule_time=(0.0, 0.002, 0.010, 0.012),
                            schedule_factor=(0.0, 1.0, 1.0, 0.0), depths=(0.0, 2e-3), threshold=727.0,
                            outputs=("temperature_history", "pass_peak_temperature", "residual_rise"))


def test_defaults_and_depth_lists():
    got = transient_from_table("s", {"mode": "transient", "field": {"depth": [5e-4, 1e-4, 1e-3, 0.0]}}, D)
    assert (got.count, got.interval, got.schedule_time, got.schedule_factor) == (1, None, None, None)
    assert got.depths == (0.0, 1e-4, 5e-4, 1e-3)
    assert got.threshold == DEFAULT_THRESHOLD
    assert transient_from_table("s", {"mode": "transient"}, None).depths == (0.0,)


def test_steady_scene_is_none_and_keeps_its_trace_output():
    assert transient_from_table("s", {"speed": 30.0}, D) is None
    assert transient_from_table("s", {"mode": "steady", "outputs": ["time_above"]}, D) is None


@pytest.mark.parametrize("key", ["passes", "schedule"])
def test_transient_keys_need_transient_mode(key):
    table = {"mode": "steady", key: ISSUE_EXAMPLE[key]}
    err = _error(table)
    assert err.key == key and "mode = \"transient\"" in str(err)
    err = _error({key: ISSUE_EXAMPLE[key]})  # mode missing: steady
    assert err.key == key


def test_transient_outputs_need_transient_mode():
    err = _error({"outputs": ["residual_rise"]})
    assert err.key == "outputs" and err.value == "residual_rise"


def test_schedule_time_not_strictly_increasing():
    for time in ([0.0, 0.002, 0.002], [0.0, 0.01, 0.005]):
        err = _error({"mode": "transient", "schedule": {"time": time, "factor": [0.0, 1.0, 0.0]}})
        assert err.key == "schedule.time" and err.value == time and "strictly increasing" in str(err)


def test_negative_factor():
    err = _error({"mode": "transient", "schedule": {"time": [0.0, 1.0], "factor": [1.0, -0.5]}})
    assert err.key == "schedule.factor" and "-0.5" in str(err) and ">= 0" in str(err)


def test_interval_shorter_than_the_contact_duration():
    err = _error({"mode": "transient", "passes": {"count": 3, "interval": 1e-4}})
    assert err.key == "passes.interval" and err.value == 1e-4
    assert "contact duration" in str(err) and "0.0004" in str(err)
    # exactly the contact duration is allowed; unknown duration: not checked
    assert transient_from_table("s", {"mode": "transient", "passes": {"count": 3, "interval": D}}, D).interval == D
    assert transient_from_table("s", {"mode": "transient", "passes": {"interval": 1e-4}}, None).interval == 1e-4


@pytest.mark.parametrize("count", [0, -2, 1.5, True, "4"])
def test_count_below_one_or_not_an_integer(count):
    err = _error({"mode": "transient", "passes": {"count": count, "interval": 0.1}})
    assert err.key == "passes.count" and ">= 1" in str(err)


@pytest.mark.parametrize("table,key", [
    ({"mode": "unsteady"}, "mode"),
    ({"mode": "transient", "passes": 4}, "passes"),
    ({"mode": "transient", "passes": {"count": 2, "gap": 0.1}}, "passes.gap"),
    ({"mode": "transient", "passes": {"interval": -0.1}}, "passes.interval"),
    ({"mode": "transient", "passes": {"interval": float("inf")}}, "passes.interval"),
    ({"mode": "transient", "schedule": {"time": [0.0, 1.0]}}, "schedule.factor"),
    ({"mode": "transient", "schedule": {"time": [0.0, 1.0], "factor": [1.0]}}, "schedule.factor"),
    ({"mode": "transient", "schedule": {"time": [], "factor": []}}, "schedule.time"),
    ({"mode": "transient", "schedule": {"time": [0.0, "x"], "factor": [1.0, 1.0]}}, "schedule.time"),
    ({"mode": "transient", "schedule": {"time": [0.0], "factor": [1.0], "step": 1}}, "schedule.step"),
    ({"mode": "transient", "field": {"depth": -1e-3}}, "field.depth"),
    ({"mode": "transient", "field": {"depth": [1e-3, "deep"]}}, "field.depth"),
    ({"mode": "transient", "field": {"threshold": -300.0}}, "field.threshold"),
    ({"mode": "transient", "outputs": "temperature_history"}, "outputs"),
])
def test_malformed_tables_name_their_key(table, key):
    err = _error(table)
    assert err.key == key
    assert f"key {key!r}" in str(err) and "is not allowed" in str(err)
