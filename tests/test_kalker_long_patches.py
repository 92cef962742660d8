"""Plugin "kalker" on patches long along rolling (b/a down to 0.2): Kalker's linear-theory coefficients at
level 3 through the public API, and the order of the rolling difference of the steady-state slip.

References: Kalker's table of C11, C22, C23, C33 (core's :mod:`railtherm.references.kalker`, interpolated in
nu as core does), at its rows b/a = 0.2, 0.3 and 0.5 (between rows the linear interpolation of C11 and C23 is
itself 1.5 and 4.4 % off at b/a = 0.25, so that ratio checks only C33); the exact linear theory of a line
contact (bounded traction at the leading edge) for the convergence orders.

Run: ``OPENBLAS_NUM_THREADS=1 python -m pytest -q tests/test_kalker_long_patches.py`` (``-m slow`` for b/a = 0.2,
0.25, 0.5 and b/a = 0.5 with as many elements across 2a as across 2b).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import railtherm
from railtherm.references.kalker import kalker_coefficients
from railtherm.testing import canonical
from railtherm_kalker.influence import Convolution, line_kernel, rolling_kernel, tangential_kernels
from railtherm_kalker.potential_area import potential_area
from railtherm_kalker.tangential_model import SECOND_ORDER_CUT_SCALE, rolling_operator
from railtherm_kalker.tangential_solver import solve_tangential, solve_tangential_nested

G, NU = 82e9, 0.28
A = 8e-3
#: small creepages: linear theory (the slip zone at the trailing edge is far below an element)
XI, ETA, PHI = 1e-6, 1e-6, 1e-4


def coefficient_errors(b_over_a: float, options: dict | None = None, level: int = 3) -> dict:
    """Relative errors [1] of C11 (Fx), C22 (Fy), C23 (from Fy(phi) and from Mz(eta)) and C33 (Mz) of
    ``railtherm.solve(scene, "kalker", level, options)`` on the ellipse a = 8 mm, b = b/a a, 100 kN, against
    Kalker's table: ``[Fx, Fy, Mz] = -G a b [[C11, 0, 0], [0, C22, c C23], [0, -c C23, c^2 C33]] [xi, eta, phi]``,
    c = sqrt(a b)."""
    b = A * b_over_a
    forces = {}
    for name, (xi, eta, phi) in {"xi": (XI, 0.0, 0.0), "eta": (0.0, ETA, 0.0), "phi": (0.0, 0.0, PHI)}.items():
        scene = canonical("ellipse-creepage", normal_force=100e3, contact={"shape": "ellipse", "semi_axes": [A, b]},
                          creepage={"longitudinal": xi, "lateral": eta, "spin": phi},
                          outputs=["creep_force_x", "creep_force_y", "spin_moment"])
        ds = railtherm.solve(scene, "kalker", level, options)
        forces[name] = (float(ds.creep_force_x), float(ds.creep_force_y), float(ds.spin_moment))
    c11, c22, c23, c33 = kalker_coefficients(A, b, NU)
    gab, c = G * A * b, math.sqrt(A * b)
    return {"C11": -forces["xi"][0] / (gab * XI) / c11 - 1, "C22": -forces["eta"][1] / (gab * ETA) / c22 - 1,
            "C23 (Fy)": -forces["phi"][1] / (gab * c * PHI) / c23 - 1,
            "C23 (Mz)": forces["eta"][2] / (gab * c * ETA) / c23 - 1,
            "C33": -forces["phi"][2] / (gab * c * c * PHI) / c33 - 1}


def check_targets(errors: dict) -> None:
    """Creep forces (C11, C22, C23 from Fy) and C23 from Mz within 1 %, the spin moment's C33 within 3 %."""
    for key in ("C11", "C22", "C23 (Fy)", "C23 (Mz)"):
        assert abs(errors[key]) < 0.01, (key, errors)
    assert abs(errors["C33"]) < 0.03, errors


def test_long_patch_at_level_3_with_the_default_options():
    """b/a = 0.3 at level 3, default options (128 elements across 2b, 512 across 2a): C11, C22, C23 within 1 %
    and C33 within 3 % of Kalker's table. Measured +0.09, +0.43, -0.04 / -0.07, +1.17 %. CONTACT's first-order
    rolling difference (option ``rolling_scheme = "first-order"``) gives C33 +3.84 % there (the forces within
    0.6 %), first order in dx with a constant growing like (a/b)^2: checked above 3 %."""
    errors = coefficient_errors(0.3)
    check_targets(errors)
    first = coefficient_errors(0.3, {"rolling_scheme": "first-order"})
    assert first["C33"] > 0.03
    assert abs(first["C11"]) < 0.01 and abs(first["C23 (Fy)"]) < 0.01


