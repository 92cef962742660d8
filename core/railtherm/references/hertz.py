"""Hertz normal contact: elliptical (point) and 2-D line contact between elastic bodies.

Conventions: x is the rolling direction, y lateral. The undeformed gap between the bodies is
``h(x, y) = A x^2 + B y^2`` [m] with curvature coefficients ``A``, ``B`` [1/m] (``A = (1/R1x + 1/R2x)/2``).
The contact ellipse has semi-axis ``a`` along x and ``b`` along y. The combined (plane-strain) modulus
``E*`` follows 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson 1985, eq. 4.22;
:func:`railtherm.physics.elastic.contact_modulus`).

References
----------
.. [1] K.L. Johnson, Contact Mechanics, Cambridge University Press, 1985, sections 3.6, 4.2, 4.3.
   doi:10.1017/CBO9781139171731
.. [2] H. Hertz, Ueber die Beruehrung fester elastischer Koerper, J. reine angew. Math. 92 (1882)
   156-171. doi:10.1515/crll.1882.92.156
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk, ellipkm1

__all__ = ["HertzEllipse", "hertz_from_curvatures", "hertz_from_penetration",
           "hertz_from_semi_axes", "hertz_line", "hertz_pressure", "curvature_ratio",
           "elliptic_k_minus_e"]


@dataclass(frozen=True)
class HertzEllipse:
    """Hertzian elliptical contact.

    Attributes
    ----------
    a : float
        Semi-axis along the rolling direction x [m].
    b : float
        Lateral semi-axis along y [m].
    max_pressure : float
        Peak pressure p0 at the centre [Pa]; ``p = p0 sqrt(1 - (x/a)^2 - (y/b)^2)``.
    approach : float
        Mutual approach (penetration) of distant points of the bodies [m]; nan when unknown.
    normal_force : float
        Total normal force N = 2 pi p0 a b / 3 [N].
    """

    a: float
    b: float
    max_pressure: float
    approach: float
    normal_force: float

    @property
    def area(self) -> float:
        """Contact area pi a b [m^2]."""
        return math.pi * self.a * self.b

    @property
    def mean_pressure(self) -> float:
        """Mean pressure N / (pi a b) = 2 p0 / 3 [Pa]."""
        return 2.0 * self.max_pressure / 3.0


# --------------------------------------------------------------------------------------------------
# Elliptic-integral combinations without cancellation for small eccentricity.
# K(m) = pi/2 sum c_n^2 m^n, E(m) = pi/2 sum c_n^2 m^n / (1 - 2n), c_n = (2n)! / (2^2n n!^2).
_NSERIES = 60
_c2 = np.empty(_NSERIES)
_c2[0] = 1.0
for _n in range(1, _NSERIES):
    _c2[_n] = _c2[_n - 1] * ((2 * _n - 1) / (2 * _n)) ** 2
_kcoef = 0.5 * math.pi * _c2
_ecoef = 0.5 * math.pi * _c2 / (1.0 - 2.0 * np.arange(_NSERIES))
# D(m) = (K - E)/m, F(m) = (E/(1-m) - K)/m: series coefficients (index n -> m^n)
_dcoef = (_kcoef - _ecoef)[1:]
_fcoef = (np.cumsum(_ecoef) - _kcoef)[1:]
_MSERIES = 0.2  # 0.2^60 ~ 1e-42: series converged to machine precision


def _poly(coef, m):
    return np.polynomial.polynomial.polyval(m, coef)


def elliptic_k_minus_e(m: float) -> tuple[float, float, float, float]:
    """Return ``(K, E, D, F)`` at parameter m = e^2 with D = (K - E)/m and F = (E/(1 - m) - K)/m.

    D and F are evaluated by power series for small m (no cancellation) and from scipy's complete
    elliptic integrals otherwise; K near m = 1 uses ``ellipkm1``.
    """
    m = float(m)
    if m < _MSERIES:
        k = float(_poly(_kcoef, m))
        e = float(_poly(_ecoef, m))
        return k, e, float(_poly(_dcoef, m)), float(_poly(_fcoef, m))
    k = float(ellipkm1(1.0 - m)) if m > 0.5 else float(ellipk(m))
    e = float(ellipe(m))
    return k, e, (k - e) / m, (e / (1.0 - m) - k) / m


def curvature_ratio(m: float) -> float:
    """Hertz curvature ratio ``A_major_curv / A_minor_curv`` as function of m = 1 - (minor/major)^2 [1].

    For an ellipse with major semi-axis along the direction of the smaller curvature coefficient
    (A_small) the ratio A_large / A_small = F(m)/D(m), increasing from 1 (circle) to infinity.
    """
    _, _, d, f = elliptic_k_minus_e(m)
    return f / d


def _solve_m(ratio: float) -> float:
    """Parameter m = e^2 of the ellipse for curvature ratio A_large/A_small >= 1."""
    if ratio < 1.0:
        raise ValueError("ratio must be >= 1")
    if ratio == 1.0:
        return 0.0
    # work in t = -log(1 - m) (so m near 1 is resolved) ; ratio grows monotonically with t
    g = lambda t: math.log(curvature_ratio(-math.expm1(-t))) - math.log(ratio)  # noqa: E731
    lo, hi = 1e-300, 1.0
    while g(hi) < 0.0:
        hi *= 2.0
        if hi > 700.0:
            raise ValueError(f"curvature ratio {ratio:g} too large")
    t = brentq(g, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    return -math.expm1(-t)


def _check_curvatures(A, B):
    if not (A > 0 and B > 0 and math.isfinite(A) and math.isfinite(B)):
        raise ValueError(f"curvatures must be positive and finite, got A={A!r}, B={B!r} [1/m]")


def _eccentricity(A: float, B: float) -> tuple[float, float, float, float]:
    """The smaller curvature [1/m], the parameter m = 1 - (c_minor/c_major)^2 [1] of the ellipse of the gap
    curvatures A, B, and K(m), D(m) = (K - E)/m [1] (Johnson 1985, section 4.2)."""
    small, large = min(A, B), max(A, B)
    m = _solve_m(large / small)
    k, _, d, _ = elliptic_k_minus_e(m)
    return small, m, k, d


def _semi_axes(c_major: float, m: float, A: float, B: float) -> tuple[float, float, float]:
    """Semi-axes a (along x), b [m] and the minor one c_minor [m]: the major axis lies along the smaller
    curvature."""
    c_minor = c_major * math.sqrt(1.0 - m)
    a, b = (c_major, c_minor) if A <= B else (c_minor, c_major)
    return a, b, c_minor


def hertz_from_curvatures(A: float, B: float, normal_force: float, e_star: float) -> HertzEllipse:
    """Hertz elliptical contact from the gap curvatures and the normal force.

    The major semi-axis lies along the direction with the smaller curvature coefficient.
    With e^2 = m = 1 - (minor/major)^2, K = K(m), E = E(m) (complete elliptic integrals),
    Johnson (1985) eqs. (3.63)-(3.64) for the major semi-axis ``c`` along the flatter direction:

    ``A_small = (3 N / (2 pi c^3 E*)) (K - E)/m``,
    ``A_large / A_small = (E/(1-m) - K) / (K - E)``,
    ``p0 = 3 N / (2 pi a b)``, approach ``delta = p0 c_minor K / E*``.

    Parameters
    ----------
    A : float
        Gap curvature coefficient along x (rolling) [1/m]; gap h = A x^2 + B y^2.
    B : float
        Gap curvature coefficient along y (lateral) [1/m].
    normal_force : float
        Normal force N [N].
    e_star : float
        Combined modulus E* [Pa] (see :func:`contact_modulus`).

    Returns
    -------
    HertzEllipse
        With the approach the load gives.

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, section 4.2. doi:10.1017/CBO9781139171731
    """
    _check_curvatures(A, B)
    if not normal_force > 0:
        raise ValueError(f"normal_force must be positive, got {normal_force!r} [N]")
    small, m, k, d = _eccentricity(A, B)
    c_major = (3.0 * normal_force * d / (2.0 * math.pi * small * e_star)) ** (1.0 / 3.0)
    a, b, c_minor = _semi_axes(c_major, m, A, B)
    p0 = 3.0 * normal_force / (2.0 * math.pi * a * b)
    approach = p0 * c_minor * k / e_star
    return HertzEllipse(a=a, b=b, max_pressure=p0, approach=approach, normal_force=float(normal_force))


def hertz_from_penetration(A: float, B: float, approach: float, e_star: float) -> HertzEllipse:
    """Hertz elliptical contact from the gap curvatures and the approach (penetration).

    ``delta = A_small c_major^2 K / D`` with D = (K - E)/m (Johnson 1985, eqs. 3.63-3.64), so
    ``c_major = sqrt(delta D / (A_small K))``; then N = 2 pi p0 a b / 3.

    Parameters
    ----------
    A, B : float
        Gap curvature coefficients along x and y [1/m].
    approach : float
        Mutual approach delta of distant points [m], > 0.
    e_star : float
        Combined modulus E* [Pa].

    Returns
    -------
    HertzEllipse
        With the normal force the approach gives.

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, section 4.2. doi:10.1017/CBO9781139171731
    """
    _check_curvatures(A, B)
    if not approach > 0:
        raise ValueError(f"approach must be positive, got {approach!r} [m]")
    small, m, k, d = _eccentricity(A, B)
    c_major = math.sqrt(approach * d / (small * k))
    a, b, c_minor = _semi_axes(c_major, m, A, B)
    p0 = approach * e_star / (c_minor * k)
    n = 2.0 * math.pi * p0 * a * b / 3.0
    return HertzEllipse(a=a, b=b, max_pressure=p0, approach=float(approach), normal_force=n)


def hertz_from_semi_axes(a: float, b: float, normal_force: float) -> HertzEllipse:
    """Hertzian pressure for given semi-axes and normal force: p0 = 3 N / (2 pi a b).

    Parameters
    ----------
    a, b : float
        Semi-axes along x and y [m].
    normal_force : float
        Normal force [N].

    Returns
    -------
    HertzEllipse
        ``approach`` is nan (it needs the elastic constants and curvatures).
    """
    if not (a > 0 and b > 0):
        raise ValueError(f"semi-axes must be positive, got a={a!r}, b={b!r} [m]")
    p0 = 3.0 * normal_force / (2.0 * math.pi * a * b)
    return HertzEllipse(a=float(a), b=float(b), max_pressure=p0, approach=math.nan,
                        normal_force=float(normal_force))


def hertz_line(load_per_width: float, radius: float, e_star: float) -> tuple[float, float]:
    """2-D Hertz line contact of a cylinder (radius R) on a half-plane (or two cylinders, 1/R = 1/R1 + 1/R2).

    ``a = sqrt(4 N R / (pi E*))``, ``p0 = 2 N / (pi a)``.

    Parameters
    ----------
    load_per_width : float
        Normal load per unit width N [N/m].
    radius : float
        Effective radius R [m].
    e_star : float
        Combined modulus E* [Pa].

    Returns
    -------
    half_width : float
        Contact half-width a [m].
    max_pressure : float
        Peak pressure p0 [Pa]; p(x) = p0 sqrt(1 - (x/a)^2).

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, eqs. (4.43)-(4.45). doi:10.1017/CBO9781139171731
    """
    if not (load_per_width > 0 and radius > 0 and e_star > 0):
        raise ValueError("load_per_width, radius and e_star must be positive")
    a = math.sqrt(4.0 * load_per_width * radius / (math.pi * e_star))
    p0 = 2.0 * load_per_width / (math.pi * a)
    return a, p0


def hertz_pressure(x, y, a: float, b: float | None, p0: float):
    """Hertzian pressure distribution, zero outside the contact.

    Parameters
    ----------
    x : array_like
        Rolling coordinate [m].
    y : array_like or None
        Lateral coordinate [m]; None for a line contact.
    a : float
        Semi-axis (half-width) along x [m].
    b : float or None
        Lateral semi-axis [m] (ignored for a line contact).
    p0 : float
        Peak pressure [Pa].

    Returns
    -------
    numpy.ndarray
        Pressure [Pa], ``p0 sqrt(1 - (x/a)^2 - (y/b)^2)`` inside, 0 outside.
    """
    x = np.asarray(x, dtype=float)
    r2 = (x / a) ** 2
    if y is not None:
        r2 = r2 + (np.asarray(y, dtype=float) / b) ** 2
    return p0 * np.sqrt(np.clip(1.0 - r2, 0.0, None))
