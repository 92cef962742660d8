"""The report's thermal-trace section: temperatures behind the patch and in depth (the seed paper's Figs
2-7 kinds of plot).

For every scene with ``field`` whose exact trace is in ``references.nc`` (written by
:func:`railtherm.analysis.reference_curves.write_reference_curves`), each method's finest successful level
is drawn against the exact reference (:mod:`.trace_figures`): temperature along x on the surface and at
the reference's depth z*, temperature against depth at the hottest surface point, each depth's peak and
the cooling rate after it, and the surface-temperature maps of the patch and its trace. One table lists
per method and heated body the maximum surface temperature, the heated depth, the time above the
threshold and the cooling rate at z* beside the exact values (:func:`trace_section` says which errors).

The report computes no physics: the methods' values are their run files', interpolated linearly in
depth to z* where needed; every exact value is ``references.nc``'s.
"""
from __future__ import annotations

import math

import numpy as np

from . import trace_figures as TF
from .document import Cell, Document
from .exact_contact import relative_error
from .document import anchor_text
from .format import finite, label, num, pct
from .load import StudyData, body_bulk
from .tables import error_text, metric_name
from .study_section import hot_note

__all__ = ["trace_scenes", "trace_rows", "trace_section", "trace_anchor", "BODIES"]

BODIES = ("wheel", "rail")
#: variables of a run that make it part of the section
TRACE_VARS = ("peak_temperature", "cooling_rate", "heated_depth", "time_above", "temperature", "surface_temperature")


def trace_scenes(data: StudyData) -> list[str]:
    """Scenes whose exact trace is in ``references.nc`` (scenes with ``field`` and an exact source)."""
    curves = data.curves or {}
    return [s for s in data.scenes if s in curves and "trace_peak_temperature" in curves[s]]


def _finest(data: StudyData, scene: str) -> dict:
    """method -> Dataset of its finest successful level (methods with a trace variable only)."""
    out = {}
    for m in data.methods:
        r = data.finest_result(scene, m)
        if r is None:
            continue
        ds = data.run_file(scene, m, r.level)
        if ds is not None and any(v in ds for v in TRACE_VARS):
            out[m] = ds
    return out


def _levels(data: StudyData, scene: str, methods) -> str:
    return ", ".join(f"{m} level {data.finest_result(scene, m).level}" for m in methods)


def heated_bodies(curve) -> list[int]:
    """Bodies that take heat: their exact surface temperature is not uniform (the other's is its bulk)."""
    t = np.asarray(curve["surface_temperature"].values, float)
    return [i for i in (0, 1) if np.nanmax(t[i]) > np.nanmin(t[i])]


def _surface(ds, name: str, body: int) -> float:
    """A run's profile ``name(body, z)`` at z = 0 (None when absent or its depth axis does not start at 0)."""
    if ds is None or name not in ds or "z" not in ds[name].dims or float(ds["z"].values[0]) != 0.0:
        return None
    return float(ds[name].isel(body=body, z=0).values)


def _interp(ds, name: str, body: int, z: float) -> float:
    """A run's profile ``name(body, z)`` linearly interpolated to depth ``z`` [m] over its finite values (NaN
    when ``z`` lies outside them: the peak was at the end of the field; None when the run has no profile)."""
    if ds is None or name not in ds or "z" not in ds[name].dims:
        return None
    zz = np.asarray(ds["z"].values, float)
    v = np.asarray(ds[name].isel(body=body).values, float)
    ok = np.isfinite(v)
    if ok.sum() < 2 or not (zz[ok].min() <= z <= zz[ok].max()):
        return math.nan
    return float(np.interp(z, zz[ok], v[ok]))


def _scalar(ds, name: str, body: int) -> float:
    if ds is None or name not in ds:
        return None
    return float(np.asarray(ds[name].values, float).reshape(-1)[body])


def values(data: StudyData, scene: str, method: str | None, body: int) -> dict:
    """The table's values of one method (None: the exact reference) for one body, in SI units (None: the run
    has no such variable; NaN: the run's own NaN, a peak at the end of its field). The surface peak is the
    scene's ``max_surface_temperature``: the run file's value, and metrics.nc's exact value
    (``analytic_max_surface_temperature``), so that it is the same number as in every other table."""
    curve = data.curves[scene]
    zs = float(curve["trace_depth"].values)
    if method is None:
        exact = np.atleast_1d(data.scene[scene].analytic.get("max_surface_temperature", np.nan))
        peak = float(exact[body]) if exact.size > body and finite(exact[body]) else \
            float(curve["trace_peak_temperature"].values[body, 0])
        return {"peak": peak, "depth": float(curve["trace_heated_depth"].values[body]),
                "above": float(curve["trace_time_above"].values[body, 0]),
                "cooling": float(curve["trace_depth_cooling_rate"].values[body])}
    r = data.finest_result(scene, method)
    ds = data.run_file(scene, method, r.level) if r is not None else None
    peak = _scalar(ds, "max_surface_temperature", body)
    if peak is None:
        peak = _surface(ds, "peak_temperature", body)
    if peak is None:   # depth axis not starting at the surface (cell centres): the surface line's maximum
        line = TF.surface_line(ds, body)
        peak = float(np.nanmax(line[1])) if line is not None and np.isfinite(line[1]).any() else None
    return {"peak": peak, "depth": _scalar(ds, "heated_depth", body),
            "above": _surface(ds, "time_above", body), "cooling": _interp(ds, "cooling_rate", body, zs)}


