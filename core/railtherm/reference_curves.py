"""Moved to :mod:`railtherm.analysis.reference_curves` (layered core, plugin API 2); this alias is kept for one
release and will be removed in 0.3."""
import sys

from .analysis import reference_curves as _moved

sys.modules[__name__] = _moved
