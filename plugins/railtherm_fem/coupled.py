"""Operator splitting of the thermoelastic rolling contact (seed section 4.1, Steps 1-4).

Step 1: theta^0 = 0 (bulk temperatures). Step 2: for theta^k solve the elastic strip with its thermal
expansion load and the contact problem (Signorini + Coulomb) -> p^k, tau^k, slip^k. Step 3: frictional
heat from the contact solution, split between the bodies, and the steady moving-frame conduction ->
theta^{k+1}. Step 4: stop when ||theta^{k+1} - theta^k||_inf <= eta ||theta^{k+1}||_inf. The update is
relaxed, theta^{k+1} = theta^k + omega_k (T(theta^k) - theta^k), with omega = 1 while the residual
contracts and Aitken's dynamic relaxation when it does not.

The heat flux (the seed's eq. 20 read as a frictional power plus a contact conductance) and the heat
partition keys are described in :func:`solve_fem`. Under a temperature law this Steps 1-4 solve, at
fixed mu per contact node, is the solve of core's temperature-friction loop
(:func:`railtherm.physics.friction.iterate_temperature_law`), which iterates the nodes' contact
temperature; a slip-velocity law is solved with each contact solve (:mod:`.friction`).
"""
from __future__ import annotations

import math
import time
import warnings
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from railtherm import Refused, SolverError
from railtherm.physics.friction import (LOOP_MU_TOLERANCE, ConstantFriction, FrictionLaw, LoopStep, contact_temperature,
                                        iterate_temperature_law)
from railtherm.physics.partition import HeatPartition

from .contact import ContactSolution, solve_contact, upstream_derivative
from .elastic import ElasticStrip
from .friction import node_surface_temperatures, solve_with_slip_law
from .mesh import graded_strip_mesh
from .thermal import ThermalBody, ThermalGrid, ThermalSolver, bilinear_weights, hat_load, thermal_grid

__all__ = ["FemProblem", "FemSolution", "solve_fem", "contact_edges", "clear_cache"]


@dataclass
class FemProblem:
    """All inputs of one FEM solve (SI units).

    Attributes
    ----------
    radius : float
        Wheel radius r0 [m].
    rail, wheel : Material-like
        shear_modulus [Pa], poisson_ratio [1], density [kg/m^3], specific_heat [J/(kg K)],
        conductivity [W/(m K)], thermal_expansion [1/K], bulk_temperature [degC]; wheel.rigid [bool].
    speed : float
        Rolling speed V [m/s].
    normal_force, penetration : float or None
        Prescribed normal force per width [N/m] or approach [m] (exactly one).
    friction : railtherm.physics.friction.FrictionLaw or None
        The scene's friction law (a number [1] is taken as the constant law of that mu); None: frictionless.
        Where one coefficient is needed (the contact's mu under a constant law, whether there is friction at
        all) it is the law's ``nominal`` (at zero slip speed and the reference temperature, :attr:`mu`); a
        slip or temperature law is applied per window node, :mod:`.friction`.
    creepage : float or None
        Longitudinal creepage xi [1]; for full sliding ``-sliding_speed / speed`` is used (the wheel surface
        moves at V + v_s: a driving wheel, negative creepage, positive force on the wheel, as CONTACT).
    sliding_speed : float or None
        Full sliding speed [m/s].
    regularization : float
        Friction regularisation eps [1] (relative micro-slip of the stick zone, see :mod:`.contact`);
        default 0: exact Coulomb. A value that is not small against |creepage| biases the creep force
        (about Fx = mu N |xi| / eps when eps > |xi|); the diagnostics report eps / |xi|.
    heat_partition : HeatPartition
        (Built from the scene's value too: a number, "equal-temperature" or "equal-mean-temperature".)
    convection : float
        [W/(m^2 K)] on the free surfaces.
    thermal_resistance : float
        r [K s/m] of the contact conductance p / r; 0 switches it off.
    strip_length, strip_depth : float or None
        Strip size [m] (None: 80 a and 40 a from the estimated half-width).
    level : int
        Refinement level: surface spacing a/(10 2^level).
    thermal : bool
        Run the thermal part and the coupling.
    two_d : bool
        2-D conduction (True) or the seed's eq. 16 (False).
    field_behind, field_depth : float or None
        The scene's ``field`` [m]: the thermal layer must reach ``field_behind`` beyond the
        trailing edge and ``field_depth`` deep. None (no field): everything as without it. With it the
        default strip is lengthened to at least 2 (behind + FIELD_MARGIN a) and deepened to at least
        2 depth, the thermal layer reaches 2 depth, and its x-spacing grows gently behind the patch
        (ratio 1 + 0.02 / 2^level, :data:`FIELD_TRAIL_RATIO`); a given strip that is too short or too
        shallow is refused (:func:`fem_limits`).
    """

    radius: float
    rail: object
    wheel: object
    speed: float
    normal_force: float | None = None
    penetration: float | None = None
    friction: FrictionLaw | None = None
    creepage: float | None = None
    sliding_speed: float | None = None
    regularization: float = 0.0
    heat_partition: HeatPartition = HeatPartition("fraction", 0.5)
    convection: float = 0.0
    thermal_resistance: float = 0.0
    strip_length: float | None = None
    strip_depth: float | None = None
    level: int = 0
    thermal: bool = True
    two_d: bool = True
    grading: float = 8.0
    window: float = 1.25
    coupling_tolerance: float = 1e-6
    coupling_max_iterations: int = 30
    frictionless: bool = False
    field_behind: float | None = None
    field_depth: float | None = None

    def __post_init__(self):
        self.heat_partition = HeatPartition.of(self.heat_partition)
        if self.friction is not None and not isinstance(self.friction, FrictionLaw):
            self.friction = ConstantFriction(float(self.friction))

    @property
    def mu(self) -> float:
        """The law's nominal coefficient of friction [1] (0 without a law)."""
        return 0.0 if self.friction is None else float(self.friction.nominal)


