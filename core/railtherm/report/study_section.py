"""The report's opening and its study section: what the study is, what each scene is and which table or
figure of the seed paper it reproduces (in the study author's words, :mod:`.study_notes`), and a note
on every scene whose temperature rise leaves the range of constant material properties."""
from __future__ import annotations

import math

import numpy as np

from .document import Document
from .environment import files_line
from .format import finite, level_range, num, quantity, short
from .load import StudyData
from .study_notes import scene_notes, seed_reference

__all__ = ["intro", "study_section", "max_rise", "hot_note", "describe_scene", "HOT", "MELTING"]

#: temperature rise [K] above which steel's conductivity, heat capacity and yield stress change so much that
#: the constant-property theory every method uses no longer holds
HOT = 1000.0
#: temperature [°C] above which rail steel melts (solidus ~1,450-1,500 °C)
MELTING = 1500.0



def _describe_profile_contact(sc) -> str:
    """A wheelset on profiles: the wheel, the wheelset's lateral shift and the patch (or why there is none)."""
    pc = sc.profile_contact
    ws = (getattr(sc, "source", None) or {}).get("wheelset", {})
    shift = ws.get("lateral_shift")
    where = f"{pc.side} wheel" + (f", lateral shift {num(float(shift) * 1e3)} mm" if shift is not None else "")
    failure = getattr(pc, "failure", None)
    if callable(failure):
        return f"wheelset on profiles ({where}): no contact"
    patch = "all patches" if pc.patch == "all" else f"patch {pc.patch} of {pc.patches}"
    return (f"wheelset on profiles ({where}, {patch}); contact angle {num(pc.contact_angle, 3)} rad; "
            f"normal force {quantity(pc.normal_force, 'N')}")


def describe_scene(sc) -> str:
    """A scene's inputs in one line, in the units a researcher reads (kN, mm, MW/m², m/s)."""
    if sc is None:
        return ""
    parts = []
    try:
        if sc.heat_source is not None:
            hs = sc.heat_source
            size = (f"semi-axes {num(hs.semi_axes[0] * 1e3)} × {num(hs.semi_axes[1] * 1e3)} mm"
                    if hs.semi_axes is not None else f"half-width {quantity(hs.half_width, 'm')}")
            parts.append(f"given heat source ({hs.shape}), flux {quantity(hs.flux, 'W/m2')}, {size}")
        elif getattr(sc, "profile_contact", None) is not None:
            parts.append(_describe_profile_contact(sc))
            if sc.friction is not None:
                parts.append(f"μ = {num(sc.friction.nominal)}")
        else:
            geo = sc.contact_shape
            if sc.semi_axes is not None:
                geo += f", semi-axes {num(sc.semi_axes[0] * 1e3)} × {num(sc.semi_axes[1] * 1e3)} mm"
            elif sc.curvatures is not None:
                geo += f", curvatures {num(sc.curvatures[0], 4)}, {num(sc.curvatures[1], 4)} 1/m"
            elif sc.contact_shape == "line":
                geo += f", wheel radius {num(sc.wheel_radius * 1e3)} mm"
            parts.append(geo + " contact")
            if sc.normal_force is not None:
                parts.append("normal force " + quantity(sc.normal_force, "N/m" if sc.contact_shape == "line" else "N"))
            elif sc.penetration is not None:
                parts.append(f"penetration {quantity(sc.penetration, 'm')}")
            if sc.creepage is not None:
                c = sc.creepage
                parts.append(f"creepage ξ = {num(c.longitudinal)}, η = {num(c.lateral)}, φ = {num(c.spin)} 1/m")
            elif sc.sliding_speed is not None:
                parts.append(f"sliding speed {num(sc.sliding_speed)} m/s")
            if sc.friction is not None:
                law = sc.friction
                parts.append(f"μ = {num(law.nominal)}" if law.kind == "constant" else f"friction {law.describe()}")
        parts.append(f"speed {num(sc.speed)} m/s")
        hp = sc.heat_partition
        parts.append(f"heat partition {hp if isinstance(hp, str) else num(hp)}"
                     + (" (all heat into the rail)" if hp == 0 else " (all heat into the wheel)" if hp == 1 else ""))
        if sc.convection:
            parts.append(f"convection {num(sc.convection)} W/(m² K)")
        if sc.wheel.rigid:
            parts.append("rigid wheel")
        if sc.mode != "steady":
            parts.append(f"mode {sc.mode}")
    except Exception:  # noqa: BLE001 - a description is optional
        pass
    return "; ".join(parts)

def intro(doc: Document, data: StudyData):
    """The paragraph under the title: the study's own description, its size and its data files."""
    study = data.study
    desc = str(getattr(study, "description", "") or "").strip()
    n_scenes = len(data.scenes)
    text = (desc.rstrip(".") + ". " if desc else "") + (
        f"{n_scenes} scenes × {len(data.methods)} methods ({', '.join(data.methods)}), levels "
        f"{level_range(data.levels) or '–'} of the resolution ladder (each level halves the cell size); "
        f"{len(data.runs)} runs.")
    doc.paragraph(text)
    line = files_line(data.out)
    if line:
        doc.paragraph(line, note=True)


