"""Green's transient scenes: the histories at the fixed section from one pass's strip flux.

The temperature model computes one pass's flux on its grid as for a steady scene; the material point on
the centre line y = 0 of each body then meets that flux once per pass (per revolution for the wheel)
and :func:`railtherm_green.transient.strip_history` superposes the passes exactly in time (the 1-D
Green function of each strip; on a 3-D contact the strips weighted by the lateral Gaussian, so that the
centre line also cools sideways between passes, :mod:`railtherm_green.lateral`). What it neglects is
conduction along x (along the rail or the tread), negligible at high Péclet number where the section sees
the same history at every x (tests/test_green_transient_lateral.py measures the rest against the exact
moving ellipse).

Superposition needs the passes to be independent: a friction law that depends on the temperature makes
each pass's heat depend on the earlier ones (the coupled loop would run per pass), and bodies at
different bulk temperatures exchange heat through the patch by a steady field that is not a pass
response; green refuses both in a transient scene (:func:`railtherm.physics.superposition_limits`).
"""
from __future__ import annotations

import numpy as np

from railtherm import SceneError, TransientHistory
from railtherm.physics import pass_peaks_and_residual, pass_time_above

from .transient import scheduled_passes, strip_history, strip_time_axis

__all__ = ["histories"]


def histories(transient, grid, flux: np.ndarray, bodies, speeds, bulk, *,
              scene_name: str = "") -> tuple[TransientHistory, dict]:
    """The :class:`TransientHistory` of both bodies and its diagnostics.

    Parameters
    ----------
    transient : railtherm.input.transient.Transient
        The scene's passes (``scene.transient``, its interval resolved): count, interval [s], schedule,
        history depths [m] and threshold [degC].
    grid : SurfaceGrid
        Green's grid of the pass (x cell edges ``grid.x_edges``).
    flux : ndarray, shape (2, nx, ny)
        Each body's flux per cell [W/m^2] (ny = 1 for a line contact).
    bodies : (Material, Material)
        Wheel and rail.
    speeds : (float, float)
        Each body's surface speed through the contact [m/s].
    bulk : (float, float)
        Bulk temperatures [degC].
    scene_name : str
        The scene's name, for the error message.

    Raises
    ------
    railtherm.SceneError
        ``passes.interval`` shorter than a body's contact duration on green's grid.
    """
    tr = transient
    x_edges = np.asarray(grid.x_edges, dtype=float)
    count, interval = int(tr.count), float(tr.interval)
    length = float(x_edges[-1] - x_edges[0])
    for v in speeds:
        if interval < length / v:
            raise SceneError.bad_value(scene_name, "passes.interval", interval,
                                       f"a time >= the contact duration 2a/V = {length / v:.6g} s (a pass must end "
                                       "before the next begins)")
    heated = [i for i in range(2) if flux[i].any()]
    y_edges = None if grid.line else np.asarray(grid.y_edges, dtype=float)
    # the heated bodies' own axes (their union when their speeds differ); passes a schedule's kink meets are
    # sampled at the edges and centres (a short spike's peak)
    axes = [strip_time_axis(x_edges, v, count, interval,
                            dense=scheduled_passes(count, interval, length / v, tr.schedule_time, tr.schedule_factor))
            for v in sorted({float(speeds[i]) for i in heated} or {float(speeds[1])})]
    time = axes[0] if len(axes) == 1 else np.unique(np.concatenate(axes))
    z = np.asarray(tr.depths, dtype=float)
    temperature = np.empty((2, time.size, z.size))
    peak = np.empty((2, count, z.size))
    residual = np.empty((2, count))
    above = np.empty((2, count, z.size))
    for i, m in enumerate(bodies):
        if i not in heated:                             # an unheated body stays at its bulk temperature
            temperature[i], peak[i], residual[i] = bulk[i], bulk[i], 0.0
            above[i] = interval if tr.threshold - bulk[i] < 0 else 0.0
            continue
        rise = strip_history(time, z, x_edges, flux[i, :, 0] if grid.line else flux[i], m.effusivity, m.diffusivity,
                             speeds[i], count=count, interval=interval, schedule_time=tr.schedule_time,
                             schedule_factor=tr.schedule_factor, y_edges=y_edges)
        p, r = pass_peaks_and_residual(time, rise, count, interval)
        peak[i], residual[i] = p + bulk[i], r[:, 0]
        # a history that never exceeds the threshold spends no time above it (what pass_time_above sums then)
        limit = tr.threshold - bulk[i]
        above[i] = pass_time_above(time, rise, count, interval, limit) if rise.max() > limit else 0.0
        np.add(rise, bulk[i], out=temperature[i])
    hist = TransientHistory(time=time, z=z, temperature=temperature, peak=peak, residual=residual, time_above=above)
    diag = {"transient_passes": count, "transient_interval": interval, "transient_time_samples": int(time.size),
            "transient_method": "Duhamel superposition of the 1-D strip Green function, the strips weighted by "
                                "the lateral Gaussian on a 3-D contact (one pass's response reused for every "
                                "pass with a constant schedule)",
            "transient_neglects": "conduction along x (the rolling direction)"}
    return hist, diag
