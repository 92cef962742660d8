"""Differences between the ``metrics.nc`` of two study runs (``railtherm diff BEFORE AFTER``).

Used to show that a refactor gives the same numbers: runs are matched by (scene, method, level), the
other dimensions by their coordinate labels; measurements of the machine (wall times, memory) are left
out by default. Each difference names the variable, what differs (values beyond a relative tolerance,
finite in one file only, text), how many entries and an example.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

__all__ = ["Difference", "MACHINE_VARIABLES", "diff_metrics"]

#: variables that measure the machine, not the numbers (left out unless asked for)
MACHINE_VARIABLES = frozenset({"wall_time", "wall_time_median", "peak_rss", "rss_growth", "timing_runs"})


@dataclass
class Difference:
    """One variable that differs between two metrics files."""

    variable: str
    kind: str                 # "only before" | "only after" | "values" | "finite in one only" | "text"
    count: int = 0            # entries that differ
    max_rel: float = 0.0      # largest relative difference of the values finite in both [1]
    example: str = ""
    keys: list = field(default_factory=list)

    def line(self) -> str:
        what = {"values": f"{self.count} values differ, max relative difference {self.max_rel:.3g}",
                "finite in one only": f"{self.count} entries finite in one file only",
                "text": f"{self.count} entries differ"}.get(self.kind, self.kind)
        return f"{self.variable}: {what}" + (f" (e.g. {self.example})" if self.example else "")


def _open(path):
    p = Path(path)
    if p.is_dir():
        p = p / "metrics.nc"
    return xr.load_dataset(p)


def _by_run(ds):
    """The run dimension relabelled by 'scene|method|level' so that two files align run by run."""
    if "run" not in ds.dims or not {"scene", "method", "level"} <= set(ds.variables):
        return ds
    keys = [f"{s}|{m}|{int(k)}" for s, m, k in zip(ds["scene"].values, ds["method"].values, ds["level"].values)]
    return ds.drop_vars([v for v in ("run",) if v in ds.coords]).assign_coords(run=np.array(keys, dtype=object))


def _label(da, index) -> str:
    return ", ".join(f"{d}={da[d].values[i]}" if d in da.coords else f"{d}#{i}" for d, i in zip(da.dims, index))


def diff_metrics(before, after, *, rtol: float = 1e-12, atol: float = 0.0,
                 include_machine: bool = False) -> list[Difference]:
    """The differences between two ``metrics.nc`` files (or output folders).

    Parameters
    ----------
    before, after : path
        ``metrics.nc`` files or the output folders holding them.
    rtol, atol : float
        Two finite numbers count as equal when ``|x - y| <= atol + rtol max(|x|, |y|)`` (``atol`` in the
        variable's units: for relative errors and energy balances near round-off, e.g. 1e-12).
    include_machine : bool
        Also compare wall times and memory (:data:`MACHINE_VARIABLES`).

    Returns
    -------
    list of Difference
        Empty when the numbers are the same.
    """
    a, b = _by_run(_open(before)), _by_run(_open(after))
    skip = set() if include_machine else set(MACHINE_VARIABLES)
    out = [Difference(v, "only before") for v in sorted(set(a.data_vars) - set(b.data_vars) - skip)]
    out += [Difference(v, "only after") for v in sorted(set(b.data_vars) - set(a.data_vars) - skip)]
    for name in sorted((set(a.data_vars) & set(b.data_vars)) - skip):
        x, y = xr.align(a[name], b[name], join="inner")
        xv, yv = np.asarray(x.values), np.asarray(y.values)
        if xv.dtype.kind in "fciu" and yv.dtype.kind in "fciu":
            xv, yv = xv.astype(float), yv.astype(float)
            fx, fy = np.isfinite(xv), np.isfinite(yv)
            # NaN (not scored), +inf (a failing metric) and finite are different kinds of value
            pattern = (fx != fy) | (~fx & ~fy & (np.isnan(xv) != np.isnan(yv))) | (np.isinf(xv) & np.isinf(yv)
                                                                                & (np.sign(xv) != np.sign(yv)))
            if pattern.any():
                i = tuple(int(j) for j in np.argwhere(pattern)[0])
                out.append(Difference(name, "finite in one only", int(pattern.sum()),
                                      example=f"{_label(x, i)}: {xv[i]!r} -> {yv[i]!r}"))
            both = fx & fy
            xv, yv = np.where(both, xv, 0.0), np.where(both, yv, 0.0)
            scale = np.maximum(np.abs(xv), np.abs(yv))
            rel = np.where(both & (scale > 0), np.abs(xv - yv) / np.where(scale > 0, scale, 1.0), 0.0)
            bad = both & (np.abs(xv - yv) > atol + rtol * scale)
            if bad.any():
                i = tuple(int(j) for j in np.unravel_index(int(np.argmax(rel)), rel.shape))
                rel = np.where(bad, rel, 0.0)
                i = tuple(int(j) for j in np.unravel_index(int(np.argmax(rel)), rel.shape))
                out.append(Difference(name, "values", int(bad.sum()), float(rel.max()),
                                      example=f"{_label(x, i)}: {xv[i]!r} -> {yv[i]!r}"))
        else:
            bad = np.asarray(xv.astype(str) != yv.astype(str))
            if bad.any():
                i = tuple(int(j) for j in np.argwhere(bad)[0]) if bad.ndim else ()
                out.append(Difference(name, "text", int(bad.sum()),
                                      example=f"{_label(x, i)}: {xv[i]!r} -> {yv[i]!r}" if i else ""))
    missing = set(a.sizes) ^ set(b.sizes)
    for dim in sorted(set(a.sizes) & set(b.sizes)):
        if dim in a.coords and dim in b.coords:
            la, lb = set(map(str, a[dim].values)), set(map(str, b[dim].values))
            if la != lb:
                out.append(Difference(f"<{dim}>", f"labels only before: {sorted(la - lb)[:5]}; only after: "
                                                  f"{sorted(lb - la)[:5]}", len(la ^ lb)))
    out += [Difference(f"<{d}>", "dimension in one file only") for d in sorted(missing)]
    return [d for d in out if not (d.kind == "values" and math.isnan(d.max_rel))]
