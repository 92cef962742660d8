"""fem on the transient study's wheel spin (studies/transient.toml): its FE section against core's exact band,
and why fem's own solve stays 2.7 % above it on the first revolution at level 2.

The exact band (:mod:`railtherm.references.transient`, scored by :mod:`railtherm.analysis.transient_metrics`)
heats with full sliding's mu p v_s. fem's contact is the elastic one of seed section 4: its slip velocity is
v_s plus the elastic creep V d(u_wheel - u_rail)/dx, which for equal elastic bodies under a full-sliding Hertz
traction is -V mu x / R across the patch (the surface strain of a Hertzian tangential traction on a half-plane,
K.L. Johnson, Contact Mechanics, Cambridge University Press, 1985, ch. 2, doi:10.1017/CBO9781139171731). Its
heat mu p |s| sits (V mu / (R v_s)) a^2 / 4 = 0.089 mm behind the patch centre (30 m/s, mu = 0.3, R = 0.4345 m,
v_s = 2 m/s, a = 5.88 mm); the schedule ramps the heat up from 0 over 5 ms from the first pass's arrival, so
heat arriving later weighs more and the first revolution's peaks rise by 1.5-2.4 %. That is the contact
model's physics, present at every level, not the section's discretisation: with the reference's own heat
the section converges to the exact band at second order (0.045 % at level 2).

Run: ``python -m pytest -n 0 -q tests/test_fem_wheel_spin.py`` (``-m slow`` for the level-2 comparisons with
the exact band, ~1-4 min each).
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

import railtherm
from railtherm.analysis.transient_metrics import transient_errors, transient_sources
from railtherm.input.study import load_study
from railtherm.physics import pass_peaks_and_residual
from railtherm.references.transient import Schedule, pass_summary, temperature_history
from railtherm.solving.section_stepping import section_history
from railtherm_fem.coupled import solve_fem
from railtherm_fem.history import fem_block
from railtherm_fem.model import FemModel

CHEAP = dict(quad_points=8, inner_points=24)    # the references at ~1e-5 of their maximum (as the metrics)
STUDY = Path(__file__).resolve().parents[1] / "studies" / "transient.toml"


def _wheel_spin():
    """The study's wheel-spin scene and the rail's exact source (MovingSource: Hertz band, a, V, q0)."""
    scene = load_study(STUDY).scene("wheel-spin")
    (_, (rail, _)), _ = transient_sources(scene)
    return scene, rail


def _schedule(scene):
    tr = scene.transient
    return Schedule(tr.schedule_time, tr.schedule_factor)


def _cells(src, shape=lambda x: 1.0, n=2048):
    """Edges [m] and the cell averages [W/m^2] of the source's Hertz flux times ``shape(x)`` on n cells
    (midpoint sums on 100 sub-cells each: the averages to 1e-6)."""
    a = src.half_width
    edges = np.linspace(-a, a, n + 1)
    fine = np.linspace(-a, a, 100 * n + 1)
    xm = 0.5 * (fine[1:] + fine[:-1])
    q = src.flux * np.sqrt(np.clip(1.0 - (xm / a) ** 2, 0.0, None)) * shape(xm)
    return edges, q.reshape(n, 100).mean(axis=1)


def _section(scene, src, edges, flux, level):
    """(time [s], rise [K] (time, depth), pass peaks [K] (pass, depth), residual rises [K]) of the rail's FE
    section under ``flux`` [W/m^2] on ``edges`` [m] with the scene's passes, schedule and depths."""
    tr = scene.transient
    m = scene.rail
    block = fem_block(src.half_width, src.speed, m.conductivity, m.density * m.specific_heat, 0.0, level,
                      tr.count * tr.interval, tr.depths, tr.schedule_time)
    t, rise, res, _ = section_history(block, edges, flux, src.speed, tr, tr.interval, level, "implicit")
    return t, rise, pass_peaks_and_residual(t, rise, tr.count, tr.interval)[0], res


def _exact_summary(scene, src):
    tr = scene.transient
    return pass_summary(tr.depths, src, scene.rail, tr.count, tr.interval, _schedule(scene), **CHEAP)


