"""fipy's pass histories of a line contact: the rail section (fixed frame, x-z, per unit width) discretised by FiPy.

FiPy's cell-centred finite volumes (``TransientTerm(rho c) == DiffusionTerm(lambda)`` on a ``Grid2D``, the deep
face at theta = 0, the rail's ends and the surface insulated, the band's flux entering the surface cells) give
the capacity C [J/(K m)] and conductance K [W/(K m)] once; core's driver (:mod:`railtherm.solving.section_stepping`)
steps ``C dT/dt = -K T + P(t)`` by Crank-Nicolson (FiPy's ``eq.solve`` would rebuild the matrix every step), each
step one multiplication per eigenmode of the separable operator (:mod:`railtherm_fipy.modes`: no factorisation),
at the section's step h/V under a source and on a ladder of growing steps between passes;
a schedule's kinks are step ends and its changing segments (tau [s]) are stepped finer (:class:`ScheduleSteps`).
Cells: width h = 2a/32/2**level along x over the section and four cells either side, growing by
``1.3 ** (1 / 2**level)`` to 2a + 2 sqrt(kappa t_end); heights from delta/4/2**level at the surface (delta =
sqrt(2 a kappa / V); from sqrt(kappa tau)/4/2**level where a schedule's segment makes that thinner), growing by
its square root down to 1.5 times the deepest output depth (:func:`_depth_widths`) and like the widths beyond.
The history at a depth: linear between the cell centres of the section's column; at the surface, extrapolated
linearly from the two top cells.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix, diags

from railtherm import ImplicitSectionStepper, SolverError
from railtherm.physics import thermal_scales

from .modes import SectionModes, separate
from .solvers import import_fipy

__all__ = ["FipyBlock", "fipy_block", "IMPLICIT_COST"]

#: one Crank-Nicolson step counted as this many explicit node updates (FiPy has no explicit stepping:
#: the model always asks the implicit scheme; the cost is recorded with the reason)
IMPLICIT_COST = 50.0


def _widths(first: float, growth: float, uniform: int, end: float) -> np.ndarray:
    """Cell widths [m] from 0: ``uniform`` cells of ``first``, then growing by ``growth`` until they reach ``end``."""
    w = [first] * uniform
    while sum(w) < end:
        w.append(w[-1] * growth)
    return np.array(w)


def _depth_widths(first: float, growth: float, output: float, end: float, surface: float | None = None) -> np.ndarray:
    """Cell heights [m] from the surface: from ``first``, growing by ``sqrt(growth)`` down to ``output`` (the
    deepest output depth, with margin) and by ``growth`` beyond, until they reach ``end``.

    The output depths sit in the tail of the profile exp(-z^2 / (4 kappa t)) while the passes are close in time
    (1 mm after 5 passes 1 ms apart: 0.2 % of the surface rise); there the cell-centred scheme's relative error
    grows like (dz z / (2 kappa t))^2 / 12, so the cells down to the output depths grow half as fast (still
    second order: growth - 1 halves per level). ``surface``: a thinner first cell [m] (a short segment of the
    schedule: the layer it heats), growing by ``growth`` up to ``first``."""
    w = [first if surface is None else min(surface, first)]
    while w[-1] * growth < first:
        w.append(w[-1] * growth)
    fine = math.sqrt(growth)
    while sum(w) < end:
        w.append(w[-1] * (fine if sum(w) < output else growth))
    return np.array(w)


class FipyBlock:
    """The section's FiPy cells and their operator (cell index i + nx j, j = 0 at the surface).

    Attributes: ``x``, ``z`` cell centres [m] (section at ``x[i0]`` = 0), ``faces_x`` [m], ``capacity``
    [J/(K m)], ``stiffness`` [W/(K m)], ``dt_stab`` (min C/K_ii [s], for the cost record), ``rows``
    (depths, 2) cells and ``weights`` (depths, 2) of the output depths, ``schedule`` (:class:`ScheduleSteps`
    or None: the steps the heat-input schedule adds), ``modes`` (:class:`~railtherm_fipy.modes.SectionModes`
    of the operator, which the stepper steps; ``rho_c`` [J/(m^3 K)], None: read off the first cell's
    capacity)."""

    def __init__(self, faces_x, faces_z, capacity, stiffness, depths, schedule: "ScheduleSteps | None" = None,
                 rho_c: float | None = None):
        self.schedule = schedule
        self.faces_x = faces_x
        self.x = 0.5 * (faces_x[1:] + faces_x[:-1])
        self.z = 0.5 * (faces_z[1:] + faces_z[:-1])
        self.i0 = int(np.argmin(np.abs(self.x)))
        self.capacity = capacity
        self.stiffness = stiffness
        self.dt_stab = float(np.min(capacity / stiffness.diagonal()))
        nx = self.x.size
        rows, weights = [], []
        for d in depths:
            if d <= self.z[0]:                           # above the first centre: extrapolated from the top two
                j = 0
            else:
                j = min(int(np.searchsorted(self.z, d)) - 1, self.z.size - 2)
            s = (d - self.z[j]) / (self.z[j + 1] - self.z[j])
            rows.append([self.i0 + nx * j, self.i0 + nx * (j + 1)])
            weights.append([1.0 - s, s])
        self.rows = np.array(rows)
        self.weights = np.array(weights)
        dx, dz = np.diff(faces_x), np.diff(faces_z)
        parts = separate(stiffness, dx, dz)
        if parts is None:
            raise SolverError(f"fipy section {self.node_shape}: FiPy's conductance is not the separable sum "
                              "Mz (x) Kx + Kz (x) Mx of its rectilinear cells; its modes cannot step it")
        rho_c = float(capacity[0] / (dx[0] * dz[0])) if rho_c is None else float(rho_c)
        self.modes = SectionModes(dx, dz, rho_c, *parts, self.i0, self.rows // nx, self.weights)

    @property
    def node_shape(self) -> str:
        return f"{self.x.size}x{self.z.size}"

    def stepper(self, x_edges, y_edges, flux, speed, factor, t0):
        """A :class:`_FipyStepper` under the band's ``flux`` (nx,) [W/m^2] on ``x_edges`` [m] at ``speed``
        [m/s], heat-input factor ``factor(t)``, from t0 [s]."""
        return _FipyStepper(self, x_edges, flux, speed, factor, t0)


def fipy_conductance(T, capacity: float, conductivity: float) -> csr_matrix:
    """FiPy's conductance K [W/K] of the cells of ``T``'s mesh (its constraints applied): the matrix FiPy
    assembles for rho c dT/dt = div(lambda grad T) (``capacity`` rho c [J/(m^3 K)], ``conductivity`` lambda
    [W/(m K)]) at a unit time step, less its capacity term. Only the matrix: FiPy's sweep would also solve the
    system once (a third of the cost)."""
    fp = import_fipy()
    eq = fp.TransientTerm(coeff=capacity) == fp.DiffusionTerm(coeff=conductivity)
    eq.cacheMatrix()
    eq._prepareLinearSystem(var=T, solver=None, boundaryConditions=(), dt=1.0)
    M = eq.matrix
    return csr_matrix(M.matrix if hasattr(M, "matrix") else M) - diags(capacity * np.asarray(T.mesh.cellVolumes,
                                                                                            dtype=float))


def fipy_block(a: float, speed: float, conductivity: float, capacity: float, convection: float, level: int,
               duration_total: float, depths, schedule_time=None, schedule_factor=None) -> FipyBlock:
    """The cells of the module docstring for a band of half-width ``a`` [m] at ``speed`` [m/s], lambda
    [W/(m K)], rho c [J/(m^3 K)], surface convection h [W/(m^2 K)] (on the surface cells' values), refinement
    ``level``, a history of ``duration_total`` [s], the output ``depths`` [m] and the heat-input schedule
    (``schedule_time`` [s], ``schedule_factor`` [1]; None: constant)."""
    fp = import_fipy()
    CellVariable, Grid2D = fp.CellVariable, fp.Grid2D
    kappa = conductivity / capacity
    delta = thermal_scales(a, speed, kappa).thermal_depth
    reach = math.sqrt(kappa * duration_total)
    growth = 1.3 ** (1.0 / 2 ** int(level))
    h = 2.0 * a / (32 * 2 ** int(level))
    side = _widths(h, growth, 4, 2.0 * a + 2.0 * reach - 0.5 * h)
    dx = np.concatenate([side[::-1], [h], side])
    schedule = ScheduleSteps.of(schedule_time, schedule_factor, level)
    surface = None if schedule is None else math.sqrt(kappa * schedule.shortest) / 4.0 / 2 ** int(level)
    dz = _depth_widths(delta / 4.0 / 2 ** int(level), growth, 1.5 * max(depths),
                       max(8.0 * reach, 10.0 * delta, 1.5 * max(depths)), surface)
    mesh = Grid2D(dx=dx, dy=dz)
    T = CellVariable(mesh=mesh, value=0.0)
    T.constrain(0.0, where=mesh.facesTop)               # FiPy's top (largest y) is the block's deep face
    K = fipy_conductance(T, capacity, conductivity)
    cap = capacity * np.asarray(mesh.cellVolumes, dtype=float)
    if convection:
        K = K + diags(np.concatenate([convection * dx, np.zeros(dx.size * (dz.size - 1))]))
    faces_x = np.concatenate([[0.0], np.cumsum(dx)]) - (side.sum() + 0.5 * h)
    faces_z = np.concatenate([[0.0], np.cumsum(dz)])
    return FipyBlock(faces_x, faces_z, cap, csr_matrix(K), depths, schedule, capacity)


@dataclass(frozen=True)
class ScheduleSteps:
    """Where the time steps meet a piecewise-linear heat-input schedule.

    Crank-Nicolson loads each step with the mean of its ends' heat input, second order only where the factor
    is linear over the step: the kinks ``times`` [s] are step ends. A segment over which the factor changes
    (length tau [s], a 10 us spike's 5 us ramps) drives the surface on its own time scale tau, which the
    section's steps h/V (the contact duration's scale) and its first cells (delta/4/2**level) do not resolve:
    the segment is stepped in ``per_segment`` = 4 * 2**level steps, the relaxation after it on steps of
    tau/per_segment doubled every ``per_segment`` steps (until the regular step takes over), and the depth
    cells start from sqrt(kappa shortest)/4/2**level (``shortest``: the shortest changing segment [s]) --
    tau's diffusion length resolved as delta is."""

    times: np.ndarray
    changing: np.ndarray          # (segments,) bool: the factor changes over [times[i], times[i + 1]]
    per_segment: int
    shortest: float

    @classmethod
    def of(cls, time, factor, level: int) -> "ScheduleSteps | None":
        """The steps of a schedule (``time`` [s], ``factor`` [1]), or None without one or when its factor never
        changes."""
        if time is None or len(time) < 2:
            return None
        t, f = np.asarray(time, dtype=float), np.asarray(factor, dtype=float)
        changing = np.diff(f) != 0.0
        if not np.any(changing):
            return None
        return cls(t, changing, 4 * 2 ** int(level), float(np.min(np.diff(t)[changing])))

    def largest_step(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """The largest step [s] on each interval (``starts``, ``ends``) [s] that lies between two kinks:
        tau / per_segment within a changing segment; after one (its relaxation has the same time scale) that
        step doubled every ``per_segment`` steps; inf elsewhere."""
        seg_t0, seg_t1 = self.times[:-1][self.changing], self.times[1:][self.changing]
        fine = (seg_t1 - seg_t0) / self.per_segment
        mid = 0.5 * (starts + ends)[:, None]
        within = (mid > seg_t0) & (mid < seg_t1)
        after = np.clip((starts[:, None] - seg_t1) / (self.per_segment * fine), 0.0, None)
        ladder = fine * 2.0 ** np.floor(np.log2(1.0 + after))
        step = np.where(within, fine, np.where(mid > seg_t1, ladder, np.inf))
        return np.min(step, axis=1)

    def ends(self, t0: float, dt: float, m: int) -> np.ndarray | None:
        """The step ends [s] of m steps of dt from t0 with the schedule's kinks added and its changing segments
        subdivided (see the class); None where the schedule adds none."""
        regular = t0 + dt * np.arange(1, m + 1)
        tol = 1e-9 * dt
        kinks = self.times[(self.times > t0 + tol) & (self.times < regular[-1] - tol)]
        kinks = kinks[np.min(np.abs(kinks[:, None] - regular[None, :]), axis=1) > tol] if kinks.size else kinks
        ends = np.union1d(regular, kinks)
        starts = np.concatenate([[t0], ends[:-1]])
        parts = np.maximum(1, np.ceil((ends - starts) / self.largest_step(starts, ends) - 1e-9)).astype(int)
        if kinks.size == 0 and np.all(parts == 1):
            return None
        return np.concatenate([s + (e - s) * np.arange(1, n + 1) / n for s, e, n in zip(starts, ends, parts)])


class _FipyStepper(ImplicitSectionStepper):
    """Crank-Nicolson (and backward-Euler start) steps of the FiPy operator (core's
    :class:`~railtherm.solving.section_stepping.ImplicitSectionStepper`): lumped cell capacities, each step
    loaded with the theta-weighted heat input of its ends, taken in the operator's eigenmodes
    (:class:`railtherm_fipy.modes.SectionModes`: the state is the modes ``Y``, ``T`` the cell values on demand;
    ``cache`` holds one set of mode multipliers per (step size, theta) where a sparse LU would hold a factorisation)."""

    heating_cost = IMPLICIT_COST
    cooling_implicit = ("Crank-Nicolson steps of FiPy's operator (one multiplication per eigenmode of the separable "
                        "operator per step; two backward-Euler start steps)")

    def __init__(self, block: FipyBlock, x_edges, flux, speed, factor, t0):
        super().__init__(block, x_edges, flux, speed, factor, t0)
        self.cum = np.concatenate([[0.0], np.cumsum(np.asarray(flux, dtype=float).reshape(-1) * np.diff(self.xe))])

    @property
    def T(self) -> np.ndarray:
        """The cell values [K] (index i + nx j)."""
        return self.b.modes.to_cells(self.Y)

    @T.setter
    def T(self, value) -> None:
        modes = self.b.modes
        self.Y = np.zeros(modes.rate.shape) if not np.any(value) else modes.of_cells(value)

    def implicit_steps(self, dt: float, m: int, arrivals=(), theta: float = 0.5, start: int = 0):
        """m theta-scheme steps of dt [s] (the first ``start`` backward Euler) under the passes arriving at
        ``arrivals`` [s], on the schedule's own steps where it has any in them (:meth:`ScheduleSteps.ends`); every
        end is sampled."""
        sched = self.b.schedule
        ends = None if sched is None or not len(arrivals) else sched.ends(self.t, dt, m)
        if ends is None:
            ends = self.t + dt * np.arange(1, m + 1)
            steps = np.full(m, float(dt))
        else:
            # equal steps share one key despite rounding (1e-12 relative); a whole step is the driver's own dt
            raw = np.diff(np.concatenate([[self.t], ends]))
            steps = np.array([dt if abs(h - dt) <= 1e-9 * dt else float(f"{h:.12g}") for h in raw])
        modes = self.b.modes
        Y, t, q_old = self.Y, self.t, self._step_power(self.t, arrivals)
        out = np.empty((ends.size, self.b.rows.shape[0]))
        for i, (t1, h) in enumerate(zip(ends, steps)):
            th = 1.0 if i < start else theta
            if (h, th) not in self.cache:
                self.cache[(h, th)] = modes.step_coefficients(h, th)
            q_new = self._step_power(t1, arrivals)
            q = None
            if q_new is not None or q_old is not None:
                q = (th * (0.0 if q_new is None else q_new) + (1.0 - th) * (0.0 if q_old is None else q_old))
            Y, out[i] = modes.step(Y, self.cache[(h, th)], q)
            self.solves += 1
            t, q_old = t1, q_new
        self.Y, self.t = Y, float(ends[-1])
        self.times.append(ends)
        self.rows.append(out)

    def _step_power(self, t: float, arrivals):
        """The heat at time t [s] as the modes' step takes it: the surface cells' (:meth:`_surface_power`)."""
        return self._surface_power(t, arrivals)

    def _surface_power(self, t: float, arrivals):
        """The heat [W/m] entering each surface cell at time t [s] from the passes arriving at ``arrivals`` [s];
        None where there is none."""
        f = float(self.factor(t))
        if f == 0.0 or not len(arrivals):
            return None
        fx = self.b.faces_x
        p = np.zeros(fx.size - 1)
        for arr in arrivals:
            shift = self.xe[-1] - self.speed * (t - arr)
            p += np.diff(np.interp(fx + shift, self.xe, self.cum))
        return f * p
