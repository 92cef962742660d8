"""The timing protocol of a run (:func:`railtherm.run.runner.execute_run`) and the default executor.

* a short solve is repeated until about 0.5 s of timing is collected, at most ``repeat`` times; a
  solve over 0.5 s is timed once (its own solve), and ``timing_runs`` says how many were timed;
* the warm-up happens once per method and process, on the study's coarsest level;
* a solve during which numba compiled is not a timing (solved again);
* the memory is read in the result's own solve (Linux: ``VmHWM``), not in an extra solve;
* a repeat times the same stages without assembling a result (``solve_time``);
* after a warm-up the process's objects are frozen out of later garbage collections;
* ``railtherm run`` uses local worker processes, one per core and at most one per run.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

import railtherm
from railtherm.run import runner
from railtherm.run.executors import resolve_executor
from railtherm.run.runner import RSSPeak, RunTask, execute_run, more_solves


def test_a_sweep_of_many_scenes_is_scored_in_a_bounded_number_of_work_items():
    """10 000 scenes scored scene by scene would pickle the study and every record 10 000 times (each work item
    carries them): the pool gets at most SCORING_PARTS items, each scene's runs in one item, every run once."""
    from types import SimpleNamespace as R

    from railtherm.analysis.metrics import SCORING_PARTS, scoring_parts, submit_scoring
    records = [R(scene=f"s--k={i // 3}", status="ok" if i % 3 else "refused") for i in range(3 * 2000)]
    items = []

    def fake_map(fn, iterable):
        items.extend(iterable)
        return []
    submit_scoring(R(tolerance=0.05), records, fake_map)
    assert 1 < len(items) <= SCORING_PARTS
    assert sorted(i for item in items for i in item) == list(range(len(records)))
    owner = {records[i].scene: k for k, item in enumerate(items) for i in item}
    assert all(owner[records[i].scene] == k for k, item in enumerate(items) for i in item)
    loads = [sum(records[i].status == "ok" for i in item) for item in items]
    assert max(loads) - min(loads) <= 2 and loads == sorted(loads, reverse=True)
    few = records[:3 * 30]                                   # the main study's 30 scenes: one item per scene
    assert len(scoring_parts(few)) == 30


def test_more_solves_repeats_only_short_solves():
    assert more_solves([0.01], 3, True) and more_solves([0.01, 0.01], 3, True)
    assert not more_solves([0.01, 0.01, 0.01], 3, True)        # at most `repeat`
    assert not more_solves([0.6], 3, True)                     # a solve over 0.5 s is timed once
    assert more_solves([0.3], 3, True) and not more_solves([0.3, 0.3], 3, True)  # 0.5 s collected
    assert more_solves([0.6], 3, False) and not more_solves([0.6] * 3, 3, False)  # a sweep: exactly repeat
    assert not more_solves([0.01], 1, True)


def test_resolve_executor_uses_the_cores_by_default():
    cores = os.cpu_count() or 1
    name, n = resolve_executor("auto", None, 600)
    assert n == cores and name == ("processes" if cores > 1 else "serial")
    assert resolve_executor("auto", None, 1) == ("serial", 1)              # one run: no worker to start
    assert resolve_executor("auto", 8, 3) == ("processes", 3)              # never more workers than runs
    assert resolve_executor("processes", None, 1) == ("processes", 1)
    assert resolve_executor("serial", 4, 100) == ("serial", 1)


def test_cli_default_executor_is_auto():
    from railtherm.cli import build_parser
    args = build_parser().parse_args(["run", "x.toml"])
    assert args.executor == "auto"


@pytest.fixture
def scene():
    st = railtherm.load_study(os.path.join(os.path.dirname(__file__), "..", "studies", "seed_paper.toml"))
    return next(s for s in st.scenes if s.name == "ek-low")


