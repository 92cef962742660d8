"""Wheelset kinematics of seed section 6.1: creepages and normal forces of both wheel-rail contacts.

A rigid wheelset with conical treads (conicity gamma = tan(delta), delta the cone and contact angle)
rolls at speed V on two rails, shifted laterally by y and yawed by psi, loaded vertically by Q; its
angular velocity is ``Omega = V (1 + theta) / r0`` with a small unknown theta (the seed's theta~).
Wheel 1 is the left wheel (contact at lateral position +e, e = gauge/2, rolling radius r1 = r0 + gamma
y, contact angle +delta), wheel 2 the right one (-e, r2 = r0 - gamma y, -delta). The creepages and the
equilibrium (axle moment -> theta; vertical force and roll moment -> the seed's linear system A N = Q,
eq. 55) are written out in :class:`_Wheelset`; :func:`wheelset_contacts` iterates creep forces (FASTSIM
on each Hertz patch) -> theta -> A -> N until N changes by less than ``rtol``. Each Hertz patch scales
with its normal force (semi-axes as N^(1/3) for curvatures, fixed for given semi-axes).

References: J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, 1990, ch. 1,
doi:10.1007/978-94-015-7889-9. K. Knothe, S. Stichel, Rail Vehicle Dynamics, Springer, 2017, ch. 5,
doi:10.1007/978-3-319-45376-7.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from railtherm.physics import combined_elastic, hertz_pressure_grid, rescale_hertz_patch
from scipy.optimize import brentq

from .simplified_theory import fastsim

__all__ = ["WheelsetSolution", "wheelset_contacts", "wheelset_contact", "PRESSURE_GAUSS", "CHAIN_RTOL"]


@dataclass
class WheelsetSolution:
    """Both contacts of a wheelset (index 0 = left wheel 1, 1 = right wheel 2)."""

    normal_force: np.ndarray      # N_i [N]
    xi: np.ndarray                # [1]
    eta: np.ndarray               # [1]
    phi: np.ndarray               # [1/m]
    creep_force_x: np.ndarray     # [N]
    creep_force_y: np.ndarray     # [N]
    theta: float                  # relative angular-velocity perturbation [1]
    radii: np.ndarray             # rolling radii [m]
    iterations: int
    converged: bool
    residuals: dict = field(default_factory=dict)
    #: the FASTSIM equilibrium a solve with another model's creep forces started from (None: this is it)
    start: "WheelsetSolution | None" = None


#: the equilibrium with a chain's own creep forces (:func:`balance_with`) stops when its relative residuals
#: (vertical, roll, axle moment) are all below this [1]
CHAIN_RTOL = 1e-9

#: Gauss-Legendre points across each cell in y of the wheelset's Hertz pressure grids [1]
#: (railtherm.physics.hertz_pressure_grid; the core default is 8)
PRESSURE_GAUSS = 12


def wheelset_contacts(*, conicity, lateral_shift, yaw_angle, vertical_load, wheel_radius, gauge, speed,
                      friction, shear_modulus, poisson_ratio, ref_normal_force, ref_semi_axes,
                      scaling="curvatures", cells=16, rtol=1e-10, maxiter=100, creep_forces=None,
                      **fastsim_options):
    """Solve the seed's wheelset kinematics (section 6.1) by its fixed-point iteration, with FASTSIM's creep
    forces or, given ``creep_forces``, with another model's (:func:`_balance_with`, from FASTSIM's solution).

    Parameters
    ----------
    conicity : float
        gamma = tan(delta) [1].
    lateral_shift : float
        Lateral displacement y of the wheelset towards wheel 1 [m].
    yaw_angle : float
        psi [rad].
    vertical_load : float
        Q on the wheelset [N].
    wheel_radius : float
        Nominal rolling radius r0 [m].
    gauge : float
        Distance 2e between the contact points [m].
    speed : float
        V [m/s].
    friction : float
        mu [1].
    shear_modulus, poisson_ratio : float
        Combined G [Pa] and nu [1].
    ref_normal_force : float
        Normal force at which ``ref_semi_axes`` hold [N].
    ref_semi_axes : tuple of float
        Hertz semi-axes (a, b) at ``ref_normal_force`` [m].
    scaling : {"curvatures", "semi_axes"}
        How the patch changes with the normal force (:func:`railtherm.physics.rescale_hertz_patch`).
    cells : int
        FASTSIM cells along 2a [1].
    rtol : float
        Convergence tolerance of the normal forces [1].
    creep_forces : callable, optional
        ``creep_forces(i, N, (xi, eta, phi)) -> (Fx, Fy)`` [N]: the creep forces on the wheel of contact i (0:
        wheel 1, 1: wheel 2) under normal force N [N] at the creepages; the equilibrium is then solved with
        these forces to relative residuals below :data:`CHAIN_RTOL` (``solution.start``: FASTSIM's).
    **fastsim_options
        bound, flexibility, leading_edge of :func:`railtherm_fastsim.simplified_theory.fastsim`.

    Returns
    -------
    WheelsetSolution
    """
    w = _Wheelset.build(conicity, lateral_shift, yaw_angle, vertical_load, wheel_radius, gauge,
                        dict(speed=speed, friction=friction, shear_modulus=shear_modulus,
                             poisson_ratio=poisson_ratio, **fastsim_options),
                        ref_normal_force, ref_semi_axes, scaling, cells)
    N = np.full(2, 0.5 * w.Q / math.cos(w.delta))
    theta = 0.0
    converged = False
    it = 0
    for it in range(1, maxiter + 1):
        theta = w.rolling_theta(N)
        fx, fy = w.forces(theta, N)
        N_new = w.normal_forces(fx, fy, N)
        change = float(np.max(np.abs(N_new - N) / np.abs(N_new)))
        N = N_new
        if change < rtol:
            converged = True
            break
    xi, eta, phi = w.creepages(theta)
    fx, fy = w.forces(theta, N)
    sol = WheelsetSolution(N, xi, eta, phi, fx, fy, float(theta), w.radii, it, converged, w.residuals(N, fx, fy))
    return sol if creep_forces is None else _balance_with(w, creep_forces, sol)


def _residual_vector(w, x, forces):
    """Relative residuals (vertical, roll, axle moment) at x = (theta, N_1 / Q, N_2 / Q) with ``forces(theta, N)
    -> (fx, fy)``, and those forces."""
    N = np.asarray(x[1:]) * w.Q
    fx, fy = forces(float(x[0]), N)
    r = w.residuals(N, fx, fy)
    return np.array([r["vertical"], r["roll"], r["axle_moment"]]), fx, fy


def _balance_with(w, creep_forces, start: WheelsetSolution, rtol: float = CHAIN_RTOL, maxiter: int = 40):
    """The equilibrium with ``creep_forces`` (:func:`wheelset_contacts`): Broyden's method on (theta, N_1 / Q,
    N_2 / Q), started at FASTSIM's equilibrium ``start`` with the Jacobian of FASTSIM's residuals there (forward
    differences): another contact model's forces differ from FASTSIM's by some per cent, so the first step is
    close and each costs one solve of both contacts. ``iterations`` counts those solves."""
    def chain(theta, N):
        xi, eta, phi = w.creepages(theta)
        pairs = [creep_forces(i, float(N[i]), (float(xi[i]), float(eta[i]), float(phi[i]))) for i in range(2)]
        return np.array([p[0] for p in pairs], float), np.array([p[1] for p in pairs], float)

    x = np.array([start.theta, *(start.normal_force / w.Q)])
    r_fast = _residual_vector(w, x, w.forces)[0]
    steps = np.array([1e-7, 1e-7, 1e-7])
    J = np.empty((3, 3))
    for k in range(3):
        dx = np.zeros(3)
        dx[k] = steps[k]
        J[:, k] = (_residual_vector(w, x + dx, w.forces)[0] - r_fast) / steps[k]
    r, fx, fy = _residual_vector(w, x, chain)
    it, converged = 1, False
    while it < maxiter:
        if np.max(np.abs(r)) < rtol:
            converged = True
            break
        dx = -np.linalg.solve(J, r)
        x = x + dx
        r_new, fx, fy = _residual_vector(w, x, chain)
        it += 1
        J += np.outer(r_new - r - J @ dx, dx) / float(dx @ dx)
        r = r_new
    else:
        converged = bool(np.max(np.abs(r)) < rtol)
    N = x[1:] * w.Q
    xi, eta, phi = w.creepages(x[0])
    return WheelsetSolution(N, xi, eta, phi, fx, fy, float(x[0]), w.radii, it, converged, w.residuals(N, fx, fy),
                            start=start)


@dataclass(frozen=True)
class _Wheelset:
    """The wheelset's geometry and FASTSIM inputs, built once per :func:`wheelset_contacts` solve, and the
    steps of its fixed-point iteration.

    Creepages of wheel i (rigid slip of the wheel relative to the rail per unit rolling distance, the
    convention of the fastsim model; the seed's eqs. after (54) in their physically consistent form --
    the seed writes the longitudinal creepage of both wheels with the sign of wheel 1):

    * ``xi_i  = 1 - (1 + theta) r_i / r0``               (longitudinal; > 0 when the wheel surface is slower)
    * ``eta_i = -psi / cos(delta_i)``                    (lateral, quasi-static: no lateral velocity)
    * ``phi_i = (1 + theta) sin(delta_i) / r0``          (spin, seed's Phi_i)

    Equilibrium without inertia and without driving torque (seed: "the normal and tangential
    components ... satisfy a system of nonlinear algebraic equations"):

    * axle moment:   ``sum_i Fx_i r_i = 0``                                     -> theta
    * vertical:      ``sum_i (N_i cos(delta_i) + Fy_i sin(delta_i)) = Q``
    * roll moment:   ``sum_i (y_i (N_i cos(delta_i) + Fy_i sin(delta_i)) + r_i (Fy_i cos(delta_i) - N_i sin(delta_i))) = 0``

    With the creep forces written as ``Fy_i = k_i N_i`` (the seed's secant coefficients E_y, from the
    current iterate), the last two equations are the seed's linear system ``A N = Q`` (55). The lateral
    force balance involves the (unknown) suspension force and is not used.
    """

    delta: float                  # contact angle of wheel 1 [rad]
    dl: np.ndarray                # contact angles (+delta, -delta) [rad]
    ys: np.ndarray                # lateral positions (+e, -e) [m]
    e: float                      # half the gauge [m]
    r0: float                     # nominal rolling radius [m]
    radii: np.ndarray             # rolling radii [m]
    Q: float                      # vertical load [N]
    yaw: float                    # psi [rad]
    fastsim_kw: dict              # speed, friction, elastic constants, fastsim options
    ref_normal_force: float
    ref_semi_axes: tuple
    scaling: str
    cells: int

    @classmethod
    def build(cls, conicity, lateral_shift, yaw_angle, vertical_load, wheel_radius, gauge, fastsim_kw,
              ref_normal_force, ref_semi_axes, scaling, cells):
        gam = float(conicity)
        delta = math.atan(gam)
        e = 0.5 * float(gauge)
        r0 = float(wheel_radius)
        return cls(delta, np.array([delta, -delta]), np.array([e, -e]), e, r0,
                   np.array([r0 + gam * lateral_shift, r0 - gam * lateral_shift]), float(vertical_load),
                   float(yaw_angle), fastsim_kw, ref_normal_force, ref_semi_axes, scaling, cells)

    def creepages(self, theta):
        """xi, eta, phi of both wheels at the angular-velocity perturbation theta."""
        xi = 1.0 - (1.0 + theta) * self.radii / self.r0
        eta = -self.yaw / np.cos(self.dl)
        phi = (1.0 + theta) * np.sin(self.dl) / self.r0
        return xi, eta, phi

    def forces(self, theta, Nv):
        """Creep forces (Fx, Fy) [N] of both wheels: FASTSIM on each Hertz patch under the normal forces Nv."""
        xi, eta, phi = self.creepages(theta)
        fx = np.zeros(2)
        fy = np.zeros(2)
        for i in range(2):
            a, b, p0 = rescale_hertz_patch(Nv[i], self.ref_normal_force, *self.ref_semi_axes, self.scaling)
            g, p = hertz_pressure_grid(a, b, p0, 0, self.cells, gauss=PRESSURE_GAUSS)
            r = fastsim(g, p, a=a, b=b, normal_force=Nv[i], xi=xi[i], eta=eta[i], phi=phi[i], **self.fastsim_kw)
            fx[i], fy[i] = r.creep_force_x, r.creep_force_y
        return fx, fy

    def rolling_theta(self, N):
        """theta that balances the axle moment ``sum Fx_i r_i = 0`` under the normal forces N (0 when the
        bracket [-0.05, 0.05] holds no sign change)."""
        def moment(th, Nv=N):
            return float(np.dot(self.forces(th, Nv)[0], self.radii))

        lo, hi = -0.05, 0.05
        m_lo, m_hi = moment(lo), moment(hi)
        return brentq(moment, lo, hi, xtol=1e-15, rtol=1e-12) if m_lo * m_hi < 0 else 0.0

    def normal_forces(self, fx, fy, N):
        """The seed's linear system ``A N = Q`` (55) with the secant coefficients ``k = Fy/N`` of the iterate."""
        k = fy / N
        alpha = np.cos(self.dl) + k * np.sin(self.dl)
        beta = k * np.cos(self.dl) - np.sin(self.dl)
        A = np.array([alpha, self.ys * alpha + self.radii * beta])
        return np.linalg.solve(A, np.array([self.Q, 0.0]))

    def residuals(self, N, fx, fy):
        """Relative residuals of the vertical, roll and axle-moment balances."""
        Q, e, r0, dl, ys, radii = self.Q, self.e, self.r0, self.dl, self.ys, self.radii
        fz = N * np.cos(dl) + fy * np.sin(dl)
        flat = fy * np.cos(dl) - N * np.sin(dl)
        return {"vertical": float(fz.sum() - Q) / Q,
                "roll": float(np.dot(ys, fz) + np.dot(radii, flat)) / (Q * e),
                "axle_moment": float(np.dot(fx, radii)) / (Q * r0)}


def wheelset_contact(wheelset, wheel, rail, speed, friction, ref_normal_force, ref_semi_axes, scaling,
                     contact=None, **fastsim_options):
    """Creepages (xi, eta, phi) and normal force of one of a wheelset's two contacts.

    The reference Hertz patch (``ref_normal_force``, ``ref_semi_axes``) is rescaled to each wheel's
    normal force (:func:`railtherm.physics.rescale_hertz_patch` with ``scaling``). Both contacts come
    from the one equilibrium of :func:`wheelset_contacts`; ``contact`` picks which one is returned.

    Parameters
    ----------
    wheelset : Wheelset
        ``conicity`` [1], ``lateral_shift`` [m], ``yaw_angle`` [rad], ``vertical_load`` [N],
        ``wheel_radius`` [m], ``gauge`` [m] and optionally ``contact`` (seed section 6.1).
    wheel, rail : Material
        ``shear_modulus`` [Pa] and ``poisson_ratio`` [1] (combined for FASTSIM).
    speed : float
        Rolling speed V [m/s].
    friction : float
        Coefficient of friction [1].
    ref_normal_force : float
        Normal force of the reference patch [N].
    ref_semi_axes : (float, float)
        Semi-axes of the reference patch [m].
    scaling : {"curvatures", "semi_axes"}
        How the patch follows the load: ``"semi_axes"`` when the scene gives its semi-axes (fixed).
    contact : {1, 2}, optional
        1: the scene's wheel (wheel 1), 2: the other wheel; default ``wheelset.contact`` (1 when the
        wheelset has no such attribute).
    **fastsim_options
        Passed to :func:`wheelset_contacts`.

    Returns
    -------
    xi, eta, phi, normal_force, solution
        Creepages [1], [1], [1/m] and normal force [N] of contact ``contact``; the whole solution.
    """
    ws = wheelset
    if contact is None:
        contact = getattr(ws, "contact", 1)
    if contact not in (1, 2):
        raise ValueError(f"wheelset contact must be 1 or 2, not {contact!r}")
    i = int(contact) - 1
    G, nu = combined_elastic(wheel, rail)
    sol = wheelset_contacts(conicity=ws.conicity, lateral_shift=ws.lateral_shift, yaw_angle=ws.yaw_angle,
                            vertical_load=ws.vertical_load, wheel_radius=ws.wheel_radius, gauge=ws.gauge,
                            speed=speed, friction=friction, shear_modulus=G, poisson_ratio=nu,
                            ref_normal_force=ref_normal_force, ref_semi_axes=ref_semi_axes, scaling=scaling,
                            **fastsim_options)
    return float(sol.xi[i]), float(sol.eta[i]), float(sol.phi[i]), float(sol.normal_force[i]), sol
