"""Exact transient curves of a transient scene for ``references.nc``: the history and the per-pass values.

:func:`transient_history_curves` evaluates, for a scene with ``mode = "transient"``, core's exact transient
references with the calls and quadrature that ``metrics.nc`` scores with (:mod:`.transient_metrics`: each
body's :func:`~.transient_metrics.transient_sources`; :func:`~railtherm.references.transient.temperature_history`
and :func:`~railtherm.references.transient.pass_summary` for a moving band or ellipse,
:func:`~railtherm.references.transient_spot.fixed_source_history` and ``fixed_source_summary`` for a source at
rest): ``exact_temperature_history(body, history_time, history_depth)``, ``exact_pass_peak_temperature(body,
pass, history_depth)``, ``exact_residual_rise(body, pass)`` and ``exact_time_above(body, pass, history_depth)``.

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, sections 10.2-10.7.
ISBN 978-0198533689. [2] J.C. Jaeger, J. Proc. Roy. Soc. New South Wales 76 (1942) 203-224.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from ..references.transient import (MovingSource, Schedule, history_time_axis, pass_summary, temperature_history,
                                    time_above)
from ..references.transient_spot import FixedSource, fixed_source_history, fixed_source_summary
from .transient_metrics import _QUAD, transient_sources

__all__ = ["transient_history_curves", "history_time", "NAME_BAND", "NAME_ELLIPSE", "NAME_AT_REST",
           "MAX_SAMPLES", "SAMPLES_PER_CONTACT", "MAX_SHAPED_PASSES"]

NAME_BAND = "exact transient band"
NAME_ELLIPSE = "exact transient ellipse"
NAME_AT_REST = "source at rest"
#: samples of ``history_time`` at most (about: the last pass's end is one more)
MAX_SAMPLES = 2000
#: samples per contact duration 2a/V over [0, 2 D] of each pass (up to :data:`MAX_SHAPED_PASSES` passes)
SAMPLES_PER_CONTACT = 40
#: up to this many passes the axis is dense around each arrival and geometric in between; beyond, uniform
MAX_SHAPED_PASSES = 20
#: samples per window of a source at rest, where the time above is located (as fixed_source_summary samples)
AT_REST_SAMPLES = 200

_TEMPERATURE = {"units": "degC", "units_metadata": "temperature: on_scale"}


def history_time(count: int, interval: float, duration: float | None, schedule_time=None) -> np.ndarray:
    """The exact history's time axis [s] from 0 to ``count * interval``.

    Up to :data:`MAX_SHAPED_PASSES` passes with a moving source (``duration`` = the shortest contact duration
    2a/V [s]): :func:`~railtherm.references.transient.history_time_axis`, :data:`SAMPLES_PER_CONTACT` per
    contact duration over [0, 2 D] of each pass and geometric spacing up to the next (the passes share their
    offsets, so the history costs one pass's samples x passes), plus the schedule's times ``schedule_time``
    [s] inside the axis (its kinks). More passes, or no moving source: uniform, the same offsets in every pass,
    at most :data:`MAX_SAMPLES` samples.
    """
    end = count * interval
    if duration and count <= MAX_SHAPED_PASSES:
        tail = max(10, min(40, MAX_SAMPLES // count - 2 * SAMPLES_PER_CONTACT))
        probe = MovingSource("band", 0.5 * duration, 1.0)      # history_time_axis reads its contact duration only
        axis = history_time_axis(probe, count, interval, SAMPLES_PER_CONTACT, tail)
    else:
        per = max(2, MAX_SAMPLES // count)
        offsets = interval * np.arange(per) / per
        axis = np.concatenate([k * interval + offsets for k in range(count)] + [[end]])
    if schedule_time is not None and count <= MAX_SHAPED_PASSES:
        kinks = np.asarray(schedule_time, float)
        axis = np.union1d(axis, kinks[(kinks > 0.0) & (kinks < end)])
    return axis


def _at_rest_time_above(rise: float, depth, src: FixedSource, material, count: int, interval: float,
                        schedule: Schedule) -> np.ndarray:
    """Time above ``rise`` [K] per window [k interval, (k + 1) interval) of a source at rest [s], shape (count,
    depths): each window sampled as :func:`fixed_source_summary` samples it, every sign change of the exact rise
    minus ``rise`` located by Brent's method (to 1e-9 of the window) on the exact history."""
    depth = np.asarray(depth, float)
    out = np.zeros((count, depth.size))
    for k in range(count):
        lo, hi = k * interval, (k + 1) * interval
        axis = np.union1d(np.linspace(lo, hi, AT_REST_SAMPLES + 1), [t for t in schedule.time if lo <= t <= hi])
        hist = fixed_source_history(axis, depth, src, material, schedule)
        for j, z in enumerate(depth):
            above = hist[:, j] > rise
            if not np.any(above):
                continue
            def excess(t, z=z):
                return fixed_source_history([t], [z], src, material, schedule)[0, 0] - rise
            total, since = 0.0, (lo if above[0] else None)
            for m in np.nonzero(above[1:] != above[:-1])[0]:
                t = optimize.brentq(excess, axis[m], axis[m + 1], xtol=1e-9 * interval)
                if above[m + 1]:
                    since = t
                else:
                    total, since = total + t - since, None
            out[k, j] = total + (hi - since if since is not None else 0.0)
    return out


def _body_curves(src, material, bulk: float, tr, depth, time, schedule, threshold) -> dict:
    """One body's exact curves: history [degC] (time, depths), peak [degC] (passes, depths), residual [K]
    (passes), time above [s] (passes, depths) or None, by the calls of :mod:`.transient_metrics`."""
    count, interval = tr.count, tr.interval
    if isinstance(src, FixedSource):
        hist = fixed_source_history(time, depth, src, material, schedule)
        summary = fixed_source_summary(depth, src, material, count, interval, schedule)
        above = (None if threshold is None else
                 _at_rest_time_above(threshold - bulk, depth, src, material, count, interval, schedule))
    else:
        hist = temperature_history(time, depth, src, material, count, interval, schedule, **_QUAD)
        summary = pass_summary(depth, src, material, count, interval, schedule, **_QUAD)
        above = (None if threshold is None else
                 time_above(threshold - bulk, depth, src, material, count, interval, schedule, **_QUAD))
    return {"history": bulk + hist, "peak": bulk + summary.peak, "residual": summary.residual[:, 0],
            "above": above}


def transient_history_curves(scene) -> tuple[dict, dict, str]:
    """Exact transient curves of a transient scene: (data variables, coordinates, reference name).

    Parameters
    ----------
    scene : Scene
        A scene; one without ``transient`` (steady) or whose heat source has no closed form gives nothing.

    Returns
    -------
    tuple
        ``data``: name -> (dims, values, attrs) of ``exact_temperature_history(body, history_time,
        history_depth)`` [degC] (absolute: bulk + rise), ``exact_pass_peak_temperature(body, pass,
        history_depth)`` [degC], ``exact_residual_rise(body, pass)`` [K] (the surface rise just before the next
        pass; after the last, one interval after it) and, when the scene asks for ``time_above`` (its threshold
        ``field.threshold``), ``exact_time_above(body, pass, history_depth)`` [s]; NaN for a body without heat.
        ``coords``: ``history_time`` [s] (:func:`history_time`), ``history_depth`` [m] (the scene's
        ``field.depth``, surface 0 first), ``pass`` [1] (1 .. count). ``name``: the references, "; "-joined
        ("" with no data).
    """
    tr = getattr(scene, "transient", None)
    got = transient_sources(scene) if tr is not None else None
    if got is None or all(src is None for src, _ in got[0]):
        return {}, {}, ""
    sources = got[0]
    schedule = None if tr.schedule_time is None else Schedule(tr.schedule_time, tr.schedule_factor)
    depth = np.asarray(tr.depths, float)
    duration = min((s.contact_duration for s, _ in sources if isinstance(s, MovingSource)), default=None)
    time = history_time(tr.count, tr.interval, duration, tr.schedule_time)
    threshold = float(tr.threshold) if "time_above" in tr.outputs else None
    n, nz = tr.count, depth.size
    hist, peak = np.full((2, time.size, nz), math.nan), np.full((2, n, nz), math.nan)
    residual, above = np.full((2, n), math.nan), np.full((2, n, nz), math.nan)
    names = []
    mixed = any(isinstance(s, FixedSource) for s, _ in sources)     # name each body's reference
    for i, (src, bulk) in enumerate(sources):
        if src is None:
            continue
        got_i = _body_curves(src, scene.body(i), bulk, tr, depth, time, schedule, threshold)
        hist[i], peak[i], residual[i] = got_i["history"], got_i["peak"], got_i["residual"]
        if got_i["above"] is not None:
            above[i] = got_i["above"]
        name = NAME_AT_REST if isinstance(src, FixedSource) else NAME_BAND if src.kind == "band" else NAME_ELLIPSE
        names.append(f"{name} ({('wheel', 'rail')[i]})" if mixed else name)
    names = list(dict.fromkeys(names))
    ref = {"reference": "; ".join(names)}
    data = {
        "exact_temperature_history": (("body", "history_time", "history_depth"), hist, {
            **_TEMPERATURE, **ref, "long_name": "exact temperature of the material point on the centre line at the "
            "fixed section (NaN: no heat or no exact reference)"}),
        "exact_pass_peak_temperature": (("body", "pass", "history_depth"), peak, {
            **_TEMPERATURE, **ref, "long_name": "exact highest temperature in each pass"}),
        "exact_residual_rise": (("body", "pass"), residual, {
            "units": "K", "units_metadata": "temperature: difference", **ref,
            "long_name": "exact surface rise above bulk just before the next pass (after the last: one interval "
            "after it)"}),
    }
    if threshold is not None:
        data["exact_time_above"] = (("body", "pass", "history_depth"), above, {
            "units": "s", **ref, "threshold": threshold, "long_name": "exact time above the threshold in each pass"})
    coords = {"history_time": ("history_time", time, {"units": "s", "long_name": "time of the exact history, 0: "
                                                      "the first pass's leading edge at the section"}),
              "history_depth": ("history_depth", depth, {"units": "m", "long_name": "depth of the history",
                                                         "positive": "down"}),
              "pass": ("pass", np.arange(1, n + 1), {"units": "1", "long_name": "pass"})}
    return data, coords, "; ".join(names)
