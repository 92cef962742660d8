"""railtherm's own plugin: the core stage models, registered like any other plugin."""
from __future__ import annotations

from ..hookspec import hookimpl


@hookimpl
def railtherm_register_models():
    from .hertz import HertzContact
    from .sliding import FullSlidingHeat, GivenHeat
    return [HertzContact, FullSlidingHeat, GivenHeat]


@hookimpl
def railtherm_register_methods():
    return []
