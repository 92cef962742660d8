"""Thermal scales of a body moving under a heat source of semi-length a.

* Péclet number ``Pe = V a / (2 kappa)`` [1] (seed eq. 25);
* thermal depth ``delta = sqrt(2 kappa a / V) = a / sqrt(Pe)`` [m], the layer heated during one
  contact (seed eq. 24);
* contact time ``t_c = 2 a / V`` [s], the time a surface point spends in the patch;
* wake length ``ell = 2 kappa / V = a / Pe`` [m]: ahead of the patch the temperature decays like
  ``exp(-2 s / ell)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ThermalScales", "thermal_scales", "peclet_number"]


def peclet_number(speed: float, a: float, diffusivity: float) -> float:
    """Péclet number ``L = V a / (2 kappa)`` [1] (seed eq. 25).

    Parameters
    ----------
    speed : float
        Speed of the body surface through the patch V [m/s].
    a : float
        Semi-axis (half-width) of the patch along the rolling direction [m].
    diffusivity : float
        Thermal diffusivity kappa = lambda/(rho c) [m^2/s].

    Returns
    -------
    float
        Pe [1].

    References
    ----------
    .. [1] J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts, Proc. Roy.
       Soc. N.S.W. 76 (1942) 203-224.
    """
    return float(speed) * float(a) / (2.0 * float(diffusivity))


@dataclass(frozen=True)
class ThermalScales:
    """Scales of the moving heat source problem for one body.

    Attributes
    ----------
    peclet : float
        Pe = V a / (2 kappa) [1].
    thermal_depth : float
        delta = sqrt(2 kappa a / V) [m].
    contact_time : float
        t_c = 2 a / V [s].
    wake_length : float
        ell = 2 kappa / V [m].
    """

    peclet: float
    thermal_depth: float
    contact_time: float
    wake_length: float


def thermal_scales(a: float, speed: float, diffusivity: float) -> ThermalScales:
    """Thermal scales of a body moving at ``speed`` under a patch of semi-length ``a``.

    Parameters
    ----------
    a : float
        Semi-axis of the patch along the rolling direction [m].
    speed : float
        Speed of the body's surface relative to the contact V [m/s], > 0.
    diffusivity : float
        Thermal diffusivity kappa [m^2/s].

    Returns
    -------
    ThermalScales

    Raises
    ------
    ValueError
        When ``speed`` is not > 0 (no moving-frame scales).

    References
    ----------
    .. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation
       of temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
    """
    if not speed > 0:
        raise ValueError(f"speed must be > 0 for the thermal scales of a moving body, got {speed!r}")
    return ThermalScales(peclet=peclet_number(speed, a, diffusivity),
                         thermal_depth=math.sqrt(2.0 * diffusivity * a / speed),
                         contact_time=2.0 * a / speed, wake_length=2.0 * diffusivity / speed)
