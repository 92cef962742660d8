"""Cross-method error metrics of a study (``metrics.nc``): errors against named references
(:mod:`.errors`), energy balance of the computed temperature field, convergence orders with Richardson
estimates, cross-method differences, timings, the status of every run and the scorecard
(:mod:`.scorecard`). The contract is ``docs/verdicts.md``.

Errors are relative and named after the quantity: ``max_surface_temperature``, ``mean_contact_temperature`` and
the steady temperatures (relative error of the *rise above the bulk temperature*, so that a hot wheel does not hide
an error), ``surface_temperature_l2`` (relative L2 of the rise), ``pressure_l2``, ``max_pressure``, ``semi_axis_a``,
``creep_force_x``, ``frictional_power``. Each error records what it was taken against: ``analytic:<tag>`` (core's exact
reference), ``method:<name>`` (another method's finest successful level), ``self:finest`` (the run's own
method at its finest level: discretisation error, never a verification).

Statuses (:func:`railtherm.analysis.verdicts.run_status`): ``ok`` only when the headline quantity is within
the tolerance of an independent reference and no error nor the energy balance exceeds it, ``inaccurate`` when one
does (or is not finite where its reference is), ``unverified`` when the headline is not checked independently.
"""
from __future__ import annotations

import functools

import math
from pathlib import Path

import numpy as np

from .._version import __version__
from ..contract.errors import SceneError
from ..contract.schema import VARIABLES, history_line
from ..output import store
from ..physics import body_speeds, peclet_number
from ..solving.plugins import get_host
from .analytic import _thermal_case, reference_values
from .scorecard import verdict_vars

from .errors import (FIELDS, MAX_FIELD_POINTS, METRICS, SCALARS, _interp_to, chain_references,  # noqa: E402,F401
                     rel_error, rel_l2 as _rel_l2, run_errors, signed_error)
from .rises import (RISES, bulk_of as _bulk,  # noqa: E402,F401  (temperatures on their rise above the bulk temperature)
                    bulk_temperatures)
from .trace_metrics import (TRACE_METRICS, TRACE_PROFILES, _semi_axis,  # noqa: E402,F401  (metrics.nc's trace metrics)
                            cooling_rate_depth, trace_errors)
from .transient_metrics import TRANSIENT_METRICS, transient_errors  # noqa: E402  (metrics.nc's transient metrics)
from .verdicts import independent, label, run_status, zero_by_symmetry  # noqa: E402,F401
from .patch_metrics import patch_columns, patch_errors  # noqa: E402  (several patches scored patch by patch)
#: the quantity a scene's verdict is given on: the first of these that the scene asks for (a transient scene's
#: pass peaks first: its one-pass field is the same in every pass and would hide what accumulates between them)
HEADLINE_ORDER = ("pass_peak_temperature", "max_surface_temperature", "mean_contact_temperature", "creep_force_x",
                  "max_pressure", "semi_axis_a", "frictional_power", "steady_wheel_temperature",
                  "steady_mean_contact_temperature")
#: errors stored and shown but never used by a status or verdict (the cooling rate at every depth: its shallow
#: depths are log-singular, see :mod:`.trace_metrics`)
UNSCORED_BY_STATUS = ("cooling_rate_all_depths",)
#: quantities compared across methods
CROSS = ("max_surface_temperature", "mean_contact_temperature", "creep_force_x", "max_pressure")
#: Péclet number V a / (2 kappa) above which the 1-D half-space energy identity is applied. Its own
#: error, measured on the exact moving-source field of a circular uniform source (level-3 grid, the
#: Abel inversion of :func:`half_space_energy`): 0.87 % at Pe 102, 0.51 % at Pe 204, 0.30 % at Pe 407,
#: 0.07 % at Pe 2444 (conduction along the surface, ~1/Pe); Jaeger's band: 0.01 % from Pe 100 up.
ENERGY_MIN_PECLET = 100.0
from ..output.store import STATUSES


