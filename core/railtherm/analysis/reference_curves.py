"""Reference curves of a study's scenes: the exact solutions a report draws beside the methods' results.

:func:`reference_curves` evaluates, for every scene that has one, core's exact references as curves (the report
overlays them; it never computes physics itself): the surface temperature along y = 0 of each body and its depth
profile (Jaeger's moving band for a line contact, the moving surface source on a half-space for an ellipse); for a
scene with ``field``, the exact thermal trace (:func:`railtherm.analysis.analytic.trace_reference`); Carter's 2-D
traction and creep curve for a line contact; and the initial slope of Kalker's linear theory for an ellipse.
:func:`write_reference_curves` writes them to ``out/references.nc`` (one netCDF4 group per scene, written to a
temporary file and renamed into place); :func:`read_reference_curves` reads the file back.

References
----------
.. [1] J.C. Jaeger, Proc. R. Soc. N.S.W. 76 (1942) 203-224 (moving band source).
.. [2] F.W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157. doi:10.1098/rspa.1926.0100
.. [3] J.J. Kalker, Three-dimensional elastic bodies in rolling contact, Kluwer, 1990. doi:10.1007/978-94-015-7889-9
"""
from __future__ import annotations

import builtins

import math
import re
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from ..contract.errors import Refused
from ..input.study import base_name
from ..output import store
from ..references.carter import carter_2d
from ..references.kalker import kalker_linear_forces
from .analytic import (_depth_rise, _identical_elastic, _surface_rise, _thermal_case, scene_hertz_geometry,
                       trace_reference)
from .trace_metrics import cooling_rate_depth
from .transient_curves import transient_history_curves

__all__ = ["reference_curves", "write_reference_curves", "read_reference_curves", "FILE_NAME"]

#: file written by :func:`write_reference_curves` in the study output folder
FILE_NAME = store.REFERENCES

NAME_JAEGER = "Jaeger moving band source (K0 kernel)"
NAME_MOVING_SOURCE = "moving surface source on a half-space (point-source superposition)"
NAME_CARTER = "Carter 2-D rolling (exact, identical elastic bodies)"
NAME_KALKER = "Kalker linear theory (initial slope, no saturation)"

_TEMPERATURE = {"units": "degC", "units_metadata": "temperature: on_scale"}
SURFACE_POINTS_LINE = 161
SURFACE_POINTS_ELLIPSE = 81
DEPTH_POINTS = 41
#: depths of the exact trace (each costs one peak search per body, ~0.1-0.5 s) and the map's points
TRACE_POINTS = 13
MAP_POINTS = (61, 31)
CREEP_POINTS = 301


def _surface_x(a: float, behind: float, n: int) -> np.ndarray:
    """Chebyshev-spaced x from -a - behind to +a (dense at the ends, where the field has square-root edges)."""
    lo, hi = -a - behind, a
    return 0.5 * (lo + hi) - 0.5 * (hi - lo) * np.cos(np.linspace(0.0, np.pi, n))


def _behind(fld) -> float:
    """How far [m] the scene's ``field`` reaches behind the patch (0 without one)."""
    behind = getattr(fld, "behind", None) if fld is not None else None
    if behind is None and isinstance(fld, dict):
        behind = fld.get("behind")
    return float(behind) if behind else 0.0


def _field_depth(fld, default: float) -> float:
    """The depth [m] a scene's ``field`` asks for, else ``default``."""
    depth = getattr(fld, "depth", None) if fld is not None else None
    return float(depth) if depth else default


def _heated_at_rest(case) -> list[bool]:
    """Per body (wheel, rail) of the thermal case (:func:`railtherm.analysis.analytic._thermal_case`): heated
    while its surface is at rest under the contact (a locked wheel: V + v_s = 0). Such a body has no steady
    moving field (a source at rest heated since t = -inf raises a band without bound), so it has none of the
    steady curves; any() of it is True when a scene has such a body."""
    a, b, shape, q, speeds, eps = case
    return [bool(q != 0 and share != 0 and not speeds[i] > 0) for i, share in enumerate((eps, 1.0 - eps))]


