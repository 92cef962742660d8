"""Executors of study runs: serial, local processes (the command line's default), dask.distributed.

Every executor calls the same :func:`railtherm.run.runner.execute_run` on each task and yields
``(index, record)`` pairs as runs finish, so the results are identical bit for bit whichever runs
them. Workers rebuild the plugin host of the calling process (:func:`host_spec`): entry points when
the caller loaded them, and every plugin registered in memory (``new_host([...])``, the conformance
kit's ``railtherm_register``), sent by reference (cloudpickle) with the caller's ``sys.path``.
Crash records are written through :mod:`railtherm.output.store`; this module never imports the runner (a
task's ``existing()`` finds what a worker wrote before it died).

Faults: a worker that dies takes only its current run with it (retried once on a fresh worker, then
``failed``); a run past its time limit is stopped inside the worker (:func:`railtherm.run.timelimit._time_limit`),
and one stuck in a C call that ignores it is ended with its worker ``grace`` seconds later (``failed``, not
retried). What was written stays on disk (atomic writes); ``--resume`` completes the study.
"""
from __future__ import annotations

import contextlib
import importlib.metadata as md
import importlib.util
import itertools
import logging
import multiprocessing as mp
import os
import pickle
import signal
import socket
import sys
import threading
import time
import warnings
from collections import deque
from multiprocessing.connection import wait
from types import ModuleType
from typing import Callable, Iterator

import cloudpickle

from ..contract.errors import PluginError, SceneError
from ..output import store
from ..solving import plugins
from ..solving.plugins import DISABLE_ENV, GROUP, get_host
from .timelimit import WATCHDOG

EXECUTORS = ("auto", "serial", "processes", "dask")

#: seconds a run may overrun its time limit before its worker process is ended
GRACE = 10.0
#: executions of one run (first attempt and retries) before a worker death marks it failed
MAX_ATTEMPTS = 2


def _crash_record(task, message, kind: str = "error"):
    """Record (and store beside the run) a run whose worker could not report a result.

    ``kind``: the failure's reason kind, "error" (the worker died) or "timeout" (it was ended).
    A chunk of the Zarr store (:class:`railtherm.run.chunks.ChunkTask`) records its own runs (a list).
    """
    crash = getattr(task, "crash", None)
    if crash is not None:
        return crash(message, kind)
    if task.path.exists():  # the worker died after writing: the run is complete after all
        done = task.existing(same_invocation=True)
        if done is not None and done.status == "ok":
            return done
    return store.crash_record(task, message, kind)


def _exit_text(code) -> str:
    if code is None:
        return "unknown exit"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit status {code}"


# ----------------------------------------------------------------------------------------------
# the plugin host of worker processes
def _split_plugins(host):
    """(autoload, [(name, plugin)]) of a host: were entry points loaded, which plugins came in memory."""
    autoload = getattr(host, "autoload", None)
    extra = getattr(host, "extra", None)
    if autoload is not None and extra is not None:
        return bool(autoload), list(extra)
    eps = {ep.name: ep.value.split(":")[0] for ep in md.entry_points(group=GROUP)}
    autoload, extra = False, []
    for name, obj in sorted(host.pm.list_name_plugin(), key=lambda t: t[0]):
        if name == "railtherm":
            continue
        if isinstance(obj, ModuleType) and eps.get(name) == obj.__name__:
            autoload = True
            continue
        extra.append((name, obj))
    if not eps:
        autoload = not os.environ.get(DISABLE_ENV)
    return autoload, extra