def _open(path):
    """A run's Dataset, read through the output folder's owner (:func:`railtherm.output.store.open_result`: a run
    file or a run of the Zarr store)."""
    return store.open_result(path)


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
    from scipy.linalg import solve_triangular  # scipy: loaded by the energy balance only, not by importing metrics
    theta = np.asarray(theta, float)
    t_edges = np.asarray(t_edges, float)
    tc = 0.5 * (t_edges[:-1] + t_edges[1:])
    gap0 = tc[:, None] - t_edges[None, :-1]
    gap1 = tc[:, None] - t_edges[None, 1:]
    K = 2.0 * (np.sqrt(np.clip(gap0, 0.0, None)) - np.sqrt(np.clip(gap1, 0.0, None)))
    flat = theta.reshape(-1, theta.shape[-1]).T  # (n, strips)
    q = solve_triangular(K, flat, lower=True, check_finite=False)
    return math.pi * (np.diff(t_edges) @ q).reshape(theta.shape[:-1])


def energy_balance(ds, speeds, wheel, rail) -> tuple[float, str]:
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

    Parameters
    ----------
    ds : xarray.Dataset
        The result.
    speeds : (float, float)
        The wheel's and the rail's surface speeds through the patch [m/s] (:func:`railtherm.physics.body_speeds`).
    wheel, rail : Material
        The bodies (diffusivity, effusivity and bulk temperature).

    Returns
    -------
    (float, str)
        ((heat entering through the surface − frictional power) / frictional power, reference).
    """
    power = float(ds["frictional_power"].sum()) if "frictional_power" in ds.variables else math.nan  # over patches
    if "heat_flux" in ds.variables and not math.isfinite(power):
        hf = ds["heat_flux"].values
        dx = float(np.diff(ds["x"].values).mean())
        dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims else 1.0
        power = float(np.nansum(hf)) * dx * dy
    if "surface_temperature" in ds.variables and math.isfinite(power) and power > 0:
        bodies = (wheel, rail)
        a = float(ds.attrs.get("semi_axis_a", math.nan))
        if "semi_axis_a" in ds.variables:
            a = float(ds["semi_axis_a"])
        if not math.isfinite(a):
            a = 0.5 * float(np.ptp(ds["x"].values))
        pe = min(peclet_number(abs(v), a, bodies[i].diffusivity) for i, v in enumerate(speeds))
        if pe >= ENERGY_MIN_PECLET and min(speeds) > 0:
            x = ds["x"].values
            if x.size >= 2:
                dx = float(np.diff(x).mean())
                edges = np.concatenate([[x[0] - dx / 2], 0.5 * (x[1:] + x[:-1]), [x[-1] + dx / 2]])
                dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims and ds.sizes["y"] > 1 else 1.0
                total = 0.0
                ts = ds["surface_temperature"].transpose("body", "x", ...).values
                for i, v in enumerate(speeds):
                    mat = bodies[i]
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
def _scalar(bulk, name, v) -> float:
    """One number for a quantity that may be per body: the entry with the largest |rise| above ``bulk`` (the
    wheel's and the rail's bulk temperatures [degC])."""
    a = np.atleast_1d(np.asarray(v, float))
    b = np.atleast_1d(_bulk(bulk, name, a.shape if a.size > 1 else ()))
    rise = a - b.ravel()[: a.size] if b.size > 1 else a - b
    return float(a[int(np.nanargmax(np.abs(rise)))]) if np.any(np.isfinite(rise)) else math.nan


def _theoretical_orders(method: str) -> dict:
    try:
        return dict(get_host().method(method).method.orders)
    except (SceneError, KeyError):
        return {}


def headline(outputs) -> str:
    """The quantity a scene's verdict is given on (see :data:`HEADLINE_ORDER`): the first of them among the
    scene's ``outputs`` (names), "" when none is."""
    for q in HEADLINE_ORDER:
        if q in outputs:
            return q
    return ""


