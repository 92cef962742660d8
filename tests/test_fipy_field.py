"""fipy behind the patch and in depth (scene key ``field``) against the exact references:
Jaeger's Hertzian band at depth (2-D, line contact) and the moving Hertzian circle on a half-space
(3-D, point-source superposition), both at Péclet 1000, rail only (heat_partition 0: the rail carries
the whole flux), a = 5 mm.

Measured (``OPENBLAS_NUM_THREADS=1 python -m pytest tests/test_fipy_field.py -s``, printed below each
run; max over the depths of the error / exact, peak as a fraction of the exact rise, cooling rate from
z = 0.1 mm, time above where it is at least a quarter of the surface's):

* band, behind = 30a, depth 0.3 mm, threshold 1100 degC, levels 0..3 (16..128 cells on 2a, 2 048 cells
  along x at level 3): peak 1.85e-2, 1.09e-2, 6.2e-3, 3.2e-3 (fitted order 0.85: the power-law scheme is
  upwind, first order, at cell Péclet numbers >> 2); cooling rate 0.11, 0.073, 0.034, 0.019; heated depth
  1.8e-2, 3.1e-3, 5.2e-3, 2.4e-3; time above 2.5e-2, 5.1e-3, 9.9e-3, 8.9e-3 (the linear crossing of
  the threshold; not monotone); the depth field behind the patch 3.7e-2 .. 6.6e-3 of its maximum;
* circle, behind = 16a, depth 0.3 mm, threshold 1000 degC, 3-D, levels 0 and 1 (17 760 and 142 080
  cells; level 2 would need about 1.1 million and is refused on the budget): peak 2.3e-2, 1.2e-2;
  cooling rate 0.12, 0.074; time above 7.0e-3, 1.8e-3; heated depth 1.0e-3, 4.3e-3; the depth field
  at y = 0 behind the patch 1.8e-2 of its maximum (level 1). The exact peak at 0.3 mm lies 3.7a behind
  the centre.

The tolerances are these numbers with a margin of ~1.5.
"""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm import Refused
from railtherm.analysis.analytic import trace_reference
from railtherm.input.scene import load_scene
from railtherm.references.moving_source import moving_source_temperature
from field_cases import A, MAT, V, BULK, TRACE, PLAIN, band_field_errors



def _scene(line: bool, behind=30 * A, depth=3e-4, threshold=1100.0, flux=1e9, outputs=TRACE):
    src = dict(flux=flux, shape="hertz", **({"half_width": A} if line else {"semi_axes": [A, A]}))
    sc = dict(name="band" if line else "circle", speed=V, heat_source=src, heat_partition=0.0, outputs=outputs)
    if behind is not None:
        sc["field"] = dict(behind=behind, threshold=threshold, **({} if depth is None else {"depth": depth}))
    return sc


def _errors(ds, ref):
    """Errors of the rail's trace against the exact reference (see the module docstring)."""
    rail = {k: ds[k].values[1] for k in ("peak_temperature", "cooling_rate", "time_above")}
    peak = np.max(np.abs(rail["peak_temperature"] - ref["peak_temperature"][1])
                  / (ref["peak_temperature"][1] - BULK))
    ok = np.isfinite(ref["cooling_rate"][1]) & (ds["z"].values >= 1e-4)   # near the surface: log-singular
    cool = np.max(np.abs(rail["cooling_rate"] - ref["cooling_rate"][1])[ok] / ref["cooling_rate"][1][ok])
    # near the heated depth the time above vanishes (ill-conditioned): where it is >= 1/4 of the surface's
    on = ref["time_above"][1] >= 0.25 * ref["time_above"][1][0]
    above = np.max(np.abs(rail["time_above"] - ref["time_above"][1])[on] / ref["time_above"][1][on])
    depth = abs(float(ds["heated_depth"].values[1]) - ref["heated_depth"][1]) / ref["heated_depth"][1]
    return {"peak": peak, "cool": cool, "above": above, "depth": depth}


def _order(errors, levels):
    """Least-squares slope of -log2(error) against the level (the cell size halves per level)."""
    return float(-np.polyfit(np.asarray(levels, dtype=float), np.log2(errors), 1)[0])


def test_fipy_declares_the_field():
    from railtherm_fipy.model import FipyTemperature
    assert FipyTemperature.capabilities.field
    assert {"peak_temperature", "cooling_rate", "heated_depth", "time_above"} <= FipyTemperature.capabilities.provides


def test_band_pe1000_against_jaeger_with_order():
    """Jaeger's Hertzian band at Pe 1000, levels 0..3: the trace converges at first order (upwinding);
    the depth field behind the patch and down to 0.3 mm against the exact band."""
    sc = _scene(True)
    levels = (0, 1, 2, 3)
    errs = []
    for level in levels:
        ds = railtherm.solve(sc, "fipy", level=level)
        assert ds["z"].values[-1] == pytest.approx(3e-4, rel=1e-12)          # reaches field.depth
        x = ds["x"].values
        assert x[0] - 0.5 * (x[1] - x[0]) < -31 * A * (1 - 1e-12)             # reaches field.behind (first edge)
        ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("fipy band Pe 1000, levels 0-3:", errs)
    peak = [e["peak"] for e in errs]
    assert peak[-1] < 5e-3 and errs[-1]["cool"] < 3e-2 and errs[-1]["depth"] < 4e-3 and errs[-1]["above"] < 1.5e-2
    order = _order(peak, levels)
    print("fitted order of the peak temperature:", order)
    assert 0.7 < order < 1.5
    assert all(b < a for a, b in zip(peak, peak[1:]))
    cool = [e["cool"] for e in errs]
    assert all(b < a for a, b in zip(cool, cool[1:])) and _order(cool, levels) > 0.6
    # the depth field behind the patch (level 3) against Jaeger's band
    rel, surface = band_field_errors(ds)
    print("fipy band depth field behind the patch, max error / max:", rel)
    assert rel < 1e-2
    # the surface trace far behind the patch
    assert surface < 1e-2


