"""Wheel and rail cross-section profiles: the checked curve, its smooth interpolant, built-in standards.

Coordinates (SIMPACK's, CONTACT's and EN 13715 / EN 13674-1's for a right-hand wheel and rail): ``y`` [m] lateral,
positive towards the field side (a wheel's flange and a rail's gauge face at negative y; a left-hand one is the
same profile, mirrored); ``z`` [m] vertical, positive downwards (into the rail; away from the axle for a wheel, so
its rolling radius at y is ``R0 + z(y)``). A :class:`Profile` is checked to be a function of y without sharp kinks
or wide gaps (:func:`check_profile`) and interpolated by a cubic spline in arc length. Built-in standards:
:func:`s1002` (EN 13715 / UIC 510-2 wheel S1002) and :func:`uic60` (EN 13674-1 rail 60E1 = UIC60).

References
----------
.. [1] EN 13715:2006+A1:2010, Railway applications - Wheelsets and bogies - Wheels - Tread profile (S1002).
.. [2] EN 13674-1:2011, Railway applications - Track - Rail - Part 1: Vignole railway rails 46 kg/m and above.
.. [3] P. Shackleton, S. Iwnicki, Vehicle System Dynamics 46 (2008) 3-28 (the Manchester Contact Benchmark).
   doi:10.1080/00423110701245083
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..contract.errors import SceneError

__all__ = ["Profile", "ProfileError", "check_profile", "s1002", "uic60", "BUILT_IN",
           "MAX_KINK", "MAX_SPACING"]

#: largest allowed change of direction between neighbouring segments [rad] (the shared S1002 file has
#: 0.072 rad at its coarsest, the shared UIC60 file 0.039 rad)
MAX_KINK = 0.15
#: largest allowed distance between neighbouring points [m] (the shared files: 1.7 mm and 0.9 mm)
MAX_SPACING = 2.0e-3


class ProfileError(SceneError):
    """A wheel or rail profile that cannot be used; the message names the source and the point/line."""


@dataclass(frozen=True, eq=False)
class Profile:
    """A checked wheel or rail cross-section and its smooth interpolant.

    Coordinates: ``y`` lateral, positive towards the field side, ``z`` positive downwards (module docstring);
    :meth:`mirrored` gives a left-hand profile's mirror image for drawing in track axes. For a wheel, R0 is the
    nominal radius at the profile origin. The curve must be strictly a function of y (y strictly increasing along
    the points), with no kink sharper than ``max_kink`` between neighbouring segments and no gap wider than
    ``max_spacing``; :func:`check_profile` raises :class:`ProfileError` naming the source and point (file line).
    The smooth interpolant is a cubic spline of y and z in arc length (steep flanks stay well conditioned),
    giving z, the slope dz/dy and the signed curvature d2z/dy2 / (1 + z'^2)^(3/2) [1/m] at any y.

    Parameters
    ----------
    y : array_like
        Lateral coordinates [m], strictly increasing (see the module's conventions).
    z : array_like
        Vertical coordinates [m], positive downwards.
    name : str
        Where the profile came from (a file path or a built-in name), used in messages.
    kind : {"wheel", "rail", None}
        What the profile describes, when known.
    lines : array_like of int, optional
        Source line of each point (for messages); the point index + 1 when not given.
    smoothing : float
        Length [m] of the Gaussian smoothing applied (0: none; see :meth:`smoothed`).
    max_kink, max_spacing : float
        Limits of :func:`check_profile` [rad], [m].
    """

    y: np.ndarray
    z: np.ndarray
    name: str = "profile"
    kind: str | None = None
    lines: np.ndarray | None = None
    smoothing: float = 0.0
    max_kink: float = MAX_KINK
    max_spacing: float = MAX_SPACING
    _spline: tuple = field(init=False, repr=False)

    def __post_init__(self):
        from scipy.interpolate import CubicSpline  # here: ~0.9 s to import, not needed without profiles
        y = np.asarray(self.y, dtype=float)
        z = np.asarray(self.z, dtype=float)
        lines = np.arange(1, y.size + 1) if self.lines is None else np.asarray(self.lines, dtype=int)
        y, z, lines = check_profile(y, z, self.name, lines, self.max_kink, self.max_spacing)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "lines", lines)
        s = np.concatenate(([0.0], np.cumsum(np.hypot(np.diff(y), np.diff(z)))))
        object.__setattr__(self, "_spline", (s, CubicSpline(s, y), CubicSpline(s, z)))

    # -- evaluation -------------------------------------------------------------------------------
    @property
    def arc_length(self) -> np.ndarray:
        """Arc length [m] of each point from the first."""
        return self._spline[0]

    def _arc_of(self, y) -> np.ndarray:
        """Arc length at which the spline's y equals ``y`` (Newton from the polyline's guess)."""
        s, sy, _ = self._spline
        yq = np.asarray(y, dtype=float)
        if np.any(yq < self.y[0] - 1e-12) or np.any(yq > self.y[-1] + 1e-12):
            raise ProfileError(f"profile {self.name!r}: y = {np.min(yq):.6g} .. {np.max(yq):.6g} m lies outside "
                               f"the profile's range {self.y[0]:.6g} .. {self.y[-1]:.6g} m")
        t = np.interp(yq, self.y, s)
        for _ in range(4):   # the spline's y(s) is monotone and nearly linear between the points
            dy = sy(t, 1)
            t = np.clip(t - (sy(t) - yq) / np.where(dy > 1e-12, dy, 1e-12), s[0], s[-1])
        return t

    def at_y(self, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """z [m], slope dz/dy [1] and signed curvature [1/m] (:meth:`curvature_at`) at ``y`` [m]."""
        _, z, slope, curv = self.at_arc(self._arc_of(y))
        return z, slope, curv

    def z_at(self, y) -> np.ndarray:
        """z [m] of the smooth interpolant at lateral positions ``y`` [m]."""
        return self._spline[2](self._arc_of(y))

    def slope_at(self, y) -> np.ndarray:
        """dz/dy [1] at ``y`` [m]."""
        t = self._arc_of(y)
        return self._spline[2](t, 1) / self._spline[1](t, 1)

    def curvature_at(self, y) -> np.ndarray:
        """Signed curvature [1/m] of the curve z(y) at ``y`` [m]: z'' / (1 + z'^2)^(3/2).

        Positive where the curve bends towards +z: a convex rail head, a concave wheel (flange root).
        """
        t = self._arc_of(y)
        _, sy, sz = self._spline
        y1, z1, y2, z2 = sy(t, 1), sz(t, 1), sy(t, 2), sz(t, 2)
        return (y1 * z2 - z1 * y2) / (y1 * y1 + z1 * z1) ** 1.5

    def at_arc(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The interpolant at arc lengths ``t`` [m] from the first point.

        Returns
        -------
        y, z, slope, curvature : ndarray
            [m], [m], dz/dy [1], signed curvature [1/m] (see :meth:`curvature_at`).
        """
        _, sy, sz = self._spline
        t = np.asarray(t, dtype=float)
        y1, z1, y2, z2 = sy(t, 1), sz(t, 1), sy(t, 2), sz(t, 2)
        return sy(t), sz(t), z1 / np.where(y1 > 1e-12, y1, 1e-12), (y1 * z2 - z1 * y2) / (y1 * y1 + z1 * z1) ** 1.5

    def sample(self, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The interpolant at points equally spaced in arc length.

        Parameters
        ----------
        spacing : float
            Largest arc-length step [m].

        Returns
        -------
        t, y, z, slope, curvature : ndarray
            Arc length [m], then as :meth:`at_arc`; y is non-decreasing.
        """
        s = self._spline[0]
        t = np.linspace(s[0], s[-1], int(np.ceil((s[-1] - s[0]) / spacing)) + 1)
        y, z, slope, curv = self.at_arc(t)
        return t, np.maximum.accumulate(y), z, slope, curv

    # -- transformations --------------------------------------------------------------------------
    def mirrored(self) -> "Profile":
        """The mirror image y -> -y (the same wheel or rail on the other side, in un-mirrored axes)."""
        return Profile(-self.y[::-1], self.z[::-1], name=f"{self.name} (mirrored)", kind=self.kind,
                       lines=self.lines[::-1], smoothing=self.smoothing, max_kink=self.max_kink,
                       max_spacing=self.max_spacing)

    def rotated(self, angle: float) -> "Profile":
        """The profile turned by ``angle`` [rad] about the origin, the top tilting towards -y.

        A rail of slope dz/dy = 0 at its crown gets dz/dy = -tan(angle) there: ``rotated(atan(1/40))``
        inclines an upright rail 1:40 towards the track centre (its gauge face at -y), and
        ``rotated(-atan(1/40))`` stands an inclined one upright.
        """
        c, s = np.cos(angle), np.sin(angle)
        return Profile(c * self.y + s * self.z, -s * self.y + c * self.z, name=self.name, kind=self.kind,
                       lines=self.lines, smoothing=self.smoothing, max_kink=self.max_kink,
                       max_spacing=self.max_spacing)

    def shifted(self, dy: float, dz: float) -> "Profile":
        """The profile moved by (dy, dz) [m]."""
        return Profile(self.y + dy, self.z + dz, name=self.name, kind=self.kind, lines=self.lines,
                       smoothing=self.smoothing, max_kink=self.max_kink, max_spacing=self.max_spacing)

    def smoothed(self, length: float) -> "Profile":
        """The profile smoothed by a Gaussian of standard deviation ``length`` [m] along its arc length.

        Only on request (a measured, noisy profile); :attr:`smoothing` records the length. The two end
        points are kept and the curve is resampled at ``length / 4``.
        """
        if not length > 0:
            raise ProfileError(f"profile {self.name!r}: smoothing length = {length!r} is not allowed: a length > 0 [m]")
        s, sy, sz = self._spline
        t = np.linspace(s[0], s[-1], int(np.ceil((s[-1] - s[0]) / (length / 4))) + 1)
        y, z = sy(t), sz(t)
        h = t[1] - t[0]
        k = np.arange(-int(4 * length / h), int(4 * length / h) + 1) * h
        w = np.exp(-0.5 * (k / length) ** 2)
        w /= w.sum()
        pad = k.size // 2
        ys = np.convolve(np.pad(y, pad, mode="reflect", reflect_type="odd"), w, mode="valid")
        zs = np.convolve(np.pad(z, pad, mode="reflect", reflect_type="odd"), w, mode="valid")
        return Profile(ys, zs, name=self.name, kind=self.kind, smoothing=float(length),
                       max_kink=self.max_kink, max_spacing=self.max_spacing)


def check_profile(y: np.ndarray, z: np.ndarray, source: str, lines: np.ndarray, max_kink: float = MAX_KINK,
                  max_spacing: float = MAX_SPACING) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Check that points form a usable profile and return them with y increasing.

    Parameters
    ----------
    y, z : ndarray
        Coordinates [m] in file order (y increasing or decreasing).
    source : str
        The file or built-in name, for messages.
    lines : ndarray of int
        Source line of each point, for messages.
    max_kink : float
        Largest change of direction between neighbouring segments [rad].
    max_spacing : float
        Largest distance between neighbouring points [m].

    Returns
    -------
    y, z, lines : ndarray
        The points ordered with y strictly increasing.

    Raises
    ------
    ProfileError
        Non-finite values, fewer than 4 points, a curve that overlaps itself (repeated points or
        crossing segments), one that is not a function of y (y turns back), a kink or a gap; the
        message names the source and line.
    """
    def fail(i, what):
        raise ProfileError(f"profile {source}, line {int(lines[i])}: {what}")
    if y.shape != z.shape or y.ndim != 1 or y.size < 4:
        raise ProfileError(f"profile {source}: {y.size} points is not allowed: at least 4 (y, z) points")
    bad = ~(np.isfinite(y) & np.isfinite(z))
    if bad.any():
        fail(int(np.argmax(bad)), f"the point ({y[bad][0]!r}, {z[bad][0]!r}) is not a finite number")
    if y[-1] < y[0]:
        y, z, lines = y[::-1], z[::-1], lines[::-1]
    dy, dz = np.diff(y), np.diff(z)
    seg = np.hypot(dy, dz)
    if np.any(seg <= 1e-12):
        i = int(np.argmax(seg <= 1e-12)) + 1
        fail(i, f"the point ({y[i]:.6g}, {z[i]:.6g}) m repeats the previous one: the profile overlaps itself")
    if np.any(dy <= 0):
        crossing = _first_crossing(y, z)
        if crossing is not None:
            fail(crossing, "the profile crosses itself (overlaps): its segments intersect here")
        i = int(np.argmax(dy <= 0)) + 1
        fail(i, f"y = {y[i]:.6g} m does not increase from the previous point ({y[i - 1]:.6g} m): the profile "
                "is not a function of y (give only the running surface, without an undercut)")
    turn = np.abs(np.diff(np.arctan2(dz, dy)))
    if np.any(turn > max_kink):
        i = int(np.argmax(turn > max_kink)) + 1
        fail(i, f"a kink of {turn[i - 1]:.3g} rad at ({y[i]:.6g}, {z[i]:.6g}) m is not allowed: at most "
                f"{max_kink:g} rad between neighbouring segments (sample the rounding more finely)")
    if np.any(seg > max_spacing):
        i = int(np.argmax(seg > max_spacing)) + 1
        fail(i, f"a gap of {seg[i - 1] * 1e3:.3g} mm before this point is not allowed: points at most "
                f"{max_spacing * 1e3:g} mm apart")
    return y, z, lines


def _first_crossing(y: np.ndarray, z: np.ndarray) -> int | None:
    """Index of the end point of the first segment that properly intersects a later non-adjacent one."""
    p, d = np.stack([y[:-1], z[:-1]], 1), np.stack([np.diff(y), np.diff(z)], 1)
    n = len(p)
    for i in range(n - 2):
        q, e = p[i + 2:], d[i + 2:]
        den = d[i, 0] * e[:, 1] - d[i, 1] * e[:, 0]
        w = q - p[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / den
            u = (w[:, 0] * d[i, 1] - w[:, 1] * d[i, 0]) / den
        if np.any((den != 0) & (t > 0) & (t < 1) & (u > 0) & (u < 1)):
            return i + 1
    return None


# -- built-in standard profiles ---------------------------------------------------------------------
#: bounds [mm] of S1002's sections H, G, F, E, D, C, B, A (EN 13715 / UIC 510-2)
_S1002_BOUNDS = (-70.0, -62.764705882, -49.662510381, -39.764473993, -38.426669071, -35.0, -26.0,
                 32.15796, 60.0)
_S1002_B = (0.0, -3.358537058e-02, 1.565681624e-03, -2.810427944e-05, 5.844240864e-08, -1.562379023e-08,
            5.309217349e-15, -5.957839843e-12, 2.646656573e-13)
_S1002_C = (-4.320221063e+03, -1.038384026e+03, -1.065501873e+02, -6.051367875, -2.054332446e-01,
            -4.169739389e-03, -4.687195829e-05, -2.252755540e-07)


def _s1002_mm(s: np.ndarray) -> np.ndarray:
    """S1002 tread height F(s) [mm] (positive downwards) at s [mm], its eight sections A-H."""
    b = _S1002_BOUNDS
    arcs = {  # sections given as circles: F = a +/- sqrt(r^2 - (s + c)^2)
        "H": (9.519259302, +1, 20.5, 49.5), "G": (16.0, +1, 12.0, 55.0), "F": (8.834924130, +1, 20.0, 58.558326413),
        "D": (16.446, -1, 13.0, 26.210665)}

    def arc(name):
        a, sign, r, c = arcs[name]
        return a + sign * np.sqrt(np.maximum(r * r - (s + c) ** 2, 0.0))
    conds = [s < b[1], s < b[2], s < b[3], s < b[4], s < b[5], s < b[6], s < b[7], s >= b[7]]
    vals = [arc("H"), arc("G"), arc("F"), -93.576667419 - 2.747477419 * s, arc("D"),
            np.polynomial.polynomial.polyval(s, _S1002_C), np.polynomial.polynomial.polyval(s, _S1002_B),
            1.364323640 - 0.066666667 * s]
    return np.select(conds, vals)


def s1002(spacing: float = 1.0e-4, y_min: float = -0.06976, y_max: float = 0.060) -> Profile:
    """The S1002 wheel profile (EN 13715, UIC 510-2) from its standard piecewise definition.

    F(s) [mm] over s = -70 .. 60 mm: section A (s > 32.158) the line 1.364323640 - s/15; B (-26 .. 32.158) a
    polynomial of degree 8; C (-35 .. -26) one of degree 7; D a circle of radius 13 (flange root); E the
    line -93.576667419 - 2.747477419 s (flange flank, 70 deg); F, G, H circles of radii 20, 12 (flange
    tip, z = 28 mm at s = -55 mm) and 20.5 (flange back). Coefficients as published with the standard.

    Parameters
    ----------
    spacing : float
        Point spacing along y [m] (the curve is sampled for :class:`Profile`).
    y_min, y_max : float
        Lateral range [m]; the default stops 0.24 mm inside the vertical flange back at -70 mm, where the
        profile stops being a function of y.

    Returns
    -------
    Profile
        ``kind = "wheel"``, z downwards (radius R0 + z), flange at negative y.

    References
    ----------
    .. [1] EN 13715:2006+A1:2010, Railway applications - Wheelsets and bogies - Wheels - Tread profile.
    """
    if not (-0.070 < y_min < y_max <= 0.060):
        raise ProfileError(f"built-in 's1002': y range {y_min!r} .. {y_max!r} m is not allowed: within -0.070 .. 0.060 m")
    # finer near the steep flange back, where z changes fast with y
    y = np.unique(np.concatenate([np.arange(y_min, y_max, spacing), [y_max],
                                  np.linspace(y_min, min(y_min + 2e-3, y_max), 81)]))
    y = y[np.concatenate([[True], np.diff(y) > 1e-3 * spacing])]
    return Profile(y, _s1002_mm(y * 1e3) * 1e-3, name="s1002", kind="wheel")


def _uic60_head_mm() -> list:
    """Arcs and flank of the 60E1 head [mm] (y right, z up, crown at the origin), the gauge-side half.

    R300 centred at (0, -300) out to y = -10.228 (20.456 / 2); R80 tangent to it out to y = -26.0265
    (52.053 / 2); R13 tangent to R80 until the tangent falls at 1:20; then the 1:20 flank down to its
    tangent point with the R3 fillet under the head (the underside at 1:2.75 through (0, -51)).
    """
    c300, r300 = np.array([0.0, -300.0]), 300.0
    y1 = -10.228
    p1 = np.array([y1, c300[1] + np.sqrt(r300 ** 2 - y1 ** 2)])
    u1 = (p1 - c300) / r300                      # outward normal at the R300/R80 joint
    c80 = p1 - 80.0 * u1
    y2 = -26.0265
    p2 = np.array([y2, c80[1] + np.sqrt(80.0 ** 2 - (y2 - c80[0]) ** 2)])
    u2 = (p2 - c80) / 80.0
    c13 = p2 - 13.0 * u2
    # the R13 arc ends where its outward normal is perpendicular to the flank direction (-1, -20)
    t = np.array([-1.0, -20.0]) / np.hypot(1.0, 20.0)
    n = np.array([-t[1], t[0]])                  # outward normal of the flank (pointing to -y, +z)
    if n[0] > 0:
        n = -n
    p3 = c13 + 13.0 * n
    # the flank p3 + l t meets the underside (through (0, -51), falling 1 in 2.75 towards the web); the R3
    # fillet between them touches the flank r tan(turn / 2) before their corner
    d = np.array([2.75, -1.0]) / np.hypot(2.75, 1.0)   # underside direction, from the flank inwards
    q = np.array([0.0, -51.0])
    A = np.array([t, -d]).T
    lam, _ = np.linalg.solve(A, q - p3)
    corner = p3 + lam * t
    turn = np.arccos(np.clip(np.dot(t, d), -1.0, 1.0))
    p4 = corner - 3.0 * np.tan(turn / 2.0) * t
    return [("arc", c300, r300, 0.0, y1), ("arc", c80, 80.0, y1, y2), ("arc", c13, 13.0, y2, p3[0]),
            ("line", p3, p4)]


def uic60(spacing: float = 1.0e-4) -> Profile:
    """The head of rail 60E1 (UIC60, EN 13674-1), upright, from its arcs: both sides of the crown.

    Running surface from flank to flank: R300 (|y| <= 10.228 mm), R80 (to |y| = 26.027 mm), R13 down to the
    1:20 flanks, which end where the R3 fillet under the head begins (35.3 mm below the crown); the
    fillet and the underside turn back and are not a function of y. Origin at the crown, z downwards.

    Parameters
    ----------
    spacing : float
        Arc-length spacing of the points [m].

    Returns
    -------
    Profile
        ``kind = "rail"``, upright (incline it with :meth:`Profile.rotated`), gauge face at negative y.

    References
    ----------
    .. [1] EN 13674-1:2011, Railway applications - Track - Rail - Part 1: Vignole railway rails 46 kg/m
       and above (profile 60E1).
    """
    h = spacing * 1e3
    pts = []
    for piece in _uic60_head_mm():
        if piece[0] == "arc":
            _, c, r, ya, yb = piece
            a0 = np.arctan2(np.sqrt(max(r * r - (ya - c[0]) ** 2, 0.0)), ya - c[0])
            a1 = np.arctan2(np.sqrt(max(r * r - (yb - c[0]) ** 2, 0.0)), yb - c[0])
            a = np.linspace(a0, a1, max(int(np.ceil(abs(a1 - a0) * r / h)), 2) + 1)
            pts.append(np.stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)], 1))
        else:
            _, p, q = piece
            m = max(int(np.ceil(np.hypot(*(q - p)) / h)), 2) + 1
            pts.append(p + np.linspace(0, 1, m)[:, None] * (q - p))
    half = np.concatenate([pts[0]] + [p[1:] for p in pts[1:]])   # from the crown to the gauge-side flank
    yz = np.concatenate([half[::-1], (half * [-1.0, 1.0])[1:]])
    return Profile(yz[:, 0] * 1e-3, -yz[:, 1] * 1e-3, name="uic60", kind="rail")


#: built-in profiles by scene name
BUILT_IN = {"s1002": s1002, "uic60": uic60, "60e1": uic60}
