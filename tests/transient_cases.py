"""Shared constants of the transient section tests (tests/test_fdm_transient.py, tests/test_fem_transient.py):
a Hertzian band of half-width A at speed V and peak flux Q, four passes INTERVAL apart with a slip event that
doubles the flux in the first pass's wake, the depths the history is asked at, the exact references' cheap
quadrature and core's default steel."""
from railtherm.input.materials import Material

A, V, Q = 6e-3, 30.0, 1e8                    # [m], [m s-1], [W m-2]
INTERVAL = 0.083                             # [s]
SLIP = {"time": [0.0, 0.083, 0.0832, 0.0836, 0.0838, 0.2], "factor": [1.0, 1.0, 2.0, 2.0, 1.0, 1.0]}
DEPTHS = [1e-4, 5e-4]                        # [m]
CHEAP = dict(quad_points=8, inner_points=24)    # the references at ~1e-5 of their maximum
STEEL = Material()
