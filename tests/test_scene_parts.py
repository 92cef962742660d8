"""The scene's typed parts: ``Scene.friction`` is the resolved friction law and ``Scene.kinematics`` holds the
speeds and creepages, each held once (the old attribute names read them)."""
import ast
import dataclasses
from pathlib import Path

import pytest

from railtherm.input.kinematics import Creepage, Kinematics
from railtherm.input.scene import Scene, load_scene
from railtherm.physics.friction import ConstantFriction, PolachFriction

BASE = dict(name="s", speed=30.0, normal_force=1e4, contact={"semi_axes": [3e-3, 4e-3]})


def test_friction_is_the_law_and_its_nominal_the_coefficient():
    sc = load_scene(dict(BASE, sliding_speed=1.0, friction=0.3))
    assert sc.friction == ConstantFriction(0.3) and sc.friction.nominal == 0.3
    polach = load_scene(dict(BASE, sliding_speed=1.0, friction={"law": "polach", "mu0": 0.4, "A": 0.5, "B": 2.0}))
    assert polach.friction == PolachFriction(0.4, 0.2, 0.5) and polach.friction.nominal == 0.4
    assert "friction_law" not in {f.name for f in dataclasses.fields(Scene)}


def test_a_scene_without_friction_has_none():
    sc = load_scene(dict(name="g", speed=10.0, heat_source={"flux": 1e8, "semi_axes": [1e-3, 1e-3]}))
    assert sc.friction is None and sc.kinematics == Kinematics(10.0)


def test_kinematics_are_built_once_and_the_scene_reads_them():
    rolling = load_scene(dict(BASE, creepage={"longitudinal": -1e-3, "spin": 0.2}, friction=0.3))
    assert rolling.kinematics == Kinematics(30.0, None, Creepage(-1e-3, 0.0, 0.2))
    sliding = load_scene(dict(BASE, sliding_speed=-2.0, friction=0.3))
    assert sliding.kinematics == Kinematics(30.0, -2.0, None)
    moved = dataclasses.replace(rolling, kinematics=Kinematics(20.0, None, Creepage(2e-3)))
    assert (moved.speed, moved.sliding_speed, moved.creepage) == (20.0, None, Creepage(2e-3))
    with pytest.raises(dataclasses.FrozenInstanceError):
        rolling.kinematics.speed = 1.0



def _is_scene(node) -> bool:
    """Whether an expression names a scene: ``scene``, ``sc``, ``s`` or an attribute ``.scene``."""
    return (isinstance(node, ast.Name) and node.id in ("scene", "sc", "s")
            or isinstance(node, ast.Attribute) and node.attr == "scene")


def test_no_code_reads_a_second_name_for_the_friction_law():
    """``scene.friction`` is the one name of the scene's law: no module of core or the plugins reads a
    scene's ``friction_law`` (directly or with getattr)."""
    root = Path(__file__).resolve().parents[1]
    readers = []
    for path in sorted([*root.glob("core/railtherm/**/*.py"), *root.glob("plugins/railtherm_*/**/*.py")]):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            direct = isinstance(node, ast.Attribute) and node.attr == "friction_law" and _is_scene(node.value)
            by_name = (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr"
                       and len(node.args) >= 2 and isinstance(node.args[1], ast.Constant)
                       and node.args[1].value == "friction_law")
            if direct or by_name:
                readers.append(f"{path.relative_to(root)}:{node.lineno}")
    assert readers == []
