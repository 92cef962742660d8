"""The part of a scene's report section that shows a transient scene over time (repeated passes, a
schedule of the heat input): the temperature histories, the per-pass peaks, residual rises and times
above the threshold, and each method's largest errors against the exact transient reference.

A scene is transient when its ``mode`` is ``"transient"`` (``scene.transient`` is set) or, without the
study file, when its runs hold ``pass_peak_temperature``. The methods' curves are their run files'
(``temperature_history``, ``pass_peak_temperature``, ``residual_rise``, ``time_above``); the exact
curves are the scene's group of ``references.nc`` when it holds them (``exact_temperature_history``,
``exact_pass_peak_temperature``, ``exact_residual_rise``, ``exact_time_above``), else they are not drawn;
the errors are ``metrics.nc``'s. The report computes no physics.
"""
from __future__ import annotations

import math

import numpy as np

from . import transient_figures as TF
from .document import Cell, Document
from .format import duration, finite, label, slug
from .load import StudyData, body_bulk
from .tables import error_text, reference_words

__all__ = ["transient_section", "is_transient", "heated_bodies", "error_rows", "METRICS"]

BODIES = ("wheel", "rail")
#: metrics.nc's transient errors, in the table's order, with their column names
METRICS = (("pass_peak_temperature", "largest pass-peak error [%]"),
           ("residual_rise", "largest residual-rise error [%]"),
           ("temperature_history", "history error, max-norm [%]"))
#: a body is heated when some method's pass peak at the surface rises this much above its bulk [K]
HEATED_RISE = 1e-6


def _transient(data: StudyData, scene: str):
    sc = data.scene[scene].scene
    return getattr(sc, "transient", None) if sc is not None else None


def is_transient(data: StudyData, scene: str, finest: dict) -> bool:
    """True for a scene with passes over time (its study says so, or its runs hold pass peaks)."""
    if data.scene[scene].scene is not None:
        return _transient(data, scene) is not None
    return any("pass_peak_temperature" in ds for ds in finest.values())


def heated_bodies(data: StudyData, scene: str, finest: dict) -> list[int]:
    """Bodies (0 wheel, 1 rail) whose surface pass peak rises above their bulk in some method's result, the
    hotter first (its history is shown, the other's behind a closed box); the rail first on a tie."""
    rise = {}
    for b in (1, 0):
        bulk = body_bulk(data, scene, b)
        for ds in finest.values():
            if "pass_peak_temperature" not in ds:
                continue
            peaks = np.asarray(ds["pass_peak_temperature"].isel(body=b, z=0).values, float)
            r = float(np.nanmax(peaks, initial=-math.inf)) - bulk
            if r > HEATED_RISE:
                rise[b] = max(rise.get(b, -math.inf), r)
    return sorted(rise, key=lambda b: -rise[b])


def _count(data: StudyData, scene: str, finest: dict) -> int:
    tr = _transient(data, scene)
    if tr is not None:
        return int(tr.count)
    return max((ds.sizes.get("pass", 1) for ds in finest.values()), default=1)


def _threshold(data: StudyData, scene: str) -> float:
    tr = _transient(data, scene)
    return float(tr.threshold) if tr is not None else 727.0


def _against(ref: str) -> str:
    """A reference tag in words; a method's own levels are never called a check."""
    if not ref:
        return "none"
    if ref.startswith("self"):
        return reference_words(ref) + " (not independent: convergence only)"
    return reference_words(ref)


def error_rows(data: StudyData, scene: str, finest: dict) -> tuple[list[str], list[list]]:
    """Header and rows: per method its finest level's largest errors on the transient metrics, the reference
    they are taken against and its best wall time."""
    header = ["method (level)"] + [h for _, h in METRICS] + ["against", "run time"]
    rows = []
    tol = data.tolerance
    for m in finest:
        r = data.finest_result(scene, m)
        refs = list(dict.fromkeys(r.references.get(k, "") for k, _ in METRICS if k in r.errors))
        row = [f"{m} (level {r.level})"]
        for k, _ in METRICS:
            e = r.errors.get(k, math.nan)
            independent = not r.references.get(k, "").startswith("self")
            css = "" if tol is None or not finite(e) or not independent else ("ok" if abs(e) <= tol else
                                                                              "inaccurate")
            row.append(Cell(error_text(r, k), css))
        row += ["; ".join(_against(x) for x in refs if x) or "no reference", duration(r.wall_time)]
        rows.append(row)
    return header, rows


