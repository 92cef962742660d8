"""Kalker coefficients, linear creep law and flexibilities (railtherm.references.kalker)."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from railtherm.references import kalker
from railtherm.references.kalker import (KALKER_TABLE, flexibilities, kalker_coefficients, kalker_linear_forces,
                                         weighted_flexibility)

_HERE = Path(__file__).resolve().parent
_CANDIDATES = [_HERE / "data" / "published.toml"]
NAMES = ("C11", "C22", "C23", "C33")
NU = (0.0, 0.25, 0.5)


@pytest.mark.parametrize("path", _CANDIDATES, ids=["tests-data"])
def test_module_copy_equals_published(path):
    """The module-level copy of Kalker's table equals published.toml [kalker_coefficients] exactly."""
    if not path.exists():
        pytest.skip(f"{path} not present")
    with open(path, "rb") as fh:
        pub = tomllib.load(fh)["kalker_coefficients"]
    assert KALKER_TABLE["a/b"]["g"] == pub["g"]
    assert KALKER_TABLE["b/a"]["g"] == pub["b_over_a"]["g"]
    for name in NAMES:
        assert KALKER_TABLE["a/b"][name] == pub[name], name
        assert KALKER_TABLE["b/a"][name] == pub["b_over_a"][name], name
    # the documented typo C23(a/b = 0.8, nu = 0.25) = 1.15 must not be in our copy
    assert KALKER_TABLE["a/b"]["C23"][7][1] == 1.25


@pytest.mark.parametrize("case", ["a/b", "b/a"])
def test_table_nodes_reproduced(case):
    """At every table node (g, nu) the interpolation returns the tabulated value (to rounding)."""
    tab = KALKER_TABLE[case]
    for i, g in enumerate(tab["g"]):
        a, b = (g, 1.0) if case == "a/b" else (1.0, g)
        for j, nu in enumerate(NU):
            got = kalker_coefficients(a, b, nu)
            want = [tab[n][i][j] for n in NAMES]
            np.testing.assert_allclose(got, want, rtol=1e-13, err_msg=f"{case} g={g} nu={nu}")


def _contact_linrol(nu, aob):
    """Literal transcription of CONTACT's linrol table branch (src/m_hertz.f90), for cross-checking."""
    if aob <= 1.0:
        g, case = aob, "a/b"
        rows = {n: KALKER_TABLE["a/b"][n] for n in NAMES}
    else:
        g, case = 1.0 / aob, "b/a"
        rows = {n: KALKER_TABLE["b/a"][n][::-1] + [KALKER_TABLE["a/b"][n][-1]] for n in NAMES}
    irow = int(10.0 * g - 0.005)          # Fortran: integer = real truncates; 1-based row index
    fac = 10.0 * g - irow
    out = []
    for n in NAMES:
        c = [fac * rows[n][irow][k] + (1.0 - fac) * rows[n][irow - 1][k] for k in range(3)]
        cc = ((nu - 0.25) * (nu - 0.5) * 8.0 / c[0] - (nu - 0.5) * nu * 16.0 / c[1]
              + nu * (nu - 0.25) * 8.0 / c[2])
        out.append(1.0 / cc)
    return out


@pytest.mark.parametrize("aob", [0.12, 0.35, 0.558, 0.77, 0.95, 1.0, 1.04, 1.3, 1.79, 2.0, 4.4, 9.5])
@pytest.mark.parametrize("nu", [0.0, 0.1, 0.28, 0.3, 0.45, 0.5])
def test_interpolation_matches_contact_linrol(aob, nu):
    """Linear in g, quadratic in nu for 1/C: same numbers as CONTACT's linrol (to 1e-12)."""
    got = kalker_coefficients(aob, 1.0, nu)
    np.testing.assert_allclose(got, _contact_linrol(nu, aob), rtol=1e-12)


def test_interpolation_is_linear_in_g_and_continuous_at_circle():
    """Midpoint in g is the mean of the neighbours (at a table nu); a/b -> 1 from both sides agrees."""
    lo, hi, mid = kalker_coefficients(0.5, 1.0, 0.25), kalker_coefficients(0.6, 1.0, 0.25), \
        kalker_coefficients(0.55, 1.0, 0.25)
    np.testing.assert_allclose(mid, 0.5 * (np.array(lo) + np.array(hi)), rtol=1e-13)
    left = kalker_coefficients(1.0 - 1e-9, 1.0, 0.28)
    right = kalker_coefficients(1.0, 1.0 - 1e-9, 0.28)
    np.testing.assert_allclose(left, right, rtol=1e-7)


def test_nu_interpolation_of_inverse_is_quadratic():
    """1/C(nu) is the parabola through the three tabulated nu (checked at the Ertz & Knothe ellipse)."""
    a, b = 5.879e-3, 10.540e-3
    nus = np.linspace(0.0, 0.5, 11)
    inv = np.array([1.0 / np.array(kalker_coefficients(a, b, nu)) for nu in nus])
    for k in range(4):
        coef = np.polyfit(nus, inv[:, k], 2)
        np.testing.assert_allclose(np.polyval(coef, nus), inv[:, k], rtol=1e-12, atol=0)