@dataclass
class FemSolution:
    """Everything a FEM solve computed (internal frame: x = 0 under the wheel axis)."""

    contact: ContactSolution
    half_width: float
    centre: float
    heat_power_density: np.ndarray          # at window nodes [W/m^2]
    heat_partition: float
    frictional_power: float                 # [W/m]
    thermal_grid: ThermalGrid | None
    theta: list | None                      # rises (wheel, rail) on the thermal grid [K]
    strip: ElasticStrip
    displacement: np.ndarray
    body_speed: tuple
    history: list = field(default_factory=list)
    omegas: list = field(default_factory=list)
    coupling_iterations: int = 0
    coupling_converged: bool = True
    diagnostics: dict = field(default_factory=dict)

    def rail_theta(self):
        """Callable theta_rail(x, z) [K] (0 outside the thermal grid)."""
        return _interpolator(self.thermal_grid, None if self.theta is None else self.theta[1])


def _interpolator(grid, values):
    """Callable theta(x, z) [K]: the bilinear interpolant of ``values`` (shape (nx, nz)) on the tensor
    ``grid`` (the P1 x P1 field of the thermal layer), 0 outside it; the zero function without a grid."""
    if grid is None or values is None:
        return lambda x, z: np.zeros(np.broadcast(np.asarray(x), np.asarray(z)).shape)
    gx, gz, v = np.asarray(grid.x, float), np.asarray(grid.z, float), np.asarray(values, float).ravel()

    def theta(x, z):
        x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
        nodes, weights = bilinear_weights(gx, gz, x, z)
        return np.sum(v[nodes] * weights, axis=0).reshape(x.shape)
    return theta


def _youngs(mat):
    return 2.0 * mat.shear_modulus * (1.0 + mat.poisson_ratio)


def _lame(mat):
    nu, G = mat.poisson_ratio, mat.shear_modulus
    return 2.0 * G * nu / (1.0 - 2.0 * nu), G


def contact_edges(x, p):
    """Trailing and leading contact edges [m] from nodal pressures.

    Near a smooth contact edge p ~ sqrt(distance), so p^2 is linear: the edge is where the line
    through p^2 of the outermost contact node and its inner neighbour vanishes (clipped to the
    interval up to the next, open node).
    """
    idx = np.nonzero(p > 0)[0]
    if idx.size == 0:
        return 0.0, 0.0
    h = x[1] - x[0]

    def edge(i, j):
        d = p[j] ** 2 - p[i] ** 2
        if d <= 0:
            return x[i] + 0.5 * (x[i] - x[j])
        return x[i] + (x[i] - x[j]) * min(p[i] ** 2 / d, 1.0)

    lo, hi = idx[0], idx[-1]
    left = edge(lo, lo + 1) if lo + 1 < x.size else x[lo] - 0.5 * h
    right = edge(hi, hi - 1) if hi >= 1 else x[hi] + 0.5 * h
    return float(left), float(right)


#: largest Hertz half-width relative to the wheel radius, a / r0 [1]: the strip is linear (small-strain)
#: elastic and the surface strain of a Hertz line contact is p0 / E* = a / (2 r0), 5 % at this limit
MAX_HALF_WIDTH_OVER_RADIUS = 0.1
#: largest Hertz half-width relative to the strip length, a / L [1]: the patch (and the condensed window
#: of 1.25 a that carries the contact unknowns) must lie well inside the clamped ends x = +-L/2, which
#: are then at least 2 a from the patch centre
MAX_HALF_WIDTH_OVER_LENGTH = 0.25

#: the strip's outflow end (x = -L/2, no conduction through it) lies at least this many half-widths a beyond
#: the end of the scene's ``field`` behind the patch [1]
FIELD_MARGIN = 2.0
#: growth ratio of the thermal x-spacing behind the patch with a ``field`` at level 0 (1 + 0.02 / 2^level) [1]
FIELD_TRAIL_RATIO = 0.02


