"""Influence coefficients of uniform loads on rectangular elements and their FFT convolution.

Two quasi-identical half-spaces (the normal and tangential problems decouple) carry piecewise-constant tractions
on a uniform grid. The displacement difference u = u(body 1) - u(body 2) at element I from a unit traction on J
depends only on I - J (Toeplitz), so it is applied by a zero-padded FFT (circulant embedding), O(N log N) per
product without dense matrices. Kernels: normal, Love's ``u_n = 1/(pi E*) int int p / r dA`` (:func:`normal_kernel`);
tangential, Boussinesq-Cerruti (:func:`tangential_kernels`); line contact in plane strain (:func:`line_kernel`).

References
----------
.. [1] A.E.H. Love, Phil. Trans. R. Soc. Lond. A 228 (1929) 377-420. doi:10.1098/rsta.1929.0009
.. [2] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990, ch. 5. doi:10.1007/978-94-015-7889-9
.. [3] K.L. Johnson, Contact Mechanics, 1985, eqs. (2.19), (3.86). doi:10.1017/CBO9781139171731
.. [4] S. Liu, Q. Wang, G. Liu, A versatile method of discrete convolution and FFT (DC-FFT) for contact analyses,
   Wear 243 (2000) 101-111. doi:10.1016/S0043-1648(00)00427-0
"""
from __future__ import annotations

import functools
import math
import threading

import numpy as np
import scipy.fft as sfft

from ._mirror import MirroredProduct, _combine
from ._work import _periodic_work_arrays, _work_arrays
from ._quadrant import (ROLLING_EXTRA, _quadrant_differences_cached, mirror_quadrant, place_even,
                        quadrant_differences, tangential_quadrants)

try:  # scipy's pocketfft binding: transforms into preallocated arrays (``out``); scipy.fft's public functions otherwise
    from scipy.fft._pocketfft import pypocketfft as _pocketfft
except Exception:  # pragma: no cover - another scipy layout
    _pocketfft = None

__all__ = ["rectangle_integrals", "normal_kernel", "tangential_kernels", "line_kernel", "Convolution",
           "rolling_kernel", "normal_operator", "element_size"]


