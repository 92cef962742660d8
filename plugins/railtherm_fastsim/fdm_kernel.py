"""Deprecated alias of :mod:`railtherm_fdm.kernels` (the FDM temperature model is its own plugin, ``fdm``).

Kept for one release: ``import railtherm_fastsim.fdm_kernel`` returns the module ``railtherm_fdm.kernels`` itself
(an alias in ``sys.modules``), so attribute changes such as monkeypatching reach the code that runs.
"""
import sys
import warnings

from railtherm_fdm import kernels as _moved

warnings.warn("railtherm_fastsim.fdm_kernel moved to railtherm_fdm.kernels; the old path is removed in the next release",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = _moved
