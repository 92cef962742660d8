"""What the report reads of a study of wheelsets on real profiles: its contacts by wheel side and lateral shift,
each run's values patch by patch (tread and flange patches told apart by the contact angle), and each patch's
flash temperature error against the reference method with the reference it was taken against.

A scene of several patches (``wheelset.patch = "all"``) gives a result with a ``patch`` dimension; a scene of
one patch a result without it (its patch number in the attribute ``wheelset_patch``). Values are the run files'
and errors metrics.nc's (``patch_errors_<metric>``, :mod:`railtherm.analysis.patch_metrics`): the report computes
no physics.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .exact_contact import relative_error
from .load import StudyData

__all__ = ["SIDES", "FLANGE_ANGLE", "QUANTITIES", "SHAPE_SHIFTS", "FLASH", "PatchValue", "PatchError",
           "wheelset_scenes", "shape_scenes", "reference_method", "patch_values", "patch_error", "role_of"]

SIDES = ("right", "left")
#: |contact angle| [rad] from which a patch is a flange patch (flange root or flank), below it a tread patch: on
#: new S1002 wheels on UIC60 rails (Manchester A-2.2) tread patches lie below 0.14 rad and flange-root patches
#: above 0.29 rad (the contact jumps between them at the two-point contact); 0.2 rad lies in that gap
FLANGE_ANGLE = 0.2
#: the flash temperature: the hotter body's maximum surface temperature
FLASH = "max_surface_temperature"
#: the plotted quantities per patch: (result variable, factor from SI, axis label with its unit)
QUANTITIES = (("contact_position_rail", 1e3, "contact position\non the rail [mm]"),
              ("contact_angle", 1.0, "contact angle [rad]"),
              ("normal_force", 1e-3, "normal force N [kN]"),
              ("max_pressure", 1e-6, "max. pressure [MPa]"),
              ("creep_force_x", 1e-3, "creep force Fx\non the wheel [kN]"),
              ("creep_force_y", 1e-3, "creep force Fy\non the wheel [kN]"),
              (FLASH, 1.0, "flash temperature\n(max. surface) [°C]"))
#: lateral shifts [m] whose patches are drawn on the rail profile (tread, the jump towards the flange, flange)
SHAPE_SHIFTS = (0.0, 5e-3, 6.5e-3)


@dataclass(frozen=True)
class PatchValue:
    """One patch of one run: its number (1 = the closest), role ("tread", "flange", or "" without a contact
    angle) and values (SI; the flash temperature the hotter body's) of :data:`QUANTITIES` the run has."""

    patch: int
    role: str
    values: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        return f"{self.role} patch" if self.role else f"patch {self.patch}"


@dataclass(frozen=True)
class PatchError:
    """The signed flash temperature error [1] of one patch against the reference method's same patch, and where
    it comes from: ``stored`` (metrics.nc's, taken against ``reference``, e.g. "method:kalker") or from the two
    run files' values (``stored`` False, ``reference`` the method's run files)."""

    error: float
    reference: str
    stored: bool


def role_of(angle: float | None) -> str:
    """"flange" for |angle| >= :data:`FLANGE_ANGLE` [rad], else "tread" ("" for no angle)."""
    if angle is None or not math.isfinite(angle):
        return ""
    return "flange" if abs(angle) >= FLANGE_ANGLE else "tread"


def _profile_scenes(data: StudyData) -> list[tuple[str, float, str, object]]:
    """(side, lateral shift [m], scene, patch key: 1, 2, 3 or "all") of the scenes with a wheelset on profiles."""
    out = []
    for s in data.scenes:
        sc = data.scene[s].scene
        pc = getattr(sc, "profile_contact", None)
        if pc is None:
            continue
        ws = (getattr(sc, "source", None) or {}).get("wheelset") or {}
        shift = data.scene[s].sweep.get("wheelset.lateral_shift", ws.get("lateral_shift", 0.0))
        out.append((pc.side, float(shift), s, getattr(pc, "patch", 1)))
    return out


def _by_side(rows) -> dict[str, list[tuple[float, str]]]:
    out: dict[str, list] = {}
    for side, shift, s, _ in rows:
        out.setdefault(side, []).append((shift, s))
    return {side: sorted(out[side]) for side in SIDES if side in out}


def wheelset_scenes(data: StudyData) -> dict[str, list[tuple[float, str]]]:
    """Wheel side -> [(lateral shift [m], scene)] of the contacts drawn against the shift, by shift: the scenes of
    all patches (``patch = "all"``) when the study has them (its scenes of one patch then only give the patch
    shapes, :func:`shape_scenes`), else every scene with a wheelset on profiles."""
    rows = _profile_scenes(data)
    if any(p == "all" for *_, p in rows):
        rows = [r for r in rows if r[3] == "all"]
    return _by_side(rows)


def shape_scenes(data: StudyData) -> dict[str, list[tuple[float, str]]]:
    """Wheel side -> [(lateral shift [m], scene)] at :data:`SHAPE_SHIFTS` whose runs may keep a pressure field, by
    shift, at each shift the scenes of every patch (``patch = "all"``: each patch's field with its share of the
    load) before the scenes of one patch (the whole vertical force on that patch)."""
    rows = [r for r in _profile_scenes(data) if any(abs(r[1] - x) < 1e-9 for x in SHAPE_SHIFTS)]
    rows.sort(key=lambda r: (r[0], r[1], r[3] != "all", r[2]))
    out: dict[str, list] = {}
    for side, shift, s, _ in rows:
        out.setdefault(side, []).append((shift, s))
    return {side: out[side] for side in SIDES if side in out}


def reference_method(data: StudyData, scenes) -> str | None:
    """The study's reference method when it is one of the methods that ran (else None)."""
    for _, s in scenes:
        ref = data.scene[s].reference_kind
        ref = ref.split(":", 1)[1] if ref.startswith("method:") else ref
        if ref in data.methods:
            return ref
    return None


def _scalar(da) -> float | None:
    v = np.asarray(da.values, float).ravel()
    if not v.size or not np.all(np.isfinite(v)):
        return None
    return float(v.max()) if v.size > 1 else float(v[0])   # the hotter body's for a per-body quantity


def patch_values(data: StudyData, scene: str, method: str) -> list[PatchValue]:
    """The patches of the method's finest successful run of ``scene`` ([] without one), by patch number."""
    r = data.finest_result(scene, method)
    ds = data.run_file(scene, method, r.level) if r is not None else None
    if ds is None:
        return []
    if "patch" in ds.dims:
        numbers = [int(p) for p in ds["patch"].values]
    else:
        given = ds.attrs.get("wheelset_patch", 1)
        numbers = [int(given) if str(given).isdigit() else 1]
    out = []
    for k in numbers:
        values = {}
        for q, *_ in QUANTITIES:
            if q in ds:
                da = ds[q].sel(patch=k) if "patch" in ds[q].dims else ds[q]
                v = _scalar(da)
                if v is not None:
                    values[q] = v
        out.append(PatchValue(k, role_of(values.get("contact_angle")), values))
    return out


def _bulk(data: StudyData, scene: str) -> float:
    try:
        return float(data.scene[scene].scene.wheel.bulk_temperature)
    except AttributeError:
        return 0.0


def patch_error(data: StudyData, scene: str, method: str, ref: str, mine: PatchValue,
                theirs: PatchValue | None) -> PatchError:
    """The flash temperature error of ``method``'s patch ``mine`` against ``ref``'s same patch ``theirs``:
    metrics.nc's when it was taken against ``ref`` (per patch for a result with several patches, its sign that of
    the difference of the hotter bodies' values), else from the run files' values (rise above the bulk)."""
    r = data.finest_result(scene, method)
    tag = r.references.get(FLASH, "") if r is not None else ""
    v = mine.values.get(FLASH)
    rv = theirs.values.get(FLASH) if theirs is not None else None
    if r is not None and tag == f"method:{ref}":
        if FLASH in r.patch_errors:
            e = r.patch_errors[FLASH].get(mine.patch, math.nan)
            if math.isfinite(e) and v is not None and rv is not None:
                return PatchError(math.copysign(e, v - rv), tag, True)
            return PatchError(e, tag, True)
        if FLASH in r.signed:
            return PatchError(r.signed[FLASH], tag, True)
    if v is None or rv is None:
        return PatchError(math.nan, "", False)
    return PatchError(relative_error(v, rv, _bulk(data, scene)), f"run files of {ref}", False)
