"""What each scene of a study is, in the study author's words: read from the study file's comments.

A study file explains its scenes in TOML comments (the vocabulary has no per-scene description key; a
scene's ``description`` is used first when a later release adds one). Three kinds of comment are read:

* a group title, ``# --- seed 5.4, Table 1 ----``: the scenes below it, up to the next title, belong
  to that group (it usually names the seed paper's table or section they reproduce);
* an entry, ``#   <label>   <text>`` with continuation lines indented deeper: the text after a quoted
  scene name (``"ek-low"``; ``"fdm-circular-q1/q10"`` names two scenes; ``"ek-exact-*"`` is a pattern)
  up to the next quoted name describes that scene; the label, when it is not a scene name, says where
  it comes from ("seed 5.4 Table 1");
* a comment on a scene's ``name = ...`` line and the comment lines below it at the same column.

The result is text for the report's study table; nothing here changes how a study runs.
"""
from __future__ import annotations

import fnmatch
import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["SceneNote", "scene_notes", "seed_reference"]

_TITLE = re.compile(r"^#\s*-{2,}\s*(.*?)\s*-*\s*$")
_ENTRY = re.compile(r"^#( {1,4})(\S.*?)(?: {2,}(\S.*))?$")
_QUOTED = re.compile(r'"([^"]+)"')
_SEED = re.compile(r"\bseed (?:§\s?)?\d+(?:\.\d+)*(?:,? (?:Table|Figs?\.?) [\d–-]+)?"
                   r"|\bseed (?:Table|Figs?\.?) [\d–-]+(?: kinds of plot)?|\bFigs? [\d–-]+\b")
_ISSUE = re.compile(r"\bissue \d+(?: item \d+)?[;,]?\s*")


@dataclass
class SceneNote:
    """A scene as its study file describes it."""

    group: str = ""        # the group title above the scene ("seed 5.4, Table 1")
    source: str = ""       # an entry's label naming a source ("seed 5.4 Table 1")
    text: str = ""         # what the scene is, in the author's words
    context: str = ""      # what the entry says of all its scenes before naming them


def _clean(text: str) -> str:
    text = _ISSUE.sub("", text)
    text = re.sub(r"\(\s*\)", "", text)
    text = re.sub(r"\(\s*;\s*", "(", text)
    text = re.sub(r"\bdegC\b", "°C", text)
    text = re.sub(r"\s+([:;,])", r"\1", " ".join(text.split()))
    return text.strip(" ,;:")


def _names(token: str) -> list[str]:
    """A quoted token -> the scene names or patterns it stands for ('a-q1/q10' -> ['a-q1', 'a-q10'])."""
    parts = token.split("/")
    first = parts[0]
    stem = first.rsplit("-", 1)[0] + "-" if "-" in first else ""
    return [first] + [stem + p for p in parts[1:] if p]


def _entries(lines: list[str]) -> list[tuple[str, str, int]]:
    """(label, text, line number) of every comment entry (continuation lines joined)."""
    out: list[list] = []
    for i, line in enumerate(lines):
        s = line.rstrip()
        if not s.startswith("#") or _TITLE.match(s):
            if not s.startswith("#"):
                out.append(None)
            continue
        body = s[1:]
        indent = len(body) - len(body.lstrip(" "))
        m = _ENTRY.match(s)
        prev = out[-1] if out else None
        if prev is not None and indent > prev[3] and body.strip():
            prev[1] += " " + body.strip()
            continue
        if m and body.strip():
            label, text = (m.group(2), m.group(3) or "") if m.group(3) else ("", m.group(2))
            out.append([label, text, i, indent])
        else:
            out.append(None)
    return [(e[0], e[1], e[2]) for e in out if e is not None]


def _segment(text: str, name: str) -> str | None:
    """The part of ``text`` that describes ``name``: after the run of quoted names it stands in, up to
    the next quoted name (None when ``name`` is not quoted in ``text``)."""
    quotes = list(_QUOTED.finditer(text))
    for k, q in enumerate(quotes):
        if not any(fnmatch.fnmatchcase(name, n) for n in _names(q.group(1))):
            continue
        j = k
        while j + 1 < len(quotes) and re.fullmatch(r"[\s,/]*(?:and\s*)?", text[quotes[j].end():quotes[j + 1].start()]):
            j += 1
        start = quotes[j].end()
        end = quotes[j + 1].start() if j + 1 < len(quotes) else len(text)
        seg = text[start:end]
        seg = re.sub(r"[;.]\s*[^;.]*$", ".", seg) if j + 1 < len(quotes) else seg   # drop the next name's lead-in
        return _clean(seg.lstrip(":; ,"))
    return None


def _scene_lines(lines: list[str]) -> list[tuple[int, str, str, str]]:
    """(line number, scene name, group title, inline comment) of every ``[[scene]]``."""
    out, group, i = [], "", 0
    while i < len(lines):
        t = _TITLE.match(lines[i].strip())
        if t:
            group = _clean(t.group(1))
        if lines[i].strip() == "[[scene]]":
            j = i + 1
            while j < len(lines) and not lines[j].strip().startswith("name"):
                j += 1
            m = re.match(r'\s*name\s*=\s*"([^"]+)"\s*(?:#\s*(.*))?$', lines[j]) if j < len(lines) else None
            if m:
                comment = [m.group(2) or ""]
                col = lines[j].find("#")
                k = j + 1
                while col > 0 and k < len(lines) and lines[k].find("#") == col and m.group(2):
                    comment.append(lines[k][col + 1:].strip())
                    k += 1
                out.append((i, m.group(1), group, _clean(" ".join(comment))))
        i += 1
    return out


def scene_notes(path, scenes) -> dict[str, SceneNote]:
    """Scene name (generated sweep members included: read by their base name) -> its :class:`SceneNote`.

    ``scenes`` are the study's Scene objects (or names); a scene's own ``description``, when it has
    one, is its text. An unreadable file gives notes from descriptions only.
    """
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines() if path else []
    except OSError:
        lines = []
    entries = _entries(lines)
    placed = {name: (group, comment) for _, name, group, comment in _scene_lines(lines)}
    out = {}
    for sc in scenes:
        name = getattr(sc, "name", sc)
        base = str(name).split("--", 1)[0]
        group, comment = placed.get(base, ("", ""))
        note = SceneNote(group=group)
        own = str(getattr(sc, "description", "") or "")
        texts = [own] if own else []
        for label, text, _ in entries:
            seg = _segment(text, base)
            lab = _segment(label, base)
            if seg is None and lab is None:
                continue
            if lab is not None:          # the label is the scene's name: the whole text is about it
                seg = _clean(text)
            elif label and not note.source:
                note.source = _clean(label)
                first = _QUOTED.search(text)
                note.context = _clean(text[:first.start()]) if first else ""
            if seg and not own:
                texts.append(seg)
        if comment and not own:
            texts.append(comment)
        note.text = " ".join((t[:1].upper() + t[1:]) if t.endswith(".") else (t[:1].upper() + t[1:] + ".")
                             for t in texts if t)
        out[str(name)] = note
    return out


def seed_reference(note: SceneNote) -> str:
    """The seed-paper tables, sections and figures a note names ('seed 5.4 Table 1; Figs 4-7'), or ''."""
    found = []
    for text in (note.group, note.source, note.context, note.text):
        for m in _SEED.finditer(text or ""):
            ref = re.sub(r"(\d),? (Table|Fig)", r"\1 \2", m.group(0)).replace("-", "–")
            if not any(ref in f or f in ref for f in found):
                found.append(ref)
    return "; ".join(found)
