"""Carter's exact solution of 2-D steady rolling with creepage between quasi-identical elastic bodies.

Hertzian line contact |x| <= a with pressure p0 sqrt(1 - (x/a)^2), Coulomb friction mu, rolling in +x
(leading edge x = +a). The stick zone of half-width a' adjoins the leading edge, ``a - 2a' <= x <= a``,
centred at d = a - a'; slip occupies the trailing part. Carter (1926): ``|xi| = mu (a - a') / R``,
``Fx / (mu Fn) = -sign(xi) (1 - (a'/a)^2)``, with CONTACT's sign convention (positive creepage gives a
negative force on body 1, the wheel). The traction on the wheel is ``-sign(xi) mu p0 [sqrt(1 - (x/a)^2)
- (a'/a) sqrt(1 - ((x - d)/a')^2)]`` (second term only in the stick zone). Full sliding when
|xi| >= mu a / R.

References: F.W. Carter, On the action of a locomotive driving wheel, Proc. R. Soc. Lond. A 112 (1926)
151-157, doi:10.1098/rspa.1926.0100. K.L. Johnson, Contact Mechanics, 1985, section 8.4,
doi:10.1017/CBO9781139171731. E.A.H. Vollebregt, CONTACT user guide, test case carter2d:
xi = -mu (a - a')/R, Fx = (1 - (a'/a)^2) mu Fn, Fn = pi a^2 G / (4 R (1 - nu)) per unit width.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["CarterResult", "carter_2d", "carter_normal_load"]


@dataclass(frozen=True)
class CarterResult:
    """Result of :func:`carter_2d`.

    Attributes
    ----------
    force_ratio : float
        Fx / (mu Fn) on the wheel [1], in [-1, 1].
    stick_half_width : float
        Half-width a' of the stick zone [m] (0 at full sliding).
    stick_centre : float
        Centre d = a - a' of the stick zone [m].
    creepage_saturation : float
        Creepage magnitude mu a / R above which the contact fully slides [1].
    traction : callable
        traction(x) -> tangential traction on the wheel [units of max_pressure, Pa if given].
    stick : callable
        stick(x) -> boolean array, True in the stick zone.
    """

    force_ratio: float
    stick_half_width: float
    stick_centre: float
    creepage_saturation: float
    traction: Callable
    stick: Callable


def carter_2d(creepage: float, half_width: float, friction: float, radius: float, *,
              max_pressure: float = 1.0) -> CarterResult:
    """Carter's 2-D rolling contact with longitudinal creepage.

    Parameters
    ----------
    creepage : float
        Longitudinal creepage xi [1]; positive gives a negative force on the wheel (CONTACT).
    half_width : float
        Contact half-width a [m].
    friction : float
        Coefficient of friction mu [1], > 0.
    radius : float
        Effective rolling radius R [m] of the cylinder-on-plane (1/R = 1/R1 + 1/R2 for two cylinders).
    max_pressure : float, optional
        Peak Hertz pressure p0 [Pa]; the traction is returned in its units (default 1: traction / p0).

    Returns
    -------
    CarterResult

    References
    ----------
    .. [1] F.W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157. doi:10.1098/rspa.1926.0100
    .. [2] K.L. Johnson, Contact Mechanics, 1985, eqs. (8.40)-(8.43). doi:10.1017/CBO9781139171731
    """
    if not (half_width > 0 and friction > 0 and radius > 0):
        raise ValueError("half_width, friction and radius must be positive")
    a, mu, r = float(half_width), float(friction), float(radius)
    sat = mu * a / r
    sgn = -math.copysign(1.0, creepage) if creepage != 0 else 0.0
    a_st = max(a - abs(creepage) * r / mu, 0.0)
    if creepage == 0:
        a_st = a
    d = a - a_st
    ratio = sgn * (1.0 - (a_st / a) ** 2)
    p0 = float(max_pressure)

    def stick(x):
        x = np.asarray(x, dtype=float)
        if a_st == 0.0:
            return np.zeros(x.shape, dtype=bool)
        return np.abs(x - d) < a_st

    def traction(x):
        x = np.asarray(x, dtype=float)
        full = np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
        corr = 0.0
        if a_st > 0.0:
            corr = (a_st / a) * np.sqrt(np.clip(1.0 - ((x - d) / a_st) ** 2, 0.0, None))
        return sgn * mu * p0 * (full - corr)

    return CarterResult(force_ratio=ratio, stick_half_width=a_st, stick_centre=d, creepage_saturation=sat,
                        traction=traction, stick=stick)


def carter_normal_load(half_width: float, radius: float, shear_modulus: float, poisson_ratio: float) -> float:
    """Normal load per unit width for a Hertz line contact of identical bodies (cylinder on plane).

    ``Fn = pi a^2 G / (4 R (1 - nu))`` [N/m], i.e. a = sqrt(4 Fn R / (pi E*)) with
    E* = G / (1 - nu) for two identical bodies (Johnson 1985, eq. 4.43).

    Parameters
    ----------
    half_width : float
        Contact half-width a [m].
    radius : float
        Effective radius R [m].
    shear_modulus : float
        G [Pa].
    poisson_ratio : float
        nu [1].

    Returns
    -------
    float
        Load per unit width [N/m].
    """
    return math.pi * half_width ** 2 * shear_modulus / (4.0 * radius * (1.0 - poisson_ratio))