def _trace(scene) -> tuple[dict, dict, list[str]]:
    """The exact thermal trace of a scene with ``field`` (see :func:`reference_curves`)."""
    fld = getattr(scene, "field", None)
    case = _thermal_case(scene) if fld is not None else None
    if case is None:
        return {}, {}, []
    a, b, shape, q, speeds, eps = case
    if any(_heated_at_rest(case)):
        # the trace is the steady moving field's, which a body at rest under its heat (a locked wheel's spot)
        # does not have; its history's exact reference is scored in metrics.nc (references.transient_spot)
        return {}, {}, []
    kappa = max(scene.body(i).diffusivity for i in (0, 1))
    depth = _field_depth(fld, 4.0 * min(a, math.sqrt(2.0 * kappa * a / max(min(speeds), 1e-12))))
    zt = depth * np.linspace(0.0, 1.0, TRACE_POINTS) ** 2
    tr = trace_reference(scene, zt)
    name = NAME_JAEGER if b is None else NAME_MOVING_SOURCE
    bulk = np.array([scene.body(i).bulk_temperature for i in (0, 1)], float)
    peak = np.asarray(tr["peak_temperature"], float)
    hot = int(np.nanargmax(peak[:, 0] - bulk))
    zh = float(tr["heated_depth"][hot])
    if not (0.0 < zh < depth):   # no isotherm inside the field: where the peak has fallen to half its rise
        half = bulk[hot] + 0.5 * (peak[hot, 0] - bulk[hot])
        below = np.flatnonzero(peak[hot] <= half)
        zh = float(np.interp(half, peak[hot, ::-1], zt[::-1])) if below.size else float(zt[-1])
    star = trace_reference(scene, [zh])
    x = _surface_x(a, _behind(fld), SURFACE_POINTS_LINE if b is None else SURFACE_POINTS_ELLIPSE)
    at_depth = np.array([bulk[i] + np.asarray(_depth_rise(scene.body(i), case, x, zh, i), float) for i in (0, 1)])
    zattrs = {"units": "m", "long_name": "depth of the exact trace", "positive": "down"}
    ref = {"reference": name}
    data = {
        "trace_peak_temperature": (("body", "z_trace"), peak, {**_TEMPERATURE, **ref, "long_name":
                                   "highest temperature of a material point on the centre line"}),
        "trace_peak_position": (("body", "z_trace"), np.asarray(tr["peak_position"], float),
                                {"units": "m", **ref, "long_name": "x of that peak"}),
        "trace_cooling_rate": (("body", "z_trace"), np.asarray(tr["cooling_rate"], float),
                               {"units": "K s-1", **ref, "long_name": "fastest cooling after the peak "
                                "(NaN at the surface: infinite)"}),
        "trace_time_above": (("body", "z_trace"), np.asarray(tr["time_above"], float),
                             {"units": "s", **ref, "long_name": "time above the threshold"}),
        "trace_heated_depth": (("body",), np.asarray(tr["heated_depth"], float),
                               {"units": "m", **ref, "long_name": "depth where the peak falls through the threshold"}),
        "trace_threshold": ((), float(fld.threshold), {**_TEMPERATURE, "long_name": "threshold (field.threshold)"}),
        "trace_cooling_depth": (("body",), cooling_rate_depth(a, speeds, scene.wheel, scene.rail),
                                {"units": "m", "long_name": "shallowest depth at which metrics.nc scores the "
                                 "cooling rate (analysis.trace_metrics.cooling_rate_depth)"}),
        "trace_depth": ((), zh, {"units": "m", "long_name": "depth z* of trace_temperature", "body": hot}),
        "trace_depth_peak_temperature": (("body",), np.asarray(star["peak_temperature"], float)[:, 0],
                                         {**_TEMPERATURE, **ref, "long_name": "peak temperature at depth trace_depth"}),
        "trace_depth_cooling_rate": (("body",), np.asarray(star["cooling_rate"], float)[:, 0],
                                     {"units": "K s-1", **ref, "long_name": "cooling rate at depth trace_depth"}),
        "trace_temperature": (("body", "x"), at_depth, {**_TEMPERATURE, **ref, "depth": zh,
                              "long_name": "temperature along y = 0 at depth trace_depth"}),
    }
    coords = {"z_trace": ("z_trace", zt, zattrs)}
    if b is not None:
        nx, ny = MAP_POINTS
        xm = np.linspace(-a - _behind(fld), a, nx)
        ym = np.linspace(-b, b, ny)
        gx, gy = np.meshgrid(xm, ym, indexing="ij")
        sm = np.array([bulk[i] + np.asarray(_surface_rise(scene.body(i), case, gx, gy, i), float) for i in (0, 1)])
        data["surface_map"] = (("body", "x_map", "y_map"), sm, {**_TEMPERATURE, **ref,
                               "long_name": "surface temperature over the patch and its trace"})
        coords.update({"x_map": ("x_map", xm, {"units": "m", "long_name": "rolling direction"}),
                       "y_map": ("y_map", ym, {"units": "m", "long_name": "lateral"})})
    return data, coords, [name]


