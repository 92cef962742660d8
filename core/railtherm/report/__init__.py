"""The study report: ``report.md``, ``report.html`` and ``figures/*.png`` of a study output folder.

:func:`write_report` reads what ``railtherm run`` wrote (``metrics.nc``, ``study.json``, the run files
and ``references.nc``) and writes, in this order:

1. the **verdict**: a scorecard (scenes × methods: the cheapest level within the tolerance of an
   independent reference on the scene's headline quantity, or the best available with its status),
   key findings computed from the metrics, and a work-precision figure with one panel per scene;
2. when a creepage sweep has a friction law: the friction-law section (:mod:`.friction_section`), creep
   curves and flash temperatures per sweep and each curve's maximum against the reference method;
   then, when scenes take an exact-contact method as their reference (``reference = "kalker"``): the
   exact-contact section (:mod:`.exact_contact`), the contact model's error (same thermal model, other
   contact) separated from the thermal model's (same contact, other thermal model), the creep-force
   curve, traction/slip/power-density maps side by side and a non-Hertzian scene;
3. when scenes report temperatures behind the patch and in depth (``field``) with an exact trace in
   ``references.nc``: the thermal-trace section (:mod:`.trace_section`), the seed paper's Figs 2-7
   kinds of plot, every method's finest level against the exact trace (temperature along the rolling
   direction on the surface and at depth, temperature against depth, peak temperature and cooling rate
   per depth, surface-temperature maps of the trace) and a table of the threshold isotherm's depth, the
   time above it and the cooling rate per method with relative errors;
4. one section per scene: inputs, references, refusals and failures (one line per reason), the runs
   with a result (collapsible table: status, timing min/median, peak RSS, energy balance,
   errors), published values beside the results, convergence orders beside the theoretical ones,
   differences between methods, and the temperature and traction figures with the exact curves;
5. one section per sweep (scenes generated from one list value): one table and one curve;
6. benchmarks (a pytest-benchmark JSON file) and the environment.

The report is a pure reader: it computes no physics (the exact curves come from ``references.nc``,
written by :func:`railtherm.reference_curves.write_reference_curves`). A figure that cannot be drawn
becomes a sentence in its place.

Modules: :mod:`.load` (reading), :mod:`.verdict` (scorecard and findings), :mod:`.tables` (table
rows), :mod:`.figures` (matplotlib), :mod:`.sections` (page order), :mod:`.exact_contact` and
:mod:`.exact_figures` (the exact-contact section), :mod:`.trace_section` and :mod:`.trace_figures` (the
thermal-trace section), :mod:`.document` (Markdown and HTML), :mod:`.format`
(numbers).
"""
from __future__ import annotations

import time
from pathlib import Path

from ..output import store
from .document import Document
from .environment import benchmark_section, environment_section
from .exact_contact import exact_contact_section
from .friction_section import friction_section
from .figures import Palette, method_colour
from .load import load
from .sections import Context, scene_section, sweep_section, verdict_section
from .study_section import intro, study_section
from .trace_section import trace_anchor, trace_scenes, trace_section
from .verdict import rows, sweep_groups

__all__ = ["write_report", "MAX_SCENE_SECTIONS", "method_colour"]

#: scenes beyond this number get a row in the scorecard but no section of their own
MAX_SCENE_SECTIONS = 40


def _write_atomic(path: Path, text: str):
    store.write_text_atomic(path, text)


def write_report(out, study=None, benchmarks=None) -> list[Path]:
    """Write ``report.md``, ``report.html`` and ``figures/*.png`` for a study output folder.

    Parameters
    ----------
    out : path
        Output folder of ``railtherm run`` (holds ``metrics.nc``, ``study.json``, ``runs/`` and
        ``references.nc``).
    study : railtherm.study.Study, optional
        The study that was run; when None it is re-loaded from the path recorded in ``study.json``
        (if that file still exists). It supplies the scene inputs, the sweeps and the published
        values; without it the report is written from the output folder alone.
    benchmarks : path, optional
        A pytest-benchmark JSON file (``--benchmark-json``); ``out/benchmarks.json`` is used when it
        exists and none is given.

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
    verdict_section(doc, ctx, table_rows)
    study_section(doc, ctx, table_rows)
    friction_section(doc, ctx)        # a friction study's point, before the long exact-contact tables
    exact_contact_section(doc, ctx)
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
    if left_out:
        doc.paragraph(f"{len(left_out)} further scenes have no section of their own (limit {limit}); the "
                      "scorecard lists them: " + ", ".join(f"`{r.label}`" for r in left_out[:20])
                      + (" …" if len(left_out) > 20 else "") + ".", note=True)
    if ctx.left_out:
        doc.paragraph(f"{len(ctx.left_out)} figures are left out: the report draws at most {ctx.max_figures} "
                      "(the run files hold the data): " + ", ".join(ctx.left_out[:12])
                      + (" …" if len(ctx.left_out) > 12 else "") + ".", note=True)
    bench = Path(benchmarks) if benchmarks else out / "benchmarks.json"
    if benchmarks or bench.exists():
        benchmark_section(doc, bench)
    environment_section(doc, data, [f"Note: {n}" for n in data.notes]
                        + [f"Report generated in {time.perf_counter() - t0:.1f} s"])
    md_path, html_path = out / store.REPORT_MD, out / store.REPORT_HTML
    _write_atomic(md_path, doc.markdown())
    _write_atomic(html_path, doc.html(f"railtherm report: {data.name}"))
    return [md_path, html_path] + ctx.figures
