"""Kalker's creepage coefficients, the linear theory of rolling contact and the simplified-theory flexibilities.

Sign convention (as CONTACT): positive creepage gives a negative force on body 1 (the wheel):

``[Fx, Fy, Mz] = -G a b [[C11, 0, 0], [0, C22, sqrt(ab) C23], [0, -sqrt(ab) C23, ab C33]] . [xi, eta, phi]``
with a the semi-axis along rolling x, b lateral, G the combined shear modulus, xi, eta the creepages [1]
and phi the spin [1/m].

References
----------
.. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990, table E.3.
   doi:10.1007/978-94-015-7889-9
.. [2] E.A.H. Vollebregt, CONTACT (Apache-2.0), src/m_hertz.f90, ``linrol`` (table) and ``simpflex``.
.. [3] J.J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
   Dynamics 11 (1982) 1-13. doi:10.1080/00423118208968684
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["KALKER_TABLE", "kalker_coefficients", "kalker_linear_forces", "flexibilities",
           "weighted_flexibility"]

# --------------------------------------------------------------------------------------------------
# Copy of tests/data/published.toml [kalker_coefficients] (Kalker 1990 table E.3 as
# tabulated in CONTACT src/m_hertz.f90 linrol; C33 from OpenVSD WRcontForce.cpp, single source).
# Each row: [nu = 0, nu = 0.25, nu = 0.5]. tests/test_references_kalker.py compares this copy with
# published.toml when that file exists.
_A_OVER_B = {  # g = a/b (a <= b), ascending g
    "g": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0],
    "C11": [[2.51, 3.31, 4.85], [2.59, 3.37, 4.81], [2.68, 3.44, 4.80], [2.78, 3.53, 4.82],
            [2.88, 3.62, 4.83], [2.98, 3.72, 4.91], [3.09, 3.81, 4.97], [3.19, 3.91, 5.05],
            [3.29, 4.01, 5.12], [3.40, 4.12, 5.20]],
    "C22": [[2.51, 2.52, 2.53], [2.59, 2.63, 2.66], [2.68, 2.75, 2.81], [2.78, 2.88, 2.98],
            [2.88, 3.01, 3.14], [2.98, 3.14, 3.31], [3.09, 3.28, 3.48], [3.19, 3.41, 3.65],
            [3.29, 3.54, 3.82], [3.40, 3.67, 3.98]],
    "C23": [[0.334, 0.473, 0.731], [0.483, 0.603, 0.809], [0.607, 0.715, 0.889], [0.720, 0.823, 0.977],
            [0.827, 0.929, 1.07], [0.930, 1.03, 1.18], [1.03, 1.14, 1.29], [1.13, 1.25, 1.40],
            [1.23, 1.36, 1.51], [1.33, 1.47, 1.63]],
    "C33": [[6.42, 8.28, 11.7], [3.46, 4.27, 5.66], [2.49, 2.96, 3.72], [2.02, 2.32, 2.77],
            [1.74, 1.93, 2.22], [1.56, 1.68, 1.86], [1.43, 1.50, 1.60], [1.34, 1.37, 1.42],
            [1.27, 1.27, 1.27], [1.21, 1.19, 1.16]],
}
_B_OVER_A = {  # g = b/a (a > b), as in published.toml: descending g 0.9 ... 0.1
    "g": [0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1],
    "C11": [[3.51, 4.22, 5.30], [3.65, 4.36, 5.42], [3.82, 4.54, 5.58], [4.06, 4.78, 5.80],
            [4.37, 5.10, 6.11], [4.84, 5.57, 6.57], [5.57, 6.34, 7.34], [6.96, 7.78, 8.82],
            [10.7, 11.7, 12.9]],
    "C22": [[3.51, 3.81, 4.16], [3.65, 3.99, 4.39], [3.82, 4.21, 4.67], [4.06, 4.50, 5.04],
            [4.37, 4.90, 5.56], [4.84, 5.48, 6.31], [5.57, 6.40, 7.51], [6.96, 8.14, 9.79],
            [10.7, 12.8, 16.0]],
    "C23": [[1.44, 1.59, 1.77], [1.58, 1.75, 1.94], [1.76, 1.95, 2.18], [2.01, 2.23, 2.50],
            [2.35, 2.62, 2.96], [2.88, 3.24, 3.70], [3.79, 4.32, 5.01], [5.72, 6.63, 7.89],
            [12.2, 14.6, 18.0]],
    "C33": [[1.16, 1.11, 1.06], [1.10, 1.04, 0.954], [1.05, 0.965, 0.852], [1.01, 0.892, 0.751],
            [0.958, 0.819, 0.650], [0.912, 0.747, 0.549], [0.868, 0.674, 0.446], [0.828, 0.601, 0.341],
            [0.795, 0.526, 0.228]],
}
KALKER_TABLE = {"a/b": _A_OVER_B, "b/a": _B_OVER_A}
_NAMES = ("C11", "C22", "C23", "C33")
_NU = (0.0, 0.25, 0.5)


def _ascending(case: str) -> tuple[np.ndarray, np.ndarray]:
    """Rows in ascending g with the shared circle row g = 1 appended to the b/a table.

    Returns g (n,) and coefficients (n, 4 coefficients, 3 nu).
    """
    if case == "a/b":
        g = np.array(_A_OVER_B["g"])
        c = np.stack([np.array(_A_OVER_B[k]) for k in _NAMES], axis=1)
        return g, c
    g = np.array(_B_OVER_A["g"])[::-1]
    c = np.stack([np.array(_B_OVER_A[k])[::-1] for k in _NAMES], axis=1)
    g = np.append(g, 1.0)
    circle = np.stack([np.array(_A_OVER_B[k][-1]) for k in _NAMES], axis=0)[None]
    return g, np.concatenate([c, circle], axis=0)


_TABLES = {case: _ascending(case) for case in ("a/b", "b/a")}


def _nu_interp(c3: np.ndarray, nu: float) -> np.ndarray:
    """Quadratic Lagrange interpolation of 1/C through nu = 0, 0.25, 0.5 (CONTACT linrol)."""
    w0 = 8.0 * (nu - 0.25) * (nu - 0.5)
    w1 = -16.0 * nu * (nu - 0.5)
    w2 = 8.0 * nu * (nu - 0.25)
    return 1.0 / (w0 / c3[..., 0] + w1 / c3[..., 1] + w2 / c3[..., 2])


def _asymptotes(case: str, g: float, nu: float) -> tuple[float, float, float]:
    """Kalker's asymptotes of C11, C22, C23 for g = min(a/b, b/a) -> 0 (as CONTACT linrol)."""
    pi = math.pi
    if case == "a/b":  # a << b
        c11 = pi ** 2 / 4.0 / (1.0 - nu)
        c22 = pi ** 2 / 4.0
        c23 = pi * math.sqrt(g) / 3.0 / (1.0 - nu) * (1.0 + nu * (math.log(16.0 / g) - 5.0))
    else:  # a >> b
        al = math.log(16.0 / g ** 2)
        c11 = 2.0 * pi / (al - 2.0 * nu) / g * (1.0 + (3.0 - math.log(4.0)) / (al - 2.0 * nu))
        c22 = (2.0 * pi / g * (1.0 + (1.0 - nu) * (3.0 - math.log(4.0)) / ((1.0 - nu) * al + 2.0 * nu))
               / ((1.0 - nu) * al + 2.0 * nu))
        c23 = 2.0 * pi / 3.0 / g ** 1.5 / ((1.0 - nu) * al - 2.0 + 4.0 * nu)
    return c11, c22, c23


