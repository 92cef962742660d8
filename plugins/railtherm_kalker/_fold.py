"""The normal problem of a gap symmetric in x and y, solved on one quadrant of the element grid.

A gap symmetric about the grid's centre lines (a centred Hertzian contact) has a pressure symmetric in x and y, and
the active-set CG of :func:`railtherm_kalker.normal_solver.solve_normal` keeps its iterates symmetric from a
symmetric start. On the quadrant, Love's operator is Toeplitz plus Hankel, ``u[a] = sum_q p[q] (K[a - q] +
K[a + q + 1])`` per axis: the symmetric convolution of a half-sample symmetric field with an even kernel, evaluated
exactly by DCT-II, the kernel's DCT-I and the inverse DCT-II (Martucci) on L >= n - 1 points per axis, about a third
of the padded FFT product's time, on a quarter of the elements. The circulant preconditioner folds likewise (a
DCT-II of n/2 points). Same iterations as the whole grid, pressure equal to round-off (tests/test_kalker_solver.py).

References
----------
.. [1] S.A. Martucci, Symmetric convolution and the discrete sine and cosine transforms, IEEE Trans. Signal
   Process. 42 (1994) 1038-1051. doi:10.1109/78.295213
"""
from __future__ import annotations

import threading

import numpy as np
import scipy.fft as sfft

try:  # scipy's pocketfft binding: transforms into preallocated arrays (``out``); scipy.fft's functions otherwise
    from scipy.fft._pocketfft import pypocketfft as _pocketfft
except Exception:  # pragma: no cover - another scipy layout
    _pocketfft = None

__all__ = ["FoldedOperator", "folded_operator", "fold", "unfold", "SYMMETRY_TOLERANCE"]

#: largest asymmetry of the gap (and of the initial pressure) relative to its largest value for which the quadrant
#: is solved, with the gap's four mirror images averaged [1]: a centred grid's gap is symmetric to a few ulps
#: (2.9e-16 on the E&K ellipse), far below the solver's tolerance
SYMMETRY_TOLERANCE = 1e-13


