"""Tangential model "kalker": Kalker's exact steady rolling with creepage on the normal stage's patch.

The patch's grid and pressure (the ``kalker`` normal model's potential contact area, or any uniform grid, e.g.
core's Hertz patch) bound the traction by mu p per element; :func:`railtherm_kalker.tangential_solver.solve_tangential_nested`
gives the tractions and slip. On the wheel (body 1), with CONTACT's sign law (a positive creepage gives a negative
force), the model fills the tractions [Pa], the slip velocity V s relative to the rail [m/s] (zero in stick), the
stick indicator, creep forces [N], spin moment ``sum (x p_y - y p_x) dA`` [N m], surface speeds V (1 - xi) and V,
and the local dissipation ``-(p . v_s)`` [W/m^2] (exactly mu p |v_s| in slip, 0 in stick) that core's heat source
``frictional`` integrates. Rolling difference: second-order upwind by default (:func:`rolling_operator`).
Creepages: the patch's own (a wheelset normal model), else the scene's, else full sliding (xi = -v_s / V).

References
----------
.. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990. doi:10.1007/978-94-015-7889-9
.. [2] F.W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157. doi:10.1098/rspa.1926.0100
"""
from __future__ import annotations

import functools

import numpy as np
from railtherm import Capabilities, Option, Refused, TangentialContactModel
from railtherm.physics import combined_elastic, creep_speeds
from railtherm.physics.friction import LAW_KINDS
from scipy.fft import next_fast_len

from .friction_laws import solve_with_law
from ._precompile import compile_kernels
from ._quadrant import (ROLLING_EXTRA, _quadrant_differences_cached, mirror_quadrant, place_rolling,
                        tangential_quadrants)
from .influence import Convolution, element_size, line_kernel, normal_operator, rolling_kernel
from .tangential_solver import TANGENTIAL_TOLERANCE, solve_tangential_nested

__all__ = ["KalkerTangential", "rolling_operator", "patch_creepages", "solve_patch_tangential", "clear_operator_caches",
           "rolling_operator_kernels"]


def patch_creepages(patch, creepage, sliding_speed, speed, scene_name: str) -> tuple[float, float, float]:
    """(xi [1], eta [1], phi [1/m]): the patch's, the scene's ``creepage``, or full sliding xi = -v_s / V
    (``sliding_speed``, ``speed`` [m/s]); ``scene_name`` names the scene in the refusal."""
    if patch.creepage is not None:
        return tuple(float(c) for c in patch.creepage)
    if creepage is not None:
        return float(creepage.longitudinal), float(creepage.lateral), float(creepage.spin)
    if sliding_speed is not None:
        return -float(sliding_speed) / float(speed), 0.0, 0.0
    raise Refused(f"scene {scene_name!r}: no creepage or sliding speed for model 'kalker'")


#: order of the rolling difference by default (:func:`railtherm_kalker.influence.rolling_kernel`): the
#: second-order upwind difference at the element centre. With CONTACT's first-order difference Kalker's C33 was
#: +3.8 / +7.6 % off at b/a = 0.3 / 0.2 at level 3 (first order in dx, growing like (a/b)^2 dx / a), with the
#: second-order one +1.2 / +2.1 %, C11, C22, C23 within 0.6 % with both (docs/kalker.md)
ROLLING_ORDER = 2

#: the second-order operator's preconditioner cut is the first-order operator's near kernels times this [1]
#: (:func:`rolling_operator`): the factor (3 - S) / 2 between the two operators is between 1 and 2. GMRES steps
#: (E&K ellipse, nested, combined / longitudinal creepage) at 100^2: 105 / 98 unscaled, 100 / 88 at 5/4,
#: 101 / 87 at 3/2 (first-order operator: 88 / 85); at 200^2: 142 / 161, 140 / 123, 147 / 128 (135 / 122)
SECOND_ORDER_CUT_SCALE = 1.25

#: the option ``rolling_scheme``: name -> order of the rolling difference
ROLLING_SCHEMES = {"second-order": 2, "first-order": 1}


