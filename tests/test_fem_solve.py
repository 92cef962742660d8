"""Method "fem" through the public entry ``railtherm.solve``: Carter, full sliding, the friction regularisation.

The direct tests (tests/test_fem_contact.py) call the solver with eps = 1e-9; these go through scene
parsing, the model's defaults and the mapping onto the patch grid, where the creep force was once 0.3x
Carter's because the default regularisation eps = 1e-3 (the seed's value) exceeded the creepages.

Run: python -m pytest tests/test_fem_solve.py -q
"""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm.references.carter import carter_2d, carter_normal_load

G, NU, R, MU, A = 82e9, 0.28, 0.5, 0.3, 1e-3
MAT = {"shear_modulus": G, "poisson_ratio": NU}
N = carter_normal_load(A, R, G, NU)   # identical bodies: half-width A [N/m]


def carter_scene(xi, **over):
    sc = {"name": "carter", "normal_force": N, "contact": {"shape": "line", "wheel_radius": R}, "speed": 10.0,
          "creepage": {"longitudinal": xi}, "friction": MU, "wheel": dict(MAT), "rail": dict(MAT),
          "outputs": ["creep_force_x", "normal_force", "semi_axis_a", "stick", "traction_x", "pressure"]}
    sc.update(over)
    return sc


@pytest.mark.parametrize("xi", [-1e-4, -2.4e-4, -4e-4])
def test_carter_through_solve(xi):
    """Identical elastic bodies at level 3: Fx/(mu Fn) and the stick-zone length within 2 % of Carter.

    Defaults only (strip 80 a x 40 a, exact Coulomb). The stick zone is read from the patch grid
    (cells = 40: 320 cells of a/160) as the distance from the trailing end of its run of stick cells to
    the leading edge x = +a (as the direct test does with the nodes).
    """
    ds = railtherm.solve(carter_scene(xi), "fem", 3, {"cells": 40})
    ref = carter_2d(xi, A, MU, R)
    fn = float(ds["normal_force"])
    assert abs(fn / N - 1) < 1e-9
    assert abs(float(ds["semi_axis_a"]) / A - 1) < 0.01
    ratio = float(ds["creep_force_x"]) / (MU * fn)
    assert abs(ratio / ref.force_ratio - 1) < 0.02, (ratio, ref.force_ratio)
    stick = ds["stick"].values
    x = ds["x"].values
    dx = x[1] - x[0]
    idx = np.nonzero(stick == 1)[0]
    # one run of stick cells ending within a node spacing (h = a/80 = 2 cells) of the leading edge: the
    # outermost contact node, where p -> 0, saturates (|tau| = mu p, slip ~1e-2 xi), as in the direct test
    assert idx.size and np.all(np.diff(idx) == 1) and idx[-1] >= stick.size - 3, idx
    length = (x[-1] + 0.5 * dx) - (x[idx[0]] - 0.5 * dx)   # trailing end of the run to the leading edge
    assert abs(length / (2 * ref.stick_half_width) - 1) < 0.02, (length, 2 * ref.stick_half_width)
    assert ds.attrs["fem_regularization"] == 0.0


def test_carter_sign_antisymmetric():
    """Positive creepage gives a negative force on the wheel; identical bodies: F(-xi) = -F(xi) exactly."""
    f = [float(railtherm.solve(carter_scene(x), "fem", 1)["creep_force_x"]) for x in (-2.4e-4, 2.4e-4)]
    assert f[0] > 0 > f[1]
    assert abs(f[0] + f[1]) < 1e-9 * abs(f[0])


def sliding(vs, rigid):
    sc = {"name": "sliding", "normal_force": N, "contact": {"shape": "line", "wheel_radius": R}, "speed": 10.0,
          "sliding_speed": vs, "friction": MU, "wheel": {**MAT, "rigid": rigid}, "rail": dict(MAT),
          "outputs": ["creep_force_x", "normal_force", "traction_x", "slip_velocity_x", "pressure", "stick"]}
    return railtherm.solve(sc, "fem", 1)


