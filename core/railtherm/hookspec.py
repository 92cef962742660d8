"""Moved to :mod:`railtherm.contract.hookspec` (layered core, plugin API 2); this alias is kept for one
release and will be removed in 0.3."""
import sys

from .contract import hookspec as _moved

sys.modules[__name__] = _moved
