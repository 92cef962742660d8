"""Bad input to a wheelset on profiles: each gives a SceneError (ProfileError for a profile file) naming
the scene, the key and, for a file, the file and line; none is a traceback of another kind. A wheel that
finds no contact loads and fails its own solves (tests/test_wheelset_profile_study.py)."""
from __future__ import annotations

import copy
from pathlib import Path

import pytest

import railtherm
from railtherm import SceneError
from railtherm.input.scene import load_scene
from railtherm.physics.profiles import ProfileError

from railtherm.input.profiles import read_profile
from manchester_cases import DATA, a22_scene


def _with(position=13, side="right", **wheelset):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(wheelset)
    return s


def test_a_good_scene_is_a_gap_scene_with_load_and_creepage():
    sc = load_scene(a22_scene(13, "right"))
    assert sc.contact_shape == "gap" and sc.wheelset is None
    assert sc.normal_force == pytest.approx(sc.profile_contact.normal_force)
    assert sc.creepage.longitudinal == sc.profile_contact.creepage[0]
    assert sc.profile_contact.patches == 1
    # one clear minimum: the plane's origin lies near the reference point (0.08 mm here)
    assert abs(sc.profile_contact.plane_position_rail - sc.profile_contact.contact_position_rail) < 0.5e-3
    rail = read_profile(str(DATA / "MBench_UIC60_v3.prr"))
    y, z = sc.profile_contact.rail_section
    assert len(y) <= 400 and (y[0], y[-1], z[0]) == (rail.y[0], rail.y[-1], rail.z[0])


def test_a_missing_profile_file_names_key_and_file(tmp_path):
    missing = str(tmp_path / "no_such.prr")
    with pytest.raises(ProfileError, match=r"scene 'a22-13-right': key 'wheelset.rail_profile': profile .*no_such\.prr: "
                                           r"cannot be read"):
        load_scene(_with(rail_profile=missing))


def test_an_unreadable_line_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("# y z in mm\n-30 1.0\n-29 0.9\nabc def\n")
    with pytest.raises(ProfileError, match=r"key 'wheelset.wheel_profile': profile .*bad\.txt, line 4: cannot read"):
        load_scene(_with(wheel_profile=str(bad)))


def test_a_contact_off_the_end_of_the_rail_profile_is_named(tmp_path):
    """The rail profile cut 12 mm left of its crown: the tread's contact at -7 mm lies beyond its end."""
    rail = read_profile(str(DATA / "MBench_UIC60_v3.prr"))
    keep = rail.y < -12e-3
    cut = tmp_path / "cut_rail.txt"
    cut.write_text("\n".join(f"{y * 1e3:.7f} {z * 1e3:.7f}" for y, z in zip(rail.y[keep], rail.z[keep])))
    with pytest.raises(SceneError, match=r"scene 'a22-1-right': key 'wheelset': no contact: side right: the closest "
                                         r"approach lies at the end of a profile \(.*rail y = -12.\d\d mm\): the "
                                         r"wheel runs off the rail"):
        railtherm.solve(load_scene(_with(1, rail_profile=str(cut))), "kalker", level=0)


def test_a_wheel_that_does_not_reach_the_rail_finds_no_contact(tmp_path):
    """The wheel profile cut to its field side beyond 50 mm: no part of it lies over the rail (lifted off)."""
    wheel = read_profile(str(DATA / "MBench_S1002_v3.prw"))
    keep = wheel.y > 50e-3
    cut = tmp_path / "field_side.txt"
    cut.write_text("\n".join(f"{y * 1e3:.7f} {z * 1e3:.7f}" for y, z in zip(wheel.y[keep], wheel.z[keep])))
    with pytest.raises(SceneError, match=r"scene 'a22-1-right': key 'wheelset': no contact: side right: the wheel "
                                         r"profile .*field_side\.txt does not overlap the rail .* laterally"):
        railtherm.solve(load_scene(_with(1, wheel_profile=str(cut))), "kalker", level=0)


@pytest.mark.parametrize("value", [-1.0, 0.0])
def test_a_force_that_is_not_positive_is_refused(value):
    with pytest.raises(SceneError, match=r"key 'wheelset.vertical_force'"):
        load_scene(_with(vertical_force=value))


def test_a_missing_vertical_force_is_named():
    s = a22_scene(13, "right")
    del s["wheelset"]["vertical_force"]
    with pytest.raises(SceneError, match=r"key 'wheelset.vertical_force' is missing"):
        load_scene(s)


def test_conical_keys_do_not_mix_with_profiles():
    with pytest.raises(SceneError, match=r"key 'wheelset.conicity'"):
        load_scene(_with(conicity=0.05))