class _Study:
    """What scoring the runs of a study needs: scenes, tolerance, the finest result of each ladder and cached
    run files and exact values."""

    def __init__(self, study, records, tol):
        self.study, self.records, self.tol = study, records, tol
        self.scenes = {s.name: s for s in study.scenes}
        self.cache: dict = {}
        self.exact: dict = {}
        self.finest_of: dict = {}     # (scene, method) -> record of its finest successful level
        self.rec_of = {(r.scene, r.method, r.level): r for r in records}
        for r in records:
            if r.status == "ok":
                k = (r.scene, r.method)
                if k not in self.finest_of or r.level > self.finest_of[k].level:
                    self.finest_of[k] = r

    def kind(self, reference: str | None) -> str:
        """The reference a scene's runs are scored against: its own ``reference``, else the study's."""
        return reference or self.study.reference

    def load(self, rec):
        """A reference run's Dataset (kept: it is read again by every level compared with it)."""
        if rec.path not in self.cache:
            self.cache[rec.path] = _open(rec.path)
        return self.cache[rec.path]

    def analytic(self, name: str) -> dict:
        """The exact values of scene ``name`` (:func:`reference_values`), computed once."""
        if name not in self.exact:
            try:
                self.exact[name] = reference_values(self.scenes[name])
            except Exception as exc:  # noqa: BLE001 - recorded, the run is then unverified
                self.exact[name] = {"_names": [f"analytic reference failed: {exc}"], "_sources": {}}
        return self.exact[name]

    def summary(self, rec):
        """(energy balance, its reference, scalar values) of a run, from its record when filled."""
        if getattr(rec, "summary", False):
            return rec.energy_balance, rec.energy_reference, rec.values
        ds = self.load(rec)
        scene = self.scenes[rec.scene]
        e, ref = energy_balance(ds, body_speeds(scene.speed, scene.sliding_speed, scene.tangential), scene.wheel,
                                scene.rail)
        return e, ref, {q: ds[q].values for q in set(CROSS) | set(SCALARS) if q in ds}

    def reference_of(self, rec):
        """(exact values, reference run, its tag, why there is none) for one run."""
        kind = self.kind(self.scenes[rec.scene].reference)
        if kind == "analytic":
            fr = self.finest_of.get((rec.scene, rec.method))
            if fr is not None and fr.level != rec.level:
                return self.analytic(rec.scene), self.load(fr), "self:finest", ""
            return self.analytic(rec.scene), None, "", "finest level of its method" if fr is not None else ""
        target = rec.method if kind == "finest" else kind
        fr = self.finest_of.get((rec.scene, target))
        if fr is None:
            return {}, None, "", f"the reference method {target!r} has no successful run of this scene"
        if target != rec.method:
            return {}, self.load(fr), f"method:{target}", ""
        if fr.level != rec.level:
            return {}, self.load(fr), "self:finest", ""
        return {}, None, "", "finest level of a self-referenced ladder"


def _base_row(rec) -> dict:
    return {"scene": rec.scene, "method": rec.method, "level": rec.level, "status": rec.status,
            "message": rec.message, "reason_kind": getattr(rec, "reason_kind", ""),
            "wall_time": rec.wall_time, "wall_time_median": getattr(rec, "wall_time_median", math.nan),
            "timing_runs": getattr(rec, "timing_runs", 0), "peak_rss": getattr(rec, "peak_rss", math.nan),
            "rss_growth": getattr(rec, "rss_growth", math.nan), "energy_balance": math.nan,
            "energy_reference": "", "headline_error": math.nan, "headline_signed_error": math.nan,
            "headline_reference": "", "not_scored": "", "cooling_rate_depth": math.nan}


