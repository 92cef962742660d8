"""Moved to :mod:`railtherm.input.scene` (layered core, plugin API 2); this alias is kept for one
release and will be removed in 0.3."""
import sys

from .input import scene as _moved

sys.modules[__name__] = _moved
