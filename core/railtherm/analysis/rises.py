"""Which quantities are compared on their rise above the bulk temperature, that bulk temperature, and the
relative error norms taken on it."""
from __future__ import annotations

import math

import numpy as np

#: quantities whose relative error is taken on the rise above the bulk temperature
RISES = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature",
         "steady_wheel_temperature", "steady_mean_contact_temperature", "peak_temperature")


def bulk_temperatures(wheel, rail) -> tuple[float, float]:
    """The bulk temperatures [degC] of the ``wheel`` and ``rail`` materials, as :func:`bulk_of` takes them."""
    return wheel.bulk_temperature, rail.bulk_temperature


def bulk_of(bulk, name: str, shape: tuple) -> np.ndarray | float:
    """Bulk temperature [degC] to subtract from quantity ``name`` of the given shape (0 if none).

    Parameters
    ----------
    bulk : (float, float) or None
        The wheel's and the rail's bulk temperatures [degC] (:func:`bulk_temperatures`); None when no
        quantity compared is a temperature.
    name : str
        The quantity: a temperature of :data:`RISES` is taken on its rise.
    shape : tuple
        Its shape: (2, ...) per body, () one value (the wheel's bulk temperature).
    """
    if name not in RISES:
        return 0.0
    if name.startswith("steady"):
        return bulk[0]
    both = np.array([bulk[0], bulk[1]])
    if len(shape) == 0:
        return bulk[0]
    return both.reshape((2,) + (1,) * (len(shape) - 1)) if shape[0] == 2 else 0.0


def _rises_where_finite(bulk, name: str, value, reference):
    """(v, r, mask) on the rise above ``bulk`` (:func:`bulk_of`), ``mask`` the finite reference entries, or the
    error itself (a float) when nothing is compared (NaN: shapes differ or no finite reference) or the run is
    not finite where the reference is (inf: the metric fails)."""
    v, r = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    if v.shape != r.shape or v.size == 0:
        return math.nan
    b = bulk_of(bulk, name, v.shape)
    v, r = v - b, r - b
    fin = np.isfinite(r)
    if not fin.any():
        return math.nan
    if not np.all(np.isfinite(v[fin])):
        return math.inf
    return v, r, fin


def rel_error(bulk, name: str, value, reference) -> float:
    """Max-norm relative error [1] of ``value`` against ``reference`` (same shape) over the entries where the
    reference is finite, temperatures on their rise above ``bulk`` (the wheel's and the rail's bulk
    temperatures [degC], :func:`bulk_of`): ``inf`` when the value is not finite at one of them, NaN when there
    is none; a zero reference gives 0 for a zero value, else NaN (no relative scale)."""
    got = _rises_where_finite(bulk, name, value, reference)
    if isinstance(got, float):
        return got
    v, r, fin = got
    scale = np.max(np.abs(r[fin]))
    if scale == 0:
        return math.nan if np.max(np.abs(v[fin])) > 0 else 0.0
    return float(np.max(np.abs(v - r)[fin]) / scale)


def rel_l2(bulk, name: str, value, reference) -> float:
    """Relative L2 norm [1] of ``value − reference`` against ``reference`` over the same entries as
    :func:`rel_error` (``bulk`` as there)."""
    got = _rises_where_finite(bulk, name, value, reference)
    if isinstance(got, float):
        return got
    v, r, fin = got
    den = np.sqrt(np.sum(r[fin] ** 2))
    if den == 0:
        return math.nan
    return float(np.sqrt(np.sum((v - r)[fin] ** 2)) / den)
