"""Several patches of one wheel sharing its vertical force (``wheelset.patch = "all"``): the load sharing at one
common approach against Hertz's exact relations, the stacked result against the chain's own per-patch solves and
the totals' definition, and the one-patch case against the CONTACT program's published A-2.2 results (the
tolerances of tests/test_manchester.py)."""
from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import pytest

import railtherm
from railtherm import SceneError
from railtherm.contract.schema import validate_dataset
from railtherm.input.scene import load_scene
from railtherm.input.wheelset_patch_scenes import patch_scenes
from railtherm.input.wheelset_profile import share_vertical_force
from railtherm.input.wheelset_profile_vertical import with_normal_forces
from railtherm.references.hertz import hertz_from_curvatures, hertz_from_penetration
from railtherm.solving.wheelset_patches import wheel_totals

from manchester_cases import A22, a22_scene

E_STAR = 82e9 / (1.0 - 0.28)          # two steel bodies, G = 82 GPa, nu = 0.28: E* = G / (1 - nu)
CURV = (1.1, 60.0)                    # [1/m]


def _all(position, side="right", **wheelset):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(patch="all", **wheelset)
    return s


def test_two_equal_patches_share_the_force_equally():
    """Two identical patches side by side: each carries Fz / 2 at Hertz's approach of Fz / 2."""
    delta, normal, lateral = share_vertical_force(1e4, [0.0, 0.0], [0.0, 0.0], [CURV, CURV], E_STAR)
    assert normal == pytest.approx([5e3, 5e3], rel=1e-9) and lateral == [0.0, 0.0]
    assert delta == pytest.approx(hertz_from_curvatures(*CURV, 5e3, E_STAR).approach, rel=1e-8)


def test_an_inclined_patch_carries_the_vertical_force_over_the_cosine():
    """One patch at contact angle gamma without lateral force: N cos(gamma) = Fz, and the approach along its normal
    is the vertical one times cos(gamma)."""
    g = -0.4
    delta, normal, _ = share_vertical_force(1e4, [0.0], [g], [CURV], E_STAR)
    assert normal[0] == pytest.approx(1e4 / math.cos(g), rel=1e-9)
    assert delta * math.cos(g) == pytest.approx(hertz_from_curvatures(*CURV, 1e4 / math.cos(g), E_STAR).approach,
                                                rel=1e-8)


def test_a_patch_the_approach_does_not_close_carries_nothing():
    """A second patch 0.1 mm above the first, beyond the first's approach under the whole force (~0.03 mm)."""
    delta, normal, _ = share_vertical_force(1e4, [0.0, 1e-4], [0.0, 0.0], [CURV, CURV], E_STAR)
    assert normal[1] == 0.0 and normal[0] == pytest.approx(1e4, rel=1e-9) and delta < 1e-4


def test_the_lateral_force_takes_its_share_of_the_vertical_force():
    """With a lateral force Fy(N) on the wheel in the plane, N cos(gamma) - Fy sin(gamma) = Fz."""
    g = -0.4
    _, normal, lateral = share_vertical_force(1e4, [0.0], [g], [CURV], E_STAR, lambda i, n: 0.25 * n)
    assert normal[0] * math.cos(g) - lateral[0] * math.sin(g) == pytest.approx(1e4, rel=1e-9)
    assert lateral[0] == pytest.approx(0.25 * normal[0], rel=1e-12)


_SOLVED: dict = {}


def _solve(position, side="right", method="kalker", level=1, **scene):
    key = (position, side, str(method), level)
    if key not in _SOLVED:
        scene = load_scene(dict(_all(position, side), **scene))
        _SOLVED[key] = scene, railtherm.solve(scene, method, level=level)
    return _SOLVED[key]


