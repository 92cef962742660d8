"""Model "fipy": dimension choice and refusals, options, bulk temperatures, body speeds, convection,
FiPy issue #1223 (equations rebuilt), 3-D symmetry, registration, and ``railtherm.solve``.

Run: ``PYTHONPATH=core:plugins python -m pytest tests/test_fipy_model.py -q``.
"""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

import railtherm
from railtherm import HeatSource, Material, Refused, SceneError, surface_grid
from railtherm.references.flash import flash_temperature_1d
from railtherm.solving.capabilities_check import capability_refusal, source_refusal
from railtherm_fipy.mesh import moving_frame_mesh
from railtherm_fipy.model import FipyTemperature
from railtherm_fipy.steady import MovingFrameSolver

STEEL = Material()
KAPPA = STEEL.diffusivity


def _scene(v, shape="ellipse", wheel=STEEL, rail=STEEL, convection=0.0, **kw):
    mats = (wheel, rail)
    ns = dict(name="t", contact_shape=shape, heat_source=None, tangential="full-sliding", speed=v, sliding_speed=None,
              field=None,
              convection=convection, wheel=wheel, rail=rail, mode="steady", outputs=(), body=lambda i: mats[i])
    ns.update(kw)
    return SimpleNamespace(**ns)


def _parts(scene):
    """The parts of ``scene`` that FipyTemperature.choose_dimension reads: the materials and the field's depth."""
    return (scene.wheel, scene.rail), None if scene.field is None else scene.field.depth


def _uniform_source(a, b, level, v, eps=0.5, speeds=None, cells=8, q=1e8):
    g = surface_grid(a, b, level, cells)
    qd = np.where(g.inside(), q, 0.0)
    return HeatSource(grid=g, power_density=qd, heat_partition=eps, body_speed=speeds or (v, v),
                      frictional_power=g.integrate(qd))


def _pe_speed(pe, a):
    return 2 * KAPPA * pe / a


# ------------------------------------------------------------------ dimension choice / refusals
def test_line_contact_is_2d_and_refuses_3d():
    v = 30.0
    src = _uniform_source(1e-3, None, 0, v)
    m = FipyTemperature()
    opts = m.resolve_options({})
    assert m.choose_dimension(*_parts(_scene(v, "line")), src, 0, opts) == (2, "line")
    with pytest.raises(Refused, match="dimension 3 needs an elliptical patch"):
        m.choose_dimension(*_parts(_scene(v, "line")), src, 0, m.resolve_options({"dimension": 3}))


def test_auto_uses_strips_at_high_peclet_and_3d_at_low():
    a = 1e-3
    m = FipyTemperature()
    v_hi = _pe_speed(1e4, a)
    assert m.choose_dimension(*_parts(_scene(v_hi)), _uniform_source(a, a, 0, v_hi), 0, m.resolve_options({}))[1] == "strips"
    v_lo = _pe_speed(10.0, a)
    assert m.choose_dimension(*_parts(_scene(v_lo)), _uniform_source(a, a, 0, v_lo), 0, m.resolve_options({}))[1] == "3-D"


def test_strips_refused_at_low_peclet_with_reason():
    a = 1e-3
    v = _pe_speed(10.0, a)
    m = FipyTemperature()
    with pytest.raises(Refused, match=r"delta/b = .* > max_strip_delta = 0.02 \(Peclet number 10"):
        m.choose_dimension(*_parts(_scene(v)), _uniform_source(a, a, 0, v), 0, m.resolve_options({"dimension": 2}))


def test_refused_when_strips_invalid_and_3d_too_large():
    a = 1e-3
    v = _pe_speed(10.0, a)
    m = FipyTemperature()
    src = _uniform_source(a, a, 3, v)
    with pytest.raises(Refused) as info:
        m.compute_temperature(_scene(v), src, 3, FipyTemperature.resolve_options({"max_cells": 1000}))
    msg = str(info.value)
    assert "delta/b" in msg and "max_cells = 1000" in msg and "cells per body" in msg


