"""The report's sections, in page order: verdict, one section per scene, one per sweep, benchmarks,
environment. Each writes into a :class:`~.document.Document`; a figure that cannot be drawn is replaced
by a sentence saying why (and a warning), never by an exception.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import figures as F
from . import scene_figures as S
from .document import Cell, Document
from .format import duration, finite, label, level_range, num, pct, plain, quantity, short, slug
from .load import StudyData
from .study_section import describe_scene, hot_note
from .sweep_maps import sweep_maps
from .transient_section import transient_section
from .wheelset_section import wheelset_findings
from .tables import (METRIC_SHORT, cross_tables, message_lines, order_table, published_table, reference_words,
                     refusal_lines, run_table)
from .verdict import (QUANTITY, SCORECARD_RULE, Row, SweepGroup, anchor_of, cell, choose, creep_force_source, findings,
                      scorecard)

#: a refusal or failure is shown in full behind a closed box when its message is longer than this
REFUSAL_CHARS = 150
#: figures a report draws at most: a reader looks at forty figures, not at a hundred
MAX_FIGURES = 40
STATUS_LEGEND = ("**ok**: within the tolerance of an independent reference (exact solution or another method); "
                 "**inaccurate**: above it; **unverified**: ran, but nothing independent to compare with "
                 "(e.g. only its own finest level); **refused**: declined before starting (validity or budget); "
                 "**failed**: error, time-out, NaN or no convergence.")


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) [px] of a PNG file, from its header."""
    with open(path, "rb") as f:
        head = f.read(24)
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


@dataclass
class Context:
    """What every section needs besides the document: the data, where figures go, the palette."""

    data: StudyData
    fig_dir: Path
    palette: F.Palette
    figures: list = field(default_factory=list)
    max_figures: int = MAX_FIGURES
    left_out: list = field(default_factory=list)   # names of figures beyond the budget
    shown: set = field(default_factory=set)        # (scene, kind) drawn by a study-wide section

    def draw(self, doc: Document, name: str, caption: str, fn, *args, **kwargs):
        """Draw one figure into ``fig_dir/name.png`` and add it with ``caption``; a failure becomes a sentence.
        Beyond :attr:`max_figures` figures nothing is drawn and the figure's name is kept for a note."""
        if len(self.figures) >= self.max_figures:
            self.left_out.append(name)
            return None
        t0 = time.perf_counter()
        try:
            res = fn(*args, path=self.fig_dir / f"{name}.png", **kwargs)
        except Exception as exc:  # noqa: BLE001 - one figure never stops the report
            msg = f"Figure '{caption}' could not be drawn: {type(exc).__name__}: {short(exc, 300)}"
            warnings.warn(f"railtherm report: {msg}", RuntimeWarning, stacklevel=2)
            doc.paragraph(msg, note=True)
            return None
        if res is None:
            return None
        path, width = res
        self.figures.append(path)
        w, h = F.SIZES.get(Path(path)) or png_size(path)
        doc.figure(f"figures/{path.name}", plain(caption), width, int(round(h * width / w)) if w and width else None)
        took = time.perf_counter() - t0
        if took > 20:
            doc.paragraph(f"(drawing this figure took {took:.0f} s)", note=True)
        return path


