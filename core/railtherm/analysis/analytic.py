"""Analytic reference of a scene: what core knows exactly, evaluated for comparison with a result.

* contact (Hertz): semi-axes, peak pressure, normal force, pressure field (exact for elastic
  half-spaces; the FEM's strip of finite depth is compared with it as the paper does);
* 2-D rolling with longitudinal creepage, identical bodies: Carter's creep force;
* temperatures of a full-sliding or given heat source without convection: the exact moving source
  (3-D half-space, :mod:`railtherm.references.moving_source`) or Jaeger's band (2-D,
  :mod:`railtherm.references.jaeger`), at any Péclet number, for each body with its share of the heat
  and its own speed;
* the thermal trace of a scene with ``field`` (same sources): the exact peak temperature, cooling
  rate and time above ``field.threshold`` of a material point on the centre line at each depth, and
  the heated depth (:func:`trace_reference`), from the same references evaluated at depth.

Values are cached per scene hash (the reference does not depend on the method or level), the
temperatures per body source (:func:`_body_key`), which scenes with the same source share.
"""
from __future__ import annotations

import math

import numpy as np

from ..contract.errors import Refused
from ..models.hertz import hertz_geometry
from ..physics import body_speeds, scene_partition
from ..references.carter import carter_2d

_NAME = {"contact": "Hertz (elliptic integrals)", "carter": "Carter 2-D rolling",
         "ms": "moving surface source on a half-space (point-source superposition)",
         "jaeger": "Jaeger moving band source (K0 kernel)",
         "sliding": "full sliding: F = mu N, P = mu N v_s (exact)",
         "given": "given heat source: P = integral of the flux (exact)"}
#: short tag of each reference, as stored in metrics.nc (``analytic:<tag>``)
TAG = {"contact": "hertz", "carter": "carter", "ms": "moving-source", "jaeger": "jaeger",
       "sliding": "full-sliding", "given": "given-source"}


# whole scene: the analysis's one reading of the scene's nine Hertz inputs (bodies, shape, load, geometry, name)
def scene_hertz_geometry(scene):
    """:func:`railtherm.models.hertz.hertz_geometry` of a scene's contact: (a [m], b [m] or None, p0 [Pa], normal
    force [N or N/m]); the analysis's one reading of the Hertz inputs off a scene."""
    return hertz_geometry(scene.wheel, scene.rail, scene.contact_shape, scene.normal_force,
                          penetration=scene.penetration, semi_axes=scene.semi_axes, curvatures=scene.curvatures,
                          wheel_radius=scene.wheel_radius, scene_name=scene.name)


# whole scene: the closed-form heat source of a scene, read from its source, friction, kinematics and contact
def _thermal_case(scene):
    """(a, b, shape, peak flux, (v_wheel, v_rail), eps) of the scene's heat source, or None (no closed form:
    convection, or a heat partition that depends on the temperatures)."""
    if scene.convection > 0 or scene.partition.needs_temperatures:
        return None
    if scene.heat_source is not None:
        hs = scene.heat_source
        a, b = hs.semi_axes if hs.semi_axes is not None else (hs.half_width, None)
        speeds = body_speeds(scene.speed, scene.sliding_speed, scene.tangential)
        return a, b, hs.shape, hs.flux, speeds, scene_partition(scene.partition, scene.wheel, scene.rail, *speeds,
                                                                scene_name=scene.name)
    mu = uniform_friction(scene.friction, scene.tangential, scene.sliding_speed)
    if scene.tangential != "full-sliding" or mu is None:
        return None
    a, b, p0, _ = scene_hertz_geometry(scene)
    speeds = body_speeds(scene.speed, scene.sliding_speed, scene.tangential)
    return a, b, "hertz", mu * abs(scene.sliding_speed) * p0, speeds, scene_partition(scene.partition, scene.wheel,
                                                                                 scene.rail, *speeds,
                                                                                 scene_name=scene.name)


