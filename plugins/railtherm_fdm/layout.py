"""Layout of the finite-difference block, shared by the 3-D and the 2-D (line contact) solvers.

What a run is made of before anything is solved: the block's extent around the patch
(:func:`block_extent`, :func:`line_extent`), the explicit stability limits, the uniform node grid and
the time steps of the transient schemes (:func:`node_grid`, :func:`plan_steps`), and the graded
cell grid of the moving-frame steady scheme (:func:`graded_grid`).

Coordinates: x along rolling with the leading edge of the patch at +a, z >= 0 into the body; the
transient schemes work in the body's frame (the patch moves over the top face at the body's speed
V), the steady scheme in the frame of the patch.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from railtherm.physics import thermal_scales

__all__ = ["Extent", "block_extent", "line_extent", "explicit_stability_limit", "line_stability_limit",
           "NodeGrid", "node_grid", "StepPlan", "plan_steps", "GradedGrid", "graded_grid", "graded_edges",
           "graded_depth_edges", "Trail", "trail_extent", "trail_edges", "field_note", "rail_nodes", "depth_nodes"]


@dataclass
class Extent:
    """Block size around the patch (patch frame, x along rolling, leading edge +a)."""

    ahead: float      # from the leading edge to the inflow / far face ahead [m]
    behind: float     # from the trailing edge (of the start position) to the far face behind [m]
    lateral: float    # from the patch's lateral edge to the side face [m]
    depth: float      # block depth [m]
    travel: float     # distance the source travels in the transient schemes [m]


def block_extent(a: float, b: float, speed: float, kappa: float, *, scale: float = 1.0) -> Extent:
    """Block size for a patch of half-lengths a (rolling) and b (lateral) [m].

    Built from the decay lengths of the moving-source field: ahead of the source it decays like
    exp(-V x / kappa); sideways and in depth (away from the wake) like exp(-V r / (2 kappa)); the
    heat of the part of the path further back than s reaches the source like exp(-V s /(4 kappa)).
    With l = 2 kappa / V and the contact-time penetration depth delta = sqrt(2 a kappa / V):
    ahead = max(a/2, 6 l), behind = max(a, 6 l), lateral = max(a, b/2, 8 l), depth =
    max(a, 8 l, 6 delta), travel = 2 a + max(2 a, 40 kappa/V) (the deficit of the field near the
    source is then below exp(-10)). ``scale`` multiplies all margins (for domain-size checks).

    Parameters
    ----------
    a, b : float
        Semi-axes of the patch along and across rolling [m].
    speed : float
        Speed V of the body relative to the contact [m/s].
    kappa : float
        Thermal diffusivity [m^2/s].
    scale : float
        Factor on every margin [1].

    Returns
    -------
    Extent
    """
    sc = thermal_scales(a, speed, kappa)
    ell, delta = sc.wake_length, sc.thermal_depth
    return Extent(ahead=scale * max(0.5 * a, 6.0 * ell), behind=scale * max(a, 6.0 * ell),
                  lateral=scale * max(a, 0.5 * b, 8.0 * ell), depth=scale * max(a, 8.0 * ell, 6.0 * delta),
                  travel=2.0 * a + scale * max(2.0 * a, 40.0 * kappa / speed))


def line_extent(a: float, speed: float, kappa: float, *, scale: float = 1.0) -> Extent:
    """Block size around a band of half-width a [m] (:func:`block_extent` of a = b; the 2-D block
    has no lateral margin)."""
    return block_extent(a, a, speed, kappa, scale=scale)


def explicit_stability_limit(d: float, kappa: float, h: float = 0.0, rho_c: float = 1.0, *,
                             dimension: int = 3) -> float:
    """Largest stable explicit-Euler step of the node grid [s].

    ``1 / (2 n kappa/d^2 + 2 h/(rho c d))`` in n = ``dimension`` dimensions: the surface node
    (half-depth dual cell) loses ``2 h dt/(rho c d)`` per step by convection on top of the 2n-neighbour
    diffusion term; without convection this is d^2/(2 n kappa).

    Parameters
    ----------
    d : float
        Cell size [m].
    kappa : float
        Diffusivity [m^2/s].
    h : float
        Convection coefficient [W/(m^2 K)].
    rho_c : float
        Volumetric heat capacity rho c [J/(m^3 K)].
    dimension : int
        Dimensions of the grid [1]: 3 for the block, 2 for the line contact's block.
    """
    return 1.0 / (2.0 * dimension * kappa / d ** 2 + 2.0 * h / (rho_c * d))


def line_stability_limit(d: float, kappa: float, h: float, rho_c: float) -> float:
    """Largest stable explicit step of the 2-D block [s]: :func:`explicit_stability_limit` with
    ``dimension=2``, ``1 / (4 kappa/d^2 + 2 h/(rho c d))``."""
    return explicit_stability_limit(d, kappa, h, rho_c, dimension=2)


@dataclass(frozen=True)
class NodeGrid:
    """Uniform node grid of a transient run along x and z (body frame).

    Attributes
    ----------
    d : float
        Node spacing [m].
    start : float
        x of the patch centre at the start [m] (``nb d + a``: the far face behind lies ``behind``
        beyond the trailing edge).
    nx, nz : int
        Nodes along x and in depth (x = 0 and x = (nx-1) d and z = (nz-1) d are fixed faces).
    """

    d: float
    start: float
    nx: int
    nz: int

    @property
    def x(self) -> np.ndarray:
        """Node x coordinates [m]."""
        return self.d * np.arange(self.nx)

    @property
    def z(self) -> np.ndarray:
        """Node depths [m]."""
        return self.d * np.arange(self.nz)


def node_grid(a: float, extent: Extent, d: float) -> NodeGrid:
    """The node grid that holds the patch's whole path: ``behind`` + the patch + ``travel`` + ``ahead``
    along x, ``depth`` (at least three nodes) in z.

    Parameters
    ----------
    a : float
        Semi-axis of the patch along rolling [m].
    extent : Extent
        Block size around the patch.
    d : float
        Node spacing [m].
    """
    nb = int(math.ceil((extent.behind + 0.5 * d) / d)) + 1
    start = nb * d + a
    nx = int(math.ceil((start + extent.travel + a + extent.ahead) / d)) + 1
    nz = max(3, int(math.ceil(extent.depth / d)) + 1)
    return NodeGrid(d, start, nx, nz)


#: largest number of node spacings over which the source's offset to the nodes may repeat [1]
MAX_PERIOD_CELLS = 8
#: fraction of the explicit stability limit a default step may reach [1]: at the limit the
#: checkerboard mode (amplification 1 - 2 dt/limit) is not damped, and the step's share of the
#: error would differ from level to level
STABLE_FRACTION = 0.9


@dataclass(frozen=True)
class StepPlan:
    """Time steps of a transient run.

    Attributes
    ----------
    dt : float
        Time step [s].
    steps : int
        Number of steps [1].
    travel : float
        Distance the source travels, steps x V dt [m].
    check_step : int
        Step after which the patch-frame field is sampled a second time for the quasi-steady check.
    period : int or None
        Steps after which the source sits at the same offset to the nodes again (None for a forced step).
    period_cells : int
        Node spacings the source travels in ``period`` steps [1].
    """

    dt: float
    steps: int
    travel: float
    check_step: int
    period: int | None
    period_cells: int = 1


def steps_per_cells(need: float, max_cells: int = MAX_PERIOD_CELLS) -> tuple[int, int]:
    """``(p, q)``: the smallest ratio p/q >= ``need`` with q <= ``max_cells`` (the smallest q among
    equal ratios); ``(1, 1)`` when ``need`` <= 1.

    p steps per q node spacings is the least number of steps the source may take per node spacing
    when each step may advance it at most 1/``need`` of a spacing.
    """
    if need <= 1.0:
        return 1, 1
    best = None
    for q in range(1, max_cells + 1):
        p = int(math.ceil(need * q * (1.0 - 1e-12)))
        if best is None or p * best[1] < best[0] * q:
            best = (p, q)
    return best


def plan_steps(d: float, speed: float, travel: float, stability_limit: float, *, scheme: str = "explicit",
               courant: float = 1.0, time_step: float | None = None, checkpoint: float | None = None,
               a: float = 0.0) -> StepPlan:
    """Time step, number of steps and quasi-steady checkpoint of a transient run.

    Without a forced ``time_step`` the source advances q d / p per step, p/q the smallest ratio
    (q <= :data:`MAX_PERIOD_CELLS`, :func:`steps_per_cells`) with a step at most ``courant d / V``
    (and, explicit scheme, at most ``stability_limit``): every p steps the patch sits at the same
    offset to the nodes, so patch-frame fields sampled p k steps apart differ only by what is still
    changing in time (no interpolation noise in the quasi-steady check). A whole number of steps
    per spacing (q = 1, the seed's one step per cell when that is stable) would waste up to half
    the steps below the stability limit: 2 steps per cell where 1.2 are stable.

    Parameters
    ----------
    d : float
        Node spacing [m].
    speed : float
        Speed V of the body relative to the contact [m/s].
    travel : float
        Distance the source must travel [m] (rounded up to whole steps).
    stability_limit : float
        Largest stable explicit step [s].
    scheme : {"explicit", "implicit"}
    courant : float
        Source advance per step in node spacings [1].
    time_step : float, optional
        Forced step [s] (the caller refuses an explicit step beyond the limit).
    checkpoint : float, optional
        Travel before the end at which the field is sampled again [m]; default ``a``.
    a : float
        Semi-axis of the patch along rolling [m].
    """
    p, q = None, 1
    if time_step is not None:
        dt = float(time_step)
    else:
        target = courant * d / speed
        if scheme == "explicit":
            target = min(STABLE_FRACTION * stability_limit, target)
        p, q = steps_per_cells(d / (speed * target))
        dt = q * d / (p * speed)
    nsteps = max(2, int(math.ceil(travel / (speed * dt) - 1e-9)))
    back = checkpoint if checkpoint is not None else a
    if p is not None:
        nback = p * max(1, int(round(back / (q * d))))
    else:
        nback = max(1, int(round(back / (speed * dt))))
    return StepPlan(dt, nsteps, nsteps * speed * dt, max(1, nsteps - nback), p, q)


# ---------------------------------------------------------------------------------------------
# graded cell grid of the moving-frame steady scheme
# ---------------------------------------------------------------------------------------------
def graded_edges(lo_in: float, hi_in: float, n_in: int, lo: float, hi: float, ratio: float) -> np.ndarray:
    """Edges: ``n_in`` uniform cells on [lo_in, hi_in], cells growing by ``ratio`` outward to lo and hi [m]."""
    core = np.linspace(lo_in, hi_in, n_in + 1)
    h = (hi_in - lo_in) / n_in

    def grow(length):
        return _grow(h, length, ratio)

    right = hi_in + grow(hi - hi_in) if hi > hi_in else np.array([])
    left = lo_in - grow(lo_in - lo)[::-1] if lo < lo_in else np.array([])
    return np.concatenate([left, core, right])


def graded_depth_edges(dz1: float, depth: float, ratio: float) -> np.ndarray:
    """Depth edges from 0 to ``depth``: first cell ``dz1``, each next one ``ratio`` times larger [m]."""
    edges = [0.0]
    w = dz1
    while edges[-1] < depth:
        nxt = edges[-1] + w
        if depth - nxt < 0.5 * w * ratio:
            nxt = depth
        edges.append(nxt)
        w *= ratio
    return np.array(edges)


@dataclass(frozen=True)
class GradedGrid:
    """Cell edges of the steady scheme's grid [m] (``y_edges`` None for the 2-D block) and the growth
    ratio at this level [1]."""

    x_edges: np.ndarray
    y_edges: np.ndarray | None
    z_edges: np.ndarray
    growth: float


def graded_grid(a: float, extent: Extent, cell: float, speed: float, kappa: float, level: int, *,
                b: float | None = None, ratio: float = 1.3, surface_layers: int = 4,
                trail: "Trail | None" = None) -> GradedGrid:
    """The steady scheme's cell grid: uniform cells of about ``cell`` over the patch, growing outward.

    The growth ratio is ``ratio ** (1 / 2**level)`` so that halving ``cell`` level by level refines the
    whole grid consistently; the first depth cell is ``min(cell, delta / surface_layers / 2**level)``
    with the contact-time penetration depth delta = sqrt(2 a kappa / V).

    Parameters
    ----------
    a : float
        Semi-axis along rolling [m].
    extent : Extent
        Block size around the patch.
    cell : float
        Cell size over the patch [m].
    speed : float
        Speed V of the body relative to the contact [m/s].
    kappa : float
        Thermal diffusivity [m^2/s].
    level : int
        Refinement level [1].
    b : float, optional
        Lateral semi-axis [m]; None for the 2-D block (no y edges).
    ratio : float
        Growth ratio of the graded cells at level 0 [1].
    surface_layers : int
        Cells across the penetration depth delta at level 0 [1].
    trail : Trail, optional
        A scene's ``field``: behind the trailing edge and down to ``trail.depth`` the cells follow the
        trail (:func:`trail_edges`) instead of growing by the ratio; beyond, they grow as without it.
        None: the grid is exactly the one without a field.
    """
    rk = ratio ** (1.0 / 2 ** level)
    ye = None
    if b is not None:
        nyb = max(2, int(round(2 * b / cell)))
        ye = graded_edges(-b, b, nyb, -b - extent.lateral, b + extent.lateral, rk)
    delta = thermal_scales(a, speed, kappa).thermal_depth
    dz1 = min(cell, delta / surface_layers / 2 ** level)         # the first depth cell [m]
    if trail is not None:
        return _trail_graded_grid(a, extent, cell, level, rk, trail, ye, dz1)
    nxa = max(2, int(round(2 * a / cell)))
    xe = graded_edges(-a, a, nxa, -a - extent.behind, a + extent.ahead, rk)
    return GradedGrid(xe, ye, graded_depth_edges(dz1, extent.depth, rk), rk)


# ---------------------------------------------------------------------------------------------
# the thermal trail behind the patch and in depth (scene key ``field``)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Trail:
    """What a scene's ``field`` asks of the block: temperatures ``behind`` [m] beyond the trailing edge
    and down to ``depth`` [m] (None: the block's own depth)."""

    behind: float
    depth: float | None


#: trail cells: width ``max(h, TRAIL_SLOPE s / 2**level)`` at distance s behind the trailing edge (and
#: ``max(dz1, TRAIL_SLOPE z / 2**level)`` at depth z): the trail at distance s varies on the scale s
#: (along x) and sqrt(kappa s / V) (in depth), so a fixed fraction of the distance resolves it alike
#: everywhere, and halving the fraction per level refines the grid consistently [1]
TRAIL_SLOPE = 0.125


def trail_extent(extent: Extent, trail: Trail, a: float, speed: float, kappa: float, *, steady: bool) -> Extent:
    """The block's extent stretched to hold the trail.

    Moving-frame steady grid: the far face behind lies ``trail.behind`` further back (the outflow face,
    zero diffusive flux, stays ``extent.behind`` beyond the end of the field). Transient schemes: the
    source travels ``trail.behind`` further (the trail at the end of the field was laid down after the
    source had already travelled ``extent.travel``, so it carries the same start-up deficit as the patch
    without field); the far face behind the start is unchanged.

    Depth, with s = sqrt(2 kappa (2a + behind) / V) the penetration depth of the trail's end (the time
    since the source passed it): the graded steady grid reaches ``trail.depth + 6 s`` (its deep cells are
    few and wide). The uniform transient grid pays for every depth alike and reaches
    ``max(6 s, trail.depth + delta)`` (delta = sqrt(2 a kappa / V), so the deepest reported depth is not
    on the fixed face): the fixed face (rise 0) perturbs the rise anywhere by at most what the unbounded
    body has at the face (maximum principle). Six penetration depths down, a half-space heated at a
    constant flux for the field's time has 4e-10 of its surface rise (6e-6 for twice that time, the
    longest any heated point of a run whose travel is 4a before the field has been heated) -- the
    criterion of the block's own depth (:func:`block_extent`) for the field's time. In both the depth is
    at least ``extent.depth``.
    """
    depth = extent.depth
    if trail.depth is not None:
        s = math.sqrt(2.0 * kappa * (2.0 * a + trail.behind) / speed)
        if steady:
            depth = max(depth, float(trail.depth) + 6.0 * s)
        else:
            delta = thermal_scales(a, speed, kappa).thermal_depth
            depth = max(depth, 6.0 * s, float(trail.depth) + delta)
    if steady:
        return Extent(extent.ahead, extent.behind + trail.behind, extent.lateral, depth, extent.travel)
    return Extent(extent.ahead, extent.behind, extent.lateral, depth, extent.travel + trail.behind)


def trail_edges(start: float, length: float, first: float, slope: float) -> np.ndarray:
    """Distances from ``start`` (0) to ``length`` [m]: cells of width ``max(first, slope s)`` at
    distance s, the last one ending exactly at ``length``."""
    out = [0.0]
    while out[-1] < length * (1.0 - 1e-12):
        w = max(first, slope * out[-1])
        nxt = out[-1] + w
        if length - nxt < 0.5 * w:
            nxt = length
        out.append(nxt)
    return start + np.array(out)


def _grow(h: float, length: float, ratio: float) -> np.ndarray:
    """Distances (excluding 0) of cells growing by ``ratio`` from width h up to ``length``."""
    out = []
    s, w = 0.0, h
    while s < length - 1e-12 * length:
        w = w * ratio
        if s + w >= length or length - (s + w) < 0.5 * w * ratio:
            out.append(length)
            break
        s += w
        out.append(s)
    return np.array(out)


def _trail_graded_grid(a, extent, cell, level, rk, trail, ye, dz1):
    """:func:`graded_grid` with cells following the trail (see there): its x and depth edges; the lateral
    edges ``ye`` and the first depth cell ``dz1`` [m] as :func:`graded_grid` builds them."""
    nxa = max(2, int(round(2 * a / cell)))
    h = 2 * a / nxa
    slope = TRAIL_SLOPE / 2 ** level
    core = graded_edges(-a, a, nxa, -a, a + extent.ahead, rk)          # the patch and ahead, as without field
    behind = float(trail.behind)
    back = -trail_edges(0.0, behind, h, slope)[1:] - a if behind > 0 else np.array([])
    last = (back[-2] - back[-1]) if back.size > 1 else h
    rest = extent.behind - behind
    far = back[-1] - _grow(last, rest, rk) if (back.size and rest > 0) else (
        -a - _grow(h, rest, rk) if rest > 0 else np.array([]))
    xe = np.concatenate([far[::-1], back[::-1], core])
    if trail.depth is None:
        ze = graded_depth_edges(dz1, extent.depth, rk)
    else:
        top = trail_edges(0.0, float(trail.depth), dz1, slope)
        w = top[-1] - top[-2]
        ze = np.concatenate([top, top[-1] + _grow(w, extent.depth - top[-1], rk)])
    return GradedGrid(xe, ye, ze, rk)


def field_note(trail) -> str:
    """The part of a budget refusal that names the scene's ``field`` (empty without one)."""
    if trail is None:
        return ""
    deep = "" if trail.depth is None else f" and {trail.depth:.4g} m deep"
    return (f", or a shorter field (the scene's field asks for temperatures {trail.behind:.4g} m behind the "
            f"trailing edge{deep}, which the block must reach)")


def rail_nodes(a: float, reach: float, level: int) -> np.ndarray:
    """Nodes along the rail [m], symmetric about the section x = 0: spacing h = 2a/32/2**level within four
    nodes of it, growing by ``1.3 ** (1 / 2**level)`` beyond, to 2a + 2 ``reach`` [m] on each side."""
    h = 2.0 * a / (32 * 2 ** int(level))
    half = 2.0 * a + 2.0 * reach
    side = list(h * np.arange(1, 5))                    # uniform h next to the section, then graded
    step = h
    while side[-1] < half:
        step *= 1.3 ** (1.0 / 2 ** int(level))
        side.append(side[-1] + step)
    side = np.array(side)
    return np.concatenate([-side[::-1], [0.0], side])


def depth_nodes(first: float, growth: float, bottom: float, exact) -> np.ndarray:
    """Graded depths [m] from 0: spacing ``first`` growing by ``growth`` to ``bottom``; the depths in
    ``exact`` made nodes (the nearest node moved onto each)."""
    z = [0.0]
    dz = first
    while z[-1] < bottom:
        z.append(z[-1] + dz)
        dz *= growth
    z = np.array(z)
    for d in exact:
        if d > 0:
            z[int(np.argmin(np.abs(z[1:] - d))) + 1] = d
    return z