# -- verdict -------------------------------------------------------------------------------------------
def verdict_section(doc: Document, ctx: Context, table_rows: list[Row], max_rows: int = 200):
    """The verdict: key findings, the scorecard, why cells are not ok, and the work-precision figure."""
    data = ctx.data
    tol = data.tolerance
    doc.heading(2, "Verdict", "verdict")
    cards = scorecard(data, table_rows)
    # the wheelset-on-profiles finding (the shifts where a chain's flash temperature misses) leads: it is the
    # point of such a study
    items = (wheelset_findings(data) + findings(data, table_rows, cards))[:5]
    if items:
        doc.heading(3, "Key findings")
        doc.bullets([plain(t) for t in items])
    shown = table_rows[:max_rows]
    body = []
    for row in shown:
        what = METRIC_SHORT.get(row.headline) or label(row.headline) or "–"
        name = (f"[{row.label}](#{row.anchor})" if row.anchor else row.label) \
            + (f" ({len(row.scenes)} scenes)" if row.group else "")
        body.append([f"{name} · {what}"] + [cell(cards[(row.label, m)]) for m in data.methods])
    heads = dict.fromkeys(r.headline for r in shown if r.headline)
    doc.table(f"Scorecard. {SCORECARD_RULE} Tolerance: "
              f"{pct(tol) if tol is not None else 'not recorded'}. A sweep is one row: its worst member's status, the "
              "largest error and time (≤). Headlines: "
              + ", ".join(f"{METRIC_SHORT.get(h) or label(h)} = {label(h)}" for h in heads) + ".",
              ["scene · headline"] + data.methods, body, css="scorecard")
    if len(table_rows) > len(shown):
        doc.paragraph(f"{len(table_rows) - len(shown)} further rows are left out of the scorecard.", note=True)
    doc.paragraph(STATUS_LEGEND, note=True)
    reasons = _cell_reasons(data, table_rows, cards)
    if reasons:
        with doc.details(f"Why cells are refused, failed or unverified ({len(reasons)} reasons)"):
            doc.bullets([plain(t) for t in reasons])
    panels = [_panel(data, row) for row in shown[:24]]
    if panels:
        ctx.draw(doc, "000-work-precision", "Work-precision of every scene: relative error of the headline "
                 "quantity against an independent reference (x) and best wall time (y), one line per method from "
                 "the coarsest to the finest level; filled markers are ok, hollow ones above the tolerance "
                 "(dashed red line); a dotted line is a self-convergence ladder (no independent reference). A sweep's "
                 "panel shows, per level, the largest error and time over its scenes.",
                 F.work_precision, panels, ctx.palette, tol, methods=_methods_with_results(data))
    counts = {s: sum(r.status == s for r in data.runs) for s in ("ok", "inaccurate", "unverified", "refused", "failed")}
    doc.paragraph(f"{len(data.runs)} runs: {len(data.scenes)} scenes × {len(data.methods)} methods "
                  f"({', '.join(data.methods)}) × levels {level_range(data.levels) or '–'}; "
                  + ", ".join(f"{v} {k}" for k, v in counts.items() if v) + ". Output folder: `"
                  + str(data.out) + "`.", note=True)


def _methods_with_results(data: StudyData) -> list[str]:
    return [m for m in data.methods if any(r.method == m and r.has_result for r in data.runs)]


def _cell_reasons(data: StudyData, table_rows, cards) -> list[str]:
    """One line per distinct reason a cell is refused, failed or unverified, naming its cells."""
    by: dict = {}
    for row in table_rows:
        for m in data.methods:
            v = cards[(row.label, m)]
            if v.status not in ("refused", "failed", "unverified"):
                continue
            # members' order, each message once (a set's order follows the string hash, which differs per process)
            msgs = list(dict.fromkeys(x.message for x in v.members)) if v.members else [v.message]
            for msg in msgs:
                text = msg.replace(f"scene '{row.scenes[0]}': ", "") if msg else "no message"
                by.setdefault((v.status, v.reason_kind, text), []).append(f"{m} on {row.label}")
    return [f"**{st}**" + (f" ({kind})" if kind else "") + f" — {', '.join(cells[:6])}"
            + (f" and {len(cells) - 6} more" if len(cells) > 6 else "") + f": {short(msg, 200)}"
            for (st, kind, msg), cells in by.items()]


def _panel(data: StudyData, row: Row) -> F.Panel:
    title = f"{row.label}: {METRIC_SHORT.get(row.headline) or label(row.headline)}"
    if row.group:
        title += " (sweep, worst)"
    panel = F.Panel(short(title, 38))
    h = row.headline
    for m in data.methods:
        by_level: dict = {}
        for s in row.scenes:
            for r in data.runs_of(s, m):
                if not r.has_result:
                    continue
                err, self_ref = r.headline_error, False
                if not finite(err) and r.references.get(h, "").startswith("self") and h in r.errors:
                    err, self_ref = r.errors[h], True
                if not finite(err):
                    continue
                p = by_level.get(r.level)
                worse = p is None or err > p.error
                status = r.status if p is None or r.status == "ok" and p.status == "ok" else \
                    (p.status if p.status != "ok" else r.status)
                by_level[r.level] = F.Point(err if worse else p.error,
                                            max(r.wall_time, p.time if p else -math.inf), r.level, status, self_ref)
        if by_level:
            panel.series[m] = list(by_level.values())
    if not panel.series:
        panel.note = "no error against a reference" if any(r.has_result for s in row.scenes for r in data.runs_of(s)) \
            else "no run produced a result"
    return panel


# -- one scene -----------------------------------------------------------------------------------------
def _references(data: StudyData, scenes: list[str]) -> list[str]:
    refs = []
    for s in scenes:
        for r in data.runs_of(s):
            for met, ref in sorted(r.references.items()):
                if ref:
                    refs.append(ref)
    return list(dict.fromkeys(refs))