def uniform_friction(friction, tangential: str, sliding_speed: float | None) -> float | None:
    """The coefficient of friction [1] when it is one number over the whole patch, so that the closed-form
    references hold: a constant law; a slip-velocity law in full sliding (every cell slips at |v_s|: mu(|v_s|));
    None for a temperature law (mu varies with the cell's temperature: no closed form).

    Parameters
    ----------
    friction : FrictionLaw or None
        The scene's friction law.
    tangential : str
        The scene's tangential regime: "full-sliding", "creepage" or "given".
    sliding_speed : float or None
        The full sliding speed [m/s] (None when rolling with creepage).
    """
    if friction is None or friction.depends_on_temperature:
        return None
    if friction.depends_on_slip:
        return float(friction.mu(abs(sliding_speed))) if tangential == "full-sliding" else None
    return float(friction.nominal)


def _surface_rise(mat, case, x, y, body):
    """Exact surface rise [K] of body ``body`` (0 wheel, 1 rail; material ``mat``) at the points (x, y) [m]
    (y None: a line contact) under the heat source ``case`` (:func:`_thermal_case`)."""
    a, b, shape, q, speeds, eps = case
    share = eps if body == 0 else 1.0 - eps
    if share == 0.0 or q == 0.0:
        return np.zeros(np.broadcast(x, y if y is not None else x).shape)
    # the exact temperatures import on first use: they load scipy and numba (about 1.3 s), which the callers
    # that read only a scene's Hertz geometry or thermal case (reference curves, trace metrics) never need
    if b is None:
        from ..references.jaeger import jaeger_band_temperature  # scipy, as above
        return jaeger_band_temperature(x, np.zeros_like(x), a, speeds[body], mat, share * q, shape)
    from ..references.moving_source import moving_source_temperature  # numba, as above
    return moving_source_temperature(x, y, np.zeros_like(x), (a, b), speeds[body], mat, share * q, shape)


def _depth_rise(mat, case, x, z, body):
    """Exact rise [K] at y = 0, depth z, of body ``body`` of material ``mat`` (x, z broadcast)."""
    a, b, shape, q, speeds, eps = case
    share = eps if body == 0 else 1.0 - eps
    x, z = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
    if share == 0.0 or q == 0.0:
        return np.zeros(x.shape)
    if b is None:
        from ..references.jaeger import jaeger_band_temperature  # scipy: on first use, as in _surface_rise
        return jaeger_band_temperature(x, z, a, speeds[body], mat, share * q, shape)
    from ..references.moving_source import moving_source_temperature  # numba: on first use, as in _surface_rise
    return moving_source_temperature(x, np.zeros_like(x), z, (a, b), speeds[body], mat, share * q, shape,
                                     quad_points=12)


#: samples of the peak bracket and of the cooling-rate spline: (fast, slow) paths of :func:`_line_trace`
_BRACKET_SAMPLES = {True: 41, False: 121}
_COOLING_SAMPLES = {True: 41, False: 241}
#: samples of the fast path's local spline around the fastest cooling (over 4 coarse intervals)
_COOLING_LOCAL_SAMPLES = 41


