"""Shared constants of the thermal-trace tests (tests/test_*_field.py): a patch half-length a = 5 mm
at Péclet number V a / (2 kappa) = 1000 with core's default material, and the output lists they ask."""
import railtherm

A = 5e-3                                     # [m]
MAT = railtherm.Material()
V = 1000.0 * 2.0 * MAT.diffusivity / A      # [m s-1]: Péclet V a / (2 kappa) = 1000
BULK = MAT.bulk_temperature                  # [degC]
TRACE = ["surface_temperature", "temperature", "peak_temperature", "cooling_rate", "heated_depth", "time_above"]
PLAIN = ["surface_temperature", "temperature", "max_surface_temperature", "mean_contact_temperature"]
