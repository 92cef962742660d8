"""Temperature model "fdm": the 3-D finite-difference rail block of seed section 6.3.

Line contacts run the 2-D (x-z) block of :mod:`railtherm_fastsim.fdm_line` (the 3-D block with a
laterally uniform source, exactly), see :meth:`FDMTemperature._compute_line`.

Each body (wheel and rail) is treated as the seed treats the rail: a block whose top face carries
the body's share of the heat source moving at the body's speed relative to the contact. (For the
wheel this is its flash temperature in one pass of the contact; the heating over revolutions is not
modelled.) The schemes -- ``explicit`` (the seed's), ``implicit`` and the moving-frame ``steady``
one for stiff cases -- are described in :mod:`railtherm_fastsim.fdm_solvers`.

Scheme choice: ``scene.numerics["scheme"]`` if the scene sets it, else the method option ``scheme``;
``"auto"`` (:func:`choose_scheme`) takes the explicit scheme when an explicit run with cells that
resolve the flash layer costs at most the option ``budget`` node updates, and otherwise the steady
scheme (or the implicit one when ``scene.mode`` is "transient").

Reported surface temperature: the transient schemes run until the source has travelled ``travel``
(:func:`railtherm_fastsim.fdm_solvers.block_extent`); the surface field in the frame of the patch at
that time is the result. It is declared quasi-steady when it differs by less than 0.2 % of its
maximum from the same field sampled one semi-axis of travel earlier (at the same offset to the
grid); diagnostics ``<body>_quasi_steady_change`` and ``<body>_quasi_steady``.
"""
from __future__ import annotations

import math

import numpy as np
from railtherm import Capabilities, Option, Refused, TemperatureField, TemperatureModel
from railtherm.physics import peclet_number, thermal_scales


__all__ = ["FDMTemperature", "choose_scheme", "explicit_cost"]


def _body(scene, i):
    """Material of body i (0 wheel, 1 rail)."""
    return scene.wheel if i == 0 else scene.rail

SCHEMES = ("auto", "explicit", "implicit", "steady")
#: cost of one implicit step of the 2-D block in explicit node updates per node (CG or LU solve)
IMPLICIT_COST_FACTOR = 50.0


def _depth_field(scene, nx, zs, depth):
    """Temperature against depth at y = 0 for both bodies on one depth grid [degC].

    The rail's depths (else the wheel's) are used; the other body is interpolated onto them (bulk
    temperature below its own block). A body without heat is at its bulk temperature; when neither
    body is heated the field is the bulk temperature at z = 0.
    """
    ref = 1 if zs[1] is not None else 0
    z = zs[ref] if zs[ref] is not None else np.zeros(1)
    temp = np.empty((2, nx, z.size))
    for i in range(2):
        bulk = _body(scene, i).bulk_temperature
        if depth[i] is None:
            temp[i] = bulk
        elif i == ref:
            temp[i] = depth[i]
        else:
            temp[i] = np.array([np.interp(z, zs[i], row, right=bulk) for row in depth[i]])
    return z, temp


def explicit_cost(a, b, speed, kappa, d, dt):
    """Estimated node updates of an explicit run: nodes x steps [1]."""
    from .block3d import block_extent
    ext = block_extent(a, b, speed, kappa)
    nx = (ext.behind + 2 * a + ext.travel + ext.ahead) / d + 3
    ny = 2 * (b + ext.lateral) / d + 1
    nz = ext.depth / d + 1
    steps = ext.travel / (speed * dt) + 1
    return nx * ny * nz * steps


def choose_scheme(requested, mode, a, b, speed, kappa, d, budget, *, time_step=None, dt_limit=math.inf,
                  courant=1.0):
    """The scheme to run: ``requested`` unless "auto".

    "auto" takes the explicit scheme when an explicit run whose cubic cells resolve the flash layer
    -- cell ``d* = min(d, delta/2)`` with the contact-time penetration depth
    delta = sqrt(2 a kappa / V) -- costs at most ``budget`` node updates; otherwise the case is
    stiff (high speed: micrometre cells, millions of steps and nodes) and the moving-frame steady
    scheme runs (the implicit one when ``mode`` is "transient"). A forced step ``time_step`` beyond
    the explicit stability limit ``dt_limit`` selects the implicit scheme.
    """
    if requested != "auto":
        return requested
    if time_step is not None and time_step > dt_limit * (1.0 + 1e-12):
        return "implicit"
    delta = thermal_scales(a, speed, kappa).thermal_depth
    dres = min(d, 0.5 * delta)
    dt = time_step if time_step is not None else min(dres ** 2 / (6.0 * kappa), courant * dres / speed)
    if explicit_cost(a, b, speed, kappa, dres, dt) <= budget:
        return "explicit"
    return "implicit" if mode == "transient" else "steady"


