"""Conduction across green's strips in its transient histories: one pass's response at the fixed section of a
3-D contact, each strip's 1-D response weighted by the lateral Gaussian.

At high Péclet number the section sees the same history, shifted in time, at every x: conduction along x is
negligible, across the strips (y) it is not between passes (83 ms after a pass its heat has spread
sqrt(4 kappa t) = 2 mm sideways). The half-space's instantaneous point source factorises into x, y and z parts;
dropping only x, strip j (y_j .. y_(j+1)) weighs its 1-D kernel by
``W_j(s) = (erf(y_(j+1)/sqrt(4 kappa s)) - erf(y_j/sqrt(4 kappa s)))/2`` [1, 2]. The response is the centre strip's
1-D one plus a smooth lateral term (:class:`LateralPassResponse`); derivation: docs/NOTES.md, "Green's transient".

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, sections 2.9,
10.2 (the instantaneous point source). [2] M. Ertz, K. Knothe, A comparison of analytical and numerical methods
for the calculation of temperatures in wheel/rail contact, Wear 253 (2002) 498-508 (DOI not verified, see
docs/references.md).
"""
from __future__ import annotations

import math

import numba
import numpy as np
from scipy.special import erfc

from .pass_response import PassResponse, far_weights_columns
from .smooth_tail import chebval_into

__all__ = ["LateralPassResponse", "lateral_weights", "scheduled_lateral"]

#: Gauss-Legendre points per lattice step of the table of Psi_p (and per piece of a cell's crossing), on [-1, 1]
GAUSS = 4
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(GAUSS)
#: erfc(x) < 2e-17 beyond this argument: a lateral term is dropped there
ERFC_ZERO = 5.9
#: degrees of the lateral far sums' Chebyshev nodes in the crossing times, from 2 D (error 5.8^-16 = 6e-13 of the
#: lateral term) and from 4 D (13.9^-12 = 2e-14): fewer nodes than the 1-D far sum's FAR_DEGREE, each node costing
#: a sum over the lateral distances
FAR_DEGREES = (16, 12)
#: erfc on [0, ERFC_ZERO] by cubic Hermite interpolation on this many intervals (error below h^4 max|erfc^(4)|/384
#: = 3e-15); libm's erfc costs several times more, and a history's far sums take 1e5 of them
ERFC_INTERVALS = 8192
_ERFC_X = np.arange(ERFC_INTERVALS + 2) * (ERFC_ZERO / ERFC_INTERVALS)
_ERFC_TABLE = np.ascontiguousarray(np.stack([erfc(_ERFC_X), -2.0 / math.sqrt(math.pi) * np.exp(-_ERFC_X ** 2)], 1))


def lateral_weights(y_edges, flux):
    """The centre strip's flux and the lateral edge weights of the module docstring.

    Parameters
    ----------
    y_edges : array_like
        Cell edges across the strips [m], increasing, (ny + 1,).
    flux : array_like
        The body's flux per cell [W/m^2], (nx, ny).

    Returns
    -------
    centre : numpy.ndarray
        ``sum_j W_j(0+) q_kj`` [W/m^2], (nx,): the strip containing y = 0 (the mean of two strips meeting there).
    rho : numpy.ndarray
        The distinct distances of the y edges from y = 0 [m], > 0, (P,).
    b : numpy.ndarray
        b_kp [W/m^2], (nx, P), only the distances whose weights are not all zero.
    """
    ye = np.asarray(y_edges, dtype=float)
    q = np.asarray(flux, dtype=float)
    if ye.ndim != 1 or q.ndim != 2 or q.shape[1] != ye.size - 1:
        raise ValueError(f"flux must be (nx, ny) with ny = y_edges.size - 1 = {ye.size - 1}, got {q.shape}")
    if not (ye[1:] > ye[:-1]).all():
        raise ValueError("y_edges must be strictly increasing [m]")
    sg = np.sign(ye)
    centre = q @ (0.5 * (sg[1:] - sg[:-1]))
    jump = np.zeros((q.shape[0], ye.size))             # q_(k,e) - q_(k,e-1), zero flux outside
    jump[:, :-1] += q
    jump[:, 1:] -= q
    mag = np.abs(ye)
    keep = mag > 1e-9 * float(mag.max())
    key = np.round(mag / float(mag.max()) * 2.0 ** 36)  # the edges at +-y (rounded apart) as one distance
    groups, inv = np.unique(key[keep], return_inverse=True)
    sign_of = np.zeros((ye.size, groups.size))         # edge e -> its distance, with the edge's sign
    sign_of[np.flatnonzero(keep), inv] = sg[keep]
    b = jump @ sign_of
    rho = np.zeros(groups.size)
    np.maximum.at(rho, inv, mag[keep])
    live = np.any(b != 0.0, axis=0)
    return centre, rho[live], np.ascontiguousarray(b[:, live])


