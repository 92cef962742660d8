"""The report's section for wheelsets on real profiles: the patch and its flash temperature against the
wheelset's lateral shift (the Manchester benchmark kind of study, ``studies/manchester_a22.toml``).

Shown when scenes have a wheelset on profiles (``wheelset`` with ``wheel_profile``/``rail_profile``; their
results carry the patch quantities of docs/DESIGN.md "Result schema"): per wheel side, one curve per method
(chain) at its finest successful level against the lateral shift, a table of the same with each method's flash
temperature error against the study's reference method, the reference's patches at :data:`SHAPE_SHIFTS`, and
the shifts where a method is off the reference (:func:`wheelset_findings`); :func:`wheelset_section` lists them.

The report computes no physics: every value is a run file's or ``metrics.nc``'s, and the rail profile the
scene's (:attr:`railtherm.input.wheelset_profile.ProfileContact.rail_section`).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .document import Document
from .exact_contact import _value, relative_error, stored_error
from .figures import figure, save
from .format import num, pct
from .load import StudyData

__all__ = ["wheelset_scenes", "wheelset_findings", "wheelset_section", "ANCHOR"]

ANCHOR = "wheelset-on-profiles"
SIDES = ("right", "left")
#: the plotted quantities: (result variable, factor from SI, axis label)
QUANTITIES = (("contact_position_rail", 1e3, "contact position on the rail [mm]"),
              ("contact_angle", 1.0, "contact angle [rad]"),
              ("max_pressure", 1e-6, "max. pressure [MPa]"),
              ("creep_force_x", 1e-3, "Fx on the wheel [kN]"),
              ("creep_force_y", 1e-3, "Fy on the wheel [kN]"),
              ("max_surface_temperature", 1.0, "flash temperature [°C]"))


def wheelset_scenes(data: StudyData) -> dict[str, list[tuple[float, str]]]:
    """Wheel side -> [(lateral shift [m], scene)] of the scenes with a wheelset on profiles, by shift."""
    out: dict[str, list] = {}
    for s in data.scenes:
        sc = data.scene[s].scene
        pc = getattr(sc, "profile_contact", None)
        if pc is None:
            continue
        ws = (getattr(sc, "source", None) or {}).get("wheelset") or {}
        shift = data.scene[s].sweep.get("wheelset.lateral_shift", ws.get("lateral_shift", 0.0))
        out.setdefault(pc.side, []).append((float(shift), s))
    return {side: sorted(out[side]) for side in SIDES if side in out}


def _reference(data: StudyData, scenes) -> str | None:
    """The study's reference method when it is one of the methods that ran (else None)."""
    for _, s in scenes:
        ref = data.scene[s].reference_kind
        ref = ref.split(":", 1)[1] if ref.startswith("method:") else ref
        if ref in data.methods:
            return ref
    return None


def _flash(data: StudyData, scene: str, method: str) -> float | None:
    """The hotter body's maximum surface temperature [degC] of the method's finest successful level, or None."""
    r = data.finest_result(scene, method)
    ds = data.run_file(scene, method, r.level) if r is not None else None
    if ds is None or "max_surface_temperature" not in ds:
        return None
    v = np.asarray(ds["max_surface_temperature"].values, float)
    return float(np.max(v)) if v.size and np.all(np.isfinite(v)) else None


def _point(data: StudyData, scene: str, method: str, q: str) -> float | None:
    """The plotted value of ``q`` (SI; the flash temperature the hotter body's), or None."""
    if q == "max_surface_temperature":
        return _flash(data, scene, method)
    v = _value(data, scene, method, q)
    return None if v is None else v[0]


def _bulk(data: StudyData, scene: str) -> float:
    try:
        return float(data.scene[scene].scene.wheel.bulk_temperature)
    except AttributeError:
        return 0.0


def _error(data: StudyData, scene: str, method: str, ref: str) -> float:
    """The flash temperature's signed error of ``method`` against ``ref``: metrics.nc's, else from the run files'
    hotter bodies' rises above the bulk temperature."""
    e = stored_error(data, scene, method, "max_surface_temperature", ref)
    if math.isfinite(e):
        return e
    v, r = _flash(data, scene, method), _flash(data, scene, ref)
    return relative_error(v, r, _bulk(data, scene)) if v is not None and r is not None else math.nan


