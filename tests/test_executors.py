"""Executors: processes and dask.distributed give the serial results bit for bit; faults lose nothing.

* a sweep of 8 runs on 2 local processes (40 on a dask LocalCluster, opt-in), every data variable of
  every run file compared byte for byte with a serial run (attributes such as wall_time may differ), and
  the scores and reference curves computed in the worker processes equal to the serial ones;
* a worker killed in the middle of a study (SIGKILL of a worker process: found with psutil for local
  processes, with ``client.run(os.getpid)`` on a scheduler and workers on loopback): files written
  before stay untouched, the killed run is retried, ``resume`` rewrites nothing;
* a run whose worker dies every time is recorded ``failed`` and ``resume`` completes the study;
* a run stuck past its time limit in a call that ignores the limit ends with its worker, ``failed``
  (local processes and dask); the limit inside a thread (dask) is raised asynchronously;
* the direct netCDF writer writes what ``xarray.Dataset.to_netcdf`` writes.

Workers are separate processes: they rebuild the plugin host of the test (fixture plugins sent by
reference, with this folder on their ``sys.path``; see :func:`railtherm.run.executors.host_spec`).
"""
from __future__ import annotations

#: statuses of runs that ran and converged (the fixture methods are not physics: their verdict is not
#: what these executor tests check)
RAN = {"ok", "inaccurate", "unverified"}

import logging
import os
import signal
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.run.runner import execute_run, make_tasks, run_tasks
from railtherm.run.timelimit import RunTimeout, _time_limit

from fixture_plugins import FlatPlugin, SleepyPlugin
from studies import steel

psutil = pytest.importorskip("psutil")


# the steel of this file's studies: elastic wheel and rail, the rail's bulk temperature 20 degC
STEEL = steel("wheel") + steel("rail", poisson=False, bulk_temperature=20.0)

SWEEP = """
schema_version = 1
[study]
name = "sweep40"
methods = {methods}
levels = [0, 1]
reference = "finest"
repeat = 1
warmup = false
timeout = {timeout}
{options}
{steel}[[scene]]
name = "map"
normal_force = 100e3
contact = {{ shape = "ellipse", curvatures = [1.015, 0.4215] }}
speed = {speeds}
sliding_speed = {sliding}
friction = 0.3
heat_partition = "equal-temperature"
outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "frictional_power"]
"""


def sweep(path: Path, methods='["flat"]', speeds=None, timeout=60, options="", sliding="[0.5, 2.0]"):
    speeds = speeds if speeds is not None else [float(v) for v in range(10, 20)]
    path.write_text(SWEEP.format(methods=methods, speeds=speeds, timeout=timeout, options=options, sliding=sliding,
                                 steel=STEEL))
    return path


@pytest.fixture(scope="module")
def hosts():
    """Core + the flat and sleepy fixture plugins, installed for this module's tests."""
    from railtherm.solving import plugins
    saved = plugins._HOST
    host = plugins.new_host([("flat", FlatPlugin()), ("sleepy", SleepyPlugin())], autoload=False, strict=True)
    plugins.set_host(host)
    yield host
    plugins.set_host(saved)


def _serial(tmp_path_factory, speeds):
    """The sweep at ``speeds`` run serially: (study path, output folder, metrics)."""
    d = tmp_path_factory.mktemp("serial")
    study = sweep(d / "sweep.toml", speeds=speeds)
    m = railtherm.run_study(study, d / "out", report=False)
    assert m.sizes["run"] == 4 * len(speeds) and set(m["status"].values) <= RAN
    return study, d / "out", m


#: speeds of the default suite's executor sweep: 8 runs (2 speeds x 2 sliding speeds x 2 levels), 4 per worker
SPEEDS8 = [10.0, 11.0]


@pytest.fixture(scope="module")
def serial_sweep(hosts, tmp_path_factory):
    return _serial(tmp_path_factory, SPEEDS8)


@pytest.fixture(scope="module")
def serial_sweep40(hosts, tmp_path_factory):
    return _serial(tmp_path_factory, [float(v) for v in range(10, 20)])


