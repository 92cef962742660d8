"""One table of study keys (railtherm.input.scene.KEY_TABLE): the scene parser's checkers, with
UDUNITS-2 units, are what swept coordinates are labelled with."""
from __future__ import annotations

import re

import pytest

from railtherm.analysis.results import _sweep_coord_attrs
from railtherm.input.scene import SCENE_KEYS, KEY_TABLE, Num, Table, key_units

#: UDUNITS-2 product of powers of symbols ("W m-2 K-1", "m s-1", "degC") or "1"
UDUNITS = re.compile(r"^(1|[A-Za-z]+(-?\d+)?( [A-Za-z]+(-?\d+)?)*)$")


def test_every_scene_key_is_in_the_table():
    for key, check in SCENE_KEYS.items():
        if isinstance(check, Table):
            assert {f"{key}.{k}" for k in check.keys} <= set(KEY_TABLE)
        else:
            assert key in KEY_TABLE


@pytest.mark.parametrize("key", sorted(k for k, c in KEY_TABLE.items() if isinstance(c, Num)))
def test_every_number_has_udunits_units(key):
    unit = key_units(key)
    assert unit and UDUNITS.match(unit), (key, unit)
    assert "/" not in unit and "^" not in unit


@pytest.mark.parametrize("key, units", [("creepage.longitudinal", "1"), ("creepage.spin", "m-1"),
                                        ("speed", "m s-1"), ("friction", "1"), ("normal_force", "N"),
                                        ("heat_source.flux", "W m-2"), ("convection", "W m-2 K-1"),
                                        ("wheel.bulk_temperature", "degC"), ("contact.semi_axes", "m")])
def test_swept_coordinates_take_their_units_from_the_table(key, units):
    assert _sweep_coord_attrs(key) == {"units": units, "long_name": f"swept study key '{key}'"}
