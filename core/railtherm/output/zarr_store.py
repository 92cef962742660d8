"""The chunked result store of a study (``[study] store = "zarr"``): ``DIR/results.zarr``.

One Zarr (format 3) group holds every run of a study as rows of arrays indexed by ``run`` (listed in
:func:`create`); run ``i`` is (scene ``i // (M L)``, method ``(i // L) % M``, level ``i % L``) of the
study's scenes, its M methods and L levels (the order of :func:`railtherm.run.runner.make_tasks`). The
``run`` dimension is cut into chunks of whole scenes (:func:`chunk_scenes`); one task runs the runs of
one chunk and writes that chunk of every array itself (:func:`write_chunk`), without a lock: no two tasks
write the same chunk, and zarr's ``LocalStore`` writes each chunk file to a temporary file and renames it.

``status`` and ``run_hash`` of a chunk are written last: a task killed while writing leaves its chunk's
previous status, so that chunk is run again and nothing else is touched; ``--resume`` reads which runs
are done from the store itself (:func:`read_region`). This module imports nothing of railtherm above
``railtherm.contract`` (the output folder's owner, :mod:`railtherm.output.store`, imports it).
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..contract.schema import VARIABLES, variable_attrs
from ..input.scene import key_units

#: the store's folder in a study output folder
ZARR = "results.zarr"
#: run statuses in code order (the same tuple as :data:`railtherm.output.store.STATUSES`; tested)
STATUS_CODES = ("ok", "inaccurate", "unverified", "refused", "failed")
#: reason kinds in code order ("" = none)
REASON_KINDS = ("", "validity", "budget", "error", "not-converged", "timeout", "invalid-input")
RUN_FLOATS = {"wall_time": ("s", "best wall time of the timed solves"),
              "wall_time_median": ("s", "median wall time of the timed solves"),
              "wall_time_cold": ("s", "wall time of the first timed solve (per-scene caches cold)"),
              "peak_rss": ("bytes", "peak resident set size during the first timed solve"),
              "rss_growth": ("bytes", "growth of the resident set during that solve"),
              "energy_balance": ("1", "(heat entering through the surface - frictional power) / frictional power")}
RUN_INTS = {"timing_runs": ("1", "timed solves (repeated while under 0.5 s in all)"), "pid": ("1", "worker process id")}
RUN_STRINGS = {"message": "reason for the status", "energy_reference": "how energy_balance was obtained",
               "run_hash": "hash of scene, method, level, options and code versions (what --resume compares)",
               "run_id": "id of the invocation that wrote the run",
               "diagnostics": "solver diagnostics of the result as JSON"}
#: environment variable of the fault-injection test hook: a worker writing the chunk that starts at this
#: run index ends its process (``os._exit``) after the data and before the status (tests only)
FAULT_ENV = "RAILTHERM_TEST_EXIT_IN_ZARR_WRITE"
#: runs per chunk aimed at (a chunk is whole scenes: at least one scene's runs) and the chunks aimed at
CHUNK_RUNS_MAX = 1000
CHUNK_COUNT = 64


def zarr_path(out) -> Path:
    """``out/results.zarr``."""
    return Path(out) / ZARR


#: separates the store from the run in a run's reference (``RunRecord.path``)
REF_SEP = "#"


def run_ref(out, scene: str, method: str, level: int) -> str:
    """The reference of a stored run: ``DIR/results.zarr#<scene>/<method>/level-<k>``."""
    return f"{zarr_path(out)}{REF_SEP}{scene}/{method}/level-{level}"


def is_ref(path) -> bool:
    return isinstance(path, str) and f"{ZARR}{REF_SEP}" in path


def open_ref(ref: str):
    """The Dataset of the run a reference names (:func:`open_run`)."""
    root, _, rest = ref.partition(REF_SEP)
    scene, method, level = rest.rsplit("/", 2)
    return open_run(Path(root).parent, scene, method, int(level[len("level-"):]))


