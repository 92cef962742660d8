"""A scene's contact from real wheel and rail profiles: the ``[scene.wheelset]`` profile keys turned into
the contact, load and creepages of one patch.

A scene whose ``wheelset`` table names profiles (``wheel_profile``, ``rail_profile``, ``nominal_radius``,
``vertical_force``, ...; see :data:`railtherm.input.profiles.WHEELSET_KEYS`) runs the contact search
(:func:`railtherm.physics.contact_search.contact_search`) when it is loaded, and the scene is then an
ordinary one in the existing vocabulary:

* ``contact = {shape = "gap", coefficients = ...}``: the patch's undeformed gap on its contact plane,
  a least-squares polynomial (terms up to y^8, x^2 y^6; the highest even degree that stays open out to
  :data:`FIT_CHECK` windows) over :data:`WINDOW` Hertz-equivalent semi-axes along x and, across, the
  stretch where the gap stays below the Hertz-equivalent approach (a nearly touching second minimum is
  inside it), so ``kalker`` solves the non-Hertzian patch. The fit's largest misfit in its window is
  :attr:`ProfileContact.gap_residual` (below 1 um at 38 of the 42 A-2.2 contacts, 1.4 - 5.5 um at
  positions 3, 4 and 11 right; 0.22 mm at position 2 right, where no even degree above 2 both fits and
  stays open, so that contact's gap is a poor quadratic and its kalker result is not to be trusted). Hertz-based chains get the Hertz-equivalent ellipse from the profiles' curvatures at the
  contact point (as vehicle-dynamics codes do) through the normal model ``wheelset-profile``
  (:mod:`railtherm.models.wheelset_profile`), which says so in its diagnostics.
* ``creepage``: the patch's creepages from the wheelset's motion (speed, yaw, roll, pitch velocity),
  railtherm's convention (wheel relative to rail; CONTACT's are minus these).
* ``normal_force``: from the wheel's ``vertical_force`` Fz. With one patch the wheel's vertical
  equilibrium is Fz = N cos(delta) - Fy sin(delta) (delta the contact angle, Fy the lateral creep force on
  the wheel in the contact plane): the lateral creep force carries part of the load on a steep flange
  (at Manchester position 13, 11 % of it). Fy is estimated here, before any contact model runs, with
  Kalker's linear theory on the Hertz-equivalent ellipse saturated by Shen, Hedrick and Elkins' rule
  [1]; N solves the equation with that estimate (:func:`normal_force_from_vertical`). The contact
  model's own Fy then differs from the estimate; :attr:`ProfileContact.normal_force` says which force
  was used and the result's attributes carry the estimate.

Limitations: one patch per scene (key ``wheelset.patch``, 1 = the closest); with several patches the
vertical force is not shared between them (each patch is given the whole ``vertical_force``), so a
scene with two patches of comparable separation is refused unless ``patch`` is given explicitly.
``roll_angle = "balance"`` and ``pitch_velocity = "free"`` are not solved here: such a scene is refused.

References
----------
.. [1] Z. Y. Shen, J. K. Hedrick, J. A. Elkins, A comparison of alternative creep force models for rail
   vehicle dynamic analysis, Vehicle System Dynamics 12 (1983) 79-83. doi:10.1080/00423118308968725
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from ..contract.errors import SceneError
from ..physics.contact_search import _rotation, contact_search
from ..physics.elastic import combined_elastic
from ..physics.profiles import ProfileError
from ..references.hertz import contact_modulus, hertz_from_curvatures
from ..references.kalker import kalker_linear_forces
from .profiles import CONICAL_ONLY_KEYS, wheelset_geometry_from_table

__all__ = ["ProfileContact", "NoContact", "NoContactError", "profile_contact", "normal_force_from_vertical", "WINDOW",
           "GAP_DEGREE"]

#: half-extents of the gap's fitting window, in Hertz-equivalent semi-axes (a along x, b across)
WINDOW = (1.6, 2.0)
#: half-width [m] of the lateral section the contact search samples the gap on
SECTION_HALF_WIDTH = 12e-3
#: how far (in fitting windows) the gap polynomial must stay open
FIT_CHECK = 1.5
#: degree of the gap polynomial in the lateral coordinate
GAP_DEGREE = 8
#: points of the rail profile a ProfileContact keeps for drawing (rail_section)
SECTION_POINTS = 400


@dataclass(frozen=True)
class ProfileContact:
    """One patch of a profile wheelset's wheel, as the scene uses it (SI units, the wheel's own axes).

    Attributes
    ----------
    side : str
        "right" or "left" (the left wheel's quantities are in its own mirrored axes).
    patch : int
        Which patch (1 = the closest) of ``patches`` found.
    patches : int
        Number of distinct elastic patches (gap minima within the first patch's approach are part of it).
    contact_position_rail, contact_height_rail : float
        Contact point on the rail in the rail profile's own coordinates [m].
    contact_angle : float
        Angle of the contact plane [rad].
    plane_position_rail, plane_angle : float
        Origin of the contact plane the gap is solved on (the gap minimum) on the rail, in the rail profile's
        own coordinates [m], and that plane's angle [rad]: a result's y across the plane lies at
        plane_position_rail + y cos(plane_angle) on the rail.
    rolling_radius : float
        [m].
    separation : float
        The patch's undeformed vertical distance above the closest one [m].
    hertz_curvatures : tuple of float
        (A, B) [1/m] of the Hertz-equivalent gap A x^2 + B y^2.
    gap_coefficients : dict
        The gap polynomial's coefficients, scene keys ``x<i>y<j>`` [m^(1-i-j)].
    gap_residual : float
        Largest misfit of the polynomial on its window [m].
    creepage : tuple of float
        (longitudinal [1], lateral [1], spin [1/m]), railtherm's convention.
    vertical_force : float
        The wheel's vertical force Fz [N].
    normal_force : float
        N [N] from Fz and the estimated lateral creep force.
    lateral_force_estimate : float
        The estimated lateral creep force on the wheel in the contact plane [N] that N used.
    rail_section : tuple of tuple of float
        (y, z) [m] of the rail profile in its own coordinates, at most :data:`SECTION_POINTS` of its points:
        what a reader of results (the report) draws the patches on without reading the profile file.
    """

    side: str
    patch: int
    patches: int
    contact_position_rail: float
    contact_height_rail: float
    contact_angle: float
    plane_position_rail: float
    plane_angle: float
    rolling_radius: float
    separation: float
    hertz_curvatures: tuple[float, float]
    gap_coefficients: dict
    gap_residual: float
    creepage: tuple[float, float, float]
    vertical_force: float
    normal_force: float
    lateral_force_estimate: float
    rail_section: tuple = field(default=((), ()), repr=False, compare=False)


class NoContactError(SceneError):
    """The wheel of a wheelset on profiles finds no contact: it does not reach the rail (lifted off), or its
    closest approach lies at a profile's end (it runs off the rail)."""


@dataclass(frozen=True)
class NoContact:
    """A wheelset on profiles whose wheel finds no contact: the scene loads (the study's other scenes run)
    and every run of it fails with :meth:`failure`, the error naming the scene and the key.

    Attributes
    ----------
    side : str
        "right" or "left".
    message, key : str
        The error's text and the key it names.
    value : object
        The value of that key.
    """

    side: str
    message: str
    key: str
    value: object = None
    patches: int = 0

    def failure(self) -> NoContactError:
        """The error a solve of the scene raises (a new instance each time)."""
        scene = self.message.split("'")[1] if self.message.startswith("scene '") else None
        return NoContactError(self.message, scene=scene, key=self.key, value=self.value)


def _rail_section(rail) -> tuple:
    """(y, z) [m] of at most SECTION_POINTS of a profile's points, its ends kept."""
    k = np.unique(np.linspace(0, rail.y.size - 1, min(SECTION_POINTS, rail.y.size)).round().astype(int))
    return tuple(float(v) for v in rail.y[k]), tuple(float(v) for v in rail.z[k])


def _saturated_lateral(a, b, G, nu, creepage, mu, N) -> float:
    """Lateral creep force on the wheel [N]: Kalker's linear theory, saturated (Shen-Hedrick-Elkins)."""
    fx, fy, _ = kalker_linear_forces(a, b, G, nu, *creepage)
    f = math.hypot(fx, fy)
    if f == 0.0 or mu * N == 0.0:
        return 0.0
    e = f / (mu * N)
    scale = (1.0 - e / 3.0 + e * e / 27.0) if e < 3.0 else 1.0 / e
    return fy * scale


def normal_force_from_vertical(vertical_force, angle, curvatures, e_star, G, nu, creepage, friction,
                               iterations: int = 30):
    """N [N] with Fz = N cos(delta) - Fy(N) sin(delta), Fy the saturated linear-theory estimate.

    Returns
    -------
    (normal_force, lateral_force) : tuple of float
        N [N] and the Fy [N] (on the wheel, in the contact plane) it balances with.
    """
    c, s = math.cos(angle), math.sin(angle)
    N, fy = vertical_force / c, 0.0
    for _ in range(iterations):
        h = hertz_from_curvatures(*curvatures, N, e_star)
        fy = _saturated_lateral(h.a, h.b, G, nu, creepage, friction, N)
        new = (vertical_force + fy * s) / c
        if abs(new - N) <= 1e-10 * vertical_force:
            N = new
            break
        N = new
    return N, fy


def _distinct_patches(patches, wheel, rail, vertical_force) -> list:
    """The patches that are elastic patches of their own: a gap minimum less than the first patch's
    Hertz-equivalent approach above it lies inside the first patch (its gap fit covers it)."""
    first = patches[0]
    A, B = first.hertz_curvatures
    if not (A > 0 and B > 0):
        return list(patches)
    h = hertz_from_curvatures(A, B, vertical_force / math.cos(first.contact_angle), contact_modulus(wheel, rail))
    return [first] + [q for q in patches[1:] if q.separation >= h.approach]


def _below(y, g, level) -> tuple[int, int]:
    """First and last index of the stretch around y = 0 where g < level (the patch's own interpenetration)."""
    lo = hi = int(np.argmin(np.abs(y)))
    while lo > 0 and g[lo - 1] < level:
        lo -= 1
    while hi < y.size - 1 and g[hi + 1] < level:
        hi += 1
    return lo, hi


def _lateral_window(p, h) -> float:
    """Half-width [m] of the gap fit across rolling: WINDOW[1] Hertz semi-axes b, widened to 1.2 times the
    reach of the stretch around the contact point where the undeformed gap stays below the Hertz-equivalent
    approach (a second, nearly touching minimum, as at Manchester position 1, lies in the elastic patch),
    at most the sampled section's reach."""
    y = np.linspace(-SECTION_HALF_WIDTH, SECTION_HALF_WIDTH, 2401)
    lo, hi = _below(y, p.gap(0.0, y) - p.gap(0.0, 0.0), h.approach)
    reach = max(-y[lo], y[hi])
    return float(min(max(WINDOW[1] * h.b, 1.2 * reach), 0.95 * SECTION_HALF_WIDTH))


def reference_point(geo, p, approach: float, speed: float) -> dict:
    """The patch's reference point and contact plane, as the planar contact approach takes them.

    The gap is solved on the plane at the gap minimum (``p``); the reported contact point is the
    centroid of the undeformed interpenetration (approach - h(0, y))+ across rolling at the
    Hertz-equivalent approach, and the contact angle the rail's there. The spin creepage is the
    wheelset's angular velocity along that plane's normal, and the longitudinal and lateral creepages
    are the rigid slip at the plane's origin (the minimum), so that kalker's slip field
    (xi - phi y, eta + phi x) is the wheel's rigid slip at every point of the plane. Where the gap has
    one clear minimum this is the minimum itself; where a second nearly touching minimum lies inside
    the patch (a two-point geometry) the plane and the spin are those of the patch's middle, as CONTACT
    reports them.

    Returns
    -------
    dict
        ``y_rail``, ``z_rail`` [m] (rail profile's own coordinates), ``angle`` [rad], ``creepage``.
    """
    y = np.linspace(-SECTION_HALF_WIDTH, SECTION_HALF_WIDTH, 2401)
    lo, hi = _below(y, p.gap(0.0, y) - p.gap(0.0, 0.0), approach)
    w = np.zeros_like(y)
    w[lo:hi + 1] = approach - (p.gap(0.0, y[lo:hi + 1]) - p.gap(0.0, 0.0))
    eta = float((w * y).sum() / w.sum()) if w.sum() > 0 else 0.0
    b = float(geo.rail_inclination)
    rail = geo.rail_profile.rotated(b) if b else geo.rail_profile
    cb, sb = math.cos(b), math.sin(b)
    y_inc = cb * p.y_rail + sb * p.z_rail + eta * math.cos(p.contact_angle)
    z_inc, slope, _ = (float(v) for v in rail.at_y(y_inc))
    angle = math.atan(slope)
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
            "creepage": (xi_ref + phi * eta, eta_ref, phi), "creepage_reference": (xi_ref, eta_ref, phi)}


def _weighted_fit(p, half_x, half_y, reach_y, degree, step, guard=0.03):
    """Least-squares gap polynomial (terms as :meth:`Patch.gap_coefficients`) on |x| <= half_x,
    |y| <= reach_y, with the points beyond |y| > half_y weighted ``guard``: they keep the polynomial
    rising where the gap rises without pulling it off the data in the window. Returns (coefficients,
    largest misfit in the window [m])."""
    x = np.arange(-half_x, half_x + 0.5 * step, step)
    y = np.arange(-reach_y, reach_y + 0.5 * step, step)
    X, Y = (a.ravel() for a in np.meshgrid(x, y))
    g = p.gap(X, Y) - p.gap(0.0, 0.0)
    ok = np.isfinite(g)
    X, Y, g = X[ok], Y[ok], g[ok]
    w = np.where(np.abs(Y) <= half_y, 1.0, guard)
    terms = [(i, j) for i in range(3) for j in range(degree + 1) if 2 <= i + j <= degree]
    A = np.stack([X ** i * Y ** j for i, j in terms], 1)
    scale = np.abs(A).max(0)
    c = np.linalg.lstsq(A / scale * w[:, None], g * w, rcond=None)[0] / scale
    names = [("" if i == 0 else f"x{i}") + ("" if j == 0 else f"y{j}") for i, j in terms]
    inside = np.abs(Y) <= half_y
    return dict(zip(names, (float(v) for v in c))), float(np.abs(A[inside] @ c - g[inside]).max())


def _gap_fit(scene_name, p, h):
    """The gap polynomial of the highest even degree (GAP_DEGREE, then lower) that stays open beyond the
    fitting window: c2(y) > 0 and min over x of h(x, y) > 0 for |y| beyond the window out to FIT_CHECK
    windows (a polynomial of high degree can turn down just outside its data, and the normal solver then
    finds no bounded patch)."""
    half_x, half_y = WINDOW[0] * h.a, _lateral_window(p, h)
    reach = half_y
    y = np.linspace(-FIT_CHECK * half_y, FIT_CHECK * half_y, 1601)
    outside = np.abs(y) > half_y
    for degree in range(GAP_DEGREE, 1, -2):
        coef, residual = _weighted_fit(p, half_x, half_y, reach, degree, min(h.a, h.b) / 12.0)
        c = [np.zeros_like(y) for _ in range(3)]
        for name, v in coef.items():
            i = int(name[1]) if name.startswith("x") else 0
            j = int(name.split("y")[1]) if "y" in name else 0
            c[i] = c[i] + v * y ** j
        if np.all(c[2] > 0):
            low = c[0] - c[1] ** 2 / (4.0 * c[2])
            if np.all(low[outside] > 0.0):
                return coef, residual
    raise SceneError(f"scene {scene_name!r}: key 'wheelset': the patch's gap at rail y = {p.y_rail * 1e3:.2f} mm has "
                     "no polynomial fit (degree <= 8) that stays open outside the patch", scene=scene_name,
                     key="wheelset")


def _fail(scene_name, key, value, allowed):
    raise SceneError.bad_value(scene_name, key, value, allowed)


def _geometry(scene_name: str, table: Mapping, base: str | None):
    """The checked wheelset geometry and patch number of a profile wheelset table (SceneError otherwise)."""
    mixed = sorted(CONICAL_ONLY_KEYS & set(table))
    if mixed:
        _fail(scene_name, f"wheelset.{mixed[0]}", table[mixed[0]],
              "no conical-wheelset key in a wheelset on profiles (it has wheel_profile/rail_profile/...): "
              "give nominal_radius and vertical_force instead of wheel_radius and vertical_load")
    patch_no = table.get("patch", 1)
    if isinstance(patch_no, bool) or patch_no not in (1, 2, 3):
        _fail(scene_name, "wheelset.patch", patch_no, "1, 2 or 3: which patch of the wheel (1 = the closest)")
    for k, what in (("nominal_radius", "the wheel radius at the wheel profile's origin [m]"),
                    ("vertical_force", "the vertical force on this wheel [N], > 0"),
                    ("pitch_velocity", "the wheelset's angular velocity about its axle [rad/s]")):
        if k not in table:
            raise SceneError(f"scene {scene_name!r}: key 'wheelset.{k}' is missing: {what}",
                             scene=scene_name, key=f"wheelset.{k}", allowed=what)
    rest = {k: v for k, v in table.items() if k != "patch"}
    geo = wheelset_geometry_from_table(scene_name, rest, base)
    for k, word in (("roll_angle", "balance"), ("pitch_velocity", "free")):
        if getattr(geo, k) == word:
            _fail(scene_name, f"wheelset.{k}", word, f"a number: the equilibrium that '{word}' asks for is not "
                  "solved yet; give the value (e.g. from the benchmark's table)")
    if not geo.vertical_force or geo.vertical_force <= 0.0:
        _fail(scene_name, "wheelset.vertical_force", table.get("vertical_force"),
              "the vertical force on this wheel [N], > 0")
    return geo, patch_no


def profile_contact(scene_name: str, table: Mapping, *, speed: float, wheel, rail, friction: float | None,
                    base: str | None = None) -> ProfileContact:
    """The contact of a profile wheelset scene (module docstring).

    Parameters
    ----------
    scene_name : str
        Named in messages.
    table : Mapping
        The scene's ``wheelset`` table (profile keys).
    speed : float
        Forward speed [m/s].
    wheel, rail : Material
        The bodies (for the Hertz-equivalent ellipse and the creep-force estimate).
    friction : float or None
        Nominal coefficient of friction (None: no creep force estimate, N = Fz / cos(delta)).
    base : str, optional
        Folder of relative profile paths.

    Raises
    ------
    SceneError
        A key's value, a missing ``vertical_force`` or ``pitch_velocity``, a roll or pitch left to the
        equilibrium, a patch number beyond those found; :class:`NoContactError` for a wheel that finds no
        contact or runs off a profile.
    """
    geo, patch_no = _geometry(scene_name, table, base)
    try:
        wc = contact_search(geo.on_track(), geo.side, speed=speed, section_half_width=SECTION_HALF_WIDTH)
    except ProfileError as exc:
        raise NoContactError(f"scene {scene_name!r}: key 'wheelset': no contact: {exc}", scene=scene_name,
                             key="wheelset", value=table.get("lateral_shift")) from None
    distinct = _distinct_patches(wc.patches, wheel, rail, geo.vertical_force)
    if patch_no > len(distinct):
        merged = len(wc.patches) - len(distinct)
        _fail(scene_name, "wheelset.patch", patch_no,
              f"at most {len(distinct)}: the search found {len(wc.patches)} gap minima on the {geo.side} wheel"
              + (f", {merged} of them within the first patch's Hertz-equivalent approach (one elastic patch "
                 "covers them; patch 1 solves it)" if merged else ""))
    p = distinct[patch_no - 1]
    curv = p.hertz_curvatures
    if not (curv[0] > 0 and curv[1] > 0):
        _fail(scene_name, "wheelset", f"patch {patch_no}",
              f"a patch whose gap closes (Hertz-equivalent curvatures {curv[0]:.4g}, {curv[1]:.4g} 1/m): a "
              "conformal contact (B <= 0) is not handled")
    e_star = contact_modulus(wheel, rail)
    G, nu = combined_elastic(wheel, rail)
    h0 = hertz_from_curvatures(*curv, geo.vertical_force / math.cos(p.contact_angle), e_star)
    ref = reference_point(geo, p, h0.approach, speed)
    if friction is None:
        N, fy = geo.vertical_force / math.cos(ref["angle"]), 0.0
    else:
        N, fy = normal_force_from_vertical(geo.vertical_force, ref["angle"], curv, e_star, G, nu,
                                           ref["creepage"], friction)
    h = hertz_from_curvatures(*curv, N, e_star)
    coef, residual = _gap_fit(scene_name, p, h)
    return ProfileContact(side=geo.side, patch=int(patch_no), patches=len(distinct),
                          contact_position_rail=ref["y_rail"], contact_height_rail=ref["z_rail"],
                          contact_angle=ref["angle"], plane_position_rail=float(p.y_rail),
                          plane_angle=float(p.contact_angle), rolling_radius=p.rolling_radius, separation=p.separation,
                          hertz_curvatures=(float(curv[0]), float(curv[1])), gap_coefficients=coef,
                          gap_residual=residual, creepage=ref["creepage"],
                          vertical_force=float(geo.vertical_force), normal_force=float(N),
                          lateral_force_estimate=float(fy), rail_section=_rail_section(geo.rail_profile))