def test_supports_needs_speed():
    m = FipyTemperature()
    why = capability_refusal(m, _scene(0.0))
    assert why is not None and "speed > 0" in why
    assert capability_refusal(m, _scene(30.0)) is None and m.supports(_scene(30.0), 0) is None


def test_options_validated():
    with pytest.raises(SceneError):
        FipyTemperature.resolve_options({"scheme": "quick"})
    with pytest.raises(SceneError):
        FipyTemperature.resolve_options({"dimension": 4})
    opts = FipyTemperature.resolve_options({})
    assert opts["scheme"] == "power-law" and opts["dimension"] == "auto"


# ------------------------------------------------------------------ physics plumbing
def test_bulk_temperature_added_and_speeds_per_body():
    """Absolute temperatures (bulk added); wheel solved with v_wheel, rail with v_rail."""
    a = 1e-3
    hot = dataclasses.replace(STEEL, bulk_temperature=150.0)
    src = _uniform_source(a, None, 2, 30.0, eps=0.5, speeds=(40.0, 10.0))
    tf = FipyTemperature().compute_temperature(_scene(30.0, "line", wheel=hot), src, 2, FipyTemperature.resolve_options({}))
    cold = FipyTemperature().compute_temperature(_scene(30.0, "line"), src, 2, FipyTemperature.resolve_options({}))
    assert np.allclose(tf.surface_temperature[0] - 150.0, cold.surface_temperature[0])
    assert np.allclose(tf.surface_temperature[1], cold.surface_temperature[1])
    # 1-D high-Péclet scaling: T ~ q / sqrt(V): the faster wheel is cooler by about sqrt(10/40)
    ratio = cold.max_surface_temperature[0] / cold.max_surface_temperature[1]
    assert ratio == pytest.approx(0.5, rel=0.03)
    assert tf.temperature.shape[:2] == (2, src.grid.x.size) and tf.z.size == tf.temperature.shape[2]
    assert tf.temperature[0].min() >= 150.0 - 1e-9


def test_line_contact_near_1d_flash_at_high_peclet():
    """At Pe ~ 1e4 the 2-D solution approaches the 1-D flash temperature (max within 1 %)."""
    a, v = 1e-3, _pe_speed(1e4, 1e-3)
    src = _uniform_source(a, None, 4, v, eps=1.0)
    tf = FipyTemperature().compute_temperature(_scene(v, "line"), src, 4, FipyTemperature.resolve_options({}))
    g = src.grid
    exact = flash_temperature_1d(g.x, 0 * g.x, a, v, STEEL, 1e8, "uniform")
    assert tf.max_surface_temperature[0] == pytest.approx(exact.max(), rel=0.01)


def test_convection_cools_and_balance_holds():
    a = 1e-3
    v = _pe_speed(1.0, a)
    g = surface_grid(a, None, 2, 8)
    mesh = moving_frame_mesh(g.x_edges, a, v, KAPPA, 2)
    s = MovingFrameSolver(mesh, v, STEEL)
    i0 = int(np.searchsorted(mesh.x_edges, -a * (1 + 1e-12)))
    q = np.zeros(s.x.size)
    q[i0:i0 + g.x.size] = 1e8
    r0 = s.solve(q, convection=0.0)
    r1 = s.solve(q, convection=1e6)
    assert r1["surface"].max() < r0["surface"].max()
    assert abs(r0["energy_balance"] - 1) < 1e-3 and abs(r1["energy_balance"] - 1) < 1e-3
    # FiPy issue #1223: every solve builds a new equation; a fresh solver gives the identical answer
    fresh = MovingFrameSolver(mesh, v, STEEL).solve(q, convection=1e6)
    assert np.allclose(fresh["surface"], r1["surface"], rtol=1e-10, atol=1e-12)
    again = s.solve(q, convection=0.0)
    assert np.allclose(again["surface"], r0["surface"], rtol=1e-10, atol=1e-12)


