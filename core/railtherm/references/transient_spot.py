"""Exact history of a half-space under a surface source at rest (a locked wheel's contact spot).

A band (2-D, per unit length) or ellipse (3-D) source, uniform or Hertzian flux (:class:`FixedSource`), sits at
rest on the insulated half-space and is switched on and off by a piecewise-linear heat-input schedule
(:class:`~railtherm.references.transient_pass.Schedule`) that starts at factor 0: a source heated since
t = -inf has no finite history on the band. The material point lies at depth z under the source's centre.
The rise is the time integral of the instantaneous surface sources (Carslaw & Jaeger 1959, 10.2-10.5),

    theta(z, t) = q / (rho c) int f(t') K(z, t - t') dt',

the source-integrated kernel K the one of :mod:`.transient_pass` at the source's centre (xi = 0: inner
integrals in closed form or by Gauss-Legendre windows), the time integral in u = sqrt(t - t') by graded
composite Gauss-Legendre panels between the schedule's kinks. Closed forms it reduces to: the uniform disc
on its axis (C&J 10.5 (6)), the 1-D half-space under a constant flux (C&J 2.9 (7)) where the source is wide
against sqrt(kappa t).

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, sections 2.9,
10.2-10.5. ISBN 978-0198533689.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ._quadrature import two_sided_rule
from .flash import thermal_properties
from .transient import PassSummary
from .transient_pass import _INNER, Schedule, _as_depth

__all__ = ["FixedSource", "fixed_source_history", "fixed_source_summary", "heating_window"]


@dataclass(frozen=True)
class FixedSource:
    """A surface heat source at rest on a half-space.

    Parameters
    ----------
    kind : {"band", "ellipse"}
        2-D band (per unit length in y) or 3-D ellipse.
    half_width : float
        Semi-axis a along x [m].
    flux : float
        Flux into the body [W/m^2]: the uniform value, or the peak q0 of the Hertzian shape.
    shape : {"uniform", "hertz"}
        Flux distribution.
    semi_axis_b : float or None
        Semi-axis b along y [m] (ellipse only).
    """

    kind: str
    half_width: float
    flux: float = 1.0
    shape: str = "uniform"
    semi_axis_b: float | None = None

    def __post_init__(self):
        if self.kind not in ("band", "ellipse"):
            raise ValueError(f"kind must be 'band' or 'ellipse', got {self.kind!r}")
        if self.shape not in ("uniform", "hertz"):
            raise ValueError(f"shape must be 'uniform' or 'hertz', got {self.shape!r}")
        if not (self.half_width > 0 and math.isfinite(self.half_width)):
            raise ValueError(f"half_width must be a positive number [m], got {self.half_width!r}")
        if not (math.isfinite(self.flux) and self.flux >= 0):
            raise ValueError(f"flux must be a finite number >= 0 [W/m^2], got {self.flux!r}")
        if self.kind == "ellipse" and not (self.semi_axis_b is not None and self.semi_axis_b > 0):
            raise ValueError(f"an ellipse needs semi_axis_b > 0 [m], got {self.semi_axis_b!r}")


def heating_window(schedule: Schedule) -> tuple[float, float]:
    """(start, stop) [s] of the times the schedule's factor is not zero (stop inf when it ends above 0).

    Raises
    ------
    ValueError
        The schedule does not start at factor 0 (a source at rest heated since t = -inf).
    """
    if schedule is None or schedule.factor[0] != 0.0:
        got = None if schedule is None else schedule.factor[0]
        raise ValueError("a source at rest needs a schedule whose first factor is 0 (switched on at a finite time; "
                         f"heated since t = -inf the band's rise has no bound), got first factor {got!r}")
    f = np.asarray(schedule.factor)
    t = np.asarray(schedule.time)
    on = np.nonzero(f != 0.0)[0]
    if on.size == 0:
        return 0.0, 0.0
    start = float(t[on[0] - 1])
    stop = float(t[on[-1] + 1]) if on[-1] + 1 < t.size else math.inf
    return start, stop


def _kernel_u(u, z, src, kappa, nx):
    """rho c / q times the source-integrated kernel at its centre times dtau/du, at tau = u^2 [s^0.5 ...]."""
    s = 2.0 * math.sqrt(kappa) * u
    out = np.zeros(u.shape)
    ok = s > 0
    if not np.any(ok):
        return out
    inner = _INNER[(src.kind, src.shape)](np.zeros(int(np.count_nonzero(ok))), s[ok], src, nx)
    with np.errstate(under="ignore"):
        depth = np.exp(-(z / s[ok]) ** 2)
    power = 1.0 if src.kind == "band" else 1.5
    out[ok] = 2.0 / (math.pi ** power * math.sqrt(kappa)) * inner * depth
    return out


def _rise_at(t, z, src, kappa, schedule, start, stop, n, nx):
    """int_{start}^{min(stop, t)} f(t') K(z, t - t') dt' [K per q/(rho c)]: panels between the schedule's
    kinks and t - z^2/(4 kappa) (the kernel's peak at depth z), each graded toward both ends in u."""
    hi = min(stop, t)
    if hi <= start:
        return 0.0
    pts = [start, hi] + [b for b in schedule.time if start < b < hi]
    peak = t - z * z / (4.0 * kappa)
    if start < peak < hi:
        pts.append(peak)
    pts = np.unique(pts)
    rule, w = two_sided_rule(int(n))
    total = 0.0
    for p, q in zip(pts[:-1], pts[1:]):
        u1, u2 = math.sqrt(t - q), math.sqrt(t - p)
        u = u1 + (u2 - u1) * rule
        total += (u2 - u1) * float(np.dot(w, schedule(t - u * u) * _kernel_u(u, z, src, kappa, nx)))
    return total


def fixed_source_history(time, depth, source: FixedSource, material, schedule: Schedule,
                         quad_points: int = 12, inner_points: int = 48) -> np.ndarray:
    """Temperature rise history under the centre of a surface source at rest.

    Parameters
    ----------
    time : array_like
        Times [s] (the schedule's time).
    depth : array_like
        Depths z >= 0 of the point under the source's centre [m].
    source : FixedSource
        The source (kind, half-width, flux, shape).
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density [kg/m^3] and specific_heat [J/(kg K)]).
    schedule : Schedule
        Heat-input factor f(t) [1], first factor 0 (see :func:`heating_window`).
    quad_points : int
        Gauss-Legendre points per graded panel of the time integral [1].
    inner_points : int
        Gauss-Legendre points of the inner window quadratures (Hertz shapes, uniform ellipse) [1].

    Returns
    -------
    numpy.ndarray
        Rise [K], shape (time.size, depth.size).

    References
    ----------
    .. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, 10.2-10.5.
       ISBN 978-0198533689
    """
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    depth = _as_depth(depth)
    start, stop = heating_window(schedule)
    lam, kappa = thermal_properties(material)
    scale = source.flux * kappa / lam
    out = np.zeros((time.size, depth.size))
    for i, t in enumerate(time):
        for j, z in enumerate(depth):
            out[i, j] = scale * _rise_at(float(t), float(z), source, kappa, schedule, start, stop, quad_points,
                                         inner_points)
    return out


def fixed_source_summary(depth, source: FixedSource, material, count: int, interval: float, schedule: Schedule,
                         samples: int = 200, quad_points: int = 12, inner_points: int = 48) -> PassSummary:
    """Per-window peak and residual rise of the point under a source at rest (the windows of a transient
    scene: [k interval, (k + 1) interval), k = 0 .. count - 1; residual at (k + 1) interval, the surface).

    Each window is sampled at ``samples`` equal steps plus the schedule's times inside it; the largest sample
    is refined by a bounded scalar search (Brent, to 1e-9 of the window) on the exact rise over its two
    neighbouring steps.

    Parameters
    ----------
    depth : array_like
        Depths [m], >= 0.
    source : FixedSource
        The source.
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density and specific_heat).
    count : int
        Windows [1].
    interval : float
        Window length [s], > 0.
    schedule : Schedule
        Heat-input factor [1], first factor 0.
    samples : int
        Samples per window [1].
    quad_points, inner_points : int
        See :func:`fixed_source_history`.

    Returns
    -------
    PassSummary
        peak [K] and peak_time [s] (count, depths), residual [K] (count, depths).
    """
    if not (interval > 0 and math.isfinite(interval)):
        raise ValueError(f"interval must be a finite number > 0 [s], got {interval!r}")
    depth = _as_depth(depth)
    opts = dict(quad_points=quad_points, inner_points=inner_points)
    peak = np.empty((int(count), depth.size))
    when = np.empty_like(peak)
    for k in range(int(count)):
        lo, hi = k * interval, (k + 1) * interval
        axis = np.union1d(np.linspace(lo, hi, int(samples) + 1)[:-1],
                          [t for t in schedule.time if lo <= t < hi])
        hist = fixed_source_history(axis, depth, source, material, schedule, **opts)
        for j, z in enumerate(depth):
            i = int(np.argmax(hist[:, j]))
            peak[k, j], when[k, j] = hist[i, j], axis[i]
            left, right = axis[max(i - 1, 0)], axis[i + 1] if i + 1 < axis.size else hi
            res = optimize.minimize_scalar(
                lambda t, z=z: -fixed_source_history([t], [z], source, material, schedule, **opts)[0, 0],
                bounds=(left, right), method="bounded", options={"xatol": 1e-9 * interval})
            if -res.fun > peak[k, j]:
                peak[k, j], when[k, j] = -res.fun, res.x
    residual = fixed_source_history(interval * np.arange(1, int(count) + 1), depth, source, material, schedule,
                                    **opts)
    return PassSummary(peak=peak, peak_time=when, residual=residual)