def host_spec() -> bytes:
    """A picklable description of this process's plugin host for workers to rebuild it.

    Raises
    ------
    railtherm.PluginError
        A plugin registered in memory cannot be sent to workers (not picklable).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        host = get_host()
    autoload, extra = _split_plugins(host)
    try:
        payload = cloudpickle.dumps(extra)
    except Exception as exc:  # noqa: BLE001
        raise PluginError(f"plugins {[n for n, _ in extra]} registered in this process cannot be sent to worker "
                          f"processes ({type(exc).__name__}: {exc}); register them through the entry-point group "
                          "'railtherm.plugins' or use the serial executor") from exc
    return pickle.dumps({"origin": _origin(), "sys_path": [p for p in sys.path if p], "autoload": autoload,
                         "extra": payload})


def _origin() -> tuple[str, int]:
    return socket.gethostname(), os.getpid()


_INSTALLED: bytes | None = None
_INSTALL_LOCK = threading.Lock()


def install_host(spec: bytes | None) -> None:
    """Build and install the plugin host described by ``spec`` in this (worker) process, once."""
    global _INSTALLED
    if spec is None or spec == _INSTALLED:
        return
    with _INSTALL_LOCK:
        if spec == _INSTALLED:
            return
        d = pickle.loads(spec)
        if tuple(d["origin"]) == _origin():  # a thread of the calling process: its host is already there
            _INSTALLED = spec
            return
        for p in d["sys_path"]:
            if p not in sys.path and os.path.isdir(p):
                sys.path.append(p)
        extra = cloudpickle.loads(d["extra"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            host = plugins.new_host(extra, autoload=d["autoload"])
        plugins.set_host(host)
        _INSTALLED = spec


# ----------------------------------------------------------------------------------------------
class SerialExecutor:
    """Runs in the calling process, in task order."""

    def map(self, fn: Callable, tasks, **kw) -> Iterator:
        for i, t in enumerate(tasks):
            yield i, fn(t, **kw)


def _preload() -> None:
    """Import the modules every run needs before a worker takes its first run, so that their import time
    (seconds on a loaded machine) does not count against that run's time limit."""
    # the point of this function: these imports happen before the first run, not inside it
    from ..solving import pipeline  # noqa: F401
    from ..contract import schema  # noqa: F401
    from ..references import hertz  # noqa: F401 - scipy.optimize: ~0.5 s
    import netCDF4  # noqa: F401
    import xarray  # noqa: F401
    for optional in ("numba.core.event", "dask.array"):
        # numba: the solve's compile watch (run.timing.compile_watch) imports it, ~0.8 s; dask: xarray
        # imports it on the first Variable it builds when it is installed, ~0.5 s
        try:
            __import__(optional)
        except ImportError:
            pass


_CONTEXT = None


def worker_context():
    """The multiprocessing context of railtherm's worker processes (runs, scoring, figures): a fork server
    that has imported :mod:`railtherm.run.warm_imports` where the platform has one (Linux, macOS), so that a
    worker starts in tens of milliseconds instead of importing the numerical libraries and the plugins (about
    2 s of CPU each); else spawn. A forked worker takes the environment of its parent at its start
    (:func:`environment`), except what the libraries read when the server imported them: the thread counts
    of BLAS and numba are those of the server's first pool (:func:`worker_threads`)."""
    global _CONTEXT
    if _CONTEXT is None:
        try:
            ctx = mp.get_context("forkserver")
            ctx.set_forkserver_preload(["railtherm.run.warm_imports"])
        except ValueError:  # pragma: no cover - no fork server on this platform (Windows)
            ctx = mp.get_context("spawn")
        _CONTEXT = ctx
    return _CONTEXT


def start_worker_server(workers: int | None) -> None:
    """Start the fork server of :func:`worker_context` now (it imports in the background while this process
    loads and checks the study), with the thread counts of ``workers`` local workers (None: one per core)."""
    ctx = worker_context()
    if ctx.get_start_method() != "forkserver":  # pragma: no cover - spawn: nothing to start
        return
    from multiprocessing import forkserver  # only where there is a fork server
    with worker_threads(workers or os.cpu_count() or 1):
        forkserver.ensure_running()


def environment(env: dict | None) -> None:
    """Make this (worker) process's environment ``env`` (the parent's at the worker's start; None: keep)."""
    if env is not None and env != dict(os.environ):
        os.environ.clear()
        os.environ.update(env)


def _worker_main(conn, spec, fn, env=None):  # pragma: no cover - runs in the worker process
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C and ends its workers
    environment(env)
    setup_error = None
    try:
        install_host(spec)
        _preload()
    except BaseException as exc:  # noqa: BLE001
        setup_error = f"worker could not set up its plugins: {type(exc).__name__}: {exc}"
    conn.send(("ready", os.getpid()))
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            break
        if msg is None:
            break
        i, task, kw = msg
        if setup_error:
            conn.send((i, setup_error))
            continue
        try:
            out = fn(task, **kw)
        except BaseException as exc:  # noqa: BLE001 - report, keep serving
            out = f"{type(exc).__name__}: {exc}"
        conn.send((i, out))
    conn.close()


#: thread-pool variables of the numerical libraries a worker process reads at start-up
THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