def _thermal(scene) -> tuple[dict, dict, list[str]]:
    """Data variables and coordinates of the temperature curves, and the reference names."""
    case = _thermal_case(scene)
    if case is None:
        return {}, {}, []
    a, b, shape, q, speeds, eps = case
    line = b is None
    x = _surface_x(a, _behind(scene.field), SURFACE_POINTS_LINE if line else SURFACE_POINTS_ELLIPSE)
    name = NAME_JAEGER if line else NAME_MOVING_SOURCE
    surface, hottest, depth = [], [], []
    # thermal layer: sqrt(2 kappa a / v) at high Peclet, ~a at low; the depth profile reaches 4x that
    kappa = max(scene.body(i).diffusivity for i in (0, 1))
    at_rest = _heated_at_rest(case)
    vmin = max(min((v for v, rest in zip(speeds, at_rest) if not rest), default=0.0), 1e-12)
    layer = min(a, math.sqrt(2.0 * kappa * a / vmin))
    z = _field_depth(scene.field, 4.0 * layer) * np.linspace(0.0, 1.0, DEPTH_POINTS) ** 2
    for body in (0, 1):
        mat = scene.body(body)
        share = eps if body == 0 else 1.0 - eps
        if at_rest[body]:      # no steady field (see _heated_at_rest): NaN curves, the moving body's drawn
            surface.append(np.full_like(x, np.nan))
            hottest.append(math.nan)
            depth.append(np.full_like(z, np.nan))
            continue
        rise = np.asarray(_surface_rise(mat, case, x, None if line else np.zeros_like(x), body), float)
        surface.append(mat.bulk_temperature + rise)
        x0 = float(x[int(np.argmax(rise))]) if np.any(rise > 0) else 0.0
        hottest.append(x0)
        if share == 0 or q == 0:
            depth.append(np.full_like(z, mat.bulk_temperature))
        elif line:
            from ..references.jaeger import jaeger_band_temperature  # scipy: loaded by a line contact's curves only
            depth.append(mat.bulk_temperature + np.asarray(
                jaeger_band_temperature(np.full_like(z, x0), z, a, speeds[body], mat, share * q, shape), float))
        else:
            from ..references.moving_source import moving_source_temperature  # numba: only an elliptic patch needs it
            depth.append(mat.bulk_temperature + np.asarray(
                moving_source_temperature(np.full_like(z, x0), np.zeros_like(z), z, (a, b), speeds[body], mat,
                                          share * q, shape), float))
    data = {
        "surface_temperature": (("body", "x"), np.array(surface),
                                {**_TEMPERATURE, "long_name": "surface temperature along y = 0", "reference": name}),
        "hottest_x": (("body",), np.array(hottest),
                      {"units": "m", "long_name": "x of the hottest surface point (y = 0)", "reference": name}),
        "temperature": (("body", "z"), np.array(depth),
                        {**_TEMPERATURE, "long_name": "temperature below the hottest surface point (y = 0)",
                         "reference": name}),
    }
    coords = {"x": ("x", x, {"units": "m", "long_name": "rolling direction, leading edge at +a"}),
              "z": ("z", z, {"units": "m", "long_name": "depth into the body", "positive": "down"})}
    return data, coords, [name]