@pytest.mark.slow
@pytest.mark.parametrize("b_over_a, options", [(0.2, None), (0.5, None), (0.5, {"rolling_refinement": 1})],
                         ids=["b/a=0.2", "b/a=0.5", "b/a=0.5-m=1"])
def test_long_patches_at_level_3(b_over_a, options):
    """At level 3, against Kalker's table: C11, C22, C23 within 1 %, C33 within 3 %. Measured (second-order
    default; CONTACT's first-order difference in parentheses): b/a = 0.2: +0.35, +0.58, +0.05 / +0.02, +2.10 %
    (C33 +7.57 %); b/a = 0.5: -0.04, +0.15, +0.16 / +0.06, +0.39 % (C33 +1.53 %); b/a = 0.5 with as many
    elements across 2a as across 2b (rolling_refinement = 1): -0.10, +0.15, +0.14 / +0.12, +0.25 % (C33
    +4.80 %). The rest of C33's error at b/a = 0.2 is the lateral discretisation: with 64 elements across 2b it
    stays at +2.4 % for 2, 4, 8, 16 times as many along x (a = 8 mm)."""
    check_targets(coefficient_errors(b_over_a, options))


@pytest.mark.slow
def test_spin_coefficient_between_the_table_rows():
    """b/a = 0.25 (the table interpolated linearly between its rows 0.2 and 0.3, which puts C11 and C23 1.5 and
    4.4 % above a power law through those rows, so only C33 is checked): C33 within 3 % with the default (measured
    +1.59 %) where CONTACT's first-order difference gives +5.26 % (checked above 4 %)."""
    assert abs(coefficient_errors(0.25)["C33"]) < 0.03
    assert coefficient_errors(0.25, {"rolling_scheme": "first-order"})["C33"] > 0.04


def test_second_order_kernel_is_the_first_order_kernel_times_three_minus_the_shift_over_two():
    """The second-order upwind difference (-u(x + 2h) + 4 u(x + h) - 3 u(x)) / (2 h) is (3 - S)/2 applied to the
    first-order (u(x + h) - u(x)) / h (S: one element upstream), kernel by kernel (1e-12 of the kernel); on a
    quadratic it is the derivative at the element centre to round-off (1e-12) where the first-order one is off by
    h/2 u'' (1e-12)."""
    nx, ny, dx, dy = 12, 9, 1.3e-4, 2.1e-4
    kernels = tangential_kernels(nx, ny, dx, dy, G, NU, extra=2)
    m = 2 * nx - 1
    for name in ("xx", "xy", "yy"):
        K = kernels[name]
        b1_all = (K[1:] - K[:-1]) / dx               # first-order kernel at the offsets -(nx + 1) ... nx
        b1, b1_up = b1_all[2:2 + m], b1_all[3:3 + m]     # at offsets k and k + 1, k = -(nx - 1) ... nx - 1
        b2 = rolling_kernel(K, dx, 2)
        np.testing.assert_allclose(b2, 0.5 * (3.0 * b1 - b1_up), rtol=0, atol=1e-12 * np.abs(b2).max())
        np.testing.assert_allclose(rolling_kernel(K[1:-1], dx, 1), b1, rtol=0, atol=1e-12 * np.abs(b1).max())
    s = np.arange(-8, 9, dtype=float)
    u = (2.0 * s ** 2 + s)[:, None]                  # u(x) with x = s dx: u'(0) = 1/dx, u'' = 4/dx^2
    centre = 8
    d2 = rolling_kernel(u, dx, 2)[centre - 2, 0]     # the difference at x = 0
    d1 = rolling_kernel(u, dx, 1)[centre - 1, 0]
    assert d2 * dx == pytest.approx(1.0, abs=1e-12)
    assert d1 * dx == pytest.approx(1.0 + 0.5 * dx * 4.0 / dx, abs=1e-12)


