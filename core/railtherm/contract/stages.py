"""Stage interfaces (plugin API 2): normal contact, tangential contact, heat source, temperature.

A scene flows through up to four stages, in this order. Each stage hands the next a small container
and never changes what it was given (it returns a new object):

* normal contact (:class:`NormalContactModel`) -> :class:`ContactPatch`: geometry, normal force
  and pressure (and, for a model that solves the kinematics, the rigid creepages);
* tangential contact (:class:`TangentialContactModel`) -> a new :class:`ContactPatch` with the
  tangential traction, slip velocity, stick/slip, creep forces and the surface speeds filled;
* heat source (:class:`HeatSourceModel`; core's ``frictional`` is traction x slip) ->
  :class:`HeatSource`: frictional power density on the patch, split between wheel and rail;
* temperature (:class:`TemperatureModel`) -> :class:`TemperatureField`: surface temperature of
  each body, optionally a depth field.

A *stage model* implements one stage; a *coupled model* (:class:`CoupledModel`) implements several
at once and receives what the plan gives it (:class:`Upstream`: the results of the stages before
its first one, a given heat source included); it never calls back into the pipeline.
Each model declares what it can do (:class:`Capabilities`) and answers :meth:`StageModel.supports`
before it runs. Plugins register model classes and :class:`Method` chains through the hooks in
:mod:`railtherm.contract.hookspec`.

Conventions (all SI, temperatures in degC as rises above the body's bulk temperature unless a
field says otherwise): x is the rolling direction with the origin at the patch centre and the
leading edge at x = +a; in the frame of the contact the body material flows in the -x direction
(enters at +a, leaves at -a); z >= 0 is depth into the body. Arrays on the surface grid have shape
``grid.shape`` = (nx, ny), or (nx,) for a line contact. Body index 0 is the wheel, 1 the rail.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

import numpy as np

from .capabilities import CONVECTION_KINDS, Capabilities, asks_history
from .errors import SceneError
from .grid import SurfaceGrid

if TYPE_CHECKING:  # pragma: no cover
    from ..input.scene import Scene

STAGES = ("normal", "tangential", "heat_source", "temperature")
BODIES = ("wheel", "rail")


@dataclass(frozen=True)
class ContactPatch:
    """Result of the contact stage.

    Attributes
    ----------
    grid : SurfaceGrid
        Surface grid of the patch.
    normal_force : float
        Normal force [N] ([N/m] for a line contact).
    a, b : float
        Semi-axes [m] (b None for a line contact).
    max_pressure : float
        Peak pressure p0 [Pa].
    pressure : ndarray
        Normal pressure on the grid [Pa].
    traction_x, traction_y : ndarray or None
        Tangential traction on body 1 (wheel) [Pa].
    slip_velocity_x, slip_velocity_y : ndarray or None
        Local slip velocity, wheel relative to rail [m/s].
    stick : ndarray or None
        1 where the cell sticks, 0 where it slips, NaN outside the patch [1].
    creep_force_x, creep_force_y, spin_moment : float or None
        Total tangential forces on the wheel [N] and spin moment [N m].
    contact_area : float or None
        Area of the contact [m^2] (the length 2a [m] for a line contact), when the normal model
        determines it from its grid (cells in contact); None: the exact pi a b (2a) of the semi-axes.
    creepage : (float, float, float) or None
        Rigid creepages (xi [1], eta [1], phi [1/m]) when the normal model determines them (the
        wheelset kinematics of seed section 6.1); None: the scene's.
    body_speed : (float, float) or None
        Surface speed of wheel and rail relative to the contact [m/s], set by the tangential stage
        (seed eqs. 32-33); None: :func:`railtherm.physics.body_speeds` of the scene.
    dissipation : ndarray or None
        Local frictional power density -(traction . slip velocity) [W/m^2], cell-averaged, when the
        tangential model integrates it exactly over each cell; None: core's heat source forms it from
        the traction and slip fields.
    contact_temperature : ndarray or None
        Contact temperature of each cell, the mean of the wheel's and the rail's surface temperature
        [degC], that a temperature-dependent friction law uses; set by core's coupled loop
        (:mod:`railtherm.solving.friction_loop`) before the tangential stage. None: the mean bulk
        temperature of the bodies (:func:`local_friction`).
    diagnostics : dict
        Solver diagnostics (iterations, residual, converged, ...).
    """

    grid: SurfaceGrid
    normal_force: float
    a: float
    b: float | None
    max_pressure: float
    pressure: np.ndarray
    traction_x: np.ndarray | None = None
    traction_y: np.ndarray | None = None
    slip_velocity_x: np.ndarray | None = None
    slip_velocity_y: np.ndarray | None = None
    stick: np.ndarray | None = None
    creep_force_x: float | None = None
    creep_force_y: float | None = None
    spin_moment: float | None = None
    creepage: tuple[float, float, float] | None = None
    contact_area: float | None = None
    body_speed: tuple[float, float] | None = None
    dissipation: np.ndarray | None = None
    diagnostics: dict = field(default_factory=dict)
    contact_temperature: np.ndarray | None = None

    #: fields a tangential model fills (:meth:`with_tangential`)
    TANGENTIAL_FIELDS: ClassVar[frozenset] = frozenset({
        "traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "stick", "creep_force_x",
        "creep_force_y", "spin_moment", "body_speed", "dissipation", "diagnostics"})

    def with_tangential(self, **fields) -> "ContactPatch":
        """A new patch with the tangential fields filled (the tangential stage's result); the normal
        fields (geometry, force, pressure) are the normal stage's and cannot be changed here."""
        bad = set(fields) - self.TANGENTIAL_FIELDS
        if bad:
            raise ValueError(f"a tangential model may fill only {sorted(self.TANGENTIAL_FIELDS)}; "
                             f"it tried to set {sorted(bad)} (the normal stage owns them)")
        return replace(self, **fields)


@dataclass(frozen=True)
class HeatSource:
    """Result of the heat-source stage.

    Attributes
    ----------
    grid : SurfaceGrid
        Surface grid (the patch grid).
    power_density : ndarray
        Total frictional power density on the grid [W/m^2].
    heat_partition : float or ndarray
        Fraction of the heat entering the wheel [1] (scalar or per cell).
    body_speed : tuple of float
        Speed of each body's surface relative to the contact (wheel, rail) [m/s]
        (seed eqs. 32-33: v_w = v0 + v_s, v_r = v0).
    frictional_power : float
        Frictional power as the heat-source model defines it [W] (integral of ``power_density``
        unless the model says otherwise in ``diagnostics``).
    patch : ContactPatch or None
        The contact patch the heat came from (None for a given heat source).
    shape : str or None
        "uniform" | "hertz" for an analytic given source (lets references be evaluated), else None.
    peak_flux : float or None
        Uniform value or peak of the analytic shape [W/m^2].
    diagnostics : dict
    """

    grid: SurfaceGrid
    power_density: np.ndarray
    heat_partition: float | np.ndarray
    body_speed: tuple[float, float]
    frictional_power: float
    patch: ContactPatch | None = None
    shape: str | None = None
    peak_flux: float | None = None
    diagnostics: dict = field(default_factory=dict)

    def flux(self, body: int | str) -> np.ndarray:
        """Heat flux entering ``body`` (0/"wheel" or 1/"rail") [W/m^2]."""
        i = BODIES.index(body) if isinstance(body, str) else int(body)
        eps = self.heat_partition
        return self.power_density * (eps if i == 0 else 1.0 - eps)

    def integrated_power(self) -> float:
        """Integral of the power density over the grid [W] ([W/m] for a line contact)."""
        return self.grid.integrate(self.power_density)


@dataclass(frozen=True)
class TemperatureField:
    """Result of the temperature stage.

    Attributes
    ----------
    surface_temperature : ndarray, shape (2, *grid.shape)
        Surface temperature of wheel and rail on the grid [degC] (absolute, bulk included).
    max_surface_temperature : ndarray, shape (2,)
        Maximum surface temperature of each body [degC].
    mean_contact_temperature : ndarray, shape (2,)
        Mean surface temperature over the contact patch [degC].
    z : ndarray or None
        Depth coordinate of the depth field [m], z >= 0.
    temperature : ndarray or None, shape (2, nx, nz)
        Temperature at y = 0 against depth [degC].
    steady_wheel_temperature, steady_mean_contact_temperature : float or None
        Long-term (steady-state) values [degC] where the model computes them.
    diagnostics : dict
    grid : SurfaceGrid or None
        The grid the fields lie on when it is not the heat source's: the
        :func:`railtherm.contract.grid.extended_grid` of a scene with ``field`` (x reaching behind the patch).
        None: the heat source's grid.
    peak_temperature, cooling_rate, time_above : ndarray or None, shape (2, nz)
        The thermal trace of a material point on the centre line at each depth ``z``: highest
        temperature [degC], fastest cooling after the peak [K s-1], time above ``field.threshold``
        [s]; NaN where the field is too short to tell (see :mod:`railtherm.physics.thermal_trace`,
        which fills them with :func:`~railtherm.physics.with_thermal_trace`).
    heated_depth : ndarray or None, shape (2,)
        Depth [m] down to which the peak exceeds ``field.threshold`` (NaN: the field is too shallow).
    """

    surface_temperature: np.ndarray
    max_surface_temperature: np.ndarray
    mean_contact_temperature: np.ndarray
    z: np.ndarray | None = None
    temperature: np.ndarray | None = None
    steady_wheel_temperature: float | None = None
    steady_mean_contact_temperature: float | None = None
    diagnostics: dict = field(default_factory=dict)
    grid: SurfaceGrid | None = None
    peak_temperature: np.ndarray | None = None
    cooling_rate: np.ndarray | None = None
    time_above: np.ndarray | None = None
    heated_depth: np.ndarray | None = None

    @classmethod
    def from_surface(cls, grid: SurfaceGrid, surface: np.ndarray, **kw) -> "TemperatureField":
        """Fill max and patch-mean from a (2, *grid.shape) surface field [degC] (absolute).

        Prefer :meth:`from_bodies`, which also adds the bulk temperatures, a body without heat and
        the common depth axis in one place.
        """
        surface = np.asarray(surface, dtype=float)
        kw.setdefault("grid", grid)
        inside = grid.inside()
        tmax = surface.reshape(2, -1).max(axis=1)
        rows = np.flatnonzero(inside.reshape(inside.shape[0], -1).any(axis=1))   # the patch's rows of a long grid
        r = slice(int(rows[0]), int(rows[-1]) + 1) if rows.size else slice(0, 0)
        tmean = np.array([surface[i][r][inside[r]].mean() for i in range(2)])
        return cls(surface, tmax, tmean, **kw)

    @classmethod
    def from_bodies(cls, grid: SurfaceGrid, bulk, wheel: "BodyTemperature | None" = None,
                    rail: "BodyTemperature | None" = None, *, z: np.ndarray | None = None,
                    steady_wheel_temperature: float | None = None,
                    steady_mean_contact_temperature: float | None = None,
                    diagnostics: Mapping[str, Any] | None = None) -> "TemperatureField":
        """Assemble the two-body result from each body's rise above its bulk temperature.

        Parameters
        ----------
        grid : SurfaceGrid
            Surface grid of the fields: the heat source's, or its :func:`railtherm.contract.grid.extended_grid`
            for a scene with ``field`` (then kept as :attr:`grid` of the result).
        bulk : (float, float)
            Bulk temperatures of wheel and rail [degC].
        wheel, rail : BodyTemperature or None
            Each body's rises [K]; None for a body without heat (it stays at its bulk temperature).
        z : ndarray, optional
            Common depth axis [m]. Default: the rail's depths, else the wheel's. Each body's depth
            profile is interpolated linearly onto it (a body is at its bulk temperature below its own
            deepest point, and everywhere if it has no depth profile). Give ``z`` to get a depth
            field even when no body has one (all bulk).
        steady_wheel_temperature, steady_mean_contact_temperature : float, optional
            Long-term values [degC] (absolute).
        diagnostics : mapping, optional
            The model's diagnostics; each body's own are added with the body's name as prefix
            (``wheel_iterations``, ``rail_residual``, ...).

        Returns
        -------
        TemperatureField
            Absolute temperatures [degC]; the arrays are new (the inputs are not kept or changed).
        """
        bodies = (wheel, rail)
        t_bulk = np.asarray(bulk, dtype=float).reshape(2)
        surface = np.empty((2,) + tuple(grid.shape))
        for i, body in enumerate(bodies):
            if body is None:
                surface[i] = t_bulk[i]
            else:            # in place: no temporary of the (long field) grid's size
                np.add(np.asarray(body.surface_rise, dtype=float).reshape(grid.shape), t_bulk[i], out=surface[i])
        if z is None:
            for body in (rail, wheel):
                if body is not None and body.z is not None:
                    z = body.z
                    break
        depth = None
        if z is not None:
            z = np.array(z, dtype=float)
            nx = grid.shape[0]
            depth = np.empty((2, nx, z.size))
            for i, body in enumerate(bodies):
                depth[i] = t_bulk[i]
                if body is None or body.z is None:
                    continue
                rise = np.asarray(body.depth_rise, dtype=float).reshape(nx, -1)
                bz = np.asarray(body.z, dtype=float)
                if bz.shape == z.shape and np.array_equal(bz, z):
                    depth[i] += rise
                else:
                    depth[i] += np.array([np.interp(z, bz, row, right=0.0) for row in rise])
        diag = dict(diagnostics or {})
        for name, body in zip(BODIES, bodies):
            if body is not None:
                diag.update({f"{name}_{k}": v for k, v in (body.diagnostics or {}).items()})
        return cls.from_surface(grid, surface, z=z, temperature=depth,
                                steady_wheel_temperature=steady_wheel_temperature,
                                steady_mean_contact_temperature=steady_mean_contact_temperature,
                                diagnostics=diag)


@dataclass(frozen=True)
class BodyTemperature:
    """One body's temperature rise above its bulk temperature, for :meth:`TemperatureField.from_bodies`.

    Attributes
    ----------
    surface_rise : ndarray, shape grid.shape
        Surface temperature rise on the patch grid [K].
    z : ndarray or None
        The body's own depth axis [m], z >= 0 (None: no depth profile).
    depth_rise : ndarray or None, shape (nx, nz)
        Rise at y = 0 against depth [K].
    diagnostics : dict
        The body's solver diagnostics (prefixed with the body's name in the field).
    """

    surface_rise: np.ndarray
    z: np.ndarray | None = None
    depth_rise: np.ndarray | None = None
    diagnostics: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Option:
    """A declared model option (``[study.options.<method>]`` / ``solve(..., options=...)``)."""

    default: Any
    doc: str
    choices: tuple | None = None
    minimum: float | None = None

    def check(self, model: str, key: str, value: Any) -> Any:
        if self.choices is not None and value not in self.choices:
            raise SceneError(f"option {key!r} of model {model!r} = {value!r} is not allowed: one of {list(self.choices)}",
                             key=key, value=value, allowed=str(list(self.choices)))
        if self.minimum is not None:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= self.minimum:
                raise SceneError(f"option {key!r} of model {model!r} = {value!r} is not allowed: a number >= {self.minimum}",
                                 key=key, value=value, allowed=f">= {self.minimum}")
        return value


def _given_semi_axis(scene) -> float | None:
    """Semi-axis along rolling [m] that the scene gives (its heat source's ``semi_axes`` or
    ``half_width``, or the contact's ``semi_axes``), else None: a Hertz patch computed from the load
    is known only after the contact stage, where :meth:`StageModel.supports_source` checks it.
    (``railtherm.physics.scene_semi_axis`` would compute it, but ``railtherm.physics.hertz`` builds a
    :class:`ContactPatch` and importing it here would close an import circle.)"""
    hs = getattr(scene, "heat_source", None)
    if hs is not None:
        axes = getattr(hs, "semi_axes", None)
        return float(axes[0]) if axes is not None else float(hs.half_width)
    axes = getattr(scene, "semi_axes", None)
    return float(axes[0]) if axes is not None else None


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

        The default enforces :attr:`capabilities`, for every model: contact shape, heat source
        kind and tangential regime; for a model of the temperature stage also the scene's mode, its
        convection, moving surfaces and each body's Péclet number (when the scene gives the
        semi-axis; :meth:`supports_source` checks the last two on the heat source itself). Override only to add the limits of the method (stability, budgets...) and
        call ``super().supports`` first; never re-check a declared capability. The reason becomes
        the message of a ``refused`` run (:class:`railtherm.Refused`, kind "validity"): it names the
        limit, the value and what would work instead.
        """
        caps = self.capabilities
        shape = scene.contact_shape
        if shape == "gap" and getattr(scene, "profile_contact", None) is not None and "normal" not in self.stages:
            # a wheelset on profiles: the later stages work on the normal stage's patch, for a Hertz-based
            # chain the Hertz-equivalent ellipse (normal model "wheelset-profile")
            shape = "ellipse"
        if shape not in caps.contacts:
            if scene.contact_shape == "gap":
                terms = ", ".join(f"x^{i} y^{j}" for (i, j) in sorted(scene.gap_coefficients or {}))
                return (f"model {self.name!r} needs a Hertzian gap h = A x^2 + B y^2 (A, B > 0); the gap of scene "
                        f"{scene.name!r} has the terms {terms}, which is not a quadratic: use a normal model "
                        "for non-Hertzian gaps (method 'kalker')")
            return f"model {self.name!r} handles {sorted(caps.contacts)} contacts, not {scene.contact_shape!r}"
        kind = "given" if scene.heat_source is not None else "computed"
        if kind not in caps.sources:
            return f"model {self.name!r} needs a {'/'.join(sorted(caps.sources))} heat source, scene gives a {kind} one"
        if scene.heat_source is None and scene.tangential not in caps.tangential:
            return f"model {self.name!r} handles {sorted(caps.tangential)}, not {scene.tangential!r}"
        law = scene.friction_law if scene.heat_source is None and "tangential" in self.stages else None
        if law is not None and law.kind not in caps.friction_laws:
            return (f"model {self.name!r} applies the friction laws {'/'.join(sorted(caps.friction_laws))}, not the "
                    f"scene's {law.kind!r} law ({law.describe()}); use a model that declares it (railtherm methods "
                    "lists each model's friction laws)")
        if "temperature" not in self.stages:
            return None
        mode = getattr(scene, "mode", "steady") or "steady"
        if mode not in caps.modes:
            other = sorted({"steady", "transient"} - set(caps.modes))
            return (f"model {self.name!r} computes mode {'/'.join(sorted(caps.modes))}, not the scene's mode {mode!r}; "
                    + (caps.advice_for("modes") or f"use a model that declares mode {'/'.join(other) or mode!r} "
                       "(railtherm methods lists each model's modes)"))
        if asks_history(scene) and not caps.histories:
            return (f"model {self.name!r} does not compute the pass histories of a transient scene (passes, "
                    "schedule, temperature_history, pass_peak_temperature, residual_rise, time_above per pass); "
                    + (caps.advice_for("histories") or "use a temperature model that declares histories=yes "
                       "(railtherm methods lists them; method 'green')"))
        fld = getattr(scene, "field", None)
        if fld is not None and not caps.field:
            return (f"model {self.name!r} reports temperatures on the patch only, but scene "
                    f"{getattr(scene, 'name', '?')!r} asks for them behind the patch and in depth (key 'field': "
                    f"behind = {fld.behind:g} m, depth = {'default' if fld.depth is None else format(fld.depth, 'g') + ' m'}); "
                    + (caps.advice_for("field") or "leave out 'field' or use a temperature model that declares "
                       "field=yes (railtherm methods lists them; method 'green')"))
        h = float(getattr(scene, "convection", 0.0) or 0.0)
        if h > 0 and not caps.convection:
            return (f"model {self.name!r} ignores convection (it declares convection=no) but scene "
                    f"{getattr(scene, 'name', '?')!r} has convection = {h:g} W/m^2K; set convection = 0 or "
                    + (caps.advice_for("convection") or "use a temperature model that declares convection=yes "
                       "(railtherm methods lists them)"))
        if not (caps.moving_surface or caps.peclet != (0.0, float("inf"))):
            return None
        from ..physics.kinematics import body_speeds
        speeds = (0.0, 0.0) if getattr(scene, "speed", None) is None else body_speeds(scene)
        return self._flow_refusal(_given_semi_axis(scene), speeds, (scene.wheel, scene.rail))

    def supports_source(self, scene: "Scene", source: HeatSource) -> str | None:
        """The checks of :meth:`supports` that need the heat source (moving surfaces and Péclet
        numbers from the source's semi-axis ``grid.a`` and ``body_speed``): None, or the reason.

        For a temperature model whose patch is known only after the contact stage (e.g. FASTSIM's
        surface speeds V (1 - xi)); call it at the top of ``compute_temperature`` and raise
        ``railtherm.Refused(reason, kind="validity")``.
        """
        return self._flow_refusal(float(source.grid.a), tuple(float(v) for v in source.body_speed),
                                  (scene.wheel, scene.rail))

    def _flow_refusal(self, a: float | None, speeds, bodies) -> str | None:
        """Moving-surface and Péclet checks of :attr:`capabilities` for semi-axis ``a`` [m] (None:
        unknown, Péclet not checked), body surface speeds [m/s] and materials (wheel, rail)."""
        caps = self.capabilities
        lo, hi = (float(x) for x in caps.peclet)
        check_pe = (lo, hi) != (0.0, float("inf"))
        for body, v in zip(BODIES, speeds):
            v = float(v)
            if caps.moving_surface and not v > 0.0:
                return (f"model {self.name!r}: the {body} moves at {v:g} m/s, so its surface does not move through "
                        f"the patch (the model works in the frame moving with the contact and needs speed > 0); "
                        + (caps.advice_for("moving_surface") or "use a model that does not need moving surfaces "
                           "(railtherm methods lists them)"))
        if not check_pe or a is None:
            return None
        from ..physics.scales import peclet_number
        for body, v, m in zip(BODIES, speeds, bodies):
            kappa = m.diffusivity
            pe = peclet_number(v, a, kappa)
            if lo <= pe <= hi:
                continue
            side = f"is below {lo:g}" if pe < lo else f"is above {hi:g}"
            return (f"model {self.name!r}: Péclet number of the {body} L = V a/(2 kappa) = {float(v):g} m/s x {a:.4g} m / "
                    f"(2 x {kappa:.3g} m^2/s) = {pe:.3g} {side} (the model's declared range is {lo:g}..{hi:g}); "
                    + (caps.advice_for("peclet") or f"use a model whose declared Péclet range contains {pe:.3g} "
                       "(railtherm methods lists each model's range)"))
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
        """Declared capabilities (:meth:`StageModel.supports`), then what every tangential model needs:
        a friction coefficient, a tangential regime (creepage, sliding speed or a wheelset that sets the
        creepages) and, for an elastic (creep) model, at least one elastic body."""
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
    :meth:`StageModel.supports` accepts the scene runs. A coupled model is named in each stage
    it covers. A chain without a ``heat_source`` stage gets core's ``frictional`` (traction x slip)
    when it has a tangential and a temperature stage. A plugin API 1 chain (stage ``contact``; a
    tangential model such as ``full-sliding`` listed under ``heat_source``) is translated by the
    plugin host, with a warning, for one release. ``default_cells`` sets the surface grid's cells
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
