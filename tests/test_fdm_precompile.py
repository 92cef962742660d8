"""The 3-D block's kernels compiled in a process's first solve (:func:`railtherm_fdm.kernels.compile_block_kernels`).

A scene's scheme depends on its level (the main study's circular sources: steady up to level 2, explicit at level
3), so a study's warm-up at the coarsest level reaches only some kernels; compiling the others there is useful only
if it compiles them for the very argument types the schemes call them with (else numba compiles again in the timed
solve). These tests record the types of every kernel call of the explicit (fused), implicit and steady schemes and
compare them with the signature table, and check that the table compiles.
"""
from __future__ import annotations

import numba

from railtherm import Material, surface_grid
from railtherm.physics import cell_average
from railtherm_fdm import kernels as K
from railtherm_fdm.block3d import steady_block, transient_block

RAIL = Material(density=7680.0, conductivity=54.0, specific_heat=460.0)
R = 2.5e-3            # contact radius [m]
SPIED = ("zline_factor", "sgs_zline", "stencil_matvec_serial", "vdot", "vaxpy", "explicit_two_steps_serial")


def _block_args():
    g = surface_grid(R, R, 0, cells=16)
    q = 1e6 * cell_average(g, "uniform", R, R)
    return g, q, g.inside().astype(float), 1.0, RAIL.conductivity, RAIL.density, RAIL.specific_heat, 0.0, R / 4


def _record_calls(monkeypatch) -> dict:
    """Replace the block's kernels by recorders (the call goes through): name -> set of argument type tuples."""
    seen = {name: set() for name in SPIED}
    for name in SPIED:
        kernel = getattr(K, name)

        def spy(*args, _name=name, _kernel=kernel):
            seen[_name].add(tuple(numba.typeof(a) for a in args))
            return _kernel(*args)
        monkeypatch.setattr(K, name, spy)
    return seen


def test_the_schemes_call_the_kernels_with_the_compiled_signatures(monkeypatch):
    """One thread (a study's worker) and the fused kernel on a small grid: every call of the explicit, implicit
    and steady schemes has the argument types of block_kernel_signatures, and every listed kernel is called."""
    monkeypatch.setattr(numba, "get_num_threads", lambda: 1)
    monkeypatch.setattr(K, "PARALLEL_MIN_NODES", 0)
    table = {k.py_func.__name__: sig for k, sig in K.block_kernel_signatures()}
    seen = _record_calls(monkeypatch)
    fused = transient_block(*_block_args(), scheme="explicit")
    transient_block(*_block_args(), scheme="implicit")
    steady_block(*_block_args(), level=0)
    assert fused.diagnostics["fused_steps"]
    names = {"explicit_two_steps_serial": "_explicit_two_steps_serial", "stencil_matvec_serial": "_stencil_matvec_serial"}
    for name, calls in seen.items():
        assert calls, f"{name} was not called"
        assert calls == {table[names.get(name, name)]}, (name, calls)


def test_the_signature_table_compiles(monkeypatch):
    """compile_block_kernels leaves each listed kernel with its listed signature compiled (or loaded)."""
    monkeypatch.setattr(numba, "get_num_threads", lambda: 1)
    monkeypatch.setattr(K, "_BLOCK_KERNELS_READY", [])
    K.compile_block_kernels()
    assert K._BLOCK_KERNELS_READY
    for kernel, sig in K.block_kernel_signatures():
        assert tuple(sig) in kernel.overloads, kernel.py_func.__name__


def test_several_threads_leave_the_kernels_to_their_first_use(monkeypatch):
    """With several numba threads nothing is compiled ahead (the parallel builds are the costly ones)."""
    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    monkeypatch.setattr(K, "_BLOCK_KERNELS_READY", [])
    calls = []
    monkeypatch.setattr(K, "block_kernel_signatures", lambda: calls.append(1) or [])
    K.compile_block_kernels()
    assert not calls and not K._BLOCK_KERNELS_READY