def _cooling_depth(z_c) -> float:
    """Shallowest depth [m] at which the cooling rate of a run is scored: the smaller of the moving bodies' ``z_c``
    (:func:`railtherm.analysis.trace_metrics.cooling_rate_depth`)."""
    z = [float(v) for v in z_c if v > 0]
    return min(z) if z else math.nan


def _score(ctx: _Study, rec) -> dict:
    """One row of metrics.nc: the run's record, its errors, energy balance, headline error and status."""
    row = _base_row(rec)
    if rec.status != "ok":           # refused or failed: the runner's status stands
        return row
    scene = ctx.scenes[rec.scene]
    ref_values, ref_ds, ref_tag, why = ctx.reference_of(rec)
    notes, signed = {}, {}
    errs = {}
    if {k for k in ref_values if not k.startswith("_")} or ref_ds is not None:
        own = ctx.cache[rec.path] if rec.path in ctx.cache else _open(rec.path)
        errs = run_errors(scene, own, ref_values, ref_ds, ref_tag=ref_tag, notes=notes, signed=signed)
        bulk = bulk_temperatures(scene.wheel, scene.rail)
        zero = zero_by_symmetry(scene.creepage, scene.contact_shape, getattr(scene, "gap_coefficients", None),
                                scene.wheel, scene.rail, wheelset=scene.wheelset, heat_source=scene.heat_source)
        patch_errors(bulk, own, ref_ds, errs, zero=zero, notes=notes, signed=signed, row=row,
                     headline=headline(scene.outputs))
        if "cooling_rate" in errs:
            speeds = body_speeds(scene.speed, scene.sliding_speed, scene.tangential)
            row["cooling_rate_depth"] = _cooling_depth(cooling_rate_depth(
                _semi_axis(own, functools.partial(_thermal_case, scene)), speeds, scene.wheel, scene.rail))
    if ctx.kind(scene.reference) == "analytic" and getattr(scene, "transient", None) is not None:
        # the exact histories need neither the steady references nor a finer level (a locked wheel has no steady one)
        own = ctx.cache[rec.path] if rec.path in ctx.cache else _open(rec.path)
        errs.update(transient_errors(scene, own, notes=notes, cache=ctx.cache))
    for k, (v, tag) in errs.items():
        row[f"error_{k}"], row[f"reference_{k}"] = v, tag
    for k, v in signed.items():
        row[f"signed_error_{k}"] = v
    named = lambda k: label(k, row["cooling_rate_depth"])  # noqa: E731
    row["not_scored"] = "; ".join(f"{named(k)}: {w}" for k, w in sorted(notes.items())
                                  if k not in errs or not math.isinf(errs[k][0]))
    e, eref, _ = ctx.summary(rec)
    row["energy_balance"], row["energy_reference"] = e, eref
    hq = headline(scene.outputs)
    if hq in errs and independent(errs[hq][1]) and not math.isnan(errs[hq][0]):
        row["headline_error"], row["headline_reference"] = errs[hq][0], errs[hq][1]
        row["headline_signed_error"] = signed.get(hq, math.nan)
    labels = {"cooling_rate": named("cooling_rate")}
    scored = {k: v for k, v in errs.items() if k not in UNSCORED_BY_STATUS}
    row["status"], row["message"] = run_status(scored, e, eref, ctx.tol, hq, labels, why, notes)
    return row


_RUN_ATTRS = {
    "scene": ("1", "scene name"), "method": ("1", "method name"), "level": ("1", "resolution level"),
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
    "headline_error": ("1", "relative error of the scene's headline quantity against an independent reference "
                            "(inf: not finite where the reference is)"),
    "headline_signed_error": ("1", "headline_error with the sign of (value - reference)"),
    "headline_reference": ("1", "reference of headline_error"),
    "not_scored": ("1", "metrics not scored and why: 'metric: reason; ...' (zero by symmetry, below the noise "
                        "floor, not independent)"),
    "cooling_rate_depth": ("m", "shallowest depth at which error_cooling_rate scores the cooling rate"),
}


