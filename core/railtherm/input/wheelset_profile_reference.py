"""The reference point of a profile wheelset's patch, where a result reports its position on the rail, its contact
angle and its creepages (the wheel's rigid slip there): the contact search's (:func:`reference_point`, the middle
of the stretch below half the Hertz-equivalent approach; Hertz-based chains) or the CONTACT program's at a normal
solution's approach (:func:`contact_reference`, the interpenetration's centre of gravity weighted by its square,
:mod:`railtherm.physics.contact_reference`; kalker). Both go through :func:`reference_at`, the rail's point and the
rigid slip at a given offset across the contact plane.

References
----------
.. [1] E. A. H. Vollebregt, Detailed wheel/rail geometry processing using the planar contact approach, Vehicle
   System Dynamics 60 (2022) 1253-1291. doi:10.1080/00423114.2020.1853180
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.contact_reference import interpenetration_weights, stretch_around
from ..physics.contact_search import _rotation

__all__ = ["reference_point", "reference_at", "contact_reference", "SEARCH_REFERENCE", "CONTACT_REFERENCE",
           "SECTION_HALF_WIDTH", "REFERENCE_FRACTION"]

#: half-width [m] of the lateral section the contact search samples the gap on
SECTION_HALF_WIDTH = 12e-3

#: the reference point is the middle of the interpenetration region at this fraction of the approach
REFERENCE_FRACTION = 0.5
#: how a result's patch reference point, contact angle and creepages were found (result attribute
#: ``wheelset_reference_point``): the contact search's (Hertz-based chains), or the CONTACT program's from the
#: normal solution of the sampled gap (kalker; ProfileContact.reported_reference)
SEARCH_REFERENCE = ("the contact search's: the middle of the stretch across rolling where the undeformed gap stays "
                    "below half the Hertz-equivalent approach; contact angle the rail's there")
CONTACT_REFERENCE = ("the CONTACT program's: the centre of gravity of the interpenetration of the sampled gap at the "
                     "normal solution's approach, weighted by the squared interpenetration; contact angle the same "
                     "weighted mean of the rail's inclination")


def _below(y, g, level) -> tuple[int, int]:
    """First and last index of the stretch around y = 0 where g < level (the patch's own interpenetration)."""
    return stretch_around(np.asarray(g) < level, int(np.argmin(np.abs(y))))


def reference_point(geo, p, approach: float, speed: float) -> dict:
    """The patch's reference point and contact plane, as the planar contact approach takes them.

    The gap is solved on the plane at the gap minimum (``p``); the reported contact point is the middle
    of the stretch across rolling where the undeformed gap h(0, y) stays below :data:`REFERENCE_FRACTION`
    (1/2) of the Hertz-equivalent ``approach`` [m] (Hertz's contact area is the interpenetration region at
    half the approach), and the contact angle the rail's there: A-2.2 position 1 right, two gap minima 11 mm
    apart in one patch, -8.644 mm and -0.0288 rad against CONTACT's -8.66 mm and -0.029 rad (the centroid of
    the interpenetration at the whole approach gave -9.86 mm). The spin creepage is the
    wheelset's angular velocity along that plane's normal. The scene's longitudinal and lateral creepages
    (``creepage``) are the rigid slip at the plane's origin (the minimum), so that kalker's slip field
    (xi - phi y, eta + phi x) is the wheel's rigid slip at every point of the plane; the reported ones
    (``creepage_reference``, :attr:`ProfileContact.reference_creepage`) are that field at the reference
    point, y = ``offset`` on the plane, where CONTACT reports its creepages. Where the gap has one clear
    minimum the reference point is the minimum itself; where a second nearly touching minimum lies inside
    the patch (a two-point geometry) the plane and the spin are those of the patch's middle, as CONTACT
    reports them.

    Returns
    -------
    dict
        ``y_rail``, ``z_rail`` [m] (rail profile's own coordinates), ``angle`` [rad], ``creepage`` (at the
        plane's origin) and ``creepage_reference`` (at the reference point) [1, 1, 1/m], ``offset`` [m] (the
        reference point across the plane from its origin), ``arm`` [m] and ``axle`` (wheel axes, z down).
    """
    y = np.linspace(-SECTION_HALF_WIDTH, SECTION_HALF_WIDTH, 2401)
    lo, hi = _below(y, p.gap(0.0, y) - p.gap(0.0, 0.0), REFERENCE_FRACTION * approach)
    return reference_at(geo, p, 0.5 * float(y[lo] + y[hi]), speed)


def reference_at(geo, p, eta: float, speed: float, angle: float | None = None) -> dict:
    """The reference point ``eta`` [m] across search patch ``p``'s contact plane from its origin: the rail's
    point there (the plane's point at ``eta`` projected onto the rail along the vertical, in the inclined rail's
    coordinates), the contact angle ``angle`` [rad] (None: the rail's inclination there) and the wheel's rigid
    slip at that point in the plane of that angle (the keys of :func:`reference_point`)."""
    b = float(geo.rail_inclination)
    rail = geo.rail_profile.rotated(b) if b else geo.rail_profile
    cb, sb = math.cos(b), math.sin(b)
    y_inc = cb * p.y_rail + sb * p.z_rail + eta * math.cos(p.contact_angle)
    z_inc, slope, _ = (float(v) for v in rail.at_y(y_inc))
    angle = math.atan(slope) if angle is None else float(angle)
    y0_inc = cb * p.y_rail + sb * p.z_rail
    z0_inc = -sb * p.y_rail + cb * p.z_rail
    sign = 1.0 if geo.side == "right" else -1.0
    rot = _rotation(sign * float(geo.roll_angle), sign * float(geo.yaw_angle))
    w_axle = float(geo.pitch_velocity) * rot[:, 1]
    # the rigid slip of the wheel at the reference point on the (undeformed) rail surface
    arm = np.array([p.x, p.y_track - sign * float(geo.lateral_shift), p.rolling_radius])
    axle = rot[:, 1]
    for _ in range(4):   # the wheel's contact point: its distance from the axle is the rolling radius
        d = arm - (arm @ axle) * axle
        arm[2] += (p.rolling_radius - math.sqrt(d @ d)) * math.sqrt(d @ d) / d[2]
    arm = arm + np.array([0.0, y_inc - y0_inc, z_inc - z0_inc])
    v = np.array([speed, 0.0, 0.0]) + np.cross(w_axle, arm)
    ca, sa = math.cos(angle), math.sin(angle)
    phi = float(w_axle[1] * -sa + w_axle[2] * ca) / speed
    xi_ref, eta_ref = float(v[0]) / speed, float(v[1] * ca + v[2] * sa) / speed
    # kalker's slip field (xi - phi y, eta + phi x) on the plane through the minimum equals it there
    return {"y_rail": cb * y_inc - sb * z_inc, "z_rail": sb * y_inc + cb * z_inc, "angle": angle,
            "creepage": (xi_ref + phi * eta, eta_ref, phi), "creepage_reference": (xi_ref, eta_ref, phi),
            "offset": eta,
            "arm": tuple(float(v) for v in arm), "axle": tuple(float(v) for v in axle)}


def contact_reference(geo, p, speed: float, section, approach: float) -> dict:
    """The CONTACT program's reference point of search patch ``p`` at the normal approach ``approach`` [m] of a
    solution of its sampled gap ``section`` (zero at the plane's origin): the interpenetration's centre of
    gravity weighted by the squared interpenetration
    (:func:`railtherm.physics.contact_reference.interpenetration_weights`), the contact angle the same weighted
    mean of the rail's inclination (CONTACT's ``set_cpatch_reference``), and the wheel's rigid slip there in
    that angle's plane (:func:`reference_at`; the keys of :func:`reference_point`)."""
    eta, w = interpenetration_weights(section, approach)
    b = float(geo.rail_inclination)
    rail = geo.rail_profile.rotated(b) if b else geo.rail_profile
    y_inc = math.cos(b) * p.y_rail + math.sin(b) * p.z_rail + eta * math.cos(p.contact_angle)
    inclination = np.arctan(np.asarray(rail.at_y(y_inc)[1], dtype=float))
    return reference_at(geo, p, float(w @ eta / w.sum()), speed, angle=float(w @ inclination / w.sum()))
