"""Warm wheel against cold rail: the surface and depth fields of the contact conduction (seed eqs. 41-44).

The long-term (steady) wheel temperature itself, Ertz & Knothe's lumped wheel (seed eqs. 40-54 in
their 3-D form, with the documented convective-area choice), is core's
:func:`railtherm.physics.lumped_wheel`; this module holds only the fields the "green" model draws
from it: after many revolutions the wheel is warm, at theta_w0 above the rail; in the patch both
surfaces take the interface temperature ``eps_c theta_w0`` (eq. 41, ``eps_c`` Blok's
equal-temperature fraction, :func:`railtherm.physics.equal_temperature_partition`) and behind it
they recover (eq. 44).

References
----------
.. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation of
   temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
.. [2] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, §2.5.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import erfc

__all__ = ["contact_conduction_surface", "contact_conduction_depth"]


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
    x = np.asarray(x, float)[:, None]
    z = np.asarray(z, float)[None, :]
    out = []
    for v, k in ((speed_wheel, diffusivity_wheel), (speed_rail, diffusivity_rail)):
        t = np.clip(a - x, 0.0, None) / v
        with np.errstate(divide="ignore", invalid="ignore"):
            arg = np.where(t > 0, z / (2.0 * np.sqrt(k * t)), np.where(z > 0, np.inf, 0.0))
        out.append(erfc(arg))
    return -(1.0 - contact_fraction) * out[0], contact_fraction * out[1]
