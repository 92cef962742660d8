"""``roll_angle = "balance"``: the wheelset's roll at which both wheels carry half the axle load, against the roll
the Manchester benchmark's A-2.2 table gives for each position (found there by iterating CONTACT's own normal
solution). Tolerance: a roll error d(phi) moves each wheel by +-L d(phi) vertically (L = 0.75 m, half the
distance between the two wheels' contacts), and a wheel's vertical force grows as its approach delta^(3/2), so the
load split moves by 1.5 L d(phi) / delta; holding that to the normal force's 3 % target gives
|d(phi)| <= 0.02 delta / L, plus half a unit of the table's last printed digit (4 significant digits)."""
from __future__ import annotations

import copy
import dataclasses
import math

import pytest

import railtherm
from railtherm.input.scene import load_scene
from railtherm.references.hertz import hertz_from_curvatures

from manchester_cases import A22, a22_scene

L_ARM = 0.75   # [m]
E_STAR = A22["setup"]["shear_modulus"] * 1e6 / (1.0 - A22["setup"]["poisson_ratio"])   # [Pa], two steel bodies


def _balanced(position, side="right", **keys):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(roll_angle="balance", vertical_force=2.0 * A22["setup"]["vertical_force"])
    return load_scene(dict(s, **keys))


def _rounding(value: float) -> float:
    """Half a unit in the fourth significant digit of a table value."""
    return 0.0 if value == 0.0 else 0.5 * 10.0 ** (math.floor(math.log10(abs(value))) - 3)


KNOWN_MISSES = {2: "position 2 right's patch is far from Hertzian (a sharp gap minimum beside a flat region 5 mm "
                   "away): the Hertz-equivalent approach the balance uses at scene load is not CONTACT's, roll "
                   "-1.95e-5 against the table's -2.30e-5 rad; the kalker chain's own approaches give it "
                   "(test_kalkers_approaches_give_position_2_the_benchmarks_roll)"}


@pytest.mark.parametrize("position", [1, 2, 5, 10, 11, 13, 16, 21])
def test_the_balanced_roll_is_the_benchmarks(position, request):
    if position in KNOWN_MISSES:
        request.applymarker(pytest.mark.xfail(reason=KNOWN_MISSES[position], strict=True))
    pc = _balanced(position).profile_contact
    want = A22["position"][position - 1]["roll"]
    # the wheel's vertical approach: its patch's Hertz-equivalent one along the normal, over cos(delta)
    hertz = hertz_from_curvatures(*pc.hertz_curvatures, pc.normal_force, E_STAR)
    approach = hertz.approach / math.cos(pc.contact_angle)
    tol = 0.02 * approach / L_ARM + _rounding(want)
    assert pc.balanced_roll == pytest.approx(want, abs=tol), (pc.balanced_roll, want, tol)


def test_the_centred_wheelset_does_not_roll():
    """Position 1: no shift, no yaw, symmetric profiles: the roll is zero to the secant's tolerance."""
    assert abs(_balanced(1).profile_contact.balanced_roll) < 1e-9


def test_the_wheel_carries_half_the_axle_load_and_the_result_says_the_roll():
    """The scene of a balanced wheel gets half the axle load as its vertical force, and its result carries the
    roll found."""
    right = _balanced(13, "right", outputs=["normal_force"])
    assert right.profile_contact.vertical_force == 1e4
    r = railtherm.solve(right, {"normal": "wheelset-profile"}, level=0)
    assert r.attrs["wheelset_roll_angle"] == right.profile_contact.balanced_roll


def test_a_hertz_equivalent_chain_keeps_the_loaded_roll_and_says_so():
    """A chain on the Hertz-equivalent ellipse gets the roll balanced with the Hertz-equivalent forces at load,
    and its result says so."""
    from railtherm.input.wheelset_profile import ROLL_BALANCE
    right = _balanced(13, "right", outputs=["normal_force"])
    r = railtherm.solve(right, {"normal": "wheelset-profile"}, level=0)
    assert r.attrs["wheelset_roll_balance"] == ROLL_BALANCE and "Hertz-equivalent" in ROLL_BALANCE
    assert r.attrs["wheelset_roll_angle"] == r.attrs["wheelset_roll_angle_hertz"] == right.profile_contact.balanced_roll