def is_zarr(out) -> bool:
    """Whether ``out`` holds a Zarr result store."""
    return (zarr_path(out) / "zarr.json").exists()


def scalar_names() -> dict[str, bool]:
    """Every scalar of the result schema: name -> per body (dims ``(body,)``)."""
    return {n: v.dims == ("body",) for n, v in VARIABLES.items() if v.dims in ((), ("body",))}


def chunk_scenes(n_scenes: int, runs_per_scene: int, grid: tuple[int, ...] = ()) -> int:
    """Scenes per chunk: about ``n_runs / CHUNK_COUNT`` runs, at most ``CHUNK_RUNS_MAX`` (at least one scene).

    ``grid``: the sweep's shape when the scenes form one cartesian sweep; a product of its trailing
    sizes is preferred, so that a chunk is a block of the sweep's own dimensions.
    """
    target = max(1, min(CHUNK_RUNS_MAX, math.ceil(n_scenes * runs_per_scene / CHUNK_COUNT)) // runs_per_scene)
    best, prod = 0, 1
    for n in reversed(grid):
        prod *= n
        if prod <= target:
            best = prod
    return max(1, min(best or target, n_scenes))


@dataclass
class Layout:
    """What the store holds: scenes (and their sweeps), methods, levels, chunking, fields kept."""

    scenes: list[str]
    methods: list[str]
    levels: list[int]
    sweeps: list[dict] = field(default_factory=list)
    chunk_scenes: int = 1
    keep_fields: bool | str = False

    @property
    def runs_per_scene(self) -> int:
        return len(self.methods) * len(self.levels)

    @property
    def n_runs(self) -> int:
        return len(self.scenes) * self.runs_per_scene

    @property
    def chunk(self) -> int:
        """Runs per chunk."""
        return self.chunk_scenes * self.runs_per_scene

    def index(self, scene_i: int, method: str, level: int) -> int:
        return (scene_i * len(self.methods) + self.methods.index(method)) * len(self.levels) + self.levels.index(level)

    def key(self) -> str:
        doc = json.dumps([self.scenes, self.methods, self.levels, self.sweeps, self.chunk_scenes,
                          self.keep_fields], default=str)
        return hashlib.sha256(doc.encode()).hexdigest()[:16]


def _sweep_columns(sweeps: list[dict]) -> dict[str, np.ndarray]:
    keys = []
    for sw in sweeps:
        keys += [k for k in sw if k not in keys]
    cols = {}
    for k in keys:
        vals = [sw.get(k) for sw in sweeps]
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
            cols[k] = np.asarray(vals, dtype=float)
        else:
            cols[k] = np.asarray(["" if v is None else json.dumps(v) for v in vals], dtype=object)
    return cols


def create(out, layout: Layout, *, resume: bool = False) -> bool:
    """Create the store's arrays (written by the calling process, before any task runs).

    With ``resume`` an existing store of the same layout is kept (returns False); any other store
    is replaced. Returns True when a new store was created. Arrays::

        <scalar>(run[, body])        every 0-d or (body,) variable of the result schema, float64, NaN = none
        status(run)                  int8: index into STATUS_CODES, -1 = not run (missing)
        reason_kind(run)             int8: index into REASON_KINDS
        message, energy_reference, run_hash, run_id, diagnostics (JSON)  strings
        wall_time, wall_time_median, wall_time_cold, peak_rss, rss_growth, energy_balance   float64
        timing_runs, pid             int32
        scene_name(scene), sweep__<key>(scene), method_name(method_name), level(level)  written here
        fields/s<scene index>/<method>/level-<k>/   the run's fields, when ``keep_fields`` asks
    """
    import zarr  # on first use: ~0.9 s to import, and only a study on the zarr store needs it

    path = zarr_path(out)
    if resume and is_zarr(out):
        try:
            if zarr.open_group(str(path), mode="r").attrs.get("layout") == layout.key():
                return False
        except Exception:  # noqa: BLE001 - an unreadable store is made anew
            pass
    if path.exists():
        shutil.rmtree(path)
    n, c = layout.n_runs, max(1, layout.chunk)
    g = zarr.open_group(str(path), mode="w", zarr_format=3)

    def arr(name, dims, shape, chunks, dtype, fill, attrs):
        return g.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill,
                              dimension_names=list(dims), attributes=attrs)
    for name, per_body in scalar_names().items():
        dims = ("run", "body") if per_body else ("run",)
        arr(name, dims, (n, 2) if per_body else (n,), (c, 2) if per_body else (c,), "f8", np.nan, variable_attrs(name))
    arr("status", ("run",), (n,), (c,), "i1", -1,
        {"units": "1", "long_name": "run status", "flag_values": list(range(len(STATUS_CODES))),
         "flag_meanings": " ".join(STATUS_CODES), "missing": -1})
    arr("reason_kind", ("run",), (n,), (c,), "i1", 0,
        {"units": "1", "long_name": "reason kind", "flag_meanings": " ".join(k or "none" for k in REASON_KINDS)})
    for name, (u, ln) in RUN_FLOATS.items():
        arr(name, ("run",), (n,), (c,), "f8", np.nan, {"units": u, "long_name": ln})
    for name, (u, ln) in RUN_INTS.items():
        arr(name, ("run",), (n,), (c,), "i4", 0, {"units": u, "long_name": ln})
    for name, ln in RUN_STRINGS.items():
        arr(name, ("run",), (n,), (c,), str, "", {"units": "1", "long_name": ln})
    s = len(layout.scenes)
    cs = max(1, layout.chunk_scenes)
    a = arr("scene_name", ("scene",), (s,), (max(cs, min(s, 65536)),), str, "", {"units": "1", "long_name": "scene name"})
    a[:] = np.asarray(layout.scenes, dtype=object)
    a = arr("method_name", ("method_name",), (len(layout.methods),), (max(1, len(layout.methods)),), str, "",
            {"units": "1", "long_name": "method"})
    a[:] = np.asarray(layout.methods, dtype=object)
    a = arr("level", ("level",), (len(layout.levels),), (max(1, len(layout.levels)),), "i4", 0,
            {"units": "1", "long_name": "resolution level"})
    a[:] = np.asarray(layout.levels, dtype="i4")
    keys = []
    for k, col in _sweep_columns(layout.sweeps).items():
        a = arr(f"sweep__{k}", ("scene",), (s,), (max(cs, min(s, 65536)),), col.dtype if col.dtype.kind == "f" else str,
                np.nan if col.dtype.kind == "f" else "", {"units": "1", "long_name": f"swept study key '{k}'", "key": k})
        a[:] = col
        keys.append(k)
    g.attrs.update({"layout": layout.key(), "n_runs": n, "chunk": c, "chunk_scenes": cs,
                    "runs_per_scene": layout.runs_per_scene, "sweep_keys": keys, "keep_fields": layout.keep_fields,
                    "Conventions": "CF-1.11", "title": "railtherm result store"})
    return True


