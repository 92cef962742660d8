"""How the bodies move through the contact: the scene's rolling speed, sliding speed and creepages.

:class:`Kinematics` is the typed part of a scene (``Scene.kinematics``) built once by
:func:`railtherm.input.scene.load_scene` from the keys ``speed``, ``sliding_speed`` and ``creepage``.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Creepage", "Kinematics"]


@dataclass(frozen=True)
class Creepage:
    """Creepages: longitudinal xi [1], lateral eta [1], spin phi [1/m]."""

    longitudinal: float = 0.0
    lateral: float = 0.0
    spin: float = 0.0


@dataclass(frozen=True)
class Kinematics:
    """How the bodies move through the contact, resolved once at load time.

    Attributes
    ----------
    speed : float
        Rolling speed V [m/s], > 0.
    sliding_speed : float or None
        Full sliding: the wheel's surface moves at ``speed + sliding_speed`` [m/s]; None when the scene
        rolls with creepage (or gives its heat source).
    creepage : Creepage or None
        Creepages of the wheel relative to the rail; None in full sliding (or with a given heat source).
    """

    speed: float
    sliding_speed: float | None = None
    creepage: Creepage | None = None
