"""Shared constants of the thermal-trace tests (tests/test_*_field.py): a patch half-length a = 5 mm
at Péclet number V a / (2 kappa) = 1000 with core's default material, the output lists they ask, the
Hertzian given-source scene (circle or band), the rail trace's errors against the exact reference and the
band's field behind the patch against Jaeger's."""
import numpy as np

import railtherm
from railtherm.references.jaeger import jaeger_band_temperature

A = 5e-3                                     # [m]
MAT = railtherm.Material()
V = 1000.0 * 2.0 * MAT.diffusivity / A      # [m s-1]: Péclet V a / (2 kappa) = 1000
BULK = MAT.bulk_temperature                  # [degC]
TRACE = ["surface_temperature", "temperature", "peak_temperature", "cooling_rate", "heated_depth", "time_above"]
PLAIN = ["surface_temperature", "temperature", "max_surface_temperature", "mean_contact_temperature"]


def hertz_scene(line: bool, behind=16 * A, depth=3e-4, threshold=1000.0, flux=1e9):
    """A Hertzian given source (band when ``line``, else the circle of radius A) at speed V, all heat into the
    rail, with ``field`` = behind [m], depth [m], threshold [degC]."""
    src = dict(flux=flux, shape="hertz", **({"half_width": A} if line else {"semi_axes": [A, A]}))
    return dict(name="band" if line else "circle", speed=V, heat_source=src, heat_partition=0.0,
                field=dict(behind=behind, depth=depth, threshold=threshold), outputs=TRACE)


def trace_errors(ds, ref):
    """Relative errors of the rail's peak temperature, cooling rate (z >= 0.1 mm), time above and heated depth
    against the exact ``trace_reference`` values ``ref``."""
    rail = {k: ds[k].values[1] for k in ("peak_temperature", "cooling_rate", "time_above")}
    peak = np.max(np.abs(rail["peak_temperature"] - ref["peak_temperature"][1])
                  / (ref["peak_temperature"][1] - BULK))
    ok = np.isfinite(ref["cooling_rate"][1]) & (ds["z"].values >= 1e-4)   # near the surface: log-singular
    cool = np.max(np.abs(rail["cooling_rate"] - ref["cooling_rate"][1])[ok] / ref["cooling_rate"][1][ok])
    on = ref["time_above"][1] > 0
    above = np.max(np.abs(rail["time_above"] - ref["time_above"][1])[on] / ref["time_above"][1][on])
    depth = abs(float(ds["heated_depth"].values[1]) - ref["heated_depth"][1]) / ref["heated_depth"][1]
    return {"peak": peak, "cool": cool, "above": above, "depth": depth}


def band_field_errors(ds):
    """Largest errors, relative to the exact maximum, of the rail's depth field (surface, mid and bottom depth)
    and of its surface trace at x = -25, -10, -3, -1 and 0.5 a (behind and at the patch) against Jaeger's
    Hertzian band of flux 1e9 W m-2 (returns depth error, surface error)."""
    x, z = ds["x"].values, ds["z"].values
    pick = np.searchsorted(x, np.array([-25.0, -10.0, -3.0, -1.0, 0.5]) * A)
    kz = [0, z.size // 2, z.size - 1]
    T = ds["temperature"].values[1][pick][:, kz] - BULK
    exact = jaeger_band_temperature(x[pick][:, None], z[kz][None, :], A, V, MAT, 1e9, "hertz")
    ts = ds["surface_temperature"].values[1][pick] - BULK
    ex = jaeger_band_temperature(x[pick], 0 * x[pick], A, V, MAT, 1e9, "hertz")
    return np.max(np.abs(T - exact)) / np.max(exact), np.max(np.abs(ts - ex)) / np.max(ex)