def test_strips_with_convection_group_by_contact_mask():
    """With h > 0 strips whose contact masks differ need their own factorisation; h = 0 needs one."""
    a = b = 1e-3
    v = _pe_speed(1e4, a)
    src = _uniform_source(a, b, 0, v)
    m = FipyTemperature()
    t0 = m.compute_temperature(_scene(v), src, 0, FipyTemperature.resolve_options({}))
    t1 = m.compute_temperature(_scene(v, convection=1e4), src, 0, FipyTemperature.resolve_options({}))
    assert t0.diagnostics["wheel_factorisations"] == 1
    assert t1.diagnostics["wheel_factorisations"] > 1
    assert np.all(t1.surface_temperature <= t0.surface_temperature + 1e-9)
    assert np.allclose(t1.max_surface_temperature, t0.max_surface_temperature, rtol=1e-3)  # Bi tiny


def test_3d_half_domain_matches_full_domain():
    """A symmetric source is solved on y >= 0; an (imperceptibly) asymmetric one on the full width."""
    a = b = 1e-3
    v = _pe_speed(100.0, a)
    src = _uniform_source(a, b, 0, v, eps=1.0)
    m = FipyTemperature()
    assert m._half(src)
    t_half = m.compute_temperature(_scene(v), src, 0, FipyTemperature.resolve_options({"dimension": 3}))
    q = src.power_density.copy()
    q[4, 2] *= 1 + 1e-9
    src2 = dataclasses.replace(src, power_density=q)
    assert not m._half(src2)
    t_full = m.compute_temperature(_scene(v), src2, 0, FipyTemperature.resolve_options({"dimension": 3}))
    assert t_full.diagnostics["max_cells"] > 1.8 * t_half.diagnostics["max_cells"]
    assert np.allclose(t_half.surface_temperature, t_full.surface_temperature, rtol=1e-6, atol=1e-6)


# ------------------------------------------------------------------ registration and pipeline
def test_registered_method_and_model():
    info = {m.name: m for m in railtherm.methods()}
    assert "fipy" in info
    chain = info["fipy"].method.chain
    assert chain["normal"] == ("wheelset", "hertz") and chain["temperature"] == ("fipy",)
    assert chain["tangential"] == ("full-sliding", "fastsim") and chain["heat_source"] == ("frictional",)


def test_solve_given_heat_source_line_contact():
    """A scene giving its flux: no contact stage; Jaeger-like band at 30 m/s through railtherm.solve."""
    scene = {"name": "band", "contact": {"shape": "line", "wheel_radius": 0.46}, "speed": 30.0,
             "heat_source": {"flux": 1e8, "shape": "hertz", "half_width": 1e-3}, "heat_partition": 0.5,
             "outputs": ["max_surface_temperature", "surface_temperature", "temperature"]}
    ds = railtherm.solve(scene, "fipy", level=1, options={"scheme": "upwind"})
    assert ds.attrs["fipy_mode"] == "line" and ds.attrs["fipy_scheme"] == "upwind"
    assert ds.attrs["fipy_converged"] == 1
    g = surface_grid(1e-3, None, 1, 16)
    exact = flash_temperature_1d(g.x, 0 * g.x, 1e-3, 30.0, Material(), 0.5e8, "hertz")
    assert ds["max_surface_temperature"].values[0] == pytest.approx(exact.max(), rel=0.02)


def test_solve_bad_option_is_scene_error():
    scene = {"name": "band", "contact": {"shape": "line", "wheel_radius": 0.46}, "speed": 30.0,
             "heat_source": {"flux": 1e8, "shape": "uniform", "half_width": 1e-3}, "heat_partition": 0.5,
             "outputs": ["max_surface_temperature"]}
    with pytest.raises(SceneError):
        railtherm.solve(scene, "fipy", level=0, options={"scheme": "quick"})


