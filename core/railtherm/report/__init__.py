"""The study report: ``report.md``, ``report.html`` and ``figures/*.png`` of a study output folder.

:func:`write_report` reads what ``railtherm run`` wrote (``metrics.nc``, ``study.json``, the run files,
``references.nc``) and writes a document a researcher reads in ten minutes: a table of contents, then
the verdict (findings, scorecard: :mod:`.verdict`, work-precision figure); the study and its scenes
(:mod:`.study_section`, :mod:`.study_notes`); when the study has them, the friction-law
(:mod:`.friction_section`), wheelset (:mod:`.wheelset_section`), exact-contact (:mod:`.exact_contact`)
and thermal-trace (:mod:`.trace_section`) sections; one section per scene and sweep (:mod:`.sections`,
details behind closed ``<details>`` boxes); benchmarks and the environment (:mod:`.environment`).

Every figure appears once, at most :data:`~.sections.MAX_FIGURES` of them; every stored name is printed
through one mapping (:func:`.format.label`). The report is a pure reader: it computes no physics (exact
curves come from ``references.nc``); a figure that cannot be drawn becomes a sentence in its place.
Other modules: :mod:`.load` (reading), :mod:`.tables`, :mod:`.figures`, :mod:`.scene_figures`,
:mod:`.exact_figures`, :mod:`.trace_figures` (matplotlib), :mod:`.document` (Markdown and HTML).
"""
from __future__ import annotations

import time
from pathlib import Path

from ..output import store
from .document import Document
from .environment import benchmark_section, environment_section
from .exact_contact import exact_contact_section
from .friction_section import friction_section
from .figures import Palette, method_colour, rendering
from .load import load
from .sections import Context, scene_section, sweep_section, verdict_section
from .study_section import intro, study_section
from .trace_section import trace_anchor, trace_scenes, trace_section
from .verdict import rows, sweep_groups
from .wheelset_section import wheelset_section

__all__ = ["write_report", "MAX_SCENE_SECTIONS", "method_colour"]

#: scenes beyond this number get a row in the scorecard but no section of their own
MAX_SCENE_SECTIONS = 40


def _write_atomic(path: Path, text: str):
    store.write_text_atomic(path, text)


def _left_out_notes(doc: Document, ctx: Context, scenes: list, limit: int):
    """Say which scenes have no section and which figures were not drawn (the figure budget)."""
    if scenes:
        doc.paragraph(f"{len(scenes)} further scenes have no section of their own (limit {limit}); the "
                      "scorecard lists them: " + ", ".join(f"`{r.label}`" for r in scenes[:20])
                      + (" …" if len(scenes) > 20 else "") + ".", note=True)
    if ctx.left_out:
        doc.paragraph(f"{len(ctx.left_out)} figures are left out: the report draws at most {ctx.max_figures} "
                      "(the run files hold the data): " + ", ".join(ctx.left_out[:12])
                      + (" …" if len(ctx.left_out) > 12 else "") + ".", note=True)


def write_report(out, study=None, benchmarks=None, workers: int = 1, context=None) -> list[Path]:
    """Write ``report.md``, ``report.html`` and ``figures/*.png`` for a study output folder.

    Parameters
    ----------
    out : path
        Output folder of ``railtherm run`` (holds ``metrics.nc``, ``study.json``, ``runs/`` and
        ``references.nc``).
    study : railtherm.input.study.Study, optional
        The study that was run; when None it is re-loaded from the path recorded in ``study.json``
        (if that file still exists). It supplies the scene inputs, the sweeps and the published
        values; without it the report is written from the output folder alone.
    benchmarks : path, optional
        A pytest-benchmark JSON file (``--benchmark-json``); ``out/benchmarks.json`` is used when it
        exists and none is given.
    workers : int
        Processes that draw the figures (spawned; 1: drawn in this process).

    Returns
    -------
    list of pathlib.Path
        ``report.md``, ``report.html`` and every figure written.

    Raises
    ------
    FileNotFoundError
        When ``out/metrics.nc`` does not exist.
    """
    out = Path(out)
    t0 = time.perf_counter()
    data = load(out, study)
    fig_dir = store.figures_dir(out)
    fig_dir.mkdir(parents=True, exist_ok=True)
    for old in list(fig_dir.glob("*.png")) + list(fig_dir.glob("*.svg")):  # an earlier report's figures
        old.unlink()
    ctx = Context(data, fig_dir, Palette(data.methods))
    doc = Document()
    doc.heading(1, f"railtherm report: study `{data.name}`")
    intro(doc, data)
    doc.contents()
    groups = sweep_groups(data)
    table_rows = rows(data, groups)
    limit = MAX_SCENE_SECTIONS
    singles = [r for r in table_rows if r.group is None]
    left_out = singles[limit:]
    for row in left_out:  # no section: the scorecard row links nowhere
        row.anchor = ""
    with rendering(workers, context):  # figures are drawn in worker processes while the sections are written
        verdict_section(doc, ctx, table_rows)
        study_section(doc, ctx, table_rows)
        friction_section(doc, ctx)        # a friction study's point, before the long exact-contact tables
        wheelset_section(doc, ctx)        # a profile study's point, before the exact-contact figures take the
        exact_contact_section(doc, ctx)   # figure budget
        traced = set(trace_scenes(data))
        trace_section(doc, ctx)
        idx = 0
        for row in table_rows:
            if row in left_out:
                continue
            idx += 1
            if row.group is None:
                scene = row.scenes[0]
                scene_section(doc, ctx, idx, scene, trace_anchor(scene) if scene in traced else "")
            else:
                sweep_section(doc, ctx, idx, row.group, row.anchor)
        _left_out_notes(doc, ctx, left_out, limit)
    bench = Path(benchmarks) if benchmarks else out / "benchmarks.json"
    if benchmarks or bench.exists():
        benchmark_section(doc, bench)
    environment_section(doc, data, [f"Note: {n}" for n in data.notes]
                        + [f"Report generated in {time.perf_counter() - t0:.1f} s"])
    md_path, html_path = out / store.REPORT_MD, out / store.REPORT_HTML
    _write_atomic(md_path, doc.markdown())
    _write_atomic(html_path, doc.html(f"railtherm report: {data.name}"))
    return [md_path, html_path] + ctx.figures
