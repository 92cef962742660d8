"""The study output folder: its layout, atomic writes, one reader, run records and crash records.

The only code that knows where things live in the output folder of ``railtherm run`` and how they are
written and read; every other layer goes through it, and it imports only the layers below it::

    DIR/runs/<scene>/<method>/level-<k>.nc           one result (xarray Dataset, netCDF4)
    DIR/runs/<scene>/<method>/level-<k>.status.json  a refused or failed run (a RunRecord as JSON)
    DIR/results.zarr/      instead of runs/ with ``[study] store = "zarr"`` (:mod:`.zarr_store`)
    DIR/metrics.nc, DIR/references.nc   verdicts and errors of every run; exact curves, a group per scene
    DIR/study.json         the invocation: study, timing, run records
    DIR/report.md, DIR/report.html, DIR/figures/      the report

Every file is written to ``.<name>.<pid>.<thread>.tmp`` beside it and renamed into place
(:func:`write_atomic`); :func:`remove_stale_tmp` removes those a killed worker left.
"""
from __future__ import annotations

import json
import os
import threading
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from ..contract.patch_grid import patch_field, patch_numbers  # a run's fields patch by patch, for readers
from ..contract.schema import SWEEP_ATTR, encode_sweep
from . import zarr_store

#: run statuses, in the order reports list them (docs/verdicts.md): the one vocabulary
STATUSES = ("ok", "inaccurate", "unverified", "refused", "failed")
#: the statuses of a run that produced a result
RESULT_STATUSES = STATUSES[:3]

__all__ = ["STATUSES", "RESULT_STATUSES", "RUNS", "METRICS", "REFERENCES", "STUDY", "REPORT_MD", "REPORT_HTML", "FIGURES",
           "run_path", "status_path", "metrics_path", "references_path", "study_path", "figures_dir",
           "run_files", "status_files",
           "write_atomic", "write_atomic_bytes", "write_text_atomic", "write_json_atomic",
           "write_dataset_atomic", "write_references", "remove_stale_tmp",
           "read_attrs", "open_dataset", "open_run", "open_result", "has_store", "run_attributes", "open_store", "read_run_scalars", "read_json", "read_study_info",
           "read_metrics", "read_references", "run_sweeps", "SWEEP_ATTR", "encode_sweep", "sweep_of",
           "patch_field", "patch_numbers",
           "RunRecord", "write_status", "read_status", "crash_record"]

# ----------------------------------------------------------------------------------------------
# layout
RUNS = "runs"
METRICS = "metrics.nc"
REFERENCES = "references.nc"
STUDY = "study.json"
REPORT_MD = "report.md"
REPORT_HTML = "report.html"
FIGURES = "figures"


def run_path(out, scene: str, method: str, level: int) -> Path:
    """``out/runs/<scene>/<method>/level-<level>.nc``."""
    return Path(out) / RUNS / scene / method / f"level-{level}.nc"


def status_path(nc: Path) -> Path:
    """The status record beside a run file: ``level-<k>.status.json``."""
    nc = Path(nc)
    return nc.with_name(nc.stem + ".status.json")


def metrics_path(out) -> Path:
    return Path(out) / METRICS


def references_path(out) -> Path:
    return Path(out) / REFERENCES


def study_path(out) -> Path:
    return Path(out) / STUDY


def figures_dir(out) -> Path:
    return Path(out) / FIGURES


def run_files(out) -> list[Path]:
    """Every run file of an output folder, sorted ([] when there is no ``runs/``)."""
    root = Path(out) / RUNS
    return sorted(root.glob("*/*/level-*.nc")) if root.is_dir() else []


def status_files(out) -> list[Path]:
    """Every status record of an output folder, sorted."""
    root = Path(out) / RUNS
    return sorted(root.glob("*/*/level-*.status.json")) if root.is_dir() else []


