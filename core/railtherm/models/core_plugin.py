"""railtherm's own plugin: the core stage models, registered like any other plugin."""
from __future__ import annotations

from ..contract.hookspec import hookimpl
from .hertz import HertzContact
from .sliding import FrictionalHeat, FullSlidingTangential, GivenHeat
from .wheelset_profile import WheelsetProfileHertz


@hookimpl
def railtherm_register_models():
    return [HertzContact, WheelsetProfileHertz, FullSlidingTangential, FrictionalHeat, GivenHeat]


@hookimpl
def railtherm_register_methods():
    return []