def kalker_coefficients(a: float, b: float, nu: float, *, beyond_table: str = "asymptotic"
                        ) -> tuple[float, float, float, float]:
    """Kalker's creepage and spin coefficients C11, C22, C23, C33 for an elliptical contact.

    Inside the table (0.1 <= g <= 1 with g = a/b for a <= b and g = b/a for a > b) each coefficient
    is interpolated linearly in g on the table rows at each of nu = 0, 0.25, 0.5 and then in nu by
    quadratic interpolation of 1/C through those three values, exactly as CONTACT's ``linrol``.

    Outside the table (g < 0.1), with ``beyond_table="asymptotic"`` (default) C11, C22, C23 follow
    Kalker's asymptotic formulas for g -> 0 as coded in CONTACT's ``linrol`` [2]_ (note these do not
    join the table continuously at g = 0.1: differences of a few percent; CONTACT switches at
    g < 0.101, here at g < 0.1 so the table nodes are returned exactly); C33 has no published
    asymptote here and is clamped to its g = 0.1 row. With ``beyond_table="clamp"`` g is clamped to 0.1
    for all four coefficients.

    Parameters
    ----------
    a : float
        Semi-axis along the rolling direction [m].
    b : float
        Lateral semi-axis [m].
    nu : float
        Combined Poisson's ratio [1], 0 <= nu <= 0.5.
    beyond_table : {"asymptotic", "clamp"}
        Treatment of g < 0.1.

    Returns
    -------
    C11, C22, C23, C33 : float
        Dimensionless Kalker coefficients [1].

    References
    ----------
    .. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990, table E.3.
       doi:10.1007/978-94-015-7889-9
    .. [2] E.A.H. Vollebregt, CONTACT, src/m_hertz.f90, subroutine linrol.
    """
    if not (a > 0 and b > 0):
        raise ValueError(f"semi-axes must be positive, got a={a!r}, b={b!r} [m]")
    if not (0.0 <= nu <= 0.5):
        raise ValueError(f"Poisson's ratio must lie in [0, 0.5], got {nu!r}")
    if beyond_table not in ("asymptotic", "clamp"):
        raise ValueError(f"beyond_table must be 'asymptotic' or 'clamp', got {beyond_table!r}")
    case = "a/b" if a <= b else "b/a"
    g = a / b if a <= b else b / a
    gt, ct = _TABLES[case]
    gc = max(g, gt[0])
    c3 = np.stack([[np.interp(gc, gt, ct[:, i, j]) for j in range(3)] for i in range(4)])  # (4 coef, 3 nu)
    c = _nu_interp(c3, nu)
    c11, c22, c23, c33 = (float(v) for v in c)
    if g < gt[0] and beyond_table == "asymptotic":
        c11, c22, c23 = _asymptotes(case, g, nu)
    return c11, c22, c23, c33


