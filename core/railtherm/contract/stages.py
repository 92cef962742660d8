"""Stage interfaces (plugin API 2): normal contact, tangential contact, heat source, temperature.

A scene flows through up to four stages, in this order; each returns a new container and never changes
what it was given: normal (:class:`NormalContactModel`) -> :class:`ContactPatch` (geometry, pressure,
rigid creepages when it solves the kinematics); tangential (:class:`TangentialContactModel`) -> a new
:class:`ContactPatch` with traction, slip, stick/slip, creep forces; heat source
(:class:`HeatSourceModel`) -> :class:`HeatSource` split between wheel and rail; temperature
(:class:`TemperatureModel`) -> :class:`TemperatureField`.

A *coupled model* (:class:`CoupledModel`) implements several stages at once and receives the results of
the stages before its first one (:class:`Upstream`); it never calls back into the pipeline. Each model
declares :class:`Capabilities` (enforced by :mod:`railtherm.solving.capabilities_check`) and answers
:meth:`StageModel.supports` for its own limits. Hooks: :mod:`railtherm.contract.hookspec`; result
containers: :mod:`railtherm.contract.results`; options: :mod:`railtherm.contract.options`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

from .capabilities import Capabilities
from .options import Option
from .results import ContactPatch, HeatSource, TemperatureField

if TYPE_CHECKING:  # pragma: no cover
    from ..input.scene import Scene

STAGES = ("normal", "tangential", "heat_source", "temperature")


class StageModel:
    """Base class of every stage model.

    Subclasses set the class attributes and implement the compute method of their stage.
    Instances are cheap; the runner makes one per run.
    """

    #: unique model name, e.g. "hertz", "fastsim", "green"
    name: ClassVar[str] = ""
    #: stages this model implements (one for a stage model, several for a coupled model)
    stages: ClassVar[tuple[str, ...]] = ()
    #: one line for ``railtherm methods``
    description: ClassVar[str] = ""
    capabilities: ClassVar[Capabilities] = Capabilities()
    #: declared options: name -> Option
    options: ClassVar[Mapping[str, Option]] = {}
    #: tag of core's exact reference that this model *is* (``"hertz"`` for the Hertz patch): its
    #: outputs equal that reference by construction, so metrics never count them as a verification
    exact_reference: ClassVar[str | None] = None
    #: version string reported in results' ``source`` (defaults to the plugin's distribution version)
    version: ClassVar[str | None] = None

    def supports(self, scene: "Scene", level: int) -> str | None:
        """Return None when the model can run ``scene`` at ``level``, else the reason it cannot.

        The plugin's hook for the limits of its method that :attr:`capabilities` cannot declare
        (stability, budgets, required scene keys...); the default has none. Core checks the declared
        capabilities before it calls this (:mod:`railtherm.solving.capabilities_check`: contacts, heat
        source kind, tangential regime, friction laws, and for a temperature model mode, histories,
        field, convection, moving surfaces and Péclet range, the last two again on the actual heat
        source right before ``compute_temperature``), so an override never re-checks a declared
        capability. The reason becomes the message of a ``refused`` run (:class:`railtherm.Refused`,
        kind "validity"): it names the limit, the value and what would work instead.
        """
        return None

    @classmethod
    def resolve_options(cls, options: Mapping[str, Any] | None) -> dict:
        """Fill defaults and validate the options that belong to this model; others are ignored."""
        options = dict(options or {})
        out = {}
        for key, opt in cls.options.items():
            out[key] = opt.check(cls.name, key, options[key]) if key in options else opt.default
        return out


class NormalContactModel(StageModel):
    """Normal-contact stage: patch geometry, normal force and pressure (e.g. core's ``hertz``)."""

    stages = ("normal",)

    def compute_patch(self, scene: "Scene", level: int, options: dict) -> ContactPatch:
        """Return the contact patch of ``scene`` on the grid of ``level`` (normal fields only)."""
        raise NotImplementedError


class TangentialContactModel(StageModel):
    """Tangential-contact stage: traction, slip, stick/slip and creep forces on a given patch
    (core's ``full-sliding``; FASTSIM)."""

    stages = ("tangential",)
    #: the model solves the elastic (creep) problem, so at least one body must be elastic
    needs_elastic_body: bool = False

    def supports(self, scene: "Scene", level: int) -> str | None:
        """What every tangential model needs beyond its declared capabilities: a friction coefficient,
        a tangential regime (creepage, sliding speed or a wheelset that sets the creepages) and, for an
        elastic (creep) model, at least one elastic body."""
        why = super().supports(scene, level)
        if why:
            return why
        if scene.heat_source is not None:
            return None   # a given heat source runs no tangential stage
        if scene.friction is None:
            return f"model {self.name!r} needs the friction coefficient (key 'friction')"
        if scene.creepage is None and scene.sliding_speed is None and getattr(scene, "wheelset", None) is None:
            return f"model {self.name!r} needs creepages, a sliding speed or a wheelset"
        if self.needs_elastic_body and getattr(scene.wheel, "rigid", False) and getattr(scene.rail, "rigid", False):
            return f"model {self.name!r} needs at least one elastic body (both are rigid)"
        c = scene.creepage
        if scene.contact_shape == "line" and c is not None and (float(c.lateral) != 0.0 or float(c.spin) != 0.0):
            return (f"model {self.name!r}: a line contact (2-D rolling) has only longitudinal creepage; the scene "
                    f"gives lateral = {float(c.lateral):g}, spin = {float(c.spin):g} 1/m: set them to 0 or use an "
                    "elliptical contact")
        return None

    def compute_tangential(self, scene: "Scene", patch: ContactPatch, level: int, options: dict) -> ContactPatch:
        """Return a new patch with the tangential fields filled (:meth:`ContactPatch.with_tangential`);
        ``patch`` is the normal stage's and is not changed."""
        raise NotImplementedError


class HeatSourceModel(StageModel):
    """Heat-source stage: frictional power density and its split between the bodies (core's
    ``frictional``: traction x slip; ``given``: the scene's own source)."""

    stages = ("heat_source",)

    def compute_source(self, scene: "Scene", patch: ContactPatch, level: int, options: dict) -> HeatSource:
        """Return the heat source of the tangential stage's ``patch`` (None for a given source)."""
        raise NotImplementedError


class TemperatureModel(StageModel):
    """Temperature stage: surface (and optionally depth) temperature of wheel and rail."""

    stages = ("temperature",)

    def compute_temperature(self, scene: "Scene", source: HeatSource, level: int, options: dict) -> TemperatureField:
        """Return the temperature field caused by ``source``."""
        raise NotImplementedError


@dataclass(frozen=True)
class Upstream:
    """What the plan hands a coupled model: the results of the stages before its first one.

    Attributes
    ----------
    patch : ContactPatch or None
        The normal (or tangential) stage's patch, when another model computed it.
    source : HeatSource or None
        The heat source, when another model computed it or the scene gives it (core's ``given``).
    """

    patch: ContactPatch | None = None
    source: HeatSource | None = None


class CoupledModel(StageModel):
    """A model that computes several stages together (e.g. the thermoelastic FEM)."""

    stages = STAGES

    def compute(self, scene: "Scene", level: int, options: dict, stages: tuple[str, ...], upstream: Upstream
                ) -> tuple[ContactPatch | None, HeatSource | None, TemperatureField | None]:
        """Compute the requested ``stages`` (a subset of :attr:`stages`, in pipeline order).

        ``upstream`` holds what earlier stages produced: when the scene gives its heat source,
        ``stages`` is ("temperature",) and ``upstream.source`` is that source (core's ``given``).
        Returns (patch, source, temperature), None for what was not requested; the patch carries
        the tangential fields when "tangential" is among ``stages``.
        """
        raise NotImplementedError


@dataclass(frozen=True)
class Method:
    """A named chain of stage models, e.g. ``Method("green", {"normal": ("hertz",),
    "tangential": ("full-sliding", "fastsim"), "temperature": ("green",)})``.

    For each stage the chain lists candidate model names; the first candidate whose
    declared capabilities and :meth:`StageModel.supports` accept the scene runs. A coupled model is named in each stage
    it covers. A chain without a ``heat_source`` stage gets core's ``frictional`` (traction x slip)
    when it has a tangential and a temperature stage; the plugin host refuses a chain naming any
    other stage (such as plugin API 1's ``contact``). ``default_cells`` sets the surface grid's cells
    along 2a at level 0.

    ``orders`` declares the theoretical convergence order of the method per error metric
    (``{"max_surface_temperature": 2.0, ...}``; metric names of :data:`railtherm.analysis.metrics.METRICS`):
    the report prints it beside each fitted order. Undeclared metrics have no stated order.
    """

    name: str
    chain: Mapping[str, tuple[str, ...]]
    description: str = ""
    default_cells: int | None = None
    orders: Mapping[str, float] = field(default_factory=dict)