def _line_trace(f, a: float, v: float, thr: float, z: float, surface_kink: bool, fast: bool = True,
                peak_only: bool = False):
    """Exact (peak, x_peak, cooling rate, time above, x of the fastest cooling) of the profile T(x) = f(x)
    [degC] at one depth.

    The peak is bracketed on samples reaching ever further behind the patch (x from +a down to
    -a - L, L doubling from 6a; 41 samples, 121 on the slow path) and refined by a bounded scalar search;
    the cooling rate is the maximum of V dT/dx behind the peak from a cubic spline through samples of
    [x_peak - span, x_peak] (slow path: 241 samples, the spline's maximum refined by a bounded search; fast
    path: 41 samples locate the maximum, a second spline through 41 samples of the 4 intervals around it,
    1.7x finer than the slow path's, gives it); the crossings of the threshold by Brent's method. At the
    surface (``surface_kink``) the exact cooling rate is infinite (the flux ends at the trailing edge): NaN.
    ``peak_only``: (peak, x_peak, NaN, NaN, NaN) without the cooling rate and the crossings.
    """
    # scipy's spline and root finders (about 1 s to import) load with the first exact trace
    from scipy.interpolate import CubicSpline
    from scipy.optimize import brentq, minimize_scalar
    length = 6.0 * a
    nb = _BRACKET_SAMPLES[bool(fast)]
    unit = np.linspace(0.0, 1.0, nb)
    xs = a - length * unit
    ts = f(xs)
    for _ in range(13):
        i = int(np.argmax(ts))
        if i < xs.size - 1 and ts[-1] < thr:
            break
        # doubling the reach with as many (odd) samples: the first half of the new samples are every
        # other old one, whose values are kept
        length *= 2.0
        half = (nb - 1) // 2
        far = a - length * unit[half + 1:]
        xs, ts = np.concatenate([xs[::2], far]), np.concatenate([ts[::2], f(far)])
    i = int(np.argmax(ts))
    if i == 0:
        i = 1
    lo, hi = xs[min(i + 1, xs.size - 1)], xs[i - 1]
    res = minimize_scalar(lambda t: -float(f(np.array([t]))[0]), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-9 * a})
    xp, tp = (float(res.x), -float(res.fun)) if -res.fun >= ts[i] else (float(xs[i]), float(ts[i]))
    if peak_only:
        return tp, xp, math.nan, math.nan, math.nan
    # cooling: V dT/dx behind the peak, on [xp - span, xp]
    cool = x_cool = math.nan
    if not surface_kink:
        span = max(2.0 * (a - xp), 4.0 * a)
        nc = _COOLING_SAMPLES[bool(fast)]
        for _ in range(6):
            xc = np.linspace(xp - span, xp, nc)
            spl = CubicSpline(xc, f(xc))
            d = spl(xc, 1)
            j = int(np.argmax(d))
            if j > 0:
                break
            span *= 2.0
        if fast and j > 0:
            xc = np.linspace(xc[max(j - 2, 0)], xc[min(j + 2, xc.size - 1)], _COOLING_LOCAL_SAMPLES)
            spl = CubicSpline(xc, f(xc))
            d = spl(xc, 1)
            j = int(np.argmax(d))
        lo, hi = xc[max(j - 1, 0)], xc[min(j + 1, xc.size - 1)]
        r2 = minimize_scalar(lambda t: -float(spl(t, 1)), bounds=(lo, hi), method="bounded",
                             options={"xatol": 1e-9 * a})
        cool = v * max(float(d[j]), -float(r2.fun))
        x_cool = float(r2.x) if -float(r2.fun) >= float(d[j]) else float(xc[j])
    above = 0.0
    if tp > thr:
        g = lambda t: float(f(np.array([t]))[0]) - thr
        front = xs[:i + 1][ts[:i + 1] <= thr]
        x_front = a if front.size == 0 else brentq(g, front[-1], xp, xtol=1e-12 * a)  # ahead of the peak
        k = i + int(np.flatnonzero(ts[i:] <= thr)[0])
        x_back = brentq(g, xs[k], xs[k - 1] if k - 1 > i else xp, xtol=1e-12 * a)
        above = (x_front - x_back) / v
    return tp, xp, cool, above, x_cool


def _heated_depth(peak, a: float) -> float:
    """Root [m] of ``peak(z) = 0`` (the peak temperature minus the threshold, falling with depth), Brent.

    0 when the surface peak is not above the threshold; otherwise Brent on [0, 0.05 a], the upper end
    doubling until it brackets. The search does not depend on the depths a run asked for, so every run of
    a scene gets the same heated depth and it is computed once per scene (:func:`trace_reference`).
    """
    from scipy.optimize import brentq  # about 1 s to import: with the first heated depth
    if peak(0.0) <= 0.0:
        return 0.0
    hi = 0.05 * a
    while peak(hi) > 0.0 and hi < 1e3 * a:
        hi *= 2.0
    return brentq(peak, 0.0 if hi == 0.05 * a else 0.5 * hi, hi, xtol=1e-9 * a)


#: exact trace values already computed, per (body source, bulk, threshold, fast path): depth -> the tuple
#: of :func:`_line_trace`, and the heated depth; the runs of one scene ask for many of the same depths
#: (a method's levels, methods on one grid), and a depth's values do not depend on the others asked with it
_LINE_CACHE: dict = {}
_DEPTH_CACHE: dict = {}
#: (maximum, mean) of the exact surface rise [K] per body source (:func:`_surface_scalars`)
_SCALAR_CACHE: dict = {}
#: scenes kept in the caches above before they are cleared
_CACHED_SCENES = 64


