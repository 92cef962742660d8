"""Exact history of a half-space under a surface source at rest (a locked wheel's contact spot).

A band (2-D, per unit length) or ellipse (3-D) source, uniform or Hertzian flux (:class:`FixedSource`), sits at
rest on the insulated half-space, switched on and off by a piecewise-linear schedule that starts at factor 0 (a
band heated since t = -inf has no finite history). The point lies at depth z under the source's centre:
theta(z, t) = q / (rho c) int f(t') K(z, t - t') dt', K the instantaneous surface sources integrated over the
source (Carslaw & Jaeger 1959, 10.2-10.5; the band's in closed form, the ellipse's by the window quadratures of
:mod:`.transient_pass`), the time integral in u = sqrt(t - t') by graded Gauss-Legendre panels between the
schedule's kinks. Limits it reduces to: the uniform disc on its axis (C&J 10.5 (6)), the 1-D half-space (2.9 (7)).

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, sections 2.9,
10.2-10.5. ISBN 978-0198533689. [2] M. Abramowitz, I.A. Stegun, Handbook of Mathematical Functions, NBS, 1964,
9.6.18-19.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize
from scipy.special import erf

from ._quadrature import graded_pair_rule
from .flash import thermal_properties
from .transient import PassSummary
from .transient_pass import _GRADE_MARGIN, _INNER, Schedule, _as_depth, _bessel_sum, check_source_geometry

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
        check_source_geometry(self)
        if not (math.isfinite(self.flux) and self.flux >= 0):
            raise ValueError(f"flux must be a finite number >= 0 [W/m^2], got {self.flux!r}")


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


def _centre_inner(s, src, nx):
    """(1/s^d) times the source's flux shape integrated against exp(-r^2/s^2) about its centre [1] (d = 1 band,
    2 ellipse): the band's in closed form, (1/s) int_{-a}^{a} exp(-x^2/s^2) dx = sqrt(pi) erf(a/s) and
    (1/s) int_{-a}^{a} sqrt(1 - x^2/a^2) exp(-x^2/s^2) dx = (pi a / (2 s)) (I0e(w) + I1e(w)), w = a^2/(2 s^2)
    (Abramowitz & Stegun 9.6.18-19); the ellipse's by :mod:`.transient_pass`'s window quadratures."""
    a = src.half_width
    if src.kind == "band" and src.shape == "uniform":
        return math.sqrt(math.pi) * erf(a / s)
    if src.kind == "band":
        return 0.5 * math.pi * a / s * _bessel_sum(0.5 * (a / s) ** 2)
    return _INNER[(src.kind, src.shape)](np.zeros(s.size), s, src, nx)


def _kernel_u(u, depth, src, kappa, nx):
    """rho c / q times the source-integrated kernel under its centre times dtau/du at tau = u^2, at each depth:
    shape (u.size, depth.size)."""
    s = 2.0 * math.sqrt(kappa) * u
    out = np.zeros((u.size, depth.size))
    ok = s > 0
    if not np.any(ok):
        return out
    power = 1.0 if src.kind == "band" else 1.5
    inner = 2.0 / (math.pi ** power * math.sqrt(kappa)) * _centre_inner(s[ok], src, nx)
    with np.errstate(under="ignore"):
        out[ok] = inner[:, None] * np.exp(-(depth[None, :] / s[ok, None]) ** 2)
    return out


def _grade_exponent(distance: float, width: float) -> int:
    """Exponent of the innermost panel [1] (:func:`~._quadrature.graded_pair_rule`) at an end of a panel of
    ``width`` in u whose nearest singularity is ``distance`` away: the kernel under a source at rest is analytic
    in u = sqrt(tau) but at u = 0 (exp(-z^2/(4 kappa u^2)), the source's edges seen at s = 2 sqrt(kappa) u -> 0),
    so an end at u is graded down to :data:`~.transient_pass._GRADE_MARGIN` of u (fully, to 1e-16, at u = 0)."""
    rel = min(max(_GRADE_MARGIN * distance / max(width, np.finfo(float).tiny), 1e-16), 0.1)
    return int(math.floor(math.log10(rel)))


def _rise_at(t, depth, src, kappa, schedule, start, stop, n, nx):
    """int_{start}^{min(stop, t)} f(t') K(z, t - t') dt' [K per q/(rho c)] at each depth: panels between the
    schedule's kinks and t - z^2/(4 kappa) (the kernel's peak at each depth z), each graded toward both ends in
    u = sqrt(t - t') as far as its distance from u = 0 needs (:func:`_grade_exponent`)."""
    hi = min(stop, t)
    if hi <= start:
        return np.zeros(depth.size)
    peaks = t - depth * depth / (4.0 * kappa)
    pts = [start, hi] + [b for b in schedule.time if start < b < hi] + [p for p in peaks if start < p < hi]
    pts = np.unique(pts)
    total = np.zeros(depth.size)
    for p, q in zip(pts[:-1], pts[1:]):
        u1, u2 = math.sqrt(t - q), math.sqrt(t - p)
        rule, w = graded_pair_rule(int(n), _grade_exponent(u1, u2 - u1), _grade_exponent(u2, u2 - u1))
        u = u1 + (u2 - u1) * rule
        total += (u2 - u1) * (w * schedule(t - u * u)) @ _kernel_u(u, depth, src, kappa, nx)
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
        out[i] = scale * _rise_at(float(t), depth, source, kappa, schedule, start, stop, quad_points, inner_points)
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