def rolling_operator(x_edges, y_edges, shear_modulus: float, poisson_ratio: float,
                     order: int = ROLLING_ORDER) -> Convolution:
    """The rolling influence operator B (slip = w - B p) on a uniform element grid.

    Parameters
    ----------
    x_edges, y_edges : ndarray
        Element edges [m] (y_edges None for a line contact).
    shear_modulus, poisson_ratio : float
        Combined G [Pa] and nu [1].
    order : {1, 2}
        Order of the upwind rolling difference [1] (:func:`railtherm_kalker.influence.rolling_kernel`; 1 is
        CONTACT's, also chosen by ``rolling_scheme = "first-order"`` or any ``slip_offset``). The second order
        puts Kalker's C33 within 2.1 % of his table at level 3 down to b/a = 0.2, where the first is 7.6 % off, and
        the local frictional power within 0.05 % of the creep forces' power at level 3 (first order: 0.5-2.6 %).

    Returns
    -------
    Convolution
        Components x (and y) [1/Pa]. Its :attr:`~railtherm_kalker.influence.Convolution.near` kernels (the cut
        the local preconditioners invert) are the first-order operator's for either order (times
        :data:`SECOND_ORDER_CUT_SCALE` for the second order): the second-order
        operator is the first-order one times ``(3 - S) / 2`` (S the shift by one element upstream), whose
        symbol has its real part in [1, 2], so the first-order cut preconditions it well; its own cut to the
        offsets +1 ... -2 leaves out the offset -3, of the size of +1, and its block LU broke down on elements
        4 times shorter along x than across (a = 8, b = 4 mm, 64 elements across 2b, m = 4), while the
        first-order cut converged there in as many GMRES steps as the first-order operator (69 and 69 in linear
        theory, tests/test_kalker_long_patches.py).
    """
    nx = len(x_edges) - 1
    dx = element_size(x_edges)
    if y_edges is None:
        return _rolling_operator(nx, dx, 1, None, float(shear_modulus), float(poisson_ratio), int(order))
    return _rolling_operator(nx, dx, len(y_edges) - 1, element_size(y_edges), float(shear_modulus),
                             float(poisson_ratio), int(order))