def _cache_for(store: dict, key):
    if key not in store and len(store) >= _CACHED_SCENES:
        store.clear()
    return store.setdefault(key, {})


def clear_trace_caches() -> None:
    """Forget every exact trace and surface value computed so far (benchmarks time a cold computation)."""
    for store in (_LINE_CACHE, _DEPTH_CACHE, _SURFACE_CACHE, _SCALAR_CACHE):
        store.clear()


def _body_key(mat, case, body: int) -> tuple:
    """Everything the exact rise of body ``body`` (material ``mat``) depends on: (a, b, shape, its heat flux [W/m^2], its speed
    [m/s], conductivity [W/(m K)], diffusivity [m^2/s]). Scenes that differ elsewhere (name, load, friction
    law, methods, outputs) but heat a body alike share its exact temperatures; the values are the same
    whichever scene computed them (the same arguments reach the same references)."""
    from ..references.flash import thermal_properties  # loads scipy.integrate and .optimize: on first use
    a, b, shape, q, speeds, eps = case
    share = eps if body == 0 else 1.0 - eps
    return (a, b, shape, share * q, float(speeds[body])) + thermal_properties(mat)


# whole scene: the trace of a scene for the reference curves and the tests: its source, materials and field
def trace_reference(scene, z, fast: bool = True) -> dict | None:
    """:func:`exact_trace` of a scene: its closed-form source (:func:`_thermal_case`), its bodies and its
    ``field.threshold`` [degC] (727 without a field); None when the scene has no exact source reference."""
    fld = getattr(scene, "field", None)
    thr = float(fld.threshold) if fld is not None else 727.0
    return exact_trace(_thermal_case(scene), scene.wheel, scene.rail, thr, z, fast)


def exact_trace(case, wheel, rail, threshold: float, z, fast: bool = True) -> dict | None:
    """Exact thermal trace of a given or full-sliding source (no convection).

    Parameters
    ----------
    case : tuple or None
        The scene's closed-form heat source (:func:`_thermal_case`); None: no exact reference.
    wheel, rail : Material
        The bodies (bulk temperature [degC], conductivity, diffusivity).
    threshold : float
        The temperature [degC] whose crossings give the time above and the heated depth.
    z : array_like
        Depths [m] at which the profiles are wanted.
    fast : bool
        The sampling of :func:`_line_trace` (41 bracket samples, a coarse and a local cooling spline)
        rather than the slow path's (121 and 241 samples) for every line trace, the heated depth's peaks
        included. tests/test_thermal_trace.py compares the two.

    Returns
    -------
    dict or None
        ``peak_temperature`` [degC], ``peak_position`` [m], ``cooling_rate`` [K s-1], ``cooling_position``
        (x of the fastest cooling) [m], ``time_above`` [s],
        each of shape (2, nz) (cooling rate NaN at z = 0, where it is infinite: the flux ends at the
        trailing edge), ``heated_depth`` (2,) [m] (the root of peak(z) = threshold, Brent), and ``tag``
        (``"moving-source"`` or ``"jaeger"``). None when the scene has no exact source reference.

    Notes
    -----
    The profiles T(x) at each depth come from :func:`railtherm.references.moving_source.moving_source_temperature`
    (point-source superposition, 12 Gauss points per panel: <= 3e-7 of the maximum) on y = 0, or
    :func:`railtherm.references.jaeger.jaeger_band_temperature` for a line contact, with each body's share
    of the heat and its own speed; the search reaches as far behind the patch as the peak lies, whatever
    the field's extent.
    """
    if case is None:
        return None
    z = np.atleast_1d(np.asarray(z, dtype=float))
    a, b, shape, q, speeds, eps = case
    thr = float(threshold)
    out = {k: np.full((2, z.size), np.nan) for k in ("peak_temperature", "peak_position", "cooling_rate",
                                                    "cooling_position", "time_above")}
    depth = np.full(2, np.nan)
    for body, mat in enumerate((wheel, rail)):
        bulk = float(mat.bulk_temperature)
        v = float(speeds[body])
        share = eps if body == 0 else 1.0 - eps
        if share == 0.0 or q == 0.0:
            out["peak_temperature"][body] = bulk
            out["cooling_rate"][body] = 0.0
            out["time_above"][body] = 0.0 if bulk <= thr else math.inf
            depth[body] = 0.0 if bulk <= thr else math.inf
            continue
        key = (_body_key(mat, case, body), bulk, thr, bool(fast))
        lines = _cache_for(_LINE_CACHE, key)
        for k, zk in enumerate(z):
            zk = float(zk)
            if zk not in lines:
                f = lambda xx, zk=zk: bulk + _depth_rise(mat, case, xx, zk, body)
                lines[zk] = _line_trace(f, a, v, thr, zk, zk == 0.0, fast)
            tp, xp, cool, above, xc = lines[zk]
            out["peak_temperature"][body, k], out["peak_position"][body, k] = tp, xp
            out["cooling_position"][body, k] = xc
            out["cooling_rate"][body, k], out["time_above"][body, k] = cool, above
        depths = _cache_for(_DEPTH_CACHE, key)
        if "heated" not in depths:
            peak = lambda zz: _line_trace(lambda xx: bulk + _depth_rise(mat, case, xx, zz, body), a, v, thr,
                                          zz, True, fast, peak_only=True)[0] - thr
            depths["heated"] = _heated_depth(peak, a)
        depth[body] = depths["heated"]
    out["heated_depth"] = depth
    out["tag"] = "jaeger" if b is None else "moving-source"
    return out