def test_strip_assembly_equals_direct_fipy_solve():
    """solve_strips (one FiPy assembly, systems derived by linearity) == FiPy's own solve per strip."""
    a = 1e-3
    v = _pe_speed(50.0, a)
    g = surface_grid(a, None, 1, 8)
    mesh = moving_frame_mesh(g.x_edges, a, v, KAPPA, 1)
    s = MovingFrameSolver(mesh, v, STEEL)
    i0 = int(np.searchsorted(mesh.x_edges, -a * (1 + 1e-12)))
    Q = np.zeros((3, s.x.size))
    C = np.zeros_like(Q, dtype=bool)
    for j, half in enumerate((1.0, 0.6, 0.3)):       # three chords of an ellipse
        inside = np.abs(s.x) < half * a
        Q[j, inside] = 1e8 * (1 + s.x[inside] / a)
        C[j] = inside
    res = s.solve_strips(Q, C, convection=5e4, keep=1)
    assert res["factorisations"] == 3 and res["residual"] < 1e-12
    for j in range(3):
        direct = MovingFrameSolver(mesh, v, STEEL).solve(Q[j], convection=5e4, contact=C[j])
        assert np.allclose(res["surface"][j], direct["surface"], rtol=1e-9, atol=1e-9)
    assert np.allclose(res["T"], MovingFrameSolver(mesh, v, STEEL).solve(Q[1], convection=5e4, contact=C[1])["T"],
                       rtol=1e-9, atol=1e-9)


def test_refine_option_subdivides_patch_cells():
    """refine = 2 puts two FiPy cells per grid cell: closer to Jaeger's band than refine = 1."""
    from railtherm.references.jaeger import jaeger_band_temperature
    a, v = 1e-3, _pe_speed(1e3, 1e-3)
    src = _uniform_source(a, None, 2, v, eps=1.0)
    g = src.grid
    exact = jaeger_band_temperature(g.x, 0 * g.x, a, v, STEEL, 1e8, "uniform")
    errs = []
    for refine in (1, 2):
        tf = FipyTemperature().compute_temperature(_scene(v, "line"), src, 2, FipyTemperature.resolve_options({"refine": refine}))
        errs.append(np.max(np.abs(tf.surface_temperature[0] - exact)) / exact.max())
        assert tf.diagnostics["refine"] == refine
    assert errs[1] < 0.8 * errs[0]


def test_conformance_kit():
    """railtherm.testing: static model checks and the canonical scenes (solved or refused with a reason)."""
    from railtherm.testing import check_method, check_model_class
    check_model_class(FipyTemperature)
    outcome = check_method("fipy")
    assert outcome["ellipse-full-sliding"] == "ok" and outcome["line-given-flux"] == "ok"
    assert all(v == "ok" or v.startswith("refused: ") for v in outcome.values()), outcome


def test_locked_wheel_refused():
    a = 1e-3
    src = _uniform_source(a, None, 0, 30.0, speeds=(0.0, 30.0))
    # core checks the source's body speeds right before compute_temperature
    why = source_refusal(FipyTemperature(), _scene(30.0, "line"), src)
    assert why is not None and "wheel moves at 0 m/s" in why


def test_low_peclet_3d_budget():
    """At Pe < 1 the 3-D budget is max_cells_low_peclet (slow Krylov convergence), with the reason."""
    a = 1e-3
    v = _pe_speed(0.1, a)
    src = _uniform_source(a, a, 1, v)
    m = FipyTemperature()
    with pytest.raises(Refused, match="max_cells_low_peclet = 100000 at Peclet number 0.1"):
        m.choose_dimension(*_parts(_scene(v)), src, 1, m.resolve_options({"dimension": 3}))
    assert m.choose_dimension(*_parts(_scene(v)), src, 1, m.resolve_options({"dimension": 3, "max_cells_low_peclet": 200_000})
                              ) == (3, "3-D")
