"""The report's exact-contact section: the contact model's error separated from the thermal model's.

A scene whose reference is a method (``reference = "kalker"``) that runs an exact tangential model is
measured against the exact contact. Per such scene and quantity, at each method's finest successful
level, the section compares the **contact model's error** (same temperature model, other tangential
model: ``green`` against ``kalker``), the **thermal model's error** (same tangential model, other
temperature model: ``fastsim-fdm`` against ``green``) and the **total** (what ``metrics.nc`` records).
It also draws a creepage sweep's creep-force curves, the traction, slip and power-density maps of one
combined-creepage scene, and a scene whose gap is not Hertzian (which only the exact method runs); the
error definitions are in :func:`exact_contact_section`. A result of several patches (a wheelset on profiles with
``wheelset.patch = "all"``) is compared patch by patch: a row per scene, patch and quantity.

The report computes no physics: every value is a run file's, every reference curve ``references.nc``'s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import exact_figures as XF
from .document import Cell, Document
from .format import finite, num, pct, quantity, short
from .format import unit as shown
from ..output.store import patch_numbers
from .load import StudyData

__all__ = ["ExactComparison", "QUANTITIES", "exact_comparisons", "exact_contact_section", "relative_error"]

#: quantity -> (label, unit) in the order of the table; temperatures are the wheel's
QUANTITIES = {
    "creep_force_x": ("creep force Fx", "N"),
    "creep_force_y": ("creep force Fy", "N"),
    "spin_moment": ("spin moment Mz", "N m"),
    "frictional_power": ("frictional power", "W"),
    "max_surface_temperature": ("max. surface temperature (wheel)", "°C"),
    "mean_contact_temperature": ("mean contact temperature (wheel)", "°C"),
}
TEMPERATURES = ("max_surface_temperature", "mean_contact_temperature")
#: |relative error| below this prints as ≈0 (the same contact model gives the same forces to round-off)
ROUND_OFF = 1e-9
#: forces [N] and moments [N m] of the exact contact below this are zero by symmetry (round-off): no row
NEGLIGIBLE = 1e-6


@dataclass
class ExactComparison:
    """The methods of one exact-contact comparison and the scenes measured against the exact method."""

    exact: str                                           # the reference method (exact contact)
    scenes: list[str]
    contact: list[str] = field(default_factory=list)     # same temperature model, other tangential model
    thermal: dict = field(default_factory=dict)          # thermal method -> the contact method it shares a contact with


def _value(data: StudyData, scene: str, method: str, q: str, patch: int | None = None):
    """(value [unit of q], level) at the method's finest successful level, or None; of patch ``patch`` [1] in a
    result of several patches (None: a result without patches; the patch missing: None)."""
    r = data.finest_result(scene, method)
    if r is None:
        return None
    ds = data.run_file(scene, method, r.level)
    if ds is None or q not in ds:
        return None
    da = ds[q]
    if "patch" in da.dims:
        if patch is None or patch not in patch_numbers(ds):
            return None
        da = da.sel(patch=patch)
    v = np.asarray(da.values, float).ravel()
    if v.size == 0 or not np.isfinite(v[0]):
        return None
    return float(v[0]), r.level      # body 0 (the wheel) for per-body quantities


def _patches(data: StudyData, scene: str, method: str) -> list[int | None]:
    """The patches [1] of the method's finest successful run of ``scene`` (``[None]``: a result without
    patches)."""
    r = data.finest_result(scene, method)
    ds = data.run_file(scene, method, r.level) if r is not None else None
    return (patch_numbers(ds) if ds is not None else []) or [None]


def _named(scene: str, patch: int | None) -> str:
    return f"`{scene}`" if patch is None else f"`{scene}` patch {patch}"


def _bulk(data: StudyData, scene: str) -> float:
    sc = data.scene[scene].scene
    try:
        return float(sc.wheel.bulk_temperature)
    except AttributeError:
        return 0.0


def stored_error(data: StudyData, scene: str, method: str, q: str, reference: str, patch: int | None = None) -> float:
    """metrics.nc's signed error of ``q`` at the method's finest successful level when it was taken against
    method ``reference`` (NaN otherwise): the number the run table and the scorecard print. For patch ``patch``
    of a result of several patches, its own error (``patch_errors_<q>``, its magnitude; the caller signs it)."""
    r = data.finest_result(scene, method)
    if r is None or r.references.get(q) != f"method:{reference}":
        return math.nan
    if patch is not None:
        return r.patch_errors.get(q, {}).get(patch, math.nan)
    return r.signed.get(q, math.nan)


def _against(data: StudyData, scene: str, method: str, q: str, value: tuple, ref_method: str, ref: tuple,
             bulk: float, patch: int | None = None) -> float:
    """The signed error of ``method`` against ``ref_method`` on ``q`` (of patch ``patch`` of a result of several
    patches): metrics.nc's where it stores it (a patch's signed as the difference of the two values), else
    (quantities metrics.nc does not score, such as Fy and Mz) from the two run files' values."""
    e = stored_error(data, scene, method, q, ref_method, patch)
    if finite(e) and patch is not None:
        return math.copysign(e, value[0] - ref[0]) if value[0] != ref[0] else 0.0
    return e if finite(e) else relative_error(value[0], ref[0], bulk)


