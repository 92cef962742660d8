"""Speeds of the two bodies' surfaces through the contact patch."""
from __future__ import annotations

__all__ = ["body_speeds", "creep_speeds"]


def body_speeds(speed: float, sliding_speed: float | None, tangential: str) -> tuple[float, float]:
    """Speeds at which wheel and rail material passes through the patch.

    Full sliding: the wheel surface moves at ``v_w = V + v_s`` and the rail at ``v_r = V`` (seed
    eqs. 32-33). A given heat source, and a creepage scene, move both bodies at the rolling speed V
    (the creepage's ``V xi`` is of the order of the creepage, 1e-3, and is left out here; the FASTSIM
    heat source reports its own ``V (1 - xi)``).

    Parameters
    ----------
    speed : float
        Rolling speed V [m/s].
    sliding_speed : float or None
        Sliding speed v_s [m/s] of full sliding (None counts as 0).
    tangential : str
        The scene's tangential kind: ``"full-sliding"``, ``"creepage"`` or ``"given"`` (a given heat
        source); only full sliding moves the wheel at V + v_s.

    Returns
    -------
    wheel, rail : float
        Surface speeds relative to the contact [m/s].

    References
    ----------
    .. [1] M. Ertz, K. Knothe, A comparison of analytical and numerical methods for the calculation
       of temperatures in wheel/rail contact, Wear 253 (2002) 498-508.
    """
    v0 = float(speed)
    if tangential == "full-sliding":
        return v0 + float(sliding_speed or 0.0), v0
    return v0, v0


def creep_speeds(speed: float, xi: float) -> tuple[float, float]:
    """Surface speeds of wheel and rail relative to the contact for a longitudinal creepage ``xi``.

    With the creepage defined as the rigid slip of the wheel relative to the rail per unit rolling
    distance (Kalker's convention, positive when the wheel surface is slower), the wheel surface moves
    at ``V (1 - xi)`` and the rail at ``V``. Full sliding at v_s is ``xi = -v_s / V``, which gives
    :func:`body_speeds`' ``V + v_s``.

    Parameters
    ----------
    speed : float
        Rolling speed V [m/s].
    xi : float
        Longitudinal creepage [1].

    Returns
    -------
    wheel, rail : float
        Surface speeds relative to the contact [m/s].
    """
    v0 = float(speed)
    return v0 * (1.0 - float(xi)), v0
