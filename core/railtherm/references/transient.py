"""Exact transient temperature of a half-space under a moving surface source, in the fixed frame.

A surface heat source (a 2-D band |x - x_c| <= a, or a 3-D ellipse ((x - x_c)/a)^2 + (y/b)^2 <= 1) moves
with speed V in +x over the half-space z >= 0 (conductivity lambda, diffusivity kappa, rho c =
lambda/kappa; the free surface is insulated outside the source). The observed material point sits at
the fixed section x = 0, on the centre line y = 0, at depth z. The source's leading edge reaches the
section at time 0 (centre x_c(t) = V t - a), so the point lies under the source for 0 <= t <= D,
``D = 2 a / V`` (the contact duration). The flux is ``f(t) q(x - x_c, y)``: a shape q (uniform, or
Hertzian ``q0 sqrt(1 - ((x - x_c)/a)^2 [- (y/b)^2]``) times a heat-input schedule f(t) (piecewise
linear, constant end values outside the given times). The source exists for all times (it comes from
far upstream and goes far downstream); a schedule that is 0 at both ends gives a finite heat input.

Passes: the same source passes the section ``count`` times, ``interval`` apart (pass k arrives at k
interval; the schedule is in the time of the whole history). The problem is linear, so the history is
the sum of the passes' responses.

Fixed-frame integral (Carslaw & Jaeger 1959, 10.2-10.3: instantaneous line and point sources on the
insulated surface, doubled by the image), with tau = t - t' and s = 2 sqrt(kappa tau):

* band: ``T = 1/(rho c) int f(t') 2/(pi s^2) exp(-z^2/s^2) int q(x') exp(-(xi - x')^2/s^2) dx' dt'``,
* ellipse: ``T = 1/(rho c) int f(t') 2/(pi^(3/2) s^3) exp(-z^2/s^2) int int q exp(-((xi - x')^2 + y'^2)/s^2)
  dx' dy' dt'``,

xi = a - V t' the point's position relative to the source centre at emission. Inner integrals:

* uniform band: closed form, ``int = (s sqrt(pi)/2) [erf((xi + a)/s) - erf((xi - a)/s)]``;
* uniform ellipse: the x' integral in closed form (erf) on each chord, the y' integral (a Gaussian
  centred on the centre line, y' = b sin(psi)) by Gauss-Legendre over its window |y'| <= 6.5 s;
* Hertz ellipse: the y' integral in closed form,
  ``int_{-c}^{c} sqrt(c^2 - y^2) exp(-y^2/s^2) dy = (pi c^2/2) [I0e(w) + I1e(w)]``, w = c^2/(2 s^2)
  (y = c sin(theta), then 2 theta = phi and I_n(w) = (1/pi) int_0^pi exp(w cos phi) cos(n phi) dphi,
  Abramowitz & Stegun 9.6.19), the x' integral (x' = -a cos(phi)) by Gauss-Legendre over the window
  |x' - xi| <= 6.5 s; the Hertz band likewise. The Gaussian's tail beyond 6.5 s is e^-42.

The outer time integral uses u = sqrt(tau) (removes the tau^(-1/2) singularity of the surface point
under the source: the integrand becomes bounded), split at the pass's edges (t' = 0, D), the
schedule's times and the depth layer tau = z^2/(4 kappa), each piece by a composite Gauss-Legendre rule
geometrically graded toward both ends (hp-quadrature, :mod:`._quadrature`), which resolves the boundary
layers of any width at the edges; the error decays exponentially with the points per panel (see
tests/test_references_transient.py). Emission times so far upstream that exp(-d^2/(4 kappa tau)) <
e^-45 (d the distance to the source's leading edge) are left out.

A constant factor (the schedule's first value, which holds from t = -inf) gives the steady moving
field swept past the point, ``T(t) = T_steady(a - V t, 0, z)``, evaluated by the steady references
(:mod:`.jaeger`, :mod:`.moving_source`); only the schedule's departure from it, ``f - f(-inf)``, is
integrated in time. ``via_time_integral=True`` integrates everything in time (the check of the two
routes against each other is a test).

References
----------
.. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, sections 10.2,
   10.3 and 10.7. ISBN 978-0198533689
.. [2] J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts, J. Proc. Roy. Soc.
   New South Wales 76 (1942) 203-224.
.. [3] M. Abramowitz, I.A. Stegun, Handbook of Mathematical Functions, NBS, 1964, 9.6.19 and 9.7.1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize
from scipy.special import erf, erfc, ive

from ._quadrature import two_sided_rule
from .flash import thermal_properties
from .jaeger import jaeger_band_temperature
from .moving_source import moving_source_temperature

__all__ = ["MovingSource", "Schedule", "PassSummary", "history_time_axis", "pass_response",
           "temperature_history", "pass_summary", "shifted_sum"]

#: half-width of the Gaussian windows of the inner quadratures in units of s = 2 sqrt(kappa tau):
#: the tail beyond is erfc(6.5) ~ e^-42 / 11
_WINDOW = 6.5
#: emission left out where the Gaussian factor exp(-d^2/(4 kappa tau)) is below e^-_FAR
_FAR = 45.0
_SQRT_PI = math.sqrt(math.pi)


@dataclass(frozen=True)
class MovingSource:
    """A surface heat source moving in +x over a half-space.

    Parameters
    ----------
    kind : {"band", "ellipse"}
        2-D band (per unit length in y) or 3-D ellipse.
    half_width : float
        Semi-axis a along the motion [m].
    speed : float
        Speed V of the source relative to the body [m/s], > 0.
    flux : float
        Flux into the body [W/m^2]: the uniform value, or the peak q0 of the Hertzian shape.
    shape : {"uniform", "hertz"}
        Flux distribution.
    semi_axis_b : float or None
        Lateral semi-axis b of the ellipse [m] (ellipse only).
    """

    kind: str
    half_width: float
    speed: float
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
        if not (self.speed > 0 and math.isfinite(self.speed)):
            raise ValueError(f"speed must be a positive number [m/s], got {self.speed!r}")
        if self.kind == "ellipse" and not (self.semi_axis_b is not None and self.semi_axis_b > 0):
            raise ValueError(f"an ellipse needs semi_axis_b > 0 [m], got {self.semi_axis_b!r}")

    @property
    def contact_duration(self) -> float:
        """Time D = 2 a / V a material point spends under the source [s]."""
        return 2.0 * self.half_width / self.speed


@dataclass(frozen=True)
class Schedule:
    """Piecewise-linear heat-input factor f(t) [1]; before the first and after the last time it keeps
    its end values.

    Parameters
    ----------
    time : sequence of float
        Strictly increasing times [s] (time 0: the first pass's leading edge reaches the section).
    factor : sequence of float
        Factors >= 0 at those times [1].
    """

    time: tuple
    factor: tuple

    def __post_init__(self):
        t = np.asarray(self.time, dtype=float)
        f = np.asarray(self.factor, dtype=float)
        if t.ndim != 1 or t.size < 1 or t.shape != f.shape:
            raise ValueError("schedule time and factor must be 1-D sequences of the same length >= 1")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
            raise ValueError("schedule time and factor must be finite")
        if np.any(np.diff(t) <= 0):
            raise ValueError(f"schedule time must be strictly increasing, got {tuple(t)}")
        if np.any(f < 0):
            raise ValueError(f"schedule factor must be >= 0, got {tuple(f)}")
        object.__setattr__(self, "time", tuple(float(v) for v in t))
        object.__setattr__(self, "factor", tuple(float(v) for v in f))

    def __call__(self, t):
        """f(t) [1]."""
        return np.interp(t, self.time, self.factor)

    @property
    def is_constant(self) -> bool:
        return len(set(self.factor)) == 1


@dataclass(frozen=True)
class PassSummary:
    """Per-pass results: ``peak`` [K] and ``peak_time`` [s] of shape (count, depths), the maximum rise
    over [k interval, (k + 1) interval); ``residual`` [K] of shape (count, depths), the rise at
    (k + 1) interval left by passes 0 .. k (just before the next pass, without the conduction ahead of
    the arriving contact, which a 1-D model cannot have; after the last pass, one interval after it)."""

    peak: np.ndarray
    peak_time: np.ndarray
    residual: np.ndarray


# ------------------------------------------------------------------------------------------------
# inner (space) integrals at given emission times, in the variable u = sqrt(tau)
# ------------------------------------------------------------------------------------------------
def _erf_diff(hi, lo):
    """erf(hi) - erf(lo) for hi >= lo without cancellation in the tails."""
    with np.errstate(invalid="ignore"):
        return np.where(lo > 0, erfc(lo) - erfc(hi), np.where(hi < 0, erfc(-hi) - erfc(-lo), erf(hi) - erf(lo)))


def _band_uniform(xi, s, src, nx):
    """(1/s) int_{-a}^{a} exp(-(xi - x')^2/s^2) dx' [1]."""
    a = src.half_width
    return 0.5 * _SQRT_PI * _erf_diff((xi + a) / s, (xi - a) / s)


def _gl(nx):
    x, w = np.polynomial.legendre.leggauss(int(nx))
    return (x + 1.0) / 2.0, w / 2.0


def _x_window(xi, s, a):
    """phi-window (x' = -a cos phi) of the Gaussian exp(-(xi - x')^2/s^2) on [-a, a]; empty where lo >= hi."""
    lo = np.clip(xi - _WINDOW * s, -a, a)
    hi = np.clip(xi + _WINDOW * s, -a, a)
    return np.arccos(-lo / a), np.arccos(-hi / a)


def _band_hertz(xi, s, src, nx):
    """(1/s) int_{-a}^{a} sqrt(1 - x'^2/a^2) exp(-(xi - x')^2/s^2) dx' [1] (x' = -a cos phi)."""
    a = src.half_width
    p1, p2 = _x_window(xi, s, a)
    t, w = _gl(nx)
    phi = p1[:, None] + (p2 - p1)[:, None] * t[None, :]
    sp = np.sin(phi)
    g = sp * sp * a * np.exp(-((xi[:, None] + a * np.cos(phi)) / s[:, None]) ** 2)
    return (g @ w) * np.maximum(p2 - p1, 0.0) / s


def _ellipse_uniform(xi, s, src, nx):
    """(1/s^2) int int_ellipse exp(-((xi - x')^2 + y'^2)/s^2) dx' dy' [1]: x' in closed form, y' = b sin psi."""
    a, b = src.half_width, src.semi_axis_b
    top = np.arcsin(np.minimum(1.0, _WINDOW * s / b))
    t, w = _gl(nx)
    psi = top[:, None] * t[None, :]
    y = b * np.sin(psi)
    cx = a * np.cos(psi)
    sc = s[:, None]
    g = np.exp(-(y / sc) ** 2) * _erf_diff((xi[:, None] + cx) / sc, (xi[:, None] - cx) / sc) * b * np.cos(psi)
    # 2 (both signs of y') * (s sqrt(pi)/2) / s^2
    return _SQRT_PI * (g @ w) * top / s


def _bessel_sum(w):
    """I0e(w) + I1e(w); above w = 1e6 (where scipy's ive returns nan from 1e10 on) its asymptotic series
    2 (1 - 1/(8 w)) / sqrt(2 pi w), relative error < 1e-13 there (Abramowitz & Stegun 9.7.1)."""
    big = w > 1e6
    wb = np.where(big, w, 1.0)
    ws = np.where(big, 0.0, w)
    return np.where(big, 2.0 * (1.0 - 0.125 / wb) / np.sqrt(2.0 * math.pi * wb), ive(0, ws) + ive(1, ws))


def _ellipse_hertz(xi, s, src, nx):
    """(1/s^2) int int sqrt(1 - x'^2/a^2 - y'^2/b^2) exp(-((xi - x')^2 + y'^2)/s^2) dx' dy' [1]: y' in
    closed form (Bessel), x' = -a cos phi by Gauss-Legendre."""
    a, b = src.half_width, src.semi_axis_b
    p1, p2 = _x_window(xi, s, a)
    t, w = _gl(nx)
    phi = p1[:, None] + (p2 - p1)[:, None] * t[None, :]
    sp = np.sin(phi)
    c = b * sp
    sc = s[:, None]
    wv = 0.5 * (c / sc) ** 2
    ycut = 0.5 * math.pi * c * c / b * _bessel_sum(wv)
    g = ycut * np.exp(-((xi[:, None] + a * np.cos(phi)) / sc) ** 2) * a * sp
    return (g @ w) * np.maximum(p2 - p1, 0.0) / (s * s)


_INNER = {("band", "uniform"): _band_uniform, ("band", "hertz"): _band_hertz,
          ("ellipse", "uniform"): _ellipse_uniform, ("ellipse", "hertz"): _ellipse_hertz}


def _integrand_u(u, theta_e, z, src, kappa, nx):
    """rho c / q * (kernel integrated over the source) * dtau/du at tau = u^2, emission time theta_e."""
    s = 2.0 * math.sqrt(kappa) * u
    xi = src.half_width - src.speed * theta_e
    out = np.zeros(u.shape)
    ok = s > 0
    if not np.any(ok):
        return out
    inner = _INNER[(src.kind, src.shape)](xi[ok], s[ok], src, nx)
    with np.errstate(under="ignore"):
        depth = np.exp(-(z / s[ok]) ** 2)
    if src.kind == "band":
        out[ok] = 2.0 / (math.pi * math.sqrt(kappa)) * inner * depth
    else:
        out[ok] = 2.0 / (math.pi ** 1.5 * math.sqrt(kappa)) * inner * depth
    return out


def _upstream_reach(theta, src, kappa):
    """Time L before arrival beyond which emissions are negligible at observation time theta: at emission
    t' = -x the point is V x ahead of the leading edge and tau <= theta + x, V^2 x^2 / (4 kappa (theta + x))
    > _FAR for x > L."""
    v2 = src.speed ** 2
    c = 4.0 * kappa * _FAR
    th = max(theta, 0.0)
    return (c + math.sqrt(c * c + 4.0 * v2 * c * th)) / (2.0 * v2)


def _far(p, q, theta, z, src, kappa):
    """True when every emission in [p, q] (times after arrival) reaches the point with a Gaussian factor
    exp(-(d^2 + z^2)/(4 kappa tau)) < e^-_FAR: d the distance from the point to the nearest source edge,
    at least V (p - D) after departure or V (-q) before arrival, tau <= theta - p."""
    d = src.speed * max(p - src.contact_duration, -q, 0.0)
    return d * d + z * z > 4.0 * kappa * (theta - p) * _FAR


def _time_integral(theta, z, src, kappa, factor, start, breaks, n, nx, stop=math.inf):
    """int_{start}^{min(stop, theta)} factor(t') K(theta - t', t') dt' [K per (q/(rho c))], u = sqrt(theta - t').

    ``factor`` is a callable of the emission time relative to the pass's arrival, zero outside
    [start, stop]; ``breaks`` the times where it has kinks. Pieces whose emissions are all too far from
    the point (:func:`_far`) are left out."""
    lo = max(start, -_upstream_reach(theta, src, kappa))
    hi = min(stop, theta)
    if lo >= hi:
        return 0.0
    pts = [lo, hi]
    pts += [b for b in breaks if lo < b < hi]
    for b in (0.0, src.contact_duration, theta - z * z / (4.0 * kappa)):
        if lo < b < hi:
            pts.append(b)
    pts = np.unique(pts)
    t, w = two_sided_rule(int(n))
    total = 0.0
    for p, q in zip(pts[:-1], pts[1:]):
        if _far(p, q, theta, z, src, kappa):
            continue
        u1, u2 = math.sqrt(theta - q), math.sqrt(theta - p)
        u = u1 + (u2 - u1) * t
        te = theta - u * u
        total += (u2 - u1) * float(np.dot(w, factor(te) * _integrand_u(u, te, z, src, kappa, nx)))
    return total


# ------------------------------------------------------------------------------------------------
# one pass
# ------------------------------------------------------------------------------------------------
def _steady_sweep(theta, z, src, material):
    """Steady moving field at the point, T_steady(a - V theta, 0, z) [K] (source on for all times)."""
    x = src.half_width - src.speed * theta
    if src.kind == "band":
        return jaeger_band_temperature(x, z, src.half_width, src.speed, material, src.flux, src.shape)
    return moving_source_temperature(x, 0.0, z, (src.half_width, src.semi_axis_b), src.speed, material,
                                     src.flux, src.shape)


def _split(schedule, via_time_integral):
    """(constant factor held from t = -inf, schedule whose time integral is added or None, subtract it)."""
    if schedule is None:
        return 1.0, None, 0.0
    if schedule.is_constant:
        return schedule.factor[0], None, 0.0
    if via_time_integral:
        return 0.0, schedule, 0.0
    return schedule.factor[0], schedule, schedule.factor[0]


def _constant_part(theta, depth, source, material, via_time_integral, quad_points, inner_points):
    """Rise [K] of one pass with factor 1 for all times, shape (theta, depth)."""
    out = np.empty((theta.size, depth.size))
    if not via_time_integral:
        for j, z in enumerate(depth):
            out[:, j] = _steady_sweep(theta, z, source, material)
        return out
    lam, kappa = thermal_properties(material)
    scale = source.flux * kappa / lam

    def one(te):
        return np.ones_like(te)
    for i, th in enumerate(theta):
        for j, z in enumerate(depth):
            out[i, j] = scale * _time_integral(th, z, source, kappa, one, -math.inf, (), quad_points,
                                               inner_points)
    return out


def _schedule_part(theta, depth, source, material, schedule, minus, arrival, quad_points, inner_points):
    """Rise [K] of one pass arriving at ``arrival`` due to the factor f(t) - minus, integrated in time."""
    lam, kappa = thermal_properties(material)
    times = np.asarray(schedule.time)
    nonzero = np.nonzero(np.asarray(schedule.factor) != minus)[0]
    if nonzero.size == 0:
        return np.zeros((theta.size, depth.size))
    # f - minus is zero before the time preceding its first nonzero value, and (when f ends at minus)
    # after the time following its last
    start = -math.inf if nonzero[0] == 0 else times[nonzero[0] - 1] - arrival
    stop = times[nonzero[-1] + 1] - arrival if nonzero[-1] + 1 < times.size else math.inf

    def factor(te):
        return schedule(te + arrival) - minus
    breaks = tuple(times - arrival)
    out = np.zeros((theta.size, depth.size))
    scale = source.flux * kappa / lam
    for i, th in enumerate(theta):
        for j, z in enumerate(depth):
            out[i, j] = scale * _time_integral(th, z, source, kappa, factor, start, breaks, quad_points,
                                               inner_points, stop)
    return out


def _as_depth(depth):
    depth = np.atleast_1d(np.asarray(depth, dtype=float)).ravel()
    if np.any(depth < 0) or not np.all(np.isfinite(depth)):
        raise ValueError(f"depth must be finite and >= 0 [m], got {depth}")
    return depth


def pass_response(theta, depth, source: MovingSource, material, schedule: Schedule | None = None,
                  arrival: float = 0.0, quad_points: int = 12, inner_points: int = 48,
                  via_time_integral: bool = False) -> np.ndarray:
    """Temperature rise of the fixed material point under one pass of a moving source.

    Parameters
    ----------
    theta : array_like
        Time since the pass's leading edge reached the section [s] (negative: before).
    depth : array_like
        Depths z >= 0 of the point [m] (1-D).
    source : MovingSource
        The source (kind, half-width, speed, flux, shape).
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density [kg/m^3] and specific_heat [J/(kg K)]).
    schedule : Schedule or None
        Heat-input factor f(t) in the history's time [1]; None: f = 1.
    arrival : float
        Time at which this pass's leading edge reaches the section, in the schedule's time [s].
    quad_points : int
        Gauss-Legendre points per graded panel of the time integral [1].
    inner_points : int
        Gauss-Legendre points of the inner window quadratures (Hertz shapes, uniform ellipse) [1].
    via_time_integral : bool
        Integrate the constant part f(-inf) in time too, instead of sweeping the steady field.

    Returns
    -------
    numpy.ndarray
        Rise [K], shape (theta.size, depth.size).

    References
    ----------
    .. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, 10.2-10.7.
       ISBN 978-0198533689
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=float)).ravel()
    depth = _as_depth(depth)
    const, sched, minus = _split(schedule, via_time_integral)
    out = np.zeros((theta.size, depth.size))
    if const != 0.0:
        out += const * _constant_part(theta, depth, source, material, via_time_integral, quad_points,
                                      inner_points)
    if sched is not None:
        out += _schedule_part(theta, depth, source, material, sched, minus, arrival, quad_points, inner_points)
    return out


# ------------------------------------------------------------------------------------------------
# passes
# ------------------------------------------------------------------------------------------------
def _check_passes(count, interval, source):
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ValueError(f"count must be an integer >= 1, got {count!r}")
    if count > 1 or interval is not None:
        if interval is None or not (interval >= source.contact_duration and math.isfinite(interval)):
            raise ValueError(f"interval must be >= the contact duration {source.contact_duration:g} s, "
                             f"got {interval!r} [s]")


def history_time_axis(source: MovingSource, count: int = 1, interval: float | None = None,
                      samples_per_contact: int = 20, tail_samples: int = 40) -> np.ndarray:
    """Time axis of a history [s]: for each pass the same offsets, ``samples_per_contact`` per contact
    duration D over [0, 2 D], then ``tail_samples`` geometrically spaced up to the next pass (the last
    pass: one interval after it; a single pass without interval: up to 100 D). The common offsets let
    :func:`temperature_history` reuse one pass's response for all passes.

    Parameters
    ----------
    source : MovingSource
        The source.
    count : int
        Number of passes [1].
    interval : float or None
        Time between passes [s], >= D.
    samples_per_contact : int
        Samples per contact duration near each pass [1].
    tail_samples : int
        Samples between 2 D and the next pass [1].

    Returns
    -------
    numpy.ndarray
        Increasing times [s] from 0 to count * interval.
    """
    _check_passes(count, interval, source)
    d = source.contact_duration
    span = interval if interval is not None else 100.0 * d
    offsets = np.linspace(0.0, min(2.0 * d, span), int(2 * samples_per_contact) + 1)
    if span > 2.0 * d:
        offsets = np.concatenate([offsets, np.geomspace(2.0 * d, span, int(tail_samples) + 1)[1:]])
    return np.concatenate([k * span + offsets[:-1] for k in range(count)] + [[count * span]])


def shifted_sum(time, count: int, interval: float | None, curve, reach: float = 0.0,
                through_pass=None) -> np.ndarray:
    """Sum of one pass's response over passes: ``out(t) = sum_k curve(t - k interval)``, k = 0 .. count - 1.

    Each time is split into its pass index n and phase t - n interval; ``curve`` is evaluated once per
    (distinct phase, n) and the passes are summed by cumulative sums over n. On an axis whose passes share
    their offsets (:func:`history_time_axis`) that is (offsets) x (count) evaluations and no
    (samples) x (count) work at all.

    Parameters
    ----------
    time : array_like
        Times [s].
    count : int
        Passes [1].
    interval : float or None
        Time between passes [s] (None: one pass).
    curve : callable
        Response of one pass arriving at 0, ``curve(theta) -> array (theta.size, m)`` [any unit].
    reach : float
        A pass contributes only where t - k interval > -reach [s] (its response ahead of arrival).
    through_pass : array_like of int or None
        Per time, the last pass counted [1]; None: all.

    Returns
    -------
    numpy.ndarray
        Shape (time.size, m).
    """
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    last = np.full(time.size, count - 1) if through_pass is None else \
        np.minimum(np.asarray(through_pass, dtype=int).ravel(), count - 1)
    if interval is None or count == 1:
        live = (time > -reach) & (last >= 0)
        first = curve(time[live]) if np.any(live) else np.zeros((0, 1))
        out = np.zeros((time.size, first.shape[1]))
        out[live] = first
        return out
    step = float(interval)
    k = np.floor(time / step + 1e-9).astype(int)
    phase = np.maximum(time - k * step, 0.0)
    uph, inv = np.unique(np.round(phase / step, 12), return_inverse=True)
    inv = inv.ravel()
    uph = uph * step
    n_lo = -int(math.ceil(reach / step)) - 1
    n_hi = max(int(k.max()), n_lo)
    ns = np.arange(n_lo, n_hi + 1)
    theta = uph[:, None] + step * ns[None, :]
    live = theta > -reach
    vals = curve(theta[live])
    table = np.zeros(theta.shape + (vals.shape[1],))
    table[live] = vals
    cum = np.concatenate([np.zeros((uph.size, 1, vals.shape[1])), np.cumsum(table, axis=1)], axis=1)
    # passes j = 0 .. last: n = k - j from k - last to k, within the table's n range
    hi = np.clip(k - n_lo + 1, 0, ns.size)
    lo = np.clip(k - last - n_lo, 0, ns.size)
    lo = np.minimum(lo, hi)
    return cum[inv, hi] - cum[inv, lo]


def temperature_history(time, depth, source: MovingSource, material, count: int = 1,
                        interval: float | None = None, schedule: Schedule | None = None,
                        quad_points: int = 12, inner_points: int = 48,
                        via_time_integral: bool = False, through_pass=None) -> np.ndarray:
    """Temperature rise history of the fixed material point under ``count`` passes.

    The response to the schedule's first value (held from t = -inf) is one curve for every pass,
    shifted: it is evaluated once per distinct shift, so a time axis from :func:`history_time_axis`
    costs (offsets per pass) x (count) evaluations whatever the schedule. The schedule's departure
    from that value is integrated in time for each pass.

    Parameters
    ----------
    time : array_like
        Times [s] (time 0: the first pass's leading edge reaches the section).
    depth : array_like
        Depths [m], >= 0.
    source : MovingSource
        The source.
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density and specific_heat).
    count : int
        Number of passes [1].
    interval : float or None
        Time between passes [s], >= the contact duration (needed when count > 1).
    schedule : Schedule or None
        Heat-input factor [1]; None: 1.
    quad_points, inner_points : int
        See :func:`pass_response`.
    via_time_integral : bool
        See :func:`pass_response`.
    through_pass : array_like of int or None
        Per time, the last pass counted [1] (passes after it left out); None: all.

    Returns
    -------
    numpy.ndarray
        Rise [K], shape (time.size, depth.size).
    """
    _check_passes(count, interval, source)
    time = np.atleast_1d(np.asarray(time, dtype=float)).ravel()
    depth = _as_depth(depth)
    lam, kappa = thermal_properties(material)
    step = 0.0 if interval is None else float(interval)
    reach = _upstream_reach(0.0, source, kappa) + source.contact_duration
    opts = dict(quad_points=quad_points, inner_points=inner_points)
    const, sched, minus = _split(schedule, via_time_integral)
    out = np.zeros((time.size, depth.size))
    if const != 0.0:
        # a pass still further ahead than its upstream reach adds less than e^-45 of its rise: skipped
        out += const * shifted_sum(time, count, interval,
                                   lambda th: _constant_part(th, depth, source, material, via_time_integral, **opts),
                                   reach=reach, through_pass=through_pass)
    if sched is not None:
        last = np.full(time.size, count - 1) if through_pass is None else np.asarray(through_pass).ravel()
        for k in range(count):
            rows = np.nonzero((time - k * step > -reach) & (k <= last))[0]
            if rows.size:
                out[rows] += _schedule_part(time[rows] - k * step, depth, source, material, sched, minus, k * step,
                                            **opts)
    return out


def _own_pass(t, k, step, depth_j, source, material, schedule, opts):
    """Rise [K] at time t due to pass k alone, at one depth."""
    return float(pass_response([t - k * step], [depth_j], source, material, schedule, arrival=k * step,
                               **opts)[0, 0])


def pass_summary(depth, source: MovingSource, material, count: int = 1, interval: float | None = None,
                 schedule: Schedule | None = None, samples_per_contact: int = 40, tail_samples: int = 40,
                 quad_points: int = 12, inner_points: int = 48, refine: bool = True) -> PassSummary:
    """Per-pass peak rise and residual rise of the fixed material point (see :class:`PassSummary`).

    The history is sampled on :func:`history_time_axis`; each pass's largest sample is then refined
    by a bounded scalar search (Brent, to 1e-7 D) over the two neighbouring sample intervals, with the
    pass's own response evaluated exactly and the other passes' (smooth there: they vary on the scale
    of the interval, not of D) interpolated quadratically through the three samples.

    Parameters
    ----------
    depth : array_like
        Depths [m], >= 0.
    source : MovingSource
        The source.
    material : Material-like
        conductivity [W/(m K)] and diffusivity [m^2/s] (or density and specific_heat).
    count : int
        Number of passes [1].
    interval : float
        Time between passes [s], >= the contact duration (also for one pass: the residual is taken
        one interval after it).
    schedule : Schedule or None
        Heat-input factor [1].
    samples_per_contact, tail_samples : int
        Sampling of :func:`history_time_axis` [1].
    quad_points, inner_points : int
        See :func:`pass_response`.
    refine : bool
        Refine the peaks by the scalar search (False: the largest sample).

    Returns
    -------
    PassSummary
        peak [K], peak_time [s], residual [K].
    """
    if interval is None:
        raise ValueError("interval is needed for the residual rise (one interval after the last pass) [s]")
    depth = _as_depth(depth)
    axis = history_time_axis(source, count, interval, samples_per_contact, tail_samples)
    opts = dict(quad_points=quad_points, inner_points=inner_points)
    hist = temperature_history(axis, depth, source, material, count, interval, schedule, **opts)
    per = (axis.size - 1) // count
    peak = np.empty((count, depth.size))
    when = np.empty((count, depth.size))
    # the passes up to k at the next arrival: the arriving pass's forerunning conduction left out
    residual = temperature_history(interval * np.arange(1, count + 1), depth, source, material, count, interval,
                                   schedule, **opts, through_pass=np.arange(count))
    d = source.contact_duration
    for k in range(count):
        seg = slice(k * per, (k + 1) * per)
        for j in range(depth.size):
            i = k * per + int(np.argmax(hist[seg, j]))
            peak[k, j], when[k, j] = hist[i, j], axis[i]
            if not refine or i == 0:
                continue
            lo, mid, hi = axis[i - 1], axis[i], axis[i + 1]
            own = [_own_pass(t, k, interval, depth[j], source, material, schedule, opts) for t in (lo, mid, hi)]
            rest = np.polyfit([lo, mid, hi], [hist[i - 1, j] - own[0], hist[i, j] - own[1],
                                              hist[i + 1, j] - own[2]], 2)

            def minus_rise(t):
                return -(_own_pass(t, k, interval, depth[j], source, material, schedule, opts)
                         + np.polyval(rest, t))
            res = optimize.minimize_scalar(minus_rise, bounds=(lo, hi), method="bounded",
                                           options={"xatol": 1e-7 * d})
            if -res.fun > peak[k, j]:
                peak[k, j], when[k, j] = -res.fun, res.x
    return PassSummary(peak=peak, peak_time=when, residual=residual)