def _finest(data: StudyData, scene: str) -> dict:
    out = {}
    for m in data.methods:
        r = data.finest_result(scene, m)
        if r is not None:
            ds = data.run_file(scene, m, r.level)
            if ds is not None:
                out[m] = ds
    return out


def _creep_sources(data: StudyData, scene: str) -> str:
    si = data.scene[scene]
    asked = "creep_force_x" in (getattr(si.scene, "outputs", ()) or ())
    if not (asked or si.headline == "creep_force_x") or not any("creep_force_x" in r.errors
                                                                 for r in data.runs_of(scene)):
        return ""
    parts = []
    for m in data.methods:
        st = data.stages(scene, m)
        src = creep_force_source(st)
        if src:
            stage = next(k for k, v in st.items() if v == src)
            parts.append(f"{m} ← {src} ({stage} stage)" if src != m else f"{m} ← {m}")
    return "Creep force computed by: " + "; ".join(parts) + "." if parts else ""


def _status_counts(runs) -> str:
    counts = {}
    for r in runs:
        counts[r.status] = counts.get(r.status, 0) + 1
    return ", ".join(f"{v} {k}" for k, v in sorted(counts.items(), key=lambda kv: ["ok", "inaccurate", "unverified",
                                                                                     "refused", "failed"].index(kv[0])
                                                       if kv[0] in ("ok", "inaccurate", "unverified", "refused",
                                                                    "failed") else 9))


def _headline_line(data: StudyData, scenes: list[str]) -> str:
    si = data.scene[scenes[0]]
    runs = [r for s in scenes for r in data.runs_of(s)]
    refs = _references(data, scenes)
    head = QUANTITY.get(si.headline, si.headline) or "none"
    ref_text = "; ".join(reference_words(r) for r in refs) or "none"
    kind = {"analytic": "exact solutions where they exist", "finest": "each method's own finest level"}.get(
        si.reference_kind, f"method {si.reference_kind}'s finest level" if si.reference_kind else "")
    if kind:
        ref_text = f"{kind} ({ref_text})" if refs else kind
    return (f"Headline quantity: **{head}**. Errors taken against: {ref_text}. "
            f"{len(runs)} runs: {_status_counts(runs)}.")


def scene_section(doc: Document, ctx: Context, idx: int, scene: str, trace_anchor: str = ""):
    """One scene: inputs, headline and references, refusals, published values, the runs (closed), and
    its figures; a scene of the thermal-trace section links there instead of repeating its figures."""
    data = ctx.data
    si = data.scene[scene]
    runs = data.runs_of(scene)
    doc.heading(2, f"{idx}. Scene `{scene}`", anchor_of(scene))
    desc = describe_scene(si.scene)
    doc.paragraph((desc + ". " if desc else "") + _headline_line(data, [scene]))
    doc.paragraph(hot_note(data, scene), css="warning")
    brief, full = refusal_lines(runs, REFUSAL_CHARS), refusal_lines(runs, 4000)
    doc.bullets([plain(t) for t in brief])
    cut = [plain(f) for b, f in zip(brief, full) if b != f]
    if cut:
        with doc.details(f"Refusals and failures in full ({len(cut)})"):
            doc.bullets(cut)
    src = _creep_sources(data, scene)
    if src:
        doc.paragraph(src)
    finest = _finest(data, scene)
    _published(doc, data, scene, finest)
    n_runs = sum(1 for r in runs if r.has_result)
    with doc.details(f"Details of `{scene}`: the {n_runs} run{'s' if n_runs != 1 else ''} with a result (status, "
                     "time, memory, errors), "
                     "convergence orders, differences between methods"):
        _run_details(doc, data, scene)
        _orders(doc, data, scene)
        _cross(doc, data, scene)
    if trace_anchor:
        doc.paragraph(f"Figures of this scene (temperature along x, in depth, maps of the trace): "
                      f"[thermal trace of `{scene}`](#{trace_anchor}).")
    else:
        _scene_figures(doc, ctx, idx, scene, finest)
    transient_section(doc, ctx, idx, scene, finest)   # nothing for a steady scene