def _spans(shifts: list[float], flagged: set[float]) -> str:
    """'5.5-7 mm, 9 mm': the flagged shifts [m] as runs of neighbours in ``shifts`` (sorted)."""
    runs, cur = [], []
    for x in shifts:
        if x in flagged:
            cur.append(x)
        elif cur:
            runs.append(cur)
            cur = []
    if cur:
        runs.append(cur)
    text = [f"{num(r[0] * 1e3)}" + (f"–{num(r[-1] * 1e3)}" if len(r) > 1 else "") for r in runs]
    return ", ".join(text) + " mm"


def wheelset_findings(data: StudyData, link: bool = True) -> list[str]:
    """One sentence per method other than the reference: the lateral shifts (per wheel) at which its flash
    temperature is more than the study's tolerance off the reference method's, with the largest error
    (``link``: the method's name links to the section)."""
    groups = wheelset_scenes(data)
    if not groups or data.tolerance is None:
        return []
    ref = _reference(data, [x for g in groups.values() for x in g])
    if ref is None:
        return []
    tol = float(data.tolerance)
    out = []
    for m in [m for m in data.methods if m != ref]:
        parts, worst, compared = [], (0.0, None, None), 0
        for side, members in groups.items():
            errs = {x: _error(data, s, m, ref) for x, s in members}
            errs = {x: e for x, e in errs.items() if math.isfinite(e)}
            compared += len(errs)
            off = {x for x, e in errs.items() if abs(e) > tol}
            if off:
                parts.append(f"{_spans(sorted(errs), off)} on the {side} wheel")
            for x, s in members:
                if x in errs and abs(errs[x]) > abs(worst[0]):
                    worst = (errs[x], (x, side), s)
        if not compared:
            continue
        where = f"[`{m}`](#{ANCHOR})" if link else f"`{m}`"
        if parts:
            x, side = worst[1]
            out.append(f"On the wheelset on profiles, the flash temperature of {where} is more than {pct(tol)} off "
                       f"the exact chain `{ref}` at lateral shifts {'; '.join(parts)} (largest "
                       f"{pct(worst[0], signed=True)} at {num(x * 1e3)} mm, {side} wheel, where `{ref}` gives "
                       f"{num(_flash(data, worst[2], ref), 3)} °C).")
        else:
            out.append(f"On the wheelset on profiles, the flash temperature of {where} is within {pct(tol)} of the "
                       f"exact chain `{ref}` at every lateral shift ({compared} contacts).")
    return out


def _curves(data: StudyData, members, methods) -> dict:
    """quantity -> method -> [(shift [mm], value in the plotted unit)]."""
    out = {}
    for q, factor, _ in QUANTITIES:
        out[q] = {}
        for m in methods:
            pts = [(x * 1e3, v * factor) for x, s in members for v in [_point(data, s, m, q)] if v is not None]
            if pts:
                out[q][m] = pts
    return out


def _figure(panels, methods, palette, *, path: Path):
    """One column per wheel side, one row per quantity, one curve per method against the lateral shift."""
    sides = list(panels)
    rows, cols = len(QUANTITIES), len(sides)
    fig = figure(10, 1.9 * rows + 0.7)
    axes = np.asarray(fig.subplots(rows, cols, squeeze=False, sharex="col"))
    handles = {}
    for j, side in enumerate(sides):
        for i, (q, _, ylabel) in enumerate(QUANTITIES):
            ax = axes[i, j]
            for m in methods:
                pts = panels[side].get(q, {}).get(m)
                if not pts:
                    continue
                (h,) = ax.plot([p[0] for p in pts], [p[1] for p in pts], **palette.style(m), label=m)
                handles.setdefault(m, h)
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            if i == 0:
                ax.set_title(f"{side} wheel", fontsize=9)
            if i == rows - 1:
                ax.set_xlabel("lateral shift of the wheelset [mm]", fontsize=8)
    fig.legend(handles=list(handles.values()), loc="outside lower center", ncol=min(len(handles), 4), fontsize=8,
               frameon=False)
    return save(fig, path)


def _rows(data: StudyData, groups, methods, ref) -> list[list[str]]:
    rows = []
    for side, members in groups.items():
        for x, s in members:
            y, angle = (next((v for m in methods for v in [_point(data, s, m, q)] if v is not None), None)
                        for q in ("contact_position_rail", "contact_angle"))
            row = [side, num(x * 1e3), num(y * 1e3, 4) if y is not None else "–",
                   num(angle, 3) if angle is not None else "–"]
            for m in methods:
                p0, t = _point(data, s, m, "max_pressure"), _flash(data, s, m)
                row += [num(p0 * 1e-6) if p0 is not None else "–", num(t, 4) if t is not None else "–"]
                if m != ref:
                    row.append(pct(_error(data, s, m, ref), signed=True) if ref else "–")
            rows.append(row)
    return rows


