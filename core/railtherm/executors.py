"""Executors of study runs: serial (default), local processes, dask.distributed.

Every executor calls the same :func:`railtherm.runner.execute_run` on each task and yields
``(index, record)`` pairs as runs finish. A worker that dies takes only its current run with it: the
run is retried once on another worker and recorded as failed if it dies again; what was already
written stays on disk (atomic writes) and ``--resume`` completes the study.
"""
from __future__ import annotations

import os
from typing import Callable, Iterator

EXECUTORS = ("serial", "processes", "dask")


def _crash_record(task, message):
    from .runner import RunRecord, status_path, write_atomic_bytes
    import json
    rec = RunRecord(task.scene.name, task.method, task.level, "failed", message, path=str(task.path),
                    scene_hash=task.scene.hash)
    write_atomic_bytes(status_path(task.path), json.dumps(rec.to_dict(), indent=1).encode())
    return rec


class SerialExecutor:
    def map(self, fn: Callable, tasks, **kw) -> Iterator:
        for i, t in enumerate(tasks):
            yield i, fn(t, **kw)


class ProcessExecutor:
    """Local worker processes (``concurrent.futures.ProcessPoolExecutor``, spawn context)."""

    def __init__(self, workers: int | None = None):
        self.workers = workers or max(1, (os.cpu_count() or 2))

    def map(self, fn, tasks, **kw):
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from concurrent.futures.process import BrokenProcessPool

        pending = dict(enumerate(tasks))
        attempts = {i: 0 for i in pending}
        while pending:
            ctx = mp.get_context("spawn")
            with ProcessPoolExecutor(self.workers, mp_context=ctx) as pool:
                futs = {pool.submit(fn, t, **kw): i for i, t in pending.items()}
                broken = False
                for fut in as_completed(futs):
                    i = futs[fut]
                    try:
                        rec = fut.result()
                    except BrokenProcessPool:
                        broken = True
                        attempts[i] += 1
                        if attempts[i] >= 2:
                            yield i, _crash_record(pending.pop(i), "worker process died twice during this run")
                        continue
                    except Exception as exc:  # noqa: BLE001
                        rec = _crash_record(pending[i], f"{type(exc).__name__}: {exc}")
                    pending.pop(i, None)
                    yield i, rec
                if not broken:
                    break
            kw = {**kw, "resume": True}


class DaskExecutor:
    """dask.distributed: one task per run, on the scheduler at ``scheduler`` or a LocalCluster."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        self.scheduler, self.workers = scheduler, workers

    def map(self, fn, tasks, **kw):
        from distributed import Client, LocalCluster, as_completed

        cluster = None
        if self.scheduler:
            client = Client(self.scheduler)
        else:
            cluster = LocalCluster(n_workers=self.workers or 2, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        try:
            futs = {}
            for i, t in enumerate(tasks):
                f = client.submit(fn, t, key=f"run-{i}-{t.scene.hash}-{t.method}-{t.level}", retries=1,
                                  pure=False, **kw)
                futs[f] = i
            for fut in as_completed(futs):
                i = futs[fut]
                try:
                    rec = fut.result()
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after retries
                    rec = _crash_record(tasks[i], f"{type(exc).__name__}: {exc}")
                yield i, rec
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def get_executor(name: str, *, scheduler: str | None = None, workers: int | None = None):
    if name == "serial":
        return SerialExecutor()
    if name == "processes":
        return ProcessExecutor(workers)
    if name == "dask":
        return DaskExecutor(scheduler, workers)
    from .errors import SceneError
    raise SceneError.bad_value(None, "executor", name, "one of " + ", ".join(EXECUTORS))