def _pure_longitudinal(creepage, friction, wheelset) -> bool:
    """Longitudinal creepage only, under a constant friction coefficient > 0, outside a wheelset."""
    return (creepage is not None and creepage.lateral == 0 and creepage.spin == 0 and friction is not None
            and friction.nominal > 0 and wheelset is None and friction.kind == "constant")


def _creepage_range(creepage, group_values: list[float]) -> np.ndarray:
    """Creepages [1] of the curve: the span of the sweep (5 % margin), else 0 to 1.5 xi; the swept values
    and 0 (when inside) are points of it."""
    values = list(group_values) or [creepage.longitudinal]
    lo, hi = min(values), max(values)
    if lo == hi:
        lo, hi = min(0.0, 1.5 * lo), max(0.0, 1.5 * hi)
        if lo == hi:
            lo, hi = -1e-3, 1e-3
    pad = 0.05 * (hi - lo)
    xs = np.linspace(lo - pad, hi + pad, CREEP_POINTS)
    extra = [float(v) for v in values] + ([0.0] if xs[0] < 0 < xs[-1] else [])
    return np.unique(np.concatenate([xs, extra]))  # the swept values themselves are points of the curve


def _creep(scene, group_values: list[float]) -> tuple[dict, dict, list[str]]:
    """Carter (line) or Kalker's linear slope (ellipse) for pure longitudinal creepage."""
    if (scene.heat_source is not None or not _pure_longitudinal(scene.creepage, scene.friction, scene.wheelset)
            or (scene.contact_shape == "line" and not _identical_elastic(scene.wheel, scene.rail))):
        return {}, {}, []
    try:
        a, b, p0, n = scene_hertz_geometry(scene)
    except Refused:
        return {}, {}, []
    xs = _creepage_range(scene.creepage, group_values)
    cattrs = {"units": "1", "long_name": "longitudinal creepage xi"}
    if scene.contact_shape == "line":
        mu = scene.friction.nominal
        c = carter_2d(scene.creepage.longitudinal, a, mu, scene.wheel_radius, max_pressure=p0)
        xp = np.linspace(-a, a, 401)
        ratio = [carter_2d(v, a, mu, scene.wheel_radius).force_ratio for v in xs]
        data = {
            "carter_traction_x": (("x_patch",), np.asarray(c.traction(xp), float),
                                  {"units": "Pa", "long_name": "tangential traction on the wheel", "reference": NAME_CARTER}),
            "carter_stick": (("x_patch",), c.stick(xp).astype("int8"),
                             {"units": "1", "long_name": "stick zone (1 stick, 0 slip)", "reference": NAME_CARTER}),
            "creep_force_ratio": (("creepage",), np.asarray(ratio, float),
                                  {"units": "1", "long_name": "creep force Fx / (mu N) on the wheel",
                                   "reference": NAME_CARTER}),
            "semi_axis_a": ((), a, {"units": "m", "long_name": "Hertz half-width", "reference": NAME_CARTER}),
        }
        coords = {"x_patch": ("x_patch", xp, {"units": "m", "long_name": "rolling direction across the patch"}),
                  "creepage": ("creepage", xs, cattrs)}
        return data, coords, [NAME_CARTER]
    w, r = scene.wheel, scene.rail
    if w.rigid or r.rigid or b is None:
        return {}, {}, []
    g = 2.0 / (1.0 / w.shear_modulus + 1.0 / r.shear_modulus)  # Kalker 1990: combined constants
    nu = 0.5 * g * (w.poisson_ratio / w.shear_modulus + r.poisson_ratio / r.shear_modulus)
    fx, _, _ = kalker_linear_forces(a, b, g, nu, 1.0, 0.0, 0.0)
    slope = fx / (scene.friction.nominal * n)
    lim = 1.0 / abs(slope) if slope else math.inf  # the linear law reaches |Fx| = mu N here
    lin = np.where(np.abs(xs) <= lim, slope * xs, np.nan)
    data = {"creep_force_ratio_linear": (("creepage",), lin,
                                         {"units": "1", "long_name": "creep force Fx / (mu N), linear theory "
                                          "(NaN beyond |Fx| = mu N)", "reference": NAME_KALKER}),
            "kalker_linear_slope": ((), float(slope), {"units": "1", "long_name": "d(Fx / mu N) / d(xi)",
                                                       "reference": NAME_KALKER})}
    return data, {"creepage": ("creepage", xs, cattrs)}, [NAME_KALKER]


