"""The rolling operator's product for tractions mirrored about the grid's centre line along x, on one half.

With p_x even and p_y odd in y (steady rolling with longitudinal creepage on a y-symmetric patch), the product on
the half j >= ny/2 is, per wave number along x, a symmetric convolution along y: Toeplitz plus Hankel for the even
kernels B_xx, B_yy on the half-sample symmetric / antisymmetric extensions and the odd kernel B_xy between them.
They are diagonal in the DCT-II (even fields) and the DST-II (odd fields) of L >= ny points, with the even kernels'
DCT-I and the odd kernel's DST-I as symbols (S.A. Martucci, IEEE Trans. Signal Process. 42 (1994) 1038-1051,
doi:10.1109/78.295213): the transforms along y run on real arrays of L points instead of complex ones of M_y >= 2 ny
- 1 (half of the product's largest pass).
"""
from __future__ import annotations

import threading

import numpy as np
import scipy.fft as sfft

try:  # scipy's pocketfft binding: transforms into preallocated arrays
    from scipy.fft._pocketfft import pypocketfft as _pocketfft
except ImportError:  # pragma: no cover - older scipy
    _pocketfft = None

try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit
except Exception:  # numba missing or unusable
    njit = None

__all__ = ["MirroredProduct"]


def _symbols(spectra_x, ny, L):
    """The symbols along y of the kernels transformed along x, ``spectra_x[key]`` (M_x/2 + 1, >= ny) complex at the
    y offsets 0, 1, ...: the DCT-I of the even kernels over the offsets 0..L (C00, C11, (M_x/2 + 1, L + 1)) and the
    DST-I of the odd one over 1..L-1 (D01, (M_x/2 + 1, L), zero at frequency 0), the kernels zero beyond ny - 1."""
    out = []
    for key, even in (((0, 0), True), ((1, 1), True), ((0, 1), False)):
        k = np.zeros((spectra_x[key].shape[0], L + 1), dtype=complex)
        k[:, :ny] = spectra_x[key][:, :ny]
        if even:
            out.append(sfft.dct(k, type=1, axis=1, workers=1))
        else:
            d = np.zeros_like(k[:, :L])
            d[:, 1:] = sfft.dst(k[:, 1:L], type=1, axis=1, workers=1)
            out.append(d)
    return out


if njit is not None:
    @njit(cache=True, nogil=True, fastmath=True)
    def _combine(G, c00, c11, d01):
        """In place on G (2, R, L): G[0] = DCT-II of the even field, G[1] = DST-II of the odd one (index k: frequency
        k + 1) -> the DCT-II of the even output, C00 c0 - D01 s1, and the DST-II of the odd output,
        D01 c0 + C11 s1, with the DST's frequencies shifted by one."""
        R, L = G.shape[1], G.shape[2]
        for r in range(R):
            prev_s = G[1, r, 0] * 0
            for f in range(L):
                c0 = G[0, r, f]
                s_at_f = prev_s                      # s1 at frequency f (zero at f = 0)
                s_next = G[1, r, f]                  # s1 at frequency f + 1
                G[0, r, f] = c00[r, f] * c0 - d01[r, f] * s_at_f
                # the odd output at frequency f: D01 c0 + C11 s1, stored at index f - 1
                if f >= 1:
                    G[1, r, f - 1] = d01[r, f] * c0 + c11[r, f] * s_at_f
                prev_s = s_next
            G[1, r, L - 1] = c11[r, L] * prev_s      # frequency L: c0 = 0 and D01 = 0 there
else:  # pragma: no cover
    _combine = None


class MirroredProduct:
    """The rolling operator's product on the half j >= ny/2 of mirrored fields (x component even, y odd in y).

    Parameters
    ----------
    spectra_x : dict
        The kernels transformed along x at the y offsets 0 .. ny - 1, ``(out, in) -> (M_x/2 + 1, ny)`` complex
        (B_yx = B_xy).
    shape : (int, int)
        The element grid (nx, ny), ny even.
    mx : int
        The padded length along x.
    """

    def __init__(self, spectra_x, shape, mx):
        nx, ny = shape
        self.shape, self.mx, self.h = (nx, ny), mx, ny // 2
        self.L = L = sfft.next_fast_len(ny, real=True)
        c00, c11, d01 = _symbols(spectra_x, ny, L)      # C11 at frequencies 0 .. L: the DST-II's last is L
        self._sym = {np.dtype(np.complex128): (np.ascontiguousarray(c00[:, :L]), c11, d01)}
        self._local = threading.local()

    def _symbols_of(self, dt):
        """The symbols in the complex precision dt (the single-precision ones converted on first use)."""
        if dt not in self._sym:
            self._sym[dt] = tuple(s.astype(dt) for s in self._sym[np.dtype(np.complex128)])
        return self._sym[dt]

    def _work(self, real):
        """This thread's work arrays for fields of precision ``real``: the transforms (2, M_x/2 + 1, L) (columns
        h.. zero between calls) and the output (2, M_x, ny/2)."""
        work = getattr(self._local, "work", None)
        if work is None:
            work = self._local.work = {}
        key = np.dtype(real).char
        if key not in work:
            cplx = np.complex64 if key == "f" else np.complex128
            work[key] = (np.zeros((2, self.mx // 2 + 1, self.L), dtype=cplx), np.empty((2, self.mx, self.h), dtype=real))
        return work[key]

    def apply(self, buf):
        """The product on the columns j >= ny/2 of the fields buf (2, M_x, ny) (rows nx.. zero; the columns j < ny/2
        are not read): returns (2, M_x, ny/2) of the same precision, overwritten by the next call."""
        h, L = self.h, self.L
        G, out = self._work(buf.dtype)
        c00, c11, d01 = self._symbols_of(G.dtype)
        _pocketfft.r2c(buf[..., h:], (1,), True, 0, G[..., :h], 1)      # G's columns h.. stay zero
        Gr = G.view(buf.dtype).reshape(2, G.shape[1], L, 2)
        _pocketfft.dct(Gr[0], 2, (1,), 0, Gr[0], 1)
        _pocketfft.dst(Gr[1], 2, (1,), 0, Gr[1], 1)
        _combine(G, c00, c11, d01)
        _pocketfft.dct(Gr[0], 3, (1,), 2, Gr[0], 1)
        _pocketfft.dst(Gr[1], 3, (1,), 2, Gr[1], 1)
        _pocketfft.c2r(G[..., :h], (1,), self.mx, False, 2, out, 1)
        G[..., h:] = 0.0
        return out
