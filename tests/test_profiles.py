"""Wheel and rail profiles: the readers on the Manchester benchmark's files and on bad files, the
built-in S1002 and 60E1 against their standard geometry and against the shared files, and the
``[scene.wheelset]`` profile keys."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial import cKDTree

from railtherm import SceneError
from railtherm.input.profiles import (load_profile, read_miniprof, read_profile, read_simpack, read_text,
                                      wheelset_geometry_from_table)
from railtherm.physics.profiles import _S1002_BOUNDS, Profile, ProfileError, _s1002_mm, s1002, uic60

DATA = Path(__file__).resolve().parent / "data" / "profiles"
PRW, PRR, BAN = DATA / "MBench_S1002_v3.prw", DATA / "MBench_UIC60_v3.prr", DATA / "MBench_UIC60_v3.ban"
#: the task's tolerance for the built-ins against the shared files [m]
FILE_TOL = 0.05e-3


def _distances(curve: Profile, y, z):
    """Normal distance [m] of points to a curve (nearest of samples 2 um apart), and whether the nearest
    sample is inside the curve (not an end point: the point lies where the two overlap)."""
    _, cy, cz, _, _ = curve.sample(2e-6)
    d, i = cKDTree(np.c_[cy, cz]).query(np.c_[y, z])
    return d, (i > 0) & (i < cy.size - 1)


# -- readers on the shared files ---------------------------------------------------------------------
def test_simpack_wheel_is_read_in_standard_axes():
    w = read_simpack(str(PRW))
    assert w.kind == "wheel"
    # mirror.y = 1 and inversion = 1: the file lists the flange at +y; read, it lies at -y as in EN 13715
    assert w.y[0] == pytest.approx(-69.612628e-3, abs=1e-12) and w.y[-1] == pytest.approx(60e-3, abs=1e-12)
    assert w.z[-1] == pytest.approx(-2.6356764e-3, abs=1e-12)   # the last file point, field side
    assert w.z.max() == pytest.approx(28e-3, abs=0.01e-3)       # the flange tip, 28 mm below the tread datum


def test_simpack_rail_and_miniprof_rail_are_the_same_rail():
    r = read_simpack(str(PRR))
    b = read_miniprof(str(BAN), mirror_y=True)
    assert r.kind == b.kind == "rail"
    assert r.y.size == b.y.size == 495
    np.testing.assert_allclose(b.y, r.y, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.z, r.z, rtol=0, atol=1e-12)
    assert r.y[0] == pytest.approx(-43.704898e-3, abs=1e-12)   # gauge face at -y, z down 38.5 mm
    assert r.z[0] == pytest.approx(38.510726e-3, abs=1e-12)


def test_read_profile_dispatches_on_the_extension():
    assert read_profile(str(PRW)).kind == "wheel"
    assert read_profile(str(BAN)).y[0] == pytest.approx(-30.595912e-3, abs=1e-12)   # as written, not mirrored


def test_text_units_are_detected_or_declared(tmp_path):
    y = np.linspace(-30, 30, 61)
    z = 300 - np.sqrt(300 ** 2 - y ** 2)
    (tmp_path / "mm.txt").write_text("# y z [mm]\n" + "\n".join(f"{a} {b}" for a, b in zip(y, z)))
    (tmp_path / "m.csv").write_text("\n".join(f"{a / 1e3},{b / 1e3}" for a, b in zip(y, z)))
    pm, pmm = read_text(str(tmp_path / "m.csv")), read_text(str(tmp_path / "mm.txt"))
    np.testing.assert_allclose(pm.y, pmm.y, atol=1e-15)
    np.testing.assert_allclose(pm.z, pmm.z, atol=1e-15)
    assert pm.curvature_at(0.0) == pytest.approx(1 / 0.3, rel=1e-4)
    (tmp_path / "amb.txt").write_text("\n".join(f"{a / 80} {b / 80}" for a, b in zip(y, z)))   # span 0.75
    with pytest.raises(ProfileError, match="amb.txt.*declare units"):
        read_text(str(tmp_path / "amb.txt"))
    assert read_text(str(tmp_path / "amb.txt"), units="m", max_spacing=0.02).y[-1] == pytest.approx(30 / 80)


# -- bad files ------------------------------------------------------------------------------------
def _write(tmp_path, name, pts, header="# y z mm\n"):
    path = tmp_path / name
    path.write_text(header + "\n".join(f"{a:.6f} {b:.6f}" for a, b in pts) + "\n")
    return str(path)


def _arc(n=41):
    y = np.linspace(-20.0, 20.0, n)
    return list(zip(y, 300 - np.sqrt(300 ** 2 - y ** 2)))


def test_a_profile_that_turns_back_is_not_a_function_of_y(tmp_path):
    pts = _arc() + [(19.5, 2.0), (19.0, 3.0)]            # an undercut at the end: y turns back at point 43
    path = _write(tmp_path, "undercut.txt", pts)
    with pytest.raises(ProfileError, match=r"undercut.txt, line 43: .*not a function of y"):
        read_text(path, units="mm")


def test_a_profile_that_crosses_itself_overlaps(tmp_path):
    pts = _arc()[:30] + [(8.0, 1.0), (8.5, -1.0)] + _arc()[30:]
    path = _write(tmp_path, "cross.txt", pts)
    with pytest.raises(ProfileError, match=r"cross.txt, line \d+: .*crosses itself"):
        read_text(path, units="mm")


def test_a_repeated_point_overlaps(tmp_path):
    pts = _arc()
    pts.insert(11, pts[10])
    with pytest.raises(ProfileError, match=r"rep.txt, line 13: .*repeats the previous one"):
        read_text(_write(tmp_path, "rep.txt", pts), units="mm")


def test_a_kink_is_refused_with_its_line(tmp_path):
    pts = [(y, 0.0) for y in np.arange(-20.0, 0.5, 0.5)] + [(y, y) for y in np.arange(0.5, 10.0, 0.5)]
    with pytest.raises(ProfileError, match=r"kink.txt, line 42: a kink of 0.785 rad"):   # 45 deg at y = 0, point 41
        read_text(_write(tmp_path, "kink.txt", pts), units="mm")


def test_a_gap_is_refused_with_its_line(tmp_path):
    pts = _arc()[:20] + _arc()[25:]        # y = -1 mm (line 21), then y = 5 mm (line 22)
    with pytest.raises(ProfileError, match=r"gap.txt, line 22: a gap of 6 mm"):
        read_text(_write(tmp_path, "gap.txt", pts), units="mm")


def test_an_unreadable_line_is_named(tmp_path):
    path = tmp_path / "bad.prr"
    text = PRR.read_text(encoding="latin-1").splitlines()
    k = next(i for i, t in enumerate(text) if "point.begin" in t) + 10
    text[k] = "1.0E+01  abc"
    path.write_text("\n".join(text))
    with pytest.raises(ProfileError, match=rf"bad.prr, line {k + 1}: cannot read '1.0E\+01  abc'"):
        read_simpack(str(path))


def test_missing_file_and_unsupported_rotation_are_named(tmp_path):
    with pytest.raises(ProfileError, match="nowhere.prw: cannot be read"):
        read_profile(str(tmp_path / "nowhere.prw"))
    text = PRR.read_text(encoding="latin-1").replace("rotate         = +0.000000000000000e+00",
                                                     "rotate         = +1.000000000000000e-02")
    (tmp_path / "rot.prr").write_text(text)
    line = 1 + next(i for i, t in enumerate(text.splitlines()) if t.strip().startswith("rotate"))
    with pytest.raises(ProfileError, match=rf"rot.prr, line {line}: rotate = \+1.0+e-02 is not supported"):
        read_simpack(str(tmp_path / "rot.prr"))


def test_miniprof_point_count_must_match_its_header(tmp_path):
    text = BAN.read_text(encoding="latin-1").replace("XYPoints=495", "XYPoints=494")
    (tmp_path / "n.ban").write_text(text)
    with pytest.raises(ProfileError, match=r"n.ban, line 7: XYPoints = 494 but the file has 495 points"):
        read_miniprof(str(tmp_path / "n.ban"))


# -- interpolant, mirroring, smoothing ---------------------------------------------------------------
def test_interpolant_slope_and_curvature_of_a_circle():
    t = np.linspace(-0.5, 0.5, 201)
    p = Profile(0.04 * np.sin(t), 0.04 * (1 - np.cos(t)), name="circle r 40 mm")
    y = np.array([-0.015, 0.0, 0.01])
    np.testing.assert_allclose(p.z_at(y), 0.04 - np.sqrt(0.04 ** 2 - y ** 2), atol=1e-10)
    np.testing.assert_allclose(p.slope_at(y), y / np.sqrt(0.04 ** 2 - y ** 2), atol=1e-7)
    np.testing.assert_allclose(p.curvature_at(y), 25.0, rtol=1e-5)
    with pytest.raises(ProfileError, match="outside the profile's range"):
        p.z_at(0.03)


def test_mirroring_is_the_mirror_image():
    w = s1002()
    m = w.mirrored()
    y = np.array([-0.05, -0.01, 0.0, 0.03])
    np.testing.assert_allclose(m.z_at(-y), w.z_at(y), atol=1e-12)
    np.testing.assert_allclose(m.slope_at(-y), -w.slope_at(y), atol=1e-9)
    np.testing.assert_allclose(m.mirrored().y, w.y, atol=0)


def test_smoothing_only_when_asked_and_recorded():
    rng = np.random.default_rng(1)
    y = np.linspace(-0.02, 0.02, 401)
    z = 0.3 - np.sqrt(0.3 ** 2 - y ** 2)
    zn = z + rng.normal(0, 1e-6, y.size)
    noisy = Profile(y, zn, name="noisy arc")
    assert noisy.smoothing == 0.0 and np.array_equal(noisy.z, zn)   # kept as given
    smooth = noisy.smoothed(0.5e-3)
    assert smooth.smoothing == 0.5e-3
    inner = np.linspace(-0.015, 0.015, 61)
    err_raw = np.abs(noisy.z_at(inner) - (0.3 - np.sqrt(0.3 ** 2 - inner ** 2))).max()
    err_smooth = np.abs(smooth.z_at(inner) - (0.3 - np.sqrt(0.3 ** 2 - inner ** 2))).max()
    assert err_smooth < 0.3 * err_raw
    with pytest.raises(ProfileError, match="smoothing length"):
        noisy.smoothed(0.0)


# -- built-ins: their standard geometry, and the shared files -------------------------------------------
def test_s1002_sections_meet_their_standard_values():
    w = s1002()
    assert w.z_at(0.0) == pytest.approx(0.0, abs=1e-12)                 # tread datum
    assert w.z_at(-0.055) == pytest.approx(0.028, abs=1e-9)             # flange tip: 16 + 12 mm (section G)
    assert w.curvature_at(-0.055) == pytest.approx(-1 / 0.012, rel=1e-4)  # convex flange tip, R12
    assert w.slope_at(0.045) == pytest.approx(-1 / 15, rel=1e-6)         # section A, 1:15 (0.066666667)
    assert w.slope_at(-0.039) == pytest.approx(-2.747477419, rel=1e-5)   # flange flank (section E)
    # the sections join: steps at their bounds below 0.15 um (the published coefficients' rounding
    # leaves 0.12 um at -35 mm, 0.04 um at -26 mm, less elsewhere)
    b = np.array(_S1002_BOUNDS[1:-1])
    assert np.abs(_s1002_mm(b - 1e-9) - _s1002_mm(b + 1e-9)).max() < 0.15e-3


def test_uic60_arcs_have_their_standard_radii():
    r = uic60()
    assert r.z.min() == pytest.approx(0.0, abs=1e-12) and r.z_at(0.0) == pytest.approx(0.0, abs=1e-12)
    for y, radius in ((0.005, 0.300), (-0.018, 0.080), (0.031, 0.013)):
        assert r.curvature_at(y) == pytest.approx(1 / radius, rel=1e-3), y
    assert r.y[0] == pytest.approx(-0.0370486, abs=1e-6)             # the 1:20 flank's lowest point
    assert r.slope_at(-0.0369) == pytest.approx(-20.0, rel=1e-3)        # the flank itself, 1:20
    assert r.y[-1] == pytest.approx(-r.y[0], abs=1e-15)                # symmetric head


def test_s1002_matches_the_shared_wheel_file():
    w = read_profile(str(PRW))
    d, inside = _distances(s1002(), w.y, w.z)
    assert inside.sum() >= w.y.size - 1
    assert d[inside].max() < FILE_TOL, d.max()


def test_uic60_inclined_1_in_40_matches_the_shared_rail_file():
    """The file is inclined 1:40 with its origin at the inclined top: the built-in, inclined by
    atan(1/40), is moved onto it by a least-squares translation (the files' origin convention) and
    then lies within 0.05 mm of every file point where the two overlap (the file also holds the R3
    fillet under the head, which the built-in leaves out)."""
    r = read_profile(str(PRR))
    b = uic60().rotated(np.arctan(1 / 40))
    _, cy, cz, _, _ = b.sample(2e-6)
    tree = cKDTree(np.c_[cy, cz])

    def res(shift):
        d, i = tree.query(np.c_[r.y - shift[0], r.z - shift[1]])
        return np.where((i > 0) & (i < cy.size - 1), d, 0.0)
    shift = least_squares(res, [0.0, 0.0]).x
    d, i = tree.query(np.c_[r.y - shift[0], r.z - shift[1]])
    inside = (i > 0) & (i < cy.size - 1)
    assert inside.sum() > 0.75 * r.y.size
    # the inclined crown's top lies 300 sin(atan(1/40)) = 7.50 mm to the field side of the crown
    assert shift[0] == pytest.approx(-300e-3 * np.sin(np.arctan(1 / 40)), abs=0.1e-3)
    assert d[inside].max() < FILE_TOL, d[inside].max()


def test_load_profile_by_name_or_path():
    assert load_profile("S1002").name == "s1002" and load_profile("60E1").kind == "rail"
    assert load_profile(PRW.name, base=str(DATA)).kind == "wheel"


# -- the [scene.wheelset] profile keys ------------------------------------------------------------------
GOOD = {"wheel_profile": "s1002", "rail_profile": "uic60", "rail_inclination": 0.025, "gauge": 1.435,
        "gauge_height": 0.014, "flange_back_distance": 1.360, "flange_back_position": -0.070,
        "nominal_radius": 0.46, "lateral_shift": 0.005, "yaw_angle": 0.012, "roll_angle": -6.272e-4,
        "pitch_velocity": -4.329, "vertical_force": 10e3, "side": "right"}


def test_wheelset_table_is_read():
    g = wheelset_geometry_from_table("curve", GOOD)
    assert g.wheel_profile.kind == "wheel" and g.rail_profile.kind == "rail"
    assert (g.lateral_shift, g.roll_angle, g.side) == (0.005, -6.272e-4, "right")
    ws = g.on_track()
    assert ws.pitch_velocity == -4.329 and ws.rail_inclination == 0.025
    g2 = wheelset_geometry_from_table("curve", {**GOOD, "roll_angle": "balance", "pitch_velocity": "free"})
    assert g2.on_track(roll_angle=0.001, pitch_velocity=-4.3).roll_angle == 0.001
    with pytest.raises(ValueError, match="balance"):
        g2.on_track()


@pytest.mark.parametrize("key, value, allowed", [
    ("gauge", -1.435, r"a number in \(0.5, 2\) m"),
    ("roll_angle", "level", r"or 'balance'"),
    ("pitch_velocity", float("nan"), r"or 'free'"),
    ("side", "middle", r"'right' or 'left'"),
    ("wheel_profile", 3, "a built-in name"),
    ("rail_profile", "s1002", "a rail profile"),
    ("cant", 0.1, "a key among"),
])
def test_bad_wheelset_keys_name_scene_key_value_and_what_is_allowed(key, value, allowed):
    with pytest.raises(SceneError, match=rf"scene 'curve': key 'wheelset.{key}' = .* is not allowed: .*{allowed}"):
        wheelset_geometry_from_table("curve", {**GOOD, key: value})


def test_wheelset_missing_radius_and_bad_file_are_named(tmp_path):
    with pytest.raises(SceneError, match="scene 'curve': key 'wheelset.nominal_radius' is missing"):
        wheelset_geometry_from_table("curve", {k: v for k, v in GOOD.items() if k != "nominal_radius"})
    (tmp_path / "w.txt").write_text("0 0\n1 1\nx y\n")
    with pytest.raises(ProfileError, match=r"scene 'curve': key 'wheelset.wheel_profile': profile .*w.txt, line 3"):
        wheelset_geometry_from_table("curve", {**GOOD, "wheel_profile": "w.txt"}, base=str(tmp_path))


def test_a_loaded_profile_file_is_read_again_only_when_it_changes(tmp_path):
    """load_profile returns the profile already read while the file is unchanged, and reads a changed file."""
    path = _write(tmp_path, "arc.txt", _arc())
    first = load_profile(path, units="mm")
    assert load_profile(path, units="mm") is first
    pts = _arc()
    _write(tmp_path, "arc.txt", [(y, z + 1.0) for y, z in pts] + [(pts[-1][0] + 0.5, pts[-1][1] + 1.0)])
    second = load_profile(path, units="mm")
    assert second is not first and second.z_at(0.0) == pytest.approx(first.z_at(0.0) + 1e-3)
    assert load_profile("s1002") is load_profile("S1002")
