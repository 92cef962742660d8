"""The contact temperature a temperature law reads, and mu per cell of a patch.

The contact temperature of a cell is the mean of the wheel's and the rail's surface temperature there
[degC]: equal to both in perfect thermal contact, and the value CONTACT's temperature-dependent friction
uses ([Vollebregt2022]_). Core's coupled loop (:mod:`railtherm.solving.friction_loop`) and the FEM's
Steps 1-4 loop both take it from :func:`contact_temperature`; :func:`field_contact_temperature` and
:func:`patch_contact_temperature` only select the surface temperatures it is taken of.

References
----------
.. [Vollebregt2022] E.A.H. Vollebregt, "User guide for CONTACT, Rolling and sliding contact with
   friction", Technical report TR09-03, version 22.1, VORtech (2022), sections on friction laws.
"""
from __future__ import annotations

import numpy as np

from ...contract.grid import behind_cells

__all__ = ["contact_temperature", "field_contact_temperature", "patch_contact_temperature", "local_friction"]


def contact_temperature(wheel_surface, rail_surface):
    """The contact temperature [degC]: the mean of the two bodies' surface temperatures.

    Parameters
    ----------
    wheel_surface, rail_surface : float or ndarray
        Surface temperature of the wheel and of the rail at the same points [degC] (broadcast).

    Returns
    -------
    float or ndarray
        0.5 (wheel_surface + rail_surface) [degC].
    """
    return 0.5 * (np.asarray(wheel_surface, dtype=float) + np.asarray(rail_surface, dtype=float))


def field_contact_temperature(temperature, patch) -> np.ndarray:
    """The contact temperature of each cell of ``patch`` from a temperature result [degC]: that of its wheel
    and rail surface temperatures, on the patch's cells of an extended field grid (``field.behind``).

    Parameters
    ----------
    temperature : TemperatureField
        Its ``surface_temperature`` (wheel, rail) [degC] on its ``grid``.
    patch : ContactPatch
        The patch whose cells are wanted.
    """
    surf = np.asarray(temperature.surface_temperature, dtype=float)
    if temperature.grid is not None and temperature.grid.shape != patch.grid.shape:
        surf = surf[:, behind_cells(patch.grid, temperature.grid):]
    return contact_temperature(surf[0], surf[1])


def patch_contact_temperature(patch, wheel_bulk: float, rail_bulk: float):
    """The contact temperature a temperature law sees on ``patch`` [degC]: the patch's
    ``contact_temperature`` (core's coupled loop puts it there), else that of the two bulk temperatures.

    Parameters
    ----------
    patch : ContactPatch
    wheel_bulk, rail_bulk : float
        Bulk temperatures of wheel and rail [degC].
    """
    t = getattr(patch, "contact_temperature", None)
    if t is not None:
        return np.asarray(t, dtype=float)
    return float(contact_temperature(float(wheel_bulk), float(rail_bulk)))


def local_friction(law, patch, wheel_bulk: float, rail_bulk: float, slip_speed=0.0) -> np.ndarray:
    """The coefficient of friction of every cell of ``patch`` [1], shape ``patch.grid.shape``: the law's mu
    at the local slip speed and at the contact temperature of :func:`patch_contact_temperature`.

    Parameters
    ----------
    law : railtherm.physics.friction.FrictionLaw
        The scene's friction law.
    patch : ContactPatch
        The patch (its grid, and ``contact_temperature`` [degC] when core's coupled loop put one there).
    wheel_bulk, rail_bulk : float
        Bulk temperatures of wheel and rail [degC] (the contact temperature when the patch has none).
    slip_speed : float or ndarray
        Local slip speed |v_slip| [m/s] (broadcast to the grid).
    """
    t = patch_contact_temperature(patch, wheel_bulk, rail_bulk)
    mu = law.mu(np.asarray(slip_speed, dtype=float), t)
    return np.broadcast_to(np.asarray(mu, dtype=float), patch.grid.shape).copy()
