"""Model options and their validation, and the validation of a whole study before anything runs.

* :class:`Option` -- one option a model declares (default, doc, allowed values), checked by its model.
* :func:`check_options` -- the options of one method (``[study.options.<method>]`` or
  ``railtherm.solve(..., options=...)``): the allowed keys are the union of the options declared by
  the method's models plus the global ``cells``; each model validates the values it declares.
* :func:`check_study` -- everything a study names that core can check without running: methods,
  option tables, option keys and values, references, levels.

Both raise :class:`railtherm.SceneError` whose message names the key, the value and what is allowed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

import numpy as np

from .errors import SceneError

__all__ = ["Option", "GLOBAL_OPTIONS", "REFERENCE_KINDS", "MAX_LEVEL", "check_options", "check_cells", "check_levels",
           "check_study"]

#: options every method takes, whatever its models declare
GLOBAL_OPTIONS = {"cells": "cells along 2a at level 0 (an integer >= 1)"}
#: references a study or scene may name besides an installed method
REFERENCE_KINDS = ("analytic", "finest")
#: highest resolution level a study may ask for
MAX_LEVEL = 12


@dataclass(frozen=True)
class Option:
    """A declared model option (``[study.options.<method>]`` / ``solve(..., options=...)``)."""

    default: Any
    doc: str
    choices: tuple | None = None
    minimum: float | None = None

    def check(self, model: str, key: str, value: Any) -> Any:
        if self.choices is not None and value not in self.choices:
            raise SceneError(f"option {key!r} of model {model!r} = {value!r} is not allowed: one of {list(self.choices)}",
                             key=key, value=value, allowed=str(list(self.choices)))
        if self.minimum is not None:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= self.minimum:
                raise SceneError(f"option {key!r} of model {model!r} = {value!r} is not allowed: a number >= {self.minimum}",
                                 key=key, value=value, allowed=f">= {self.minimum}")
        return value


def _key(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _is_integral(value: Any) -> bool:
    ints, floats = (int, np.integer), (float, np.floating)
    if isinstance(value, bool):
        return False
    if isinstance(value, ints):
        return True
    return isinstance(value, floats) and math.isfinite(value) and float(value).is_integer()


def check_cells(value: Any, *, where: str = "") -> int:
    """The global ``cells`` option as an int, or :class:`SceneError` unless it is an integer >= 1."""
    key = _key(where, "cells")
    if not _is_integral(value) or int(value) < 1:
        raise SceneError(f"key {key!r} = {value!r} is not allowed: an integer >= 1 (cells along 2a at level 0)",
                         key=key, value=value, allowed="an integer >= 1")
    return int(value)


def allowed_options(method_info) -> dict[str, str]:
    """Every option key ``method_info`` takes -> the model(s) that declare it (or "global")."""
    out: dict[str, str] = dict.fromkeys(GLOBAL_OPTIONS, "global")
    for info in method_info.models:
        for cls in getattr(info, "classes", (info.cls,)):
            for key in getattr(cls, "options", {}) or {}:
                if cls.name not in str(out.get(key, "")).split(", "):
                    out[key] = cls.name if out.get(key) in (None, "global") else f"{out[key]}, {cls.name}"
    return out


def check_options(method_info, options: Mapping[str, Any] | None, *, method: str | None = None,
                  where: str = "") -> dict:
    """Validate the options of one method; return them as a dict.

    Parameters
    ----------
    method_info : railtherm.solving.plugins.MethodInfo
        The method (its ``models`` declare the allowed options).
    options : mapping or None
        Option key -> value.
    method : str, optional
        Method name used in messages (default: ``method_info.name``).
    where : str, optional
        Dotted prefix of the keys in messages, e.g. ``"study.options.green"``: an unknown key ``foo``
        is then reported as ``'study.options.green.foo'``.

    Raises
    ------
    railtherm.SceneError
        An unknown key (the message lists the allowed keys, sorted), a ``cells`` that is not an
        integer >= 1, or a value a model rejects.
    """
    method = method or getattr(method_info, "name", "?")
    if options is None:
        options = {}
    if not isinstance(options, Mapping):
        key = where or "options"
        raise SceneError(f"key {key!r} = {options!r} is not allowed: a table of option = value for method "
                         f"{method!r}", key=key, value=options, allowed="a table of options")
    options = dict(options)
    allowed = allowed_options(method_info)
    names = sorted(allowed)
    for key in options:
        if not isinstance(key, str) or key not in allowed:
            full = _key(where, str(key))
            raise SceneError(f"unknown option {full!r} (value {options[key]!r}) for method "
                             f"{method!r}; allowed: {', '.join(names)}", key=full, value=options[key],
                             allowed=", ".join(names))
    if "cells" in options:
        options["cells"] = check_cells(options["cells"], where=where)
    for cls in (c for info in method_info.models for c in getattr(info, "classes", (info.cls,))):
        try:
            cls.resolve_options(options)
        except SceneError as exc:
            if not where:  # the model's message names the option and the model; callers add the scene
                raise
            k = exc.key if exc.key is not None else "?"
            full = k if str(k).startswith(where + ".") else _key(where, k)
            raise SceneError(f"key {full!r} (method {method!r}): {exc}", scene=exc.scene, key=full,
                             value=exc.value, allowed=exc.allowed) from None
    return options


def check_levels(levels: Iterable[Any], *, key: str = "levels") -> list[int]:
    """Levels as sorted unique ints, or :class:`SceneError` for an empty list, a negative or
    non-integral level or one above :data:`MAX_LEVEL`."""
    allowed = f"a non-empty list of integers 0..{MAX_LEVEL}"
    if isinstance(levels, (str, bytes)) or not isinstance(levels, Iterable):
        raise SceneError(f"key {key!r} = {levels!r} is not allowed: {allowed}", key=key, value=levels,
                         allowed=allowed)
    levels = list(levels)
    if not levels:
        raise SceneError(f"key {key!r} = [] is not allowed: {allowed}", key=key, value=levels, allowed=allowed)
    for k in levels:
        if not _is_integral(k) or not 0 <= int(k) <= MAX_LEVEL:
            raise SceneError(f"key {key!r}: level {k!r} is not allowed: {allowed}", key=key, value=k,
                             allowed=allowed)
    return sorted({int(k) for k in levels})


def _installed(host, study) -> dict[str, Any]:
    """Installed methods plus the study's own chains (used like method names), name -> info or None."""
    out: dict[str, Any] = dict(host.methods)
    for name, chain in (getattr(study, "chains", None) or {}).items():
        key = f"study.chains.{name}"
        if name in out:
            raise SceneError(f"key {key!r}: chain {name!r} has the name of an installed method; choose another "
                             f"(installed methods: {', '.join(sorted(out))})", key=key, value=name,
                             allowed="a name that is not an installed method")
        out[name] = host.compose(chain, name, where=key)   # SceneError: unknown stage or model
    return out


