"""The study runner: every applicable (scene x method x level), timed, written atomically, resumable.

Each run is executed by :func:`execute_run` (in this process, in local worker processes or on dask
workers: the same function everywhere, so results are identical bit for bit). A run that raises,
exceeds the per-run time limit or returns NaN is recorded as ``failed`` with its message; a scene
outside a method's validity is ``refused``; neither stops the study. Results go to
``<out>/runs/<scene>/<method>/level-<k>.nc`` (temporary file, then rename); refusals and failures
are recorded beside them as ``level-<k>.status.json``. ``resume`` skips runs whose file exists with the same
run hash (scene, method, level, options and code versions, :func:`run_hash`; failed runs are retried).
:mod:`railtherm.output.store` owns the folder's layout, its atomic writes and the run records;
:mod:`railtherm.run.timelimit` the per-run time limit. Timing and memory: see :func:`execute_run`.

Statuses written here: ``ok`` (ran and converged: metrics then decides ok, inaccurate or unverified), ``refused``
(``reason_kind`` validity or budget) and ``failed`` (``reason_kind`` error, not-converged, timeout or invalid-input).
"""
from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
import os
import sys
import time
import traceback
import uuid
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import psutil

from tqdm.auto import tqdm

from .._version import __version__
from ..analysis.metrics import energy_balance
from ..contract.errors import Refused, SceneError, SolverError
from ..contract.options import check_study
from ..contract.schema import history_line
from ..input.scene import Scene
from ..input.study import Study, base_name, load_study
from ..output import store, zarr_store
from ..output.store import RunRecord
from ..physics import body_speeds
from ..report import write_report
from ..solving.plugins import get_host
from .analysis_phase import analyse
from .chunks import layout_of, make_chunks, row_of_record
from .executors import (get_executor, require_optional, resolve_executor, start_worker_server,
                        worker_context)
from .timelimit import RunTimeout, _time_limit
from .timing import TIMING_BUDGET, RSSPeak, compile_watch, freeze_process_objects, more_solves


#: a run-sweep study (``warmup = false``) traces the memory of one run in this many per (method, level)
MEMORY_SAMPLE = 100
#: quantities whose values a record carries, so that metrics need not open the file again
RECORD_VALUES = ("max_surface_temperature", "mean_contact_temperature", "creep_force_x", "max_pressure",
                 "frictional_power", "semi_axis_a", "normal_force", "steady_wheel_temperature",
                 "steady_mean_contact_temperature")


@dataclass
class RunTask:
    """One (scene, method, level) to run; picklable (sent to worker processes and dask workers)."""

    scene: Scene
    method: str
    level: int
    options: dict
    out: str
    repeat: int = 3
    warmup: bool = True
    timeout: float = 600.0
    #: id of the study invocation that runs this task, and when it started (set by :func:`run_tasks`)
    run_id: str = ""
    run_started: float = 0.0
    #: measure peak memory where it costs a separate solve (no ``VmHWM``: a sample of a sweep's runs)
    trace_memory: bool = True
    #: the level the per-process warm-up solves (the study's coarsest)
    warmup_level: int = 0
    #: why this run would repeat another study method's computation (refused, not run); "" otherwise
    duplicate: str = ""
    #: the run's plan refuses it or it is a duplicate: a local-process executor runs it in the parent (it takes
    #: milliseconds; a worker would spend more on the round trip than on the run)
    refused_early: bool = False
    #: the stage models of a chain the study composes (``[study.chains.<method>]``); None: a registered method
    chain: dict | None = None

    @property
    def path(self) -> Path:
        return store.run_path(self.out, self.scene.name, self.method, self.level)

    @property
    def run_hash(self) -> str:
        """Hash of what decides the result: scene, method, level, method options and code versions.

        ``--resume`` reuses a result only when this matches (a result computed with other options
        or another version of railtherm or of the method's plugins is computed again).
        """
        return run_hash(self.scene, self.spec, self.level, self.options)

    @property
    def affinity(self) -> tuple:
        """Runs that may share a model's per-process cache: one method, level and swept scene (sweep members
        keep their geometry unless the sweep changes it, e.g. fem's factorised strip across a creepage sweep).
        A local-process executor gives a free worker the next run of its last run's affinity first."""
        return self.method, self.level, base_name(self.scene.name)

    @property
    def spec(self) -> "str | dict":
        """What :func:`railtherm.solve` takes as ``method``: the name, or the study's chain with its name."""
        return self.method if not self.chain else {"name": self.method, **self.chain}

    def existing(self, *, same_invocation: bool = False) -> "RunRecord | None":
        """The record of this run already on disk with the same run hash, else None (:func:`_existing`).

        Executors call it on a task whose worker died (they never import the runner).
        """
        return _existing(self, same_invocation=same_invocation)


