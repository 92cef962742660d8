"""The scenes the transient benchmarks time: the rail heated by a given Hertzian source, steady or over passes.

Shared by the green, fdm and FiPy transient benchmarks, so that their cost ratios are taken on one scene.
"""
from __future__ import annotations

A, B, V, Q = 6e-3, 4e-3, 30.0, 1e8       # half-width / semi-axes [m], speed [m/s], peak flux [W/m^2]
INTERVAL = 0.083                          # [s] between passes
SOURCES = {"band": {"shape": "hertz", "half_width": A}, "ellipse": {"shape": "hertz", "semi_axes": [A, B]}}


def transient_scene(name: str, passes: int | None, kind: str = "band") -> dict:
    """The rail (all the heat) under the given Hertzian ``kind`` source at V; ``passes`` None: the steady scene,
    else ``passes`` passes INTERVAL apart with the histories at 0.1 and 0.5 mm and a 400 degC threshold."""
    out = {"name": name, "speed": V, "heat_source": {"flux": Q, **SOURCES[kind]},
           "heat_partition": 0.0, "rail": {"bulk_temperature": 20.0}, "wheel": {"bulk_temperature": 20.0}}
    if passes is not None:
        out.update(mode="transient", passes={"count": passes, "interval": INTERVAL},
                   field={"depth": [1e-4, 5e-4], "threshold": 400.0},
                   outputs=["temperature_history", "pass_peak_temperature", "residual_rise", "time_above"])
    return out