#: (key, header, unit scale, digits, metric of metrics.nc whose error stands beside it, or None: a
#: difference at one point, computed here and named as such)
COLUMNS = (("peak", "max. surface temperature [°C]", 1.0, 3, "max_surface_temperature"),
           ("depth", "depth of the threshold isotherm [mm]", 1e3, 3, "heated_depth"),
           ("above", "time above the threshold at the surface [ms]", 1e3, 3, None),
           ("cooling", "cooling rate at z* [K/s]", 1.0, 3, None))
#: metrics.nc errors that have no value column: the scored cooling rate and its all-depths variant
STORED = ("cooling_rate", "cooling_rate_all_depths")
DIFFERENCE = {"above": "difference at the surface [%]", "cooling": "difference at z* [%]"}


def _css(text: str, err: float, tol) -> str:
    if text == "not finite":
        return "inaccurate"
    return "" if not finite(err) or tol is None else ("ok" if abs(err) <= tol else "inaccurate")


def _stored(run, metric: str, tol) -> Cell:
    """A run's error on ``metric`` as metrics.nc stores it (signed where the sign is stored)."""
    text = error_text(run, metric) if run is not None else "–"
    return Cell(text + (" %" if text not in ("–", "—", "not finite") else ""),
                _css(text, run.errors.get(metric, math.nan) if run is not None else math.nan, tol))


def _cell(v: float | None, ref: float, scale: float, digits: int, bulk: float, tol) -> list:
    """A value and its difference from the exact value at the same point (signed)."""
    if v is None:
        return ["–", "–"]
    if not finite(v):
        return ["NaN (field too short)" if v != v else num(v, digits), "–"]
    err = relative_error(v, ref, bulk) if finite(ref) else math.nan
    css = "" if not finite(err) or tol is None else ("ok" if abs(err) <= tol else "inaccurate")
    return [num(v * scale, digits), Cell(pct(err, signed=True) if finite(err) else "–", css)]


def _depths(data: StudyData, scene: str) -> list[float]:
    return [r.cooling_depth for r in data.runs_of(scene) if r.has_result]


def trace_header(data: StudyData, scenes: list[str]) -> list[str]:
    depths = [z for s in scenes for z in _depths(data, s)]
    header = ["scene", "body", "method (level)"]
    for key, h, _, _, metric in COLUMNS:
        header += [h, "error [%]" if metric else DIFFERENCE[key]]
    return header + [f"error of {metric_name(m, depths)} [%]" for m in STORED]


def trace_rows(data: StudyData, scenes: list[str] | None = None) -> tuple[list[str], list[list]]:
    """Header and rows of the thermal-trace table (exact row first per scene and body). Errors of metrics are
    metrics.nc's, one per run (over its heated bodies: in the method's first row); the differences at the
    surface and at z* are per body and point."""
    scenes = trace_scenes(data) if scenes is None else scenes
    rows = []
    for s in scenes:
        curve = data.curves[s]
        thr = float(curve["trace_threshold"].values)
        zs = float(curve["trace_depth"].values)
        finest = _finest(data, s)
        first = set()
        for body in heated_bodies(curve):
            bulk = body_bulk(data, s, body)
            ref = values(data, s, None, body)
            scored = metric_name("cooling_rate", _depths(data, s))
            row = [f"`{s}` ({thr:g} °C; z* = {zs * 1e3:.3g} mm" + (f"; {scored} scored" if "≥" in scored else "")
                   + ")", BODIES[body], "**exact**"]
            for k, _, scale, digits, _ in COLUMNS:
                row += [num(ref[k] * scale, digits) if finite(ref[k]) else "–", ""]
            rows.append(row + [""] * len(STORED))
            for m in finest:
                run = data.finest_result(s, m)
                v = values(data, s, m, body)
                row = ["", "", f"{m} (level {run.level})"]
                for k, _, scale, digits, metric in COLUMNS:
                    if metric is None:
                        row += _cell(v[k], ref[k], scale, digits, bulk if k == "peak" else 0.0, data.tolerance)
                    else:
                        row += [_cell(v[k], ref[k], scale, digits, 0.0, None)[0],
                                _stored(run, metric, data.tolerance) if m not in first else "″"]
                rows.append(row + ([_stored(run, x, data.tolerance) for x in STORED] if m not in first
                                   else ["″"] * len(STORED)))
                first.add(m)
    return trace_header(data, scenes), rows


