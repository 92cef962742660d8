"""Number, unit and label formatting for every text and axis of the report.

Numbers: three significant digits for quantities (:func:`num`, :func:`quantity`), two for relative
errors (:func:`pct`), thousands grouped ("7,080"). Units are the ones a railway researcher reads: MPa,
mm, kN, mm², kW, MW/m² (:func:`quantity` converts from SI). Labels: :func:`label` is the one mapping
from the names railtherm stores (reference tags such as ``analytic:moving-source``, dotted study keys
such as ``creepage.longitudinal``, result variables such as ``surface_temperature_l2``) to the words
the report prints, in text and on axes; :func:`plain` applies it to free text.
"""
from __future__ import annotations

import math
import re

__all__ = ["finite", "num", "pct", "duration", "memory", "level_range", "short", "slug", "exact", "level",
           "quantity", "ratio", "label", "plain", "grouped"]


def finite(v) -> bool:
    try:
        return v is not None and math.isfinite(float(v))
    except (TypeError, ValueError):
        return False


def grouped(text: str) -> str:
    """'7080' -> '7,080' (the integer part of a plain decimal number; exponents are left alone)."""
    if "e" in text:
        return text
    sign = "-" if text.startswith("-") else ""
    body = text[len(sign):]
    whole, dot, frac = body.partition(".")
    if len(whole) > 3 and whole.isdigit():
        whole = f"{int(whole):,}"
    return sign + whole + dot + frac


def num(v, digits: int = 3) -> str:
    """``v`` with ``digits`` significant digits, '–' when missing; no exponent between 1e-3 and 1e6."""
    if not finite(v):
        return "–"
    v = float(v)
    if v == 0:
        return "0"
    if 1e-3 <= abs(v) < 1e6:
        s = sig(v, digits)
        return grouped(s.rstrip("0").rstrip(".") if "." in s else s)
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
    if r != 0 and math.floor(math.log10(abs(r))) > e:   # 9.96 -> 10.0: one digit fewer after the point
        e += 1
    return f"{r:.{max(n - 1 - e, 0)}f}"


#: relative values below this print as "< 0.001 %": their digits are round-off, not information
PCT_FLOOR = 1e-5


def pct(v, unit: bool = True, signed: bool = False, floor: float = 0.0) -> str:
    """A relative value [1] as a percentage with two significant digits: 0.0038 -> '0.38 %'.

    ``floor`` [1]: magnitudes below it print as '≈0' (round-off); other magnitudes below 0.001 % print
    as '< 0.001 %'; ``signed`` adds '+' to positive values.
    """
    if not finite(v):
        return "–"
    v = float(v)
    p = abs(v) * 100.0
    sign = "−" if v < 0 else "+" if signed and v > 0 else ""
    u = " %" if unit else ""
    if p == 0:
        return "0" + u
    if abs(v) < floor:
        return "≈0" + u
    if abs(v) < PCT_FLOOR:
        return "< 0.001" + u
    return sign + grouped(sig(p, 2)) + u


def ratio(r) -> str:
    """A time ratio in words: 7075.3 -> '7,080× the time', 0.5 -> 'half the time'."""
    if not finite(r) or r <= 0:
        return "–"
    if abs(r - 0.5) < 0.05:
        return "half the time"
    return f"{grouped(sig(r, 3))}× the time"


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


#: SI unit -> (unit shown, factor from SI): what a researcher reads for contact and heat quantities
UNITS = {"Pa": ("MPa", 1e-6), "m": ("mm", 1e3), "N": ("kN", 1e-3), "N/m": ("kN/m", 1e-3), "m2": ("mm²", 1e6),
         "m²": ("mm²", 1e6), "W": ("kW", 1e-3), "W/m2": ("MW/m²", 1e-6), "W/m²": ("MW/m²", 1e-6),
         "N m": ("N m", 1.0), "m/s": ("m/s", 1.0), "K/s": ("K/s", 1.0), "s": ("ms", 1e3), "degC": ("°C", 1.0),
         "°C": ("°C", 1.0), "K": ("K", 1.0), "1": ("", 1.0), "m-1": ("1/m", 1.0), "1/m": ("1/m", 1.0)}


def unit(si: str) -> str:
    """The unit :func:`quantity` shows a value of SI unit ``si`` in ('Pa' -> 'MPa')."""
    return UNITS.get(si, (si, 1.0))[0]


def quantity(v, si: str, digits: int = 3, with_unit: bool = True) -> str:
    """A value in SI unit ``si`` in the unit a researcher reads, three significant digits:
    (8.051e8, 'Pa') -> '805 MPa', (5.88e-3, 'm') -> '5.88 mm', (1e5, 'N') -> '100 kN'."""
    shown, f = UNITS.get(si, (si, 1.0))
    text = num(float(v) * f, digits) if finite(v) else "–"
    return f"{text} {shown}" if with_unit and shown and text != "–" else text


