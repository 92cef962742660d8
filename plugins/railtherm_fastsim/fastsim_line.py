"""FASTSIM for a line contact (2-D rolling): one strip, one flexibility, longitudinal creepage.

In 2-D the simplified theory has a single strip |x| <= a and a single creepage xi; the traction on the
wheel follows the 3-D rule: from the leading edge x = +a, in adhesion ``p(x) = -(xi / L) (a - x)``, and
where this exceeds the bound ``g = mu p_z`` the traction sits on the bound and the wheel slips. The
flexibility ``L = 4 a (1 - nu) / (pi G)`` reproduces Carter's linear creep law
(:func:`line_flexibility`); beyond the linear range the creep curve is not Carter's
(:func:`fastsim_line_force_ratio`). For the analytic (concave) bounds the continuous strip solution is
integrated exactly over every cell (``integration="exact"``, the default: no discretisation error in
forces and powers, :func:`_exact_cells`); Kalker's discrete sweep is kept as ``integration="sweep"``.

References: J.J. Kalker, Vehicle System Dynamics 11 (1982) 1-13, doi:10.1080/00423118208968684.
F.W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157, doi:10.1098/rspa.1926.0100. K.L. Johnson,
Contact Mechanics, 1985, section 8.4, doi:10.1017/CBO9781139171731.
"""
from __future__ import annotations

import math

import numpy as np

from .simplified_theory import (BOUNDS, LEADING_EDGES, FastsimResult, law_arguments, law_diagnostics,
                                power_diagnostics)

__all__ = ["line_flexibility", "fastsim_line", "fastsim_line_force_ratio", "stick_slip_boundary"]


def line_flexibility(a: float, shear_modulus: float, poisson_ratio: float) -> float:
    """Flexibility of the 2-D simplified theory that reproduces Carter's linear creep law [m/Pa].

    ``L = 4 a (1 - nu) / (pi G)``: FASTSIM's small-creepage force ``-(2 a^2/L) xi`` per unit width
    then equals Carter's ``-(pi a G / (2 (1 - nu))) xi``. Carter's problem for quasi-identical bodies
    gives, for small creepage, ``Fx / (mu N) = -2 xi R / (mu a)`` (the linear term of Carter's
    ``1 - (1 - |xi| R/(mu a))^2``), i.e. with ``N = pi a^2 G / (4 R (1 - nu))`` that force; FASTSIM's
    stick solution gives ``Fx = -(2 a^2 / L) xi``, so equal slopes need this L (about 1.27 a (1 - nu)/G,
    not a (1 - nu)/G). The 2-D linear law in these terms does not involve R, so it also serves bodies
    that are not identical (combined G and nu, :func:`railtherm.physics.combined_elastic`), where Carter's
    theory itself is only approximate.

    Parameters
    ----------
    a : float
        Contact half-width [m].
    shear_modulus : float
        Combined shear modulus G [Pa].
    poisson_ratio : float
        Combined Poisson's ratio nu [1].

    Returns
    -------
    float
        L [m/Pa].

    References
    ----------
    .. [1] F.W. Carter, Proc. R. Soc. Lond. A 112 (1926) 151-157. doi:10.1098/rspa.1926.0100
    """
    return 4.0 * float(a) * (1.0 - float(poisson_ratio)) / (math.pi * float(shear_modulus))


def fastsim_line_force_ratio(s: float) -> float:
    """Exact |Fx| / (mu N) of 2-D FASTSIM (elliptic bound, flexibility :func:`line_flexibility`) [1].

    The creep curve of this simplified theory is *not* Carter's beyond the linear range. With ``c = pi
    s / 2`` the exact curve is ``|Fx| / (mu N) = (2/pi) [c (1 - u*)^2 / 2 + (asin u* + u* sqrt(1 -
    u*^2))/2 + pi/4]``, ``u* = (c^2 - 1)/(c^2 + 1)`` (stick zone u* < x/a <= 1 at the leading edge, slip
    behind it): it approaches 1 only asymptotically (0.927 at s = 1, 0.973 at s = 1.5), and its largest
    deviation from Carter is -0.082 mu N at s = 0.88.

    Parameters
    ----------
    s : float
        Creepage relative to Carter's saturation, ``|xi| R / (mu a)`` [1], >= 0.

    Returns
    -------
    float
        Force ratio in [0, 1); Carter's is ``1 - (1 - s)^2`` for s <= 1 and 1 beyond.
    """
    s = abs(float(s))
    if s == 0.0:
        return 0.0
    c = 0.5 * math.pi * s                   # |xi| a / (L mu p0)
    u = (c * c - 1.0) / (c * c + 1.0)       # stick/slip boundary x/a
    stick = 0.5 * c * (1.0 - u) ** 2
    slip = 0.5 * (math.asin(u) + u * math.sqrt(max(0.0, 1.0 - u * u))) + 0.25 * math.pi
    return 2.0 / math.pi * (stick + slip)


