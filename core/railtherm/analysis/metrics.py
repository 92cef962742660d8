"""Cross-method error metrics of a study: errors against named references, energy balance of the
computed temperature field, convergence orders with Richardson estimates, cross-method differences,
timings and the verdict (status) of every run. The contract is ``docs/verdicts.md``.

Errors are relative and named after the quantity: ``max_surface_temperature``,
``mean_contact_temperature`` and the steady temperatures (relative error of the *rise above the
bulk temperature*, so that a hot wheel does not hide an error), ``surface_temperature_l2``
(relative L2 of the rise), ``pressure_l2``, ``max_pressure``, ``semi_axis_a``, ``creep_force_x``,
``frictional_power``. Each error records what it was taken against:

* ``analytic:<tag>``: core's exact reference (:mod:`railtherm.analytic`), when the scene's
  reference is "analytic" and one exists for the quantity;
* ``method:<name>``: another method's finest successful level (scene or study ``reference`` names a
  method);
* ``self:finest``: the run's own method at its finest level (``reference = "finest"``, or an
  "analytic" scene for quantities without an exact value). Such errors estimate discretisation
  error; they never verify a run.

An error is not counted at all when the run's chain contains the model that *is* the reference
(the Hertz patch against Hertz, full sliding against μN): that is a comparison with itself.

Verdicts (``status``): ``ok`` when at least one independent error exists and every error and the
energy balance are within the tolerance, ``inaccurate`` when one is not, ``unverified`` when the run
converged but nothing independent was compared; ``refused`` and ``failed`` come from the runner.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..output import store
from ..physics import body_speeds  # noqa: F401  (also importable from here for one release)

SCALARS = ("max_surface_temperature", "mean_contact_temperature", "max_pressure", "semi_axis_a",
           "creep_force_x", "frictional_power", "steady_wheel_temperature", "steady_mean_contact_temperature")
FIELDS = ("surface_temperature", "pressure")
METRICS = SCALARS + tuple(f + "_l2" for f in FIELDS)
from .rises import RISES, bulk_of as _bulk  # noqa: E402,F401  (temperatures on their rise above the bulk temperature)
from .trace_metrics import TRACE_METRICS, TRACE_PROFILES, trace_errors  # noqa: E402,F401  (metrics.nc's trace metrics)
#: the quantity a scene's verdict is given on: the first of these that the scene asks for
HEADLINE_ORDER = ("max_surface_temperature", "mean_contact_temperature", "creep_force_x", "max_pressure",
                  "semi_axis_a", "frictional_power", "steady_wheel_temperature", "steady_mean_contact_temperature")
#: cells at which an analytic field reference is evaluated per run (a regular subsample of the grid)
MAX_FIELD_POINTS = 1500
#: quantities compared across methods
CROSS = ("max_surface_temperature", "mean_contact_temperature", "creep_force_x", "max_pressure")
#: Péclet number V a / (2 kappa) above which the 1-D half-space energy identity is applied. Its own
#: error, measured on the exact moving-source field of a circular uniform source (level-3 grid, the
#: Abel inversion of :func:`half_space_energy`): 0.87 % at Pe 102, 0.51 % at Pe 204, 0.30 % at Pe 407,
#: 0.07 % at Pe 2444 (conduction along the surface, ~1/Pe); Jaeger's band: 0.01 % from Pe 100 up.
ENERGY_MIN_PECLET = 100.0
from ..output.store import STATUSES


def _open(path):
    """A run's Dataset, read through the output folder's owner (:func:`railtherm.store.open_result`: a run
    file or a run of the Zarr store)."""
    return store.open_result(path)


# ----------------------------------------------------------------------------------------------
# relative errors
def rel_error(scene, name: str, value, reference) -> float:
    """Max-norm relative error of ``value`` against ``reference`` [1]; temperatures on their rise.

    Parameters
    ----------
    scene : Scene
        For the bulk temperatures of the bodies [degC].
    name : str
        Quantity name (decides whether the rise above bulk is compared).
    value, reference : array_like
        Same shape.
    """
    v, r = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    if v.shape != r.shape or v.size == 0:
        return math.nan
    b = _bulk(scene, name, v.shape)
    v, r = v - b, r - b
    scale = np.max(np.abs(r))
    if not np.isfinite(scale) or scale == 0:
        return math.nan if np.max(np.abs(v)) > 0 else 0.0
    return float(np.max(np.abs(v - r)) / scale)


def _rel_l2(scene, name, v, r):
    v, r = np.asarray(v, float), np.asarray(r, float)
    b = _bulk(scene, name, v.shape)
    v, r = v - b, r - b
    den = np.sqrt(np.sum(r ** 2))
    if den == 0 or not np.isfinite(den):
        return math.nan
    return float(np.sqrt(np.sum((v - r) ** 2)) / den)


def _interp_to(ref, ds, name):
    """Field ``name`` of run ``ref`` on the grid of run ``ds`` (linear, extrapolating at the edges)."""
    da = ref[name]
    kw = {d: ds[d] for d in ("x", "y") if d in da.dims and d in ds.dims}
    return da.interp(kw, kwargs={"fill_value": "extrapolate"}).values


# ----------------------------------------------------------------------------------------------
# energy balance of the computed temperature field
def half_space_energy(theta: np.ndarray, t_edges: np.ndarray) -> np.ndarray:
    """Heat per unit area [J/m^2] that entered a 1-D half-space, from its surface temperature rise.

    For a half-space initially at its bulk temperature, the surface rise θ(t) and the entering
    flux q(t) satisfy θ(t) = (1/(β√π)) ∫_0^t q(τ) (t − τ)^(-1/2) dτ (β = √(λρc), the
    effusivity). With q constant on each cell, θ at the cell centres t_i is a lower-triangular
    system θ_i = (1/(β√π)) Σ_k K_ik q_k, K_ik = 2 (√(t_i − t_k0)₊ − √(t_i − t_k1)₊), exact for
    such a flux; solving it (Abel inversion by forward substitution) gives the cell fluxes, and the
    energy is E = Σ q_k Δt_k = β√π Σ (K⁻¹θ)_k Δt_k. Returned as π Σ (K⁻¹θ)_k Δt_k, which equals
    ∫_0^T θ(τ) (T − τ)^(-1/2) dτ (E = (β/√π) times it; the caller multiplies).

    Parameters
    ----------
    theta : ndarray, shape (..., n)
        Surface temperature rise at the cell centres, in time order [K].
    t_edges : ndarray, shape (n + 1,)
        Times of the cell edges, increasing from 0 [s].

    Returns
    -------
    ndarray, shape (...)
        π Σ_k (K⁻¹ θ)_k Δt_k [K s^(1/2)]; times β/√π it is the energy per area [J/m^2].
    """
    from scipy.linalg import solve_triangular
    theta = np.asarray(theta, float)
    t_edges = np.asarray(t_edges, float)
    tc = 0.5 * (t_edges[:-1] + t_edges[1:])
    gap0 = tc[:, None] - t_edges[None, :-1]
    gap1 = tc[:, None] - t_edges[None, 1:]
    K = 2.0 * (np.sqrt(np.clip(gap0, 0.0, None)) - np.sqrt(np.clip(gap1, 0.0, None)))
    flat = theta.reshape(-1, theta.shape[-1]).T  # (n, strips)
    q = solve_triangular(K, flat, lower=True, check_finite=False)
    return math.pi * (np.diff(t_edges) @ q).reshape(theta.shape[:-1])


def energy_balance(scene, ds) -> tuple[float, str]:
    """Energy balance of a result's computed temperature field [1] and how it was obtained.

    Core's check (``analytic:half-space-1d``): at Péclet numbers above
    :data:`ENERGY_MIN_PECLET`, conduction along the surface is negligible during the passage, and
    each strip of each body is a 1-D half-space; the heat that entered it follows from its computed
    surface temperature alone (:func:`half_space_energy`, an Abel inversion). Summed over strips and bodies
    (power = V × energy per area × strip width) it must equal the frictional power. The
    temperature solution enters; the heat source is only the yardstick. Its own error is of the
    order of 1/√Pe (neglected conduction along x) plus the quadrature error.

    Otherwise the temperature solver's own balance (global attribute ``<model>_heat_balance_error``,
    reference ``solver``) is used when it reports one; else NaN with an empty reference.

    Returns
    -------
    (float, str)
        ((heat entering through the surface − frictional power) / frictional power, reference).
    """
    from ..physics import peclet_number
    power = float(ds["frictional_power"]) if "frictional_power" in ds.variables else math.nan
    if "heat_flux" in ds.variables and not math.isfinite(power):
        hf = ds["heat_flux"].values
        dx = float(np.diff(ds["x"].values).mean())
        dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims else 1.0
        power = float(np.nansum(hf)) * dx * dy
    if "surface_temperature" in ds.variables and math.isfinite(power) and power > 0:
        speeds = body_speeds(scene)
        a = float(ds.attrs.get("semi_axis_a", math.nan))
        if "semi_axis_a" in ds.variables:
            a = float(ds["semi_axis_a"])
        if not math.isfinite(a):
            a = 0.5 * float(np.ptp(ds["x"].values))
        pe = min(peclet_number(abs(v), a, scene.body(i).diffusivity) for i, v in enumerate(speeds))
        if pe >= ENERGY_MIN_PECLET and min(speeds) > 0:
            x = ds["x"].values
            if x.size >= 2:
                dx = float(np.diff(x).mean())
                edges = np.concatenate([[x[0] - dx / 2], 0.5 * (x[1:] + x[:-1]), [x[-1] + dx / 2]])
                dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims and ds.sizes["y"] > 1 else 1.0
                total = 0.0
                ts = ds["surface_temperature"].transpose("body", "x", ...).values
                for i, v in enumerate(speeds):
                    mat = scene.body(i)
                    theta = ts[i] - mat.bulk_temperature  # (x, [y])
                    if not np.all(np.isfinite(theta)):
                        return math.nan, ""
                    theta = np.moveaxis(theta, 0, -1)[..., ::-1]  # time order: leading edge (+x) first
                    t_edges = (edges[-1] - edges[::-1]) / v
                    e = half_space_energy(theta, t_edges) * mat.effusivity / math.sqrt(math.pi)
                    total += v * float(np.sum(e)) * dy
                return (total - power) / power, "analytic:half-space-1d"
    own = [float(v) for k, v in ds.attrs.items() if k.endswith("heat_balance_error")
           and isinstance(v, (int, float, np.integer, np.floating))]
    if own:
        return max(own, key=abs), "solver"
    return math.nan, ""


# ----------------------------------------------------------------------------------------------
def _chain_references(ds) -> set[str]:
    """Tags of core's exact references that a model of the run's chain reproduces by construction."""
    from ..solving.plugins import get_host
    host = get_host()
    tags = set()
    for part in str(ds.attrs.get("stages", "")).split():
        stage, _, name = part.rpartition(":")
        info = host.models.get(name)
        cls = None
        if info is not None:
            try:
                cls = info.for_stage(stage) if stage else info.cls
            except KeyError:
                cls = info.cls
        tag = getattr(cls, "exact_reference", None)
        if tag:
            tags.add(tag)
    return tags


def run_errors(scene, ds, ref_values: dict, ref_ds=None, *, ref_tag: str = "", sources: dict | None = None
               ) -> dict[str, tuple[float, str]]:
    """Relative errors of one result: metric -> (error, reference tag).

    Parameters
    ----------
    scene : Scene
    ds : xarray.Dataset
        The result.
    ref_values : dict
        Exact values (:func:`railtherm.analytic.reference_values`); ``"_sources"`` (quantity -> tag)
        names them, or ``sources``.
    ref_ds : xarray.Dataset, optional
        A reference run for quantities without an exact value.
    ref_tag : str
        Tag of ``ref_ds`` (``method:<name>`` or ``self:finest``).
    """
    from .analytic import reference_fields
    sources = dict(sources if sources is not None else ref_values.get("_sources", {}))
    values = {k: v for k, v in ref_values.items() if not k.startswith("_")}
    same = _chain_references(ds) if values else set()
    if scene.heat_source is not None:  # every method takes a given source as it is
        same.add("given-source")
    err: dict[str, tuple[float, str]] = {}
    # the analytic field is evaluated on at most ~MAX_FIELD_POINTS cells (a regular subsample of the grid)
    if values:
        n = ds.sizes["x"] * ds.sizes.get("y", 1)
        stride = max(1, int(math.ceil(math.sqrt(n / MAX_FIELD_POINTS))))
        sub = ds.isel({d: slice(stride // 2, None, stride) for d in ("x", "y") if d in ds.dims})
        fields = reference_fields(scene, sub)
    else:
        sub, fields = ds, {}

    def exact(name):
        tag = sources.get(name, "analytic")
        return None if tag in same else f"analytic:{tag}"

    for name in SCALARS:
        if name not in ds:
            continue
        if name in values:
            tag = exact(name)
            if tag:
                err[name] = (rel_error(scene, name, ds[name].values, values[name]), tag)
        elif ref_ds is not None and name in ref_ds:
            err[name] = (rel_error(scene, name, ds[name].values, ref_ds[name].values), ref_tag)
    for name in FIELDS:
        if name not in ds:
            continue
        if name in fields:
            tag = exact(name)
            if tag:
                err[name + "_l2"] = (_rel_l2(scene, name, sub[name].values, fields[name]), tag)
        elif ref_ds is not None and name in ref_ds:
            try:
                err[name + "_l2"] = (_rel_l2(scene, name, ds[name].values, _interp_to(ref_ds, ds, name)), ref_tag)
            except Exception:  # noqa: BLE001 - incompatible grids: no field error
                pass
    err.update(trace_errors(scene, ds, fields, values, ref_ds, ref_tag, exact))
    return err


def independent(tag: str) -> bool:
    """Whether an error taken against ``tag`` verifies a run (an exact reference or another method)."""
    return tag.startswith("analytic:") or tag.startswith("method:")


def convergence_order(levels, errors) -> float:
    """Slope of log(error) against log(h) with h = 2^-level (fit over finite, positive errors)."""
    lv = np.asarray(levels, float)
    e = np.asarray(errors, float)
    ok = np.isfinite(e) & (e > 0)
    if ok.sum() < 2:
        return math.nan
    h = 2.0 ** (-lv[ok])
    return float(np.polyfit(np.log(h), np.log(e[ok]), 1)[0])


def richardson(levels, values, theoretical: float = math.nan) -> tuple[float, float, float]:
    """Richardson estimate of the error of the finest level of a refinement ladder.

    With values Q_k on levels k (h halving), the observed order from the three finest levels is
    p = log2((Q_{K-2} − Q_{K-1}) / (Q_{K-1} − Q_K)) and the error of Q_K is estimated as
    (Q_K − Q_{K-1}) / (2^p − 1). Its uncertainty is the spread of that estimate over the orders at
    hand (the previous triple's order, the theoretical order), or the estimate itself when there is
    no second order (or the ladder is not in its asymptotic range).

    Returns
    -------
    (estimate, uncertainty, p)
        Absolute error estimate and uncertainty [units of Q], and the observed order [1]; NaN when
        fewer than three consecutive levels or no monotone convergence.
    """
    lv = np.asarray(levels, int)
    q = np.asarray(values, float)
    order = np.argsort(lv)
    lv, q = lv[order], q[order]
    if q.size < 3 or not np.all(np.isfinite(q[-3:])) or not np.all(np.diff(lv[-3:]) == 1):
        return math.nan, math.nan, math.nan

    def observed(q3):
        d1, d2 = q3[1] - q3[0], q3[2] - q3[1]
        if d1 == 0 or d2 == 0 or d1 * d2 < 0:
            return math.nan
        return math.log2(abs(d1 / d2))

    p = observed(q[-3:])
    last = q[-1] - q[-2]
    if not math.isfinite(p) or p <= 0:
        return math.nan, math.nan, p
    est = last / (2.0 ** p - 1.0)
    others = []
    if q.size >= 4 and np.all(np.diff(lv[-4:]) == 1):
        p0 = observed(q[-4:-1])
        if math.isfinite(p0) and p0 > 0:
            others.append(last / (2.0 ** p0 - 1.0))
    if math.isfinite(theoretical) and theoretical > 0:
        others.append(last / (2.0 ** theoretical - 1.0))
    unc = max((abs(o - est) for o in others), default=abs(est))
    return abs(est), unc, p


# ----------------------------------------------------------------------------------------------
def _scalar(scene, name, v) -> float:
    """One number for a quantity that may be per body: the entry with the largest |rise|."""
    a = np.atleast_1d(np.asarray(v, float))
    b = np.atleast_1d(_bulk(scene, name, a.shape if a.size > 1 else ()))
    rise = a - b.ravel()[: a.size] if b.size > 1 else a - b
    return float(a[int(np.nanargmax(np.abs(rise)))]) if np.any(np.isfinite(rise)) else math.nan


def _theoretical_orders(method: str) -> dict:
    from ..contract.errors import SceneError
    from ..solving.plugins import get_host
    try:
        return dict(get_host().method(method).method.orders)
    except (SceneError, KeyError):
        return {}


def headline(scene) -> str:
    """The quantity a scene's verdict is given on (see :data:`HEADLINE_ORDER`)."""
    for q in HEADLINE_ORDER:
        if q in scene.outputs:
            return q
    return ""


def compute_metrics(study, out, records, tolerance: float | None = None):
    """Build the metrics Dataset of a study from its run records (and the run files).

    See ``docs/verdicts.md`` for every variable.
    """
    import xarray as xr
    from .analytic import reference_values

    tol = tolerance if tolerance is not None else getattr(study, "tolerance", 0.05)
    metrics = METRICS + (TRACE_METRICS if any(getattr(s, "field", None) is not None for s in study.scenes) else ())
    out = Path(out)
    scenes = {s.name: s for s in study.scenes}
    cache: dict = {}

    def load(rec):
        if rec.path not in cache:
            cache[rec.path] = _open(rec.path)
        return cache[rec.path]

    # finest successful level of each (scene, method), in one pass (O(runs))
    finest_of: dict = {}
    for r in records:
        if r.status == "ok":
            k = (r.scene, r.method)
            if k not in finest_of or r.level > finest_of[k].level:
                finest_of[k] = r

    def summary(rec):
        """(energy balance, its reference, scalar values) of a run, from its record when filled."""
        if getattr(rec, "summary", False):
            return rec.energy_balance, rec.energy_reference, rec.values
        ds = load(rec)
        e, ref = energy_balance(scenes[rec.scene], ds)
        return e, ref, {q: ds[q].values for q in set(CROSS) | set(SCALARS) if q in ds}

    analytic_cache: dict = {}

    def analytic(scene):
        if scene.name not in analytic_cache:
            try:
                analytic_cache[scene.name] = reference_values(scene)
            except Exception as exc:  # noqa: BLE001 - recorded, the run is then unverified
                analytic_cache[scene.name] = {"_names": [f"analytic reference failed: {exc}"], "_sources": {}}
        return analytic_cache[scene.name]

    rows = []
    for rec in records:
        row = {"scene": rec.scene, "method": rec.method, "level": rec.level, "status": rec.status,
               "message": rec.message, "reason_kind": getattr(rec, "reason_kind", ""),
               "wall_time": rec.wall_time, "wall_time_median": getattr(rec, "wall_time_median", math.nan),
               "timing_runs": getattr(rec, "timing_runs", 0), "peak_rss": getattr(rec, "peak_rss", math.nan),
               "rss_growth": getattr(rec, "rss_growth", math.nan),
               "energy_balance": math.nan, "energy_reference": "", "headline_error": math.nan,
               "headline_reference": ""}
        if rec.status == "ok":
            scene = scenes[rec.scene]
            kind = scene.reference or study.reference
            ref_values, ref_ds, ref_tag, why = {}, None, "", ""
            if kind == "analytic":
                ref_values = analytic(scene)
                fr = finest_of.get((rec.scene, rec.method))
                if fr is not None and fr.level != rec.level:
                    ref_ds, ref_tag = load(fr), "self:finest"
                elif fr is not None:
                    why = "finest level of its method"
            else:
                target = rec.method if kind == "finest" else kind
                fr = finest_of.get((rec.scene, target))
                if fr is None:
                    why = f"the reference method {target!r} has no successful run of this scene"
                elif target != rec.method:
                    ref_ds, ref_tag = load(fr), f"method:{target}"
                elif fr.level != rec.level:
                    ref_ds, ref_tag = load(fr), "self:finest"
                else:
                    why = "finest level of a self-referenced ladder"
            if {k for k in ref_values if not k.startswith("_")} or ref_ds is not None:
                own = cache.get(rec.path) or _open(rec.path)
                errs = run_errors(scene, own, ref_values, ref_ds, ref_tag=ref_tag)
            else:
                errs = {}
            for k, (v, tag) in errs.items():
                row[f"error_{k}"], row[f"reference_{k}"] = v, tag
            e, eref, _ = summary(rec)
            row["energy_balance"], row["energy_reference"] = e, eref
            hq = headline(scene)
            if hq in errs and independent(errs[hq][1]):
                row["headline_error"], row["headline_reference"] = errs[hq][0], errs[hq][1]
            finite = {k: v for k, (v, t) in errs.items() if np.isfinite(v)}
            indep = {k: v for k, (v, t) in errs.items() if np.isfinite(v) and independent(t)}
            bad = {k: v for k, v in finite.items() if v > tol}
            if math.isfinite(e) and abs(e) > tol:
                bad["energy_balance"] = abs(e)
            if bad:
                worst = max(bad, key=bad.get)
                against = errs[worst][1] if worst in errs else eref
                row["status"] = "inaccurate"
                row["message"] = (f"relative error {bad[worst]:.3g} in {worst} (against {against}) exceeds "
                                  f"the tolerance {tol:g}")
            elif indep:
                worst = max(indep, key=indep.get)
                row["message"] = (f"checked against {', '.join(sorted({errs[k][1] for k in indep}))}; largest "
                                  f"error {indep[worst]:.3g} in {worst}")
            else:
                row["status"] = "unverified"
                if finite:
                    row["message"] = ("compared only with its own finest level (self-convergence): "
                                      "no independent reference for " + ", ".join(sorted(finite)))
                else:
                    row["message"] = "nothing independent to compare with" + (f": {why}" if why else "")
        rows.append(row)

    n = len(rows)
    data = {}
    str_cols = ("scene", "method", "status", "message", "reason_kind", "energy_reference", "headline_reference") \
        + tuple(f"reference_{m}" for m in metrics)
    for col in str_cols:
        data[col] = ("run", np.array([r.get(col, "") for r in rows], dtype=object))
    data["level"] = ("run", np.array([r["level"] for r in rows], dtype="int32"))
    data["timing_runs"] = ("run", np.array([int(r["timing_runs"] or 0) for r in rows], dtype="int32"))
    for col in ("wall_time", "wall_time_median", "peak_rss", "rss_growth", "energy_balance", "headline_error") \
            + tuple(f"error_{m}" for m in metrics):
        data[col] = ("run", np.array([r.get(col, math.nan) for r in rows], dtype=float))
    ds = xr.Dataset(data, coords={"run": np.arange(n)})
    attrs = {"scene": ("1", "scene name"), "method": ("1", "method name"), "level": ("1", "resolution level"),
             "status": ("1", "run status: " + " | ".join(STATUSES)), "message": ("1", "reason for the status"),
             "reason_kind": ("1", "refused: validity | budget; failed: error | not-converged | timeout | invalid-input"),
             "wall_time": ("s", "best (minimum) wall time of the timed solves"),
             "wall_time_median": ("s", "median wall time of the timed solves"),
             "timing_runs": ("1", "number of timed solves after the warm-up"),
             "peak_rss": ("bytes", "peak resident set size of the process during one untimed solve (absolute)"),
             "rss_growth": ("bytes", "growth of the resident set during that solve"),
             "energy_balance": ("1", "(heat entering through the surface of the computed temperature field "
                                     "- frictional power) / frictional power"),
             "energy_reference": ("1", "how energy_balance was obtained: analytic:half-space-1d | solver"),
             "headline_error": ("1", "relative error of the scene's headline quantity against an independent reference"),
             "headline_reference": ("1", "reference of headline_error")}
    for k, (u, ln) in attrs.items():
        ds[k].attrs.update(units=u, long_name=ln)
    for m in metrics:
        ds[f"error_{m}"].attrs.update(units="1", long_name=f"relative error of {m} against reference_{m}")
        ds[f"reference_{m}"].attrs.update(units="1", long_name=f"reference of error_{m}: analytic:<name> | "
                                                               "method:<name> | self:finest")
    ds["run"].attrs.update(units="1", long_name="run index")

    # per scene: headline, reference kind, analytic values used
    snames = [s.name for s in study.scenes]
    mnames = sorted({r.method for r in records})
    heads = [headline(scenes[s]) for s in snames]
    ds = ds.assign_coords(scene_name=("scene_name", np.array(snames, dtype=object)),
                          method_name=("method_name", np.array(mnames, dtype=object)),
                          other_method=("other_method", np.array(mnames, dtype=object)),
                          metric=("metric", np.array(metrics, dtype=object)),
                          quantity=("quantity", np.array(CROSS, dtype=object)),
                          body=("body", np.array(["wheel", "rail"], dtype=object)))
    ds["headline"] = ("scene_name", np.array(heads, dtype=object),
                      {"units": "1", "long_name": "quantity the scene's verdict is given on"})
    ds["reference_kind"] = ("scene_name", np.array([scenes[s].reference or study.reference for s in snames],
                                                   dtype=object), {"units": "1", "long_name": "reference of the scene"})
    from ..contract.schema import VARIABLES
    used = {s: analytic(scenes[s]) for s in snames if (scenes[s].reference or study.reference) == "analytic"}
    for q in SCALARS + ("normal_force", "semi_axis_b", "heat_partition"):
        if not any(q in v for v in used.values()):
            continue
        per_body = "body" in VARIABLES[q].dims
        arr = np.full((len(snames), 2) if per_body else (len(snames),), np.nan)
        for i, s in enumerate(snames):
            if s in used and q in used[s]:
                arr[i] = used[s][q]
        var = VARIABLES[q]
        a = {"units": var.units, "long_name": f"exact reference value of {q} ({var.long_name})"}
        if var.temperature:
            a["units_metadata"] = "temperature: on_scale"
        ds[f"analytic_{q}"] = (("scene_name", "body") if per_body else ("scene_name",), arr, a)

    # convergence orders, Richardson estimates and cross-method differences
    order = np.full((len(snames), len(mnames), len(metrics)), np.nan)
    order_ref = np.full((len(snames), len(mnames), len(metrics)), "", dtype=object)
    theo = np.full((len(snames), len(mnames), len(metrics)), np.nan)
    rich = np.full((len(snames), len(mnames), len(metrics)), np.nan)
    rich_u = np.full((len(snames), len(mnames), len(metrics)), np.nan)
    cross = np.full((len(snames), len(CROSS), len(mnames), len(mnames)), np.nan)
    by_sm: dict = {}
    rec_of = {(r.scene, r.method, r.level): r for r in records}
    for r in rows:
        if r["status"] in ("ok", "inaccurate", "unverified"):
            by_sm.setdefault((r["scene"], r["method"]), []).append(r)
    orders_of = {m: _theoretical_orders(m) for m in mnames}
    for i, s in enumerate(snames):
        vals = {}
        for j, m in enumerate(mnames):
            sel = sorted(by_sm.get((s, m), []), key=lambda r: r["level"])
            for k, met in enumerate(metrics):
                theo[i, j, k] = float(orders_of[m].get(met, math.nan))
            if len(sel) >= 2:  # (one level: no order)
                for k, met in enumerate(metrics):
                    errs = [r.get(f"error_{met}", math.nan) for r in sel]
                    tags = sorted({r.get(f"reference_{met}", "") for r, e in zip(sel, errs) if np.isfinite(e)})
                    order[i, j, k] = convergence_order([r["level"] for r in sel], errs)
                    order_ref[i, j, k] = "; ".join(t for t in tags if t)
            if len(sel) >= 3:
                for k, met in enumerate(metrics):
                    if met not in SCALARS:
                        continue
                    lv, qs = [], []
                    for r in sel:
                        v = summary(rec_of[(s, m, r["level"])])[2].get(met)
                        if v is not None:
                            lv.append(r["level"])
                            qs.append(_scalar(scenes[s], met, v))
                    est, unc, _ = richardson(lv, qs, theo[i, j, k])
                    if math.isfinite(est):
                        scale = abs(qs[-1] - np.ravel(_bulk(scenes[s], met, ()))[0]) or math.nan
                        rich[i, j, k], rich_u[i, j, k] = est / scale, unc / scale
            fr = finest_of.get((s, m))
            if fr is not None:
                v = summary(fr)[2]
                vals[m] = {q: np.asarray(v[q], float) for q in CROSS if q in v}
        for q_i, q in enumerate(CROSS):
            for j, m1 in enumerate(mnames):
                for k, m2 in enumerate(mnames):
                    if m1 in vals and m2 in vals and q in vals[m1] and q in vals[m2]:
                        cross[i, q_i, j, k] = rel_error(scenes[s], q, vals[m1][q], vals[m2][q])
    dims3 = ("scene_name", "method_name", "metric")
    ds["convergence_order"] = (dims3, order, {"units": "1", "long_name": "fitted slope of log(error) against "
                                                                       "log(h), h = 2^-level"})
    ds["order_reference"] = (dims3, order_ref, {"units": "1", "long_name": "reference of the errors the order was "
                                                                         "fitted to (self:finest = self-convergence)"})
    ds["theoretical_order"] = (dims3, theo, {"units": "1", "long_name": "convergence order declared by the method"})
    ds["richardson_error"] = (dims3, rich, {"units": "1", "long_name": "Richardson estimate of the relative error "
                                                                     "of the finest level"})
    ds["richardson_uncertainty"] = (dims3, rich_u, {"units": "1", "long_name": "uncertainty of richardson_error"})
    ds["cross_difference"] = (("scene_name", "quantity", "method_name", "other_method"), cross,
                              {"units": "1", "long_name": "relative difference |q_m - q_o| / |q_o| at the finest "
                                                          "levels (temperatures: rises above bulk)"})
    for c, ln in (("scene_name", "scene"), ("method_name", "method"), ("other_method", "method compared with"),
                  ("metric", "error metric"), ("quantity", "compared quantity"), ("body", "body")):
        ds[c].attrs.update(units="1", long_name=ln)
    from .._version import __version__
    from ..contract.schema import history_line
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm metrics of study {study.name}",
                     "source": f"railtherm {__version__}", "history": history_line("railtherm metrics"),
                     "study": study.name, "tolerance": tol, "energy_min_peclet": ENERGY_MIN_PECLET})
    return ds
