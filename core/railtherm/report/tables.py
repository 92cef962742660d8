"""Rows of the report's tables, built from what :mod:`.load` read, sized to fit a 1024 px page.

Columns that are missing or zero in every row are dropped (their names are returned for a note);
refused and failed runs are not rows but one line per reason (methods and levels named, counted);
identical messages are said once with their count.
"""
from __future__ import annotations

import math

import numpy as np

from .document import Cell
from .format import duration, exact, finite, label, level_range, memory, num, pct, short
from .load import Run, StudyData

__all__ = ["METRIC_SHORT", "metric_name", "error_text", "run_table", "refusal_lines", "message_lines", "order_table", "published_table",
           "cross_tables", "reference_words"]

METRIC_SHORT = {"max_surface_temperature": "max T", "mean_contact_temperature": "mean T",
                "surface_temperature_l2": "T (L2 norm)", "pressure_l2": "p (L2 norm)", "max_pressure": "p max",
                "semi_axis_a": "a", "creep_force_x": "Fx", "frictional_power": "P",
                "steady_wheel_temperature": "steady T wheel", "steady_mean_contact_temperature": "steady mean T",
                "peak_temperature": "peak T", "cooling_rate": "cooling rate", "cooling_rate_all_depths":
                "cooling rate, all depths", "heated_depth": "isotherm depth", "time_above": "time above",
                "pass_peak_temperature": "pass peak T", "residual_rise": "residual rise",
                "temperature_history": "T history"}
METRIC_ORDER = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature_l2", "creep_force_x",
                "max_pressure", "semi_axis_a", "pressure_l2", "frictional_power", "steady_wheel_temperature",
                "steady_mean_contact_temperature")
#: words a reference is shown with
SELF_MARK, METHOD_MARK = "†", "‡"


def _metric_order(names) -> list[str]:
    names = set(names)
    return [m for m in METRIC_ORDER if m in names] + sorted(names - set(METRIC_ORDER))


def reference_words(ref: str) -> str:
    """A reference tag in words (:func:`~.format.label`): 'analytic:jaeger' -> 'exact Jaeger band',
    'method:green' -> "green's finest level", 'self:finest' -> 'own finest level'."""
    return label(ref) if ref else "none"


def _timing(r: Run) -> str:
    t = duration(r.wall_time)
    if finite(r.wall_time_median) and r.wall_time_median != r.wall_time:
        t += " / " + duration(r.wall_time_median)
    if finite(r.timing_runs):
        t += f" ({int(r.timing_runs)})"
    return t


def metric_name(metric: str, depths=()) -> str:
    """A metric's short column name; the cooling rate with the depths it is scored at (metrics.nc's
    ``cooling_rate_depth``: "cooling rate, z ≥ 26 µm") and the all-depths variant marked as not used by the
    verdict."""
    if metric == "cooling_rate":
        zs = sorted({float(f"{z * 1e6:.3g}") for z in depths if finite(z)})
        if zs:
            return "cooling rate, z ≥ " + (f"{num(zs[0])} µm" if len(zs) == 1 else f"{num(zs[0])}–{num(zs[-1])} µm")
    if metric == "cooling_rate_all_depths":
        return "cooling rate, all depths (not used by the verdict)"
    return METRIC_SHORT.get(metric) or label(metric)


def error_text(r: Run, metric: str) -> str:
    """A run's error on ``metric`` as the run table prints it: signed where metrics.nc stores the sign,
    "not finite" for an infinite error (a value that is not finite where its reference is), "—" when the
    metric is not scored (metrics.nc's ``not_scored`` says why), "–" when there is none."""
    e = r.errors.get(metric, math.nan)
    if e == math.inf:
        return "not finite"
    if finite(e):
        s = r.signed.get(metric, math.nan)
        return pct(s, unit=False, signed=True) if finite(s) else pct(e, unit=False)
    return "—" if metric in r.not_scored else "–"


