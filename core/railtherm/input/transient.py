"""Transient scenes: the vocabulary of heating over time (passes, a heat-input schedule, histories).

A scene with ``mode = "transient"`` may give
* ``passes = { count = <int >= 1>, interval = <s> }``: the contact passes the same rail section
  ``count`` times, ``interval`` apart (default: the revolution period 2 pi wheel.radius / speed);
* ``schedule = { time = [<s>, ...], factor = [<1>, ...] }``: a piecewise-linear factor on the heat
  input, constant outside the times (time 0: the first pass's leading edge reaches the section);
* ``field = { depth = <m> or [<m>, ...], threshold = <degC> }``: the depths of the histories (the
  surface always included) and the temperature of ``time_above``;
* ``outputs`` naming ``temperature_history``, ``pass_peak_temperature``, ``residual_rise``, ``time_above``.

:func:`transient_from_table` checks these keys and returns a frozen :class:`Transient`; every error is a
:class:`railtherm.SceneError` naming the scene, the key, the value and what is allowed.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Mapping

from ..contract.errors import SceneError
from .materials import Material

__all__ = ["Transient", "TRANSIENT_OUTPUTS", "DEFAULT_THRESHOLD", "transient_from_table", "scene_transient"]

#: outputs only a transient scene has (``time_above`` is per pass there)
TRANSIENT_OUTPUTS = ("temperature_history", "pass_peak_temperature", "residual_rise", "time_above")
#: default threshold [degC]: the eutectoid temperature of rail steel (austenite, white etching layers)
DEFAULT_THRESHOLD = 727.0

_PASSES_KEYS = ("count", "interval")
_SCHEDULE_KEYS = ("time", "factor")


@dataclass(frozen=True)
class Transient:
    """The transient part of a scene, validated.

    Attributes
    ----------
    count : int
        Passes of the contact over the section (revolutions for the wheel) [1].
    interval : float or None
        Time between passes [s]; None: not given (for the wheel, the revolution period).
    schedule_time : tuple of float or None
        Strictly increasing times of the heat-input factor [s]; None: factor 1 throughout.
    schedule_factor : tuple of float or None
        Factors >= 0 at those times [1].
    depths : tuple of float
        Depths of the histories [m], increasing, starting with the surface 0.
    threshold : float
        Temperature of ``time_above`` [degC].
    outputs : tuple of str
        The transient outputs asked for (subset of :data:`TRANSIENT_OUTPUTS`).
    """

    count: int = 1
    interval: float | None = None
    schedule_time: tuple[float, ...] | None = None
    schedule_factor: tuple[float, ...] | None = None
    depths: tuple[float, ...] = (0.0,)
    threshold: float = DEFAULT_THRESHOLD
    outputs: tuple[str, ...] = ()


def _fail(scene, key, value, allowed):
    raise SceneError.bad_value(scene, key, value, allowed)


def _number(value) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(float(value))


def _table(scene, key, value, allowed_keys):
    if not isinstance(value, Mapping):
        _fail(scene, key, value, "a table { " + ", ".join(f"{k} = ..." for k in allowed_keys) + " }")
    for k in value:
        if k not in allowed_keys:
            _fail(scene, f"{key}.{k}", value[k], f"one of the keys {', '.join(allowed_keys)} of {key!r}")
    return value


def _passes(scene, value, contact_duration):
    t = _table(scene, "passes", value, _PASSES_KEYS)
    count = t.get("count", 1)
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        _fail(scene, "passes.count", count, "an integer >= 1 (passes over the section)")
    interval = t.get("interval")
    if interval is not None:
        if not _number(interval) or interval <= 0:
            _fail(scene, "passes.interval", interval, "a finite number > 0 [s]")
        if contact_duration is not None and interval < contact_duration:
            _fail(scene, "passes.interval", interval,
                  f"a time >= the contact duration 2a/V = {contact_duration:.6g} s (a pass must end before "
                  "the next begins)")
        interval = float(interval)
    return int(count), interval


def _schedule(scene, value):
    t = _table(scene, "schedule", value, _SCHEDULE_KEYS)
    for k in _SCHEDULE_KEYS:
        if k not in t:
            _fail(scene, f"schedule.{k}", None, "a list of numbers (schedule needs both time [s] and factor [1])")
    time, factor = t["time"], t["factor"]
    for k, seq in (("time", time), ("factor", factor)):
        if isinstance(seq, (str, bytes, Mapping)) or not hasattr(seq, "__len__") or len(seq) < 1 \
                or not all(_number(v) for v in seq):
            _fail(scene, f"schedule.{k}", seq, "a non-empty list of finite numbers")
    if len(time) != len(factor):
        _fail(scene, "schedule.factor", factor, f"a list as long as schedule.time ({len(time)} values)")
    for i in range(1, len(time)):
        if not time[i] > time[i - 1]:
            _fail(scene, "schedule.time", time,
                  f"strictly increasing times [s] (value {i}, {time[i]!r}, is not after {time[i - 1]!r})")
    for v in factor:
        if v < 0:
            _fail(scene, "schedule.factor", factor, f"factors >= 0 [1] ({v!r} is negative)")
    return tuple(float(v) for v in time), tuple(float(v) for v in factor)


def _field(scene, value):
    if value is None:
        return (0.0,), DEFAULT_THRESHOLD
    if not isinstance(value, Mapping):
        _fail(scene, "field", value, "a table { depth = <m> or [<m>, ...], threshold = <degC> }")
    depth = value.get("depth", [])
    seq = depth if isinstance(depth, (list, tuple)) else [depth]
    if not all(_number(v) and v >= 0 for v in seq):
        _fail(scene, "field.depth", depth, "a depth >= 0 [m] or a list of them")
    threshold = value.get("threshold", DEFAULT_THRESHOLD)
    if not _number(threshold) or threshold <= -273.15:
        _fail(scene, "field.threshold", threshold, "a finite temperature > -273.15 [degC]")
    return tuple(sorted({0.0, *(float(v) for v in seq)})), float(threshold)


def _outputs(scene, value):
    if value is None:
        return ()
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
        _fail(scene, "outputs", value, "a list of output names")
    return tuple(o for o in value if o in TRANSIENT_OUTPUTS)


def transient_from_table(scene_name: str | None, table: Mapping[str, Any],
                         contact_duration: float | None) -> Transient | None:
    """Check the transient keys of a scene and return them, or None for a steady scene.

    Parameters
    ----------
    scene_name : str or None
        The scene's name, for the error messages.
    table : Mapping
        The scene as written (keys ``mode``, ``passes``, ``schedule``, ``field``, ``outputs``; others
        are ignored here).
    contact_duration : float or None
        2a/V [s] of the scene's contact, the shortest allowed ``passes.interval``; None: not checked
        (not known yet).

    Returns
    -------
    Transient or None
        None when ``mode`` is not ``"transient"`` (then no transient key may be given).

    Raises
    ------
    railtherm.SceneError
        A transient key without ``mode = "transient"``, a ``passes.count`` < 1, an interval shorter than
        the contact duration, schedule times not strictly increasing, negative factors, or a malformed
        table; the message names the scene, the key, the value and what is allowed.
    """
    mode = table.get("mode", "steady")
    if mode not in ("steady", "transient"):
        _fail(scene_name, "mode", mode, "'steady' or 'transient'")
    if mode != "transient":
        for key in ("passes", "schedule"):
            if key in table:
                _fail(scene_name, key, table[key], f"only with mode = \"transient\" (the scene's mode is {mode!r})")
        asked = [o for o in _outputs(scene_name, table.get("outputs")) if o != "time_above"]
        if asked:
            _fail(scene_name, "outputs", asked[0], "a transient output (" + ", ".join(TRANSIENT_OUTPUTS[:3])
                  + f") only with mode = \"transient\" (the scene's mode is {mode!r})")
        return None
    if contact_duration is not None and not (_number(contact_duration) and contact_duration > 0):
        raise ValueError(f"contact_duration must be a number > 0 [s] or None, got {contact_duration!r}")
    count, interval = _passes(scene_name, table.get("passes", {}), contact_duration)
    time, factor = _schedule(scene_name, table["schedule"]) if "schedule" in table else (None, None)
    depths, threshold = _field(scene_name, table.get("field"))
    return Transient(count=count, interval=interval, schedule_time=time, schedule_factor=factor, depths=depths,
                     threshold=threshold, outputs=_outputs(scene_name, table.get("outputs")))


def _contact_duration(c: dict, speed: float) -> float | None:
    """2a/V [s] when the scene gives the semi-axis along rolling, else None (a Hertz patch from the load is
    known only after the contact stage; the temperature model checks the interval then)."""
    hs = c.get("heat_source") or {}
    a = (hs.get("semi_axes") or (None,))[0] or hs.get("half_width") or ((c.get("contact") or {}).get("semi_axes")
                                                                         or (None,))[0]
    return None if a is None else 2.0 * float(a) / speed


def scene_transient(name: str, c: dict, raw: Mapping, kw: dict) -> Transient | None:
    """The scene loader's transient part (:func:`transient_from_table` on the checked keys ``c`` of the scene
    ``raw``; ``kw`` the scene's resolved speed and line wheel radius), its interval resolved: without
    ``passes.interval`` a pass is one revolution of the wheel, 2 pi wheel_radius / speed."""
    table = {k: c[k] for k in ("mode", "passes", "schedule") if k in c}
    if "field" in c:
        table["field"] = {k: v for k, v in c["field"].items() if k != "behind"}
    if "outputs" in raw:
        table["outputs"] = list(c.get("outputs", ()))
    tr = transient_from_table(name, table, _contact_duration(c, kw["speed"]))
    if tr is None:
        return None
    if "behind" in c.get("field", {}):
        _fail(name, "field.behind", c["field"]["behind"], "no 'behind' in a transient scene (its histories are at "
              "the fixed section: field = { depth = <m> or [<m>, ...], threshold = <degC> })")
    if tr.interval is None:
        radius = kw.get("line_wheel_radius") or c.get("wheel", {}).get("radius", Material.radius)
        tr = dataclasses.replace(tr, interval=2.0 * math.pi * float(radius) / kw["speed"])
        duration = _contact_duration(c, kw["speed"])
        if duration is not None and tr.interval < duration:
            raise SceneError.bad_value(name, "passes.interval", None,
                                       f"an interval >= the contact duration 2a/V = {duration:.6g} s (the wheel's "
                                       f"revolution period {tr.interval:.6g} s is shorter: give passes.interval)")
    return tr
