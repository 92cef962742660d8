"""Wheel and rail profile files, and the ``[scene.wheelset]`` keys that place a wheelset on a track.

Readers (each returns a checked :class:`railtherm.physics.profiles.Profile` in metres, z downwards; every error
names the file and the line): SIMPACK ``.prr`` / ``.prw`` (:func:`read_simpack`), MiniProf ``.ban`` / ``.whl``
(:func:`read_miniprof`) and plain two-column text (:func:`read_text`); :func:`load_profile` also knows the
built-in standards. ``mirror_y=True`` mirrors a profile given for the left side (y -> -y) so that its flange or
gauge face lies at negative y.

:func:`wheelset_geometry_from_table` checks the ``[scene.wheelset]`` profile keys and returns a
:class:`WheelsetGeometry` that :func:`railtherm.physics.contact_search.contact_search` can use.
"""
from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..contract.errors import SceneError
from ..physics.contact_search import WheelsetOnTrack
from ..physics.profiles import BUILT_IN, Profile, ProfileError

#: keys that make a ``wheelset`` table a profile wheelset (the conical one has none of them)
PROFILE_ONLY_KEYS = frozenset({"wheel_profile", "rail_profile", "rail_inclination", "gauge_height",
                               "flange_back_distance", "flange_back_position", "nominal_radius", "roll_angle",
                               "pitch_velocity", "vertical_force", "side", "patch"})
#: keys of the conical wheelset only
CONICAL_ONLY_KEYS = frozenset({"conicity", "vertical_load", "wheel_radius", "contact"})


def is_profile_wheelset(table) -> bool:
    """Whether a ``wheelset`` table describes a wheelset on profiles (any profile-only key)."""
    return isinstance(table, Mapping) and bool(PROFILE_ONLY_KEYS & set(table))


__all__ = ["read_profile", "read_simpack", "read_miniprof", "read_text", "load_profile", "WheelsetGeometry",
           "wheelset_geometry_from_table", "WHEELSET_KEYS"]

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"
_ROW = re.compile(rf"^\s*({_NUMBER})\s*[,;\s]\s*({_NUMBER})(?:\s*[,;\s]\s*{_NUMBER})*\s*$")


def _numbers(text: str, path: str, line: int) -> tuple[float, float]:
    m = _ROW.match(text)
    if not m:
        raise ProfileError(f"profile {path}, line {line}: cannot read {text.strip()!r}: expected two numbers "
                           "y z (a third column, e.g. a weight, is ignored)")
    return float(m.group(1).replace("d", "e").replace("D", "e")), float(m.group(2).replace("d", "e").replace("D", "e"))


def _lines(path: str) -> list[str]:
    try:
        with open(path, encoding="latin-1") as f:
            return f.read().splitlines()
    except OSError as exc:
        raise ProfileError(f"profile {path}: cannot be read ({exc.strerror or exc})") from None


def _profile(path, y, z, lines, kind, mirror_y, **kw) -> Profile:
    y, z, lines = np.asarray(y, float), np.asarray(z, float), np.asarray(lines, int)
    if mirror_y:
        y = -y
    return Profile(y, z, name=str(path), kind=kind, lines=lines, **kw)