def code_versions(method: "str | Mapping[str, Any]") -> str:
    """railtherm's version and the versions of the plugins behind ``method``: a registered method's name,
    or a study's chain of stage models (``{"name": ..., "normal": "kalker", ...}``), whose every
    candidate model is named with its plugin's version, so that a new plugin version re-runs the chain."""
    try:
        mi = get_host().resolve(method)
    except SceneError:
        return f"railtherm {__version__}"
    parts = {f"{mi.plugin} {mi.version}"} | {f"{m.plugin} {m.version} {c.name} {c.version or ''}"
                                             for m in mi.models for c in m.classes}
    return "; ".join([f"railtherm {__version__}", *sorted(parts)])


def run_hash(scene: Scene, method: "str | Mapping[str, Any]", level: int, options: Mapping[str, Any]) -> str:
    """Hash [hex] of the scene, method (a name, or a study's chain with its stage models), level,
    method options and code versions of one run."""
    doc = {"scene": scene.hash, "method": method if isinstance(method, str) else dict(method), "level": int(level),
           "options": {k: options[k] for k in sorted(options)}, "versions": code_versions(method)}
    return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()[:16]


# ----------------------------------------------------------------------------------------------
def _values(ds) -> dict:
    out = {}
    variables = ds.variables
    for name in RECORD_VALUES:
        var = variables.get(name)
        if var is not None and var.ndim <= 1 and var.size <= 2:
            v = np.asarray(var.values, dtype=float)
            out[name] = float(v) if v.ndim == 0 else [float(t) for t in v]
    return out


#: global attributes of a result that are solver diagnostics (the documented vocabulary)
DIAGNOSTIC_KEYS = ("converged", "iterations", "residual", "heat_balance_error")


def _diagnostics(attrs: Mapping[str, Any]) -> dict:
    out = {}
    for k, v in attrs.items():
        if any(k.endswith(key) for key in DIAGNOSTIC_KEYS):
            if isinstance(v, (int, float, np.integer, np.floating)):
                out[k] = float(v)
    return out


def _summarise(rec: RunRecord, scene: Scene, ds) -> None:
    """Fill the record's energy balance, scalar values and diagnostics from the result ``ds``."""
    rec.energy_balance, rec.energy_reference = energy_balance(
        ds, body_speeds(scene.speed, scene.sliding_speed, scene.tangential), scene.wheel, scene.rail)
    rec.values, rec.diagnostics, rec.summary = _values(ds), _diagnostics(ds.attrs), True


def _record_from_file(task: RunTask, p: Path, attrs: Mapping[str, Any], resumed: bool) -> RunRecord:
    rec = RunRecord(task.scene.name, task.method, task.level, "ok", "",
                    wall_time=float(attrs.get("wall_time", math.nan)), peak_rss=float(attrs.get("peak_rss", math.nan)),
                    rss_growth=float(attrs.get("rss_growth", math.nan)),
                    timing_runs=int(attrs.get("timing_runs", 0)), path=str(p), scene_hash=task.scene.hash,
                    run_hash=str(attrs.get("run_hash", "")),
                    wall_time_median=float(attrs.get("wall_time_median", math.nan)), resumed=resumed,
                    run_id=str(attrs.get("run_id", "")), pid=os.getpid(), sweep=dict(task.scene.sweep))
    try:  # the summary metrics need, read here (in the worker) rather than by metrics (serially)
        _summarise(rec, task.scene, store.open_dataset(p))
    except Exception:  # noqa: BLE001 - metrics will open the file itself
        pass
    return rec


