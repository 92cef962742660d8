"""Documentation in the repository: cited documents exist, no machine paths, one DOI per reference; the
plugin guide's example plugin and conformance test run as written and keep core's sign conventions."""
from __future__ import annotations

import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _files():
    for top in ("core", "plugins", "tests", "studies", "docs"):
        for p in sorted((ROOT / top).rglob("*")):
            if p.is_file() and p.suffix in {".py", ".toml", ".md", ".txt", ".cfg"} and "__pycache__" not in p.parts:
                yield p
    for name in ("README.md", "pyproject.toml"):
        if (ROOT / name).exists():
            yield ROOT / name


def test_every_document_cited_under_docs_exists():
    cited = set()
    for p in _files():
        cited |= set(re.findall(r"\bdocs/([\w.-]+\.md)\b", p.read_text(errors="replace")))
    # relative links between the documents of docs/
    for p in DOCS.glob("*.md"):
        cited |= set(re.findall(r"\]\(([\w.-]+\.md)\)", p.read_text()))
    assert {"DESIGN.md", "NOTES.md", "verdicts.md", "references.md", "plugins.md"} <= cited | {"plugins.md"}
    missing = sorted(c for c in cited if not (DOCS / c).is_file())
    assert not missing, f"cited but not in docs/: {missing}"


def test_every_cited_test_or_benchmark_file_exists():
    """A document that names a test or benchmark module (``tests/test_x.py``) names one that exists."""
    docs = [ROOT / "README.md", *DOCS.glob("*.md"), *(ROOT / "tests").rglob("*.md"), *(ROOT / "benchmarks").rglob("*.md")]
    cited = {(p.relative_to(ROOT), c) for p in docs if p.is_file()
             for c in re.findall(r"\b((?:tests|benchmarks)/[\w/.-]+\.py)\b", p.read_text(errors="replace"))}
    assert cited, "no document names a test module"
    missing = sorted((str(p), c) for p, c in cited if not (ROOT / c).is_file())
    assert not missing, f"documents name test modules that do not exist: {missing}"


def test_cited_sections_exist():
    design = (DOCS / "DESIGN.md").read_text()
    for section in ("Scene vocabulary", "Result schema", "Stages", "Statuses", "Commands and exit codes"):
        assert f"## {section}" in design, section
    for p in _files():
        for sec in re.findall(r'docs/DESIGN\.md[^"\n]{0,4}\("?"([^"]+)"\)?|docs/DESIGN\.md, "([^"]+)"',
                              p.read_text(errors="replace")):
            name = next(s for s in sec if s)
            assert f"## {name}" in design, (p, name)


def test_no_machine_paths():
    bad = []
    needles = ("/work/", "../" + "shared")
    for p in _files():
        if p == Path(__file__).resolve():
            continue
        text = p.read_text(errors="replace")
        for n in needles:
            if n in text:
                bad.append(f"{p.relative_to(ROOT)}: {n}")
    assert not bad, bad


# a DOI may hold balanced parentheses (10.1016/S0043-1648(99)00113-1); it never ends in a period
_DOI = re.compile(r"(?:doi:|doi\.org/)\s*(10\.\d{4,9}/(?:[^\s,;()\]]|\([^\s()]*\))*(?:[^\s,;.()\]]|\([^\s()]*\)))", re.I)


AUTHORS = ("Ertz", "Kalker", "Carter", "Johnson", "Hertz", "Richardson", "Guyer", "Alart", "Hueeber",
           "Hüeber", "Byrd", "Stichel", "Polonsky")
_MARKERS = (".. [", "\n- ", "\n#", "\n\n", "\n|")


def _citations():
    """(file, author, year, doi) of every DOI in the sources, with the citation text just before it."""
    for p in _files():
        if p == Path(__file__).resolve():
            continue
        text = p.read_text(errors="replace")
        prev = 0
        for m in _DOI.finditer(text):
            ctx = text[prev:m.start()]
            prev = m.end()
            line_start = text.rfind("\n", 0, m.start()) + 1
            if text.startswith("|", line_start):  # a markdown table row: the row is the citation
                ctx = text[line_start:m.start()]
            cut = max(ctx.rfind(k) for k in _MARKERS)
            ctx = ctx[max(cut, 0):]
            for author in AUTHORS:
                if author in ctx:
                    year = re.search(r"(1[89]\d\d|20\d\d)", ctx[ctx.index(author):])
                    yield p, author, year.group(1) if year else "", m.group(1).rstrip(".")
                    break


