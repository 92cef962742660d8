"""Contact search between a wheel and a rail profile for a wheelset on a track (undeformed geometry).

Track axes: x along the track in the direction of travel, y lateral towards the right rail, z downwards. Each
wheel is computed in its own axes, the left wheel's being the track's mirrored y -> -y (lateral shift, roll and yaw
change sign, the pitch velocity does not), so both see the profiles as given (flange and gauge face at negative y,
:mod:`railtherm.physics.profiles`). The search follows the "contact locus" [1] (:func:`contact_search`); each
:class:`Patch` carries its contact points, angle, rolling radius, curvatures, creepages and undeformed gap.

References
----------
.. [1] E. A. H. Vollebregt, Detailed wheel/rail geometry processing using the planar contact approach, Vehicle
   System Dynamics 60 (2022) 1253-1291 (contact locus, creepages, CONTACT's module 1). doi:10.1080/00423114.2020.1853180
.. [2] E. A. H. Vollebregt, User guide for CONTACT, Technical report TR09-03, Vtech CMCC (module 1; no DOI).
.. [3] P. Shackleton, S. Iwnicki, Vehicle System Dynamics 46 (2008) 3-28 (the Manchester Contact Benchmark).
   doi:10.1080/00423110701245083
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .profiles import Profile, ProfileError

__all__ = ["WheelsetOnTrack", "Patch", "GapSection", "WheelContact", "contact_search", "rail_placement",
           "MAX_SEPARATION", "MAX_PATCHES"]

#: largest vertical distance [m] of a secondary gap minimum above the smallest for it to be a patch
MAX_SEPARATION = 0.2e-3
#: largest number of patches per wheel
MAX_PATCHES = 3
#: arc-length spacing [m] of the wheel and rail tables the search runs on
WHEEL_SPACING, RAIL_SPACING = 0.05e-3, 0.02e-3


@dataclass(frozen=True, eq=False)
class WheelsetOnTrack:
    """A wheelset's profiles, track and position (the ``[scene.wheelset]`` keys, SI units).

    Placement: the rail profile is inclined by ``rail_inclination`` towards the track centre
    (:meth:`Profile.rotated`), its top (smallest z) put at z = 0, and shifted laterally so that its gauge point
    (the innermost point at ``gauge_height`` below the top) lies at y = gauge / 2 (:func:`rail_placement`). The
    wheel profile is a surface of revolution about the axle with radius r(s) = R0 + z_w(s) at wheel-profile
    position s; its flange back (s = ``flange_back_position``) lies ``flange_back_distance / 2`` from the
    wheelset centre. The wheelset is rotated by R = Rz(yaw) Rx(roll) about its centre.

    Parameters
    ----------
    wheel_profile, rail_profile : Profile
        Right-side profiles (flange, gauge face at negative y), z downwards.
    rail_inclination : float
        Inclination of the rails towards the track centre [rad] (0 when the rail profile already is).
    gauge : float
        Distance between the rails' gauge points [m].
    gauge_height : float
        Depth of the gauge points below the rail top [m].
    flange_back_distance : float
        Distance between the two wheels' flange backs [m].
    flange_back_position : float
        Lateral position of the flange back in wheel-profile coordinates [m].
    nominal_radius : float
        Wheel radius at the wheel profile's origin [m].
    lateral_shift : float
        Wheelset lateral displacement, towards the right rail positive [m].
    yaw_angle : float
        Wheelset yaw about the downward vertical [rad].
    roll_angle : float
        Wheelset roll about the track's x axis [rad] (positive: right wheel down).
    pitch_velocity : float or None
        Wheelset angular velocity about its axle [rad/s] (negative when rolling forwards); None: no
        creepages.
    """

    wheel_profile: Profile
    rail_profile: Profile
    rail_inclination: float = 0.0
    gauge: float = 1.435
    gauge_height: float = 0.014
    flange_back_distance: float = 1.360
    flange_back_position: float = -0.070
    nominal_radius: float = 0.46
    lateral_shift: float = 0.0
    yaw_angle: float = 0.0
    roll_angle: float = 0.0
    pitch_velocity: float | None = None


@dataclass(frozen=True, eq=False)
class GapSection:
    """The undeformed gap on a patch's contact plane as the contact search samples it (:meth:`Patch.gap`).

    h(x, y) = h_lat(y) + k_x(y) (x - x_c(y))^2 / 2 - ``origin``, interpolated linearly in y between the samples:
    the lateral section's normal distance between rail and wheel, plus the wheel's drop along x (each slice's own
    curvature along rolling and locus offset); outside the sampled stretch of y it is +inf.

    Attributes
    ----------
    eta : ndarray
        Lateral sample positions on the contact plane, increasing [m].
    h : ndarray
        Normal distance between the two profiles at ``eta`` [m].
    xc : ndarray
        Longitudinal offset of the wheel's slice at ``eta`` (the contact locus) [m].
    kx : ndarray
        The wheel slice's curvature along rolling, cos(alpha) / r [1/m].
    origin : float
        Subtracted from every value [m] (0: the distances as sampled).
    """

    eta: np.ndarray
    h: np.ndarray
    xc: np.ndarray
    kx: np.ndarray
    origin: float = 0.0

    def __call__(self, x, y) -> np.ndarray:
        """h(x, y) [m] at points x (rolling) and y (lateral) on the plane [m]."""
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        inside = (y >= self.eta[0]) & (y <= self.eta[-1])
        lat = np.interp(y, self.eta, self.h)
        xc = np.interp(y, self.eta, self.xc)
        k = np.interp(y, self.eta, self.kx)
        return np.where(inside, lat + 0.5 * k * (x - xc) ** 2 - self.origin, np.inf)


@dataclass(frozen=True, eq=False)
class Patch:
    """One contact patch of a wheel found by :func:`contact_search` (in the wheel's own axes).

    The contact point on the rail is given in the rail profile's own coordinates (as CONTACT reports ``ycp_r``),
    the curvatures as vehicle-dynamics codes take them for the Hertz-equivalent ellipse's A, B, and the
    undeformed gap on the contact plane (:meth:`gap`) for a non-Hertzian normal solver.

    Creepages follow railtherm's convention (the wheel is body 1; slip of the wheel relative to the rail per
    unit rolling distance): longitudinal xi = v . e_x / V, lateral eta = v . e_y / V, spin phi = omega . n / V
    [1/m], with v the velocity of the wheel material at the contact point, omega the wheelset's angular velocity
    (pitch velocity about the axle), e_y the lateral direction in the contact plane towards the field side and
    n = e_x x e_y the normal into the rail. CONTACT reports the rail relative to the wheel: its creepages are
    minus these; and it reports the left wheel along the track's y, so there its lateral position, contact
    angle, lateral creepage and spin change sign once more (see the tests against its A-2.2 results).

    Attributes
    ----------
    y_rail, z_rail : float
        Contact point on the rail in the rail profile's own coordinates [m].
    y_wheel, z_wheel : float
        Contact point on the wheel in wheel-profile coordinates [m].
    x : float
        Longitudinal position of the contact point relative to the wheelset centre [m] (yaw moves it).
    y_track, z_track : float
        Lateral and vertical position of the contact point on the rail in the wheel's axes [m] (z
        downwards from the rail top).
    contact_angle : float
        Angle of the contact plane about x [rad]: atan(dz/dy) of the rail at the contact point.
    rolling_radius : float
        Distance of the contact point from the axle [m].
    separation : float
        Vertical distance [m] of this patch's gap minimum above the wheel's smallest (0 for the first).
    curvature_wheel_x, curvature_wheel_y, curvature_rail_y : float
        Curvatures [1/m], convex positive: the wheel's along rolling (cos(alpha) / r) and across, the
        rail's across (the rail is straight along x).
    creepage : tuple of float or None
        (longitudinal [1], lateral [1], spin [1/m]) in railtherm's convention (above).
    """

    index: int
    y_rail: float
    z_rail: float
    y_wheel: float
    z_wheel: float
    x: float
    y_track: float
    z_track: float
    contact_angle: float
    rolling_radius: float
    separation: float
    curvature_wheel_x: float
    curvature_wheel_y: float
    curvature_rail_y: float
    creepage: tuple[float, float, float] | None
    _section_of: object = field(repr=False, default=None)
    _section_cache: dict = field(repr=False, default_factory=dict)

    @property
    def hertz_curvatures(self) -> tuple[float, float]:
        """(A, B) [1/m] of the Hertz-equivalent gap h = A x^2 + B y^2 (the scene's ``contact.curvatures``):
        half the sums of the two bodies' curvatures along and across rolling. B <= 0 (a conformal
        flange root) has no Hertz ellipse."""
        return 0.5 * self.curvature_wheel_x, 0.5 * (self.curvature_wheel_y + self.curvature_rail_y)

    def gap(self, x, y) -> np.ndarray:
        """Undeformed normal gap [m] between wheel and rail on this patch's contact plane.

        Parameters
        ----------
        x : array_like
            Rolling-direction coordinate from the contact point [m].
        y : array_like
            Lateral coordinate in the contact plane from the contact point, towards the field side [m]
            (within the sampled section, about +-12 mm; outside it the gap is +inf).

        Returns
        -------
        ndarray
            h(x, y) [m]: the lateral section's normal distance plus the wheel's drop along x,
            (x - x_c(y))^2 cos(alpha) / (2 r) with x_c the locus offset; h(0, 0) = the patch's
            separation along its normal. The wheel's curvature along x is each slice's own radius's, and
            the locus offset x_c is first order in the yaw angle (the only small-angle approximation: the
            search itself has none).
        """
        return self.section()(x, y)

    def section(self, half_width: float | None = None) -> GapSection:
        """The sampled gap of :meth:`gap` as a :class:`GapSection` (``origin`` 0), over the search's section
        (sampled on first use: the search itself does not need it) or, with ``half_width`` [m], over
        |y| <= half_width (sampled anew)."""
        if half_width is not None:
            s = self._section_of(half_width=float(half_width))
        else:
            if not self._section_cache:
                self._section_cache.update(self._section_of())
            s = self._section_cache
        return GapSection(s["eta"], s["h"], s["xc"], s["kx"])

    def gap_coefficients(self, half_x: float, half_y: float, degree: int = 6, step: float = 0.1e-3):
        """A polynomial fit of the gap for the scene's ``contact = {shape = "gap", coefficients = ...}``.

        h(x, y) - h(0, 0) ~ sum c_ij x^i y^j over i <= 2, 2 <= i + j <= ``degree`` (no constant or
        linear term: the patch's own minimum is at the origin; h(0, 0) is :attr:`separation` along the
        normal, which a multi-patch solver adds itself), least squares on a grid of ``step`` [m] over
        |x| <= half_x, |y| <= half_y [m].

        Returns
        -------
        coefficients : dict
            ``{"x2": ..., "x1y1": ..., "y2": ..., ...}`` [m^(1 - i - j)], SI.
        residual : float
            Largest |fit - gap| on the grid [m].
        """
        x = np.arange(-half_x, half_x + 0.5 * step, step)
        y = np.arange(-half_y, half_y + 0.5 * step, step)
        X, Y = (a.ravel() for a in np.meshgrid(x, y))
        h = self.gap(X, Y) - self.gap(0.0, 0.0)
        ok = np.isfinite(h)
        terms = [(i, j) for i in range(3) for j in range(degree + 1) if 2 <= i + j <= degree]
        A = np.stack([X[ok] ** i * Y[ok] ** j for i, j in terms], 1)
        scale = np.abs(A).max(0)
        c = np.linalg.lstsq(A / scale, h[ok], rcond=None)[0] / scale
        names = [("" if i == 0 else f"x{i}") + ("" if j == 0 else f"y{j}") for i, j in terms]
        return dict(zip(names, (float(v) for v in c))), float(np.abs(A @ c - h[ok]).max())

    def gap_grid(self, dx: float, dy: float, half_x: float, half_y: float):
        """The gap on a grid of element centres, for a non-Hertzian normal solver.

        Parameters
        ----------
        dx, dy : float
            Element sizes [m] along rolling and across.
        half_x, half_y : float
            Half-extents of the grid [m].

        Returns
        -------
        x, y : ndarray
            Element-centre coordinates [m] (1-D).
        h : ndarray
            Gap [m], shape (len(y), len(x)).
        """
        nx, ny = max(int(round(half_x / dx)), 1), max(int(round(half_y / dy)), 1)
        x = (np.arange(-nx, nx) + 0.5) * dx
        y = (np.arange(-ny, ny) + 0.5) * dy
        return x, y, self.gap(x[None, :], y[:, None])


@dataclass(frozen=True)
class WheelContact:
    """All patches of one wheel, first the closest (``separation`` 0); ``gap`` [m] is the closest one's
    vertical distance to the rail with the wheelset centre at its nominal height (z = -nominal_radius, z down):
    how far the wheel must move down to touch."""

    side: str
    patches: tuple[Patch, ...]
    rail_offset: float
    wheel_offset: float
    gap: float = 0.0


# -- tables -----------------------------------------------------------------------------------------
@functools.lru_cache(maxsize=16)
def _rail_table(rail: Profile, inclination: float, spacing: float):
    placed = rail.rotated(inclination) if inclination else rail
    t, y, z, slope, curv = placed.sample(spacing)
    return placed, t, y, z, slope, curv


@functools.lru_cache(maxsize=16)
def _wheel_table(wheel: Profile, spacing: float):
    return wheel.sample(spacing)


def rail_placement(rail: Profile, inclination: float, gauge: float, gauge_height: float,
                   spacing: float = RAIL_SPACING) -> tuple[float, float]:
    """Lateral offset and top of a rail on the track.

    Parameters
    ----------
    rail : Profile
        Right-side rail profile.
    inclination : float
        Rail inclination towards the track centre [rad].
    gauge, gauge_height : float
        Track gauge [m] and the depth below the rail top where it is measured [m].
    spacing : float
        Table spacing [m].

    Returns
    -------
    offset : float
        Track y of the (inclined) rail profile's origin [m].
    top : float
        z of the rail top in the inclined profile's coordinates [m] (the track's z = 0).
    """
    _, _, y, z, _, _ = _rail_table(rail, float(inclination), spacing)
    top = float(z.min())
    below = np.nonzero(z <= top + gauge_height)[0]
    i = int(below[0])
    if i == 0:
        raise ProfileError(f"profile {rail.name}: the rail's gauge side does not reach {gauge_height * 1e3:g} mm "
                           "below its top, so the gauge point is undefined")
    f = (top + gauge_height - z[i - 1]) / (z[i] - z[i - 1])
    y_gauge = y[i - 1] + f * (y[i] - y[i - 1])
    return 0.5 * gauge - float(y_gauge), top


def _rotation(roll: float, yaw: float) -> np.ndarray:
    cf, sf, cp, sp = np.cos(roll), np.sin(roll), np.cos(yaw), np.sin(yaw)
    rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cf, -sf], [0.0, sf, cf]])
    return rz @ rx


def _locus(r, dr, y_axle, rot, shift, z_centre):
    """Track coordinates of the wheel points whose normal has no x component (one per profile slice).

    With R = Rz(yaw) Rx(roll) and the wheel point (r sin th, y_axle, r cos th), the normal
    (sin th, -r', cos th) has x component A sin th + B + C cos th = 0 with A = R00, B = -R01 r',
    C = R02; th = asin(-B / sqrt(A^2 + C^2)) - atan2(C, A) is the branch on the lower half.
    """
    a, c = rot[0, 0], rot[0, 2]
    b = -rot[0, 1] * dr
    th = np.arcsin(np.clip(-b / np.hypot(a, c), -1.0, 1.0)) - np.arctan2(c, a)
    px, pz = r * np.sin(th), r * np.cos(th)
    x = rot[0, 0] * px + rot[0, 1] * y_axle + rot[0, 2] * pz
    y = rot[1, 0] * px + rot[1, 1] * y_axle + rot[1, 2] * pz + shift
    z = rot[2, 0] * px + rot[2, 1] * y_axle + rot[2, 2] * pz + z_centre
    return x, y, z


def _minima(g: np.ndarray, max_separation: float, max_patches: int) -> list[int]:
    """Indices of the gap's local minima within ``max_separation`` of the smallest, distinct patches."""
    gi = g[1:-1]
    cand = np.nonzero((gi <= g[:-2]) & (gi < g[2:]))[0] + 1
    cand = cand[g[cand] - g[cand].min() <= max_separation] if cand.size else cand
    chosen: list[int] = []
    for i in cand[np.argsort(g[cand])]:
        # a separate patch only where the gap rises between it and every chosen one
        if all(g[min(i, j):max(i, j) + 1].max() - g[i] > 1e-6 for j in chosen):
            chosen.append(int(i))
        if len(chosen) == max_patches:
            break
    return chosen


def contact_search(ws: WheelsetOnTrack, side: str = "right", speed: float | None = None,
                   max_separation: float = MAX_SEPARATION, max_patches: int = MAX_PATCHES,
                   wheel_spacing: float = WHEEL_SPACING, rail_spacing: float = RAIL_SPACING,
                   section_half_width: float = 12e-3) -> WheelContact:
    """The contact patches of one wheel of a wheelset on the undeformed profiles.

    The rail is prismatic along x, so at a contact the wheel's surface normal has no x component. For every
    wheel-profile position s that condition fixes the angle theta(s) on the wheel circle in closed form (the
    contact locus), exactly for any yaw and roll. The vertical gap g(s) = z_rail(y(s)) - z(s) between the locus
    and the rail has its local minima where the two profiles' slopes match; every minimum within
    ``max_separation`` of the smallest (up to ``max_patches``) is a patch, refined by parabolas through the
    smooth gap (the profiles' splines) at shrinking steps.

    Parameters
    ----------
    ws : WheelsetOnTrack
        Profiles, track and wheelset position.
    side : {"right", "left"}
        The wheel; results in that wheel's own axes (module docstring: the left wheel's mirror y).
    speed : float, optional
        Forward speed V [m/s] of the wheelset; with ``ws.pitch_velocity`` it gives the creepages.
    max_separation : float
        Largest vertical distance [m] of a secondary gap minimum above the smallest.
    max_patches : int
        Largest number of patches.
    wheel_spacing, rail_spacing : float
        Arc-length spacing [m] of the tables the search runs on.
    section_half_width : float
        Half-width [m] of the lateral section sampled for :meth:`Patch.gap`.

    Returns
    -------
    WheelContact
        The patches, closest first.

    Raises
    ------
    ProfileError
        The closest approach lies at the end of the wheel or rail profile (the wheel runs off it).
    """
    if side not in ("right", "left"):
        raise ValueError(f"side = {side!r} is not allowed: 'right' or 'left'")
    sign = 1.0 if side == "right" else -1.0
    placed, t_r, y_r, z_r, slope_r, curv_r = _rail_table(ws.rail_profile, float(ws.rail_inclination), rail_spacing)
    offset, top = rail_placement(ws.rail_profile, float(ws.rail_inclination), ws.gauge, ws.gauge_height, rail_spacing)
    t_w, s_w, z_w, slope_w, curv_w = _wheel_table(ws.wheel_profile, wheel_spacing)
    R0 = float(ws.nominal_radius)
    wheel_offset = 0.5 * ws.flange_back_distance - ws.flange_back_position
    rot = _rotation(sign * ws.roll_angle, sign * ws.yaw_angle)
    shift, zc = sign * ws.lateral_shift, -R0
    r = R0 + z_w
    x, y, z = _locus(r, slope_w, wheel_offset + s_w, rot, shift, zc)
    yr = y - offset                     # in the inclined rail profile's coordinates
    on = (yr >= y_r[0]) & (yr <= y_r[-1])
    g = np.where(on, np.interp(yr, y_r, z_r) - top - z, np.inf)
    if not np.isfinite(g).any():
        raise ProfileError(f"side {side}: the wheel profile {ws.wheel_profile.name} does not overlap the rail "
                           f"{ws.rail_profile.name} laterally (lateral_shift = {ws.lateral_shift!r} m)")
    i0 = int(np.argmin(g))
    if i0 in (0, g.size - 1) or not (np.isfinite(g[i0 - 1]) and np.isfinite(g[i0 + 1])):
        where = f"wheel y = {s_w[i0] * 1e3:.2f} mm, rail y = {yr[i0] * 1e3:.2f} mm"
        raise ProfileError(f"side {side}: the closest approach lies at the end of a profile ({where}): the "
                           f"wheel runs off the rail (lateral_shift = {ws.lateral_shift!r} m)")
    frame = (ws, placed, rot, shift, zc, wheel_offset, offset, top)
    found = sorted((_refine(frame, t_w, g, i, wheel_spacing) for i in _minima(g, max_separation, max_patches)),
                   key=lambda tg: tg[1])
    g0 = found[0][1]
    patches = [_patch(k, t, gk - g0, g0, frame, sign, speed, section_half_width)
               for k, (t, gk) in enumerate(found) if gk - g0 <= max_separation]
    return WheelContact(side=side, patches=tuple(patches), rail_offset=offset, wheel_offset=wheel_offset,
                        gap=float(g0))


def _gap_at(frame, t) -> np.ndarray:
    """Vertical gap [m] between the wheel's locus and the rail at wheel arc lengths ``t`` (smooth)."""
    ws, placed, rot, shift, zc, wheel_offset, offset, top = frame
    s, zw, dzw, _ = ws.wheel_profile.at_arc(t)
    _, y, z = _locus(float(ws.nominal_radius) + zw, dzw, wheel_offset + s, rot, shift, zc)
    return placed.z_at(y - offset) - top - z


def _refine(frame, t_w, g, i, spacing) -> tuple[float, float]:
    """Arc length and gap of the minimum near table index i: the tables' parabola, then two parabolas
    through the smooth gap at steps spacing/4 and spacing/100 (the position to well under 0.1 um)."""
    den = g[i - 1] - 2.0 * g[i] + g[i + 1]
    f = 0.5 * (g[i - 1] - g[i + 1]) / den if den > 0 else 0.0
    t = t_w[i] + f * (t_w[i + 1] - t_w[i])
    lo, hi = t_w[max(i - 1, 0)], t_w[min(i + 1, t_w.size - 1)]
    gt = None
    for h in (0.25 * spacing, 0.01 * spacing):
        t = min(max(t, lo + h), hi - h)
        gm, gt, gp = _gap_at(frame, np.array([t - h, t, t + h]))
        den = gm - 2.0 * gt + gp
        if den > 0:
            step = float(np.clip(0.5 * h * (gm - gp) / den, -h, h))
            t += step
            gt = gt - 0.25 * (gm - gp) * step / h   # the parabola's value at its vertex
    return float(t), float(gt)


def _patch(k, t, separation, g0, frame, sign, speed, half_width) -> Patch:
    """The patch's quantities at the refined wheel arc length t."""
    ws, placed, rot, shift, zc, wheel_offset, offset, top = frame
    s, zw, dzw, kw = (float(v) for v in ws.wheel_profile.at_arc(t))
    r = float(ws.nominal_radius) + zw
    x, y, z = (float(v) for v in _locus(np.array(r), np.array(dzw), wheel_offset + s, rot, shift, zc))
    yr_inc = y - offset
    z_rail_inc, slope, kr = (float(v) for v in placed.at_y(yr_inc))
    delta = float(np.arctan(slope))
    # the contact point in the rail profile's own (not inclined) coordinates
    b = float(ws.rail_inclination)
    cb, sb = np.cos(b), np.sin(b)
    y_own, z_own = cb * yr_inc - sb * z_rail_inc, sb * yr_inc + cb * z_rail_inc
    creep = None
    if speed is not None and ws.pitch_velocity is not None:
        creep = _creepages(float(speed), float(ws.pitch_velocity), rot, np.array([x, y - shift, z - zc]), delta)
    section = functools.partial(_section, frame, t, np.array([x, y, z_rail_inc - top]), delta,
                                half_width=half_width, g0=g0)
    alpha = np.arctan(dzw)
    return Patch(index=k, y_rail=float(y_own), z_rail=float(z_own), y_wheel=s, z_wheel=zw, x=x, y_track=y,
                 z_track=z_rail_inc - top, contact_angle=delta, rolling_radius=r, separation=float(separation),
                 curvature_wheel_x=float(np.cos(alpha) / r), curvature_wheel_y=-float(kw), curvature_rail_y=kr,
                 creepage=creep, _section_of=section)


def _creepages(V: float, omega: float, rot: np.ndarray, arm: np.ndarray, delta: float):
    """(xi, eta, phi) of the wheel relative to the rail at the contact point (railtherm's convention)."""
    if not V > 0:
        raise ValueError(f"speed = {V!r} is not allowed: a forward speed > 0 [m/s]")
    w = omega * rot[:, 1]                  # angular velocity about the (rolled, yawed) axle
    v = np.array([V, 0.0, 0.0]) + np.cross(w, arm)
    cd, sd = np.cos(delta), np.sin(delta)
    ey, n = np.array([0.0, cd, sd]), np.array([0.0, -sd, cd])
    return float(v[0] / V), float(v @ ey / V), float(w @ n / V)


def _section(frame, t0, p0, delta, half_width, g0) -> dict:
    """The lateral section of the gap on the contact plane around the patch, for :meth:`Patch.gap`.

    Rail and wheel locus points within +-1.5 half-widths of the contact point p0 (on the rail; its x
    from the locus), expressed in the plane's lateral coordinate eta and normal coordinate zeta (into
    the rail), the wheel lowered by g0 so that the wheel's closest approach touches; their zeta
    difference at equal eta is the lateral gap; each slice brings its x offset and curvature along x.
    """
    from scipy.interpolate import CubicSpline  # here: ~0.9 s to import, not needed without profiles
    ws, placed, rot, shift, zc, wheel_offset, offset, top = frame
    cd, sd = np.cos(delta), np.sin(delta)
    span = 1.5 * half_width
    wp = ws.wheel_profile
    tw = np.linspace(max(t0 - span, wp.arc_length[0]), min(t0 + span, wp.arc_length[-1]), 721)
    s, zw, dzw, _ = wp.at_arc(tw)
    r = float(ws.nominal_radius) + zw
    x, y, z = _locus(r, dzw, wheel_offset + s, rot, shift, zc)
    z = z + g0                  # the wheelset lowered onto the rail: its closest approach closes
    eta_w = (y - p0[1]) * cd + (z - p0[2]) * sd
    zeta_w = -(y - p0[1]) * sd + (z - p0[2]) * cd
    kx = np.cos(np.arctan(dzw)) / r
    yr0 = p0[1] - offset
    ys = np.linspace(yr0 - span, yr0 + span, 721)
    ys = ys[(ys >= placed.y[0]) & (ys <= placed.y[-1])]
    zr = placed.z_at(ys) - top
    eta_r = (ys + offset - p0[1]) * cd + (zr - p0[2]) * sd
    zeta_r = -(ys + offset - p0[1]) * sd + (zr - p0[2]) * cd
    # the curves turn back beyond +-90 deg from the contact plane (a flange seen from the tread): keep the
    # run of increasing eta through the contact point
    w, rr = _monotone_run(eta_w), _monotone_run(eta_r)
    eta_w, zeta_w, x, kx = eta_w[w], zeta_w[w], x[w], kx[w]
    eta_r, zeta_r = eta_r[rr], zeta_r[rr]
    lo = max(-half_width, eta_w.min(), eta_r.min())
    hi = min(half_width, eta_w.max(), eta_r.max())
    eta = np.linspace(lo, hi, 1921)
    h = CubicSpline(eta_r, zeta_r)(eta) - CubicSpline(eta_w, zeta_w)(eta)
    return {"eta": eta, "h": h, "xc": CubicSpline(eta_w, x)(eta) - p0[0], "kx": CubicSpline(eta_w, kx)(eta)}


def _monotone_run(eta: np.ndarray) -> slice:
    """The longest stretch of strictly increasing ``eta`` that contains the point nearest eta = 0."""
    i = int(np.argmin(np.abs(eta)))
    up = np.diff(eta) > 0
    a = i
    while a > 0 and up[a - 1]:
        a -= 1
    b = i
    while b < up.size and up[b]:
        b += 1
    return slice(a, b + 1)
