"""Figures drawn in worker processes (``write_report(..., workers=2)``): the same PNG files byte for byte
and the same HTML as drawn in this process, and every file present when the report returns."""
from __future__ import annotations

import shutil

import railtherm
from railtherm.report import write_report
from railtherm.run.executors import worker_context

from test_report_document import STUDY


def test_figures_drawn_in_worker_processes_equal_those_drawn_here(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    study = railtherm.load_study(path)
    serial = tmp_path / "serial"
    railtherm.run_study(study, out=serial, report=False)
    parallel = tmp_path / "parallel"
    shutil.copytree(serial, parallel)
    one = write_report(serial, study, workers=1)
    two = write_report(parallel, study, workers=2, context=worker_context())   # as run_study and the CLI draw
    figs = sorted(p.name for p in one if p.suffix == ".png")
    assert figs and figs == sorted(p.name for p in two if p.suffix == ".png")
    for name in figs:
        assert (serial / "figures" / name).read_bytes() == (parallel / "figures" / name).read_bytes(), name

    def page(folder):
        text = (folder / "report.html").read_text().replace(str(folder), "OUT")
        return [line for line in text.splitlines() if "Report generated in" not in line]
    assert page(serial) == page(parallel)


def test_a_render_worker_that_dies_costs_no_figure(tmp_path):
    """The render pool's workers are killed before they draw: the figures handed to them, and those handed
    after the pool broke, are drawn in this process instead, byte for byte the same as drawn here."""
    import os
    import signal

    from matplotlib.figure import Figure

    from railtherm.report import figures

    def fig(k):
        f = Figure(figsize=(2.0, 1.5), layout="constrained")
        f.subplots().plot([0, 1, 2], [0, k, 1])
        return f

    figures.save(fig(0), tmp_path / "here.png")
    with figures.rendering(2):
        pool = figures._RENDER[0]
        figures.save(fig(0), tmp_path / "a.png")
        for pid in list(pool._processes):
            os.kill(pid, signal.SIGKILL)
        for pid, proc in list(pool._processes.items()):
            proc.join(10)
        figures.save(fig(0), tmp_path / "b.png")
    for name in ("a.png", "b.png"):
        assert (tmp_path / name).read_bytes() == (tmp_path / "here.png").read_bytes(), name
