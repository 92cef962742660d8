"""The verdict: one scorecard cell per scene (or sweep) × method, and key findings in words.

The scorecard is read from ``metrics.nc`` (``verdict_level``, ``verdict_error``, ``verdict_time``,
``verdict_status``, ``verdict_message``: docs/verdicts.md), never recomputed; for metrics of an earlier
release without them, the same rule (:func:`railtherm.analysis.verdicts.ladder_verdict`) is applied to the
run table. A cell shows the cheapest level that is within the tolerance of an independent reference on the
headline together with every finer level that ran (its status, headline error, wall time and level). When no
level qualifies, the cell shows the status of the finest level that ran (``inaccurate`` with its headline
error, ``unverified``, ``failed``) or ``refused``. A ladder whose error rises again under refinement says
"non-monotone"; a verdict against a scene's reference method that is not converged itself says "reference not
converged". The scene's reference method gets no verdict: its cell says ``reference`` with its finest
successful level. A sweep is one row: the cell summarises its members' cells.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

from ..contract.verdict_rules import RISE_FRACTION, cheapest
from ..output import store
from .document import Cell
from .format import duration, label, level, level_range, pct, ratio, short
from .load import Run, StudyData, independent

__all__ = ["SweepGroup", "Row", "Verdict", "sweep_groups", "rows", "choose", "scorecard", "findings",
           "creep_force_source"]

#: keys preferred as the swept axis when a scene sweeps several
SWEEP_AXES = ("creepage.longitudinal", "sliding_speed")
#: worst first: the status a sweep's cell takes
SEVERITY = ("failed", "inaccurate", "unverified", "refused", "ok", "reference", "none")

QUANTITY = {"max_surface_temperature": "max. surface temperature", "mean_contact_temperature":
            "mean contact temperature", "creep_force_x": "creep force", "max_pressure": "max. pressure",
            "semi_axis_a": "semi-axis a", "frictional_power": "frictional power",
            "surface_temperature_l2": "surface temperature (L2 norm)", "pressure_l2": "pressure (L2 norm)",
            "steady_wheel_temperature": "steady wheel temperature",
            "steady_mean_contact_temperature": "steady mean contact temperature",
            "pass_peak_temperature": "peak temperature of each pass"}


@dataclass
class SweepGroup:
    base: str
    key: str
    others: tuple
    members: list  # [(value, scene name)], sorted by value

    @property
    def label(self) -> str:
        return self.base + (f" ({', '.join(f'{k}={v}' for k, v in self.others)})" if self.others else "")


@dataclass
class Row:
    label: str
    anchor: str
    scenes: list[str]
    headline: str
    group: SweepGroup | None = None


@dataclass
class Verdict:
    method: str
    status: str  # ok | inaccurate | unverified | refused | failed | none
    run: Run | None = None
    error: float = math.nan
    time: float = math.nan
    reason_kind: str = ""
    message: str = ""
    richardson: float = math.nan
    members: list = field(default_factory=list)  # a sweep's member verdicts
    note: str = ""                               # metrics.nc's verdict_message (non-monotone, reference not converged)
    signed: float = math.nan                     # the headline error with its sign (metrics.nc), NaN when not stored
    cooling_depth: float = math.nan              # shallowest depth [m] its cooling-rate error scores (metrics.nc)


def _numeric(v) -> bool:
    try:
        float(v)
        return True
    except (TypeError, ValueError):
        return False


def sweep_groups(data: StudyData) -> list[SweepGroup]:
    """Scenes generated from one list value: same base name, same other swept values (2 members or more)."""
    groups: dict = {}
    for nm in data.scenes:
        sweep = data.scene[nm].sweep
        keys = [k for k in SWEEP_AXES if k in sweep] + [k for k in sweep if k not in SWEEP_AXES and _numeric(sweep[k])]
        if not keys:
            continue
        key = keys[0]
        others = tuple(sorted((k, str(v)) for k, v in sweep.items() if k != key))
        groups.setdefault((data.scene[nm].base, key, others), []).append((float(sweep[key]), nm))
    return [SweepGroup(b, k, o, sorted(v)) for (b, k, o), v in groups.items() if len(v) >= 2]


def rows(data: StudyData, groups: list[SweepGroup]) -> list[Row]:
    """Scorecard rows in study order: each scene, a sweep where its first member stands."""
    in_group = {nm: g for g in groups for _, nm in g.members}
    out, seen = [], set()
    for i, nm in enumerate(data.scenes):
        g = in_group.get(nm)
        if g is None:
            out.append(Row(nm, f"scene-{_anchor(nm)}", [nm], data.scene[nm].headline))
        elif id(g) not in seen:
            seen.add(id(g))
            names = [n for _, n in g.members]
            out.append(Row(g.label, f"sweep-{_anchor(g.label)}", names, data.scene[names[0]].headline, g))
    return out


def _anchor(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-").lower() or "x"


def anchor_of(scene: str) -> str:
    return f"scene-{_anchor(scene)}"


#: the rule the scorecard's caption states
SCORECARD_RULE = ("Each cell: the cheapest level (smallest wall time; levels within a factor 1.5 of it count as equal "
                  "and the lowest is taken) whose headline quantity is within the tolerance "
                  "of an independent reference (an exact solution or another method, never the method's own finest "
                  "level) together with every finer level that ran, with its status, signed headline error, best wall "
                  "time and level; \"ok\" also needs every other error within the tolerance. When no level qualifies: "
                  "the status of the finest level that ran. \"non-monotone\": the headline error rises again under "
                  "refinement; \"reference not converged\": the reference method's own finest-level error exceeds "
                  "a quarter of the tolerance.")


def stored_verdicts(data) -> dict:
    """(scene, method) -> metrics.nc's verdict (level, error, time, status, message) and (scene, method, level)
    -> headline_signed_error, read once per StudyData; {} when metrics.nc has no verdict variables."""
    cached = getattr(data, "_stored_verdicts", None)
    if cached is not None:
        return cached
    out: dict = {}
    try:
        m = store.read_metrics(data.out)
    except Exception:  # noqa: BLE001 - synthetic data or no metrics.nc: the rule is applied to the run table
        m = None
    if m is not None and "verdict_level" in m:
        scenes, methods = [str(x) for x in m["scene_name"].values], [str(x) for x in m["method_name"].values]
        for i, s in enumerate(scenes):
            for j, me in enumerate(methods):
                lv = float(m["verdict_level"].values[i, j])
                out[(s, me)] = {"level": int(lv) if math.isfinite(lv) else -1,
                                "error": float(m["verdict_error"].values[i, j]),
                                "time": float(m["verdict_time"].values[i, j]),
                                "status": str(m["verdict_status"].values[i, j] or ""),
                                "message": str(m["verdict_message"].values[i, j] or "")
                                if "verdict_message" in m else ""}
        for var, extra in (("headline_signed_error", ()), ("cooling_rate_depth", ("cooling_rate_depth",))):
            if var in m:
                for s, me, lv, e in zip(m["scene"].values, m["method"].values, m["level"].values, m[var].values):
                    out[(str(s), str(me), int(lv)) + extra] = float(e)
    try:
        data._stored_verdicts = out
    except AttributeError:  # pragma: no cover - a frozen stand-in
        pass
    return out


def ladder_rule(runs: list, tol: float) -> dict:
    """docs/verdicts.md's scorecard rule for metrics.nc files written without ``verdict_*`` (an earlier
    release): the report reads only the output folder, so it applies the rule that
    :func:`railtherm.analysis.verdicts.ladder_verdict` stores (tests/test_verdict_headline.py holds the two
    equal) to the run table. Returns ``level`` (−1: none qualifies), ``error``, ``time``, ``status``,
    ``message``."""
    ran = sorted((r for r in runs if r.has_result or (r.status == "failed" and r.reason_kind != "timeout")),
                 key=lambda r: r.level)
    within = [r.has_result and math.isfinite(r.headline_error) and r.headline_error <= tol for r in ran]
    qual = [r for i, r in enumerate(ran) if all(within[i:])]
    errors = [(r.level, r.headline_error) for r in ran if math.isfinite(r.headline_error)]
    rises = any(e - min(x for _, x in errors[:i]) > RISE_FRACTION * tol for i, (_, e) in enumerate(errors) if i)
    message = ("non-monotone: the headline error rises again under refinement ("
               + " → ".join(f"{100 * e:.2g} %" for _, e in errors) + " at levels "
               + ", ".join(str(lv) for lv, _ in errors) + ")") if rises else ""
    if not qual:
        return {"level": -1, "error": math.nan, "time": math.nan, "status": "", "message": message}
    ok = [r for r in qual if r.status == "ok"]
    r = cheapest(ok or qual, time=lambda r: r.wall_time, level=lambda r: r.level)
    return {"level": r.level, "error": r.headline_error, "time": r.wall_time, "status": r.status, "message": message}


def _verdict_of(data, scene: str, method: str, runs: list) -> dict:
    """The stored verdict of one ladder, else :func:`ladder_rule` on its runs (metrics without it)."""
    got = stored_verdicts(data).get((scene, method))
    if got is not None:
        return got
    return ladder_rule(runs, data.tolerance if data.tolerance is not None else 0.05)


def _signed(data, scene: str, method: str, level: int) -> float:
    e = stored_verdicts(data).get((scene, method, level), math.nan)
    return e if isinstance(e, float) else math.nan


def _depth(data, scene: str, method: str, level: int) -> float:
    return stored_verdicts(data).get((scene, method, level, "cooling_rate_depth"), math.nan)


def choose(data: StudyData, scene: str, method: str) -> Verdict:
    """The scorecard verdict of one method on one scene (metrics.nc's ``verdict_*``)."""
    runs = data.runs_of(scene, method)
    if not runs:
        return Verdict(method, "none")
    v = _verdict_of(data, scene, method, runs)
    note = v.get("message", "")
    if data.scene[scene].reference_kind == method:  # the scene's reference: measured against itself only
        r = data.finest_result(scene, method)
        if r is not None:
            return Verdict(method, "reference", r, math.nan, r.wall_time, message=f"{method} is the reference of "
                           f"{scene}", note=note)
    if v["level"] >= 0 and v["status"]:
        r = next((x for x in runs if x.level == v["level"]), None)
        return Verdict(method, v["status"], r, v["error"], v["time"], message=r.message if r else "", note=note,
                       signed=_signed(data, scene, method, v["level"]),
                       cooling_depth=_depth(data, scene, method, v["level"]))
    ran = [r for r in runs if r.has_result or (r.status == "failed" and r.reason_kind != "timeout")]
    if ran:
        r = max(ran, key=lambda x: x.level)
        if r.status == "failed":
            return Verdict(method, "failed", None, reason_kind=r.reason_kind, message=r.message, note=note)
        status = r.status
        h = data.scene[scene].headline
        rich = next((o.richardson for o in data.orders.get(scene, []) if o.method == method and o.metric == h),
                    math.nan) if status == "unverified" else math.nan
        return Verdict(method, status, r, r.headline_error, r.wall_time, message=r.message or note, richardson=rich,
                       note=note, signed=_signed(data, scene, method, r.level),
                       cooling_depth=_depth(data, scene, method, r.level))
    failed = [r for r in runs if r.status == "failed"]
    pick = failed or [r for r in runs if r.status == "refused"] or runs
    r = pick[0]
    kinds = sorted({x.reason_kind for x in pick if x.reason_kind})
    return Verdict(method, r.status if r.status in ("failed", "refused") else "none", None,
                   reason_kind=", ".join(kinds), message=r.message, note=note)


def group_verdict(verdicts: list[Verdict], method: str) -> Verdict:
    present = [v for v in verdicts if v.status != "none"]
    if not present:
        return Verdict(method, "none")
    worst = min(present, key=lambda v: SEVERITY.index(v.status))
    errs = [v.error for v in present if math.isfinite(v.error)]
    times = [v.time for v in present if math.isfinite(v.time)]
    kinds = sorted({v.reason_kind for v in present if v.reason_kind})
    notes = "; ".join(dict.fromkeys(v.note for v in present if v.note))
    return Verdict(method, worst.status, None, max(errs) if errs else math.nan, max(times) if times else math.nan,
                   reason_kind=", ".join(kinds), message=worst.message, members=verdicts, note=notes)


def marks(v: Verdict) -> list[str]:
    """The words a cell adds from its verdict message: "non-monotone", "reference not converged" (none for a
    refused cell: nothing ran to be judged)."""
    if v.status in ("refused", "none"):
        return []
    return [w for w in ("non-monotone", "reference not converged") if w in v.note]


def scorecard(data: StudyData, table_rows: list[Row]) -> dict:
    """(row label, method) -> Verdict."""
    out = {}
    for row in table_rows:
        for m in data.methods:
            if row.group is None:
                out[(row.label, m)] = choose(data, row.scenes[0], m)
            else:
                out[(row.label, m)] = group_verdict([choose(data, s, m) for s in row.scenes], m)
    return out


#: metrics shown but never used by a status (metrics.nc: analysis.metrics.UNSCORED_BY_STATUS)
NOT_A_VERDICT = ("cooling_rate_all_depths",)


def metric_words(name: str, cooling_depth: float = math.nan) -> str:
    """A metric's name in words; the cooling rate with the depths it is scored at ("cooling rate, z ≥ 26 µm")."""
    if name == "cooling_rate" and math.isfinite(cooling_depth):
        return f"cooling rate, z ≥ {cooling_depth * 1e6:.3g} µm"
    if name == "cooling_rate_all_depths":
        return "cooling rate, all depths (not used by the verdict)"
    return QUANTITY.get(name) or label(name)


def _worst_other(v: Verdict) -> str:
    """For an inaccurate run whose headline error is smaller than its worst error against an independent
    reference: that metric and its error ("cooling rate, z ≥ 26 µm 20 %"), so that the cell says why it is
    inaccurate."""
    if v.status != "inaccurate" or v.run is None:
        return ""
    refs = getattr(v.run, "references", {}) or {}
    errs = [(k, e) for k, e in (v.run.errors or {}).items()
            if isinstance(e, float) and not math.isnan(e) and independent(refs.get(k, "")) and k not in NOT_A_VERDICT]
    if not errs:
        return ""
    name, err = max(errs, key=lambda t: t[1])
    if not math.isnan(v.error) and err <= v.error:
        return ""
    signed = (getattr(v.run, "signed", {}) or {}).get(name, math.nan)
    depth = v.cooling_depth if math.isfinite(v.cooling_depth) else getattr(v.run, "cooling_depth", math.nan)
    text = "not finite" if err == math.inf else pct(signed, signed=True) if math.isfinite(signed) else pct(err)
    return f"{metric_words(name, depth)} {text}"


def cell(v: Verdict) -> Cell:
    """The text of a scorecard cell (its status also colours the HTML cell)."""
    if v.status == "none":
        return Cell("–")
    if v.status == "reference":   # the scene's reference method: not a verdict (no error, no status colour)
        pre = "≤" if v.members else ""
        return Cell(" · ".join(["reference"] + ([pre + duration(v.time)] if math.isfinite(v.time) else [])
                               + ([level(v.run.level)] if v.run is not None else []) + marks(v)), "reference")
    if v.members:
        n = len(v.members)
        k = sum(1 for x in v.members if x.status == v.status)
        count = f" {k}/{n}" if k < n else f" ({n}/{n})" if v.status == "ok" else ""
        parts = [v.status + count]
        if math.isfinite(v.error):
            parts.append("≤" + pct(v.error))
        if math.isfinite(v.time):
            parts.append("≤" + duration(v.time))
        if v.reason_kind and v.status in ("refused", "failed"):
            parts[0] += f" ({v.reason_kind})"
        return Cell(" · ".join(parts + marks(v)), v.status)
    if v.status in ("refused", "failed"):
        return Cell(" · ".join([v.status + (f" ({v.reason_kind})" if v.reason_kind else "")] + marks(v)), v.status)
    parts = [v.status]
    if v.status == "unverified":
        parts.append("headline not checked independently")
    elif v.error == math.inf:
        parts.append("not finite")
    elif math.isfinite(v.signed):
        parts.append(pct(v.signed, signed=True))
    elif math.isfinite(v.error):
        parts.append(pct(v.error))
    worst = _worst_other(v)
    if worst:
        parts.append(worst)
    if math.isfinite(v.time):
        parts.append(duration(v.time))
    if v.run is not None:
        parts.append(level(v.run.level))
    if v.status == "unverified" and math.isfinite(v.richardson):
        parts.append(f"Richardson ≈{pct(v.richardson)}")
    return Cell(" · ".join(parts + marks(v)), v.status)


def creep_force_source(stages: dict[str, str]) -> str:
    """The stage model that computed the creep force of a chain: its tangential stage, else its heat
    source (which computes traction and slip when the chain has no tangential stage), else its contact."""
    for stage in ("tangential", "heat_source", "contact", "normal"):
        if stage in stages:
            return stages[stage]
    return ""


def _names(items: list[str]) -> str:
    items = list(dict.fromkeys(items))
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def acting(data, scene: str, method: str) -> str:
    """The method's name in a sentence about ``scene``, with the model that did the work when only its
    temperature stage ran (a given heat source: "kalker (green's temperatures; the heat source is given)"),
    so that a finding does not credit a contact model that did not run."""
    stages = data.stages(scene, method)
    model = stages.get("temperature", "")
    if stages.get("heat_source") == "given" and model and model != method:
        return f"{method} ({model}'s temperatures; the heat source is given)"
    return method


def _signed_range(errors: list[float]) -> str:
    """"+27 to +31 %" (signed percentages, smallest to largest)."""
    lo, hi = min(errors), max(errors)
    return pct(lo, signed=True) if pct(lo, signed=True) == pct(hi, signed=True) else \
        f"{pct(lo, unit=False, signed=True)} to {pct(hi, signed=True)}"


def contact_split(data, table_rows: list[Row]) -> list[str]:
    """Key findings on scenes whose reference is an exact-contact method: the contact model's share of the
    headline error (a method with the reference's temperature model and another tangential model, against the
    reference) and the thermal model's (a method with that tangential model and another temperature model,
    against the contact method: (1 + e_total) / (1 + e_contact) − 1), from metrics.nc's signed headline
    errors at each method's finest level."""
    signed = stored_verdicts(data)
    groups: dict = {}
    for row in table_rows:
        for s in row.scenes:
            ref = data.scene[s].reference_kind
            if ref not in data.methods:
                continue
            st_ref = data.stages(s, ref)
            if not st_ref.get("tangential"):
                continue
            for c in data.methods:
                st_c = data.stages(s, c)
                if c == ref or not st_c.get("tangential") or st_c.get("tangential") == st_ref["tangential"] \
                        or st_c.get("temperature") != st_ref.get("temperature"):
                    continue
                e_c = _finest_signed(data, signed, s, c)
                if e_c is None:
                    continue
                key = (ref, c, st_c["tangential"], row.headline)
                groups.setdefault(key, {"scenes": [], "contact": [], "thermal": {}})
                g = groups[key]
                g["scenes"].append(s)
                g["contact"].append(e_c)
                for t in data.methods:
                    st_t = data.stages(s, t)
                    e_t = _finest_signed(data, signed, s, t)
                    if t in (c, ref) or e_t is None or st_t.get("tangential") != st_c["tangential"] \
                            or not st_t.get("temperature") or st_t.get("temperature") == st_c.get("temperature"):
                        continue
                    g["thermal"].setdefault((t, st_t["temperature"]), []).append((1 + e_t) / (1 + e_c) - 1)
    out = []
    for (ref, c, model, h), g in groups.items():
        what = QUANTITY.get(h, h)
        tol = data.tolerance if data.tolerance is not None else 0.05
        groups_of = _clusters(list(zip(g["scenes"], g["contact"])), tol)
        if len(groups_of) == 1:
            costs = f"{_signed_range(g['contact'])} in {what}"
            where = f"On {_scene_span(g['scenes'])} (reference {ref}, exact contact), the"
        else:
            costs = f"in {what} " + "; ".join(
                f"{_signed_range([e for _, e in b])} on " + ", ".join(f"`{sc}`" for sc, _ in b) for b in groups_of)
            where = f"Against {ref} (exact contact), the"
        text = f"{where} {model} contact model alone costs {costs} ({c}: the same temperature model as {ref})"
        for (t, temp), errs in g["thermal"].items():
            text += f"; the {temp} thermal model adds {_signed_range(errs)} ({t} against {c})"
        out.append(text + ".")
    return out


def _clusters(pairs: list, gap: float) -> list[list]:
    """(scene, error) pairs grouped where sorted errors lie within ``gap`` of their neighbour, largest first."""
    pairs = sorted(pairs, key=lambda t: t[1])
    out = [[pairs[0]]] if pairs else []
    for p in pairs[1:]:
        if p[1] - out[-1][-1][1] > gap:
            out.append([p])
        else:
            out[-1].append(p)
    return out[::-1]


def _finest_signed(data, signed: dict, scene: str, method: str):
    r = data.finest_result(scene, method)
    if r is None:
        return None
    e = signed.get((scene, method, r.level), math.nan)
    return e if isinstance(e, float) and math.isfinite(e) else None


def _scene_span(scenes: list[str]) -> str:
    """"`ek-exact-*`" for scenes sharing a prefix, else their names."""
    names = list(dict.fromkeys(scenes))
    if len(names) == 1:
        return f"`{names[0]}`"
    prefix = os.path.commonprefix(names).rstrip("-")
    return f"`{prefix}-*` ({len(names)} scenes)" if len(prefix) >= 3 else ", ".join(f"`{n}`" for n in names)


def _error(v: Verdict) -> str:
    """A verdict's headline error in words: signed where metrics.nc stores the sign."""
    return pct(v.signed, signed=True) if math.isfinite(v.signed) else pct(v.error)


def findings(data: StudyData, table_rows: list[Row], cards: dict, limit: int = 5) -> list[str]:
    """3-5 sentences computed from the metrics: who is fastest at the tolerance, what misses it, what is
    unverified, what failed."""
    tol = data.tolerance
    tol_text = pct(tol) if tol is not None else "the tolerance"
    compare, misses, unverified = [], [], []
    for row in table_rows:
        vs = [cards[(row.label, m)] for m in data.methods]
        what = QUANTITY.get(row.headline, row.headline or "headline quantity")
        where = f"the `{row.label}` sweep" if row.group else f"`{row.label}`"
        sentence = _comparison(data, row, vs, where, what, tol_text)
        if sentence is not None:
            compare.append(sentence)
        bad = [v for v in vs if v.status == "inaccurate"]
        if bad:
            misses.append(_miss(data, row, bad, where, what, tol_text))
        for v in vs:
            if "non-monotone" in v.note and not row.group:
                words = next(w for w in v.note.split("; ") if w.startswith("non-monotone"))
                misses.append(f"On {where}, {v.method} is {words}; no level is quoted unless it holds at every finer "
                              "level.")
            if v.status == "unverified":
                unverified.append(_unverified(v, where, what))
    failed = [r for r in data.runs if r.status == "failed"]
    out = []
    if failed:
        out.append(_failed_sentence(failed))
    split = contact_split(data, table_rows) if hasattr(data, "scene") else []
    out += split[:1]
    compare.sort(key=lambda t: -t[0])
    pairs, first, rest = set(), [], []
    for _, text, pair in compare:  # one sentence per pair of methods first
        (rest if pair in pairs else first).append(text)
        pairs.add(pair)
    out += first[:2]
    out += misses[:1]
    out += unverified[:1]
    out += (first[2:] + rest)[:1] + misses[1:2] + split[1:2]
    refused = [r for r in data.runs if r.status == "refused"]
    if refused and len(out) < limit:
        kinds = {}
        for r in refused:
            kinds[r.reason_kind or "reason not classified"] = kinds.get(r.reason_kind or "reason not classified", 0) + 1
        out.append(f"{len(refused)} of {len(data.runs)} runs were refused before they started ("
                   + ", ".join(f"{v} {k}" for k, v in sorted(kinds.items())) + "); each scene's section says why.")
    if not failed and len(out) < limit:
        out.append(f"No run failed ({len(data.runs)} runs).")
    return out[:limit]


def _comparison(data: StudyData, row: Row, vs: list, where: str, what: str, tol_text: str):
    """(speed ratio, sentence, methods) comparing the fastest and the slowest method within the tolerance on
    one row, or naming the only one within it; None when neither applies."""
    ok = sorted((v for v in vs if v.status == "ok" and math.isfinite(v.time)), key=lambda v: v.time)
    if len(ok) >= 2:
        fast, slow = ok[0], ok[-1]
        times = slow.time / fast.time if fast.time > 0 else math.inf
        pre = "≤" if row.group else ""
        text = (f"For {where} ({what}), {acting(data, row.scenes[0], fast.method)} reaches {pre}{_error(fast)} "
                f"error in {pre}{duration(fast.time)}; {acting(data, row.scenes[0], slow.method)} needs "
                f"{pre}{duration(slow.time)} for {pre}{_error(slow)}"
                + (f" ({ratio(times)} of {fast.method})." if 10 <= times < math.inf else "."))
        return times, text, (fast.method, slow.method)
    if len(ok) == 1 and len([v for v in vs if v.status != "none"]) > 1:
        v = ok[0]
        return (0.0, f"For {where} ({what}), only {acting(data, row.scenes[0], v.method)} is within "
                     f"{tol_text}: {_error(v)} "
                     f"in {duration(v.time)}.", (v.method,))
    return None


def _miss(data: StudyData, row: Row, bad: list, where: str, what: str, tol_text: str) -> str:
    """The sentence naming the methods of one row that miss the tolerance (``bad``) and their worst error."""
    worst = max((v.error for v in bad if not math.isnan(v.error)), default=math.nan)
    worst_text = "not finite" if worst == math.inf else pct(worst)
    if row.group:
        counts = [sum(1 for x in v.members if x.status == "inaccurate") for v in bad]
        at = f" at {max(counts)} of {len(row.scenes)} {row.group.key} values"
    else:
        at = ""
    tail = ""
    if row.headline == "creep_force_x":
        src = {v.method: creep_force_source(data.stages(row.scenes[0], v.method)) for v in bad}
        foreign = {m: s for m, s in src.items() if s and s != m}
        if foreign:
            tail = (f"; the creep force of {_names(list(foreign))} is computed by "
                    f"{_names(sorted(set(foreign.values())))}")
    who = _names([v.method for v in bad])
    if row.group:
        return (f"On {where}, {who} miss the {tol_text} tolerance at every level for{at[3:]} "
                f"(worst {worst_text}){tail}.")
    # the headline may be within the tolerance while another metric is not: name it
    why = "; ".join(f"{v.method}: {w}" for v in bad for w in [_worst_other(v)] if w)
    return (f"No level of {who} is within {tol_text} on {where} (worst {what} error "
            f"{worst_text}{'; ' + why if why else ''}){tail}.")


def _unverified(v, where: str, what: str) -> str:
    """The sentence saying that a method's result on a row is not checked against an independent reference."""
    rich = f"; Richardson estimate of its finest level's error {pct(v.richardson)}" \
        if math.isfinite(v.richardson) else ""
    checked = v.message.split("; checked: ", 1)[1] if "; checked: " in v.message else ""
    return (f"{v.method} is unverified on {where}: its {what} is not checked against an "
            f"independent reference (checked: {short(checked, 120)}){rich}." if checked else
            f"{v.method} is unverified on {where}: no independent reference, "
            f"only self-convergence{rich}.")


def _failed_sentence(failed: list) -> str:
    """The sentence counting the failed runs and naming the first three (method, scene) with their reasons."""
    by = {}
    for r in failed:
        by.setdefault((r.method, r.scene), []).append(r)
    parts = [f"{m} on `{s}` (level {level_range(x.level for x in rs)}"
             + (f", {rs[0].reason_kind}" if rs[0].reason_kind else "") + f": {short(rs[0].message, 70)})"
             for (m, s), rs in list(by.items())[:3]]
    more = f" and {len(by) - 3} more" if len(by) > 3 else ""
    return f"{len(failed)} run{'s' if len(failed) > 1 else ''} failed: " + "; ".join(parts) + more + "."