def _error_column(r: Run, met: str, marked: dict):
    text = error_text(r, met)
    if text in ("–", "—"):
        return text
    ref = r.references.get(met, "")
    mark = SELF_MARK if ref.startswith("self") else METHOD_MARK if ref.startswith("method:") else ""
    if mark == METHOD_MARK:
        marked.setdefault(ref, set()).add(r.method)
    return text + mark


def run_table(data: StudyData, scene: str) -> tuple[list[str], list[list], list[str], list[str]]:
    """Runs with a result: header, rows, names of dropped columns, notes (references of marked errors, the
    reasons of metrics not scored)."""
    runs = sorted((r for r in data.runs_of(scene) if r.has_result), key=lambda r: (r.method, r.level))
    metrics = _metric_order({k for r in runs for k in list(r.errors) + list(r.not_scored)})
    if "cooling_rate_all_depths" in metrics and "cooling_rate" in metrics:   # beside the scored one
        metrics.remove("cooling_rate_all_depths")
        metrics.insert(metrics.index("cooling_rate") + 1, "cooling_rate_all_depths")
    depths = [r.cooling_depth for r in runs]
    median = any(finite(r.wall_time_median) for r in runs)
    time_head = "time min" + (" / median" if median else "") + (" (n)" if any(finite(r.timing_runs) for r in runs)
                                                                 else "")
    energy_head = "energy balance [%]"
    cols = [("method", lambda r: r.method, False), ("level", lambda r: str(r.level), False),
            ("status", lambda r: Cell(r.status, r.status), False),
            (time_head, _timing, False),
            (data.memory_label, lambda r: r.memory, True),
            (energy_head, lambda r: r.energy_balance, True)]
    marked = {}
    for met in metrics:
        cols.append((f"err {metric_name(met, depths)} [%]", lambda r, met=met: _error_column(r, met, marked), False))
    header, table, dropped = [], [[] for _ in runs], []
    for name, get, numeric in cols:
        vals = [get(r) for r in runs]
        if numeric and all(not finite(x) or float(x) == 0.0 for x in vals):
            dropped.append(name)
            continue
        if name.startswith("err ") and all(v in ("–", "0") for v in vals):
            dropped.append(name)
            continue
        header.append(name)
        for row, v in zip(table, vals):
            if name == data.memory_label:
                row.append(memory(v))
            elif name == energy_head:
                row.append(pct(v, unit=False, floor=1e-9))
            else:
                row.append(v)
    notes = []
    if any(SELF_MARK in str(c) for row in table for c in row):
        notes.append(f"{SELF_MARK} error against the method's own finest level: an estimate of its discretisation "
                     "error, not a verification")
    for ref, methods in sorted(marked.items()):
        notes.append(f"{METHOD_MARK} error of {', '.join(sorted(methods))} against {reference_words(ref)}")
    if any("not finite" in str(c) for row in table for c in row):
        notes.append("not finite: the run's value is NaN or infinite where its reference is finite; the metric "
                     "fails (inaccurate)")
    notes += _not_scored_notes(runs, metrics, depths)
    return header, table, dropped, notes


def _not_scored_notes(runs: list[Run], metrics: list[str], depths) -> list[str]:
    """One note per (metric, reason) of the runs whose metric is not scored: '— creep force Fx: zero by
    symmetry ... (green levels 0–2)'."""
    by: dict = {}
    for r in runs:
        for met in metrics:
            if met in r.not_scored and not finite(r.errors.get(met, math.nan)) and r.errors.get(met) != math.inf:
                by.setdefault((met, r.not_scored[met]), {}).setdefault(r.method, []).append(r.level)
    return [f"— {metric_name(met, depths)} not scored: {short(why, 200)} ("
            + "; ".join(f"{m} level {level_range(lv)}" for m, lv in sorted(who.items())) + ")"
            for (met, why), who in by.items()]


