"""The report as a document a researcher reads: a table of contents whose links resolve, a way back from
every section, the study described from its own file, plain labels and researcher's units, wide tables
that scroll in their box, a note where constant properties no longer hold, a figure budget, and the
data files, commit and versions at the end.

A small study (green at level 0) is run once; the formatting functions are tested on their own.
"""
from __future__ import annotations

import html as htmllib
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from studies import ELLIPSE_CURVATURES, ellipse_scene

STUDY = """
# A small study whose comments say what its scenes are.
#
#   seed 6.4           "hot-band": a Hertzian band flux at 30 m/s, ten times the seed's, past melting.
#   seed 5.4 Table 1   "ellipse-sliding": Ertz & Knothe's ellipse in full sliding at 30 m/s.
schema_version = 1

[study]
name = "document-test"
description = "Scenes that exercise every part of the report"
methods = ["green"]
levels = [0]
reference = "analytic"
tolerance = 0.05

[study.published."rail-only"]
max_surface_temperature = 5.5
source = "a stand-in for a published value"

[defaults]
convection = 0.0

# --- seed 6.4, rail block ------------------------------------------------------------------------
[[scene]]
name = "hot-band"
speed = 30.0
heat_source = { flux = 2.5e9, shape = "hertz", half_width = 5.8789e-3 }
field = { behind = 0.02, depth = 0.15e-3, threshold = 1000.0 }
outputs = ["max_surface_temperature", "surface_temperature", "temperature", "peak_temperature", "cooling_rate",
           "heated_depth", "time_above"]

[[scene]]
name = "rail-only"               # all heat into the rail: the wheel stays at its bulk temperature
speed = 1.0
heat_source = { flux = 1e6, shape = "uniform", half_width = 2.5e-3 }
heat_partition = 0.0
outputs = ["max_surface_temperature", "surface_temperature"]

# --- seed 5.4, Table 1 ---------------------------------------------------------------------------
""" + ellipse_scene("ellipse-sliding", contact=ELLIPSE_CURVATURES) + """heat_partition = "equal-temperature"
outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "max_pressure",
           "semi_axis_a"]
"""


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    import railtherm
    from railtherm.report import write_report
    tmp = tmp_path_factory.mktemp("document")
    path = tmp / "study.toml"
    path.write_text(STUDY)
    study = railtherm.load_study(path)
    out = tmp / "out"
    railtherm.run_study(study, out=out, report=False)
    paths = write_report(out, study)
    return out, paths, (out / "report.md").read_text(), (out / "report.html").read_text()


def _scene(md: str, name: str) -> str:
    """The Markdown of a scene's own section."""
    return re.split(rf"^## \d+\. Scene `{re.escape(name)}`", md, flags=re.M)[1].split("\n## ")[0]


def _ids(html: str) -> set[str]:
    return set(re.findall(r'\sid="([^"]+)"', html))


def _h2s(html: str) -> list[str]:
    return re.findall(r"<h2[^>]*>.*?</h2>", html, flags=re.S)


def _text(html: str) -> str:
    """The visible text of the body, without code spans (scene names), tags and entities."""
    body = html.split("<body>", 1)[1]
    body = re.sub(r"<code>.*?</code>", " ", body, flags=re.S)
    return htmllib.unescape(re.sub(r"<[^>]+>", " ", body))


def test_contents_lists_every_section_and_every_link_resolves(report):
    _, _, _, html = report
    nav = re.search(r'<nav id="contents">(.*?)</nav>', html, flags=re.S)
    assert nav, "no table of contents"
    targets = re.findall(r'href="#([^"]+)"', nav.group(1))
    h2_ids = [re.search(r'id="([^"]+)"', h).group(1) for h in _h2s(html)]
    assert targets == h2_ids and len(targets) >= 6        # every section, in page order
    ids = _ids(html)
    missing = sorted({t for t in re.findall(r'href="#([^"]+)"', html)} - ids)
    assert not missing, missing
    assert html.index('<nav id="contents">') < html.index('<h2 id="verdict">')


def test_every_section_links_back_to_the_contents(report):
    _, _, md, html = report
    for h in _h2s(html):
        assert 'href="#contents"' in h, h
    assert md.count("[↑ back to contents](#contents)") == len(_h2s(html))


