"""Heat balance of the finite-difference block (3-D and 2-D; transient and steady schemes).

Every run reports where the heat put in went (docs/verdicts.md): ``heat_balance_error`` = (heat
carried by the field - heat put in) / heat put in, with the heat carried = stored + lost through the
fixed faces + convected (transient schemes, :class:`EnergyLedger`) or carried out of the outflow
face + lost through the fixed faces + convected (steady scheme, :func:`steady_heat_balance`).
Energies are in [J] for the 3-D block and [J/m] per unit width for the 2-D block (powers [W], [W/m]).
"""
from __future__ import annotations

import numpy as np

__all__ = ["EnergyLedger", "steady_heat_balance", "quasi_steady_change"]


class EnergyLedger:
    """Energy put into and lost from a transient block, step by step.

    The fixed faces are the far faces x = 0 and x = L_x (nodes 0 and nx-1, reached from nodes 1 and
    nx-2) and the bottom (reached from the nodes one above it); the loss through them in one step
    is ``dt lambda / d`` x (face areas x rises of the neighbouring nodes).

    Parameters
    ----------
    dt : float
        Time step [s].
    conductivity : float
        lambda [W/(m K)].
    d : float
        Node spacing [m].
    x_face_area : ndarray (nz,) or (ny, nz)
        Areas of the nodes' faces normal to x [m^2] ([m] in 2-D).
    bottom_area : float or ndarray (ny,)
        Areas of the bottom faces [m^2] ([m] in 2-D); a float when they are all alike (the sum is
        then scaled once).
    capacity : float or ndarray (ny,)
        Heat capacity of a surface node per unit rise [J/K] ([J/(K m)]).

    Attributes
    ----------
    energy_in, fixed_faces, convection : float
        Running sums [J] ([J/m]).
    """

    def __init__(self, dt, conductivity, d, x_face_area, bottom_area, capacity):
        self.g = dt * conductivity / d
        self.x_face_area, self.bottom_area, self.capacity = x_face_area, bottom_area, capacity
        self.energy_in = 0.0
        self.fixed_faces = 0.0
        self.convection = 0.0

    def fixed_face_loss(self, T) -> float:
        """Heat lost in one step through the fixed faces from the rises ``T`` [J] ([J/m])."""
        bottom = T[1:-1, ..., -2]
        if np.ndim(self.bottom_area):
            b = float((self.bottom_area * bottom).sum())
        else:
            b = self.bottom_area * float(bottom.sum())
        return self.g * (float((self.x_face_area * T[1]).sum()) + float((self.x_face_area * T[-2]).sum()) + b)

    def convective_loss(self, T, hloss) -> float:
        """Heat convected in one step from the surface rises of ``T`` with loss factors ``hloss`` [J]."""
        return float((hloss[1:-1] * self.capacity * T[1:-1, ..., 0]).sum())

    def summary(self, stored: float) -> dict:
        """Diagnostics: ``energy_in``, ``energy_stored``, ``energy_lost_fixed_faces``,
        ``energy_lost_convection`` and ``heat_balance_error`` (stored + lost - in) / in [1]."""
        e_in = self.energy_in
        lost = self.fixed_faces + self.convection
        return {"energy_in": e_in, "energy_stored": stored, "energy_lost_fixed_faces": self.fixed_faces,
                "energy_lost_convection": self.convection,
                "heat_balance_error": (stored + lost - e_in) / e_in if e_in > 0 else 0.0}


def steady_heat_balance(Q, flow, T, inflow, bottom, hA) -> dict:
    """Heat balance of a steady moving-frame solution (exact for the discrete equations).

    Parameters
    ----------
    Q : ndarray
        Heat into each top cell [W] ([W/m]).
    flow : ndarray
        Advective capacity flow rho c V A_x through the outflow face (x min) [W/K] ([W/(m K)]).
    T : ndarray (nx, [ny,] nz)
        Cell rises [K].
    inflow : ndarray
        Conductance of the inflow face (x max, theta = 0 beyond it) per cell [W/K].
    bottom : ndarray
        Conductance to the fixed bottom per column [W/K].
    hA : ndarray
        Convective conductance of each top cell [W/K].

    Returns
    -------
    dict
        ``energy_in``, ``energy_out_advected``, ``energy_lost_fixed_faces``, ``energy_lost_convection``
        [W] and ``heat_balance_error`` (heat carried out - heat put in) / heat put in [1].
    """
    e_in = float(Q.sum())
    out_adv = float((flow * T[0]).sum())
    out_inflow = float((inflow * T[-1]).sum())
    out_bottom = float((bottom * T[..., -1]).sum())
    out_conv = float((hA * T[..., 0]).sum())
    balance = (out_adv + out_inflow + out_bottom + out_conv - e_in) / e_in if e_in > 0 else 0.0
    return {"energy_in": e_in, "energy_out_advected": out_adv, "energy_lost_fixed_faces": out_inflow + out_bottom,
            "energy_lost_convection": out_conv, "heat_balance_error": balance}


def quasi_steady_change(surface, earlier) -> float:
    """Largest change of the patch-frame surface field against the same field sampled earlier,
    relative to its maximum [1] (0 when there is no earlier sample)."""
    smax = float(np.max(np.abs(surface))) or 1.0
    return float(np.max(np.abs(surface - (surface if earlier is None else earlier)))) / smax