def test_a_flange_root_and_a_tread_patch_are_solved_and_stacked():
    """A-2.2 position 11 right: the flange root and, 0.022 mm above it, the tread (their interpenetration regions
    apart) share the 10 kN at one common approach (the result's ``wheelset_approach``: each patch's normal force is
    the Hertz-equivalent force of its approach there, rel 1e-9, after the exact chain balanced the wheel's vertical
    force with its own creep forces); each patch of the stacked result is the chain's own solve of that patch's
    scene at those shares to the last bit, and the totals are the patches' forces turned into track axes."""
    scene, r = _solve(11)
    validate_dataset(r, "kalker")
    assert r.sizes["patch"] == 2 and list(r["patch"].values) == [1, 2] and r["patch"].attrs["units"] == "1"
    assert r["normal_force"].dims == ("patch",) and r["max_surface_temperature"].dims == ("body", "patch")
    pcs = scene.profile_contact.contacts
    assert pcs[1].separation > 0.0 and pcs[1].contact_angle > pcs[0].contact_angle   # the tread, flatter
    assert pcs[1].contact_position_rail - pcs[0].contact_position_rail > 5e-3
    delta = float(r.attrs["wheelset_approach"])
    for c, n in zip(pcs, r["normal_force"].values):
        h = hertz_from_penetration(*c.hertz_curvatures, (delta - c.separation) * math.cos(c.contact_angle), E_STAR)
        assert float(n) == pytest.approx(h.normal_force, rel=1e-9)
    shared = with_normal_forces(scene.profile_contact, r["normal_force"].values, delta, "as solved")
    balanced = dataclasses.replace(scene, profile_contact=shared)
    for k, sub in enumerate(patch_scenes(balanced, [o for o in scene.outputs if not o.startswith("wheel_force")]
                                         + ["normal_force", "creep_force_x", "creep_force_y", "contact_angle"])):
        one = railtherm.solve(sub, "kalker", level=1)
        for name in ("normal_force", "creep_force_x", "creep_force_y", "max_pressure", "contact_position_rail"):
            assert float(r[name][k]) == float(one[name]), (k, name)
    fx, fy, fz = wheel_totals(r["normal_force"], r["creep_force_x"], r["creep_force_y"], r["contact_angle"])
    assert (float(r["wheel_force_x"]), float(r["wheel_force_y"]), float(r["wheel_force_z"])) == (fx, fy, fz)
    for name in ("wheel_force_x", "wheel_force_y", "wheel_force_z"):
        assert r[name].dims == () and r[name].attrs["units"] == "N"


def test_the_shares_balance_the_vertical_force_with_the_lateral_force_estimate():
    """The loaded shares balance Fz with each patch's estimated lateral force at the contact angles they were shared
    with (the search's): sum N cos(d) - Fy_estimate sin(d) = Fz (rel 1e-9). The exact chain's result balances it
    with its own (tests/test_wheelset_vertical_force.py)."""
    scene = load_scene(_all(11))
    pcs = scene.profile_contact.contacts
    est = np.array([c.lateral_force_estimate for c in pcs])
    d = np.array([c.contact_angle for c in pcs])
    n = np.array([c.normal_force for c in pcs])
    assert float((n * np.cos(d) - est * np.sin(d)).sum()) == pytest.approx(1e4, rel=1e-9)


def test_a_hertz_chain_solves_the_same_patches_at_the_same_shares():
    scene, r = _solve(11, method={"normal": "wheelset-profile", "tangential": "fastsim"}, level=0,
                      outputs=["normal_force", "creep_force_y", "wheel_force_z"])
    assert r.sizes["patch"] == 2
    assert list(r["normal_force"].values) == [c.normal_force for c in scene.profile_contact.contacts]


def test_position_1_is_one_patch():
    """Position 1 right: the second gap minimum, 11 mm from the first and 8 um above it, lies inside the first's
    interpenetration region: one patch carrying the whole force, as CONTACT reports it."""
    pc = load_scene(_all(1)).profile_contact
    assert pc.patches == 1 and len(pc.contacts) == 1


