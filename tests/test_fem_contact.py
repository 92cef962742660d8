"""Method "fem", contact part: 2-D Hertz (rigid cylinder on a deep strip) and Carter (identical bodies).

Run: PYTHONPATH=core:plugins python -m pytest tests/test_fem_contact.py -q  (slow ladders: -m slow)
"""
from __future__ import annotations

from types import SimpleNamespace as NS

import numpy as np
import pytest

from railtherm.references.carter import carter_2d
from railtherm.references.hertz import hertz_line
from railtherm_fem.contact import solve_contact
from railtherm_fem.coupled import FemProblem, contact_edges, solve_fem

G, NU = 82e9, 0.28
E = 2 * G * (1 + NU)
R = 0.5
A = 1e-3  # target half-width [m]


def steel(rigid=False):
    return NS(shear_modulus=G, poisson_ratio=NU, density=7850.0, specific_heat=450.0, conductivity=50.0,
              thermal_expansion=12e-6, bulk_temperature=0.0, rigid=rigid)


def hertz_case(level, depth_factor=40.0):
    """Rigid cylinder on a deep strip, force per width giving a = 1 mm on a half-plane."""
    e_star = E / (1 - NU ** 2)
    F = np.pi * A ** 2 * e_star / (4 * R)
    prob = FemProblem(radius=R, rail=steel(), wheel=steel(rigid=True), speed=10.0, normal_force=F,
                      thermal=False, frictionless=True, level=level,
                      strip_depth=depth_factor * A, strip_length=2 * depth_factor * A)
    sol = solve_fem(prob)
    a_ref, p0_ref = hertz_line(F, R, e_star)
    c = sol.contact
    pex = p0_ref * np.sqrt(np.clip(1 - (c.x / a_ref) ** 2, 0, None))
    l2 = np.sqrt(np.sum((c.pressure - pex) ** 2) / np.sum(pex ** 2))
    return dict(a=sol.half_width / a_ref - 1, p0=c.pressure.max() / p0_ref - 1, l2=l2,
                h=c.x[1] - c.x[0], converged=c.converged, iterations=c.iterations)


def test_hertz_line_half_width_peak_and_profile():
    """Level 3 (h = a/80): a and p0 within 1 %, relative L2 of the profile within 2 %."""
    r = hertz_case(3)
    assert r["converged"]
    assert abs(r["a"]) < 0.01, r
    assert abs(r["p0"]) < 0.01, r
    assert r["l2"] < 0.02, r


def test_hertz_mesh_convergence_rate():
    """L2 pressure error against h on levels 0..3: fitted rate >= 1 (measured about 1.3).

    Theory: the pressure has a square-root edge, so its P1/nodal L2 error cannot beat h^1.5; the
    edge node placement (error ~ h in the edge position) limits it further to about h^1 .. h^1.5.
    """
    res = [hertz_case(k) for k in range(4)]
    h = np.array([r["h"] for r in res])
    e = np.array([r["l2"] for r in res])
    rate = np.polyfit(np.log(h), np.log(e), 1)[0]
    assert rate > 1.0, (rate, e)
    assert np.all(np.diff(e) < 0), e


@pytest.mark.slow
def test_hertz_finite_depth_error_decreases():
    """A finite strip on a rigid foundation is stiffer than the half-plane: a too small, p0 too high.

    At fixed mesh level the deviation from 2-D Hertz must shrink as the depth grows.
    """
    errs = [hertz_case(3, d) for d in (2.5, 5.0, 10.0, 40.0)]
    da = np.array([abs(r["a"]) for r in errs])
    dp = np.array([abs(r["p0"]) for r in errs])
    assert np.all(np.diff(da) < 0), da
    assert np.all(np.diff(dp) < 0), dp


def carter_case(xi, level=3, eps=1e-9):
    e_star = E / (2 * (1 - NU ** 2))
    F = np.pi * A ** 2 * e_star / (4 * R)
    mu = 0.3
    prob = FemProblem(radius=R, rail=steel(), wheel=steel(), speed=10.0, normal_force=F, friction=mu,
                      creepage=xi, regularization=eps, thermal=False, level=level,
                      strip_depth=40 * A, strip_length=80 * A)
    sol = solve_fem(prob)
    c = sol.contact
    ref = carter_2d(xi, A, mu, R)
    left, right = contact_edges(c.x, c.pressure)
    st = np.nonzero(c.stick)[0]
    # stick zone adjoins the leading edge; its trailing end is halfway between the last slip node
    # and the first stick node
    first = st[0]
    boundary = 0.5 * (c.x[first] + c.x[first - 1])
    stick_len = right - boundary
    ratio = c.tangential_force / (mu * c.normal_force)
    return dict(ratio=ratio / ref.force_ratio - 1, stick=stick_len / (2 * ref.stick_half_width) - 1,
                converged=c.converged, it=c.iterations, contiguous=np.all(np.diff(st) == 1))


@pytest.mark.parametrize("xi", [-1e-4, -2.4e-4, -4e-4])
def test_carter_force_and_stick_zone(xi):
    """Identical elastic bodies (coupling cancelled): Fx/(mu Fn) and stick length within 2 % of Carter."""
    r = carter_case(xi)
    assert r["converged"] and r["contiguous"], r
    assert abs(r["ratio"]) < 0.02, r
    assert abs(r["stick"]) < 0.02, r


@pytest.mark.filterwarnings("ignore:friction regularisation:RuntimeWarning")  # large eps on purpose
@pytest.mark.parametrize("eps", [1e-1, 1e-3, 1e-5, 1e-7, 1e-9, 0.0])
def test_contact_converges_for_any_regularization(eps):
    """The semismooth Newton converges from eps = 1e-1 down to exact Coulomb (eps = 0)."""
    prob = FemProblem(radius=R, rail=steel(), wheel=steel(rigid=True), speed=10.0,
                      normal_force=np.pi * A ** 2 * E / (1 - NU ** 2) / (4 * R), friction=0.3,
                      creepage=-2e-4, regularization=eps, thermal=False, level=1,
                      strip_depth=40 * A, strip_length=80 * A)
    c = solve_fem(prob).contact
    assert c.converged and c.iterations < 40, (c.iterations, c.history)
    assert np.all(np.abs(c.traction) <= 0.3 * c.pressure * (1 + 1e-9) + 1e-6)


@pytest.mark.filterwarnings("ignore:friction regularisation:RuntimeWarning")  # large eps on purpose
def test_carter_regularized_tends_to_coulomb():
    """As eps -> 0 the regularised creep force converges to the Coulomb (eps = 0) value."""
    vals = [carter_case(-2.4e-4, level=1, eps=e)["ratio"] for e in (1e-4, 1e-6, 1e-8, 0.0)]
    d = np.abs(np.array(vals[:-1]) - vals[-1])
    assert np.all(np.diff(d) <= 1e-12) and d[-1] < 1e-4, vals


def test_semismooth_newton_small_problem_exact():
    """Two-node sanity check: decoupled unit compliances, rigid flat punch -> p = delta/c."""
    x = np.array([-1.0, 0.0, 1.0])
    I = np.eye(3)
    sol = solve_contact(x, np.ones(3), np.array([1.0, 0.0, 1.0]), I, 0 * I, 0 * I, I, penetration=0.5)
    assert np.allclose(sol.pressure, [0.0, 0.5, 0.0])
    assert np.allclose(sol.gap, [0.5, 0.0, 0.5])