@functools.lru_cache(maxsize=8)
def _rolling_operator(nx, dx, ny, dy, shear_modulus, poisson_ratio, order):
    """:func:`rolling_operator` of a grid, computed once per grid, material and order (the solves of a study, a
    friction loop, the nested grids and a wheelset's patches share it)."""
    rx, ry = min(Convolution.NEAR, nx - 1), min(Convolution.NEAR, ny - 1)
    if dy is None:
        k = {"xx": line_kernel(nx, dx, (1.0 - poisson_ratio) / shear_modulus, extra=order)}
        keys = {(0, 0): "xx"}
        kernels = {key: rolling_kernel(k[name], dx, order) for key, name in keys.items()}
        placed = False
    else:
        # the kernels placed on the padded grid in one pass; the tangential kernels at the offsets of the cut
        # (-r-1 .. r+1 along x for the first-order difference at -r .. r) from a small quadrant
        padded = (next_fast_len(2 * nx - 1, real=True), next_fast_len(2 * ny - 1, real=True))
        kernels = rolling_operator_kernels(nx, ny, dx, dy, shear_modulus, poisson_ratio, order, padded)
        placed = True
        q = tangential_quadrants(rx + 2, ry + 1, dx, dy, shear_modulus, poisson_ratio)
        k = {name: mirror_quadrant(q[name], rx + 2, ry + 1, odd=name == "xy") for name in ("xx", "xy", "yy")}
        keys = {(0, 0): "xx", (0, 1): "xy", (1, 1): "yy"}
    near = None
    if order != 1 or placed:
        # the first-order kernel at the offsets of the cut only (Convolution.NEAR on each side): offset o of k[name]
        # is at index o + c (c: the index of offset 0), and the first-order difference at -r..r needs -r-1..r+1;
        # the same arithmetic for both orders, so that the second order's cut is the first order's times the scale
        c = rx + 1 if placed else nx - 1 + order
        rows = slice(c - rx - 1, c + rx + 2)
        cols = slice(k["xx"].shape[1] // 2 - ry, k["xx"].shape[1] // 2 + ry + 1)
        scale = SECOND_ORDER_CUT_SCALE if order != 1 else 1.0
        near = {key: scale * rolling_kernel(k[name][rows, cols], dx, 1) for key, name in keys.items()}
    return Convolution(kernels, (nx, ny), near_kernels=near, placed=placed)


def rolling_operator_kernels(nx: int, ny: int, dx: float, dy: float, shear_modulus: float, poisson_ratio: float,
                             order: int, padded: tuple[int, int]) -> dict:
    """The rolling kernels ``(A[k + 1] - A[k]) / dx`` or ``(-A[k + 2] + 4 A[k + 1] - 3 A[k]) / (2 dx)``
    (:func:`railtherm_kalker.influence.rolling_kernel`) of the Boussinesq-Cerruti kernels
    (:func:`railtherm_kalker.influence.tangential_kernels`), placed circulantly on the padded grid
    (``Convolution(..., placed=True)``): ``(0, 0), (0, 1), (1, 1) -> ndarray padded`` [1/Pa].

    Placed from the kernels' quadrants (:func:`railtherm_kalker._quadrant.tangential_quadrants`, whose corner
    differences the grid's normal operator shares; :func:`railtherm_kalker._quadrant.place_rolling`) instead of the
    full kernels, their differences and their placement as separate array passes (the tests compare the two).
    """
    mx, my = padded
    if order not in (1, 2):
        raise ValueError(f"order = {order!r}: the rolling difference is of order 1 or 2")
    q = tangential_quadrants(nx + order, ny, dx, dy, shear_modulus, poisson_ratio,
                             differences=_quadrant_differences_cached(nx + ROLLING_EXTRA, ny, float(dx), float(dy)))
    out = np.zeros((3, mx, my))
    place_rolling(q["xx"], q["xy"], q["yy"], nx, ny, order, float(dx), out)
    return {(0, 0): out[0], (0, 1): out[1], (1, 1): out[2]}


def clear_operator_caches() -> None:
    """Empty the caches of the operators' set-up (normal and rolling operators, the shared corner differences of
    their kernels), so that the next solve on a grid computes them as a study's first solve does."""
    normal_operator.cache_clear()
    _rolling_operator.cache_clear()
    _quadrant_differences_cached.cache_clear()


def solve_patch_tangential(patch, friction, creepages, shear_modulus: float, poisson_ratio: float,
                           tol: float = TANGENTIAL_TOLERANCE, initial=None, offset: float = 0.0,
                           order: int = ROLLING_ORDER):
    """Solve the steady rolling problem on a patch's grid and pressure.

    Parameters
    ----------
    patch : railtherm.ContactPatch
        Grid (uniform) and pressure [Pa].
    friction : float or ndarray (nx, ny)
        mu [1], one number or per element (a friction law).
    creepages : (float, float, float)
        xi [1], eta [1], phi [1/m].
    shear_modulus, poisson_ratio : float
        Combined G [Pa], nu [1].
    tol : float
        Solver tolerance [1].
    initial : ndarray (ncomp, nx, ny), optional
        Warm start [Pa] (the previous solve of a friction loop on the same patch).
    offset : float
        Rigid slip evaluated at x + offset dx [elements] (0: the element centre; 1/6: CONTACT's steady-state
        discretisation with ``order = 1``, see docs/kalker.md). The returned slip is the slip at that evaluation
        point.
    order : {1, 2}
        Order of the upwind rolling difference [1] (:func:`rolling_operator`).

    Returns
    -------
    solution : TangentialSolution
        Tractions on the bound in slip, slip exactly zero in stick.
    X, Y : ndarray (nx, ny)
        Element centres [m].
    """
    grid = patch.grid
    line = grid.y_edges is None
    nx = grid.x.size
    ny = 1 if line else grid.y.size
    p = np.asarray(patch.pressure, dtype=float).reshape(nx, ny)
    if line:
        X, Y = grid.x[:, None], np.zeros((nx, 1))
    else:
        X, Y = np.meshgrid(grid.x, grid.y, indexing="ij")
    g = friction * np.clip(p, 0.0, None)
    sol = solve_tangential_nested(lambda xe, ye: rolling_operator(xe, ye, shear_modulus, poisson_ratio, order),
                                  grid.x_edges, grid.y_edges, g, creepages, tol=tol, initial=initial, offset=offset)
    # polish: stick has zero slip, slip has its traction on the bound against the slip (both to the
    # solver's residual already; exact here so that -p . s = mu p |s| holds to round-off)
    s = np.where(sol.stick[None], 0.0, sol.slip)
    ns = np.sqrt(np.sum(s * s, axis=0))
    slipping = (g > 0) & ~sol.stick & (ns > 0)
    t = np.where(slipping[None], -g * s / np.where(ns > 0, ns, 1.0), sol.traction)
    sol.traction, sol.slip = t, s
    return sol, X, Y


class KalkerTangential(TangentialContactModel):
    """Kalker's exact theory of steady rolling on the half-space: tractions, slip and stick/slip areas
    from the creepages (longitudinal, lateral, spin) and Coulomb's law per element, with the
    Boussinesq-Cerruti influence coefficients applied by FFT and semismooth Newton-GMRES. Line
    contacts (plane strain, longitudinal creepage) run through the same solver (Carter's case).

    References
    ----------
    .. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990.
       doi:10.1007/978-94-015-7889-9
    """

    name = "kalker"
    description = ("Kalker's exact steady rolling (half-space, Boussinesq-Cerruti by FFT, semismooth "
                   "Newton-GMRES): tractions, slip, stick, creep forces, spin moment, dissipation")
    needs_elastic_body = True
    capabilities = Capabilities(
        contacts=frozenset({"ellipse", "line", "gap"}), sources=frozenset({"computed"}),
        tangential=frozenset({"creepage", "full-sliding"}),
        provides=frozenset({"traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "stick",
                            "creep_force_x", "creep_force_y", "spin_moment"}),
        friction_laws=LAW_KINDS)
    options = {"tangential_tolerance": Option(TANGENTIAL_TOLERANCE, "tolerance of the tangential solver, "
                                              "max |F| / max(mu p) [1]", minimum=0.0),
               "rolling_scheme": Option("second-order", "the rolling derivative of the steady-state slip: "
                                        "'second-order' upwind difference at the element centre, or 'first-order', "
                                        "CONTACT's (u(x + dx) - u(x)) / dx (docs/kalker.md)",
                                        choices=tuple(ROLLING_SCHEMES)),
               "slip_offset": Option(0.0, "rigid slip (and so the slip, the traction direction and the frictional "
                                     "power) evaluated at x + offset dx [elements] with the first-order scheme (an "
                                     "offset other than 0 selects it); 1/6: CONTACT's steady-state discretisation "
                                     "(docs/kalker.md)", minimum=0.0)}

    def compute_tangential(self, scene, patch, level, options):
        compile_kernels()           # all of the plugin's kernels in the process's first solve (the runner's warm-up)
        xi, eta, phi = patch_creepages(patch, scene.creepage, scene.sliding_speed, scene.speed, scene.name)
        if patch.b is None and (eta != 0.0 or phi != 0.0):
            raise Refused(f"model 'kalker': a line contact has only longitudinal creepage (lateral = {eta:g}, "
                          f"spin = {phi:g} 1/m given)")
        try:
            G, nu = combined_elastic(scene.wheel, scene.rail)
        except ValueError as exc:
            raise Refused(f"model 'kalker': {exc}") from exc
        V = float(scene.speed)
        tol = float(options.get("tangential_tolerance", TANGENTIAL_TOLERANCE))
        off = float(options.get("slip_offset", 0.0))
        order = 1 if off != 0.0 else ROLLING_SCHEMES[options.get("rolling_scheme", "second-order")]
        law_diag = {}
        if scene.friction.kind == "constant":
            sol, X, Y = solve_patch_tangential(patch, float(scene.friction.nominal), (xi, eta, phi), G, nu, tol, offset=off,
                                               order=order)
        else:
            # warm start: the previous solve of core's temperature loop on this patch and creepage (this instance
            # serves one run) or of the slip-law iteration
            key = (patch.grid.x_edges.tobytes(), None if patch.b is None else patch.grid.y_edges.tobytes(),
                   np.asarray(patch.pressure).tobytes(), (xi, eta, phi), G, nu, tol, off, order)
            warm = self.__dict__.setdefault("_warm", {})

            def solve(mu, previous=None):
                start = previous[0].traction if previous is not None else warm.get(key)
                out = solve_patch_tangential(patch, mu, (xi, eta, phi), G, nu, tol, initial=start, offset=off,
                                             order=order)
                warm[key] = out[0].traction
                return out

            b0 = abs(float(rolling_operator(patch.grid.x_edges, patch.grid.y_edges, G, nu, order).self_coefficient))
            sol, X, Y, _, law_diag = solve_with_law(scene.friction, patch, scene.wheel.bulk_temperature,
                                                    scene.rail.bulk_temperature, solve, b0, V)
        grid = patch.grid
        area = grid.cell_area
        shape = np.shape(patch.pressure)
        tx = sol.traction[0]
        vx = V * sol.slip[0]
        inside = np.asarray(patch.pressure).reshape(tx.shape) > 0
        stick = np.where(inside, sol.stick.astype(float), np.nan)
        fields = dict(traction_x=tx.reshape(shape), slip_velocity_x=vx.reshape(shape), stick=stick.reshape(shape),
                      creep_force_x=float(tx.sum()) * area)
        q = -tx * vx
        fy = mz = 0.0
        if patch.b is not None:
            ty, vy = sol.traction[1], V * sol.slip[1]
            q = q - ty * vy
            fy = float(ty.sum()) * area
            mz = float((X * ty - Y * tx).sum()) * area
            fields.update(traction_y=ty, slip_velocity_y=vy, creep_force_y=fy, spin_moment=mz)
        fx = fields["creep_force_x"]
        global_power = -V * (xi * fx + eta * fy + phi * mz)
        local_power = float(q.sum()) * area
        diag = {"converged": bool(sol.converged), "iterations": int(sol.iterations), "residual": float(sol.residual),
                "residual_history": np.asarray(sol.history, dtype=float),
                "linear_iterations": int(sol.linear_iterations), "products": int(sol.products),
                "stick_elements": int(np.count_nonzero(sol.stick & inside)),
                "slip_elements": int(np.count_nonzero(~sol.stick & inside)),
                "combined_shear_modulus": G, "combined_poisson_ratio": nu,
                "creepage_longitudinal": xi, "creepage_lateral": eta, "creepage_spin": phi,
                "local_power": local_power, "global_power": global_power, "rolling_order": order, **law_diag}
        return patch.with_tangential(**fields, body_speed=creep_speeds(V, xi), dissipation=q.reshape(shape),
                                     diagnostics=diag)