@pytest.mark.parametrize("side", ["right", "left"])
def test_one_patch_against_contact(side):
    """Position 13: one patch per wheel; patch = "all" meets the published results with the benchmark's
    tolerances (position 0.5 mm, angle 0.02 rad, normal force 3 %, creep forces 5 %, pmax 8 %)."""
    _, r = _solve(13, side, level=2)
    ref = next(x for x in A22["result"] if x["side"] == side and x["position"] == 13)
    m = 1.0 if side == "right" else -1.0
    assert r.sizes["patch"] == 1
    assert m * float(r["contact_position_rail"][0]) == pytest.approx(ref["ycp_r"] * 1e-3, abs=0.5e-3)
    assert m * float(r["contact_angle"][0]) == pytest.approx(ref["contact_angle"], abs=0.02)
    assert float(r["normal_force"][0]) == pytest.approx(ref["fn"], rel=0.03)
    assert -float(r["creep_force_x"][0]) == pytest.approx(ref["fx"], rel=0.05)
    assert -m * float(r["creep_force_y"][0]) == pytest.approx(ref["fs"], rel=0.05)
    assert float(r["max_pressure"][0]) == pytest.approx(ref["pmax"] * 1e6, rel=0.08)


def test_a_pass_history_in_a_scene_of_several_patches_is_refused():
    s = dict(_all(11), outputs=["normal_force", "temperature_history"])
    with pytest.raises(SceneError, match=r"scene 'a22-11-right': key 'outputs' = 'temperature_history' is not "
                                         r"allowed: a quantity over the body and the patch's grid in a scene of "
                                         r"several patches"):
        load_scene(s)


def test_the_wheel_totals_need_every_patch():
    s = dict(a22_scene(13, "right"), outputs=["normal_force", "wheel_force_z"])
    with pytest.raises(SceneError, match=r"key 'outputs' = 'wheel_force_z' is not allowed: the wheel's total force "
                                         r"over its patches only with wheelset.patch = \"all\""):
        load_scene(s)


def test_a_plain_scene_cannot_ask_the_wheel_totals():
    plain = {"name": "ellipse", "speed": 30.0, "friction": 0.3, "normal_force": 1e4,
             "contact": {"semi_axes": [6e-3, 4e-3]}, "creepage": {"longitudinal": -1e-3},
             "outputs": ["wheel_force_x"]}
    with pytest.raises(SceneError, match=r"'ellipse'.*outputs.*wheel_force_x.*wheel_profile"):
        load_scene(plain)


def test_a_scene_of_several_patches_runs_in_a_study(tmp_path):
    """Position 11 right with patch = "all" in a study (a Hertz + FASTSIM chain): the run is written with its
    patch dimension and the wheel's totals, and the metrics phase reads it (runs are not failed)."""
    import json

    import xarray as xr

    from railtherm.output import store
    s = _all(11)
    ws = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in s["wheelset"].items())
    study = tmp_path / "patches.toml"
    study.write_text(f'schema_version = 1\n[study]\nname = "patches"\nmethods = ["equivalent"]\nlevels = [0]\n'
                     f'repeat = 1\nwarmup = false\n'
                     f'reference = "equivalent"\n[study.chains.equivalent]\nnormal = "wheelset-profile"\n'
                     f'tangential = "fastsim"\n[[scene]]\nname = "p11"\nspeed = {s["speed"]}\n'
                     f'friction = {s["friction"]}\n'
                     f'outputs = ["normal_force", "creep_force_x", "creep_force_y", "wheel_force_z"]\n'
                     f'wheel = {{ shear_modulus = 82e9, poisson_ratio = 0.28 }}\n'
                     f'rail = {{ shear_modulus = 82e9, poisson_ratio = 0.28 }}\nwheelset = {{ {ws} }}\n')
    out = tmp_path / "out"
    railtherm.run_study(str(study), out=out, executor="serial", report=False)
    rec = json.loads(store.study_path(out).read_text())["records"][0]
    assert rec["status"] != "failed", rec
    with xr.open_dataset(out / "runs" / "p11" / "equivalent" / "level-0.nc") as ds:
        assert ds.sizes["patch"] == 2 and ds["wheel_force_z"].dims == ()
