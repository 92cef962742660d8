"""Kalker's FASTSIM sweep (numba): tractions, slip, stick/slip map and frictional power density.

The simplified theory replaces the elastic half-space by a Winkler bed of springs, ``u = L p``
(displacement ``u`` [m], traction ``p`` [Pa], flexibility ``L`` [m/Pa]). In steady rolling the body
material flows through the patch in -x (it enters at the leading edge x = +a), and the slip of body 1
(wheel) relative to body 2 (rail), per unit rolling distance, is ``s = w - du/dx`` with the rigid slip
``w = (xi - phi y, eta + phi x)`` ([1] [2]). Each strip is swept from its leading edge (the stepping
rule: :func:`fastsim_sweep`; one cell's stick or slip: :func:`_cell_update`). Traction ``p`` acts on
the wheel: a positive creepage gives a negative force (CONTACT's convention).

References
----------
.. [1] J.J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
   Dynamics 11 (1982) 1-13. doi:10.1080/00423118208968684
.. [2] E.A.H. Vollebregt, CONTACT (Apache-2.0), src/m_solvpt.f90 ``modif_fastsim``, src/m_scontc.f90.
"""
from __future__ import annotations

import math
import types

import numba
import numpy as np


@numba.njit(cache=True, fastmath=False, boundscheck=False)
def fastsim_sweep(x, y, bound, lead, xi, eta, phi, L1, L2, L3, speed, spin_offset, edge_mode,
                  px, py, sx, sy, stick, power):  # pragma: no cover - compiled
    """Kalker's sweep with the traction bound ``bound`` = mu p per cell (any constant or per-cell mu):
    :func:`fastsim_sweep_mu` (``law_mode = 0``); returns its first six results.

    Stepping from a cell at x to the next one downstream at x - dq:

    * adhesion (s = 0):   ``p_h = p' - dq (xi/L1 - phi y/L3,  eta/L2 + phi x*/L3)``
    * traction bound:     if ``|p_h| > g = mu p_z`` then ``p = g p_h/|p_h|`` (slip), else ``p = p_h``;
    * slip per unit rolling distance (cell i): ``s_x = L1 (p_x - p_hx)/dq``, ``s_y = L2 (p_y - p_hy)/dq``;
      the slip velocity is ``V s`` [m/s] and the frictional power density ``-V p . s >= 0`` [W/m^2]
      (the seed's "modified FASTSIM" power density; its printed formula for ``P_d`` is garbled, this
      is the local dissipation of the Winkler model that the seed describes in words).

    With three flexibilities (L1, L2, L3) the spin term is weighted by 1/L3 exactly as in CONTACT's
    ``M=3`` (rigid shift scaled by L1/L3, L2/L3); x* is where the spin slip is sampled (see
    ``spin_offset``).
    """
    r = fastsim_sweep_mu(x, y, bound, lead, xi, eta, phi, L1, L2, L3, speed, spin_offset, edge_mode,
                         0, 0.0, 0.0, 1.0, px, py, sx, sy, stick, power)
    return r[0], r[1], r[2], r[3], r[4], r[5]


