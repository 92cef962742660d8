"""Ertz & Knothe's lumped wheel: the long-term (steady) wheel temperature (seed eqs. 40-54, 3-D form).

After many revolutions the wheel is warm, at a nearly uniform temperature theta_w0 above the rail and
the air (seed §5.1-5.3; the wheel's Biot number is small, so it is treated as lumped). It loses heat by
conduction into the cold rail at each contact (eqs. 40-43, :func:`conduction_conductance`) and by
convection to the air through the area A (eqs. 45-49, :func:`convective_area`; the one choice,
:data:`CONVECTIVE_AREA` = "wheel", is fitted to the published table). Steady state (eqs. 50-52):
``eps P = (G_cond + alpha A) theta_inf``; the steady mean contact temperature (eq. 54) superposes the
cold-body flash field and the warm-wheel conduction field: ``theta_mean_inf = theta_mean + eps_c
theta_inf``. Eq. 53 (``theta_inf/theta_mean``) is garbled in the seed and not used.

References: M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
temperatures in wheel/rail contact, Wear 253 (2002) 498-508. H. Blok, Theoretical study of temperature
rise at surfaces of actual contact under oiliness lubricating conditions, Proc. General Discussion on
Lubrication, IMechE 2 (1937) 222-235.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .partition import equal_temperature_partition

__all__ = ["CONVECTIVE_AREA", "CONVECTIVE_AREAS", "ELLIPSE_SQRT_WIDTH", "LumpedWheel", "conduction_conductance",
           "convective_area", "lumped_wheel"]

#: int_{-1}^{1} (1 - eta^2)^{1/4} d eta = B(1/2, 5/4) [1]: effective width of the conduction on an
#: ellipse / b (scipy.special.beta(0.5, 1.25), kept as a literal so that importing railtherm needs no scipy)
ELLIPSE_SQRT_WIDTH = 1.7480383695280797

#: the documented convective-area choice of the lumped wheel (see :func:`convective_area`)
CONVECTIVE_AREA = "wheel"
#: the convective areas :func:`convective_area` knows
CONVECTIVE_AREAS = ("wheel", "tread")


def conduction_conductance(effusivity_rail: float, speed_rail: float, contact_fraction: float, a: float,
                           b: float | None) -> float:
    """Conductance of the warm-wheel-to-cold-rail conduction through the patch (eqs. 40-43, 3-D form).

    Two half-spaces at temperatures theta_w0 and 0 brought into contact take the interface temperature
    ``theta_m = eps_c theta_w0`` (eq. 41), with the equal-temperature (Blok) fraction ``eps_c`` of
    :func:`railtherm.physics.equal_temperature_partition` (for v_w = v_r it is eq. 41's
    beta_w/(beta_w+beta_r)). The rail then takes the flux ``q(x) = eps_c beta_r theta_w0 sqrt(v_r / (pi
    (a_y - x)))`` (eq. 42), i.e. per unit width of a strip of half-length a_y, ``eps_c beta_r theta_w0
    sqrt(8 a_y v_r / pi)`` (eq. 43). On the ellipse the strips have ``a_y = a sqrt(1 - y^2/b^2)`` and the
    exact total conductance is

        G_cond = eps_c beta_r sqrt(8 a v_r / pi) * b * B(1/2, 5/4),   B(1/2, 5/4) = 1.74804

    (the seed's effective width b* = 4b/3 instead of b B(1/2, 5/4) reproduces the printed eq. 52,
    239.7 / 138.4 degC, not its Table 1; the 3-D form gives 182.8 / 105.5 against 182.6 / 105.4).

    Parameters
    ----------
    effusivity_rail : float
        beta_r = sqrt(lambda rho c) of the rail [W s^0.5 / (m^2 K)].
    speed_rail : float
        Rail surface speed through the patch v_r [m/s].
    contact_fraction : float
        eps_c, interface temperature / wheel excess temperature [1].
    a : float
        Semi-axis along the rolling direction [m].
    b : float or None
        Lateral semi-axis [m]; None for a line contact (result per unit width).

    Returns
    -------
    float
        Heat flow per kelvin of wheel excess temperature [W/K] ([W/(m K)] for a line contact):
        ``eps_c beta_r sqrt(8 a v_r / pi) * b B(1/2, 5/4)`` on an ellipse.
    """
    per_width = contact_fraction * effusivity_rail * math.sqrt(8.0 * a * speed_rail / math.pi)
    return per_width if b is None else per_width * b * ELLIPSE_SQRT_WIDTH


def convective_area(radius: float, b: float | None, kind: str = CONVECTIVE_AREA) -> float:
    """Convective surface of the lumped wheel (eq. 48 in 3-D): ``Q_conv = alpha A theta_w0`` goes through it.

    The default ``"wheel"``, the whole lumped wheel as a solid disc of the rolling radius r0, was FITTED,
    not derived: inverting the steady rows of Ertz & Knothe (2002) Table 1 (``tests/data/published.toml``)
    gives A = 1.57-1.59 m^2 for every alpha and both speeds, the disc of r0 = 0.49 m; agreement with those
    rows is a consistency check, not a verification. ``"tread"``, the running band only (eq. 48 literally,
    per unit width of the band), is ~25x smaller and makes convection negligible.

    Parameters
    ----------
    radius : float
        Wheel rolling radius r0 [m].
    b : float or None
        Lateral semi-axis of the contact [m]; the running band is 2b wide. None for a line
        contact: the result is per unit width, 2 pi r0 [m], for either kind.
    kind : {"wheel", "tread"}
        "wheel" (the default, :data:`CONVECTIVE_AREA`): a solid disc of radius r0,
        ``2 pi r0^2 + 2 pi r0 2b``; "tread": the running band, ``2 pi r0 2b``.

    Returns
    -------
    float
        Area [m^2] ([m] per unit width for a line contact).
    """
    if kind not in CONVECTIVE_AREAS:
        raise ValueError(f"convective area kind {kind!r}: one of 'wheel', 'tread'")
    if b is None:
        return 2.0 * math.pi * radius
    band = 2.0 * math.pi * radius * 2.0 * b
    return band if kind == "tread" else band + 2.0 * math.pi * radius * radius


@dataclass(frozen=True)
class LumpedWheel:
    """Long-term state of the lumped wheel (rises above rail and air).

    Attributes
    ----------
    wheel_rise : float
        theta_inf [K].
    mean_contact_rise : float
        theta_mean_inf = theta_mean + eps_c theta_inf [K].
    wheel_power : float
        Frictional heat into the wheel eps P [W] ([W/m] line).
    conduction : float
        G_cond [W/K] ([W/(m K)] line).
    convection : float
        alpha A [W/K] ([W/(m K)] line).
    area : float
        Convective area A [m^2] ([m] line).
    contact_fraction : float
        eps_c [1].
    """

    wheel_rise: float
    mean_contact_rise: float
    wheel_power: float
    conduction: float
    convection: float
    area: float
    contact_fraction: float

    @property
    def conductance(self) -> float:
        """Total loss conductance G_cond + alpha A [W/K] ([W/(m K)] line)."""
        return self.conduction + self.convection

    @property
    def convection_ratio(self) -> float:
        """Q_convection / Q_rail (seed eq. 49) [1]."""
        return self.convection / self.conduction


def lumped_wheel(wheel_power: float, mean_flash_rise: float, *, wheel, rail, speed_wheel: float,
                 speed_rail: float, a: float, b: float | None, radius: float, heat_transfer: float = 0.0,
                 area_kind: str = CONVECTIVE_AREA) -> LumpedWheel:
    """Steady-state wheel temperature and mean contact temperature of the lumped wheel (seed eqs. 50-54).

    Parameters
    ----------
    wheel_power : float
        Frictional heat flowing into the wheel, eps P_friction [W] ([W/m] for a line contact).
    mean_flash_rise : float
        theta_mean, mean contact temperature rise of the first contact of a cold wheel [K].
    wheel, rail : Material-like
        Bodies with ``effusivity`` [W s^0.5 / (m^2 K)].
    speed_wheel, speed_rail : float
        Surface speeds through the patch [m/s].
    a : float
        Semi-axis along rolling [m].
    b : float or None
        Lateral semi-axis [m]; None for a line contact.
    radius : float
        Wheel rolling radius r0 [m].
    heat_transfer : float
        Convective heat transfer coefficient alpha [W/(m^2 K)].
    area_kind : {"wheel", "tread"}
        Convective surface (:func:`convective_area`); the documented choice is the default.

    Returns
    -------
    LumpedWheel
        ``wheel_rise = eps P / (G_cond + alpha A)`` (0 when nothing carries heat away and no heat
        comes in).
    """
    eps_c = equal_temperature_partition(wheel, rail, speed_wheel, speed_rail)
    g_cond = conduction_conductance(rail.effusivity, speed_rail, eps_c, a, b)
    area = convective_area(radius, b, area_kind)
    g_conv = float(heat_transfer) * area
    g_tot = g_cond + g_conv
    theta = wheel_power / g_tot if g_tot > 0 else (0.0 if wheel_power == 0 else math.inf)
    return LumpedWheel(theta, mean_flash_rise + eps_c * theta, wheel_power, g_cond, g_conv, area, eps_c)