def _reference_name(curve, data: StudyData, scene: str, finest: dict) -> str:
    """The exact history's name: references.nc's ``transient_reference``, else the errors' reference."""
    if curve is not None and curve.attrs.get("transient_reference"):
        return label(str(curve.attrs["transient_reference"]))
    for m in finest:
        ref = data.finest_result(scene, m).references.get("pass_peak_temperature", "")
        if ref and not ref.startswith("self"):
            return reference_words(ref)
    return ""


def transient_section(doc: Document, ctx, idx: int, scene: str, finest: dict):
    """Write a transient scene's histories, per-pass figure and error table (nothing for a steady scene)."""
    data = ctx.data
    if not is_transient(data, scene, finest):
        return
    runs = {m: ds for m, ds in finest.items() if "pass_peak_temperature" in ds or "temperature_history" in ds}
    doc.heading(3, f"`{scene}` over time: passes, histories, residual rise")
    if not runs:
        doc.paragraph("No method produced a transient result for this scene: no history is drawn.", note=True)
        return
    curve = (data.curves or {}).get(scene)
    has_exact = curve is not None and any(k in curve for k in ("exact_temperature_history",
                                                               "exact_pass_peak_temperature"))
    ref = _reference_name(curve, data, scene, finest)
    count, thr = _count(data, scene, runs), _threshold(data, scene)
    levels = ", ".join(f"{m} level {data.finest_result(scene, m).level}" for m in runs)
    band = (f"grey band: {ref or 'the exact history'} (`references.nc`)" if has_exact else
            "no exact history is drawn (`references.nc` holds none for this scene)")
    joined = TF.exact_joined(runs, curve)
    history_band = band if joined is not False else (
        f"grey dots: the samples of {ref or 'the exact history'} (`references.nc`; its time axis is coarser than "
        "a contact, so they are not joined and fall between the passes' peaks: the per-pass figure holds the "
        "exact peaks)")
    header, rows = error_rows(data, scene, runs)
    doc.table(f"`{scene}`, {count} pass{'es' if count != 1 else ''}: each method's finest successful level, its "
              "largest relative errors over the passes and bodies (`metrics.nc`: pass peak and residual rise per "
              "pass, the history as the max-norm of the rise over it, signed where stored) against the reference "
              "named, and its best wall time. Cell colour: within (green) or above (orange) the study's tolerance; "
              "an error against the method's own finest level is not coloured.", header, rows)
    bodies = heated_bodies(data, scene, runs) or [1]
    base = f"{idx:03d}-{slug(scene)}"
    ctx.draw(doc, f"{base}-per-pass", f"`{scene}`: per pass, the peak surface temperature, the residual rise above "
             "the bulk left just before the next pass (after the last: one interval after it)"
             + f" and, where some pass reaches {thr:g} °C, the time the surface spends above it, of each heated body; "
             f"methods at their finest level ({levels}); {band}.", TF.per_pass, runs, curve, bodies, thr,
             ctx.palette, f"{scene}: per pass")
    many = count > TF.FEW_PASSES
    for body in bodies:
        who = BODIES[body]
        caption = (f"`{scene}`, {who}: temperature of the material point on the contact's centre line at the "
                   "fixed section, at the surface and the history depths, "
                   + (f"over the first {TF.FIRST_PASSES} and the last {TF.LAST_PASSES} of {count} passes (left, "
                      "right)" if many else "over the whole history") + f"; methods at their finest level "
                   f"({levels}); {history_band}; dotted: {thr:g} °C where reached.")
        args = (TF.histories, runs, curve, body, count, thr, ctx.palette, f"{scene} ({who}): temperature history")
        if body == bodies[0]:
            ctx.draw(doc, f"{base}-history-{who}", caption, *args)
        else:
            with doc.details(f"The {who}'s temperature history"):
                ctx.draw(doc, f"{base}-history-{who}", caption, *args)
