"""The element-wise parts of the normal solver's active-set conjugate gradients, fused per step.

:func:`railtherm_kalker.normal_solver.solve_normal` spends its time in one FFT product and one preconditioner
application per iteration and, with numpy, in about twenty element-wise passes (masks, means over the contact
set, inner products): as much again at 100^2 elements. Each function here is one pass over the flat arrays
(compiled by numba when available; the numpy versions are the reference and the fallback). ``C`` is the contact
set (bool), ``fm`` whether the force is prescribed (the constant vector deflated: means over C removed).
"""
from __future__ import annotations

import numpy as np

__all__ = ["residual", "direction", "step", "enter"]


def _residual_np(h, u, C, fm, approach, r):
    e = h + u
    delta = float(e[C].mean()) if fm else float(approach)
    r[:] = np.where(C, delta - e, 0.0)
    return delta


def _direction_np(z, r, r_prev, v, C, fm, rz_old, first):
    z[:] = np.where(C, z, 0.0)
    if fm:
        z[C] -= z[C].mean()
    rz = float(np.sum(z * r))
    beta = 0.0 if (first or rz_old <= 0) else max(0.0, (rz - float(np.sum(z * r_prev))) / rz_old)
    v[:] = z + beta * np.where(C, v, 0.0)
    if fm:
        v[C] -= v[C].mean()
    return rz


def _step_np(q, v, r, C, fm, p, u):
    qc = q - float(q[C].mean()) if fm else q
    vav = float(np.sum(np.where(C, qc, 0.0) * v))
    alpha = float(np.sum(r * v)) / vav if vav > 0 else 0.0
    p += alpha * v
    u += alpha * q
    change = abs(alpha) * float(np.sum(np.abs(v))) / max(float(np.sum(np.abs(p))), 1e-300)
    return alpha, change, int(np.count_nonzero(C & (p < 0.0)))


def _enter_np(h, u, C, fm, approach):
    e = h + u
    delta = float(e[C].mean()) if fm else float(approach)
    new = ~C & (e < delta)
    C |= new
    return delta, int(np.count_nonzero(new))


try:  # pragma: no cover - exercised when numba is installed (a declared dependency)
    from numba import njit

    #: reassociation lets the reductions vectorise (sums in another order: round-off only); no assumption on NaN/inf
    FAST = {"reassoc", "nsz", "contract"}

    @njit(cache=True, nogil=True, fastmath=FAST)
    def _residual_nb(h, u, C, fm, approach, r):
        delta = approach
        if fm:
            s, m = 0.0, 0
            for i in range(h.size):
                s += (1.0 if C[i] else 0.0) * (h[i] + u[i])
                m += C[i]
            delta = s / m
        for i in range(h.size):
            r[i] = (1.0 if C[i] else 0.0) * (delta - (h[i] + u[i]))
        return delta

    @njit(cache=True, nogil=True, fastmath=FAST)
    def _direction_nb(z, r, r_prev, v, C, fm, rz_old, first):
        # the sums over C of z, z r, z r_prev, r and r_prev in one pass: the projected z's products follow
        # (sum (z - zm) r = sum z r - zm sum r)
        n = z.size
        sz, szr, szp, sr, srp, m = 0.0, 0.0, 0.0, 0.0, 0.0, 0
        for i in range(n):                      # masks as factors: a branch-free loop that vectorises
            c = 1.0 if C[i] else 0.0
            zc = c * z[i]
            sz += zc
            szr += zc * r[i]
            szp += zc * r_prev[i]
            sr += c * r[i]
            srp += c * r_prev[i]
            m += C[i]
        zm = sz / m if (fm and m > 0) else 0.0
        rz = szr - zm * sr
        beta = 0.0
        if not first and rz_old > 0:
            beta = max(0.0, (rz - (szp - zm * srp)) / rz_old)
        vm = 0.0
        for i in range(n):
            c = 1.0 if C[i] else 0.0
            zi = c * (z[i] - zm)
            z[i] = zi
            vi = zi + c * beta * v[i]
            v[i] = vi
            vm += vi
        if fm and m > 0:
            vm = vm / m
            for i in range(n):
                v[i] -= (1.0 if C[i] else 0.0) * vm
        return rz

    @njit(cache=True, nogil=True, fastmath=FAST)
    def _step_nb(q, v, r, C, fm, p, u):
        # sum over C of (q - qm) v = sum q v - qm sum v, with the sums of q, q v, v over C in one pass
        n = q.size
        sq, sqv, sv, rv, m = 0.0, 0.0, 0.0, 0.0, 0
        for i in range(n):                      # masks as factors: a branch-free loop that vectorises
            c = 1.0 if C[i] else 0.0
            rv += r[i] * v[i]
            sq += c * q[i]
            sqv += c * q[i] * v[i]
            sv += c * v[i]
            m += C[i]
        qm = sq / m if (fm and m > 0) else 0.0
        vav = sqv - qm * sv
        alpha = rv / vav if vav > 0 else 0.0
        sabs, sp, neg = 0.0, 0.0, 0
        for i in range(n):
            p[i] += alpha * v[i]
            u[i] += alpha * q[i]
            sabs += abs(v[i])
            sp += abs(p[i])
            neg += C[i] and p[i] < 0.0
        return alpha, abs(alpha) * sabs / max(sp, 1e-300), neg

    @njit(cache=True, nogil=True, fastmath=FAST)
    def _enter_nb(h, u, C, fm, approach):
        delta = approach
        if fm:
            s, m = 0.0, 0
            for i in range(h.size):
                if C[i]:
                    s += h[i] + u[i]
                    m += 1
            delta = s / m
        new = 0
        for i in range(h.size):
            if not C[i] and h[i] + u[i] < delta:
                C[i] = True
                new += 1
        return delta, new
except Exception:  # numba missing or unusable
    _residual_nb = _direction_nb = _step_nb = _enter_nb = None

#: the fused passes (numba), or the numpy reference when numba is missing
residual = _residual_nb or _residual_np
direction = _direction_nb or _direction_np
step = _step_nb or _step_np
enter = _enter_nb or _enter_np
