"""Hook implementations of the kalker plugin (registration only; the models do the work)."""
from __future__ import annotations

from railtherm import Method, hookimpl

from .normal_model import DEFAULT_CELLS, KalkerNormal
from .tangential_model import KalkerTangential


@hookimpl
def railtherm_register_models():
    """Model ``kalker`` for the normal stage (:class:`KalkerNormal`) and for the tangential stage
    (:class:`KalkerTangential`): one name, one class per stage."""
    return [KalkerNormal, KalkerTangential]


@hookimpl
def railtherm_register_methods():
    """Method ``kalker``: Kalker's exact normal and tangential contact on the half-space, core's
    frictional heat (traction x slip velocity), Ertz & Knothe's Green-function temperatures."""
    return [Method("kalker", {"normal": ("kalker",), "tangential": ("kalker",), "heat_source": ("frictional",),
                              "temperature": ("green",)},
                   description="Kalker's exact rolling contact on the half-space (FFT influence coefficients; "
                               "FFT-preconditioned CG normal, semismooth Newton-GMRES tangential) -> frictional heat "
                               "-> 1-D moving Green-function temperatures",
                   default_cells=DEFAULT_CELLS,
                   orders={
                       # piecewise-constant pressure with a square-root edge: the peak pressure converges at
                       # O(h^2) on the Hertz patch (tests/test_kalker_normal.py fits ~2), the edge location at O(h)
                       "max_pressure": 2.0,
                       # the default second-order rolling difference leaves the contact edge's staircase, first
                       # order in the element size (irregular), in the creep forces and the frictional power (its
                       # numerical dissipation is second order: tests/test_kalker.py)
                       "creep_force_x": 1.0,
                       "frictional_power": 1.0,
                   })]
