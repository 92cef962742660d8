"""Cold start of the main study's workers: fastsim-fdm's numba compilation on an empty cache (its warm-up, and
the first level-3 solve of the explicit scheme) and the FEM's first solve of a geometry against its repeat
(benchmarks/cold_start.py says what each measures). Each measurement runs in a fresh process (one numba and
BLAS thread, as a study's worker), so no kernel or factorisation of this process is reused.
Measured (this machine, 2 cores, at a load of 4-8; CPU time, the wall time was 1.5-3x that): the warm-up
compiles 8 kernels in 6.8 s, the fused explicit kernel that level 3 needs among them, so that the first
level-3 solve of fdm-circular-q10 compiles only core's thermal-trace kernel (2.0 s against 0.36 s for its
repeat; the warm-up scene has no field). The FEM's cold solve (its mesh, stiffness and factorisation, about
60 % of it SuperLU's factorisation) is 2.4-9x its repeat: fem-seed L0 0.51 / 0.054 s, carter L3 0.52 / 0.091 s.
Printed and recorded in ``extra_info``, not asserted: timings are measurements, never verdicts.
Run: ``python -m pytest benchmarks/test_cold_start_benchmark.py -m benchmark --benchmark-enable -n 0
-p no:cacheprovider -s``.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ONE_THREAD = {k: "1" for k in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def _measure(kind: str, env: dict) -> dict:
    """benchmarks/cold_start.py ``kind`` in a fresh process; its JSON result."""
    out = subprocess.run([sys.executable, str(HERE / "cold_start.py"), kind], env={**os.environ, **ONE_THREAD, **env},
                         capture_output=True, text=True, check=True, timeout=900)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _kernels(step: dict) -> str:
    return ", ".join(f"{name} {t:.2f} s" for name, t in step["compiled"]) or "none"


@pytest.mark.benchmark
def test_benchmark_fastsim_fdm_compile_on_empty_cache(benchmark, tmp_path):
    res = benchmark.pedantic(_measure, args=("compile", {"NUMBA_CACHE_DIR": str(tmp_path)}), rounds=1, iterations=1)
    for step in ("warmup", "explicit_first", "explicit_repeat"):
        s = res[step]
        print(f"fastsim-fdm {step}: wall {s['wall']:.2f} s, CPU {s['cpu']:.2f} s; compiled: {_kernels(s)}")
        benchmark.extra_info.update({f"{step}_wall_s": s["wall"], f"{step}_cpu_s": s["cpu"],
                                     f"{step}_kernels": len(s["compiled"])})


@pytest.mark.benchmark
def test_benchmark_fem_first_solve_of_a_geometry(benchmark):
    res = benchmark.pedantic(_measure, args=("fem", {}), rounds=1, iterations=1)
    for run, r in res.items():
        print(f"fem {run}: cold {r['cold']:.3f} s (CPU {r['cold_cpu']:.3f}), warm {r['warm']:.3f} s "
              f"(CPU {r['warm_cpu']:.3f}), ratio {r['cold'] / r['warm']:.1f}")
        benchmark.extra_info.update({f"{run} cold_s": r["cold"], f"{run} warm_s": r["warm"]})
