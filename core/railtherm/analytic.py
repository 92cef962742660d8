"""Moved to :mod:`railtherm.analysis.analytic` (layered core, plugin API 2); this alias is kept for one
release and will be removed in 0.3."""
import sys

from .analysis import analytic as _moved

sys.modules[__name__] = _moved
