"""The scorecard of ``metrics.nc`` (scene × method), so that the report and any reader show the same verdict:
the converged verdict level of each ladder (:func:`railtherm.analysis.verdicts.ladder_verdict`), and whether a
scene's reference method is converged itself (:func:`railtherm.analysis.verdicts.reference_note`).
Contract: ``docs/verdicts.md``."""
from __future__ import annotations

import math

import numpy as np

from ..output.store import RESULT_STATUSES
from .verdicts import ladder_verdict, reference_convergence, reference_note

RESULTS = RESULT_STATUSES


def finest_step(rows: list[dict], metric: str) -> float:
    """|Q_{K−1} − Q_K| / |Q_K| [1] of a ladder on ``metric``: the error of its second-finest level with a result
    against its finest (``self:finest``); NaN when it has fewer than two such levels."""
    got = sorted((r for r in rows if r["status"] in RESULTS), key=lambda r: r["level"])
    if len(got) < 2 or got[-2].get(f"reference_{metric}", "") != "self:finest":
        return math.nan
    return float(got[-2].get(f"error_{metric}", math.nan))


def _reference_estimates(ds, by_sm: dict, snames: list, mnames: list, metrics: list) -> np.ndarray:
    """(scene, metric) -> the scene's reference method's own finest-level error estimate [1] (NaN when the
    scene's reference is not a method)."""
    est = np.full((len(snames), len(metrics)), np.nan)
    kinds = [str(k) for k in ds["reference_kind"].values]
    for i, s in enumerate(snames):
        ref = kinds[i]
        if ref not in mnames:
            continue
        j = mnames.index(ref)
        for k, met in enumerate(metrics):
            rich = float(ds["richardson_error"].values[i, j, k]) if "richardson_error" in ds else math.nan
            est[i, k] = reference_convergence(rich, finest_step(by_sm.get((s, ref), []), met))
    return est


def compared(rows: list[dict], reference: str, headline: str) -> list[str]:
    """The metrics of one scene that some run compares with ``method:<reference>`` (finite or failing), the
    headline first."""
    tag = f"method:{reference}"
    got = {k[len("reference_"):] for r in rows for k, v in r.items()
           if k.startswith("reference_") and v == tag and not math.isnan(r.get("error_" + k[len("reference_"):],
                                                                                 math.nan))}
    return sorted(got, key=lambda k: (k != headline, k))


def _reference_words(reference: str, est, metrics_compared: list[str], metrics: list[str], tol: float) -> str:
    """"reference not converged: ..." naming each compared metric whose reference estimate is not below a
    quarter of the tolerance ("" when none)."""
    bad = [reference_note(reference, float(est[metrics.index(k)]), tol, k) for k in metrics_compared if k in metrics]
    bad = [b for b in bad if b]
    if not bad:
        return ""
    head = bad[0].split(": ", 1)[0]
    return head + ": " + "; ".join(b.split(": ", 1)[1] for b in bad)


def verdict_vars(ds, rows: list[dict], snames: list, mnames: list, tol: float):
    """Add ``verdict_level``, ``verdict_error``, ``verdict_time``, ``verdict_status``, ``verdict_message``
    (scene_name × method_name) and ``reference_convergence_error`` (scene_name × metric) to ``ds``."""
    by_sm: dict = {}
    rows_of: dict = {}
    for r in rows:
        by_sm.setdefault((r["scene"], r["method"]), []).append(r)
        rows_of.setdefault(r["scene"], []).append(r)
    shape = (len(snames), len(mnames))
    level, error, time = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    status, message = np.full(shape, "", dtype=object), np.full(shape, "", dtype=object)
    metrics = [str(m) for m in ds["metric"].values]
    est = _reference_estimates(ds, by_sm, snames, mnames, metrics)
    heads = [str(h) for h in ds["headline"].values]
    kinds = [str(k) for k in ds["reference_kind"].values]
    for i, s in enumerate(snames):
        note = _reference_words(kinds[i], est[i], compared(rows_of.get(s, []), kinds[i], heads[i]), metrics, tol) \
            if kinds[i] in mnames else ""
        for j, m in enumerate(mnames):
            ladder = [{"level": r["level"], "status": r["status"], "reason_kind": r.get("reason_kind", ""),
                       "headline_error": float(r.get("headline_error", math.nan)),
                       "wall_time": float(r.get("wall_time", math.nan))} for r in by_sm.get((s, m), [])]
            if not ladder:
                continue
            v = ladder_verdict(ladder, tol)
            if v["level"] >= 0:
                level[i, j], error[i, j], time[i, j], status[i, j] = v["level"], v["error"], v["time"], v["status"]
            words = [v["message"]] if v["message"] else []
            if m == kinds[i]:
                words.insert(0, f"the reference of {s}")
            if note:
                words.append(note)
            message[i, j] = "; ".join(words)
    dims = ("scene_name", "method_name")
    ds["verdict_level"] = (dims, level, {"units": "1", "long_name": "cheapest level that is within the tolerance "
                                                                    "on the headline with every finer level that ran "
                                                                    "(NaN: no level qualifies)"})
    ds["verdict_error"] = (dims, error, {"units": "1", "long_name": "headline error at verdict_level"})
    ds["verdict_time"] = (dims, time, {"units": "s", "long_name": "best wall time at verdict_level"})
    ds["verdict_status"] = (dims, status, {"units": "1", "long_name": "status of the run at verdict_level "
                                                                      "(empty: no level qualifies)"})
    ds["verdict_message"] = (dims, message, {"units": "1", "long_name": "the verdict in words: why no level "
                                                                        "qualifies, non-monotone ladders, a reference "
                                                                        "that is not converged"})
    ds["reference_convergence_error"] = (("scene_name", "metric"), est, {
        "units": "1", "long_name": "the scene's reference method's own finest-level error estimate (Richardson, "
                                   "else the finest step); NaN when the reference is not a method"})
    return ds
