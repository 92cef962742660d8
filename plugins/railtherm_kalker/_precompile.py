"""The plugin's numba kernels compiled (or loaded from numba's disk cache) together, in a process's first solve.

A numba kernel compiles for the argument types of its first call, and a solve reaches only some kernels: a line
contact never forms the two-component products (:func:`railtherm_kalker.influence._mac2`), a coarse solve in full
slip never reaches the Newton solver's. A study's warm-up (one coarse solve of the first scene a worker sees,
the timing protocol in docs/DESIGN.md) would leave the other kernels to compile in a later timed solve: in a fresh
install, 0.6-3 s in the main study's first level-3 solves of carter and of the E&K ellipses (carter at xi = -5e-5:
2.95 s against 0.018 s). :func:`compile_kernels` compiles every kernel for the signatures the models call it with
(:func:`kernel_signatures`), once per process, from the models' first solve: the warm-up carries all compilation
and no later solve compiles. With a filled disk cache it loads them (about 0.2 s for all).
"""
from __future__ import annotations

import threading

from . import _band, _cg, _mirror, _sweep, influence, tangential_solver

try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import types
except Exception:  # numba missing: the kernels are plain Python or numpy, nothing to compile
    types = None

__all__ = ["compile_kernels", "kernel_signatures", "CALLEES"]

#: kernels called only from other kernels (compiled into their callers' code): not compiled on their own
CALLEES = frozenset({"invert_block", "_assemble"})

_LOCK = threading.Lock()
_DONE = False
#: (kernel name, signature, error) of the compilations that failed (the kernel then compiles on its first call)
FAILED: list = []


def kernel_signatures() -> list:
    """(kernel, argument types) of every signature the models call the plugin's numba kernels with: float64 fields,
    int64 indices, bool masks, C-contiguous; the FFT products also in single precision (inexact inner products).
    Not listed: the operators' fallbacks without scipy's pocketfft binding and calls of the kernels with other
    layouts outside the models (they compile on first use). Empty without numba."""
    if types is None:
        return []
    f8, c16, c8, i8, b1 = types.float64, types.complex128, types.complex64, types.int64, types.boolean

    def a(dt, nd):
        return types.Array(dt, nd, "C")

    band_solve = (a(f8, 2), a(i8, 2), a(i8, 1), a(f8, 3), a(f8, 3), a(f8, 3), a(f8, 3))
    sigs = [(_band._factor, (a(i8, 1), a(i8, 2), a(i8, 2), a(i8, 1), a(b1, 1), a(f8, 2), a(f8, 1), f8, a(f8, 3))),
            (_band._solve, band_solve), (_band._solve2, band_solve),
            (_cg.residual, (a(f8, 1), a(f8, 1), a(b1, 1), b1, f8, a(f8, 1))),
            (_cg.direction, (a(f8, 1), a(f8, 1), a(f8, 1), a(f8, 1), a(b1, 1), b1, f8, b1)),
            (_cg.step, (a(f8, 1), a(f8, 1), a(f8, 1), a(b1, 1), b1, a(f8, 1), a(f8, 1))),
            (_cg.enter, (a(f8, 1), a(f8, 1), a(b1, 1), b1, f8)),
            (_sweep._sweep_nb, (a(f8, 2), a(f8, 3), a(f8, 3), a(i8, 1), a(i8, 1))),
            # GMRES's rows, called in double precision whatever the basis's (float32 converted exactly, rows rounded)
            (tangential_solver._jacobian_rows, (a(f8, 2), a(f8, 2), a(b1, 1), a(f8, 2), a(f8, 1), f8))]
    for c in (c16, c8):
        sigs.append((getattr(_mirror, "_combine", None), (a(c, 3), a(c, 2), a(c, 2), a(c, 2))))
        sigs.append((influence._mac2, (a(c, 3), a(c, 2), a(c, 2), a(c, 2), a(c, 2), a(c, 3))))
    return [(k, s) for k, s in sigs if k is not None and hasattr(k, "compile")]


def compile_kernels() -> None:
    """Compile (or load from numba's disk cache) every kernel for the signatures of :func:`kernel_signatures`, once
    per process; later calls return at once. Thread-safe. A compilation that fails is recorded in :data:`FAILED`
    and left to the kernel's first call (which raises it there if it concerns that solve)."""
    global _DONE
    if _DONE:
        return
    with _LOCK:
        if _DONE:
            return
        for kernel, sig in kernel_signatures():
            try:
                kernel.compile(sig)
            except Exception as exc:  # noqa: BLE001 - the kernel's own call reports it where it matters
                FAILED.append((kernel.py_func.__name__, sig, f"{type(exc).__name__}: {exc}"))
        _DONE = True