def assert_same_runs(a: Path, b: Path, minimum: int = 8):
    """Every data variable (and coordinate) of every run file equal byte for byte."""
    fa = sorted(p.relative_to(a) for p in a.glob("runs/*/*/level-*.nc"))
    fb = sorted(p.relative_to(b) for p in b.glob("runs/*/*/level-*.nc"))
    assert fa == fb and len(fa) >= minimum
    for rel in fa:
        with xr.open_dataset(a / rel) as x, xr.open_dataset(b / rel) as y:
            assert sorted(x.variables) == sorted(y.variables), rel
            for name in x.variables:
                vx, vy = x[name].values, y[name].values
                assert vx.dtype == vy.dtype and vx.shape == vy.shape, (rel, name)
                assert vx.tobytes() == vy.tobytes(), f"{rel}: {name} differs"
            for key in ("scene", "method", "level", "scene_hash"):
                assert x.attrs[key] == y.attrs[key]


# -- first the tests that score no study (the last one only in its final resume): with an empty numba cache,
# under pytest-xdist, the other test worker meanwhile compiles the moving-source reference that scoring
# needs, and this one loads it from the disk cache (tests/numba_compile_lock.py) instead of waiting for it


def test_time_limit_in_a_thread_raises_in_that_thread():
    """dask runs tasks in threads, where SIGALRM cannot reach: the limit is raised asynchronously."""
    box = {}

    def target():
        t0 = time.perf_counter()
        try:
            with _time_limit(0.2):
                while time.perf_counter() - t0 < 10:
                    time.sleep(0.01)
        except RunTimeout:
            box["after"] = time.perf_counter() - t0
        # a later, finished block is never hit by a stale timer
        with _time_limit(0.05):
            pass
        time.sleep(0.1)
        box["clean"] = True
    th = threading.Thread(target=target)
    th.start()
    th.join(15)
    assert 0.2 <= box["after"] < 1.0 and box.get("clean")


def test_scheduler_needs_the_dask_executor():
    with pytest.raises(railtherm.SceneError, match="scheduler"):
        run_tasks([], executor="processes", scheduler="tcp://127.0.0.1:8786")


def test_a_kind_on_its_first_run_is_not_started_twice():
    """A (method, level) on its first run compiles its kernels (cached on disk): another worker takes the next
    other task meanwhile, the order otherwise kept; once that kind has a result (not a refusal) it is warm;
    when every pending task waits for a compilation the first is taken."""
    from collections import deque
    from types import SimpleNamespace as T

    from railtherm.run.executors import _FirstRuns
    tasks = [T(method=m, level=3) for m in ("kalker", "kalker", "fdm", "kalker", "fdm")]
    first, pending = _FirstRuns(tasks), deque(range(5))
    order = []
    for _ in range(3):
        i = first.take(pending)
        first.started(i)
        order.append(i)
    assert order == [0, 2, 1] and list(pending) == [3, 4]
    first.ended(1, T(status="refused"))            # a refusal compiled nothing: kalker still compiling (run 0)
    assert first.take(pending) == 3                # all wait: the first is taken
    pending.appendleft(3)
    first.ended(0, T(status="ok"))
    assert ("kalker", 3) in first.done and first.take(pending) == 3


def test_a_free_worker_takes_the_next_run_of_its_last_runs_affinity():
    """A model's per-process cache (fem's factorised strip) serves the next member of the same sweep at the same
    level: a free worker takes that one first, the order otherwise kept; without a last run, the first."""
    from collections import deque
    from types import SimpleNamespace as T

    from railtherm.run.executors import _FirstRuns
    tasks = [T(method="fem", level=3, affinity=a) for a in (("fem", 3, "carter"), ("fem", 3, "seed"),
                                                             ("fem", 3, "carter"), ("fem", 3, "strip"))]
    first = _FirstRuns(tasks)
    first.done.add(("fem", 3))
    pending = deque([1, 2, 3])
    assert first.take(pending, last=0) == 2 and list(pending) == [1, 3]
    assert first.take(pending, last=0) == 1                     # none of that affinity left: the first
    assert first.take(pending) == 3
    pending = deque([0, 1, 2])                                  # another worker holds carter: seed first
    assert first.take(pending, others=[("fem", 3, "carter"), None]) == 1
    assert first.take(pending, others=[("fem", 3, "carter")]) == 0   # only carter left: taken