def _sweep_groups(scenes) -> dict[str, list[float]]:
    """Scene name -> the longitudinal creepages of its sweep group (same base name, same other sweep keys)."""
    groups: dict = {}
    for sc in scenes:
        sweep = dict(getattr(sc, "sweep", {}) or {})
        if "creepage.longitudinal" not in sweep:
            continue
        key = (base_name(sc.name),
               tuple(sorted((k, str(v)) for k, v in sweep.items() if k != "creepage.longitudinal")))
        groups.setdefault(key, []).append(sc)
    out = {}
    for members in groups.values():
        vals = sorted(float(s.sweep["creepage.longitudinal"]) for s in members)
        for s in members:
            out[s.name] = vals
    return out


def scene_reference_curves(scene, group_values: list[float] | None = None):
    """Reference curves of one scene as an xarray Dataset, or None when core has none for it."""
    data, coords, names = {}, {}, []
    for part in (lambda: _thermal(scene), lambda: _trace(scene), lambda: _creep(scene, group_values or [])):
        d, c, n = part()
        data.update(d)
        coords.update(c)
        names += [x for x in n if x not in names]
    transient, tcoords, tname = transient_history_curves(scene)
    data.update(transient)
    coords.update(tcoords)
    if not data:
        return None
    if "body" in {dim for v in data.values() for dim in v[0]}:
        coords["body"] = ("body", np.array(["wheel", "rail"]), {"units": "1", "long_name": "body"})
    ds = xr.Dataset({k: xr.Variable(*v) for k, v in data.items()},
                    coords={k: xr.Variable(*v) for k, v in coords.items()})
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm reference curves of scene {scene.name}",
                     "source": f"railtherm {__version__} (railtherm.analysis.reference_curves)",
                     "scene": scene.name, "scene_hash": scene.hash, "reference": "; ".join(names)})
    if tname:
        ds.attrs["transient_reference"] = tname
    return ds


def reference_curves(study, map=None) -> dict:
    """Exact reference curves of each scene of ``study`` that has one.

    Parameters
    ----------
    study : railtherm.input.study.Study
        The study (its scenes after sweep expansion).
    map : callable, optional
        A ``map(fn, iterable)`` that may run in other processes (a process pool's): the scenes' curves
        are independent, so they are computed in parallel; the result is the same.

    Returns
    -------
    dict of str to xarray.Dataset
        Scene name -> curves (below); every variable carries ``units``, ``long_name`` and ``reference``,
        the Dataset the attribute ``reference`` naming all of them. A scene whose reference cannot be
        evaluated is left out with a warning.

    Notes
    -----
    The curves:

    * ``surface_temperature(body, x)`` [degC]: surface temperature along y = 0 of each body, for a
      full-sliding or given heat source without convection (Jaeger's moving band for a line contact, the
      moving surface source on a half-space for an ellipse), with ``hottest_x(body)`` [m], the x of its
      maximum, and ``temperature(body, z)`` [degC], the depth profile through that point;
    * for a scene with ``field`` and such a source, the exact thermal trace
      (:func:`railtherm.analysis.analytic.trace_reference`) on the depths ``z_trace`` from the surface to
      ``field.depth``: ``trace_peak_temperature(body, z_trace)`` [degC], ``trace_peak_position(body,
      z_trace)`` [m], ``trace_cooling_rate(body, z_trace)`` [K s-1] (NaN at z = 0, where it is infinite),
      ``trace_time_above(body, z_trace)`` [s], ``trace_heated_depth(body)`` [m] and ``trace_threshold``
      [degC]; ``trace_depth`` [m], the depth z* of the curve ``trace_temperature(body, x)`` [degC] along
      the rolling direction and of ``trace_depth_peak_temperature(body)`` [degC] and
      ``trace_depth_cooling_rate(body)`` [K s-1] (the hotter body's heated depth when it lies inside the field, else the depth
      where its peak temperature has fallen to half its surface rise); and, for an ellipse,
      ``surface_map(body, x_map, y_map)`` [degC], the surface temperature over the patch and its trace.
      ``temperature(body, z)`` then reaches ``field.depth`` and ``surface_temperature`` reaches
      ``field.behind`` beyond the trailing edge;
    * ``carter_traction_x(x_patch)`` [Pa] and ``carter_stick(x_patch)`` [1]: Carter's 2-D traction and
      stick zone for a line contact of identical elastic bodies with pure longitudinal creepage;
    * ``creep_force_ratio(creepage)`` [1]: Carter's Fx / (mu N) over the creepages of the scene's sweep
      (or around its own creepage);
    * ``creep_force_ratio_linear(creepage)`` [1] and ``kalker_linear_slope`` [1]: the initial slope
      d(Fx / mu N)/d(xi) of Kalker's linear theory for an elliptic Hertz contact with pure longitudinal
      creepage, drawn up to |Fx| = mu N (no saturation);
    * for a transient scene (``mode = "transient"``), the exact history and per-pass values of
      :func:`railtherm.analysis.transient_curves.transient_history_curves` (the calls ``metrics.nc`` scores
      with): ``exact_temperature_history(body, history_time, history_depth)`` [degC],
      ``exact_pass_peak_temperature(body, pass, history_depth)`` [degC], ``exact_residual_rise(body, pass)``
      [K] and ``exact_time_above(body, pass, history_depth)`` [s], the group attribute
      ``transient_reference`` naming the references.
    """
    jobs = curve_jobs(study)
    return collect_curves(jobs, (map or builtins.map)(scene_curves_job, jobs))