_ARRAYS: dict = {}


def _group(out, mode="r+"):
    import zarr  # on first use: ~0.9 s to import, and only a study on the zarr store needs it
    return zarr.open_group(str(zarr_path(out)), mode=mode)


def _arrays(out) -> dict:
    """The store's per-run arrays, opened once per process."""
    key = str(Path(out).resolve())
    got = _ARRAYS.get(key)
    if got is None or got[0] != _stamp(out):
        g = _group(out)
        got = (_stamp(out), {name: a for name, a in g.arrays() if a.metadata.dimension_names[0] == "run"},
               dict(g.attrs))
        _ARRAYS[key] = got
    return got[1]


def _stamp(out):
    try:
        return (zarr_path(out) / "zarr.json").stat().st_mtime_ns
    except OSError:
        return None


def attrs(out) -> dict:
    """Global attributes of the store (layout key, chunk size, sweep keys, ...)."""
    return dict(_group(out, "r").attrs)


def _set_all(arrays: dict, cols: dict, sel: slice) -> None:
    """Write ``cols`` into rows ``sel`` of their arrays, concurrently (zarr's asynchronous arrays)."""
    # zarr's own event loop, loaded with zarr on first use (as in create)
    import asyncio
    from zarr.core.sync import sync

    async def write_all():
        await asyncio.gather(*(arrays[k]._async_array.setitem(sel, v) for k, v in cols.items()))
    try:
        sync(write_all())
    except AttributeError:  # pragma: no cover - a zarr without Array._async_array
        for k, v in cols.items():
            arrays[k][sel] = v


