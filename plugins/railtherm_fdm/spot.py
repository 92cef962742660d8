"""fdm's history of a body whose surface does not move through the contact: a locked wheel's spot.

The rail's section is passed by the contact (:mod:`.history`); the locked wheel's material under the contact
stays there, heated in place while the schedule heats it. fdm steps that spot on the blocks of the passes (x-z
of a line contact, x-y-z of a patch), the source at rest over the block's centre: ``C d theta/dt = -K theta +
f(t) P``. The depth grid resolves sqrt(kappa t_heat) (the moving blocks' sqrt(2 a kappa / V) with the contact time
2a/V replaced by the heating time). Crank-Nicolson steps, equal within each piece of the schedule, at most
t_heat / (:data:`STEPS_PER_HEATING` 2**level), the first two of each piece backward Euler (Rannacher's start [1]:
the heating rate jumps at the schedule's kinks). Exact reference: :mod:`railtherm.references.transient_spot`.

References: [1] R. Rannacher, Finite element solution of diffusion problems with irregular data, Numer. Math. 43
(1984) 309-327, doi:10.1007/BF01390130. [2] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed.,
Oxford, 1959, 10.2-10.5, ISBN 978-0198533689.
"""
from __future__ import annotations

import math
import time as _time

import numpy as np
from railtherm import Refused, TransientHistory, theta_steps
from railtherm.physics import pass_peaks_and_residual, pass_time_above
from railtherm.references.transient import Schedule
from railtherm.references.transient_spot import heating_window

from .history import BandSource, ImplicitSection, section_block
from .history3d import EllipseSource, Implicit3D, ellipse_block

__all__ = ["STEPS_PER_HEATING", "heating_time", "spot_history", "resting_body_history", "with_resting_body"]

#: Crank-Nicolson steps per heating time t_heat at level 0 (doubled per level)
STEPS_PER_HEATING = 200


def heating_time(tr, body: str) -> tuple[float, float]:
    """(start, stop) [s] of the schedule's heating; stop the history's end when it heats to the end.

    Raises
    ------
    railtherm.Refused
        No schedule, or one that does not start at factor 0: the spot at rest would have been heated since
        t = -inf (no finite history on a band, a steady one on a patch that is no pass history).
    """
    end = int(tr.count) * float(tr.interval)
    schedule = None if tr.schedule_time is None else Schedule(tr.schedule_time, tr.schedule_factor)
    try:
        start, stop = heating_window(schedule)
    except ValueError:
        raise Refused(f"model 'fdm' ({body}): its surface does not move through the contact (speed 0: a locked wheel), "
                      "so its spot is heated as long as the schedule heats it; the schedule must start at factor 0 "
                      "(switched on at a finite time) -- without one the spot would be heated since t = -inf",
                      kind="validity") from None
    return start, min(stop, end)


def spot_history(block, power: np.ndarray, sample: np.ndarray, implicit, tr, level: int,
                 t_heat: float) -> tuple[np.ndarray, np.ndarray, dict]:
    """Rise history [K] of the block's centre column under a source at rest: (time (nt,), rise (nt, depths),
    diagnostics).

    Parameters
    ----------
    block : SectionBlock or EllipseBlock
        The block (``capacity`` [J/K], ``stiffness`` [W/K]).
    power : numpy.ndarray
        Nodal heat input at factor 1 [W] (or [W/m] on the 2-D block), one entry per unknown.
    sample : numpy.ndarray of int
        The unknowns recorded (the centre column at the output depths).
    implicit : object
        The block's theta-step solver, ``step(T, dt, theta, p_old, p_new)``.
    tr : railtherm.input.transient.Transient
        Passes (the history ends at count * interval [s]) and schedule (first factor 0).
    level : int
        Refinement level [1].
    t_heat : float
        The heating time [s] that sets the largest step.
    """
    t_start = _time.perf_counter()
    end = int(tr.count) * float(tr.interval)
    st, sf = np.asarray(tr.schedule_time, dtype=float), np.asarray(tr.schedule_factor, dtype=float)
    cuts = np.unique([0.0, end] + [float(t) for t in tr.schedule_time if 0.0 < t < end])
    dt_max = t_heat / (STEPS_PER_HEATING * 2 ** int(level))
    T = np.zeros(block.capacity.size)
    times, rows, steps = [np.zeros(1)], [np.zeros((1, sample.size))], 0
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        m = max(8 * 2 ** int(level), int(math.ceil((hi - lo) / dt_max)))
        T, _, out, t = theta_steps(T, float(lo), (hi - lo) / m, m, lambda s: float(np.interp(s, st, sf)) * power,
                                   implicit.step, lambda T: T[sample], sample.size, 0.5, start=2)
        times.append(t)
        rows.append(out)
        steps += m
    diag = {"nodes": int(block.capacity.size), "node_shape": block.node_shape, "scheme": "Crank-Nicolson, source at rest",
            "reason": ("the surface does not move through the contact: its spot is heated in place, Crank-Nicolson "
                       f"steps of at most t_heat / {STEPS_PER_HEATING * 2 ** int(level)} = {dt_max:.3g} s within each "
                       "piece of the schedule, two backward-Euler steps at each of its kinks"),
            "heating_time": t_heat, "implicit_solves": steps, "first_depth_cell": float(block.z[1]),
            "block_depth": float(block.z[-1]), "wall_time_solver": _time.perf_counter() - t_start}
    return np.concatenate(times), np.concatenate(rows), diag


