"""fem's pass histories of a line contact: the rail (or wheel) section in the fixed frame (x-z, per unit width).

The heat equation ``rho c dT/dt = lambda laplace T`` on a block around the fixed section, bilinear (Q1)
finite elements on a tensor mesh assembled by scikit-fem (consistent mass M, stiffness K, convection on the
surface), T = 0 on the deep face, the block's ends insulated; the band's piecewise-constant flux enters the
surface nodes as its exact integrals against the hat functions. Core's driver
(:mod:`railtherm.solving.section_stepping`) steps the passes: Crank-Nicolson steps of
``M dT/dt = -K T + P(t)`` at the section's step h/V while the source is over the block, a ladder of growing
steps between the passes; the steps are solved in the depth modes of the tensor-product operators
(:class:`TensorSection`: one tridiagonal LU per step size, reused by every step of that size). Nodes: spacing
h = 2a/32/2**level along x over the section and four cells either side, growing by ``1.3 ** (1 / 2**level)``
to 2a + 2 sqrt(kappa t_end); in depth from delta/4/2**level at the surface (delta = sqrt(2 a kappa / V)),
growing by ``1.2 ** (1 / 2**level)`` to max(8 sqrt(kappa t_end), 10 delta, 1.5 x the deepest output). The
history at a depth: the section's node column, linear in z between nodes (the elements' own interpolant).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg import eigh
from scipy.linalg.lapack import dgttrf, dgttrs
from scipy.sparse import csr_matrix
from skfem import Basis, BilinearForm, ElementQuad1, FacetBasis, MeshQuad, asm

from railtherm import ImplicitSectionStepper, Refused, SceneError, histories_at_section
from railtherm.physics import thermal_scales

from .thermal import _fe_1d

__all__ = ["FemBlock", "fem_block", "hat_integrals", "section_histories", "IMPLICIT_COST", "TensorSection"]

#: one Crank-Nicolson LU solve counted as this many explicit node updates (the FE section has no explicit
#: stepping: the model always asks the implicit scheme; the cost is recorded with the reason)
IMPLICIT_COST = 50.0

#: growth ratio of the element lengths away from the section along x at level 0 (the k-th root at level k) [1]
X_GROWTH = 1.3
#: growth ratio of the element depths away from the surface at level 0 (the k-th root at level k) [1]: finer
#: than along x, the depth's diffusion front of passes a few contact durations apart (passes 1 ms apart: the
#: second pass's peak at 0.5 mm, 0.3 % of the surface's, within 1.6 % of the exact band at level 2, 2.1 % with 1.3)
Z_GROWTH = 1.2

#: two-point Gauss-Legendre abscissae on [-1, 1] (weights 1)
_GAUSS = (-1.0 / math.sqrt(3.0), 1.0 / math.sqrt(3.0))


def _spacings(first: float, growth: float, uniform: int, end: float) -> np.ndarray:
    """Element lengths [m] from 0: ``uniform`` of ``first``, then growing by ``growth`` until they reach ``end``."""
    w = [first] * uniform
    while sum(w) < end:
        w.append(w[-1] * growth)
    return np.array(w)


def hat_integrals(x: np.ndarray, edges: np.ndarray, flux: np.ndarray) -> np.ndarray:
    """Exact integrals int q(s) phi_i(s) ds [W/m] of a piecewise-constant flux against the P1 hats of ``x``.

    Parameters
    ----------
    x : ndarray
        Increasing nodes [m].
    edges : ndarray
        Increasing edges of the flux's cells [m], shape (n + 1,).
    flux : ndarray
        Flux in each cell [W/m^2], shape (n,); zero outside the cells.

    Returns
    -------
    ndarray
        Nodal loads [W/m], shape (x.size,).

    Notes
    -----
    With Q(s) = int_{-inf}^s q and R(s) = int_{-inf}^s Q (piecewise quadratic, exact at any s), integration by
    parts gives the interior load ``(R(x_{i+1}) - R(x_i)) / h_i - (R(x_i) - R(x_{i-1})) / h_{i-1}`` and at the
    ends ``(R(x_1) - R(x_0)) / h_0 - Q(x_0)`` and ``Q(x_n) - (R(x_n) - R(x_{n-1})) / h_{n-1}``.
    """
    e = np.asarray(edges, dtype=float)
    q = np.asarray(flux, dtype=float).reshape(-1)
    w = np.diff(e)
    Q = np.concatenate([[0.0], np.cumsum(q * w)])
    R = np.concatenate([[0.0], np.cumsum(Q[:-1] * w + 0.5 * q * w * w)])
    s = np.asarray(x, dtype=float)
    k = np.clip(np.searchsorted(e, s, side="right") - 1, 0, q.size - 1)
    d = np.clip(s - e[k], 0.0, w[k])                  # within cell k (clipped: before e[0] / after e[-1])
    Rs = R[k] + Q[k] * d + 0.5 * q[k] * d * d + Q[-1] * np.clip(s - e[-1], 0.0, None)
    Qs = np.interp(s, e, Q)
    h = np.diff(s)
    slope = np.diff(Rs) / h                           # mean of Q over each element
    load = np.empty(s.size)
    load[1:-1] = slope[1:] - slope[:-1]
    load[0] = slope[0] - Qs[0]
    load[-1] = Qs[-1] - slope[-1]
    return load


class TensorSection:
    """The section's operators as tensor products of 1-D P1 matrices, stepped in depth modes.

    On the tensor mesh the Q1 mass and stiffness of the free nodes (x outer, z inner; the deep face fixed) are
    ``M = rho c Mx (x) Mz`` and ``K = lambda Kx (x) Mz + Mx (x) Kz'`` with ``Kz' = lambda Kz + h e0 e0^T``
    (conduction in depth and the surface convection), exactly (tests/test_fem_transient.py). With the
    generalised eigenvectors of (Kz', Mz) (``Phi^T Kz' Phi = diag(mu)``, ``Phi^T Mz Phi = I``) the nodal
    temperatures are ``T[i, j] = sum_k Phi[j, k] eta[k, i]`` and the theta-scheme step
    ``(M / dt + theta K) T' = (M / dt - (1 - theta) K) T + p`` splits into one tridiagonal x-system per depth
    mode k, ``((rho c / dt + theta mu_k) Mx + theta lambda Kx) eta'_k = ((rho c / dt - (1 - theta) mu_k) Mx -
    (1 - theta) lambda Kx) eta_k + Phi[0, k] p`` (p the surface nodes' load): all modes in one band factorised by
    LAPACK ``dgttrf``, a step O(nx nz) against the sparse LU's fill (a level-3 section: 161 x 223 nodes, 4.4e6
    LU entries, 25-50 ms a solve). The same discrete solution as the assembled system, to round-off
    (tests/test_fem_wheel_spin.py). The state is ``eta`` (modes outer, x inner); :meth:`nodal` gives T.

    Parameters
    ----------
    x, z : ndarray
        Nodes along the rail and in depth [m] (z[0] = 0 the surface, the last the fixed deep face).
    conductivity : float
        lambda [W/(m K)].
    capacity : float
        rho c [J/(m^3 K)].
    convection : float
        Surface heat transfer coefficient h [W/(m^2 K)].
    """

    def __init__(self, x, z, conductivity: float, capacity: float, convection: float):
        Kx, Mx = _fe_1d(np.asarray(x, float))
        Kz, Mz = _fe_1d(np.asarray(z, float))
        m = z.size - 1                                       # free depths: the deep face fixed
        Kz = conductivity * Kz[:m, :m].toarray()
        Kz[0, 0] += convection
        self.mu, self.phi = eigh(Kz, Mz[:m, :m].toarray())
        self.nx, self.m = x.size, m
        self.rc, self.lam = float(capacity), float(conductivity)
        self.mx = [Mx.diagonal(k) for k in (-1, 0, 1)]
        self.kx = [Kx.diagonal(k) for k in (-1, 0, 1)]

    def factor(self, dt: float, theta: float):
        """The solver of one step's x-systems, ``((rho c / dt + theta mu_k) Mx + theta lambda Kx) eta_k = r_k``
        for every mode [s, 1]: an object with ``solve(r)`` (r and the result modes outer, x inner)."""
        scale = self.rc / dt + theta * self.mu                # per mode (m,)
        sub, diag, sup = (np.outer(scale, mx) + theta * self.lam * kx for mx, kx in zip(self.mx, self.kx))
        sub = np.concatenate([sub, np.zeros((self.m, 1))], axis=1).ravel()[:-1]    # no coupling between modes
        sup = np.concatenate([sup, np.zeros((self.m, 1))], axis=1).ravel()[:-1]
        dl, d, du, du2, ipiv, info = dgttrf(sub, diag.ravel(), sup)
        if info != 0:
            raise np.linalg.LinAlgError(f"tridiagonal LU of the FE section's depth modes failed (info = {info})")
        return _ModalSolve((dl, d, du, du2, ipiv))

    def rhs(self, eta: np.ndarray, dt: float, theta: float, load: np.ndarray) -> np.ndarray:
        """The right side of a step in modes, ``((rho c / dt - (1 - theta) mu_k) Mx - (1 - theta) lambda Kx)
        eta_k + Phi[0, k] load`` [W/m], for the state ``eta`` and the surface nodes' ``load`` (nx,) [W/m]."""
        e = np.asarray(eta, dtype=float).reshape(self.m, self.nx)
        out = (self.rc / dt - (1.0 - theta) * self.mu)[:, None] * _tridiagonal(self.mx, e)
        out -= (1.0 - theta) * self.lam * _tridiagonal(self.kx, e)
        out += np.outer(self.phi[0], load)
        return out.ravel()

    def nodal(self, eta: np.ndarray) -> np.ndarray:
        """Nodal temperatures of the free nodes (x outer, z inner) [K] of the state ``eta``."""
        return (np.asarray(eta, dtype=float).reshape(self.m, self.nx).T @ self.phi.T).ravel()

    def sampler(self, i: int, rows, weights):
        """(indices (n, m), weights (n, m)) into the state that give sum_p weights[:, p] T[i, rows[:, p]] (rows:
        free depth indices of x-node i): the output depths read in modes."""
        rows, weights = np.asarray(rows), np.asarray(weights, dtype=float)
        coef = np.einsum("np,npk->nk", weights, self.phi[rows])
        return i + self.nx * np.tile(np.arange(self.m), (rows.shape[0], 1)), coef


