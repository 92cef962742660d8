"""The temperature stage's result for a transient scene: the histories at the fixed section.

A temperature model that computes a scene with ``mode = "transient"`` returns a
:class:`TransientTemperatureField`: the steady fields of one pass (:class:`TemperatureField`) and the
:class:`TransientHistory` of the material point on the centre line y = 0 at the fixed section, which
:func:`railtherm.contract.schema.build_dataset` turns into ``temperature_history``,
``pass_peak_temperature``, ``residual_rise`` and ``time_above`` (docs/DESIGN.md "Result schema").
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .results import TemperatureField

__all__ = ["TransientHistory", "TransientTemperatureField", "with_history"]


@dataclass(frozen=True)
class TransientHistory:
    """Histories of both bodies on one time axis.

    Attributes
    ----------
    time : ndarray, shape (nt,)
        Increasing times [s] from 0 (the first pass's leading edge at the section) to the last pass plus
        one interval: the model's own axis.
    z : ndarray, shape (nz,)
        Depths [m], the surface 0 first.
    temperature : ndarray, shape (2, nt, nz)
        Temperature of wheel and rail [degC] (absolute).
    peak : ndarray, shape (2, passes, nz)
        Highest temperature in each pass [degC].
    residual : ndarray, shape (2, passes)
        Surface rise above the bulk temperature just before the next pass (after the last: one interval
        after it) [K].
    time_above : ndarray or None, shape (2, passes, nz)
        Time above the scene's threshold in each pass [s].
    """

    time: np.ndarray
    z: np.ndarray
    temperature: np.ndarray
    peak: np.ndarray
    residual: np.ndarray
    time_above: np.ndarray | None = None

    def __post_init__(self):
        nt, nz = np.size(self.time), np.size(self.z)
        if np.shape(self.temperature) != (2, nt, nz):
            raise ValueError(f"temperature must have shape (2, {nt}, {nz}), got {np.shape(self.temperature)}")
        n = np.shape(self.peak)[1] if np.ndim(self.peak) == 3 else -1
        if np.shape(self.peak) != (2, n, nz) or np.shape(self.residual) != (2, n):
            raise ValueError(f"peak must have shape (2, passes, {nz}) and residual (2, passes), got "
                             f"{np.shape(self.peak)} and {np.shape(self.residual)}")
        if self.time_above is not None and np.shape(self.time_above) != (2, n, nz):
            raise ValueError(f"time_above must have shape (2, {n}, {nz}), got {np.shape(self.time_above)}")


@dataclass(frozen=True)
class TransientTemperatureField(TemperatureField):
    """A :class:`TemperatureField` (one pass's steady fields) with the transient :attr:`history`."""

    history: TransientHistory | None = None


def with_history(result: TemperatureField, history: TransientHistory) -> TransientTemperatureField:
    """``result`` with ``history`` attached (its other fields unchanged)."""
    return TransientTemperatureField(**{f.name: getattr(result, f.name) for f in fields(result)}, history=history)
