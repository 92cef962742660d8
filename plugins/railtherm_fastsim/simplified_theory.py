"""Kalker's FASTSIM (simplified theory of rolling contact) on a cell grid: tractions, slip, forces and the
local frictional power p . s.

The seed (section 6.2) computes the frictional power density with a "modified FASTSIM": the tractions
of Kalker's simplified theory and the local slip give ``P_d = -p . s`` [W/m^2] in each cell (its
printed formula for P_d is garbled; this is the local dissipation it describes). Summed over the patch
this *local* power can differ from the *global* ``-V (xi Fx + eta Fy + phi Mz)`` under spin
(:func:`power_diagnostics`); both are reported: ``frictional_power`` is the local integral,
``diagnostics["global_power"]`` the global one. Sign convention (CONTACT's): tractions and forces act on
the wheel; a positive creepage gives a negative force; the dissipated powers are positive. Line
contacts run one strip (:mod:`railtherm_fastsim.fastsim_line`); forces and powers are then per unit
width. The stage model is :class:`railtherm_fastsim.tangential.FastsimTangential`.

References: J.J. Kalker, Vehicle System Dynamics 11 (1982) 1-13, doi:10.1080/00423118208968684.
E.A.H. Vollebregt, CONTACT (Apache-2.0): src/m_solvpt.f90 ``modif_fastsim``, src/m_hertz.f90 ``simpflex``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from railtherm.references.kalker import flexibilities as _flexibilities
from railtherm.references.kalker import kalker_coefficients, weighted_flexibility

__all__ = ["FastsimResult", "fastsim", "fastsim_flexibilities", "ellipse_cell_integrals", "law_arguments",
           "law_diagnostics", "power_diagnostics", "BOUNDS", "FLEXIBILITIES", "LEADING_EDGES"]

BOUNDS = ("elliptic", "parabolic")
FLEXIBILITIES = ("three", "one", "contact")
LEADING_EDGES = ("exact", "contact")


def fastsim_flexibilities(a, b, G, nu, xi, eta, phi, mu, normal_force, kind="three"):
    """Flexibilities (L1, L2, L3) of the simplified theory [m/Pa].

    Parameters
    ----------
    a, b : float
        Semi-axes along x (rolling) and y [m].
    G : float
        Combined shear modulus [Pa].
    nu : float
        Combined Poisson's ratio [1].
    xi, eta : float
        Creepages [1].
    phi : float
        Spin [1/m].
    mu : float
        Friction coefficient [1].
    normal_force : float
        N [N].
    kind : {"three", "one", "contact"}
        ``"three"``: Kalker's L1 = 8a/(3 C11 G), L2 = 8a/(3 C22 G), L3 = pi a sqrt(a/b)/(4 C23 G)
        (FASTSIM's forces then equal Kalker's linear theory for small creepage, except the spin
        moment). ``"one"``: Kalker's (1982) single weighted flexibility
        L = (|xi| L1 + |eta| L2 + c |phi| L3) / sqrt(xi^2 + eta^2 + c^2 phi^2), c = sqrt(ab).
        ``"contact"``: CONTACT's ``simpflex`` (creepages prescribed): the three flexibilities
        blended towards ``L_crss`` with weight min(1, f_crp/3), where f_crp is the creepage
        magnitude relative to the characteristic creepages mu N/(c^2 G C11), mu N/(c^2 G C22),
        mu N/(c^3 G C23). CONTACT forms f_crp from xi, eta and phi in its units (mm, 1/mm); it is
        reproduced here in those units so that CONTACT's results are matched.

    Returns
    -------
    L1, L2, L3 : float
    """
    l1, l2, l3 = _flexibilities(a, b, G, nu)
    if kind == "three":
        return l1, l2, l3
    if kind == "one":
        if xi == 0 and eta == 0 and phi == 0:
            return l1, l2, l3
        L = weighted_flexibility(a, b, G, nu, xi, eta, phi, form="kalker")
        return L, L, L
    if kind == "contact":
        c11, c22, c23, _ = kalker_coefficients(a, b, nu)
        mm = 1e3                                   # CONTACT's length unit [mm]
        cc = math.sqrt(a * b) * mm
        ga = G / mm ** 2                           # [N/mm^2]
        ch = (mu * normal_force / (cc ** 2 * ga * c11), mu * normal_force / (cc ** 2 * ga * c22),
              mu * normal_force / (cc ** 3 * ga * c23))
        phm = phi / mm                             # [1/mm]
        den = ch[0] ** 2 + ch[1] ** 2 + ch[2] ** 2
        f_crp = math.sqrt((xi ** 2 + eta ** 2 + phm ** 2) / den) if den > 0 else 0.0
        w = min(1.0, max(0.0, f_crp / 3.0))
        if w == 0.0:
            return l1, l2, l3
        lc = weighted_flexibility(a, b, G, nu, xi, eta, phi, form="contact")
        return tuple((1.0 - w) * L + w * lc for L in (l1, l2, l3))
    raise ValueError(f"flexibility kind must be one of {FLEXIBILITIES}, got {kind!r}")


@dataclass
class FastsimResult:
    """FASTSIM solution on a surface grid (tractions on the wheel)."""

    traction_x: np.ndarray        # [Pa]
    traction_y: np.ndarray        # [Pa]
    slip_velocity_x: np.ndarray   # wheel relative to rail [m/s]
    slip_velocity_y: np.ndarray   # [m/s]
    stick: np.ndarray             # 1 stick, 0 slip, NaN outside [1]
    power_density: np.ndarray     # -p . s [W/m^2]
    pressure: np.ndarray          # normal pressure used (parabolic bound: the redistributed one) [Pa]
    creep_force_x: float          # [N]
    creep_force_y: float          # [N]
    spin_moment: float            # [N m]
    local_power: float            # integral of power_density [W]
    global_power: float           # -V (xi Fx + eta Fy + phi Mz) [W]
    diagnostics: dict = field(default_factory=dict)


def ellipse_cell_integrals(grid, a, b, n_gauss=12):
    """Cell averages of the indicator and of the parabola of the ellipse (x/a)^2 + (y/b)^2 <= 1.

    Exact along x in each cell, Gauss-Legendre (``n_gauss`` points) across y. Vectorised numpy, once per solve
    (about 1 ms at 100 x 100 cells, where a compiled loop would cost each process about a second to compile).

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
    a, b : float
        Semi-axes [m].

    Returns
    -------
    fraction : ndarray (nx, ny)
        Fraction of each cell inside the ellipse [1].
    parabola : ndarray (nx, ny)
        Cell average of max(0, 1 - x^2/a^2 - y^2/b^2) [1].
    """
    t, w = np.polynomial.legendre.leggauss(int(n_gauss))
    xe, ye = np.asarray(grid.x_edges, dtype=float), np.asarray(grid.y_edges, dtype=float)
    dx, a, b = xe[1] - xe[0], float(a), float(b)
    inv_a2 = 1.0 / (a * a)
    lo0, hi0 = xe[:-1, None], xe[1:, None]
    frac = np.zeros((xe.size - 1, ye.size - 1))
    par = np.zeros_like(frac)
    # one Gauss line across y at a time: each cell sums its lines in the order of the nodes, a line outside the
    # ellipse or a cell outside its chord adds nothing (where=)
    for q in range(t.size):
        yy = 0.5 * (ye[:-1] + ye[1:]) + 0.5 * (ye[1:] - ye[:-1]) * t[q]
        c2 = 1.0 - (yy / b) * (yy / b)
        lim = a * np.sqrt(np.maximum(c2, 0.0))              # the chord's half-length at yy
        inside = (c2 > 0.0) & (hi0 > -lim) & (lo0 < lim)
        lo, hi = np.maximum(lo0, -lim), np.minimum(hi0, lim)
        wq = 0.5 * w[q] / dx
        np.copyto(frac, frac + wq * (hi - lo), where=inside)
        np.copyto(par, par + wq * (c2 * (hi - lo) - (hi * (hi * hi) - lo * (lo * lo)) * inv_a2 / 3.0), where=inside)
    return frac, par


# over 80 lines only through its docstring (the public FASTSIM call's parameters); the body is 35 lines
def fastsim(grid, pressure, *, a, b, normal_force, friction, shear_modulus, poisson_ratio, xi, eta, phi, speed,
            bound="elliptic", flexibility="three", leading_edge="exact", slip_law=None):
    """Kalker's FASTSIM on a rectangular cell-centred grid covering an elliptical patch.

    Parameters
    ----------
    grid : railtherm.SurfaceGrid
        Uniform grid, x ascending, leading edge at +a.
    pressure : ndarray (nx, ny)
        Normal pressure [Pa]; cells with p <= 0 are outside the contact (elliptic bound). Cell
        averages (as core's Hertz model gives them) for ``leading_edge="exact"``, centre values
        (CONTACT) for ``"contact"``.
    a, b : float
        Semi-axes of the contact ellipse [m].
    normal_force : float
        N [N].
    friction : float or ndarray (nx, ny)
        mu [1], one value or one per cell (a temperature law); with ``slip_law`` the nominal mu (only
        CONTACT's flexibility blend uses it).
    shear_modulus, poisson_ratio : float
        Combined G [Pa] and nu [1].
    xi, eta : float
        Longitudinal and lateral creepage [1] (rigid slip of the wheel relative to the rail per unit
        rolling distance: ``w = (xi - phi y, eta + phi x)``).
    phi : float
        Spin creepage [1/m].
    speed : float
        Rolling speed V [m/s].
    bound : {"elliptic", "parabolic"}
        Traction bound mu p with the given (Hertzian) pressure, or Kalker's parabolic bound
        ``mu p_par``, ``p_par = 2 N/(pi a b) (1 - x^2/a^2 - y^2/b^2)`` (same load; CONTACT B=3),
        which then also replaces the pressure.
    flexibility : {"three", "one", "contact"}
        See :func:`fastsim_flexibilities`.
    leading_edge : {"exact", "contact"}
        ``"exact"`` (default): each strip is integrated from its true leading edge
        a(y) = a sqrt(1 - y^2/b^2), the spin slip is sampled at the middle of every step (exact in
        stick), the tractions are point values at the cell centres bounded by mu times the mean
        pressure over the part of the cell inside the ellipse (cell average / inside fraction), and
        forces, moment and power are integrated with that fraction (cut cells); the fields
        returned are cell averages (point value x fraction), so that their grid sums are the
        totals (in full sliding, exactly mu N). ``"contact"``: CONTACT's discretisation -- the
        first cell of a strip takes a full step dx from zero traction, the spin slip is sampled at
        x + dx/6, whole cells count, and the parabolic bound is taken at the cell centres.
    slip_law : railtherm.physics.friction.SlipVelocityFriction, optional
        Exponential slip-velocity law (or Polach's): the bound of each slipping cell is mu(v) p with v
        the cell's own slip speed, solved cell by cell (:func:`railtherm_fastsim.fastsim_kernel.slip_law_bound`).
        The diagnostics then hold ``friction_iterations`` (most steps of one cell), ``friction_contraction``
        (largest kappa over the contact), ``friction_nonunique_cells`` and ``friction_nonunique_kappa``:
        cells whose local equation has several solutions (the caller refuses).

    Returns
    -------
    FastsimResult
    """
    from .fastsim_kernel import sweep_kernel   # numba: imported on first use (keeps plugin loading light)

    if bound not in BOUNDS:
        raise ValueError(f"bound must be one of {BOUNDS}, got {bound!r}")
    if leading_edge not in LEADING_EDGES:
        raise ValueError(f"leading_edge must be one of {LEADING_EDGES}, got {leading_edge!r}")
    x = np.ascontiguousarray(grid.x, dtype=float)
    y = np.ascontiguousarray(grid.y, dtype=float)
    X, Y = grid.mesh()
    p, frac, g, mode, offset = _cell_bounds(grid, X, Y, pressure, a, b, normal_force, friction, bound,
                                            leading_edge, slip_law)
    mu_nominal = float(friction) if np.ndim(friction) == 0 else float(np.max(friction))
    L1, L2, L3 = fastsim_flexibilities(a, b, shear_modulus, poisson_ratio, xi, eta, phi, mu_nominal,
                                       normal_force, flexibility)
    inside = g > 0
    lead = _strip_leading_edges(x, y, a, b, inside, float(grid.dx))
    shape = p.shape
    px, py, sx, sy, stick, power = (np.empty(shape) for _ in range(6))
    law = law_arguments(slip_law)
    out = sweep_kernel(law[0])(x, y, np.ascontiguousarray(g, dtype=float), lead, float(xi), float(eta), float(phi),
                               L1, L2, L3, float(speed), offset, mode, *law, px, py, sx, sy, stick, power)
    nstick, nslip = out[4], out[5]
    w = np.where(inside, frac, 0.0)
    tx, ty, pd = px * w, py * w, power * w
    area = grid.cell_area
    Fx, Fy = float(tx.sum()) * area, float(ty.sum()) * area
    Mz = float((X * ty - Y * tx).sum()) * area
    P = float(pd.sum()) * area
    G = -speed * (xi * Fx + eta * Fy + phi * Mz)
    diag = {"flexibility_L1": L1, "flexibility_L2": L2, "flexibility_L3": L3, "bound": bound,
            "flexibility": flexibility, "leading_edge": leading_edge, "stick_cells": int(nstick),
            "slip_cells": int(nslip), **power_diagnostics(P, G),
            "creepage_longitudinal": float(xi), "creepage_lateral": float(eta), "creepage_spin": float(phi),
            **law_diagnostics(slip_law, out)}
    return FastsimResult(tx, ty, sx, sy, stick, pd, p, Fx, Fy, Mz, P, G, diag)


def _cell_bounds(grid, X, Y, pressure, a, b, normal_force, friction, bound, leading_edge, slip_law):
    """The pressure, inside fraction and traction bound of every cell, and the sweep's edge mode.

    Returns
    -------
    p : ndarray (nx, ny)
        Pressure [Pa] (the parabolic one with ``bound="parabolic"``).
    frac : ndarray (nx, ny)
        Fraction of each contact cell inside the ellipse (``"contact"``: 1 where p > 0) [1].
    g : ndarray (nx, ny)
        Bound mu p [Pa] (with a slip law: p, mu being the law's) -- at a cut cell the mean pressure
        over its inside part.
    mode, offset : int, float
        :func:`~railtherm_fastsim.fastsim_kernel.fastsim_sweep_law`'s ``edge_mode`` and ``spin_offset``.
    """
    dq = float(grid.dx)
    p_par0 = 2.0 * normal_force / (math.pi * a * b)
    if leading_edge == "exact":
        frac, par = ellipse_cell_integrals(grid, a, b)
        mode, offset = 1, 0.5 * dq
    else:
        par = np.clip(1.0 - (X / a) ** 2 - (Y / b) ** 2, 0.0, None)
        frac = None
        mode, offset = 0, dq / 6.0
    p = p_par0 * par if bound == "parabolic" else np.asarray(pressure, dtype=float)
    mu = 1.0 if slip_law is not None else (friction if np.ndim(friction) == 0 else np.asarray(friction, dtype=float))
    if frac is None:
        frac = (p > 0).astype(float)
        g = mu * p
    else:
        # p holds cell averages: the bound at a cut cell is the mean pressure over its inside part
        frac = np.where(p > 0, frac, 0.0)
        g = np.where(frac > 1e-12, mu * p / np.where(frac > 1e-12, frac, 1.0), 0.0)
    return p, frac, g, mode, offset


def _strip_leading_edges(x, y, a, b, inside, dq):
    """Leading edge a(y) = a sqrt(1 - y^2/b^2) of every strip [m]; strips beyond |y| = b that a
    cell-averaged pressure still reaches (cut cells) start at the leading edge of their first contact cell."""
    lead = a * np.sqrt(np.clip(1.0 - (y / b) ** 2, 0.0, None))
    for j in np.nonzero(inside.any(axis=0))[0]:
        if lead[j] <= 0.0:
            lead[j] = x[np.nonzero(inside[:, j])[0][-1]] + 0.5 * dq
    return lead


def power_diagnostics(local: float, global_: float) -> dict:
    """The local (sum of -p . s) and global (-V creepages . forces) frictional powers and their difference.

    They differ when the traction turns within the slip zone (spin): by 37 % in CONTACT's FASTSIM example
    on fine grids (44 % with the parabolic bound), a difference that does not vanish with refinement (the
    Winkler bed with three flexibilities is not a conservative elastic model); for longitudinal creepage
    alone the two agree in the limit (first-order convergence).
    """
    return {"global_power": global_, "local_power": local, "power_difference": local - global_,
            "power_difference_relative": (local - global_) / global_ if global_ != 0 else 0.0}


def law_arguments(slip_law) -> tuple:
    """(law_mode, mu_kin, dmu, decay) of :func:`railtherm_fastsim.fastsim_kernel.fastsim_sweep_law` for an
    exponential slip-velocity law (``None``: the bound array is mu p, law_mode 0)."""
    if slip_law is None:
        return 0, 0.0, 0.0, 1.0
    return 1, float(slip_law.kinetic), float(slip_law.static) - float(slip_law.kinetic), float(slip_law.decay)


def law_diagnostics(slip_law, out) -> dict:
    """The slip law's diagnostics from the kernel's results (empty without a law)."""
    if slip_law is None:
        return {}
    return {"friction_iterations": int(out[6]), "friction_nonunique_cells": int(out[7]),
            "friction_contraction": float(out[8]), "friction_nonunique_kappa": float(out[9])}


