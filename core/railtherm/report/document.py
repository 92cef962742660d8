"""The report's document model: blocks (headings, paragraphs, lists, numbered tables and figures,
collapsible details, a table of contents) rendered once to Markdown and once to self-contained HTML.

Inline markup understood in every text: `code`, **bold** and [text](#anchor) or [text](relative/file)
links. Table cells are strings or :class:`Cell` (a string with a CSS class: the HTML colours the status
of a run). Every section (a level-2 heading) has an anchor and, once the document has a table of
contents, a link back to it; every table sits in a box that scrolls sideways when it is wider than the
page, so that the page itself never does.
"""
from __future__ import annotations

import html
import re
from dataclasses import dataclass, field
from typing import Union

__all__ = ["Cell", "Document"]


@dataclass(frozen=True)
class Cell:
    """A table cell with a CSS class (``ok``, ``inaccurate``, ``unverified``, ``refused``, ``failed``)."""

    text: str
    css: str = ""

    def __str__(self) -> str:
        return self.text


CellLike = Union[str, Cell]


_LINK = re.compile(r"\[([^\]]+)\]\((#[^)\s]+|[A-Za-z0-9_][A-Za-z0-9_./-]*)\)")


def _code_bold(text: str) -> str:
    out = []
    for part in re.split(r"(`[^`]*`)", text):
        if len(part) >= 2 and part.startswith("`") and part.endswith("`"):
            out.append(f"<code>{html.escape(part[1:-1])}</code>")
            continue
        out.append(re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", html.escape(part)))
    return "".join(out)


def inline_html(text: str) -> str:
    """HTML-escape ``text`` keeping `code`, **bold** and [text](#anchor) or [text](file) links (whose text
    may hold `code` and **bold** itself)."""
    text, out, pos = str(text), [], 0
    for m in _LINK.finditer(text):
        out.append(_code_bold(text[pos:m.start()]))
        out.append(f'<a href="{html.escape(m.group(2))}">{_code_bold(m.group(1))}</a>')
        pos = m.end()
    out.append(_code_bold(text[pos:]))
    return "".join(out)


def _md_cell(c: CellLike) -> str:
    return str(c).replace("|", "\\|").replace("\n", " ")


#: anchor of the table of contents, the target of every section's link back
CONTENTS = "contents"


@dataclass
class _Heading:
    level: int
    text: str
    anchor: str | None
    back: bool = False   # a link back to the table of contents (set when the document has one)

    def md(self) -> str:
        out = (f'<a id="{self.anchor}"></a>\n\n' if self.anchor else "") + "#" * self.level + " " + self.text
        return out + (f"\n\n[↑ back to contents](#{CONTENTS})" if self.back else "")

    def html(self) -> str:
        anchor = f' id="{html.escape(self.anchor)}"' if self.anchor else ""
        back = f' <a class="back" href="#{CONTENTS}">↑ back to contents</a>' if self.back else ""
        return f"<h{self.level}{anchor}>{inline_html(self.text)}{back}</h{self.level}>"


@dataclass
class _Contents:
    """The table of contents: a link to every section (level-2 heading), filled in when rendered."""

    entries: list = field(default_factory=list)   # [(anchor, text)]

    def md(self) -> str:
        return (f'<a id="{CONTENTS}"></a>\n\n**Contents**\n\n'
                + "\n".join(f"- [{_strip_links(t)}](#{a})" for a, t in self.entries))

    def html(self) -> str:
        items = "".join(f'<li><a href="#{html.escape(a)}">{inline_html(_strip_links(t))}</a></li>'
                        for a, t in self.entries)
        return f'<nav id="{CONTENTS}"><b>Contents</b><ul class="toc">{items}</ul></nav>'


def _strip_links(text: str) -> str:
    return re.sub(r"\[([^\]]+)\]\([^)]*\)", r"\1", text)


def anchor_text(text: str) -> str:
    """An HTML id from a heading's text: 'Scene `ek-low`' -> 'scene-ek-low'."""
    return re.sub(r"[^A-Za-z0-9]+", "-", _strip_links(text)).strip("-").lower() or "section"


@dataclass
class _Paragraph:
    text: str
    css: str = ""

    def md(self) -> str:
        return self.text

    def html(self) -> str:
        cls = f' class="{self.css}"' if self.css else ""
        return f"<p{cls}>{inline_html(self.text)}</p>"


@dataclass
class _List:
    items: list[str]

    def md(self) -> str:
        return "\n".join("- " + t for t in self.items)

    def html(self) -> str:
        return "<ul>" + "".join(f"<li>{inline_html(t)}</li>" for t in self.items) + "</ul>"


@dataclass
class _Table:
    number: int
    caption: str
    header: list[str]
    rows: list[list[CellLike]]
    css: str = ""

    def md(self) -> str:
        lines = [f"**Table {self.number}.** {self.caption}", "",
                 "| " + " | ".join(_md_cell(h) for h in self.header) + " |",
                 "|" + "|".join("---" for _ in self.header) + "|"]
        lines += ["| " + " | ".join(_md_cell(c) for c in r) + " |" for r in self.rows]
        return "\n".join(lines)

    def html(self) -> str:
        head = "".join(f"<th>{inline_html(h)}</th>" for h in self.header)

        def td(c):
            cls = f' class="{c.css}"' if isinstance(c, Cell) and c.css else ""
            return f"<td{cls}>{inline_html(str(c))}</td>"

        rows = "".join("<tr>" + "".join(td(c) for c in r) + "</tr>" for r in self.rows)
        cls = f' class="{self.css}"' if self.css else ""
        return (f'<div class="scroll"><table{cls}><caption><b>Table {self.number}.</b> {inline_html(self.caption)}'
                f"</caption><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table></div>")


@dataclass
class _Figure:
    number: int
    src: str
    caption: str
    width: int | None  # CSS pixels (the PNG holds twice as many)
    height: int | None = None

    def md(self) -> str:
        return f"![Figure {self.number}]({self.src})\n\n**Figure {self.number}.** {self.caption}"

    def html(self) -> str:
        w = (f' width="{self.width}"' if self.width else "") + (f' height="{self.height}"' if self.height else "")
        return (f'<figure><img src="{html.escape(self.src)}"{w} alt="Figure {self.number}">'
                f"<figcaption><b>Figure {self.number}.</b> {inline_html(self.caption)}</figcaption></figure>")


@dataclass
class _Details:
    summary: str
    blocks: list = field(default_factory=list)

    def md(self) -> str:
        inner = "\n\n".join(b.md() for b in self.blocks)
        return f"<details><summary>{html.escape(self.summary)}</summary>\n\n{inner}\n\n</details>"

    def html(self) -> str:
        inner = "\n".join(b.html() for b in self.blocks)
        return f"<details><summary>{inline_html(self.summary)}</summary>\n{inner}\n</details>"


STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;max-width:980px;margin:1.2em auto;padding:0 12px;
color:#222;line-height:1.4;font-size:15px}
h1{font-size:1.5em;margin:0.3em 0}h2{border-bottom:1px solid #ccc;margin-top:1.8em;font-size:1.25em}
h3{font-size:1.05em}
a.back{float:right;font-size:0.62em;font-weight:normal;color:#245;text-decoration:none;margin-top:0.45em}
nav#contents{background:#f6f8fa;border:1px solid #dde;padding:6px 12px;margin:0.8em 0}
ul.toc{columns:2;column-gap:2em;margin:0.3em 0;padding-left:0.4em;list-style:none;font-size:0.9em}
ul.toc li{margin:0.1em 0}
div.scroll{overflow-x:auto;max-width:100%;margin:0.5em 0 0.9em}
table{border-collapse:collapse;font-size:0.82em}
caption{caption-side:top;text-align:left;font-size:0.95em;color:#333;padding:2px 0}
th,td{border:1px solid #bbb;padding:2px 5px;text-align:left;vertical-align:top;overflow-wrap:break-word}
th{background:#eee}
td.ok{background:#dff0d8}td.inaccurate{background:#fbe3c8}td.unverified{background:#eeeeee;font-style:italic}
td.refused{background:#f7f7f7;color:#666}td.failed{background:#f5c6c6}
img{max-width:100%;height:auto}figure{margin:0.8em 0}figcaption{font-size:0.85em;color:#444}
code{background:#f2f2f2;padding:0 3px;font-size:0.92em}
details{margin:0.4em 0 0.8em}summary{cursor:pointer;color:#245}
p.note{font-size:0.88em;color:#555}p.warning{background:#fff4e5;border-left:4px solid #e8a33d;padding:4px 8px}
table.scorecard td:first-child{white-space:nowrap}li{margin:0.2em 0}
"""


class Document:
    """An ordered list of blocks; tables and figures are numbered in the order they are added.

    Every level-2 heading gets an anchor (from its text when none is given, made unique); after
    :meth:`contents` the rendered document lists them there and each links back to it.
    """

    def __init__(self):
        self.blocks: list = []
        self._stack: list[list] = [self.blocks]
        self.tables = 0
        self.figures = 0
        self._contents: _Contents | None = None
        self._anchors: set[str] = set()

    @property
    def _target(self) -> list:
        return self._stack[-1]

    def heading(self, level: int, text: str, anchor: str | None = None):
        if level == 2 and not anchor:
            anchor = anchor_text(text)
        if anchor:
            base, k = anchor, 2
            while anchor in self._anchors:
                anchor, k = f"{base}-{k}", k + 1
            self._anchors.add(anchor)
        self._target.append(_Heading(level, text, anchor))

    def contents(self):
        """Place the table of contents here: every section added before or after is listed."""
        self._contents = _Contents()
        self._target.append(self._contents)

    def paragraph(self, text: str, note: bool = False, css: str = ""):
        if text:
            self._target.append(_Paragraph(text, css or ("note" if note else "")))

    def bullets(self, items, css: str = ""):
        items = [t for t in items if t]
        if items:
            self._target.append(_List(items))

    def table(self, caption: str, header: list[str], rows: list[list[CellLike]], css: str = "") -> int | None:
        """Add a numbered table; returns its number (None when ``rows`` is empty: nothing added)."""
        if not rows:
            return None
        self.tables += 1
        self._target.append(_Table(self.tables, caption, list(header), [list(r) for r in rows], css))
        return self.tables

    def figure(self, src: str, caption: str, width: int | None = None, height: int | None = None) -> int:
        self.figures += 1
        self._target.append(_Figure(self.figures, src, caption, width, height))
        return self.figures

    def details(self, summary: str):
        """Context manager: blocks added inside go into a collapsible ``<details>`` (closed; none when empty)."""
        doc = self

        class _Ctx:
            def __enter__(self_):
                d = self_.block = _Details(summary)
                doc._target.append(d)
                doc._stack.append(d.blocks)
                return d

            def __exit__(self_, *exc):
                blocks = doc._stack.pop()
                parent = doc._target
                if not blocks and parent and parent[-1] is self_.block:   # nothing went in: no empty box
                    parent.pop()
                return False

        return _Ctx()

    def _finish(self):
        """Fill the table of contents and give every section its link back."""
        if self._contents is None:
            return
        sections = [b for b in self.blocks if isinstance(b, _Heading) and b.level == 2 and b.anchor]
        self._contents.entries = [(b.anchor, b.text) for b in sections]
        for b in sections:
            b.back = True

    def markdown(self) -> str:
        self._finish()
        return "\n\n".join(b.md() for b in self.blocks) + "\n"

    def html(self, title: str) -> str:
        self._finish()
        body = "\n".join(b.html() for b in self.blocks)
        return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                f'<meta name="viewport" content="width=device-width, initial-scale=1">'
                f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>\n{body}\n</body></html>\n")