def _bound_antiderivative(bound, u):
    """Antiderivative of the bound shape f(u) (Hertz sqrt(1 - u^2) or parabola 1 - u^2) [1]."""
    u = np.clip(u, -1.0, 1.0)
    if bound == "elliptic":
        return 0.5 * (u * np.sqrt(1.0 - u * u) + np.arcsin(u))
    return u - u ** 3 / 3.0


def _bound_shape(bound, u):
    u = np.clip(u, -1.0, 1.0)
    return np.sqrt(1.0 - u * u) if bound == "elliptic" else 1.0 - u * u


def stick_slip_boundary(c: float, bound: str = "elliptic") -> float:
    """Position u* = x*/a where the stick traction ``c (1 - u)`` meets the bound (slip for u < u*) [1].

    Parameters
    ----------
    c : float
        ``|xi| a / (L g0)`` with g0 the peak of the bound (mu p0 or mu 3N/(4a)) [1].
    bound : {"elliptic", "parabolic"}
        Bound shape sqrt(1 - u^2) or 1 - u^2 (both concave: one stick zone at the leading edge).
    """
    if c <= 0.0:
        return -1.0
    if bound == "elliptic":
        return (c * c - 1.0) / (c * c + 1.0)
    return min(max(c - 1.0, -1.0), 1.0)


def _exact_cells(x_edges, a, bound, g0, xi, L, speed):
    """Cell averages of the continuous 2-D FASTSIM solution (concave analytic bound g0 f(x/a)).

    The stick/slip boundary is a single point x*, where ``|xi| (a - x)/L`` meets the bound; for the
    analytic bounds (Hertz, parabolic: both concave, so one stick zone at the leading edge and slip
    behind it) the strip solution is integrated exactly over every cell: forces and powers have no
    discretisation error. The power density ``-p . s`` with the slip velocity of the wheel relative to
    the rail ``s = V (xi - L dp/dx)`` is zero in stick and ``V g (|xi| + L dg/dx)`` in slip (more heat in
    the trailing half, where g falls); its integral equals the global ``-V xi Fx`` exactly (the elastic
    energy stored in the stick zone, ``L g(x*)^2/2``, is released in the slip zone). Kalker's discrete
    sweep (``integration="sweep"``) misses it by ``V L sum((Delta p)^2)/2``, first order in the cell
    size, and gives no power while the slip zone is narrower than a cell; its force converges at second
    order (the stick/slip kink inside one cell).

    Returns traction (signed, on the wheel), slip velocity, power density, stick indicator (cell
    centre) and the stick/slip boundary x* [m].
    """
    dx = np.diff(x_edges)
    xc = 0.5 * (x_edges[1:] + x_edges[:-1])
    lo = np.clip(x_edges[:-1], -a, a)
    hi = np.clip(x_edges[1:], -a, a)
    k = abs(xi) / L                                       # stick traction slope [Pa/m]
    sigma = -math.copysign(1.0, xi) if xi != 0 else 0.0
    if xi == 0:
        us = -1.0                                         # no creepage: stick, no traction
    elif g0 <= 0.0:
        us = 1.0                                          # no friction: slip everywhere, no traction
    else:
        us = stick_slip_boundary(k * a / g0, bound)
    xs = us * a
    # stick part [max(lo, xs), hi], slip part [lo, min(hi, xs)]
    s_lo, s_hi = np.maximum(lo, xs), hi
    st = s_hi > s_lo
    stick_int = np.where(st, k * ((a - s_lo) ** 2 - (a - s_hi) ** 2) / 2.0, 0.0)      # int k (a - x) dx
    p_lo, p_hi = lo, np.minimum(hi, xs)
    sl = p_hi > p_lo
    F = lambda x: g0 * a * _bound_antiderivative(bound, x / a)  # noqa: E731
    gv = lambda x: g0 * _bound_shape(bound, x / a)  # noqa: E731
    slip_int = np.where(sl, F(p_hi) - F(p_lo), 0.0)                                   # int g dx
    g_hi, g_lo = np.where(sl, gv(p_hi), 0.0), np.where(sl, gv(p_lo), 0.0)
    traction = sigma * (stick_int + slip_int) / dx
    # slip velocity of the wheel relative to the rail V (xi - L dp/dx); power -p.s = V g (|xi| + L g')
    slip = np.where(sl, speed * (xi * (p_hi - p_lo) - L * sigma * (g_hi - g_lo)), 0.0) / dx
    power = np.where(sl, speed * (abs(xi) * slip_int + 0.5 * L * (g_hi ** 2 - g_lo ** 2)), 0.0) / dx
    inside = (xc > -a) & (xc < a)
    stick = np.where(inside, (xc >= xs).astype(float), np.nan)
    return traction, slip, power, stick, xs


