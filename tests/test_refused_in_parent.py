"""Runs whose plan refuses them (a model's validity, a study method that repeats another's computation) are
refused in the study's own process while local workers run the rest: the same records as a serial run's, and
no worker round trip for them."""
from __future__ import annotations

import os

from railtherm.input.study import load_study
from railtherm.run.runner import make_tasks, run_tasks

STUDY = """
[study]
name = "refusals"
methods = ["green", "fem"]
levels = [0]
repeat = 1

[defaults]
speed = 30.0
sliding_speed = 1.0
friction = 0.3
normal_force = 1e4
heat_partition = 0.5
outputs = ["max_surface_temperature"]
wheel = { shear_modulus = 82e9, poisson_ratio = 0.28, density = 7850.0, specific_heat = 450.0, conductivity = 50.0 }
rail = { shear_modulus = 82e9, poisson_ratio = 0.28, density = 7850.0, specific_heat = 450.0, conductivity = 50.0 }

[[scene]]
name = "ellipse"
contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
"""


def _records(tmp_path, name, executor, early):
    path = tmp_path / f"{name}.toml"
    path.write_text(STUDY)
    tasks = make_tasks(load_study(path), tmp_path / name)
    for t in tasks:
        t.refused_early = t.refused_early and early
    return tasks, run_tasks(tasks, executor=executor, workers=2)


def test_plan_refusals_are_marked_and_refused_in_this_process(tmp_path):
    tasks, recs = _records(tmp_path, "here", "processes", True)
    early = {(t.method, t.level) for t in tasks if t.refused_early}
    assert ("fem", 0) in early                          # fem takes line contacts only: its plan refuses
    assert ("green", 0) not in early
    for t, r in zip(tasks, recs):
        assert (r.pid == os.getpid()) == t.refused_early, (t.method, r.pid)
        assert r.status == ("refused" if t.refused_early else "ok"), (t.method, r.status, r.message)
    _, serial = _records(tmp_path, "serial", "serial", True)   # every run in this process, none marked early
    for a, b in zip(recs, serial):
        assert (a.method, a.status, a.reason_kind, a.message) == (b.method, b.status, b.reason_kind, b.message)


def test_a_run_its_plan_refuses_warms_nothing_up(tmp_path, monkeypatch):
    """The plan's refusal comes from the run's own solve: no warm-up solve of another level of the scene (it
    would solve, and compile, in the study's process beside the workers)."""
    from railtherm.run import runner
    path = tmp_path / "s.toml"
    path.write_text(STUDY)
    task = next(t for t in make_tasks(load_study(path), tmp_path / "o") if t.refused_early)
    monkeypatch.setattr(runner, "_WARM", set())
    rec = runner.execute_run(task)
    assert rec.status == "refused" and rec.phases["warmup"] == 0.0 and task.method not in runner._WARM