class FoldedOperator:
    """Love's operator of an (nx, ny) grid (nx, ny even) restricted to doubly symmetric fields, on the quadrant
    i >= nx/2, j >= ny/2 (shape (nx/2, ny/2)), with the folded circulant preconditioner; the interface that
    :func:`railtherm_kalker.normal_solver.solve_normal` uses (``apply``, ``precondition``, ``products``).

    Parameters
    ----------
    kernel_quadrant : ndarray
        Love's kernel at the offsets 0 ... >= nx - 1, 0 ... >= ny - 1 [m/Pa].
    shape : (int, int)
        The full element grid (nx, ny), both even.
    inverse : ndarray (nx, ny/2 + 1)
        The inverse eigenvalues of the preconditioner's circulant on the periodic (nx, ny) grid (numpy's rfft2
        layout) [Pa/m].
    """

    def __init__(self, kernel_quadrant, shape, inverse):
        nx, ny = shape
        self.full_shape = (nx, ny)
        self.shape = (nx // 2, ny // 2)
        self.transform = (sfft.next_fast_len(nx - 1, real=True), sfft.next_fast_len(ny - 1, real=True))
        lx, ly = self.transform
        k = np.zeros((lx + 1, ly + 1))
        k[:nx, :ny] = kernel_quadrant[:nx, :ny]           # offsets beyond n - 1 never enter the product
        self._symbol = sfft.dctn(k, type=1, workers=1)[:lx, :ly]
        hx, hy = self.shape
        self._inverse32 = np.ascontiguousarray(inverse[:hx, :hy], dtype=np.float32)
        self.products = 0
        self._local = threading.local()

    def _work(self):
        """This thread's work arrays: the quadrant padded along y (hx, Ly), its transform along y padded along x
        (Lx, Ly; rows hx.. stay zero), the spectrum (Lx, Ly), the inverse along y (hx, Ly), the preconditioner's
        float32 field and spectrum (hx, hy)."""
        work = getattr(self._local, "work", None)
        if work is None:
            (hx, hy), (lx, ly) = self.shape, self.transform
            work = self._local.work = (np.zeros((hx, ly)), np.zeros((lx, ly)), np.empty((lx, ly)),
                                       np.empty((hx, ly)), np.empty((hx, hy), dtype=np.float32),
                                       np.empty((hx, hy), dtype=np.float32))
        return work

    def apply(self, p):
        """u = A p on the quadrant for the doubly symmetric field whose quadrant is p (1, nx/2, ny/2) [Pa]. The
        2-D DCTs skip the zero rows: along y on the quadrant's rows only, and back along y on the rows kept."""
        self.products += 1
        hx, hy = self.shape
        a, f, F, g = self._work()[:4]
        a[:, :hy] = np.asarray(p).reshape(self.shape)              # columns hy.. stay zero
        if _pocketfft is None:
            F[...] = sfft.dctn(np.pad(a, ((0, f.shape[0] - hx), (0, 0))), type=2, workers=1)
            F *= self._symbol
            return sfft.idctn(F, type=2, workers=1)[None, :hx, :hy]
        _pocketfft.dct(a, 2, (1,), 0, f[:hx], 1)                      # rows hx.. of f stay zero
        _pocketfft.dct(f, 2, (0,), 0, F, 1)
        F *= self._symbol
        _pocketfft.dct(F, 3, (0,), 2, F, 1)                           # the inverse DCT-II: DCT-III / (2 L)
        _pocketfft.dct(F[:hx], 3, (1,), 2, g, 1)
        return g[None, :, :hy].copy()

    def precondition(self, r):
        """The folded inverse of the circulant applied to the quadrant r (nx/2, ny/2), in float32; float64 out."""
        if _pocketfft is None:
            f = sfft.dctn(np.asarray(r, dtype=np.float32), type=2, workers=1)
            f *= self._inverse32
            return sfft.idctn(f, type=2, workers=1, overwrite_x=True).astype(float)
        a, f = self._work()[4:]
        a[...] = r
        _pocketfft.dct(a, 2, (0, 1), 0, f, 1)
        f *= self._inverse32
        _pocketfft.dct(f, 3, (0, 1), 2, f, 1)
        return f.astype(float)


def _mirror_average(a):
    """(nx/2, ny/2): the mean of the four mirror images of a on the quadrant i >= nx/2, j >= ny/2."""
    hx, hy = a.shape[0] // 2, a.shape[1] // 2
    return 0.25 * (a[hx:, hy:] + a[hx - 1::-1, hy:] + a[hx:, hy - 1::-1] + a[hx - 1::-1, hy - 1::-1])


def _symmetric(a) -> bool:
    scale = float(np.max(np.abs(a))) or 1.0
    return (float(np.max(np.abs(a - a[::-1]))) <= SYMMETRY_TOLERANCE * scale
            and float(np.max(np.abs(a - a[:, ::-1]))) <= SYMMETRY_TOLERANCE * scale)


def folded_operator(conv, gap, initial):
    """The :class:`FoldedOperator` of the normal operator ``conv`` when the problem can be folded: a 2-D grid of
    even sides whose preconditioner's periodic grid is the element grid, a gap (and initial pressure, if any)
    symmetric in x and y to :data:`SYMMETRY_TOLERANCE`; else None. Cached on the operator."""
    q = getattr(conv, "kernel_quadrant", None)
    nx, ny = np.shape(gap)
    if (q is None or nx % 2 or ny % 2 or nx < 2 or ny < 2 or getattr(conv, "_inverse32", None) is None
            or tuple(conv.circulant_grid) != (nx, ny) or tuple(conv.shape) != (nx, ny)):
        return None
    if not _symmetric(gap) or (initial is not None and not _symmetric(np.asarray(initial, dtype=float))):
        return None
    fold_op = getattr(conv, "_folded", None)
    if fold_op is None:
        fold_op = conv._folded = FoldedOperator(q, (nx, ny), conv._inverse32)
    return fold_op


def fold(a):
    """The quadrant (mean of the mirror images) of a doubly symmetric field (nx, ny), or None."""
    return None if a is None else _mirror_average(np.asarray(a, dtype=float))


def unfold(q):
    """The doubly symmetric field (nx, ny) of its quadrant q (nx/2, ny/2) (i >= nx/2, j >= ny/2)."""
    hx, hy = q.shape
    out = np.empty((2 * hx, 2 * hy))
    out[hx:, hy:] = q
    out[:hx, hy:] = q[::-1]
    out[:, :hy] = out[:, hy:][:, ::-1]
    return out