def test_direct_netcdf_writer_matches_xarray(hosts, tmp_path):
    import netCDF4

    from railtherm.output.store import _direct_writable, write_dataset_atomic
    from railtherm.testing import canonical
    for name in ("ellipse-full-sliding", "line-full-sliding", "line-given-flux"):
        ds = railtherm.solve(canonical(name), "flat", 1)
        ds.attrs.update(peak_memory=float("nan"), run_id="abc", timing_runs=3)
        assert _direct_writable(ds)
        write_dataset_atomic(ds, tmp_path / f"{name}-direct.nc")
        ds.to_netcdf(tmp_path / f"{name}-xarray.nc", engine="netcdf4")
        with xr.open_dataset(tmp_path / f"{name}-direct.nc") as a, xr.open_dataset(tmp_path / f"{name}-xarray.nc") as b:
            assert a.identical(b)
        with netCDF4.Dataset(tmp_path / f"{name}-direct.nc") as a, netCDF4.Dataset(tmp_path / f"{name}-xarray.nc") as b:
            assert a.data_model == b.data_model == "NETCDF4"
            for v in b.variables:
                assert a[v].dtype == b[v].dtype and a[v].dimensions == b[v].dimensions
                assert {k: repr(a[v].getncattr(k)) for k in a[v].ncattrs()} == \
                       {k: repr(b[v].getncattr(k)) for k in b[v].ncattrs()}
            assert {k: repr(a.getncattr(k)) for k in a.ncattrs()} == {k: repr(b.getncattr(k)) for k in b.ncattrs()}
    # anything unusual goes through xarray
    ds = railtherm.solve(canonical("ellipse-full-sliding"), "flat", 0)
    ds = ds.assign_coords(label=("x", np.array([f"c{i}" for i in range(ds.sizes["x"])])))
    assert not _direct_writable(ds)


@pytest.fixture(scope="module")
def loopback_cluster(hosts):
    """A scheduler and two worker processes on loopback, one retry after a worker death."""
    pytest.importorskip("distributed")
    import dask
    from distributed import Client, LocalCluster
    with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=":0", silence_logs=logging.ERROR)
    client = Client(cluster)
    yield cluster, client
    client.close()
    cluster.close()


def test_dask_stuck_run_ends_with_its_worker(loopback_cluster, tmp_path):
    """A run stuck in a call that the soft (asynchronous) limit cannot interrupt ends its worker."""
    from railtherm.run.executors import DaskExecutor
    cluster, client = loopback_cluster
    study = railtherm.load_study(sweep(tmp_path / "s.toml", methods='["sleepy"]', speeds=[10.0, 11.0], timeout=1.0,
                                       sliding="0.5", options="[study.options.sleepy]\nstuck_at_speed = 11.0\n"))
    tasks = make_tasks(study, tmp_path / "out", levels=[0])
    for t in tasks:
        t.run_id, t.run_started = "dstuck", time.time()
    t0 = time.time()
    recs = dict(DaskExecutor(cluster.scheduler_address, grace=0.5).map(execute_run, tasks))
    assert time.time() - t0 < 40
    by = {tasks[i].scene.speed: r for i, r in recs.items()}
    assert by[10.0].status == "ok"
    assert by[11.0].status == "failed" and "time limit of 1 s" in by[11.0].message
    assert "dask worker process was ended" in by[11.0].message
    client.wait_for_workers(2, timeout=30)  # the nanny has replaced the worker


