"""Heat partition between wheel and rail (scene key ``heat_partition``), resolved once into a
:class:`HeatPartition`: a given fraction, Blok's equal-temperature fraction, or the rule that equalises the
two bodies' mean surface temperatures over the patch (which needs the temperatures it produces).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..contract.errors import Refused

__all__ = ["HeatPartition", "equal_temperature_partition", "scene_partition"]


def equal_temperature_partition(wheel, rail, wheel_speed: float, rail_speed: float) -> float:
    """Fraction of the frictional heat entering the wheel so that both flash temperatures are equal.

    In the 1-D high-Péclet model (seed eqs. 32-33) a flux q_i into body i moving at v_i raises its
    surface by q_i / (beta_i sqrt(v_i)) times the same shape factor, so equal temperatures need
    ``eps = beta_w sqrt(v_w) / (beta_w sqrt(v_w) + beta_r sqrt(v_r))`` (seed eq. 38 with
    v_w = v0 + v_s, v_r = v0). This is Blok's partition for two bodies at high Péclet number; the
    two kernels differ only by ``1/(beta sqrt(v))``, so the same constant equalises the two surface
    temperatures at every point of the patch. It is also the interface fraction ``eps_c`` of a warm
    wheel against a cold rail (seed eq. 41).

    A surface that does not move through the patch (speed <= 0, e.g. a locked wheel) is treated as
    speed 0: it takes no heat in this model (the other body takes all of it); when neither moves the
    split is even (0.5). Nothing divides by zero.

    Parameters
    ----------
    wheel, rail : Material-like
        Bodies with ``effusivity`` beta = sqrt(lambda rho c) [W s^0.5 m^-2 K^-1].
    wheel_speed, rail_speed : float
        Speed of each surface relative to the contact [m/s].

    Returns
    -------
    float
        eps [1], fraction entering the wheel, in [0, 1].

    References
    ----------
    .. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation
       of temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
    .. [2] H. Blok, Theoretical study of temperature rise at surfaces of actual contact under oiliness
       lubricating conditions, Proc. Gen. Discussion on Lubrication, IMechE 2 (1937) 222-235.
    """
    gw = wheel.effusivity * math.sqrt(max(wheel_speed, 0.0))
    gr = rail.effusivity * math.sqrt(max(rail_speed, 0.0))
    if gw + gr == 0.0:
        return 0.5
    return gw / (gw + gr)


@dataclass(frozen=True)
class HeatPartition:
    """The scene's heat partition: which fraction of the frictional heat enters the wheel.

    Attributes
    ----------
    rule : str
        ``"fraction"``: the given number; ``"equal-temperature"``: Blok's fraction
        (:func:`equal_temperature_partition`), the same constant for every method; ``"equal-mean-temperature"``:
        the fraction that makes the wheel's and the rail's mean absolute surface temperatures over the patch
        equal, found by a model that solves both bodies' temperatures with the split (the FEM); it differs
        from Blok's where the bulk temperatures differ, conduction is not one-dimensional or a contact
        conductance couples the surfaces.
    fraction : float or None
        The given fraction [1] of rule ``"fraction"``, in [0, 1].
    """

    rule: str
    fraction: float | None = None

    #: the scene's words for the rules that are not a number
    RULES: ClassVar[tuple[str, ...]] = ("equal-temperature", "equal-mean-temperature")

    @classmethod
    def of(cls, value) -> "HeatPartition":
        """The partition of a scene value: a number in [0, 1], one of :data:`RULES`, or a HeatPartition."""
        if isinstance(value, HeatPartition):
            return value
        if isinstance(value, str):
            if value not in cls.RULES:
                raise ValueError(f"heat_partition {value!r}: allowed a number in [0, 1] or one of {cls.RULES}")
            return cls(value)
        return cls("fraction", float(value))

    @property
    def value(self) -> float | str:
        """The scene's value: the number, or the rule's name."""
        return self.fraction if self.rule == "fraction" else self.rule

    @property
    def needs_temperatures(self) -> bool:
        """Whether the fraction depends on the temperatures it produces (only a model that solves both
        bodies together can apply it)."""
        return self.rule == "equal-mean-temperature"

    def wheel_fraction(self, wheel, rail, wheel_speed: float, rail_speed: float) -> float:
        """Fraction of the heat entering the wheel [1].

        Parameters
        ----------
        wheel, rail : Material-like
            With ``effusivity`` [W s^0.5 m^-2 K^-1] (Blok's rule).
        wheel_speed, rail_speed : float
            Surface speeds through the patch [m/s].

        Raises
        ------
        railtherm.Refused
            (validity) for ``"equal-mean-temperature"``, which a fraction fixed before the temperatures
            are known cannot honour.
        """
        if self.rule == "fraction":
            return float(self.fraction)
        if self.rule == "equal-temperature":
            return equal_temperature_partition(wheel, rail, wheel_speed, rail_speed)
        raise Refused("heat_partition = 'equal-mean-temperature' equalises the mean surface temperatures of wheel "
                      "and rail, which needs the temperatures the split produces: only a model that solves both "
                      "bodies' temperatures with the split applies it (the FEM, 'fem'); use 'equal-temperature' "
                      "(Blok's fraction) or a number", kind="validity")


def scene_partition(partition: HeatPartition, wheel, rail, wheel_speed: float, rail_speed: float, *,
                    scene_name: str | None = None) -> float:
    """The scene's heat partition: the fraction of the heat entering the wheel [1], a refusal naming the
    scene.

    Parameters
    ----------
    partition : HeatPartition
        The scene's resolved ``heat_partition`` (a scene value, a number in [0, 1] or a rule's name, is
        resolved by :meth:`HeatPartition.of`).
    wheel, rail : Material-like
        With ``effusivity`` [W s^0.5 m^-2 K^-1] (Blok's rule).
    wheel_speed, rail_speed : float
        Surface speeds through the patch [m/s] (:func:`railtherm.physics.body_speeds`).
    scene_name : str, optional
        For messages.

    Returns
    -------
    float
        eps [1], the fraction entering the wheel.

    Raises
    ------
    railtherm.Refused
        For a partition that needs the temperatures (:meth:`HeatPartition.wheel_fraction`).
    """
    try:
        return HeatPartition.of(partition).wheel_fraction(wheel, rail, wheel_speed, rail_speed)
    except Refused as exc:
        raise Refused(f"scene {scene_name!r}: {exc}", kind=exc.kind) from None
