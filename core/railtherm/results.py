"""Open a study's results as one xarray Dataset."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def open_results(out, *, variables=None):
    """Open the scalar results of every run of a study output folder as one Dataset.

    Dimensions ``scene``, ``method``, ``level`` (and ``body`` for per-body scalars); each swept parameter
    (``sweep_<key>`` attributes of the runs, e.g. ``convection`` or ``creepage_longitudinal``) becomes a
    coordinate along ``scene``. Runs that were refused or failed are NaN.

    Parameters
    ----------
    out : path
        Study output folder (holding ``runs/``).
    variables : iterable of str, optional
        Scalar variables to collect (default: every 0-d or ``(body,)`` variable found).
    """
    import xarray as xr

    from .schema import VARIABLES, variable_attrs

    root = Path(out) / "runs"
    files = sorted(root.glob("*/*/level-*.nc"))
    records = []
    for f in files:
        with xr.open_dataset(f, engine="netcdf4") as ds:
            vals = {k: ds[k].values.copy() for k in ds.data_vars
                    if ds[k].dims in ((), ("body",)) and (variables is None or k in variables)}
            sweep = {k[len("sweep_"):]: v for k, v in ds.attrs.items() if k.startswith("sweep_")}
            records.append((ds.attrs["scene"], ds.attrs["method"], int(ds.attrs["level"]), vals, sweep,
                            float(ds.attrs.get("wall_time", np.nan))))
    scenes = sorted({r[0] for r in records})
    methods = sorted({r[1] for r in records})
    levels = sorted({r[2] for r in records})
    names = sorted({k for r in records for k in r[3]})
    si = {s: i for i, s in enumerate(scenes)}
    mi = {m: i for i, m in enumerate(methods)}
    li = {k: i for i, k in enumerate(levels)}
    shape = (len(scenes), len(methods), len(levels))
    data = {}
    for n in names:
        per_body = VARIABLES[n].dims == ("body",)
        arr = np.full(shape + ((2,) if per_body else ()), np.nan)
        for s, m, k, vals, _, _ in records:
            if n in vals:
                arr[si[s], mi[m], li[k]] = vals[n]
        dims = ("scene", "method", "level") + (("body",) if per_body else ())
        data[n] = (dims, arr, variable_attrs(n))
    wt = np.full(shape, np.nan)
    for s, m, k, _, _, w in records:
        wt[si[s], mi[m], li[k]] = w
    data["wall_time"] = (("scene", "method", "level"), wt, {"units": "s", "long_name": "best wall time of the solve"})
    coords = {"scene": ("scene", np.array(scenes, dtype=object)), "method": ("method", np.array(methods, dtype=object)),
              "level": ("level", np.array(levels, dtype="int32")), "body": ("body", np.array(["wheel", "rail"]))}
    sweep_keys = sorted({k for r in records for k in r[4]})
    for key in sweep_keys:
        col = np.full(len(scenes), np.nan, dtype=object)
        for s, _, _, _, sw, _ in records:
            if key in sw:
                col[si[s]] = sw[key]
        try:
            col = col.astype(float)
        except (TypeError, ValueError):
            pass
        coords[key] = ("scene", col)
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm results of {Path(out).name}"})
    return ds