def fem_limits(prob: FemProblem) -> str | None:
    """Why the FEM cannot solve ``prob`` (the patch does not fit the strip or breaks small strain), or None.

    The half-width is Hertz's for a half-plane under the normal force (or, under a prescribed
    penetration, the geometric overlap half-width sqrt(2 r0 delta)); both are upper bounds of the
    strip's patch (a strip on a rigid foundation is stiffer than the half-plane), so the check may
    refuse a load the strip would just have carried, never the reverse. Checked before any mesh is built.
    """
    a = _estimate_half_width(prob)
    R = float(prob.radius)
    if prob.normal_force is not None:
        what = f"normal_force = {prob.normal_force:g} N/m"
        fix = lambda lim: f"normal_force <= {prob.normal_force * (lim / a) ** 2:.3g} N/m"
    else:
        what = f"penetration = {prob.penetration:g} m"
        fix = lambda lim: f"penetration <= {lim ** 2 / (2.0 * R):.3g} m"
    if a > MAX_HALF_WIDTH_OVER_RADIUS * R:
        lim = MAX_HALF_WIDTH_OVER_RADIUS * R
        return (f"model 'fem': {what} gives a Hertz half-width a = {a:.4g} m = {a / R:.3g} x wheel_radius "
                f"{R:g} m, above the small-strain limit a/r0 <= {MAX_HALF_WIDTH_OVER_RADIUS:g} (surface strain "
                f"p0/E* = a/(2 r0) <= 5 %) of the linear elastic strip; use {fix(lim)}")
    L = prob.strip_length
    if L is not None and a > MAX_HALF_WIDTH_OVER_LENGTH * L:
        lim = MAX_HALF_WIDTH_OVER_LENGTH * L
        return (f"model 'fem': {what} gives a Hertz half-width a = {a:.4g} m, above the limit "
                f"a <= L/{1 / MAX_HALF_WIDTH_OVER_LENGTH:g} = {lim:.4g} m of the strip (length L = {L:g} m): the "
                f"patch would reach the strip's clamped ends; use strip length >= {a / MAX_HALF_WIDTH_OVER_LENGTH:.4g} m "
                f"or {fix(lim)}")
    if prob.field_behind is not None and L is not None and 0.5 * L < prob.field_behind + (1.0 + FIELD_MARGIN) * a:
        need = 2.0 * (prob.field_behind + (1.0 + FIELD_MARGIN) * a)
        return (f"model 'fem': field.behind = {prob.field_behind:g} m does not fit on the strip (length L = {L:g} m): "
                f"its outflow end x = -L/2 must lie {FIELD_MARGIN:g} a beyond -a - behind (Hertz half-width "
                f"a = {a:.4g} m); use strip length >= {need:.4g} m, leave strip.length out (then the strip is "
                f"lengthened) or shorten field.behind to <= {max(0.5 * L - (1.0 + FIELD_MARGIN) * a, 0.0):.4g} m")
    D = prob.strip_depth
    if prob.field_depth is not None and D is not None and D < 2.0 * prob.field_depth:
        return (f"model 'fem': field.depth = {prob.field_depth:g} m is too deep for the strip (depth {D:g} m): its "
                f"thermal layer (temperature rise 0 at the bottom) must reach 2 x field.depth; use strip depth >= "
                f"{2.0 * prob.field_depth:.4g} m, leave strip.depth out, or field.depth <= {0.5 * D:.4g} m")
    return None


def _estimate_half_width(prob: FemProblem) -> float:
    e_inv = (1 - prob.rail.poisson_ratio ** 2) / _youngs(prob.rail)
    if not getattr(prob.wheel, "rigid", False):
        e_inv += (1 - prob.wheel.poisson_ratio ** 2) / _youngs(prob.wheel)
    if prob.normal_force is not None:
        return math.sqrt(4.0 * prob.normal_force * prob.radius * e_inv / math.pi)
    return math.sqrt(2.0 * prob.radius * prob.penetration)  # geometric overlap: an upper bound