def test_one_doi_per_reference():
    """A cited work gets one DOI everywhere (Ertz & Knothe 2002 had two); Ertz & Knothe none (not verified)."""
    by_work: dict = {}
    for p, author, year, doi in _citations():
        by_work.setdefault((author, year), {}).setdefault(doi, []).append(str(p.relative_to(ROOT)))
    many = {k: v for k, v in by_work.items() if len(v) > 1}
    assert not many, many
    assert not [k for k in by_work if k[0] == "Ertz"], by_work.get(("Ertz", "2002"))
    # every DOI of the code is listed in docs/references.md
    listed = (DOCS / "references.md").read_text()
    unlisted = sorted({d for v in by_work.values() for d in v if d not in listed})
    assert not unlisted, unlisted


def test_references_identify_the_seed_paper():
    text = (DOCS / "references.md").read_text()
    assert "Comparison of Numerical Methods for Solution of Thermoelastic Wheel–Rail" in text
    assert "Ertz" in text and "DOI not verified" in text


# ---------------------------------------------------------------------------------------------
# docs/plugins.md: its example plugin and its conformance test run as written

def _block(path: Path, first_line: str) -> str:
    text = path.read_text()
    m = re.search(r"```python\n(" + re.escape(first_line) + r"\n.*?)```", text, re.S)
    assert m, f"{path.name}: no python block starting with {first_line!r}"
    return m.group(1)


def _module(name: str, code: str):
    mod = types.ModuleType(name)
    exec(compile(code, name, "exec"), mod.__dict__)
    return mod


def _my_plugin(sliding_code: str):
    pkg = types.ModuleType("my_plugin")
    pkg.__path__ = []
    pkg.plugin = _module("my_plugin.plugin", _block(ROOT / "README.md", "# my_plugin/plugin.py"))
    pkg.sliding = _module("my_plugin.sliding", sliding_code)
    return pkg


def test_plugin_guide_example_passes_the_conformance_kit_as_written(railtherm_register, monkeypatch):
    """The guide's tangential model (with the README's temperature model) through the guide's own test."""
    pkg = _my_plugin(_block(DOCS / "plugins.md", "# my_plugin/sliding.py"))
    for name, mod in (("my_plugin", pkg), ("my_plugin.plugin", pkg.plugin), ("my_plugin.sliding", pkg.sliding)):
        monkeypatch.setitem(sys.modules, name, mod)
    test = _block(DOCS / "plugins.md", "from railtherm.testing import check_method")
    _module("guide_test", test).test_conformance(railtherm_register)
    from railtherm.testing import check_method
    out = check_method("plain")
    assert out["ellipse-full-sliding"] == "ok" and out["line-full-sliding"] == "ok"
    assert out.models["plain-sliding"].startswith("sign conventions checked on ellipse-full-sliding")


def test_plugin_guide_example_with_the_old_sign_fails_the_kit(railtherm_register):
    """The same model with 'dissipation = traction x slip velocity' (what the guide said before it stated the
    conventions) is caught: a frictional heat source of -30 kW."""
    code = _block(DOCS / "plugins.md", "# my_plugin/sliding.py")
    assert code.count("dissipation=-traction * slip") == 1
    pkg = _my_plugin(code.replace("dissipation=-traction * slip", "dissipation=traction * slip"))
    host = railtherm_register("crude", pkg.plugin)
    host.add_plugin(pkg.sliding, "plain")
    host.build()
    from railtherm.testing import check_method
    with pytest.raises(AssertionError, match=r"'plain'.*'plain-sliding' gives a frictional power density of -"):
        check_method("plain")


