"""A scene's contact from real wheel and rail profiles: the ``[scene.wheelset]`` profile keys turned into
the gap, load and creepages of its patches, when the scene is loaded (docs/DESIGN.md "Scene vocabulary").

The contact search (:func:`railtherm.physics.contact_search.contact_search`) finds the wheel's patches. Per
patch: ``contact = {shape = "gap"}`` with the undeformed gap on its contact plane as a polynomial (:func:`_gap_fit`)
for ``kalker``, the Hertz-equivalent ellipse for Hertz-based chains (normal model ``wheelset-profile``); the
wheelset's rigid slip (railtherm's sign, minus CONTACT's) at the plane's origin for the models, reported at the
patch's reference point (:mod:`.wheelset_profile_reference`); N from Fz (:func:`normal_force_from_vertical`, [1]).
``patch = "all"``: every patch, sharing Fz at one common approach (:func:`share_vertical_force`). ``roll_angle =
"balance"``: the roll giving both wheels half the axle load (:func:`balance_roll`); ``pitch_velocity = "free"``:
the solve finds it (:mod:`railtherm.solving.wheelset_equilibrium`). No contact: :class:`NoContact`, runs fail.

References
----------
.. [1] Z. Y. Shen, J. K. Hedrick, J. A. Elkins, Vehicle System Dynamics 12 (1983) 79-83. doi:10.1080/00423118308968725
"""
from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from ..contract.errors import SceneError
from ..physics.contact_search import contact_search
from ..physics.elastic import combined_elastic
from ..physics.profiles import ProfileError
from ..physics.elastic import contact_modulus
from ..references.hertz import hertz_from_curvatures, hertz_from_penetration
from ..references.kalker import kalker_linear_forces
from .profiles import CONICAL_ONLY_KEYS, wheelset_geometry_from_table
from .wheelset_profile_reference import (CONTACT_REFERENCE, SEARCH_REFERENCE, SECTION_HALF_WIDTH, _below,
                                         contact_reference, reference_at, reference_point)

__all__ = ["ProfileContact", "ProfileContacts", "NoContact", "NoContactError", "profile_contact",
           "roll_height_mismatch", "normal_force_from_vertical", "share_vertical_force", "WINDOW", "GAP_DEGREE",
           "ROLL_BALANCE", "VERTICAL_ESTIMATE", "VERTICAL_SHARE", "GAP_SECTION_HALF_WIDTH", "SEARCH_REFERENCE",
           "CONTACT_REFERENCE", "reference_at", "contact_reference"]

#: half-extents of the gap's fitting window, in Hertz-equivalent semi-axes (a along x, b across)
WINDOW = (1.6, 2.0)
#: half-width [m] of the sampled gap a patch carries for a solver of the gap itself (ProfileContact.gap_section):
#: twice the search's section (A-2.2 position 1 right's interpenetration reaches 12.4 mm from the plane's origin)
GAP_SECTION_HALF_WIDTH = 2.0 * SECTION_HALF_WIDTH
#: how far (in fitting windows) the gap polynomial must stay open
FIT_CHECK = 1.5
#: degree of the gap polynomial in the lateral coordinate
GAP_DEGREE = 8
#: points of the rail profile a ProfileContact keeps for drawing (rail_section)
SECTION_POINTS = 400
#: which forces balance the roll found at scene load (``roll_angle = "balance"``; result attribute
#: ``wheelset_roll_balance``); a chain with a non-Hertzian normal stage corrects it with its own
#: (:func:`railtherm.solving.wheelset_equilibrium.solve_balanced_roll`)
ROLL_BALANCE = ("Hertz-equivalent normal forces of each wheel's patches (the profiles' curvatures at the contact), "
                "the lateral creep force estimated by Kalker's linear theory, saturated (Shen-Hedrick-Elkins)")
