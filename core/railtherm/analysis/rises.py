"""Which quantities are compared on their rise above the bulk temperature, that bulk temperature, and the
relative error norms taken on it."""
from __future__ import annotations

import math

import numpy as np

#: quantities whose relative error is taken on the rise above the bulk temperature
RISES = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature",
         "steady_wheel_temperature", "steady_mean_contact_temperature", "peak_temperature")


def bulk_of(scene, name: str, shape: tuple) -> np.ndarray | float:
    """Bulk temperature [degC] to subtract from quantity ``name`` of the given shape (0 if none)."""
    if name not in RISES:
        return 0.0
    if name.startswith("steady"):
        return scene.wheel.bulk_temperature
    bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
    if len(shape) == 0:
        return scene.wheel.bulk_temperature
    return bulk.reshape((2,) + (1,) * (len(shape) - 1)) if shape[0] == 2 else 0.0


def _rises_where_finite(scene, name: str, value, reference):
    """(v, r, mask) on the rise above bulk, ``mask`` the finite reference entries, or the error itself (a
    float) when nothing is compared (NaN: shapes differ or no finite reference) or the run is not finite
    where the reference is (inf: the metric fails)."""
    v, r = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    if v.shape != r.shape or v.size == 0:
        return math.nan
    b = bulk_of(scene, name, v.shape)
    v, r = v - b, r - b
    fin = np.isfinite(r)
    if not fin.any():
        return math.nan
    if not np.all(np.isfinite(v[fin])):
        return math.inf
    return v, r, fin


def rel_error(scene, name: str, value, reference) -> float:
    """Max-norm relative error [1] of ``value`` against ``reference`` (same shape) over the entries where the
    reference is finite, temperatures on their rise above bulk: ``inf`` when the value is not finite at one of
    them, NaN when there is none; a zero reference gives 0 for a zero value, else NaN (no relative scale)."""
    got = _rises_where_finite(scene, name, value, reference)
    if isinstance(got, float):
        return got
    v, r, fin = got
    scale = np.max(np.abs(r[fin]))
    if scale == 0:
        return math.nan if np.max(np.abs(v[fin])) > 0 else 0.0
    return float(np.max(np.abs(v - r)[fin]) / scale)


def rel_l2(scene, name: str, value, reference) -> float:
    """Relative L2 norm [1] of ``value − reference`` against ``reference`` over the same entries as
    :func:`rel_error`."""
    got = _rises_where_finite(scene, name, value, reference)
    if isinstance(got, float):
        return got
    v, r, fin = got
    den = np.sqrt(np.sum(r[fin] ** 2))
    if den == 0:
        return math.nan
    return float(np.sqrt(np.sum((v - r)[fin] ** 2)) / den)