def write_chunk(out, start: int, cols: dict, *, worker: bool = False) -> tuple[float, int]:
    """Write one chunk (rows ``start:start + len``) of every array in ``cols``, status and run hash last.

    ``worker``: called by the task that ran the chunk (only there does the test hook :data:`FAULT_ENV` act).

    Returns (seconds, bytes of the chunk files written).
    """
    t0 = time.perf_counter()
    arrays = _arrays(out)
    last = ("status", "run_hash")
    n = len(next(iter(cols.values())))
    _set_all(arrays, {k: v for k, v in cols.items() if k not in last}, slice(start, start + n))
    if worker and os.environ.get(FAULT_ENV) == str(start):  # test hook: a worker killed in the middle of a write
        os._exit(71)
    _set_all(arrays, {k: cols[k] for k in last if k in cols}, slice(start, start + n))
    took = time.perf_counter() - t0
    chunk_id = start // max(1, int(next(iter(arrays.values())).chunks[0]))
    size = 0
    for name in cols:
        d = zarr_path(out) / name / "c" / str(chunk_id)
        try:
            size += d.stat().st_size if d.is_file() else sum(p.stat().st_size for p in d.rglob("*") if p.is_file())
        except OSError:
            pass
    return took, size


def read_region(out, start: int, stop: int, names=None) -> dict:
    """Rows ``start:stop`` of the per-run arrays (``names``: which; default all) as numpy arrays."""
    arrays = _arrays(out)
    return {k: np.asarray(a[start:stop]) for k, a in arrays.items() if names is None or k in names}


def empty_rows(out, n: int) -> dict:
    """A chunk's columns as the store's fill values (what a run that has not run holds)."""
    cols = {}
    for k, a in _arrays(out).items():
        shape = (n,) + tuple(a.shape[1:])
        if a.dtype.kind == "f":
            cols[k] = np.full(shape, np.nan)
        elif a.dtype.kind in "iu":
            cols[k] = np.full(shape, a.fill_value, dtype=a.dtype)
        else:
            cols[k] = np.full(shape, "", dtype=object)
    return cols


def status_text(code) -> str:
    c = int(code)
    return STATUS_CODES[c] if 0 <= c < len(STATUS_CODES) else "missing"


def row_of(cols: dict, j: int, scalars: bool = True) -> dict:
    """Row ``j`` of a chunk's columns as plain Python values (status and reason kind decoded)."""
    out = {}
    names = scalar_names()
    for k, v in cols.items():
        x = v[j]
        if k == "status":
            out[k] = status_text(x)
        elif k == "reason_kind":
            out[k] = REASON_KINDS[int(x)] if 0 <= int(x) < len(REASON_KINDS) else ""
        elif k in names:
            if scalars:
                out[k] = np.asarray(x, dtype=float)
        elif isinstance(x, (np.floating, float)):
            out[k] = float(x)
        elif isinstance(x, (np.integer, int)):
            out[k] = int(x)
        else:
            out[k] = str(x)
    return out


