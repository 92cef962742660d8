"""A wheelset scene's normal forces for another vertical force of the estimate, and the scene's patch with them:
what the solve's balance of the wheel's vertical force with a chain's own creep forces moves
(:mod:`railtherm.solving.wheelset_vertical`).

A scene on profiles is loaded with its normal forces from the wheel's vertical force Fz and Kalker's linear
theory's lateral creep force, saturated (Shen-Hedrick-Elkins [1]): N cos(delta) - Fy sin(delta) = Fz, one patch
(:func:`railtherm.input.wheelset_profile.normal_force_from_vertical`) or every patch at one common approach
(:func:`railtherm.input.wheelset_profile.share_vertical_force`). :func:`estimated_normal_forces` gives the same
normal forces for any vertical force ``u`` in place of Fz; a chain whose own Fy differs from the estimate meets
Fz at the ``u`` whose normal forces its own forces balance.

References
----------
.. [1] Z. Y. Shen, J. K. Hedrick, J. A. Elkins, Vehicle System Dynamics 12 (1983) 79-83. doi:10.1080/00423118308968725
"""
from __future__ import annotations

import dataclasses
import math

from ..physics.elastic import combined_elastic, contact_modulus
from ..references.hertz import hertz_from_curvatures
from .wheelset_profile import ProfileContacts, _saturated_lateral, normal_force_from_vertical, share_vertical_force

__all__ = ["estimated_normal_forces", "with_normal_forces", "patch_contacts"]


def patch_contacts(pc) -> tuple:
    """The patches (:class:`railtherm.input.wheelset_profile.ProfileContact`) of a scene's ``profile_contact``:
    every loaded one of a scene of every patch, else the scene's one."""
    return tuple(pc.contacts) if isinstance(pc, ProfileContacts) else (pc,)


def estimated_normal_forces(pc, vertical_force: float, wheel, rail, friction: float | None):
    """The normal forces the scene's estimate gives its patches when the wheel carries ``vertical_force``.

    Parameters
    ----------
    pc : ProfileContact or ProfileContacts
        The scene's patch or patches, as loaded (contact angles, curvatures, creepages and separations).
    vertical_force : float
        The vertical force [N] in place of the scene's, > 0.
    wheel, rail : Material
        The bodies (Hertz-equivalent ellipse and creep-force estimate).
    friction : float or None
        Nominal coefficient of friction [1] (None: no lateral force, N = Fz / cos(delta)).

    Returns
    -------
    (approach, normal_forces, lateral_forces) : float or None, list of float, list of float
        The patches' common vertical approach [m] (None for a scene of one patch), each patch's normal force [N]
        and the estimated lateral creep force [N] on the wheel it balances with; at the scene's own vertical
        force they are the loaded ones.
    """
    e_star = contact_modulus(wheel, rail)
    G, nu = combined_elastic(wheel, rail)
    if not isinstance(pc, ProfileContacts):
        if friction is None:
            return None, [vertical_force / math.cos(pc.contact_angle)], [0.0]
        normal, fy = normal_force_from_vertical(vertical_force, pc.contact_angle, pc.hertz_curvatures, e_star, G, nu,
                                                pc.creepage, friction)
        return None, [normal], [fy]
    contacts = pc.contacts

    def lateral(i, n):
        if friction is None:
            return 0.0
        h = hertz_from_curvatures(*contacts[i].hertz_curvatures, n, e_star)
        return _saturated_lateral(h.a, h.b, G, nu, contacts[i].creepage, friction, n)

    return share_vertical_force(float(vertical_force), [c.separation for c in contacts],
                                [c.contact_angle for c in contacts], [c.hertz_curvatures for c in contacts], e_star,
                                lateral)


def with_normal_forces(pc, normal_forces, approach: float | None, balance: str):
    """``pc`` with each patch's normal force [N] replaced (and a scene of every patch's common ``approach`` [m]),
    its ``vertical_balance`` set to ``balance`` (the patches of a scene of every patch keep theirs, a share)."""
    if isinstance(pc, ProfileContacts):
        contacts = tuple(dataclasses.replace(c, normal_force=float(n)) for c, n in zip(pc.contacts, normal_forces))
        return dataclasses.replace(pc, contacts=contacts, approach=float(approach), vertical_balance=balance)
    (normal,) = normal_forces
    return dataclasses.replace(pc, normal_force=float(normal), vertical_balance=balance)