def _tridiagonal(diagonals, e: np.ndarray) -> np.ndarray:
    """The tridiagonal matrix of ``diagonals`` (sub, main, super) applied along the last axis of ``e``."""
    sub, main, sup = diagonals
    out = main * e
    out[:, 1:] += sub * e[:, :-1]
    out[:, :-1] += sup * e[:, 1:]
    return out


class _ModalSolve:
    """One factorised step matrix of a :class:`TensorSection` (see there)."""

    def __init__(self, lu):
        self.lu = lu

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        eta, info = dgttrs(*self.lu, np.asarray(rhs, dtype=float).reshape(-1, 1))
        if info != 0:
            raise np.linalg.LinAlgError(f"tridiagonal solve of the FE section's depth modes failed (info = {info})")
        return eta.ravel()


class FemBlock:
    """The section's Q1 elements and their operators (free node i (nz - 1) + j, j = 0 at the surface).

    Attributes: ``x`` node positions along the rail [m] (the section at ``x[i0]`` = 0), ``z`` node depths [m]
    (the last, deep one fixed at 0), ``mass`` and ``stiffness`` [J/(K m)], [W/(K m)] on the free nodes (as
    scikit-fem assembles them), ``tensor`` (the same operators as a :class:`TensorSection`, whose depth modes are
    the stepper's state), ``capacity`` (the lumped mass, one entry per unknown), ``dt_stab`` (min C/K_ii [s], for
    the cost record), ``surface`` (free indices of the surface nodes), ``nodal_rows`` and ``nodal_weights``
    (depths, 2): the output depths linear between two free nodes of the section's column; ``rows`` and
    ``weights`` (depths, modes): the same read from the state."""

    def __init__(self, x, z, mass, stiffness, depths, breaks, tensor: TensorSection):
        self.x, self.z = np.asarray(x, float), np.asarray(z, float)
        self.tensor = tensor
        self.breaks = np.asarray(sorted(breaks), dtype=float)
        self.i0 = int(np.argmin(np.abs(self.x)))
        self.mass, self.stiffness = mass, stiffness
        self.capacity = np.asarray(mass.sum(axis=1)).ravel()
        self.dt_stab = float(np.min(self.capacity / stiffness.diagonal()))
        m = self.z.size - 1                               # free nodes per column
        self.surface = np.arange(self.x.size) * m
        rows, weights = [], []
        for d in depths:
            j = int(np.clip(np.searchsorted(self.z, d, side="right") - 1, 0, self.z.size - 2))
            s = (d - self.z[j]) / (self.z[j + 1] - self.z[j])
            lower = j + 1 if j + 1 < m else j             # the deep node is 0: weight 0 below
            rows.append([j, lower])
            weights.append([1.0 - s, s if j + 1 < m else 0.0])
        self.nodal_rows = self.i0 * m + np.array(rows)
        self.nodal_weights = np.array(weights)
        self.rows, self.weights = tensor.sampler(self.i0, rows, weights)

    @property
    def node_shape(self) -> str:
        return f"{self.x.size}x{self.z.size}"

    def stepper(self, x_edges, y_edges, flux, speed, factor, t0):
        """A :class:`_FemStepper` under the band's ``flux`` (nx,) [W/m^2] on ``x_edges`` [m] at ``speed``
        [m/s], heat-input factor ``factor(t)``, from t0 [s]."""
        return _FemStepper(self, x_edges, flux, speed, factor, t0)


