"""The contact reference point of a wheel-rail patch as the CONTACT program places it: the centre of gravity of
the interpenetration region, each point weighted by the square of its interpenetration, at the normal solution's
approach (CONTACT's ``compute_wgt_center_1d`` with its default squared weights; the same weights average the rail's
inclination into its contact angle, ``set_cpatch_reference``) [1, 2]. Along rolling the weight of a lateral slice of
the gap is integrated exactly (:func:`interpenetration_weights`); across, the section's uniform samples are summed.

References
----------
.. [1] E. A. H. Vollebregt, Detailed wheel/rail geometry processing using the planar contact approach, Vehicle
   System Dynamics 60 (2022) 1253-1291 (the contact reference point). doi:10.1080/00423114.2020.1853180
.. [2] E. A. H. Vollebregt, CONTACT, module 1 (wheel-rail contact), source m_wr_locatecp.f90
   (``compute_wgt_center_1d``, ``set_cpatch_reference``), Apache-2.0 (no DOI).
"""
from __future__ import annotations

import numpy as np

__all__ = ["interpenetration_weights", "interpenetration_centre", "stretch_around"]


def stretch_around(inside: np.ndarray, i: int) -> tuple[int, int]:
    """First and last index of the run of True entries of the boolean array ``inside`` that holds index ``i``
    (a patch's own connected region of a sampled section; ``(i, i)`` when only ``inside[i]`` or none holds)."""
    lo = hi = int(i)
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    while hi < inside.size - 1 and inside[hi + 1]:
        hi += 1
    return lo, hi


def interpenetration_weights(section, approach: float) -> tuple[np.ndarray, np.ndarray]:
    """The lateral samples of a patch's interpenetration region and their squared-interpenetration weights.

    On the contact plane the undeformed gap is h(x, y) = h_lat(y) + k_x(y) (x - x_c(y))^2 / 2
    (:class:`railtherm.physics.contact_search.GapSection`). At the approach d the interpenetration is
    p = d - h where positive; along x it closes at |x - x_c| = t0 = sqrt(2 c / k_x), c = d - h_lat(y), so a slice
    weighs w(y) = int p^2 dx = 2 c^2 t0 - (2/3) k_x c t0^3 + (1/10) k_x^2 t0^5 = (16/15) c^(5/2) / sqrt(k_x / 2).
    The slices kept are the connected stretch around the plane's origin where c > 0 (the patch's own region, as
    CONTACT weighs each patch's). w vanishes like (y - y_edge)^(5/2) at the stretch's ends, so sums over uniform
    samples in y are accurate to O(dy^(7/2)).

    Parameters
    ----------
    section : GapSection
        The undeformed gap on the contact plane (``eta`` [m], ``h`` [m], ``kx`` [1/m], ``origin`` [m]).
    approach : float
        The normal approach d [m] of the two bodies beyond the gap's zero (> 0 where the gap is zero at the
        plane's origin).

    Returns
    -------
    eta : ndarray
        Lateral positions [m] on the plane of the connected stretch around the origin where d > h_lat.
    weights : ndarray
        w(eta) = int (d - h)^2 dx [m^3] of each sample.

    Raises
    ------
    ValueError
        ``approach`` does not reach the gap at the sample nearest the origin (no interpenetration there).
    """
    eta = np.asarray(section.eta, dtype=float)
    c = float(approach) - (np.asarray(section.h, dtype=float) - float(section.origin))
    i = int(np.argmin(np.abs(eta)))
    if not c[i] > 0.0:
        raise ValueError(f"approach = {approach!r} m does not reach the gap at the plane's origin "
                         f"(gap {c[i] - approach:.3g} m there): no interpenetration")
    lo, hi = stretch_around(c > 0.0, i)
    c, kx = c[lo:hi + 1], np.asarray(section.kx, dtype=float)[lo:hi + 1]
    return eta[lo:hi + 1], 16.0 / 15.0 * c ** 2.5 / np.sqrt(0.5 * kx)


def interpenetration_centre(section, approach: float) -> float:
    """The lateral position [m] on the contact plane of the interpenetration's centre of gravity, weighted by
    the squared interpenetration (:func:`interpenetration_weights`; module docstring).

    Parameters
    ----------
    section : GapSection
        The undeformed gap on the contact plane.
    approach : float
        The normal approach [m].
    """
    eta, w = interpenetration_weights(section, approach)
    return float(w @ eta / w.sum())