def test_circle_pe1000_3d_peak_behind_the_patch_at_0p3mm():
    """The issue's case in 3-D: Hertzian circle at Pe 1000; at 0.3 mm the exact peak lies 3.7a behind the
    centre. Levels 0 and 1 (level 2 is over the cell budget, see the refusal test)."""
    sc = _scene(False, behind=16 * A, threshold=1000.0)
    errs = []
    for level in (0, 1):
        ds = railtherm.solve(sc, "fipy", level=level)
        assert ds.attrs["fipy_dimension"] == 3
        ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("fipy circle Pe 1000 3-D, levels 0-1:", errs)
    assert abs(ref["peak_position"][1, -1] / A + 3.71) < 0.02
    assert errs[1]["peak"] < 2e-2 and errs[1]["peak"] < 0.7 * errs[0]["peak"]
    assert errs[1]["depth"] < 1e-2 and errs[1]["cool"] < 0.12
    # the depth field behind the patch at y = 0 against the exact moving source
    x, z = ds["x"].values, ds["z"].values
    pick = np.searchsorted(x, np.array([-12.0, -6.0, -3.7, -1.5, 0.0]) * A)
    kz = [z.size // 3, 2 * z.size // 3, z.size - 1]
    T = ds["temperature"].values[1][pick][:, kz] - BULK
    X, Z = np.meshgrid(x[pick], z[kz], indexing="ij")
    exact = moving_source_temperature(X, 0 * X, Z, (A, A), V, MAT, 1e9, "hertz", quad_points=12)
    rel = np.max(np.abs(T - exact)) / np.max(exact)
    print("fipy circle depth field behind the patch, max error / max:", rel)
    assert rel < 3e-2


def test_3d_field_over_the_budget_is_refused_with_the_reason():
    sc = _scene(False, behind=16 * A, threshold=1000.0)
    with pytest.raises(Refused) as info:
        railtherm.solve(sc, "fipy", level=2)
    assert info.value.kind == "budget"
    assert "behind the patch (field)" in str(info.value) and "max_cells" in str(info.value)


def test_2d_field_over_the_budget_is_refused_with_the_reason():
    with pytest.raises(Refused) as info:
        railtherm.solve(_scene(True), "fipy", level=2, options={"max_cells": 5000})
    assert info.value.kind == "budget" and "behind the patch" in str(info.value)


def test_field_patch_values_close_to_the_patch_only_run():
    """On the patch the extended run agrees with the patch-only run (the meshes differ: the outflow is
    further away and the mesh deeper; the difference is the patch-only run's outflow error)."""
    plain = railtherm.solve(_scene(True, behind=None, outputs=PLAIN), "fipy", level=1)
    ext = railtherm.solve(_scene(True, behind=4 * A, depth=None, outputs=PLAIN), "fipy", level=1)
    n = ext.sizes["x"] - plain.sizes["x"]
    assert n > 0 and np.allclose(ext["x"].values[n:], plain["x"].values, rtol=0, atol=1e-15)
    a, b = plain["surface_temperature"].values - BULK, ext["surface_temperature"].values[:, n:] - BULK
    assert np.max(np.abs(a - b)) / np.max(a) < 1e-3
    assert np.all(ext["heat_flux"].values[:, :n] == 0)
    assert ext.attrs["fipy_field_cells_behind"] == n


def test_too_short_a_field_is_flagged_not_a_peak():
    """With the field ending before the deep peaks, the trace is NaN with the reason, not a peak."""
    ds = railtherm.solve(_scene(True, behind=1 * A, depth=6e-4), "fipy", level=0)
    peak = ds["peak_temperature"].values[1]
    assert np.isfinite(peak[0]) and np.isnan(peak[-1])
    assert "field too short" in ds.attrs["fipy_trace_rail_notes"]


def test_ellipse_strips_at_high_peclet_peak_at_depth():
    """An ellipse a x 2a at Pe 2e4 is solved strip by strip (dimension 2): the centre strip's peak at depth,
    behind = 6a, down to 0.1 mm (where the peaks are found), against the exact moving source. Measured: 1.9e-2 (level 0), 1.2e-2
    (level 1) of the exact rise."""
    V2 = 2e4 * 2.0 * MAT.diffusivity / A
    sc = dict(name="ellipse", speed=V2, heat_source=dict(flux=1e9, shape="hertz", semi_axes=[A, 2 * A]),
              heat_partition=0.0, field=dict(behind=6 * A, depth=1e-4, threshold=1000.0), outputs=TRACE)
    errs = []
    for level in (0, 1):
        ds = railtherm.solve(sc, "fipy", level=level)
        assert ds.attrs["fipy_mode"] == "strips"
        ref = trace_reference(load_scene(sc), ds["z"].values)
        p, r = ds["peak_temperature"].values[1], ref["peak_temperature"][1]
        ok = np.isfinite(p) & np.isfinite(r)        # the deepest peaks lie beyond 6a: flagged (NaN) in both
        assert ok.sum() >= p.size // 2 and np.array_equal(np.isfinite(p)[ok], np.isfinite(r)[ok])
        errs.append(float(np.max(np.abs(p - r)[ok] / (r - BULK)[ok])))
    print("fipy ellipse strips Pe 2e4, levels 0-1:", errs)
    assert errs[1] < 1.8e-2 and errs[1] < 0.8 * errs[0]