def resting_body_history(tr, grid, flux, material, convection: float, level: int, body: str,
                         max_nodes: float = math.inf):
    """The history of a body at rest under the contact (its spot): (time [s], rise [K] (nt, depths),
    diagnostics), on fdm's block of the contact (2-D for a line contact, 3-D for a patch, refused above
    ``max_nodes`` nodes) with the source's ``flux`` [W/m^2] on the source grid ``grid`` at rest over the block's
    centre."""
    a = float(grid.a)
    start, stop = heating_time(tr, body)
    end = int(tr.count) * float(tr.interval)
    t_heat = max(stop - start, 1e-12 * end)
    speed = 2.0 * a / t_heat                   # the block's thermal layer sqrt(2 a kappa / V) = sqrt(kappa t_heat)
    args = (speed, material.conductivity, material.density * material.specific_heat, convection, level, end,
            np.asarray(tr.depths, dtype=float))
    xe = np.asarray(grid.x_edges, dtype=float)
    if grid.line:
        block = section_block(a, *args)
        nz = block.z.size
        power = np.zeros(block.capacity.size)
        # the band's source moving at 1 m/s, taken at tau = x_lead: its centre over the section
        power[np.arange(block.x.size) * nz] = BandSource(block, xe, flux, 1.0).power(float(xe[-1]))
        sample, implicit = block.i0 * nz + block.depth_index, ImplicitSection(block)
    else:
        block = ellipse_block(a, float(grid.b), *args, max_nodes=max_nodes, body=body)
        ny, nz = block.y.size, block.z.size
        power = np.zeros(block.capacity.size)
        top = (np.arange(block.x.size)[:, None] * ny + np.arange(ny)[None, :]) * nz
        power[top] = EllipseSource(block, xe, grid.y_edges, flux, 1.0).power(float(xe[-1]))
        sample, implicit = (block.i0 * ny) * nz + block.depth_index, Implicit3D(block)
    return spot_history(block, power, sample, implicit, tr, level, t_heat)


def with_resting_body(hist: TransientHistory, i: int, time, rise, tr, bulk: float) -> TransientHistory:
    """``hist`` (body ``i`` at its bulk temperature) with body ``i``'s history ``rise`` [K] on ``time`` [s] put in:
    the union of the time axes (each body linearly interpolated onto it), body i's per-pass peaks, time above the
    threshold and residual (its surface rise at the end of each window) from its own samples."""
    t = np.union1d(hist.time, time)
    temp = np.stack([np.stack([np.interp(t, hist.time, hist.temperature[b, :, j]) for j in range(hist.z.size)],
                              axis=1) for b in range(2)])
    temp[i] = bulk + np.stack([np.interp(t, time, rise[:, j]) for j in range(rise.shape[1])], axis=1)
    count, interval = int(tr.count), float(tr.interval)
    peak, residual, above = hist.peak.copy(), hist.residual.copy(), None
    p, res = pass_peaks_and_residual(time, rise, count, interval)
    peak[i], residual[i] = p + bulk, res[:, 0]
    if hist.time_above is not None:
        above = hist.time_above.copy()
        above[i] = pass_time_above(time, rise, count, interval, float(tr.threshold) - bulk)
    return TransientHistory(time=t, z=hist.z, temperature=temp, peak=peak, residual=residual, time_above=above)