def curve_jobs(study) -> list[tuple]:
    """The ``(scene, sweep group)`` jobs of :func:`reference_curves`, one per scene; a caller may submit
    :func:`scene_curves_job` over them to a pool early and hand the results to :func:`collect_curves`."""
    groups = _sweep_groups(study.scenes)
    return [(sc, groups.get(sc.name)) for sc in study.scenes]


def collect_curves(jobs: list[tuple], done) -> dict:
    """Scene name -> curves from the results ``done`` of :func:`scene_curves_job` over ``jobs`` (in order); a
    scene whose reference could not be evaluated is left out with a warning."""
    out = {}
    for (sc, _), (ds, problem) in zip(jobs, done):
        if problem:
            warnings.warn(f"reference curves of scene {sc.name!r} left out: {problem}", RuntimeWarning, stacklevel=2)
        elif ds is not None:
            out[sc.name] = ds
    return out


def scene_curves_job(job) -> tuple:
    """(curves or None, problem text or "") of one ``(scene, sweep group)``: no exact theory for the scene
    (e.g. a line contact given by penetration) is None; any other error is the problem, never raised (one
    scene's reference never stops the others)."""
    sc, group = job
    try:
        return scene_reference_curves(sc, group), ""
    except Refused:
        return None, ""
    except Exception as exc:  # noqa: BLE001 - reported by the caller
        return None, f"{type(exc).__name__}: {exc}"


def _group_name(i: int, scene: str) -> str:
    return f"s{i:04d}_" + re.sub(r"[^A-Za-z0-9_]+", "_", scene)[:60]


def write_reference_curves(study, out, map=None, curves: dict | None = None) -> Path:
    """Write :func:`reference_curves` of ``study`` to ``out/references.nc`` (atomically) and return the path.

    One netCDF4 group per scene; the group's attribute ``scene`` holds the scene name. The file is
    written even when no scene has a reference (then it holds none), so that a reader can tell
    "no reference" from "not computed". ``map``: as for :func:`reference_curves`; ``curves``: its result,
    when the caller computed it already.
    """
    curves = reference_curves(study, map) if curves is None else curves
    attrs = {"Conventions": "CF-1.11", "title": f"railtherm reference curves of study {study.name}",
             "study": study.name, "scenes": len(curves)}
    groups = {_group_name(i, name): ds for i, (name, ds) in enumerate(curves.items())}
    return store.write_references(store.references_path(out), attrs, groups)


def read_reference_curves(path) -> dict:
    """Scene name -> Dataset of a file written by :func:`write_reference_curves` (loaded into memory)."""
    return store.read_references(path)