def _existing(task: RunTask, *, same_invocation: bool = False) -> RunRecord | None:
    """A record of a run already on disk with the same :attr:`RunTask.run_hash`, else None.

    ``same_invocation``: only what this invocation (``task.run_id``) wrote, success or failure
    (a retried run never repeats itself); otherwise (``--resume``) any result file and any
    refusal, but not failures (they are retried). A result of the same scene computed with other
    options or another code version has another run hash and is computed again.
    """
    p = task.path
    h = task.run_hash
    if p.exists():
        try:
            attrs = store.read_attrs(p)
        except Exception:  # noqa: BLE001 - an unreadable file is recomputed
            attrs = {}
        if attrs.get("run_hash") == h and (not same_invocation or attrs.get("run_id") == task.run_id):
            return _record_from_file(task, p, attrs, resumed=True)
    sp = store.status_path(p)
    if sp.exists():
        try:
            rec = store.read_status(p)
        except Exception:  # noqa: BLE001
            return None
        if rec.run_hash != h:
            return None
        if (same_invocation and rec.run_id == task.run_id) or (not same_invocation and rec.status == "refused"):
            rec.resumed = True
            return rec
    return None


#: methods solved at least once in this process (their modules and kernels are loaded)
_WARM: set = set()
#: methods solved at least once in this process on a scene with a temperature field (scene key ``field``)
_WARM_FIELD: set = set()


def _written_since(task: RunTask, since: float) -> bool:
    """Whether the run's file or status record was written after ``since`` (a stat, not an open)."""
    for p in (task.path, store.status_path(task.path)):
        try:
            if p.stat().st_mtime >= since:
                return True
        except OSError:
            pass
    return False


def _failure(exc: BaseException, timeout: float) -> tuple[str, str, str]:
    """(status, reason kind, message) of a run that raised ``exc``."""
    if isinstance(exc, Refused):
        return "refused", getattr(exc, "kind", "validity"), str(exc)
    if isinstance(exc, SceneError):
        return "failed", "invalid-input", f"invalid input: {exc}"
    if isinstance(exc, RunTimeout):
        return "failed", "timeout", f"run exceeded the per-run time limit of {timeout:g} s"
    if isinstance(exc, MemoryError):
        return "failed", "error", "out of memory"
    if isinstance(exc, SolverError):
        return "failed", "not-converged", str(exc)
    tb = traceback.extract_tb(exc.__traceback__)
    where = f" at {tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else ""
    return "failed", "error", f"{type(exc).__name__}: {exc}{where}"


def _warm_up(task: RunTask) -> float:
    """Once per method and process: an untimed solve of the study's coarsest level of this scene; once more at
    the method's first scene with a temperature field (scene key ``field``), whose depth fields run kernels
    that a scene without one never reaches (a model's depth-field kernels, e.g. green's Toeplitz weights).

    Imports, numba compilation (or loading from its disk cache) and first-touch costs fall here, not
    in a timed solve; what the process then holds is frozen out of later garbage collections
    (:func:`~railtherm.run.timing.freeze_process_objects`). A warm-up that raises is ignored (the run's
    own solve reports its problem). Returns the time it took [s] (0 when the method was already warm).
    """
    from ..solving.pipeline import solve  # scipy and the plugins: the runner's import stays light for the CLI
    field = getattr(task.scene, "field", None) is not None
    if task.method in _WARM and (not field or task.method in _WARM_FIELD):
        return 0.0
    t0 = time.perf_counter()
    try:
        solve(task.scene, task.spec, task.warmup_level, task.options, validate=False)
    except Exception:  # noqa: BLE001 - the timed solve raises it again if it concerns this run
        pass
    _WARM.add(task.method)
    if field:
        _WARM_FIELD.add(task.method)
    freeze_process_objects()
    return time.perf_counter() - t0