# -- the patch shapes on the rail profile ---------------------------------------------------------------------
#: lateral shifts [m] whose patches are drawn on the rail profile (tread, the jump towards the flange, flange)
SHAPE_SHIFTS = (0.0, 5e-3, 6.5e-3)
SHAPE_COLOURS = ("#1f77b4", "#ff7f0e", "#d62728")


def _rail(data: StudyData, scene: str):
    """(y, z) [m] of the scene's rail profile in its own coordinates, as the scene keeps it (None without)."""
    section = getattr(getattr(data.scene[scene].scene, "profile_contact", None), "rail_section", None)
    if not section or not len(section[0]):
        return None
    return np.asarray(section[0], float), np.asarray(section[1], float)


def _shapes(data: StudyData, groups, method: str) -> dict:
    """side -> [(shift [m], reference point (y, z) on the rail [m], patch outline data)] at :data:`SHAPE_SHIFTS`:
    the method's cells with pressure in the rail profile's lateral coordinate y = y0 + s cos(delta0) (s across
    the contact plane, y0 and delta0 the plane's origin and angle) and x."""
    out = {}
    for side, members in groups.items():
        for shift in SHAPE_SHIFTS:
            s = next((sc for x, sc in members if abs(x - shift) < 1e-9), None)
            r = data.finest_result(s, method) if s is not None else None
            ds = data.run_file(s, method, r.level) if r is not None else None
            if ds is None or "pressure" not in ds or "y" not in ds.dims:
                continue
            pc = data.scene[s].scene.profile_contact
            y = pc.plane_position_rail + np.asarray(ds["y"].values, float) * math.cos(pc.plane_angle)
            p = np.asarray(ds["pressure"].transpose("x", "y").values, float)
            out.setdefault(side, []).append((shift, (pc.contact_position_rail, pc.contact_height_rail),
                                             (y, np.asarray(ds["x"].values, float), p > 0.0)))
    return out


def _shape_figure(rails, shapes, *, path: Path):
    """Per wheel side: the rail profile with each patch's lateral extent and reference point (top), and the
    patches seen from above on the rail head (bottom)."""
    sides = list(shapes)
    fig = figure(10, 6.2)
    axes = np.asarray(fig.subplots(2, len(sides), squeeze=False, height_ratios=[1, 1.4]))
    for j, side in enumerate(sides):
        top, plan = axes[0, j], axes[1, j]
        ry, rz = rails[side]
        top.plot(ry * 1e3, rz * 1e3, color="0.3", lw=1.0)
        for k, (shift, (y0, z0), (y, x, inside)) in enumerate(shapes[side]):
            c = SHAPE_COLOURS[k % len(SHAPE_COLOURS)]
            cols = inside.any(axis=0)
            yy = np.linspace(y[cols].min(), y[cols].max(), 50)
            top.plot(yy * 1e3, np.interp(yy, ry, rz) * 1e3, color=c, lw=4, solid_capstyle="butt",
                     label=f"shift {num(shift * 1e3)} mm")
            top.plot([y0 * 1e3], [z0 * 1e3], "o", color=c, ms=4)
            plan.contourf(y * 1e3, x * 1e3, inside.astype(float), levels=[0.5, 1.5], colors=[c], alpha=0.6)
            plan.contour(y * 1e3, x * 1e3, inside.astype(float), levels=[0.5], colors=[c], linewidths=0.8)
        top.invert_yaxis()
        top.set_title(f"{side} wheel: rail profile (z down) and patches", fontsize=9)
        top.set_ylabel("z [mm]", fontsize=8)
        plan.set_xlabel("lateral position on the rail, rail profile's coordinates [mm]", fontsize=8)
        plan.set_ylabel("x, rolling direction [mm]", fontsize=8)
        plan.set_xlim(top.get_xlim())
        for ax in (top, plan):
            ax.grid(True, alpha=0.3)
            ax.tick_params(labelsize=7)
        top.legend(fontsize=7, frameon=False)
    return save(fig, path)


