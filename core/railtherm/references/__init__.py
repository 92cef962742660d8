"""Exact and published reference solutions (pure numpy/scipy functions).

Submodules: ``hertz`` (Hertz normal contact: elliptical and line contact, contact modulus, pressure);
``kalker`` (Kalker's creepage coefficients, table E.3, linear creep law, FASTSIM flexibilities);
``carter`` (Carter's 2-D rolling contact with creepage: stick/slip, traction profile); ``flash`` (1-D
high-Péclet flash temperature of a band source: closed forms, erfc depth profile); ``jaeger`` (Jaeger's
moving band heat source on a half-plane at any Péclet number); ``moving_source`` (moving elliptical
surface heat source on a half-space at any Péclet number); ``transient_pass`` (one pass of a moving
band/ellipse source over a fixed material point: exact fixed-frame integrals); ``transient`` (histories
under repeated passes with a heat-input schedule: superposition, pass peaks, residuals).

Import the submodule you need, e.g. ``from railtherm.references.hertz import hertz_from_curvatures``;
submodules are loaded lazily on attribute access (``railtherm.references.hertz``).
"""
from __future__ import annotations

import importlib

_SUBMODULES = ("hertz", "kalker", "carter", "flash", "jaeger", "moving_source", "transient_pass", "transient")
__all__ = list(_SUBMODULES)


def __getattr__(name):
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'railtherm.references' has no attribute {name!r}")