def assemble_section(x, z, conductivity: float, capacity: float, convection: float):
    """Consistent mass M [J/(K m)] and stiffness K [W/(K m)] (conduction plus surface convection) of Q1
    elements on the tensor mesh of nodes ``x`` (along the rail) and ``z`` (depth, 0 the surface) [m], all
    nodes in the order i z.size + j, by scikit-fem."""
    mesh = MeshQuad.init_tensor(np.asarray(x, float), np.asarray(z, float))
    basis = Basis(mesh, ElementQuad1())

    @BilinearForm
    def conduction(u, v, w):
        return conductivity * (u.grad[0] * v.grad[0] + u.grad[1] * v.grad[1])

    @BilinearForm
    def heat(u, v, w):
        return capacity * u * v

    K = asm(conduction, basis)
    if convection:
        top = FacetBasis(mesh, ElementQuad1(), facets=mesh.facets_satisfying(lambda p: np.isclose(p[1], 0.0)))

        @BilinearForm
        def loss(u, v, w):
            return convection * u * v
        K = K + asm(loss, top)
    return csr_matrix(asm(heat, basis)), csr_matrix(K)


def fem_block(a: float, speed: float, conductivity: float, capacity: float, convection: float, level: int,
              duration_total: float, depths, breaks=()) -> FemBlock:
    """The nodes and operators of the module docstring for a band of half-width ``a`` [m] at ``speed``
    [m/s], lambda [W/(m K)], rho c [J/(m^3 K)], surface convection h [W/(m^2 K)], refinement ``level``, a
    history of ``duration_total`` [s], the output ``depths`` [m] and the schedule's ``breaks`` [s] (its
    times, where the heat-input factor has kinks: each step's mean load is integrated piecewise between
    them)."""
    kappa = conductivity / capacity
    delta = thermal_scales(a, speed, kappa).thermal_depth
    reach = math.sqrt(kappa * duration_total)
    growth = X_GROWTH ** (1.0 / 2 ** int(level))
    h = 2.0 * a / (32 * 2 ** int(level))
    side = np.cumsum(_spacings(h, growth, 4, 2.0 * a + 2.0 * reach))
    x = np.concatenate([-side[::-1], [0.0], side])
    zg = Z_GROWTH ** (1.0 / 2 ** int(level))
    z = np.concatenate([[0.0], np.cumsum(_spacings(delta / 4.0 / 2 ** int(level), zg, 1,
                                                    max(8.0 * reach, 10.0 * delta, 1.5 * max(depths))))])
    M, K = assemble_section(x, z, conductivity, capacity, convection)
    free = np.ones((x.size, z.size), dtype=bool)
    free[:, -1] = False                                # the deep face: T = 0
    free = free.ravel()
    return FemBlock(x, z, M[free][:, free].tocsr(), K[free][:, free].tocsr(), depths, breaks,
                    TensorSection(x, z, conductivity, capacity, convection))


