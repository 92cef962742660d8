"""Shared constants of the thermal-trace tests (tests/test_*_field.py): a patch half-length a = 5 mm
at Péclet number V a / (2 kappa) = 1000 with core's default material, the output lists they ask, the
Hertzian given-source scene (circle or band) and the rail trace's errors against the exact reference."""
import numpy as np

import railtherm

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