def test_plugin_guide_states_the_sign_conventions_core_uses():
    """The conventions the guide writes down are the ones of core's reference models (full sliding at v_s > 0:
    traction +mu p on the wheel, slip -v_s, dissipation mu p v_s) and of core's frictional heat source."""
    import railtherm
    from railtherm.testing import canonical
    guide = (DOCS / "plugins.md").read_text()
    for words in ("material flows towards −x", "act **on the wheel**", "−(traction · slip\n  velocity) ≥ 0"):
        assert words in guide, words
    ds = railtherm.solve(canonical("ellipse-full-sliding", outputs=["traction_x", "slip_velocity_x", "heat_flux",
                                                                     "frictional_power", "creep_force_x"]),
                         {"normal": "hertz", "tangential": "full-sliding", "heat_source": "frictional"}, 0)
    inside = ds.heat_flux.sum("body").values > 0
    assert np.all(ds.traction_x.values[inside] > 0) and np.all(ds.slip_velocity_x.values[inside] == -1.0)
    assert float(ds.creep_force_x) > 0
    assert float(ds.frictional_power) == pytest.approx(0.3 * 100e3 * 1.0, rel=1e-12)


def test_every_path_of_designs_layout_table_exists():
    """docs/DESIGN.md's layout table names folders and modules of the tree: each exists (indented rows are
    inside core/railtherm/), and every layer folder of core/railtherm/ is in the table."""
    import re
    root = DOCS.parent
    text = (DOCS / "DESIGN.md").read_text()
    table = text[text.index("## Layout"):]
    table = table[:table.index("\n\n")]
    named = []
    for line in table.splitlines()[2:]:
        cell = line.split("|")[1].strip()
        inside = cell.startswith("`  ")                      # indented: a part of core/railtherm/
        for path in re.findall(r"`\s*([\w./-]+)`", cell):
            named.append(root / "core" / "railtherm" / path if inside else root / path)
    missing = [str(p.relative_to(root)) for p in named if not p.exists()]
    assert named and missing == []
    layers = {p.name for p in (root / "core" / "railtherm").iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert layers <= {p.name for p in named}, layers - {p.name for p in named}


def test_designs_layout_table_orders_the_layers_as_the_import_graph_test():
    """The indented rows of docs/DESIGN.md's layout table, read bottom up, are the layers of
    tests/test_import_graph.py's ``RANKS`` rank by rank (two layers in one row share a rank), and the
    count the table states is the number of rows."""
    import re
    from test_import_graph import RANKS
    text = (DOCS / "DESIGN.md").read_text()
    table = text[text.index("## Layout"):]
    table = table[:table.index("\n\n")]
    rows = [line.split("|")[1].strip() for line in table.splitlines()[2:]]
    layers = [{p.split("/")[0].split(".")[0] for p in re.findall(r"`\s*([\w./-]+)`", cell)}
              for cell in rows if cell.startswith("`  ")]
    ranked = {}
    for name, rank in RANKS.items():
        ranked.setdefault(rank, set()).add("cli" if name == "top" else name)
    expected = [ranked[r] - {"_version"} for r in sorted(ranked)]
    assert [layer - {"testing"} for layer in reversed(layers)] == expected
    words = {"seven": 7, "eight": 8, "nine": 9, "ten": 10}
    stated = re.search(r"in (\w+) layers", table)
    assert stated and words[stated.group(1)] == len(layers), stated


def test_paths_the_contract_docs_cite_exist():
    """Every dotted name ``railtherm...`` (or a built-in plugin's) in backticks in docs/DESIGN.md and
    docs/NOTES.md is a module, or an attribute of one, of this tree (no alias path, no removed module); the
    entry-point group ``railtherm.plugins`` is a name, not a module."""
    import importlib
    def resolves(dotted):
        parts = dotted.split(".")
        for i in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
            except ImportError:
                continue
            try:
                for name in parts[i:]:
                    obj = getattr(obj, name)
            except AttributeError:
                return False
            return True
        return False
    assert not resolves("railtherm.runner") and resolves("railtherm.physics.friction.LAW_KINDS")
    cited = {(doc, m) for doc in ("DESIGN.md", "NOTES.md")
             for m in re.findall(r"`(railtherm(?:_\w+)?(?:\.\w+)+)", (DOCS / doc).read_text())}
    missing = sorted(f"{doc}: {m}" for doc, m in cited if m != "railtherm.plugins" and not resolves(m))
    assert cited and missing == [], missing