class _Mechanics:
    """Strip(s), condensation and the relative compliance blocks for one mesh."""

    def __init__(self, prob: FemProblem, length, depth, window, h):
        self.mesh = graded_strip_mesh(length, depth, window, h, grading=prob.grading)
        lam, G = _lame(prob.rail)
        V = prob.speed
        self.rail = ElasticStrip(self.mesh, lam, G, prob.rail.density, V, prob.rail.thermal_expansion)
        rigid = bool(getattr(prob.wheel, "rigid", False))
        m = self.mesh.window.size
        w = np.full(m, h)
        C = self.rail.compliance
        Cxx, Cxy, Cyx, Cyy = C[:m, :m], C[:m, m:], C[m:, :m], C[m:, m:]
        # sink = A_nn p + A_nt tau ; U = u_x(wheel) - u_x(rail) = A_tn p + A_tt tau
        A_nn, A_nt, A_tn, A_tt = Cyy * w, Cyx * w, Cxy * w, Cxx * w
        self.wheel = None
        if not rigid:
            same = all(getattr(prob.wheel, k) == getattr(prob.rail, k)
                       for k in ("shear_modulus", "poisson_ratio", "density", "thermal_expansion"))
            if same:
                self.wheel = self.rail
            else:
                lw, Gw = _lame(prob.wheel)
                self.wheel = ElasticStrip(self.mesh, lw, Gw, prob.wheel.density, V, prob.wheel.thermal_expansion)
            Cw = self.wheel.compliance
            # mirrored strip: x unchanged, y flipped -> coupling blocks change sign
            A_nn = A_nn + Cw[m:, m:] * w
            A_tt = A_tt + Cw[:m, :m] * w
            A_nt = A_nt - Cw[m:, :m] * w
            A_tn = A_tn - Cw[:m, m:] * w
        self.blocks = (A_nn, A_nt, A_tn, A_tt)
        self.w = w
        self.x = self.mesh.x_window
        R = prob.radius
        self.h0 = R - np.sqrt(R * R - self.x ** 2)

    @property
    def nbytes(self) -> int:
        """Estimated memory held [B]: the strip(s) (:attr:`ElasticStrip.nbytes`) and the compliance blocks."""
        strips = [self.rail] + ([self.wheel] if self.wheel is not None and self.wheel is not self.rail else [])
        return int(sum(st.nbytes for st in strips) + sum(b.nbytes for b in self.blocks))

    def thermal_operators(self, grid, depth):
        """Thermal load operators (rail, wheel or None) of a rise on the thermal ``grid`` down to ``depth``
        [m] (:meth:`ElasticStrip.thermal_load_operator`); built once per solve, applied every iteration."""
        rail = self.rail.thermal_load_operator(grid, depth=depth)
        if self.wheel is None:
            return rail, None
        return rail, (rail if self.wheel is self.rail else self.wheel.thermal_load_operator(grid, depth=depth))

    def thermal_offsets(self, operators, theta_rail, theta_wheel):
        """Sink W0 and relative tangential displacement U0 from thermal expansion; full rail field.

        ``operators``: :meth:`thermal_operators`; ``theta_rail``, ``theta_wheel``: rises on its grid [K].
        """
        win = self.mesh.window
        u_r = self.rail.solve(operators[0](theta_rail))
        ux, uy = u_r[self.rail.node_dofs[0, win]], u_r[self.rail.node_dofs[1, win]]
        W0, U0 = -uy, -ux   # rail surface rising closes the gap
        if self.wheel is not None and theta_wheel is not None:
            u_w = self.wheel.solve(operators[1](theta_wheel))
            W0 = W0 - u_w[self.wheel.node_dofs[1, win]]
            U0 = U0 + u_w[self.wheel.node_dofs[0, win]]
        return W0, U0, u_r


#: the kept mechanics (:func:`_mechanics`), least recently used first
_MECH_CACHE: "OrderedDict" = OrderedDict()
#: how many meshes are kept (a penetration-controlled solve uses a coarse and a fine one)
CACHE_SIZE = 2
#: the kept mechanics hold at most this many bytes in all (estimated from the factor fill; an L3 strip of
#: 3e4 unknowns holds about 60 MB); one that alone is larger is not kept [B]
CACHE_BYTES = 256 * 2 ** 20


def _material_key(mat):
    """What of a material the mechanics uses: Lamé constants, density (moving-frame term), expansion, rigidity."""
    return tuple(float(getattr(mat, k, 0.0) or 0.0) for k in
                 ("shear_modulus", "poisson_ratio", "density", "thermal_expansion")) + (bool(getattr(mat, "rigid", False)),)


def _mechanics_key(prob: FemProblem, length, depth, window, h) -> tuple:
    """Every input of :class:`_Mechanics`: the mesh (strip length and depth, window half-length, surface
    spacing, grading [m, 1]), the moving-frame speed [m/s], the wheel radius of the gap [m] and both materials.
    Nothing else (friction, creepage, load, heat, regularisation, level other than through the spacing)
    enters the mesh, the stiffness or its factorisation."""
    return (float(length), float(depth), float(window), float(h), float(prob.grading), float(prob.speed),
            float(prob.radius), _material_key(prob.rail), _material_key(prob.wheel))


def _mechanics(prob: FemProblem, length, depth, window, h) -> "_Mechanics":
    """The mechanics of one mesh (graded mesh, stiffness, its factorisation with the window last and the
    window compliance), kept for the next solve on the same mesh with the same materials.

    What it saves: building and factorising the strip, about 60 % of a level-3 solve of the main study
    (0.5-1 s). Who reuses it: a creepage, friction or load sweep on one geometry (the carter scene), the
    coarse first pass of a penetration-controlled solve at every level, and a repeated solve of the same
    scene and level. The key is every input of the mechanics (:func:`_mechanics_key`), so a solve never
    finds another geometry's or material's factorisation; the results are bit for bit those of a cold
    solve (tests/test_fem_mesh.py). Bounded: the :data:`CACHE_SIZE` most recently used, at most
    :data:`CACHE_BYTES` in all. A timed repeat of an identical solve therefore excludes this set-up; the
    runner's first timed solve of a run (``wall_time_cold``) includes it unless an earlier run in the same
    process built the same mesh. :func:`clear_cache` forgets it.
    """
    key = _mechanics_key(prob, length, depth, window, h)
    mech = _MECH_CACHE.get(key)
    if mech is not None:
        _MECH_CACHE.move_to_end(key)
        return mech
    mech = _Mechanics(prob, length, depth, window, h)
    if mech.nbytes <= CACHE_BYTES:
        _MECH_CACHE[key] = mech
        while len(_MECH_CACHE) > CACHE_SIZE or sum(m.nbytes for m in _MECH_CACHE.values()) > CACHE_BYTES:
            _MECH_CACHE.popitem(last=False)
    return mech