def _measured_solve(task: RunTask, result: bool, memory: bool):
    """One solve, its wall time [s] (what the result's ``wall_time`` measures), whether numba compiled during it,
    and the process's memory during it (:class:`RSSPeak`, or None). ``result``: the run's result, validated;
    otherwise a repeat for the timing only (:func:`~railtherm.solving.pipeline.solve_time`: the same stages,
    no result assembled), and None for the result."""
    from ..solving.pipeline import solve, solve_time  # scipy and the plugins: the runner's import stays light
    mem = RSSPeak() if memory else contextlib.nullcontext()
    with compile_watch() as compiled, mem:
        if result:
            ds = solve(task.scene, task.spec, task.level, task.options, validate=True)
            wall = float(ds.attrs["wall_time"])
        else:
            ds, wall = None, solve_time(task.scene, task.spec, task.level, task.options)
    return ds, wall, bool(compiled), (mem if memory else None)


def _solve_timed(task: RunTask, rec: RunRecord, phases: dict, t_begin: float):
    """Warm up once per method, solve, repeat while short, measure memory (:func:`execute_run`);
    fill ``rec`` and return the result."""

    hwm = RSSPeak.native()  # memory read in the timed solve itself (Linux); else a separate solve
    if task.duplicate:
        raise Refused(task.duplicate, kind="validity")
    with _time_limit(task.timeout):
        # a run its plan refuses raises at its plan below: warming its method up would solve another level of
        # the scene for nothing (in the study's own process, beside the workers)
        phases["warmup"] = 0.0 if task.refused_early else _warm_up(task)
        t0 = time.perf_counter()
        ds, first, compiled, mem = _measured_solve(task, True, hwm)
        phases["solve"] = time.perf_counter() - t0
        phases["compute"] = first
        times, recompiled = ([] if compiled else [first]), int(compiled)
        mem = None if compiled else mem
        t1 = time.perf_counter()
        budget = max(0.0, task.timeout - (time.perf_counter() - t_begin)) / 2
        while (not times or more_solves(times, task.repeat, task.warmup)) and sum(times) + first < budget:
            _, t, compiled, again = _measured_solve(task, False, hwm and mem is None)
            mem = again if again is not None and not compiled else mem
            if compiled:  # compilation is never a timing
                recompiled += 1
                if recompiled > 2:
                    break
                continue
            times.append(t)
        phases["repeats"] = time.perf_counter() - t1
        # every solve this run cost: warm-up, timed solves, solves that compiled (and a memory solve below)
        phases["solves"] = float((phases["warmup"] > 0) + len(times) + recompiled)
        if task.trace_memory and not hwm:
            t2 = time.perf_counter()
            _, _, _, mem = _measured_solve(task, False, True)
            phases["memory"] = time.perf_counter() - t2
            phases["solves"] += 1.0
    times = times or [first]
    if mem is not None:
        rec.peak_rss, rec.rss_growth = mem.peak, mem.growth
    rec.wall_time, rec.wall_time_median, rec.wall_time_cold = min(times), float(np.median(times)), times[0]
    rec.timing_runs = len(times)
    _summarise(rec, task.scene, ds)
    ds.attrs.update({"wall_time": rec.wall_time, "wall_time_median": rec.wall_time_median,
                     "wall_time_cold": rec.wall_time_cold, "peak_rss": rec.peak_rss, "rss_growth": rec.rss_growth,
                     "timing_runs": rec.timing_runs, "status": "ok", "run_id": task.run_id, "run_hash": rec.run_hash})
    how = (f"best and median of {len(times)} timed solve(s) (repeated while under {TIMING_BUDGET:g} s in all,"
           f" at most {task.repeat}); compilation and imports in one warm-up per method and process"
           + (f"; {recompiled} solve(s) that compiled were not timed" if recompiled else ""))
    ds.attrs["history"] = ds.attrs["history"] + "\n" + history_line(f"railtherm run: {how}")
    return ds