def _line_linear_theory(n: int, order: int, shift: float) -> np.ndarray:
    """Linear theory (no slip) on a line contact |x| < 1 (compliance 1) with n elements across it, the grid shifted
    by ``shift`` elements against the contact: (F, M) of the rigid slips w0 = 1e-3 and k x (k = 1e-3), relative to
    pi/4 1e-3 against the exact F(w0) = -pi/2, M(w0) = pi/4, F(kx) = -pi/4, M(kx) = 0 (times 1e-3)."""
    h = 2.0 / n
    xe = np.arange(-4, n + 5) * h - 1.0 + shift * h
    x = 0.5 * (xe[1:] + xe[:-1])
    k = line_kernel(x.size, h, 1.0, extra=order)
    near = None if order == 1 else {(0, 0): SECOND_ORDER_CUT_SCALE * rolling_kernel(k[1:-1], h, 1)}
    conv = Convolution({(0, 0): rolling_kernel(k, h, order)}, (x.size, 1), near_kernels=near)
    g = 1e3 * np.sqrt(np.clip(1.0 - x ** 2, 0.0, None))[:, None]
    out = []
    for w in (np.ones_like(x), x):
        t = solve_tangential(conv, g, 1e-3 * w[None, :, None], tol=1e-13).traction[0, :, 0]
        out += [t.sum() * h, (x * t).sum() * h]
    exact = np.array([-math.pi / 2, math.pi / 4, -math.pi / 4, 0.0]) * 1e-3
    return (np.array(out) - exact) / (math.pi / 4 * 1e-3)


def order(hs, errors) -> float:
    return float(np.polyfit(np.log(hs), np.log(np.abs(errors)), 1)[0])


def test_the_spin_term_converges_at_second_order_with_the_second_order_difference():
    """The 1-D analogue of C33 is the moment M(kx) of the traction of a linearly varying rigid slip w = k x on a line
    contact (exact: 0). On a ladder of 64, 128, 256, 512 elements, with the contact's edges on element edges and
    with the grid shifted by 0.37 element: the second-order difference's M(kx) converges at order 2 (measured
    2.0 and 2.0; -2.4e-4 and -5.1e-4 at 64 elements, relative to pi/4 k), the first-order difference's at order 1
    (1.0; -1.55e-2 at 64). Checked: orders 2 +- 0.2 and 1 +- 0.2. The force and moment of a constant slip and the
    force of k x stay first order with both (the staircase of the contact's edges and the singular trailing edge:
    measured order 1.0, e.g. F(w0) +1.07e-2 and -4.7e-3 at 64): in 2-D, where the rows' edges fall anywhere within
    an element, their errors largely cancel over the rows (C11, C22, C23 within 0.6 % at level 3)."""
    ns = np.array([64, 128, 256, 512])
    hs = 2.0 / ns
    for shift in (0.0, 0.37):
        second = np.array([_line_linear_theory(n, 2, shift) for n in ns])
        first = np.array([_line_linear_theory(n, 1, shift) for n in ns])
        assert order(hs, second[:, 3]) == pytest.approx(2.0, abs=0.2)
        assert order(hs, first[:, 3]) == pytest.approx(1.0, abs=0.2)
        assert np.all(np.abs(second[:, 3]) < 0.05 * np.abs(first[:, 3]))


def test_second_order_operator_is_preconditioned_by_the_first_order_cut():
    """The second-order operator's near kernels (the cut the line and sweep preconditioners invert) are the
    first-order operator's times SECOND_ORDER_CUT_SCALE (1e-15). On elements 4 times shorter along x than across
    (a = 8, b = 4 mm, 64 elements across 2b, 256 across 2a), where the line preconditioner built on the
    second-order operator's own cut broke down (GMRES diverged), the nested solve converges to the 1e-10 residual
    of the law (computed with the full operator) in linear theory in as many GMRES steps as the first-order
    operator's (measured 69 and 69, summed over the grids; checked below 100)."""
    area = potential_area(8e-3, 4e-3, 64, refine_x=4)
    X, Y = area.mesh()
    c1 = rolling_operator(area.x_edges, area.y_edges, G, NU, order=1)
    c2 = rolling_operator(area.x_edges, area.y_edges, G, NU, order=2)
    for key, near in c2.near.items():
        np.testing.assert_allclose(near, SECOND_ORDER_CUT_SCALE * c1.near[key], rtol=1e-15, atol=0)
    g = 0.3 * 1e9 * np.sqrt(np.clip(1 - (X / 8e-3) ** 2 - (Y / 4e-3) ** 2, 0, None))
    sol = solve_tangential_nested(lambda xe, ye: rolling_operator(xe, ye, G, NU, order=2), area.x_edges,
                                  area.y_edges, g, (0.0, 0.0, PHI))
    assert sol.converged and sol.residual <= 1e-10
    assert sol.linear_iterations < 100