def test_asymptotes_beyond_table():
    """g < 0.1: Kalker's asymptotes (as CONTACT); they approach the g = 0.1 rows within 6 %
    and follow their limits: C11 -> pi^2/(4(1-nu)), C22 -> pi^2/4 for a << b."""
    nu = 0.25
    near = kalker_coefficients(0.0999, 1.0, nu)
    node = kalker_coefficients(0.1, 1.0, nu)
    np.testing.assert_allclose(near[:3], node[:3], rtol=0.06)
    assert near[3] == node[3]                      # C33 clamped (no asymptote with a source)
    c11, c22, c23, _ = kalker_coefficients(1e-4, 1.0, nu)
    assert c11 == pytest.approx(math.pi ** 2 / (4 * (1 - nu)), rel=1e-14)
    assert c22 == pytest.approx(math.pi ** 2 / 4, rel=1e-14)
    assert c23 > 0 and c23 < node[2]
    near_b = kalker_coefficients(1.0, 0.0999, nu)
    node_b = kalker_coefficients(1.0, 0.1, nu)
    np.testing.assert_allclose(near_b[:3], node_b[:3], rtol=0.06)
    # a >> b: all grow as g -> 0
    far = kalker_coefficients(1.0, 0.01, nu)
    assert all(f > n for f, n in zip(far[:3], node_b[:3]))
    clamp = kalker_coefficients(1.0, 0.01, nu, beyond_table="clamp")
    assert clamp == node_b


def test_linear_forces_sign_and_structure():
    """Positive creepage gives a negative force on the wheel; the matrix is as in the brief."""
    a, b, G, nu = 8e-3, 4e-3, 82e9, 0.28
    c11, c22, c23, c33 = kalker_coefficients(a, b, nu)
    c = math.sqrt(a * b)
    mat = -G * a * b * np.array([[c11, 0, 0], [0, c22, c * c23], [0, -c * c23, c * c * c33]])
    for cre in ([1e-3, 0, 0], [0, -6.25e-4, 0], [0, 0, 0.625], [-2e-3, 1e-3, 0.2]):
        np.testing.assert_allclose(kalker_linear_forces(a, b, G, nu, *cre), mat @ np.array(cre), rtol=1e-14,
                                   atol=1e-12)
    fx, fy, mz = kalker_linear_forces(a, b, G, nu, 1e-3, 1e-3, 0.0)
    assert fx < 0 and fy < 0
    # spin/lateral coupling is antisymmetric: Fy from phi equals minus Mz from eta (per unit creepage)
    fy_phi = kalker_linear_forces(a, b, G, nu, 0, 0, 1.0)[1]
    mz_eta = kalker_linear_forces(a, b, G, nu, 0, 1.0, 0)[2]
    assert fy_phi == pytest.approx(-mz_eta, rel=1e-14)


def test_flexibilities_formulas_and_weighting():
    """L1 = 8a/(3 C11 G) etc.; a single creepage component selects its own flexibility."""
    a, b, G, nu = 8e-3, 4e-3, 82e9, 0.28
    c11, c22, c23, _ = kalker_coefficients(a, b, nu)
    l1, l2, l3 = flexibilities(a, b, G, nu)
    assert l1 == pytest.approx(8 * a / (3 * c11 * G), rel=1e-15)
    assert l2 == pytest.approx(8 * a / (3 * c22 * G), rel=1e-15)
    assert l3 == pytest.approx(math.pi * a * math.sqrt(a / b) / (4 * c23 * G), rel=1e-15)
    for form in ("kalker", "contact"):
        assert weighted_flexibility(a, b, G, nu, 1e-3, 0, 0, form=form) == pytest.approx(l1, rel=1e-14)
        assert weighted_flexibility(a, b, G, nu, 0, -1e-3, 0, form=form) == pytest.approx(l2, rel=1e-14)
        assert weighted_flexibility(a, b, G, nu, 0, 0, 0.5, form=form) == pytest.approx(l3, rel=1e-14)
        mixed = weighted_flexibility(a, b, G, nu, 0, -6.25e-4, 0.625, form=form)
        assert min(l2, l3) <= mixed <= max(l2, l3)
    # Kalker 1982: L = (|xi| L1 + |eta| L2 + |phi| c L3)/sqrt(xi^2 + eta^2 + c^2 phi^2)
    c = math.sqrt(a * b)
    xi, eta, phi = 1e-3, -2e-3, 0.3
    want = (abs(xi) * l1 + abs(eta) * l2 + abs(phi) * c * l3) / math.sqrt(xi ** 2 + eta ** 2 + (c * phi) ** 2)
    assert weighted_flexibility(a, b, G, nu, xi, eta, phi) == pytest.approx(want, rel=1e-15)


def test_invalid_inputs():
    with pytest.raises(ValueError):
        kalker_coefficients(-1.0, 1.0, 0.28)
    with pytest.raises(ValueError):
        kalker_coefficients(1.0, 1.0, 0.6)
    with pytest.raises(ValueError):
        weighted_flexibility(1e-3, 1e-3, 82e9, 0.28, 1e-3, 0, 0, form="other")
    assert kalker.__doc__ and "doi:" in kalker.__doc__
