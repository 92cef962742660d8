"""The thermal trace's metrics in ``metrics.nc`` (scenes with ``field``, issue 14): relative max-norm
errors of the trace profiles over the depths where run and reference have a value, and the depth range on
which the cooling rate is scored (:data:`COOLING_TRAVEL`)."""
from __future__ import annotations

import math

import numpy as np

from .rises import bulk_of

#: metrics of the thermal trace (scenes with ``field``): relative max-norm errors over the depths where
#: both the run and the reference have a value (the run's NaN, "field too short", are left out), the
#: peak temperature on its rise above the bulk temperature. metrics.nc carries them only for a study
#: with a ``field`` scene (so that other studies' files keep their variables).
TRACE_PROFILES = ("peak_temperature", "cooling_rate", "time_above")
TRACE_METRICS = TRACE_PROFILES + ("heated_depth",)
#: the cooling rate is scored at the depths where the material point's cooling is spread over at least this
#: fraction of the patch half-length a of travel: the exact cooling at depth z is smoothed over a travel
#: l(z) = V z^2 / (4 kappa) (the time z^2 / (4 kappa) heat takes to reach z, at the body's speed V), so
#: z >= z_c = sqrt(kappa a / (4 V)) (~0.35 of the thermal layer sqrt(2 kappa a / V)). Shallower, the rate grows
#: like log(1/z) towards its infinite surface value (the flux ends at the trailing edge) within l << a cell,
#: set by the grid, not by the method: on trace-band at level 3 the max-norm over all depths was 14-24 % for
#: every method, all of it at z < 16 um, against 0.03 % (green) to 3.4 % (fipy) at z >= z_c (26 um), with
#: orders 2.5 / 2.0 / 2.9 / 0.8 (green / fastsim-fdm / fem / fipy) on levels 1-3. The profile is reported at
#: every depth; only the metric leaves the shallow depths out.
COOLING_TRAVEL = 1.0 / 16.0


def cooling_rate_depth(scene, a: float) -> np.ndarray:
    """Shallowest depth z_c [m] per body (wheel, rail) at which the cooling-rate metric scores a run:
    ``sqrt(4 f kappa a / V)`` with f = :data:`COOLING_TRAVEL` (= ``sqrt(kappa a / (4 V))``), where the
    cooling is spread over f a of travel (0 for a body at rest).

    Parameters
    ----------
    scene : Scene
    a : float
        Semi-axis of the patch along the rolling direction [m].
    """
    from ..physics import body_speeds
    speeds = body_speeds(scene)
    return np.array([math.sqrt(4.0 * COOLING_TRAVEL * scene.body(i).diffusivity * float(a) / abs(float(v)))
                     if v and a and a > 0 else 0.0 for i, v in enumerate(speeds)])


def _shallow_nan(values, z, z_c) -> np.ndarray:
    """``values`` (body, z) with NaN at the depths shallower than each body's ``z_c``."""
    v = np.array(values, dtype=float)
    v[np.asarray(z, float)[None, :] < np.asarray(z_c, float)[:, None]] = np.nan
    return v


def rel_error_finite(scene, name: str, value, reference) -> float:
    """Like :func:`rel_error`, over the entries where both are finite [1] (NaN when there are none):
    the thermal trace's flagged values ("field too short") and the infinite exact cooling rate at the
    surface are left out."""
    v, r = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    if v.shape != r.shape or v.size == 0:
        return math.nan
    b = bulk_of(scene, name, v.shape)
    v, r = v - b, r - b
    ok = np.isfinite(v) & np.isfinite(r)
    if not ok.any():
        return math.nan
    scale = np.max(np.abs(r[ok]))
    if scale == 0:
        return math.nan if np.max(np.abs(v[ok])) > 0 else 0.0
    return float(np.max(np.abs(v - r)[ok]) / scale)


def _semi_axis(scene, ds) -> float:
    """Semi-axis a [m] of a result's patch: the run's ``semi_axis_a``, else the scene's source."""
    if "semi_axis_a" in ds and np.isfinite(float(ds["semi_axis_a"].values)):
        return float(ds["semi_axis_a"].values)
    from .analytic import _thermal_case
    case = _thermal_case(scene)
    return float(case[0]) if case is not None else math.nan


def trace_errors(scene, ds, fields: dict, values: dict, ref_ds=None, ref_tag: str = "", exact=None) -> dict:
    """Errors of the trace metrics of one result: metric -> (error, reference tag).

    Parameters
    ----------
    scene : Scene
    ds : xarray.Dataset
        The result.
    fields, values : dict
        Exact trace profiles (:func:`railtherm.analysis.analytic.reference_fields`) and scalars
        (``heated_depth``) of the scene.
    ref_ds : xarray.Dataset, optional
        A reference run for the profiles without an exact value (the same depth axis).
    ref_tag : str
        Tag of ``ref_ds``.
    exact : callable
        Metric name -> tag of its exact reference (``analytic:<name>``), or None when that reference is the
        run's own input (not independent).
    """
    err: dict[str, tuple[float, str]] = {}
    if not any(name in ds for name in TRACE_METRICS):
        return err
    for name in TRACE_METRICS:
        if name not in ds:
            continue
        value = ds[name].values
        # fields: reference_fields of the run's subsample (the depth axis is not subsampled)
        ref = fields.get(name) if name != "heated_depth" else values.get(name)
        if ref is None and ref_ds is not None and name in ref_ds and ref_ds[name].shape == ds[name].shape and (
                "z" not in ds[name].dims or np.array_equal(ref_ds["z"].values, ds["z"].values)):
            ref, tag = ref_ds[name].values, ref_tag
        elif ref is not None:
            tag = exact(name)
        else:
            continue
        if not tag:
            continue
        if name == "cooling_rate":           # the resolvable depths only (COOLING_TRAVEL)
            z_c = cooling_rate_depth(scene, _semi_axis(scene, ds))
            value, ref = _shallow_nan(value, ds["z"].values, z_c), _shallow_nan(ref, ds["z"].values, z_c)
        err[name] = (rel_error_finite(scene, name, value, ref), tag)
    return err
