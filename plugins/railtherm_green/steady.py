"""Long-term (steady-state) wheel temperature: seed eqs. 40-54 in a 3-D consistent form.

After many revolutions the wheel is warm, at a nearly uniform temperature theta_w0 above the rail
and the air (seed §5.1-5.3; the Biot number of the wheel is small, so it is treated as lumped).
Each time a wheel point passes the contact, the warm wheel meets the cold rail:

* Conduction into the rail (eqs. 40-43). Two half-spaces at temperatures theta_w0 and 0 brought
  into contact take the interface temperature ``theta_m = eps_c theta_w0`` (eq. 41). With the
  bodies moving at v_w and v_r through the patch the equal-interface-temperature fraction is the
  Blok one, ``eps_c = beta_w sqrt(v_w) / (beta_w sqrt(v_w) + beta_r sqrt(v_r))`` (for v_w = v_r it
  is eq. 41's beta_w/(beta_w+beta_r)). The rail then takes the flux
  ``q(x) = eps_c beta_r theta_w0 sqrt(v_r / (pi (a_y - x)))`` (eq. 42), i.e. per unit width of a
  strip of half-length a_y, ``eps_c beta_r theta_w0 sqrt(8 a_y v_r / pi)`` (eq. 43).
  The seed writes its balance per unit of an effective width b* that it takes the same for the
  frictional power (eq. 51: N = (pi/2) p0 a b*, so b* = 4b/3) and for the conduction; on the ellipse
  the strips have a_y = a sqrt(1 - y^2/b^2), and the exact total conductance is

      G_cond = eps_c beta_r sqrt(8 a v_r / pi) * b * B(1/2, 5/4),   B(1/2, 5/4) = 1.74804

  (instead of b* = 1.3333 b). This 3-D form is what we implement; with it, eq. 52 becomes
  ``theta_inf = eps P / G_cond`` and reproduces the seed's Table 1 steady values without convection
  (182.8 / 105.5 degC against 182.6 / 105.4), which eq. 52 as printed (239.7 / 138.4) does not.
* Convection to the air (eqs. 45-49): ``Q_conv = alpha A theta_w0``. Eq. 48 takes, per unit width,
  the circumference 2 pi r0; in 3-D the lumped wheel convects through its exposed surface A. Two
  choices (model option ``convective_area``): ``"tread"``, the running band swept by the contact,
  ``A = 2 pi r0 (2 b)`` (eq. 48 literally, per unit width of the contact band), and ``"wheel"``,
  the whole lumped wheel as a solid disc of the rolling radius, ``A = 2 pi r0^2 + 2 pi r0 (2 b)``
  (both faces and the band).
* Steady state (eqs. 50-52): frictional heat into the wheel = heat out,
  ``eps P = (G_cond + alpha A) theta_inf``.
* Steady mean contact temperature (eq. 54): by superposition of the cold-body flash field and the
  warm-wheel conduction field, ``theta_mean_inf = theta_mean + eps_c theta_inf``.

Eq. 53 (``theta_inf/theta_mean``) is garbled in the seed and not used; it follows from the above.

References
----------
.. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
   temperatures in wheel/rail contact, Wear 253 (2002) 498-508. doi:10.1016/S0043-1648(02)00120-3
.. [2] H. Blok, Theoretical study of temperature rise at surfaces of actual contact under oiliness
   lubricating conditions, Proc. General Discussion on Lubrication, IMechE 2 (1937) 222-235.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import beta as _beta_fn

__all__ = ["blok_partition", "conduction_conductance", "convective_area", "SteadyState", "steady_state",
           "contact_conduction_surface", "contact_conduction_depth", "ELLIPSE_SQRT_WIDTH"]

#: int_{-1}^{1} (1 - eta^2)^{1/4} d eta = B(1/2, 5/4): effective width of the conduction on an ellipse / b
ELLIPSE_SQRT_WIDTH = float(_beta_fn(0.5, 1.25))


def blok_partition(effusivity_wheel: float, effusivity_rail: float, speed_wheel: float, speed_rail: float) -> float:
    """Equal-surface-temperature heat partition (fraction into the wheel), seed eq. 38 with eqs. 32-33.

    ``eps = beta_w sqrt(v_w) / (beta_w sqrt(v_w) + beta_r sqrt(v_r))``. In the 1-D Green function
    model the two bodies' kernels differ only by the factor ``1/(beta sqrt(v))``, so this constant
    fraction makes the two surface temperatures equal at *every* point of the patch for any flux
    distribution: a per-cell ("local") equal-temperature partition is the same constant.

    Parameters
    ----------
    effusivity_wheel, effusivity_rail : float
        beta = sqrt(lambda rho c) of wheel and rail [W s^0.5 / (m^2 K)].
    speed_wheel, speed_rail : float
        Surface speeds through the patch, v_w = v0 + v_s and v_r = v0 [m/s].

    Returns
    -------
    float
        Fraction of the heat entering the wheel [1].
    """
    w = effusivity_wheel * math.sqrt(speed_wheel)
    r = effusivity_rail * math.sqrt(speed_rail)
    return w / (w + r)


def conduction_conductance(effusivity_rail: float, speed_rail: float, contact_fraction: float, a: float,
                           b: float | None) -> float:
    """Conductance of the warm-wheel-to-cold-rail conduction through the patch (eqs. 42-43, 3-D form).

    Parameters
    ----------
    effusivity_rail : float
        beta_r [W s^0.5 / (m^2 K)].
    speed_rail : float
        Rail surface speed v_r = v0 [m/s].
    contact_fraction : float
        eps_c, interface temperature / wheel excess temperature [1] (:func:`blok_partition`).
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


