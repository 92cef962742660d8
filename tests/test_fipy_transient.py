"""Transient mode of model "fipy": wheel heating over many revolutions (railtherm_fipy.transient).

Checks: (1) early times against the exact half-space solution with constant flux and a linear loss
(Carslaw & Jaeger 1959, 2.7: ``T_s = (q/H) (1 - exp(b^2) erfc(b))``, ``b = H sqrt(kappa t)/lambda``)
on a wheel so large that curvature is negligible, with refinement in space and time; (2) the late
state converges to the lumped steady state ``eps P / (G_cond + alpha A)``; (3) the seed's Table 1
steady row without convection (the wheel radius does not enter it), through ``railtherm.solve``.

Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_fipy_transient.py -q``.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.special import erfcx

import railtherm
from railtherm import HeatSource, Material, surface_grid
from railtherm.physics import conduction_conductance, equal_temperature_partition
from railtherm_fipy.transient import wheel_heating

STEEL = Material()
PUBLISHED = Path(__file__).parent / "data" / "published.toml"


def _source(a=5e-3, b=5e-3, q=1e7, eps=0.5, v=30.0):
    g = surface_grid(a, b, 0, 8)
    qd = np.where(g.inside(), q, 0.0)
    return HeatSource(grid=g, power_density=qd, heat_partition=eps, body_speed=(v, v), frictional_power=g.integrate(qd))


def _scene(radius, numerics, convection=0.0):
    return SimpleNamespace(wheel=STEEL, rail=STEEL, convection=convection, wheel_radius=radius, numerics=numerics)


def _half_space_error(level):
    h = wheel_heating(_scene(20.0, {"time_step": 0.5, "duration": 20.0}), _source(), level, {})
    q, H = h["power"] / h["area"], h["g_cond"] / h["area"]
    b = H * math.sqrt(STEEL.diffusivity * h["t"][-1]) / STEEL.conductivity
    exact = q / H * (1.0 - erfcx(b))
    return abs(h["tread"][-1] - exact) / exact, h


def test_early_heating_matches_half_space_solution():
    e0, h0 = _half_space_error(0)
    e1, h1 = _half_space_error(1)
    assert h1["steps"] == 2 * h0["steps"] and h1["radial_cells"] == 2 * h0["radial_cells"]
    assert e1 < 5e-4 and e1 < e0 / 4, (e0, e1)
    assert h1["converged"] and h1["residual"] < 1e-9


def test_late_state_is_the_lumped_steady_state():
    """A small wheel (R = 5 cm: R^2/kappa = 180 s) run for 30 time constants reaches eps P / G."""
    src = _source()
    h = wheel_heating(_scene(0.05, {}, convection=50.0), src, 0, {})
    tau = h["tau"]
    h = wheel_heating(_scene(0.05, {"duration": 30 * tau}, convection=50.0), src, 0, {})
    eps_c = equal_temperature_partition(STEEL, STEEL, 30.0, 30.0)
    g = conduction_conductance(STEEL.effusivity, 30.0, eps_c, 5e-3, 5e-3) + 50.0 * h["convective_area"]
    assert h["t_inf"] == pytest.approx(h["power"] / g, rel=1e-12)
    assert h["tread"][-1] == pytest.approx(h["t_inf"], rel=2e-3)
    assert h["mean"][-1] == pytest.approx(h["t_inf"], rel=5e-3)
    assert np.all(np.diff(h["tread"]) >= -1e-12)               # monotone warm-up
    assert np.all(h["mean"] <= h["tread"] + 1e-12)             # heated from the tread


def _ek_scene(case, **kw):
    with open(PUBLISHED, "rb") as f:
        ek = tomllib.load(f)["ertz_knothe_2002"]
    c = ek[case]
    steel = {k: ek[k] for k in ("shear_modulus", "poisson_ratio", "density", "specific_heat", "conductivity")}
    scene = {"name": f"ek-{case}", "normal_force": ek["normal_force"],
             "contact": {"shape": "ellipse", "semi_axes": list(ek["semi_axes"])},
             "speed": c["speed"], "sliding_speed": c["sliding_speed"], "friction": c["friction"],
             "heat_partition": ek["heat_partition"], "convection": 0.0,
             "outputs": ["max_surface_temperature", "mean_contact_temperature", "steady_wheel_temperature",
                         "steady_mean_contact_temperature"],
             "wheel": dict(steel), "rail": dict(steel)}
    scene.update(kw)
    return scene, c["steady"]["0"]


@pytest.mark.parametrize("case", ["low_speed", "high_speed"])
def test_table1_steady_row_without_convection(case):
    """Seed Table 1, 'steady-state temperature without convection' (the radius does not enter it):
    the transient, run for 100 hours of driving, and the steady-mode lumped values within 1 %."""
    scene, (theta_inf, theta_mean_inf) = _ek_scene(case, mode="transient", numerics={"duration": 3.6e5})
    ds = railtherm.solve(scene, "fipy", level=0)
    assert ds["steady_wheel_temperature"].item() == pytest.approx(theta_inf, rel=0.01)
    assert ds["steady_mean_contact_temperature"].item() == pytest.approx(theta_mean_inf, rel=0.01)
    assert ds.attrs["fipy_transient_tread_fraction_of_steady"] > 0.995
    steady, _ = _ek_scene(case)
    ds_s = railtherm.solve(steady, "fipy", level=0)
    assert ds_s["steady_wheel_temperature"].item() == pytest.approx(theta_inf, rel=0.01)
    assert ds_s["steady_mean_contact_temperature"].item() == pytest.approx(theta_mean_inf, rel=0.01)


def test_revolutions_set_the_duration():
    scene, _ = _ek_scene("low_speed", mode="transient", numerics={"revolutions": 1000})
    ds = railtherm.solve(scene, "fipy", level=0)
    v_w = 31.0
    radius = Material().radius
    assert ds.attrs["fipy_transient_duration"] == pytest.approx(1000 * 2 * math.pi * radius / v_w, rel=1e-9)
    # after 1000 revolutions (~1.5 min) the tread is well on its way but not yet steady
    assert 0.3 < ds.attrs["fipy_transient_tread_fraction_of_steady"] < 0.95


def test_time_stepping_equals_fipy_transient_term():
    """The stepping re-uses one FiPy assembly; each step must equal FiPy's own TransientTerm solve."""
    from railtherm_fipy.solvers import assemble, import_fipy, lu_factor, make_solver, solve_checked
    import scipy.sparse as sp
    fp = import_fipy()
    m = fp.CylindricalGrid1D(dx=np.geomspace(0.02, 0.001, 25))
    n = m.faceNormals
    q = fp.FaceVariable(mesh=m, value=np.where(m.facesRight.value, 1e6, 0.0))
    h = fp.FaceVariable(mesh=m, value=np.where(m.facesRight.value, 500.0, 0.0))
    rho_c, lam = 3.5e6, 50.0
    T = fp.CellVariable(mesh=m, value=0.0, hasOld=True)
    eq = (fp.TransientTerm(coeff=rho_c) == fp.DiffusionTerm(coeff=lam) + (q * n).divergence
          - fp.ImplicitSourceTerm(coeff=(h * n).divergence))
    L, b = assemble((fp.DiffusionTerm(coeff=lam) + (q * n).divergence
                     - fp.ImplicitSourceTerm(coeff=(h * n).divergence)) == 0, T)
    cap = rho_c * np.asarray(m.cellVolumes)
    x = np.zeros(cap.size)
    for dt in (0.01, 0.1, 1.0, 10.0):
        T.updateOld()
        solve_checked(eq, T, make_solver("lu"), dt=dt)
        x = lu_factor((sp.diags(cap / dt) - L).tocsc()).solve(cap / dt * x - b)
        assert np.allclose(x, T.value, rtol=1e-10, atol=1e-12)


def test_every_scene_of_the_transient_study_is_refused_with_the_reason():
    """fipy's transient is the wheel's bulk heating over revolutions, not the pass histories: each scene of
    studies/transient.toml (passes, a schedule, the history outputs) and a scene with passes asking only a
    steady output are refused naming the pass histories, none answered with a steady field."""
    from pathlib import Path

    import railtherm
    from railtherm import Refused
    from railtherm.input.study import load_study
    study = load_study(Path(__file__).resolve().parents[1] / "studies" / "transient.toml")
    steady_only = {"name": "passes-steady-output", "speed": 30.0, "mode": "transient", "heat_partition": 0.0,
                   "heat_source": {"flux": 1e8, "shape": "hertz", "half_width": 6e-3},
                   "passes": {"count": 2, "interval": 0.05}, "outputs": ["max_surface_temperature"]}
    for scene in [*study.scenes, steady_only]:
        with pytest.raises(Refused, match="does not compute the pass histories"):
            railtherm.solve(scene, "fipy", level=0)