@contextlib.contextmanager
def worker_threads(workers: int):
    """Within the block, start worker processes with cpu_count // ``workers`` (>= 1) threads for BLAS, OpenMP
    and numba, unless the user set those variables: N workers on N cores that each started one BLAS thread per
    core would oversubscribe the machine (measured: the 10k sweep on 2 workers, 105 s instead of 29 s)."""
    n = str(max(1, (os.cpu_count() or 1) // max(1, int(workers))))
    added = [k for k in THREAD_ENV if k not in os.environ]
    for k in added:
        os.environ[k] = n
    try:
        yield
    finally:
        for k in added:
            os.environ.pop(k, None)


class _Worker:
    """A worker process, its pipe, the run it holds (None: idle) and the last run it finished (None: none yet)."""

    def __init__(self, ctx, spec, fn):
        parent, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker_main, args=(child, spec, fn, dict(os.environ)), daemon=True,
                                name="railtherm-worker")
        self.proc.start()
        child.close()
        self.conn = parent
        self.ready = False
        self.task: int | None = None
        self.last: int | None = None
        self.t0 = 0.0

    def send(self, i, task, kw) -> bool:
        try:
            self.conn.send((i, task, kw))
        except (OSError, ValueError):
            return False
        self.task, self.t0 = i, time.monotonic()
        return True

    def stop(self, timeout=2.0):
        if not self.ready:  # still loading: nothing to finish
            self.proc.kill()
        try:
            self.conn.send(None)
        except (OSError, ValueError):
            pass
        self.proc.join(timeout)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(1.0)
        self.conn.close()


class _FirstRuns:
    """The kinds of run (method, level) that have finished with a result, and those on their first run in a
    worker. A kind's first run compiles the kernels of its code path, which numba then caches on disk: a second
    worker that took the same kind meanwhile would compile them again, so it takes the next other task instead
    (the order is otherwise kept; when every pending task waits for a compilation, the first is taken)."""

    RESULTS = store.RESULT_STATUSES
    #: pending tasks looked at for one not waiting for a compilation
    LOOKAHEAD = 64

    def __init__(self, tasks):
        self.tasks, self.done, self.compiling, self.first = tasks, set(), {}, {}

    def _kind(self, i):
        return getattr(self.tasks[i], "method", None), getattr(self.tasks[i], "level", None)

    def affinity(self, i):
        """The :attr:`~railtherm.run.runner.RunTask.affinity` of task ``i`` (None: an index of None, or a task
        without one)."""
        return None if i is None else getattr(self.tasks[i], "affinity", None)

    def take(self, pending: deque, last=None, others=()) -> int:
        """The next task for a free worker whose last task was ``last`` (an index, or None), among the pending
        tasks not waiting for a compilation: the first of the same :attr:`affinity` (a model's per-process
        cache, e.g. fem's factorised strip, serves it), else the first whose affinity is none of ``others``
        (the other workers' current and last tasks': their caches serve those), else the first."""
        ready = [(j, i) for j, i in enumerate(itertools.islice(pending, self.LOOKAHEAD))
                 if self._kind(i) in self.done or not self.compiling.get(self._kind(i))]
        if not ready:
            return pending.popleft()
        want, held = self.affinity(last), set(others) - {None}
        j, i = (next((p for p in ready if want is not None and self.affinity(p[1]) == want), None)
                or next((p for p in ready if self.affinity(p[1]) not in held), None) or ready[0])
        del pending[j]
        return i

    def started(self, i: int) -> None:
        k = self._kind(i)
        if k not in self.done:
            self.compiling[k] = self.compiling.get(k, 0) + 1
            self.first[i] = k

    def ended(self, i: int, record=None) -> None:
        k = self.first.pop(i, None)
        if k is not None:
            self.compiling[k] -= 1
        if getattr(record, "status", "") in self.RESULTS:
            self.done.add(self._kind(i))


class ProcessExecutor:
    """Local worker processes (spawn), one run at a time each, supervised.

    The parent knows which run each worker holds, so a worker that dies costs only that run (retried
    once on a fresh worker, then recorded ``failed``), and a worker stuck past its run's time limit
    plus ``grace`` seconds is ended and the run recorded ``failed``. A worker gets its first run once
    it has loaded its plugins and modules (the time limit counts from the start of the run). A worker may
    die killed, by a segfault or out of memory; a result written just before its death is found by the retry
    and not written again (same ``run_id``).
    """

    def __init__(self, workers: int | None = None, grace: float = GRACE, max_attempts: int = MAX_ATTEMPTS):
        self.workers = workers or max(1, (os.cpu_count() or 2))
        self.grace, self.max_attempts = grace, max_attempts
        self.pids: list[int] = []  # current worker pids (for monitoring and tests)

    # one supervision loop: dispatch, results, worker deaths, overrun runs and respawns share the pool state
    # (which worker holds which run, attempts per run), so splitting it would pass all of that around
    def map(self, fn, tasks, **kw):
        n = len(tasks)
        if n == 0:
            return
        ctx = worker_context()
        spec = host_spec()
        # finest levels first (longest-processing-time order): the long level-3 solves start while there is
        # still short work to fill the other workers, instead of ending the study one worker at a time
        pending = deque(sorted(range(n), key=lambda i: -getattr(tasks[i], "level", 0)))
        first = _FirstRuns(tasks)
        attempts = [0] * n
        with worker_threads(min(self.workers, n)):
            pool = [_Worker(ctx, spec, fn) for _ in range(min(self.workers, n))]
        self.pids = [w.proc.pid for w in pool]
        done = startup_deaths = 0
        started = False
        try:
            while done < n:
                for w in pool:
                    if w.ready and w.task is None and pending:
                        i = first.take(pending, w.last, [first.affinity(x) for v in pool if v is not w
                                                         for x in (v.task, v.last)])
                        attempts[i] += 1
                        if not w.send(i, tasks[i], kw):  # a dead worker: found below
                            attempts[i] -= 1
                            pending.appendleft(i)
                        else:
                            first.started(i)
                watched = [w for w in pool if w.task is not None or not w.ready]
                ready = set(wait([w.conn for w in watched] + [w.proc.sentinel for w in watched], timeout=0.5))
                for k, w in enumerate(pool):
                    if w.ready and w.task is None:
                        continue
                    i = w.task
                    broken = False
                    if w.conn in ready or w.conn.poll():
                        try:
                            j, out = w.conn.recv()
                        except (EOFError, OSError):
                            broken = True  # the worker is going away
                        else:
                            if j == "ready":
                                w.ready = started = True
                                continue
                            w.task, w.last = None, j
                            done += 1
                            if isinstance(out, str):
                                out = _crash_record(tasks[j], out)
                            first.ended(j, out)
                            yield j, out
                            continue
                    if broken or w.proc.sentinel in ready or not w.proc.is_alive():
                        w.proc.join(1.0)
                        if w.proc.is_alive():
                            w.proc.kill()
                            w.proc.join(5.0)
                        why = _exit_text(w.proc.exitcode)
                        if i is not None:
                            first.ended(i)
                            if attempts[i] >= self.max_attempts:
                                done += 1
                                yield i, _crash_record(tasks[i], f"worker process died ({why}) in each of "
                                                       f"{attempts[i]} attempts at this run")
                            else:
                                pending.appendleft(i)
                        elif not w.ready:
                            startup_deaths += 1
                            if startup_deaths >= 3 * len(pool) and not started:
                                raise RuntimeError(f"railtherm worker processes die while starting ({why}); "
                                                   "try --executor serial to see the error")
                        w.conn.close()
                        with worker_threads(len(pool)):
                            pool[k] = _Worker(ctx, spec, fn) if pending else None
                        continue
                    limit = tasks[i].timeout if i is not None else 0
                    if limit and limit > 0 and time.monotonic() - w.t0 > limit + self.grace:
                        w.proc.kill()
                        w.proc.join(5.0)
                        w.conn.close()
                        done += 1
                        first.ended(i)
                        with worker_threads(len(pool)):
                            pool[k] = _Worker(ctx, spec, fn) if pending else None
                        yield i, _crash_record(tasks[i], f"run exceeded the per-run time limit of {limit:g} s and "
                                               f"did not stop; its worker process was ended after {self.grace:g} s more", "timeout")
                pool = [w for w in pool if w is not None]
                self.pids = [w.proc.pid for w in pool]
        finally:
            for w in pool:
                w.stop()


def _dask_run(task, *, spec, fn, kw, grace):  # pragma: no cover - runs on a dask worker
    install_host(spec)
    _preload()  # once per worker process (imports are cached); not in the run's time limit
    limit = task.timeout
    token = None
    if limit and limit > 0:
        def end_worker():
            # the run ignored its time limit (stuck in a C call): record it, then end this worker
            # process; the nanny starts a new one, and the retried task finds this record
            _crash_record(task, f"run exceeded the per-run time limit of {limit:g} s and did not stop; its "
                                f"dask worker process was ended after {grace:g} s more", "timeout")
            os._exit(70)
        token = WATCHDOG.add(limit + grace, end_worker)
    try:
        return fn(task, **kw)
    finally:
        if token is not None:
            WATCHDOG.cancel(token)


class DaskExecutor:
    """dask.distributed: one task per run (``client.map``), on the scheduler at ``scheduler`` or on a LocalCluster.

    A LocalCluster (one thread per worker process) is started unless a scheduler address is given. The scheduler
    retries a task whose worker died; a LocalCluster started here allows one retry
    (``distributed.scheduler.allowed-failures = 1``), a remote scheduler uses its own setting; a task that exhausts
    them is recorded ``failed`` (KilledWorker).
    """

    def __init__(self, scheduler: str | None = None, workers: int | None = None, grace: float = GRACE):
        self.scheduler, self.workers, self.grace = scheduler, workers, grace
        self.client = None

    def map(self, fn, tasks, **kw):
        # dask.distributed: the optional 'sweep' extra
        import dask
        from distributed import Client, LocalCluster, as_completed

        if not tasks:
            return
        spec = host_spec()
        cluster = None
        if self.scheduler:
            try:
                client = Client(self.scheduler, timeout="30s")
            except (OSError, TimeoutError) as exc:
                raise SceneError.bad_value(None, "scheduler", self.scheduler,
                                           f"the address of a running dask scheduler (start one with "
                                           f"'dask scheduler --port 8786'); connecting failed: {exc}") from None
        else:
            with dask.config.set({"distributed.scheduler.allowed-failures": MAX_ATTEMPTS - 1}):
                nw = self.workers or max(1, os.cpu_count() or 2)
                with worker_threads(nw):
                    # dashboard on any free port: None means the configured :8787, taken by any other cluster
                    cluster = LocalCluster(n_workers=nw, threads_per_worker=1, processes=True,
                                           dashboard_address=":0", silence_logs=logging.ERROR)
            client = Client(cluster)
        self.client = client
        try:
            run_id = tasks[0].run_id or "x"
            keys = [f"railtherm-{run_id}-{i}" for i in range(len(tasks))]
            futs = client.map(_dask_run, tasks, key=keys, pure=False, spec=spec, fn=fn, kw=kw, grace=self.grace)
            index = {f.key: i for i, f in enumerate(futs)}
            done = as_completed(futs)
            del futs
            for fut in done:
                i = index[fut.key]
                try:
                    rec = fut.result()
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker after the retries
                    name = type(exc).__name__
                    msg = (f"worker process died in each attempt at this run (dask {name}: {exc})"
                           if name == "KilledWorker" else f"{name}: {exc}")
                    rec = _crash_record(tasks[i], msg)
                fut.release()
                yield i, rec
        finally:
            self.client = None
            client.close()
            if cluster is not None:
                cluster.close()


def resolve_executor(name: str, workers: int | None, n_tasks: int) -> tuple[str, int]:
    """The executor and the number of workers a study of ``n_tasks`` tasks runs with.

    ``"auto"`` (the command line's default): local worker processes, one per core (``workers`` if
    given), at most one per task; serial when that makes one. ``"processes"`` likewise never starts
    more workers than tasks. The count is what shared the machine while runs were timed.
    """
    cores = os.cpu_count() or 1
    if name in ("auto", "processes"):
        n = max(1, min(workers or cores, max(1, n_tasks)))
        return ("serial", 1) if name == "auto" and n == 1 else ("processes", n)
    if name == "dask":
        return name, int(workers or cores)
    return name, 1


#: the optional extra that holds dask.distributed and zarr (``pip install 'railtherm[sweep]'``): the main
#: study needs neither, so a first install does not pay for them
SWEEP_EXTRA = "railtherm[sweep]"


def require_optional(module: str, key: str, value: str) -> None:
    """Raise :class:`railtherm.contract.errors.SceneError` naming ``key`` = ``value`` when the optional package
    ``module`` (of the ``sweep`` extra) is not installed, before any run starts."""
    if importlib.util.find_spec(module) is None:
        raise SceneError(f"key {key!r} = {value!r} needs the optional package {module!r}, which is not installed: "
                         f"python -m pip install '{SWEEP_EXTRA}' (or choose another {key})", key=key, value=value,
                         allowed=f"{value!r} with {SWEEP_EXTRA} installed")


def get_executor(name: str, *, scheduler: str | None = None, workers: int | None = None):
    """The executor called ``name`` ("serial", "processes" or "dask"; "auto": :func:`resolve_executor`)."""
    if scheduler and name != "dask":
        raise SceneError.bad_value(None, "scheduler", scheduler, "an address only with executor 'dask'")
    if name == "auto":
        name, workers = resolve_executor(name, workers, 2)
    if name == "serial":
        return SerialExecutor()
    if name == "processes":
        return ProcessExecutor(workers)
    if name == "dask":
        require_optional("distributed", "executor", name)
        return DaskExecutor(scheduler, workers)
    raise SceneError.bad_value(None, "executor", name, "one of " + ", ".join(EXECUTORS))
