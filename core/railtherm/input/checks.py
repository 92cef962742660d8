"""Value checkers of the scene vocabulary: each takes ``(scene, key, value)`` and returns the cleaned value
or raises :class:`railtherm.SceneError` naming the scene, the key, the value and what is allowed.

:mod:`railtherm.input.scene` builds its key table (``SCENE_KEYS``) from them; the friction checker reads
each law's parameters from :mod:`railtherm.physics.friction`, so a law's keys are declared once.
"""
from __future__ import annotations

import math
import re
from typing import Any, Mapping

from ..contract.errors import SceneError
from ..contract.schema import VARIABLES
from ..physics.friction import LAWS as FRICTION_LAWS
from ..physics.friction import Parameter

# --------------------------------------------------------------------------------------------
# value checkers: each returns the cleaned value or raises SceneError naming scene/key/value/allowed
# --------------------------------------------------------------------------------------------
class Check:
    allowed = "a value"
    sweepable = True
    #: UDUNITS-2 string of the value ("1" for a dimensionless number, None for text, flags and tables)
    unit: str | None = None

    def __call__(self, scene: str | None, key: str, value: Any) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def fail(self, scene, key, value):
        raise SceneError.bad_value(scene, key, value, self.allowed)


class Num(Check):
    """A finite real number in [lo, hi] (open ends where ``lo_open`` / ``hi_open``)."""

    def __init__(self, lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False, unit="1", note=""):
        self.lo, self.hi, self.lo_open, self.hi_open = lo, hi, lo_open, hi_open
        self.unit = unit  # UDUNITS-2: "m s-1", "W m-2 K-1", "1" (dimensionless)
        parts = []
        if lo > -math.inf:
            parts.append(f"{'>' if lo_open else '>='} {lo:g}")
        if hi < math.inf:
            parts.append(f"{'<' if hi_open else '<='} {hi:g}")
        self.allowed = ("a finite number" + (" " + " and ".join(parts) if parts else "")
                        + (f" [{unit}]" if unit != "1" else "") + (f" ({note})" if note else ""))

    def __call__(self, scene, key, value):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(scene, key, value)
        v = float(value)
        if not math.isfinite(v):
            self.fail(scene, key, value)
        if v < self.lo or (self.lo_open and v == self.lo) or v > self.hi or (self.hi_open and v == self.hi):
            self.fail(scene, key, value)
        return v


class Int(Check):
    def __init__(self, lo=0):
        self.lo = lo
        self.allowed = f"an integer >= {lo}"

    def __call__(self, scene, key, value):
        if isinstance(value, bool) or not isinstance(value, int) or value < self.lo:
            self.fail(scene, key, value)
        return int(value)


class Choice(Check):
    def __init__(self, *choices):
        self.choices = choices
        self.allowed = "one of " + ", ".join(repr(c) for c in choices)

    def __call__(self, scene, key, value):
        # the value and the choice must be of one type: 1 is not "1", and true is not 1
        if isinstance(value, bool) or not any(type(value) is type(c) and value == c for c in self.choices):
            self.fail(scene, key, value)
        return value


class Text(Check):
    allowed = "a non-empty string without '/'"
    sweepable = False

    def __call__(self, scene, key, value):
        if not isinstance(value, str) or not value.strip() or "/" in value or "\\" in value:
            self.fail(scene, key, value)
        return value


class ProfileSpec(Check):
    """A wheel or rail profile: a built-in name or a file path (read and checked by the wheelset)."""

    allowed = "a built-in profile name ('s1002', 'uic60') or a profile file path"
    sweepable = False

    def __call__(self, scene, key, value):
        if not isinstance(value, str) or not value.strip():
            self.fail(scene, key, value)
        return value


class Flag(Check):
    allowed = "true or false"
    sweepable = False

    def __call__(self, scene, key, value):
        if not isinstance(value, bool):
            self.fail(scene, key, value)
        return value


class Either(Check):
    def __init__(self, *checks):
        self.checks = checks
        self.allowed = " or ".join(c.allowed for c in checks)
        self.unit = next((c.unit for c in checks if c.unit), None)

    def __call__(self, scene, key, value):
        for c in self.checks:
            try:
                return c(scene, key, value)
            except SceneError:
                pass
        self.fail(scene, key, value)