def clear_cache() -> None:
    """Forget the kept mechanics (the next solve builds its mesh and factorisation anew)."""
    _MECH_CACHE.clear()


def solve_fem(prob: FemProblem) -> FemSolution:
    """Solve the (coupled) FEM problem: mechanics on a graded mesh, then the Steps 1-4 loop.

    Heat flux (the seed's eq. 20 is dimensionally inconsistent as printed; what is used instead): the
    frictional power density ``P = tau . s`` (traction times slip velocity, = mu p |s| where it slips; the
    seed writes mu V F_2, i.e. assumes the whole speed V slips) is split by the heat partition eps
    (fraction into the wheel): the rail receives (1 - eps) P, the wheel eps P. The seed's ``theta F_2 / r``
    term is read as a pressure-dependent thermal contact conductance h_c = p / r [W/(m^2 K)] (r [K s/m],
    the seed's 1000), which carries heat from the hotter to the colder surface: ``q_rail = (1 - eps) P -
    h_c (theta_rail - theta_wheel)``. As printed, the term would *add* heat in proportion to the
    temperature (a positive feedback without physical meaning) and be scaled by the partition; it is
    applied as a conductance between the two surfaces, not scaled. The seed's temperature-dependent
    friction factor (1 - k rho c theta / mu) has no value of k in section 4.2; the scene's friction law
    takes its place (a slip-velocity law is solved with each contact solve, :mod:`.friction`).

    Heat partition (:class:`railtherm.physics.partition.HeatPartition`): a given fraction;
    ``"equal-temperature"``, Blok's fraction at the FEM's body speeds, as every method uses it;
    ``"equal-mean-temperature"``, the FEM's own rule: in every Step 3 the fraction that makes the wheel's
    and the rail's mean absolute surface temperatures over the patch equal (the temperatures are affine in
    the fraction: two solves and a root).

    Under a temperature law (with the thermal part), the Steps 1-4 solve at fixed mu per window node is the
    solve of the one temperature-friction loop, :func:`railtherm.physics.friction.iterate_temperature_law`,
    on the contact temperature of the window nodes; its history goes into the diagnostics
    (``friction_loop_*``, comma-separated; ``friction_loop_coupling_iterations``: the Steps 1-4 iterations
    of each of its solves).
    """
    law = prob.friction
    if (prob.thermal and law is not None and law.depends_on_temperature and not prob.frictionless
            and prob.mu > 0):
        return _solve_under_temperature_law(prob, law)
    return _solve_steps(prob)


def _solve_under_temperature_law(prob: FemProblem, law) -> FemSolution:
    """The Steps 1-4 solve with mu = law(T_c) per window node, T_c iterated by core's temperature-friction
    loop on the window nodes of its first solve (the mesh, and with it the nodes, is the same in every solve;
    np.interp keeps a node that moved on the loop's points)."""
    bulk = (prob.wheel.bulk_temperature, prob.rail.bulk_temperature)
    nodes, steps = {}, []

    def solve(t_in):
        if "x" in nodes:
            xs, ts = nodes["x"], np.asarray(t_in, dtype=float)
            sol = _solve_steps(prob, lambda x: np.interp(x, xs, ts))
        else:
            sol = _solve_steps(prob, lambda x: np.full(np.shape(x), float(t_in)))
        c = sol.contact
        x = nodes.setdefault("x", c.x.copy())
        t_out = contact_temperature(*node_surface_temperatures(c.x, sol.thermal_grid, sol.theta, *bulk))
        steps.append(sol.coupling_iterations)
        return LoopStep(sol, np.interp(x, c.x, t_out), abs(float(c.tangential_force)),
                        law.nominal * float(c.normal_force), np.interp(x, c.x, c.pressure) > 0)

    sol, hist = iterate_temperature_law(law, solve, float(contact_temperature(*bulk)), what="model 'fem'")
    sol.diagnostics.update(friction_loop_iterations=len(hist.mu_change),
                           friction_loop_mu_change=",".join(f"{h:.3e}" for h in hist.mu_change),
                           friction_loop_force_change=",".join(f"{h:.3e}" for h in hist.force_change),
                           friction_loop_mean_mu=",".join(f"{h:.5f}" for h in hist.mean_mu),
                           friction_loop_max_contact_temperature=",".join(f"{h:.6g}" for h in hist.max_temperature),
                           friction_loop_coupling_iterations=",".join(str(n) for n in steps),
                           friction_loop_tolerance=LOOP_MU_TOLERANCE)
    return sol


