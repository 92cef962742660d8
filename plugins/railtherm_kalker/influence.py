"""Influence coefficients of uniform loads on rectangular elements and their FFT convolution.

Two quasi-identical elastic half-spaces (the normal and tangential problems decouple, Kalker's
quasi-identity) are loaded by piecewise-constant tractions on a uniform rectangular grid. The
displacement *difference* u = u(body 1) - u(body 2) at the centre of element I caused by a unit
traction on element J depends only on the offset I - J (a Toeplitz structure), so it is applied by a
zero-padded FFT (circulant embedding), O(N log N) per product, without dense matrices.

Normal (Love 1929, both bodies, contact modulus E*)::

    u_n = 1/(pi E*) int int p / r dA

Tangential (Boussinesq-Cerruti, both bodies, combined G and nu)::

    u_x = 1/(pi G) int int [(1 - nu)/r + nu (x - x')^2/r^3] p_x + nu (x - x')(y - y')/r^3 p_y dA
    u_y = 1/(pi G) int int nu (x - x')(y - y')/r^3 p_x + [(1 - nu)/r + nu (y - y')^2/r^3] p_y dA

The integrals over a rectangle follow from corner functions F with d2F/dxdy = integrand:
1/r -> x asinh(y/|x|) + y asinh(x/|y|); x^2/r^3 -> y asinh(x/|y|); y^2/r^3 -> x asinh(y/|x|);
xy/r^3 -> -r (terms depending on x or on y alone cancel in the corner sum and are left out).

Line contact (plane strain, per unit width): u = -(2 c/pi) int q(x') ln|x - x'| dx' with c = 1/E*
for the normal and c = (1 - nu)/G for the tangential problem; the element integral of ln|t| is
t ln|t| - t. The additive constant (the logarithm's length unit) is arbitrary in 2-D: it is absorbed
by the approach (normal) and cancels in the rolling derivative (tangential).

References
----------
.. [1] A.E.H. Love, The stress produced in a semi-infinite solid by pressure on part of the boundary,
   Phil. Trans. R. Soc. Lond. A 228 (1929) 377-420. doi:10.1098/rsta.1929.0009
.. [2] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990, ch. 5.
   doi:10.1007/978-94-015-7889-9
.. [3] K.L. Johnson, Contact Mechanics, 1985, eqs. (2.19), (3.86). doi:10.1017/CBO9781139171731
.. [4] S. Liu, Q. Wang, G. Liu, A versatile method of discrete convolution and FFT (DC-FFT) for
   contact analyses, Wear 243 (2000) 101-111. doi:10.1016/S0043-1648(00)00427-0
"""
from __future__ import annotations

import math

import numpy as np
import scipy.fft as sfft

__all__ = ["rectangle_integrals", "normal_kernel", "tangential_kernels", "line_kernel", "Convolution",
           "rolling_kernel"]


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
    X, Y = np.meshgrid(_offsets(nx, extra) * dx, _offsets(ny) * dy, indexing="ij")
    return rectangle_integrals("1/r", X, Y, dx, dy) / (math.pi * e_star)


def tangential_kernels(nx: int, ny: int, dx: float, dy: float, shear_modulus: float, poisson_ratio: float,
                       extra: int = 0) -> dict:
    """Boussinesq-Cerruti influence coefficients of the tangential problem for all element offsets.

    Parameters
    ----------
    nx, ny : int
        Elements along x and y [1].
    dx, dy : float
        Element sides [m].
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
    X, Y = np.meshgrid(_offsets(nx, extra) * dx, _offsets(ny) * dy, indexing="ij")
    nu, c = float(poisson_ratio), 1.0 / (math.pi * shear_modulus)
    inv_r = rectangle_integrals("1/r", X, Y, dx, dy)
    return {"xx": c * ((1.0 - nu) * inv_r + nu * rectangle_integrals("xx", X, Y, dx, dy)),
            "xy": c * nu * rectangle_integrals("xy", X, Y, dx, dy),
            "yy": c * ((1.0 - nu) * inv_r + nu * rectangle_integrals("yy", X, Y, dx, dy))}


def line_kernel(nx: int, dx: float, compliance: float, extra: int = 0, length: float | None = None) -> np.ndarray:
    """Influence coefficients of uniform strips on two half-planes (plane strain, per unit width).

    ``u(x) = -(2 c / pi) int q(x') ln(|x - x'| / L) dx'``.

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
        the grid: an additive constant, see the module docstring).

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


