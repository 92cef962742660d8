"""Heat partition between wheel and rail: moved to :mod:`railtherm.physics.partition`.

This module re-exports it for one release; import from :mod:`railtherm.physics`.
"""
from __future__ import annotations

from ..physics.partition import equal_temperature_partition, scene_partition

__all__ = ["equal_temperature_partition", "scene_partition"]
