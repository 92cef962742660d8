"""Shared constants of the transient section tests (tests/test_fdm_transient.py, tests/test_fem_transient.py):
a Hertzian band of half-width A at speed V and peak flux Q, four passes INTERVAL apart with a slip event that
doubles the flux in the first pass's wake, the depths the history is asked at, the exact references' cheap
quadrature and core's default steel; and the transient study's train of axles against its exact 3-D ellipse
(:func:`train_of_axles`), shared by the green and fipy tests; the theta steps by sparse LU that fipy's per-mode
steps are checked against (:func:`lu_theta_steps`)."""
from pathlib import Path

import numpy as np

from scipy.sparse import diags
from scipy.sparse.linalg import splu

from railtherm.analysis.transient_metrics import transient_sources
from railtherm.input.materials import Material
from railtherm.input.study import load_study
from railtherm.references.transient import pass_summary
from railtherm.solving.pipeline import solve

A, V, Q = 6e-3, 30.0, 1e8                    # [m], [m s-1], [W m-2]
INTERVAL = 0.083                             # [s]
SLIP = {"time": [0.0, 0.083, 0.0832, 0.0836, 0.0838, 0.2], "factor": [1.0, 1.0, 2.0, 2.0, 1.0, 1.0]}
DEPTHS = [1e-4, 5e-4]                        # [m]
CHEAP = dict(quad_points=8, inner_points=24)    # the references at ~1e-5 of their maximum
STEEL = Material()

TRANSIENT_STUDY = Path(__file__).parent.parent / "studies" / "transient.toml"


def train_of_axles(method: str, level: int, depths):
    """The transient study's train-4-axles (4 passes of a Hertz ellipse a = 6, b = 4 mm over the rail at 30 m/s,
    83 ms apart) solved by ``method`` at ``level``: ``(result, peaks, exact)``, the rail's pass peaks above its
    bulk at ``depths`` [m] (passes, depths) [K] and the exact 3-D moving ellipse's pass summary at the same depths
    (:func:`railtherm.references.transient.pass_summary`, cheap quadrature)."""
    scene = load_study(TRANSIENT_STUDY).scene("train-4-axles")
    ds = solve(scene, method, level=level)
    tr = scene.transient
    (_, _), (src, bulk) = transient_sources(scene)[0]
    z = np.asarray(ds["z"].values)
    cols = [int(np.flatnonzero(np.isclose(z, d))[0]) for d in depths]
    exact = pass_summary(list(depths), src, scene.body(1), tr.count, tr.interval, **CHEAP)
    return ds, ds["pass_peak_temperature"].values[1][:, cols] - bulk, exact


def lu_theta_steps(C, K, top: int, theta: float, rng):
    """Theta steps by sparse LU, ``(C/dt + theta K) T1 = (C/dt - (1 - theta) K) T0 + theta p1 + (1 - theta) p0``,
    of sizes 1e-7, 3.1e-6, 1e-3 and 1 s [s] from a random state, under random heat p0, p1 [W] on the first ``top``
    cells (capacities ``C`` [J/K], conductance ``K`` [W/K]): the initial state [K] and an iterator of
    ``(dt, load, state)``, the step's theta-weighted heat on those cells [W] and the state after it [K]."""
    T0 = rng.standard_normal(C.size)

    def steps():
        T = T0
        for dt in (1e-7, 3.1e-6, 1e-3, 1.0):
            p0, p1 = np.zeros(C.size), np.zeros(C.size)
            p0[:top], p1[:top] = rng.random(top), rng.random(top)
            lu = splu((diags(C / dt) + theta * K).tocsc())
            T = lu.solve(C / dt * T - (1.0 - theta) * (K @ T) + theta * p1 + (1.0 - theta) * p0)
            yield dt, theta * p1[:top] + (1.0 - theta) * p0[:top], T
    return T0, steps()
