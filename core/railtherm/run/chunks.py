"""Runs of a study written to the Zarr store (``[study] store = "zarr"``): one task per chunk.

A :class:`ChunkTask` is the runs of whole scenes that fill one chunk of the store
(:mod:`railtherm.output.zarr_store`); :func:`railtherm.run.runner.execute_chunk` runs them in one worker
and writes the chunk once. This module holds what needs no runner: the store's layout of a list of
run tasks, the chunk tasks, and the translation between run records and rows of the store.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..output import store, zarr_store


def layout_of(tasks, keep_fields=False) -> zarr_store.Layout:
    """The store layout of run tasks in :func:`railtherm.run.runner.make_tasks` order (scene, method, level)."""
    scenes, methods, levels = [], [], []
    for t in tasks:
        if not scenes or scenes[-1] is not t.scene:
            scenes.append(t.scene)
        if t.method not in methods:
            methods.append(t.method)
        if t.level not in levels:
            levels.append(t.level)
    sweeps = [dict(s.sweep) for s in scenes]
    cart = zarr_store.cartesian({k: np.asarray([sw.get(k, np.nan) for sw in sweeps], dtype=float)
                                 for k in sweeps[0]}) if sweeps and sweeps[0] and all(
        all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in sw.values()) for sw in sweeps) else None
    grid = tuple(len(v) for v in cart[1]) if cart else ()
    lay = zarr_store.Layout([s.name for s in scenes], methods, levels, sweeps, keep_fields=keep_fields)
    if len(tasks) != lay.n_runs or any(
            t.method != lay.methods[(i // len(levels)) % len(methods)] or t.level != lay.levels[i % len(levels)]
            for i, t in enumerate(tasks)):
        raise ValueError("run tasks are not every (scene, method, level) in order; the Zarr store needs make_tasks'")
    lay.chunk_scenes = zarr_store.chunk_scenes(len(scenes), lay.runs_per_scene, grid)
    return lay


@dataclass
class ChunkTask:
    """The runs of one chunk of the store (picklable: sent to worker processes and dask workers)."""

    tasks: list
    start: int
    out: str
    keep_fields: bool | str = False
    #: scene index (in the study) of each run
    scene_index: list = field(default_factory=list)
    run_id: str = ""
    run_started: float = 0.0

    @property
    def timeout(self) -> float:
        """Time limit of the whole chunk [s]: the sum of its runs' (each run has its own inside)."""
        return float(sum(t.timeout for t in self.tasks))

    @property
    def path(self) -> Path:
        return zarr_store.zarr_path(self.out)

    def ref(self, j: int) -> str:
        t = self.tasks[j]
        return zarr_store.run_ref(self.out, t.scene.name, t.method, t.level)

    def done(self, cols: dict, resume: bool) -> list[bool]:
        """Which runs of the chunk are done: written by this invocation (a retry after its worker died),
        or with ``resume`` an ok or refused run of the same run hash."""
        out = []
        for j, t in enumerate(self.tasks):
            status = zarr_store.status_text(cols["status"][j])
            if status == "missing":
                out.append(False)
            elif t.run_id and str(cols["run_id"][j]) == t.run_id:
                out.append(True)
            else:
                out.append(resume and not t.duplicate and status in ("ok", "refused")
                           and str(cols["run_hash"][j]) == t.run_hash)
        return out

    def record(self, j: int, cols: dict, record_values, resumed: bool = True) -> store.RunRecord:
        """The run record of row ``j`` of the chunk's columns."""
        t = self.tasks[j]
        row = zarr_store.row_of(cols, j)
        diag = json.loads(row.get("diagnostics") or "{}")
        diag.pop("_stages", None)
        values = {}
        for name in record_values:
            v = row.get(name)
            if v is not None and not np.isnan(v).all():
                values[name] = float(v) if v.ndim == 0 else [float(x) for x in v]
        ok = row["status"] == "ok"
        return store.RunRecord(t.scene.name, t.method, t.level, row["status"], row["message"],
                               wall_time=row["wall_time"], peak_rss=row["peak_rss"], rss_growth=row["rss_growth"],
                               timing_runs=row["timing_runs"], path=self.ref(j), scene_hash=t.scene.hash,
                               run_hash=row["run_hash"], wall_time_median=row["wall_time_median"],
                               wall_time_cold=row.get("wall_time_cold", math.nan),
                               reason_kind=row["reason_kind"], diagnostics=diag, resumed=resumed,
                               run_id=row["run_id"], energy_balance=row["energy_balance"] if ok else math.nan,
                               energy_reference=row["energy_reference"] if ok else "", values=values if ok else {},
                               summary=ok, pid=row["pid"], sweep=dict(t.scene.sweep))

    def crash(self, message: str, kind: str = "error") -> list:
        """Record the runs of a chunk whose worker could not report (it died or was ended) as failed,
        in the store, except those this invocation had written; returns the chunk's records."""
        n = len(self.tasks)
        cols = zarr_store.read_region(self.out, self.start, self.start + n)
        done = self.done(cols, resume=False)
        recs = []
        for j, t in enumerate(self.tasks):
            if not done[j]:
                zarr_store.set_row(cols, j, {"status": "failed", "reason_kind": kind, "message": message,
                                             "run_hash": t.run_hash, "run_id": t.run_id})
        if not all(done):
            zarr_store.write_chunk(self.out, self.start, cols)
        for j in range(n):
            rec = self.record(j, cols, (), resumed=done[j])
            if not done[j]:
                rec.scene_hash, rec.sweep = self.tasks[j].scene.hash, dict(self.tasks[j].scene.sweep)
            recs.append(rec)
        return recs


def make_chunks(tasks, layout: zarr_store.Layout, out) -> list[ChunkTask]:
    """Cut run tasks (make_tasks order) into one :class:`ChunkTask` per chunk of the store."""
    c = layout.chunk
    per = layout.runs_per_scene
    return [ChunkTask(tasks[i:i + c], i, str(out), layout.keep_fields, [(i + j) // per for j in range(len(tasks[i:i + c]))])
            for i in range(0, len(tasks), c)]


def row_of_record(rec: store.RunRecord, ds=None) -> dict:
    """The store's row of a run record (and the scalars of its result ``ds``)."""
    row = {"status": rec.status, "reason_kind": rec.reason_kind, "message": rec.message,
           "wall_time": rec.wall_time, "wall_time_median": rec.wall_time_median,
           "wall_time_cold": rec.wall_time_cold, "peak_rss": rec.peak_rss,
           "rss_growth": rec.rss_growth, "energy_balance": rec.energy_balance,
           "energy_reference": rec.energy_reference, "run_hash": rec.run_hash, "run_id": rec.run_id,
           "timing_runs": rec.timing_runs, "pid": rec.pid}
    diag = dict(rec.diagnostics)
    if ds is not None:
        diag["_stages"] = str(ds.attrs.get("stages", ""))
        for name, var in ds.variables.items():
            if var.dims in ((), ("body",)) and name in zarr_store.scalar_names():
                row[name] = np.asarray(var.values, dtype=float)
    row["diagnostics"] = json.dumps(diag)
    return row
