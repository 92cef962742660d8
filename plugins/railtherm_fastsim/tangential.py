"""Tangential model "fastsim": Kalker's FASTSIM on the normal stage's patch (seed section 6.2).

The model fills the tangential fields of the patch (tractions, slip velocity, stick/slip, creep forces,
spin moment), the surface speeds V (1 - xi) and V, and the local dissipation -p . s per cell, which
core's heat source ``frictional`` turns into the heat flux. It never changes the normal stage's
geometry or pressure: Kalker's parabolic bound (option ``bound = "parabolic"``) bounds the tractions by
mu p_par, but the reported pressure stays the normal model's. Creepages: the patch's own (the wheelset
kinematics of seed section 6.1, :class:`railtherm_fastsim.wheelset_normal.WheelsetNormal`), else
``scene.creepage``, else full sliding (``scene.sliding_speed`` v_s as xi = -v_s/V: the wheel surface
moves at V + v_s, seed eqs. 32-33). Friction laws apply cell by cell: a temperature law's mu at the
patch's contact temperature (core's coupled loop puts it there), a slip-velocity law solved in the
sweep (:func:`friction_of`).

References: J.J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
Dynamics 11 (1982) 1-13. doi:10.1080/00423118208968684
"""
from __future__ import annotations

from railtherm import Capabilities, Option, Refused, TangentialContactModel
from railtherm.physics import combined_elastic, creep_speeds
from railtherm.physics.friction import LAW_KINDS, SlipVelocityFriction, local_friction

from .fastsim_line import fastsim_line
from .simplified_theory import BOUNDS, FLEXIBILITIES, LEADING_EDGES, fastsim

__all__ = ["FastsimTangential", "FASTSIM_OPTIONS", "ONE_SWEEP", "scene_creepages"]

#: verdict keys of one FASTSIM sweep (docs/verdicts.md): a marching of the strips from their leading
#: edges, exact for the simplified theory's discretisation -- nothing is iterated
ONE_SWEEP = {"converged": True, "iterations": 0, "residual": 0.0}

#: FASTSIM's options (also declared by the wheelset normal model, which runs FASTSIM in its iteration)
FASTSIM_OPTIONS = {
    "bound": Option("elliptic", "traction bound: 'elliptic' (Hertz pressure, CONTACT's advice) or "
                                "'parabolic' (Kalker's FASTSIM: mu times the parabola of the same load)", choices=BOUNDS),
    "flexibility": Option("three", "'three' (L1, L2, L3 from Kalker's coefficients), 'one' (Kalker's "
                                   "weighted single flexibility) or 'contact' (CONTACT's blend)",
                          choices=FLEXIBILITIES),
    "leading_edge": Option("exact", "'exact' (integrate from the true leading edge) or 'contact' "
                                    "(CONTACT's cell discretisation)", choices=LEADING_EDGES),
}


def scene_creepages(patch, creepage, sliding_speed, speed, *, scene_name=None) -> tuple[float, float, float]:
    """(xi [1], eta [1], phi [1/m]) for FASTSIM: the patch's (wheelset kinematics), the scene's
    creepage, or full sliding xi = -v_s / V.

    Parameters
    ----------
    patch : ContactPatch
        The normal stage's patch (its ``creepage``, when the normal model solved a wheelset).
    creepage : Creepage or None
        The scene's creepages (``longitudinal`` [1], ``lateral`` [1], ``spin`` [1/m]).
    sliding_speed : float or None
        The scene's sliding speed v_s [m/s].
    speed : float
        Rolling speed V [m/s].
    scene_name : str, optional
        For messages.
    """
    if patch.creepage is not None:
        return tuple(float(c) for c in patch.creepage)
    if creepage is not None:
        c = creepage
        return float(c.longitudinal), float(c.lateral), float(c.spin)
    if sliding_speed is not None:
        return -float(sliding_speed) / float(speed), 0.0, 0.0
    raise Refused(f"scene {scene_name!r}: no creepage or sliding speed for FASTSIM, and the normal model did not "
                  "solve a wheelset's kinematics (method chains list 'wheelset' before 'hertz' for that)")