def check_study(study, host, methods: Iterable[str] | None = None, levels: Iterable[Any] | None = None) -> None:
    """Check everything a study names before the first run.

    Parameters
    ----------
    study : railtherm.input.study.Study
    host : railtherm.solving.plugins.PluginHost
        The plugin host the study will run with (``host.methods``: name -> MethodInfo).
    methods, levels : optional
        Restrictions given on the command line or to :func:`railtherm.run_study`.

    Raises
    ------
    railtherm.SceneError
        An unknown method (``study.methods`` or ``methods``); an options table for a method that
        does not exist; an unknown option key or a bad value; an unknown reference (the study's or a
        scene's; allowed: "analytic", "finest" or an installed method); a level that is negative,
        non-integral or above :data:`MAX_LEVEL`. The message names the key, the value and what is
        allowed.
    """
    installed = _installed(host, study)
    names = sorted(installed)
    listing = ", ".join(names) or "none"
    problems = f" (plugin problems: {'; '.join(host.problems)})" if getattr(host, "problems", None) else ""

    def unknown_methods(values, key):
        if isinstance(values, str):
            values = [values]
        bad = [m for m in values if not isinstance(m, str) or m not in installed]
        if bad:
            raise SceneError(f"key {key!r}: unknown method(s) {bad}; installed methods: {listing}{problems}",
                             key=key, value=bad if len(bad) > 1 else bad[0], allowed=listing)

    if study.methods != "all":
        unknown_methods(study.methods, "study.methods")
    if methods is not None:
        methods = [methods] if isinstance(methods, str) else list(methods)
        if not methods:
            raise SceneError("key 'methods' = [] is not allowed: at least one installed method "
                             f"({listing})", key="methods", value=[], allowed=listing)
        unknown_methods(methods, "methods")

    for m, table in (study.options or {}).items():
        key = f"study.options.{m}"
        if m not in installed:
            raise SceneError(f"key {key!r}: options for method {m!r}, which is not installed; installed methods: "
                             f"{listing}{problems}", key=key, value=m, allowed=listing)
        check_options(installed[m], table, method=m, where=key)

    refs = list(REFERENCE_KINDS) + names
    allowed_refs = '"analytic", "finest" or an installed method (' + listing + ")"

    def check_ref(value, key, scene=None):
        if not isinstance(value, str) or value not in refs:
            raise SceneError.bad_value(scene, key, value, allowed_refs)

    check_ref(study.reference, "study.reference")
    for sc in study.scenes:
        if sc.reference is not None:
            check_ref(sc.reference, "reference", sc.name)

    check_levels(study.levels, key="study.levels")
    if levels is not None:
        check_levels(levels, key="levels")
