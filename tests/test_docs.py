"""Documentation in the repository: cited documents exist, no machine paths, one DOI per reference."""
from __future__ import annotations

import re
from pathlib import Path

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
