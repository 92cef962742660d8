"""The report's section for wheelsets on real profiles: the patches and their flash temperature against the
wheelset's lateral shift (the Manchester benchmark kind of study, ``studies/manchester_a22.toml``).

Shown when scenes have a wheelset on profiles (``wheelset`` with ``wheel_profile``/``rail_profile``; their
results carry the patch quantities of docs/DESIGN.md "Result schema"): per wheel side, one curve per method
(chain) and patch (tread, flange) at the method's finest successful level against the lateral shift
(:mod:`.wheelset_figures`), the patches at :data:`~.wheelset_data.SHAPE_SHIFTS` on the rail profile, a table per
contact and patch with each method's flash temperature error against the study's reference method, and the
shifts where a method is off the reference (:func:`wheelset_findings`); :func:`wheelset_section` lists them.

The report computes no physics: every value is a run file's or ``metrics.nc``'s (:mod:`.wheelset_data`), and
the rail profile the scene's (:attr:`railtherm.input.wheelset_profile.ProfileContact.rail_section`).
"""
from __future__ import annotations

import math

from .document import Document
from .format import num, pct
from .load import StudyData
from .wheelset_data import (FLANGE_ANGLE, FLASH, SHAPE_SHIFTS, PatchError, patch_error, patch_values,
                            reference_method, shape_scenes, wheelset_scenes)
from .wheelset_figures import curve_panels, curves_figure, patch_shapes, rail_of, shapes_figure

__all__ = ["wheelset_scenes", "wheelset_findings", "wheelset_section", "ANCHOR"]

ANCHOR = "wheelset-on-profiles"
ROLES = ("tread", "flange", "")


def _spans(shifts: list[float], flagged: set[float]) -> str:
    """'5.5–7, 9': the flagged shifts [m] as runs of neighbours in ``shifts`` (sorted), in mm."""
    runs, cur = [], []
    for x in shifts:
        if x in flagged:
            cur.append(x)
        elif cur:
            runs.append(cur)
            cur = []
    if cur:
        runs.append(cur)
    return ", ".join(f"{num(r[0] * 1e3)}" + (f"–{num(r[-1] * 1e3)}" if len(r) > 1 else "") for r in runs)


def _compared(data: StudyData, members, method: str, ref: str) -> list[tuple]:
    """[(shift [m], scene, method's PatchValue, ref's PatchValue, PatchError)] of every patch of ``members`` that
    both methods have (matched by patch number)."""
    out = []
    for x, s in members:
        theirs = {pv.patch: pv for pv in patch_values(data, s, ref)}
        for pv in patch_values(data, s, method):
            out.append((x, s, pv, theirs.get(pv.patch), patch_error(data, s, method, ref, pv, theirs.get(pv.patch))))
    return out


def _where(rows, tol: float) -> str:
    """'0–0.5 mm (tread patch) and 7.5–10 mm (flange patch)': per patch role, the shifts off by more than
    ``tol`` (runs of neighbours among the shifts where that role has a patch)."""
    parts = []
    for role in ROLES:
        mine = [(x, e) for x, _, pv, _, e in rows if pv.role == role and math.isfinite(e.error)]
        off = {x for x, e in mine if abs(e.error) > tol}
        if off:
            parts.append(f"{_spans(sorted({x for x, _ in mine}), off)} mm ({role + ' patch' if role else 'patch'})")
    return " and ".join(parts)


def _sources(rows, ref: str, ref_level) -> str:
    """The sentence saying which reference the errors of ``rows`` were taken against."""
    stored = sorted({e.reference for *_, e in rows if e.stored and math.isfinite(e.error)})
    files = sum(1 for *_, e in rows if not e.stored and math.isfinite(e.error))
    level = f" (level {ref_level})" if ref_level is not None else ""
    parts = []
    if stored:
        n = sum(1 for *_, e in rows if e.stored and math.isfinite(e.error))
        parts.append(f"{n} patch errors are metrics.nc's (reference " + ", ".join(f"`{t}`" for t in stored)
                     + f": `{ref}`'s finest successful level{level}, each patch against its same patch)")
    if files:
        parts.append(f"{files} are taken from the run files' values (metrics.nc has no error against `{ref}` "
                     "for them)")
    return "Reference of the errors: " + "; ".join(parts) + "." if parts else ""


