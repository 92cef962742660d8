"""Plugin API 1 path of FASTSIM, kept for one release.

FASTSIM's algorithm is now in :mod:`railtherm_fastsim.simplified_theory` and its stage model, a
tangential model, in :mod:`railtherm_fastsim.tangential` (``FastsimHeatSource`` is its old name).
"""
from __future__ import annotations

import warnings

from .simplified_theory import (BOUNDS, FLEXIBILITIES, LEADING_EDGES, FastsimResult, ellipse_cell_integrals,
                                fastsim, fastsim_flexibilities)
from .tangential import ONE_SWEEP, FastsimTangential

FastsimHeatSource = FastsimTangential

__all__ = ["FastsimResult", "fastsim", "fastsim_flexibilities", "ellipse_cell_integrals", "FastsimHeatSource",
           "BOUNDS", "FLEXIBILITIES", "LEADING_EDGES", "ONE_SWEEP"]

warnings.warn("railtherm_fastsim.fastsim_model is deprecated: use railtherm_fastsim.simplified_theory (the "
              "algorithm) and railtherm_fastsim.tangential (the stage model)", DeprecationWarning, stacklevel=2)