def _run_table(rows: list[dict], metrics: tuple):
    """The per-run variables of metrics.nc (dimension ``run``)."""
    import xarray as xr  # xarray (with pandas, ~1 s): loaded when metrics.nc is built, not by importing metrics
    signed = tuple(m for m in SCALARS if m in metrics)
    str_cols = ("scene", "method", "status", "message", "reason_kind", "energy_reference", "headline_reference",
                "not_scored") + tuple(f"reference_{m}" for m in metrics)
    data = {col: ("run", np.array([r.get(col, "") for r in rows], dtype=object)) for col in str_cols}
    data["level"] = ("run", np.array([r["level"] for r in rows], dtype="int32"))
    data["timing_runs"] = ("run", np.array([int(r["timing_runs"] or 0) for r in rows], dtype="int32"))
    for col in ("wall_time", "wall_time_median", "peak_rss", "rss_growth", "energy_balance", "headline_error",
                "headline_signed_error", "cooling_rate_depth") + tuple(f"error_{m}" for m in metrics) \
            + tuple(f"signed_error_{m}" for m in signed):
        data[col] = ("run", np.array([r.get(col, math.nan) for r in rows], dtype=float))
    ds = xr.Dataset(data, coords={"run": np.arange(len(rows))})
    for k, (u, ln) in _RUN_ATTRS.items():
        ds[k].attrs.update(units=u, long_name=ln)
    for m in metrics:
        what = label(m) + (" at the depths z >= cooling_rate_depth" if m == "cooling_rate" else "")
        ds[f"error_{m}"].attrs.update(units="1", long_name=f"relative error of {what} against reference_{m} "
                                                           "(NaN: not scored; inf: not finite where the reference is)")
        ds[f"reference_{m}"].attrs.update(units="1", long_name=f"reference of error_{m}: analytic:<name> | "
                                                               "method:<name> | self:finest")
    for m in signed:
        ds[f"signed_error_{m}"].attrs.update(units="1", long_name=f"error_{m} with the sign of (value - reference)")
    ds["run"].attrs.update(units="1", long_name="run index")
    return patch_columns(ds, rows)


def _scene_vars(ds, ctx: _Study, snames: list, mnames: list, metrics: tuple):
    """Per-scene variables: headline, reference kind and the exact values used."""
    scenes = ctx.scenes
    ds = ds.assign_coords(scene_name=("scene_name", np.array(snames, dtype=object)),
                          method_name=("method_name", np.array(mnames, dtype=object)),
                          other_method=("other_method", np.array(mnames, dtype=object)),
                          metric=("metric", np.array(metrics, dtype=object)),
                          quantity=("quantity", np.array(CROSS, dtype=object)),
                          body=("body", np.array(["wheel", "rail"], dtype=object)))
    ds["headline"] = ("scene_name", np.array([headline(scenes[s].outputs) for s in snames], dtype=object),
                      {"units": "1", "long_name": "quantity the scene's verdict is given on"})
    ds["reference_kind"] = ("scene_name", np.array([ctx.kind(scenes[s].reference) for s in snames], dtype=object),
                            {"units": "1", "long_name": "reference of the scene"})
    used = {s: ctx.analytic(s) for s in snames if ctx.kind(scenes[s].reference) == "analytic"}
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
    return ds


