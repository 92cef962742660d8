"""Strip quadrature of the 1-D moving-half-space Green function (seed eqs. 30-33).

At high Péclet number heat flows into each body only perpendicular to the surface, so every strip
y = const of the patch is an independent 1-D problem: a surface point that entered the patch at the
leading edge x = +a has been heated for the time t = (x' - x)/v by the flux it met at x' > x (material
flows in -x). For a body with effusivity beta = sqrt(lambda rho c) moving at speed v (seed eq. 32):
``theta(x, z) = 1 / (beta sqrt(pi v)) int_x^inf q(x') exp(-z^2 v / (4 kappa (x' - x))) dx' / sqrt(x' - x)``.
With q constant per cell the integral over each cell is exact: at the surface :func:`surface_weights`
(Toeplitz on a uniform grid, :func:`toeplitz_weights`), in depth the primitive :func:`_depth_primitive`
(seed eq. 34 is its uniform-flux case). All strips of both bodies are one product ``W @ [q_wheel,
q_rail]`` scaled by ``1/(beta sqrt(pi v))`` per body (:func:`upper_matmul`, :func:`toeplitz_matmul`);
long field grids use :func:`surface_rise`'s trail interpolation and FFT.

References: Ertz & Knothe, Wear 253 (2002) 498-508 (DOI not verified, docs/references.md); Carslaw &
Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford 1959, section 2.9.
"""
from __future__ import annotations

import math
from collections import OrderedDict

import numba
import numpy as np
from scipy import fft as sfft
from scipy.special import erfc

__all__ = ["surface_weights", "toeplitz_weights", "surface_rise", "depth_rise", "strip_prefactor",
           "upper_matmul", "toeplitz_matmul", "toeplitz_columns", "fft_toeplitz", "trail_toeplitz"]

_CACHE: "OrderedDict[bytes, np.ndarray]" = OrderedDict()
_CACHE_BYTES = 64 * 2 ** 20
#: relative tolerance on the cell widths for a grid to count as uniform (linspace round-off ~1e-14)
_UNIFORM_RTOL = 1e-9


def _cached(key: bytes, build):
    w = _CACHE.get(key)
    if w is None:
        w = build()
        w.setflags(write=False)
        if w.nbytes <= _CACHE_BYTES:
            _CACHE[key] = w
            while sum(v.nbytes for v in _CACHE.values()) > _CACHE_BYTES:
                _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(key)
    return w


def _uniform_step(x_edges: np.ndarray) -> float | None:
    d = np.diff(x_edges)
    h = float(d.mean())
    return h if h > 0 and np.all(np.abs(d - h) <= _UNIFORM_RTOL * h) else None


def toeplitz_weights(nx: int, h: float) -> np.ndarray:
    """First row w_k, k = 0..nx-1, of the surface weights on a uniform grid of step h [m^0.5].

    ``w_0 = sqrt(2 h)`` (the upstream half of the own cell), ``w_k = 2 (sqrt((k+1/2) h) - sqrt((k-1/2) h))``.
    """
    def build():
        k = np.arange(nx, dtype=float)
        w = np.empty(nx)
        w[0] = math.sqrt(2.0 * h)
        w[1:] = 2.0 * math.sqrt(h) / (np.sqrt(k[1:] + 0.5) + np.sqrt(k[1:] - 0.5))
        return w
    return _cached(b"T" + np.array([nx, h]).tobytes(), build)


def _weights(x_edges: np.ndarray) -> np.ndarray:
    xc = 0.5 * (x_edges[1:] + x_edges[:-1])
    s = x_edges[None, :] - xc[:, None]            # (nx, nx+1): edge j minus centre i
    r = np.sqrt(np.clip(s, 0.0, None))
    return 2.0 * (r[:, 1:] - r[:, :-1])           # W[i, j] = int over cell j, x' >= x_i, of ds/sqrt(s)


