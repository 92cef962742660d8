"""The parameters of a friction law as the law declares them: name, unit and allowed range.

Each law (:mod:`railtherm.physics.friction.laws`) lists its parameters once as :class:`Parameter`; the scene
validator (:class:`railtherm.input.scene.Friction`) builds its checks and its messages from that list, so
the keys of the scene table ``friction = { law = ..., ... }`` exist in one place.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Parameter", "unit_label"]


@dataclass(frozen=True)
class Parameter:
    """One parameter of a friction law.

    Attributes
    ----------
    name : str
        The key in the scene table (``static``, ``decay``, ``reference_temperature``, ...).
    unit : str
        UDUNITS-2 string (``"1"`` for a dimensionless number, ``"m s-1"``, ``"degC"``, ...).
    lower : float
        Least allowed value (``-inf``: no bound below).
    lower_open : bool
        Whether ``lower`` itself is excluded (``> lower`` instead of ``>= lower``).
    meaning : str
        What the parameter is, for messages and documents.
    """

    name: str
    unit: str = "1"
    lower: float = -math.inf
    lower_open: bool = False
    meaning: str = ""

    @property
    def label(self) -> str:
        """The name with its unit as written in messages: ``decay [m/s]``, ``static`` (dimensionless)."""
        return self.name if self.unit == "1" else f"{self.name} [{unit_label(self.unit)}]"


def unit_label(unit: str) -> str:
    """A UDUNITS-2 unit in the slash form of messages: ``"m s-1"`` -> ``"m/s"``, ``"s m-1"`` -> ``"s/m"``,
    ``"degC"`` -> ``"degC"`` (only exponents -1 and 1 occur in the laws' units)."""
    num = [t for t in unit.split() if not t.endswith("-1")]
    den = [t[:-2] for t in unit.split() if t.endswith("-1")]
    return " ".join(num or ["1"]) + "".join(f"/{d}" for d in den)