def _run_details(doc: Document, data: StudyData, scene: str):
    """The runs with a result as a table, the columns left out, the reference marks and the runs' messages."""
    header, rows, dropped, notes = run_table(data, scene)
    if not rows:
        return
    msgs = message_lines(data.runs_of(scene))
    doc.table(f"Runs of `{scene}` with a result. Time: best / median of the timed solves (number of solves); "
              f"errors relative, in %.", header, rows, css="runs")
    if dropped:
        doc.paragraph("Columns left out (missing or zero in every run): " + ", ".join(dropped) + ".", note=True)
    for n in notes:
        doc.paragraph(plain(n) + ".", note=True)
    if msgs:
        doc.bullets([plain(m) for m in msgs])


def _published(doc: Document, data: StudyData, scene: str, finest: dict):
    header, rows, source = published_table(data, scene, finest)
    if rows:
        doc.table(f"Published values (as given; source: {source}) beside each method's finest result and its "
                  "difference Δ from them.", header, rows)


def _orders(doc: Document, data: StudyData, scene: str):
    header, rows, notes = order_table(data, scene)
    if rows:
        doc.table("Fitted convergence order (slope of log error against log h, h = 2^-level), with the method's "
                  "theoretical order (th.) where it declares one.", header, rows)
    for n in notes:
        doc.paragraph(plain(n) + ".", note=True)


def _cross(doc: Document, data: StudyData, scene: str):
    for q, header, rows in cross_tables(data, scene):
        doc.table(f"Difference between methods at their finest levels, {QUANTITY.get(q) or label(q)}: "
                  "|row − column| / |column| [%].", header, rows)


def _bulk(si) -> tuple | None:
    sc = si.scene
    if sc is None:
        return None
    return (sc.wheel.bulk_temperature, sc.rail.bulk_temperature)


def _scene_figures(doc: Document, ctx: Context, idx: int, scene: str, finest: dict):
    """The surface-temperature figure, the depth figure (when there is a reference profile) and the
    traction figure (when the scene asks for traction) of one scene."""
    data = ctx.data
    si = data.scene[scene]
    curve = (data.curves or {}).get(scene)
    base = f"{idx:03d}-{slug(scene)}"
    wants_curve = any("surface_temperature" in ds or "temperature" in ds or "traction_x" in ds
                      for ds in finest.values())
    if finest and wants_curve and data.curves is None:
        doc.paragraph("Exact reference curves are not drawn: `references.nc` is missing from the output folder.",
                      note=True)
    exact = curve is not None and "surface_temperature" in curve
    ref_name = label(str(curve.attrs.get("reference", ""))) if curve is not None else ""
    ref_method = si.reference_kind if si.reference_kind in finest else ""
    bulk = _bulk(si) or (0.0, 0.0)
    ref_words = (f", with the exact solution ({ref_name}, grey band) and each method's difference from it" if exact
                 else f", with the reference method {ref_method} as a grey band" if ref_method else "")
    ctx.draw(doc, f"{base}-surface", f"`{scene}`: surface temperature rise above the bulk along the rolling direction "
             "through the hottest surface point, each method's finest successful level" + ref_words + ".",
             S.surface, finest, curve, ctx.palette, f"{scene}: surface temperature", bulk=bulk, ref_method=ref_method)
    exact_depth = curve is not None and "temperature" in curve
    law = getattr(si.scene, "friction", None) if si.scene is not None else None
    mu = None if law is None else law.nominal
    outputs = set(getattr(si.scene, "outputs", ()) or ())
    traction = si.scene is None or bool(outputs & {"traction_x", "stick"})   # full sliding: slip everywhere
    with doc.details(f"More figures of `{scene}`: " + ("depth profile and traction" if traction else "depth profile")):
        ctx.draw(doc, f"{base}-depth", f"`{scene}`: temperature rise against depth through the hottest surface "
                 "point, " + ("the exact profile as a grey band" if exact_depth else f"the reference method "
                              f"{ref_method} as a grey band") + ".", S.depth, finest, curve, bulk, ctx.palette,
                 f"{scene}: depth profile", ref_method=ref_method)
        if traction and (scene, "traction") not in ctx.shown:   # the exact-contact section's maps show it
            ctx.draw(doc, f"{base}-traction", f"`{scene}`: tangential traction and stick (black) / slip (grey) of "
                     "each method's finest level" + (", with Carter's exact solution" if curve is not None
                                                     and "carter_traction_x" in curve else "") + ".",
                     F.traction, finest, curve, mu, ctx.palette, f"{scene}: traction and stick/slip")