@numba.njit(cache=True)
def _erfc(x, table):  # pragma: no cover - compiled
    """erfc(x) for 0 <= x <= ERFC_ZERO by cubic Hermite interpolation of ``table`` (erfc and its derivative)."""
    h = ERFC_ZERO / ERFC_INTERVALS
    u = x / h
    k = min(int(u), ERFC_INTERVALS - 1)
    t = u - k
    t1 = 1.0 - t
    return ((1.0 + 2.0 * t) * t1 * t1 * table[k, 0] + t * t * (3.0 - 2.0 * t) * table[k + 1, 0]
            + h * t * t1 * (t1 * table[k, 1] - t * table[k + 1, 1]))


@numba.njit(cache=True)
def _lateral_factor(s, rho, kappa, weights, table):  # pragma: no cover - compiled
    """``sum_p weights[p] erfc(rho_p / sqrt(4 kappa s)) / 2`` at one s > 0 [s] (rho increasing: the sum stops
    where erfc is below 2e-17)."""
    inv = 0.5 / math.sqrt(kappa * s)
    acc = 0.0
    for p in range(rho.size):
        x = rho[p] * inv
        if x > ERFC_ZERO:
            break
        acc += weights[p] * _erfc(x, table)
    return 0.5 * acc


@numba.njit(cache=True)
def _psi_table(step, last, rho, cs, kappa, nodes, gweights, table):  # pragma: no cover - compiled
    """Psi_p (module docstring) at the lattice points i step, i = 0 .. last, (P, m, last + 1), by Gauss-Legendre
    (``nodes``, ``gweights`` on [0, 1]) on every lattice step, cumulated; and per p the first lattice point where
    it is not 0 (rho increasing; erfc below 2e-17 counts as 0)."""
    npts, m = rho.size, cs.size
    big = np.zeros((npts, m, last + 1))
    first = np.full(npts, last + 1)
    g = np.empty(m)
    for i in range(last):
        for a in range(nodes.size):
            s = step * (i + nodes[a])
            inv = 0.5 / math.sqrt(kappa * s)
            for j in range(m):
                g[j] = gweights[a] * step * math.exp(-cs[j] / s) / math.sqrt(s)
            for p in range(npts):
                x = rho[p] * inv
                if x > ERFC_ZERO:
                    break
                first[p] = min(first[p], i + 1)
                e = 0.5 * _erfc(x, table)
                for j in range(m):
                    big[p, j, i + 1] += e * g[j]
        for p in range(npts):
            if first[p] > i + 1:
                break
            for j in range(m):
                big[p, j, i + 1] += big[p, j, i]
    return big, first