def kalker_linear_forces(a: float, b: float, G: float, nu: float, xi: float, eta: float, phi: float
                         ) -> tuple[float, float, float]:
    """Creep forces and spin moment of Kalker's linear theory (no saturation).

    ``Fx = -G a b C11 xi``, ``Fy = -G a b (C22 eta + sqrt(ab) C23 phi)``,
    ``Mz = -G a b (-sqrt(ab) C23 eta + ab C33 phi)``.

    Parameters
    ----------
    a, b : float
        Semi-axes [m] of the contact ellipse along x (rolling) and y.
    G, nu : float
        Combined shear modulus [Pa] and Poisson's ratio [1] (:func:`railtherm.physics.combined_elastic`).
    xi, eta, phi : float
        Longitudinal and lateral creepage [1], spin creepage [1/m].

    Returns
    -------
    Fx, Fy : float
        Creep forces on body 1 (wheel) [N].
    Mz : float
        Spin moment [N m].

    References
    ----------
    .. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990.
       doi:10.1007/978-94-015-7889-9
    """
    c11, c22, c23, c33 = kalker_coefficients(a, b, nu)
    c = math.sqrt(a * b)
    gab = G * a * b
    fx = -gab * c11 * xi
    fy = -gab * (c22 * eta + c * c23 * phi)
    mz = -gab * (-c * c23 * eta + c * c * c33 * phi)
    return fx, fy, mz


def flexibilities(a: float, b: float, G: float, nu: float) -> tuple[float, float, float]:
    """Flexibilities of Kalker's simplified theory (FASTSIM).

    ``L1 = 8 a / (3 C11 G)``, ``L2 = 8 a / (3 C22 G)``, ``L3 = pi a sqrt(a/b) / (4 C23 G)``.

    Parameters
    ----------
    a, b, G, nu : float
        As :func:`kalker_linear_forces`: semi-axes [m], combined shear modulus [Pa] and Poisson's ratio [1].

    Returns
    -------
    L1, L2, L3 : float
        Flexibilities [m/Pa].

    References
    ----------
    .. [1] J.J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
       Dynamics 11 (1982) 1-13. doi:10.1080/00423118208968684
    .. [2] E.A.H. Vollebregt, CONTACT, src/m_hertz.f90, subroutine simpflex.
    """
    c11, c22, c23, _ = kalker_coefficients(a, b, nu)
    l1 = 8.0 * a / (3.0 * c11 * G)
    l2 = 8.0 * a / (3.0 * c22 * G)
    l3 = math.pi * a * math.sqrt(a / b) / (4.0 * c23 * G)
    return l1, l2, l3


def weighted_flexibility(a: float, b: float, G: float, nu: float, xi: float, eta: float, phi: float,
                         *, form: str = "kalker") -> float:
    """Single flexibility of the simplified theory, weighted by the creepages.

    ``form="kalker"`` (Kalker 1982 [1]_, used by FASTSIM with one flexibility):
    ``L = (|xi| L1 + |eta| L2 + |phi| c L3) / sqrt(xi^2 + eta^2 + (c phi)^2)``, c = sqrt(a b).

    ``form="contact"`` (CONTACT ``simpflex`` [2]_, combined flexibility ``L_crss``):
    ``L = (xi^2 + eta^2 + (phi f)^2) / (xi^2/L1 + eta^2/L2 + (phi f)^2/L3)``, f = 3 pi a / 32.

    With zero creepage the mean (L1 + L2 + L3)/3 is returned for ``"kalker"`` and the harmonic-type
    limit is undefined, so the mean is also returned for ``"contact"``.

    Parameters
    ----------
    a, b, G, nu, xi, eta, phi : float
        As :func:`kalker_linear_forces`: semi-axes [m], combined shear modulus [Pa] and Poisson's ratio [1],
        creepages [1] and spin creepage [1/m].
    form : {"kalker", "contact"}
        Weighting rule.

    Returns
    -------
    float
        Flexibility L [m/Pa].

    References
    ----------
    .. [1] J.J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
       Dynamics 11 (1982) 1-13. doi:10.1080/00423118208968684
    .. [2] E.A.H. Vollebregt, CONTACT, src/m_hertz.f90, subroutine simpflex.
    """
    l1, l2, l3 = flexibilities(a, b, G, nu)
    if xi == 0 and eta == 0 and phi == 0:
        return (l1 + l2 + l3) / 3.0
    if form == "kalker":
        c = math.sqrt(a * b)
        return (abs(xi) * l1 + abs(eta) * l2 + abs(phi) * c * l3) / math.sqrt(xi ** 2 + eta ** 2 + (c * phi) ** 2)
    if form == "contact":
        f = 3.0 * math.pi * a / 32.0
        s = phi * f
        return (xi ** 2 + eta ** 2 + s ** 2) / (xi ** 2 / l1 + eta ** 2 / l2 + s ** 2 / l3)
    raise ValueError(f"form must be 'kalker' or 'contact', got {form!r}")