@numba.njit(cache=True, fastmath=False, boundscheck=False)
def slip_law_bound(habs, pc, keff, mu_kin, dmu, decay):  # pragma: no cover - compiled
    """Traction bound of one cell under the exponential slip-velocity law mu(v) = mu_kin + dmu exp(-v/decay).

    In a slipping cell the traction is ``g h/|h|`` and the slip speed is ``v = keff (|h| - g)`` (the
    sweep's slip ``V L (q - h)/dq``, with ``keff = V |L h|/(|h| dq)`` [m/(s Pa)]); the bound solves the
    scalar equation ``F(g) = g - pc mu(keff (|h| - g)) = 0``. For a falling law F is concave in g, so:

    * ``|h| > mu(0) pc`` (the cell cannot stick): F(mu_min pc) < 0 < F(mu_max pc), exactly one root,
      found by Newton safeguarded by bisection on that bracket;
    * ``|h| <= mu(0) pc``: the cell sticks (g = |h|) -- unique unless F also has (two) slip roots,
      which happens iff kappa = |dmu/dv(0)| pc keff > 1 and F(g*) >= 0 at its maximum
      g* = |h| - decay ln(kappa)/keff (then ``flag = 2``: non-unique).

    Parameters
    ----------
    habs : float
        |h|, the stick (trial) traction [Pa].
    pc : float
        Pressure of the cell's bound [Pa] (> 0).
    keff : float
        Slip speed per unit traction deficit [m/(s Pa)].
    mu_kin, dmu, decay : float
        Law: kinetic mu [1], static - kinetic [1], reference slip speed [m/s].

    Returns
    -------
    g : float
        The bound [Pa] (``habs`` in stick: the sweep then sticks).
    iterations : int
        Newton/bisection steps.
    flag : int
        0 slip, 1 stick, 2 non-unique (stick taken; the caller refuses).
    kappa : float
        |dmu/dv(0)| pc keff [1] (:func:`railtherm.physics.friction.contraction_limit`).
    """
    mu_st = mu_kin + dmu
    kappa = abs(dmu) / decay * pc * keff
    if habs <= mu_st * pc:
        if dmu > 0.0 and kappa > 1.0:
            gstar = habs - decay * math.log(kappa) / keff
            if gstar > mu_kin * pc and gstar - pc * mu_kin - decay / keff >= 0.0:
                return habs, 0, 2, kappa
        return habs, 0, 1, kappa
    if dmu == 0.0:
        return mu_kin * pc, 0, 0, kappa
    lo = min(mu_kin, mu_st) * pc
    hi = min(max(mu_kin, mu_st) * pc, habs)
    g = 0.5 * (lo + hi)
    tol = 1e-14 * hi
    it = 0
    for it in range(1, 200):
        e = math.exp(-keff * (habs - g) / decay)
        f = g - pc * (mu_kin + dmu * e)
        if f > 0.0:
            hi = g
        else:
            lo = g
        if f == 0.0 or hi - lo <= tol:
            break
        df = 1.0 - pc * keff * dmu / decay * e
        gn = g - f / df if df != 0.0 else lo - 1.0
        if not (lo < gn < hi):
            gn = 0.5 * (lo + hi)
        if abs(gn - g) <= tol:
            g = gn
            break
        g = gn
    return g, it, 0, kappa


@numba.njit(cache=True, fastmath=False, boundscheck=False)
def _law_cell(habs, hx, hy, pc, v_over_dq, L1, L2, mu_kin, dmu, decay, stats):  # pragma: no cover - compiled
    """The bound g of one cell under the slip law (:func:`slip_law_bound` with keff = V |L h| / (|h| dx)),
    recording in ``stats`` the largest Newton count, the largest kappa, the count of non-unique cells and
    their largest kappa."""
    keff = v_over_dq * math.hypot(L1 * hx, L2 * hy) / habs if habs > 0.0 else 0.0
    g, nit, flag, kap = slip_law_bound(habs, pc, keff, mu_kin, dmu, decay)
    if nit > stats[0]:
        stats[0] = nit
    if kap > stats[1]:
        stats[1] = kap
    if flag == 2:
        stats[2] += 1
        if kap > stats[3]:
            stats[3] = kap
    return g


@numba.njit(cache=True, fastmath=False, boundscheck=False, inline="always")
def _cell_update(hx, hy, habs, g, speed, inv_dq, L1, L2):  # pragma: no cover - compiled
    """FASTSIM's update of one contact cell from its trial (stick) traction ``h = (hx, hy)`` [Pa],
    ``habs = |h|``, and its traction bound ``g`` [Pa].

    In stick (``|h| <= g``) the traction is ``h`` and there is no slip; otherwise the traction is
    ``g h/|h|`` and the wheel slips relative to the rail at ``V L (q - h)/dq``. Every cell of the
    sweep goes through here (the cut cells at a strip's leading edge too).

    Returns
    -------
    qx, qy : float
        Traction on the wheel [Pa].
    vx, vy : float
        Slip velocity [m/s].
    stuck : bool
        True in stick.
    pd : float
        Frictional power density ``-q . v`` [W/m^2] (0 in stick).
    """
    if habs <= g:
        return hx, hy, 0.0, 0.0, True, 0.0
    f = g / habs
    qx = hx * f
    qy = hy * f
    # slip per unit rolling distance, then velocity
    vx = speed * L1 * (qx - hx) * inv_dq
    vy = speed * L2 * (qy - hy) * inv_dq
    return qx, qy, vx, vy, False, -(qx * vx + qy * vy)