def test_contact_keys_are_set_by_the_wheelset():
    s = a22_scene(13, "right")
    s["normal_force"] = 1e4
    with pytest.raises(SceneError, match=r"key 'normal_force'.*a wheelset on profiles sets"):
        load_scene(s)


def test_a_patch_beyond_those_found_is_refused():
    with pytest.raises(SceneError, match=r"key 'wheelset.patch' = 2 is not allowed: at most 1"):
        load_scene(_with(patch=2))


def test_a_bad_side_is_named():
    with pytest.raises(SceneError, match=r"wheelset.side"):
        load_scene(_with(side="middle"))


def test_the_second_patch_of_a_two_patch_wheel_is_a_scene():
    """Position 10: tread contact and the flange root 0.07 mm above it (more than the Hertz-equivalent
    approach, 0.024 mm): two patches; patch 2 lies on the gauge side at a steeper angle. (Each scene gets the
    whole vertical force: the force is not shared between patches.)"""
    one, two = (load_scene(_with(10, patch=k)).profile_contact for k in (1, 2))
    assert one.patches == two.patches == 2
    assert two.contact_angle < one.contact_angle
    assert two.contact_position_rail < one.contact_position_rail


def test_a_second_minimum_inside_the_first_patch_is_not_a_patch_of_its_own():
    """Position 1: the second gap minimum lies 8 um above the first, inside the approach: one elastic patch
    (patch 1 covers both, as CONTACT's does), and patch 2 is refused, saying why."""
    assert load_scene(_with(1)).profile_contact.patches == 1
    with pytest.raises(SceneError, match=r"key 'wheelset.patch' = 2 is not allowed: at most 1: the search found 2 gap "
                                         r"minima .*one elastic patch covers them"):
        load_scene(_with(1, patch=2))


@pytest.mark.parametrize("wheelset, words", [
    ('rail_profile = "{d}/no_such.prr", vertical_force = 1e4', "key 'wheelset.rail_profile': profile .*no_such.prr: cannot be read"),
    ('rail_profile = "uic60", vertical_force = -1.0', "key 'wheelset.vertical_force' = -1.0 is not allowed")])
def test_the_command_line_names_bad_profile_input_without_a_traceback(tmp_path, capsys, wheelset, words):
    """``railtherm validate`` and ``run`` on a study with a bad wheelset on profiles: one error line naming the
    scene and the key (or the file), exit status 1 / 2, no traceback, nothing run."""
    import re
    from railtherm.cli import main
    study = tmp_path / "bad.toml"
    study.write_text(_cli_study(wheelset.format(d=tmp_path)))
    assert main(["validate", str(study)]) == 1
    assert main(["run", str(study), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and re.search(r"railtherm: error: scene 'w': " + words, err), err
    assert not (tmp_path / "out" / "runs").exists()


def _cli_study(wheelset: str) -> str:
    return (f'schema_version = 1\n[study]\nname = "bad"\nmethods = ["kalker"]\nlevels = [0]\n'
            f'[[scene]]\nname = "w"\nspeed = 2.0\nfriction = 0.3\nwheelset = {{ wheel_profile = "s1002", '
            f'nominal_radius = 0.46, pitch_velocity = -4.35, {wheelset} }}\n')


def test_the_command_line_names_a_wheel_without_contact_and_runs_the_study(tmp_path, capsys):
    """A wheel that runs off the rail: ``validate`` names it (exit 1); ``run`` records the scene's run as failed
    with the same words (exit 3, a run failed), no traceback."""
    from railtherm.cli import main
    study = tmp_path / "off.toml"
    study.write_text(_cli_study('rail_profile = "uic60", gauge = 1.6, vertical_force = 1e4'))
    words = ("scene 'w': key 'wheelset': no contact: side right: the closest approach lies at the end of a "
             "profile")
    assert main(["validate", str(study)]) == 1
    assert f"error: {words}" in capsys.readouterr().err
    assert main(["run", str(study), "--out", str(tmp_path / "out"), "--executor", "serial", "--no-report"]) == 3
    assert "Traceback" not in capsys.readouterr().err
    status = (tmp_path / "out" / "runs" / "w" / "kalker" / "level-0.status.json").read_text()
    assert words in status


def test_a_close_minimum_apart_from_the_first_patch_is_a_patch_of_its_own():
    """Position 11 right: the tread's minimum lies 0.022 mm above the flange root's, less than the approach, but
    the gap between them rises above it (two interpenetration regions): two patches, the second on the tread."""
    one, two = (load_scene(_with(11, patch=k)).profile_contact for k in (1, 2))
    assert one.patches == two.patches == 2
    assert 0.0 < two.separation < 3e-5 and two.contact_position_rail - one.contact_position_rail > 5e-3
