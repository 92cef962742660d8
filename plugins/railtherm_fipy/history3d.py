"""fipy's pass histories of an elliptical patch: the rail section as a 3-D block of FiPy cells (x, y, z).

The 2-D section of :mod:`.history` with the lateral direction added: FiPy's cell-centred finite volumes
(``TransientTerm(rho c) == DiffusionTerm(lambda)``, theta = 0 on the deep face, the block's ends, sides and
surface insulated, the flux entering the surface cells) on rectilinear cells: the conductance is the separable
sum ``K = Mz (x) My (x) Kx + Mz (x) Ky (x) Mx + Kz (x) My (x) Mx`` (M: cell widths), its 1-D parts assembled by
FiPy on ``Grid1D`` meshes (:func:`fipy_line_conductance`; the tests check their sum against FiPy's ``Grid3D``
matrix, :func:`fipy_3d_stiffness`, which would take ~20 s and ~3 GB at level 2's 1e6 cells). :class:`BlockModes`
steps ``C dT/dt = -K T + P(t)`` by Crank-Nicolson, one multiplication per eigenmode (no factorisation), only the
modes the outputs read (:meth:`BlockModes.read`: on the symmetric widths the odd ones vanish on the centre column,
a quarter of the cells stays). Core's driver (:mod:`railtherm.solving.section_stepping`) runs the passes, cooling
ladder and superposition. Cells: :func:`ellipse_cells`. Outputs: the centre line's column (x = 0, y = 0) at the
history depths, linear between cell centres. Neglected: conduction beyond the block's ends and sides (insulated).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.linalg import eigh
from scipy.sparse import csr_matrix, diags, kron

from railtherm import Refused
from railtherm.physics import thermal_scales

from .history import IMPLICIT_COST, ScheduleSteps, _depth_widths, _FipyStepper, _widths, fipy_conductance
from .modes import theta_coefficients
from .solvers import import_fipy

__all__ = ["EllipseBlock", "BlockModes", "fipy_ellipse_block", "fipy_line_conductance", "fipy_3d_stiffness",
           "ellipse_cells", "separate3", "MAX_HISTORY_CELLS"]

#: default largest 3-D history block [cells]: every step touches each mode the outputs read (a quarter of the
#: cells) and the stepper keeps two multipliers per mode and step size (~20 sizes); 8x a level. Measured: the
#: Hertz ellipse a = 6, b = 4 mm at 30 m/s over 1,000 passes 83 ms apart at level 2, 133 x 175 x 155 = 3.6e6
#: cells: 7 s, 0.85 GB peak (benchmarks/test_fipy_transient_benchmark.py); level 3 of a 4-pass train, ~8e6, is refused
MAX_HISTORY_CELLS = 4_000_000

#: a mode whose value on the centre line's column is below this fraction of the largest is not stepped (the
#: odd modes of the symmetric widths: 1e-16 of it, rounding)
READ_RTOL = 1e-12


def separate3(K, dx: np.ndarray, dy: np.ndarray, dz: np.ndarray, rtol: float = 1e-12):
    """``(Kx, Ky, Kz)`` dense [W/(K m^3)] with ``K = Mz (x) My (x) Kx + Mz (x) Ky (x) Mx + Kz (x) My (x) Mx``
    (``K`` [W/K] on the cells ``dx``, ``dy``, ``dz`` [m], FiPy's index i + nx j + nx ny k), or None where ``K`` is
    not that sum to ``rtol`` of its largest entry."""
    K = csr_matrix(K)
    nx, ny, nz = dx.size, dy.size, dz.size
    Kx, Ky, Kz = np.zeros((nx, nx)), np.zeros((ny, ny)), np.zeros((nz, nz))
    i, j, k = np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1)
    Kx[i, i + 1] = Kx[i + 1, i] = np.asarray(K[i, i + 1]).ravel() / (dy[0] * dz[0])
    Ky[j, j + 1] = Ky[j + 1, j] = np.asarray(K[nx * j, nx * (j + 1)]).ravel() / (dx[0] * dz[0])
    Kx[np.arange(nx), np.arange(nx)] = -Kx.sum(axis=1)           # insulated ends: rows sum to zero
    Ky[np.arange(ny), np.arange(ny)] = -Ky.sum(axis=1)           # insulated sides
    step = nx * ny
    Kz[k, k + 1] = Kz[k + 1, k] = np.asarray(K[step * k, step * (k + 1)]).ravel() / (dx[0] * dy[0])
    col = np.asarray(K[step * np.arange(nz), step * np.arange(nz)]).ravel()
    Kz[np.arange(nz), np.arange(nz)] = (col - (Kx[0, 0] * dy[0] + Ky[0, 0] * dx[0]) * dz) / (dx[0] * dy[0])
    Mx, My, Mz = diags(dx), diags(dy), diags(dz)
    rebuilt = (kron(Mz, kron(My, csr_matrix(Kx))) + kron(Mz, kron(csr_matrix(Ky), Mx))
               + kron(csr_matrix(Kz), kron(My, Mx)))
    if abs(K - rebuilt).max() > rtol * abs(K).max():
        return None
    return Kx, Ky, Kz


class BlockModes:
    """The eigenmodes of the separable 3-D operator (the cells ``dx``, ``dy``, ``dz`` [m], ``rho_c``
    [J/(m^3 K)], the parts of :func:`separate3`), the output column ``(i0, j0)`` and the sampled depth rows
    ``rows_z`` (n, 2) with ``weights`` (n, 2).

    A state is ``Y`` (nz, my, mx) with ``T = (Vz (x) Vy (x) Vx) Y`` (each V orthonormal in its widths:
    ``V^T M V = 1``, ``V^T K V = diag(w)``), so ``rho_c dY/dt = -(wz + wy + wx) Y + V^T p``: each mode is one
    scalar equation, one theta step one multiplication. The heat enters the surface cells only:
    ``V^T p = Vz[0] (x) (Vy^T P Vx)`` with P (ny, nx) [W] the surface cells' power; the output at depth row r
    reads ``Vz[r] . (Y Vx[i0]) Vy[j0]``. All modes (my = ny, mx = nx), or those the outputs read (:meth:`read`)."""

    def __init__(self, dx, dy, dz, rho_c: float, Kx, Ky, Kz, i0: int, j0: int, rows_z, weights):
        self.shape = (dz.size, dy.size, dx.size)
        self.dx, self.dy, self.dz = np.asarray(dx, float), np.asarray(dy, float), np.asarray(dz, float)
        self.rho_c = float(rho_c)
        self.wx, self.vx = eigh(Kx, np.diag(self.dx))
        self.wy, self.vy = eigh(Ky, np.diag(self.dy))
        self.wz, self.vz = eigh(Kz, np.diag(self.dz))
        self.i0, self.j0 = int(i0), int(j0)
        self.read_rows = np.asarray(rows_z)
        self.weights = np.asarray(weights, float)
        self._derive()

    def _derive(self) -> None:
        """The decay rates, the surface's, column's and line's shares of the modes."""
        self.rate = self.wz[:, None, None] + self.wy[None, :, None] + self.wx[None, None, :]
        self.surface = self.vz[0]
        self.column = self.vx[self.i0]
        self.line = self.vy[self.j0]
        self.read_z = self.vz[self.read_rows]                    # (n, 2, nz)

    def read(self, rtol: float = READ_RTOL) -> "BlockModes":
        """The modes the outputs read: those whose value on the column ``i0`` (along x) and on the line ``j0``
        (across) exceeds ``rtol`` of the largest. The modes are independent, so the outputs of the states
        stepped in these alone are those of all modes; on symmetric widths with the column at the centre the
        odd modes drop (their value there is rounding)."""
        keep_x = np.abs(self.vx[self.i0]) > rtol * np.max(np.abs(self.vx[self.i0]))
        keep_y = np.abs(self.vy[self.j0]) > rtol * np.max(np.abs(self.vy[self.j0]))
        out = object.__new__(BlockModes)
        out.__dict__.update(self.__dict__)
        out.wx, out.vx = self.wx[keep_x], self.vx[:, keep_x]
        out.wy, out.vy = self.wy[keep_y], self.vy[:, keep_y]
        out._derive()
        return out

    def coefficients(self, dt: float, theta: float):
        """``(a, b)`` (nz, my, mx): one theta step is ``Y1 = a Y0 + b V^T (theta p1 + (1 - theta) p0)``."""
        return theta_coefficients(self.rho_c, self.rate, dt, theta)

    def step_coefficients(self, dt: float, theta: float):
        """``(a, b Vz[0])`` of :meth:`coefficients`, the surface's share folded in (what :meth:`step` takes),
        in one pass over the modes (:func:`_theta_multipliers`)."""
        a, bs = np.empty(self.rate.shape), np.empty(self.rate.shape)
        _theta_multipliers(self.rho_c / float(dt), float(theta), self.wz, self.wy, self.wx, self.surface, a, bs)
        return a, bs

    def project(self, p_surface: np.ndarray) -> np.ndarray:
        """The x-y modes' share ``Vy^T P Vx`` (my, mx) [W] of the heat ``p_surface`` (ny, nx) [W] entering the
        surface cells (what :meth:`step` takes)."""
        return self.vy.T @ p_surface @ self.vx

    def step(self, Y: np.ndarray, coefficients, load):
        """``Y = a Y + b Vz[0] (x) load`` in place and :meth:`sample` of it, in one pass over the modes
        (:func:`_step_and_read`): ``(Y, outputs)``;
        ``load`` (my, mx) [W]: the theta-weighted surface heat projected (:meth:`project`), None: none."""
        a, bs = coefficients
        acc = np.empty(Y.shape[0])
        heated = load is not None
        _step_and_read(Y, a, bs, load if heated else bs[0], heated, self.column, self.line, acc)
        return Y, np.sum((self.read_z @ acc) * self.weights, axis=1)

    def load(self, p_surface: np.ndarray) -> np.ndarray:
        """The modes' share (nz, my, mx) [W] of the heat ``p_surface`` (ny, nx) [W] entering the surface cells."""
        return self.surface[:, None, None] * (self.vy.T @ p_surface @ self.vx)[None]

    def sample(self, Y: np.ndarray) -> np.ndarray:
        """The outputs (n,) [K]: the column (i0, j0) at the sampled rows, weighted."""
        return np.sum((self.read_z @ ((Y @ self.column) @ self.line)) * self.weights, axis=1)

    def to_cells(self, Y: np.ndarray) -> np.ndarray:
        """The cell values (nz ny nx,) [K] of the modes ``Y``."""
        T = np.einsum("kc,cba->kba", self.vz, Y)
        T = np.einsum("jb,kba->kja", self.vy, T)
        return (T @ self.vx.T).reshape(-1)

    def of_cells(self, T: np.ndarray) -> np.ndarray:
        """The modes (nz, my, mx) of the cell values ``T`` (nz ny nx,) [K] (``V^-1 = V^T M``; with the modes
        of :meth:`read`, the projection on them)."""
        T3 = np.asarray(T, float).reshape(self.shape)
        W = self.dz[:, None, None] * T3 * self.dy[None, :, None] * self.dx[None, None, :]
        W = np.einsum("kc,kba->cba", self.vz, W)
        W = np.einsum("jb,kja->kba", self.vy, W)
        return W @ self.vx


@njit(cache=True)
def _theta_multipliers(c_dt, theta, wz, wy, wx, surface, a, bs):
    """:func:`railtherm_fipy.modes.theta_coefficients` of the rates ``wz[k] + wy[j] + wx[i]`` (``c_dt`` = rho c /
    dt [W/(K m^3)]) into ``a`` and ``bs`` = b surface[k] (nz, my, mx)."""
    for k in range(wz.size):
        for j in range(wy.size):
            for i in range(wx.size):
                rate = wz[k] + wy[j] + wx[i]
                b = 1.0 / (c_dt + theta * rate)
                a[k, j, i] = b * (c_dt - (1.0 - theta) * rate)
                bs[k, j, i] = b * surface[k]


@njit(cache=True)
def _step_and_read(Y, a, bs, load, heated, column, line, acc):
    """``Y = a Y + bs load`` in place (Y, a, bs (nz, my, mx), load (my, mx); without the heat term where not
    ``heated``) and ``acc[k] = line . (Y[k] column)`` (the centre column's value of each depth mode) in the
    same pass."""
    nz, my, mx = Y.shape
    for k in range(nz):
        total = 0.0
        for j in range(my):
            row = 0.0
            for i in range(mx):
                y = a[k, j, i] * Y[k, j, i]
                if heated:
                    y += bs[k, j, i] * load[j, i]
                Y[k, j, i] = y
                row += column[i] * y
            total += line[j] * row
        acc[k] = total


def ellipse_cells(a: float, b: float, speed: float, kappa: float, level: int, duration_total: float, depths,
                  schedule: ScheduleSteps | None = None):
    """The cell widths ``(dx, dy, dz)`` [m] of the block for an ellipse of semi-axes ``a``, ``b`` [m] at ``speed``
    [m/s], diffusivity ``kappa`` [m^2/s], refinement ``level``, a history of ``duration_total`` [s], the output
    ``depths`` [m] and the schedule's steps (its shortest changing segment thins the top cells).

    Along x those of the 2-D section (width h = 2a/32/2**level at the section, four cells either side, growing by
    ``1.3 ** (1 / 2**level)`` to 2a + 2 sqrt(kappa t_end)); across, the full width, a cell of b/8/2**level
    centred on the centre line y = 0, uniform over the patch and growing like x beyond it to b + 2 sqrt(kappa
    t_end); in depth those of the 2-D section (:func:`railtherm_fipy.history._depth_widths`)."""
    delta = thermal_scales(a, speed, kappa).thermal_depth
    reach = math.sqrt(kappa * duration_total)
    k = 2 ** int(level)
    growth = 1.3 ** (1.0 / k)
    h = 2.0 * a / (32 * k)
    side = _widths(h, growth, 4, 2.0 * a + 2.0 * reach - 0.5 * h)
    dx = np.concatenate([side[::-1], [h], side])
    hy = b / (8 * k)
    lateral = _widths(hy, growth, int(math.ceil((b - 0.5 * hy) / hy)), b + 2.0 * reach - 0.5 * hy)
    dy = np.concatenate([lateral[::-1], [hy], lateral])
    surface = None if schedule is None else math.sqrt(kappa * schedule.shortest) / 4.0 / k
    dz = _depth_widths(delta / 4.0 / k, growth, 1.5 * max(depths),
                       max(8.0 * reach, 10.0 * delta, 1.5 * max(depths)), surface)
    return dx, dy, dz


class EllipseBlock:
    """The 3-D block's FiPy cells and the modes of its operator (cell index i + nx j + nx ny k, k = 0 at the
    surface), with the attributes core's driver reads: ``x``, ``y``, ``z`` cell centres [m] (section at
    ``x[i0]`` = 0, centre line at ``y[j0]`` = 0), ``capacity`` [J/K], ``dt_stab`` (min C/K_ii [s], for the
    cost record), ``rows`` (depths, 2) depth rows and ``weights`` of the outputs, ``schedule``
    (:class:`~railtherm_fipy.history.ScheduleSteps` or None), ``parts`` (the 1-D conductances ``Kx``, ``Ky``,
    ``Kz`` of :func:`separate3`), ``stiffness`` (their sum K [W/K], sparse, built on demand) and ``modes`` (the
    :class:`BlockModes` the outputs read, which the stepper steps; :meth:`all_modes`: every mode)."""

    def __init__(self, faces_x, faces_y, faces_z, parts, depths, rho_c: float,
                 schedule: ScheduleSteps | None = None):
        self.schedule = schedule
        self.faces_x, self.faces_y = faces_x, faces_y
        self.x = 0.5 * (faces_x[1:] + faces_x[:-1])
        self.y = 0.5 * (faces_y[1:] + faces_y[:-1])
        self.z = 0.5 * (faces_z[1:] + faces_z[:-1])
        self.i0 = int(np.argmin(np.abs(self.x)))
        self.j0 = int(np.argmin(np.abs(self.y)))
        self.rho_c = float(rho_c)
        self.widths = tuple(np.diff(f) for f in (faces_x, faces_y, faces_z))
        self.parts = tuple(np.asarray(k, dtype=float) for k in parts)
        # C_ii / K_ii = rho_c / (Kx_ii/dx_i + Ky_jj/dy_j + Kz_kk/dz_k): its minimum takes each direction's largest
        self.dt_stab = self.rho_c / sum(float(np.max(np.diag(k) / d)) for k, d in zip(self.parts, self.widths))
        rows, weights = [], []
        for d in depths:
            j = 0 if d <= self.z[0] else min(int(np.searchsorted(self.z, d)) - 1, self.z.size - 2)
            s = (d - self.z[j]) / (self.z[j + 1] - self.z[j])
            rows.append([j, j + 1])
            weights.append([1.0 - s, s])
        self.rows = np.array(rows)
        self.weights = np.array(weights)
        self.modes = self.all_modes().read()

    def all_modes(self) -> BlockModes:
        """Every mode of the block's operator."""
        return BlockModes(*self.widths, self.rho_c, *self.parts, self.i0, self.j0, self.rows, self.weights)

    @property
    def capacity(self) -> np.ndarray:
        """The cells' capacities rho c dx dy dz (nz ny nx,) [J/K]."""
        dx, dy, dz = self.widths
        return self.rho_c * (dz[:, None, None] * dy[None, :, None] * dx[None, None, :]).reshape(-1)

    @property
    def stiffness(self) -> csr_matrix:
        """The conductance ``Mz (x) My (x) Kx + Mz (x) Ky (x) Mx + Kz (x) My (x) Mx`` [W/K] (sparse)."""
        (dx, dy, dz), (Kx, Ky, Kz) = self.widths, self.parts
        Mx, My, Mz = diags(dx), diags(dy), diags(dz)
        return csr_matrix(kron(Mz, kron(My, csr_matrix(Kx))) + kron(Mz, kron(csr_matrix(Ky), Mx))
                          + kron(csr_matrix(Kz), kron(My, Mx)))

    @property
    def node_shape(self) -> str:
        return f"{self.x.size}x{self.y.size}x{self.z.size}"

    def stepper(self, x_edges, y_edges, flux, speed, factor, t0):
        """A :class:`_EllipseStepper` under the patch's ``flux`` (nx, ny) [W/m^2] on the source grid's
        ``x_edges``, ``y_edges`` [m] at ``speed`` [m/s], heat-input factor ``factor(t)``, from t0 [s]."""
        return _EllipseStepper(self, (x_edges, y_edges), flux, speed, factor, t0)


def check_cell_budget(shape, level: int, max_cells: float, body: str) -> None:
    """Refuse a 3-D history block of more than ``max_cells`` cells, naming its shape, the level and the option.

    Raises
    ------
    railtherm.Refused
        kind "budget": each step's work and the stepper's memory (two multipliers per mode and step size) grow
        with the cell count, 8x a level.
    """
    total = int(np.prod(shape))
    if total > max_cells:
        raise Refused(f"model 'fipy' ({body}): the 3-D section block of this history needs {'x'.join(map(str, shape))} "
                      f"= {total:.3g} cells at level {int(level)}, above the budget max_history_cells = {max_cells:.3g} "
                      "(every step and the stepper's memory grow with the cells, 8x a level and with the "
                      "history's length): use a lower level, a shorter history or raise the option max_history_cells",
                      kind="budget")


def fipy_line_conductance(widths, conductivity: float, capacity: float, deep: bool = False,
                          convection: float = 0.0) -> np.ndarray:
    """FiPy's 1-D conductance (n, n) dense [W/(K m^2)] (per unit cross-section) of the cells ``widths`` [m]:
    ``TransientTerm(rho c) == DiffusionTerm(lambda)`` on a ``Grid1D`` (``conductivity`` lambda [W/(m K)],
    ``capacity`` rho c [J/(m^3 K)]), its matrix at dt = 1 s less the cells' capacities; ends insulated, the last
    face at theta = 0 where ``deep``; ``convection`` h [W/(m^2 K)] on the first cell."""
    fp = import_fipy()
    widths = np.asarray(widths, dtype=float)
    mesh = fp.Grid1D(dx=widths)
    T = fp.CellVariable(mesh=mesh, value=0.0)
    if deep:
        T.constrain(0.0, where=mesh.facesRight)
    K = fipy_conductance(T, capacity, conductivity).toarray()
    K[0, 0] += convection
    return K


def fipy_3d_stiffness(dx, dy, dz, conductivity: float, capacity: float, convection: float = 0.0) -> csr_matrix:
    """FiPy's 3-D conductance K [W/K] (sparse, FiPy's index i + nx j + nx ny k) of the cells ``dx``, ``dy``,
    ``dz`` [m] assembled on a ``Grid3D`` (the deep face, FiPy's largest z, at theta = 0; lambda, rho c and h as
    in :func:`fipy_line_conductance`): what the block's separable sum of 1-D parts stands for (checked by the
    tests; slow beyond ~1e5 cells)."""
    fp = import_fipy()
    dx, dy, dz = (np.asarray(d, dtype=float) for d in (dx, dy, dz))
    mesh = fp.Grid3D(dx=dx, dy=dy, dz=dz)
    T = fp.CellVariable(mesh=mesh, value=0.0)
    # the deep face: FiPy's largest z (the bottom layer's side faces have their centres half a cell above it)
    deep = np.abs(np.asarray(mesh.faceCenters[2]) - float(np.sum(dz))) < 0.25 * dz[-1]
    T.constrain(0.0, where=mesh.exteriorFaces & deep)
    K = fipy_conductance(T, capacity, conductivity)
    if convection:
        K = K + diags(np.concatenate([convection * np.outer(dy, dx).ravel(), np.zeros(dx.size * dy.size * (dz.size - 1))]))
    return csr_matrix(K)


def fipy_ellipse_block(a: float, b: float, speed: float, conductivity: float, capacity: float, convection: float,
                       level: int, duration_total: float, depths, schedule_time=None, schedule_factor=None,
                       max_cells: float = MAX_HISTORY_CELLS, body: str = "rail") -> EllipseBlock:
    """The block of the module docstring for an ellipse of semi-axes ``a``, ``b`` [m] at ``speed`` [m/s],
    lambda [W/(m K)], rho c [J/(m^3 K)], surface convection h [W/(m^2 K)], refinement ``level``, a history of
    ``duration_total`` [s], the output ``depths`` [m] and the heat-input schedule (``schedule_time`` [s],
    ``schedule_factor`` [1]; None: constant); refused above ``max_cells`` cells (:func:`check_cell_budget`)."""
    schedule = ScheduleSteps.of(schedule_time, schedule_factor, level)
    dx, dy, dz = ellipse_cells(a, b, speed, conductivity / capacity, level, duration_total, depths, schedule)
    check_cell_budget((dx.size, dy.size, dz.size), level, max_cells, body)
    parts = (fipy_line_conductance(dx, conductivity, capacity), fipy_line_conductance(dy, conductivity, capacity),
             fipy_line_conductance(dz, conductivity, capacity, deep=True, convection=convection))
    faces = [np.concatenate([[0.0], np.cumsum(d)]) for d in (dx, dy, dz)]
    faces[0] = faces[0] - faces[0][-1] / 2.0
    faces[1] = faces[1] - faces[1][-1] / 2.0
    return EllipseBlock(faces[0], faces[1], faces[2], parts, depths, capacity, schedule)


class _EllipseStepper(_FipyStepper):
    """The 2-D section's Crank-Nicolson stepping in modes (:class:`railtherm_fipy.history._FipyStepper`) on
    the 3-D block: the heat of a pass enters the surface cells as the source grid's flux (piecewise constant)
    integrated exactly over each cell's x-y face, shifted by the pass's travel."""

    heating_cost = IMPLICIT_COST

    def __init__(self, block: EllipseBlock, edges, flux, speed, factor, t0):
        x_edges, y_edges = edges
        super(_FipyStepper, self).__init__(block, x_edges, flux, speed, factor, t0)
        self.args = (edges, flux, speed)                 # what fresh() hands a new stepper
        self.xe = np.asarray(x_edges, dtype=float)
        ye = np.asarray(y_edges, dtype=float)
        q = np.asarray(flux, dtype=float).reshape(self.xe.size - 1, ye.size - 1)
        self.cum = np.concatenate([np.zeros((1, q.shape[1])), np.cumsum(q * np.diff(self.xe)[:, None], axis=0)])
        fy = block.faces_y
        # overlap [m] (ny cells, strips) of each cell's y face with each strip of the source grid
        self.over = np.clip(np.minimum(fy[1:, None], ye[None, 1:]) - np.maximum(fy[:-1, None], ye[None, :-1]),
                            0.0, None)
        self.over_modes = block.modes.vy.T @ self.over       # (my, strips): the strips' share of the y modes

    def _surface_power(self, t: float, arrivals):
        """The heat [W] entering each surface cell (ny, nx) at time t [s] from the passes arriving at
        ``arrivals`` [s]; None where there is none."""
        strips = self._strips(t, arrivals)
        return None if strips is None else self.over @ strips.T

    def _step_power(self, t: float, arrivals):
        """:meth:`_surface_power` projected on the x-y modes (``BlockModes.project``), the strips first."""
        strips = self._strips(t, arrivals)
        return None if strips is None else (self.over_modes @ strips.T) @ self.b.modes.vx

    def _strips(self, t: float, arrivals):
        """The heat per unit width [W/m] of each source strip over each cell's x face (nx, strips) at time t [s]
        from the passes arriving at ``arrivals`` [s], the factor applied; None where there is none."""
        f = float(self.factor(t))
        if f == 0.0 or not len(arrivals):
            return None
        fx = self.b.faces_x
        strips = np.zeros((fx.size - 1, self.cum.shape[1]))
        for arr in arrivals:
            shift = self.xe[-1] - self.speed * (t - arr)
            if fx[-1] + shift <= self.xe[0] or fx[0] + shift >= self.xe[-1]:
                continue
            # np.interp of every strip's cumulative heat at the shifted faces, the weights shared by the strips
            xq = np.clip(fx + shift, self.xe[0], self.xe[-1])
            i = np.clip(np.searchsorted(self.xe, xq, side="right"), 1, self.xe.size - 1)
            w = ((xq - self.xe[i - 1]) / (self.xe[i] - self.xe[i - 1]))[:, None]
            strips += np.diff(self.cum[i - 1] * (1.0 - w) + self.cum[i] * w, axis=0)
        return f * strips