class FDMTemperature(TemperatureModel):
    """Finite differences in a rail block with a moving surface heat source (seed 6.3): 3-D for an
    elliptical patch, 2-D (x-z, per unit width) for a line contact."""

    name = "fdm"
    description = ("finite-difference block per body (seed 6.3; 3-D, or 2-D for line contacts): explicit "
                   "transient as the paper, implicit, or moving-frame steady for stiff cases; insulated sides, "
                   "fixed far faces, convection")
    capabilities = Capabilities(
        contacts=frozenset({"ellipse", "line"}), sources=frozenset({"computed", "given"}),
        tangential=frozenset({"full-sliding", "creepage"}), convection=True,
        modes=frozenset({"steady", "transient"}),
        provides=frozenset({"surface_temperature", "max_surface_temperature", "mean_contact_temperature",
                            "temperature"}))
    options = {
        "scheme": Option("auto", "'explicit' (seed), 'implicit', 'steady' (moving frame) or 'auto'",
                         choices=SCHEMES),
        "cell_size": Option(0.0, "cell size d at level 0 [m]; 0: 2 min(a, b)/8", minimum=0.0),
        "courant": Option(1.0, "transient schemes: source advance per step in cells (capped by stability)",
                          minimum=1e-6),
        "budget": Option(4e9, "'auto': largest explicit cost in node updates", minimum=0.0),
        "threads": Option(0, "numba threads for the explicit stencil (0: numba's default)", minimum=0),
        "max_nodes": Option(5e7, "transient schemes: largest node count of the block (refused above)", minimum=1),
        "max_cells": Option(4e6, "steady scheme: largest cell count of the graded grid (refused above)", minimum=1),
        "line_x_scheme": Option("upwind2", "line contacts, steady scheme: fluxes along x 'upwind2' (second-order "
                                           "upwind, default) or 'exponential' (as the 3-D block)",
                                choices=("upwind2", "exponential")),
    }

    # -- helpers -------------------------------------------------------------------------------
    @staticmethod
    def _cell(options, a, b, level):
        d0 = float(options.get("cell_size") or 0.0) or 2.0 * min(a, b) / 8.0
        return d0 / 2 ** int(level)

    @staticmethod
    def _requested(scene, options):
        num = dict(scene.numerics or {})
        return num.get("scheme") or options.get("scheme") or "auto"

    def _check_step(self, scheme, ts, d, kappa, h, rc, body):
        from .block3d import explicit_stability_limit
        if scheme != "explicit" or ts is None:
            return
        lim = explicit_stability_limit(d, kappa, h, rc)
        if ts > lim * (1.0 + 1e-12):
            raise Refused(
                f"model 'fdm' ({body}): the forced explicit time step {ts:.4g} s exceeds the stability limit "
                f"1/(6 kappa/d^2 + 2 h/(rho c d)) = {lim:.4g} s (d = {d:.4g} m, kappa = {kappa:.4g} m^2/s, "
                f"h = {h:g} W/m^2K; without convection d^2/(6 kappa) = {d * d / (6 * kappa):.4g} s); "
                f"use a step <= {lim:.4g} s, or scheme 'implicit' or 'steady'")

    #: below this Péclet number the steady 3-D block's iterative solve does not converge
    STEADY_PECLET_MIN = 0.1

    def supports(self, scene, level):
        """Ellipses (3-D block) and line contacts (2-D block). A forced explicit step beyond the
        stability limit is refused by :meth:`compute_temperature`, which knows the cell size
        (a method option)."""
        return super().supports(scene, level)

    # -- compute -------------------------------------------------------------------------------
    def compute_temperature(self, scene, source, level, options):
        from .block3d import explicit_stability_limit, steady_block, transient_block   # numba on first use
        opts = options                                  # resolved by core (pipeline)
        grid = source.grid
        if grid.line:
            return self._compute_line(scene, source, level, opts)
        threads = int(opts.get("threads") or 0)
        if threads > 0:
            import numba
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        a, b = float(grid.a), float(grid.b)
        d = self._cell(opts, a, b, level)
        num = dict(scene.numerics or {})
        ts = num.get("time_step")
        ts = float(ts) if ts is not None else None
        requested = self._requested(scene, opts)
        h = float(scene.convection or 0.0)
        cover = grid.inside().astype(float)
        nxp, nyp = grid.shape
        surf = np.zeros((2, nxp, nyp))
        depth = [None, None]
        zs = [None, None]
        diag = {"cell_size": d, "requested_scheme": requested}
        for i, body in enumerate(("wheel", "rail")):
            m = _body(scene, i)
            q = np.asarray(source.flux(i), dtype=float)
            surf[i] = m.bulk_temperature
            if not np.any(q > 0):
                diag[f"{body}_scheme"] = "none (no heat)"
                continue
            V = float(source.body_speed[i])
            rc = m.density * m.specific_heat
            kappa = m.conductivity / rc
            lim = explicit_stability_limit(d, kappa, h, rc)
            scheme = choose_scheme(requested, getattr(scene, "mode", "steady"), a, b, V, kappa, d,
                                   float(opts["budget"]), time_step=ts, dt_limit=lim,
                                   courant=float(opts["courant"]))
            self._check_step(scheme, ts, d, kappa, h, rc, body)
            pe = peclet_number(V, a, kappa)
            if scheme == "steady" and pe < self.STEADY_PECLET_MIN:
                raise Refused(
                    f"model 'fdm' ({body}): Péclet number V a/(2 kappa) = {pe:.3g} < {self.STEADY_PECLET_MIN:g}: the "
                    "moving-frame steady block is diffusion-dominated there and its GMRES+ILU solve does not "
                    "converge (stability study: 400 iterations, residual 0.05 at Péclet 0.01); use method 'fipy' "
                    "or the exact railtherm.references.moving_source")
            if scheme == "steady":
                res = steady_block(grid, q, cover, V, m.conductivity, m.density, m.specific_heat, h, d, level=level,
                                   max_cells=float(opts["max_cells"]))
            else:
                res = transient_block(grid, q, cover, V, m.conductivity, m.density, m.specific_heat, h, d,
                                      scheme=scheme, time_step=ts, courant=float(opts["courant"]),
                                      max_nodes=float(opts["max_nodes"]))
            _record_body(diag, surf, depth, zs, i, body, m, res, peclet_number(V, a, kappa), scheme, grid.integrate(q))
        _summarise(diag)
        z = temp = None
        if "temperature" in tuple(getattr(scene, "outputs", ()) or ()):
            z, temp = _depth_field(scene, grid.shape[0], zs, depth)
        return TemperatureField.from_surface(grid, surf, z=z, temperature=temp, diagnostics=diag)

    # -- line contacts (2-D block) ----------------------------------------------------------------
    def _compute_line(self, scene, source, level, opts):
        """The 2-D (x-z) block of :mod:`railtherm_fastsim.fdm_line` for each body.

        Cells: along x over the band ``cell_size`` (default 2a/16) halved per level (steady scheme,
        graded depth grid from ``min(cell, delta/4/2**level)``); the transient schemes use a uniform
        node spacing ``min(cell_size, delta/2) / 2**level`` that resolves the contact-time
        penetration depth delta = sqrt(2 a kappa / V) from level 0 on. ``"auto"``: the steady
        scheme for ``scene.mode == "steady"`` (the quantity asked for, directly); for transient
        scenes the explicit scheme when its cost is within ``budget`` node updates, else the
        implicit one (one step counted as :data:`IMPLICIT_COST_FACTOR` updates per node, measured),
        else refused.
        """
        from .block2d import line_extent, line_stability_limit, steady_line, transient_line
        grid = source.grid
        a = float(grid.a)
        cell0 = float(opts.get("cell_size") or 0.0) or 2.0 * a / 16.0
        cell = cell0 / 2 ** int(level)
        num = dict(scene.numerics or {})
        ts = num.get("time_step")
        ts = float(ts) if ts is not None else None
        requested = self._requested(scene, opts)
        mode = getattr(scene, "mode", "steady")
        h = float(scene.convection or 0.0)
        cover = grid.inside().astype(float)
        surf = np.zeros((2, grid.shape[0]))
        depth, zs = [None, None], [None, None]
        diag = {"cell_size": cell, "requested_scheme": requested, "dimension": 2}
        for i, body in enumerate(("wheel", "rail")):
            m = _body(scene, i)
            q = np.asarray(source.flux(i), dtype=float)
            surf[i] = m.bulk_temperature
            if not np.any(q > 0):
                diag[f"{body}_scheme"] = "none (no heat)"
                continue
            V = float(source.body_speed[i])
            if not V > 0.0:
                raise Refused(f"model 'fdm' ({body}, line): the {body} surface moves at {V:g} m/s relative to the "
                              "contact; the 2-D block needs a body moving through the contact (speed > 0): a "
                              "line source at rest on a half-plane has no steady state")
            rc = m.density * m.specific_heat
            kappa = m.conductivity / rc
            delta = thermal_scales(a, V, kappa).thermal_depth
            d = min(cell0, 0.5 * delta) / 2 ** int(level)
            lim = line_stability_limit(d, kappa, h, rc)
            scheme = requested
            if scheme == "auto":
                if ts is not None and ts > lim * (1.0 + 1e-12):
                    scheme = "implicit"
                elif mode != "transient":
                    scheme = "steady"
                else:
                    ext = line_extent(a, V, kappa)
                    nodes = ((ext.behind + 2 * a + ext.travel + ext.ahead) / d) * (ext.depth / d)
                    dt = ts if ts is not None else min(lim, float(opts["courant"]) * d / V)
                    cost_exp = nodes * ext.travel / (V * dt)
                    dt_imp = ts if ts is not None else float(opts["courant"]) * d / V
                    cost_imp = IMPLICIT_COST_FACTOR * nodes * ext.travel / (V * dt_imp)
                    budget = float(opts["budget"])
                    if cost_exp <= budget:
                        scheme = "explicit"
                    elif cost_imp <= budget:
                        scheme = "implicit"
                    else:
                        raise Refused(kind="budget", message=
                            f"model 'fdm' ({body}, line): a transient 2-D run at level {level} costs about "
                            f"{min(cost_exp, cost_imp):.3g} node updates (explicit {cost_exp:.3g}, implicit "
                            f"~{cost_imp:.3g}), above the option budget = {budget:.3g} (Péclet number "
                            f"{peclet_number(V, a, kappa):.3g}, cells {d:.3g} m resolving the flash layer); use "
                            "mode 'steady' or scheme 'steady' (the moving-frame quasi-steady state), a lower "
                            "level, or a larger budget")
            if scheme == "explicit" and ts is not None and ts > lim * (1.0 + 1e-12):
                raise Refused(
                    f"model 'fdm' ({body}, line): the forced explicit time step {ts:.4g} s exceeds the 2-D stability "
                    f"limit 1/(4 kappa/d^2 + 2 h/(rho c d)) = {lim:.4g} s (d = {d:.4g} m, kappa = {kappa:.4g} m^2/s, "
                    f"h = {h:g} W/m^2K); use a step <= {lim:.4g} s, or scheme 'implicit' or 'steady'")
            args = (grid, q, cover, V, m.conductivity, m.density, m.specific_heat, h)
            if scheme == "steady":
                res = steady_line(*args, cell, level=level, x_scheme=opts["line_x_scheme"],
                                  max_cells=float(opts["max_cells"]))
            else:
                res = transient_line(*args, d, scheme=scheme, time_step=ts, courant=float(opts["courant"]),
                                     max_nodes=float(opts["max_nodes"]))
            _record_body(diag, surf, depth, zs, i, body, m, res, peclet_number(V, a, kappa), scheme, grid.integrate(q))
        _summarise(diag)
        z = temp = None
        if "temperature" in tuple(getattr(scene, "outputs", ()) or ()):
            z, temp = _depth_field(scene, grid.shape[0], zs, depth)
        return TemperatureField.from_surface(grid, surf, z=z, temperature=temp, diagnostics=diag)


