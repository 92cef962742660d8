"""The undeformed gap of a scene, contact = { shape = "gap", coefficients = {...} },
and the scalar contact_area [m2]."""
from __future__ import annotations

import math

import pytest

import railtherm
from railtherm import SceneError
from railtherm.testing import canonical

NON_HERTZ = {"x2": 1.015, "y2": 0.4215, "y4": 2.0e3}


def _scene(coefficients, **kw):
    sc = canonical("ellipse-creepage", outputs=["max_pressure", "contact_area"])
    sc["contact"] = {"shape": "gap", "coefficients": coefficients, **kw}
    return sc


def test_gap_coefficients_are_read_as_powers():
    s = railtherm.load_scene(_scene(NON_HERTZ))
    assert s.contact_shape == "gap" and s.curvatures is None
    assert s.gap_coefficients == {(2, 0): 1.015, (0, 2): 0.4215, (0, 4): 2.0e3}


def test_a_quadratic_gap_is_the_ellipse_of_its_curvatures():
    gap = railtherm.load_scene(_scene({"x2": 1.015, "y2": 0.4215}))
    assert gap.contact_shape == "ellipse" and gap.curvatures == (1.015, 0.4215)
    sc = canonical("ellipse-creepage", outputs=["max_pressure", "semi_axis_a", "contact_area"])
    sc["contact"] = {"shape": "ellipse", "curvatures": [1.015, 0.4215]}
    a = railtherm.solve(_scene({"x2": 1.015, "y2": 0.4215}), "green", 0)
    b = railtherm.solve(sc, "green", 0)
    assert float(a.max_pressure) == float(b.max_pressure)


@pytest.mark.parametrize("coefficients, key", [({"z2": 1.0}, "contact.coefficients.z2"),
                                               ({"x1": 1.0}, "contact.coefficients.x1"),
                                               ({"x2": "a"}, "contact.coefficients.x2"),
                                               ({}, "contact.coefficients")])
def test_bad_coefficients_name_the_key(coefficients, key):
    with pytest.raises(SceneError) as err:
        railtherm.load_scene(_scene(coefficients))
    assert err.value.key == key


def test_a_gap_takes_coefficients_only():
    with pytest.raises(SceneError, match="coefficients' only"):
        railtherm.load_scene(_scene(NON_HERTZ, semi_axes=[1e-3, 1e-3]))
    with pytest.raises(SceneError, match="needs 'coefficients'"):
        railtherm.load_scene({**_scene(NON_HERTZ), "contact": {"shape": "gap"}})


@pytest.mark.parametrize("method", ["green", "fipy", "fastsim-fdm"])
def test_hertz_based_methods_refuse_a_non_quadratic_gap_naming_why(method):
    if method not in {m.name for m in railtherm.methods()}:
        pytest.skip(f"method {method!r} is not installed")
    with pytest.raises(railtherm.Refused, match=r"Hertzian gap h = A x\^2 \+ B y\^2.*x\^0 y\^4.*not a quadratic"):
        railtherm.solve(_scene(NON_HERTZ), method, 0)


def test_contact_area_of_the_hertz_patch_is_pi_a_b():
    ds = railtherm.solve(canonical("ellipse-creepage", outputs=["contact_area", "semi_axis_a", "semi_axis_b"]),
                         "green", 0)
    assert ds.contact_area.attrs["units"] == "m2"
    assert float(ds.contact_area) == pytest.approx(math.pi * float(ds.semi_axis_a) * float(ds.semi_axis_b),
                                                   rel=1e-14)
    line = railtherm.solve(canonical("line-full-sliding", outputs=["contact_area", "semi_axis_a"]), "green", 0)
    assert float(line.contact_area) == pytest.approx(2 * float(line.semi_axis_a), rel=1e-14)


@pytest.fixture
def kalker():
    if "kalker" not in {m.name for m in railtherm.methods()}:
        pytest.skip("method 'kalker' is not installed")


def test_kalker_runs_a_non_hertzian_gap_end_to_end(kalker):
    """The y^4 term stiffens the gap across: at the same load the patch is narrower in y than the Hertz
    patch of the quadratic part; the contact area is that of the cells in contact (the Hertz one within
    the staircase error of level 1), and the mean contact temperature is taken over those cells."""
    outs = ["contact_area", "semi_axis_b", "pressure", "surface_temperature", "mean_contact_temperature"]
    quad = railtherm.solve(_scene({"x2": 1.015, "y2": 0.4215}) | {"outputs": outs}, "kalker", 1)
    gap = railtherm.solve(_scene(NON_HERTZ) | {"outputs": outs}, "kalker", 1)
    assert gap.attrs["stages"] == "normal:kalker tangential:kalker heat_source:frictional temperature:green"
    hertz = railtherm.solve(_scene({"x2": 1.015, "y2": 0.4215}) | {"outputs": ["contact_area"]}, "green", 1)
    assert float(quad.contact_area) == pytest.approx(float(hertz.contact_area), rel=0.05)
    assert float(gap.semi_axis_b) < 0.9 * float(quad.semi_axis_b)
    cells = gap.pressure.values > 0
    dx, dy = float(gap.x[1] - gap.x[0]), float(gap.y[1] - gap.y[0])
    assert float(gap.contact_area) == pytest.approx(cells.sum() * dx * dy, rel=1e-12)
    for i in range(2):
        assert float(gap.mean_contact_temperature[i]) == pytest.approx(
            float(gap.surface_temperature[i].values[cells].mean()), rel=1e-12)