_CACHE: dict[str, dict] = {}


def _contact_scalars(geometry, friction, tangential: str, kinematics, wheel, rail, wheel_radius: float,
                     out: dict) -> None:
    """Put the Hertz patch and, where exact, the creep force and frictional power (full sliding, Carter) of a
    scene without a given heat source into ``out`` with their tags in ``out["_sources"]``.

    Parameters
    ----------
    geometry : (float, float or None, float, float)
        The scene's Hertz geometry (:func:`scene_hertz_geometry`): a [m], b [m] (None: a line contact), peak
        pressure [Pa], normal force [N or N/m].
    friction : FrictionLaw or None
        The scene's friction law.
    tangential : str
        "full-sliding" or "creepage".
    kinematics : Kinematics
        The scene's sliding speed [m/s] and creepages.
    wheel, rail : Material
        The bodies (Carter's theory needs them elastically identical).
    wheel_radius : float
        The wheel's rolling radius [m] (Carter's cylinder).
    """
    a, b, p0, n = geometry
    src = out["_sources"]
    out.update(semi_axis_a=a, max_pressure=p0, normal_force=n)
    src.update(semi_axis_a="hertz", max_pressure="hertz", normal_force="hertz", pressure="hertz")
    if b is not None:
        out["semi_axis_b"] = b
        src["semi_axis_b"] = "hertz"
    out["_names"].append(_NAME["contact"])
    sliding_speed, creepage = kinematics.sliding_speed, kinematics.creepage
    mu = uniform_friction(friction, tangential, sliding_speed)
    if tangential == "full-sliding" and mu is not None:
        out["frictional_power"] = mu * abs(sliding_speed) * n
        out["creep_force_x"] = math.copysign(mu * n, sliding_speed) if sliding_speed else 0.0
        src.update(frictional_power="full-sliding", creep_force_x="full-sliding")
        out["_names"].append(_NAME["sliding"])
    elif (b is None and creepage is not None and creepage.lateral == 0 and creepage.spin == 0
          and _identical_elastic(wheel, rail) and friction.nominal > 0 and friction.kind == "constant"):
        c = carter_2d(creepage.longitudinal, a, friction.nominal, wheel_radius)
        out["creep_force_x"] = c.force_ratio * friction.nominal * n
        src["creep_force_x"] = "carter"
        out["_names"].append(_NAME["carter"])