def _ladder_orders(ctx: _Study, sel: list, s: str, m: str, metrics: tuple, theo: list):
    """(orders, their references, Richardson estimates and uncertainties) of one ladder, per metric."""
    nk = len(metrics)
    order, oref = np.full(nk, np.nan), np.full(nk, "", dtype=object)
    rich, rich_u = np.full(nk, np.nan), np.full(nk, np.nan)
    if len(sel) >= 2:  # (one level: no order)
        for k, met in enumerate(metrics):
            errs = [r.get(f"error_{met}", math.nan) for r in sel]
            tags = sorted({r.get(f"reference_{met}", "") for r, e in zip(sel, errs) if np.isfinite(e)})
            order[k] = convergence_order([r["level"] for r in sel], errs)
            oref[k] = "; ".join(t for t in tags if t)
    if len(sel) >= 3:
        bulk = bulk_temperatures(ctx.scenes[s].wheel, ctx.scenes[s].rail)
        for k, met in enumerate(metrics):
            if met not in SCALARS:
                continue
            lv, qs = [], []
            for r in sel:
                v = ctx.summary(ctx.rec_of[(s, m, r["level"])])[2].get(met)
                if v is not None:
                    lv.append(r["level"])
                    qs.append(_scalar(bulk, met, v))
            est, unc, _ = richardson(lv, qs, theo[k])
            if math.isfinite(est):
                scale = abs(qs[-1] - np.ravel(_bulk(bulk, met, ()))[0]) or math.nan
                rich[k], rich_u[k] = est / scale, unc / scale
    return order, oref, rich, rich_u


def _convergence_vars(ds, ctx: _Study, by_sm: dict, snames: list, mnames: list, metrics: tuple):
    """Convergence orders, Richardson estimates (scene x method x metric) and cross-method differences."""
    shape = (len(snames), len(mnames), len(metrics))
    order, order_ref = np.full(shape, np.nan), np.full(shape, "", dtype=object)
    theo, rich, rich_u = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    cross = np.full((len(snames), len(CROSS), len(mnames), len(mnames)), np.nan)
    orders_of = {m: _theoretical_orders(m) for m in mnames}
    for i, s in enumerate(snames):
        vals = {}
        bulk = bulk_temperatures(ctx.scenes[s].wheel, ctx.scenes[s].rail)
        for j, m in enumerate(mnames):
            theo[i, j] = [float(orders_of[m].get(met, math.nan)) for met in metrics]
            sel = sorted(by_sm.get((s, m), []), key=lambda r: r["level"])
            order[i, j], order_ref[i, j], rich[i, j], rich_u[i, j] = _ladder_orders(ctx, sel, s, m, metrics,
                                                                                   list(theo[i, j]))
            fr = ctx.finest_of.get((s, m))
            if fr is not None:
                v = ctx.summary(fr)[2]
                vals[m] = {q: np.asarray(v[q], float) for q in CROSS if q in v}
        for q_i, q in enumerate(CROSS):
            for j, m1 in enumerate(mnames):
                for k, m2 in enumerate(mnames):
                    if m1 in vals and m2 in vals and q in vals[m1] and q in vals[m2]:
                        cross[i, q_i, j, k] = rel_error(bulk, q, vals[m1][q], vals[m2][q])
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
    return ds


def score_runs(study, records, tol: float, indices) -> list[tuple[int, dict]]:
    """The metrics rows of ``records[i]`` for ``i`` in ``indices``: a worker's share of :func:`compute_metrics`.
    A run is scored with nothing but the study and the records (its references are exact values or runs of
    the same scene, read from the output folder), so runs can be scored in separate processes."""
    ctx = _Study(study, records, tol)
    return [(i, _score(ctx, records[i])) for i in indices]


def scoring_groups(records) -> list[list[int]]:
    """Indices of ``records`` grouped by scene, the groups with the most runs to score first (a pool that
    takes them in this order finishes the long ones early). A scene's runs stay in one process because they
    share its exact references: the caches of :mod:`railtherm.analysis.analytic` evaluate each surface point
    and trace depth once per scene, and a method's levels and methods on one grid ask for many of the same."""
    groups: dict[str, list[int]] = {}
    for i, r in enumerate(records):
        groups.setdefault(r.scene, []).append(i)
    return sorted(groups.values(), key=lambda g: -sum(records[i].status == "ok" for i in g))


#: at most this many work items score a study in a pool: each carries the study and all its records
SCORING_PARTS = 32