# -- sweeps --------------------------------------------------------------------------------------------
def _headline_value(data: StudyData, scene: str, method: str, headline: str, normalise: bool):
    """(value of the headline quantity at the method's finest result, its error, status) or None."""
    r = data.finest_result(scene, method)
    if r is None:
        return None
    ds = data.run_file(scene, method, r.level)
    if ds is None or headline not in ds:
        return None
    v = float(np.nanmax(np.asarray(ds[headline].values, float)))
    if normalise:
        sc = data.scene[scene].scene
        law = getattr(sc, "friction", None)
        mu = None if law is None else law.nominal
        n = float(ds["normal_force"]) if "normal_force" in ds else getattr(sc, "normal_force", None)
        if not mu or not n:
            return None
        v = v / (mu * n)
    signed = r.signed.get(headline, math.nan)
    return v, signed if finite(signed) else r.headline_error, r.status


def sweep_section(doc: Document, ctx: Context, idx: int, group: SweepGroup, anchor: str):
    data = ctx.data
    names = [n for _, n in group.members]
    first = data.scene[names[0]]
    h = first.headline
    key = label(group.key)
    doc.heading(2, f"{idx}. Sweep `{group.label}` over {key} ({len(names)} scenes)", anchor)
    desc = describe_scene(first.scene)
    if desc:
        doc.paragraph(desc + f"; swept: {key} = " + ", ".join(num(v, 4) for v, _ in group.members) + ".")
    runs = [r for s in names for r in data.runs_of(s)]
    doc.paragraph(_headline_line(data, names))
    doc.bullets([plain(t) for t in refusal_lines(runs)])
    src = _creep_sources(data, names[0])
    if src:
        doc.paragraph(src)
    creep = h == "creep_force_x" and group.key == "creepage.longitudinal"
    normalise = creep and first.scene is not None
    what = "creep force Fx / (μ N) [1]" if normalise else QUANTITY.get(h) or label(h)
    series = F.SweepSeries(key, what)
    methods = _methods_with_results(data)
    ref_col = {}
    if creep:
        curve = (data.curves or {}).get(names[0])
        if curve is not None and "creep_force_ratio" in curve and normalise:
            xs, ys = curve["creepage"].values, curve["creep_force_ratio"].values
            series.reference = (xs, ys, "Carter (exact, 2-D)", False)
            ref_col = {v: float(ys[np.argmin(np.abs(xs - v))]) for v, _ in group.members}
        elif curve is not None and "creep_force_ratio_linear" in curve and normalise:
            xs, ys = curve["creepage"].values, curve["creep_force_ratio_linear"].values
            series.reference = (xs, ys, "Kalker linear theory (initial slope)", True)
    rows = []
    for v, s in group.members:
        row = [num(v, 4)] + ([num(ref_col[v], 4)] if ref_col else [])
        for m in methods:
            got = _headline_value(data, s, m, h, normalise)
            if got is None:
                st = choose(data, s, m).status
                row.append(Cell(st if st != "none" else "–", st if st != "none" else ""))
                continue
            val, err, status = got
            series.values.setdefault(m, []).append((v, val, abs(err), status))   # the figure's axis is log
            text = "not finite" if err == math.inf else pct(err, signed=True) if finite(err) else ""
            row.append(Cell(num(val, 4) + (f" ({text})" if text else ""), status))
        rows.append(row)
    if series.values:
        ctx.draw(doc, f"{idx:03d}-sweep-{slug(group.label)}", f"Sweep `{group.label}`: {what} against "
                 f"{key} (left) and its relative error (right), each method at its finest successful level"
                 + ("; the exact curve as a grey band" if series.reference and not series.reference[3] else
                    "; Kalker's linear theory dashed" if series.reference else "") + ".",
                 F.sweep, series, ctx.palette, data.tolerance, group.label, methods=methods)
    # the figure shows these values; the table is the detail behind it
    with doc.details(f"{what} over the sweep as a table ({len(rows)} rows)"):
        doc.table(f"{what} of each method's finest successful level over the sweep, its error against the "
                  "reference in brackets (cell colour: status of that level).",
                  [key] + (["exact"] if ref_col else []) + methods, rows)
    if creep and data.curves is None:
        doc.paragraph("The exact creep-force curve is not drawn: `references.nc` is missing from the output folder.",
                      note=True)
    sweep_maps(doc, ctx, idx, first.base, methods)  # over two swept keys, once per swept [[scene]]
    msgs = message_lines(runs)
    if msgs:
        with doc.details(f"Messages of runs with a result ({len(msgs)} distinct)"):
            doc.bullets([plain(m) for m in msgs])
