"""The thermal trace: what a material point on the centre line lives through as it passes the contact.

In the frame of the contact the body's material flows in -x at its surface speed V (it enters the patch
at x = +a, leaves at -a), so a steady field T(x, z) at y = 0 is the history of the material point at
depth z (at x at time t = (x0 - x)/V). Hence its **peak temperature** ``max_x T(x, z)`` [degC]; its
**cooling rate**, the fastest cooling after the peak ``max_{x < x_peak} V dT/dx`` [K s-1] (> 0); its
**time above** a threshold T*, the length of {x : T(x, z) > T*} divided by V [s]; and the **heated
depth**, down to which the peak exceeds T* [m]. Values the field is too short or shallow to hold are NaN
with a note, never a false peak; the ends and the discretisation are in :class:`Trace`.
One implementation for every method: a temperature model calls :func:`with_thermal_trace` on its
:class:`railtherm.TemperatureField`.

References: H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, section 10.7
(the moving frame's temperature is a material point's history). K.L. Johnson, Contact Mechanics,
Cambridge University Press, 1985, section 13.3. doi:10.1017/CBO9781139171731
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..contract.grid import embed as embed_field, extended_grid
from .trace_scan import trace_columns

__all__ = ["Trace", "thermal_trace", "with_thermal_trace", "field_grid", "embed_field", "extended_grid", "TRACE_OUTPUTS",
           "FIELD_TOO_SHORT"]

#: result variables of the trace (railtherm.contract.schema.VARIABLES)
TRACE_OUTPUTS = ("peak_temperature", "cooling_rate", "heated_depth", "time_above")
#: why a trace value is NaN
FIELD_TOO_SHORT = "field too short"


@dataclass(frozen=True)
class Trace:
    """Thermal trace of one body (arrays over the depths z).

    A field has ends: x runs from x_0 (= -a - field.behind) to +a, z from 0 to field.depth. A maximum
    (of T or of the cooling rate) at the first or last x of the field, or a temperature above T* at an
    end of the field, only says that the true value lies beyond the field: it is reported as NaN, with a
    note "field too short" (diagnostics ``trace_*``), never as a peak. The heated depth is NaN when the
    peak at the deepest z still exceeds T* ("field too shallow"), or when the crossing lies next to a
    depth whose peak is unknown. A body that gets no heat (T equal to its bulk temperature everywhere)
    has its bulk temperature as peak, no cooling (0) and no time above unless its bulk temperature is
    above T*.

    Discretisation: values are sampled at the field's x nodes (cell centres); maxima are refined by the
    parabola through the largest sample and its two neighbours, dT/dx is taken by second-order central
    differences (:func:`numpy.gradient`'s formula on a non-uniform x), crossings of T* by linear
    interpolation in x, and the heated depth by linear interpolation of the peak between the two depths
    that bracket T*. Each of these is second order in the spacing for a smooth field
    (tests/test_thermal_trace.py fits the orders against the exact moving-source references); a kink of
    the field (the surface temperature of a uniform flux at the trailing edge, where the exact cooling
    rate is infinite) lowers them. All depths are scanned at once
    (:func:`railtherm.physics.trace_scan.trace_columns`).

    Attributes
    ----------
    peak_temperature : ndarray, shape (nz,)
        Highest temperature of the material point at each depth [degC]; NaN where the maximum lies at
        an end of the field.
    peak_position : ndarray, shape (nz,)
        x of that maximum [m] (NaN where flagged).
    cooling_rate : ndarray, shape (nz,)
        Fastest cooling after the peak, max of V dT/dx behind it [K s-1] (>= 0; NaN where the peak
        or the fastest cooling lies at an end of the field).
    time_above : ndarray, shape (nz,)
        Time above the threshold [s] (NaN where the field is above it at one of its x ends).
    heated_depth : float
        Depth down to which the peak exceeds the threshold [m]; NaN when the field is too shallow
        or the crossing's neighbour is unknown.
    notes : tuple of str
        Why values are NaN ("field too short: ...").
    """

    peak_temperature: np.ndarray
    peak_position: np.ndarray
    cooling_rate: np.ndarray
    time_above: np.ndarray
    heated_depth: float
    notes: tuple = field(default_factory=tuple)


def thermal_trace(x, z, temperature, speed: float, threshold: float) -> Trace:
    """Thermal trace of one body from its steady depth field at y = 0 (the values: :class:`Trace`).

    Parameters
    ----------
    x : array_like, shape (nx,)
        Rolling coordinate in the frame of the contact [m], increasing (material flows in -x).
    z : array_like, shape (nz,)
        Depths [m], increasing from the surface.
    temperature : array_like, shape (nx, nz)
        Temperature T(x, z) [degC].
    speed : float
        Speed V of the body's material through the patch [m s-1], > 0.
    threshold : float
        Threshold temperature T* [degC] for ``time_above`` and ``heated_depth``.

    Returns
    -------
    Trace
        Peak temperature [degC], its position [m], cooling rate [K s-1] and time above T* [s] per
        depth, heated depth [m], and the notes on the values that are NaN (field too short).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(-4.0, 1.0, 501)
    >>> T = 20 + 800 * np.exp(-(x[:, None] + 1.0) ** 2 / (1 + np.array([0.0, 1.0])))
    >>> tr = thermal_trace(x, [0.0, 1.0], T, speed=2.0, threshold=727.0)
    >>> np.round(tr.peak_temperature, 6).tolist()
    [820.0, 820.0]
    """
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    T = np.asarray(temperature, dtype=float).reshape(x.size, z.size)
    v = float(speed)
    if not v > 0.0:
        raise ValueError(f"speed must be > 0, got {speed!r} [m/s]")
    thr = float(threshold)
    nz = z.size
    peak, where, cool, above, status = trace_columns(x, T, v, thr)
    short_peak = list(z[(status & 1) != 0])
    short_cool = list(z[(status & 2) != 0])
    short_above = list(z[(status & 4) != 0])
    # heated depth: the deepest crossing of the peak profile through the threshold
    known_above = np.where(np.isfinite(peak), peak > thr, T.max(axis=0) > thr)   # a field max above T*: so is the peak
    unknown = ~np.isfinite(peak) & ~known_above
    notes = []
    hd = math.nan
    if known_above.any():
        kd = int(np.flatnonzero(known_above)[-1])
        if kd == nz - 1:
            notes.append(f"heated_depth: {FIELD_TOO_SHORT} in depth (the peak at the deepest z = {z[-1]:.4g} m is "
                         f"still above {thr:g} degC; increase field.depth)")
        elif unknown[kd + 1] or not np.isfinite(peak[kd]):
            notes.append(f"heated_depth: {FIELD_TOO_SHORT} (the peak temperature next to the crossing of "
                         f"{thr:g} degC, at z = {z[kd]:.4g}..{z[kd + 1]:.4g} m, lies beyond the field; increase "
                         "field.behind)")
        else:
            p0, p1 = peak[kd], peak[kd + 1]
            hd = float(z[kd] + (z[kd + 1] - z[kd]) * (p0 - thr) / (p0 - p1))
    elif unknown[0]:
        notes.append(f"heated_depth: {FIELD_TOO_SHORT} (the surface peak lies beyond the field)")
    else:
        hd = 0.0

    def span(zs):
        return f"z = {min(zs):.4g}..{max(zs):.4g} m ({len(zs)} of {nz} depths)"
    if short_peak:
        notes.append(f"peak_temperature: {FIELD_TOO_SHORT} at {span(short_peak)}: the highest temperature lies at an "
                     f"end of the field (x = {x[0]:.4g} or {x[-1]:.4g} m); increase field.behind")
    if short_cool:
        notes.append(f"cooling_rate: {FIELD_TOO_SHORT} at {span(short_cool)}: the fastest cooling lies at the end of "
                     f"the field (x = {x[0]:.4g} m); increase field.behind")
    if short_above:
        notes.append(f"time_above: {FIELD_TOO_SHORT} at {span(short_above)}: the temperature is above {thr:g} degC at "
                     "an end of the field; increase field.behind")
    return Trace(peak, where, cool, above, hd, tuple(notes))


def field_grid(grid, field):
    """The grid a temperature model reports on: ``grid`` extended ``field.behind`` [m] beyond the trailing
    edge (:func:`railtherm.contract.grid.extended_grid`), or ``grid`` itself without a field.

    Contact and heat fields go onto it with :func:`embed_field` (:func:`railtherm.contract.grid.embed`: zero behind the
    patch).

    Parameters
    ----------
    grid : SurfaceGrid
        The patch grid.
    field : railtherm.input.scene.Field or None
        The scene's ``field``: ``behind`` [m] beyond the trailing edge (None: the patch only).
    """
    return grid if field is None else extended_grid(grid, field.behind)


def with_thermal_trace(temperature, field, source, outputs=None):
    """The temperature field with its thermal trace filled (one implementation for every method).

    Parameters
    ----------
    temperature : railtherm.TemperatureField
        A result with a depth field (``z`` and ``temperature``, shape (2, nx, nz), at y = 0) on
        ``temperature.grid`` (the extended grid of the scene's ``field``).
    field : railtherm.input.scene.Field or None
        The scene's ``field``: its ``threshold`` [degC] is the threshold (727 degC without a field).
    source : railtherm.HeatSource
        Its ``body_speed`` (wheel, rail) [m s-1] is the speed of each body's material.
    outputs : iterable of str, optional
        Not used for selection (all four are filled); kept for symmetry with the models' calls.

    Returns
    -------
    railtherm.TemperatureField
        A new field with ``peak_temperature``, ``cooling_rate``, ``time_above`` (2, nz) and
        ``heated_depth`` (2,), and diagnostics ``trace_threshold`` [degC] and, for a value that is NaN,
        ``trace_<body>_notes`` (why: field too short).

    Raises
    ------
    ValueError
        When the field has no depth field.
    """
    if temperature.z is None or temperature.temperature is None:
        raise ValueError("the thermal trace needs a depth field (TemperatureField.z and .temperature)")
    grid = temperature.grid
    if grid is None:
        grid = source.grid
    thr = float(field.threshold) if field is not None else 727.0
    x = np.asarray(grid.x, dtype=float)
    z = np.asarray(temperature.z, dtype=float)
    arrays = {k: np.empty((2, z.size)) for k in ("peak_temperature", "cooling_rate", "time_above")}
    depth = np.empty(2)
    diag = dict(temperature.diagnostics or {})
    diag["trace_threshold"] = thr
    for i, name in enumerate(("wheel", "rail")):
        tr = thermal_trace(x, z, temperature.temperature[i], float(source.body_speed[i]), thr)
        arrays["peak_temperature"][i] = tr.peak_temperature
        arrays["cooling_rate"][i] = tr.cooling_rate
        arrays["time_above"][i] = tr.time_above
        depth[i] = tr.heated_depth
        if tr.notes:
            diag[f"trace_{name}_notes"] = "; ".join(tr.notes)
    return replace(temperature, heated_depth=depth, diagnostics=diag, **arrays)
