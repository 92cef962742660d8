"""Friction laws: the coefficient of friction as a function of the local slip speed and the local surface
temperature (scene key ``friction``; docs/DESIGN.md "Scene vocabulary").

Four laws, each a frozen dataclass with the same small interface (:class:`FrictionLaw`):

* :class:`ConstantFriction` -- ``friction = 0.3``: one number, as in the first release.
* :class:`SlipVelocityFriction` -- ``friction = { law = "slip-velocity", static, kinetic, decay }``:
  exponentially falling friction mu(v) = mu_kin + (mu_st - mu_kin) exp(-v / v_ref), ``decay`` = v_ref
  [m/s] (CONTACT's exponential law; [Vollebregt2022]_).
* :class:`PolachFriction` -- ``friction = { law = "polach", mu0, A, B }``: mu(w) = mu_0 ((1 - A) exp(-B w)
  + A) with A = mu_inf / mu_0 [1] and B [s/m] ([Polach2005]_, eq. 6): the same exponential with
  mu_st = mu_0, mu_kin = A mu_0, v_ref = 1 / B.
* :class:`TemperatureFriction` -- ``friction = { law = "temperature", reference, reference_temperature,
  change, over }``: mu piecewise linear in the local surface temperature T [degC]: mu_ref for
  T <= T_ref, mu_ref + change (T - T_ref) / over between, mu_ref + change above T_ref + over
  (CONTACT's form; [Vollebregt2022]_).

The slip speed is the magnitude of the local slip velocity of the wheel relative to the rail [m/s]; the
temperature that enters a temperature law is the contact temperature of the cell, the mean of the wheel's
and the rail's surface temperature there [degC] (equal in perfect thermal contact; the core loop of
:mod:`railtherm.solving.friction_loop` takes it from the chain's temperature model).

References
----------
.. [Polach2005] O. Polach, "Creep forces in simulations of traction vehicles running on adhesion limit",
   Wear 258 (2005) 992-1000, doi:10.1016/j.wear.2004.03.046.
.. [Vollebregt2022] E.A.H. Vollebregt, "User guide for CONTACT, Rolling and sliding contact with
   friction", Technical report TR09-03, version 22.1, VORtech (2022), sections on friction laws.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["FrictionLaw", "ConstantFriction", "SlipVelocityFriction", "PolachFriction", "TemperatureFriction",
           "LAW_KINDS", "friction_law", "contraction_limit"]


class FrictionLaw:
    """Interface of a friction law (all laws are frozen dataclasses).

    Attributes
    ----------
    kind : str
        ``"constant"``, ``"slip-velocity"``, ``"polach"`` or ``"temperature"`` (the scene's ``law``).
    depends_on_slip, depends_on_temperature : bool
        Whether mu changes with the slip speed / the surface temperature.
    """

    kind: ClassVar[str] = ""
    depends_on_slip: ClassVar[bool] = False
    depends_on_temperature: ClassVar[bool] = False

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

    Built from Polach's parameters with :meth:`from_polach`: ``mu0`` [1] (> 0, the maximum at zero
    slip), ``A`` = mu_inf / mu0 [1] (> 0), ``B`` [s/m] (> 0): static = mu0, kinetic = A mu0, decay = 1/B.
    """

    kind: ClassVar[str] = "polach"

    @classmethod
    def from_polach(cls, mu0: float, A: float, B: float) -> "PolachFriction":
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


#: the laws of the scene key ``friction``, by ``law``: their keys (in the order the docs give them)
LAW_KINDS: dict[str, tuple[str, ...]] = {
    "slip-velocity": ("static", "kinetic", "decay"),
    "polach": ("mu0", "A", "B"),
    "temperature": ("reference", "reference_temperature", "change", "over"),
}


def friction_law(value) -> FrictionLaw:
    """The law of a validated scene value ``friction`` (a number or a table with ``law``)."""
    if isinstance(value, FrictionLaw):
        return value
    if not isinstance(value, dict):
        return ConstantFriction(float(value))
    kind = value["law"]
    p = {k: float(value[k]) for k in LAW_KINDS[kind]}
    if kind == "slip-velocity":
        return SlipVelocityFriction(**p)
    if kind == "polach":
        return PolachFriction.from_polach(**p)
    return TemperatureFriction(**p)


def contraction_limit(law: FrictionLaw, pressure: float, stiffness: float) -> float:
    """The steepest slope of ``mu(v_slip) p`` against the slip the traction drives, at one cell [1].

    In a slipping cell the traction bound g = mu(v) p and the slip speed v are tied by the elastic
    (or, for FASTSIM, the flexibility) relation v = (|p_candidate| - g) / stiffness; the fixed point
    g = mu((|p_c| - g) / stiffness) p is unique and the monotone iteration on it converges when
    ``|d mu/dv| p / stiffness < 1`` (the law falls slower than the traction can follow).
    Returns that number at v = 0 (the steepest point of the exponential laws); >= 1 means no unique
    local solution.

    Parameters
    ----------
    law : FrictionLaw
    pressure : float
        Local pressure p [Pa].
    stiffness : float
        Traction drop per unit slip speed in the cell, -dp_t/dv [Pa s/m].
    """
    return float(abs(law.dmu_dslip(0.0)) * pressure / stiffness) if stiffness > 0 else math.inf


def contact_temperature(scene, patch) -> np.ndarray | float:
    """The contact temperature a temperature law sees on the patch [degC]: the patch's
    ``contact_temperature`` (core's coupled loop sets it), else the mean bulk temperature of wheel and rail."""
    t = getattr(patch, "contact_temperature", None)
    if t is not None:
        return np.asarray(t, dtype=float)
    return 0.5 * (float(scene.wheel.bulk_temperature) + float(scene.rail.bulk_temperature))


def local_friction(scene, patch, slip_speed=0.0) -> np.ndarray:
    """The coefficient of friction of every cell of ``patch`` [1], shape ``patch.grid.shape``.

    Parameters
    ----------
    scene : Scene
        Its ``friction_law``.
    patch : ContactPatch
        The patch (its grid, and the contact temperature of :func:`contact_temperature`).
    slip_speed : float or ndarray
        Local slip speed |v_slip| [m/s] (broadcast to the grid).
    """
    law = scene.friction_law
    mu = law.mu(np.asarray(slip_speed, dtype=float), contact_temperature(scene, patch))
    return np.broadcast_to(np.asarray(mu, dtype=float), patch.grid.shape).copy()


#: the slip-velocity outer iteration stops when mu changes by less than this over the contact [1]
SLIP_MU_TOLERANCE = 1e-5
#: ... and fails after this many steps (not converged: a failed run, :class:`railtherm.SolverError`)
SLIP_MAX_OUTER = 60


def iterate_slip_law(law: FrictionLaw, solve, slip_speed, shape, kappa_of, *, model: str, speed: float,
                     tol: float = SLIP_MU_TOLERANCE, max_outer: int = SLIP_MAX_OUTER):
    """Solve a tangential problem under a slip-velocity law by the monotone outer iteration on mu.

    The traction bound of a slipping cell, mu(v) p, depends on its own slip speed v, which depends on the
    bound. The map mu -> law(v(mu)) is monotone increasing (a higher bound gives less slip, and the law
    falls with slip), so the iteration started at the law's maximum (mu at zero slip) decreases
    monotonically to the largest fixed point, the solution of least slip. It contracts at the rate kappa =
    max |dmu/dv| p V s_self (the law's slope against the slip a cell's own traction drives,
    :func:`contraction_limit`); kappa >= 1 (no unique local solution: outside the model's validity) is
    refused before the iteration goes on; an iteration with kappa < 1 that has not met ``tol`` after
    ``max_outer`` steps is a solver that did not converge, a failed run. Used by the exact
    (``kalker``) and the FEM tangential problems; FASTSIM solves its local equation in its sweep.

    Parameters
    ----------
    law : FrictionLaw
        A law that depends on the slip speed.
    solve : callable
        ``solve(mu, previous) -> solution`` with mu per cell (``shape``) [1] and the previous solution (None
        at the first step; a warm start where the solver takes one).
    slip_speed : callable
        ``slip_speed(solution) -> ndarray`` (``shape``): |v_slip| per cell [m/s].
    shape : tuple
        Shape of mu.
    kappa_of : callable
        ``kappa_of(solution) -> (kappa, inside)``: the contraction number [1] and the contact mask, from the
        first solution.
    model : str
        Model name for the messages.
    speed : float
        Rolling speed V [m/s] (the refusal says which speed would work).
    tol, max_outer : float, int
        Stop when max |mu_{k+1} - mu_k| over the contact < ``tol`` [1]; fail after ``max_outer`` steps.

    Returns
    -------
    solution, mu, history, kappa
        The last solve (it used ``mu``, which the law reproduces within ``tol``), mu per cell [1], the
        change of mu at each step [1], and kappa [1].

    Raises
    ------
    railtherm.Refused
        (validity) kappa >= 1.
    railtherm.SolverError
        No convergence in ``max_outer`` steps (the run is ``failed``, reason not-converged).
    """
    from ..contract.errors import Refused, SolverError
    mu = np.full(shape, float(law.mu(0.0)))
    sol, kappa, inside, history = None, None, None, []
    for _ in range(max_outer):
        sol = solve(mu, sol)
        if kappa is None:
            kappa, inside = kappa_of(sol)
            if not kappa < 1.0:
                decay = getattr(law, "decay", None)
                raise Refused(
                    f"model {model!r}: the friction law ({law.describe()}) falls too steeply for a unique local "
                    f"solution: kappa = |dmu/dv| p V s_self = {kappa:.3g} >= 1 at the most loaded cell (its slip "
                    f"cannot follow its falling traction bound); use a slower decay"
                    + (f" (decay >= {kappa * decay:.3g} m/s)" if decay else "")
                    + f", a speed <= {abs(float(speed)) / kappa:.3g} m/s or a lower load", kind="validity")
        new = np.asarray(law.mu(np.nan_to_num(slip_speed(sol))), dtype=float).reshape(shape)
        change = float(np.max(np.abs(new - mu)[inside], initial=0.0))
        history.append(change)
        if change < tol:
            return sol, mu, history, kappa
        mu = new
    raise SolverError(f"model {model!r}: the slip-velocity friction iteration did not converge in {max_outer} "
                      f"steps (last change of mu {history[-1]:.2e}, tolerance {tol:g}; kappa = {kappa:.3g})")