def test_verdict_and_key_findings_come_first_then_the_study(report):
    _, _, _, html = report
    heads = [re.sub(r"<[^>]+>", "", h).replace("↑ back to contents", "").strip() for h in _h2s(html)]
    assert heads[0] == "Verdict" and heads[1] == "The study and its scenes"
    verdict = html.split('<h2 id="verdict">')[1].split("<h2")[0]
    assert verdict.index("Key findings") < verdict.index("Scorecard")


def test_study_described_from_its_file(report):
    _, _, md, _ = report
    study = md.split("## The study and its scenes")[1].split("\n## ")[0]
    row = next(line for line in study.splitlines() if line.startswith("| [hot-band]"))
    assert "Hertzian band flux at 30 m/s" in row and "seed 6.4" in row
    row = next(line for line in study.splitlines() if line.startswith("| [ellipse-sliding]"))
    assert "Ertz & Knothe's ellipse" in row and "seed 5.4" in row and "Table 1" in row
    row = next(line for line in study.splitlines() if line.startswith("| [rail-only]"))
    assert "all heat into the rail" in row.lower()                # the comment on its name line
    assert "Scenes that exercise every part of the report" in md.split("## ")[0]  # the study's description


def test_hot_scene_says_constant_properties_no_longer_hold(report):
    _, _, md, _ = report
    for part in (_scene(md, "hot-band"), md.split("## The study")[1].split("\n## ")[0]):
        assert "past melting" in part or "constant material properties" in part
    scene = _scene(md, "hot-band")
    assert "constant material properties" in scene and "melts" in scene
    cool = _scene(md, "ellipse-sliding")
    assert "constant material properties" not in cool


def test_figures_once_and_each_in_its_section(report):
    out, paths, md, html = report
    srcs = re.findall(r'<img src="([^"]+)"', html)
    assert len(srcs) == len(set(srcs)) <= 40
    scene = _scene(md, "hot-band")   # a trace scene: its figures are in the trace section
    assert "figures/" not in scene and "(#trace-hot-band)" in scene
    assert '<a href="#trace-hot-band">thermal trace of <code>hot-band</code></a>' in html   # a link with code in it
    for src in srcs:                                          # each image states its size: the page does not jump
        assert re.search(rf'<img src="{re.escape(src)}" width="\d+" height="\d+"', html), src


def test_no_internal_labels_in_the_text(report):
    _, _, _, html = report
    text = _text(html)
    for raw in ("analytic:", "self:finest", "method:", "creepage.longitudinal", "max_surface_temperature",
                "× slower", "Δ −100 %"):
        assert raw not in text, raw
    assert not re.search(r"\d[eE]-?\d+\s?%", text)                # no "1.4e-14 %"
    level = re.search(r".{0,40}\bL\d\b(?! norm).{0,40}", text)   # the scorecard's cells included
    assert not level, level.group(0)
    assert "exact moving source" in text or "exact Jaeger band" in text


def test_units_a_researcher_reads(report):
    _, _, md, _ = report
    scene = _scene(md, "ellipse-sliding")
    assert "normal force 100 kN" in scene
    band = _scene(md, "hot-band")
    assert "flux 2,500 MW/m²" in band and "half-width 5.88 mm" in band


def test_unheated_body_is_not_a_minus_100_percent_error(report):
    _, _, md, _ = report
    scene = _scene(md, "rail-only")
    row = next(line for line in scene.splitlines() if line.startswith("| `max_surface_temperature` |"))
    assert "(rail)" in row and "−100 %" not in row and "wheel / rail" not in row


def test_tables_scroll_inside_their_box(report):
    _, _, _, html = report
    tables = html.count("<table")
    assert tables >= 4 and html.count('<div class="scroll"><table') == tables
    assert "div.scroll{overflow-x:auto" in html
    assert "white-space:nowrap" not in html.split("table.runs", 1)[-1].split("}", 1)[0]


def test_data_files_commit_and_versions_at_the_end(report):
    out, _, md, html = report
    for name in ("metrics.nc", "references.nc", "study.json"):
        assert (out / name).exists()
        assert f'<a href="{name}">' in html
    env = md.split("## Environment and code")[1]
    assert re.search(r"railtherm \d+\.\d+", env)
    assert "commit `" in env or "no commit id" in env
    assert re.search(r"Plugins and versions that produced the runs: .*green \d+\.\d+", env)


