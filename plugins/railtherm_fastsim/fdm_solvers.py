"""Deprecated alias of :mod:`railtherm_fdm.block3d` (the FDM temperature model is its own plugin, ``fdm``).

Kept for one release: ``import railtherm_fastsim.fdm_solvers`` returns the module ``railtherm_fdm.block3d`` itself
(an alias in ``sys.modules``), so attribute changes such as monkeypatching reach the code that runs.
"""
import sys
import warnings

from railtherm_fdm import block3d as _moved

warnings.warn("railtherm_fastsim.fdm_solvers moved to railtherm_fdm.block3d; the old path is removed in the next release",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
