"""Core's enforcement of the capabilities a stage model declares (:class:`railtherm.Capabilities`).

The pipeline asks :func:`capability_refusal` before a model's own :meth:`railtherm.StageModel.supports`
(so a plugin never re-checks a declared capability), and :func:`source_refusal` right before a
temperature model computes: a patch computed from the load is known only after the contact stage,
so the moving-surface and Péclet checks on its semi-axis and body speeds wait for the heat source.
Each answer is None or the reason, which becomes the message of a ``refused`` run (kind "validity"):
it names the limit, the value and what would work instead.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..contract.capabilities import asks_history
from ..contract.results import BODIES, HeatSource
from ..contract.stages import StageModel
from ..physics.kinematics import body_speeds
from ..physics.scales import peclet_number

if TYPE_CHECKING:  # pragma: no cover
    from ..input.scene import Scene

__all__ = ["capability_refusal", "source_refusal", "refusal"]


def refusal(model: StageModel, scene: "Scene", level: int) -> str | None:
    """Why ``model`` cannot run ``scene`` at ``level``: its declared capabilities
    (:func:`capability_refusal`), then its own limits (:meth:`railtherm.StageModel.supports`); None
    when it can."""
    return capability_refusal(model, scene) or model.supports(scene, level)


def capability_refusal(model: StageModel, scene: "Scene") -> str | None:
    """Why ``scene`` lies outside the capabilities ``model`` declares, or None.

    For every model: contact shape, heat source kind, tangential regime and (a tangential model)
    friction law; for a model of the temperature stage also the scene's mode, pass histories, field,
    convection, moving surfaces and each body's Péclet number (when the scene gives the semi-axis;
    :func:`source_refusal` checks the last two on the heat source itself).
    """
    return _contact_refusal(model, scene) or (_temperature_refusal(model, scene)
                                              if "temperature" in model.stages else None)


def source_refusal(model: StageModel, scene: "Scene", source: HeatSource) -> str | None:
    """The capability checks that need the heat source (moving surfaces and Péclet numbers from the
    source's semi-axis ``grid.a`` and ``body_speed``): None, or the reason."""
    return _flow_refusal(model, float(source.grid.a), tuple(float(v) for v in source.body_speed),
                         (scene.wheel, scene.rail))


def _contact_refusal(model: StageModel, scene: "Scene") -> str | None:
    """Contact shape, heat source kind, tangential regime and friction law against the declaration."""
    caps = model.capabilities
    shape = scene.contact_shape
    if shape == "gap" and getattr(scene, "profile_contact", None) is not None and "normal" not in model.stages:
        # a wheelset on profiles: the later stages work on the normal stage's patch, for a Hertz-based
        # chain the Hertz-equivalent ellipse (normal model "wheelset-profile")
        shape = "ellipse"
    if shape not in caps.contacts:
        if scene.contact_shape == "gap":
            terms = ", ".join(f"x^{i} y^{j}" for (i, j) in sorted(scene.gap_coefficients or {}))
            return (f"model {model.name!r} needs a Hertzian gap h = A x^2 + B y^2 (A, B > 0); the gap of scene "
                    f"{scene.name!r} has the terms {terms}, which is not a quadratic: use a normal model "
                    "for non-Hertzian gaps (method 'kalker')")
        return f"model {model.name!r} handles {sorted(caps.contacts)} contacts, not {scene.contact_shape!r}"
    kind = "given" if scene.heat_source is not None else "computed"
    if kind not in caps.sources:
        return f"model {model.name!r} needs a {'/'.join(sorted(caps.sources))} heat source, scene gives a {kind} one"
    if scene.heat_source is None and scene.tangential not in caps.tangential:
        return f"model {model.name!r} handles {sorted(caps.tangential)}, not {scene.tangential!r}"
    law = scene.friction if scene.heat_source is None and "tangential" in model.stages else None
    if law is not None and law.kind not in caps.friction_laws:
        return (f"model {model.name!r} applies the friction laws {'/'.join(sorted(caps.friction_laws))}, not the "
                f"scene's {law.kind!r} law ({law.describe()}); use a model that declares it (railtherm methods "
                "lists each model's friction laws)")
    return None


def _temperature_refusal(model: StageModel, scene: "Scene") -> str | None:
    """Mode, pass histories, field, convection, moving surfaces and Péclet range of a temperature model."""
    caps = model.capabilities
    mode = getattr(scene, "mode", "steady") or "steady"
    if mode not in caps.modes:
        other = sorted({"steady", "transient"} - set(caps.modes))
        return (f"model {model.name!r} computes mode {'/'.join(sorted(caps.modes))}, not the scene's mode {mode!r}; "
                + (caps.advice_for("modes") or f"use a model that declares mode {'/'.join(other) or mode!r} "
                   "(railtherm methods lists each model's modes)"))
    if asks_history(scene) and not caps.histories:
        return (f"model {model.name!r} does not compute the pass histories of a transient scene (passes, "
                "schedule, temperature_history, pass_peak_temperature, residual_rise, time_above per pass); "
                + (caps.advice_for("histories") or "use a temperature model that declares histories=yes "
                   "(railtherm methods lists them; method 'green')"))
    fld = getattr(scene, "field", None)
    if fld is not None and not caps.field:
        return (f"model {model.name!r} reports temperatures on the patch only, but scene "
                f"{getattr(scene, 'name', '?')!r} asks for them behind the patch and in depth (key 'field': "
                f"behind = {fld.behind:g} m, depth = {'default' if fld.depth is None else format(fld.depth, 'g') + ' m'}); "
                + (caps.advice_for("field") or "leave out 'field' or use a temperature model that declares "
                   "field=yes (railtherm methods lists them; method 'green')"))
    h = float(getattr(scene, "convection", 0.0) or 0.0)
    if h > 0 and not caps.convection:
        return (f"model {model.name!r} ignores convection (it declares convection=no) but scene "
                f"{getattr(scene, 'name', '?')!r} has convection = {h:g} W/m^2K; set convection = 0 or "
                + (caps.advice_for("convection") or "use a temperature model that declares convection=yes "
                   "(railtherm methods lists them)"))
    if not (caps.moving_surface or caps.peclet != (0.0, float("inf"))):
        return None
    speeds = ((0.0, 0.0) if getattr(scene, "speed", None) is None
              else body_speeds(scene.speed, scene.sliding_speed, scene.tangential))
    return _flow_refusal(model, _given_semi_axis(scene), speeds, (scene.wheel, scene.rail))


def _given_semi_axis(scene) -> float | None:
    """Semi-axis along rolling [m] that the scene gives (its heat source's ``semi_axes`` or
    ``half_width``, or the contact's ``semi_axes``), else None: a Hertz patch computed from the load
    is known only after the contact stage, where :func:`source_refusal` checks it."""
    hs = getattr(scene, "heat_source", None)
    if hs is not None:
        axes = getattr(hs, "semi_axes", None)
        return float(axes[0]) if axes is not None else float(hs.half_width)
    axes = getattr(scene, "semi_axes", None)
    return float(axes[0]) if axes is not None else None


def _flow_refusal(model: StageModel, a: float | None, speeds, bodies) -> str | None:
    """Moving-surface and Péclet checks of the model's capabilities for semi-axis ``a`` [m] (None:
    unknown, Péclet not checked), body surface speeds [m/s] and materials (wheel, rail)."""
    caps = model.capabilities
    lo, hi = (float(x) for x in caps.peclet)
    check_pe = (lo, hi) != (0.0, float("inf"))
    for body, v in zip(BODIES, speeds):
        v = float(v)
        if caps.moving_surface and not v > 0.0:
            return (f"model {model.name!r}: the {body} moves at {v:g} m/s, so its surface does not move through "
                    f"the patch (the model works in the frame moving with the contact and needs speed > 0); "
                    + (caps.advice_for("moving_surface") or "use a model that does not need moving surfaces "
                       "(railtherm methods lists them)"))
    if not check_pe or a is None:
        return None
    for body, v, m in zip(BODIES, speeds, bodies):
        kappa = m.diffusivity
        pe = peclet_number(v, a, kappa)
        if lo <= pe <= hi:
            continue
        side = f"is below {lo:g}" if pe < lo else f"is above {hi:g}"
        return (f"model {model.name!r}: Péclet number of the {body} L = V a/(2 kappa) = {float(v):g} m/s x {a:.4g} m / "
                f"(2 x {kappa:.3g} m^2/s) = {pe:.3g} {side} (the model's declared range is {lo:g}..{hi:g}); "
                + (caps.advice_for("peclet") or f"use a model whose declared Péclet range contains {pe:.3g} "
                   "(railtherm methods lists each model's range)"))
    return None