def test_runs_whose_worker_dies_or_hangs_are_failed_then_resume_completes(hosts, tmp_path):
    """Speed 11 kills its worker every time (recorded failed after the retry); speed 12 hangs in a
    call that ignores SIGALRM (its worker is ended after the time limit and the grace period)."""
    from railtherm.run.executors import ProcessExecutor
    path = sweep(tmp_path / "s.toml", methods='["sleepy"]', speeds=[10.0, 11.0, 12.0], sliding="0.5", timeout=1.0,
                 options="[study.options.sleepy]\ndie_at_speed = 11.0\nstuck_at_speed = 12.0\n")
    out = tmp_path / "out"
    tasks = make_tasks(railtherm.load_study(path), out, levels=[0])
    for t in tasks:
        t.run_id, t.run_started = "faults", time.time()
    t0 = time.time()
    by = {tasks[i].scene.speed: r for i, r in ProcessExecutor(2, grace=0.5).map(execute_run, tasks)}
    assert time.time() - t0 < 60
    assert by[10.0].status == "ok"
    assert by[11.0].status == "failed" and "worker process died (killed by SIGKILL) in each of 2 attempts" \
        in by[11.0].message
    assert by[12.0].status == "failed" and "time limit of 1 s" in by[12.0].message \
        and "worker process was ended" in by[12.0].message
    for speed in (11.0, 12.0):  # the failure is stored beside the run, and no result file
        p = next(t.path for t in tasks if t.scene.speed == speed)
        assert not p.exists() and p.with_name("level-0.status.json").exists()
    written = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/level-*.nc")}
    assert len(written) == 1
    # resumed with the same study: what is done is kept, the failures are retried (and fail again); one
    # worker, ended and replaced at each failure in turn (the faults above met two)
    again = make_tasks(railtherm.load_study(path), out, levels=[0])
    recs = {again[i].scene.speed: r for i, r in ProcessExecutor(1, grace=0.5).map(execute_run, again, resume=True)}
    assert recs[10.0].resumed and recs[11.0].status == recs[12.0].status == "failed"
    for f, t in written.items():
        assert f.stat().st_mtime_ns == t
    # the causes are gone, and with them the options: the run hash changes, every run is computed anew
    sweep(path, methods='["sleepy"]', speeds=[10.0, 11.0, 12.0], sliding="0.5")
    m = railtherm.run_study(path, out, levels=[0], resume=True, report=False)
    assert set(m["status"].values) <= RAN and m.sizes["run"] == 3
    for f, t in written.items():
        assert f.stat().st_mtime_ns != t


# -- studies scored in this file's worker


def test_processes_match_serial_bit_for_bit(serial_sweep, tmp_path, monkeypatch):
    """The run files, and the scores of metrics.nc: with the threshold of parallel scoring lowered to this
    sweep's 8 runs, the runs are scored and the reference curves computed in worker processes too."""
    from railtherm.run import analysis_phase
    study, ref, serial = serial_sweep
    monkeypatch.setattr(analysis_phase, "PARALLEL_METRICS_MIN_RUNS", 4 * len(SPEEDS8))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)   # the worker-process scoring fell back to this process
        m = railtherm.run_study(study, tmp_path / "out", executor="processes", workers=2, report=False)
    assert set(m["status"].values) <= RAN
    assert_same_runs(ref, tmp_path / "out")
    assert list(m["status"].values) == list(serial["status"].values)
    for v in ("error_max_surface_temperature", "energy_balance", "headline_error"):
        assert m[v].values.tobytes() == serial[v].values.tobytes(), v
    from railtherm.analysis.reference_curves import read_reference_curves
    got, exp = read_reference_curves(tmp_path / "out" / "references.nc"), read_reference_curves(ref / "references.nc")
    assert sorted(got) == sorted(exp) and len(exp) == 2 * len(SPEEDS8)
    for scene in exp:
        assert got[scene].identical(exp[scene]), scene
    # the workers' CPU time is recorded (forked from the fork server, they are not this process's children):
    # at least the runs' own solves
    import json
    study_json = json.loads((tmp_path / "out" / "study.json").read_text())
    solved = sum(r["phases"]["cpu"] for r in study_json["records"] if r.get("phases"))
    assert study_json["timing"]["cpu_local_workers"] >= solved > 0


@pytest.mark.slow  # the dask path's bit-for-bit check in the default suite: test_real_method_bit_for_bit_on_every_executor
def test_dask_local_cluster_matches_serial_bit_for_bit(serial_sweep40, tmp_path):
    """executor="dask" without a scheduler starts a LocalCluster (2 worker processes), one task per run."""
    import json
    pytest.importorskip("distributed")
    study, ref, _ = serial_sweep40
    m = railtherm.run_study(study, tmp_path / "out", executor="dask", workers=2, report=False)
    assert set(m["status"].values) <= RAN
    assert_same_runs(ref, tmp_path / "out", minimum=40)
    recs = json.loads((tmp_path / "out" / "study.json").read_text())["records"]
    assert len({r["pid"] for r in recs}) == 2 and os.getpid() not in {r["pid"] for r in recs}


def _workers_of_this_process():
    """Worker processes started for this process: forks of its fork server (the server is this process's child,
    its workers are the server's) or spawned children; not multiprocessing's resource tracker."""
    out = []
    for c in psutil.Process().children(recursive=True):
        try:
            cmd, parent = " ".join(c.cmdline()), c.ppid()
        except psutil.Error:
            continue
        if "resource_tracker" in cmd:
            continue
        if "spawn_main" in cmd or ("forkserver" in cmd and parent != os.getpid()):
            out.append(c)
    return out