def rolling_kernel(kernel: np.ndarray, dx: float) -> np.ndarray:
    """Kernel of the rolling derivative (u(x + dx) - u(x)) / dx, the steady-state slip's displacement
    term discretised as CONTACT does (upwind: the material enters at the leading edge +x).

    Parameters
    ----------
    kernel : ndarray, shape (2 nx + 1, m)
        Influence coefficients with one extra offset on each side along x (``extra=1``).
    dx : float
        Element length along rolling [m].

    Returns
    -------
    ndarray, shape (2 nx - 1, m)
        ``(A[k + 1] - A[k]) / dx`` for offsets k = -(nx - 1) ... nx - 1 [1/Pa].
    """
    return (kernel[2:] - kernel[1:-1]) / dx


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

    Notes
    -----
    ``apply(p)`` with p of shape (ncomp, nx, ny) returns u of the same shape. ``single=True``
    evaluates in float32 (for inexact inner Krylov products; about twice as fast).
    """

    #: offsets kept in :attr:`near` on each side [elements]
    NEAR = 2

    def __init__(self, kernels: dict, shape: tuple[int, int], symmetric: bool = True):
        nx, ny = shape
        self.shape = (int(nx), int(ny))
        self.ncomp = 1 + max(max(k) for k in kernels)
        mx = sfft.next_fast_len(2 * nx - 1, real=True)
        my = sfft.next_fast_len(2 * ny - 1, real=True) if ny > 1 else 1
        self.padded = (mx, my)
        spectra = {}
        for key, k in kernels.items():
            k = np.asarray(k, dtype=float)
            if k.shape != (2 * nx - 1, 2 * ny - 1):
                raise ValueError(f"kernel {key} has shape {k.shape}, expected {(2 * nx - 1, 2 * ny - 1)}")
            emb = np.zeros((mx, my))
            # offset o goes to index o mod m (circulant embedding)
            ix = np.arange(-(nx - 1), nx) % mx
            iy = np.arange(-(ny - 1), ny) % my
            emb[np.ix_(ix, iy)] = k
            spectra[key] = sfft.rfft2(emb) if my > 1 else sfft.rfft(emb[:, 0])[:, None]
        if symmetric and (0, 1) in spectra and (1, 0) not in spectra:
            spectra[(1, 0)] = spectra[(0, 1)]
        #: the (0, 0) kernel at offset zero (an element's influence on itself)
        self.self_coefficient = float(np.asarray(kernels[(0, 0)])[nx - 1, ny - 1])
        #: the kernels at the offsets of the near neighbours, ``(out, in) -> ndarray (2 rx + 1, 2 ry + 1)``
        #: over offsets -rx..rx, -ry..ry (rx = min(NEAR, nx - 1), ry likewise); for local preconditioners
        rx, ry = min(self.NEAR, nx - 1), min(self.NEAR, ny - 1)
        self.near_radius = (rx, ry)
        self.near = {key: np.array(np.asarray(k, dtype=float)[nx - 1 - rx:nx + rx, ny - 1 - ry:ny + ry])
                     for key, k in kernels.items()}
        if symmetric and (0, 1) in self.near and (1, 0) not in self.near:
            self.near[(1, 0)] = self.near[(0, 1)]
        self._spec = spectra
        self._spec32 = {k: v.astype(np.complex64) for k, v in spectra.items()}
        self.products = 0

    def _fwd(self, a):
        if self.padded[1] == 1:
            return sfft.rfft(a[:, 0], n=self.padded[0])[:, None]
        return sfft.rfft2(a, s=self.padded)

    def _inv(self, f):
        nx, ny = self.shape
        if self.padded[1] == 1:
            return sfft.irfft(f[:, 0], n=self.padded[0])[:nx, None]
        return sfft.irfft2(f, s=self.padded)[:nx, :ny]

    def apply(self, p: np.ndarray, single: bool = False) -> np.ndarray:
        """u = A p for tractions p of shape (ncomp, nx, ny) [Pa]; returns (ncomp, nx, ny)."""
        self.products += 1
        dt = np.float32 if single else np.float64
        spec = self._spec32 if single else self._spec
        p = np.asarray(p, dtype=dt).reshape((self.ncomp,) + self.shape)
        fp = [self._fwd(p[j]) if np.any(p[j]) else None for j in range(self.ncomp)]
        out = np.zeros((self.ncomp,) + self.shape, dtype=dt)
        for i in range(self.ncomp):
            acc = None
            for j in range(self.ncomp):
                k = spec.get((i, j))
                if k is None or fp[j] is None:
                    continue
                acc = k * fp[j] if acc is None else acc + k * fp[j]
            if acc is not None:
                out[i] = self._inv(acc)
        return out
