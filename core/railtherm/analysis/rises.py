"""Which quantities are compared on their rise above the bulk temperature, and that bulk temperature."""
from __future__ import annotations

import numpy as np

#: quantities whose relative error is taken on the rise above the bulk temperature
RISES = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature",
         "steady_wheel_temperature", "steady_mean_contact_temperature", "peak_temperature")


def bulk_of(scene, name: str, shape: tuple) -> np.ndarray | float:
    """Bulk temperature [degC] to subtract from quantity ``name`` of the given shape (0 if none)."""
    if name not in RISES:
        return 0.0
    if name.startswith("steady"):
        return scene.wheel.bulk_temperature
    bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
    if len(shape) == 0:
        return scene.wheel.bulk_temperature
    return bulk.reshape((2,) + (1,) * (len(shape) - 1)) if shape[0] == 2 else 0.0
