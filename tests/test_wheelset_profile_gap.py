"""The undeformed gap a patch of a wheelset on profiles carries for a solver of the gap itself
(``ProfileContact.gap_section``, the contact search's sampled gap) and what ``kalker`` solves: the sampled gap where
it is sampled, the scene's polynomial beyond. Checked against the polynomial's own misfit (``gap_residual``, the
largest on its fitting window) and against the patch it has to hold (Manchester A-2.2, tests/manchester_cases.py)."""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm.input.scene import load_scene
from railtherm.input.wheelset_profile import GAP_SECTION_HALF_WIDTH, WINDOW
from railtherm_kalker.potential_area import Gap, SampledGap, scene_gap

from manchester_cases import a22_scene


def _scene(position, side="right"):
    return load_scene(a22_scene(position, side))


@pytest.mark.parametrize("position,side", [(13, "right"), (13, "left"), (2, "right")])
def test_the_sampled_gap_is_zero_at_the_origin_and_the_polynomial_fits_it(position, side):
    """The sampled gap is zero at the plane's origin (the gap minimum) and positive around it; on the polynomial's
    fitting window (its semi-axes WINDOW[0] a along x, the scene's fitted width across) the polynomial stays within
    its reported misfit (plus 1e-12 m) of it. A-2.2 position 2 right: a misfit of 0.22 mm, where the sampled gap
    rises by less than 0.1 mm from its minimum."""
    scene = _scene(position, side)
    pc = scene.profile_contact
    s = pc.gap_section
    assert abs(float(s(0.0, 0.0))) < 1e-15
    x = np.linspace(-2e-3, 2e-3, 9)[None, :]
    y = np.linspace(-3e-3, 3e-3, 13)[:, None]
    assert np.all(s(x, y)[(x != 0) | (y != 0)] > 0.0)
    poly = Gap({tuple(int(v) for v in k): c for k, c in scene.gap_coefficients.items()})
    a = float(railtherm.solve(scene, "kalker", level=0)["semi_axis_a"])
    xs = np.linspace(-WINDOW[0] * a, WINDOW[0] * a, 7)[None, :]
    ys = np.linspace(-2e-3, 2e-3, 41)[:, None]
    assert np.max(np.abs(poly(xs, ys) - s(xs, ys))) <= pc.gap_residual + 1e-12
    if (position, side) == (2, "right"):
        assert pc.gap_residual > 1e-4


def test_kalker_solves_the_sampled_gap_and_the_polynomial_beyond_it():
    """A wheelset scene's gap in kalker is the sampled gap over |y| <= GAP_SECTION_HALF_WIDTH (to the bit) and the
    scene's polynomial beyond; a scene of a typed-in gap keeps its polynomial."""
    scene = _scene(2)
    gap = scene_gap(scene)
    assert isinstance(gap, SampledGap)
    x = np.array([0.0, 1e-3, -2e-3])
    y = np.array([5e-3, -10e-3, 0.5 * GAP_SECTION_HALF_WIDTH])
    assert np.array_equal(gap(x, y), scene.profile_contact.gap_section(x, y))
    far = np.array([1.2 * GAP_SECTION_HALF_WIDTH])
    assert gap(np.zeros(1), far) == Gap.__call__(gap, np.zeros(1), far)
    typed = load_scene({"name": "typed", "speed": 30.0, "friction": 0.3, "normal_force": 1e4,
                        "contact": {"shape": "gap", "coefficients": {"x2": 1.0, "y2": 2.0, "y4": 50.0}},
                        "creepage": {"longitudinal": -1e-3}})
    assert type(scene_gap(typed)) is Gap


def test_the_sampled_gap_holds_the_wide_patch_of_position_1():
    """A-2.2 position 1 right (two gap minima 11 mm apart in one patch): kalker's interpenetration at its approach
    ends inside the sampled gap (the gap at its ends exceeds the approach; the search's own section, 12 mm,
    ends inside the patch: 12.5 um at -12 mm against an approach of 16 um)."""
    scene = _scene(1)
    r = railtherm.solve(scene, "kalker", level=1)
    approach = float(r.attrs["kalker_approach"])
    s = scene.profile_contact.gap_section
    ends = s(np.zeros(2), np.array([s.eta[0], s.eta[-1]]))
    assert np.all(ends > approach)
    assert float(s(0.0, -12e-3)) < approach