def _record_body(diag, surf, depth, zs, i, body, m, res, peclet, scheme, power):
    """Store body ``i``'s absolute surface and depth fields and its prefixed solver diagnostics.

    ``power`` is the heat put into the body [W] ([W/m] for a line contact), the weight of its
    ``heat_balance_error`` in the model's overall one.
    """
    surf[i] = res.surface + m.bulk_temperature
    depth[i] = res.depth + m.bulk_temperature
    zs[i] = res.z
    diag[f"{body}_peclet"] = peclet
    diag[f"{body}_power"] = float(power)
    diag[f"{body}_scheme"] = scheme
    for k, v in res.diagnostics.items():
        if k != "scheme":
            diag[f"{body}_{k}"] = v


def _summarise(diag):
    """Overall scheme and the verdict keys (docs/verdicts.md) from the per-body diagnostics.

    ``converged``: every heated body's solve converged (GMRES / every implicit step's CG to its own
    tolerance; LU and explicit stepping are direct); ``iterations``: their sum (0 when direct);
    ``residual``: the worst relative residual [1]; ``heat_balance_error``: the bodies' balances weighted
    by the heat put into each, (heat carried out or stored by the field - heat put in) / heat put in [1].
    A model run with no heated body did nothing iterative: converged, 0 iterations, residual 0.
    """
    diag["scheme"] = diag.get("rail_scheme", diag.get("wheel_scheme"))
    bodies = [bd for bd in ("wheel", "rail") if f"{bd}_converged" in diag]
    diag["converged"] = bool(all(diag[f"{bd}_converged"] for bd in bodies))
    diag["iterations"] = int(sum(int(diag.get(f"{bd}_iterations", 0)) for bd in bodies))
    diag["residual"] = float(max([float(diag.get(f"{bd}_residual", 0.0)) for bd in bodies] or [0.0]))
    pairs = [(float(diag.get(f"{bd}_power", 0.0)), float(diag[f"{bd}_heat_balance_error"]))
             for bd in bodies if f"{bd}_heat_balance_error" in diag]
    total = sum(p for p, _ in pairs)
    if pairs and total > 0:
        diag["heat_balance_error"] = float(sum(p * e for p, e in pairs) / total)
