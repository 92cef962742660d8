"""Deprecated alias of :mod:`railtherm_fdm.block2d` (the FDM temperature model is its own plugin, ``fdm``).

Kept for one release: ``import railtherm_fastsim.fdm_line`` returns the module ``railtherm_fdm.block2d`` itself
(an alias in ``sys.modules``), so attribute changes such as monkeypatching reach the code that runs.
"""
import sys
import warnings

from railtherm_fdm import block2d as _moved

warnings.warn("railtherm_fastsim.fdm_line moved to railtherm_fdm.block2d; the old path is removed in the next release",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