class _FemStepper(ImplicitSectionStepper):
    """Crank-Nicolson (and backward-Euler start) steps of the FE section (core's
    :class:`~railtherm.solving.section_stepping.ImplicitSectionStepper`): consistent mass, each step loaded with
    its mean heat input."""

    heating_cost = IMPLICIT_COST
    cooling_implicit = ("Crank-Nicolson steps of the FE section in depth modes (one tridiagonal LU per step size; "
                        "two backward-Euler start steps)")

    def __init__(self, block: FemBlock, x_edges, flux, speed, factor, t0):
        super().__init__(block, x_edges, flux, speed, factor, t0)
        self.flux = np.asarray(flux, dtype=float).reshape(-1)
        self._last = None

    def _factor(self, dt: float, th: float):
        return self.b.tensor.factor(dt, th)

    def _rhs(self, T, dt, th, p_old, p_mean):
        return self.b.tensor.rhs(T, dt, th, p_mean)

    def _load(self, dt: float, arrivals):
        # the "power" at the end of each step is the step's mean load (the end values' mean, composite over the
        # schedule's kinks inside the step: a spike shorter than the step keeps its energy)
        return lambda t: self._mean_power(t, dt, arrivals)

    def _power(self, t, arrivals):
        """Heat input of the surface nodes [W/m] at time t of the passes arriving at ``arrivals`` [s]: the
        leading edge of pass k at x = V (t - arrival_k), the band moving towards +x."""
        p = np.zeros(self.b.x.size)
        f = float(self.factor(t))
        if f == 0.0:
            return p
        for arr in arrivals:
            shift = self.xe[-1] - self.speed * (t - arr)      # source coordinate of block position 0
            p += hat_integrals(self.b.x + shift, self.xe, self.flux)
        return f * p

    def _mean_power(self, t1: float, dt: float, arrivals):
        """Trapezoidal mean heat input of the surface nodes [W/m] over the step (t1 - dt, t1] [s], composite over the pieces
        between the schedule's breaks inside the step (its kinks): without a break the end values' mean of
        Crank-Nicolson, and a spike shorter than the step keeps its energy."""
        if not len(arrivals):
            return np.zeros(self.b.x.size)
        t0 = t1 - dt
        inner = self.b.breaks[(self.b.breaks > t0) & (self.b.breaks < t1)]
        cuts = np.concatenate([[t0], inner, [t1]])
        ends = [self._power_at(t, arrivals) for t in cuts]
        return sum(0.5 * (hi - lo) * (p + q) for lo, hi, p, q in zip(cuts[:-1], cuts[1:], ends[:-1], ends[1:])) / dt

    def _power_at(self, t: float, arrivals):
        """:meth:`_power` at t, the last value kept (each step's start is the last step's end)."""
        key = (float(t), tuple(arrivals))
        if self._last is None or self._last[0] != key:
            self._last = (key, self._power(t, arrivals))
        return self._last[1]


