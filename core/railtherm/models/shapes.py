"""Cell averages of the analytic surface distributions: moved to :mod:`railtherm.physics.averaging`.

This module re-exports them for one release; import from :mod:`railtherm.physics`.
"""
from __future__ import annotations

from ..physics.averaging import cell_average, exact_total

__all__ = ["cell_average", "exact_total"]