# over 80 lines only through its docstring (the public line FASTSIM call's parameters); the body is 36 lines
def fastsim_line(grid, pressure, *, a, normal_force, friction, shear_modulus, poisson_ratio, xi, speed,
                 bound="elliptic", leading_edge="exact", flexibility=None, integration=None, slip_law=None):
    """FASTSIM on a line contact: traction, slip, stick, creep force and power per unit width.

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Line grid (``y_edges`` None) covering |x| <= a, uniform, x ascending, leading edge at +a.
    pressure : ndarray (nx,)
        Normal pressure [Pa] (cell averages as core's Hertz model gives them).
    a : float
        Half-width [m].
    normal_force : float
        Load per unit width N [N/m].
    friction : float or ndarray (nx,)
        mu [1], one value or one per cell (a temperature law: the sweep runs); with ``slip_law`` ignored.
    shear_modulus, poisson_ratio : float
        Combined G [Pa] and nu [1].
    xi : float
        Longitudinal creepage [1] (positive gives a negative force on the wheel).
    speed : float
        Rolling speed V [m/s].
    bound : {"elliptic", "parabolic"}
        Traction bound mu p with the given pressure, or Kalker's parabolic bound
        ``mu (3 N / (4 a)) (1 - x^2/a^2)`` (same load), which then also replaces the pressure.
    leading_edge : {"exact", "contact"}
        ``"exact"``: the strip starts at x = +a; ``"contact"``: CONTACT's full first step dx from
        zero traction (discrete sweep).
    flexibility : float, optional
        L [m/Pa]; default :func:`line_flexibility`.
    integration : {"exact", "sweep"}, optional
        ``"exact"`` (default with ``leading_edge="exact"``): the continuous strip solution -- stick
        from the leading edge to the point x* where ``|xi| (a - x)/L`` meets the bound, slip behind
        it -- integrated exactly over every cell, for the analytic bounds: the Hertz bound
        ``mu p0 sqrt(1 - x^2/a^2)``, p0 = 2N/(pi a) (used when the given pressure is the Hertzian
        one to 1e-9; otherwise the sweep runs), or the parabolic one. The fields are cell averages
        (the stick map is taken at the cell centres), the force and the local power have no
        discretisation error, and the local power equals the global ``-V xi Fx`` exactly.
        ``"sweep"``: Kalker's discrete sweep (:func:`.fastsim_kernel.fastsim_sweep`, one strip; the seed's
        modified FASTSIM as in 3-D): tractions at the cell centres, power ``-p.s`` per cell. A friction
        that varies (per cell, or ``slip_law``) always runs the sweep.
    slip_law : railtherm.physics.friction.SlipVelocityFriction, optional
        Exponential slip-velocity law, solved cell by cell in the sweep
        (:func:`railtherm_fastsim.simplified_theory.fastsim`).

    Returns
    -------
    FastsimResult
        Fields of shape (nx,); ``creep_force_x`` [N/m], ``local_power`` and ``global_power`` [W/m];
        ``creep_force_y`` and ``spin_moment`` are 0.
    """
    if not grid.line:
        raise ValueError("fastsim_line needs a line grid (y_edges None)")
    if bound not in BOUNDS:
        raise ValueError(f"bound must be one of {BOUNDS}, got {bound!r}")
    if leading_edge not in LEADING_EDGES:
        raise ValueError(f"leading_edge must be one of {LEADING_EDGES}, got {leading_edge!r}")
    if integration is None:
        integration = "exact" if leading_edge == "exact" else "sweep"
    if integration not in ("exact", "sweep"):
        raise ValueError(f"integration must be 'exact' or 'sweep', got {integration!r}")
    if slip_law is not None or np.ndim(friction) > 0:
        integration = "sweep"                  # the continuous solution is for one constant mu
        mu = 1.0 if slip_law is not None else np.asarray(friction, dtype=float).reshape(-1)
        friction = float(np.max(mu))           # g0 (unused by the sweep)
    else:
        mu = friction
    dq = float(grid.dx)
    p, g0, integration = _line_bound(grid, pressure, a, normal_force, friction, bound, integration)
    L = float(flexibility) if flexibility is not None else line_flexibility(a, shear_modulus, poisson_ratio)
    diag = {"flexibility_L1": L, "flexibility": "line (Carter's linear slope)", "bound": bound,
            "leading_edge": leading_edge, "integration": integration}
    if integration == "exact":
        tx, sx, pd, stick, xs = _exact_cells(grid.x_edges, float(a), bound, g0, float(xi), L, float(speed))
        nstick = int(np.nansum(stick))
        nslip = int(np.sum(stick == 0.0))
        diag["stick_slip_boundary"] = xs
    else:
        tx, sx, pd, stick, nstick, nslip = _sweep_cells(grid, p, mu, a, xi, L, speed, leading_edge, slip_law, diag)
    Fx = float(tx.sum()) * dq
    P = float(pd.sum()) * dq
    Gp = -speed * xi * Fx
    diag.update({"stick_cells": int(nstick), "slip_cells": int(nslip), **power_diagnostics(P, Gp),
                 "creepage_longitudinal": float(xi), "creepage_lateral": 0.0, "creepage_spin": 0.0})
    return FastsimResult(tx, np.zeros_like(tx), sx, np.zeros_like(tx), stick, pd, p, Fx, 0.0, 0.0, P, Gp, diag)