def _source_scalars(case, heat_source, wheel, rail, field, out: dict) -> None:
    """Put the exact temperatures (maximum and patch mean per body), the heat partition, a given source's
    frictional power and, with a ``field``, the heated depth of the closed-form source ``case``
    (:func:`_thermal_case`) into ``out`` with their tags in ``out["_sources"]``; ``heat_source`` is the scene's
    given source (None: frictional heat), ``wheel``, ``rail`` the bodies."""
    src = out["_sources"]
    a, b, shape, q, speeds, eps = case
    out["heat_partition"] = eps
    if heat_source is not None:
        from ..physics import exact_total  # the given source's total: only for a scene with one
        out["frictional_power"] = q * exact_total(shape, a, b)
        src["frictional_power"] = "given-source"
    peaks = [_surface_scalars(mat, case, body) for body, mat in enumerate((wheel, rail))]
    out["max_surface_temperature"] = np.array([p[0] for p in peaks])
    out["mean_contact_temperature"] = np.array([p[1] for p in peaks])
    tag = "jaeger" if b is None else "moving-source"
    src.update(max_surface_temperature=tag, mean_contact_temperature=tag, surface_temperature=tag,
               heat_partition=tag)
    out["_names"].append(_NAME["jaeger" if b is None else "ms"])
    if field is not None:
        tr = exact_trace(case, wheel, rail, float(field.threshold), [0.0])
        out["heated_depth"] = tr["heated_depth"]
        src.update(heated_depth=tag, peak_temperature=tag, cooling_rate=tag, time_above=tag)


def _surface_scalars(mat, case, body: int) -> tuple[float, float]:
    """(maximum, mean over the patch) of the exact surface temperature [degC] of ``body`` of material ``mat``
    (the rises cached per body source, :func:`_body_key`)."""
    bulk = mat.bulk_temperature
    rises = _cache_for(_SCALAR_CACHE, _body_key(mat, case, body))
    if "rises" not in rises:
        rises["rises"] = _surface_rises(mat, case, body)
    top, mean = rises["rises"]
    return bulk + top, bulk + mean


def _surface_rises(mat, case, body: int) -> tuple[float, float]:
    """(maximum, mean over the patch) of the exact surface rise [K] of ``body`` (material ``mat``): the maximum on y = 0
    (symmetric sources) from 161 samples refined by a bounded search, the mean by Gauss-Legendre in x
    (and across y on the chord for an ellipse)."""
    from scipy.optimize import minimize_scalar  # about 1 s to import: with the first exact surface rise
    a, b = case[0], case[1]
    xs = np.linspace(-1.0, 1.0, 161) * a
    f = lambda xx: _surface_rise(mat, case, np.atleast_1d(xx), None if b is None else np.zeros(1), body)
    vals = f(xs) if b is None else _surface_rise(mat, case, xs, np.zeros_like(xs), body)
    i = int(np.argmax(vals))
    lo, hi = xs[max(i - 1, 0)], xs[min(i + 1, xs.size - 1)]
    res = minimize_scalar(lambda t: -float(f(t)[0]), bounds=(lo, hi), method="bounded", options={"xatol": 1e-6 * a})
    tmax = max(float(vals[i]), -float(res.fun))
    if b is None:
        gx, wx = np.polynomial.legendre.leggauss(64)
        return tmax, 0.5 * float(np.sum(wx * f(gx * a)))
    gs, ws = np.polynomial.legendre.leggauss(24)
    gx, wx = np.polynomial.legendre.leggauss(40)
    X = a * gx[:, None] * np.ones_like(gs)[None, :]
    chord = np.sqrt(1.0 - gx ** 2)[:, None]
    Y = b * chord * gs[None, :]
    W = wx[:, None] * ws[None, :] * chord
    T = _surface_rise(mat, case, X.ravel(), Y.ravel(), body).reshape(X.shape)
    return tmax, float(np.sum(W * T) / np.sum(W))


def _identical_elastic(wheel, rail) -> bool:
    """Two elastic bodies with the same elastic constants (quasi-identical): Carter's theory needs them, and
    so does a creep force that is zero by symmetry (:func:`railtherm.analysis.verdicts.zero_by_symmetry`)."""
    return (not wheel.rigid and not rail.rigid and wheel.shear_modulus == rail.shear_modulus
            and wheel.poisson_ratio == rail.poisson_ratio)


