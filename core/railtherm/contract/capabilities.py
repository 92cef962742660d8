"""What a stage model can do (:class:`Capabilities`): declared by each model, enforced once by core
(:mod:`railtherm.solving.capabilities_check`), listed by ``railtherm methods``."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["Capabilities", "CONVECTION_KINDS"]


#: values of :attr:`Capabilities.convection`
CONVECTION_KINDS = (False, True, "long-term")


@dataclass(frozen=True)
class Capabilities:
    """What a stage model can do; enforced by core (:mod:`railtherm.solving.capabilities_check`) and listed
    by ``railtherm methods``.

    Core checks every declared field once, for every model (built-in or third-party), before the
    model runs; a model's own ``supports`` adds only the limits of its method. ``modes``,
    ``convection``, ``peclet`` and ``moving_surface`` concern the temperature, so they are checked
    for models that implement the temperature stage.

    Attributes
    ----------
    contacts : frozenset of {"ellipse", "line", "gap"}
        Contact shapes the model handles; ``gap`` is a non-Hertzian undeformed gap
        (``scene.gap_coefficients``; a quadratic gap is read as an ellipse with those curvatures).
    sources : frozenset of {"computed", "given"}
        Whether the model takes a patch computed by an earlier stage and/or a given heat source.
    tangential : frozenset of {"full-sliding", "creepage"}
    convection : {False, True, "long-term"}
        Whether the model honours the scene's convection coefficient [W/m^2K]: False refuses a scene
        with convection > 0 (the model would silently ignore it); True honours it in every output;
        "long-term" honours it only in the long-term (steady) wheel temperature, the flash
        temperatures ignoring it (it is negligible over one contact time).
    modes : frozenset of {"steady", "transient"}
        Scene modes the model computes (the scene's ``mode``).
    peclet : (float, float)
        Péclet range [lo, hi] (L = V a / 2 kappa, :func:`railtherm.physics.peclet_number`) in which
        the model is valid; each body's number, from the semi-axis along rolling and the body's
        surface speed (:func:`railtherm.physics.body_speeds`), must lie in it. Checked before the
        model is chosen when the scene gives the semi-axis (``semi_axes`` or a given heat source), and
        on the heat source right before the model computes (a Hertz patch from the load is known only
        after the contact stage).
    moving_surface : bool
        The model works in the frame moving with the contact and needs both bodies' surfaces to
        move through the patch (surface speed > 0).
    provides : frozenset of str
        Result variables the model fills (names of :data:`railtherm.contract.schema.VARIABLES`).
    field : bool
        The model reports temperatures behind the patch and in depth as the scene's ``field`` asks
        (on :func:`railtherm.contract.grid.extended_grid`, depth down to ``field.depth``) and the thermal trace
        (:func:`railtherm.physics.with_thermal_trace`); False refuses a scene with ``field``.
    friction_laws : frozenset of {"constant", "slip-velocity", "polach", "temperature"}
        Friction laws (scene key ``friction``, :mod:`railtherm.physics.friction`) the model applies cell
        by cell; checked for models of the tangential stage (and coupled models that cover it). A
        ``temperature`` law is evaluated with the contact temperature core puts on the patch
        (:attr:`ContactPatch.contact_temperature`) in its coupled loop
        (:mod:`railtherm.solving.friction_loop`); a coupled model that computes its own temperatures
        applies it itself.
    histories : bool
        The model computes the pass histories of a transient scene (``passes``, ``schedule``,
        ``temperature_history``, ``pass_peak_temperature``, ``residual_rise``, per-pass ``time_above``);
        False refuses a scene that asks for them (:func:`asks_history`).
    advice : tuple of (str, str)
        Optional method-specific reason and alternative appended to a refusal, per capability
        ("modes", "convection", "peclet", "moving_surface", "field", "histories"); a mapping is accepted. Without it core
        says which declaration would work (``railtherm methods`` lists each model's).
    """

    contacts: frozenset = frozenset({"ellipse", "line"})
    sources: frozenset = frozenset({"computed", "given"})
    tangential: frozenset = frozenset({"full-sliding", "creepage"})
    convection: bool | str = False
    modes: frozenset = frozenset({"steady"})
    peclet: tuple[float, float] = (0.0, float("inf"))
    moving_surface: bool = False
    provides: frozenset = frozenset()
    advice: tuple = ()
    field: bool = False
    friction_laws: frozenset = frozenset({"constant"})
    histories: bool = False

    def __post_init__(self):
        if self.convection not in CONVECTION_KINDS or not isinstance(self.convection, (bool, str)):
            raise ValueError(f"Capabilities.convection must be one of {CONVECTION_KINDS}, got {self.convection!r}")
        if isinstance(self.advice, Mapping):
            object.__setattr__(self, "advice", tuple(sorted(self.advice.items())))
        unknown = {k for k, _ in self.advice} - {"modes", "convection", "peclet", "moving_surface", "field", "histories"}
        if unknown:
            raise ValueError(f"Capabilities.advice has unknown keys {sorted(unknown)}")

    def advice_for(self, key: str) -> str | None:
        """The declared advice for capability ``key``, or None."""
        return dict(self.advice).get(key)

    def describe(self) -> str:
        """One line for ``railtherm methods``: every field core enforces (the temperature ones apply
        to models of the temperature stage)."""
        lo, hi = self.peclet
        conv = {True: "yes", False: "no", "long-term": "long-term wheel temperature only"}[self.convection]
        return (f"enforced by core: contacts={'/'.join(sorted(self.contacts))}; sources={'/'.join(sorted(self.sources))}; "
                f"tangential={'/'.join(sorted(self.tangential))}; if a temperature model: "
                f"modes={'/'.join(sorted(self.modes))}; convection={conv}; Peclet {lo:g}..{hi:g}; "
                f"moving surfaces needed={'yes' if self.moving_surface else 'no'}; "
                f"field (behind the patch, in depth)={'yes' if self.field else 'no'}; "
                f"histories (transient passes)={'yes' if self.histories else 'no'}; "
                f"friction laws={'/'.join(sorted(self.friction_laws))}")


def asks_history(scene) -> bool:
    """True when a transient scene asks for the pass histories: it gives ``passes`` or ``schedule`` or names
    a transient output (``time_above`` counts only in a transient scene). A transient scene without
    them may still mean a model's own transient (fipy's wheel over revolutions, ``numerics.duration``);
    only temperature models that declare ``Capabilities(histories=True)`` compute the histories."""
    tr = getattr(scene, "transient", None)
    if tr is None:
        return False
    source = getattr(scene, "source", {}) or {}
    return "passes" in source or "schedule" in source or bool(tr.outputs)
