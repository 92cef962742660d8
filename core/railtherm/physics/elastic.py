"""Combined elastic constants of two bodies in contact.

A body whose ``rigid`` attribute is true contributes no compliance. The contact modulus E* of Hertz
theory lives with the exact reference (:func:`railtherm.references.hertz.contact_modulus`) and is
re-exported here.
"""
from __future__ import annotations

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


def contact_modulus(wheel, rail) -> float:
    """Combined plane-strain contact modulus E* [Pa] (``inf`` when both are rigid).

    ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``; see
    :func:`railtherm.references.hertz.contact_modulus`.

    Parameters
    ----------
    wheel, rail : Material-like
        Objects with ``shear_modulus`` [Pa], ``poisson_ratio`` [1] and optionally ``rigid`` [bool].

    Returns
    -------
    float
        E* [Pa].

    References
    ----------
    .. [1] K.L. Johnson, Contact Mechanics, 1985, eq. (4.22). doi:10.1017/CBO9781139171731
    """
    from ..references.hertz import contact_modulus as _contact_modulus
    return _contact_modulus(wheel, rail)