def _bulk(data: StudyData, scene: str, body: int) -> float:
    sc = data.scene[scene].scene
    try:
        return float(sc.body(body).bulk_temperature)
    except (AttributeError, TypeError):
        return 0.0


def max_rise(data: StudyData, scene: str) -> tuple[float, float]:
    """(largest surface temperature rise above the bulk [K], that temperature [°C]) of a scene: the exact
    value where ``metrics.nc`` has one, else the median over the methods' finest results (NaN: none)."""
    exact = data.scene[scene].analytic.get("max_surface_temperature")
    if exact is not None and np.isfinite(exact).any():
        vals = np.atleast_1d(np.asarray(exact, float))
    else:
        per_method = []
        for m in data.methods:
            r = data.finest_result(scene, m)
            ds = data.run_file(scene, m, r.level) if r is not None else None
            if ds is not None and "max_surface_temperature" in ds:
                per_method.append(np.atleast_1d(np.asarray(ds["max_surface_temperature"].values, float)))
        if not per_method:
            return math.nan, math.nan
        width = max(v.size for v in per_method)
        stack = np.array([np.pad(v, (0, width - v.size), constant_values=np.nan) for v in per_method])
        vals = np.nanmedian(stack, axis=0)
    rises = [(float(v) - _bulk(data, scene, i), float(v)) for i, v in enumerate(vals[:2]) if finite(v)]
    return max(rises) if rises else (math.nan, math.nan)


def hot_note(data: StudyData, scene: str) -> str:
    """A warning when a scene's rise exceeds :data:`HOT` (constant properties no longer hold) or its
    temperature passes :data:`MELTING`; '' otherwise."""
    rise, temp = max_rise(data, scene)
    if not finite(rise) or rise <= HOT:
        return ""
    text = (f"**Outside constant-property theory:** the surface temperature rises by {num(rise)} K (to "
            f"{num(temp)} °C). Above a rise of about {num(HOT)} K the steel's conductivity, heat capacity and "
            "strength change markedly, so the constant material properties every method here assumes no longer "
            "hold")
    if temp > MELTING:
        text += f"; above about {num(MELTING)} °C rail steel melts, so the computed peak is not physical"
    return text + ". The numbers still compare the methods on the same idealised problem."


def _what(data: StudyData, scene: str, note, shared: dict) -> str:
    """The author's words for a scene, shortened; when several scenes share them, the inputs that set this
    scene apart ('creepage ξ = 0, η = 0, φ = 0.4 1/m')."""
    text = note.text if note is not None else ""
    if not text:
        return short(describe_scene(data.scene[scene].scene), 150) or "–"
    others = [s for s in shared.get(note.text, []) if s != scene]
    text = short(text, 110 if others else 150)
    if others:
        mine = describe_scene(data.scene[scene].scene).split("; ")
        theirs = [set(describe_scene(data.scene[s].scene).split("; ")) for s in others]
        own = [p for p in mine if p and all(p not in t for t in theirs)]
        if own:
            text += " This scene: " + "; ".join(own) + "."
    return text


def _source(seed: str, group: str) -> str:
    """'seed 5.4 Table 1' and the group 'seed 5.4, Table 1' -> 'seed 5.4, Table 1' (said once)."""
    flat = group.replace(",", "")
    extra = [p for p in seed.split("; ") if p and p.replace(",", "") not in flat]
    return " · ".join(x for x in (group, "; ".join(extra)) if x) or "–"


def study_section(doc: Document, ctx, table_rows) -> None:
    """One row per scorecard row: the scene (linked to its section), what it is, the seed paper's
    table or figure it reproduces, and a flag when it leaves constant-property theory."""
    data = ctx.data
    study = data.study
    path = getattr(study, "path", None) or data.info.get("path")
    scenes = list(getattr(study, "scenes", ()) or [])
    notes = scene_notes(path, scenes or data.scenes) if (scenes or path) else {}
    doc.heading(2, "The study and its scenes", "study")
    rows, shared = [], {}
    for row in table_rows:
        note = notes.get(row.scenes[0])
        if note is not None and note.text:
            shared.setdefault(note.text, []).append(row.scenes[0])
    for row in table_rows:
        scene = row.scenes[0]
        note = notes.get(scene)
        name = (f"[{row.label}](#{row.anchor})" if row.anchor else row.label) \
            + (f" ({len(row.scenes)} scenes)" if row.group else "")
        src = seed_reference(note) if note is not None else ""
        group = note.group if note is not None else ""
        hot, temp = max_rise(data, scene) if not row.group else (math.nan, math.nan)
        flag = f"rise {num(hot)} K: past melting" if finite(hot) and hot > HOT and temp > MELTING else \
            f"rise {num(hot)} K: beyond constant properties" if finite(hot) and hot > HOT else ""
        rows.append([name, _what(data, scene, note, shared), _source(src, group), flag])
    if not any(r[3] for r in rows):
        rows = [r[:3] for r in rows]
    doc.table("The scenes in the study's order, as the study file describes them (its comments), with the seed "
              "paper's section, table or figure each reproduces and the study file's group; a scene whose "
              f"temperature rise exceeds {num(HOT)} K is flagged (see its section).",
              ["scene", "what it is", "seed paper · group"] + (["note"] if len(rows[0]) > 3 else []), rows)
