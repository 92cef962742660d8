"""Combined elastic constants of two bodies in contact: Kalker's shear modulus and Poisson's ratio, and
the plane-strain contact modulus E* of Hertz theory.

A body whose ``rigid`` attribute is true contributes no compliance.
"""
from __future__ import annotations

import math

__all__ = ["combined_elastic", "contact_modulus"]


def combined_elastic(wheel, rail) -> tuple[float, float]:
    """Combined shear modulus and Poisson's ratio of two bodies (Kalker).

    ``1/G = (1/G1 + 1/G2)/2`` and ``nu = G (nu1/G1 + nu2/G2)/2``; a rigid body contributes no
    compliance. Equal materials give G = G1, nu = nu1.

    Parameters
    ----------
    wheel, rail : Material-like
        Objects with ``shear_modulus`` [Pa], ``poisson_ratio`` [1] and optionally ``rigid`` [bool].

    Returns
    -------
    G : float
        Combined shear modulus [Pa].
    nu : float
        Combined Poisson's ratio [1].

    Raises
    ------
    ValueError
        When both bodies are rigid.

    References
    ----------
    .. [1] J.J. Kalker, Three-dimensional elastic bodies in rolling contact, Kluwer 1990.
       doi:10.1007/978-94-015-7889-9
    """
    comp = 0.0
    nug = 0.0
    for m in (wheel, rail):
        if getattr(m, "rigid", False):
            continue
        comp += 0.5 / m.shear_modulus
        nug += 0.5 * m.poisson_ratio / m.shear_modulus
    if comp == 0.0:
        raise ValueError("both bodies are rigid: no tangential compliance")
    g = 1.0 / comp
    return g, g * nug


def _youngs(body) -> float:
    """Young's modulus of ``body`` [Pa]: its ``youngs_modulus``, else ``2 G (1 + nu)``."""
    e = getattr(body, "youngs_modulus", None)
    if e is None:
        e = 2.0 * body.shear_modulus * (1.0 + body.poisson_ratio)
    return float(e)


def contact_modulus(wheel, rail) -> float:
    """Combined contact modulus E* of two bodies (plane strain).

    ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` with ``E = 2 G (1 + nu)``; a rigid body contributes
    nothing.

    Parameters
    ----------
    wheel, rail : Material-like
        As :func:`combined_elastic`.

    Returns
    -------
    float
        E* [Pa]. ``inf`` when both bodies are rigid.

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, eq. (4.22). doi:10.1017/CBO9781139171731
    """
    compliance = 0.0
    for body in (wheel, rail):
        if getattr(body, "rigid", False):
            continue
        nu = float(body.poisson_ratio)
        compliance += (1.0 - nu * nu) / _youngs(body)
    return math.inf if compliance == 0.0 else 1.0 / compliance