# -- the pieces ---------------------------------------------------------------------------------------
def test_figures_drawn_in_worker_processes_equal_those_drawn_here(report, tmp_path):
    """``write_report(..., workers=2)`` as run_study and the CLI draw (the study's fork-server context): the
    same PNG files byte for byte and the same HTML as the report drawn in this process, every file present
    when the report returns. Drawn again into a copy of the study's output without its report."""
    import railtherm
    from railtherm.report import write_report
    from railtherm.run.executors import worker_context
    out, one, _, _ = report
    parallel = tmp_path / "parallel"
    shutil.copytree(out, parallel)
    for p in one:
        (parallel / p.relative_to(out)).unlink()
    two = write_report(parallel, railtherm.load_study(out.parent / "study.toml"), workers=2, context=worker_context())
    figs = sorted(p.name for p in one if p.suffix == ".png")
    assert figs and figs == sorted(p.name for p in two if p.suffix == ".png")
    for name in figs:
        assert (out / "figures" / name).read_bytes() == (parallel / "figures" / name).read_bytes(), name

    def page(folder):
        text = (folder / "report.html").read_text().replace(str(folder), "OUT")
        return [line for line in text.splitlines() if "Report generated in" not in line]
    assert page(out) == page(parallel)


def test_number_and_unit_formats():
    from railtherm.report.format import num, pct, quantity, ratio, short
    assert quantity(8.051e8, "Pa") == "805 MPa" and quantity(5.8789e-3, "m") == "5.88 mm"
    assert quantity(1e5, "N") == "100 kN" and quantity(2.5e-5, "m2") == "25 mm²" and quantity(7.1154e6, "N/m") == "7,120 kN/m"
    assert num(7075.3) == "7,080" and num(149.1, 4) == "149.1" and num(99.96) == "100"
    assert pct(1.4e-16) == "< 0.001 %" and pct(0.0038) == "0.38 %" and pct(-12.3) == "−1,200 %"
    assert ratio(7075.3) == "7,080× the time"
    msg = "model 'fipy': 81920 cells > max_cells = 50000 (raise max_cells or use level 2)"
    cut = short(msg, 50)
    assert cut.endswith(" …") and msg.startswith(cut[:-2]) and msg[len(cut) - 2] == " "   # at a word boundary


def test_labels_one_mapping():
    from railtherm.report.format import label, level, plain
    assert label("analytic:moving-source") == "exact moving source"
    assert label("self:finest") == "own finest level" and label("method:kalker") == "kalker's finest level"
    assert label("creepage.longitudinal") == "longitudinal creepage"
    assert label("surface_temperature_l2") == "surface temperature (L2 norm)" and level(2) == "level 2"
    text = plain("against analytic:jaeger and self:finest over creepage.spin (7075× slower); see metrics.nc, "
                 "`creepage.spin`")
    assert text == ("against exact Jaeger band and own finest level over spin creepage (7,080× the time); see "
                    "metrics.nc, `creepage.spin`")


def test_figure_budget(tmp_path):
    """Beyond the budget nothing is drawn; the names are kept for the report's note."""
    from railtherm.report.document import Document
    from railtherm.report.figures import Palette, figure, save
    from railtherm.report.sections import Context

    def draw(*, path):
        fig = figure(2, 1)
        fig.subplots().plot([0, 1])
        return save(fig, path)

    ctx = Context(data=None, fig_dir=tmp_path, palette=Palette(), max_figures=2)
    doc = Document()
    for i in range(4):
        ctx.draw(doc, f"f{i}", "a figure", draw)
    assert len(ctx.figures) == 2 and ctx.left_out == ["f2", "f3"] and doc.figures == 2


def test_surface_line_goes_through_the_hottest_point():
    """A spin creepage heats the flanks: the line of the surface figure is where the body is hottest, not y = 0."""
    import xarray as xr

    from railtherm.report.scene_figures import line_y
    x, y = np.linspace(-1e-3, 1e-3, 11), np.linspace(-2e-3, 2e-3, 9)
    t = np.zeros((2, 11, 9))
    t[:, :, 1] = 9.0                    # 9 K on the flank y = -1.5 mm, nothing on the centre line
    ds = xr.Dataset({"surface_temperature": (("body", "x", "y"), t)}, coords={"x": x, "y": y})
    assert line_y(ds, 0) == pytest.approx(-1.5e-3)