# whole scene: the analysis's entry: a scene's exact values read its contact, friction, kinematics, source and field
def reference_values(scene) -> dict:
    """Scalar references of ``scene``: name -> float or (2,) array [SI, temperatures in degC].

    Also ``"_names"`` (list of str: the references used, in words) and ``"_sources"`` (quantity ->
    short tag of its reference, e.g. ``"hertz"``, ``"carter"``, ``"moving-source"``; fields
    ``pressure`` and ``surface_temperature`` included). Cached by scene hash (a Scene holds dicts and is
    not hashable).
    """
    key = scene.hash
    if key not in _CACHE:
        if len(_CACHE) > 512:
            _CACHE.clear()
        found: dict = {"_names": [], "_sources": {}}
        # the contact's load of a wheelset without given motion comes from its equilibrium (normal model
        # "wheelset"), not from the scene's nominal load; a non-Hertzian gap has no closed-form contact: no
        # exact reference downstream of them, nor of a contact Hertz refuses
        exact = not ((getattr(scene, "wheelset", None) is not None and scene.creepage is None
                      and scene.sliding_speed is None) or scene.contact_shape == "gap")
        if exact and scene.heat_source is None:
            try:
                geometry = scene_hertz_geometry(scene)
            except Refused:
                exact = False
            else:
                _contact_scalars(geometry, scene.friction, scene.tangential, scene.kinematics, scene.wheel,
                                 scene.rail, scene.wheel_radius, found)
        case = _thermal_case(scene) if exact else None
        if case is not None:
            _source_scalars(case, scene.heat_source, scene.wheel, scene.rail, getattr(scene, "field", None), found)
        _CACHE[key] = found
    out = dict(_CACHE[key])
    out["_names"] = list(out.get("_names", []))
    out["_sources"] = dict(out.get("_sources", {}))
    return out


#: exact surface rises already computed, per body source (:func:`_body_key`): (x, y) -> rise [K]; the runs
#: of one scene share many grid points (a method's nested levels, methods on one grid), each point is evaluated once
_SURFACE_CACHE: dict = {}


def _cached_surface_rise(mat, case, x: np.ndarray, y: np.ndarray | None, body: int) -> np.ndarray:
    """:func:`_surface_rise` at the points (x, y) [m] (y None: a line contact), the points not seen before for
    this body source evaluated in one call."""
    known = _cache_for(_SURFACE_CACHE, _body_key(mat, case, body))
    keys = list(zip(x.tolist(), (y if y is not None else np.zeros_like(x)).tolist()))
    new = [i for i, k in enumerate(keys) if k not in known]
    if new:
        idx = np.array(new)
        vals = np.asarray(_surface_rise(mat, case, x[idx], None if y is None else y[idx], body), float)
        known.update(zip((keys[i] for i in new), np.broadcast_to(vals, idx.shape).tolist()))
    return np.array([known[k] for k in keys], float)


# whole scene: the analysis's entry for fields: the scene's Hertz inputs, closed-form source, bodies and field
def reference_fields(scene, ds) -> dict:
    """Field references on the grid of result ``ds``: pressure [Pa], surface_temperature [degC]."""
    out = {}
    line = "y" not in ds.dims
    x = ds["x"].values
    y = None if line else ds["y"].values
    if "pressure" in ds and scene.heat_source is None:
        try:
            from ..references.hertz import hertz_pressure  # scipy.optimize: with the first pressure field
            a, b, p0, _ = scene_hertz_geometry(scene)
            if line:
                out["pressure"] = hertz_pressure(x, None, a, None, p0)
            else:
                X, Y = np.meshgrid(x, y, indexing="ij")
                out["pressure"] = hertz_pressure(X, Y, a, b, p0)
        except Refused:
            pass
    case = _thermal_case(scene)
    if case is not None and "surface_temperature" in ds:
        if line:
            X, Y = x, None
        else:
            X, Y = np.meshgrid(x, y, indexing="ij")
        fields = []
        for body, mat in enumerate((scene.wheel, scene.rail)):
            r = _cached_surface_rise(mat, case, X.ravel(), None if Y is None else Y.ravel(), body)
            fields.append(mat.bulk_temperature + r.reshape(np.shape(X)))
        out["surface_temperature"] = np.stack(fields)
    want = [k for k in ("peak_temperature", "cooling_rate", "time_above") if k in ds]
    if case is not None and want and "z" in ds.coords and getattr(scene, "field", None) is not None:
        tr = exact_trace(case, scene.wheel, scene.rail, float(scene.field.threshold), ds["z"].values)
        out.update({k: tr[k] for k in want})
        out["trace_peak_position"], out["trace_cooling_position"] = tr["peak_position"], tr["cooling_position"]
    return out
