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
    """The keywords of wheel_heating for a steel wheel of ``radius`` [m] on steel."""
    return dict(bodies=(STEEL, STEEL), convection=convection, wheel_radius=radius, numerics=numerics)


def _half_space_error(level):
    h = wheel_heating(**_scene(20.0, {"time_step": 0.5, "duration": 20.0}), source=_source(), level=level, options={})
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
    h = wheel_heating(**_scene(0.05, {}, convection=50.0), source=src, level=0, options={})
    tau = h["tau"]
    h = wheel_heating(**_scene(0.05, {"duration": 30 * tau}, convection=50.0), source=src, level=0, options={})
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


def test_transient_study_histories_supported_on_line_contacts_and_ellipses():
    """fipy computes the pass histories of every scene of studies/transient.toml, line contacts (its 2-D FiPy
    section) and ellipses (its 3-D block, railtherm_fipy.history3d; checked against the exact ellipse in
    tests/test_fipy_ellipse_history.py); a body at rest under the contact is still refused with the reason,
    before any solve (a line scene with passes returns its history, none a steady field)."""
    import railtherm
    from railtherm import Refused
    from railtherm.input.study import load_study
    from railtherm_fipy.model import FipyTemperature
    study = load_study(Path(__file__).resolve().parents[1] / "studies" / "transient.toml")
    model = FipyTemperature()
    kinds = {}
    for scene in study.scenes:
        kinds[scene.name] = scene.contact_shape
        assert model.supports(scene, 0) is None, scene.name
    assert "ellipse" in kinds.values() and "line" in kinds.values()
    locked = {"name": "locked-ellipse", "normal_force": 0.8e6, "contact": {"shape": "ellipse", "semi_axes": [6e-3, 4e-3]},
              "speed": 10.0, "sliding_speed": -10.0, "friction": 0.3, "heat_partition": 0.066, "mode": "transient",
              "passes": {"count": 1, "interval": 0.1}, "field": {"depth": [1e-4]}, "outputs": ["temperature_history"]}
    with pytest.raises(Refused, match="moving_surface|moves at"):
        railtherm.solve(locked, "fipy", level=0)
    line = {"name": "passes-line", "speed": 30.0, "mode": "transient", "heat_partition": 0.0,
            "heat_source": {"flux": 1e8, "shape": "hertz", "half_width": 6e-3},
            "passes": {"count": 2, "interval": 0.05}, "field": {"depth": [1e-4, 5e-4]},
            "outputs": ["temperature_history", "residual_rise", "max_surface_temperature"]}
    ds = railtherm.solve(line, "fipy", level=0)
    assert ds.residual_rise.sel(body="rail").values.shape == (2,) and np.all(ds.residual_rise.values[1] > 0)
    assert ds.attrs["fipy_rail_history_heating_scheme"] == "implicit"
    # the one-pass surface maximum beside the histories (the moving frame's steady field), its depth field not
    assert list(ds.z.values) == [0.0, 1e-4, 5e-4] and ds.max_surface_temperature.sel(body="rail") > 20.0


A, V, Q = 6e-3, 30.0, 1e8
INTERVAL = 0.083
SLIP = {"time": [0.0, 0.083, 0.0832, 0.0836, 0.0838, 0.2], "factor": [1.0, 1.0, 2.0, 2.0, 1.0, 1.0]}
DEPTHS = [1e-4, 5e-4]
CHEAP = dict(quad_points=8, inner_points=24)    # the references at ~1e-5 of their maximum


def _band_errors(shape: str, level: int):
    """fipy's rail history through railtherm.solve for a given band (``shape``, a = 6 mm, 1e8 W/m^2 into the
    rail), 4 passes 83 ms apart, the heat doubled for 0.4 ms in the second: the largest relative errors of the
    pass peaks, residual rises and history (max-norm per depth over the maximum rise, at about 40 samples per
    contact duration during the passes) against the exact moving band."""
    import railtherm
    from railtherm.input.materials import Material
    from railtherm.references.transient import MovingSource, Schedule, pass_summary, temperature_history
    scene = {"name": "rail-section", "speed": V, "heat_source": {"flux": Q, "shape": shape, "half_width": A},
             "heat_partition": 0.0, "rail": {"bulk_temperature": 20.0}, "wheel": {"bulk_temperature": 20.0},
             "mode": "transient", "passes": {"count": 4, "interval": INTERVAL}, "schedule": SLIP,
             "field": {"depth": DEPTHS, "threshold": 400.0},
             "outputs": ["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"]}
    ds = railtherm.solve(scene, "fipy", level=level)
    src = MovingSource("band", A, V, Q, shape)
    sched = Schedule(tuple(SLIP["time"]), tuple(SLIP["factor"]))
    t, depths = ds.time.values, ds.z.values
    every = max(1, int(round(2 * A / V / np.median(np.diff(t)) / 40)))
    got = ds.temperature_history.sel(body="rail").values[::every] - 20.0
    exact = temperature_history(t[::every], depths, src, Material(), 4, INTERVAL, sched, **CHEAP)
    ref = pass_summary(depths, src, Material(), 4, INTERVAL, sched, **CHEAP)
    peak = ds.pass_peak_temperature.sel(body="rail").values - 20.0
    assert np.all(ds.temperature_history.sel(body="wheel").values == 20.0)
    return (np.max(np.abs(peak / ref.peak - 1)),
            np.max(np.abs(ds.residual_rise.sel(body="rail").values / ref.residual[:, 0] - 1)),
            np.max(np.abs(got - exact).max(axis=0) / exact.max(axis=0)))