def scoring_parts(records, parts: int | None = None) -> list[list[int]]:
    """:func:`scoring_groups` packed into at most ``parts`` work items of whole scenes, each scene to the item
    with the fewest runs to score so far (longest first): a work item pickles the study and every record once
    and builds its own scoring context, so a sweep of 10 000 scenes submitted scene by scene costs 10 000 of
    each (quadratic in the scenes). A study with at most ``parts`` (default :data:`SCORING_PARTS`) scenes keeps
    one item per scene."""
    parts = SCORING_PARTS if parts is None else int(parts)
    groups = scoring_groups(records)
    if len(groups) <= parts:
        return groups
    items: list[list[int]] = [[] for _ in range(parts)]
    load = [0] * parts
    for g in groups:
        k = min(range(parts), key=load.__getitem__)
        items[k].extend(g)
        load[k] += max(1, sum(records[i].status == "ok" for i in g))
    return [items[k] for k in sorted(range(parts), key=lambda k: -load[k]) if items[k]]


def submit_scoring(study, records, map, tolerance: float | None = None):
    """``map`` of :func:`score_runs` over :func:`scoring_parts` (a pool's map submits every part at once):
    the ``scored`` argument of :func:`compute_metrics`, with the same tolerance."""
    tol = study_tolerance(study, tolerance)
    return map(functools.partial(score_runs, study, records, tol), scoring_parts(records))


def study_tolerance(study, tolerance: float | None = None) -> float:
    """The relative tolerance [1] a study's runs are scored with: ``tolerance``, else the study's, else 5 %."""
    return tolerance if tolerance is not None else getattr(study, "tolerance", 0.05)


def compute_metrics(study, out, records, tolerance: float | None = None, *, map=None, scored=None):
    """Build the metrics Dataset of a study from its run records (and the run files or Zarr store).

    ``map``: a ``map(fn, iterable)`` that may run in other processes (e.g. a process pool's), to score
    the scenes in parallel (:func:`score_runs`); the rows are the same as scored here. ``scored``: instead,
    the results of :func:`score_runs` over :func:`scoring_groups` already submitted by the caller (so that a
    pool can take other work behind them). See ``docs/verdicts.md`` for every variable.
    """
    tol = study_tolerance(study, tolerance)
    metrics = METRICS + (TRACE_METRICS if any(getattr(s, "field", None) is not None for s in study.scenes) else ())
    metrics += TRANSIENT_METRICS if any(getattr(s, "transient", None) is not None for s in study.scenes) else ()
    ctx = _Study(study, records, tol)
    if map is None and scored is None:
        rows = [_score(ctx, rec) for rec in records]
    else:
        rows = [None] * len(records)
        if scored is None:
            scored = submit_scoring(study, records, map, tol)
        for part in scored:
            for i, row in part:
                rows[i] = row
    ds = _run_table(rows, metrics)
    snames = [s.name for s in study.scenes]
    mnames = sorted({r.method for r in records})
    ds = _scene_vars(ds, ctx, snames, mnames, metrics)
    by_sm: dict = {}
    for r in rows:
        if r["status"] in store.RESULT_STATUSES:
            by_sm.setdefault((r["scene"], r["method"]), []).append(r)
    ds = _convergence_vars(ds, ctx, by_sm, snames, mnames, metrics)
    ds = verdict_vars(ds, rows, snames, mnames, tol)
    for c, ln in (("scene_name", "scene"), ("method_name", "method"), ("other_method", "method compared with"),
                  ("metric", "error metric"), ("quantity", "compared quantity"), ("body", "body")):
        ds[c].attrs.update(units="1", long_name=ln)
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm metrics of study {study.name}",
                     "source": f"railtherm {__version__}", "history": history_line("railtherm metrics"),
                     "study": study.name, "tolerance": tol, "energy_min_peclet": ENERGY_MIN_PECLET})
    return ds