def refusal_lines(runs: list[Run], n: int = 260) -> list[str]:
    """One line per (status, reason): 'fipy refused levels 2–3 (budget): <reason>'; methods sharing a
    reason are named together, and the reason is said once, shortened at a word to ``n`` characters."""
    groups: dict = {}
    for r in runs:
        if r.status in ("refused", "failed"):
            groups.setdefault((r.status, r.reason_kind, r.message), {}).setdefault(r.method, []).append(r.level)
    lines = []
    for (status, kind, msg), by_method in groups.items():
        lv = {m: level_range(v) for m, v in by_method.items()}
        same = len(set(lv.values())) == 1
        who = (", ".join(sorted(by_method)) + f" {status} level{'s' if len(next(iter(by_method.values()))) > 1 else ''} "
               f"{next(iter(lv.values()))}") if same else \
            "; ".join(f"{m} {status} levels {v}" for m, v in sorted(lv.items()))
        lines.append(f"**{who}**" + (f" ({kind})" if kind else "") + f": {short(msg, n) or 'no message'}")
    return lines


def message_lines(runs: list[Run]) -> list[str]:
    """Messages of runs with a result, each once with the runs it applies to."""
    groups: dict = {}
    for r in runs:
        if r.has_result and r.message:
            groups.setdefault(r.message, {}).setdefault(r.method, []).append(r.level)
    out = []
    for msg, by in groups.items():
        n = sum(len(v) for v in by.values())
        who = "; ".join(f"{m} level {level_range(v)}" for m, v in sorted(by.items()))
        out.append(f"{short(msg, 200)} ({n} run{'s' if n > 1 else ''}: {who})")
    return out


def _order_words(o) -> str:
    if not finite(o.order):
        return "–"
    if o.order < 0:
        return f"no convergence ({num(o.order, 2).replace('-', '−')})"
    if abs(o.order) < 0.1:
        return f"error floor ({num(o.order, 2).replace('-', '−')})"
    return num(o.order, 3)


def order_table(data: StudyData, scene: str) -> tuple[list[str], list[list], list[str]]:
    """Fitted orders with the theoretical ones beside them, marks for self- and method-referenced ladders,
    and notes naming the references (with their own accuracy where known) and the Richardson estimates."""
    orders = [o for o in data.orders.get(scene, []) if finite(o.order)]
    rich = [o for o in data.orders.get(scene, []) if finite(o.richardson)]
    if not orders and not rich:
        return [], [], []
    metrics = _metric_order({o.metric for o in orders})
    methods = sorted({o.method for o in orders})
    depths = [r.cooling_depth for r in data.runs_of(scene) if r.has_result]
    header = ["method"] + [metric_name(m, depths) for m in metrics]
    rows, independent_refs, method_refs = [], [], []
    for meth in methods:
        row = [meth]
        for met in metrics:
            o = next((x for x in orders if x.method == meth and x.metric == met), None)
            if o is None:
                row.append("–")
                continue
            ref = o.reference or _ladder_reference(data, scene, meth, met)
            text = _order_words(o)
            if finite(o.theoretical):
                text += f" (th. {num(o.theoretical, 2)})"
            if ref.startswith("self"):
                text += " " + SELF_MARK
            elif ref.startswith("method:"):
                text += " " + METHOD_MARK
                method_refs.append(ref)
            elif ref:
                independent_refs.append(ref)
            row.append(text)
        rows.append(row)
    notes = []
    if independent_refs:
        notes.append("Unmarked orders are against an exact reference: "
                     + ", ".join(reference_words(r) for r in dict.fromkeys(independent_refs)))
    for ref in dict.fromkeys(method_refs):
        notes.append(f"{METHOD_MARK} against {_against(data, scene, ref)}")
    if any(SELF_MARK in c for r in rows for c in r):
        notes.append(f"{SELF_MARK} self-convergence: slope of the error against the method's own finest level; it "
                     "says how fast the ladder settles, not that it settles on the right answer")
    for o in rich:
        unc = f" ± {pct(o.richardson_uncertainty)}" if finite(o.richardson_uncertainty) else ""
        notes.append(f"{o.method}, {metric_name(o.metric, depths)}: Richardson estimate of the finest "
                     f"level's error {pct(o.richardson)}{unc}")
    return header, rows, notes