class FastsimTangential(TangentialContactModel):
    """Kalker's FASTSIM on the patch: tractions, slip, stick/slip, creep forces, spin moment and the
    local frictional power density -p.s (:func:`railtherm_fastsim.simplified_theory.fastsim`).

    Line contacts (longitudinal creepage or full sliding only): one strip with Carter's
    flexibility (:func:`railtherm_fastsim.fastsim_line.fastsim_line`); forces and powers per unit width.
    """

    name = "fastsim"
    description = ("Kalker's FASTSIM (simplified theory, elliptic or parabolic bound): tractions, slip, "
                   "creep forces and the local frictional power density -p.s (seed 6.2)")
    needs_elastic_body = True
    capabilities = Capabilities(
        contacts=frozenset({"ellipse", "line"}), sources=frozenset({"computed"}),
        tangential=frozenset({"creepage", "full-sliding"}),
        provides=frozenset({"traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "stick",
                            "creep_force_x", "creep_force_y", "spin_moment"}),
        friction_laws=LAW_KINDS)
    options = FASTSIM_OPTIONS

    def supports(self, scene, level):
        why = super().supports(scene, level)
        if why:
            return why
        if scene.contact_shape == "line":  # lateral creepage of a line contact: refused by core
            if scene.creepage is None and scene.sliding_speed is None:
                return ("model 'fastsim': the wheelset kinematics (seed 6.1) needs an elliptical contact; a line "
                        "contact needs a creepage or a sliding speed")
        return None

    def compute_tangential(self, scene, patch, level, options):
        xi, eta, phi = scene_creepages(patch, scene.creepage, scene.sliding_speed, scene.speed,
                                       scene_name=scene.name)
        try:
            G, nu = combined_elastic(scene.wheel, scene.rail)
        except ValueError as exc:
            raise Refused(f"model 'fastsim': {exc}") from exc
        V = float(scene.speed)
        friction, slip_law = friction_of(scene.friction, patch, scene.wheel.bulk_temperature,
                                         scene.rail.bulk_temperature)
        common = dict(normal_force=patch.normal_force, friction=friction, shear_modulus=G, poisson_ratio=nu, xi=xi,
                      speed=V, bound=options["bound"], leading_edge=options["leading_edge"], slip_law=slip_law)
        if patch.b is None:
            if eta != 0.0 or phi != 0.0:
                raise Refused(f"model 'fastsim': a line contact has only longitudinal creepage (lateral = {eta:g}, "
                              f"spin = {phi:g} 1/m given); use an elliptical contact")
            res = fastsim_line(patch.grid, patch.pressure, a=patch.a, **common)
        else:
            res = fastsim(patch.grid, patch.pressure, a=patch.a, b=patch.b, eta=eta, phi=phi,
                          flexibility=options["flexibility"], **common)
        diag = {**res.diagnostics, "combined_shear_modulus": G, "combined_poisson_ratio": nu, **ONE_SWEEP}
        fields = dict(traction_x=res.traction_x, slip_velocity_x=res.slip_velocity_x, stick=res.stick,
                      creep_force_x=res.creep_force_x)
        if patch.b is not None:
            fields.update(traction_y=res.traction_y, slip_velocity_y=res.slip_velocity_y,
                          creep_force_y=res.creep_force_y, spin_moment=res.spin_moment)
        return patch.with_tangential(**fields, body_speed=creep_speeds(V, xi), dissipation=res.power_density,
                                     diagnostics=diag)


def friction_of(law, patch, wheel_bulk, rail_bulk):
    """(friction, slip_law) for :func:`~railtherm_fastsim.simplified_theory.fastsim`: the constant mu (a float),
    mu per cell of a temperature law at the patch's contact temperature, or the
    nominal mu and the slip-velocity law solved in the sweep.

    Parameters
    ----------
    law : railtherm.physics.friction.FrictionLaw
        The scene's friction law (its ``nominal`` [1] is the one coefficient of the constant and slip laws).
    patch : ContactPatch
        The normal stage's patch (its grid, and ``contact_temperature`` [degC] when core's coupled loop
        put one there).
    wheel_bulk, rail_bulk : float
        Bulk temperatures of wheel and rail [degC] (the contact temperature when the patch has none).

    An exponential slip-velocity law (or Polach's) makes the bound of a slipping cell mu(v) p with v its
    own slip speed, v = V |L (q - h)| / dx, solved per cell in the sweep
    (:func:`railtherm_fastsim.fastsim_kernel.slip_law_bound`). A cell that cannot stick (|h| > mu(0) p)
    has exactly one root (the local equation is concave). A cell that can stick (|h| <= mu(0) p) sticks:
    static friction holds until it is exceeded. That is the solution of largest traction and least slip,
    the one kalker's monotone iteration from mu(0) converges to; where the law falls steeply (kappa =
    |dmu/dv| p V L / dx > 1, :func:`~railtherm.physics.friction.contraction_limit`; FASTSIM's kappa grows
    as 1/dx) such a cell would also have two slip roots, and the diagnostics count those cells
    (``friction_nonunique_cells``, their largest kappa ``friction_nonunique_kappa``) instead of refusing.
    """
    if law.kind == "constant":
        return float(law.nominal), None
    if law.depends_on_slip:
        if not isinstance(law, SlipVelocityFriction):
            raise Refused(f"model 'fastsim': friction law {law.kind!r} ({law.describe()}) is not an exponential "
                          "slip-velocity law, the form FASTSIM's sweep solves cell by cell")
        return float(law.nominal), law
    return local_friction(law, patch, wheel_bulk, rail_bulk), None
