"""The study runner: every applicable (scene x method x level), timed, written atomically, resumable.

Each run is executed by :func:`execute_run` (in this process, in local worker processes or on dask
workers: the same function everywhere, so results are identical bit for bit). A run that raises,
exceeds the per-run time limit or returns NaN is recorded as ``failed`` with its message; a scene
outside a method's validity is ``refused``; neither stops the study. Results go to
``<out>/runs/<scene>/<method>/level-<k>.nc`` (temporary file, then rename); refusals and failures
are recorded beside them as ``level-<k>.status.json``. ``resume`` skips runs whose file exists for
the same scene hash (failed runs are retried).
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import time
import traceback
import tracemalloc
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping

from .errors import Refused, SceneError
from .scene import Scene
from .study import Study, load_study

STATUSES = ("ok", "inaccurate", "refused", "failed")


@dataclass
class RunTask:
    scene: Scene
    method: str
    level: int
    options: dict
    out: str
    repeat: int = 3
    warmup: bool = True
    timeout: float = 600.0

    @property
    def path(self) -> Path:
        return run_path(self.out, self.scene.name, self.method, self.level)


@dataclass
class RunRecord:
    scene: str
    method: str
    level: int
    status: str
    message: str = ""
    wall_time: float = float("nan")
    peak_memory: float = float("nan")
    timing_runs: int = 0
    path: str = ""
    scene_hash: str = ""
    resumed: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


def run_path(out, scene: str, method: str, level: int) -> Path:
    return Path(out) / "runs" / scene / method / f"level-{level}.nc"


def status_path(nc: Path) -> Path:
    return nc.with_name(nc.stem + ".status.json")


def write_atomic_bytes(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def write_dataset_atomic(ds, path: Path) -> None:
    """Write a Dataset as netCDF4 to a temporary file in the same folder, then rename it into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


class RunTimeout(Exception):
    pass


@contextlib.contextmanager
def _time_limit(seconds: float):
    """Raise :class:`RunTimeout` after ``seconds`` (SIGALRM; main thread of a POSIX process only)."""
    usable = seconds and seconds > 0 and hasattr(signal, "SIGALRM")
    if usable:
        import threading
        usable = threading.current_thread() is threading.main_thread()
    if not usable:
        yield
        return

    def handler(signum, frame):
        raise RunTimeout(f"run exceeded the per-run time limit of {seconds:g} s")

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _existing(task: RunTask) -> RunRecord | None:
    """A record for a run already written for the same scene hash (``--resume``), else None."""
    p = task.path
    if p.exists():
        try:
            import xarray as xr
            with xr.open_dataset(p, engine="netcdf4") as ds:
                if ds.attrs.get("scene_hash") == task.scene.hash:
                    return RunRecord(task.scene.name, task.method, task.level, "ok", "",
                                     float(ds.attrs.get("wall_time", "nan")), float(ds.attrs.get("peak_memory", "nan")),
                                     int(ds.attrs.get("timing_runs", 0)), str(p), task.scene.hash, resumed=True)
        except Exception:  # noqa: BLE001 - an unreadable file is recomputed
            return None
    sp = status_path(p)
    if sp.exists():
        try:
            rec = json.loads(sp.read_text())
        except Exception:  # noqa: BLE001
            return None
        if rec.get("scene_hash") == task.scene.hash and rec.get("status") == "refused":
            rec["resumed"] = True
            return RunRecord(**rec)
    return None