def _line_bound(grid, pressure, a, normal_force, friction, bound, integration):
    """The pressure of every cell [Pa], the bound's peak g0 [Pa] and the integration that applies:
    ``"exact"`` falls back to ``"sweep"`` when the given pressure is not the Hertzian one."""
    dq = float(grid.dx)
    lo = np.clip(grid.x_edges[:-1], -a, a)
    hi = np.clip(grid.x_edges[1:], -a, a)
    if bound == "parabolic":
        # cell averages of (3N/4a)(1 - x^2/a^2) over the part of each cell inside |x| <= a
        p = 0.75 * normal_force / a * ((hi - lo) - (hi ** 3 - lo ** 3) / (3 * a * a)) / dq
        g0 = friction * 0.75 * normal_force / a
    else:
        p = np.asarray(pressure, dtype=float).reshape(-1)
        p0 = 2.0 * normal_force / (math.pi * a)
        g0 = friction * p0
        if integration == "exact":
            hz = p0 * a * (_bound_antiderivative("elliptic", hi / a) - _bound_antiderivative("elliptic", lo / a)) / dq
            if not np.allclose(p, hz, rtol=1e-9, atol=1e-9 * p0):
                integration = "sweep"          # not the Hertzian pressure: the analytic bound does not apply
    return p, g0, integration


def _sweep_cells(grid, p, mu, a, xi, L, speed, leading_edge, slip_law, diag):
    """Kalker's discrete sweep on the one strip: traction, slip velocity, power density, stick map (cell
    values, scaled by the inside fraction) and the stick and slip cell counts; the slip law's
    diagnostics go into ``diag``."""
    from .fastsim_kernel import sweep_kernel  # numba: loaded when a line is first swept, not when the plugin loads

    x = np.ascontiguousarray(grid.x, dtype=float)
    dq = float(grid.dx)
    lo = np.clip(grid.x_edges[:-1], -a, a)
    hi = np.clip(grid.x_edges[1:], -a, a)
    # inside fraction of each cell (the grid spans [-a, a]: 1 everywhere unless cells stick out)
    frac = np.clip((hi - lo) / dq, 0.0, 1.0)
    frac = np.where(p > 0, frac, 0.0)
    inside = frac > 1e-12
    g = np.where(inside, mu * p / np.where(inside, frac, 1.0), 0.0)
    mode = 1 if leading_edge == "exact" else 0
    lead = np.array([float(a) if mode == 1 else x[np.nonzero(inside)[0][-1]] + 0.5 * dq])
    shape = (x.size, 1)
    px, py, sxx, syy, st, power = (np.empty(shape) for _ in range(6))
    law = law_arguments(slip_law)
    out = sweep_kernel(law[0])(x, np.zeros(1), np.ascontiguousarray(g.reshape(shape)), lead, float(xi), 0.0, 0.0,
                               L, L, L, float(speed), 0.5 * dq, mode, *law, px, py, sxx, syy, st, power)
    diag.update(law_diagnostics(slip_law, out))
    return px[:, 0] * frac, sxx[:, 0].copy(), power[:, 0] * frac, st[:, 0].copy(), out[4], out[5]