def trace_section(doc: Document, ctx, scenes: list[str] | None = None):
    """Write the section (nothing when no scene has an exact thermal trace).

    The table's maximum surface temperature is the run's ``max_surface_temperature`` (the number every
    other table shows), the heated depth that of the ``field.threshold`` isotherm (``heated_depth``), the
    time above it ``time_above`` at z = 0. The errors are ``metrics.nc``'s (one per run, signed where
    stored, the cooling rate's named with the depths it is scored at, its all-depths error beside it); the
    time above and the cooling rate at z* are single points of a profile, so their signed differences
    (value - exact) / |exact| are named "difference at the surface" and "difference at z*".
    """
    data = ctx.data
    scenes = trace_scenes(data) if scenes is None else scenes
    if not scenes:
        return
    doc.heading(2, "Thermal trace: behind the patch and in depth", "thermal-trace")
    doc.paragraph(
        f"{len(scenes)} scenes report temperatures behind the patch and in depth (scene key `field`). A material "
        "point on the centre line moves to −x through the patch: x is its history (t = −x/V). Each method at "
        "its finest successful level against the exact trace (moving surface source on a half-space or "
        "Jaeger's band, evaluated at depth; `references.nc`): the temperature along the rolling direction on "
        "the surface and at a depth z* (the exact depth of the threshold isotherm when it lies inside the "
        "field, else where the exact peak has fallen to half its surface rise), the temperature against depth "
        "at the hottest surface point, the highest temperature each depth reaches and the fastest cooling "
        "after it, and the surface-temperature maps of the patch and its trace. A peak at the end of a "
        "method's field is NaN (the field was too short), never a peak.")
    header, rows = trace_rows(data, scenes)
    with doc.details(f"The trace in numbers: peak, isotherm depth, time above, cooling rate per method and body "
                     f"({len(rows)} rows)"):
        doc.table("The thermal trace per heated body: maximum surface temperature, depth of the isotherm of the "
                  "scene's `field.threshold` (°C, in brackets with z*), time the surface spends above it, and "
                  "cooling rate after the peak at depth z* (methods: linear interpolation of their profile), each "
                  "method's finest successful level beside the exact values. \"error\": the run's error in "
                  "`metrics.nc` (signed where stored; one per run over its heated bodies, in the method's first "
                  "row, ″ below), the same number as in the scene's run table and the scorecard; the cooling rate "
                  "is scored at the depths named in its header, and its all-depths error is not used by the "
                  "verdict. \"difference at the surface\" and \"difference at z*\": (value − exact) / |exact| at "
                  "that one point and body. Cell colour: within (green) or above (orange) the study's tolerance "
                  f"{pct(data.tolerance) if data.tolerance is not None else '–'}.", header, rows)
    for s in scenes:
        _scene(doc, ctx, s)


def trace_anchor(scene: str) -> str:
    """The anchor of a scene's part of the thermal-trace section."""
    return "trace-" + anchor_text(scene)


def _scene(doc: Document, ctx, scene: str):
    """One scene: a heading, the constant-property note, one figure per heated body (along x above in
    depth), and the surface maps of the trace behind a closed box."""
    data = ctx.data
    curve = data.curves[scene]
    finest = _finest(data, scene)
    ref = label(str(curve.attrs.get("reference", "exact")))
    zs = float(curve["trace_depth"].values)
    lv = _levels(data, scene, finest) if finest else "no method ran it"
    bodies = heated_bodies(curve) or [1]
    doc.heading(3, f"`{scene}` behind the patch and in depth", trace_anchor(scene))
    doc.paragraph(hot_note(data, scene), css="warning")
    rises = {b: float(np.nanmax(np.asarray(curve["trace_peak_temperature"].values[b], float))) - body_bulk(data, scene, b)
             for b in bodies}
    main = max(bodies, key=lambda b: rises[b])
    for body in [main] + [b for b in bodies if b != main]:
        who = BODIES[body]
        caption = (f"`{scene}`, {who}: temperature rise above the bulk along the rolling direction (y = 0) on the "
                   f"surface and at depth z* = {num(zs * 1e3)} mm, including the trace behind the patch (top); rise "
                   "against depth at the hottest surface point, the highest rise each depth reaches during the pass "
                   "and the fastest cooling after it (bottom; exact: infinite at the surface); grey band: exact "
                   f"({ref}); methods at their finest level ({lv}).")
        args = (TF.trace, finest, curve, body, ctx.palette, f"{scene} ({who}): thermal trace")
        if body == main:
            ctx.draw(doc, f"trace-{scene}-{who}", caption, *args, bulk=body_bulk(data, scene, body))
        else:
            with doc.details(f"The {who}'s trace (its rise peaks at {num(rises[body])} K, the {BODIES[main]}'s at "
                             f"{num(rises[main])} K)"):
                ctx.draw(doc, f"trace-{scene}-{who}", caption, *args, bulk=body_bulk(data, scene, body))
    if "surface_map" in curve:
        with doc.details(f"Surface map of the trace of `{scene}` ({BODIES[main]})"):
            for body in [main]:
                who = BODIES[body]
                ctx.draw(doc, f"trace-map-{scene}-{who}", f"`{scene}`, {who}: surface temperature rise [K] over the "
                         f"patch (dashed outline) and its trace behind it, exact ({ref}) and each method at its "
                         f"finest level ({lv}); one colour scale.", TF.maps, finest, curve, body,
                         f"{scene} ({who}): surface temperature rise", bulk=body_bulk(data, scene, body))