def test_one_warm_up_per_method_and_process_on_the_coarsest_level(scene, tmp_path, monkeypatch):
    calls = []
    real = runner._measured_solve

    def spy(task, result, memory):
        calls.append(task.level)
        return real(task, result, memory)
    monkeypatch.setattr(runner, "_WARM", set())
    monkeypatch.setattr(runner, "_measured_solve", spy)
    r1 = execute_run(RunTask(scene, "green", 1, {}, str(tmp_path / "a"), warmup_level=0))
    r2 = execute_run(RunTask(scene, "green", 2, {}, str(tmp_path / "b"), warmup_level=0))
    assert r1.status == r2.status == "ok", (r1.message, r2.message)
    assert r1.phases["warmup"] > 0 and r2.phases["warmup"] == 0.0        # the second run is not warmed again
    assert set(calls) == {1, 2}                                          # the warm-up (level 0) is not timed
    assert calls.count(1) == r1.timing_runs and calls.count(2) == r2.timing_runs
    for r in (r1, r2):
        assert 1 <= r.timing_runs <= 3
        assert r.wall_time <= r.wall_time_median and np.isfinite(r.wall_time_cold)
        if r.wall_time_cold > 0.5:
            assert r.timing_runs == 1


def test_the_first_scene_with_a_temperature_field_is_warmed_up_once_more(scene, tmp_path, monkeypatch):
    """A method warm on a scene without a temperature field is warmed up again, untimed, at its first scene with
    one (the thermal trace's kernels), and not at the next."""
    st = railtherm.load_study(os.path.join(os.path.dirname(__file__), "..", "studies", "seed_paper.toml"))
    field = next(s for s in st.scenes if s.name == "fdm-circular-q1")
    assert scene.field is None and field.field is not None
    monkeypatch.setattr(runner, "_WARM", set())
    monkeypatch.setattr(runner, "_WARM_FIELD", set())
    r0 = execute_run(RunTask(scene, "green", 0, {}, str(tmp_path / "a"), warmup_level=0))
    r1 = execute_run(RunTask(field, "green", 1, {}, str(tmp_path / "b"), warmup_level=0))
    r2 = execute_run(RunTask(field, "green", 0, {}, str(tmp_path / "c"), warmup_level=0))
    r3 = execute_run(RunTask(scene, "green", 1, {}, str(tmp_path / "d"), warmup_level=0))
    assert all(r.status == "ok" for r in (r0, r1, r2, r3)), [r.message for r in (r0, r1, r2, r3)]
    assert r0.phases["warmup"] > 0 and r1.phases["warmup"] > 0
    assert r2.phases["warmup"] == 0.0 and r3.phases["warmup"] == 0.0
    assert runner._WARM == runner._WARM_FIELD == {"green"}


@pytest.mark.skipif(not RSSPeak.native(), reason="the high-water mark is read in the timed solve on Linux only")
def test_memory_is_read_in_the_results_own_solve(scene, tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "_WARM", {"green"})
    rec = execute_run(RunTask(scene, "green", 0, {}, str(tmp_path / "o"), repeat=1))
    assert rec.status == "ok" and rec.timing_runs == 1
    assert "memory" not in rec.phases                                   # no extra solve for memory
    assert rec.peak_rss > 50e6 and rec.rss_growth >= 0                  # the interpreter included


def test_repeats_time_the_stages_without_assembling_a_result(scene, tmp_path, monkeypatch):
    """Only the result's own solve builds a dataset; the repeats time the same stages (solve_time)."""
    from railtherm.solving import pipeline
    built = []
    real = pipeline.build_dataset

    def counting(*a, **kw):
        built.append(1)
        return real(*a, **kw)
    monkeypatch.setattr(runner, "_WARM", {"green"})
    monkeypatch.setattr(pipeline, "build_dataset", counting)
    rec = execute_run(RunTask(scene, "green", 0, {}, str(tmp_path / "o"), repeat=3))
    assert rec.status == "ok", rec.message
    assert rec.timing_runs == 3 and len(built) == 1                     # green at level 0 takes milliseconds
    assert 0 < rec.wall_time <= rec.wall_time_median and np.isfinite(rec.wall_time_cold)


