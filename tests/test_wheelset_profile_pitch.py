"""``pitch_velocity = "free"``: the pitch velocity at which the chain's own forces on both wheels have no moment
about the axle, against the pitch velocities of the Manchester benchmark's A-2.2 table (found there by iterating
CONTACT, the exact theory, as ``kalker`` is) and CONTACT's published longitudinal creep force. Tolerance on the
pitch velocity: the creep force's 5 % target in the linear regime, |d(omega)| r / V <= 0.05 |xi| (xi CONTACT's
longitudinal creepage, r the rolling radius)."""
from __future__ import annotations

import copy

import pytest

import railtherm
from railtherm.input.scene import load_scene

from manchester_cases import A22, a22_scene

SPEED = A22["setup"]["speed"] * 1e-3


def _free(position, side="right", **keys):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(pitch_velocity="free")
    return load_scene(dict(s, **keys))


@pytest.mark.slow
@pytest.mark.parametrize("side", ["right", "left"])
def test_the_free_pitch_velocity_and_fx_are_the_benchmarks(side):
    """Position 13, kalker at level 2: omega -4.32919 against the table's -4.32937 rad/s (right wheel) and the
    longitudinal creep force within 5 % of CONTACT's."""
    r = railtherm.solve(_free(13, side), "kalker", level=2)
    ref = next(x for x in A22["result"] if x["side"] == side and x["position"] == 13)
    want = A22["position"][12]["pitch_velocity"]
    tol = 0.05 * abs(ref["longitudinal_creepage"]) * SPEED / 0.46
    assert r.attrs["wheelset_pitch_velocity"] == pytest.approx(want, abs=tol)
    assert -float(r["creep_force_x"]) == pytest.approx(ref["fx"], rel=0.05)


def test_the_free_result_is_the_result_at_the_pitch_velocity_found():
    """A Hertz + FASTSIM chain: the result of the "free" scene is, to the last bit, the result of the scene with
    that pitch velocity given; the moment left is below the secant's tolerance (1e-7 of sum N times R0)."""
    chain = {"normal": "wheelset-profile", "tangential": "fastsim"}
    outputs = ["normal_force", "creep_force_x", "creep_force_y", "contact_angle", "creepage_longitudinal"]
    r = railtherm.solve(_free(13, outputs=outputs), chain, level=0)
    w = r.attrs["wheelset_pitch_velocity"]
    s = copy.deepcopy(a22_scene(13, "right"))
    s["wheelset"].update(pitch_velocity=w)
    given = railtherm.solve(load_scene(dict(s, outputs=outputs)), chain, level=0)
    for name in outputs:
        assert float(r[name]) == float(given[name]), name
    assert abs(r.attrs["wheelset_axle_moment"]) <= 1e-7 * 2e4 * 0.47
    assert w == pytest.approx(-SPEED / 0.46, rel=0.01)     # rolling, near the nominal radius's pitch velocity


@pytest.mark.slow
@pytest.mark.parametrize("side", ["right", "left"])
def test_the_equilibrium_from_the_scene_keys_alone_meets_the_benchmark(side):
    """Position 13 with roll_angle = "balance" (the axle load 20 kN) and pitch_velocity = "free" instead of the
    table's roll and pitch velocity: kalker at level 2 meets CONTACT's published results with the benchmark's
    tolerances (right wheel, its normal force meeting the vertical force with kalker's own creep forces: N 9712.8 /
    9709, Fx 880.3 / 880.0, Fy 2776.1 / 2775.0 N)."""
    s = copy.deepcopy(a22_scene(13, side))
    s["wheelset"].update(pitch_velocity="free", roll_angle="balance",
                         vertical_force=2.0 * A22["setup"]["vertical_force"])
    r = railtherm.solve(load_scene(s), "kalker", level=2)
    ref = next(x for x in A22["result"] if x["side"] == side and x["position"] == 13)
    m = 1.0 if side == "right" else -1.0
    assert m * float(r["contact_position_rail"]) == pytest.approx(ref["ycp_r"] * 1e-3, abs=0.5e-3)
    assert m * float(r["contact_angle"]) == pytest.approx(ref["contact_angle"], abs=0.02)
    assert float(r["normal_force"]) == pytest.approx(ref["fn"], rel=0.03)
    assert -float(r["creep_force_x"]) == pytest.approx(ref["fx"], rel=0.05)
    assert -m * float(r["creep_force_y"]) == pytest.approx(ref["fs"], rel=0.05)
    assert float(r["max_pressure"]) == pytest.approx(ref["pmax"] * 1e6, rel=0.08)
