"""Which scheme of the finite-difference block runs, and the forced steps it refuses.

Scheme choice: the scene's ``numerics["scheme"]`` if it sets it, else the method option ``scheme``
(:func:`requested_scheme`). ``"auto"`` picks, per body, the explicit scheme (the seed's) when it is
affordable and otherwise the moving-frame steady scheme -- or the implicit one when the scene asks
for a transient (:func:`choose_scheme` for the 3-D block, :func:`choose_line_scheme` for the 2-D
block of a line contact). A forced explicit step beyond the stability limit is refused
(:func:`check_explicit_step`).
"""
from __future__ import annotations

import math

from railtherm import Refused
from railtherm.physics import peclet_number, thermal_scales

from .layout import block_extent, line_extent

__all__ = ["SCHEMES", "IMPLICIT_COST_FACTOR", "requested_scheme", "explicit_cost", "choose_scheme",
           "choose_line_scheme", "check_explicit_step"]

SCHEMES = ("auto", "explicit", "implicit", "steady")
#: cost of one implicit step of the 2-D block in explicit node updates per node (CG or LU solve)
IMPLICIT_COST_FACTOR = 50.0


def requested_scheme(numerics, options) -> str:
    """The scheme asked for: ``numerics["scheme"]`` (the scene's ``numerics`` mapping, or None), else the
    option ``scheme`` ("auto" when neither is set)."""
    num = dict(numerics or {})
    return num.get("scheme") or options["scheme"] or "auto"


def explicit_cost(a, b, speed, kappa, d, dt):
    """Estimated node updates of an explicit 3-D run: nodes x steps [1].

    Parameters
    ----------
    a, b : float
        Semi-axes of the patch [m].
    speed : float
        Body speed relative to the contact [m/s].
    kappa : float
        Diffusivity [m^2/s].
    d : float
        Node spacing [m].
    dt : float
        Time step [s].
    """
    ext = block_extent(a, b, speed, kappa)
    nx = (ext.behind + 2 * a + ext.travel + ext.ahead) / d + 3
    ny = 2 * (b + ext.lateral) / d + 1
    nz = ext.depth / d + 1
    steps = ext.travel / (speed * dt) + 1
    return nx * ny * nz * steps


def choose_scheme(requested, mode, a, b, speed, kappa, d, budget, *, time_step=None, dt_limit=math.inf,
                  courant=1.0):
    """The scheme of the 3-D block: ``requested`` unless "auto".

    "auto" takes the explicit scheme when an explicit run whose cubic cells resolve the flash layer
    -- cell ``d* = min(d, delta/2)`` with the contact-time penetration depth
    delta = sqrt(2 a kappa / V) -- costs at most ``budget`` node updates (:func:`explicit_cost`);
    otherwise the case is stiff (high speed: micrometre cells, millions of steps and nodes) and the
    moving-frame steady scheme runs (the implicit one when ``mode`` is "transient"). A forced step
    ``time_step`` beyond the explicit stability limit ``dt_limit`` [s] selects the implicit scheme.
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


def choose_line_scheme(requested, mode, a, speed, kappa, d, budget, *, time_step=None, dt_limit=math.inf,
                       courant=1.0, body="rail", level=0):
    """The scheme of the 2-D block of a line contact: ``requested`` unless "auto".

    "auto": the implicit scheme for a forced step beyond the stability limit ``dt_limit``; the
    steady scheme for a steady scene (the quantity asked for, directly); for a transient scene the
    explicit scheme when its cost is within ``budget`` node updates, else the implicit one (one step
    counted as :data:`IMPLICIT_COST_FACTOR` updates per node, measured), else refused.

    Raises
    ------
    railtherm.Refused
        (kind "budget") when neither transient scheme fits in ``budget``.
    """
    if requested != "auto":
        return requested
    if time_step is not None and time_step > dt_limit * (1.0 + 1e-12):
        return "implicit"
    if mode != "transient":
        return "steady"
    ext = line_extent(a, speed, kappa)
    nodes = ((ext.behind + 2 * a + ext.travel + ext.ahead) / d) * (ext.depth / d)
    dt = time_step if time_step is not None else min(dt_limit, courant * d / speed)
    cost_exp = nodes * ext.travel / (speed * dt)
    dt_imp = time_step if time_step is not None else courant * d / speed
    cost_imp = IMPLICIT_COST_FACTOR * nodes * ext.travel / (speed * dt_imp)
    if cost_exp <= budget:
        return "explicit"
    if cost_imp <= budget:
        return "implicit"
    raise Refused(kind="budget", message=
                  f"model 'fdm' ({body}, line): a transient 2-D run at level {level} costs about "
                  f"{min(cost_exp, cost_imp):.3g} node updates (explicit {cost_exp:.3g}, implicit "
                  f"~{cost_imp:.3g}), above the option budget = {budget:.3g} (Péclet number "
                  f"{peclet_number(speed, a, kappa):.3g}, cells {d:.3g} m resolving the flash layer); use "
                  "mode 'steady' or scheme 'steady' (the moving-frame quasi-steady state), a lower "
                  "level, or a larger budget")


def check_explicit_step(scheme, time_step, limit, *, d, kappa, h, body, line=False):
    """Refuse a forced explicit ``time_step`` [s] beyond the stability ``limit`` [s] (any other case passes).

    Raises
    ------
    railtherm.Refused
        (kind "validity") naming the limit, the values and what works instead.
    """
    if scheme != "explicit" or time_step is None or not time_step > limit * (1.0 + 1e-12):
        return
    if line:
        raise Refused(
            f"model 'fdm' ({body}, line): the forced explicit time step {time_step:.4g} s exceeds the 2-D stability "
            f"limit 1/(4 kappa/d^2 + 2 h/(rho c d)) = {limit:.4g} s (d = {d:.4g} m, kappa = {kappa:.4g} m^2/s, "
            f"h = {h:g} W/m^2K); use a step <= {limit:.4g} s, or scheme 'implicit' or 'steady'")
    raise Refused(
        f"model 'fdm' ({body}): the forced explicit time step {time_step:.4g} s exceeds the stability limit "
        f"1/(6 kappa/d^2 + 2 h/(rho c d)) = {limit:.4g} s (d = {d:.4g} m, kappa = {kappa:.4g} m^2/s, "
        f"h = {h:g} W/m^2K; without convection d^2/(6 kappa) = {d * d / (6 * kappa):.4g} s); "
        f"use a step <= {limit:.4g} s, or scheme 'implicit' or 'steady'")