class Pair(Check):
    """A list of two numbers, each checked by ``item``."""

    sweepable = False

    def __init__(self, item: Num):
        self.unit = item.unit
        self.item = item
        self.allowed = f"a list of two numbers, each {item.allowed.removeprefix('a ')}"

    def __call__(self, scene, key, value):
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            self.fail(scene, key, value)
        try:
            return tuple(self.item(scene, key, v) for v in value)
        except SceneError:
            self.fail(scene, key, value)


class Names(Check):
    sweepable = False

    def __init__(self, known):
        self.known = known

    @property
    def allowed(self):
        return "a list of variable names from: " + ", ".join(sorted(self.known()))

    def __call__(self, scene, key, value):
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, (list, tuple)) or not value:
            self.fail(scene, key, value)
        known = self.known()
        for v in value:
            if not isinstance(v, str) or v not in known:
                raise SceneError.bad_value(scene, key, v, self.allowed)
        return tuple(dict.fromkeys(value))


class GapCoefficients(Check):
    """Coefficients of an undeformed gap h(x, y) = sum c_ij x^i y^j [m]: a table whose keys are
    ``x<i>y<j>``, ``x<i>`` or ``y<j>`` (i + j >= 2; ``x2`` is c_20, ``y4`` c_04), SI units
    (c_ij in m^(1-i-j)); returned with its keys as written (see :func:`gap_powers`)."""

    sweepable = False
    allowed = ("a table of gap coefficients c_ij of h = sum c_ij x^i y^j [m] (SI), keys 'x<i>y<j>', 'x<i>' or "
               "'y<j>' with i + j >= 2, e.g. { x2 = 1.015, y2 = 0.4215, y4 = 2.0e3 }")

    _KEY = re.compile(r"^(?:x(\d+))?(?:y(\d+))?$")

    def __call__(self, scene, key, value):
        if not isinstance(value, Mapping) or not value:
            self.fail(scene, key, value)
        out = {}
        for k, v in value.items():
            m = self._KEY.match(str(k))
            if not k or not m:
                raise SceneError.bad_value(scene, f"{key}.{k}", v, self.allowed)
            i, j = int(m.group(1) or 0), int(m.group(2) or 0)
            if i + j < 2:
                raise SceneError.bad_value(scene, f"{key}.{k}", v, self.allowed)
            out[str(k)] = ANY(scene, f"{key}.{k}", v)
        return out


def gap_powers(coefficients: Mapping[str, float]) -> dict[tuple[int, int], float]:
    """``{"x2": 1.015, "y4": 2e3}`` -> ``{(2, 0): 1.015, (0, 4): 2e3}`` (keys checked by the scene)."""
    out = {}
    for k, c in coefficients.items():
        m = GapCoefficients._KEY.match(k)
        out[(int(m.group(1) or 0), int(m.group(2) or 0))] = float(c)
    return out


def quadratic_curvatures(coefficients: Mapping[tuple[int, int], float]) -> tuple[float, float] | None:
    """(A, B) [m-1] when the gap is Hertzian, h = A x^2 + B y^2 with A, B > 0; else None."""
    nonzero = {k: v for k, v in coefficients.items() if v != 0.0}
    if set(nonzero) <= {(2, 0), (0, 2)} and nonzero.get((2, 0), 0) > 0 and nonzero.get((0, 2), 0) > 0:
        return float(nonzero[(2, 0)]), float(nonzero[(0, 2)])
    return None


def gap_text(coefficients: Mapping[tuple[int, int], float]) -> str:
    """h(x, y) of a gap as text: ``1.015 x^2 + 0.4215 y^2 + 2000 y^4``."""
    def term(i, j, c):
        xs = "" if i == 0 else (" x" if i == 1 else f" x^{i}")
        ys = "" if j == 0 else (" y" if j == 1 else f" y^{j}")
        return f"{c:g}{xs}{ys}"
    return " + ".join(term(i, j, c) for (i, j), c in sorted(coefficients.items()))