def execute_run(task: RunTask, *, resume: bool = False) -> RunRecord:
    """Run one (scene, method, level): warm up, time, measure memory, write atomically.

    The same function runs in every executor, so results are identical bit for bit.

    Timing: the first run of a method in a process is preceded by one untimed warm-up solve of the
    study's coarsest level of its scene (imports, numba compilation, first touch). The result's own
    solve is timed; a verification study (``task.warmup``) repeats it while the timed solves add up to
    under :data:`TIMING_BUDGET` s, at most ``task.repeat`` solves (a solve over 0.5 s is timed once); a
    sweep (``warmup = false``) takes exactly ``task.repeat``. A solve during which numba compiled is
    solved again and not counted. ``wall_time`` is the best, ``wall_time_median`` the median and
    ``wall_time_cold`` the first timed solve (a per-scene cache of a model is cold there).
    Memory: on Linux the kernel's high-water mark, reset before and read after the first timed solve
    (no extra solve, no sampling thread); elsewhere a separate solve sampled by a thread (with
    ``task.trace_memory``), so that the sampling does not perturb the timing.

    Parameters
    ----------
    task : RunTask
        The run; ``task.run_id`` identifies the study invocation (a retry after a worker died
        returns what this invocation already wrote instead of running again).
    resume : bool
        Return the record of a result already on disk with the same run hash (or a refusal).

    Returns
    -------
    RunRecord
        Status (ok | refused | failed; metrics later decides ok, inaccurate or unverified) and
        message, best and median wall time [s], peak RSS and its growth [bytes], energy balance and
        scalar values of the result, and ``phases``: where the time went [s]. Never raises for a
        problem of the run itself.
    """
    t_begin, cpu_begin = time.perf_counter(), time.thread_time()
    if resume and not task.duplicate:
        rec = _existing(task)
        if rec is not None:
            return rec
    if task.run_id and _written_since(task, task.run_started - 2.0):  # a retry finds its own result
        rec = _existing(task, same_invocation=True)
        if rec is not None:
            return rec
    rec = RunRecord(task.scene.name, task.method, task.level, "failed", path=str(task.path),
                    scene_hash=task.scene.hash, run_hash=task.run_hash, run_id=task.run_id, pid=os.getpid(),
                    sweep=dict(task.scene.sweep))
    sp = store.status_path(task.path)
    phases: dict[str, float] = {}
    rec.phases = phases
    try:
        ds = _solve_timed(task, rec, phases, t_begin)
        t3 = time.perf_counter()
        store.write_dataset_atomic(ds, task.path)
        phases["write"] = time.perf_counter() - t3
        rec.status = "ok"
        if sp.exists():
            sp.unlink()
        phases["total"] = time.perf_counter() - t_begin
        phases["cpu"] = time.thread_time() - cpu_begin
        return rec
    except Exception as exc:  # noqa: BLE001 - a failing plugin never takes the study down
        rec.status, rec.reason_kind, rec.message = _failure(exc, task.timeout)
    rec.values, rec.energy_balance, rec.summary = {}, math.nan, False
    if task.path.exists():
        task.path.unlink()
    store.write_status(rec, task.path)
    phases["total"] = time.perf_counter() - t_begin
    phases["cpu"] = time.thread_time() - cpu_begin
    return rec


