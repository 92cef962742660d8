"""Open a study's results as one xarray Dataset.

:func:`open_results` reads every run file of a study output folder (``runs/<scene>/<method>/level-<k>.nc``)
and the status records of runs without a file (``level-<k>.status.json``: refused or failed), and
gathers the scalar results on dimensions ``scene``, ``method_name``, ``level`` (and ``body``). The swept
parameters of the study become coordinates along ``scene``; ``unstack=True`` turns a cartesian sweep
into one dimension per swept parameter.

A run file names its swept study keys in one global attribute, ``sweep``: a JSON object of the dotted
study keys and their values (``{"creepage.longitudinal": -0.001}``); :func:`sweep_of` decodes it. Files
are read with netCDF4-python directly (about 2 ms per run file, 20 s for a sweep of 10 000 scenes;
xarray's ``open_dataset`` takes five times longer).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import xarray as xr

from ..contract.schema import VARIABLES, variable_attrs
from ..input.scene import key_units
from ..output import store
# the sweep attribute is part of the run file's format: railtherm.output.store owns it (importable from here)
from ..output.store import SWEEP_ATTR, encode_sweep, run_sweeps, sweep_of  # noqa: F401

def _sweep_coord_attrs(key: str) -> dict:
    """units (UDUNITS-2, from the one table of study keys) and long_name of a swept study key."""
    return {"units": key_units(key) or "1", "long_name": f"swept study key '{key}'"}


def _read_run(path: Path, variables):
    """(scene, method, level, {name: value}, {sweep key: value}, wall_time, status) of one run file."""
    attrs, vals = store.read_run_scalars(path, variables)
    sweep = sweep_of(attrs)
    return (str(attrs["scene"]), str(attrs["method"]), int(attrs["level"]), vals, sweep,
            float(attrs.get("wall_time", np.nan)), str(attrs.get("status", "ok")))


def open_results(out, *, variables=None, unstack: bool | None = None):
    """Open the scalar results of every run of a study output folder as one Dataset.

    A folder written with the Zarr store (``[study] store = "zarr"``: ``results.zarr``) is opened
    lazily, backed by dask (:func:`railtherm.output.store.open_store`): nothing but the coordinates is
    read until values are asked for, and a study whose scenes are one cartesian sweep gets one
    dimension per swept key by default, so ``ds.max_surface_temperature.sel(speed=30)`` reads only
    the chunks it needs. A folder of run files is read into memory, as before.

    Parameters
    ----------
    out : path
        Study output folder (holding ``runs/``).
    variables : iterable of str, optional
        Scalar variables to collect (default: every 0-d or ``(body,)`` variable found).
    unstack : bool, optional
        Turn the ``scene`` dimension into one dimension per swept parameter (a cartesian sweep
        gives a dense grid; combinations that were not run are NaN). Needs every scene to carry the
        same swept keys. Default: False for run files; for the Zarr store, True when its scenes are
        one cartesian sweep of numbers.

    Returns
    -------
    xarray.Dataset
        Dimensions ``scene``, ``method_name``, ``level`` (and ``body`` for per-body scalars); the method
        dimension is not called ``method`` because ``Dataset.sel(method=...)`` is xarray's fill method
        (as in ``metrics.nc``). Variables: the
        scalar results with the units of the result schema, ``wall_time`` [s] and ``status``
        (ok | refused | failed | missing). Refused, failed and missing runs are NaN. Each swept
        parameter is a coordinate along ``scene`` named after its dotted study key
        (``creepage.longitudinal``, ``wheel.bulk_temperature``; select with
        ``ds.sel({"creepage.longitudinal": -1e-3})``); a swept key that is also the name of a result
        variable (``normal_force``) is called ``sweep_<key>``.

    Examples
    --------
    >>> ds = railtherm.open_results("runs/sweep_10k")                    # doctest: +SKIP
    >>> ds["max_surface_temperature"].sel(method_name="green", level=0, body="wheel")  # doctest: +SKIP
    >>> grid = railtherm.open_results("runs/sweep_10k", unstack=True)     # doctest: +SKIP
    """
    if store.has_store(out):
        return store.open_store(out, variables=variables, unstack=unstack)
    root = Path(out) / store.RUNS
    if not root.is_dir():
        raise FileNotFoundError(f"{str(root)!r} does not exist: give the output folder of 'railtherm run'")
    wanted = set(variables) if variables is not None else None
    records = [_read_run(f, wanted) for f in store.run_files(out)]
    have = {(r[0], r[1], r[2]) for r in records}
    statuses = _missing_runs(out, have)
    if not records and not statuses:
        raise FileNotFoundError(f"no run files in {str(root)!r}")
    scenes = sorted({r[0] for r in records} | {s[0] for s in statuses})
    methods = sorted({r[1] for r in records} | {s[1] for s in statuses})
    levels = sorted({r[2] for r in records} | {s[2] for s in statuses})
    si = {s: i for i, s in enumerate(scenes)}
    mi = {m: i for i, m in enumerate(methods)}
    li = {k: i for i, k in enumerate(levels)}
    shape = (len(scenes), len(methods), len(levels))
    data = _result_arrays(records, statuses, si, mi, li, shape)
    coords = {"scene": ("scene", np.array(scenes, dtype=object), {"units": "1", "long_name": "scene name"}),
              "method_name": ("method_name", np.array(methods, dtype=object), {"units": "1", "long_name": "method"}),
              "level": ("level", np.array(levels, dtype="int32"), {"units": "1", "long_name": "resolution level"}),
              "body": ("body", np.array(["wheel", "rail"]), {"units": "1", "long_name": "body"})}
    sweep_names = _add_sweep_coords(records, statuses, si, len(scenes), data, coords)
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm results of {Path(out).name}",
                     "source": f"railtherm open_results of {str(Path(out))}",
                     "swept_parameters": " ".join(sweep_names.values())})
    if unstack and sweep_names:
        ds = _unstack(ds, list(sweep_names.values()))
    return ds


def _missing_runs(out, have):
    """(scene, method, level, status, sweep) of the runs of a study folder that left a status file but no run
    file (refused or failed)."""
    statuses = []  # runs without a file: refused or failed
    for f in store.status_files(out):
        try:
            rec = store.read_json(f)
        except (OSError, ValueError):
            continue
        key = (str(rec.get("scene")), str(rec.get("method")), int(rec.get("level", -1)))
        if key not in have and key[2] >= 0:
            statuses.append((*key, str(rec.get("status", "failed")), rec.get("sweep") or {}))
    return statuses


def _result_arrays(records, statuses, si, mi, li, shape):
    """The Dataset variables of :func:`open_results` (name -> (dims, array, attrs)): every scalar result
    found in the run files, the wall time and the status (refused, failed, missing) of every run."""
    names = sorted({k for r in records for k in r[3] if k in VARIABLES})
    data = {}
    for n in names:
        per_body = VARIABLES[n].dims == ("body",)
        arr = np.full(shape + ((2,) if per_body else ()), np.nan)
        for s, m, k, vals, *_ in records:
            if n in vals:
                arr[si[s], mi[m], li[k]] = vals[n]
        dims = ("scene", "method_name", "level") + (("body",) if per_body else ())
        data[n] = (dims, arr, variable_attrs(n))
    wt = np.full(shape, np.nan)
    status = np.full(shape, "missing", dtype=object)
    for s, m, k, _, _, w, st in records:
        wt[si[s], mi[m], li[k]] = w
        status[si[s], mi[m], li[k]] = st
    for s, m, k, st, _ in statuses:
        status[si[s], mi[m], li[k]] = st
    data["wall_time"] = (("scene", "method_name", "level"), wt, {"units": "s", "long_name": "best wall time of the solve"})
    data["status"] = (("scene", "method_name", "level"), status,
                      {"units": "1", "long_name": "run status: ok | refused | failed | missing"})
    return data


def _add_sweep_coords(records, statuses, si, n_scenes, data, coords):
    """Add to ``coords`` one coordinate along ``scene`` per swept study key (``sweep_<key>`` when the key is
    also a variable's name); returns {key: coordinate name}."""
    sweeps = {}
    for r in records:
        sweeps.setdefault(r[0], r[4])
    for s in statuses:
        sweeps.setdefault(s[0], dict(s[4]))
    keys = sorted({k for sw in sweeps.values() for k in sw})  # (netCDF does not keep attribute order)
    sweep_names = {}
    for key in keys:
        col = np.full(n_scenes, np.nan, dtype=object)
        for s, sw in sweeps.items():
            if key in sw:
                col[si[s]] = sw[key]
        try:
            col = col.astype(float)
        except (TypeError, ValueError):
            pass
        name = key
        if name in data or name in coords:
            name = "sweep_" + name
        if name in sweep_names.values():
            continue
        sweep_names[key] = name
        coords[name] = ("scene", col, _sweep_coord_attrs(key))
    return sweep_names


def _unstack(ds, names):
    """One dimension per swept parameter (needs every scene to give each of them as a number)."""
    for n in names:
        col = ds[n].values
        if col.dtype.kind != "f" or np.isnan(col).any():
            raise ValueError(f"cannot unstack: swept parameter {n!r} is not a number given for every scene; "
                             "open without unstack=True and select scenes")
    attrs = {n: dict(ds[n].attrs) for n in names}
    ds = ds.assign(scene_name=("scene", ds["scene"].values, {"units": "1", "long_name": "scene name"}))
    out = ds.drop_vars("scene").set_index(scene=names).unstack("scene")
    for n in names:
        out[n].attrs.update(attrs[n])
    out.attrs.update(ds.attrs)
    return out