def set_row(cols: dict, j: int, row: dict) -> None:
    """Fill row ``j`` of a chunk's columns from ``row`` (status and reason kind as text)."""
    for k, v in row.items():
        if k not in cols:
            continue
        if k == "status":
            v = STATUS_CODES.index(v) if v in STATUS_CODES else -1
        elif k == "reason_kind":
            v = REASON_KINDS.index(v) if v in REASON_KINDS else 0
        cols[k][j] = v


# -- fields ------------------------------------------------------------------------------------------------
def fields_group(scene_i: int, method: str, level: int) -> str:
    return f"fields/s{scene_i}/{method}/level-{level}"


def write_fields(out, scene_i: int, method: str, level: int, ds) -> None:
    """Write the non-scalar variables of a result ``ds`` (and its coordinates) as their own arrays."""
    names = [n for n, v in ds.data_vars.items() if v.dims not in ((), ("body",))]
    if not names:
        return
    sub = ds[names]
    sub.attrs = {}
    if "body" in sub.coords:  # variable-length strings (zarr 3 has no stable fixed-length string type)
        sub = sub.assign_coords(body=sub["body"].astype(object))
    sub.to_zarr(str(zarr_path(out)), group=fields_group(scene_i, method, level), mode="w", zarr_format=3,
                consolidated=False)


def read_fields(out, scene_i: int, method: str, level: int):
    """The kept fields of a run (loaded), or None."""
    import xarray as xr  # on first use: ~0.5 s to import
    p = zarr_path(out) / fields_group(scene_i, method, level)
    if not (p / "zarr.json").exists():
        return None
    with xr.open_zarr(str(zarr_path(out)), group=fields_group(scene_i, method, level), consolidated=False,
                      chunks=None) as ds:
        return ds.load()


def remove_partial(out) -> None:
    """Remove temporary chunk files (``*.partial``) left by workers killed mid-write."""
    root = zarr_path(out)
    if root.is_dir():
        for p in root.rglob("*.partial"):
            p.unlink(missing_ok=True)


# -- reading ---------------------------------------------------------------------------------------------
@dataclass
class Table:
    """The whole per-run table of a store, in memory (a few hundred bytes per run)."""

    scenes: list[str]
    methods: list[str]
    levels: list[int]
    sweeps: list[dict]
    cols: dict

    def index(self, scene: str, method: str, level: int) -> int | None:
        si = self._si.get(scene)
        if si is None or method not in self.methods or level not in self.levels:
            return None
        return (si * len(self.methods) + self.methods.index(method)) * len(self.levels) + self.levels.index(level)

    def __post_init__(self):
        self._si = {s: i for i, s in enumerate(self.scenes)}


_TABLES: dict = {}


def _coords(g) -> tuple[list, list, list, list]:
    scenes = [str(s) for s in np.asarray(g["scene_name"][:])]
    methods = [str(s) for s in np.asarray(g["method_name"][:])]
    levels = [int(k) for k in np.asarray(g["level"][:])]
    sweeps = [dict() for _ in scenes]
    for k in g.attrs.get("sweep_keys", []):
        col = np.asarray(g[f"sweep__{k}"][:])
        for i, v in enumerate(col):
            if col.dtype.kind == "f":
                if not math.isnan(v):
                    sweeps[i][k] = float(v)
            elif str(v):
                sweeps[i][k] = json.loads(str(v))
    return scenes, methods, levels, sweeps


def read_table(out) -> Table:
    """Every run of the store as numpy columns (cached while the store's status does not change)."""
    key = str(Path(out).resolve())
    try:
        stamp = (_stamp(out), (zarr_path(out) / "status" / "c").stat().st_mtime_ns)
    except OSError:
        stamp = (_stamp(out), None)
    got = _TABLES.get(key)
    if got is not None and got[0] == stamp:
        return got[1]
    g = _group(out, "r")
    scenes, methods, levels, sweeps = _coords(g)
    cols = {name: np.asarray(a[:]) for name, a in g.arrays() if a.metadata.dimension_names[0] == "run"}
    table = Table(scenes, methods, levels, sweeps, cols)
    _TABLES[key] = (stamp, table)
    return table