def relative_error(value: float, reference: float, bulk: float = 0.0) -> float:
    """Signed relative error ``(value - reference) / |reference - bulk|`` [1] (NaN for a zero reference)."""
    den = abs(reference - bulk)
    if not den or not math.isfinite(den):
        return math.nan
    return (value - reference) / den


def exact_comparisons(data: StudyData) -> list[ExactComparison]:
    """The exact-contact comparisons of a study: scenes whose reference is a method that ran them with
    a tangential model, and the methods that differ from it in the contact model or in the thermal model."""
    out = []
    refs = {}
    for s in data.scenes:
        kind = data.scene[s].reference_kind
        if kind and kind in data.methods and data.finest_result(s, kind) is not None:
            refs.setdefault(kind, []).append(s)
    for exact, scenes in refs.items():
        st_e = _stages(data, scenes, exact)
        if not st_e.get("tangential"):
            continue
        comp = ExactComparison(exact, scenes)
        others = [m for m in data.methods if m != exact]
        for m in others:
            st = _stages(data, scenes, m)
            if st.get("tangential") and st.get("tangential") != st_e["tangential"] and \
                    st.get("temperature") == st_e.get("temperature"):
                comp.contact.append(m)
        for m in others:
            st = _stages(data, scenes, m)
            for c in comp.contact:
                st_c = _stages(data, scenes, c)
                if m != c and st.get("tangential") == st_c.get("tangential") and st.get("temperature") and \
                        st.get("temperature") != st_c.get("temperature"):
                    comp.thermal.setdefault(m, c)
        out.append(comp)
    return out


def _stages(data: StudyData, scenes: list[str], method: str) -> dict:
    """Stages of ``method`` on the first scene where it ran its temperature stage (else any scene)."""
    found = {}
    for s in scenes:
        st = data.stages(s, method)
        if st.get("temperature"):
            return st
        found = found or st
    return found


def _thermal_scenes(data: StudyData, comp: ExactComparison) -> list[str]:
    """Scenes with temperatures of the exact method (on some patch) and a result of a compared method."""
    return [s for s in comp.scenes
            if any(_value(data, s, comp.exact, q, k) for q in TEMPERATURES for k in _patches(data, s, comp.exact))
            and any(data.finest_result(s, m) is not None for m in comp.contact)]


def error_rows(data: StudyData, comp: ExactComparison) -> tuple[list[str], list[list]]:
    """Header and rows of the contact-model / thermal-model error table."""
    e = comp.exact
    header = ["scene", "quantity [unit]", f"{e} (exact contact) [unit]"]
    for c in comp.contact:
        header += [f"{c} [unit]", f"contact-model error of {c}, reference {e} [%]"]
    for t, c in comp.thermal.items():
        header += [f"{t} [unit]", f"thermal-model error of {t}, reference {c} [%]",
                   f"total error of {t}, reference {e} [%]"]
    header.append("levels used")
    rows = []
    for s in _thermal_scenes(data, comp):
        for k in _patches(data, s, e):
            rows += _patch_rows(data, comp, s, k)
    return header, rows


