"""The thermal trace's metrics in ``metrics.nc`` (scenes with ``field``): relative max-norm errors of the
trace profiles over the depths where the reference has a value (a run's non-finite value there fails the
metric), and the depth range on which the cooling rate is scored (:data:`COOLING_TRAVEL`);
``cooling_rate_all_depths`` scores it at every depth (shown beside it, not used by the verdict)."""
from __future__ import annotations

import math

import numpy as np

from .rises import rel_error

#: metrics of the thermal trace (scenes with ``field``): relative max-norm errors over the depths where
#: both the run and the reference have a value (the run's NaN, "field too short", are left out), the
#: peak temperature on its rise above the bulk temperature. metrics.nc carries them only for a study
#: with a ``field`` scene (so that other studies' files keep their variables).
TRACE_PROFILES = ("peak_temperature", "cooling_rate", "time_above")
TRACE_METRICS = TRACE_PROFILES + ("heated_depth", "cooling_rate_all_depths")
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


def cooling_rate_depth(a: float, speeds, wheel, rail) -> np.ndarray:
    """Shallowest depth z_c [m] per body (wheel, rail) at which the cooling-rate metric scores a run:
    ``sqrt(4 f kappa a / V)`` with f = :data:`COOLING_TRAVEL` (= ``sqrt(kappa a / (4 V))``), where the
    cooling is spread over f a of travel (0 for a body at rest).

    Parameters
    ----------
    a : float
        Semi-axis of the patch along the rolling direction [m].
    speeds : (float, float)
        The wheel's and the rail's surface speeds through the patch [m/s]
        (:func:`railtherm.physics.body_speeds`).
    wheel, rail : Material
        The bodies (their diffusivities kappa [m^2/s]).
    """
    return np.array([math.sqrt(4.0 * COOLING_TRAVEL * mat.diffusivity * float(a) / abs(float(v)))
                     if v and a and a > 0 else 0.0 for mat, v in zip((wheel, rail), speeds)])


def _shallow_nan(values, z, z_c) -> np.ndarray:
    """``values`` (body, z) with NaN at the depths shallower than each body's ``z_c``."""
    v = np.array(values, dtype=float)
    v[np.asarray(z, float)[None, :] < np.asarray(z_c, float)[:, None]] = np.nan
    return v


def _on_depths(ref_ds, ds, name):
    """Profile ``name`` (body, z) of run ``ref_ds`` at the depths of run ``ds`` (linear in z; NaN outside the
    reference's depth range); the scalar ``heated_depth`` as it is. None when the shapes cannot match."""
    ref = ref_ds[name]
    if "z" not in ref.dims:
        return ref.values if ref.shape == ds[name].shape else None
    if np.array_equal(ref_ds["z"].values, ds["z"].values):
        return ref.values
    out = ref.interp(z=ds["z"].values, kwargs={"fill_value": np.nan}).transpose(*ds[name].dims).values
    return out if out.shape == ds[name].shape else None


def _within_field(ds, name: str, ref, fields: dict, notes: dict):
    """The exact profile ``ref`` with NaN at the depths whose exact event (the peak; for the cooling rate the
    fastest cooling) lies behind the end of the run's field: the field the scene asks for does not hold it,
    for the exact solution either, so those depths are not scored (and ``notes`` says so)."""
    where = fields.get("trace_cooling_position" if name == "cooling_rate" else "trace_peak_position")
    if where is None or "x" not in ds.coords or name == "heated_depth":
        return ref
    beyond = np.asarray(where, float) < float(ds["x"].min())
    if not beyond.any():
        return ref
    ref = np.array(ref, dtype=float)
    ref[beyond] = np.nan
    what = "fastest cooling" if name == "cooling_rate" else "peak"
    notes[name] = (f"the exact {what} lies behind the end of the field at {int(beyond.sum())} of {beyond.size} "
                   "depths (field.behind too short): not scored there")
    return ref


def _semi_axis(ds, case) -> float:
    """Semi-axis a [m] of a result's patch: the run's ``semi_axis_a``, else that of the scene's closed-form
    source, ``case()`` (:func:`railtherm.analysis.analytic._thermal_case`; called only then, None without one)."""
    if "semi_axis_a" in ds and np.isfinite(float(ds["semi_axis_a"].values)):
        return float(ds["semi_axis_a"].values)
    source = case()
    return float(source[0]) if source is not None else math.nan


def trace_errors(ds, fields: dict, values: dict, ref_ds=None, ref_tag: str = "", exact=None,
                 notes: dict | None = None, *, bulk, speeds, wheel, rail, case) -> dict:
    """Errors of the trace metrics of one result: metric -> (error [1], reference tag).

    Parameters
    ----------
    ds : xarray.Dataset
        The result.
    fields, values : dict
        Exact trace profiles (:func:`railtherm.analysis.analytic.reference_fields`) and scalars
        (``heated_depth``) of the scene.
    ref_ds : xarray.Dataset, optional
        A reference run for the profiles without an exact value (put on the run's depths, linear in z).
    ref_tag : str
        Tag of ``ref_ds``.
    exact : callable
        Metric name -> tag of its exact reference (``analytic:<name>``), or None when that reference is the
        run's own input (not independent).
    notes : dict, optional
        Filled with metric -> why it fails (``inf``).
    bulk : (float, float)
        The wheel's and the rail's bulk temperatures [degC] (the peak temperature is scored on its rise).
    speeds : (float, float)
        The bodies' surface speeds through the patch [m/s], and ``wheel``, ``rail`` their materials: the
        depths the cooling rate is scored at (:func:`cooling_rate_depth`).
    case : callable
        ``case()``: the scene's closed-form heat source (:func:`_semi_axis`), asked only when the run has no
        semi-axis.
    """
    err: dict[str, tuple[float, str]] = {}
    notes = {} if notes is None else notes
    for name in TRACE_METRICS[:4]:
        if name not in ds:
            continue
        value = ds[name].values
        # fields: reference_fields of the run's subsample (the depth axis is not subsampled)
        ref = fields.get(name) if name != "heated_depth" else values.get(name)
        if ref is None and ref_ds is not None and name in ref_ds:
            ref, tag = _on_depths(ref_ds, ds, name), ref_tag
        elif ref is not None:
            tag = exact(name)
            ref = _within_field(ds, name, ref, fields, notes)
        else:
            continue
        if ref is None:
            err[name] = (math.inf, tag)
            notes[name] = "the reference profile could not be put on the run's depths"
            continue
        if not tag:
            continue
        if name == "cooling_rate":           # the resolvable depths only (COOLING_TRAVEL); all depths beside it
            err["cooling_rate_all_depths"] = (rel_error(bulk, name, value, ref), tag)
            z_c = cooling_rate_depth(_semi_axis(ds, case), speeds, wheel, rail)
            value, ref = _shallow_nan(value, ds["z"].values, z_c), _shallow_nan(ref, ds["z"].values, z_c)
        err[name] = (rel_error(bulk, name, value, ref), tag)
        if math.isinf(err[name][0]):
            notes[name] = "not finite at a depth where its reference is"
    return err