def test_section_steps_in_depth_modes_solve_the_assembled_system():
    """One theta-scheme step of the FE section in depth modes (railtherm_fem.history.TensorSection) equals the
    step of scikit-fem's assembled M and K with a sparse direct solve, ``(M/dt + theta K) T' = (M/dt - (1 - theta)
    K) T + p``, to round-off (1e-10), with surface convection, for Crank-Nicolson and backward Euler; the output
    depths read from the modes equal the nodal interpolation."""
    rng = np.random.default_rng(7)
    block = fem_block(6e-3, 30.0, 50.0, 3.6e6, 2e4, 1, 0.1, (0.0, 1e-4, 5e-4))
    tensor = block.tensor
    for dt, theta in ((2e-6, 0.5), (1e-3, 1.0)):
        eta = rng.normal(size=block.capacity.size)
        load = rng.normal(size=block.x.size) * 1e3
        T = tensor.nodal(eta)
        p = np.zeros(T.size)
        p[block.surface] = load
        M, K = block.mass, block.stiffness
        want = spsolve(sp.csc_matrix(M / dt + theta * K), M @ T / dt - (1.0 - theta) * (K @ T) + p)
        got = tensor.nodal(tensor.factor(dt, theta).solve(tensor.rhs(eta, dt, theta, load)))
        assert np.max(np.abs(got - want)) < 1e-10 * np.max(np.abs(want)), (dt, theta)
        nodal = np.sum(T[block.nodal_rows] * block.nodal_weights, axis=1)
        modal = np.sum(eta[block.rows] * block.weights, axis=1)
        assert np.allclose(modal, nodal, rtol=1e-12, atol=1e-12 * np.max(np.abs(T)))


def test_fem_slip_velocity_is_the_elastic_creep_of_full_sliding():
    """The wheel spin's contact by fem at level 1 (mechanics only): inside 0.8 a the slip velocity of the wheel
    relative to the rail is -v_s + V mu x / R, the rigid slip plus the elastic creep of equal half-planes under
    the full-sliding Hertz traction (module docstring): the fitted slope within 0.5 % of V mu / R = 20.71 1/s
    (measured 20.701, 0.06 %; level 0: 20.689, level 2: 20.710) and the intercept within 0.1 % of -v_s
    (-1.9991). Its heat mu p |s| therefore sits 0.089 mm behind the patch centre in any fine enough solve."""
    scene, _ = _wheel_spin()
    model = FemModel()
    prob = model._problem(1, model.resolve_options({}), False, wheel=scene.wheel, rail=scene.rail, speed=scene.speed,
                          wheel_radius=scene.wheel_radius, normal_force=scene.normal_force,
                          penetration=scene.penetration, friction=scene.friction, creepage=scene.creepage,
                          sliding_speed=scene.sliding_speed, heat_partition=scene.partition,
                          convection=scene.convection, strip=None, field=None, numerics=None)
    sol = solve_fem(prob)
    c = sol.contact
    speed = scene.speed * c.slip
    inside = np.abs(c.x - sol.centre) < 0.8 * sol.half_width
    slope, intercept = np.polyfit(c.x[inside], speed[inside], 1)
    creep = scene.speed * scene.friction.nominal / scene.wheel_radius
    assert slope == pytest.approx(creep, rel=5e-3)
    assert intercept == pytest.approx(-scene.sliding_speed, rel=1e-3)


# the exact history on ~1,600 samples with the schedule and the pass summary (~1 min): opt-in (-m slow)
@pytest.mark.slow
def test_section_under_the_references_heat_meets_the_targets_at_level_2():
    """The rail's FE section at level 2 under the exact reference's heat (full sliding's mu p v_s, Hertz band,
    a = 5.88 mm, 30 m/s; 3 revolutions, the heat ramped over 5 ms from 0): pass peaks and residual rises within
    2 %, the history's max-norm within 3 % of the exact band (measured 0.045 %, 0.038 % and 0.12 %, the
    history at about 40 samples per contact duration)."""
    scene, src = _wheel_spin()
    edges, flux = _cells(src)
    t, rise, peak, residual = _section(scene, src, edges, flux, 2)
    ref = _exact_summary(scene, src)
    tr = scene.transient
    assert np.max(np.abs(peak / ref.peak - 1)) < 0.02, peak / ref.peak
    assert np.max(np.abs(residual / ref.residual[:, 0] - 1)) < 0.02, residual / ref.residual[:, 0]
    every = max(1, int(round(src.contact_duration / np.median(np.diff(t)) / 40)))
    exact = temperature_history(t[::every], tr.depths, src, scene.rail, tr.count, tr.interval, _schedule(scene),
                                **CHEAP)
    history = np.max(np.abs(rise[::every] - exact).max(axis=0) / exact.max(axis=0))
    assert history < 0.03, history


