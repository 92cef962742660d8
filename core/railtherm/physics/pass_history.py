"""Per-pass quantities of a sampled temperature history at a fixed material point (transient scenes).

Any method that samples the history of the point on a time axis (green's Duhamel superposition, a
time-stepping scheme) reports the same per-pass peak, residual rise and time above a threshold from
it; these are those reductions, written once. Times in [s], rises in [K] above the bulk temperature.
"""
from __future__ import annotations

import numpy as np

__all__ = ["pass_peaks_and_residual", "pass_time_above", "superposition_limits"]

#: outputs of one pass's steady depth field, on another axis than the pass histories
_ONE_PASS_DEPTH = ("temperature", "peak_temperature", "cooling_rate", "heated_depth")


def superposition_limits(friction, heat_source, wheel, rail, outputs, model: str) -> str | None:
    """Why a history built by superposing one pass's response over the passes does not hold, or None: it
    holds while every pass gets the same heat, independent of the temperatures. A friction law that depends
    on the temperature makes each pass's heat depend on the earlier ones (the coupled loop would run per
    pass); bodies at different bulk temperatures exchange heat through the patch by a steady field that is
    no pass response; and one pass's depth-field outputs live on another axis than the histories.

    Parameters
    ----------
    friction : FrictionLaw or None
        The scene's friction law (its ``depends_on_temperature`` is read), None without one.
    heat_source : object or None
        The scene's given heat source; when given, no friction law sets the heat.
    wheel, rail : Material
        The bodies (their ``bulk_temperature`` [degC] is read).
    outputs : sequence of str
        The output names the scene asks for.
    model : str
        The model named in the reason.

    Returns
    -------
    str or None
        The first condition that fails, naming ``model`` and what to change; None when superposition holds.
    """
    if heat_source is None and friction is not None and friction.depends_on_temperature:
        return (f"model {model!r} superposes one pass's response over the passes, which holds only while the heat "
                "input does not depend on the temperature; a temperature-dependent friction law needs the coupled "
                f"loop in every pass, which {model!r} does not run: use a constant or slip-velocity friction law")
    t_wheel, t_rail = float(wheel.bulk_temperature), float(rail.bulk_temperature)
    if t_wheel != t_rail:
        return (f"model {model!r} superposes the frictional heat of the passes only; wheel and rail at different bulk "
                f"temperatures ({t_wheel:g} and {t_rail:g} degC) exchange heat through the patch by a steady field "
                "that is no pass response: give both bodies one bulk temperature")
    depth = [o for o in tuple(outputs or ()) if o in _ONE_PASS_DEPTH]
    if depth:
        return (f"model {model!r} does not return {depth[0]!r} in a transient scene with passes (the depth field is "
                "one pass's, on another axis than the histories): ask temperature_history, pass_peak_temperature, "
                "residual_rise or time_above")
    return None


def pass_peaks_and_residual(time, history, count: int, interval: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-pass peak over the samples of [k interval, (k + 1) interval) and residual rise at (k + 1) interval
    (the next pass's arrival; after the last, one interval after it; linear interpolation between
    samples if the time is not on the axis).

    Parameters
    ----------
    time : array_like
        Increasing times [s] covering [0, count * interval].
    history : array_like
        Rise [K], shape (time.size, depths).
    count : int
        Passes [1].
    interval : float
        Time between passes [s].

    Returns
    -------
    peak, residual : numpy.ndarray
        [K], shape (count, depths).
    """
    time, history, edges = _pass_windows(time, history, count, interval)
    lo = np.searchsorted(time, edges, side="left")        # first sample >= k interval: windows by index
    if np.all(lo[1:] > lo[:-1]) and lo[-2] < time.size:   # every window holds a sample: one reduction
        peak = np.maximum.reduceat(history, lo[:-1], axis=0)
        peak[-1] = history[lo[-2]:lo[-1]].max(axis=0)          # the last window ends at its boundary
    else:
        peak = np.empty((count, history.shape[1]))
        for k in range(count):
            peak[k] = history[lo[k]:lo[k + 1]].max(axis=0)
    residual = np.stack([np.interp(edges[1:], time, history[:, j]) for j in range(history.shape[1])], axis=1)
    return peak, residual


def pass_time_above(time, history, count: int, interval: float, rise: float) -> np.ndarray:
    """Time per pass above a rise, from a sampled history: the crossings linearly interpolated between
    samples, each pass's window [k interval, (k + 1) interval] (error O(dt^2) per crossing for a smooth
    history; the sampling sets which short excursions are seen).

    Parameters
    ----------
    time, history, count, interval : array_like, array_like, int, float
        Times [s], rise [K], passes [1] and time between passes [s], as in :func:`pass_peaks_and_residual`.
    rise : float
        Threshold rise above the bulk temperature [K].

    Returns
    -------
    numpy.ndarray
        [s], shape (count, depths).
    """
    time, history, edges = _pass_windows(time, history, count, interval)
    # one axis for all windows: the pass boundaries (values interpolated) and the samples strictly inside
    # the windows; each interval between neighbours belongs to the window of its left end
    on_edge = edges[np.clip(np.searchsorted(edges, time), 0, count)] == time
    if np.count_nonzero(on_edge) == count + 1:          # every boundary a sample: that axis as it is
        within = (time >= edges[0]) & (time <= edges[-1])
        t, g = (time, history - rise) if within.all() else (time[within], history[within] - rise)
    else:
        ends = np.stack([np.interp(edges, time, history[:, j]) for j in range(history.shape[1])], axis=1)
        inside = (time > edges[0]) & (time < edges[-1]) & ~on_edge
        t_in = time[inside]
        at = np.searchsorted(t_in, edges)
        t = np.insert(t_in, at, edges)
        g = np.insert(history[inside], at, ends, axis=0) - rise
    # imported here, not at the top: the compiled pass needs numba, which ``import railtherm`` (the CLI,
    # the conformance kit loaded as a pytest plugin) should not load
    from ._pass_kernels import time_above_sums
    # writable C arrays always (a read-only one, e.g. an xarray index, would compile a second specialisation)
    return time_above_sums(np.require(t, float, "CW"), np.require(g, float, "CW"), np.require(edges, float, "CW"),
                           int(count))


def _pass_windows(time, history, count: int, interval: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The time axis [s] and history [K] as float arrays, the history as (time.size, depths), and the
    ``count + 1`` pass boundaries k interval [s] that bound the passes' windows."""
    time = np.asarray(time, dtype=float)
    return time, np.asarray(history, dtype=float).reshape(time.size, -1), interval * np.arange(count + 1)