def _patch_rows(data: StudyData, comp: ExactComparison, s: str, k: int | None) -> list[list]:
    """The rows of :func:`error_rows` of scene ``s``'s patch ``k`` (None: a result without patches)."""
    e, bulk, rows = comp.exact, _bulk(data, s), []
    for q, (label, unit) in QUANTITIES.items():
        ref = _value(data, s, e, q, k)
        if ref is None or (q not in TEMPERATURES and q != "frictional_power" and abs(ref[0]) < NEGLIGIBLE):
            continue
        b = bulk if q in TEMPERATURES else 0.0
        levels = {e: ref[1]}
        row = [_named(s, k), f"{label} [{shown(unit)}]", quantity(ref[0], unit, with_unit=False)]
        got = {}
        for c in comp.contact:
            v = _value(data, s, c, q, k)
            got[c] = v
            if v is None:
                row += ["–", "–"]
                continue
            levels[c] = v[1]
            contact = _against(data, s, c, q, v, e, ref, b, k)
            row += [quantity(v[0], unit, with_unit=False),
                    Cell(pct(contact, signed=True, floor=ROUND_OFF), _css(contact, data.tolerance))]
        for t, c in comp.thermal.items():
            v = _value(data, s, t, q, k)
            if v is None:
                row += ["–", "–", "–"]
                continue
            levels[t] = v[1]
            vc = got.get(c)
            thermal = relative_error(v[0], vc[0], b) if vc is not None else math.nan
            total = _against(data, s, t, q, v, e, ref, b, k)
            row += [quantity(v[0], unit, with_unit=False),
                    Cell(pct(thermal, signed=True, floor=ROUND_OFF), _css(thermal, data.tolerance)),
                    Cell(pct(total, signed=True, floor=ROUND_OFF), _css(total, data.tolerance))]
        row.append(", ".join(f"{m} level {lv}" for m, lv in levels.items()))
        rows.append(row)
    return rows


def _split_summary(data: StudyData, comp: ExactComparison, q: str = "max_surface_temperature") -> str:
    """One sentence: the range over the scenes of the contact model's and the thermal model's signed error on
    the wheel's maximum surface temperature ('' when there is nothing to compare)."""
    parts = []
    scenes = _thermal_scenes(data, comp)
    for who, ref_of in [(c, lambda c: comp.exact) for c in comp.contact] + [(t, (lambda t: comp.thermal[t]))
                                                                          for t in comp.thermal]:
        ref_m = ref_of(who)
        errs = []
        for s in scenes:
            for k in _patches(data, s, comp.exact):
                v, r = _value(data, s, who, q, k), _value(data, s, ref_m, q, k)
                if v is not None and r is not None:
                    errs.append(_against(data, s, who, q, v, ref_m, r, _bulk(data, s), k))
        errs = [e for e in errs if finite(e)]
        if errs:
            kind = "contact model" if who in comp.contact else "thermal model"
            span = pct(min(errs), signed=True) if len(errs) == 1 or pct(min(errs)) == pct(max(errs)) else \
                f"{pct(min(errs), signed=True)} to {pct(max(errs), signed=True)}"
            parts.append(f"the {kind} of `{who}` (against `{ref_m}`) {span}")
    if not parts:
        return ""
    over = "its one scene" if len(scenes) == 1 else f"the {len(scenes)} scenes"
    patches = sum(len(_patches(data, s, comp.exact)) for s in scenes)
    if patches > len(scenes):
        over += f" ({patches} patches: each patch of a wheelset on profiles on its own)"
    return f"On the wheel's maximum surface temperature over {over}: " + "; ".join(parts) + " (finest levels)."


def _css(err: float, tol: float | None) -> str:
    if not finite(err) or tol is None:
        return ""
    return "ok" if abs(err) <= tol else "inaccurate"


def _sweep_scenes(data: StudyData, comp: ExactComparison) -> list[tuple[float, str]]:
    """(longitudinal creepage, scene) of the longest longitudinal-creepage sweep among the scenes."""
    groups: dict = {}
    for s in comp.scenes:
        sw = data.scene[s].sweep
        if "creepage.longitudinal" in sw:
            rest = tuple(sorted((k, str(v)) for k, v in sw.items() if k != "creepage.longitudinal"))
            groups.setdefault((data.scene[s].base, rest), []).append((float(sw["creepage.longitudinal"]), s))
    if not groups:
        return []
    return sorted(max(groups.values(), key=len))


