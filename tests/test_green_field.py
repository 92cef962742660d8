"""green behind the patch and in depth (scene key ``field``) against the exact references:
the moving Hertzian circle on a half-space (point-source superposition, Péclet 1000) and Jaeger's
Hertzian band (2-D), rail only (heat_partition 0, so the rail carries the whole flux).

Measured (OPENBLAS_NUM_THREADS=1 python -m pytest tests/test_green_field.py -s): see the printed
errors; the tolerances below are those numbers with a margin of ~1.5-2.
"""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm.analysis.analytic import trace_reference
from railtherm.input.scene import load_scene
from railtherm.references.jaeger import jaeger_band_temperature
from railtherm.references.moving_source import moving_source_temperature
from field_cases import A, MAT, V, BULK, TRACE, hertz_scene as _scene, trace_errors as _errors

OPTS = {"depth_points": 9}


def test_circle_pe1000_peak_behind_the_patch_at_0p3mm():
    """The issue's case: Hertzian flux on a circle, Pe 1000, at 0.3 mm the peak lies 3.7 a behind the
    centre (exact); green's 1-D strips reach it within 0.5 %, the cooling rate within 3 %."""
    ds = railtherm.solve(_scene(False), "green", level=2, options=OPTS)
    ref = trace_reference(load_scene(_scene(False)), ds["z"].values)
    assert abs(ref["peak_position"][1, -1] / A + 3.71) < 0.02
    err = _errors(ds, ref)
    print("circle Pe 1000, level 2:", err)
    assert err["peak"] < 6e-3 and err["above"] < 3e-2 and err["cool"] < 4e-2 and err["depth"] < 3e-2
    # the depth field behind the patch and the surface trace against the exact moving source
    x = ds["x"].values
    pick = np.searchsorted(x, np.array([-12.0, -6.0, -3.7, -1.5, 0.0]) * A)
    z = ds["z"].values
    T = ds["temperature"].values[1][pick][:, [2, 5, 8]] - BULK
    X, Z = np.meshgrid(x[pick], z[[2, 5, 8]], indexing="ij")
    exact = moving_source_temperature(X, 0 * X, Z, (A, A), V, MAT, 1e9, "hertz", quad_points=12)
    rel = np.max(np.abs(T - exact)) / np.max(exact)
    print("circle depth field behind the patch, max error / max:", rel)
    assert rel < 1e-2
    y0 = int(np.argmin(np.abs(ds["y"].values)))
    ts = ds["surface_temperature"].values[1][pick, y0] - BULK
    ex = moving_source_temperature(x[pick], ds["y"].values[y0] + 0 * pick, 0 * pick, (A, A), V, MAT, 1e9, "hertz")
    assert np.max(np.abs(ts - ex)) / np.max(ex) < 2e-2


def test_band_pe1000_against_jaeger_with_orders():
    """Jaeger's Hertzian band at Pe 1000: peak, time above and heated depth converge toward the exact
    values (the remaining floor is the 1-D model's neglect of conduction along x, ~1/Pe)."""
    sc = _scene(True, behind=30 * A, depth=3e-4, threshold=1100.0, flux=1e9)
    errs = []
    for level in (0, 1, 2):
        ds = railtherm.solve(sc, "green", level=level, options=OPTS)
        if level == 0:
            ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("band Pe 1000, levels 0-2:", errs)
    for k in ("peak", "above"):
        e = [d[k] for d in errs]
        assert e[-1] < 1e-3, (k, e)
        assert e[-1] < 0.5 * e[0], (k, e)      # converging (toward the 1-D model's floor, ~1e-4)
    assert all(d["cool"] < 2e-3 for d in errs)   # measured 1.5e-3, 4.8e-4, 9.2e-4: at its floor
    # the heated depth's error is that of the linear interpolation between 9 depths (independent of level)
    assert all(d["depth"] < 6e-3 for d in errs)
    # the depth field behind the patch against Jaeger's band
    x = ds["x"].values
    pick = np.searchsorted(x, np.array([-25.0, -10.0, -3.0, -1.0, 0.5]) * A)
    z = ds["z"].values[[0, 4, 8]]
    T = ds["temperature"].values[1][pick][:, [0, 4, 8]] - BULK
    exact = jaeger_band_temperature(x[pick][:, None], z[None, :], A, V, MAT, 1e9, "hertz")
    rel = np.max(np.abs(T - exact)) / np.max(exact)
    print("band depth field behind the patch, max error / max:", rel)
    assert rel < 1e-2