def execute_chunk(chunk, *, resume: bool = False) -> list[RunRecord]:
    """Run the runs of one chunk of the Zarr store (:class:`railtherm.run.chunks.ChunkTask`) and write
    the chunk once; the same timed solve as :func:`execute_run`, so the values are identical bit for bit.

    Runs already done (by this invocation, or with ``resume`` ok or refused with the same run hash)
    are read from the store and not run again; a chunk whose runs are all done is not written.
    ``phases["write"]`` of each record is the chunk's write time divided by its runs [s], and
    ``phases["bytes"]`` its share of the chunk files written [bytes].
    """

    out, start, n = chunk.out, chunk.start, len(chunk.tasks)
    cols = zarr_store.read_region(out, start, start + n)
    done = chunk.done(cols, resume)
    records: list[RunRecord] = []
    finest: dict = {}
    changed: set = set()  # arrays a run of this chunk set (the others keep what the store holds)
    for j, task in enumerate(chunk.tasks):
        if done[j]:
            records.append(chunk.record(j, cols, RECORD_VALUES))
            continue
        t_begin, cpu_begin = time.perf_counter(), time.thread_time()
        rec = RunRecord(task.scene.name, task.method, task.level, "failed", path=chunk.ref(j),
                        scene_hash=task.scene.hash, run_hash=task.run_hash, run_id=task.run_id, pid=os.getpid(),
                        sweep=dict(task.scene.sweep))
        rec.phases = phases = {}
        ds = None
        try:
            ds = _solve_timed(task, rec, phases, t_begin)
            rec.status = "ok"
        except Exception as exc:  # noqa: BLE001 - a failing plugin never takes the study down
            rec.status, rec.reason_kind, rec.message = _failure(exc, task.timeout)
            rec.values, rec.energy_balance, rec.summary = {}, math.nan, False
        row = row_of_record(rec, ds)
        zarr_store.set_row(cols, j, row)
        changed.update(row)
        if ds is not None and chunk.keep_fields is True:
            zarr_store.write_fields(out, chunk.scene_index[j], task.method, task.level, ds)
        elif ds is not None and chunk.keep_fields == "finest":
            key = (chunk.scene_index[j], task.method)
            if key not in finest or task.level > finest[key][0]:
                finest[key] = (task.level, ds)
        phases["total"] = time.perf_counter() - t_begin
        phases["cpu"] = time.thread_time() - cpu_begin
        records.append(rec)
    for (si, method), (level, ds) in finest.items():
        zarr_store.write_fields(out, si, method, level, ds)
    ran = n - sum(done)
    if ran:
        took, size = zarr_store.write_chunk(out, start, {k: v for k, v in cols.items() if k in changed}, worker=True)
        for j, rec in enumerate(records):
            if not done[j]:
                rec.phases["write"], rec.phases["bytes"] = took / ran, size / n
    return records


# ----------------------------------------------------------------------------------------------
def _progress(total: int, desc: str):
    quiet = not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty())
    return tqdm(total=total, desc=desc, file=sys.stderr, disable=quiet, unit="run")


def make_tasks(study: Study, out, methods: Iterable[str] | None = None, levels: Iterable[int] | None = None
               ) -> list[RunTask]:

    host = get_host()
    chains = dict(getattr(study, "chains", None) or {})
    names = list(methods) if methods else study.method_names(host.methods)
    unknown = [m for m in names if m not in host.methods and m not in chains]
    if unknown:
        raise SceneError(f"study {study.name!r}: unknown method(s) {unknown}; installed: {sorted(host.methods)}"
                         + (f"; plugin problems: {host.problems}" if host.problems else ""),
                         key="study.methods", value=unknown, allowed=str(sorted(host.methods)))
    lv = sorted(set(levels)) if levels is not None else study.levels
    tasks = []
    for i, scene in enumerate(study.scenes):
        for m in names:
            for k in lv:
                tasks.append(RunTask(scene, m, k, dict(study.options.get(m, {})), str(out), study.repeat,
                                     study.warmup, study.timeout,
                                     trace_memory=study.warmup or i % MEMORY_SAMPLE == 0, warmup_level=min(lv),
                                     chain=chains.get(m)))
    _mark_refusals(tasks, host)
    return tasks


def _mark_refusals(tasks: list[RunTask], host) -> None:
    """Mark each task whose plan refuses it (:func:`railtherm.solving.pipeline.plan`: a model's validity or
    capabilities) or whose executed stage models are another study method's on its scene
    (:func:`railtherm.solving.pipeline.duplicate_of`, its reason in ``duplicate``): ``refused_early``, the
    refusal then comes from the run's own solve in the study's process. Every invocation decides afresh from
    the study's current methods (a resumed study never reuses a stale decision). A wheelset on profiles plans
    per patch in its solve: its plan's refusal is never predicted."""
    from ..solving.pipeline import duplicate_of, plan  # scipy and the plugins: see _warm_up
    peers = list({t.method: (t.spec, t.options) for t in tasks}.values())
    for t in tasks:
        refused = False
        if getattr(t.scene, "profile_contact", None) is None:
            try:
                plan(t.scene, host.resolve(t.spec), t.level, host)
            except Refused:
                refused = True
            except Exception:  # noqa: BLE001 - a method that cannot be planned reports that when it runs
                pass
        try:
            t.duplicate = "" if refused or len(peers) < 2 else \
                (duplicate_of(t.scene, t.spec, t.level, peers, t.options, host) or "")
        except Exception:  # noqa: BLE001 - as above
            t.duplicate = ""
        t.refused_early = refused or bool(t.duplicate)