def run_row(out, scene: str, method: str, level: int) -> dict | None:
    """The stored row of one run (status decoded), or None when the store has no such run."""
    t = read_table(out)
    i = t.index(scene, method, level)
    return None if i is None else row_of(t.cols, i)


def run_attrs(out, scene: str, method: str, level: int) -> dict:
    """What a run file's global attributes would say of a stored run: scene, method, level, sweep, ..."""
    t = read_table(out)
    i = t.index(scene, method, level)
    if i is None or t.cols["status"][i] < 0:
        return {}
    row = row_of(t.cols, i, scalars=False)
    d = json.loads(row.get("diagnostics") or "{}")
    return {"scene": scene, "method": method, "level": level, "status": row["status"],
            "sweep": json.dumps(t.sweeps[t._si[scene]]), "wall_time": row["wall_time"],
            "wall_time_median": row["wall_time_median"], "wall_time_cold": row.get("wall_time_cold", math.nan),
            "run_hash": row["run_hash"], "run_id": row["run_id"],
            "stages": d.pop("_stages", ""), **d}


def open_run(out, scene: str, method: str, level: int):
    """A stored run as a Dataset: its scalars (with the schema's attributes), fields when kept; or None."""
    import xarray as xr  # on first use: ~0.5 s to import

    t = read_table(out)
    i = t.index(scene, method, level)
    if i is None or status_text(t.cols["status"][i]) not in STATUS_CODES[:3]:   # a run with a result
        return None
    data = {}
    for name, per_body in scalar_names().items():
        v = t.cols[name][i]
        if np.isnan(v).all():
            continue
        data[name] = (("body",) if per_body else (), np.asarray(v, dtype=float), variable_attrs(name))
    ds = xr.Dataset(data, coords={"body": ("body", np.array(["wheel", "rail"]))} if any(
        d[0] for d in data.values()) else None)
    fields = read_fields(out, t._si[scene], method, level)
    if fields is not None:
        ds = xr.merge([fields, ds], compat="override", combine_attrs="drop")
    ds.attrs.update(run_attrs(out, scene, method, level))
    return ds


def sweeps(out) -> dict:
    """Scene name -> sweep of every scene of the store."""
    t = read_table(out)
    return dict(zip(t.scenes, t.sweeps))


def cartesian(cols: dict) -> tuple[list[str], list[np.ndarray]] | None:
    """(keys, values of each) when the scenes' sweep columns (key -> float array along scene) are exactly
    their keys' cartesian product in C order (as a swept ``[[scene]]`` expands), else None."""
    keys = list(cols)
    if not keys or any(np.asarray(c).dtype.kind != "f" or np.isnan(c).any() for c in cols.values()):
        return None
    n = len(cols[keys[0]])
    values = []
    for k in keys:
        u, first = np.unique(cols[k], return_index=True)
        values.append(u[np.argsort(first)])
    if math.prod(len(v) for v in values) != n:
        return None
    idx = np.indices([len(v) for v in values]).reshape(len(keys), -1)
    for k, v, ix in zip(keys, values, idx):
        if not np.array_equal(v[ix], cols[k]):
            return None
    return keys, values


def _written(out, name: str) -> bool:
    d = zarr_path(out) / name / "c"
    return d.is_dir() and any(d.iterdir())