def read_simpack(path: str, mirror_y: bool = False, **checks) -> Profile:
    """Read a SIMPACK rail (``.prr``) or wheel (``.prw``) profile.

    The ``spline`` block's processing data (unit factor ``units.len.f``, ``shift.y/z``, bounds, ``mirror.y/z``,
    ``inversion``) is applied to ``point.begin`` .. ``point.end``; ``rotate`` other than 0 is refused (its sense
    is not stated by the format).

    Parameters
    ----------
    path : str
        The file.
    mirror_y : bool
        Mirror y after SIMPACK's own processing (a file describing the left side).
    **checks
        ``max_kink`` [rad], ``max_spacing`` [m] for :class:`Profile`.

    Returns
    -------
    Profile
        In metres, z downwards, ``kind`` from the header's ``type`` (0 rail, 1 wheel).
    """
    text = _lines(path)
    opts: dict[str, tuple[str, int]] = {}
    pts, lines, inside, block = [], [], False, ""
    for n, raw in enumerate(text, 1):
        s = raw.split("!", 1)[0].strip()
        if not s:
            continue
        if s == "point.begin":
            inside = True
        elif s == "point.end":
            inside = False
        elif inside:
            pts.append(_numbers(s, path, n))
            lines.append(n)
        elif s.endswith(".begin") or s.endswith(".end"):
            block = s[:-6] if s.endswith(".begin") else ""
        elif "=" in s:
            k, v = (t.strip() for t in s.split("=", 1))
            opts[f"{block}:{k}" if block == "header" else k] = (v.strip("'\""), n)
    if not pts:
        raise ProfileError(f"profile {path}: no points between 'point.begin' and 'point.end'")

    def num(key, default):
        if key not in opts:
            return default
        v, n = opts[key]
        try:
            return float(v)
        except ValueError:
            raise ProfileError(f"profile {path}, line {n}: {key} = {v!r} is not a number") from None
    kind = {0: "rail", 1: "wheel"}.get(int(num("header:type", -1)))
    if kind is None:
        ext = os.path.splitext(path)[1].lower()
        kind = {".prr": "rail", ".prw": "wheel"}.get(ext)
    factor = num("units.len.f", 1.0)   # length unit per metre
    if not factor > 0:
        raise ProfileError(f"profile {path}, line {opts['units.len.f'][1]}: units.len.f = {factor!r} is not "
                           "allowed: a factor > 0 (user length units per metre, 1000 for mm)")
    if num("rotate", 0.0) != 0.0:
        raise ProfileError(f"profile {path}, line {opts['rotate'][1]}: rotate = {opts['rotate'][0]} is not "
                           "supported: rotate the points in the file (or give the angle as rail_inclination)")
    p = np.array(pts)
    y, z = p[:, 0] + num("shift.y", 0.0), p[:, 1] + num("shift.z", 0.0)
    keep = np.ones(y.size, bool)
    for c, lo, hi in ((y, "bound.y.min", "bound.y.max"), (z, "bound.z.min", "bound.z.max")):
        a, b = num(lo, 1.0), num(hi, 0.0)
        if a < b:   # SIMPACK: a bound is active only when min < max
            keep &= (c >= a) & (c <= b)
    y, z, ln = y[keep], z[keep], np.asarray(lines)[keep]
    if num("mirror.y", 0) == 1:
        y = -y
    if num("mirror.z", 0) == 1:
        z = -z
    return _profile(path, y / factor, z / factor, ln, kind, mirror_y, **checks)


def read_miniprof(path: str, mirror_y: bool = False, **checks) -> Profile:
    """Read a MiniProf rail (``.ban``) or wheel (``.whl``) profile (mm, columns as ``ColumnDef``).

    A ``Key=Value`` header, ``ColumnDef=X,Y`` and the points in mm (X lateral, Y vertical downwards). Points
    written with a leading ``"`` (MiniProf's flagged points) are counted in ``XYPoints`` and read like the others.

    Parameters
    ----------
    path : str
        The file.
    mirror_y : bool
        Mirror y (a profile measured on the left side, or written with the gauge face at +y as the
        shared ``MBench_UIC60_v3.ban``).
    **checks
        ``max_kink`` [rad], ``max_spacing`` [m] for :class:`Profile`.

    Returns
    -------
    Profile
        In metres, z downwards.
    """
    text = _lines(path)
    header: dict[str, tuple[str, int]] = {}
    pts, lines = [], []
    for n, raw in enumerate(text, 1):
        s = raw.strip()
        if not s:
            continue
        if "=" in s and not pts:
            k, v = s.split("=", 1)
            header[k.strip().lower()] = (v.strip(), n)
            continue
        pts.append(_numbers(s.lstrip('"'), path, n))
        lines.append(n)
    if not pts:
        raise ProfileError(f"profile {path}: no points after the header")
    cols = [c.strip().upper() for c in header.get("columndef", ("X,Y", 0))[0].split(",")]
    if cols[:2] != ["X", "Y"]:
        raise ProfileError(f"profile {path}, line {header['columndef'][1]}: ColumnDef = "
                           f"{header['columndef'][0]!r} is not supported: X,Y first")
    if "xypoints" in header:
        v, n = header["xypoints"]
        if not v.isdigit() or int(v) != len(pts):
            raise ProfileError(f"profile {path}, line {n}: XYPoints = {v} but the file has {len(pts)} points")
    ext = os.path.splitext(path)[1].lower()
    kind = {".ban": "rail", ".whl": "wheel"}.get(ext)
    p = np.array(pts) * 1e-3
    return _profile(path, p[:, 0], p[:, 1], lines, kind, mirror_y, **checks)