def test_solve_time_refuses_what_solve_refuses(scene):
    from railtherm.solving.pipeline import solve_time
    assert 0 < solve_time(scene, "green", 0) < 60
    with pytest.raises(railtherm.SceneError, match="level"):
        solve_time(scene, "green", -1)
    with pytest.raises(railtherm.SceneError, match="method"):
        solve_time(scene, "no-such-method", 0)


def test_the_warm_up_freezes_what_the_process_holds(scene, tmp_path, monkeypatch):
    """After a warm-up, the objects the process holds (modules, compiled kernels) sit in the garbage
    collector's permanent generation: a timed solve's full collections no longer traverse them."""
    import gc
    monkeypatch.setattr(runner, "_WARM", set())
    gc.unfreeze()
    try:
        rec = execute_run(RunTask(scene, "green", 0, {}, str(tmp_path / "o"), repeat=1))
        assert rec.status == "ok" and rec.phases["warmup"] > 0
        assert gc.get_freeze_count() > 10_000
    finally:
        gc.unfreeze()


def test_a_solve_that_compiles_is_not_a_timing(scene, tmp_path, monkeypatch):
    """A kernel first compiled inside the timed solve: that solve is repeated and not counted."""
    numba = pytest.importorskip("numba")
    from railtherm.solving import pipeline
    fresh = {"compiled": False}
    real = pipeline.solve

    def solve_and_compile(*a, **kw):
        if not fresh["compiled"]:
            fresh["compiled"] = True
            numba.njit(lambda x: x + 1)(1)  # a new function: compiles now
        return real(*a, **kw)
    monkeypatch.setattr(runner, "_WARM", {"green"})
    monkeypatch.setattr(pipeline, "solve", solve_and_compile)
    rec = execute_run(RunTask(scene, "green", 0, {}, str(tmp_path / "o"), repeat=1))
    assert rec.status == "ok" and rec.timing_runs == 1
    import xarray as xr
    with xr.open_dataset(rec.path) as ds:
        assert "compiled were not timed" in ds.attrs["history"]


@pytest.mark.parametrize("parts", [None, 2])
def test_metrics_scored_in_worker_processes_equal_the_serial_ones(tmp_path, write_study, monkeypatch, parts):
    """The scenes of a study scored in a process pool (the study's: forked from the fork server, the plugin host
    rebuilt) give metrics.nc's values exactly as scored in this process; also with its three scenes packed
    into two work items (``parts = 2``: a sweep of more scenes than :data:`SCORING_PARTS`)."""
    import json
    from concurrent.futures import ProcessPoolExecutor

    from railtherm.analysis import metrics
    from railtherm.analysis.metrics import compute_metrics
    if parts is not None:
        monkeypatch.setattr(metrics, "SCORING_PARTS", parts)
    from railtherm.output.store import RunRecord
    from railtherm.run.executors import host_spec, install_host, worker_context
    study = write_study(methods='["green"]', speed="[20.0, 30.0, 60.0]")
    out = tmp_path / "out"
    serial = railtherm.run_study(study, out, report=False)
    st = railtherm.load_study(study)
    recs = [RunRecord.from_dict(r) for r in json.loads((out / "study.json").read_text())["records"]]
    with ProcessPoolExecutor(2, mp_context=worker_context(), initializer=install_host,
                             initargs=(host_spec(),)) as pool:
        par = compute_metrics(st, out, recs, map=pool.map)
    assert set(par.data_vars) == set(serial.data_vars)
    for v in serial.data_vars:
        a, b = serial[v].values, par[v].values
        assert a.shape == b.shape, v
        assert (np.array_equal(a, b, equal_nan=True) if a.dtype.kind == "f" else (a == b).all()), v
    assert serial.sizes["run"] == 6 and set(map(str, serial.status.values)) <= {"ok", "inaccurate", "unverified"}

