"""1-D high-Péclet flash temperature of a band heat source (seed paper eqs. 30-39).

At high Péclet number L = V a / (2 kappa) conduction along the rolling direction is negligible: each
material line normal to the surface is heated as a 1-D half-space by the flux it sees while it crosses
the contact (time t = (a - x)/V since the leading edge x = +a). Seed eq. (30), with the effusivity
beta = sqrt(lambda rho c) (eq. 31):
``theta(z, t) = 1/(beta sqrt(pi)) int_0^t q(t - t') exp(-z^2/(4 kappa t')) dt' / sqrt(t')``.
Coordinates: material flows in -x, z >= 0 is depth; the seed's xi runs from the leading edge -1 to the
trailing edge +1 (``xi_seed = -x/a``) and delta = sqrt(2 kappa a / V). The seed's eqs. 34, 36, 37 and
39 have misprints; the consistent forms are implemented (docs/NOTES.md lists them).

References: H. Blok, IMechE Proc. General Discussion on Lubrication 2 (1937) 222-235. J.C. Jaeger, Moving
sources of heat and the temperature at sliding contacts, J. Proc. Roy. Soc. New South Wales 76 (1942)
203-224. H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, section 2.9
(constant flux into a half-space: ierfc). ISBN 978-0198533689
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy import integrate, optimize
from scipy.special import ellipe, ellipk, ellipkm1, erfc

from .hertz import _ecoef, _kcoef, _poly

__all__ = ["flash_temperature_1d", "flash_max_hertz_coefficient", "flash_max_hertz_location",
           "flash_uniform_max_coefficient", "flash_uniform_mean_coefficient", "hertz_band_integral",
           "thermal_properties"]

_SQRT_PI = math.sqrt(math.pi)


def thermal_properties(material) -> tuple[float, float]:
    """Return (conductivity lambda [W/(m K)], diffusivity kappa [m^2/s]) of a Material-like object.

    ``material`` needs ``conductivity`` and either ``diffusivity`` or ``density`` and ``specific_heat``.
    """
    lam = float(material.conductivity)
    kappa = getattr(material, "diffusivity", None)
    if kappa is None:
        kappa = lam / (float(material.density) * float(material.specific_heat))
    return lam, float(kappa)


def _ierfc(s):
    """First integral of erfc: ierfc(s) = exp(-s^2)/sqrt(pi) - s erfc(s)."""
    return np.exp(-s * s) / _SQRT_PI - s * erfc(s)


# Series (small parameter n) of G(n) = [(2n - 2) K(n) + (2 - n) E(n)] / n^2 (no cancellation)
_gcoef_full = 2.0 * np.concatenate([[0.0], _kcoef[:-1]]) - 2.0 * _kcoef + 2.0 * _ecoef \
    - np.concatenate([[0.0], _ecoef[:-1]])
_gcoef = _gcoef_full[2:]


def hertz_band_integral(xi) -> np.ndarray:
    """Exact ``I(xi) = int_{max(xi,-1)}^{1} sqrt(1 - u^2) / sqrt(u - xi) du`` in complete elliptic integrals.

    For -1 <= xi <= 1 (m = (1 - xi)/2): ``I = (4 sqrt(2)/3) [(1 - m) K(m) + (2m - 1) E(m)]``;
    for xi < -1 (n = 2/(1 - xi)): ``I = 8 [(2n - 2) K(n) + (2 - n) E(n)] / (3 n^2 sqrt(1 - xi))``;
    0 for xi >= 1. Here xi = x/a in railtherm coordinates (leading edge +1). Derived by the
    substitutions u = xi + (1 - xi) sin^2(theta) and u = 1 - 2 sin^2(phi) and the standard integrals
    of sin^2 and sin^4 over sqrt(1 - m sin^2) (Byrd & Friedman 1971, 310-312, doi:10.1007/978-3-642-65138-0).

    Parameters
    ----------
    xi : array_like
        Dimensionless position x/a [1].

    Returns
    -------
    numpy.ndarray
        I(xi) [1].
    """
    xi = np.asarray(xi, dtype=float)
    out = np.zeros_like(xi)
    inside = (xi >= -1.0) & (xi < 1.0)
    m = (1.0 - xi[inside]) / 2.0
    # (1-m) K(m) -> 0 at m = 1; ellipkm1 keeps K accurate near m = 1
    k = np.where(m > 0.5, ellipkm1(np.clip(1.0 - m, 1e-300, None)), ellipk(np.minimum(m, 0.5)))
    out[inside] = 4.0 * math.sqrt(2.0) / 3.0 * ((1.0 - m) * k + (2.0 * m - 1.0) * ellipe(m))
    behind = xi < -1.0
    n = 2.0 / (1.0 - xi[behind])
    small = n < 0.2
    g = np.empty_like(n)
    g[small] = _poly(_gcoef, n[small])
    nb = n[~small]
    kb = np.where(nb > 0.5, ellipkm1(np.clip(1.0 - nb, 1e-300, None)), ellipk(np.minimum(nb, 0.5)))
    g[~small] = ((2.0 * nb - 2.0) * kb + (2.0 - nb) * ellipe(nb)) / nb ** 2
    out[behind] = 8.0 * g / (3.0 * np.sqrt(1.0 - xi[behind]))
    return out


def flash_temperature_1d(x, z, half_width: float, speed: float, material, flux: float = 1.0,
                         shape: str | Callable = "uniform") -> np.ndarray:
    """Steady flash temperature rise of a band source in the 1-D (high-Péclet) approximation.

    Uniform flux q (Carslaw & Jaeger 1959, 2.9; seed eqs. 34, 36, corrected), with t1 = (a - x)/V
    (time since the leading edge) and t2 = (-a - x)/V (time since the trailing edge):

    ``T = (2 q / lambda) [sqrt(kappa t1) ierfc(z / (2 sqrt(kappa t1))) - H(t2) sqrt(kappa t2) ierfc(...)]``,

    at z = 0 ``T = (2 q / beta) sqrt(t1/pi)`` in the contact; max ``2 sqrt(2/pi) (q/beta) sqrt(a/V)``
    at the trailing edge.

    Hertz (semi-elliptical) flux ``q0 sqrt(1 - (x/a)^2)``: at z = 0 exactly
    ``T = (q0/beta) sqrt(a/(pi V)) I(x/a)`` with :func:`hertz_band_integral`; at depth z > 0 the
    integral ``T = q0/(beta sqrt(pi V)) int q(x')/q0 exp(-z^2 V / (4 kappa (x' - x))) dx' / sqrt(x' - x)``
    is evaluated by adaptive Gauss-Jacobi quadrature (scipy.integrate.quad, weight='alg').

    Parameters
    ----------
    x : array_like
        Rolling coordinate [m]; leading edge at +a, material flows to -x.
    z : array_like
        Depth [m], >= 0 (broadcast with x).
    half_width : float
        Half-width a of the band [m].
    speed : float
        Speed V of the body relative to the heat source [m/s], > 0.
    material : Material-like
        Provides conductivity [W/(m K)] and diffusivity [m^2/s] (or density and specific_heat).
    flux : float
        Heat flux into the body [W/m^2]: the uniform value, or the peak q0 for ``shape="hertz"``.
    shape : {"uniform", "hertz"} or callable
        Flux distribution; a callable f(u) of u = x/a in [-1, 1] gives q = flux * f(u) (quadrature).

    Returns
    -------
    numpy.ndarray
        Temperature rise [K].

    References
    ----------
    .. [1] H.S. Carslaw, J.C. Jaeger, Conduction of Heat in Solids, 2nd ed., Oxford, 1959, section 2.9.
       ISBN 978-0198533689
    .. [2] J.C. Jaeger, Moving sources of heat and the temperature at sliding contacts, J. Proc. Roy.
       Soc. New South Wales 76 (1942) 203-224.
    """
    if not (half_width > 0 and speed > 0):
        raise ValueError("half_width and speed must be positive")
    lam, kappa = thermal_properties(material)
    beta = lam / math.sqrt(kappa)
    a, v = float(half_width), float(speed)
    x, z = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
    if np.any(z < 0):
        raise ValueError("depth z must be >= 0")
    if isinstance(shape, str) and shape == "uniform":
        t1 = np.clip((a - x) / v, 0.0, None)
        t2 = np.clip((-a - x) / v, 0.0, None)

        def term(t):
            st = np.sqrt(kappa * t)
            with np.errstate(divide="ignore", invalid="ignore"):
                val = st * _ierfc(np.where(st > 0, z / (2.0 * np.where(st > 0, st, 1.0)), np.inf))
            return np.where(st > 0, val, 0.0)

        return 2.0 * flux / lam * (term(t1) - term(t2))
    if isinstance(shape, str) and shape == "hertz":
        out = np.empty(x.shape)
        surface = z == 0
        out[surface] = flux / beta * math.sqrt(a / (math.pi * v)) * hertz_band_integral(x[surface] / a)
        if np.any(~surface):
            out[~surface] = _quad_depth(x[~surface] / a, z[~surface], a, v, kappa, beta, flux,
                                        lambda u: np.sqrt(np.clip(1.0 - u * u, 0.0, None)), hertz=True)
        return out
    if callable(shape):
        return _quad_depth(x.ravel() / a, z.ravel(), a, v, kappa, beta, flux, shape,
                           hertz=False).reshape(x.shape)
    raise ValueError(f"shape must be 'uniform', 'hertz' or a callable, got {shape!r}")


def _quad_depth(xi, z, a, v, kappa, beta, flux, f, hertz):
    """T = q/(beta sqrt(pi V)) * sqrt(a) int f(u) exp(-c/(u - xi)) du / sqrt(u - xi), c = z^2 V/(4 kappa a)."""
    out = np.empty(np.shape(xi))
    pref = flux / beta * math.sqrt(a / (math.pi * v))
    for i, (s, zz) in enumerate(zip(np.ravel(xi), np.ravel(z))):
        if s >= 1.0:
            out.flat[i] = 0.0
            continue
        c = zz * zz * v / (4.0 * kappa * a)
        lo = max(s, -1.0)
        if hertz:
            # weight (u - lo)^alpha (1 - u)^(1/2); the remaining factor is smooth
            if s >= -1.0:
                g = lambda u: math.sqrt(1.0 + u) * math.exp(-c / (u - s)) if u > s else 0.0  # noqa: E731
                val = integrate.quad(g, lo, 1.0, weight="alg", wvar=(-0.5, 0.5), epsabs=0, epsrel=1e-11,
                                     limit=200)[0]
            else:
                g = lambda u: math.exp(-c / (u - s)) / math.sqrt(u - s)  # noqa: E731
                val = integrate.quad(g, -1.0, 1.0, weight="alg", wvar=(0.5, 0.5), epsabs=0, epsrel=1e-11,
                                     limit=200)[0]
        else:
            if s >= -1.0:
                g = lambda u: float(f(u)) * math.exp(-c / (u - s)) if u > s else 0.0  # noqa: E731
                val = integrate.quad(g, lo, 1.0, weight="alg", wvar=(-0.5, 0.0), epsabs=0, epsrel=1e-11,
                                     limit=200)[0]
            else:
                g = lambda u: float(f(u)) * math.exp(-c / (u - s)) / math.sqrt(u - s)  # noqa: E731
                val = integrate.quad(g, -1.0, 1.0, epsabs=0, epsrel=1e-11, limit=200)[0]
        out.flat[i] = pref * val
    return out


def flash_uniform_max_coefficient() -> float:
    """Coefficient C of the 1-D uniform-band maximum ``T_max = C (q/beta) sqrt(a/V)``: C = 2 sqrt(2/pi)."""
    return 2.0 * math.sqrt(2.0 / math.pi)


def flash_uniform_mean_coefficient() -> float:
    """Coefficient C of the 1-D uniform-band mean ``T_mean = C (q/beta) sqrt(a/V)``: 4 sqrt(2)/(3 sqrt(pi)) [1]."""
    return 4.0 * math.sqrt(2.0) / (3.0 * _SQRT_PI)


def _hertz_max():
    res = optimize.minimize_scalar(lambda s: -float(hertz_band_integral(np.array([s]))[0]),
                                   bounds=(-1.0, 1.0), method="bounded", options={"xatol": 1e-12})
    return res.x, -res.fun / _SQRT_PI


def flash_max_hertz_coefficient() -> float:
    """Coefficient C of the 1-D maximum for a Hertzian band: ``T_max = C (q0/beta) sqrt(a/V)``.

    Computed as max over xi of ``I(xi)/sqrt(pi)`` (:func:`hertz_band_integral`): C = 1.2346...
    (the seed paper's eq. 39 quotes 1.253).

    Returns
    -------
    float
        C [1].
    """
    return float(_hertz_max()[1])


def flash_max_hertz_location() -> float:
    """Position x/a [1] of the 1-D maximum for a Hertzian band (railtherm coordinates): -0.652..."""
    return float(_hertz_max()[0])
