"""The undeformed gap of a scene, the potential contact area chosen from it, and the border check.

The gap between the undeformed surfaces is ``h(x, y) = sum c_ij x^i y^j`` [m]: an elliptical contact's is the
quadratic ``A x^2 + B y^2`` of its Hertz geometry (given ``semi_axes``, the curvatures of :func:`hertz_curvatures`,
so the exact solution under the scene's load is its Hertz patch), a line contact's ``x^2 / (2 R)``, and
``contact = { shape = "gap", coefficients = {...} }`` gives the coefficients (:func:`scene_gap`; a wheelset on
profiles: its sampled gap, :class:`SampledGap`). The potential contact area is a rectangle of elements around the
expected contact (Hertz semi-axes a, b, or a coarse solution's extent): level k has ``n = cells 2^k`` elements
across 2b and ``m n`` across 2a (m of :func:`rolling_refinement`: the first-order rolling slip's error is one of dx)
plus :func:`margin_elements` on every side; :func:`check_border` refuses a patch reaching the outermost ring.

References
----------
.. [1] K.L. Johnson, Contact Mechanics, 1985, sec. 4.2, eqs. 3.63-3.64. doi:10.1017/CBO9781139171731
.. [2] E.A.H. Vollebregt, User guide for CONTACT, report TR09-03 (potential contact area).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from railtherm import Refused, SolverError, SurfaceGrid
from railtherm.physics import contact_modulus
from railtherm.references.hertz import (elliptic_k_minus_e, hertz_from_curvatures, hertz_from_penetration,
                                        hertz_line)

__all__ = ["Gap", "SampledGap", "scene_gap", "hertz_curvatures", "PotentialArea", "potential_area", "margin_elements",
           "check_border", "rolling_refinement", "MAX_ELEMENTS", "MAX_ROLLING_REFINEMENT"]

#: budget of the potential contact area [elements]: a larger grid is refused (kind "budget"). The
#: tangential solver holds about 40 fields of this size (plus the padded FFT work arrays, 4x larger):
#: 2**20 elements are ~0.6 GB and ~1 min per solve on two cores.
MAX_ELEMENTS = 2 ** 20

#: largest rolling refinement m of :func:`rolling_refinement` [1] (reached for a > b). Larger m cost more than
#: in proportion: the tangential solve on a = 8, b = 4 mm at level 3 (creepage (-2e-3, 1e-3, 0.2 1/m)) took
#: 0.8, 1.6, 6.3, 22 s CPU with m = 1, 2, 4, 8 (Newton steps 7, 9, 14, 17 on the finest grid, the upwind
#: sweep preconditioning elongated elements less well); the option rolling_refinement takes 8 and more
MAX_ROLLING_REFINEMENT = 4


@dataclass(frozen=True)
class Gap:
    """Undeformed gap ``h(x, y) = sum c_ij x^i y^j`` [m].

    Attributes
    ----------
    coefficients : dict
        ``(i, j) -> c_ij`` [m^(1-i-j)].
    line : bool
        A line contact (h depends on x only, loads per unit width).
    hertz : (float, float | None, float) or None
        Hertz semi-axes a, b [m] and the approach [m] (NaN when the load is prescribed) when the gap is
        the quadratic of a Hertz patch; None otherwise.
    """

    coefficients: dict
    line: bool = False
    hertz: tuple | None = None

    def __call__(self, x, y=None):
        """h at points (x, y) [m]."""
        x = np.asarray(x, dtype=float)
        y = np.zeros_like(x) if y is None else np.asarray(y, dtype=float)
        h = np.zeros(np.broadcast(x, y).shape)
        for (i, j), c in self.coefficients.items():
            h = h + c * x ** i * y ** j
        return h

    @property
    def quadratic(self) -> tuple[float, float]:
        """The curvature coefficients (c_20, c_02) [1/m]."""
        return float(self.coefficients.get((2, 0), 0.0)), float(self.coefficients.get((0, 2), 0.0))

    @property
    def is_quadratic(self) -> bool:
        """Only x^2 and y^2 terms (a Hertz gap)."""
        return set(self.coefficients) <= {(2, 0), (0, 2)}


@dataclass(frozen=True)
class SampledGap(Gap):
    """The gap of a wheelset on profiles as the contact search samples it (``section``, a
    :class:`railtherm.physics.contact_search.GapSection`), the scene's polynomial (``coefficients``) beyond the
    sampled stretch across rolling. The polynomial of degree 8 misses the sampled gap by up to 0.22 mm at Manchester
    A-2.2 position 2 right (a sharp gap minimum beside a flat second region), where its patch is not the profiles'.

    Attributes
    ----------
    section : callable
        ``section(x, y)`` [m], +inf outside the sampled stretch of y.
    """

    section: object = None

    def __call__(self, x, y=None):
        """h at points (x, y) [m]."""
        x = np.asarray(x, dtype=float)
        y = np.zeros_like(x) if y is None else np.asarray(y, dtype=float)
        h = self.section(x, y)
        return np.where(np.isfinite(h), h, super().__call__(x, y))


def hertz_curvatures(a: float, b: float, normal_force: float, e_star: float) -> tuple[float, float]:
    """Curvature coefficients A, B of the gap ``A x^2 + B y^2`` whose Hertz patch under the normal
    force has the semi-axes a, b.

    With the major semi-axis c, m = 1 - (minor/major)^2, D = (K - E)/m and F = (E/(1 - m) - K)/m
    (Johnson 1985, eqs. 3.63-3.64): ``A_small = 3 N D / (2 pi c^3 E*)``, ``A_large = 3 N F / (2 pi c^3 E*)``.

    Parameters
    ----------
    a, b : float
        Semi-axes along x (rolling) and y [m].
    normal_force : float
        N [N].
    e_star : float
        Contact modulus E* [Pa].

    Returns
    -------
    A, B : float
        Gap curvature coefficients along x and y [1/m].
    """
    major, minor = max(a, b), min(a, b)
    m = 1.0 - (minor / major) ** 2
    _, _, d, f = elliptic_k_minus_e(m)
    scale = 3.0 * normal_force / (2.0 * math.pi * major ** 3 * e_star)
    small, large = scale * d, scale * f
    return (large, small) if a <= b else (small, large)


# whole scene: the adapter from the scene's contact geometry (shape, gap, radii, profile), load, materials to a Gap
def scene_gap(scene) -> Gap:
    """The undeformed gap of a scene (see the module docstring).

    Parameters
    ----------
    scene : Scene-like
        ``contact_shape`` ("ellipse", "line" or "gap"), ``gap_coefficients`` for a gap (with a wheelset on
        profiles also ``profile_contact.gap_section``: :class:`SampledGap`), else ``curvatures`` [1/m] or
        ``semi_axes`` [m], ``wheel_radius`` [m] for a line; ``normal_force``
        [N] ([N/m]) or ``penetration`` [m]; ``wheel``, ``rail`` materials.

    Returns
    -------
    Gap

    Raises
    ------
    railtherm.Refused
        No load, rigid bodies, or a gap that does not close (no positive curvature).
    """
    e_star = contact_modulus(scene.wheel, scene.rail)
    if not math.isfinite(e_star):
        raise Refused(f"scene {scene.name!r}: both bodies are rigid; the half-space theory needs an elastic body")
    n = scene.normal_force
    if n is not None and not n > 0:
        raise Refused(f"scene {scene.name!r}: normal_force = {n!r} gives no contact")
    shape = scene.contact_shape
    if shape == "gap":
        coef = getattr(scene, "gap_coefficients", None)
        if not coef:
            raise Refused(f"scene {scene.name!r}: contact shape 'gap' without coefficients")
        coef = {tuple(int(v) for v in k): float(c) for k, c in dict(coef).items()}
        section = getattr(getattr(scene, "profile_contact", None), "gap_section", None)
        gap = Gap(coef) if section is None else SampledGap(coef, section=section)
        A, B = gap.quadratic
        if not (A > 0 and B > 0):
            raise Refused(f"scene {scene.name!r}: the gap's x2 = {A:g} and y2 = {B:g} 1/m must both be > 0 "
                          "(a gap that does not close has no bounded contact patch)")
        return gap
    if shape == "line":
        if n is None:
            raise Refused(f"scene {scene.name!r}: a line contact on a half-plane has no finite approach; give "
                          "normal_force [N/m]")
        R = float(scene.wheel_radius)
        a, _ = hertz_line(n, R, e_star)
        return Gap({(2, 0): 0.5 / R}, line=True, hertz=(a, None, math.nan))
    if scene.curvatures is not None:
        A, B = (float(c) for c in scene.curvatures)
        h = (hertz_from_curvatures(A, B, n, e_star) if n is not None
             else hertz_from_penetration(A, B, scene.penetration, e_star))
    else:
        a, b = (float(s) for s in scene.semi_axes)
        A, B = hertz_curvatures(a, b, n, e_star)
        h = hertz_from_curvatures(A, B, n, e_star)
    return Gap({(2, 0): A, (0, 2): B}, hertz=(h.a, h.b, h.approach if n is None else math.nan))


def rolling_refinement(half_x: float, half_y: float | None) -> int:
    """Elements along x per element along y of the potential contact area, m [1].

    ``m = 2^ceil(log2(2 (a/b)^2))``, at least 1 and at most :data:`MAX_ROLLING_REFINEMENT` (1 for a line
    contact): so that ``dx = 2a / (m n) <= b^2 / (a n)`` with n elements across 2b up to a/b = sqrt(2)
    (the cap bounds the cost; beyond, the spin error grows like (a/b)^2 / 4). The upwind rolling
    slip's first-order error is one of dx (the element count across y matters much less): the
    spin moment's grows like (a/b)^2 dx / a and the frictional power's (the scheme's numerical
    dissipation) like dx / a. Measured at level 3 (n = 128), creepage (-2e-3, 1e-3, 0.2 1/m), mu = 0.3:
    local against global frictional power -4.75 % on a circle with m = 1, -2.40 % with m = 2; Kalker's
    C33 +4.7 % on a = 8, b = 4 mm with m = 1, +1.5 % with m = 4. Ertz & Knothe's ellipse (a/b = 0.56)
    keeps m = 1 (power -1.36 %, C33 +0.64 %). At b/a = 0.3 and 0.25 (m = 4) C33 is +3.8 and +5.3 %;
    the option ``rolling_refinement = 8`` brings them to +2.5 and +3.5 % (at 4 to 8 times the CPU time).
    Kalker's C33 on a = 8, b = 4 mm (Hertz pressure at the element centres, linear theory): 128 elements across
    2a with 32, 64, 128 across 2b +3.0, +4.1, +4.7 % (converging in y); 64 across 2b with 128, 256, 512 across
    2a +4.1, +1.8, +1.0 % (first order in dx). The default second-order rolling difference does not need m
    (C33 within 2.4 % at level 3 down to b/a = 0.2 with m = 1, docs/kalker.md); m applies to both schemes, so
    a scene's grid does not depend on the scheme and the first-order option keeps its accuracy.

    Parameters
    ----------
    half_x, half_y : float
        Expected half-extents a (along rolling) and b of the contact [m] (half_y None: line contact).
    """
    if half_y is None:
        return 1
    k = int(math.ceil(math.log2(2.0 * (half_x / half_y) ** 2) - 1e-9))
    return int(min(MAX_ROLLING_REFINEMENT, 2 ** max(k, 0)))


def margin_elements(n: int) -> int:
    """Elements of margin on each side of the expected contact for n elements across it [1]: at least
    5 % of n and 2, rounded up so that n + 2 margin is a multiple of 8 where that costs at most 4 more
    (the tangential solver's nested grids halve the element count three times)."""
    m = max(2, int(math.ceil(0.05 * n)))
    for extra in range(5):
        if (n + 2 * (m + extra)) % 8 == 0:
            return m + extra
    return m


@dataclass(frozen=True)
class PotentialArea(SurfaceGrid):
    """A rectangular grid of elements over the potential contact area: core's :class:`railtherm.SurfaceGrid`
    (its edges, centres and sizes) with the rolling refinement, and a line contact held as one row of
    elements across (``shape`` (nx, 1), ``mesh`` of that shape) as the solvers' 2-D arrays need.

    Attributes
    ----------
    x_edges, y_edges, a, b
        As :class:`railtherm.SurfaceGrid`: element edges [m] (y None for a line contact) and the expected
        half-extents of the contact that the grid was built on [m] (b None for a line).
    refine_x : int
        Elements along x per element along y of the expected contact [1] (:func:`rolling_refinement`).
    """

    refine_x: int = 1

    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny); ny = 1 for a line contact."""
        return (self.x.size, 1 if self.line else self.y.size)

    def mesh(self):
        """Element centres X, Y of shape (nx, ny) [m]."""
        if self.line:
            return self.x[:, None], np.zeros((self.x.size, 1))
        return super().mesh()


def _edges(centre: float, half: float, n: int, m: int) -> np.ndarray:
    h = 2.0 * half / n
    return centre + (np.arange(-m, n + m + 1) * h - half)


def potential_area(half_x: float, half_y: float | None, n: int, *, centre=(0.0, 0.0), margin: int | None = None,
                   name: str = "?", refine_x: int = 1) -> PotentialArea:
    """The potential contact area with n elements across each expected extent (refine_x n along x) plus a margin.

    Parameters
    ----------
    half_x, half_y : float
        Expected half-extents of the contact along x and y [m] (half_y None for a line contact).
    n : int
        Elements across 2 half_y, and across 2 half_x when refine_x = 1 [1].
    centre : (float, float)
        Centre of the expected contact [m].
    margin : int, optional
        Elements added on each side (default :func:`margin_elements` of the elements across each extent;
        a given margin is refine_x times larger along x).
    name : str
        Scene name, for messages.
    refine_x : int
        Elements along x per element along y, m >= 1 (:func:`rolling_refinement`): ``m n`` elements
        across 2 half_x [1].

    Returns
    -------
    PotentialArea

    Raises
    ------
    railtherm.Refused
        (kind "budget") above :data:`MAX_ELEMENTS` elements.
    """
    r = int(refine_x)
    if r < 1:
        raise ValueError(f"refine_x = {refine_x!r} must be an integer >= 1")
    nx_in = r * n
    m = margin_elements(n) if margin is None else int(margin)
    mx = margin_elements(nx_in) if margin is None else r * int(margin)
    nx = nx_in + 2 * mx
    ny = 1 if half_y is None else n + 2 * m
    if nx * ny > MAX_ELEMENTS:
        raise Refused(f"scene {name!r}, model 'kalker': the potential contact area needs {nx} x {ny} = "
                      f"{nx * ny:.3g} elements, above the budget railtherm_kalker.potential_area.MAX_ELEMENTS = "
                      f"{MAX_ELEMENTS:.3g} (memory ~{nx * ny * 600 / 1e9:.1f} GB); use a lower level", kind="budget")
    xe = _edges(centre[0], half_x, nx_in, mx)
    ye = None if half_y is None else _edges(centre[1], half_y, n, m)
    return PotentialArea(xe, ye, float(half_x), None if half_y is None else float(half_y), refine_x=r)


def check_border(area: PotentialArea, pressure: np.ndarray, name: str = "?") -> None:
    """Raise :class:`railtherm.SolverError` when the contact reaches the outermost ring of elements.

    Parameters
    ----------
    area : PotentialArea
    pressure : ndarray, shape area.shape
        Normal pressure [Pa].
    name : str
        Scene name, for messages.
    """
    p = np.asarray(pressure).reshape(area.shape)
    ring = np.zeros(area.shape, dtype=bool)
    ring[0, :] = ring[-1, :] = True
    if area.y_edges is not None:
        ring[:, 0] = ring[:, -1] = True
    if np.any(p[ring] > 0.0):
        raise SolverError(f"scene {name!r}, model 'kalker': the contact patch reaches the border of the potential "
                          f"contact area ({int(np.count_nonzero(p[ring] > 0))} border elements loaded; area "
                          f"x {area.x_edges[0]:.4g}..{area.x_edges[-1]:.4g} m"
                          + ("" if area.y_edges is None else f", y {area.y_edges[0]:.4g}..{area.y_edges[-1]:.4g} m")
                          + "): the gap's estimate of the patch was too small")
