"""Signorini contact with (regularised) Coulomb friction on the condensed contact window.

Unknowns at the m window nodes: pressure p_i >= 0 [Pa] and the tangential traction on the wheel tau_i
[Pa] (plus the approach delta [m] when the normal force is prescribed). The condensed strip (and wheel)
give the total sink W (positive opens the gap) and the relative tangential displacement U = u_x(wheel)
- u_x(rail): ``W = A_nn p + A_nt tau + W0``, ``U = A_tn p + A_tt tau + U0``; gap ``g = h0(x) - delta +
W`` with the undeformed wheel profile h0 = R - sqrt(R^2 - x^2), and the dimensionless slip of the wheel
relative to the rail ``s_hat = xi - dU/dx`` (slip velocity s = V s_hat [m/s]; dU/dx by second-order
upstream differences, :func:`upstream_derivative`). The Alart-Curnier contact law and its epsilon
regularisation, solved by semismooth Newton, are written out in :func:`solve_contact`.

References: P. Alart, A. Curnier, CMAME 92 (1991) 353-375, doi:10.1016/0045-7825(91)90022-X.
S. Hueeber, G. Stadler, B. Wohlmuth, SIAM J. Sci. Comput. 30 (2008) 572-596, doi:10.1137/060671061.
J.J. Kalker, Three-dimensional elastic bodies in rolling contact, Kluwer, 1990,
doi:10.1007/978-94-015-7889-9.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["ContactSolution", "solve_contact", "upstream_derivative"]


def upstream_derivative(m: int, h: float, order: int = 2) -> np.ndarray:
    """Matrix D with (D U)_i ~ dU/dx at node i from node i and its upstream neighbours i+1, i+2.

    Parameters
    ----------
    m : int
        Number of uniformly spaced nodes.
    h : float
        Node spacing [m].
    order : {1, 2}
        Order of the one-sided difference.
    """
    D = np.zeros((m, m))
    for i in range(m):
        if order == 2 and i + 2 < m:
            D[i, i:i + 3] = np.array([-3.0, 4.0, -1.0]) / (2.0 * h)
        elif i + 1 < m:
            D[i, i:i + 2] = np.array([-1.0, 1.0]) / h
        else:
            D[i, i - 1:i + 1] = np.array([-1.0, 1.0]) / h
    return D


@dataclass
class ContactSolution:
    """Nodal solution of the contact problem on the window.

    Attributes
    ----------
    x : ndarray
        Window node coordinates [m].
    pressure, traction : ndarray
        Normal pressure and tangential traction on the wheel [Pa].
    slip : ndarray
        Dimensionless slip s_hat of the wheel relative to the rail (slip velocity / V) [1].
    gap : ndarray
        Deformed gap [m].
    stick : ndarray of bool
        True where p > 0 and |tau| < mu p.
    approach : float
        delta [m].
    normal_force, tangential_force : float
        sum w p, sum w tau [N/m].
    iterations : int
    residual : float
        Final residual (max norm) relative to the mean pressure [1].
    converged : bool
    """

    x: np.ndarray
    pressure: np.ndarray
    traction: np.ndarray
    slip: np.ndarray
    gap: np.ndarray
    stick: np.ndarray
    approach: float
    normal_force: float
    tangential_force: float
    iterations: int
    residual: float
    converged: bool
    history: list = field(default_factory=list)


def solve_contact(x, weights, h0, A_nn, A_nt, A_tn, A_tt, *, friction=0.0, creepage=None,
                  regularization=0.0, normal_force=None, penetration=None, W0=None, U0=None,
                  derivative=None, initial=None, tol=1e-10, maxit=100) -> ContactSolution:
    """Solve the condensed frictional contact problem by semismooth Newton.

    Contact law, written as a semismooth system (Alart-Curnier complementarity functions):

    * Signorini: ``p - max(0, p - c_n g) = 0`` (exact: g >= 0, p >= 0, p g = 0).
    * Friction, regularised with epsilon as in the seed (section 4.2, eps = 1e-3):
      ``tau - proj_[-mu p, mu p](tau - c_t (mu p s_hat + eps tau)) = 0``.
      In stick this is ``s_hat = -eps tau / (mu p)`` (an elastic micro-slip of relative size eps); in slip
      ``tau = -mu p sign(s_hat)`` with |s_hat| >= eps. This is the piecewise-linear form of the seed's
      regularisation tau = -mu p s/sqrt(s^2 + eps^2): same limits, same slope mu p / eps at s = 0, and it
      tends to exact Coulomb friction as eps -> 0 (eps = 0 is allowed: exact Coulomb, the model's default;
      eps must be small against |xi|, else the stick zone creeps and Fx -> mu N |xi| / eps). Written this
      way the Newton iteration does not degrade as eps -> 0 (the seed's smooth form has a Jacobian of
      size 1/eps). The semismooth Newton method on the dense system is in effect a primal-dual
      active-set method, with a backtracking line search on the residual norm; the c_n, c_t constants
      only affect the path, not the solution.

    Parameters
    ----------
    x : ndarray, shape (m,)
        Window node coordinates [m], uniformly spaced, increasing.
    weights : ndarray, shape (m,)
        Tributary length of each node [m] (nodal force = pressure * weight, per unit width).
    h0 : ndarray, shape (m,)
        Undeformed gap at zero approach [m].
    A_nn, A_nt, A_tn, A_tt : ndarray, shape (m, m)
        Compliance blocks: sink per pressure, sink per traction, relative tangential displacement
        per pressure, per traction [m/Pa].
    friction : float or ndarray, shape (m,)
        Coulomb coefficient mu [1], one value or one per window node (a friction law evaluated by the
        caller at the node's slip speed or surface temperature; fixed during this solve).
    creepage : float or None
        Rigid slip xi [1] (creepage, or sliding speed / V for full sliding); None: frictionless
        normal problem only.
    regularization : float
        eps [1] (relative slip below which friction is not saturated); 0 is exact Coulomb.
    normal_force : float, optional
        Prescribed normal force per unit width [N/m] (delta becomes an unknown).
    penetration : float, optional
        Prescribed approach delta [m].
    W0, U0 : ndarray, optional
        Sink and relative tangential displacement from other loads (thermal expansion) [m].
    derivative : ndarray, optional
        Matrix of d/dx on the window (default: :func:`upstream_derivative` of order 2).
    initial : ContactSolution, optional
        Starting point (warm start).
    tol : float
        Stop when the residual max-norm is below tol times the mean pressure.
    maxit : int
        Maximum Newton iterations.
    """
    sy = _ContactSystem.build(x, weights, h0, A_nn, A_nt, A_tn, A_tt, friction=friction, creepage=creepage,
                              regularization=regularization, normal_force=normal_force, penetration=penetration,
                              W0=W0, U0=U0, derivative=derivative)
    p, tau, delta = sy.start(initial)
    sy.scale(p)
    z, nrm, it, converged, history, g, s = _newton(sy, sy.pack(p, tau, delta), tol, maxit)
    p, tau, delta = sy.unpack(z)
    p = np.maximum(p, 0.0)
    if s is None:
        s = np.full(sy.m, np.nan)
        stick = np.zeros(sy.m, bool)
    else:
        stick = (p > 0) & (np.abs(tau) < sy.mu * p * (1.0 - 1e-9))
    return ContactSolution(x=sy.x, pressure=p, traction=tau, slip=s, gap=g, stick=stick, approach=float(delta),
                           normal_force=float(sy.w @ p), tangential_force=float(sy.w @ tau), iterations=it,
                           residual=float(nrm), converged=converged, history=history)


def _newton(sy, z, tol, maxit):
    """Semismooth Newton with a backtracking line search on the residual norm, from ``z``: the unknowns, the
    final residual max-norm relative to the pressure scale, the iterations, whether it converged, the residual
    history, and the last gap and slip."""
    history = []
    converged = False
    it = 0
    R, J, g, s = sy.residual(z, jac=True)
    nrm = np.max(np.abs(R)) / sy.p_ref
    history.append(nrm)
    for it in range(1, maxit + 1):
        try:
            dz = np.linalg.solve(J, -R)
        except np.linalg.LinAlgError:
            dz = np.linalg.lstsq(J, -R, rcond=None)[0]
        alpha = 1.0
        f0 = np.linalg.norm(R)
        for _ in range(12):
            Rn, _, _, _ = sy.residual(z + alpha * dz)
            if np.linalg.norm(Rn) <= (1.0 - 1e-4 * alpha) * f0:
                break
            alpha *= 0.5
        else:
            alpha = 1.0  # no decrease found: take the full (active-set) step
        z = z + alpha * dz
        R, J, g, s = sy.residual(z, jac=True)
        nrm = np.max(np.abs(R)) / sy.p_ref
        history.append(nrm)
        if nrm < tol:
            converged = True
            break
    return z, nrm, it, converged, history, g, s


@dataclass
class _ContactSystem:
    """The condensed contact problem of :func:`solve_contact`, built once per solve: the window, the compliance
    blocks, the friction, the control (force or approach), and the scales of the complementarity functions."""

    x: np.ndarray
    w: np.ndarray
    h0: np.ndarray
    A_nn: np.ndarray
    A_nt: np.ndarray
    A_tn: np.ndarray
    A_tt: np.ndarray
    W0: np.ndarray
    U0: np.ndarray
    D: np.ndarray
    mu: object                    # float, or ndarray (m,) with per_node
    per_node: bool
    frictional: bool
    eps: float
    creepage: object
    normal_force: object
    penetration: object
    force_control: bool
    diag_nn: np.ndarray
    cn: np.ndarray
    p_ref: float = 1.0
    ct: float = 1.0
    xi: float = 0.0

    @classmethod
    def build(cls, x, weights, h0, A_nn, A_nt, A_tn, A_tt, *, friction, creepage, regularization, normal_force,
              penetration, W0, U0, derivative):
        x = np.asarray(x, float)
        m = x.size
        w = np.asarray(weights, float)
        h0 = np.asarray(h0, float)
        W0 = np.zeros(m) if W0 is None else np.asarray(W0, float)
        U0 = np.zeros(m) if U0 is None else np.asarray(U0, float)
        force_control = normal_force is not None
        if force_control == (penetration is not None):
            raise ValueError("give exactly one of normal_force and penetration")
        per_node = np.ndim(friction) > 0
        mu = np.asarray(friction, dtype=float) if per_node else float(friction)
        frictional = creepage is not None and float(np.max(mu)) > 0.0
        eps = float(regularization)
        if per_node and mu.shape != (m,):
            raise ValueError(f"friction per node needs shape ({m},), got {mu.shape}")
        D = upstream_derivative(m, float(x[1] - x[0])) if derivative is None else derivative
        diag_nn = np.diag(A_nn).copy()
        return cls(x, w, h0, A_nn, A_nt, A_tn, A_tt, W0, U0, D, mu, per_node, frictional, eps, creepage,
                   normal_force, penetration, force_control, diag_nn, 1.0 / diag_nn)

    @property
    def m(self) -> int:
        return self.x.size

    @property
    def n_unk(self) -> int:
        m, fc = self.m, self.force_control
        return 2 * m + (1 if fc else 0) if self.frictional else m + (1 if fc else 0)

    def start(self, initial):
        """Starting pressure, traction and approach: the warm start, else a Hertz-like pressure (force
        control) or the pressure that closes the gap at half the local stiffness (approach control)."""
        m, x, w, h0 = self.m, self.x, self.w, self.h0
        normal_force = self.normal_force
        if initial is not None:
            p = initial.pressure.copy()
            tau = initial.traction.copy() if self.frictional else np.zeros(m)
            delta = initial.approach if self.force_control else float(self.penetration)
            return p, tau, delta
        if self.force_control:
            # Hertz-like start: half-width from the curvature of h0 and the local compliance
            curv = np.polyfit(x, h0, 2)[0]
            a0 = max(3 * (x[1] - x[0]), min(0.5 * x[-1], (normal_force * np.median(self.diag_nn) / (np.pi * curv * w[0])) ** (1 / 3)))
            a0 = min(a0, 0.6 * x[-1])
            p = np.where(np.abs(x) < a0, 2 * normal_force / (np.pi * a0) * np.sqrt(np.clip(1 - (x / a0) ** 2, 0, None)), 0.0)
            inside = p > 0
            delta = float(np.mean((h0 + self.A_nn @ p + self.W0)[inside]))
        else:
            delta = float(self.penetration)
            p = np.maximum(0.0, -(h0 - delta + self.W0)) / self.diag_nn * 0.5
        return p, np.zeros(m), delta

    def scale(self, p) -> None:
        """Pressure scale of the residual and the tangential constant (slip response to traction)."""
        self.p_ref = (self.normal_force / self.w.sum() * 3.0) if self.force_control else max(float(np.max(p)), 1.0)
        J_st = -self.D @ self.A_tt
        mu, eps = self.mu, self.eps
        self.ct = 1.0 / (max(float(np.max(mu)), 1e-12) * self.p_ref * np.median(np.abs(np.diag(J_st))) + eps) \
            if self.frictional else 1.0
        self.xi = float(self.creepage) if self.frictional else 0.0

    def unpack(self, z):
        m = self.m
        p_ = z[:m]
        t_ = z[m:2 * m] if self.frictional else np.zeros(m)
        d_ = z[-1] if self.force_control else float(self.penetration)
        return p_, t_, d_

    def pack(self, p_, t_, d_):
        parts = [p_]
        if self.frictional:
            parts.append(t_)
        if self.force_control:
            parts.append([d_])
        return np.concatenate(parts)

    def residual(self, z, jac=False):
        """Complementarity residual R(z) (normal, tangential, force balance), its generalized Jacobian (``jac``),
        the gap and the slip (None without friction)."""
        m, n_unk, cn = self.m, self.n_unk, self.cn
        p_, t_, d_ = self.unpack(z)
        g = self.h0 - d_ + self.A_nn @ p_ + self.A_nt @ t_ + self.W0
        R = np.empty(n_unk)
        J = np.zeros((n_unk, n_unk)) if jac else None
        r = p_ - cn * g
        act = r > 0
        R[:m] = np.where(act, cn * g, p_)
        if jac:
            ia = np.nonzero(act)[0]
            ii = np.nonzero(~act)[0]
            J[ia, :m] = cn[ia, None] * self.A_nn[ia]
            if self.frictional:
                J[ia, m:2 * m] = cn[ia, None] * self.A_nt[ia]
            if self.force_control:
                J[ia, -1] = -cn[ia]
            J[ii, ii] = 1.0
        s = None
        if self.frictional:
            s = self._tangential(p_, t_, R, J)
        if self.force_control:
            w = self.w
            R[-1] = (w @ p_ - self.normal_force) / w.sum()
            if jac:
                J[-1, :m] = w / w.sum()
        return R, J, g, s

    def _tangential(self, p_, t_, R, J):
        """Fill the tangential rows of R (and of J when not None); returns the slip."""
        m, n_unk, D, mu, per_node, ct, eps = self.m, self.n_unk, self.D, self.mu, self.per_node, self.ct, self.eps
        U = self.A_tn @ p_ + self.A_tt @ t_ + self.U0
        s = self.xi - D @ U
        bound = mu * np.maximum(p_, 0.0)
        arg = t_ - ct * (mu * p_ * s + eps * t_)
        stick = np.abs(arg) < bound
        up = (~stick) & (arg >= 0)
        lo = (~stick) & (arg < 0)
        Rt = np.where(stick, ct * (mu * p_ * s + eps * t_), t_ - np.where(up, bound, -bound))
        R[m:2 * m] = Rt
        if J is not None:
            ist = np.nonzero(stick)[0]
            # d(s) = -D (A_tn dp + A_tt dtau)
            DS_p = -D @ self.A_tn
            DS_t = -D @ self.A_tt
            Jt = np.zeros((m, n_unk))
            mst = mu[ist] if per_node else mu
            mcol = mu[ist, None] if per_node else mu
            Jt[ist, :m] = ct * mcol * p_[ist, None] * DS_p[ist]
            Jt[ist, ist] += ct * mst * s[ist]
            Jt[ist, m:2 * m] = ct * mcol * p_[ist, None] * DS_t[ist]
            Jt[ist, m + ist] += ct * eps
            iu = np.nonzero(up)[0]
            il = np.nonzero(lo)[0]
            pos = p_ > 0
            Jt[iu, m + iu] = 1.0
            Jt[iu, iu] -= (mu[iu] if per_node else mu) * pos[iu]
            Jt[il, m + il] = 1.0
            Jt[il, il] += (mu[il] if per_node else mu) * pos[il]
            J[m:2 * m] = Jt
        return s
