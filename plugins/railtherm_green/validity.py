"""Validity of the 1-D Green-function model: Péclet number limits and the model's measured error.

The model drops conduction along the surface. Scaled by the semi-axis a along x and the thermal
layer delta = a/sqrt(L) in depth, the neglected terms are of relative order 1/L along x and
(a/b)^2/L across (seed §5, eq. 25). Below L = 10 the model is refused; between 10 and 1000 its error
is reported from measurements against the exact references of core (Jaeger's band source for line
contacts, the moving elliptical source on a half-space for ellipses): see :data:`ERROR_TABLE` and
the slow test ``tests/test_green_validity.py::test_error_table_regenerates``, which recomputes it.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import optimize
from scipy.special import beta as beta_fn

from railtherm import Material
from railtherm.physics import peclet_number
from railtherm.references import flash, jaeger, moving_source

__all__ = ["PECLET_MIN", "PECLET_ACCURATE", "ADVICE", "model_error", "ERROR_TABLE", "ERROR_NOTE"]

#: below this body Péclet number the scene is refused
PECLET_MIN = 10.0
#: above this the measured error of the model is below 1 % (no estimate reported beyond)
PECLET_ACCURATE = 1000.0

#: Measured relative error (1-D model - exact) / exact of the maximum surface temperature and of the
#: mean contact temperature (over the whole patch), against Péclet number L, for Hertzian
#: (semi-elliptical) and uniform flux of unit partition (one body): "line": band on a half-plane
#: against references.jaeger; "ellipse": the Ertz & Knothe ellipse (a/b = 0.558) against
#: references.moving_source. The 1-D values are the exact continuous ones (no grid error).
#: Regenerate with ``python -m railtherm_green.validity`` (prints this table; a few minutes); the
#: slow test ``test_error_table_regenerates`` recomputes rows of it.
#: Read: the max error of the Hertzian ellipse is ~0.16/L (1.7 % at L = 10, 0.015 % at L = 1000),
#: its mean error -0.04/L ... -0.07/L; on a band the Hertzian maximum is far better (9e-4 at
#: L = 10, ~0.09/L^2) but the mean is -0.14/L ... -0.16/L; a uniform flux (discontinuous at the
#: leading edge) has a max error ~0.33/L^0.87 on the ellipse and (0.24 ... 0.48)/L on a band.
ERROR_TABLE = {
    "peclet": (10.0, 30.0, 100.0, 300.0, 1000.0),
    ("line", "hertz", "max"): (9.052e-04, 9.315e-05, 8.222e-06, 9.092e-07, 8.206e-08),
    ("line", "hertz", "mean"): (-1.401e-02, -5.000e-03, -1.541e-03, -5.181e-04, -1.559e-04),
    ("line", "uniform", "max"): (2.389e-02, 9.792e-03, 3.571e-03, 1.390e-03, 4.840e-04),
    ("line", "uniform", "mean"): (-1.426e-02, -5.382e-03, -1.733e-03, -5.977e-04, -1.830e-04),
    ("ellipse", "hertz", "max"): (1.666e-02, 5.224e-03, 1.536e-03, 5.089e-04, 1.524e-04),
    ("ellipse", "hertz", "mean"): (-3.947e-03, -1.876e-03, -6.373e-04, -2.210e-04, -6.732e-05),
    ("ellipse", "uniform", "max"): (3.275e-02, 1.251e-02, 4.362e-03, 1.651e-03, 5.620e-04),
    ("ellipse", "uniform", "mean"): (-2.244e-03, -1.599e-03, -6.475e-04, -2.454e-04, -7.922e-05),
}
#: semi-axes of the ellipse the "ellipse" rows were measured on [m] (Ertz & Knothe)
ERROR_ELLIPSE = (5.88e-3, 10.54e-3)

ERROR_NOTE = ("model_error_* = measured relative error of the 1-D model (1-D minus exact, over exact) at this "
              "Péclet number for the source's shape (Hertz-like unless uniform) on the Ertz-Knothe ellipse "
              "(a/b = 0.558) or a band, interpolated in log L; 0 reported above L = 1000 (error < 0.06 %)")


#: what the refusals of core (the declared ``peclet`` range, ``moving_surface``, ``modes``; see
#: :func:`railtherm.solving.capabilities_check.capability_refusal`) add for this model: why the limit holds and what works instead
ADVICE = {
    "peclet": ("heat conduction along the rolling direction is no longer negligible and the 1-D model is "
               "invalid. Use method 'fipy' (or 'fastsim-fdm'), or the exact railtherm.references.moving_source "
               "(jaeger for a line contact)"),
    "moving_surface": ("for a body at rest use method 'fdm', or the exact railtherm.references.transient_spot (a source at "
                       "rest over time) or railtherm.references.moving_source (a steady moving source)"),
    "modes": ("it computes the quasi-steady flash temperature and transient histories of passes (conduction along "
              "x neglected); use 'fdm' or 'fipy' for other transients"),
}


def model_error(pe: float, *, line: bool = False, shape: str | None = None) -> dict[str, float]:
    """Estimated relative error of the 1-D model at Péclet number ``pe`` (measured, see :data:`ERROR_TABLE`).

    Parameters
    ----------
    pe : float
        The smaller of the two bodies' Péclet numbers [1].
    line : bool
        Line contact (band on a half-plane) instead of an ellipse.
    shape : {"uniform", "hertz", None}
        Flux shape; None (a computed source) uses the Hertz row.

    Returns
    -------
    dict
        ``{"max_surface_temperature": e1, "mean_contact_temperature": e2}`` relative errors [1]
        (signed, 1-D minus exact); zeros above :data:`PECLET_ACCURATE`.
    """
    if pe >= PECLET_ACCURATE:
        return {"max_surface_temperature": 0.0, "mean_contact_temperature": 0.0}
    geo = "line" if line else "ellipse"
    kind = "uniform" if shape == "uniform" else "hertz"
    lx = np.log(ERROR_TABLE["peclet"])
    out = {}
    for key, name in (("max", "max_surface_temperature"), ("mean", "mean_contact_temperature")):
        e = np.asarray(ERROR_TABLE[(geo, kind, key)], dtype=float)
        sign = np.sign(e[0])
        out[name] = float(sign * np.exp(np.interp(math.log(max(pe, PECLET_MIN)), lx, np.log(np.abs(e)))))
    return out


# --------------------------------------------------------------------------------------------------
# measurement of the table (uses core's exact references; slow: ~1-10 s per point)
def _one_d_coefficients(geometry: str, shape: str) -> tuple[float, float]:
    """Exact 1-D max and patch-mean coefficients C: T = C (q0/beta) sqrt(a/v)."""
    if shape == "hertz":
        cmax = flash.flash_max_hertz_coefficient()
        strip_mean = _hertz_strip_mean()
        # ellipse: strips q0 s, a s (s = sqrt(1 - y^2/b^2)) -> T ~ s^1.5, length ~ s: mean ~ B(1/2, 9/4)
        return cmax, strip_mean if geometry == "line" else strip_mean * 2.0 * float(beta_fn(0.5, 2.25)) / math.pi
    cmax = flash.flash_uniform_max_coefficient()
    strip_mean = flash.flash_uniform_mean_coefficient()
    return cmax, strip_mean if geometry == "line" else strip_mean * 2.0 * float(beta_fn(0.5, 1.75)) / math.pi


def _hertz_strip_mean() -> float:
    """(1/2) int_{-1}^{1} I(xi)/sqrt(pi) d xi for the Hertzian band (I: references.flash.hertz_band_integral)."""
    xg, wg = np.polynomial.legendre.leggauss(64)
    # I(xi) ~ sqrt(1 - xi)^3 near the leading edge, smooth elsewhere: substitute xi = 1 - 2 t^2
    t = 0.5 * (xg + 1.0)
    xi = 1.0 - 2.0 * t * t
    val = flash.hertz_band_integral(xi) / math.sqrt(math.pi) * 4.0 * t
    return float(0.5 * np.sum(0.5 * wg * val))


#: Gauss points per panel of the references (their default 8 gives up to 1.2e-6 (jaeger) and ~1e-5
#: (moving_source, L >= 1000) relative accuracy, measured against 16; 12 gives ~1e-9 / ~1e-8)
QUAD_POINTS = 12


def measure_model_error(pe: float, geometry: str = "ellipse", shape: str = "hertz", *,
                        mean_points: tuple[int, int] = (24, 64)) -> dict[str, float]:
    """Measure the relative error of the 1-D model against core's exact references at Péclet ``pe``.

    Parameters
    ----------
    pe : float
        Péclet number L = V a / (2 kappa) [1].
    geometry : {"ellipse", "line"}
        Ertz & Knothe ellipse (:data:`ERROR_ELLIPSE`, vs references.moving_source) or a band
        (vs references.jaeger).
    shape : {"hertz", "uniform"}
        Flux shape.
    mean_points : (int, int)
        Gauss-Legendre points in r and trapezoid points in angle for the patch mean of the exact
        field on the ellipse [1].

    Returns
    -------
    dict
        ``{"max": e_max, "mean": e_mean}``: (1-D - exact) / exact [1].
    """
    m = Material()
    a, b = ERROR_ELLIPSE
    v = 2.0 * m.diffusivity * pe / a
    c1d = m.effusivity ** -1 * math.sqrt(a / v)
    cmax, cmean = _one_d_coefficients(geometry, shape)

    if geometry == "line":
        def field(x):
            x = np.atleast_1d(np.asarray(x, float))
            return jaeger.jaeger_band_temperature(x, 0.0 * x, a, v, m, 1.0, shape, quad_points=QUAD_POINTS)
    else:
        def field(x, y=None):
            x = np.atleast_1d(np.asarray(x, float))
            y = 0.0 * x if y is None else y
            return moving_source.moving_source_temperature(x, y, 0.0 * x, (a, b), v, m, 1.0, shape,
                                                           quad_points=QUAD_POINTS)

    xs = np.linspace(-a, a, 201)
    t = field(xs)
    i = int(np.argmax(t))
    if 0 < i < xs.size - 1:
        res = optimize.minimize_scalar(lambda s: -float(field(s)[0]), bounds=(xs[i - 1], xs[i + 1]),
                                       method="bounded", options={"xatol": 1e-10 * a})
        tmax = -res.fun
    else:
        tmax = float(t[i])
    if geometry == "line":
        g, w = np.polynomial.legendre.leggauss(64)
        # x = -a cos(theta): removes the square-root ends
        th = 0.5 * math.pi * (g + 1.0)
        tmean = float(np.sum(0.5 * math.pi * w * field(-a * np.cos(th)) * np.sin(th)) / 2.0)
    else:
        nr, nt = mean_points
        u, wu = np.polynomial.legendre.leggauss(nr)
        u, wu = 0.5 * (u + 1.0), 0.5 * wu
        r, wr = 1.0 - u * u, 2.0 * u * wu        # r = 1 - u^2: the sqrt(a_y - x) edge becomes smooth
        th = np.arange(nt) * 2.0 * math.pi / nt
        R, TH = np.meshgrid(r, th, indexing="ij")
        tt = field((a * R * np.cos(TH)).ravel(), (b * R * np.sin(TH)).ravel()).reshape(R.shape)
        tmean = float(np.sum(tt * R * wr[:, None]) * (2.0 * math.pi / nt) / math.pi)
    return {"max": cmax * c1d / tmax - 1.0, "mean": cmean * c1d / tmean - 1.0}


if __name__ == "__main__":  # pragma: no cover - regeneration script for ERROR_TABLE
    for geo in ("line", "ellipse"):
        for shp in ("hertz", "uniform"):
            rows = [measure_model_error(p, geo, shp) for p in ERROR_TABLE["peclet"]]
            for key in ("max", "mean"):
                print(f"    ({geo!r}, {shp!r}, {key!r}): (" + ", ".join(f"{r[key]:.3e}" for r in rows) + "),")
