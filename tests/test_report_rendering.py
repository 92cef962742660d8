"""The render pool of the report's figures: a worker that dies costs no figure.

That figures drawn in worker processes are the same as drawn here is checked on the report of
``test_report_document`` (:func:`test_report_document.test_figures_drawn_in_worker_processes_equal_those_drawn_here`),
whose study is run once for all its tests."""
from __future__ import annotations


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
