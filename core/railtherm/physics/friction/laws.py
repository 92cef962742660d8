"""Friction laws: mu as a function of the local slip speed v [m/s] and contact temperature T [degC].

Scene key ``friction``; each law is a frozen dataclass with the interface :class:`FrictionLaw` that
declares its parameters once (:data:`FrictionLaw.PARAMETERS`):
* :class:`ConstantFriction` -- ``friction = 0.3``;
* :class:`SlipVelocityFriction` -- ``{ law = "slip-velocity", static, kinetic, decay }``:
  mu(v) = kinetic + (static - kinetic) exp(-v / decay) (CONTACT's exponential law, [Vollebregt2022]_);
* :class:`PolachFriction` -- ``{ law = "polach", mu0, A, B }``: mu(v) = mu0 ((1 - A) exp(-B v) + A)
  ([Polach2005]_ eq. 6), the same exponential with static = mu0, kinetic = A mu0, decay = 1 / B;
* :class:`TemperatureFriction` -- ``{ law = "temperature", reference, reference_temperature, change, over }``:
  mu_ref for T <= T_ref, mu_ref + change above T_ref + over, linear between (CONTACT's form).

.. [Polach2005] O. Polach, Wear 258 (2005) 992-1000, doi:10.1016/j.wear.2004.03.046.
.. [Vollebregt2022] E.A.H. Vollebregt, User guide for CONTACT, TR09-03 v22.1, VORtech (2022), friction laws.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Mapping

import numpy as np

from .parameters import Parameter

__all__ = ["FrictionLaw", "ConstantFriction", "SlipVelocityFriction", "PolachFriction", "TemperatureFriction",
           "LAWS", "LAW_KINDS", "friction_law"]

#: a coefficient of friction that must stay > 0 [1]
_POSITIVE = dict(lower=0.0, lower_open=True)


class FrictionLaw:
    """Interface of a friction law (all laws are frozen dataclasses).

    Attributes
    ----------
    kind : str
        ``"constant"``, ``"slip-velocity"``, ``"polach"`` or ``"temperature"`` (the scene's ``law``).
    depends_on_slip, depends_on_temperature : bool
        Whether mu changes with the slip speed / the surface temperature.
    PARAMETERS : tuple of Parameter
        The keys of the scene table ``friction = { law = kind, ... }``, in the order the docs give them
        (empty for the constant law, which the scene gives as one number).
    """

    kind: ClassVar[str] = ""
    depends_on_slip: ClassVar[bool] = False
    depends_on_temperature: ClassVar[bool] = False
    PARAMETERS: ClassVar[tuple[Parameter, ...]] = ()

    @classmethod
    def from_parameters(cls, **values: float) -> "FrictionLaw":
        """The law from the values of its :data:`PARAMETERS` (checked by the scene)."""
        return cls(**{k: float(v) for k, v in values.items()})

    @classmethod
    def parameter_conflict(cls, values: Mapping[str, float]) -> tuple[str, str] | None:
        """A condition between parameters that ``values`` breaks, as (key, what is allowed), else None
        (each value on its own is checked against its :class:`Parameter` range first)."""
        return None

    def mu(self, slip_speed=0.0, temperature=0.0) -> np.ndarray:
        """Coefficient of friction [1] at the slip speed [m/s] and contact temperature [degC]
        (broadcast; a scalar for scalar input)."""
        raise NotImplementedError

    def dmu_dslip(self, slip_speed=0.0) -> np.ndarray:
        """d mu / d v_slip [s/m] (0 for a law without slip dependence)."""
        return np.zeros_like(np.asarray(slip_speed, dtype=float))

    @property
    def nominal(self) -> float:
        """mu at zero slip speed and at (or below) the reference temperature [1]: the scene's ``friction``
        for models and metrics that take one number."""
        return float(self.mu(0.0, -math.inf if self.depends_on_temperature else 0.0))

    @property
    def bounds(self) -> tuple[float, float]:
        """The least and the greatest mu the law can give [1]."""
        raise NotImplementedError

    def describe(self) -> str:
        """One line for reports: the law with its parameters."""
        raise NotImplementedError


@dataclass(frozen=True)
class ConstantFriction(FrictionLaw):
    """mu = ``value`` everywhere [1]."""

    value: float
    kind: ClassVar[str] = "constant"

    def mu(self, slip_speed=0.0, temperature=0.0):
        shape = np.broadcast(np.asarray(slip_speed), np.asarray(temperature)).shape
        return np.full(shape, float(self.value)) if shape else float(self.value)

    @property
    def bounds(self):
        return float(self.value), float(self.value)

    def describe(self):
        return f"constant mu = {self.value:g}"


@dataclass(frozen=True)
class SlipVelocityFriction(FrictionLaw):
    """Exponential slip-velocity law mu(v) = kinetic + (static - kinetic) exp(-v / decay).

    Parameters
    ----------
    static : float
        mu at zero slip speed [1], > 0.
    kinetic : float
        mu at large slip speed [1], > 0.
    decay : float
        Reference slip speed v_ref [m/s], > 0.
    """

    static: float
    kinetic: float
    decay: float
    kind: ClassVar[str] = "slip-velocity"
    depends_on_slip: ClassVar[bool] = True
    PARAMETERS: ClassVar[tuple[Parameter, ...]] = (
        Parameter("static", meaning="mu at zero slip speed", **_POSITIVE),
        Parameter("kinetic", meaning="mu at large slip speed", **_POSITIVE),
        Parameter("decay", "m s-1", meaning="reference slip speed v_ref of the exponential", **_POSITIVE))

    def mu(self, slip_speed=0.0, temperature=0.0):
        v = np.abs(np.asarray(slip_speed, dtype=float))
        out = self.kinetic + (self.static - self.kinetic) * np.exp(-v / self.decay)
        if np.ndim(temperature):
            out = np.broadcast_to(out, np.broadcast(v, np.asarray(temperature)).shape).copy()
        return out if np.ndim(out) else float(out)

    def dmu_dslip(self, slip_speed=0.0):
        v = np.abs(np.asarray(slip_speed, dtype=float))
        return -(self.static - self.kinetic) / self.decay * np.exp(-v / self.decay)

    @property
    def bounds(self):
        return min(self.static, self.kinetic), max(self.static, self.kinetic)

    def describe(self):
        return (f"slip-velocity: mu = {self.kinetic:g} + ({self.static:g} - {self.kinetic:g}) "
                f"exp(-v_slip / {self.decay:g} m/s)")


@dataclass(frozen=True)
class PolachFriction(SlipVelocityFriction):
    """Polach's falling friction mu(w) = mu0 ((1 - A) exp(-B w) + A) ([Polach2005]_, eq. 6).

    Built from Polach's parameters with :meth:`from_parameters`: ``mu0`` [1] (> 0, the maximum at zero
    slip), ``A`` = mu_inf / mu0 [1] (> 0), ``B`` [s/m] (> 0): static = mu0, kinetic = A mu0, decay = 1/B.
    """

    kind: ClassVar[str] = "polach"
    PARAMETERS: ClassVar[tuple[Parameter, ...]] = (
        Parameter("mu0", meaning="mu at zero slip speed (the maximum)", **_POSITIVE),
        Parameter("A", meaning="mu_inf / mu0", **_POSITIVE),
        Parameter("B", "s m-1", meaning="exponential decay rate of mu with the slip speed", **_POSITIVE))

    @classmethod
    def from_parameters(cls, mu0: float, A: float, B: float) -> "PolachFriction":
        return cls(static=float(mu0), kinetic=float(A) * float(mu0), decay=1.0 / float(B))

    def describe(self):
        return (f"polach: mu = {self.static:g} ((1 - {self.kinetic / self.static:g}) exp(-{1 / self.decay:g} w) "
                f"+ {self.kinetic / self.static:g})")


@dataclass(frozen=True)
class TemperatureFriction(FrictionLaw):
    """mu piecewise linear in the contact temperature T [degC] (CONTACT's form).

    Parameters
    ----------
    reference : float
        mu_ref [1] at and below ``reference_temperature``, > 0.
    reference_temperature : float
        T_ref [degC].
    change : float
        Delta mu [1] reached at T_ref + ``over`` (negative: friction falls); mu_ref + change > 0.
    over : float
        Delta T [K] over which mu changes linearly, > 0.
    """

    reference: float
    reference_temperature: float
    change: float
    over: float
    kind: ClassVar[str] = "temperature"
    depends_on_temperature: ClassVar[bool] = True
    PARAMETERS: ClassVar[tuple[Parameter, ...]] = (
        Parameter("reference", meaning="mu_ref at and below reference_temperature", **_POSITIVE),
        Parameter("reference_temperature", "degC", lower=-273.15, lower_open=True, meaning="T_ref"),
        Parameter("change", meaning="Delta mu reached at T_ref + over"),
        Parameter("over", "K", meaning="Delta T over which mu changes linearly", **_POSITIVE))

    @classmethod
    def parameter_conflict(cls, values):
        if values["reference"] + values["change"] <= 0:
            return "change", (f"a number > {-values['reference']:g} (reference + change is the friction above "
                              "reference_temperature + over and must stay > 0)")
        return None

    def mu(self, slip_speed=0.0, temperature=0.0):
        t = np.asarray(temperature, dtype=float)
        frac = np.clip((t - self.reference_temperature) / self.over, 0.0, 1.0)
        out = self.reference + self.change * frac
        if np.ndim(slip_speed):
            out = np.broadcast_to(out, np.broadcast(np.asarray(slip_speed), t).shape).copy()
        return out if np.ndim(out) else float(out)

    def dmu_dtemperature(self) -> float:
        """Slope of the linear part, change / over [1/K]."""
        return self.change / self.over

    @property
    def bounds(self):
        return min(self.reference, self.reference + self.change), max(self.reference, self.reference + self.change)

    def describe(self):
        return (f"temperature: mu = {self.reference:g} below {self.reference_temperature:g} degC, "
                f"{self.reference + self.change:g} above {self.reference_temperature + self.over:g} degC, linear between")


#: the laws a scene gives as a table ``friction = { law = kind, ... }``, by kind (the constant law is a number)
LAWS: dict[str, type[FrictionLaw]] = {law.kind: law for law in (SlipVelocityFriction, PolachFriction,
                                                                  TemperatureFriction)}
#: every law key of the scene's ``friction`` (a model that applies them all declares these capabilities)
LAW_KINDS: frozenset[str] = frozenset({ConstantFriction.kind, *LAWS})


def friction_law(value) -> FrictionLaw:
    """The law of a validated scene value ``friction``: a number (constant) or a table with ``law``."""
    if isinstance(value, FrictionLaw):
        return value
    if not isinstance(value, Mapping):
        return ConstantFriction(float(value))
    law = LAWS[value["law"]]
    return law.from_parameters(**{p.name: float(value[p.name]) for p in law.PARAMETERS})
