"""The transient metrics of ``metrics.nc`` (scenes with ``mode = "transient"``): a run's histories at the
fixed section against core's exact transient references (:mod:`railtherm.references.transient`: the
moving band for a line contact, the moving ellipse in 3-D, uniform or Hertzian flux, at any depth, with
the scene's passes and schedule; a locked wheel's spot: :mod:`railtherm.references.transient_spot`).

* ``error_pass_peak_temperature``: the largest relative error of the per-pass peak rise, over bodies,
  passes and depths (entries whose exact peak is below :data:`FLOOR` of the body's largest are left out:
  a pass the schedule leaves unheated has no relative scale);
* ``error_residual_rise``: the same for the residual surface rise before the next pass;
* ``error_temperature_history``: the max-norm of the rise's error over the history (the run's own time
  axis), relative to the exact history's largest rise at that depth, the largest over depths and bodies.

Temperatures are scored on their rise above each body's bulk temperature. A scene whose heat source has
no closed form (convection, a friction law that is not one number over the patch, a computed contact
other than full sliding) is not scored.
"""
from __future__ import annotations

import math

import numpy as np

from ..references.transient import MovingSource, Schedule, pass_summary, temperature_history
from ..references.transient_spot import FixedSource, fixed_source_history, fixed_source_summary
from .analytic import _thermal_case

__all__ = ["TRANSIENT_METRICS", "FLOOR", "transient_errors", "transient_sources", "history_samples"]

#: metrics of a transient scene, in metrics.nc only for a study with a transient scene
TRANSIENT_METRICS = ("pass_peak_temperature", "residual_rise", "temperature_history")
#: entries of the per-pass peaks and residuals below this fraction of the body's largest exact value are
#: not scored (no relative scale: a pass the schedule leaves unheated)
FLOOR = 1e-3
#: the references' quadrature (railtherm.references.transient.pass_response): ~1e-5 of the maximum
#: (tests/test_references_transient.py), 3x cheaper than the default
_QUAD = dict(quad_points=8, inner_points=24)
#: the exact history is evaluated on at most this many of the run's samples (a schedule makes the reference
#: cost ~0.5-1 ms per sample at 4 depths, so a 1,000-pass axis of 5e5 samples is out of reach): a longer axis is first
#: thinned to every k-th sample, as long as :data:`MIN_PER_CONTACT` remain per contact duration, so that
#: every level of a method is scored over the same passes with the same scale; what still exceeds it is
#: scored over its first whole passes (the per-pass peaks and residuals cover every pass)
MAX_HISTORY_SAMPLES = 5000
#: samples per contact duration 2a/V kept by the thinning (the history axis's own minimum)
MIN_PER_CONTACT = 20


def transient_sources(scene):
    """Each body's exact source as (MovingSource, FixedSource for a body at rest under the contact -- a
    locked wheel's spot, scored when the schedule switches it on at a finite time -- or None, bulk temperature
    [degC]) for wheel and rail, and the reference's tag; None when the scene's heat source has no closed form."""
    case = _thermal_case(scene)
    if case is None:
        return None
    a, b, shape, q0, speeds, eps = case
    if not np.ndim(eps) == 0:
        return None
    kind = "band" if b is None else "ellipse"
    out = []
    for i, (frac, body) in enumerate(((float(eps), scene.wheel), (1.0 - float(eps), scene.rail))):
        q = q0 * frac
        src = MovingSource(kind, a, float(speeds[i]), q, shape, b) if q > 0 and speeds[i] > 0 else None
        tr = getattr(scene, "transient", None)
        if q > 0 and not speeds[i] > 0 and tr is not None and tr.schedule_factor and tr.schedule_factor[0] == 0:
            src = FixedSource(kind, a, q, shape, b)
        out.append((src, float(body.bulk_temperature)))
    at_rest = any(isinstance(src, FixedSource) for src, _ in out)
    return out, f"transient-{kind}-moving-and-at-rest" if at_rest else f"transient-{kind}"


def _rel(value, exact, floor: float) -> float:
    """Largest relative error over the entries whose exact value is at least ``floor`` of the largest."""
    value, exact = np.asarray(value, dtype=float), np.asarray(exact, dtype=float)
    scale = np.max(np.abs(exact)) if exact.size else 0.0
    if scale == 0:
        return math.nan
    keep = np.abs(exact) >= floor * scale
    if not np.all(np.isfinite(value[keep])):
        return math.inf
    return float(np.max(np.abs(value[keep] / exact[keep] - 1.0)))