# long: one fused numba loop over the cells of every strip, whose per-strip state (previous traction,
# in-contact flag) and running sums a split would pass through calls in the innermost loop; half of
# it is the parameter docstring, and the cell update itself is _cell_update
def _sweep(x, y, bound, lead, xi, eta, phi, L1, L2, L3, speed, spin_offset, edge_mode,
           law_mode, mu_kin, dmu, decay,
           px, py, sx, sy, stick, power):  # pragma: no cover - compiled
    """Sweep every strip y_j from the leading edge (x = +a) to the trailing edge.

    Compiled twice (:func:`_compile_sweep`): :func:`fastsim_sweep_law` (every ``law_mode``) and
    :func:`fastsim_sweep_mu` (``law_mode = 0`` only, without the slip-law code).

    Parameters
    ----------
    x : ndarray (nx,)
        Cell centres along the rolling direction, ascending, uniform spacing dq [m].
    y : ndarray (ny,)
        Cell centres across [m].
    bound : ndarray (nx, ny)
        ``law_mode == 0``: traction bound g = mu p [Pa]; ``law_mode == 1``: the bound's pressure p [Pa]
        (the bound is mu(v) p, :func:`slip_law_bound`). Cells with bound <= 0 are outside the contact.
    lead : ndarray (ny,)
        Leading-edge position a(y_j) of each strip [m] (used when ``edge_mode == 1``).
    xi, eta : float
        Longitudinal and lateral creepage [1].
    phi : float
        Spin creepage [1/m].
    L1, L2, L3 : float
        Flexibilities for xi, eta and phi [m/Pa].
    speed : float
        Rolling speed V [m/s] (scales slip velocity and power only).
    spin_offset : float
        x* - x_i of the spin term for interior steps [m] (dq/2: midpoint of the step; CONTACT: dq/6).
    law_mode : int
        0: ``bound`` is mu p; 1: exponential slip-velocity law ``mu_kin + dmu exp(-v/decay)``.
    mu_kin, dmu, decay : float
        The slip law's kinetic mu [1], static - kinetic [1] and reference slip speed [m/s] (law_mode 1).
    edge_mode : int
        0: the first contact cell of a strip takes a full step dq from a zero traction (CONTACT);
        1: the first step starts at the exact leading edge ``lead[j]``, and every step samples the
        spin at the step's midpoint (exact for stick); a cut cell whose centre lies ahead of the
        edge gets the traction of the middle of its inside part without advancing the strip.
    px, py, sx, sy, stick, power : ndarray (nx, ny)
        Outputs: traction on the wheel [Pa], slip velocity of the wheel relative to the rail [m/s],
        stick map (1 stick, 0 slip, NaN outside), frictional power density [W/m^2].

    Returns
    -------
    fx, fy, mz, pw : float
        Sums of px, py, x py - y px, and power over the cells (multiply by the cell area for
        forces [N], moment [N m] and power [W]).
    nstick, nslip : int
        Number of cells in stick and slip.
    max_iterations : int
        Most Newton/bisection steps of one cell (law_mode 1).
    nonunique : int
        Number of cells whose local equation has more than one solution (law_mode 1; stick taken).
    kappa_max, kappa_bad : float
        Largest kappa = |dmu/dv(0)| p keff over the contact cells, and over the non-unique ones [1].
    """
    nx = x.shape[0]
    ny = y.shape[0]
    dq = x[1] - x[0] if nx > 1 else 1.0
    inv_dq = 1.0 / dq
    ax0 = xi / L1
    ay0 = eta / L2
    k3 = phi / L3
    pvx = np.zeros(ny)
    pvy = np.zeros(ny)
    incon = np.zeros(ny, dtype=np.bool_)
    fx = 0.0
    fy = 0.0
    mz = 0.0
    pw = 0.0
    nstick = 0
    nslip = 0
    stats = np.zeros(4)          # largest Newton count, largest kappa, non-unique cells, their largest kappa
    nan = np.nan
    for ii in range(nx):
        i = nx - 1 - ii
        xi_ = x[i]
        for j in range(ny):
            g = bound[i, j]
            if g <= 0.0:
                px[i, j] = 0.0
                py[i, j] = 0.0
                sx[i, j] = 0.0
                sy[i, j] = 0.0
                stick[i, j] = nan
                power[i, j] = 0.0
                pvx[j] = 0.0
                pvy[j] = 0.0
                incon[j] = False
                continue
            yj = y[j]
            if edge_mode == 1 and not incon[j]:
                step = lead[j] - xi_
                if step <= 0.0:
                    # cut cell whose centre lies ahead of the strip's leading edge: its inside part
                    # [x - dq/2, a(y)] carries the traction of its middle; the strip still starts
                    # at a(y) (the state is not advanced)
                    step = 0.5 * (lead[j] - (xi_ - 0.5 * dq))
                    if step < 0.0:
                        step = 0.0
                    xs = lead[j] - 0.5 * step
                    hx = -step * (ax0 - k3 * yj)
                    hy = -step * (ay0 + k3 * xs)
                    advance = False
                else:
                    xs = 0.5 * (lead[j] + xi_)
                    hx = pvx[j] - step * (ax0 - k3 * yj)
                    hy = pvy[j] - step * (ay0 + k3 * xs)
                    advance = True
            else:
                xs = xi_ + spin_offset
                hx = pvx[j] - dq * (ax0 - k3 * yj)     # traction increment per unit rolling distance [Pa/m]
                hy = pvy[j] - dq * (ay0 + k3 * xs)
                advance = True
            habs = math.sqrt(hx * hx + hy * hy)
            if _SLIP_LAW and law_mode == 1:
                g = _law_cell(habs, hx, hy, g, speed * inv_dq, L1, L2, mu_kin, dmu, decay, stats)
            qx, qy, vx, vy, stuck, pd = _cell_update(hx, hy, habs, g, speed, inv_dq, L1, L2)
            px[i, j] = qx
            py[i, j] = qy
            sx[i, j] = vx
            sy[i, j] = vy
            power[i, j] = pd
            if stuck:
                stick[i, j] = 1.0
                nstick += 1
            else:
                stick[i, j] = 0.0
                nslip += 1
            fx += qx
            fy += qy
            mz += xi_ * qy - yj * qx
            pw += pd
            if advance:
                pvx[j] = qx
                pvy[j] = qy
                incon[j] = True
    return fx, fy, mz, pw, nstick, nslip, int(stats[0]), int(stats[2]), stats[1], stats[3]


