"""One pass of a moving surface source over a fixed material point of a half-space: exact fixed-frame rise.

A band or ellipse source (:class:`MovingSource`, uniform or Hertz flux) moves with speed V over the insulated
half-space; the point sits at depth z under the centre line of the fixed section x = 0 and lies under the source
for 0 <= t <= D = 2 a / V. The flux is a shape times a piecewise-linear heat-input schedule (:class:`Schedule`).
:func:`pass_response` gives the rise as the fixed-frame integral of instantaneous surface sources (Carslaw &
Jaeger 1959, 10.2-10.3), inner integrals in closed form (erf, Bessel I0e + I1e) or Gauss-Legendre, the time
integral in u = sqrt(tau) by hp-quadrature (:mod:`._quadrature`). The schedule's first value gives the steady
moving field swept past the point (:mod:`.jaeger`, :mod:`.moving_source`); only its departure is integrated in
time. The derivation is in docs/NOTES.md, "Exact pass response".

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, 10.2, 10.3 and
10.7, ISBN 978-0198533689. [2] J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts,
J. Proc. Roy. Soc. New South Wales 76 (1942) 203-224. [3] M. Abramowitz, I.A. Stegun, Handbook of Mathematical
Functions, NBS, 1964, 9.6.19 and 9.7.1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numba
import numpy as np
from scipy.special import erf, erfc, ive

from ._quadrature import graded_pair_rule
from .flash import thermal_properties
from .jaeger import jaeger_band_temperature
from .moving_source import moving_source_temperature

__all__ = ["MovingSource", "Schedule", "pass_level", "pass_response", "upstream_reach"]

#: half-width of the Gaussian windows of the inner quadratures in units of s = 2 sqrt(kappa tau):
#: the tail beyond is erfc(6.5) ~ e^-42 / 11
_WINDOW = 6.5
#: emission left out where the Gaussian factor exp(-d^2/(4 kappa tau)) is below e^-_FAR
_FAR = 45.0
_SQRT_PI = math.sqrt(math.pi)



def check_source_geometry(source) -> None:
    """Raise ValueError unless ``source`` (a moving or fixed surface source) has a known ``kind`` ("band",
    "ellipse") and ``shape`` ("uniform", "hertz"), a finite ``half_width`` > 0 [m] and, for an ellipse,
    ``semi_axis_b`` > 0 [m]."""
    if source.kind not in ("band", "ellipse"):
        raise ValueError(f"kind must be 'band' or 'ellipse', got {source.kind!r}")
    if source.shape not in ("uniform", "hertz"):
        raise ValueError(f"shape must be 'uniform' or 'hertz', got {source.shape!r}")
    if not (source.half_width > 0 and math.isfinite(source.half_width)):
        raise ValueError(f"half_width must be a positive number [m], got {source.half_width!r}")
    if source.kind == "ellipse" and not (source.semi_axis_b is not None and source.semi_axis_b > 0):
        raise ValueError(f"an ellipse needs semi_axis_b > 0 [m], got {source.semi_axis_b!r}")

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
        check_source_geometry(self)
        if not (self.speed > 0 and math.isfinite(self.speed)):
            raise ValueError(f"speed must be a positive number [m/s], got {self.speed!r}")

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


@lru_cache(maxsize=32)
def _gl(nx):
    """Gauss-Legendre nodes and weights on [0, 1] (cached: the inner quadratures ask for the same few rules
    at every emission time)."""
    x, w = np.polynomial.legendre.leggauss(int(nx))
    x, w = (x + 1.0) / 2.0, w / 2.0
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


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

#: depth factors exp(-x) with x above this are below 1e-304: their nodes add nothing to a double sum
_UNDERFLOW = 700.0


@numba.njit(cache=True)
def _band_hertz_depth(xi, s, z, a, t, w, scale):  # pragma: no cover - compiled (checked against _band_hertz)
    """scale * _band_hertz(xi, s) * exp(-(z/s)^2) per node, compiled: the same window quadrature node by node,
    without the (nodes x points) temporaries; nodes whose window is empty or whose depth factor is below
    e^-_UNDERFLOW are exactly (or to 1e-304) zero and skipped."""
    out = np.zeros(xi.size)
    for i in range(xi.size):
        si = s[i]
        if si <= 0.0:
            continue
        x2 = (z[i] / si) ** 2
        if x2 > _UNDERFLOW:
            continue
        lo = min(max(xi[i] - _WINDOW * si, -a), a)
        hi = min(max(xi[i] + _WINDOW * si, -a), a)
        p1, p2 = math.acos(-lo / a), math.acos(-hi / a)
        if not p2 > p1:
            continue
        acc = 0.0
        for k in range(t.size):
            phi = p1 + (p2 - p1) * t[k]
            sp = math.sin(phi)
            r = (xi[i] + a * math.cos(phi)) / si
            acc += w[k] * (sp * sp * a * math.exp(-r * r))
        out[i] = scale * acc * (p2 - p1) / si * math.exp(-x2)
    return out


def _integrand_u(u, theta_e, z, src, kappa, nx):
    """rho c / q * (kernel integrated over the source) * dtau/du at tau = u^2, emission time theta_e, depth z
    (a number or one per u)."""
    s = 2.0 * math.sqrt(kappa) * u
    xi = src.half_width - src.speed * theta_e
    if src.kind == "band" and src.shape == "hertz":     # the transient scenes' source: compiled
        t, w = _gl(nx)
        return _band_hertz_depth(np.ascontiguousarray(xi, dtype=float).ravel(), s.ravel(),
                                 np.ascontiguousarray(np.broadcast_to(z, u.shape), dtype=float).ravel(),
                                 float(src.half_width), t, w, 2.0 / (math.pi * math.sqrt(kappa))).reshape(u.shape)
    out = np.zeros(u.shape)
    ok = s > 0
    if not np.any(ok):
        return out
    inner = _INNER[(src.kind, src.shape)](xi[ok], s[ok], src, nx)
    zz = np.broadcast_to(z, u.shape)[ok]
    with np.errstate(under="ignore"):
        depth = np.exp(-(zz / s[ok]) ** 2)
    if src.kind == "band":
        out[ok] = 2.0 / (math.pi * math.sqrt(kappa)) * inner * depth
    else:
        out[ok] = 2.0 / (math.pi ** 1.5 * math.sqrt(kappa)) * inner * depth
    return out


def upstream_reach(theta, src, kappa):
    """Time L before arrival beyond which emissions are negligible at observation time theta: at emission
    t' = -x the point is V x ahead of the leading edge and tau <= theta + x, V^2 x^2 / (4 kappa (theta + x))
    > _FAR for x > L."""
    v2 = src.speed ** 2
    c = 4.0 * kappa * _FAR
    th = max(theta, 0.0)
    return (c + math.sqrt(c * c + 4.0 * v2 * c * th)) / (2.0 * v2)


def _far(p, q, theta, z, src, kappa):
    """True (element-wise) when every emission in [p, q] (times after arrival) reaches the point with a Gaussian factor
    exp(-(d^2 + z^2)/(4 kappa tau)) < e^-_FAR: d the distance from the point to the nearest source edge,
    at least V (p - D) after departure or V (-q) before arrival, tau <= theta - p."""
    d = src.speed * np.maximum(np.maximum(p - src.contact_duration, -q), 0.0)
    return d * d + z * z > 4.0 * kappa * (theta - p) * _FAR


def _time_integral(theta, z, src, kappa, factor, start, breaks, n, nx, stop=math.inf):
    """int_{start}^{min(stop, theta)} factor(t') K(theta - t', t') dt' [K per (q/(rho c))], u = sqrt(theta - t'),
    at one observation time and depth (:func:`_time_integrals` for many)."""
    return float(_time_integrals(np.array([theta], float), np.array([z], float), src, kappa, factor, start, breaks,
                                 n, nx, stop)[0])


def _panels(theta, z, src, kappa, start, breaks, stop):
    """The time integral's panels [p, q] of emission times, shape (M, B + 1) each, per observation time and
    depth (M): between max(start, -upstream reach) and min(stop, theta), split at the factor's ``breaks``, the
    source's arrival (0) and departure (D) and theta - z^2/(4 kappa) (the depth's kernel peak); a panel that is
    empty or whose emissions are all too far from the point (:func:`_far`) has ``keep`` False."""
    v2 = src.speed ** 2
    c = 4.0 * kappa * _FAR
    reach = (c + np.sqrt(c * c + 4.0 * v2 * c * np.maximum(theta, 0.0))) / (2.0 * v2)   # upstream_reach
    lo = np.maximum(start, -reach)
    hi = np.minimum(stop, theta)
    d = src.contact_duration
    cand = np.column_stack([np.broadcast_to(np.asarray(b, float), theta.shape) for b in breaks]
                           + [np.zeros_like(theta), np.full_like(theta, d), theta - z * z / (4.0 * kappa)])
    inside = (cand > lo[:, None]) & (cand < hi[:, None])
    pts = np.sort(np.column_stack([lo, hi, np.where(inside, cand, hi[:, None])]), axis=1)
    p, q = pts[:, :-1], pts[:, 1:]
    far = _far(p, q, theta[:, None], z[:, None], src, kappa)
    keep = (q > p) & (lo < hi)[:, None] & ~far
    return p, q, keep


#: panels of the time integral evaluated together (each n-point graded rule x nx inner points)
_PANEL_CHUNK = 96
#: the graded rules' innermost panel at an end, relative to the panel: this fraction of the distance from that
#: end to the integrand's nearest singularity (:func:`_grading`), to a power of 10 below
_GRADE_MARGIN = 0.1


def _grading(u1, u2, src, kappa):
    """Exponents (toward u1, toward u2) of each panel's :func:`~._quadrature.graded_pair_rule` in u = sqrt(tau).

    The integrand is analytic in u on the panel except near u = 0 (tau -> 0: the kernel's point source,
    exp(-z^2/(4 kappa u^2)) and the source's sharp edges) and it varies on the scale sqrt(kappa)/V in u wherever
    the source's edges pass (the edge smoothed over s = 2 sqrt(kappa) u moves past in s/V of time, which is
    sqrt(kappa)/V in u at any u). So toward u1 the nearest singularity is min(u1, sqrt(kappa)/V) away, toward
    u2 sqrt(kappa)/V; each end is graded down to :data:`_GRADE_MARGIN` of that distance (relative to the panel,
    to 1e-16 at most: u1 = 0, a panel reaching the observation time, is graded fully)."""
    width = np.maximum(u2 - u1, np.finfo(float).tiny)
    h = math.sqrt(kappa) / src.speed if getattr(src, "speed", 0.0) > 0 else math.inf

    def exponent(distance):
        rel = np.clip(_GRADE_MARGIN * distance / width, 1e-16, 0.1)
        return np.floor(np.log10(rel)).astype(int)
    return exponent(np.minimum(u1, h)), exponent(np.full(u1.shape, h))


def _time_integrals(theta, z, src, kappa, factor, start, breaks, n, nx, stop=math.inf):
    """int_{start}^{min(stop, theta_i)} factor(t') K(theta_i - t', t') dt' at depth z_i [K per (q/(rho c))], for
    each observation time theta_i and depth z_i (arrays of one shape), u = sqrt(theta - t'): the panels of
    :func:`_panels`, each by a rule graded toward both ends in u (:func:`~._quadrature.graded_pair_rule`, as far
    as :func:`_grading` finds the integrand's singularities need it), all evaluated in chunks of
    :data:`_PANEL_CHUNK` panels.

    ``factor`` is a callable of the emission time relative to the pass's arrival (any array shape), zero outside
    [start, stop] and linear between ``breaks``, the times where it has kinks (a panel where it is zero at both
    ends is left out)."""
    theta = np.asarray(theta, dtype=float).ravel()
    z = np.broadcast_to(np.asarray(z, dtype=float).ravel(), theta.shape)
    out = np.zeros(theta.size)
    if theta.size == 0:
        return out
    p, q, keep = _panels(theta, z, src, kappa, start, breaks, stop)
    # the factor is linear on each panel (split at its kinks): zero at both ends, zero throughout
    keep &= (factor(p) != 0.0) | (factor(q) != 0.0)
    row, col = np.nonzero(keep)                      # row-major: each point's panels in increasing time
    u1, u2 = np.sqrt(theta[row] - q[row, col]), np.sqrt(theta[row] - p[row, col])
    low, high = _grading(u1, u2, src, kappa)
    sums = np.empty(row.size)
    for lo_e, hi_e in set(zip(low.tolist(), high.tolist())):
        t, w = graded_pair_rule(int(n), lo_e, hi_e)
        sel = np.flatnonzero((low == lo_e) & (high == hi_e))
        for c0 in range(0, sel.size, _PANEL_CHUNK):
            i = sel[c0:c0 + _PANEL_CHUNK]
            th = theta[row[i]][:, None]
            a, b = u1[i][:, None], u2[i][:, None]
            u = a + (b - a) * t[None, :]
            te = th - u * u
            vals = factor(te) * _integrand_u(u.ravel(), te.ravel(), np.repeat(z[row[i]], t.size), src, kappa,
                                             nx).reshape(u.shape)
            sums[i] = (b - a)[:, 0] * np.sum(vals * w, axis=1)   # row-wise: see jaeger._band_integral
    # summed per point in the panels' order (as a running sum over each point's panels)
    return out + np.bincount(row, weights=sums, minlength=theta.size)


# ------------------------------------------------------------------------------------------------
# one pass
# ------------------------------------------------------------------------------------------------
def _steady_sweep(theta, z, src, material):
    """Steady moving field at the point, T_steady(a - V theta, 0, z) [K] (source on for all times)."""
    x = src.half_width - src.speed * theta
    if src.kind == "band":
        return jaeger_band_temperature(x, z, src.half_width, src.speed, material, src.flux, src.shape)
    # 12 points per panel: <= 3e-7 of the maximum (8, the steady default: 2e-5)
    return moving_source_temperature(x, 0.0, z, (src.half_width, src.semi_axis_b), src.speed, material,
                                     src.flux, src.shape, quad_points=12)


def _split(schedule, via_time_integral):
    """(constant factor held from t = -inf, schedule whose time integral is added or None, subtract it)."""
    if schedule is None:
        return 1.0, None, 0.0
    if schedule.is_constant:
        return schedule.factor[0], None, 0.0
    if via_time_integral:
        return 0.0, schedule, 0.0
    return schedule.factor[0], schedule, schedule.factor[0]


def pass_level(schedule: Schedule, arrival: float, held: float, via_time_integral: bool = False) -> float:
    """The factor [1] whose steady sweep a pass arriving at ``arrival`` [s] takes as its constant part: the
    schedule's value at the arrival (``held``, the factor held from t = -inf, with ``via_time_integral``).

    The rise is linear in the factor, so level * (steady sweep) + the time integral of f - level is the same
    rise for any level; taking the factor at the arrival leaves the time integral only the schedule's
    departures from it, and none for a pass the schedule holds constant while the source is near the point
    (its panels are then zero or too far, :func:`_time_integrals`)."""
    if via_time_integral:
        return held
    return float(schedule(arrival))


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
    th, zz = np.meshgrid(theta, depth, indexing="ij")
    return scale * _time_integrals(th.ravel(), zz.ravel(), source, kappa, one, -math.inf, (), quad_points,
                                   inner_points).reshape(out.shape)


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
    scale = source.flux * kappa / lam
    th, zz = np.meshgrid(theta, depth, indexing="ij")
    return scale * _time_integrals(th.ravel(), zz.ravel(), source, kappa, factor, start, breaks, quad_points,
                                   inner_points, stop).reshape(th.shape)


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
    if sched is not None:
        const = minus = pass_level(sched, arrival, minus, via_time_integral)
    out = np.zeros((theta.size, depth.size))
    if const != 0.0:
        out += const * _constant_part(theta, depth, source, material, via_time_integral, quad_points,
                                      inner_points)
    if sched is not None:
        out += _schedule_part(theta, depth, source, material, sched, minus, arrival, quad_points, inner_points)
    return out
