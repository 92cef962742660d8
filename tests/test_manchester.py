"""The Manchester contact benchmark, case A-2.2, through the scene vocabulary of a wheelset on profiles and
``railtherm.solve(scene, "kalker", level=2)``, against the CONTACT program's published results
(tests/data/profiles/manchester_a22.toml: mm, N, MPa there; forces on the rail, creepages of the rail
relative to the wheel, the left wheel along the track's y).

railtherm reports forces on the wheel and creepages of the wheel relative to the rail (both minus
CONTACT's), and the left wheel in its own mirrored axes (lateral quantities and the contact angle change
sign once more). Tolerances are the targets of the benchmark check: contact position 0.5 mm, contact angle
0.02 rad, normal force 3 %, creep forces 5 % where |F| > 0.1 uN, max pressure 8 %.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import railtherm
from railtherm.input.scene import load_scene

DATA = Path(__file__).resolve().parent / "data" / "profiles"
A22 = tomllib.loads((DATA / "manchester_a22.toml").read_text())
POSITION_TOL, ANGLE_TOL, NORMAL_RTOL, CREEP_RTOL, PMAX_RTOL = 0.5e-3, 0.02, 0.03, 0.05, 0.08


def a22_scene(position: int, side: str) -> dict:
    """The benchmark's wheel ``side`` at ``position`` as a scene mapping (SI units)."""
    s, p = A22["setup"], A22["position"][position - 1]
    assert p["id"] == position
    mat = {"shear_modulus": s["shear_modulus"] * 1e6, "poisson_ratio": s["poisson_ratio"]}
    return {"name": f"a22-{position}-{side}", "speed": s["speed"] * 1e-3, "friction": s["friction"],
            "wheel": mat, "rail": mat,
            "wheelset": {"wheel_profile": str(DATA / "MBench_S1002_v3.prw"),
                         "rail_profile": str(DATA / "MBench_UIC60_v3.prr"),
                         "rail_inclination": s["rail_cant"], "gauge": s["gauge"] * 1e-3,
                         "gauge_height": s["gauge_height"] * 1e-3,
                         "flange_back_distance": s["flange_back_distance"] * 1e-3,
                         "flange_back_position": s["flange_back_position"] * 1e-3,
                         "nominal_radius": s["nominal_radius"] * 1e-3, "lateral_shift": p["lateral_shift"] * 1e-3,
                         "yaw_angle": p["yaw"], "roll_angle": p["roll"], "pitch_velocity": p["pitch_velocity"],
                         "vertical_force": s["vertical_force"], "side": side}}


def _reference(side, position):
    return next(r for r in A22["result"] if r["side"] == side and r["position"] == position)


_SOLVED: dict = {}


def _solve(position, side):
    if (position, side) not in _SOLVED:
        scene = load_scene(a22_scene(position, side))
        _SOLVED[position, side] = scene, railtherm.solve(scene, "kalker", level=2)
    return _SOLVED[position, side]


def _compare(position, side) -> dict:
    """Every compared quantity: (railtherm in CONTACT's convention, CONTACT's, tolerance, relative?)."""
    scene, r = _solve(position, side)
    ref = _reference(side, position)
    pc = scene.profile_contact
    m = 1.0 if side == "right" else -1.0          # the left wheel's own axes against the track's y
    return {
        "contact_position": (m * pc.contact_position_rail, ref["ycp_r"] * 1e-3, POSITION_TOL, False),
        "contact_angle": (m * pc.contact_angle, ref["contact_angle"], ANGLE_TOL, False),
        "normal_force": (float(r["normal_force"]), ref["fn"], NORMAL_RTOL, True),
        "creep_force_x": (-float(r["creep_force_x"]), ref["fx"], CREEP_RTOL, True),
        "creep_force_y": (-m * float(r["creep_force_y"]), ref["fs"], CREEP_RTOL, True),
        "max_pressure": (float(r["max_pressure"]), ref["pmax"] * 1e6, PMAX_RTOL, True),
    }


CASES = [(13, "right"), (13, "left"), (1, "right")]
QUANTITIES = ["contact_position", "contact_angle", "normal_force", "creep_force_x", "creep_force_y", "max_pressure"]
#: misses, with why (docs: the module docstring of railtherm.input.wheelset_profile)
KNOWN_MISSES = {
    (1, "right", "contact_position"): "two-point geometry: the reference point is the centroid of the undeformed "
                                      "interpenetration at the Hertz-equivalent approach, -9.86 mm against CONTACT's "
                                      "-8.66 mm (kalker's pressure centroid lies at -9.0 mm); CONTACT's own definition "
                                      "of the point for such a patch is not reproduced",
    (1, "right", "creep_force_x"): "CONTACT's Fx is 0.28 N (the pitch velocity balances the wheel's moment); 5 % of it "
                                   "is a longitudinal creepage accuracy of 1e-9, below the planar approach's "
                                   "reference-point choice (railtherm's Fx is 15 N)",
    (1, "right", "creep_force_y"): "two-point geometry: the one elastic patch spans two gap minima 11 mm apart and "
                                   "Fy comes from spin, which depends on the plane chosen for the whole patch; the "
                                   "plane at the interpenetration centroid gives +6.9 %",
}


@pytest.mark.parametrize("quantity", QUANTITIES)
@pytest.mark.parametrize("position,side", CASES)
def test_a22_against_contact(position, side, quantity, request):
    if (position, side, quantity) in KNOWN_MISSES:
        request.applymarker(pytest.mark.xfail(reason=KNOWN_MISSES[position, side, quantity], strict=True))
    got, want, tol, relative = _compare(position, side)[quantity]
    if relative:
        assert got == pytest.approx(want, rel=tol), (quantity, got, want)
    else:
        assert got == pytest.approx(want, abs=tol), (quantity, got, want)


def test_a22_position_1_one_patch_spans_both_minima():
    """CONTACT's one patch at position 1 has 1291 elements of 0.2 mm (51.6 mm2): the gap fitted over the
    nearly touching second minimum gives the same area (within the max-pressure tolerance)."""
    _, r = _solve(1, "right")
    assert float(r["contact_area"]) == pytest.approx(_reference("right", 1)["contact_elements"] * 0.04e-6,
                                                     rel=PMAX_RTOL)
