"""Conduction across green's strips in its transient histories: one pass's response at the fixed section of a
3-D contact, each strip's 1-D response weighted by the lateral Gaussian.

At high Péclet number the section sees the same history, shifted in time, at every x, so conduction along x
is negligible, while across the strips (y) it is not between passes: 83 ms after a pass its heat has spread
sqrt(4 kappa t) = 2 mm sideways, half an ellipse's semi-axis. The instantaneous point source of an insulated
half-space factorises into x, y and z parts; dropping only the x part (a delta in x) gives at the centre line
(y = 0, depth z) [1, 2]

``T(t) = int int q(t', y') G_y(y', t - t') g_z(t - t') dy' dt' / (beta sqrt(pi))``,
``G_y(y, s) = exp(-y^2/(4 kappa s)) / sqrt(4 pi kappa s)``, ``g_z(s) = exp(-z^2/(4 kappa s)) / sqrt(s)``,

q(t', y') the flux over the section point (x0, y') at t'. With q piecewise constant on green's cells, strip j
(y_j .. y_(j+1)) weighs its 1-D kernel by ``W_j(s) = (erf(y_(j+1)/sqrt(4 kappa s)) - erf(y_j/sqrt(4 kappa s)))/2``,
which tends to W_j(0+) = (sgn y_(j+1) - sgn y_j)/2 (the strip containing y = 0) as s -> 0 and sums to 1 over
strips covering all y (a band: unchanged). Splitting W_j = W_j(0+) - (W_j(0+) - W_j) and summing by parts over
the y edges gives the centre strip's 1-D response (:class:`railtherm_green.pass_response.PassResponse`) plus

``dR(theta) = sum_p sum_k d_kp Psi_p(theta - c_k) / (beta sqrt(pi))``,  ``Psi_p(s) = int_0^s psi_p``,
``psi_p(s) = erfc(rho_p / sqrt(4 kappa s)) g_z(s) / 2``,

over the distinct distances rho_p > 0 of the y edges from the centre line and the x edges k (crossed at c_k),
with ``b_kp = sum_(|y_e| = rho_p) sgn(y_e) (q_(k,e) - q_(k,e-1))`` and d_kp = b_(k-1)p - b_kp. psi_p vanishes
with all its derivatives at s = 0, so dR is smooth: it is tabulated on the lattice of half cell-crossing times up
to two contact durations (Psi_p by Gauss-Legendre on each lattice step, the edge sums as discrete convolutions,
cubic Hermite between lattice points) and past them summed at the crossing times' Chebyshev nodes as the 1-D far
sum. The whole response is 1/theta times a function analytic in 1/theta (each term erf(rho/sqrt(4 kappa s)) g_z
is 1/s times a power series in 1/s; the log of the integral cancels by the weights' zero sum), so its tail is
interpolated as theta R (``tail_power`` = -1). Derivation: docs/NOTES.md, "Green's transient".

References: [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, sections 2.9,
10.2 (the instantaneous point source). [2] M. Ertz, K. Knothe, A comparison of analytical and numerical methods
for the calculation of temperatures in wheel/rail contact, Wear 253 (2002) 498-508 (DOI not verified, see
docs/references.md).
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .pass_response import FAR_DEGREE, PassResponse, _far_weights
from .smooth_tail import chebval_into

__all__ = ["LateralPassResponse", "lateral_weights", "scheduled_lateral"]

#: Gauss-Legendre points per lattice step of the table of Psi_p
GAUSS = 4
#: erfc(x) < 2e-17 beyond this argument: a lateral term is dropped there
ERFC_ZERO = 5.9


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
    groups = np.unique(key[keep])
    rho = np.array([mag[key == g].max() for g in groups])
    b = np.stack([(jump[:, key == g] * sg[key == g]).sum(axis=1) for g in groups], axis=1) if groups.size else \
        np.zeros((q.shape[0], 0))
    live = np.any(b != 0.0, axis=0)
    return centre, rho[live], np.ascontiguousarray(b[:, live])


@numba.njit(cache=True)
def _lateral_factor(s, rho, kappa, weights):  # pragma: no cover - compiled
    """``sum_p weights[p] erfc(rho_p / sqrt(4 kappa s)) / 2`` at one s > 0 [s] (rho increasing: the sum stops
    where erfc is below 2e-17)."""
    inv = 0.5 / math.sqrt(kappa * s)
    acc = 0.0
    for p in range(rho.size):
        x = rho[p] * inv
        if x > ERFC_ZERO:
            break
        acc += weights[p] * 0.5 * math.erfc(x)
    return acc


@numba.njit(cache=True)
def _psi_tables(step, last, rho, cs, kappa, nodes, gweights):  # pragma: no cover - compiled
    """Psi_p and psi_p (module docstring) at the lattice points i step, i = 0 .. last: (P, m, last + 1) each, Psi
    by Gauss-Legendre (``nodes``, ``gweights`` on [0, 1]) on every lattice step, cumulated; rho increasing."""
    npts, m = rho.size, cs.size
    big = np.zeros((npts, m, last + 1))
    small = np.zeros((npts, m, last + 1))
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
                e = 0.5 * math.erfc(x)
                for j in range(m):
                    big[p, j, i + 1] += e * g[j]
        s = step * (i + 1)
        inv = 0.5 / math.sqrt(kappa * s)
        for p in range(npts):
            x = rho[p] * inv
            for j in range(m):
                big[p, j, i + 1] += big[p, j, i]
                if x <= ERFC_ZERO:
                    small[p, j, i + 1] = 0.5 * math.erfc(x) * math.exp(-cs[j] / s) / math.sqrt(s)
    return big, small


@numba.njit(cache=True)
def _lattice_sums(d_lead, table, stride):  # pragma: no cover - compiled
    """``sum_p sum_r d_lead[r, p] table[p, :, i - stride r]`` for every lattice point i, shape (last + 1, m):
    the edge r from the lead is crossed ``stride r`` lattice points after the arrival."""
    nr, npts = d_lead.shape
    _, m, size = table.shape
    acc = np.zeros((m, size))
    for p in range(npts):
        for r in range(nr):
            w = d_lead[r, p]
            shift = stride * r
            if w == 0.0 or shift >= size:
                continue
            for j in range(m):
                row = table[p, j]
                out = acc[j]
                for i in range(shift, size):
                    out[i] += w * row[i - shift]
    return acc.T.copy()


@numba.njit(cache=True)
def _far_lateral(theta, nodes, weights, rho, cs, kappa):  # pragma: no cover - compiled
    """``sum_l sum_p weights[p, l] psi_p(theta - c_l)`` at the times theta (n,) past the nodes c_l [s], (n, m)."""
    out = np.zeros((theta.size, cs.size))
    for i in range(theta.size):
        for l in range(nodes.size):
            s = theta[i] - nodes[l]
            if s <= 0.0:
                continue
            lat = _lateral_factor(s, rho, kappa, weights[:, l])
            if lat == 0.0:
                continue
            for j in range(cs.size):
                out[i, j] += lat * math.exp(-cs[j] / s) / math.sqrt(s)
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
    after arrival: the centre strip's 1-D response plus the lateral term dR of the module docstring.

    The same interface as :class:`railtherm_green.pass_response.PassResponse` (``far``, ``with_tail``,
    ``cs``, ``duration``, ``tail_power``), so that green's sums over passes take either.
    """

    #: the tail interpolant is of theta R (:func:`railtherm_green.smooth_tail.with_smooth_tail`)
    tail_power = -1.0

    def __init__(self, x_edges, y_edges, flux, speed, depth, effusivity, diffusivity, snap):
        x = np.ascontiguousarray(x_edges, dtype=float)
        centre, self.rho, b = lateral_weights(y_edges, flux)
        self.base_flux = centre
        order = np.argsort(self.rho)
        self.rho, b = np.ascontiguousarray(self.rho[order]), b[:, order]
        self.base = PassResponse(x, centre, speed, depth, effusivity, diffusivity, snap)
        self.cs, self.duration, self.scale = self.base.cs, self.base.duration, self.base.scale
        self.kappa = float(diffusivity)
        self.b = b
        self.d = _edge_weights(b)
        self.c_edge = self.base.c_edge
        self.far_nodes = _far_weights(self.c_edge, np.zeros(self.c_edge.size), self.duration, FAR_DEGREE)[0]
        self.far_weights = np.zeros((self.rho.size, self.far_nodes.size))
        for p in range(self.rho.size):                  # the crossing times' Chebyshev weights per distance
            self.far_weights[p] = _far_weights(self.c_edge, np.ascontiguousarray(self.d[:, p]), self.duration,
                                               FAR_DEGREE)[1]
        self.half = self.base.half
        self.uniform = self.base.uniform
        self._table = None

    def _tables(self):
        """dR and its slope at the lattice points i half, i = 0 .. 4 n (two contact durations), (4 n + 1, m) each."""
        if self._table is None:
            last = 4 * self.base.n
            nodes, gw = np.polynomial.legendre.leggauss(GAUSS)
            big, small = _psi_tables(self.half, last, self.rho, self.cs, self.kappa, 0.5 * (nodes + 1.0), 0.5 * gw)
            d_lead = np.ascontiguousarray(self.d[::-1])
            self._table = (_lattice_sums(d_lead, big, 2) * self.scale, _lattice_sums(d_lead, small, 2) * self.scale)
        return self._table

    def delta(self, theta):
        """The lateral term dR at the times theta (n,) [s], (n, m): 0 at theta <= 0, on the lattice table (cubic
        Hermite between its points) before two contact durations, by the far sum after them."""
        theta = np.ascontiguousarray(theta, dtype=float)
        out = np.zeros((theta.size, self.cs.size))
        two_d = 2.0 * self.duration
        far = theta >= two_d
        near = (theta > 0.0) & ~far
        if far.any():
            out[far] = self._far_delta(theta[far])
        if near.any():
            if self.uniform:
                values, slopes = self._tables()
                out[near] = _hermite(theta[near], self.half, values, slopes)
            else:
                out[near] = _cell_quadrature(theta[near], self._cells(), self.rho, self.cs, self.kappa) * self.scale
        return out

    def _cells(self):
        """Each cell's crossing [start, end] [s], factor 1 and no slope, and its lateral weights b (nx, P)."""
        start, end = self.c_edge[1:], self.c_edge[:-1]
        one = np.ones(start.size)
        return start, end, one, np.zeros(start.size), self.b

    def _far_delta(self, theta):
        return _far_lateral(theta, self.far_nodes, self.far_weights, self.rho, self.cs, self.kappa) * self.scale

    def far(self, theta):
        """The whole response at times theta >= 2 D [s] (:meth:`PassResponse.far` plus the lateral far sum)."""
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


