"""Heat partition between wheel and rail: Blok's equal-temperature fraction."""
from __future__ import annotations

import math

__all__ = ["equal_temperature_partition", "scene_partition"]


def equal_temperature_partition(wheel, rail, wheel_speed: float, rail_speed: float) -> float:
    """Fraction of the frictional heat entering the wheel so that both flash temperatures are equal.

    In the 1-D high-Péclet model (seed eqs. 32-33) a flux q_i into body i moving at v_i raises its
    surface by q_i / (beta_i sqrt(v_i)) times the same shape factor, so equal temperatures need
    ``eps = beta_w sqrt(v_w) / (beta_w sqrt(v_w) + beta_r sqrt(v_r))`` (seed eq. 38 with
    v_w = v0 + v_s, v_r = v0). This is Blok's partition for two bodies at high Péclet number; the
    two kernels differ only by ``1/(beta sqrt(v))``, so the same constant equalises the two surface
    temperatures at every point of the patch. It is also the interface fraction ``eps_c`` of a warm
    wheel against a cold rail (seed eq. 41).

    A surface that does not move through the patch (speed <= 0, e.g. a locked wheel) is treated as
    speed 0: it takes no heat in this model (the other body takes all of it); when neither moves the
    split is even (0.5). Nothing divides by zero.

    Parameters
    ----------
    wheel, rail : Material-like
        Bodies with ``effusivity`` beta = sqrt(lambda rho c) [W s^0.5 m^-2 K^-1].
    wheel_speed, rail_speed : float
        Speed of each surface relative to the contact [m/s].

    Returns
    -------
    float
        eps [1], fraction entering the wheel, in [0, 1].

    References
    ----------
    .. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation
       of temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
    .. [2] H. Blok, Theoretical study of temperature rise at surfaces of actual contact under oiliness
       lubricating conditions, Proc. Gen. Discussion on Lubrication, IMechE 2 (1937) 222-235.
    """
    gw = wheel.effusivity * math.sqrt(max(wheel_speed, 0.0))
    gr = rail.effusivity * math.sqrt(max(rail_speed, 0.0))
    if gw + gr == 0.0:
        return 0.5
    return gw / (gw + gr)


def scene_partition(scene, wheel_speed: float, rail_speed: float) -> float:
    """The scene's heat partition: its number, or the equal-temperature fraction.

    Parameters
    ----------
    scene : Scene-like
        With ``heat_partition`` (a number [1] or "equal-temperature"), ``wheel`` and ``rail``.
    wheel_speed, rail_speed : float
        Surface speeds through the patch [m/s] (:func:`railtherm.physics.body_speeds`).

    Returns
    -------
    float
        Fraction of the heat entering the wheel [1].
    """
    if isinstance(scene.heat_partition, str):
        return equal_temperature_partition(scene.wheel, scene.rail, wheel_speed, rail_speed)
    return float(scene.heat_partition)
