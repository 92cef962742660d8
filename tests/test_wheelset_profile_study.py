"""A wheelset on profiles that finds no contact (lifted off) or whose contact lies off a profile's end fails
its own runs, with the scene and the key in the message; the study's other scenes run and are written."""
from __future__ import annotations

import json
import re

import pytest
import xarray as xr

import railtherm
from railtherm import SceneError
from railtherm.input.profiles import read_profile
from railtherm.input.scene import load_scene
from railtherm.input.study import load_study
from railtherm.output import store

from manchester_cases import DATA

WHEELSET = {"wheel_profile": '"s1002"', "rail_profile": '"uic60"', "rail_inclination": "0.025",
            "nominal_radius": "0.46", "pitch_velocity": "-4.35", "vertical_force": "1e4"}


def _table(**change) -> str:
    return ", ".join(f"{k} = {v}" for k, v in {**WHEELSET, **change}.items())


def _study(tmp_path, **lost) -> str:
    """A study of one good scene and one whose wheelset table is changed by ``lost`` (TOML values)."""
    path = tmp_path / "lost.toml"
    path.write_text(f'schema_version = 1\n[study]\nname = "lost"\nmethods = ["equivalent"]\nlevels = [0]\n'
                    f'reference = "equivalent"\n[study.chains.equivalent]\nnormal = "wheelset-profile"\n'
                    f'[defaults]\nspeed = 2.0\nfriction = 0.3\n'
                    f'outputs = ["normal_force", "max_pressure", "contact_position_rail"]\n'
                    f'[[scene]]\nname = "good"\nwheelset = {{ {_table()} }}\n'
                    f'[[scene]]\nname = "lost"\nwheelset = {{ {_table(**lost)} }}\n')
    return str(path)


def _lifted_wheel(tmp_path) -> str:
    """The wheel profile cut to its field side beyond 50 mm: no part of it lies over the rail."""
    wheel = read_profile(str(DATA / "MBench_S1002_v3.prw"))
    keep = wheel.y > 50e-3
    cut = tmp_path / "field_side.txt"
    cut.write_text("\n".join(f"{y * 1e3:.7f} {z * 1e3:.7f}" for y, z in zip(wheel.y[keep], wheel.z[keep])))
    return str(cut)


def _records(out):
    return {r["scene"]: r for r in json.loads(store.study_path(out).read_text())["records"]}


@pytest.mark.parametrize("lost, words", [
    ({"gauge": "1.6"}, r"key 'wheelset': no contact: side right: the closest approach lies at the end of a profile"),
    ({"wheel_profile": "'{wheel}'"}, r"key 'wheelset': no contact: side right: the wheel profile .*field_side\.txt "
                                  r"does not overlap the rail")])
def test_a_scene_without_contact_fails_its_runs_and_the_study_goes_on(tmp_path, lost, words):
    """The study loads; the good scene's result is written; the lost scene's run is failed (invalid input)
    with a message naming the scene and the key; solving the lost scene raises the same SceneError."""
    lost = {k: v.format(wheel=_lifted_wheel(tmp_path)) for k, v in lost.items()}
    study = load_study(_study(tmp_path, **lost))
    assert [s.name for s in study.scenes] == ["good", "lost"]
    out = tmp_path / "out"
    railtherm.run_study(study, out=out, executor="serial", report=False)
    rec = _records(out)
    assert rec["good"]["status"] != "failed"
    with xr.open_dataset(out / "runs" / "good" / "equivalent" / "level-0.nc") as ds:
        assert float(ds["normal_force"]) == pytest.approx(1e4, rel=0.05)
    assert rec["lost"]["status"] == "failed" and rec["lost"]["reason_kind"] == "invalid-input"
    assert re.search(r"scene 'lost': " + words, rec["lost"]["message"]), rec["lost"]["message"]
    with pytest.raises(SceneError, match=r"scene 'lost': " + words):
        railtherm.solve(study.scenes[1], {"normal": "kalker"}, level=0)


def test_a_lost_scene_loads_and_says_why():
    """load_scene keeps a scene whose wheel finds no contact: it carries the reason, and asking it for a patch
    quantity is no error at load."""
    s = {"name": "lost", "speed": 2.0, "friction": 0.3, "outputs": ["normal_force", "contact_angle"],
         "wheelset": {"wheel_profile": "s1002", "rail_profile": "uic60", "rail_inclination": 0.025,
                      "nominal_radius": 0.46, "pitch_velocity": -4.35, "vertical_force": 1e4, "gauge": 1.6}}
    sc = load_scene(s)
    err = sc.profile_contact.failure()
    assert isinstance(err, SceneError) and (err.scene, err.key) == ("lost", "wheelset")
    assert str(err).startswith("scene 'lost': key 'wheelset': no contact: side right: the closest approach")


def test_the_report_describes_a_scene_without_contact_as_such(tmp_path):
    """The report's scene table says a lost wheel found no contact (not "gap contact; normal force 0 kN")
    and describes a good one by its wheel, shift and patch."""
    from railtherm.report.study_section import describe_scene
    study = load_study(_study(tmp_path, gauge="1.6"))
    good, lost = study.scenes
    assert describe_scene(lost).startswith("wheelset on profiles (right wheel") and "no contact" in describe_scene(lost)
    assert "gap contact" not in describe_scene(lost) and "normal force" not in describe_scene(lost)
    assert re.match(r"wheelset on profiles \(right wheel(, lateral shift [-\d.]+ mm)?, patch 1 of \d\); contact angle",
                    describe_scene(good)), describe_scene(good)
