"""The Manchester benchmark's case A-2.2 (tests/data/profiles/manchester_a22.toml) as scene mappings, shared
by tests/test_manchester.py and benchmarks/test_manchester_benchmark.py."""
from __future__ import annotations

import tomllib
from pathlib import Path

DATA = Path(__file__).resolve().parent / "data" / "profiles"
A22 = tomllib.loads((DATA / "manchester_a22.toml").read_text())


def a22_scene(position: int, side: str, **material) -> dict:
    """The benchmark's wheel ``side`` at ``position`` as a scene mapping (SI units; the file's lengths are in
    mm, speeds in mm/s, moduli in MPa). ``material``: thermal constants added to both bodies' elastic ones."""
    s, p = A22["setup"], A22["position"][position - 1]
    assert p["id"] == position
    mat = {"shear_modulus": s["shear_modulus"] * 1e6, "poisson_ratio": s["poisson_ratio"], **material}
    return {"name": f"a22-{position}-{side}", "speed": s["speed"] * 1e-3, "friction": s["friction"],
            "wheel": mat, "rail": mat,
            "wheelset": {"wheel_profile": str(DATA / "MBench_S1002_v3.prw"),
                         "rail_profile": str(DATA / "MBench_UIC60_v3.prr"),
                         "rail_inclination": s["rail_cant"], "gauge": s["gauge"] * 1e-3,
                         "gauge_height": s["gauge_height"] * 1e-3,
                         "flange_back_distance": s["flange_back_distance"] * 1e-3,
                         "flange_back_position": s["flange_back_position"] * 1e-3,
                         "nominal_radius": s["nominal_radius"] * 1e-3, "lateral_shift": p["lateral_shift"] * 1e-3,
                         "yaw_angle": p["yaw"], "roll_angle": p["roll"], "pitch_velocity": p["pitch_velocity"],
                         "vertical_force": s["vertical_force"], "side": side}}