def _ladder_reference(data: StudyData, scene: str, method: str, metric: str) -> str:
    refs = [r.references.get(metric, "") for r in sorted(data.runs_of(scene, method), key=lambda r: r.level)
            if metric in r.errors]
    return next((x for x in refs if x), "")


def _against(data: StudyData, scene: str, ref: str) -> str:
    words = reference_words(ref)
    if ref.startswith("method:"):  # the reference's own accuracy, where the metrics know it
        other = ref.split(":", 1)[1]
        fr = data.finest_result(scene, other)
        if fr is not None and finite(fr.headline_error):
            words += f" (whose own error is {pct(fr.headline_error)} at level {fr.level})"
    return words


BODIES = ("wheel", "rail")


def _value_text(v: np.ndarray, bulk=(0.0, 0.0)) -> tuple[str, np.ndarray]:
    """A per-body value as text and the values to compare: both bodies when they differ, the heated one
    alone when the other stays at its bulk temperature (an unheated body is not a −100 % error)."""
    v = np.atleast_1d(np.asarray(v, float))
    if v.size == 2 and np.isfinite(v).all():
        heated = [i for i in (0, 1) if abs(v[i] - bulk[i]) > 1e-9 * max(1.0, abs(v[i]))]
        if len(heated) == 1:
            i = heated[0]
            return f"{num(v[i], 4)} ({BODIES[i]})", v[i:i + 1]
        if abs(v[0] - v[1]) > 1e-3 * max(abs(v[0]), abs(v[1]), 1e-300):
            return f"{num(v[0], 4)} / {num(v[1], 4)} (wheel / rail)", v
    return num(v.flat[0], 4), v[:1]


#: unit of a published quantity, by the name of the result variable
PUBLISHED_UNITS = {"max_surface_temperature": "°C", "mean_contact_temperature": "°C", "steady_wheel_temperature": "°C",
                   "steady_mean_contact_temperature": "°C"}


def published_table(data: StudyData, scene: str, finest: dict) -> tuple[list[str], list[list], str]:
    """Published values exactly as given, each method's finest result and its difference [%]."""
    pub = {k: v for k, v in data.scene[scene].published.items() if k != "source"}
    if not pub:
        return [], [], ""
    sc = data.scene[scene].scene
    bulk = (float(sc.wheel.bulk_temperature), float(sc.rail.bulk_temperature)) if sc is not None else (0.0, 0.0)
    methods = sorted(finest)
    rows = []
    for var, value in pub.items():
        unit = PUBLISHED_UNITS.get(var, "")
        row = [f"`{var}`", exact(value)]
        for meth in methods:
            ds = finest[meth]
            if var not in ds:
                row.append("–")
                continue
            text, vals = _value_text(ds[var].values, bulk if unit == "°C" else (0.0, 0.0))
            try:
                ref = float(value)
                deltas = " / ".join(pct((x - ref) / abs(ref), signed=True) for x in vals) if ref else ""
            except (TypeError, ValueError):
                deltas = ""
            row.append(text + (f" (Δ {deltas})" if deltas else ""))
        rows.append(row)
    header = ["quantity", "published"] + [f"{m} (level {int(finest[m].attrs.get('level', -1))})" for m in methods]
    return header, rows, str(data.scene[scene].published.get("source", "not given"))


def cross_tables(data: StudyData, scene: str) -> list[tuple[str, list[str], list[list]]]:
    """Cross-method relative differences at the finest levels: (quantity, header, rows) per quantity."""
    out = []
    for q, (methods, mat) in data.cross.get(scene, {}).items():
        off = np.array(mat, float)
        np.fill_diagonal(off, np.nan)
        if not np.isfinite(off).any():
            continue
        rows = [[methods[i]] + ["" if i == j else pct(mat[i][j], unit=False) for j in range(len(methods))]
                for i in range(len(methods))]
        out.append((q, ["method \\ vs"] + methods, rows))
    return out