class Table(Check):
    """A nested table with its own keys."""

    sweepable = False

    def __init__(self, keys: Mapping[str, Check]):
        self.keys = dict(keys)
        self.allowed = "a table with keys " + ", ".join(self.keys)

    def __call__(self, scene, key, value):
        if not isinstance(value, Mapping):
            self.fail(scene, key, value)
        out = {}
        for k, v in value.items():
            if k not in self.keys:
                raise SceneError(f"scene {scene!r}: unknown key {key + '.' + k!r} (value {v!r}); allowed keys of "
                                 f"{key!r}: {', '.join(self.keys)}", scene=scene, key=f"{key}.{k}", value=v,
                                 allowed=", ".join(self.keys))
            out[k] = self.keys[k](scene, f"{key}.{k}", v)
        return out


def _parameter_check(p: Parameter) -> Num:
    """The scene check of one law parameter, from the range the law declares."""
    return Num(p.lower, lo_open=p.lower_open, unit=p.unit)


def _friction_allowed() -> str:
    """What the key ``friction`` allows, in words, from the laws' parameters."""
    tables = ["{ law = " + f'"{kind}", ' + ", ".join(p.label for p in law.PARAMETERS) + " }"
              for kind, law in FRICTION_LAWS.items()]
    return "a number >= 0, or a table " + ", ".join(tables[:-1]) + " or " + tables[-1]


class Friction(Check):
    """Scene key ``friction``: a number >= 0 (constant coefficient) or a friction-law table
    ``{ law = ..., ... }`` whose keys and ranges the law declares (:mod:`railtherm.physics.friction`)."""

    unit = "1"
    #: law -> its parameters' checks, built from the laws' own :class:`~railtherm.physics.friction.Parameter`
    PARAMETER_CHECKS = {kind: {p.name: _parameter_check(p) for p in law.PARAMETERS}
                        for kind, law in FRICTION_LAWS.items()}
    allowed = _friction_allowed()

    def __call__(self, scene, key, value):
        if not isinstance(value, Mapping):
            return Num(0)(scene, key, value)
        law = value.get("law")
        if law not in self.PARAMETER_CHECKS:
            raise SceneError.bad_value(scene, f"{key}.law", law,
                                       "one of " + ", ".join(repr(k) for k in self.PARAMETER_CHECKS))
        keys = self.PARAMETER_CHECKS[law]
        out = {"law": law}
        for k, v in value.items():
            if k == "law":
                continue
            if k not in keys:
                raise SceneError(f"scene {scene!r}: unknown key {key + '.' + k!r} (value {v!r}); the law {law!r} "
                                 f"takes: {', '.join(keys)}", scene=scene, key=f"{key}.{k}", value=v,
                                 allowed=", ".join(keys))
            out[k] = keys[k](scene, f"{key}.{k}", v)
        missing = [k for k in keys if k not in out]
        if missing:
            raise SceneError(f"scene {scene!r}: key '{key}.{missing[0]}' is missing: the law {law!r} needs "
                             f"{', '.join(repr(k) for k in missing)} (it takes {', '.join(keys)})", scene=scene, key=f"{key}.{missing[0]}", value=None,
                             allowed=keys[missing[0]].allowed)
        conflict = FRICTION_LAWS[law].parameter_conflict(out)
        if conflict is not None:
            k, allowed = conflict
            raise SceneError.bad_value(scene, f"{key}.{k}", out[k], allowed)
        return out


def variable_names():
    return set(VARIABLES)


class Numbers(Check):
    """A list of numbers, not a sweep (a schedule's times or factors); the transient vocabulary
    (:func:`railtherm.input.transient.transient_from_table`) checks the values."""

    sweepable = False

    def __init__(self, unit="1", what="numbers"):
        self.unit = unit
        self.allowed = f"a list of {what}" + (f" [{unit}]" if unit != "1" else " [1]")

    def __call__(self, scene, key, value):
        if not isinstance(value, (list, tuple)):
            self.fail(scene, key, value)
        return list(value)


class DepthList(Numbers):
    """Depths of a transient scene's histories: one number or a list (the list itself, not a sweep)."""

    def __init__(self):
        super().__init__("m", "depths >= 0")


class FieldDepth(Either):
    """``field.depth``: one depth [m] > 0, or (transient scenes) a list of the histories' depths, which is
    the depths and not a sweep."""

    sweepable = False

    def __init__(self):
        super().__init__(Num(0, lo_open=True, unit="m"), DepthList())


#: any finite number (a gap coefficient)
ANY = Num()