def _table_tolerance(pc, want):
    hertz = hertz_from_curvatures(*pc.hertz_curvatures, pc.normal_force, E_STAR)
    return 0.02 * hertz.approach / math.cos(pc.contact_angle) / L_ARM + _rounding(want)


def test_the_kalker_chain_balances_the_roll_with_its_own_approaches():
    """Position 13, kalker at level 1: the roll moves from the Hertz-equivalent one by the approaches' difference
    (-6.27071e-4 -> -6.27214e-4 rad, measured; the table's -6.272e-4); at the roll returned, the wheels' heights
    with kalker's approaches, recomputed here, agree to 1e-10 m, and the roll is within the table's tolerance."""
    from railtherm.input.wheelset_profile import roll_height_mismatch
    from railtherm.solving import wheelset_equilibrium as we
    sc = _balanced(13, outputs=["normal_force"])
    r = railtherm.solve(sc, "kalker", level=1)
    roll, hertz_roll = r.attrs["wheelset_roll_angle"], r.attrs["wheelset_roll_angle_hertz"]
    assert "(kalker)" in r.attrs["wheelset_roll_balance"] and hertz_roll == sc.profile_contact.balanced_roll
    assert abs(roll - hertz_roll) > 1e-8
    inner = dict(method="kalker", level=1, options=None, solve_one=railtherm.solve, host=None)
    loaded = (sc.source, sc.profile_contact.vertical_force)
    heights = (roll_height_mismatch(sc, roll) + we._approach_correction(*loaded, "right", roll, **inner)[0]
               - we._approach_correction(*loaded, "left", roll, **inner)[0])
    assert abs(heights) < we.HEIGHT_TOL
    want = A22["position"][12]["roll"]
    assert roll == pytest.approx(want, abs=_table_tolerance(sc.profile_contact, want))


def test_kalkers_approaches_give_position_2_the_benchmarks_roll():
    """Position 2 right (the non-Hertzian patch of KNOWN_MISSES), kalker at level 2 on the contact search's sampled
    gap, each wheel's normal force meeting its vertical force with kalker's own creep forces: -2.3514e-5 rad against
    the table's -2.304e-5 (tolerance 6.9e-7) and the Hertz-equivalent -1.950e-5 (measured; -2.3486e-5 with the
    estimate's normal forces). The grid does not move it: -2.3521, -2.3513, -2.3514, -2.3513e-5 at levels 0 to 3;
    solving the gap polynomial instead (0.22 mm misfit) gave -2.104e-5 at every level, outside the tolerance."""
    sc = _balanced(2, outputs=["normal_force"])
    r = railtherm.solve(sc, "kalker", level=2)
    want = A22["position"][1]["roll"]
    assert r.attrs["wheelset_roll_angle"] == pytest.approx(want, abs=_table_tolerance(sc.profile_contact, want))


def test_the_hertz_equivalent_heights_of_both_wheels_agree_at_the_balanced_roll():
    """With the forces the attribute names (each wheel's Hertz-equivalent approach under half the axle load plus
    its gap to first touch, input.wheelset_profile._wheel_height), the wheelset centre's height is the same for
    both wheels at the balanced roll to 1e-10 m (secant tolerance 1e-11 m); 1 urad away they differ by more than
    0.3 um (the arm L = 0.75 m moves the wheels apart by 2 L d(phi) = 1.5 um)."""
    from railtherm.input import wheelset_profile as wp
    from railtherm.physics.elastic import combined_elastic
    from railtherm.physics.elastic import contact_modulus
    sc = _balanced(13)
    pc = sc.profile_contact
    geo, _ = wp._geometry(sc.name, dict(sc.source["wheelset"], roll_angle=0.0), None)
    base = dataclasses.replace(wp._nominal(geo, sc.speed), vertical_force=0.5 * geo.vertical_force)
    bodies = (contact_modulus(sc.wheel, sc.rail), *combined_elastic(sc.wheel, sc.rail))

    def mismatch(roll):
        return (wp._wheel_height(sc.name, base, "right", roll, bodies, sc.friction.nominal, sc.speed)
                - wp._wheel_height(sc.name, base, "left", roll, bodies, sc.friction.nominal, sc.speed))

    assert abs(mismatch(pc.balanced_roll)) < 1e-10
    assert abs(mismatch(pc.balanced_roll + 1e-6)) > 3e-7