def creep_curve(data: StudyData, comp: ExactComparison) -> XF.CreepCurve | None:
    """Fx / (mu N) of the exact and the compared methods over the sweep, with the linear theory."""
    members = _sweep_scenes(data, comp)
    if len(members) < 2:
        return None
    curve = XF.CreepCurve(comp.exact)
    names = [s for _, s in members]
    exact_tang = _stages(data, names, comp.exact).get("tangential")
    compared, seen = [], set()
    for m in comp.contact + list(comp.thermal):     # one line per other contact model, by the first that ran it
        tang = _stages(data, names, m).get("tangential")
        if tang and tang != exact_tang and tang not in seen and any(data.finest_result(s, m) for s in names):
            seen.add(tang)
            compared.append(m)
            curve.labels[m] = f"{m} ({tang} contact)"
    for xi, s in members:
        sc = data.scene[s].scene
        law = getattr(sc, "friction", None)
        mu = None if law is None else law.nominal
        if sc is None:        # no study at hand: the friction coefficient is unknown
            mu, curve.ylabel = 1.0, "Fx / N [1] (μ unknown: the study file was not loaded)"
        for m in [comp.exact] + compared:
            fx = _value(data, s, m, "creep_force_x")
            n = _value(data, s, m, "normal_force")
            if fx is None or n is None or not mu:
                continue
            curve.values.setdefault(m, []).append((xi, fx[0] / (mu * n[0]), fx[1]))
    ref = (data.curves or {}).get(members[0][1])
    if ref is not None and "creep_force_ratio_linear" in ref:
        curve.linear = (np.asarray(ref["creepage"].values, float), np.asarray(ref["creep_force_ratio_linear"].values, float),
                        str(ref["creep_force_ratio_linear"].attrs.get("reference", "linear theory")))
    return curve if comp.exact in curve.values else None


def _combined_scene(data: StudyData, comp: ExactComparison, scenes: list[str]) -> str | None:
    """The thermal scene with the most non-zero creepage components (a combined creepage), not a wheelset on
    profiles (its patches have their own section, and a result of several patches keeps its fields per patch)."""
    scenes = [s for s in scenes if getattr(data.scene[s].scene, "profile_contact", None) is None]
    def count(s):
        c = getattr(data.scene[s].scene, "creepage", None)
        return sum(1 for v in (getattr(c, "longitudinal", 0), getattr(c, "lateral", 0), getattr(c, "spin", 0)) if v) \
            if c is not None else ("combined" in s)
    best = max(scenes, key=count, default=None)
    return best


def _gap_scenes(data: StudyData, comp: ExactComparison) -> list[str]:
    """Scenes with a typed-in non-Hertzian gap (a wheelset on profiles has its own section)."""
    out = []
    for s in comp.scenes:
        sc = data.scene[s].scene
        if getattr(sc, "profile_contact", None) is not None:
            continue
        if sc is not None and getattr(sc, "contact_shape", "") == "gap":
            out.append(s)
        elif sc is None and not any(data.finest_result(s, m) for m in data.methods if m != comp.exact):
            out.append(s)
    return out


def exact_contact_section(doc: Document, ctx, comps: list[ExactComparison] | None = None):
    """Write the section (nothing when the study has no scene measured against an exact contact).

    Errors are signed and relative [1], temperatures on their rise above the bulk temperature. The contact
    model's and the total error are ``metrics.nc``'s signed errors (``signed_error_<quantity>``, taken
    against the exact method), the number the run tables and the scorecard print; quantities ``metrics.nc``
    does not score (Fy, Mz) and the thermal model's error (a method against another method that is not the
    scene's reference) are ``(value - reference) / |reference - bulk|`` of the run files' values (the
    wheel's). The creep-force curve of a creepage sweep is the compared method's Fx / (mu N) against the
    exact method's, with core's linear theory from ``references.nc``.
    """
    data = ctx.data
    comps = exact_comparisons(data) if comps is None else comps
    comps = [c for c in comps if c.contact]
    if not comps:
        return
    doc.heading(2, "Exact contact: contact model against thermal model", "exact-contact")
    for comp in comps:
        _one(doc, ctx, comp)


