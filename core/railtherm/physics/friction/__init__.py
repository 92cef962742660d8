"""Friction, in one place: the laws and their parameters (:mod:`.laws`, :mod:`.parameters`), the contact
temperature a temperature law reads and mu per patch cell (:mod:`.contact_temperature`), the slip-velocity
iteration (:mod:`.slip_iteration`), the coupled temperature-friction loop (:mod:`.temperature_loop`) and the
tolerances every friction iteration stops at (:mod:`.tolerances`).

The scene validator reads the laws' parameters from here; core's chains
(:mod:`railtherm.solving.friction_loop`), ``kalker``, FASTSIM and the FEM evaluate the laws and run the
iterations from here.
"""
from __future__ import annotations

from .contact_temperature import (contact_temperature, field_contact_temperature, local_friction,
                                  patch_contact_temperature)
from .laws import (LAW_KINDS, LAWS, ConstantFriction, FrictionLaw, PolachFriction, SlipVelocityFriction,
                   TemperatureFriction, friction_law)
from .parameters import Parameter
from .slip_iteration import contraction_limit, iterate_slip_law
from .temperature_loop import LoopHistory, LoopStep, iterate_temperature_law
from .tolerances import (LOOP_FORCE_TOLERANCE, LOOP_MAX_ITERATIONS, LOOP_MU_TOLERANCE, SLIP_MAX_STEPS,
                         SLIP_MU_TOLERANCE)

__all__ = ["FrictionLaw", "ConstantFriction", "SlipVelocityFriction", "PolachFriction", "TemperatureFriction",
           "LAWS", "LAW_KINDS", "Parameter", "friction_law", "contact_temperature", "field_contact_temperature",
           "patch_contact_temperature",
           "local_friction", "contraction_limit", "iterate_slip_law", "LoopStep", "LoopHistory",
           "iterate_temperature_law", "LOOP_MU_TOLERANCE", "LOOP_FORCE_TOLERANCE",
           "LOOP_MAX_ITERATIONS", "SLIP_MU_TOLERANCE", "SLIP_MAX_STEPS"]