def _cell_quadrature(theta, cells, rho, cs, kappa):
    """``sum_k sum_p b_kp int_(start_k)^(end_k) (f0_k + slope_k (c - start_k)) psi_p(theta - c) dc`` (n, m) at the
    times theta [s] by Gauss-Legendre (GAUSS points) on each piece, cut at theta (psi_p is smooth, flat at 0);
    ``cells`` = (start, end, f0, slope, b)."""
    gx, gw = np.polynomial.legendre.leggauss(GAUSS)
    return _piece_sums(theta, *(np.ascontiguousarray(v, dtype=float) for v in cells), rho, cs, kappa, gx, gw)


@numba.njit(cache=True)
def _piece_sums(theta, start, end, f0, slope, b, rho, cs, kappa, gx, gw):  # pragma: no cover - compiled
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
                lat = _lateral_factor(s, rho, kappa, b[k])
                if lat == 0.0:
                    continue
                for j in range(cs.size):
                    out[i, j] += f * lat * math.exp(-cs[j] / s) / math.sqrt(s)
    return out


def scheduled_lateral(theta, response, pieces):
    """The lateral term dR (n, m) of a pass heated under a schedule at the times theta > 0 after its arrival [s]:
    ``pieces`` = (start, end, cell, f0, slope): each cell's crossing cut at the schedule's times, with the cell
    index and the factor (value at the start, slope [1/s]) on it. Before two contact durations Gauss-Legendre on
    every piece; after them the far sum, its weights ``int f(c) b_p(c) l_l(c) dc`` of the Lagrange basis l_l of
    the crossing times' Chebyshev nodes integrated exactly (Gauss-Legendre of degree FAR_DEGREE + 1 per piece)."""
    theta = np.ascontiguousarray(theta, dtype=float)
    start, end, cell, f0, slope = pieces
    b = np.ascontiguousarray(response.b[cell])
    out = np.zeros((theta.size, response.cs.size))
    two_d = 2.0 * response.duration
    near = theta < two_d
    if near.any():
        out[near] = _cell_quadrature(theta[near], (start, end, f0, slope, b), response.rho, response.cs,
                                     response.kappa)
    if (~near).any():
        weights = _scheduled_far_weights(response.far_nodes, start, end, f0, slope, b)
        out[~near] = _far_lateral(theta[~near], response.far_nodes, weights, response.rho, response.cs,
                                  response.kappa)
    return out * response.scale


def _scheduled_far_weights(nodes, start, end, f0, slope, b):
    """``K_pl = int f(c) b_p(c) l_l(c) dc`` (P, L) over the pieces, l_l the Lagrange basis of ``nodes``."""
    gx, gw = np.polynomial.legendre.leggauss((nodes.size + 2) // 2 + 1)
    c = start[:, None] + 0.5 * (gx[None, :] + 1.0) * (end - start)[:, None]          # (pieces, gauss)
    f = (f0[:, None] + slope[:, None] * (c - start[:, None])) * 0.5 * gw[None, :] * (end - start)[:, None]
    diff = c[..., None] - nodes[None, None, :]                                          # (pieces, gauss, L)
    basis = np.empty_like(diff)
    for l in range(nodes.size):                       # the Lagrange basis, product form (L = 25 nodes)
        others = np.delete(np.arange(nodes.size), l)
        basis[..., l] = np.prod(diff[..., others], axis=-1) / np.prod(nodes[l] - nodes[others])
    return np.ascontiguousarray(np.einsum("kg,kgl,kp->pl", f, basis, b))