# four levels of the section and the exact pass summary (~1 min): opt-in (-m slow)
@pytest.mark.slow
def test_section_converges_at_second_order_on_the_wheel_spin():
    """The same section at levels 0 .. 3 (Q1 elements at h = 2a/32/2**level, Crank-Nicolson at h/V, the peak
    taken on that axis): the largest relative errors of the pass peaks (surface, 0.1, 0.5, 1 mm) and of the
    residual rises fall like h^2, the theory's order (O(h^2) in space, O(dt^2) = O(h^2) in time and in the
    sampled peak): fitted slopes within 0.3 of 2 (measured peaks 0.50, 0.14, 0.045, 0.011 %, residual 0.50,
    0.13, 0.038, 0.011 %: slopes 1.81 and 1.84)."""
    scene, src = _wheel_spin()
    edges, flux = _cells(src)
    ref = _exact_summary(scene, src)
    hs, peaks, residuals = [], [], []
    for level in (0, 1, 2, 3):
        _, _, peak, residual = _section(scene, src, edges, flux, level)
        hs.append(2.0 * src.half_width / 32 / 2 ** level)
        peaks.append(np.max(np.abs(peak / ref.peak - 1)))
        residuals.append(np.max(np.abs(residual / ref.residual[:, 0] - 1)))
    for err in (peaks, residuals):
        assert np.polyfit(np.log(hs), np.log(err), 1)[0] == pytest.approx(2.0, abs=0.3), err


# fem's solve at level 2, the section under the creep heat and the pass summary (~1.5 min): opt-in (-m slow)
@pytest.mark.slow
def test_fem_first_revolution_offset_is_its_elastic_creep_heat():
    """fem's own solve of the wheel spin at level 2 against the exact band: its pass peaks and residual rises
    (rail) equal, within 0.3 % of the exact values, those of the same FE section heated by the exact Hertz
    pressure times the elastic creep slip |s| = v_s - V mu x / R (measured differences at most 0.22 %: fem's
    contact converges to that heat at first order). That heat puts the first revolution's surface peak 2.44 %
    and its peaks below the surface 1.5 % above the exact band (the later revolutions, at factor 1: the
    surface 0.8 %, below it < 0.1 %) whatever the section's level (level 3: 2.46 %, 1.5 %), so the 2 % target on
    the pass peaks is out of reach of a model that has the creep, while the residual rises stay within 2 %
    (1.45 %)."""
    scene, src = _wheel_spin()
    creep = scene.speed * scene.friction.nominal / scene.wheel_radius / scene.sliding_speed
    edges, flux = _cells(src, lambda x: 1.0 - creep * x)
    _, _, peak, residual = _section(scene, src, edges, flux, 2)
    ds = railtherm.solve(scene, "fem", level=2)
    ref = _exact_summary(scene, src)
    bulk = scene.rail.bulk_temperature
    fem_peak = ds.pass_peak_temperature.sel(body="rail").values - bulk
    fem_residual = ds.residual_rise.sel(body="rail").values
    assert np.max(np.abs((fem_peak - peak) / ref.peak)) < 3e-3, (fem_peak - peak) / ref.peak
    assert np.max(np.abs((fem_residual - residual) / ref.residual[:, 0])) < 3e-3
    first = peak[0] / ref.peak[0] - 1
    assert first[0] > 0.02 and np.all(first[1:] > 0.01), first
    assert np.max(np.abs(residual / ref.residual[:, 0] - 1)) < 0.02


# the level-2 solve scored by metrics.nc's transient metrics (~3 min): opt-in (-m slow)
@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError, reason="fem's heat has the elastic creep of its contact (first revolution's surface "
                                       "peak 2.66 % above the rigid-slip exact band; see the test above)")
def test_wheel_spin_within_the_targets_at_level_2_through_the_metrics():
    """The study's wheel spin with fem at level 2 scored as the study scores it (metrics.nc): pass peaks and
    residual rise within 2 %, the history within 3 % of the exact band. Measured 2.66 %, 1.30 % and 1.91 %:
    the pass peaks miss by the first revolution's surface peak, the creep heat's (module docstring)."""
    scene, _ = _wheel_spin()
    ds = railtherm.solve(scene, "fem", level=2)
    notes = {}
    got = {k: v[0] for k, v in transient_errors(scene, ds, notes, {}).items()}
    assert got["pass_peak_temperature"] < 0.02 and got["residual_rise"] < 0.02, (got, notes)
    assert got["temperature_history"] < 0.03, (got, notes)