@numba.njit(cache=True)
def upper_matmul(w: np.ndarray, q: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """``W @ q`` for an upper-triangular W (nx, nx) and q (nx, m), skipping the zero triangle.

    A small single-threaded numba loop (0.2-0.3 ms at 216 x 90): a BLAS matmul is as fast with one thread
    but 4-20x slower and erratic when OpenBLAS spreads this small product over two busy cores (measured).
    """
    nx, m = q.shape
    out = np.zeros((nx, m))
    for i in range(nx):
        for j in range(i, nx):
            wij = w[i, j]
            for c in range(m):
                out[i, c] += wij * q[j, c]
    return out


@numba.njit(cache=True)
def toeplitz_matmul(w: np.ndarray, q: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """``W @ q`` for the upper-triangular Toeplitz W[i, i+k] = w[k] and q (nx, m)."""
    nx, m = q.shape
    out = np.zeros((nx, m))
    for i in range(nx):
        for k in range(nx - i):
            wk = w[k]
            for c in range(m):
                out[i, c] += wk * q[i + k, c]
    return out


def surface_weights(x_edges: np.ndarray) -> np.ndarray:
    """Exact cell weights of the surface kernel 1/sqrt(x' - x) at the cell centres (full matrix).

    Parameters
    ----------
    x_edges : ndarray, shape (nx+1,)
        Increasing cell edges along the rolling direction [m].

    Returns
    -------
    ndarray, shape (nx, nx)
        ``W[i, j] = int_{cell j, x' >= x_i} dx' / sqrt(x' - x_i)`` [m^0.5]; upper triangular.
        Read-only and cached per grid (up to 64 MB of matrices).

    Notes
    -----
    With ``int dx'/sqrt(s) = 2 sqrt(s)``, cell j contributes ``2 (sqrt(x_{j+1/2} - x_i) - sqrt(max(x_{j-1/2}
    - x_i, 0)))`` at the centre x_i; the cell that contains x_i contributes only its upstream half,
    ``sqrt(2 dx)`` (CONTACT's Fortran strip sum adds a cell's own heat twice, biasing maxima ~10 % high at
    dx = 0.2 mm). The weights depend only on the grid, not on the body, its speed or material. On a
    uniform grid W is Toeplitz (:func:`toeplitz_weights`, O(nx) memory).
    """
    x_edges = np.ascontiguousarray(x_edges, dtype=float)
    return _cached(b"W" + x_edges.tobytes(), lambda: _weights(x_edges))


def _heated_rows(q: np.ndarray, behind: int) -> tuple[np.ndarray, int, int, int]:
    """``(q2, nx, j0, j1)``: the columns ``q`` as a float (rows, m) array, the rows nx of the grid (q's and
    the ``behind`` zero rows before them) and the support [j0, j1) of q's nonzero rows on that grid
    ((0, 0) when q is all zero): only those rows carry heat into :func:`fft_toeplitz` and :func:`trail_toeplitz`."""
    q2 = q.reshape(q.shape[0], -1)
    rows = np.flatnonzero(np.any(q2 != 0.0, axis=1))
    if not rows.size:
        return q2, q2.shape[0] + behind, 0, 0
    return q2, q2.shape[0] + behind, behind + int(rows[0]), behind + int(rows[-1]) + 1


def fft_toeplitz(w: np.ndarray, q: np.ndarray, scale: float = 1.0, out: np.ndarray | None = None,
                 behind: int = 0) -> np.ndarray:
    """``scale W @ q`` for the upper-triangular Toeplitz W[i, i+k] = w[k] by FFT: O(nx log nx) per column.

    ``out[i] = sum_k w[k] q[i+k]`` is a correlation. Only the rows where q is not zero (the patch of an
    extended grid: zero flux behind it) enter the transform, and rows upstream of the last of them are
    0: for the support [j0, j1) of q the full convolution of ``q[j0:j1]`` with the reversed ``w[:j1]``
    (length (j1 - j0) + j1 - 1, padded to a fast FFT size) holds every row, ``out[i] = c[j1 - j0 - 1 + i]``.
    Used for the long extended grids of a scene with ``field`` (the direct loop is O(nx^2)); agrees with :func:`toeplitz_matmul` to ~1e-15 of the maximum
    (tests/test_green_kernel.py).

    Parameters
    ----------
    w : ndarray, shape (nx,) or (nx, m)
        First row of W, one for all columns of q or one per column [any unit].
    q : ndarray, shape (nx - behind,) or (nx - behind, m)
        Columns to multiply [any unit]: their last nx - ``behind`` rows (the first ``behind`` are 0); a
        single column broadcasts against a 2-D ``w``.
    scale : float
        Factor applied to the product (in the frequency domain, free) [any unit].
    out : ndarray, shape (nx, m), optional
        Where to write the product (every row is written); a view into a larger array avoids a copy.
    behind : int
        Rows of zeros before ``q`` (the cells of an extended grid behind the patch) [1].

    Returns
    -------
    ndarray, shape (nx, max(m_w, m_q)) (or (nx,) when both are 1-D)
        ``scale W @ q`` (``out`` when given).
    """
    w = np.asarray(w, dtype=float)
    q = np.asarray(q, dtype=float)
    behind = int(behind)
    q2, nx, j0, j1 = _heated_rows(q, behind)
    flat = w.ndim == 1 and q.ndim == 1 and out is None
    w2 = w.reshape(nx, -1)
    if out is None:
        out = np.empty((nx, max(w2.shape[1], q2.shape[1])))
    if j1:
        p = j1 - j0
        n = sfft.next_fast_len(p + j1 - 1, real=True)
        # transforms along axis 0 (pocketfft batches the columns): the result's rows are out's rows, no
        # transposed copies (15-20 % faster than transforming contiguous transposed rows, measured)
        wt = sfft.rfft(w2[:j1][::-1], n, axis=0)
        if scale != 1.0:
            wt *= scale
        qt = sfft.rfft(q2[j0 - behind:j1 - behind], n, axis=0)
        qt = qt * wt if qt.shape[1] < wt.shape[1] else np.multiply(qt, wt, out=qt)
        out[:j1] = sfft.irfft(qt, n, axis=0)[p - 1:p - 1 + j1]
    out[j1:] = 0.0
    return out[:, 0] if flat else out


#: Chebyshev nodes of the far-trail sums (:func:`trail_toeplitz`); with :data:`_NEAR_FRACTION` the far rows
#: are 2 patch half-lengths or more from the singularity of w(k), error ~ (2 + sqrt 3)^-24 ~ 2e-14 (measured
#: 1e-15 of the maximum, tests/test_green_kernel.py)
_TRAIL_NODES = 24
#: rows behind the heated ones within this fraction of their number are summed exactly (dense product)
_NEAR_FRACTION = 0.5


def _surface_weight(k: np.ndarray, h: float) -> np.ndarray:
    """The surface weight ``w_k = 2 sqrt(h) / (sqrt(k + 1/2) + sqrt(k - 1/2))`` of :func:`toeplitz_weights`
    at real k >= 1/2 [m^0.5]: analytic there (branch points at k = +-1/2)."""
    return 2.0 * math.sqrt(h) / (np.sqrt(k + 0.5) + np.sqrt(k - 0.5))


def _chebyshev_basis(n: int, p: int) -> tuple[np.ndarray, np.ndarray]:
    """p Chebyshev points (first kind) on [0, n-1] and their Lagrange basis at 0..n-1, shape (n, p)
    (barycentric form; a node that falls on an integer gets its exact row)."""
    def build():
        j = np.arange(p)
        theta = (2 * j + 1) * np.pi / (2 * p)
        nodes = 0.5 * (n - 1) * (1.0 + np.cos(theta))
        bw = (-1.0) ** j * np.sin(theta)
        diff = np.arange(n, dtype=float)[:, None] - nodes[None, :]
        hit = diff == 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = bw / diff
            basis = t / t.sum(axis=1, keepdims=True)
        rows = np.flatnonzero(hit.any(axis=1))
        basis[rows] = hit[rows].astype(float)
        return np.concatenate([nodes[None, :], basis])
    nb = _cached(b"C" + np.array([n, p]).tobytes(), build)
    return nb[0], nb[1:]


def trail_toeplitz(h: float, q: np.ndarray, scale: float = 1.0, out: np.ndarray | None = None,
                   behind: int = 0) -> np.ndarray:
    """``scale W @ q`` for the surface weights W[i, i+k] = w_k of a uniform grid (:func:`toeplitz_weights`),
    on the long grid of a scene with ``field``: heat on the patch only, a long trail without heat behind it.

    ``out[i] = sum_k w_k q[i+k]``. With q's heated rows [j0, j1) (n = j1 - j0 of them), the rows upstream
    of them are 0, the heated rows and the ``n/2`` rows behind them are summed exactly (one dense
    product), and each row further behind, at d >= n/2 cells from the first heated row, by Chebyshev
    interpolation of the smooth weight ``k -> w(d + k)`` over the heated rows:
    ``out[j0 - d] = sum_m w(d + t_m) M_m`` with the moments ``M_m = sum_k L_m(k) q[j0 + k]`` of the p =
    24 Lagrange polynomials L_m. w(k) has its branch points at k = +-1/2, at least n/2 from the
    interpolation interval, so the interpolation error is ~ (2 + sqrt 3)^-24 ~ 2e-14 of the local values
    (measured: agrees with :func:`toeplitz_matmul` and :func:`fft_toeplitz` to ~1e-15 of the maximum,
    tests/test_green_kernel.py). Cost O((n^2 + nx p) m) for m columns, against
    O(nx log nx m) by FFT: on the benchmark's ellipse (896 x 256 cells) 0.8 ms against the FFT's 3.2 ms.

    Parameters
    ----------
    h : float
        Cell width of the uniform grid [m].
    q : ndarray, shape (nx - behind,) or (nx - behind, m)
        Columns to multiply [any unit]: the last nx - ``behind`` rows (the first ``behind`` are 0).
    scale : float
        Factor applied to the product [any unit].
    out, behind : ndarray, int
        As :func:`fft_toeplitz`: where to write the product, shape (nx, m), optional, and the rows of zeros
        before ``q`` (the cells of an extended grid behind the patch) [1].

    Returns
    -------
    ndarray, shape (nx, m) (or (nx,) for a 1-D q without ``out``)
        ``scale W @ q`` [unit of q times m^0.5 times scale].
    """
    q = np.asarray(q, dtype=float)
    behind = int(behind)
    flat = q.ndim == 1 and out is None
    q2, nx, j0, j1 = _heated_rows(q, behind)
    if out is None:
        out = np.empty((nx, q2.shape[1]))
    if not j1:
        out[:] = 0.0
        return out[:, 0] if flat else out
    n = j1 - j0
    heated = q2[j0 - behind:j1 - behind]
    near = max(int(math.ceil(_NEAR_FRACTION * n)), 1)
    p = _TRAIL_NODES
    i0 = j0 - near + 1 if j0 >= near and n > 2 * p else 0       # rows [i0, j1) exactly, [0, i0) by the nodes
    w = toeplitz_weights(j1, h)
    k = j0 + np.arange(n)[None, :] - np.arange(i0, j1)[:, None]             # (j1 - i0, n): k = j - i
    dense = np.where(k >= 0, w[np.clip(k, 0, j1 - 1)], 0.0)
    if scale != 1.0:
        dense *= scale
    np.matmul(dense, heated, out=out[i0:j1])
    if i0:
        nodes, basis = _chebyshev_basis(n, p)
        moments = basis.T @ heated                                             # (p, m)
        d = j0 - np.arange(i0, dtype=float)                                    # >= near
        far = _surface_weight(d[:, None] + nodes[None, :], h)                  # (i0, p)
        if scale != 1.0:
            far *= scale
        np.matmul(far, moments, out=out[:i0])
    out[j1:] = 0.0
    return out[:, 0] if flat else out


@numba.njit(cache=True)
def toeplitz_columns(w: np.ndarray, q: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """``out[i, c] = sum_k w[k, c] q[i + k]``: one upper-triangular Toeplitz matrix per column c
    (the depths of :func:`depth_rise`) applied to one vector q (nx,)."""
    nx, m = w.shape
    out = np.zeros((nx, m))
    for i in range(nx):
        for k in range(nx - i):
            qk = q[i + k]
            if qk != 0.0:
                for c in range(m):
                    out[i, c] += w[k, c] * qk
    return out


def _apply(x_edges: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """W @ q2 for q2 of shape (nx, m), Toeplitz path on uniform grids."""
    x_edges = np.ascontiguousarray(x_edges, dtype=float)
    q2 = np.ascontiguousarray(q2, dtype=float)
    h = _uniform_step(x_edges)
    if h is not None:
        return toeplitz_matmul(toeplitz_weights(q2.shape[0], h), q2)
    return upper_matmul(surface_weights(x_edges), q2)


def _prepend_zeros(q: np.ndarray, behind: int) -> np.ndarray:
    """``q`` with ``behind`` cells of zero flux before its x axis (axis 1 of a 3-D (body, x, y) flux, else 0)."""
    pad = [(0, 0)] * q.ndim
    pad[1 if q.ndim == 3 else 0] = (behind, 0)
    return np.pad(q, pad)


def strip_prefactor(effusivity: float, speed: float) -> float:
    """Factor ``1 / (beta sqrt(pi v))`` of the strip integral [K m^1.5 / W].

    Parameters
    ----------
    effusivity : float
        beta = sqrt(lambda rho c) [W s^0.5 / (m^2 K)].
    speed : float
        Speed of the body's surface through the patch [m/s], > 0.
    """
    return 1.0 / (effusivity * math.sqrt(math.pi * speed))


def surface_rise(x_edges: np.ndarray, flux: np.ndarray, effusivity, speed, extended: bool = False,
                 behind: int = 0) -> np.ndarray:
    """Surface temperature rise at the cell centres for a piecewise constant flux.

    On the extended grid of a scene with ``field`` (~7x longer, zero flux behind the patch: ``behind`` =
    the cells before it) the heated rows and the half patch behind them are summed exactly (one dense
    product) and the long trail further behind by Chebyshev interpolation of the smooth weight over the
    heated rows (:func:`trail_toeplitz`, rank 24, ~1e-15 of the maximum); :func:`depth_rise` transforms
    only the heated rows by FFT (:func:`fft_toeplitz`). On the benchmark's ellipse (896 x 256 cells, 41
    depths): surface 0.8 ms, depth 1.0 ms (benchmarks/test_green_field_benchmark.py).

    Parameters
    ----------
    x_edges : ndarray, shape (nx+1,)
        Cell edges along the rolling direction [m] (material flows in -x, enters at the last edge).
    flux : ndarray, shape (nbody, nx - behind, ny) or (nx - behind, ny) or (nx - behind,)
        Heat flux into the body per cell [W/m^2] of the last nx - ``behind`` cells.
    effusivity : float or sequence of float
        beta [W s^0.5 / (m^2 K)] per body (one value per leading entry of a 3-D ``flux``).
    speed : float or sequence of float
        Body surface speed [m/s] per body.
    extended : bool
        The long grid of a ``field`` (uniform grids): each strip's heated rows and the trail behind them by
        :func:`trail_toeplitz`.
    behind : int
        Cells of zero flux before ``flux`` (the extended grid behind the patch) [1].

    Returns
    -------
    ndarray, shape of ``flux`` with nx along x
        Temperature rise [K].
    """
    q = np.asarray(flux, dtype=float)
    behind = int(behind)
    h = _uniform_step(np.asarray(x_edges, dtype=float)) if extended else None
    if behind and h is None:         # the direct sums: the zero rows explicitly
        q, behind = _prepend_zeros(q, behind), 0
    if q.ndim == 3:
        nb, nx, ny = q.shape
        nx += behind
        k = np.asarray([strip_prefactor(b, v) for b, v in
                        zip(np.broadcast_to(effusivity, (nb,)), np.broadcast_to(speed, (nb,)))])
        if h is not None:
            # a long (extended) grid: body by body, only the strips that get heat, written in place
            out = np.zeros((nb, nx, ny))
            for b in range(nb):
                live = np.flatnonzero(np.any(q[b] != 0.0, axis=0))      # strips without heat stay at 0
                if not live.size:
                    continue
                if live[-1] - live[0] + 1 == live.size:        # one run of strips: written in place
                    cols = slice(int(live[0]), int(live[-1]) + 1)
                    trail_toeplitz(h, q[b][:, cols], k[b], out=out[b][:, cols], behind=behind)
                else:
                    out[b][:, live] = trail_toeplitz(h, q[b][:, live], k[b], behind=behind)
            return out
        # one product for all strips of all bodies: (nx, nx) @ (nx, nb*ny)
        t = _apply(x_edges, q.transpose(1, 0, 2).reshape(nx, nb * ny))
        return t.reshape(nx, nb, ny).transpose(1, 0, 2) * k[:, None, None]
    k = strip_prefactor(float(effusivity), float(speed))
    if h is not None:                # the long grid of a field, uniform
        t = trail_toeplitz(h, q.reshape(q.shape[0], -1), k, behind=behind)
        return t.reshape((q.shape[0] + behind,) + q.shape[1:])
    return _apply(x_edges, q.reshape(q.shape[0], -1)).reshape(q.shape) * k


def _depth_primitive(s: np.ndarray, c) -> np.ndarray:
    """``F(s) = int_0^s exp(-c/u) du / sqrt(u) = 2 sqrt(s) exp(-c/s) - 2 sqrt(pi c) erfc(sqrt(c/s))`` [m^0.5]
    for s >= 0 and c = z^2 v / (4 kappa) >= 0 [m] (broadcast); F(0) = 0, F = 2 sqrt(s) at c = 0."""
    s, c = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(c, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.where(s > 0.0, c / s, np.inf)
        f = 2.0 * np.sqrt(s) * np.exp(-ratio) - 2.0 * np.sqrt(np.pi * c) * erfc(np.sqrt(ratio))
    return np.where(c == 0.0, 2.0 * np.sqrt(s), f)


@numba.njit(cache=True)
def _toeplitz_depth_weights(nx, h, c):  # pragma: no cover - compiled
    """``w[e, k] = F(s_{e+1}, c_k) - F(s_e, c_k)``, s_e = max((e - 1/2) h, 0), of :func:`_depth_primitive`
    in one pass (no temporaries; numpy's version cost 3 ms for 900 x 41 on a field grid)."""
    nz = c.size
    w = np.empty((nx, nz))
    for k in range(nz):
        ck = c[k]
        rc = 2.0 * math.sqrt(math.pi * ck)
        prev = 0.0                                               # F(0) = 0
        for e in range(nx):
            s = (e + 0.5) * h
            if ck == 0.0:
                cur = 2.0 * math.sqrt(s)
            else:
                r = ck / s
                cur = 2.0 * math.sqrt(s) * math.exp(-r) - rc * math.erfc(math.sqrt(r))
            w[e, k] = cur - prev
            prev = cur
    return w


def depth_rise(x_edges: np.ndarray, flux: np.ndarray, z: np.ndarray, effusivity: float, speed: float,
               diffusivity: float, extended: bool = False, behind: int = 0) -> np.ndarray:
    """Temperature rise below the surface of one strip (seed eq. 32), exact per cell.

    Parameters
    ----------
    x_edges : ndarray, shape (nx+1,)
        Cell edges along the rolling direction [m].
    flux : ndarray, shape (nx - behind,)
        Heat flux into the body per cell [W/m^2] of the last nx - ``behind`` cells.
    z : ndarray, shape (nz,)
        Depths [m], >= 0.
    effusivity : float
        beta [W s^0.5 / (m^2 K)].
    speed : float
        Body surface speed [m/s].
    diffusivity : float
        kappa [m^2/s].
    extended : bool
        The long grid of a ``field`` (uniform grids): all depths in one FFT product (:func:`fft_toeplitz`;
        the depth weights' essential singularity exp(-c/s) rules out :func:`trail_toeplitz`'s interpolation).
    behind : int
        Cells of zero flux before ``flux`` (the extended grid behind the patch) [1].

    Returns
    -------
    ndarray, shape (nx, nz)
        Temperature rise [K] at the cell centres and depths z.
    """
    x_edges = np.ascontiguousarray(x_edges, dtype=float)
    q = np.ascontiguousarray(flux, dtype=float)
    z = np.asarray(z, dtype=float).ravel()
    h = _uniform_step(x_edges)
    behind = int(behind)
    if not np.any(q):
        return np.zeros((q.size + behind, z.size))
    if behind and not (extended and h is not None):       # the direct sums: the zero rows explicitly
        q, behind = _prepend_zeros(q, behind), 0
    nx = q.size + behind
    c = z * z * speed / (4.0 * diffusivity)                       # (nz,) [m]
    if h is not None:
        # Toeplitz: distances edge - centre are (e - 1/2) h, e = j - i; all depths at once, (nx+1, nz)
        w = _toeplitz_depth_weights(nx, h, c)                                # (nx, nz): w[k, depth]
        if extended:
            out = fft_toeplitz(w, q, behind=behind)
        else:
            out = toeplitz_columns(np.ascontiguousarray(w), q)
    else:
        xc = 0.5 * (x_edges[1:] + x_edges[:-1])
        s = np.clip(x_edges[None, :] - xc[:, None], 0.0, None)       # (nx, nx+1)
        out = np.empty((q.size, z.size))
        for k, ck in enumerate(c):
            f = _depth_primitive(s, ck)
            out[:, k] = (f[:, 1:] - f[:, :-1]) @ q
    return out * strip_prefactor(effusivity, speed)