# one Steps 1-4 solve from mesh set-up to the result, kept in one piece: its stages share the mesh, the
# window, the thermal grid and the relaxation state, which a split would pass around as a dozen arguments
def _solve_steps(prob: FemProblem, node_temperature=None) -> FemSolution:
    """One FEM solve: mechanics on a graded mesh, then the Steps 1-4 loop, with mu of a temperature law from
    ``node_temperature(x)`` [degC] at the window nodes x (default: that of the bulk temperatures)."""
    t_start = time.perf_counter()
    why = fem_limits(prob)
    if why:
        raise Refused(why, kind="validity")
    a_ref = _estimate_half_width(prob)
    length = prob.strip_length or 80.0 * a_ref
    depth = prob.strip_depth or 40.0 * a_ref
    if prob.field_behind is not None and not prob.strip_length:
        length = max(length, 2.0 * (prob.field_behind + (1.0 + FIELD_MARGIN) * a_ref))
    if prob.field_depth is not None and not prob.strip_depth:
        depth = max(depth, 2.0 * prob.field_depth)
    frictional = not prob.frictionless and prob.mu > 0
    xi = None
    if frictional:
        xi = prob.creepage if prob.creepage is not None else -(prob.sliding_speed or 0.0) / prob.speed
    eps = float(prob.regularization)
    eps_ratio = eps / abs(xi) if (frictional and xi) else 0.0
    if eps_ratio > 0.01:
        warnings.warn(f"friction regularisation eps = {eps:g} is {eps_ratio:.3g} x |rigid slip| = {abs(xi):g}: the "
                      "stick zone creeps viscously and the creep force is biased (towards mu N |xi| / eps when "
                      "eps > |xi|); use eps <= 0.01 |xi|, or 0 (exact Coulomb, the default)",
                      RuntimeWarning, stacklevel=2)
    law = prob.friction if frictional else None
    law = None if law is None or law.kind == "constant" else law
    temperature_law = law is not None and law.depends_on_temperature
    law_state = {"mu": None}
    if node_temperature is None:
        bulk = float(contact_temperature(prob.wheel.bulk_temperature, prob.rail.bulk_temperature))
        node_temperature = lambda x: np.full(np.shape(x), bulk)     # noqa: E731

    def node_mu(x):
        return np.asarray(law.mu(0.0, node_temperature(x)), dtype=float)

    def contact(mech, common, W0, U0, initial=None):
        """solve_contact on ``mech`` with mu per node from the law (the constant mu without one)."""
        def run(mu, init):
            return solve_contact(mech.x, mech.w, mech.h0, *mech.blocks, W0=W0, U0=U0, initial=init,
                                 **{**common, "friction": mu})
        if law is None:
            return run(common["friction"], initial)
        if temperature_law:
            law_state["mu"] = node_mu(mech.x)
            return run(law_state["mu"], initial)
        D = upstream_derivative(mech.x.size, float(mech.x[1] - mech.x[0]))
        self_slip = np.abs(np.einsum("ij,ji->i", D, mech.blocks[3]))
        sol_, mu_, hist_, kappa_ = solve_with_slip_law(law, run, prob.speed, self_slip)
        law_state.update(mu=mu_, slip_history=hist_, kappa=kappa_)
        return sol_

    # a first, coarse pass when only the penetration is known (the half-width is not)
    a_est = a_ref
    if prob.normal_force is None:
        win0 = 1.1 * a_ref
        mech0 = _mechanics(prob, length, depth, win0, win0 / 40.0)
        s0 = solve_contact(mech0.x, mech0.w, mech0.h0, *mech0.blocks, penetration=prob.penetration)
        l0, r0 = contact_edges(s0.x, s0.pressure)
        a_est = max(0.5 * (r0 - l0), 4 * win0 / 40.0)
    window = prob.window * a_est
    h = a_est / (10.0 * 2 ** prob.level)
    # the window must stay inside the strip (its surface nodes uniformly spaced, two spare cells to the ends)
    window_max = 0.5 * length - 2.0 * h
    for attempt in range(4):
        window_n = min(max(window, 4 * h), window_max)
        mech = _mechanics(prob, length, depth, window_n, h)
        common = dict(friction=prob.mu if frictional else 0.0, creepage=xi, regularization=eps,
                      normal_force=prob.normal_force, penetration=prob.penetration)
        sol = contact(mech, common, None, None)
        inside = np.nonzero(sol.pressure > 0)[0]
        if inside.size and inside[0] >= 2 and inside[-1] <= mech.x.size - 3:
            break
        if window_n >= window_max:
            attempt = 3
            break
        window *= 1.5
    if not (inside.size and inside[0] >= 2 and inside[-1] <= mech.x.size - 3):
        raise SolverError(
            f"model 'fem': the contact reaches the edge of the condensed window (half-length {window_n:g} m, "
            f"{mech.x.size} nodes at {h:g} m; strip length {length:g} m) after {attempt + 1} attempts: "
            f"{inside.size} nodes in contact, from x = {mech.x[inside[0]] if inside.size else float('nan'):g} to "
            f"{mech.x[inside[-1]] if inside.size else float('nan'):g} m; contact Newton converged={sol.converged}, "
            f"residual={sol.residual:.3g}")
    t_mech = time.perf_counter()

    V = prob.speed
    history, omegas = [], []
    theta = None
    grid = None
    u_r = None
    left, right = contact_edges(sol.x, sol.pressure)
    a = 0.5 * (right - left)
    power = V * np.abs(sol.traction * np.nan_to_num(sol.slip)) if frictional else np.zeros_like(sol.x)
    vs_mean = V * float(np.sum(power) / max(np.sum(np.abs(sol.traction)) * V, 1e-300)) if frictional else 0.0
    body_speed = (V + abs(vs_mean), V)
    partition = prob.heat_partition
    # the equal-mean-temperature fraction is found with the temperatures (Step 3); without them it stays 0.5
    eps_part = 0.5 if partition.needs_temperatures else partition.wheel_fraction(prob.wheel, prob.rail, *body_speed)
    it = 0
    converged = True
    thermal_unknowns = 0
    thermal_residual = 0.0
    coupling_residual = 0.0
    if prob.thermal:
        rail, wheel = prob.rail, prob.wheel
        rb = ThermalBody(rail.conductivity, rail.density * rail.specific_heat, body_speed[1], prob.convection)
        wb = ThermalBody(wheel.conductivity, wheel.density * wheel.specific_heat, body_speed[0], prob.convection)
        kap = min(rb.diffusivity / rb.speed, wb.diffusivity / wb.speed)  # kappa / V [m]
        dx = mech.x[1] - mech.x[0]
        x_min = -0.5 * length
        x_max = mech.x[-1] + (max(30 * kap, 4 * dx) if prob.two_d else dx)
        ztop = 8.0 * math.sqrt(max(rb.diffusivity / rb.speed, wb.diffusivity / wb.speed) * (x_max - x_min)) + 4 * kap
        zdepth = min(depth, ztop)
        rz = 1.0 + 0.2 / 2 ** prob.level
        dz0 = 0.5 * min(math.sqrt(kap * dx), dx)
        if prob.field_behind is None and prob.field_depth is None:
            grid = thermal_grid(mech.x[-1], dx, x_min, x_max, dz0, zdepth, rz, rz)
        else:    # the scene's field: deep enough, and the x-spacing growing gently behind the patch
            if prob.field_depth is not None:
                zdepth = min(depth, max(ztop, 2.0 * prob.field_depth))
            grid = thermal_grid(mech.x[-1], dx, x_min, x_max, dz0, zdepth, rz, rz,
                                ratio_trail=1.0 + FIELD_TRAIL_RATIO / 2 ** prob.level)
        nx = grid.x.size
        theta = [np.zeros(grid.shape), np.zeros(grid.shape)]
        solver = solver_hc = operators = None
        omega = 1.0
        r_prev = None
        converged = False
        for it in range(1, prob.coupling_max_iterations + 1):
            # Step 3: heat from the current contact solution
            power = V * np.abs(sol.traction * np.nan_to_num(sol.slip)) if frictional else np.zeros_like(sol.x)
            qf = lambda s, pw=power: np.interp(s, sol.x, pw, left=0.0, right=0.0)
            load = hat_load(grid.x, qf, breaks=sol.x, order=2)
            hc = None
            if prob.thermal_resistance > 0:
                hc = np.interp(grid.x, sol.x, sol.pressure, left=0.0, right=0.0) / prob.thermal_resistance
            # the conduction operator is the same in every iteration (fixed grid, speeds and properties):
            # factorised once; only a contact conductance, which follows the pressure, changes it
            if solver is None or not np.array_equal(hc, solver_hc):
                solver, solver_hc = ThermalSolver(grid, [wb, rb], prob.two_d, hc), hc
            dT = wheel.bulk_temperature - rail.bulk_temperature
            # bulk difference drives conduction through h_c: load on wheel -h_c dT, on rail +h_c dT
            cond = np.zeros(nx) if hc is None else hc * dT * np.asarray(_lumped(grid.x))
            if partition.needs_temperatures:
                t_w1, t_r1 = solver.solve([load - cond, cond])
                t_w0, t_r0 = solver.solve([-cond, load + cond])
                sel = (grid.x >= left) & (grid.x <= right)
                mw1, mr1 = t_w1[sel, 0].mean(), t_r1[sel, 0].mean()
                mw0, mr0 = t_w0[sel, 0].mean(), t_r0[sel, 0].mean()
                # wheel - rail mean (absolute) temperature, affine in eps
                f0 = wheel.bulk_temperature + mw0 - rail.bulk_temperature - mr0
                f1 = wheel.bulk_temperature + mw1 - rail.bulk_temperature - mr1
                eps_part = float(np.clip(f0 / (f0 - f1), 0.0, 1.0)) if f0 != f1 else 0.5
                new = [t_w0 + eps_part * (t_w1 - t_w0), t_r0 + eps_part * (t_r1 - t_r0)]
            else:
                new = solver.solve([eps_part * load - cond, (1 - eps_part) * load + cond])
            thermal_unknowns = solver.unknowns
            thermal_residual = max(thermal_residual, solver.residual)
            # Step 4: convergence test on the rail temperature (the field that loads the strip)
            r = [new[0] - theta[0], new[1] - theta[1]]
            rn = max(np.abs(r[0]).max(), np.abs(r[1]).max())
            scale = max(np.abs(new[0]).max(), np.abs(new[1]).max(), 1e-300)
            history.append(rn / scale)
            if r_prev is not None:
                if history[-1] >= history[-2]:  # not contracting: Aitken relaxation
                    dr = np.concatenate([(r[j] - r_prev[j]).ravel() for j in range(2)])
                    rv = np.concatenate([r_prev[j].ravel() for j in range(2)])
                    den = float(dr @ dr)
                    if den > 0:
                        omega = float(np.clip(-omega * float(rv @ dr) / den, 0.05, 1.0))
                else:
                    omega = min(1.0, omega * 1.5) if omega < 1.0 else 1.0
            omegas.append(omega)
            theta = [theta[j] + omega * r[j] for j in range(2)]
            r_prev = r
            coupling_residual = history[-1]
            expansion = bool(prob.rail.thermal_expansion or (mech.wheel is not None and prob.wheel.thermal_expansion))
            one_way = not expansion
            if one_way:
                # nothing couples back (no thermal expansion; mu is fixed during these steps): T(theta) does
                # not depend on theta, so one pass is the fixed point and its residual is exactly 0
                coupling_residual = 0.0
            if history[-1] <= prob.coupling_tolerance or one_way:
                converged = True
                break
            # Step 2: contact with the thermal expansion of theta^{k+1}
            W0 = U0 = None
            if expansion:
                if operators is None:
                    operators = mech.thermal_operators(grid, zdepth)
                W0, U0, u_r = mech.thermal_offsets(operators, theta[1], theta[0] if mech.wheel is not None else None)
            sol = contact(mech, common, W0, U0, initial=sol)
            left, right = contact_edges(sol.x, sol.pressure)
            a = 0.5 * (right - left)
    # final full displacement field (contact forces + thermal expansion)
    m = mech.mesh.window.size
    f = mech.rail.window_load(-sol.traction * mech.w, -sol.pressure * mech.w)
    if theta is not None and prob.rail.thermal_expansion:
        E = operators[0] if operators is not None else mech.rail.thermal_load_operator(grid, depth=grid.z[-1])
        f = f + E(theta[1])
    u = mech.rail.solve(f)
    power = V * np.abs(sol.traction * np.nan_to_num(sol.slip)) if frictional else np.zeros_like(sol.x)
    diag = dict(dofs=int(mech.rail.ndofs), window_nodes=int(m), surface_spacing=float(mech.x[1] - mech.x[0]),
                strip_length=float(length), strip_depth=float(depth), approach=float(sol.approach),
                contact_iterations=int(sol.iterations), contact_residual=float(sol.residual),
                contact_converged=bool(sol.converged), regularization=eps,
                regularization_over_slip=float(eps_ratio),
                mechanics_time=float(t_mech - t_start), total_time=float(time.perf_counter() - t_start),
                thermal_unknowns=int(thermal_unknowns), thermal_residual=float(thermal_residual),
                coupling_residual=float(coupling_residual),
                factor_fill=int(mech.rail.condensed.fill), **fem_law_diagnostics(law, law_state))
    return FemSolution(contact=sol, half_width=float(a), centre=float(0.5 * (left + right)),
                       heat_power_density=power, heat_partition=float(eps_part),
                       frictional_power=float(np.sum(power * mech.w)), thermal_grid=grid, theta=theta,
                       strip=mech.rail, displacement=u, body_speed=body_speed, history=history, omegas=omegas,
                       coupling_iterations=it, coupling_converged=converged, diagnostics=diag)


def fem_law_diagnostics(law, state) -> dict:
    """Diagnostics of the friction law (empty without one): its kind and the slip law's outer iteration
    (the temperature law's loop adds its own, :func:`solve_fem`)."""
    if law is None:
        return {}
    out = {"friction_law": law.kind}
    if law.depends_on_slip and "slip_history" in state:
        out.update(friction_iterations=len(state["slip_history"]), friction_contraction=float(state["kappa"]),
                   friction_mu_change=",".join(f"{h:.3e}" for h in state["slip_history"]))
    return out


def _lumped(x):
    """Lumped P1 mass (tributary lengths) of 1-D nodes [m]."""
    d = np.diff(x)
    m = np.zeros(x.size)
    m[:-1] += 0.5 * d
    m[1:] += 0.5 * d
    return m