@pytest.mark.parametrize("rigid", [True, False])
def test_full_sliding_signs(rigid):
    """v_s > 0 (wheel surface faster): Fx = +mu N, traction_x = +mu p, wheel slips at -v_s relative to the rail.

    The local slip is -v_s plus the elastic part -V dU/dx, which in full sliding (tau = mu p) does not
    depend on v_s: the slips at two sliding speeds differ by exactly their difference.
    """
    d1, d2 = sliding(0.5, rigid), sliding(2.0, rigid)
    for ds, vs in ((d1, 0.5), (d2, 2.0)):
        fn = float(ds["normal_force"])
        assert abs(float(ds["creep_force_x"]) / (MU * fn) - 1) < 1e-12
        p, tx = ds["pressure"].values, ds["traction_x"].values
        assert np.allclose(tx, MU * p, rtol=1e-12, atol=1e-12 * p.max())
        assert np.nansum(ds["stick"].values) == 0
        s = ds["slip_velocity_x"].values[p > 0]
        assert np.all(s < 0)
    p = d1["pressure"].values > 0
    ds_ = d2["slip_velocity_x"].values[p] - d1["slip_velocity_x"].values[p]
    assert np.allclose(ds_, -1.5, rtol=0, atol=1e-9), ds_


def test_regularization_default_is_exact_coulomb_and_large_eps_warns():
    """The seed's eps = 1e-3 at a creepage of 1e-4 makes the stick zone creep: a warning, Fx below mu N |xi| / eps."""
    with pytest.warns(RuntimeWarning, match="regularisation"):
        ds = railtherm.solve(carter_scene(-1e-4, numerics={"regularization": 1e-3}), "fem", 1)
    ratio = float(ds["creep_force_x"]) / (MU * float(ds["normal_force"]))
    assert ds.attrs["fem_regularization"] == 1e-3
    assert abs(ds.attrs["fem_regularization_over_slip"] - 10.0) < 1e-9
    assert ratio <= 0.1 * (1 + 1e-9)          # tau = -mu p s / eps with 0 < s <= |xi| ...
    assert ratio < 0.5 * carter_2d(-1e-4, A, MU, R).force_ratio   # ... far below Carter's 0.306


def _main_study_fem_seed(**over):
    import tomllib
    from pathlib import Path
    doc = tomllib.loads((Path(__file__).resolve().parents[1] / "studies" / "seed_paper.toml").read_text())
    sc = next(dict(s) for s in doc["scene"] if s["name"] == "fem-seed")
    for key, value in over.items():
        sc[key] = {**sc[key], **value} if isinstance(value, dict) and isinstance(sc.get(key), dict) else value
    return sc


def test_main_study_fem_seed_creep_force_is_unbiased_and_not_carters():
    """fem-seed of the main study runs without the FEM's regularisation warning (eps <= 0.01 |xi|). Its rigid
    wheel is not quasi-identical to the strip (Poisson coupling), so Carter is no reference for its creep
    force: more than 5 % above Carter, while the same scene with an elastic wheel of the same steel is
    within 1 % of Carter (contact only, level 1)."""
    import warnings
    out = ["creep_force_x", "normal_force", "semi_axis_a"]
    ratios = {}
    for rigid in (True, False):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            ds = railtherm.solve(_main_study_fem_seed(wheel={"rigid": rigid}, outputs=out), "fem", 1)
        sc = _main_study_fem_seed()
        ref = carter_2d(sc["creepage"]["longitudinal"], float(ds["semi_axis_a"]), sc["friction"],
                        sc["contact"]["wheel_radius"])
        ratios[rigid] = float(ds["creep_force_x"]) / (sc["friction"] * float(ds["normal_force"])) / ref.force_ratio
    assert ratios[True] > 1.05 and abs(ratios[False] - 1) < 0.01, ratios


def test_frictionless_scene_returns_every_tangential_output():
    """friction = 0 with the tangential outputs asked (a hostile scene of tests/test_hypothesis_methods.py
    found fem declaring them and returning none): no traction, no creep force, no stick inside the patch,
    and every point slipping at the rigid slip V xi, the limit of the frictional solution as mu -> 0."""
    import railtherm
    base = dict(name="f0", contact={"shape": "line", "wheel_radius": 0.46}, normal_force=1e5,
                creepage={"longitudinal": -1e-3}, speed=30.0,
                outputs=["stick", "traction_x", "slip_velocity_x", "creep_force_x"])
    ds = railtherm.solve(railtherm.load_scene({**base, "friction": 0.0}), "fem", level=0)
    assert np.all(ds["traction_x"].values == 0.0) and float(ds["creep_force_x"]) == 0.0
    stick = ds["stick"].values
    assert np.all(stick[np.isfinite(stick)] == 0.0) and np.isfinite(stick).any()
    np.testing.assert_allclose(ds["slip_velocity_x"].values, 30.0 * -1e-3, rtol=1e-12)
    near = railtherm.solve(railtherm.load_scene({**base, "friction": 1e-9}), "fem", level=0)
    inside = np.isfinite(stick)
    np.testing.assert_allclose(near["slip_velocity_x"].values[inside], ds["slip_velocity_x"].values[inside], rtol=1e-6)