def _finding(data: StudyData, groups, m: str, ref: str, tol: float, link: bool) -> tuple[str, str] | None:
    """One method's key finding and the sentence on its errors' reference (see :func:`wheelset_findings`), None
    when no patch is compared."""
    per_side = {side: _compared(data, members, m, ref) for side, members in groups.items()}
    rows = [(side, *r) for side, rs in per_side.items() for r in rs if math.isfinite(r[4].error)]
    if not rows:
        return None
    where = f"[`{m}`](#{ANCHOR})" if link else f"`{m}`"
    parts = [f"{w} on the {side} wheel" for side, rs in per_side.items() for w in [_where(rs, tol)] if w]
    side, x, s, pv, rv, e = max(rows, key=lambda r: abs(r[5].error))
    hot = max(rows, key=lambda r: r[4].values.get(FLASH, -math.inf) if r[4] is not None else -math.inf)
    at = lambda r: f"{num(r[1] * 1e3)} mm, {r[0]} wheel, {r[3].label}"
    ref_r = next((data.finest_result(r[2], ref) for r in rows), None)
    sources = _sources([r[1:] for r in rows], ref, ref_r.level if ref_r is not None else None)
    if parts:
        text = (f"On the wheelset on profiles, the flash temperature of {where} is more than {pct(tol)} off the exact "
                f"chain `{ref}` at lateral shifts {'; '.join(parts)} (largest {pct(e.error, signed=True)} at "
                f"{at((side, x, s, pv))}, where `{ref}` gives {num(rv.values.get(FLASH), 3)} °C")
    else:
        text = (f"On the wheelset on profiles, the flash temperature of {where} is within {pct(tol)} of the exact "
                f"chain `{ref}` on every patch at every lateral shift ({len(rows)} patches (largest "
                f"{pct(e.error, signed=True)} at {at((side, x, s, pv))}")
    if hot is not None and hot[4] is not None and hot[4].values.get(FLASH) is not None:
        text += (f"; at the hottest contact, {at(hot[:4])}, {num(hot[4].values[FLASH], 3)} °C, it is "
                 f"{pct(hot[5].error, signed=True)}")
    return text + (")." if parts else "))."), sources


def wheelset_findings(data: StudyData, link: bool = True) -> list[str]:
    """One sentence per method other than the reference: the lateral shifts (per wheel and patch role) at which
    its flash temperature is more than the study's tolerance off the reference method's same patch, the largest
    error, the error at the hottest contact, and which reference the errors were taken against (``link``: the
    method's name links to the section)."""
    groups = wheelset_scenes(data)
    if not groups or data.tolerance is None:
        return []
    ref = reference_method(data, [x for g in groups.values() for x in g])
    if ref is None:
        return []
    out = []
    for m in [m for m in data.methods if m != ref]:
        found = _finding(data, groups, m, ref, float(data.tolerance), link)
        if found:
            out.append(found[0] + (" " + found[1] if found[1] else ""))
    return out


def _rows(data: StudyData, groups, methods, ref) -> list[list[str]]:
    """One row per contact and patch: the first method's (the reference's) position and angle, the normal force,
    and each method's maximum pressure, flash temperature and (not the reference) its error against the
    reference."""
    rows = []
    for side, members in groups.items():
        for x, s in members:
            per = {m: {pv.patch: pv for pv in patch_values(data, s, m)} for m in methods}
            for k in sorted({k for v in per.values() for k in v}):
                first = next(v[k] for v in per.values() if k in v)
                g = first.values.get
                row = [side, num(x * 1e3), f"{k} {first.role}" if first.role else str(k),
                       num(g("contact_position_rail") * 1e3, 4) if g("contact_position_rail") is not None else "–",
                       num(g("contact_angle"), 3) if g("contact_angle") is not None else "–",
                       num(g("normal_force") * 1e-3, 3) if g("normal_force") is not None else "–"]
                for m in methods:
                    pv = per[m].get(k)
                    p0, t = (pv.values.get(q) if pv else None for q in ("max_pressure", FLASH))
                    row += [num(p0 * 1e-6) if p0 is not None else "–", num(t, 4) if t is not None else "–"]
                    if m != ref:
                        e = patch_error(data, s, m, ref, pv, per[ref].get(k)) if ref and pv else PatchError(
                            math.nan, "", False)
                        row.append(pct(e.error, signed=True) if math.isfinite(e.error) else "–")
                rows.append(row)
    return rows


