"""Cell averages of the analytic surface distributions: a re-export of :mod:`railtherm.physics.averaging`.

Import them from :mod:`railtherm.physics`.
"""
from __future__ import annotations

from ..physics.averaging import cell_average, exact_total

__all__ = ["cell_average", "exact_total"]