def read_text(path: str, units: str | None = None, mirror_y: bool = False, kind: str | None = None,
              **checks) -> Profile:
    """Read a plain two-column (y, z) profile, z downwards.

    Columns separated by whitespace, comma or semicolon; ``#``, ``!``, ``%`` start a comment.

    Parameters
    ----------
    path : str
        The file.
    units : {"mm", "m", None}
        Length unit of the columns; None detects it from the lateral span (> 1 unit: mm, < 0.5: m;
        in between the file must declare it).
    mirror_y : bool
        Mirror y (a left-side profile).
    kind : {"wheel", "rail", None}
        What the profile describes.
    **checks
        ``max_kink`` [rad], ``max_spacing`` [m] for :class:`Profile`.
    """
    if units not in (None, "mm", "m"):
        raise ProfileError(f"profile {path}: units = {units!r} is not allowed: 'mm', 'm' or None (detect)")
    pts, lines = [], []
    for n, raw in enumerate(_lines(path), 1):
        s = re.split(r"[#!%]", raw, maxsplit=1)[0].strip()
        if s:
            pts.append(_numbers(s, path, n))
            lines.append(n)
    if not pts:
        raise ProfileError(f"profile {path}: no points")
    p = np.array(pts)
    if units is None:
        span = float(np.ptp(p[:, 0]))
        if span > 1.0:
            units = "mm"
        elif span < 0.5:
            units = "m"
        else:
            raise ProfileError(f"profile {path}: lateral span {span:g} does not tell mm from m: declare units")
    p = p * (1e-3 if units == "mm" else 1.0)
    return _profile(path, p[:, 0], p[:, 1], lines, kind, mirror_y, **checks)


