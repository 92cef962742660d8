"""Compact number formatting for report tables and sentences: times, percentages, memory, ranges."""
from __future__ import annotations

import math
import re

__all__ = ["finite", "num", "pct", "duration", "memory", "level_range", "short", "slug", "exact"]


def finite(v) -> bool:
    try:
        return v is not None and math.isfinite(float(v))
    except (TypeError, ValueError):
        return False


def num(v, digits: int = 3) -> str:
    """``v`` with ``digits`` significant digits, '–' when missing."""
    if not finite(v):
        return "–"
    v = float(v)
    if v == 0:
        return "0"
    s = f"{v:.{digits}g}"
    if "e" in s:  # 1.2e-05 -> 1.2e-5
        mant, exp = s.split("e")
        s = f"{mant}e{int(exp)}"
    return s


def sig(x: float, n: int = 2) -> str:
    """``x`` to ``n`` significant digits without an exponent for |x| >= 1e-3: 123.4 -> '120', 0.0123 -> '0.012'."""
    x = float(x)
    if x == 0 or not math.isfinite(x):
        return "0" if x == 0 else "–"
    e = math.floor(math.log10(abs(x)))
    if e < -3:
        mant, exp = f"{x:.{max(n - 1, 0)}e}".split("e")
        return f"{mant}e{int(exp)}"
    r = round(x, -(e - n + 1))
    return f"{r:.{max(n - 1 - e, 0)}f}"


def pct(v, unit: bool = True, signed: bool = False, floor: float = 0.0) -> str:
    """A relative value [1] as a percentage with two significant digits: 0.0038 -> '0.38 %'.

    ``floor`` [1]: magnitudes below it print as '≈0' (round-off); ``signed`` adds '+' to positive values.
    """
    if not finite(v):
        return "–"
    v = float(v)
    p = abs(v) * 100.0
    sign = "−" if v < 0 else "+" if signed and v > 0 else ""
    if p == 0:
        return "0" + (" %" if unit else "")
    if abs(v) < floor:
        return "≈0" + (" %" if unit else "")
    return sign + sig(p, 2) + (" %" if unit else "")


def duration(s) -> str:
    """Seconds as '380 µs', '2.1 ms', '0.24 s', '14 s', '3.2 min'."""
    if not finite(s):
        return "–"
    s = float(s)
    if s < 1e-3:
        return f"{sig(s * 1e6)} µs"
    if s < 0.1:
        return f"{sig(s * 1e3)} ms"
    if s < 100:
        return f"{sig(s)} s"
    return f"{sig(s / 60)} min"


def memory(b) -> str:
    """Bytes as '850 kB', '12 MB', '1.3 GB'."""
    if not finite(b):
        return "–"
    b = float(b)
    for unit, f in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if abs(b) >= f:
            return f"{sig(b / f)} {unit}"
    return f"{b:.0f} B"


def level_range(levels) -> str:
    """[0, 1, 2, 5] -> '0–2, 5'."""
    lv = sorted(set(int(x) for x in levels))
    parts, i = [], 0
    while i < len(lv):
        j = i
        while j + 1 < len(lv) and lv[j + 1] == lv[j] + 1:
            j += 1
        parts.append(str(lv[i]) if i == j else f"{lv[i]}–{lv[j]}")
        i = j + 1
    return ", ".join(parts)


def short(text, n: int = 160) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 1] + "…"


def slug(text: str) -> str:
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", str(text)).strip("_.")
    return s[:80] or "x"


def exact(v) -> str:
    """A published value printed as given in the study file: 149.7 -> '149.7' (shortest repr)."""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # the shortest text that reads back as the same float: 149.7, 55.0
    return str(v)
