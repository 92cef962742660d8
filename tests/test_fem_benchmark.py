"""Method "fem": timing of a full contact solve at about 1e5 displacement unknowns (pytest-benchmark).

Run: OPENBLAS_NUM_THREADS=1 PYTHONPATH=core:plugins python -m pytest tests/test_fem_benchmark.py -m benchmark --benchmark-enable
Timed (cold: the kept mechanics is cleared before every round): graded quadtree mesh, array assembly,
nested-dissection ordering, one SuperLU factorisation with the window last (Schur complement = trailing
factor block), semismooth Newton with friction (creepage). ``extra_info`` holds the process CPU time of
each round as well (the wall time on a shared machine can be twice the CPU time).
"""
from __future__ import annotations

import os
import time
from types import SimpleNamespace as NS

import numpy as np
import pytest

from railtherm.references.hertz import hertz_line
from railtherm_fem.coupled import FemProblem, clear_cache, solve_fem

G, NU, R = 82e9, 0.28, 0.5


def problem():
    mat = NS(shear_modulus=G, poisson_ratio=NU, density=7850.0, specific_heat=450.0, conductivity=50.0,
             thermal_expansion=12e-6, bulk_temperature=0.0, rigid=False)
    wheel = NS(**{**mat.__dict__, "rigid": True})
    e_star = 2 * G * (1 + NU) / (1 - NU ** 2)
    F = np.pi * (1e-3) ** 2 * e_star / (4 * R)
    return FemProblem(radius=R, rail=mat, wheel=wheel, speed=10.0, normal_force=F, friction=0.3, creepage=-2e-4,
                      regularization=0.0, thermal=False, level=3, grading=20.0,
                      strip_depth=0.04, strip_length=0.08), F, e_star


@pytest.mark.benchmark
def test_benchmark_contact_solve_1e5_dofs(benchmark):
    prob, F, e_star = problem()
    solve_fem(prob)  # warm-up (imports)
    cpu = []

    def timed():
        c0 = time.process_time()
        out = solve_fem(prob)
        cpu.append(time.process_time() - c0)
        return out

    sol = benchmark.pedantic(timed, setup=clear_cache, rounds=3, iterations=1)
    a_ref, p0_ref = hertz_line(F, R, e_star)
    benchmark.extra_info.update(dofs=sol.diagnostics["dofs"], window_nodes=sol.diagnostics["window_nodes"],
                                half_width_error=sol.half_width / a_ref - 1,
                                max_pressure_error=float(sol.contact.pressure.max() / p0_ref - 1),
                                contact_iterations=sol.contact.iterations,
                                blas_threads=os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
                                cpu_time_min=min(cpu), cpu_time_max=max(cpu),
                                mechanics_time=sol.diagnostics["mechanics_time"])
    assert sol.diagnostics["dofs"] >= 0.9e5
    assert sol.contact.converged