def test_field_leaves_the_patch_values_as_they_were():
    """The patch cells of the extended field are the patch-only run's to round-off (the added cells
    carry zero flux and the strip sums run over the same cells in the same order; the cell width is
    the mean of the extended edges, equal to ~1e-16)."""
    sc = _scene(False, behind=4 * A)
    plain = {k: v for k, v in sc.items() if k != "field"}
    plain["outputs"] = ["surface_temperature", "temperature", "max_surface_temperature", "mean_contact_temperature"]
    sc["outputs"] = plain["outputs"]
    sc["field"] = dict(behind=4 * A, threshold=1000.0)       # default depth: green's own
    a = railtherm.solve(plain, "green", level=0)
    b = railtherm.solve(sc, "green", level=0)
    n = b.sizes["x"] - a.sizes["x"]
    assert n == 4 * 16 and np.array_equal(b["x"].values[n:], a["x"].values)
    for k in ("max_surface_temperature", "mean_contact_temperature"):
        np.testing.assert_allclose(b[k].values, a[k].values, rtol=1e-13)
    np.testing.assert_allclose(b["surface_temperature"].values[:, n:], a["surface_temperature"].values, rtol=1e-13,
                               atol=1e-12)
    np.testing.assert_allclose(b["temperature"].values[:, n:], a["temperature"].values, rtol=1e-13, atol=1e-12)
    assert np.all(b["heat_flux"].values[:, :n] == 0) and b.attrs["green_field_cells_behind"] == n


def test_too_short_a_field_is_flagged_not_a_peak():
    """With the field ending before the deep peaks, the trace is NaN with the reason in the
    diagnostics, and railtherm.solve returns it (NaN allowed there and commented), not a failure."""
    from railtherm.physics import with_thermal_trace
    from railtherm.solving.pipeline import _run, plan
    sc = load_scene(_scene(False, behind=2 * A, depth=6e-4))
    pl = plan(sc, "green", 0)
    _, src, temp, _ = _run(pl, sc, 0, OPTS)
    peak = temp.peak_temperature[1]
    assert np.isfinite(peak[0]) and np.isnan(peak[-1])
    assert "field too short" in temp.diagnostics["trace_rail_notes"]
    assert np.array_equal(with_thermal_trace(temp, sc.field, src).peak_temperature, temp.peak_temperature,
                          equal_nan=True)
    ds = railtherm.solve(sc, "green", 0, OPTS)
    assert "peak_temperature" in ds.attrs["nan_allowed"].split()
    assert np.isnan(ds["peak_temperature"].values[1, -1]) and "too short" in ds["peak_temperature"].attrs["comment"]


def test_metrics_compare_the_trace_with_the_exact_band():
    """metrics.run_errors takes the trace's errors against core's exact reference, naming it."""
    from railtherm.analysis.analytic import reference_values
    from railtherm.analysis.metrics import run_errors
    sc = load_scene(_scene(True, behind=30 * A, depth=3e-4, threshold=1100.0))
    ds = railtherm.solve(sc, "green", level=1, options=OPTS)
    err = run_errors(sc, ds, reference_values(sc))
    # the cooling rate's worst depth is the first below the surface (z = 3.75 um), where the exact rate of a
    # Hertzian flux is nearly log-singular behind the trailing edge: 27 % at level 1 (0.1 % from z = 0.1 mm)
    bound = {"peak_temperature": 6e-3, "cooling_rate": 0.4, "time_above": 6e-3, "heated_depth": 6e-3}
    for name, most in bound.items():
        value, tag = err[name]
        assert tag == "analytic:jaeger" and 0 <= value < most, (name, value, tag)
