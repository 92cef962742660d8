"""Scene and study parsing: defaults, sweeps, validation messages, stable hashes."""
import math

import pytest

import railtherm
from railtherm.input.scene import load_scene
from railtherm.input.study import parse_study

BASE = {"name": "s", "normal_force": 100e3, "contact": {"shape": "ellipse", "semi_axes": [5.88e-3, 10.54e-3]},
        "speed": 30.0, "sliding_speed": 1.0, "friction": 0.3}


def _err(**changes):
    s = dict(BASE)
    s.update(changes)
    with pytest.raises(railtherm.SceneError) as ei:
        load_scene(s)
    return str(ei.value)


@pytest.mark.parametrize("key,value,allowed", [
    ("friction", -0.3, ">= 0"),
    ("speed", math.nan, "finite"),
    ("speed", "fast", "finite number"),
    ("normal_force", -1.0, ">= 0"),
    ("heat_partition", 1.5, "equal-temperature"),
    ("convection", True, "finite number"),
])
def test_bad_values_name_scene_key_value_allowed(key, value, allowed):
    msg = _err(**{key: value})
    assert "scene 's'" in msg and repr(key) in msg and repr(value) in msg and allowed in msg


def test_unknown_key_lists_allowed():
    msg = _err(fricton=0.3)
    assert "unknown key 'fricton'" in msg and "friction" in msg


def test_nested_unknown_and_negative_radius():
    msg = _err(contact={"shape": "line", "wheel_radius": -0.46})
    assert "contact.wheel_radius" in msg and "-0.46" in msg
    msg = _err(wheel={"density": 7850.0, "colour": "red"})
    assert "wheel.colour" in msg


def test_missing_keys_say_what_to_give():
    s = dict(BASE)
    del s["friction"]
    with pytest.raises(railtherm.SceneError, match="friction"):
        load_scene(s)
    s = dict(BASE)
    s["creepage"] = {"longitudinal": 1e-3}
    with pytest.raises(railtherm.SceneError, match="exactly one of 'sliding_speed'"):
        load_scene(s)


def test_youngs_modulus_converts_and_hash_is_stable():
    a = load_scene(dict(BASE, wheel={"youngs_modulus": 2 * 82e9 * 1.28, "poisson_ratio": 0.28}))
    assert a.wheel.shear_modulus == pytest.approx(82e9)
    b = load_scene(dict(BASE, name="other", wheel={"youngs_modulus": 2 * 82e9 * 1.28, "poisson_ratio": 0.28}))
    assert a.hash == b.hash  # the name is not physics
    c = load_scene(dict(BASE, friction=0.31))
    assert c.hash != a.hash
    assert load_scene(a.to_dict()).hash == a.hash


def test_given_heat_source_scene():
    s = load_scene({"name": "g", "speed": 1.0, "heat_source": {"flux": 1e6, "shape": "uniform", "semi_axes": [2e-3, 2e-3]}})
    assert s.heat_source.flux == 1e6 and s.contact_shape == "ellipse" and s.tangential == "given"
    with pytest.raises(railtherm.SceneError, match="exactly one of 'semi_axes'"):
        load_scene({"name": "g", "speed": 1.0, "heat_source": {"flux": 1e6}})


def test_study_defaults_and_sweeps():
    doc = {"schema_version": 1, "study": {"name": "x", "levels": [0, 2]},
           "defaults": {"wheel": {"density": 7000.0}, "friction": 0.3},
           "scene": [dict(BASE, convection=[0.0, 10.0], speed=[30.0, 90.0], wheel={"conductivity": 40.0})]}
    st = parse_study(doc)
    assert len(st.scenes) == 4
    names = [s.name for s in st.scenes]
    assert "s--speed=30,convection=0" in names or "s--convection=0,speed=30" in names
    sc = st.scenes[0]
    assert sc.wheel.density == 7000.0 and sc.wheel.conductivity == 40.0  # defaults filled, scene wins
    assert set(sc.sweep) == {"convection", "speed"}
    assert len({s.hash for s in st.scenes}) == 4


def test_study_level_errors():
    with pytest.raises(railtherm.SceneError, match="study.levels"):
        parse_study({"study": {"levels": [-1]}, "scene": [BASE]})
    with pytest.raises(railtherm.SceneError, match="unknown key 'study.colour'"):
        parse_study({"study": {"colour": 1}, "scene": [BASE]})
    with pytest.raises(railtherm.SceneError, match="used twice"):
        parse_study({"scene": [BASE, BASE]})


@pytest.mark.parametrize("value, ok", [(1, True), (2, True), (3, False), ("1", False), (True, False), (1.0, False)])
def test_an_integer_choice_takes_integers_only(value, ok):
    """wheelset.contact is 1 or 2: the integer, not "1", true or 1.0 (Choice compares type and value)."""
    import railtherm
    sc = {"name": "ws", "contact": {"shape": "ellipse", "semi_axes": [6e-3, 10e-3]}, "speed": 20.0, "friction": 0.3,
          "wheelset": {"conicity": 0.05, "contact": value}}
    if ok:
        assert railtherm.load_scene(sc).wheelset.contact == value
    else:
        with pytest.raises(railtherm.SceneError, match="wheelset.contact"):
            railtherm.load_scene(sc)