#: whether a build of :func:`_sweep` holds the slip-law code (each build reads its own copy, a compile-time constant)
_SLIP_LAW = True


def _compile_sweep(name: str, slip_law: bool):
    """A numba build of :func:`_sweep` named ``name``, with (``slip_law``) or without the slip-law code.

    The build without it never compiles :func:`_law_cell` and :func:`slip_law_bound` (numba drops the
    branch on the constant ``_SLIP_LAW``): about 40 % of the sweep's compilation, paid on a cold cache
    by every process whose scenes have a constant friction coefficient. Both builds are the same Python
    code, so they cannot drift apart; the distinct name keeps numba's on-disk cache entries apart.
    """
    glob = dict(_sweep.__globals__, _SLIP_LAW=bool(slip_law))
    twin = types.FunctionType(_sweep.__code__, glob, name, _sweep.__defaults__, _sweep.__closure__)
    twin.__qualname__ = name
    twin.__doc__ = _sweep.__doc__
    twin.__module__ = _sweep.__module__
    return numba.njit(cache=True, fastmath=False, boundscheck=False)(twin)


fastsim_sweep_law = _compile_sweep("fastsim_sweep_law", True)
fastsim_sweep_mu = _compile_sweep("fastsim_sweep_mu", False)


def sweep_kernel(law_mode: int):
    """The build of the sweep for ``law_mode`` (:func:`_sweep`): :func:`fastsim_sweep_mu` for a bound
    mu p (0), :func:`fastsim_sweep_law` for a slip-velocity law (1); both give the same results for 0."""
    return fastsim_sweep_law if int(law_mode) == 1 else fastsim_sweep_mu
