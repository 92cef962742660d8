"""Cross-method error metrics of a study: errors against the reference, heat balance, convergence
orders, cross-method differences, wall times and the status of every run.

Errors are relative and named after the quantity: ``max_surface_temperature``,
``mean_contact_temperature``, ``surface_temperature_l2`` (relative L2 of the temperature *rise* over
the grid), ``pressure_l2``, ``max_pressure``, ``semi_axis_a``, ``creep_force_x``,
``frictional_power``. The reference of a scene is its own ``reference`` key or the study's:
"analytic" (core's exact references, falling back to the method's finest level for quantities
without one), a method name (that method's finest level) or "finest".
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

SCALARS = ("max_surface_temperature", "mean_contact_temperature", "max_pressure", "semi_axis_a",
           "creep_force_x", "frictional_power", "steady_wheel_temperature", "steady_mean_contact_temperature")
FIELDS = ("surface_temperature", "pressure")
METRICS = SCALARS + tuple(f + "_l2" for f in FIELDS)
#: quantity compared across methods
#: cells at which an analytic field reference is evaluated per run (a regular subsample of the grid)
MAX_FIELD_POINTS = 1500
CROSS = ("max_surface_temperature", "mean_contact_temperature", "creep_force_x", "max_pressure")


def _open(path):
    import xarray as xr
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def _rel(v, r):
    v, r = np.asarray(v, dtype=float), np.asarray(r, dtype=float)
    if v.shape != r.shape or v.size == 0:
        return math.nan
    scale = np.max(np.abs(r))
    if not np.isfinite(scale) or scale == 0:
        return math.nan if np.max(np.abs(v)) > 0 else 0.0
    return float(np.max(np.abs(v - r)) / scale)


def _rise(scene, name, arr):
    if name == "surface_temperature":
        bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
        return arr - bulk.reshape((2,) + (1,) * (arr.ndim - 1))
    return arr


def _rel_l2(scene, name, v, r):
    v, r = _rise(scene, name, np.asarray(v, float)), _rise(scene, name, np.asarray(r, float))
    den = np.sqrt(np.sum(r ** 2))
    if den == 0 or not np.isfinite(den):
        return math.nan
    return float(np.sqrt(np.sum((v - r) ** 2)) / den)


def _interp_to(ref, ds, name):
    """Field ``name`` of run ``ref`` on the grid of run ``ds`` (linear, extrapolating at the edges)."""
    da = ref[name]
    kw = {d: ds[d] for d in ("x", "y") if d in da.dims and d in ds.dims}
    return da.interp(kw, kwargs={"fill_value": "extrapolate"}).values


def heat_balance(ds) -> float:
    """(integrated heat flux into both bodies - frictional power) / frictional power [1]."""
    if "heat_flux" not in ds or "frictional_power" not in ds:
        return math.nan
    p = float(ds["frictional_power"])
    if p == 0:
        return math.nan
    dx = float(np.diff(ds["x"].values).mean()) if ds.sizes["x"] > 1 else 1.0
    dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims and ds.sizes["y"] > 1 else 1.0
    total = float(ds["heat_flux"].sum()) * dx * dy
    return (total - p) / p


def run_errors(scene, ds, ref_values: dict, ref_ds=None) -> dict[str, float]:
    """Relative errors of one result against analytic values and/or a reference run."""
    from .analytic import reference_fields
    err = {}
    # the analytic field is evaluated on at most ~MAX_FIELD_POINTS cells (a regular subsample of the grid)
    if ref_values:
        n = ds.sizes["x"] * ds.sizes.get("y", 1)
        stride = max(1, int(math.ceil(math.sqrt(n / MAX_FIELD_POINTS))))
        sub = ds.isel({d: slice(stride // 2, None, stride) for d in ("x", "y") if d in ds.dims})
        fields = reference_fields(scene, sub)
    else:
        sub, fields = ds, {}
    for name in SCALARS:
        if name not in ds:
            continue
        if name in ref_values:
            err[name] = _rel(ds[name].values, ref_values[name])
        elif ref_ds is not None and name in ref_ds:
            err[name] = _rel(ds[name].values, ref_ds[name].values)
    for name in FIELDS:
        if name not in ds:
            continue
        if name in fields:
            err[name + "_l2"] = _rel_l2(scene, name, sub[name].values, fields[name])
        elif ref_ds is not None and name in ref_ds:
            try:
                err[name + "_l2"] = _rel_l2(scene, name, ds[name].values, _interp_to(ref_ds, ds, name))
            except Exception:  # noqa: BLE001 - incompatible grids: no field error
                pass
    return err


def convergence_order(levels, errors) -> float:
    """Slope of log(error) against log(h) with h = 2^-level (fit over finite, positive errors)."""
    lv = np.asarray(levels, float)
    e = np.asarray(errors, float)
    ok = np.isfinite(e) & (e > 0)
    if ok.sum() < 2:
        return math.nan
    h = 2.0 ** (-lv[ok])
    return float(np.polyfit(np.log(h), np.log(e[ok]), 1)[0])


def compute_metrics(study, out, records, tolerance: float | None = None):
    """Build the metrics Dataset of a study from its run records (and the run files)."""
    import xarray as xr
    from .analytic import reference_values

    tol = tolerance if tolerance is not None else getattr(study, "tolerance", 0.05)
    out = Path(out)
    scenes = {s.name: s for s in study.scenes}
    cache: dict = {}

    def load(rec):
        if rec.path not in cache:
            cache[rec.path] = _open(rec.path)
        return cache[rec.path]

    # finest ok level of each (scene, method), in one pass (O(runs))
    finest_of: dict = {}
    for r in records:
        if r.status == "ok":
            k = (r.scene, r.method)
            if k not in finest_of or r.level > finest_of[k].level:
                finest_of[k] = r

    def finest(scene, method):
        return finest_of.get((scene, method))

    def summary(rec):
        """(heat balance, scalar values) of a run: from its record when the worker filled them."""
        if getattr(rec, "summary", False):
            return rec.heat_balance, rec.values
        ds = load(rec)
        return heat_balance(ds), {q: ds[q].values for q in CROSS if q in ds}

    rows = []
    for rec in records:
        row = {"scene": rec.scene, "method": rec.method, "level": rec.level, "status": rec.status,
               "message": rec.message, "wall_time": rec.wall_time, "peak_memory": rec.peak_memory,
               "reference": "", "heat_balance": math.nan}
        if rec.status == "ok":
            scene = scenes[rec.scene]
            kind = scene.reference or study.reference
            ref_values, ref_ds, names = {}, None, []
            if kind == "analytic":
                try:
                    rv = reference_values(scene)
                except Exception as exc:  # noqa: BLE001
                    rv = {"_names": [f"analytic reference failed: {exc}"]}
                names = list(rv.pop("_names", []))
                ref_values = rv
                fr = finest(rec.scene, rec.method)
                if fr is not None and fr.level != rec.level:
                    ref_ds = load(fr)
                    names.append(f"finest level of {rec.method} (level {fr.level}) where no analytic value")
            else:
                target = rec.method if kind == "finest" else kind
                fr = finest(rec.scene, target)
                if fr is not None and (target != rec.method or fr.level != rec.level):
                    ref_ds = load(fr)
                    names.append(f"{target} level {fr.level}")
            row["reference"] = "; ".join(names)
            if ref_values or ref_ds is not None:  # (the run itself is not cached: only finest levels are reused)
                own = cache.get(rec.path) or _open(rec.path)
                errs = run_errors(scene, own, ref_values, ref_ds)
            else:  # nothing to compare with: the file is not opened again
                errs = {}
            row.update({f"error_{k}": v for k, v in errs.items()})
            row["heat_balance"] = summary(rec)[0]
            finite = [v for v in errs.values() if np.isfinite(v)]
            if finite and max(finite) > tol:
                row["status"] = "inaccurate"
                worst = max(errs, key=lambda k: errs[k] if np.isfinite(errs[k]) else -1)
                row["message"] = f"relative error {errs[worst]:.3g} in {worst} exceeds the tolerance {tol:g}"
        rows.append(row)

    n = len(rows)
    data = {}
    str_cols = ("scene", "method", "status", "message", "reference")
    for col in str_cols:
        data[col] = ("run", np.array([r[col] for r in rows], dtype=object))
    data["level"] = ("run", np.array([r["level"] for r in rows], dtype="int32"))
    for col in ("wall_time", "peak_memory", "heat_balance") + tuple(f"error_{m}" for m in METRICS):
        data[col] = ("run", np.array([r.get(col, math.nan) for r in rows], dtype=float))
    ds = xr.Dataset(data, coords={"run": np.arange(n)})
    attrs = {"scene": ("1", "scene name"), "method": ("1", "method name"), "level": ("1", "resolution level"),
             "status": ("1", "run status: ok | inaccurate | refused | failed"), "message": ("1", "reason for the status"),
             "reference": ("1", "what the run was compared with"), "wall_time": ("s", "best wall time of the solve"),
             "peak_memory": ("bytes", "peak traced memory of the solve"),
             "heat_balance": ("1", "(integrated heat flux - frictional power) / frictional power")}
    for k, (u, ln) in attrs.items():
        ds[k].attrs.update(units=u, long_name=ln)
    for m in METRICS:
        ds[f"error_{m}"].attrs.update(units="1", long_name=f"relative error of {m} against the reference")
    ds["run"].attrs.update(units="1", long_name="run index")

    # convergence orders and cross-method differences
    snames = [s.name for s in study.scenes]
    mnames = sorted({r.method for r in records})
    order = np.full((len(snames), len(mnames), len(METRICS)), np.nan)
    cross = np.full((len(snames), len(CROSS), len(mnames), len(mnames)), np.nan)
    by_sm: dict = {}
    for r in rows:
        if r["status"] in ("ok", "inaccurate"):
            by_sm.setdefault((r["scene"], r["method"]), []).append(r)
    for i, s in enumerate(snames):
        vals = {}
        for j, m in enumerate(mnames):
            sel = by_sm.get((s, m), [])
            if len(sel) >= 2:  # (one level: no order)
                for k, met in enumerate(METRICS):
                    order[i, j, k] = convergence_order([r["level"] for r in sel],
                                                       [r.get(f"error_{met}", math.nan) for r in sel])
            fr = finest(s, m)
            if fr is not None:
                v = summary(fr)[1]
                vals[m] = {q: np.asarray(v[q], float) for q in CROSS if q in v}
        for q_i, q in enumerate(CROSS):
            for j, m1 in enumerate(mnames):
                for k, m2 in enumerate(mnames):
                    if m1 in vals and m2 in vals and q in vals[m1] and q in vals[m2]:
                        cross[i, q_i, j, k] = _rel(vals[m1][q], vals[m2][q])
    ds = ds.assign_coords(scene_name=("scene_name", np.array(snames, dtype=object)),
                          method_name=("method_name", np.array(mnames, dtype=object)),
                          other_method=("other_method", np.array(mnames, dtype=object)),
                          metric=("metric", np.array(METRICS, dtype=object)),
                          quantity=("quantity", np.array(CROSS, dtype=object)))
    ds["convergence_order"] = (("scene_name", "method_name", "metric"), order,
                               {"units": "1", "long_name": "fitted slope of log(error) against log(h), h = 2^-level"})
    ds["cross_difference"] = (("scene_name", "quantity", "method_name", "other_method"), cross,
                              {"units": "1", "long_name": "relative difference |q_m - q_o| / |q_o| at the finest levels"})
    for c, ln in (("scene_name", "scene"), ("method_name", "method"), ("other_method", "method compared with"),
                  ("metric", "error metric"), ("quantity", "compared quantity")):
        ds[c].attrs.update(units="1", long_name=ln)
    from . import __version__
    from .schema import history_line
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm metrics of study {study.name}",
                     "source": f"railtherm {__version__}", "history": history_line("railtherm metrics"),
                     "study": study.name, "tolerance": tol})
    return ds