def _draw_shapes(doc: Document, ctx, methods: list[str], reference: str):
    """The patch-shapes figure, or a note saying why it is not drawn."""
    groups = shape_scenes(ctx.data)
    shapes = patch_shapes(ctx.data, groups, methods)
    if not shapes:
        if groups or wheelset_scenes(ctx.data):
            doc.paragraph("The patch shapes are not drawn: no run at lateral shifts "
                          + ", ".join(num(x * 1e3) for x in SHAPE_SHIFTS) + " mm keeps its pressure field (the "
                          "scenes do not ask the output `pressure`).", note=True)
        return
    rails = {side: next((r for _, s in groups[side] for r in [rail_of(ctx.data, s)] if r is not None), None)
             for side in shapes}
    missing = [side for side, r in rails.items() if r is None]
    if missing:
        doc.paragraph(f"The patch shapes are not drawn: the {missing[0]} wheel's scene keeps no rail profile "
                      "(the study file was not at hand).", note=True)
        return
    ctx.draw(doc, "wheelset-patch-shapes", _shapes_caption(shapes, methods, reference), shapes_figure, rails,
             shapes, reference)


def _shapes_caption(shapes, methods, reference) -> str:
    several = sorted({(side, sh.shift) for side, v in shapes.items() for sh in v if sh.patch > 1})
    where = ", ".join(f"{num(x * 1e3)} mm on the {side} wheel" for side, x in several)
    others = ", ".join(f"`{m}`" for m in methods if m != reference) or "other methods"
    whole = sorted({(side, sh.shift) for side, v in shapes.items() for sh in v if not sh.shared})
    text = ("The patches at lateral shifts " + ", ".join(num(x * 1e3) for x in SHAPE_SHIFTS) + " mm on the rail "
            f"profile: the lateral extent of each patch of `{reference}` on the profile and the contact search's "
            "reference point "
            f"(top), and the cells in contact seen from above (bottom; `{reference}` filled, {others} outlined "
            "dashed; the contact plane's lateral coordinate projected on the rail's). ")
    if not whole:
        return text + ("Each patch is drawn from its own pressure field in the result of every patch of the wheel "
                       "(`wheelset.patch = \"all\"`), carrying its own share of the wheel's vertical force (N in "
                       "the legend)" + (f"; the wheel has several patches at {where}" if several else "") + ".")
    at = ", ".join(f"{num(x * 1e3)} mm on the {side} wheel" for side, x in whole)
    return text + (f"At {at} the patch is a scene of one patch carrying the wheel's whole vertical force (the study "
                   "has no result of every patch there that keeps its pressure field)"
                   + (f"; where the wheel has several patches, at {where}, they share it and the drawn patches are "
                      "larger than the shared ones" if several else "") + ".")