#: the lateral creep force a scene's normal forces balance Fz with when it is loaded (``vertical_balance`` None)
VERTICAL_ESTIMATE = "the lateral creep force estimated by Kalker's linear theory, saturated (Shen-Hedrick-Elkins)"
#: ``vertical_balance`` of each patch of a scene of every patch: its normal force is its share of the wheel's
#: force, which the wheel's patches balance together (:class:`ProfileContacts`), never one patch alone
VERTICAL_SHARE = "a share of the wheel's vertical force at the patches' common approach"


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
    gap_section : GapSection
        The undeformed gap on the contact plane as the contact search samples it over |y| <=
        :data:`GAP_SECTION_HALF_WIDTH`, zero at the origin (:class:`railtherm.physics.contact_search.GapSection`):
        what a solver of the gap itself takes (kalker)
        instead of the polynomial, whose misfit is not small where the patch is far from Hertzian.
    creepage : tuple of float
        (longitudinal [1], lateral [1], spin [1/m]), railtherm's convention: the wheel's rigid slip at the
        contact plane's origin, where the scene's contact models take it (their slip field (xi - phi y,
        eta + phi x) on the plane is the wheel's rigid slip everywhere on it).
    reference_offset : float
        The reference point's coordinate across the contact plane from its origin [m] (on the rail at
        plane_position_rail + reference_offset cos(plane_angle)).
    vertical_force : float
        The wheel's vertical force Fz [N].
    normal_force : float
        N [N] from Fz and the estimated lateral creep force.
    lateral_force_estimate : float
        The estimated lateral creep force on the wheel in the contact plane [N] that N used.
    rail_section : tuple of tuple of float
        (y, z) [m] of the rail profile in its own coordinates, at most :data:`SECTION_POINTS` of its points:
        what a reader of results (the report) draws the patches on without reading the profile file.
    balanced_roll : float or None
        The roll [rad] that ``roll_angle = "balance"`` found (:func:`balance_roll`), else None.
    free_pitch : float or None
        With ``pitch_velocity = "free"``: the pitch velocity [rad/s] of the creepages here (-V / R0); the
        solve finds the one that balances the axle's moment (:mod:`railtherm.solving.wheelset_equilibrium`).
    arm, axle : tuple of float
        The reference point relative to the wheelset centre [m] and the axle's unit vector, wheel axes (z down).
    reference_of : callable
        ``reference_of(approach)``: :func:`contact_reference` of this patch's sampled gap at a normal solution's
        approach [m] (None: not available).
    vertical_balance : str or None
        Whose lateral creep force ``normal_force`` balances Fz with. None: the estimate's, and the solve may
        replace it with the chain's own (:mod:`railtherm.solving.wheelset_vertical`); the patch of a scene of
        every patch: :data:`VERTICAL_SHARE` (its wheel's forces are balanced together); otherwise the balance
        the solve settled on.
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
    reference_offset: float = 0.0
    gap_section: object = field(default=None, repr=False, compare=False)
    rail_section: tuple = field(default=((), ()), repr=False, compare=False)
    #: the wheelset's roll [rad] found by ``roll_angle = "balance"`` (None: the scene gave it)
    balanced_roll: float | None = None
    #: the forces that balance that roll (:data:`ROLL_BALANCE`)
    roll_balance: ClassVar[str] = ROLL_BALANCE
    #: the pitch velocity [rad/s] the creepages were taken at when the scene left it ``"free"`` (None: given)
    free_pitch: float | None = None
    #: the reference point relative to the wheelset centre and the axle's direction, in the wheel's axes (z down)
    arm: tuple = field(default=(), repr=False, compare=False)
    axle: tuple = field(default=(), repr=False, compare=False)
    reference_of: object = field(default=None, repr=False, compare=False)
    #: whose lateral creep force ``normal_force`` balances Fz with (None: the estimate's, to be settled by the solve)
    vertical_balance: str | None = None

    @property
    def reference_creepage(self) -> tuple[float, float, float]:
        """(longitudinal [1], lateral [1], spin [1/m]) at the contact reference point, as a result reports them:
        the contact models' slip field (xi - phi y, eta + phi x) of :attr:`creepage` at x = 0, y =
        :attr:`reference_offset`. The CONTACT program reports its creepages at its contact reference point, where
        its ``ycp_r`` lies (Vollebregt 2022, :mod:`railtherm.physics.contact_search` [1])."""
        xi, eta, phi = self.creepage
        return xi - phi * self.reference_offset, eta, phi

    def reported_reference(self, approach: float | None = None) -> dict:
        """The patch's reference point as a result reports it: ``y_rail`` (``contact_position_rail``) [m],
        ``angle`` (``contact_angle``) [rad], ``creepage`` (longitudinal [1], lateral [1], spin [1/m], the wheel's
        rigid slip there) and ``how`` (:data:`SEARCH_REFERENCE` or :data:`CONTACT_REFERENCE`).

        With the ``approach`` [m] of a normal solution of :attr:`gap_section` (kalker's): the CONTACT program's
        reference point at that approach (:func:`contact_reference`), where CONTACT reports its position, angle
        and creepages. Without (a Hertz-based chain): the contact search's, :attr:`contact_position_rail`,
        :attr:`contact_angle` and :attr:`reference_creepage`. The scene's creepages, which the contact models
        solve with, are the same either way."""
        if approach is None or self.reference_of is None:
            return {"y_rail": self.contact_position_rail, "angle": self.contact_angle,
                    "creepage": self.reference_creepage, "how": SEARCH_REFERENCE}
        ref = self.reference_of(float(approach))
        return {"y_rail": ref["y_rail"], "angle": ref["angle"], "creepage": ref["creepage_reference"],
                "how": CONTACT_REFERENCE}


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
    """The patches that are elastic patches of their own: a gap minimum inside the first patch's interpenetration
    region at its Hertz-equivalent approach under the whole force (:func:`_connected`) lies inside the first
    patch (its gap fit covers it); one beyond that approach, or apart from the region, is a patch of its own."""
    first = patches[0]
    A, B = first.hertz_curvatures
    if not (A > 0 and B > 0):
        return list(patches)
    h = hertz_from_curvatures(A, B, vertical_force / math.cos(first.contact_angle), contact_modulus(wheel, rail))
    return [first] + [q for q in patches[1:] if not _connected(first, q, h.approach)]


def _lateral_window(p, h) -> float:
    """Half-width [m] of the gap fit across rolling: WINDOW[1] Hertz semi-axes b, widened to 1.2 times the
    reach of the stretch around the contact point where the undeformed gap stays below the Hertz-equivalent
    approach (a second, nearly touching minimum, as at Manchester position 1, lies in the elastic patch),
    at most the sampled section's reach."""
    y = np.linspace(-SECTION_HALF_WIDTH, SECTION_HALF_WIDTH, 2401)
    lo, hi = _below(y, p.gap(0.0, y) - p.gap(0.0, 0.0), h.approach)
    reach = max(-y[lo], y[hi])
    return float(min(max(WINDOW[1] * h.b, 1.2 * reach), 0.95 * SECTION_HALF_WIDTH))


def _weighted_fit(p, half_x, half_y, reach_y, degree, step, guard=0.03):
    """Least-squares gap polynomial (terms as :meth:`railtherm.physics.contact_search.Patch.gap_coefficients`) on
    |x| <= half_x, |y| <= reach_y, with the points beyond |y| > half_y weighted ``guard``: they keep the polynomial
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
    finds no bounded patch). Terms to y^8 and x^2 y^6; the misfit (:attr:`ProfileContact.gap_residual`) is below
    1 um at 38 of the 42 CONTACT A-2.2 contacts, 0.22 mm at position 2 right: kalker solves the sampled gap
    (:attr:`ProfileContact.gap_section`) instead; the polynomial is the scene's ``contact`` for the others."""
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
    if isinstance(patch_no, bool) or patch_no not in (1, 2, 3, "all"):
        _fail(scene_name, "wheelset.patch", patch_no, "1, 2 or 3: which patch of the wheel (1 = the closest), or "
              "\"all\": every patch, sharing the wheel's vertical force")
    for k, what in (("nominal_radius", "the wheel radius at the wheel profile's origin [m]"),
                    ("vertical_force", "the vertical force on this wheel [N], > 0"),
                    ("pitch_velocity", "the wheelset's angular velocity about its axle [rad/s]")):
        if k not in table:
            raise SceneError(f"scene {scene_name!r}: key 'wheelset.{k}' is missing: {what}",
                             scene=scene_name, key=f"wheelset.{k}", allowed=what)
    rest = {k: v for k, v in table.items() if k != "patch"}
    geo = wheelset_geometry_from_table(scene_name, rest, base)
    if not geo.vertical_force or geo.vertical_force <= 0.0:
        _fail(scene_name, "wheelset.vertical_force", table.get("vertical_force"),
              "the vertical force on this wheel [N], > 0")
    return geo, patch_no


def profile_contact(scene_name: str, table: Mapping, *, speed: float, wheel, rail, friction: float | None,
                    base: str | None = None):
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

    Returns
    -------
    ProfileContact or ProfileContacts
        The patch ``wheelset.patch``; with ``patch = "all"`` every patch that the shared load closes.

    Raises
    ------
    SceneError
        A key's value, a missing ``vertical_force`` or ``pitch_velocity``, a roll or pitch left to the
        equilibrium, a patch number beyond those found; :class:`NoContactError` for a wheel that finds no
        contact or runs off a profile.
    """
    geo, patch_no = _geometry(scene_name, table, base)
    try:
        wc = contact_search(_nominal(geo, speed).on_track(), geo.side, speed=speed,
                            section_half_width=SECTION_HALF_WIDTH)
    except ProfileError as exc:
        raise NoContactError(f"scene {scene_name!r}: key 'wheelset': no contact: {exc}", scene=scene_name,
                             key="wheelset", value=table.get("lateral_shift")) from None
    bodies = (contact_modulus(wheel, rail), *combined_elastic(wheel, rail))
    roll = None
    free = -speed / geo.nominal_radius if geo.pitch_velocity == "free" else None
    if geo.roll_angle == "balance":
        roll = balance_roll(scene_name, geo, bodies, friction, speed)
        geo = dataclasses.replace(geo, roll_angle=roll, vertical_force=0.5 * geo.vertical_force)
        wc = contact_search(_nominal(geo, speed).on_track(), geo.side, speed=speed,
                            section_half_width=SECTION_HALF_WIDTH)
    geo = _nominal(geo, speed)
    distinct = _distinct_patches(wc.patches, wheel, rail, geo.vertical_force)
    if patch_no == "all":
        return _all_patches(scene_name, geo, wc.patches, bodies, friction, speed, roll, free)
    if patch_no > len(distinct):
        merged = len(wc.patches) - len(distinct)
        _fail(scene_name, "wheelset.patch", patch_no,
              f"at most {len(distinct)}: the search found {len(wc.patches)} gap minima on the {geo.side} wheel"
              + (f", {merged} of them inside the first patch's interpenetration region (one elastic patch "
                 "covers them; patch 1 solves it)" if merged else ""))
    p = distinct[patch_no - 1]
    _check_curvatures(scene_name, p, patch_no)
    e_star, G, nu = bodies
    h0 = hertz_from_curvatures(*p.hertz_curvatures, geo.vertical_force / math.cos(p.contact_angle), e_star)
    ref = reference_point(geo, p, h0.approach, speed)
    if friction is None:
        N, fy = geo.vertical_force / math.cos(ref["angle"]), 0.0
    else:
        N, fy = normal_force_from_vertical(geo.vertical_force, ref["angle"], p.hertz_curvatures, e_star, G, nu,
                                           ref["creepage"], friction)
    return _patch_contact(scene_name, geo, p, patch_no, len(distinct), ref, N, fy, e_star, roll, free, speed=speed)


def _check_curvatures(scene_name, p, patch_no) -> None:
    curv = p.hertz_curvatures
    if not (curv[0] > 0 and curv[1] > 0):
        _fail(scene_name, "wheelset", f"patch {patch_no}",
              f"a patch whose gap closes (Hertz-equivalent curvatures {curv[0]:.4g}, {curv[1]:.4g} 1/m): a "
              "conformal contact (B <= 0) is not handled")


def _patch_contact(scene_name, geo, p, patch_no, patches, ref, N, fy, e_star, roll=None,
                   free=None, *, speed: float) -> ProfileContact:
    """The ProfileContact of search patch ``p`` at normal force N [N] (Fy [N] its lateral force estimate; speed
    [m/s] the wheelset's, for the rigid slip at a reference point found later)."""
    curv = p.hertz_curvatures
    coef, residual = _gap_fit(scene_name, p, hertz_from_curvatures(*curv, N, e_star))
    section = _zeroed(p.section(GAP_SECTION_HALF_WIDTH))
    return ProfileContact(side=geo.side, patch=int(patch_no), patches=int(patches),
                          contact_position_rail=ref["y_rail"], contact_height_rail=ref["z_rail"],
                          contact_angle=ref["angle"], plane_position_rail=float(p.y_rail),
                          plane_angle=float(p.contact_angle), rolling_radius=p.rolling_radius, separation=p.separation,
                          hertz_curvatures=(float(curv[0]), float(curv[1])), gap_coefficients=coef,
                          gap_residual=residual, creepage=ref["creepage"],
                          vertical_force=float(geo.vertical_force), normal_force=float(N),
                          lateral_force_estimate=float(fy), reference_offset=float(ref["offset"]),
                          gap_section=section, rail_section=_rail_section(geo.rail_profile),
                          balanced_roll=roll, free_pitch=free, arm=ref["arm"], axle=ref["axle"],
                          reference_of=functools.partial(contact_reference, geo, p, speed, section))


def _zeroed(section):
    """``section`` with its value at the plane's origin subtracted (the patch's own gap, zero at its minimum)."""
    return dataclasses.replace(section, origin=float(section(0.0, 0.0)))


# -- several patches of one wheel sharing its vertical force -------------------------------------------------
@dataclass(frozen=True)
class ProfileContacts:
    """Every patch of a profile wheelset's wheel that the shared vertical force closes (``patch = "all"``).

    Attributes
    ----------
    side : str
        "right" or "left".
    contacts : tuple of ProfileContact
        The loaded patches, closest first, each with its share of the force as ``normal_force``.
    approach : float
        The wheel's common vertical approach [m] beyond first touch (:func:`share_vertical_force`).
    vertical_force : float
        The wheel's vertical force Fz [N].
    patches : int
        Loaded patches (gap minima that the approach does not close carry no load and are left out).
    vertical_balance : str or None
        Whose lateral creep forces the shares balance Fz with (as :attr:`ProfileContact.vertical_balance`).
    """

    side: str
    contacts: tuple
    approach: float
    vertical_force: float
    patches: int
    vertical_balance: str | None = None

    patch = "all"

    def __getattr__(self, name):   # the first patch stands for the scene (its gap, load and creepages)
        if name.startswith("__") or name == "contacts":
            raise AttributeError(name)
        return getattr(self.contacts[0], name)


def share_vertical_force(vertical_force: float, separations, angles, curvatures, e_star: float,
                         lateral=None, rtol: float = 1e-10):
    """The patches' normal forces at one common vertical approach that carries the wheel's vertical force.

    The wheel moves down by ``delta`` [m] from first touch; patch i, ``separations[i]`` [m] above the closest,
    is pressed along its normal by (delta - s_i) cos(gamma_i) and carries the Hertz force of its curvatures
    (A_i, B_i) [1/m] there (zero while delta <= s_i). ``delta`` solves sum_i N_i cos(gamma_i) - Fy_i sin(gamma_i)
    = Fz by bisection, Fy_i = ``lateral(i, N_i)`` [N] (the lateral force on the wheel in patch i's plane; None:
    0).

    Returns
    -------
    (delta, normal_forces, lateral_forces) : float, list of float, list of float
        [m], [N], [N].
    """
    lateral = lateral or (lambda i, n: 0.0)

    def forces(delta):
        normal, side = [], []
        for i, (s, g, (A, B)) in enumerate(zip(separations, angles, curvatures)):
            d = (delta - s) * math.cos(g)
            n = hertz_from_penetration(A, B, d, e_star).normal_force if d > 0.0 else 0.0
            normal.append(n)
            side.append(lateral(i, n) if n > 0.0 else 0.0)
        vertical = sum(n * math.cos(g) - f * math.sin(g) for n, f, g in zip(normal, side, angles))
        return vertical, normal, side

    lo, hi = 0.0, 1e-6
    while forces(hi)[0] < vertical_force:
        lo, hi = hi, 2.0 * hi
        if hi > 1e-2:
            raise ValueError(f"no approach below 10 mm carries the vertical force {vertical_force:g} N")
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if forces(mid)[0] < vertical_force else (lo, mid)
    _, normal, side = forces(hi)
    return hi, normal, side


def _connected(p, q, depth: float) -> bool:
    """True when search patch ``q``'s gap minimum lies on ``p``'s section within the stretch around ``p``'s
    minimum where the gap stays below ``depth`` [m] (p's normal approach): one interpenetration region, one
    elastic patch (``p``'s gap fit covers both minima)."""
    y_q = (q.y_rail - p.y_rail) / math.cos(p.contact_angle)
    if depth <= 0.0 or abs(y_q) > 0.95 * SECTION_HALF_WIDTH:
        return False
    y = np.linspace(min(0.0, y_q), max(0.0, y_q), 401)
    return bool(np.all(p.gap(0.0, y) - p.gap(0.0, 0.0) < depth))


def _shares(geo, found, refs, bodies, friction):
    """:func:`share_vertical_force` over the search patches ``found`` with their reference points ``refs``."""
    e_star, G, nu = bodies

    def lateral(i, n):
        if friction is None:
            return 0.0
        h = hertz_from_curvatures(*found[i].hertz_curvatures, n, e_star)
        return _saturated_lateral(h.a, h.b, G, nu, refs[i]["creepage"], friction, n)

    return share_vertical_force(float(geo.vertical_force), [p.separation for p in found], [r["angle"] for r in refs],
                                [p.hertz_curvatures for p in found], e_star, lateral)


def _loaded(scene_name, geo, found, bodies, friction, speed, rounds: int = 2):
    """The search patches ``found`` that the shared vertical force closes (:func:`share_vertical_force`), a patch
    whose interpenetration region joins a closer one's merged into it (:func:`_connected`): (patches, reference
    points, common approach [m], normal forces [N], lateral force estimates [N]). The shares are found with the
    reference points at the whole force's Hertz-equivalent approach, then ``rounds`` times more with them at each
    loaded patch's own approach (the last shares are those of the reference points kept)."""
    e_star = bodies[0]
    fz = float(geo.vertical_force)
    found = list(found)
    for k, p in enumerate(found, 1):
        _check_curvatures(scene_name, p, k)
    refs = [reference_point(geo, p, hertz_from_curvatures(*p.hertz_curvatures, fz / math.cos(p.contact_angle),
                                                          e_star).approach, speed) for p in found]
    delta, normal, side = _shares(geo, found, refs, bodies, friction)
    keep = []
    for k, n in enumerate(normal):
        if n > 0.0 and not any(_connected(found[j], found[k], (delta - found[j].separation)
                                          * math.cos(found[j].contact_angle)) for j in keep):
            keep.append(k)
    found, refs, normal = [found[k] for k in keep], [refs[k] for k in keep], [normal[k] for k in keep]
    for _ in range(rounds):   # the reference points at the loaded patches' own approaches, then their shares
        refs = [reference_point(geo, p, hertz_from_curvatures(*p.hertz_curvatures, n, e_star).approach, speed)
                if n > 0.0 else r for p, r, n in zip(found, refs, normal)]
        delta, normal, side = _shares(geo, found, refs, bodies, friction)
    return found, refs, delta, normal, side


def _all_patches(scene_name, geo, found, bodies, friction, speed, roll=None, free=None) -> ProfileContacts:
    """Every search patch that the shared vertical force closes (:func:`_loaded`), as :class:`ProfileContacts`."""
    found, refs, delta, normal, side = _loaded(scene_name, geo, found, bodies, friction, speed)
    loaded = [k for k, n in enumerate(normal) if n > 0.0]
    contacts = tuple(dataclasses.replace(_patch_contact(scene_name, geo, found[k], j + 1, len(loaded), refs[k],
                                                        normal[k], side[k], bodies[0], roll, free, speed=speed),
                                         vertical_balance=VERTICAL_SHARE) for j, k in enumerate(loaded))
    return ProfileContacts(side=geo.side, contacts=contacts, approach=float(delta),
                           vertical_force=float(geo.vertical_force), patches=len(loaded))


# -- the wheelset's roll that balances the vertical forces of its two wheels ----------------------------------
def _nominal(geo, speed: float):
    """``geo`` with numbers for roll and pitch velocity where the scene left them to the equilibrium: no roll,
    and the pitch velocity of rolling at the nominal radius, -V / R0 [rad/s] (the contact search needs
    numbers; the equilibrium replaces them)."""
    roll = 0.0 if geo.roll_angle == "balance" else geo.roll_angle
    pitch = -speed / geo.nominal_radius if geo.pitch_velocity == "free" else geo.pitch_velocity
    return dataclasses.replace(geo, roll_angle=roll, pitch_velocity=pitch)


def _wheel_height(scene_name, geo, side, roll, bodies, friction, speed) -> float:
    """How far [m] the wheelset centre must move down from its nominal height for wheel ``side`` to carry its
    ``vertical_force``: the gap to first touch plus the common approach of its patches (:func:`_loaded`, the
    reference points at the whole force's Hertz-equivalent approach)."""
    g = dataclasses.replace(geo, side=side, roll_angle=roll)
    try:
        wc = contact_search(g.on_track(), side, speed=speed, section_half_width=SECTION_HALF_WIDTH)
    except ProfileError as exc:
        raise NoContactError(f"scene {scene_name!r}: key 'wheelset.roll_angle': no contact while balancing the "
                             f"roll (roll = {roll:.6g} rad): {exc}", scene=scene_name, key="wheelset.roll_angle",
                             value="balance") from None
    return wc.gap + _loaded(scene_name, g, wc.patches, bodies, friction, speed, rounds=0)[2]


def balance_roll(scene_name: str, geo, bodies, friction, speed: float, tol: float = 1e-11) -> float:
    """The wheelset's roll [rad] at which both wheels carry half of ``geo.vertical_force`` (the axle load).

    The wheelset centre sits at one height: each wheel's height to carry Fz / 2 (:func:`_wheel_height`, its
    patches' Hertz-equivalent forces, as the normal force of a scene is estimated) must be the same for the
    right and the left wheel; the roll that makes them equal is found by the secant method to ``tol`` [m].
    A scene with ``pitch_velocity = "free"`` balances the roll at -V / R0. This roll (:data:`ROLL_BALANCE`,
    result attribute ``wheelset_roll_balance``) is found when the scene is loaded; the solve of a chain whose
    normal stage is not Hertzian (kalker) corrects it with that stage's approaches
    (:func:`railtherm.solving.wheelset_equilibrium.solve_balanced_roll`).
    """
    base = dataclasses.replace(_nominal(geo, speed), vertical_force=0.5 * float(geo.vertical_force))

    def mismatch(roll):
        return (_wheel_height(scene_name, base, "right", roll, bodies, friction, speed)
                - _wheel_height(scene_name, base, "left", roll, bodies, friction, speed))

    r0, r1 = 0.0, -1e-4
    f0, f1 = mismatch(r0), mismatch(r1)
    for _ in range(40):
        if abs(f1) <= tol or f1 == f0:
            break
        r0, f0, r1 = r1, f1, r1 - f1 * (r1 - r0) / (f1 - f0)
        f1 = mismatch(r1)
    else:
        raise SceneError(f"scene {scene_name!r}: key 'wheelset.roll_angle' = 'balance': no roll balances the two "
                         f"wheels' vertical forces (height mismatch {f1:.3g} m after 40 steps)", scene=scene_name,
                         key="wheelset.roll_angle", value="balance")
    return float(r1)


def roll_height_mismatch(scene, roll: float) -> float:
    """The wheelset centre's height for the right wheel to carry half the axle load minus the left wheel's [m]
    (:func:`_wheel_height`, Hertz-equivalent forces) at ``roll`` [rad], for a scene loaded with ``roll_angle =
    "balance"`` (:func:`balance_roll` zeroes it; :mod:`railtherm.solving.wheelset_equilibrium` corrects it with
    the chain's own normal approaches)."""
    table = dict(scene.source["wheelset"], roll_angle=0.0)
    geo, _ = _geometry(scene.name, {k: v for k, v in table.items() if k != "patch"}, None)
    base = dataclasses.replace(_nominal(geo, scene.speed), vertical_force=0.5 * float(geo.vertical_force))
    bodies = (contact_modulus(scene.wheel, scene.rail), *combined_elastic(scene.wheel, scene.rail))
    mu = None if scene.friction is None else scene.friction.nominal
    return (_wheel_height(scene.name, base, "right", roll, bodies, mu, scene.speed)
            - _wheel_height(scene.name, base, "left", roll, bodies, mu, scene.speed))