def _kill_one_worker_midway(out: Path, pids, wait_files=4, timeout=60.0):
    """Wait until ``wait_files`` runs are written, SIGKILL one worker, return (pid, {file: mtime})."""
    deadline = time.time() + timeout
    while time.time() < deadline and len(list(out.glob("runs/*/*/level-*.nc"))) < wait_files:
        time.sleep(0.02)
    victims = pids()
    assert victims, "no worker process found"
    pid = victims[0]
    os.kill(pid, signal.SIGKILL)
    written = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/level-*.nc")}
    return pid, written


def _run_in_thread(**kw):
    box = {}

    def target():
        try:
            box["metrics"] = railtherm.run_study(**kw)
        except BaseException as exc:  # noqa: BLE001
            box["error"] = exc
    th = threading.Thread(target=target, daemon=True)
    th.start()
    return th, box


OPTS_SLEEP = "[study.options.sleepy]\nsleep = 0.15\n"


def _check_after_kill(study, out, written, m):
    assert set(m["status"].values) <= RAN, list(zip(m["scene"].values, m["message"].values))
    for f, t in written.items():
        assert f.stat().st_mtime_ns == t, f"{f} was rewritten after the kill"
    assert len(list(out.glob("runs/*/sleepy/level-*.nc"))) == m.sizes["run"]
    assert not list(out.glob("runs/**/.*.tmp"))
    before = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/level-*.nc")}
    m2 = railtherm.run_study(study, out, resume=True, report=False)
    assert set(m2["status"].values) <= RAN
    assert {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/level-*.nc")} == before


def test_processes_worker_killed_mid_study(hosts, tmp_path):
    study = sweep(tmp_path / "s.toml", methods='["sleepy"]', speeds=[10.0, 11.0, 12.0, 13.0],
                  options=OPTS_SLEEP)
    out = tmp_path / "out"
    th, box = _run_in_thread(study_or_path=study, out=out, executor="processes", workers=2, report=False)
    pid, written = _kill_one_worker_midway(out, lambda: [p.pid for p in _workers_of_this_process()], wait_files=3)
    th.join(120)
    assert not th.is_alive() and "error" not in box, box.get("error")
    assert 3 <= len(written) < 16
    _check_after_kill(study, out, written, box["metrics"])


def test_dask_worker_killed_mid_study(loopback_cluster, tmp_path):
    cluster, client = loopback_cluster
    study = sweep(tmp_path / "s.toml", methods='["sleepy"]', speeds=[10.0, 11.0, 12.0, 13.0],
                  options=OPTS_SLEEP)
    out = tmp_path / "out"
    th, box = _run_in_thread(study_or_path=study, out=out, executor="dask", scheduler=cluster.scheduler_address,
                             report=False)

    def worker_pids():
        return sorted(client.run(os.getpid).values())
    pid, written = _kill_one_worker_midway(out, worker_pids)
    th.join(120)
    assert not th.is_alive() and "error" not in box, box.get("error")
    assert 4 <= len(written) < 16
    _check_after_kill(study, out, written, box["metrics"])


GREEN = """
schema_version = 1
[study]
name = "green-bits"
methods = ["green"]
levels = [0]
repeat = 1
warmup = false
[defaults]
heat_partition = "equal-temperature"
outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "heat_flux",
           "frictional_power"]
""" + STEEL + """[[scene]]
name = "ellipse"
normal_force = 100e3
contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
speed = [20.0, 30.0]
sliding_speed = 0.5
friction = 0.3
[[scene]]
name = "line-given"
speed = 10.0
heat_source = { flux = 1e7, shape = "hertz", half_width = 2e-3 }
"""


@pytest.fixture
def green_host():
    """Core and the built-in green plugin (sent to workers by reference)."""
    green_plugin = pytest.importorskip("railtherm_green.plugin")
    from railtherm.solving import plugins
    saved = plugins._HOST
    host = plugins.new_host([("green", green_plugin)], autoload=False, strict=True)
    plugins.set_host(host)
    yield host
    plugins.set_host(saved)


def test_real_method_bit_for_bit_on_every_executor(green_host, tmp_path):
    """A real method (green, level 0; three runs of two scenes) gives the same result files in this
    process, in local worker processes (the default executor) and on a dask LocalCluster: every data variable compared
    byte for byte."""
    import json
    pytest.importorskip("distributed")
    study = tmp_path / "green.toml"
    study.write_text(GREEN)
    ref = railtherm.run_study(study, tmp_path / "serial", report=False)
    assert ref.sizes["run"] == 3 and set(ref["status"].values) <= RAN, list(ref["message"].values)
    # "auto" is the CLI's default: local processes here (2 for the 3 runs); the LocalCluster gets one worker
    # process (its start-up is most of this test's time; the opt-in 40-run dask sweep uses two)
    for executor, workers in (("dask", 1), ("auto", 2)):
        out = tmp_path / executor
        m = railtherm.run_study(study, out, executor=executor, workers=workers, report=False)
        assert m.attrs["executor"] == ("processes" if executor == "auto" else executor)
        assert list(m["status"].values) == list(ref["status"].values), executor
        assert_same_runs(tmp_path / "serial", out, minimum=3)
        recs = json.loads((out / "study.json").read_text())["records"]
        assert os.getpid() not in {r["pid"] for r in recs}, f"{executor}: a run was executed in this process"


def test_a_sweep_takes_exactly_repeat_solves(green_host, tmp_path):
    """warmup = false (a sweep): repeat = 1 means the result's own solve is its timing, no extra solves
    (the 10k sweep's wall time is its solves); a verification study (warmup = true) repeats a short
    solve (green level 0: milliseconds) up to ``repeat`` = 3 times."""
    import xarray as xr
    text = """
schema_version = 1
[study]
name = "one-solve"
methods = ["green"]
levels = [0]
reference = "finest"
repeat = {repeat}
warmup = {warmup}
[[scene]]
name = "s"
normal_force = 100e3
contact = {{ shape = "ellipse", curvatures = [1.015, 0.4215] }}
speed = 30.0
sliding_speed = [1.0, 2.0]
friction = 0.3
outputs = ["max_surface_temperature"]
"""
    counts = {}
    for warmup, repeat in (("false", 1), ("true", 3)):
        p = tmp_path / f"s-{warmup}.toml"
        p.write_text(text.format(repeat=repeat, warmup=warmup))
        out = tmp_path / f"out-{warmup}"
        railtherm.run_study(p, out=out, report=False)     # the timings are in metrics.nc; no report needed
        m = xr.open_dataset(out / "metrics.nc")
        counts[warmup] = sorted(set(int(v) for v in m.timing_runs.values))
        m.close()
    assert counts["false"] == [1]
    assert counts["true"] == [3]


def test_auto_with_one_worker_starts_no_fork_server(green_host, tmp_path, monkeypatch):
    """``executor = "auto"`` with one worker runs serially, so no fork server is started for it (the server
    imports the numerical libraries in a process of its own: wasted CPU for a serial run). Every way to a
    fork server goes through ``ForkServer.ensure_running`` (starting one, or a worker forked from one): it is
    watched while the study runs, and it does see :func:`start_worker_server` (the check can fail)."""
    from multiprocessing import forkserver

    from railtherm.run.executors import start_worker_server
    asked = []
    watch = lambda: asked.append(True)   # noqa: E731 - records the request, starts nothing
    monkeypatch.setattr(forkserver._forkserver, "ensure_running", watch)   # the server's own calls
    monkeypatch.setattr(forkserver, "ensure_running", watch)               # the module's function
    study = tmp_path / "green.toml"
    study.write_text(GREEN)
    m = railtherm.run_study(study, tmp_path / "out", executor="auto", workers=1, levels=[0], report=False)
    assert m.attrs["executor"] == "serial" and set(m["status"].values) <= RAN
    assert asked == []
    start_worker_server(2)
    assert asked == [True]


def _numba_functions_at_start(_):
    from numba.core.registry import cpu_target
    return len(cpu_target.typing_context._functions)


def test_workers_start_with_numba_contexts_built():
    """The fork server builds numba's typing and target contexts once (railtherm.run.warm_imports): a worker's
    first kernel, compiled or loaded from the disk cache, does not build them again (about 0.4 s each)."""
    pytest.importorskip("numba")
    from railtherm.run.executors import worker_context
    ctx = worker_context()
    if ctx.get_start_method() != "forkserver":
        pytest.skip("no fork server on this platform")
    with ctx.Pool(1) as pool:
        assert pool.map(_numba_functions_at_start, [0])[0] > 100