def run_tasks(tasks: list[RunTask], *, executor: str = "serial", scheduler: str | None = None,
              resume: bool = False, workers: int | None = None, desc: str = "railtherm",
              run_id: str | None = None) -> list[RunRecord]:
    """Execute tasks with the chosen executor; records come back in task order.

    Each task gets this invocation's ``run_id`` (a new one unless given), and each file and status record carries
    the ``run_id`` that wrote it: a run executed again within the same invocation (its worker died after writing
    but before reporting back) finds its own result and does not write it again.
    """

    run_id = run_id or uuid.uuid4().hex[:12]
    started = time.time()
    for t in tasks:
        t.run_id, t.run_started = run_id, started
    chunked = bool(tasks) and hasattr(tasks[0], "tasks")  # ChunkTasks of the Zarr store
    for t in tasks:
        for u in getattr(t, "tasks", ()):
            u.run_id, u.run_started = run_id, started
    # refusals known from the plan run in a thread of this process while the workers run the rest: the same
    # execute_run, milliseconds each, without a worker's round trip
    # (never beside runs timed in this process: a serial executor runs every task itself)
    early = [] if chunked else [i for i, t in enumerate(tasks) if t.refused_early]
    if executor == "auto":
        executor, workers = resolve_executor(executor, workers, max(1, len(tasks) - len(early)))
    here = [] if executor == "serial" else early
    away = sorted(set(range(len(tasks))) - set(here))
    ex = get_executor(executor, scheduler=scheduler, workers=workers)
    records: list = [None] * len(tasks)
    total = sum(len(t.tasks) for t in tasks) if chunked else len(tasks)
    with _progress(total, desc) as bar, ThreadPoolExecutor(1, thread_name_prefix="railtherm-refusals") as pool:
        local = pool.submit(lambda: [(i, execute_run(tasks[i], resume=resume)) for i in here])
        remote = ((away[j], rec) for j, rec in ex.map(execute_chunk if chunked else execute_run,
                                                       [tasks[i] for i in away], resume=resume))
        for i, rec in itertools.chain(remote, _deferred(local)):
            records[i] = rec
            if bar is not None:
                last = rec[-1] if isinstance(rec, list) else rec
                bar.update(len(rec) if isinstance(rec, list) else 1)
                bar.set_postfix_str(f"{last.scene[:24]} {last.method} L{last.level} {last.status}", refresh=False)
    if chunked:
        zarr_store.remove_partial(tasks[0].out)
        return [r for rs in records if rs is not None for r in rs]
    store.remove_stale_tmp({Path(t.path).parent for t in tasks})
    return [r for r in records if r is not None]


def _deferred(future):
    """The items of the list ``future`` returns, once it is done (an exception it raised propagates)."""
    yield from future.result()


def _children_cpu() -> float:
    """CPU time [s] of the finished local worker processes, user + system: this process's finished children,
    and those of its living children (the fork server reaps the workers forked from it; psutil reads its
    children's time from /proc)."""
    try:
        import resource  # Unix only
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        total = r.ru_utime + r.ru_stime
    except (ImportError, OSError):  # pragma: no cover
        return math.nan
    try:
        for child in psutil.Process().children(recursive=False):
            try:
                t = child.cpu_times()
                total += getattr(t, "children_user", 0.0) + getattr(t, "children_system", 0.0)
            except psutil.Error:
                pass
    except ImportError:  # pragma: no cover
        pass
    return total


