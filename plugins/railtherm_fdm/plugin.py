"""Hook implementations of the "fdm" plugin (registration only; the work is in :mod:`.model`).

The plugin registers the temperature model ``fdm`` and no method of its own: method ``fastsim-fdm``
(plugin ``fastsim``) names the model, and the plugin host resolves the name across plugins.
"""
from __future__ import annotations

from railtherm import hookimpl

from .model import FDMTemperature


@hookimpl
def railtherm_register_models():
    """The temperature model ``fdm`` (3-D block for an ellipse, 2-D for a line contact)."""
    return [FDMTemperature]
