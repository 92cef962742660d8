"""Temperature model "fdm": the 3-D finite-difference rail block of seed section 6.3.

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


__all__ = ["FDMTemperature", "choose_scheme", "explicit_cost"]


def _body(scene, i):
    """Material of body i (0 wheel, 1 rail)."""
    return scene.wheel if i == 0 else scene.rail

SCHEMES = ("auto", "explicit", "implicit", "steady")


def explicit_cost(a, b, speed, kappa, d, dt):
    """Estimated node updates of an explicit run: nodes x steps [1]."""
    from .fdm_solvers import block_extent
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
    delta = math.sqrt(2.0 * a * kappa / speed)
    dres = min(d, 0.5 * delta)
    dt = time_step if time_step is not None else min(dres ** 2 / (6.0 * kappa), courant * dres / speed)
    if explicit_cost(a, b, speed, kappa, dres, dt) <= budget:
        return "explicit"
    return "implicit" if mode == "transient" else "steady"


class FDMTemperature(TemperatureModel):
    """3-D finite differences in a rail block with a moving surface heat source (seed 6.3)."""

    name = "fdm"
    description = ("3-D finite-difference block per body (seed 6.3): explicit transient as the paper, "
                   "implicit, or moving-frame steady for stiff cases; insulated sides, fixed far faces, convection")
    capabilities = Capabilities(
        contacts=frozenset({"ellipse"}), sources=frozenset({"computed", "given"}),
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
        from .fdm_solvers import explicit_stability_limit
        if scheme != "explicit" or ts is None:
            return
        lim = explicit_stability_limit(d, kappa, h, rc)
        if ts > lim * (1.0 + 1e-12):
            raise Refused(
                f"model 'fdm' ({body}): the forced explicit time step {ts:.4g} s exceeds the stability limit "
                f"1/(6 kappa/d^2 + 2 h/(rho c d)) = {lim:.4g} s (d = {d:.4g} m, kappa = {kappa:.4g} m^2/s, "
                f"h = {h:g} W/m^2K; without convection d^2/(6 kappa) = {d * d / (6 * kappa):.4g} s); "
                f"use a step <= {lim:.4g} s, or scheme 'implicit' or 'steady'")

    def supports(self, scene, level):
        """Ellipses only (a line contact has no lateral extent). A forced explicit step beyond the
        stability limit is refused by :meth:`compute_temperature`, which knows the cell size
        (a method option)."""
        return super().supports(scene, level)

    # -- compute -------------------------------------------------------------------------------
    def compute_temperature(self, scene, source, level, options):
        from .fdm_solvers import explicit_stability_limit, steady_block, transient_block   # numba on first use
        opts = {**{k: o.default for k, o in self.options.items()}, **(options or {})}
        grid = source.grid
        if grid.line:
            raise Refused("model 'fdm' is three-dimensional: a line contact has no lateral extent; "
                          "use method 'green' or 'fipy' for line contacts")
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
            if scheme == "steady":
                res = steady_block(grid, q, cover, V, m.conductivity, m.density, m.specific_heat, h, d, level=level,
                                   max_cells=float(opts["max_cells"]))
            else:
                res = transient_block(grid, q, cover, V, m.conductivity, m.density, m.specific_heat, h, d,
                                      scheme=scheme, time_step=ts, courant=float(opts["courant"]),
                                      max_nodes=float(opts["max_nodes"]))
            surf[i] = res.surface + m.bulk_temperature
            depth[i] = res.depth + m.bulk_temperature
            zs[i] = res.z
            diag[f"{body}_peclet"] = V * a / (2.0 * kappa)
            diag[f"{body}_scheme"] = scheme
            for k, v in res.diagnostics.items():
                if k != "scheme":
                    diag[f"{body}_{k}"] = v
        diag["scheme"] = diag.get("rail_scheme", diag.get("wheel_scheme"))
        conv = [diag[f"{bd}_converged"] for bd in ("wheel", "rail") if f"{bd}_converged" in diag]
        if conv:
            diag["converged"] = bool(all(conv))
            diag["iterations"] = int(sum(diag.get(f"{bd}_gmres_iterations", 0) for bd in ("wheel", "rail")))
            diag["residual"] = float(max(diag.get(f"{bd}_residual", 0.0) for bd in ("wheel", "rail")))
        z = temp = None
        if "temperature" in tuple(getattr(scene, "outputs", ()) or ()):
            ref = 1 if zs[1] is not None else 0
            if zs[ref] is not None:
                z = zs[ref]
                temp = np.empty((2, nxp, z.size))
                for i in range(2):
                    bulk = _body(scene, i).bulk_temperature
                    if depth[i] is None:
                        temp[i] = bulk
                    elif i == ref:
                        temp[i] = depth[i]
                    else:
                        temp[i] = np.array([np.interp(z, zs[i], row, right=bulk) for row in depth[i]])
        return TemperatureField.from_surface(grid, surf, z=z, temperature=temp, diagnostics=diag)