def level(k) -> str:
    """A level of the resolution ladder in words: 2 -> 'level 2'."""
    return f"level {int(k)}"


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
    """``text`` on one line, shortened at a word boundary to at most ``n`` characters (with '…')."""
    text = " ".join(str(text).split())
    if len(text) <= n:
        return text
    cut = text[: n - 1]
    space = cut.rfind(" ")
    if space > n // 2:
        cut = cut[:space]
    return cut.rstrip(" ,;:") + " …"


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


# -- labels ----------------------------------------------------------------------------------------------
#: exact references by their tag in metrics.nc (``analytic:<tag>``)
EXACT_NAMES = {"moving-source": "exact moving source", "jaeger": "exact Jaeger band", "hertz": "exact Hertz",
               "carter": "exact Carter (2-D rolling)", "full-sliding": "exact full sliding",
               "given-source": "exact given source", "half-space-1d": "exact 1-D half-space"}
#: result variables and metrics
NAMES = {"max_surface_temperature": "max. surface temperature", "mean_contact_temperature": "mean contact temperature",
         "surface_temperature_l2": "surface temperature (L2 norm)", "pressure_l2": "pressure (L2 norm)",
         "max_pressure": "max. pressure", "semi_axis_a": "semi-axis a", "semi_axis_b": "semi-axis b",
         "creep_force_x": "creep force Fx", "creep_force_y": "creep force Fy", "spin_moment": "spin moment",
         "frictional_power": "frictional power", "normal_force": "normal force", "contact_area": "contact area",
         "steady_wheel_temperature": "steady wheel temperature",
         "steady_mean_contact_temperature": "steady mean contact temperature",
         "surface_temperature": "surface temperature", "peak_temperature": "peak temperature",
         "cooling_rate": "cooling rate", "cooling_rate_all_depths": "cooling rate, all depths",
         "heated_depth": "depth of the threshold isotherm", "time_above": "time above the threshold",
         "energy_balance": "energy balance", "headline": "headline quantity",
         "pass_peak_temperature": "peak temperature of each pass", "residual_rise": "residual rise before the next pass",
         "temperature_history": "temperature history"}
#: dotted study keys, where the general rule ("a.b" -> "a b") reads badly
KEYS = {"creepage.longitudinal": "longitudinal creepage", "creepage.lateral": "lateral creepage",
        "creepage.spin": "spin creepage", "heat_source.flux": "heat source flux",
        "numerics.regularization": "friction regularisation", "numerics.time_step": "time step"}


def label(name: str) -> str:
    """The words the report prints for a name railtherm stores.

    ``analytic:moving-source`` -> 'exact moving source'; ``self:finest`` -> 'own finest level';
    ``method:green`` -> "green's finest level"; ``creepage.longitudinal`` -> 'longitudinal creepage';
    ``surface_temperature_l2`` -> 'surface temperature (L2 norm)'; anything else is returned unchanged.
    """
    name = str(name)
    kind, sep, rest = name.partition(":")
    if sep and kind == "analytic":
        return EXACT_NAMES.get(rest, "exact " + rest.replace("-", " "))
    if sep and kind == "self":
        return "own finest level"
    if sep and kind == "method":
        return f"{rest}'s finest level"
    if name in NAMES:
        return NAMES[name]
    if name in KEYS:
        return KEYS[name]
    if re.fullmatch(r"[a-z][a-z0-9_]*(\.[a-z][a-z0-9_]*)+", name):    # another dotted study key
        parts = name.split(".")
        return " ".join(p.replace("_", " ") for p in parts)
    return name


_TOKEN = re.compile(r"\b(?:analytic|self|method):[A-Za-z0-9_.+-]*[A-Za-z0-9_]"
                    r"|\b[a-z][a-z0-9_]*(?:\.[a-z][a-z0-9_]+)+\b|\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")
_SLOWER = re.compile(r"\b(\d+(?:\.\d+)?)× slower\b")


def plain(text: str) -> str:
    """Free text with every stored name :func:`label` knows replaced by its words, and time ratios said as
    '7,080× the time' (file names such as ``metrics.nc`` and text inside backticks are left alone)."""
    parts = re.split(r"(`[^`]*`)", str(text))
    out = []
    for part in parts:
        if part.startswith("`") and part.endswith("`") and len(part) >= 2:
            out.append(part)
            continue
        part = _TOKEN.sub(lambda m: label(m.group(0)) if _known(m.group(0)) else m.group(0), part)
        part = _SLOWER.sub(lambda m: ratio(float(m.group(1))), part)
        out.append(part)
    return "".join(out)


def _known(token: str) -> bool:
    if token.split(":", 1)[0] in ("analytic", "self", "method") and ":" in token:
        return True
    if "." not in token:                  # a result variable: only the ones with words of their own
        return token in NAMES
    return token in KEYS or token.split(".", 1)[0] in ("creepage", "heat_source", "numerics", "wheel", "rail",
                                                        "contact", "field", "wheelset", "strip", "friction")