@numba.njit(cache=True)
def _psi_points(step, last, rho, cs, kappa, table):  # pragma: no cover - compiled
    """psi_p at the lattice points i step, i = 0 .. last, (P, m, last + 1) (0 at i = 0)."""
    out = np.zeros((rho.size, cs.size, last + 1))
    for i in range(1, last + 1):
        s = step * i
        inv = 0.5 / math.sqrt(kappa * s)
        for p in range(rho.size):
            x = rho[p] * inv
            if x > ERFC_ZERO:
                break
            e = 0.5 * _erfc(x, table) / math.sqrt(s)
            for j in range(cs.size):
                out[p, j, i] = e * math.exp(-cs[j] / s)
    return out


@numba.njit(cache=True)
def _lattice_sums(d_lead, tab, stride, first, want):  # pragma: no cover - compiled
    """``sum_p sum_r d_lead[r, p] tab[p, :, i - stride r]`` at the lattice points i of ``want`` (n,), (n, m): the
    edge r from the lead is crossed ``stride r`` lattice points after the arrival; tab[p] is 0 before first[p]."""
    nr, npts = d_lead.shape
    m = tab.shape[1]
    out = np.zeros((want.size, m))
    for p in range(npts):
        f = first[p]
        for n in range(want.size):
            i = want[n]
            if i < f:
                continue
            top = min(nr - 1, (i - f) // stride)         # tab[p, :, i - stride r] = 0 beyond
            for j in range(m):
                row = tab[p, j]
                acc = 0.0
                for r in range(top + 1):
                    acc += d_lead[r, p] * row[i - stride * r]
                out[n, j] += acc
    return out


@numba.njit(cache=True)
def _far_lateral(theta, nodes, weights, rho, cs, kappa, table):  # pragma: no cover - compiled
    """``sum_l sum_p weights[l, p] psi_p(theta - c_l)`` at the times theta (n,) past the nodes c_l [s], (n, m)."""
    out = np.zeros((theta.size, cs.size))
    for i in range(theta.size):
        for l in range(nodes.size):
            s = theta[i] - nodes[l]
            if s <= 0.0:
                continue
            lat = _lateral_factor(s, rho, kappa, weights[l], table)
            if lat == 0.0:
                continue
            root = math.sqrt(s)
            for j in range(cs.size):
                out[i, j] += lat * math.exp(-cs[j] / s) / root
    return out


@numba.njit(cache=True)
def _hermite(theta, step, values, slopes):  # pragma: no cover - compiled
    """Cubic Hermite interpolation (n, m) of the lattice values (last + 1, m) and their slopes at theta (n,) [s],
    0 <= theta <= last step (exact at the lattice points)."""
    last = values.shape[0] - 1
    out = np.empty((theta.size, values.shape[1]))
    for i in range(theta.size):
        u = theta[i] / step
        k = min(max(int(math.floor(u)), 0), last - 1)
        t = u - k
        h00 = (1.0 + 2.0 * t) * (1.0 - t) ** 2
        h10 = t * (1.0 - t) ** 2
        h01 = t * t * (3.0 - 2.0 * t)
        h11 = t * t * (t - 1.0)
        for j in range(values.shape[1]):
            out[i, j] = (h00 * values[k, j] + h01 * values[k + 1, j]
                         + step * (h10 * slopes[k, j] + h11 * slopes[k + 1, j]))
    return out


def _edge_weights(b):
    """d_kp = b_(k-1)p - b_kp over the x edges k = 0 .. nx (b zero outside), (nx + 1, P)."""
    d = np.zeros((b.shape[0] + 1, b.shape[1]))
    d[1:] += b
    d[:-1] -= b
    return d


class LateralPassResponse:
    """One pass's rise [K] at the depths z for a constant factor 1 under a 3-D contact, as a function of the time
    after arrival: the centre strip's 1-D response plus the lateral term dR.

    With the flux q piecewise constant on green's cells, at the centre line (y = 0, depth z)
    ``T(t) = sum_j int q_j(t') W_j(t - t') g_z(t - t') dt' / (beta sqrt(pi))``, g_z(s) = exp(-z^2/(4 kappa s))/sqrt(s).
    W_j tends to W_j(0+) = (sgn y_(j+1) - sgn y_j)/2 (the strip containing y = 0) as s -> 0 and sums to 1 over
    strips covering all y (a band: unchanged). Splitting W_j = W_j(0+) - (W_j(0+) - W_j) and summing by parts over
    the y edges gives the centre strip's 1-D response (:class:`railtherm_green.pass_response.PassResponse`) plus

    ``dR(theta) = sum_p sum_k d_kp Psi_p(theta - c_k) / (beta sqrt(pi))``,  ``Psi_p(s) = int_0^s psi_p``,
    ``psi_p(s) = erfc(rho_p / sqrt(4 kappa s)) g_z(s) / 2``,

    over the distinct distances rho_p > 0 of the y edges from the centre line and the x edges k (crossed at c_k),
    with ``b_kp = sum_(|y_e| = rho_p) sgn(y_e) (q_(k,e) - q_(k,e-1))`` and d_kp = b_(k-1)p - b_kp. psi_p vanishes
    with all its derivatives at s = 0, so dR is smooth: it is tabulated on the lattice of half cell-crossing times
    up to two contact durations (Psi_p by Gauss-Legendre on each lattice step, the edge sums as discrete
    convolutions, cubic Hermite between lattice points) and past them summed at the crossing times' Chebyshev
    nodes as the 1-D far sum. The whole response is 1/theta times a function analytic in 1/theta (each
    erf(rho/sqrt(4 kappa s)) g_z is 1/s times a power series in 1/s; the log of the integral cancels by the
    weights' zero sum), so its tail is interpolated as theta R (``tail_power`` = -1).

    The same interface as :class:`railtherm_green.pass_response.PassResponse` (``far``, ``with_tail``,
    ``cs``, ``duration``, ``tail_power``), so that green's sums over passes take either.
    """

    #: the tail interpolant is of theta R (:func:`railtherm_green.smooth_tail.with_smooth_tail`)
    tail_power = -1.0

    def __init__(self, x_edges, y_edges, flux, speed, depth, effusivity, diffusivity, snap):
        x = np.ascontiguousarray(x_edges, dtype=float)
        centre, rho, b = lateral_weights(y_edges, flux)
        order = np.argsort(rho)
        self.rho, self.b = np.ascontiguousarray(rho[order]), np.ascontiguousarray(b[:, order])
        self.base_flux = centre
        self.base = PassResponse(x, centre, speed, depth, effusivity, diffusivity, snap)
        self.cs, self.duration, self.scale = self.base.cs, self.base.duration, self.base.scale
        self.kappa = float(diffusivity)
        self.d = _edge_weights(self.b)
        self.c_edge = self.base.c_edge
        self.half, self.uniform, self.snap = self.base.half, self.base.uniform, self.base.snap
        # per degree of FAR_DEGREES: the crossing times' Chebyshev nodes (L,) and each distance's weights (L, P)
        self.far_sets = [_far_set(self.c_edge, self.d, self.duration, deg) for deg in FAR_DEGREES]
        self._psi = None

    def _lattice(self):
        """Psi_p on the lattice of half cell-crossing times up to two contact durations and where it starts."""
        if self._psi is None:
            self._psi = _psi_table(self.half, 4 * self.base.n, self.rho, self.cs, self.kappa, 0.5 * (_GAUSS_X + 1.0),
                                   0.5 * _GAUSS_W, _ERFC_TABLE)
        return self._psi

    def _on_lattice(self, theta):
        """dR at times theta (n,) before two contact durations on a uniform grid, (n, m): the discrete convolution
        at lattice points (within ``snap``), cubic Hermite between them (its slopes: psi_p convolved alike)."""
        big, first = self._lattice()
        last = big.shape[2] - 1
        d_lead = np.ascontiguousarray(self.d[::-1])
        at = np.rint(theta / self.half)
        on = np.abs(theta - at * self.half) <= self.snap
        out = np.empty((theta.size, self.cs.size))
        if on.all():
            return _lattice_sums(d_lead, big, 2, first, at.astype(np.int64)) * self.scale
        every = np.arange(last + 1)
        values = _lattice_sums(d_lead, big, 2, first, every)
        slopes = _lattice_sums(d_lead, _psi_points(self.half, last, self.rho, self.cs, self.kappa, _ERFC_TABLE), 2,
                               first, every)
        out[:] = _hermite(theta, self.half, values, slopes)
        return out * self.scale

    def delta(self, theta):
        """The lateral term dR at the times theta (n,) [s], (n, m): 0 at theta <= 0, on the lattice before two
        contact durations (a uniform grid; else by Gauss-Legendre on every cell), by the far sums after them."""
        theta = np.ascontiguousarray(theta, dtype=float)
        out = np.zeros((theta.size, self.cs.size))
        two_d = 2.0 * self.duration
        far = theta >= two_d
        near = (theta > 0.0) & ~far
        if far.any():
            out[far] = self._far_delta(theta[far])
        if near.any():
            if self.uniform:
                out[near] = self._on_lattice(theta[near])
            else:
                start, end = self.c_edge[1:], self.c_edge[:-1]
                out[near] = _cell_quadrature(theta[near], (start, end, np.ones(start.size), np.zeros(start.size),
                                                           self.b), self.rho, self.cs, self.kappa) * self.scale
        return out

    def _far_delta(self, theta, sets=None):
        """dR at times theta >= 2 D [s] by the far sums (the nodes of FAR_DEGREES[0] before 4 D, [1] after)."""
        sets = self.far_sets if sets is None else sets
        out = np.empty((theta.size, self.cs.size))
        late = theta >= 4.0 * self.duration
        for mask, (nodes, weights) in ((~late, sets[0]), (late, sets[1])):
            if mask.any():
                out[mask] = _far_lateral(np.ascontiguousarray(theta[mask]), nodes, weights, self.rho, self.cs,
                                         self.kappa, _ERFC_TABLE)
        return out * self.scale

    def far(self, theta):
        """The whole response at times theta >= 2 D [s] (:meth:`PassResponse.far` plus the lateral far sums)."""
        theta = np.ascontiguousarray(theta, dtype=float)
        return self.base.far(theta) + self._far_delta(theta)

    def __call__(self, theta):
        return self.with_tail(theta, math.inf, 0.0, 1.0, np.zeros((1, self.cs.size)))

    def with_tail(self, theta, after, lo, hi, coef):
        """The response at the times theta (n,) [s], (n, depths): from ``after`` [s] on by the tail interpolant
        coef of theta R (on [1/hi, 1/lo]; after = inf: none), before it the centre strip plus dR."""
        theta = np.ascontiguousarray(theta, dtype=float)
        out = np.empty((theta.size, self.cs.size))
        tail = theta >= after
        near = ~tail
        out[near] = self.base(theta[near]) + self.delta(theta[near])
        if tail.any():
            vals = np.empty((int(tail.sum()), self.cs.size))
            chebval_into(np.ascontiguousarray(theta[tail]), lo, hi, np.ascontiguousarray(coef.T), vals,
                         self.tail_power)
            out[tail] = vals
        return out


def _far_set(c_edge, d, duration, degree):
    """The Chebyshev-Lobatto nodes (degree + 1,) [s] of the crossing times and each lateral distance's far
    weights (degree + 1, P) [W/m^2 s]: :func:`railtherm_green.pass_response.far_weights_columns` of d."""
    return far_weights_columns(np.ascontiguousarray(c_edge, dtype=float), np.ascontiguousarray(d), float(duration),
                                int(degree))


def _cell_quadrature(theta, cells, rho, cs, kappa):
    """``sum_k sum_p b_kp int_(start_k)^(end_k) (f0_k + slope_k (c - start_k)) psi_p(theta - c) dc`` (n, m) at the
    times theta [s] by Gauss-Legendre (GAUSS points) on each piece, cut at theta (psi_p is smooth, flat at 0);
    ``cells`` = (start, end, f0, slope, b)."""
    return _piece_sums(theta, *(np.ascontiguousarray(v, dtype=float) for v in cells), rho, cs, kappa, _GAUSS_X,
                       _GAUSS_W, _ERFC_TABLE)


@numba.njit(cache=True)
def _piece_sums(theta, start, end, f0, slope, b, rho, cs, kappa, gx, gw, table):  # pragma: no cover - compiled
    """:func:`_cell_quadrature` compiled."""
    out = np.zeros((theta.size, cs.size))
    for i in range(theta.size):
        for k in range(start.size):
            lo, hi = start[k], min(end[k], theta[i])
            if hi <= lo:
                continue
            for a in range(gx.size):
                c = lo + 0.5 * (gx[a] + 1.0) * (hi - lo)
                s = theta[i] - c
                if s <= 0.0:
                    continue
                f = (f0[k] + slope[k] * (c - start[k])) * 0.5 * gw[a] * (hi - lo)
                lat = _lateral_factor(s, rho, kappa, b[k], table)
                if lat == 0.0:
                    continue
                for j in range(cs.size):
                    out[i, j] += f * lat * math.exp(-cs[j] / s) / math.sqrt(s)
    return out


def scheduled_lateral(theta, response, pieces):
    """The lateral term dR (n, m) of a pass heated under a schedule at the times theta > 0 after its arrival [s]:
    ``pieces`` = (start, end, cell, f0, slope): each cell's crossing cut at the schedule's times, with the cell
    index and the factor (value at the start, slope [1/s]) on it. Before two contact durations Gauss-Legendre on
    every piece; after them the far sums, their weights ``int f(c) b_p(c) l_l(c) dc`` of the Lagrange basis l_l of
    the crossing times' Chebyshev nodes integrated exactly (Gauss-Legendre of the basis' degree + 1 per piece)."""
    theta = np.ascontiguousarray(theta, dtype=float)
    start, end, cell, f0, slope = pieces
    b = np.ascontiguousarray(response.b[cell])
    out = np.zeros((theta.size, response.cs.size))
    near = theta < 2.0 * response.duration
    if near.any():
        out[near] = _cell_quadrature(theta[near], (start, end, f0, slope, b), response.rho, response.cs,
                                     response.kappa) * response.scale
    if (~near).any():
        sets = [(nodes, _scheduled_far_weights(nodes, start, end, f0, slope, b)) for nodes, _ in response.far_sets]
        out[~near] = response._far_delta(theta[~near], sets)
    return out


def _scheduled_far_weights(nodes, start, end, f0, slope, b):
    """``K_lp = int f(c) b_p(c) l_l(c) dc`` (L, P) over the pieces, l_l the Lagrange basis of ``nodes``."""
    gx, gw = np.polynomial.legendre.leggauss(nodes.size // 2 + 2)
    c = start[:, None] + 0.5 * (gx[None, :] + 1.0) * (end - start)[:, None]          # (pieces, gauss)
    f = (f0[:, None] + slope[:, None] * (c - start[:, None])) * 0.5 * gw[None, :] * (end - start)[:, None]
    diff = c[..., None] - nodes[None, None, :]                                          # (pieces, gauss, L)
    basis = np.empty_like(diff)
    for l in range(nodes.size):                       # the Lagrange basis in product form (17 or 13 nodes)
        others = np.delete(np.arange(nodes.size), l)
        basis[..., l] = np.prod(diff[..., others], axis=-1) / np.prod(nodes[l] - nodes[others])
    return np.ascontiguousarray(np.einsum("kg,kgl,kp->lp", f, basis, b))