def run_study(study_or_path: Study | str | os.PathLike, out: str | os.PathLike = "out", *, executor: str = "serial",
              scheduler: str | None = None, methods: Iterable[str] | None = None, levels: Iterable[int] | None = None,
              resume: bool = False, report: bool = True, workers: int | None = None):
    """Run a study and write runs, ``metrics.nc`` and the report to ``out``.

    Parameters
    ----------
    study_or_path : Study or path
        A parsed study or the path of a study TOML file.
    out : path
        Output folder.
    executor : {"serial", "processes", "dask", "auto"}
        Where runs execute: this process, local worker processes, or a dask.distributed cluster
        (one task per run); "auto" (the command line's default): local processes, one per core and at
        most one per run (:func:`railtherm.run.executors.resolve_executor`). Results other than timings
        are identical bit for bit.
    scheduler : str, optional
        Address of a dask.distributed scheduler (``executor="dask"``), e.g. ``tcp://10.0.0.5:8786``;
        a LocalCluster is started if None.
    methods, levels : optional
        Restrict the study's methods / levels.
    resume : bool
        Skip runs already written for the same scene hash.
    report : bool
        Write report.md, report.html and figures/ after the runs.
    workers : int, optional
        Number of local worker processes (processes executor, LocalCluster); default: CPU count.

    Returns
    -------
    xarray.Dataset
        The metrics (also written to ``out/metrics.nc``).
    """
    t0, c0, w0 = time.perf_counter(), time.process_time(), _children_cpu()
    if resolve_executor(executor, workers, 2)[0] == "processes":  # not when "auto" will run serially
        start_worker_server(workers)   # its imports overlap the loading and checking of the study below
    study = study_or_path if isinstance(study_or_path, Study) else load_study(study_or_path)
    check_study(study, get_host(), methods=methods, levels=levels)  # everything, before the first task
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SceneError(f"output folder {str(out)!r} is an existing file, not a folder", key="out",
                         value=str(out), allowed="a folder (created if missing)")
    out.mkdir(parents=True, exist_ok=True)
    tasks, kind = _plan_tasks(study, out, methods, levels, resume)
    if executor == "dask":
        require_optional("distributed", "executor", executor)
    executor, workers = resolve_executor(executor, workers, len(tasks))
    t1 = time.perf_counter()
    records = run_tasks(tasks, executor=executor, scheduler=scheduler, resume=resume, workers=workers,
                        desc=study.name)
    t2 = time.perf_counter()
    metrics = analyse(study, out, records, executor, workers, kind)
    t3 = time.perf_counter()
    timing = {"setup": t1 - t0, "runs": t2 - t1, "metrics": t3 - t2, "executor": executor, "store": kind,
              "workers": workers, "runs_total": len(records),
              "cpu_main": time.process_time() - c0, "cpu_local_workers": _children_cpu() - w0,
              "cpu_count": os.cpu_count(), "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}
    env = {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                                          "NUMBA_NUM_THREADS")}
    path = str(Path(study.path).resolve()) if study.path else None
    store.write_json_atomic(store.study_path(out), {"study": study.name, "path": path, "argv": sys.argv,
                                                    "timing": timing, "environment": env,
                                                    "records": [r.to_dict() for r in records]},
                            indent=1, default=str)
    if report:
        write_report(out, study=study, workers=workers if executor == "processes" else 1, context=worker_context())
    return metrics


def _plan_tasks(study: Study, out: Path, methods, levels, resume: bool):
    """The study's run tasks and its store ("files", or "zarr": created, and the runs grouped in its chunks)."""
    tasks = make_tasks(study, out, methods, levels)
    kind = study.store_for(len(tasks)) if hasattr(study, "store_for") else "files"
    if kind == "zarr":
        require_optional("zarr", "study.store", kind)
        layout = layout_of(tasks, getattr(study, "keep_fields", False))
        zarr_store.create(out, layout, resume=resume)
        tasks = make_chunks(tasks, layout, out)
    return tasks, kind
