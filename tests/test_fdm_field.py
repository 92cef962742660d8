"""fastsim-fdm (temperature model ``fdm``) behind the patch and in depth (scene key ``field``)
against core's exact references: the moving Hertzian circle on a half-space (point-source superposition,
Péclet 1000, peak at 0.3 mm depth 3.7 a behind the centre) and Jaeger's Hertzian band (2-D), rail only
(heat_partition 0, so the rail carries the whole flux).

At Péclet 1000 the 3-D block runs its moving-frame steady scheme (``auto`` switches to it when a field
asks for depth and the uniform transient grid does not resolve the thermal layer); its fluxes along x are
exponential (upwind at this cell Péclet number): first order. The 2-D block's second-order upwind
fluxes give order ~1.8.

Measured (OPENBLAS_NUM_THREADS=1 python -m pytest tests/test_fdm_field.py -s, errors relative to the
exact peak rise / cooling rate / time above / heated depth):

* circle, levels 0, 1, 2: peak 6.8e-2, 3.1e-2, 1.5e-2 (order 1.1); heated depth 6.4e-2, 2.5e-2, 1.2e-2;
  cooling rate (z >= 0.1 mm) 0.21, 0.14, 0.075; depth field behind the patch (x = -12a..0, z = 0.05..0.3
  mm) 1.6e-2 and surface trace 1.0e-2 of the maximum at level 2; level 3 refused (budget: 4.8e6 cells >
  max_cells 4e6). The time above 1000 degC is not asserted for the circle: at the deepest depth whose exact
  peak exceeds it by a hair, the 1.5 % peak error decides whether the point is above at all (error 1.0 at
  levels 0 and 2, 0.13 at level 1);
* band, levels 0-3: peak 1.5e-2, 4.5e-3, 1.4e-3, 4.1e-4 (order ~1.75); cooling rate 2.2e-2, 4.7e-3, 1.0e-3,
  3.5e-4; time above 4.4e-3, 1.9e-3, 6.3e-3, 1.9e-3; heated depth 1.9e-3, 5.4e-4, 3.9e-4, 4.2e-5; depth field
  behind the patch (x = -25a..0.5a) 1.9e-3 of the maximum at level 3;
* slow circle (Péclet 2.5) on the explicit block, level 1: peak 8.1e-3.

Tolerances are these numbers with a margin of ~1.5.
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

METHOD = "fastsim-fdm"


def _order(errs, key):
    """Least-squares order of the error against the cell size (halved per level)."""
    e = np.array([d[key] for d in errs])
    return -np.polyfit(np.arange(e.size), np.log2(e), 1)[0]


def test_circle_pe1000_peak_behind_the_patch_at_0p3mm_with_order():
    """The issue's case on the 3-D block: the steady graded grid follows the trail 16 a behind and 0.3 mm
    deep; peak and heated depth converge at first order toward the exact moving source."""
    sc = _scene(False)
    errs, ds = [], None
    for level in (0, 1, 2):
        ds = railtherm.solve(sc, METHOD, level=level)
        assert ds.attrs["fdm_rail_scheme"] == "steady"
        ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("fdm circle Pe 1000, levels 0-2:", errs)
    assert abs(ds["z"].values[-1] - 3e-4) < 1e-12 and np.all(np.isfinite(ds["peak_temperature"].values[1]))
    assert errs[-1]["peak"] < 2.5e-2 and errs[-1]["depth"] < 2e-2 and errs[-1]["cool"] < 0.12
    assert _order(errs, "peak") > 0.9 and _order(errs, "depth") > 0.9
    # the depth field behind the patch and the surface trace against the exact moving source (level 2)
    x = ds["x"].values
    pick = np.searchsorted(x, np.array([-12.0, -6.0, -3.7, -1.5, 0.0]) * A)
    z = ds["z"].values
    kz = [np.searchsorted(z, zz) for zz in (0.5e-4, 1.5e-4, 3e-4)]
    T = ds["temperature"].values[1][pick][:, kz] - BULK
    X, Z = np.meshgrid(x[pick], z[kz], indexing="ij")
    exact = moving_source_temperature(X, 0 * X, Z, (A, A), V, MAT, 1e9, "hertz", quad_points=12)
    rel = np.max(np.abs(T - exact)) / np.max(exact)
    print("fdm circle depth field behind the patch, max error / max:", rel)
    assert rel < 3e-2
    y0 = int(np.argmin(np.abs(ds["y"].values)))
    ts = ds["surface_temperature"].values[1][pick, y0] - BULK
    ex = moving_source_temperature(x[pick], ds["y"].values[y0] + 0 * pick, 0 * pick, (A, A), V, MAT, 1e9, "hertz")
    srel = np.max(np.abs(ts - ex)) / np.max(ex)
    print("fdm circle surface trace, max error / max:", srel)
    assert srel < 3e-2


def test_band_pe1000_against_jaeger_with_orders():
    """Jaeger's Hertzian band at Pe 1000 on the 2-D steady block, levels 0-3: second-order-like
    convergence of peak, cooling rate and heated depth."""
    sc = _scene(True, behind=30 * A, depth=3e-4, threshold=1100.0)
    errs = []
    for level in (0, 1, 2, 3):
        ds = railtherm.solve(sc, METHOD, level=level)
        ref = trace_reference(load_scene(sc), ds["z"].values)
        errs.append(_errors(ds, ref))
    print("fdm band Pe 1000, levels 0-3:", errs)
    assert errs[-1]["peak"] < 7e-4 and errs[-1]["cool"] < 7e-4 and errs[-1]["depth"] < 1e-4
    assert errs[-1]["above"] < 4e-3
    assert _order(errs, "peak") > 1.5 and _order(errs, "cool") > 1.5
    x = ds["x"].values
    pick = np.searchsorted(x, np.array([-25.0, -10.0, -3.0, -1.0, 0.5]) * A)
    z = ds["z"].values
    kz = [0, np.searchsorted(z, 1.5e-4), z.size - 1]
    T = ds["temperature"].values[1][pick][:, kz] - BULK
    exact = jaeger_band_temperature(x[pick][:, None], z[kz][None, :], A, V, MAT, 1e9, "hertz")
    rel = np.max(np.abs(T - exact)) / np.max(exact)
    print("fdm band depth field behind the patch, max error / max:", rel)
    assert rel < 3e-3


def test_patch_values_with_a_field_stay_close_to_the_patch_only_run():
    """The field adds cells behind and below; on the patch the band's surface temperature moves by less
    than the discretisation error (the grid behind the patch changes, the patch cells do not)."""
    sc = _scene(True, behind=4 * A)
    plain = {k: v for k, v in sc.items() if k != "field"}
    plain["outputs"] = ["surface_temperature", "max_surface_temperature"]
    a = railtherm.solve(plain, METHOD, level=2)
    b = railtherm.solve(sc, METHOD, level=2)
    n = b.sizes["x"] - a.sizes["x"]
    assert n == 4 * 32 and np.array_equal(b["x"].values[n:], a["x"].values)
    ta, tb = a["surface_temperature"].values[1], b["surface_temperature"].values[1, n:]
    assert np.max(np.abs(ta - tb)) / (np.max(ta) - BULK) < 2e-3
    assert b.attrs["fdm_field_cells_behind"] == n


def test_refusals_name_the_field():
    """Too far for the cell budget: refused (budget) naming the field; an explicit scheme whose uniform grid
    does not resolve the thermal layer: refused (validity) instead of a depth field it cannot compute."""
    with pytest.raises(railtherm.Refused) as err:
        railtherm.solve(_scene(False), METHOD, level=3)
    assert err.value.kind == "budget" and "field" in str(err.value)
    with pytest.raises(railtherm.Refused) as err:
        railtherm.solve(_scene(False), METHOD, level=0, options={"scheme": "explicit"})
    assert err.value.kind == "validity" and "thermal layer" in str(err.value)


def test_transient_block_reaches_behind_the_patch():
    """A slow circle (Péclet 2.5) on the explicit block: the source travels field.behind further and the
    trace behind the patch matches the exact moving source (coarse level 1: a few per cent)."""
    v = 2.5 * 2.0 * MAT.diffusivity / A
    sc = dict(_scene(False, behind=4 * A, depth=2e-3, threshold=100.0, flux=5e7), speed=v)
    ds = railtherm.solve(sc, METHOD, level=1, options={"scheme": "explicit"})
    assert ds.attrs["fdm_rail_scheme"] == "explicit"
    ref = trace_reference(load_scene(sc), ds["z"].values)
    peak = ds["peak_temperature"].values[1]
    ok = np.isfinite(ref["peak_temperature"][1])
    assert np.all(np.isfinite(peak[ok]))
    rel = np.max(np.abs(peak - ref["peak_temperature"][1])[ok] / (ref["peak_temperature"][1][ok] - BULK))
    print("fdm explicit circle Pe 2.5, level 1, peak error:", rel)
    assert rel < 5e-2