def _one(doc: Document, ctx, comp: ExactComparison):
    data = ctx.data
    e = comp.exact
    st_e = _stages(data, comp.scenes, e)
    chain = lambda m: " → ".join(v for k, v in _stages(data, comp.scenes, m).items() if k != "heat_source")  # noqa: E731
    doc.paragraph(
        f"{len(comp.scenes)} scenes take method `{e}` as their reference (exact contact: "
        f"{chain(e)}). The **contact model's error** is that of a method with the same temperature model "
        f"(`{st_e.get('temperature', '–')}`) and another contact model: "
        + ", ".join(f"`{c}` ({chain(c)})" for c in comp.contact) + ", against `" + e + "`. "
        + ("The **thermal model's error** is that of a method with the same contact model and another "
           "temperature model, against that method: "
           + ", ".join(f"`{t}` ({chain(t)}) against `{c}`" for t, c in comp.thermal.items()) + "; its **total** "
           f"error is against `{e}`. " if comp.thermal else "")
        + "Each method at its finest successful level; errors signed, (value − reference) / |reference|, "
        "temperatures on their rise above the bulk temperature.")
    header, rows = error_rows(data, comp)
    levels_note = "listed in the last column"
    if rows and len({str(r[-1]) for r in rows}) == 1:   # one set of levels: say it once, keep the rows short
        levels_note = f"for every row: {rows[0][-1]}"
        header, rows = header[:-1], [r[:-1] for r in rows]
    doc.paragraph(_split_summary(data, comp))
    if rows:
        with doc.details(f"Contact-model and thermal-model errors, scene by scene ({len(rows)} rows)"):
            doc.table(f"Contact-model and thermal-model errors against the exact contact. Values in the unit of their "
                      f"row; each error column names its reference method (finest successful level, {levels_note}); "
                      f"cell colour: within (green) or above (orange) the study's tolerance "
                      f"{pct(data.tolerance) if data.tolerance is not None else '–'}. `{e}`'s own error is its "
                      f"discretisation error (it is the reference; see each scene's section). Forces and moments "
                      f"that vanish by symmetry (|{e}| < {NEGLIGIBLE:g} N or N m) are left out.", header, rows)
    else:
        doc.paragraph(f"No scene measured against `{e}` has temperatures of `{e}`: no error table.", note=True)
    curve = creep_curve(data, comp)
    if curve is not None:
        members = _sweep_scenes(data, comp)
        rows = []
        for m in [m for m in curve.values if m != e]:
            ex = dict((x, (v, lv)) for x, v, lv in curve.values.get(e, []))
            for x, v, lv in curve.values.get(m, []):
                if x in ex:   # Fx's error is μ N's: metrics.nc's where it stores it against the exact method
                    err = stored_error(data, dict(members).get(x, ""), m, "creep_force_x", e)
                    err = err if finite(err) else relative_error(v, ex[x][0])
                    rows.append([num(x), num(ex[x][0]) + f" (level {ex[x][1]})", f"`{m}`", num(v) + f" (level {lv})",
                                 Cell(pct(err, signed=True, floor=ROUND_OFF), _css(err, data.tolerance))])
        with doc.details(f"Creep-force curve as a table ({len(rows)} rows)"):
            doc.table(f"Creep-force curve of the sweep `{data.scene[members[0][1]].base}` over the longitudinal "
                      f"creepage ξ [1]: Fx / (μ N) [1] of the exact contact (`{e}`) and of each contact model, with "
                      f"the error of the latter against `{e}` [%] (level in brackets).",
                      ["longitudinal creepage ξ [1]", f"Fx / (μ N) of {e} [1]", "method", "Fx / (μ N) [1]",
                       f"error, reference {e} [%]"], rows)
        ctx.draw(doc, "exact-creep-curve", f"Creep-force curve: Fx / (μ N) against the longitudinal creepage of "
                 f"the exact contact (`{e}`, black) and of " + ", ".join(f"`{c}`" for c in curve.values if c != e)
                 + (f"; dashed: {curve.linear[2]} (core, `references.nc`), valid at small creepage" if curve.linear
                    else "") + ". Right: relative error against the exact contact.",
                 XF.creep_curve_figure, curve, ctx.palette)
    thermal = _thermal_scenes(data, comp)
    combined = _combined_scene(data, comp, thermal)
    if combined is not None:
        maps = {m: data.run_file(combined, m, data.finest_result(combined, m).level)
                for m in [e] + comp.contact if data.finest_result(combined, m) is not None}
        maps = {m: ds for m, ds in maps.items() if ds is not None}
        ctx.shown.add((combined, "traction"))
        ctx.draw(doc, "exact-maps", f"`{combined}`: traction |q| [MPa], slip velocity |v_s| [m/s] and frictional "
                 "power density [MW/m²] (both bodies) side by side, exact contact against "
                 + ", ".join(f"`{c}`" for c in comp.contact) + " (finest levels; cells outside the contact "
                 "blank; one colour scale per column).", XF.maps_figure, maps, f"{combined}: exact vs simplified")
    hertzian = combined if combined is not None and getattr(data.scene[combined].scene, "contact_shape", "") \
        == "ellipse" else None
    for s in _gap_scenes(data, comp):
        _gap(doc, ctx, comp, s, hertzian)