def section_histories(transient, convection, bodies, source, level: int, scene_name: str = ""):
    """The pass histories of both bodies under one pass's ``source`` on the FE sections of :func:`fem_block`,
    stepped by core's driver (:func:`railtherm.solving.section_stepping.histories_at_section`: Crank-Nicolson, one
    pass's response superposed over the passes under a constant schedule): (TransientHistory, diagnostics,
    the source's grid).

    Parameters
    ----------
    transient : railtherm.input.transient.Transient
        The scene's passes (``scene.transient``, its interval resolved): count, interval [s], schedule, history
        depths [m].
    convection : float or None
        The surface heat transfer coefficient [W/(m^2 K)] (None: 0).
    bodies : (Material, Material)
        The wheel's and the rail's materials, with their bulk temperatures [degC].
    source : HeatSource
        One pass's heat source of a line contact: flux [W/m^2] on its grid, ``body_speed`` [m/s].
    level : int
        Refinement level of the sections [1].
    scene_name : str
        The scene's name, for the error messages.

    Raises
    ------
    railtherm.Refused
        An elliptical patch, or a heated body whose surface does not move through the contact.
    railtherm.SceneError
        ``passes.interval`` shorter than a heated body's contact duration 2a/V.
    """
    grid = source.grid
    tr = transient
    if not grid.line:
        raise Refused(f"scene {scene_name!r}: model 'fem' computes the pass histories of a line contact only",
                      kind="validity")
    fluxes = [np.asarray(source.flux(i), dtype=float).reshape(-1) for i in range(2)]
    speeds = tuple(float(v) for v in source.body_speed)
    span = float(grid.x_edges[-1] - grid.x_edges[0])
    for i, q in enumerate(fluxes):
        if not np.any(q != 0):
            continue
        body = ("wheel", "rail")[i]
        if not speeds[i] > 0.0:
            raise Refused(f"model 'fem' ({body}): its surface moves at {speeds[i]:g} m/s relative to the contact; "
                          "the section's passes need a body moving through it", kind="validity")
        if float(tr.interval) < span / speeds[i]:
            raise SceneError.bad_value(scene_name, "passes.interval", float(tr.interval),
                                       f"a time >= the contact duration 2a/V = {span / speeds[i]:.6g} s of the {body} "
                                       "(a pass must end before the next begins)")

    def make_block(v, m, convection, duration, z):
        return fem_block(float(grid.a), v, m.conductivity, m.density * m.specific_heat, convection, level,
                         duration, z, tr.schedule_time or ())
    bulk = (float(bodies[0].bulk_temperature), float(bodies[1].bulk_temperature))
    hist, diag = histories_at_section(
        tr, convection, grid.x_edges, grid.y_edges, [q if np.any(q != 0) else None for q in fluxes], speeds,
        tuple(bodies), bulk, int(level), "implicit", make_block, "bilinear finite elements (scikit-fem) of the fixed "
        "section (x-z), Crank-Nicolson steps, one LU per step size", "conduction along the rail beyond the section's "
        "ends; the wheel's curvature")
    diag.update({"converged": True, "iterations": 0, "residual": 0.0,
                 "scheme": "transient FE section (Crank-Nicolson)"})
    return hist, diag, grid