# fipy's level 1 and the exact history (~5 s): opt-in (-m slow)
@pytest.mark.slow
def test_band_history_at_level_1_within_the_level_2_targets():
    """Uniform band at level 1 (the Hertz band at level 2 below): pass peaks and residual rise within 2 %, the
    history within 3 % of the exact band."""
    peak, residual, history = _band_errors("uniform", 1)
    assert peak < 0.02 and residual < 0.02 and history < 0.03, (peak, residual, history)


# level 2 and the Hertz band's reference on the history (~30 s): opt-in (-m slow)
@pytest.mark.slow
def test_hertz_band_history_at_level_2_within_the_targets():
    """The targets at level 2 on the Hertz band: pass peaks and residual rise within 2 %, the history within 3 %
    (measured 0.081 %, 0.012 %, 0.40 %)."""
    peak, residual, history = _band_errors("hertz", 2)
    assert peak < 0.02 and residual < 0.02 and history < 0.03, (peak, residual, history)


# levels 0 .. 2 of the FiPy section (the finest ~7k cells, ~2 s): opt-in (-m slow)
@pytest.mark.slow
def test_section_history_converges_at_second_order():
    """The wheel spin's schedule (a 5 ms ramp through the first pass, then 1) on the Hertz band (exact cell
    averages on 2048 cells), 2 passes 20 ms apart, the FiPy section at levels 0 .. 2 (cell-centred volumes,
    h = 2a/32/2**level, Crank-Nicolson at h/V): pass peaks at the surface and 0.5 mm and the residual rises
    converge to the exact band like h^2 (fitted slopes within 0.3 of 2; measured peaks 0.76, 0.24, 0.052 %,
    residual 0.45, 0.10, 0.026 %). Level 3 drops the peaks to 0.0077 % (slope 2.5 on levels 1 .. 3): the time
    steps' share of the 0.5 mm peak error (1.6e-3, 3.3e-4, ~5e-5 at levels 1 .. 3 with the cells held at
    level 3) vanishes faster than the cells' (7.2e-4, 2.1e-4, 7e-5 with the steps held at level 4)."""
    from railtherm.input.materials import Material
    from railtherm.physics import pass_peaks_and_residual
    from railtherm.solving.section_stepping import section_history
    from railtherm.references.transient import MovingSource, Schedule, pass_summary
    from railtherm_fipy.history import fipy_block
    steel = Material()
    sched = Schedule((0.0, 0.005, 0.195, 0.2), (0.0, 1.0, 1.0, 0.0))
    ref = pass_summary([0.0, 5e-4], MovingSource("band", A, V, Q, "hertz"), steel, 2, 0.02, sched, **CHEAP)
    xe = np.linspace(-A, A, 2049)
    x = xe / A
    flux = Q * np.diff(0.5 * A * (x * np.sqrt(1.0 - x * x) + np.arcsin(x))) / np.diff(xe)
    tr = SimpleNamespace(count=2, interval=0.02, schedule_time=sched.time, schedule_factor=sched.factor,
                         depths=(0.0, 5e-4), threshold=400.0)
    hs, peak, residual = [], [], []
    for level in (0, 1, 2):
        block = fipy_block(A, V, steel.conductivity, steel.density * steel.specific_heat, 0.0, level, 0.04, tr.depths)
        t, rise, res, _ = section_history(block, xe, flux, V, tr, 0.02, level, "implicit")
        p, _ = pass_peaks_and_residual(t, rise, 2, 0.02)
        hs.append(2 * A / 32 / 2 ** level)
        peak.append(np.max(np.abs(p / ref.peak - 1)))
        residual.append(np.max(np.abs(res / ref.residual[:, 0] - 1)))
    for err in (peak, residual):
        assert np.polyfit(np.log(hs), np.log(err), 1)[0] == pytest.approx(2.0, abs=0.3), err