def open_lazy(out, *, variables=None, unstack: bool | None = None):
    """The store as an xarray Dataset backed by dask: nothing but the coordinates is read.

    Dimensions ``scene``, ``method_name``, ``level`` (and ``body``) as :func:`railtherm.open_results`
    gives them for a run folder; with ``unstack`` (default: when the scenes are one cartesian sweep)
    ``scene`` becomes one dimension per swept study key, so that ``ds.max_surface_temperature.sel(speed=30)``
    reads only the chunks it needs. Runs not run are NaN with status ``missing``.
    """
    import xarray as xr  # on first use: ~0.5 s to import

    path = str(zarr_path(out))
    g = _group(out, "r")
    gattrs = dict(g.attrs)
    raw = xr.open_zarr(path, chunks={}, consolidated=False, mask_and_scale=False)
    methods = [str(s) for s in np.asarray(g["method_name"][:])]
    levels = [int(k) for k in np.asarray(g["level"][:])]
    S, M, L = raw.sizes["scene"], len(methods), len(levels)
    wanted = set(variables) if variables is not None else None
    data = {}
    for name, per_body in scalar_names().items():
        if (wanted is not None and name not in wanted) or not _written(out, name):
            continue
        v = raw[name]
        data[name] = (("scene", "method_name", "level") + (("body",) if per_body else ()),
                      v.data.reshape((S, M, L) + ((2,) if per_body else ())), dict(v.attrs))
    data["wall_time"] = (("scene", "method_name", "level"), raw["wall_time"].data.reshape(S, M, L),
                         {"units": "s", "long_name": "best wall time of the solve"})
    names = np.asarray(STATUS_CODES + ("missing",), dtype=object)
    status = raw["status"].data.map_blocks(lambda b: names[np.asarray(b, dtype=int)], dtype=object)
    data["status"] = (("scene", "method_name", "level"), status.reshape(S, M, L),
                      {"units": "1", "long_name": "run status: ok | refused | failed | missing"})
    coords = {"scene": ("scene", raw["scene_name"].data, {"units": "1", "long_name": "scene name"}),
              "method_name": ("method_name", np.array(methods, dtype=object), {"units": "1", "long_name": "method"}),
              "level": ("level", np.array(levels, dtype="int32"), {"units": "1", "long_name": "resolution level"}),
              "body": ("body", np.array(["wheel", "rail"]), {"units": "1", "long_name": "body"})}
    cols, sweep_names = {}, {}
    for k in gattrs.get("sweep_keys", []):
        cols[k] = np.asarray(g[f"sweep__{k}"][:])
        sweep_names[k] = "sweep_" + k if k in data or k in coords else k
    for k, n in sweep_names.items():
        col = cols[k] if cols[k].dtype.kind == "f" else np.asarray(cols[k], dtype=object)
        coords[n] = ("scene", col, {"units": key_units(k) or "1", "long_name": f"swept study key '{k}'"})
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"Conventions": "CF-1.11", "title": f"railtherm results of {Path(out).name}",
                     "source": f"railtherm open_results of {path} (zarr store)",
                     "swept_parameters": " ".join(sweep_names.values())})
    grid = cartesian(cols) if sweep_names else None
    if unstack and grid is None and sweep_names:
        raise ValueError("cannot unstack: the scenes of this store are not one cartesian sweep of numbers; "
                         "open without unstack=True and select scenes")
    if grid is None or unstack is False:
        return ds
    keys, values = grid
    shape = tuple(len(v) for v in values)
    dims = tuple(sweep_names[k] for k in keys)
    out_vars = {}
    for name, v in ds.data_vars.items():
        out_vars[name] = (dims + v.dims[1:], v.data.reshape(shape + v.shape[1:]), v.attrs)
    new_coords = {sweep_names[k]: (sweep_names[k], np.asarray(vals), ds[sweep_names[k]].attrs)
                  for k, vals in zip(keys, values)}
    new_coords.update({c: ds[c].variable for c in ("method_name", "level", "body")})
    new_coords["scene_name"] = (dims, raw["scene_name"].data.reshape(shape),
                                {"units": "1", "long_name": "scene name"})
    res = xr.Dataset(out_vars, coords=new_coords)
    res.attrs.update(ds.attrs)
    return res