def _intro(doc: Document, groups, ref):
    n = sum(len(g) for g in groups.values())
    doc.paragraph(f"{n} contacts of a wheelset on real profiles, each method at its finest successful level, each "
                  "patch of a wheel on its own (tread patch: |contact angle| below "
                  f"{num(FLANGE_ANGLE)} rad; flange patch: from it). The contact position (in the rail profile's "
                  "own coordinates) and contact angle are each method's patch reference point (the run's attribute "
                  "wheelset_reference_point: the exact chain the CONTACT program's, a Hertz-based chain the contact "
                  "search's); the normal force is each method's own: the exact chain meets the wheel's vertical force "
                  "with its own creep forces (the run's attribute wheelset_vertical_balance), a Hertz-based chain "
                  "keeps the contact search's estimate of them (Shen-Hedrick-Elkins); forces are on the wheel (the CONTACT program reports them on the rail, with the "
                  "opposite sign); the left wheel is in its own mirrored axes. The flash temperature is the hotter "
                  "body's maximum surface temperature"
                  + (f"; its error against the study's reference `{ref}` is metrics.nc's, patch by patch (the "
                     "largest over both bodies of the difference in rise above the bulk temperature, relative to "
                     "the reference patch's larger rise)." if ref else "."))


def wheelset_section(doc: Document, ctx):
    """Write the section (nothing when no scene has a wheelset on profiles).

    For each wheel side, with one curve per method (chain) and patch role (tread, flange) at the method's
    finest successful level, against the lateral shift [mm] of the wheelset:

    * the contact position on the rail [mm] (rail profile's own coordinates) and the contact angle [rad] (each
      chain's patch reference point) and the normal force [kN] (each chain's own: the exact chain balances the
      wheel's vertical force with its own creep forces, a Hertz-based chain keeps the search's estimate);
    * the maximum pressure [MPa], the creep forces Fx, Fy on the wheel [kN] (the CONTACT program reports them
      on the rail: minus these) and the flash temperature, the hotter body's maximum surface temperature [°C];
    * the patches at the lateral shifts :data:`~.wheelset_data.SHAPE_SHIFTS` (0, 5 and 6.5 mm: tread, the jump
      towards the flange, flange) drawn on the rail profile and seen from above;
    * a table of the same per contact and patch (collapsed), with each method's flash temperature error against
      the study's reference method (``metrics.nc``'s, per patch);
    * the key finding (:func:`wheelset_findings`, also among the verdict's key findings): the shifts at which a
      method's flash temperature is more than the study's tolerance off the reference (the Hertz + FASTSIM
      chains against the exact chain ``kalker`` in the benchmark study), and the reference of those errors.
    """
    data = ctx.data
    groups = wheelset_scenes(data)
    methods = [m for m in data.methods if any(data.finest_result(s, m) for g in groups.values() for _, s in g)]
    if not groups or not methods:
        return
    ref = reference_method(data, [x for g in groups.values() for x in g])
    methods = ([ref] if ref in methods else []) + [m for m in methods if m != ref]
    doc.heading(2, "Wheelset on profiles: the patches and their flash temperature against lateral shift", ANCHOR)
    _intro(doc, groups, ref)
    for text in wheelset_findings(data, link=False):
        doc.paragraph("**Key finding:** " + text)
    panels = {side: curve_panels(data, members, methods) for side, members in groups.items()}
    ctx.draw(doc, "wheelset-against-shift", "Per patch (tread: solid lines, filled markers; flange: dashed, open "
             "markers) against the wheelset's lateral shift, one curve per method (colour): contact position on "
             "the rail, contact angle, normal force, maximum pressure, creep forces on the wheel and flash "
             "temperature.", curves_figure, panels, methods, ctx.palette)
    _draw_shapes(doc, ctx, methods, ref or methods[0])
    head = ["wheel", "shift [mm]", "patch", "y on rail [mm]", "angle [rad]", "N [kN]"]
    for m in methods:
        head += [f"`{m}` p0 [MPa]", f"`{m}` T_max [°C]"] + ([f"`{m}` ΔT_max [%]"] if m != ref else [])
    rows = _rows(data, groups, methods, ref)
    with doc.details(f"The patches contact by contact as a table ({len(rows)} rows)"):
        doc.table("Per contact and patch: " + (f"`{ref}`'s" if ref else "the first method's") + " position on "
                  "the rail, contact angle (its patch reference point) and normal force; each method's maximum pressure, flash temperature (the hotter body's) and its error "
                  "against " + (f"`{ref}`" if ref else "the reference") + f" (tolerance {pct(data.tolerance)}).",
                  head, rows)