def _monomial(k) -> str:
    """(i, j) or 'x2y4' -> 'x^i y^j'."""
    if isinstance(k, (tuple, list)) and len(k) == 2:
        i, j = int(k[0]), int(k[1])
        return " ".join(p for p in ((f"x^{i}" if i > 1 else "x" if i == 1 else ""),
                                    (f"y^{j}" if j > 1 else "y" if j == 1 else "")) if p)
    return str(k)


def _gap(doc: Document, ctx, comp: ExactComparison, scene: str, hertzian: str | None):
    """A typed-in non-Hertzian gap: who runs it, its values beside the Hertzian ellipse ``hertzian`` (when the
    study has one) and the exact method's maps."""
    data = ctx.data
    e = comp.exact
    r = data.finest_result(scene, e)
    if r is None:
        return
    sc = data.scene[scene].scene
    coeffs = getattr(sc, "gap_coefficients", None) or {}
    gap = " + ".join(f"{v:g} " + _monomial(k) for k, v in coeffs.items()) if coeffs else "not Hertzian"
    others = sorted({x.message for x in data.runs_of(scene) if x.method != e and x.status == "refused"})
    ran = sorted({m for m in data.methods if m != e and data.finest_result(scene, m) is not None})
    doc.paragraph(f"Non-Hertzian contact `{scene}`: undeformed gap h = {gap} [m] (x, y in m); "
                  + (f"`{e}` and " + ", ".join(f"`{m}`" for m in ran) + " run it" if ran else f"only `{e}` runs it")
                  + (" (the others refuse, e.g. " + short(others[0], 240) + ")" if others and not ran else "") + ".")
    if hertzian is not None:
        _beside_hertzian(doc, data, e, scene, hertzian)
    ds = data.run_file(scene, e, r.level)
    if ds is not None:
        ctx.shown.add((scene, "traction"))
        ctx.draw(doc, "exact-gap-maps", f"`{scene}`: pressure, traction |q| and frictional power density of `{e}` "
                 "on the non-Hertzian patch (finest level).", XF.maps_figure, {e: ds}, f"{scene} ({e})",
                 pressure=True)


def _beside_hertzian(doc: Document, data, e: str, scene: str, hertzian: str):
    """Table: the non-Hertzian ``scene`` by the exact method ``e`` beside the Hertzian ellipse ``hertzian``."""
    qs = dict(QUANTITIES, contact_area=("contact area", "m²"), semi_axis_a=("half-length a", "m"),
              semi_axis_b=("half-width b", "m"), max_pressure=("max. pressure", "Pa"))
    rows = []
    for q, (label, unit) in qs.items():
        v = _value(data, scene, e, q)
        if v is None:
            continue
        h = _value(data, hertzian, e, q)
        rows.append([f"{label} [{shown(unit)}]", quantity(v[0], unit, with_unit=False) + f" (level {v[1]})",
                     (quantity(h[0], unit, with_unit=False) + f" (level {h[1]})") if h else "–",
                     pct(relative_error(v[0], h[0], _bulk(data, scene) if q in TEMPERATURES else 0.0), signed=True)
                     if h else "–"])
    doc.table(f"`{scene}` (non-Hertzian) by `{e}` beside the Hertzian ellipse `{hertzian}` by `{e}`: values in "
              "the unit of their row (level in brackets), difference relative to the Hertzian scene [%].",
              ["quantity [unit]", f"{scene}", f"{hertzian} (reference)", "difference [%]"], rows)