def convective_area(radius: float, b: float | None, kind: str = "wheel") -> float:
    """Convective surface of the lumped wheel (eq. 48 in 3-D).

    Parameters
    ----------
    radius : float
        Wheel rolling radius r0 [m].
    b : float or None
        Lateral semi-axis of the contact [m]; the running band is 2b wide. None for a line
        contact: the result is per unit width, 2 pi r0 [m], for either kind.
    kind : {"wheel", "tread"}
        "tread": the running band, ``2 pi r0 2b``; "wheel": a solid disc of radius r0,
        ``2 pi r0^2 + 2 pi r0 2b``.

    Returns
    -------
    float
        Area [m^2] ([m] per unit width for a line contact).
    """
    if kind not in ("wheel", "tread"):
        raise ValueError(f"convective area kind {kind!r}: one of 'wheel', 'tread'")
    if b is None:
        return 2.0 * math.pi * radius
    band = 2.0 * math.pi * radius * 2.0 * b
    return band if kind == "tread" else band + 2.0 * math.pi * radius * radius


@dataclass(frozen=True)
class SteadyState:
    """Long-term wheel temperature (rises above rail and air).

    Attributes
    ----------
    wheel_rise : float
        theta_inf [K].
    mean_contact_rise : float
        theta_mean_inf = theta_mean + eps_c theta_inf [K].
    wheel_power : float
        Frictional heat into the wheel eps P [W] ([W/m] line).
    conduction : float
        G_cond [W/K].
    convection : float
        alpha A [W/K].
    area : float
        A [m^2].
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
    def convection_ratio(self) -> float:
        """Q_convection / Q_rail (seed eq. 49) [1]."""
        return self.convection / self.conduction


def steady_state(wheel_power: float, mean_flash_rise: float, *, effusivity_wheel: float, effusivity_rail: float,
                 speed_wheel: float, speed_rail: float, a: float, b: float | None, radius: float,
                 heat_transfer: float = 0.0, area_kind: str = "wheel") -> SteadyState:
    """Steady-state wheel temperature and mean contact temperature (seed eqs. 50-54).

    Parameters
    ----------
    wheel_power : float
        Frictional heat flowing into the wheel, eps P_friction [W] ([W/m] for a line contact).
    mean_flash_rise : float
        theta_mean, mean contact temperature rise of the first contact of a cold wheel [K].
    effusivity_wheel, effusivity_rail : float
        beta of wheel and rail [W s^0.5 / (m^2 K)].
    speed_wheel, speed_rail : float
        Surface speeds through the patch [m/s].
    a : float
        Semi-axis along rolling [m].
    b : float or None
        Lateral semi-axis [m]; None for a line contact.
    radius : float
        Wheel radius r0 [m].
    heat_transfer : float
        Convective heat transfer coefficient alpha [W/(m^2 K)].
    area_kind : {"wheel", "tread"}
        Convective surface, see :func:`convective_area`.

    Returns
    -------
    SteadyState
    """
    eps_c = blok_partition(effusivity_wheel, effusivity_rail, speed_wheel, speed_rail)
    g_cond = conduction_conductance(effusivity_rail, speed_rail, eps_c, a, b)
    area = convective_area(radius, b, area_kind)
    g_conv = float(heat_transfer) * area
    theta = wheel_power / (g_cond + g_conv)
    return SteadyState(theta, mean_flash_rise + eps_c * theta, wheel_power, g_cond, g_conv, area, eps_c)


def contact_conduction_surface(x: np.ndarray, half_length: np.ndarray,
                               contact_fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """Surface temperature change of a warm wheel against a cold rail, per unit excess (eqs. 41, 44).

    For a strip of half-length a_y (material enters at x = +a_y): upstream of the patch nothing has
    happened; in the patch the interface sits at ``eps_c`` (eq. 41); behind it (x < -a_y) the
    surfaces recover as ``(2/pi) arcsin(sqrt(2 a_y / (a_y - x)))`` (eq. 44, exact for the flux of
    eq. 42).

    Parameters
    ----------
    x : ndarray
        Rolling coordinate of the points [m] (broadcast against ``half_length``).
    half_length : ndarray
        Contact half-length a_y of each point's strip [m]; <= 0 where the strip misses the patch.
    contact_fraction : float
        eps_c [1].

    Returns
    -------
    wheel, rail : ndarray
        Temperature change per kelvin of (wheel bulk - rail bulk) [1]: wheel <= 0, rail >= 0.
    """
    x, ay = np.broadcast_arrays(np.asarray(x, float), np.asarray(half_length, float))
    shape = np.zeros(x.shape)
    inside = (ay > 0) & (np.abs(x) <= ay)
    behind = (ay > 0) & (x < -ay)
    shape[inside] = 1.0
    shape[behind] = (2.0 / math.pi) * np.arcsin(np.sqrt(2.0 * ay[behind] / (ay[behind] - x[behind])))
    return -(1.0 - contact_fraction) * shape, contact_fraction * shape


def contact_conduction_depth(x: np.ndarray, z: np.ndarray, a: float, contact_fraction: float, speed_wheel: float,
                             speed_rail: float, diffusivity_wheel: float, diffusivity_rail: float
                             ) -> tuple[np.ndarray, np.ndarray]:
    """Depth profile of the warm-wheel conduction in the centre strip, per unit excess temperature.

    Inside the patch (|x| <= a) the surface is held at the interface temperature for the time
    t = (a - x)/v since entry, so (Carslaw & Jaeger §2.5)
    wheel: ``-(1 - eps_c) erfc(z / (2 sqrt(kappa_w t_w)))``, rail: ``eps_c erfc(z / (2 sqrt(kappa_r t_r)))``.

    Parameters
    ----------
    x : ndarray, shape (nx,)
        Points of the centre strip, all within [-a, a] [m].
    z : ndarray, shape (nz,)
        Depths [m].
    a : float
        Semi-axis [m].
    contact_fraction : float
        eps_c [1].
    speed_wheel, speed_rail : float
        [m/s].
    diffusivity_wheel, diffusivity_rail : float
        kappa [m^2/s].

    Returns
    -------
    wheel, rail : ndarray, shape (nx, nz)
        Temperature change per kelvin of (wheel bulk - rail bulk) [1].
    """
    from scipy.special import erfc

    x = np.asarray(x, float)[:, None]
    z = np.asarray(z, float)[None, :]
    out = []
    for v, k in ((speed_wheel, diffusivity_wheel), (speed_rail, diffusivity_rail)):
        t = np.clip(a - x, 0.0, None) / v
        with np.errstate(divide="ignore", invalid="ignore"):
            arg = np.where(t > 0, z / (2.0 * np.sqrt(k * t)), np.where(z > 0, np.inf, 0.0))
        out.append(erfc(arg))
    return -(1.0 - contact_fraction) * out[0], contact_fraction * out[1]