def history_samples(time, count: int, interval: float, duration: float, notes: dict) -> tuple[int, int, np.ndarray]:
    """The run's samples the history is scored on: (stride k, count n, thinned axis [s]), the first n of
    every k-th sample (:data:`MAX_HISTORY_SAMPLES`); ``duration`` the shortest contact duration [s]. The
    thinning or truncation is noted in ``notes``."""
    per = int(np.count_nonzero((time >= 0.0) & (time < duration)))        # samples over the first pass
    every = max(1, min(int(math.ceil(time.size / MAX_HISTORY_SAMPLES)), per // MIN_PER_CONTACT))
    thin = time[::every]
    n = thin.size
    if every > 1:
        notes["temperature_history"] = (f"scored on one in {every} of the run's {time.size} samples "
                                        f"({per // every} per contact duration)")
    if n > MAX_HISTORY_SAMPLES:
        keep = max(1, int(thin[MAX_HISTORY_SAMPLES - 1] // interval))     # whole passes within the samples
        n = int(np.searchsorted(thin, keep * interval, side="right"))
        notes["temperature_history"] = (f"scored over the first {keep} of {count} passes ({n} of {time.size} samples"
                                        + (f", one in {every}" if every > 1 else "")
                                        + "; peaks and residuals over every pass)")
    return every, n, thin


def _cached_history(cache: dict | None, key, time: np.ndarray, compute) -> np.ndarray:
    """The exact history at ``time`` [s], shape (time, depths), computed by ``compute(times)`` only at the times
    not yet in ``cache[key]`` (a scene's runs share many samples: a method's levels, methods on one axis). The
    exact value at a time does not depend on the other times asked with it, so the cached values are the ones
    computed afresh."""
    if cache is None:
        return compute(time)
    known_t, known_v = cache.get(key, (np.empty(0), None))
    new = np.setdiff1d(time, known_t)
    if new.size:
        fresh = compute(new)
        known_t = np.concatenate([known_t, new])
        known_v = fresh if known_v is None else np.concatenate([known_v, fresh])
        order = np.argsort(known_t, kind="stable")
        known_t, known_v = known_t[order], known_v[order]
        cache[key] = (known_t, known_v)
    return known_v[np.searchsorted(known_t, time)]


def transient_errors(scene, ds, notes: dict | None = None, cache: dict | None = None) -> dict:
    """Errors of the transient metrics of one result: metric -> (error [1], ``analytic:<tag>``).

    Parameters
    ----------
    scene : Scene
        A transient scene (``scene.transient``).
    ds : xarray.Dataset
        The run's result (``temperature_history``, ``pass_peak_temperature``, ``residual_rise``, ``time``,
        ``z``).
    notes : dict, optional
        Filled with metric -> why it is not scored.
    cache : dict, optional
        Per-scene cache of the exact per-pass summary (the same for every level of the scene) and of the exact
        history at every time already asked.
    """
    notes = {} if notes is None else notes
    tr = getattr(scene, "transient", None)
    if tr is None or "temperature_history" not in ds:
        return {}
    got = transient_sources(scene)
    if got is None:
        for m in TRANSIENT_METRICS:
            notes[m] = "no exact transient reference for this heat source"
        return {}
    sources, tag = got
    sched = None if tr.schedule_time is None else Schedule(tr.schedule_time, tr.schedule_factor)
    z = np.asarray(ds["z"].values, dtype=float)
    every, n, t = history_samples(np.asarray(ds["time"].values, dtype=float), tr.count, tr.interval,
                                  min((s.contact_duration for s, _ in sources if isinstance(s, MovingSource)),
                                      default=0.0), notes)
    errs: dict[str, list[float]] = {m: [] for m in TRANSIENT_METRICS}
    for i, (src, bulk) in enumerate(sources):
        if src is None:
            continue
        at_rest = isinstance(src, FixedSource)
        key = ("transient-summary", scene.name, i, tuple(z))
        if cache is None or key not in cache:
            summary = (fixed_source_summary(z, src, scene.body(i), tr.count, tr.interval, sched) if at_rest else
                       pass_summary(z, src, scene.body(i), tr.count, tr.interval, sched, **_QUAD))
            if cache is not None:
                cache[key] = summary
        summary = cache[key] if cache is not None else summary
        errs["pass_peak_temperature"].append(_rel(ds["pass_peak_temperature"].values[i] - bulk, summary.peak, FLOOR))
        errs["residual_rise"].append(_rel(ds["residual_rise"].values[i], summary.residual[:, 0], FLOOR))
        exact = _cached_history(cache, ("transient-history", scene.name, i, tuple(z)), t[:n],
                                lambda times: (fixed_source_history(times, z, src, scene.body(i), sched) if at_rest else
                                               temperature_history(times, z, src, scene.body(i), tr.count, tr.interval,
                                                                   sched, **_QUAD)))
        rise = ds["temperature_history"].values[i, ::every][:n] - bulk
        scale = np.max(np.abs(exact), axis=0)
        ok = scale > 0
        if not np.all(np.isfinite(rise)):
            errs["temperature_history"].append(math.inf)
        elif np.any(ok):
            errs["temperature_history"].append(float(np.max(np.max(np.abs(rise - exact), axis=0)[ok] / scale[ok])))
    out = {}
    for m, values in errs.items():
        finite = [v for v in values if not math.isnan(v)]
        if finite:
            out[m] = (max(finite), f"analytic:{tag}")
        else:
            notes[m] = "no heated body to score"
    return out