def _draw_shapes(doc: Document, ctx, groups, method: str):
    """The patch-shapes figure, or a note saying why it is not drawn."""
    shapes = _shapes(ctx.data, groups, method)
    if not shapes:
        return
    rails = {side: next((r for _, s in groups[side] for r in [_rail(ctx.data, s)] if r is not None), None)
             for side in shapes}
    missing = [side for side, r in rails.items() if r is None]
    if missing:
        doc.paragraph(f"The patch shapes are not drawn: the {missing[0]} wheel's scene keeps no rail profile "
                      "(the study file was not at hand).", note=True)
        return
    ctx.draw(doc, "wheelset-patch-shapes", f"The patches of `{method}` at lateral shifts "
             + ", ".join(f"{num(x * 1e3)}" for x in SHAPE_SHIFTS) + " mm on the rail profile: the lateral extent of "
             "each patch on the profile and its reference point (top), and the cells in contact seen from above "
             "(bottom; the contact plane's lateral coordinate projected on the rail's).", _shape_figure, rails, shapes)


def wheelset_section(doc: Document, ctx):
    """Write the section (nothing when no scene has a wheelset on profiles).

    For each wheel side, with one curve per method (chain) at its finest successful level, against the lateral
    shift [mm] of the wheelset:

    * the contact position on the rail [mm] (rail profile's own coordinates) and the contact angle [rad] (the
      contact search's, the same for every chain);
    * the maximum pressure [MPa], the creep forces Fx, Fy on the wheel [kN] (the CONTACT program reports them
      on the rail: minus these) and the flash temperature, the hotter body's maximum surface temperature [°C];
    * a table of the same per shift, with each method's flash temperature error against the study's reference
      method (``metrics.nc``'s, the scorecard's number: the largest over both bodies of the difference in rise
      above the bulk temperature, relative to the reference's larger rise);
    * the patches of the reference method at the lateral shifts :data:`SHAPE_SHIFTS` (0, 5 and 6.5 mm: tread,
      the jump towards the flange, flange) drawn on the rail profile and seen from above;
    * the key finding (:func:`wheelset_findings`, also among the verdict's key findings): the shifts at which a
      method's flash temperature is more than the study's tolerance off the reference (the Hertz + FASTSIM
      chains against the exact chain ``kalker`` in the benchmark study).
    """
    data = ctx.data
    groups = wheelset_scenes(data)
    methods = [m for m in data.methods if any(data.finest_result(s, m) for g in groups.values() for _, s in g)]
    if not groups or not methods:
        return
    ref = _reference(data, [x for g in groups.values() for x in g])
    methods = ([ref] if ref in methods else []) + [m for m in methods if m != ref]
    doc.heading(2, "Wheelset on profiles: the patch and its flash temperature against lateral shift", ANCHOR)
    n = sum(len(g) for g in groups.values())
    doc.paragraph(f"{n} contacts of a wheelset on real profiles, each method at its finest successful level. The "
                  "contact position (in the rail profile's own coordinates) and the contact angle are the contact "
                  "search's, the same for every method; forces are on the wheel (the CONTACT program reports them "
                  "on the rail, with the opposite sign); the left wheel is in its own mirrored axes. The flash "
                  "temperature is the hotter body's maximum surface temperature"
                  + (f"; its error against the study's reference `{ref}` is the scorecard's (the largest over both "
                     "bodies of the difference in rise above the bulk temperature, relative to the reference's larger "
                     "rise)." if ref else "."))
    for text in wheelset_findings(data, link=False):
        doc.paragraph("**Key finding:** " + text)
    panels = {side: _curves(data, members, methods) for side, members in groups.items()}
    ctx.draw(doc, "wheelset-against-shift", "Contact position, contact angle, maximum pressure, creep forces on the "
             "wheel and flash temperature against the wheelset's lateral shift, one curve per method.", _figure,
             panels, methods, ctx.palette)
    _draw_shapes(doc, ctx, groups, ref or methods[0])
    head = ["wheel", "shift [mm]", "y on rail [mm]", "angle [rad]"]
    for m in methods:
        head += [f"`{m}` p0 [MPa]", f"`{m}` T_max [°C]"] + ([f"`{m}` ΔT_max [%]"] if m != ref else [])
    doc.table("Per contact: the contact search's position on the rail and contact angle; each method's maximum "
              "pressure, flash temperature (the hotter body's) and its error against "
              + (f"`{ref}`" if ref else "the reference") + f" (tolerance {pct(data.tolerance)}).", head,
              _rows(data, groups, methods, ref))
