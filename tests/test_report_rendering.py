"""Figures drawn in worker processes (``write_report(..., workers=2)``): the same PNG files byte for byte
and the same HTML as drawn in this process, and every file present when the report returns."""
from __future__ import annotations

import shutil

import railtherm
from railtherm.report import write_report

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
    two = write_report(parallel, study, workers=2)
    figs = sorted(p.name for p in one if p.suffix == ".png")
    assert figs and figs == sorted(p.name for p in two if p.suffix == ".png")
    for name in figs:
        assert (serial / "figures" / name).read_bytes() == (parallel / "figures" / name).read_bytes(), name

    def page(folder):
        text = (folder / "report.html").read_text().replace(str(folder), "OUT")
        return [line for line in text.splitlines() if "Report generated in" not in line]
    assert page(serial) == page(parallel)