def read_profile(path: str, mirror_y: bool = False, units: str | None = None, **checks) -> Profile:
    """Read a profile file by its extension (``.prr``/``.prw``: SIMPACK, ``.ban``/``.whl``: MiniProf, else
    plain text with ``units``); see :func:`read_simpack`, :func:`read_miniprof`, :func:`read_text`."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext in (".prr", ".prw"):
        return read_simpack(path, mirror_y, **checks)
    if ext in (".ban", ".whl"):
        return read_miniprof(path, mirror_y, **checks)
    return read_text(path, units, mirror_y, **checks)


#: profiles already read or built, by file (path, modification time, size) or built-in name and the reader's
#: arguments: a study's scenes share their profiles, and reading a SIMPACK file costs ~30 ms
_LOADED: dict = {}
_LOADED_MAX = 64


def load_profile(spec: str, base: str | None = None, **kw) -> Profile:
    """A built-in profile by name (``"s1002"``, ``"uic60"`` / ``"60e1"``) or a file (relative to ``base``).

    A profile is immutable, so one already loaded is returned again (a file only while its modification time
    and size are unchanged)."""
    name = str(spec).lower()
    if name in BUILT_IN:
        key = ("built-in", name)
    else:
        path = spec if base is None or os.path.isabs(spec) else os.path.join(base, spec)
        try:
            st = os.stat(path)
            key = ("file", os.path.realpath(path), st.st_mtime_ns, st.st_size, tuple(sorted(kw.items())))
            hash(key)
        except (OSError, TypeError):
            return read_profile(path, **kw)      # its own error names the file
    if key not in _LOADED:
        if len(_LOADED) >= _LOADED_MAX:
            _LOADED.clear()
        _LOADED[key] = BUILT_IN[name]() if name in BUILT_IN else read_profile(path, **kw)
    return _LOADED[key]


# -- the [scene.wheelset] profile keys --------------------------------------------------------------
#: key -> (meaning, unit, lower bound, upper bound) of the numbers; bounds are open unless noted
WHEELSET_KEYS = {
    "rail_inclination": ("rail inclination towards the track centre (0 when the file is already inclined)",
                         "rad", -0.1, 0.1),
    "gauge": ("track gauge, measured gauge_height below the top of the rails", "m", 0.5, 2.0),
    "gauge_height": ("depth below the rail top at which the gauge is measured", "m", 0.0, 0.03),
    "flange_back_distance": ("inner distance between the two wheels' flange backs", "m", 0.5, 2.0),
    "flange_back_position": ("lateral position of the flange back in wheel-profile coordinates", "m", -0.2, 0.2),
    "nominal_radius": ("wheel radius at the wheel profile's origin", "m", 0.1, 1.5),
    "lateral_shift": ("wheelset lateral displacement, positive towards the right rail", "m", -0.05, 0.05),
    "yaw_angle": ("wheelset yaw about the vertical (downward) axis", "rad", -0.1, 0.1),
    "roll_angle": ("wheelset roll about the track's x axis (right wheel down positive), or 'balance'",
                   "rad", -0.1, 0.1),
    "pitch_velocity": ("wheelset angular velocity about its axle (negative rolling forwards), or 'free'",
                       "rad/s", -1e4, 1e4),
    "vertical_force": ("vertical force on this wheel, or the axle load with roll_angle = 'balance'", "N", 0.0, 1e7),
}
_DEFAULTS = {"rail_inclination": 0.0, "gauge": 1.435, "gauge_height": 0.014, "flange_back_distance": 1.360,
             "flange_back_position": -0.070, "lateral_shift": 0.0, "yaw_angle": 0.0, "roll_angle": 0.0}


@dataclass(frozen=True)
class WheelsetGeometry:
    """The ``[scene.wheelset]`` profile keys of one scene, checked, with the profiles loaded.

    ``roll_angle`` is a number [rad] or ``"balance"``; ``pitch_velocity`` a number [rad/s], ``"free"`` or
    None (not given); :meth:`on_track` needs numbers for both (the equilibrium that fills them in is
    not part of the geometry).
    """

    wheel_profile: Profile
    rail_profile: Profile
    rail_inclination: float
    gauge: float
    gauge_height: float
    flange_back_distance: float
    flange_back_position: float
    nominal_radius: float
    lateral_shift: float
    yaw_angle: float
    roll_angle: float | str
    pitch_velocity: float | str | None
    vertical_force: float | None
    side: str

    def on_track(self, roll_angle: float | None = None, pitch_velocity: float | None = None) -> WheelsetOnTrack:
        """The wheelset for :func:`railtherm.physics.contact_search.contact_search`, with roll [rad] and
        pitch velocity [rad/s] given here when the scene left them to the equilibrium."""
        roll = self.roll_angle if roll_angle is None else roll_angle
        pitch = self.pitch_velocity if pitch_velocity is None else pitch_velocity
        if isinstance(roll, str) or isinstance(pitch, str):
            raise ValueError(f"roll_angle = {roll!r}, pitch_velocity = {pitch!r}: the equilibrium must give numbers")
        return WheelsetOnTrack(wheel_profile=self.wheel_profile, rail_profile=self.rail_profile,
                               rail_inclination=self.rail_inclination, gauge=self.gauge,
                               gauge_height=self.gauge_height, flange_back_distance=self.flange_back_distance,
                               flange_back_position=self.flange_back_position,
                               nominal_radius=self.nominal_radius, lateral_shift=self.lateral_shift,
                               yaw_angle=self.yaw_angle, roll_angle=float(roll),
                               pitch_velocity=None if pitch is None else float(pitch))


def wheelset_geometry_from_table(scene_name: str, table: Mapping, base: str | None = None) -> WheelsetGeometry:
    """Check the ``[scene.wheelset]`` profile keys of a scene and load its profiles.

    Parameters
    ----------
    scene_name : str
        The scene, named in messages.
    table : Mapping
        The ``wheelset`` table: ``wheel_profile``, ``rail_profile`` (built-in name or path) and the
        numbers of :data:`WHEELSET_KEYS` in SI units; ``nominal_radius`` is required, the others default
        to a standard track (gauge 1.435 m at 14 mm, flange backs 1.360 m apart at -70 mm, no inclination,
        shift, yaw or roll). ``side`` is ``"right"`` (default) or ``"left"``.
    base : str, optional
        Folder that relative profile paths are relative to (the study file's).

    Returns
    -------
    WheelsetGeometry

    Raises
    ------
    SceneError
        Naming the scene, the key, the value and what is allowed (a profile file's own errors name the
        file and line, prefixed with the scene and key).
    """
    if not isinstance(table, Mapping):
        raise SceneError.bad_value(scene_name, "wheelset", table, "a table of wheelset keys")
    known = set(WHEELSET_KEYS) | {"wheel_profile", "rail_profile", "side"}
    for k in table:
        if k not in known:
            raise SceneError.bad_value(scene_name, f"wheelset.{k}", table[k],
                                       f"a key among {', '.join(sorted(known))}")
    out = {}
    for k, (meaning, unit, lo, hi) in WHEELSET_KEYS.items():
        key = f"wheelset.{k}"
        if k not in table:
            if k == "nominal_radius":
                raise SceneError(f"scene {scene_name!r}: key {key!r} is missing: the {meaning} [{unit}]",
                                 scene=scene_name, key=key)
            out[k] = _DEFAULTS.get(k)
            continue
        v = table[k]
        if (k, v) in (("roll_angle", "balance"), ("pitch_velocity", "free")):
            out[k] = v
            continue
        word = {"roll_angle": " or 'balance'", "pitch_velocity": " or 'free'"}.get(k, "")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo < v < hi:
            raise SceneError.bad_value(scene_name, key, v, f"the {meaning}: a number in ({lo:g}, {hi:g}) {unit}{word}")
        out[k] = float(v)
    side = table.get("side", "right")
    if side not in ("right", "left"):
        raise SceneError.bad_value(scene_name, "wheelset.side", side, "'right' or 'left'")
    profiles = {}
    for k, default in (("wheel_profile", "s1002"), ("rail_profile", "uic60")):
        spec = table.get(k, default)
        if not isinstance(spec, str) or not spec:
            raise SceneError.bad_value(scene_name, f"wheelset.{k}", spec,
                                       f"a built-in name ({', '.join(sorted(BUILT_IN))}) or a profile file path")
        try:
            profiles[k] = load_profile(spec, base)
        except ProfileError as exc:
            raise ProfileError(f"scene {scene_name!r}: key 'wheelset.{k}': {exc}", scene=scene_name,
                               key=f"wheelset.{k}", value=spec) from None
    want = {"wheel_profile": "wheel", "rail_profile": "rail"}
    for k, p in profiles.items():
        if p.kind not in (None, want[k]):
            raise SceneError.bad_value(scene_name, f"wheelset.{k}", table.get(k),
                                       f"a {want[k]} profile (this file holds a {p.kind} profile)")
    return WheelsetGeometry(wheel_profile=profiles["wheel_profile"], rail_profile=profiles["rail_profile"],
                            side=side, **out)
