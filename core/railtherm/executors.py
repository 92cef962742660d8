"""Moved to :mod:`railtherm.run.executors` (layered core, plugin API 2); this alias is kept for one
release and will be removed in 0.3."""
import sys

from .run import executors as _moved

sys.modules[__name__] = _moved