def execute_run(task: RunTask, *, resume: bool = False) -> RunRecord:
    """Run one (scene, method, level): warm-up, best of ``repeat`` timed solves, atomic write.

    Never raises for a problem of the run itself: the returned record carries the status and message.
    """
    from .pipeline import solve
    from .schema import history_line

    if resume:
        rec = _existing(task)
        if rec is not None:
            return rec
    rec = RunRecord(task.scene.name, task.method, task.level, "failed", path=str(task.path),
                    scene_hash=task.scene.hash)
    sp = status_path(task.path)
    try:
        t_start = time.perf_counter()
        with _time_limit(task.timeout):
            tracemalloc.start()
            try:
                ds = solve(task.scene, task.method, task.level, task.options)
                _, peak = tracemalloc.get_traced_memory()
            finally:
                tracemalloc.stop()
            times = [float(ds.attrs["wall_time"])]
            # best of n after a warm-up (compile time excluded); a slow first run is its own timing
            if task.warmup and task.repeat > 0 and times[0] < 2.0:
                times = []
                budget = max(0.0, task.timeout - (time.perf_counter() - t_start)) / 2
                for _ in range(task.repeat):
                    again = solve(task.scene, task.method, task.level, task.options, validate=False)
                    times.append(float(again.attrs["wall_time"]))
                    if sum(times) > min(budget, 5.0):
                        break
        rec.wall_time = min(times)
        rec.timing_runs = len(times)
        rec.peak_memory = float(peak)
        ds.attrs.update({"wall_time": rec.wall_time, "peak_memory": rec.peak_memory,
                         "timing_runs": rec.timing_runs, "status": "ok"})
        ds.attrs["history"] = ds.attrs["history"] + "\n" + history_line(
            f"railtherm run: best of {len(times)} timed solves after a warm-up")
        write_dataset_atomic(ds, task.path)
        rec.status = "ok"
        if sp.exists():
            sp.unlink()
        return rec
    except Refused as exc:
        rec.status, rec.message = "refused", str(exc)
    except SceneError as exc:
        rec.status, rec.message = "failed", f"invalid input: {exc}"
    except RunTimeout as exc:
        rec.status, rec.message = "failed", str(exc)
    except MemoryError:
        rec.status, rec.message = "failed", "out of memory"
    except Exception as exc:  # noqa: BLE001 - a failing plugin never takes the study down
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" at {tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else ""
        rec.status, rec.message = "failed", f"{type(exc).__name__}: {exc}{where}"
    if task.path.exists() and rec.status != "ok":
        task.path.unlink()
    write_atomic_bytes(sp, json.dumps(rec.to_dict(), indent=1).encode())
    return rec


# ----------------------------------------------------------------------------------------------
def _progress(total: int, desc: str):
    quiet = not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty())
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover
        return contextlib.nullcontext(None)
    return tqdm(total=total, desc=desc, file=sys.stderr, disable=quiet, unit="run")


def make_tasks(study: Study, out, methods: Iterable[str] | None = None, levels: Iterable[int] | None = None
               ) -> list[RunTask]:
    from .plugins import get_host

    host = get_host()
    names = list(methods) if methods else study.method_names(host.methods)
    unknown = [m for m in names if m not in host.methods]
    if unknown:
        raise SceneError(f"study {study.name!r}: unknown method(s) {unknown}; installed: {sorted(host.methods)}"
                         + (f"; plugin problems: {host.problems}" if host.problems else ""),
                         key="study.methods", value=unknown, allowed=str(sorted(host.methods)))
    lv = sorted(set(levels)) if levels is not None else study.levels
    tasks = []
    for scene in study.scenes:
        for m in names:
            for k in lv:
                tasks.append(RunTask(scene, m, k, dict(study.options.get(m, {})), str(out), study.repeat,
                                     study.warmup, study.timeout))
    return tasks


def run_tasks(tasks: list[RunTask], *, executor: str = "serial", scheduler: str | None = None,
              resume: bool = False, workers: int | None = None, desc: str = "railtherm") -> list[RunRecord]:
    """Execute tasks with the chosen executor; records come back in task order."""
    from .executors import get_executor

    ex = get_executor(executor, scheduler=scheduler, workers=workers)
    records: list[RunRecord | None] = [None] * len(tasks)
    with _progress(len(tasks), desc) as bar:
        for i, rec in ex.map(execute_run, tasks, resume=resume):
            records[i] = rec
            if bar is not None:
                bar.update(1)
                bar.set_postfix_str(f"{rec.scene[:24]} {rec.method} L{rec.level} {rec.status}", refresh=False)
    return [r for r in records if r is not None]


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
    executor : {"serial", "processes", "dask"}
    scheduler : str, optional
        Address of a dask.distributed scheduler (``executor="dask"``); a LocalCluster is started if None.
    methods, levels : optional
        Restrict the study's methods / levels.
    resume : bool
        Skip runs already written for the same scene hash.
    report : bool
        Write report.md, report.html and figures/ after the runs.

    Returns
    -------
    xarray.Dataset
        The metrics (also written to ``out/metrics.nc``).
    """
    from .metrics import compute_metrics

    study = study_or_path if isinstance(study_or_path, Study) else load_study(study_or_path)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = make_tasks(study, out, methods, levels)
    records = run_tasks(tasks, executor=executor, scheduler=scheduler, resume=resume, workers=workers,
                        desc=study.name)
    metrics = compute_metrics(study, out, records)
    write_dataset_atomic(metrics, out / "metrics.nc")
    write_atomic_bytes(out / "study.json", json.dumps({"study": study.name, "path": study.path,
                                                      "argv": sys.argv, "records": [r.to_dict() for r in records]},
                                                     indent=1, default=str).encode())
    if report:
        from .report import write_report
        write_report(out, study=study)
    return metrics
