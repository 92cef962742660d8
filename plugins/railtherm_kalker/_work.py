"""Work arrays of the operators' FFT products (:class:`railtherm_kalker.influence.Convolution`), allocated once per
padded grid and thread and shared by the operators of that grid, so that a product allocates nothing (the page faults
of fresh temporaries made a float64 product 2-3 times slower, docs/kalker.md)."""
from __future__ import annotations

import functools

import numpy as np

__all__ = ["_work_arrays", "_periodic_work_arrays"]


@functools.lru_cache(maxsize=6)
def _work_arrays(dt: str, nc: int, mx: int, ny: int, my: int, thread: int) -> list:
    """Work arrays of :meth:`Convolution._buffered` for nc fields of precision dt ('d' or 'f') on a padded grid,
    shared by the operators of that grid (the normal and rolling operators, materials, orders) and allocated once:
    [the fields padded along x (nc, M_x, ny), their transforms along x padded along y (nc, M_x/2 + 1, M_y; the
    padding is never written), the inverse (nc, M_x, ny), the elements of apply_at's last field (the field is zero
    elsewhere), the spectra (nc, M_x/2 + 1, M_y)]. One set per thread (``thread``: its identifier), so that solves
    in threads of one process do not share them. About 6 nc M_x ny values: 45 MB for the float64 and float32
    two-component arrays at 400^2 elements; the cache keeps the six most recent."""
    real = np.float32 if dt == "f" else np.float64
    cplx = np.complex64 if dt == "f" else np.complex128
    return [np.zeros((nc, mx, ny), dtype=real), np.zeros((nc, mx // 2 + 1, my), dtype=cplx),
            np.empty((nc, mx, ny), dtype=real), None, np.empty((nc, mx // 2 + 1, my), dtype=cplx)]


@functools.lru_cache(maxsize=6)
def _periodic_work_arrays(cx: int, cy: int, thread: int) -> tuple:
    """float32 work arrays of :meth:`Convolution._precondition_periodic` on a (cx, cy) periodic grid, one set per
    thread (``thread``: its identifier): the field (zero beyond the elements, which every call overwrites), its
    spectrum (cx, cy/2 + 1) and the inverse transform."""
    return (np.zeros((cx, cy), dtype=np.float32), np.empty((cx, cy // 2 + 1), dtype=np.complex64),
            np.empty((cx, cy), dtype=np.float32))