# ----------------------------------------------------------------------------------------------
# atomic writes
def _tmp_name(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")


def write_atomic(path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it into place.

    The one implementation of an atomic write: the folder is created, and the temporary file is
    removed whatever happens.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _tmp_name(path)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def write_atomic_bytes(path, data: bytes) -> Path:
    """Write ``data`` atomically (flushed to disk before the rename)."""
    def write(tmp):
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return write_atomic(path, write)


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` (UTF-8) atomically."""
    return write_atomic_bytes(path, text.encode("utf-8"))


def write_json_atomic(path, obj, **kw) -> Path:
    """Write ``json.dumps(obj, **kw)`` atomically."""
    return write_atomic_bytes(path, json.dumps(obj, **kw).encode())


def _attr_ok(v) -> bool:
    if isinstance(v, (bool, np.bool_)):
        return False
    if isinstance(v, (str, int, float, np.integer, np.floating)):
        return True
    return isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind in "if"


def _direct_writable(ds) -> bool:
    """True when :func:`_write_netcdf4` writes ``ds`` exactly as ``xarray.Dataset.to_netcdf`` would."""
    if set(ds.coords) - set(ds.dims):  # non-index coordinates need xarray's 'coordinates' attribute
        return False
    for v in ds.variables.values():
        if v.encoding or "_FillValue" in v.attrs or v.dtype.kind not in "fiU":
            return False
        if not all(_attr_ok(a) for a in v.attrs.values()):
            return False
    return all(_attr_ok(a) for a in ds.attrs.values())


def _write_netcdf4(ds, path) -> None:
    """Write a result with netCDF4-python directly: the file xarray writes, in half the CPU time.

    Float variables get ``_FillValue = NaN`` and strings become variable-length strings, as in
    :meth:`xarray.Dataset.to_netcdf` (engine netcdf4, format NETCDF4); only datasets of those
    dtypes without encodings or non-index coordinates take this path (see :func:`_direct_writable`).
    """
    import netCDF4  # on first use: a study on the zarr store, or a reader of metrics only, needs none

    nc = netCDF4.Dataset(path, "w", format="NETCDF4")
    try:
        _fill_netcdf4(ds, nc)
    finally:
        nc.close()


def _fill_netcdf4(ds, nc) -> None:
    """Write ``ds`` into an open netCDF4 Dataset or Group ``nc`` (see :func:`_write_netcdf4`)."""
    for d, n in ds.sizes.items():
        nc.createDimension(d, n)
    for name, v in ds.variables.items():
        kind = v.dtype.kind
        if kind == "U":
            var = nc.createVariable(name, str, v.dims)
            var.set_auto_maskandscale(False)
            var.setncatts(dict(v.attrs))
            if v.size:
                var[...] = np.asarray(v.values, dtype=object)
            continue
        var = nc.createVariable(name, v.dtype, v.dims, fill_value=np.nan if kind == "f" else None)
        var.set_auto_maskandscale(False)
        var.setncatts(dict(v.attrs))
        if v.ndim == 0:
            var.assignValue(v.values)
        elif v.size:
            var[...] = v.values
    nc.setncatts(dict(ds.attrs))


def write_dataset_atomic(ds, path) -> Path:
    """Write a Dataset as netCDF4 to a temporary file in the same folder, then rename it into place."""
    def write(tmp):
        if _direct_writable(ds):
            _write_netcdf4(ds, tmp)
        else:
            ds.to_netcdf(tmp, engine="netcdf4")
    return write_atomic(path, write)


def write_references(path, attrs: Mapping[str, Any], groups: Mapping[str, Any]) -> Path:
    """Write a reference-curves file atomically: global ``attrs`` and one netCDF4 group per Dataset.

    Written even when ``groups`` is empty, so that a reader can tell "no reference" from "not computed".
    """
    import netCDF4  # on first use: a study on the zarr store, or a reader of metrics only, needs none

    def write(tmp):
        rest = {}
        with netCDF4.Dataset(tmp, "w", format="NETCDF4") as nc:  # one session: reopening per group is O(n^2)
            nc.setncatts(dict(attrs))
            for name, ds in groups.items():
                if _direct_writable(ds):
                    _fill_netcdf4(ds, nc.createGroup(name))
                else:
                    rest[name] = ds
        for name, ds in rest.items():
            ds.to_netcdf(tmp, mode="a", group=name, engine="netcdf4")
    return write_atomic(path, write)


def remove_stale_tmp(folders) -> None:
    """Remove temporary files left by workers killed in the middle of a write (no writer is left)."""
    for d in folders:
        try:
            for p in Path(d).glob(".*.tmp"):
                p.unlink(missing_ok=True)
        except OSError:
            pass


# ----------------------------------------------------------------------------------------------
# reading
def read_attrs(path) -> dict:
    """Global attributes of a netCDF file (netCDF4-python; ten times cheaper than xarray)."""
    import netCDF4  # on first use: a study on the zarr store, or a reader of metrics only, needs none
    with netCDF4.Dataset(path, "r") as nc:
        return {k: nc.getncattr(k) for k in nc.ncattrs()}


def open_dataset(path, **kw):
    """A netCDF file as an xarray Dataset, loaded into memory and the file closed."""
    import xarray as xr  # on first use: ~0.5 s to import
    with xr.open_dataset(path, engine="netcdf4", **kw) as ds:
        return ds.load()


def open_run(out, scene: str, method: str, level: int):
    """The Dataset of one run (loaded), or None when the run has no file (or no result in the Zarr store)."""
    if zarr_store.is_zarr(out):
        return zarr_store.open_run(out, scene, method, level)
    p = run_path(out, scene, method, level)
    return open_dataset(p) if p.exists() else None


def open_result(path):
    """The Dataset of a run from its record's ``path``: a run file, or a run of the Zarr store (loaded)."""
    if zarr_store.is_ref(str(path)):
        return zarr_store.open_ref(str(path))
    return open_dataset(path)


def has_store(out) -> bool:
    """Whether ``out`` keeps its runs in the Zarr store (``results.zarr``) rather than ``runs/``."""
    return zarr_store.is_zarr(out)


def run_attributes(out, scene: str, method: str, level: int) -> dict:
    """Global attributes of a run ({} when it has none): of its file, or what the Zarr store records."""
    if zarr_store.is_zarr(out):
        return zarr_store.run_attrs(out, scene, method, level)
    p = run_path(out, scene, method, level)
    return read_attrs(p) if p.exists() else {}


def open_store(out, *, variables=None, unstack=None):
    """The Zarr store of ``out`` as a lazy (dask-backed) Dataset (:func:`railtherm.output.zarr_store.open_lazy`)."""
    return zarr_store.open_lazy(out, variables=variables, unstack=unstack)


def read_run_scalars(path, variables=None):
    """(global attributes, {name: value}) of a run file: its 0-d and ``(body,)`` variables as floats.

    ``variables``: names to read (default: all such variables). netCDF4-python directly (about 2 ms
    per file; xarray's ``open_dataset`` takes five times longer).
    """
    import netCDF4  # on first use: a study on the zarr store, or a reader of metrics only, needs none
    with netCDF4.Dataset(path, "r") as nc:
        nc.set_auto_maskandscale(False)
        attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
        vals = {}
        for name, var in nc.variables.items():
            if name in nc.dimensions or (variables is not None and name not in variables):
                continue
            if var.dimensions in ((), ("body",)):
                vals[name] = np.asarray(var[...], dtype=float)
    return attrs, vals


def read_json(path):
    """The JSON document at ``path``."""
    return json.loads(Path(path).read_text())


def read_study_info(out) -> dict:
    """``study.json`` of an output folder ({} when it is missing); raises when it is unreadable."""
    p = study_path(out)
    return read_json(p) if p.exists() else {}


def read_metrics(out):
    """``metrics.nc`` of an output folder (loaded); FileNotFoundError saying how to write it."""
    path = metrics_path(out)
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: write it with `railtherm run STUDY.toml --out {out}` first")
    return open_dataset(path)


def read_references(path) -> dict:
    """Scene name -> Dataset of a reference-curves file (one netCDF4 group per scene; loaded)."""
    import netCDF4  # on first use: a study on the zarr store, or a reader of metrics only, needs none
    with netCDF4.Dataset(path, "r") as nc:
        groups = list(nc.groups)
    out = {}
    for g in groups:
        ds = open_dataset(path, group=g)
        out[str(ds.attrs.get("scene", g))] = ds
    return out


# -- the sweep attribute of a run file (written by the pipeline: railtherm.contract.schema.encode_sweep) ----


def sweep_of(attrs) -> dict:
    """The sweep of a run from its global attributes: ``{dotted study key: value}``, read from the JSON
    attribute ``sweep`` ({} without one).

    Raises
    ------
    ValueError
        The attribute is not a JSON object.
    """
    raw = attrs.get(SWEEP_ATTR) if hasattr(attrs, "get") else None
    if raw is None:
        return {}
    raw = raw.decode() if isinstance(raw, bytes) else str(raw)
    try:
        out = json.loads(raw)
    except ValueError as exc:
        raise ValueError(f"run attribute 'sweep' is not JSON ({raw!r}): {exc}") from None
    if not isinstance(out, dict):
        raise ValueError(f"run attribute 'sweep' is not a JSON object: {raw!r}")
    return out


def run_sweeps(out) -> dict:
    """Scene name -> sweep of a study output folder, from the first run file of each scene (or the Zarr store)."""
    if zarr_store.is_zarr(out):
        return zarr_store.sweeps(out)
    found = {}
    for f in run_files(out):
        if f.parent.parent.name in found:
            continue
        try:
            attrs = read_attrs(f)
        except OSError:
            continue
        if "scene" in attrs:
            found[str(attrs["scene"])] = sweep_of(attrs)
    return found


# ----------------------------------------------------------------------------------------------
# run records
@dataclass
class RunRecord:
    """Outcome of one run, as returned by every executor (and stored in ``study.json``)."""

    scene: str
    method: str
    level: int
    status: str
    message: str = ""
    wall_time: float = float("nan")
    #: peak resident set size of the process during the run's first timed solve [bytes] (absolute)
    peak_rss: float = float("nan")
    #: growth of the resident set during that solve [bytes]
    rss_growth: float = float("nan")
    timing_runs: int = 0
    path: str = ""
    scene_hash: str = ""
    #: :func:`railtherm.run.runner.run_hash` of the run (what --resume compares)
    run_hash: str = ""
    #: median of the timed solves [s]
    wall_time_median: float = float("nan")
    #: the first timed solve [s]: a cache a model keeps per scene (e.g. a factorisation) is cold in it
    #: unless the process's warm-up solved the same scene and level
    wall_time_cold: float = float("nan")
    #: refused: "validity" | "budget"; failed: "error" | "not-converged" | "timeout" | "invalid-input"
    reason_kind: str = ""
    #: solver diagnostics of the result (global attributes ``<model>_converged`` etc.)
    diagnostics: dict = field(default_factory=dict)
    resumed: bool = False
    run_id: str = ""
    #: (heat entering through the surface of the computed temperature field - frictional power)
    #: / frictional power [1], and how it was obtained (see :func:`railtherm.analysis.metrics.energy_balance`)
    energy_balance: float = float("nan")
    energy_reference: str = ""
    #: scalar results (RECORD_VALUES present in the result): name -> float or [wheel, rail]
    values: dict = field(default_factory=dict)
    #: True when energy_balance and values were filled from the result (metrics need not open the file)
    summary: bool = False
    #: where the time of this run went [s] (wall): warmup, solve (of which compute: the stages), repeats,
    #: memory, write, total; and cpu: CPU time of the thread that ran it
    phases: dict = field(default_factory=dict)
    #: process id of the worker that ran it
    pid: int = 0
    #: swept parameters of the scene (study key -> value), so that a status record places the run
    sweep: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "RunRecord":
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in names})


def write_status(rec: RunRecord, nc: Path) -> Path:
    """Store a refused or failed run's record beside its (absent) run file ``nc``."""
    return write_atomic_bytes(status_path(nc), json.dumps(rec.to_dict(), indent=1).encode())


def read_status(nc: Path) -> RunRecord:
    """The status record stored beside run file ``nc`` (raises when missing or unreadable)."""
    return RunRecord.from_dict(read_json(status_path(nc)))


def crash_record(task, message: str, kind: str = "error") -> RunRecord:
    """Record and store a run whose worker could not report a result (it died or was ended).

    ``task``: the run (``scene``, ``method``, ``level``, ``path``, ``run_hash``, ``run_id``);
    ``kind``: the failure's reason kind, "error" (the worker died) or "timeout" (it was ended).
    """
    rec = RunRecord(task.scene.name, task.method, task.level, "failed", message, path=str(task.path),
                    scene_hash=task.scene.hash, run_hash=task.run_hash, run_id=task.run_id,
                    sweep=dict(task.scene.sweep), reason_kind=kind)
    write_status(rec, task.path)
    return rec