def _times_asinh(a, b):
    """a asinh(b/|a|), 0 where a = 0 (its limit)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        out = a * np.arcsinh(b / np.abs(a))
    return np.where(a == 0.0, 0.0, out)


def _corner(kind, x, y):
    if kind == "1/r":
        return _times_asinh(x, y) + _times_asinh(y, x)
    if kind == "xx":
        return _times_asinh(y, x)
    if kind == "yy":
        return _times_asinh(x, y)
    if kind == "xy":
        return -np.hypot(x, y)
    raise ValueError(kind)


def rectangle_integrals(kind: str, X, Y, dx: float, dy: float):
    """Integral of a half-space kernel over the rectangle |x'| <= dx/2, |y'| <= dy/2.

    The sum over the four corners of a function F with d2F/dxdy = integrand: 1/r -> x asinh(y/|x|) +
    y asinh(x/|y|); x^2/r^3 -> y asinh(x/|y|); y^2/r^3 -> x asinh(y/|x|); xy/r^3 -> -r (terms depending on x or
    on y alone cancel in the corner sum and are left out).

    Parameters
    ----------
    kind : {"1/r", "xx", "yy", "xy"}
        Integrand 1/r, (x-x')^2/r^3, (y-y')^2/r^3 or (x-x')(y-y')/r^3 with r = |(x-x', y-y')|.
    X, Y : array_like
        Field points relative to the rectangle's centre [m].
    dx, dy : float
        Rectangle sides [m].

    Returns
    -------
    ndarray
        The integral [m].
    """
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float)
    hx, hy = 0.5 * dx, 0.5 * dy
    return (_corner(kind, X + hx, Y + hy) - _corner(kind, X - hx, Y + hy)
            - _corner(kind, X + hx, Y - hy) + _corner(kind, X - hx, Y - hy))


def _offsets(n: int, extra: int = 0) -> np.ndarray:
    """Offsets -(n - 1) - extra ... (n - 1) + extra [elements]."""
    return np.arange(-(n - 1) - extra, n + extra)


def normal_kernel(nx: int, ny: int, dx: float, dy: float, e_star: float, extra: int = 0) -> np.ndarray:
    """Love's influence coefficients of the normal problem for all element offsets.

    Parameters
    ----------
    nx, ny : int
        Elements along x and y [1].
    dx, dy : float
        Element sides [m].
    e_star : float
        Contact modulus E* [Pa].
    extra : int
        Extra offsets along x on each side [1].

    Returns
    -------
    ndarray, shape (2 nx - 1 + 2 extra, 2 ny - 1)
        Normal displacement difference [m/Pa] at offset (i - j, k - l); index 0 is offset
        -(nx - 1) - extra.
    """
    xa, ya, _ = quadrant_differences(nx + extra, ny, dx, dy)
    return mirror_quadrant((xa + ya) / (math.pi * e_star), nx + extra, ny)


def tangential_kernels(nx: int, ny: int, dx: float, dy: float, shear_modulus: float, poisson_ratio: float,
                       extra: int = 0) -> dict:
    """Boussinesq-Cerruti influence coefficients of the tangential problem for all element offsets::

        u_x = 1/(pi G) int int [(1 - nu)/r + nu (x - x')^2/r^3] p_x + nu (x - x')(y - y')/r^3 p_y dA
        u_y = 1/(pi G) int int nu (x - x')(y - y')/r^3 p_x + [(1 - nu)/r + nu (y - y')^2/r^3] p_y dA

    Parameters
    ----------
    nx, ny, dx, dy : int, int, float, float
        Elements along x and y [1] and element sides [m], as in :func:`normal_kernel`.
    shear_modulus : float
        Combined shear modulus G [Pa].
    poisson_ratio : float
        Combined Poisson's ratio nu [1].
    extra : int
        Extra offsets along x on each side [1] (the rolling derivative needs one).

    Returns
    -------
    dict
        ``{"xx", "xy", "yy"}`` -> ndarray of shape (2 nx - 1 + 2 extra, 2 ny - 1) [m/Pa]
        (``A_yx = A_xy``).
    """
    q = tangential_quadrants(nx + extra, ny, dx, dy, shear_modulus, poisson_ratio)
    return {name: mirror_quadrant(q[name], nx + extra, ny, odd=name == "xy") for name in ("xx", "xy", "yy")}


def line_kernel(nx: int, dx: float, compliance: float, extra: int = 0, length: float | None = None) -> np.ndarray:
    """Influence coefficients of uniform strips on two half-planes (plane strain, per unit width).

    ``u(x) = -(2 c / pi) int q(x') ln(|x - x'| / L) dx'``; the element integral of ln|t| is t ln|t| - t. The
    additive constant (the length unit L) is arbitrary in 2-D: it is absorbed by the approach (normal problem)
    and cancels in the rolling derivative (tangential).

    Parameters
    ----------
    nx : int
        Elements [1].
    dx : float
        Element length [m].
    compliance : float
        c [1/Pa]: 1/E* for the normal problem, (1 - nu)/G for the tangential one.
    extra : int
        Extra offsets on each side [1].
    length : float, optional
        Length unit L of the logarithm [m] (default 4 e nx dx, which makes the kernel positive on
        the grid: an additive constant, see above).

    Returns
    -------
    ndarray, shape (2 nx - 1 + 2 extra, 1)
        Displacement difference per unit traction [m/Pa].
    """
    L = float(length) if length is not None else 4.0 * math.e * nx * dx
    t = _offsets(nx, extra) * dx

    def prim(s):
        s = np.asarray(s, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            v = s * np.log(np.abs(s) / L) - s
        return np.where(s == 0.0, 0.0, v)

    k = -(2.0 * compliance / math.pi) * (prim(t + 0.5 * dx) - prim(t - 0.5 * dx))
    return k[:, None]


def rolling_kernel(kernel: np.ndarray, dx: float, order: int = 1) -> np.ndarray:
    """Kernel of the rolling derivative du/dx of the steady-state slip, upwind (the material enters at the
    leading edge +x).

    ``order = 1``: ``(u(x + dx) - u(x)) / dx``, CONTACT's discretisation, the derivative at x + dx/2 (first
    order at the element centre). ``order = 2``: ``(-u(x + 2 dx) + 4 u(x + dx) - 3 u(x)) / (2 dx)``, the
    second-order upwind difference at the element centre, where the traction and Coulomb's law are
    collocated. Its symbol is the first-order one times ``(3 - e^{i k dx}) / 2`` (real part between 1 and 2):
    dissipative like the first-order difference (real part of the symbol ``-(1 - cos k dx)^2 / dx <= 0``
    against ``-(1 - cos k dx) / dx``) but only at O(dx^3) for the long waves, where it is consistent to O(dx^2).

    Parameters
    ----------
    kernel : ndarray, shape (2 nx - 1 + 2 order, m)
        Influence coefficients with ``order`` extra offsets on each side along x (``extra=order``).
    dx : float
        Element length along rolling [m].
    order : {1, 2}
        Order of the difference [1].

    Returns
    -------
    ndarray, shape (2 nx - 1, m)
        The rolling kernel for offsets k = -(nx - 1) ... nx - 1 [1/Pa]: ``(A[k + 1] - A[k]) / dx`` or
        ``(-A[k + 2] + 4 A[k + 1] - 3 A[k]) / (2 dx)``.

    References
    ----------
    .. [1] R.J. LeVeque, Finite Difference Methods for Ordinary and Partial Differential Equations, SIAM,
       2007, sec. 10.10 (one-sided second-order differences; the upwind Beam-Warming stencil).
       doi:10.1137/1.9780898717839
    """
    if order == 1:
        return (kernel[2:] - kernel[1:-1]) / dx
    if order == 2:
        return (-kernel[4:] + 4.0 * kernel[3:-1] - 3.0 * kernel[2:-2]) / (2.0 * dx)
    raise ValueError(f"order = {order!r}: the rolling difference is of order 1 or 2")


class Convolution:
    """Toeplitz (discrete convolution) operator on an (nx, ny) element grid applied by zero-padded FFT.

    Parameters
    ----------
    kernels : dict
        ``(out, in) -> ndarray`` of shape (2 nx - 1, 2 ny - 1) over the offsets (index 0 is offset
        -(n - 1)); components are numbered 0 (x or normal) and 1 (y). A missing (out, in) pair is
        zero; ``(1, 0)`` defaults to ``(0, 1)`` when ``symmetric``.
    shape : (int, int)
        Element grid (nx, ny); ny = 1 for a line contact.
    symmetric : bool
        Whether the cross kernel is shared (``A_yx = A_xy``).
    near_kernels : dict, optional
        Kernels (as ``kernels``, or already cut to the offsets of :attr:`near`, shape (2 rx + 1, 2 ry + 1)) whose
        offsets near zero are kept in :attr:`near`, the cut that the local preconditioners invert (default:
        ``kernels``).
    circulant : ndarray, optional
        For a one-component operator: the kernel over the offsets -(M/2) ... M/2 of the periodic grid M of
        the preconditioner (``(2 (M_x // 2) + 1, 2 (M_y // 2) + 1)``), whose circulant (Strang's choice) is
        inverted by :meth:`precondition`.
    placed : bool
        The kernels are given already placed circulantly on the padded grid (shape :attr:`padded`, offset o at
        index o mod M, zero elsewhere; :func:`railtherm_kalker.tangential_model.rolling_operator_kernels`)
        instead of over the offsets.
    circulant_grid : (int, int), optional
        That periodic grid M (default :attr:`padded`). The inverse of Love's circulant is nearly local (its
        symbol grows like |k|), so a grid as small as the element grid (:func:`normal_operator`) preconditions
        as well as the padded one at a quarter of the transform's size.

    Notes
    -----
    ``apply(p)`` with p of shape (ncomp, nx, ny) returns u of the same shape. The padded grid is the
    smallest fast real-FFT length >= 2 n - 1 per axis (the circulant embedding of an n-element
    Toeplitz operator needs 2 n - 1). All components are transformed together, one worker, as two 1-D
    passes (:meth:`_fwd`, :meth:`_inv`) that skip the padding's zero columns: 15-30 % less time per
    product than ``scipy.fft.rfftn`` of the padded field. ``single=True`` evaluates in float32 (for inexact inner Krylov
    products and preconditioners; about twice as fast).
    """

    #: offsets kept in :attr:`near` on each side [elements]
    NEAR = 2

    def __init__(self, kernels: dict, shape: tuple[int, int], symmetric: bool = True, circulant=None,
                 near_kernels: dict | None = None, circulant_grid: tuple[int, int] | None = None,
                 placed: bool = False):
        nx, ny = shape
        self.shape = (int(nx), int(ny))
        self.ncomp = 1 + max(max(k) for k in kernels)
        mx = sfft.next_fast_len(2 * nx - 1, real=True)
        my = sfft.next_fast_len(2 * ny - 1, real=True) if ny > 1 else 1
        self.padded = (mx, my)
        rx, ry = min(self.NEAR, nx - 1), min(self.NEAR, ny - 1)
        spectra = {}
        for key, k in kernels.items():
            k = np.asarray(k, dtype=float)
            want = (mx, my) if placed else (2 * nx - 1, 2 * ny - 1)
            if k.shape != want:
                raise ValueError(f"kernel {key} has shape {k.shape}, expected {want}")
            spectra[key] = k if placed else self._embed(k, nx - 1, ny - 1)    # placed: transformed when first used
        if symmetric and (0, 1) in spectra and (1, 0) not in spectra:
            spectra[(1, 0)] = spectra[(0, 1)]
        if placed:      # offset o at o mod M: the offsets -r..r of the near neighbours by index
            kernels = {key: np.asarray(k)[np.ix_(np.arange(-rx, rx + 1) % mx, np.arange(-ry, ry + 1) % my)]
                       for key, k in kernels.items()}
        #: the (0, 0) kernel at offset zero (an element's influence on itself)
        self.self_coefficient = float(np.asarray(kernels[(0, 0)])[(rx, ry) if placed else (nx - 1, ny - 1)])
        #: the kernels at the offsets of the near neighbours, ``(out, in) -> ndarray (2 rx + 1, 2 ry + 1)``
        #: over offsets -rx..rx, -ry..ry (rx = min(NEAR, nx - 1), ry likewise); for local preconditioners
        self.near_radius = (rx, ry)
        self.near = {key: np.array(np.asarray(k, dtype=float)[nx - 1 - rx:nx + rx, ny - 1 - ry:ny + ry]
                                   if np.shape(k) != (2 * rx + 1, 2 * ry + 1) else k, dtype=float)
                     for key, k in (kernels if near_kernels is None else near_kernels).items()}
        if symmetric and (0, 1) in self.near and (1, 0) not in self.near:
            self.near[(1, 0)] = self.near[(0, 1)]
        self._spec_cache = None if placed else spectra
        self._placed_kernels = spectra if placed else None
        self._lazy = threading.Lock()             # the spectra and the mirrored product are made on first use
        self._spec32_cache = None
        self._inverse32 = None
        #: the periodic grid of the preconditioner's circulant (:meth:`precondition`)
        self.circulant_grid = self.padded if circulant_grid is None else (int(circulant_grid[0]),
                                                                          int(circulant_grid[1]))
        if circulant is not None:
            c = np.asarray(circulant, dtype=float)
            cx, cy = self.circulant_grid
            if self.circulant_grid == self.padded:
                lam = self._embed(c, mx // 2, my // 2).real
            else:
                if cx < nx or cy < ny or my == 1:
                    raise ValueError(f"circulant grid {self.circulant_grid} smaller than the elements {self.shape}")
                emb = np.zeros((cx, cy))
                emb[np.ix_(np.arange(-(cx // 2), cx // 2 + 1) % cx, np.arange(-(cy // 2), cy // 2 + 1) % cy)] = c
                lam = sfft.rfft2(emb, workers=1).real
            if lam.min() <= 0.0:
                raise ValueError("the circulant of the kernel is not positive definite")
            self._inverse32 = (1.0 / lam).astype(np.float32)
        self.products = 0
        self._buffered_ok = _pocketfft is not None and my > 1
        self._local_half = threading.local()

    @property
    def _spec(self):
        """The kernels' spectra in the layout of :meth:`_fwd`; for kernels given placed, transformed on the first
        whole-grid product (never for the normal operator of a gap symmetric in x and y, whose solve runs on the
        folded operator, :mod:`railtherm_kalker._fold`, nor for the rolling operator of a problem mirrored about its
        centre line, :attr:`mirrored_product`). Under a lock: threads may share a cached operator."""
        if self._spec_cache is None:
            with self._lazy:
                if self._spec_cache is None:
                    spectra, done = {}, {}
                    for key, k in self._placed_kernels.items():
                        if id(k) not in done:
                            done[id(k)] = self._spectrum(k)
                        spectra[key] = done[id(k)]
                    self._spec_cache, self._placed_kernels = spectra, None
        return self._spec_cache

    def _mirrorable(self):
        """Whether :meth:`apply_at` can take mirrored fields by :class:`railtherm_kalker._mirror.MirroredProduct`."""
        return self.ncomp == 2 and self.shape[1] % 2 == 0 and self._buffered_ok and _combine is not None

    @property
    def _spec32(self):
        """The spectra in single precision, converted on the first single-precision product (the normal operator
        never needs them: its preconditioner has its own)."""
        if self._spec32_cache is None:
            self._spec32_cache = {k: v.astype(np.complex64) for k, v in self._spec.items()}
        return self._spec32_cache

    def _embed(self, k, hx, hy):
        """Spectrum of kernel k over offsets -hx..hx, -hy..hy placed circulantly (offset o at o mod M), in the
        layout of :meth:`_fwd` (real transform along x, complex along y)."""
        mx, my = self.padded
        emb = np.zeros((mx, my))
        if 2 * hx + 1 <= mx and 2 * hy + 1 <= my:      # the four quadrants by slices (offset o at o mod M)
            emb[:hx + 1, :hy + 1] = k[hx:, hy:]
            emb[:hx + 1, my - hy:] = k[hx:, :hy]
            emb[mx - hx:, :hy + 1] = k[:hx, hy:]
            emb[mx - hx:, my - hy:] = k[:hx, :hy]
        else:
            emb[np.ix_(np.arange(-hx, hx + 1) % mx, np.arange(-hy, hy + 1) % my)] = k
        return self._spectrum(emb)

    def _spectrum(self, emb):
        """Spectrum of a kernel placed circulantly on the padded grid, in the layout of :meth:`_fwd`."""
        return self._along_y(self._along_x(emb))

    def _along_x(self, emb):
        """The real transform along x of a kernel placed on the padded grid (or of some of its columns),
        (M_x/2 + 1, columns) complex."""
        if _pocketfft is None or self.padded[1] == 1:
            return sfft.rfft(emb, axis=0, workers=1)
        f = np.empty((self.padded[0] // 2 + 1, emb.shape[1]), dtype=complex)
        _pocketfft.r2c(emb, (0,), True, 0, f, 1)
        return f

    def _along_y(self, f):
        """The complex transform along y of :meth:`_along_x`'s f, in place where the pocketfft binding is there."""
        if self.padded[1] == 1:
            return f
        if _pocketfft is None:
            return sfft.fft(f, axis=1, workers=1, overwrite_x=True)
        return _pocketfft.c2c(f, (1,), True, 0, f, 1)

    def _fwd(self, a):
        """Spectra of the fields a (..., nx, ny), zero-padded to M: a real transform along x of the ny
        data columns, then a complex one along y of the mx/2 + 1 rows (the padding's zero columns are
        not transformed along x: about a quarter of a 2-D real transform saved)."""
        f = sfft.rfft(a, n=self.padded[0], axis=-2, workers=1)
        if self.padded[1] == 1:
            return f
        return sfft.fft(f, n=self.padded[1], axis=-1, workers=1, overwrite_x=True)

    def _inv(self, f):
        """Fields (..., nx, ny) of the spectra f: the inverse of :meth:`_fwd` cut to the grid (the padding's
        columns are dropped before the real inverse along x)."""
        nx, ny = self.shape
        if self.padded[1] > 1:
            f = sfft.ifft(f, axis=-1, workers=1, overwrite_x=True)[..., :ny]
        return sfft.irfft(f, n=self.padded[0], axis=-2, workers=1)[..., :nx, :]

    def _product(self, fp, spec):
        """Spectra of the outputs from the inputs' spectra fp (ncomp, ...): sum_j spec[(i, j)] fp[j]."""
        if self.ncomp == 2 and _mac2 is not None and fp.ndim == 3:
            return _mac2(fp, spec[(0, 0)], spec[(0, 1)], spec[(1, 0)], spec[(1, 1)])
        acc = np.empty_like(fp)
        for i in range(self.ncomp):
            acc[i] = spec[(i, 0)] * fp[0] if (i, 0) in spec else 0.0
            for j in range(1, self.ncomp):
                if (i, j) in spec:
                    acc[i] += spec[(i, j)] * fp[j]
        return acc

    def apply(self, p: np.ndarray, single: bool = False) -> np.ndarray:
        """u = A p for tractions p of shape (ncomp, nx, ny) [Pa]; returns (ncomp, nx, ny)."""
        self.products += 1
        dt = np.float32 if single else np.float64
        spec = self._spec32 if single else self._spec
        p = np.asarray(p, dtype=dt).reshape((self.ncomp,) + self.shape)
        if self._buffered_ok:
            nx = self.shape[0]
            work = self._work_arrays(dt, self.ncomp)
            work[0][:, :nx, :] = p                   # rows nx.. stay zero
            work[3] = None                           # no longer apply_at's field
            return self._buffered(work, spec)[:, :nx, :].copy()
        if self.ncomp == 1:
            return self._inv(spec[(0, 0)] * self._fwd(p[0]))[None]
        return self._inv(self._product(self._fwd(p), spec))

    def _work_arrays(self, dt, nc):
        """The work arrays of precision dt for nc fields on this operator's padded grid (:func:`_work_arrays`)."""
        (mx, my), ny = self.padded, self.shape[1]
        return _work_arrays(np.dtype(dt).char, nc, mx, ny, my, threading.get_ident())

    def _buffered(self, work, spec, mirrored=False):
        """Inverse transform of ``spec`` times the spectra of the padded fields work[0], in the work arrays (no
        allocation: with scipy.fft's functions the temporaries of a product at 200^2 elements are 0.3-0.6 MB each,
        and their allocation's page faults made a float64 product 2-3 times slower). Returns work[2] (nc, M_x, ny),
        overwritten by the next call. ``mirrored``: two fields with x component even and y component odd about the
        grid's centre line along x (:meth:`apply_at`), given and returned on the columns j >= ny/2 only (the
        transforms along x of the other half are their mirror images)."""
        buf, half, out, F = work[0], work[1], work[2], work[4]
        ny = self.shape[1]
        if mirrored:
            h = ny // 2
            _pocketfft.r2c(buf[..., h:], (1,), True, 0, half[..., h:ny], 1)
            half[0, :, h - 1::-1] = half[0, :, h:ny]
            np.negative(half[1, :, h:ny], out=half[1, :, h - 1::-1])
        else:
            _pocketfft.r2c(buf, (1,), True, 0, half[..., :ny], 1)      # half's columns ny.. stay zero
        _pocketfft.c2c(half, (2,), True, 0, F, 1)
        if F.shape[0] == 1:
            np.multiply(F[0], spec[(0, 0)] if isinstance(spec, dict) else spec, out=F[0])
        elif F.shape[0] == 2 and _mac2 is not None:
            _mac2(F, spec[(0, 0)], spec[(0, 1)], spec[(1, 0)], spec[(1, 1)], F)
        else:
            F[...] = self._product(F, spec)
        _pocketfft.c2c(F, (2,), False, 2, F, 1)
        lo = ny // 2 if mirrored else 0
        _pocketfft.c2r(F[..., lo:ny], (1,), self.padded[0], False, 2, out[..., lo:], 1)
        return out

    def apply_at(self, v: np.ndarray, idx: np.ndarray, single: bool = False, mirrored: bool = False) -> np.ndarray:
        """(A p)[idx] for the tractions p that are v on the elements ``idx`` and zero elsewhere.

        v : ndarray (ncomp, len(idx)) [Pa]; idx: flat indices into the (nx, ny) grid. The values are
        scattered straight into the array padded along x (a flat index i ny + j is the same in the
        (M_x, ny) array) and gathered from the unpadded inverse: no zero-padding copies. Returns
        (ncomp, len(idx)), float32 when ``single``. ``mirrored`` (two components, ny even, idx on the columns
        j >= ny/2): p is also -- x component even, y component odd -- the mirror image of v on the elements
        (i, ny - 1 - j); the transforms along x run on half of the columns.
        """
        self.products += 1
        nc, ny, (mx, my) = self.ncomp, self.shape[1], self.padded
        dt = np.float32 if single else np.float64
        spec = self._spec32 if single else self._spec
        v = np.asarray(v, dtype=dt).reshape(nc, -1)
        if mirrored and not (self._buffered_ok and nc == 2 and ny % 2 == 0):
            twin = idx - 2 * (idx % ny) + ny - 1           # the general path on both halves
            out = self.apply_at(np.hstack([v, v * np.array([[1.0], [-1.0]], dtype=dt)]), np.concatenate([idx, twin]),
                                single=single)
            return out[:, :idx.size]
        if mirrored:
            work = self._work_arrays(dt, nc)
            buf = work[0].reshape(nc, mx * ny)
            if work[3] is not idx:
                buf[...] = 0.0
                work[3] = idx
            _scatter(buf, idx, v)
            if self.mirrored_product is None:
                return _gather(self._buffered(work, spec, mirrored=True).reshape(nc, mx * ny), idx)
            h = ny // 2
            at = self._half_index(idx)
            return _gather(self.mirrored_product.apply(work[0]).reshape(nc, mx * h), at)
        if self._buffered_ok:
            work = self._work_arrays(dt, nc)
            buf = work[0].reshape(nc, mx * ny)
            if work[3] is not idx:                   # other elements than the last call's: clear the field
                buf[...] = 0.0
                work[3] = idx
            _scatter(buf, idx, v)
            return _gather(self._buffered(work, spec).reshape(nc, mx * ny), idx)
        buf = np.zeros((nc, mx * ny), dtype=dt)
        _scatter(buf, idx, v)
        f = sfft.rfft(buf.reshape(nc, mx, ny), axis=-2, workers=1)
        if my > 1:
            f = sfft.fft(f, n=my, axis=-1, workers=1, overwrite_x=True)
        f = self._product(f, spec)
        if my > 1:
            f = sfft.ifft(f, axis=-1, workers=1, overwrite_x=True)[..., :ny]
        u = sfft.irfft(f, n=mx, axis=-2, workers=1)
        return _gather(u.reshape(nc, mx * ny), idx)

    @property
    def mirrored_product(self):
        """The product on one half of mirrored fields by DCT/DST along y (:class:`railtherm_kalker._mirror.
        MirroredProduct`), made on the first mirrored product; None where it does not apply (one component, odd ny,
        no pocketfft binding or numba): :meth:`apply_at` then transforms the whole padded grid along y."""
        mp = getattr(self, "_mirrored_product", False)
        if mp is False:
            with self._lazy:
                mp = getattr(self, "_mirrored_product", False)
                if mp is False:
                    mp = None
                    if self._mirrorable():
                        mp = MirroredProduct(self._mirror_kernels(), self.shape, self.padded[0])
                    self._mirrored_product = mp
        return mp

    def _mirror_kernels(self):
        """The kernels transformed along x at the y offsets 0 .. ny - 1 (columns :ny); called under the lock."""
        keys, ny = ((0, 0), (0, 1), (1, 1)), self.shape[1]
        if self._placed_kernels is not None:          # the whole spectra not made (yet): the ny columns along x
            return {key: self._along_x(self._placed_kernels[key][:, :ny]) for key in keys}
        return {key: sfft.ifft(self._spec_cache[key], axis=1, workers=1)[:, :ny] for key in keys}

    def _half_index(self, idx):
        """Flat indices of the elements idx (columns j >= ny/2) in the half grid (M_x, ny/2); the last one kept."""
        last = getattr(self._local_half, "last", None)
        if last is not None and last[0] is idx:
            return last[1]
        ny = self.shape[1]
        h = ny // 2
        at = (idx // ny) * h + (idx % ny - h)
        self._local_half.last = (idx, at)
        return at

    def precondition(self, r: np.ndarray) -> np.ndarray:
        """The inverse of the Strang circulant applied to r (nx, ny), in float32 (an approximate inverse of A
        whose error is corrected by the Krylov iteration); returns float64 (nx, ny)."""
        if self._inverse32 is None:
            raise ValueError("no circulant given for this operator")
        if self.circulant_grid != self.padded:
            return self._precondition_periodic(r)
        if self._buffered_ok:
            nx = self.shape[0]
            work = self._work_arrays(np.float32, 1)
            work[0][0, :nx, :] = r
            work[3] = None
            return self._buffered(work, self._inverse32)[0, :nx, :].astype(float)
        return self._inv(self._inverse32 * self._fwd(np.asarray(r, dtype=np.float32))).astype(float)


    def _precondition_periodic(self, r):
        """:meth:`precondition` on the circulant's own periodic grid (:attr:`circulant_grid`, at least the
        element grid; the fields are zero beyond the elements): one 2-D real transform pair in float32."""
        nx, ny = self.shape
        cx, cy = self.circulant_grid
        if _pocketfft is None or not self._buffered_ok:
            a = np.zeros((cx, cy), dtype=np.float32)
            a[:nx, :ny] = r
            u = sfft.irfft2(sfft.rfft2(a, workers=1) * self._inverse32, s=(cx, cy), workers=1)
            return u[:nx, :ny].astype(float)
        a, f, out = _periodic_work_arrays(cx, cy, threading.get_ident())
        a[:nx, :ny] = r                                      # the rest of a stays zero
        _pocketfft.r2c(a, (0, 1), True, 0, f, 1)
        np.multiply(f, self._inverse32, out=f)
        _pocketfft.c2r(f, (0, 1), cy, False, 2, out, 1)
        return out[:nx, :ny].astype(float)

try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit

    @njit(cache=True, nogil=True, fastmath=True)
    def _mac2(fp, s00, s01, s10, s11, out=None):
        """The two-component spectral product in one pass (no temporaries); ``out`` may be ``fp``."""
        if out is None:
            out = np.empty_like(fp)
        n0, n1 = fp.shape[1], fp.shape[2]
        for i in range(n0):
            for j in range(n1):
                a, b = fp[0, i, j], fp[1, i, j]
                out[0, i, j] = s00[i, j] * a + s01[i, j] * b
                out[1, i, j] = s10[i, j] * a + s11[i, j] * b
        return out
except Exception:  # numba missing or unusable
    _mac2 = None


def _scatter(buf, idx, v):
    """buf[c, idx[k]] = v[c, k] for each component c (np.put: as fast as a compiled pass at the main study's sizes,
    a few microseconds, without its compilation)."""
    for c in range(v.shape[0]):
        np.put(buf[c], idx, v[c])


def _gather(u, idx):
    """u[:, idx] (np.take along the last axis): a new (nc, idx.size) array."""
    return np.take(u, idx, axis=1)


def element_size(edges) -> float:
    """Element size of uniform edges [m], (last - first) / n rounded to 12 significant digits: the key of the
    operator caches, so that grids equal up to round-off (patches at other positions) share one operator."""
    return float(f"{(float(edges[-1]) - float(edges[0])) / (len(edges) - 1):.12g}")


@functools.lru_cache(maxsize=4)
def normal_operator(nx: int, ny: int, dx: float, dy: float | None, e_star: float) -> Convolution:
    """Love's normal operator on an (nx, ny) grid with its circulant preconditioner, computed once per grid.

    Cached (keyed by the grid and the contact modulus) so that the solves of a study, a friction loop
    and a wheelset's patches on the same grid share the influence coefficients and their spectra.

    Parameters
    ----------
    nx, ny : int
        Elements [1] (ny = 1 and dy None for a line contact).
    dx, dy : float
        Element sides [m].
    e_star : float
        Contact modulus E* [Pa].
    """
    mx = sfft.next_fast_len(2 * nx - 1, real=True)
    if dy is None:
        L = 4.0 * math.e * nx * dx
        return Convolution({(0, 0): line_kernel(nx, dx, 1.0 / e_star, length=L)}, (nx, 1),
                           circulant=line_kernel(mx // 2 + 1, dx, 1.0 / e_star, length=L))
    my = sfft.next_fast_len(2 * ny - 1, real=True)
    if ny == 1:      # one row: the circulant on the padded grid
        cx, cy = mx, my
    else:            # the periodic element grid (Convolution's circulant_grid)
        cx, cy = sfft.next_fast_len(nx, real=True), sfft.next_fast_len(ny, real=True)
    # the quadrant of the rolling operator of this grid (ROLLING_EXTRA more offsets along x) when it covers this one
    hx, hy = max(nx, cx // 2 + 1), max(ny, cy // 2 + 1)
    if hx <= nx + ROLLING_EXTRA and hy <= ny:
        xa, ya, _ = _quadrant_differences_cached(nx + ROLLING_EXTRA, ny, float(dx), float(dy))
    else:
        xa, ya, _ = quadrant_differences(hx, hy, dx, dy)
    q = (xa[:hx, :hy] + ya[:hx, :hy]) / (math.pi * e_star)
    conv = Convolution({(0, 0): place_even(q, nx, ny, mx, my)}, (nx, ny), placed=True,
                       circulant_grid=None if ny == 1 else (cx, cy),
                       circulant=mirror_quadrant(q, cx // 2 + 1, cy // 2 + 1))
    #: the kernel at the offsets 0 ... >= nx - 1, 0 ... >= ny - 1 (the normal solver's folded operator for gaps
    #: symmetric in x and y, :mod:`railtherm_kalker._fold`)
    conv.kernel_quadrant = q
    return conv
