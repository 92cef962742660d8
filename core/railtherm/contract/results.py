"""Results the stages hand on: :class:`ContactPatch` (normal and tangential contact),
:class:`HeatSource` (heat-source stage), :class:`TemperatureField` (temperature stage) and
:class:`BodyTemperature`, one body's rises from which a temperature model assembles its field.

Each is frozen: a stage returns a new object and never changes what it was given.

Conventions (all SI, temperatures in degC as rises above the body's bulk temperature unless a
field says otherwise): x is the rolling direction with the origin at the patch centre and the
leading edge at x = +a; in the frame of the contact the body material flows in the -x direction
(enters at +a, leaves at -a); z >= 0 is depth into the body. Arrays on the surface grid have shape
``grid.shape`` = (nx, ny), or (nx,) for a line contact. Body index 0 is the wheel, 1 the rail.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Mapping

import numpy as np

from .grid import SurfaceGrid

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
        temperature of the bodies (:func:`railtherm.physics.friction.local_friction`).
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
    surface_temperature : ndarray or None, shape (2, *grid.shape)
        Surface temperature of wheel and rail on the grid [degC] (absolute, bulk included). None only with
        a pass history (:attr:`history`) of a scene whose outputs ask for no one-pass field: not computed.
    max_surface_temperature : ndarray or None, shape (2,)
        Maximum surface temperature of each body [degC] (None with ``surface_temperature``).
    mean_contact_temperature : ndarray or None, shape (2,)
        Mean surface temperature over the contact patch [degC] (None with ``surface_temperature``).
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

