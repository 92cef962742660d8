"""railtherm.physics: each toolkit function against an exact value or a published number, and a
check that no built-in plugin keeps its own copy of them.

Published numbers come from ``tests/data/published.toml`` (Ertz & Knothe 2002 as quoted in the seed
paper, and the Hertz patch of its curvatures from the CONTACT example input).
"""
from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import railtherm
from railtherm import Material, Refused, SurfaceGrid, physics, surface_grid
from railtherm.models.hertz import hertz_geometry, hertz_patch, scene_semi_axis

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED = ROOT / "tests" / "data" / "published.toml"
STEEL = Material()


def _ek():
    with open(PUBLISHED, "rb") as f:
        return tomllib.load(f)["ertz_knothe_2002"]


def _scene(**kw):
    base = dict(name="s", wheel=STEEL, rail=STEEL, contact_shape="ellipse", normal_force=100e3, semi_axes=None,
                curvatures=(1.015, 0.4215), penetration=None, wheel_radius=0.46, heat_source=None, speed=30.0,
                sliding_speed=1.0, tangential="full-sliding", heat_partition="equal-temperature")
    base.update(kw)
    return SimpleNamespace(**base)


def _hertz(scene):
    """:func:`railtherm.models.hertz.hertz_geometry` on a scene's parts."""
    return hertz_geometry(scene.wheel, scene.rail, scene.contact_shape, scene.normal_force,
                          penetration=scene.penetration, semi_axes=scene.semi_axes,
                          curvatures=scene.curvatures, wheel_radius=scene.wheel_radius, scene_name=scene.name)


def _semi_axis(scene):
    """:func:`railtherm.models.hertz.scene_semi_axis` on a scene's parts."""
    return scene_semi_axis(scene.heat_source, scene.wheel, scene.rail, scene.contact_shape,
                           scene.normal_force, penetration=scene.penetration, semi_axes=scene.semi_axes,
                           curvatures=scene.curvatures, wheel_radius=scene.wheel_radius)


# ------------------------------------------------------------------ Hertz
def test_hertz_geometry_of_the_ertz_knothe_curvatures():
    """published.toml: the curvatures (1.015, 0.4215) 1/m at 100 kN give a = 5.879 mm, b = 10.540 mm,
    p0 = 770.5 MPa (quoted to 4 digits: tolerance half a unit of the last digit)."""
    a, b, p0, n = _hertz(_scene())
    assert a == pytest.approx(5.879e-3, abs=0.5e-6)
    assert b == pytest.approx(10.540e-3, abs=0.5e-6)
    assert p0 == pytest.approx(770.5e6, abs=0.05e6)
    assert n == 100e3


def test_hertz_geometry_from_semi_axes_and_line_is_exact():
    a, b, p0, n = _hertz(_scene(semi_axes=(5.88e-3, 10.54e-3)))
    assert (a, b) == (5.88e-3, 10.54e-3)
    assert p0 == pytest.approx(3 * 100e3 / (2 * math.pi * a * b), rel=1e-14)
    # line contact (Johnson eq. 4.43): a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a)
    e_star = STEEL.youngs_modulus / (2 * (1 - STEEL.poisson_ratio ** 2))
    a, b, p0, n = _hertz(_scene(contact_shape="line", normal_force=1e6, wheel_radius=0.5))
    assert b is None
    assert a == pytest.approx(math.sqrt(4 * 1e6 * 0.5 / (math.pi * e_star)), rel=1e-12)
    assert p0 == pytest.approx(2 * 1e6 / (math.pi * a), rel=1e-12)
    assert physics.contact_modulus(STEEL, STEEL) == pytest.approx(e_star, rel=1e-14)


def test_hertz_geometry_refuses_what_has_no_patch():
    with pytest.raises(Refused, match="normal_force"):
        _hertz(_scene(normal_force=0.0))
    rigid = Material(rigid=True)
    with pytest.raises(Refused, match="rigid"):
        _hertz(_scene(wheel=rigid, rail=rigid))
    assert _semi_axis(_scene(wheel=rigid, rail=rigid)) is None


def test_scene_semi_axis():
    given = SimpleNamespace(semi_axes=(2e-3, 3e-3), half_width=None)
    assert _semi_axis(_scene(heat_source=given)) == 2e-3
    assert _semi_axis(_scene(heat_source=SimpleNamespace(semi_axes=None, half_width=1e-3))) == 1e-3
    assert _semi_axis(_scene(semi_axes=(4e-3, 5e-3))) == 4e-3
    assert _semi_axis(_scene()) == _hertz(_scene())[0]


def test_rescaled_patch_is_the_hertz_patch_at_the_new_load():
    """Fixed curvatures: a, b ~ N^(1/3) (Johnson eq. 4.32), checked against the elliptic integrals."""
    a1, b1, p1, _ = _hertz(_scene())
    a2, b2, p2, _ = _hertz(_scene(normal_force=270e3))
    a, b, p0 = physics.rescale_hertz_patch(270e3, 100e3, a1, b1, "curvatures")
    assert (a, b, p0) == (pytest.approx(a2, rel=1e-9), pytest.approx(b2, rel=1e-9), pytest.approx(p2, rel=1e-9))
    assert physics.rescale_hertz_patch(270e3, 100e3, a1, b1, "semi_axes")[:2] == (a1, b1)
    # line contact: a ~ sqrt(N)
    la1 = _hertz(_scene(contact_shape="line", normal_force=1e6))[0]
    la2, _, lp2 = physics.rescale_hertz_patch(4e6, 1e6, la1, None)
    assert la2 == pytest.approx(2 * la1, rel=1e-14)
    assert lp2 == pytest.approx(2 * 4e6 / (math.pi * la2), rel=1e-14)


def test_hertz_patch_carries_the_load():
    """Cell averages are exact in x: the sampled pressure integrates to N to round-off (measured 2e-16)."""
    for scene in (_scene(), _scene(contact_shape="line", normal_force=1e6)):
        patch = hertz_patch(*_hertz(scene), 1, 16, label="test")
        assert patch.grid.integrate(patch.pressure) == pytest.approx(scene.normal_force, rel=1e-12)
        assert patch.max_pressure == _hertz(scene)[2]


# ------------------------------------------------------------------ cell averages
@pytest.mark.parametrize("shape", ["hertz", "uniform"])
def test_cell_average_integrates_to_the_exact_total(shape):
    a, b = 2e-3, 3e-3
    g = surface_grid(a, b, 0, 16)
    total = g.integrate(physics.cell_average(g, shape, a, b)) / physics.exact_total(shape, a, b)
    # Hertz: the chord integral is a polynomial in y (Gauss-exact); uniform: a sqrt edge across y
    # (measured 7.3e-6 at 16 cells)
    assert total == pytest.approx(1.0, rel=1e-12 if shape == "hertz" else 2e-5)
    gl = surface_grid(a, None, 0, 7)
    assert gl.integrate(physics.cell_average(gl, shape, a, None)) == pytest.approx(
        physics.exact_total(shape, a, None), rel=1e-14)
    assert physics.exact_total("hertz", a, b) == pytest.approx(2 * math.pi * a * b / 3, rel=1e-15)


def test_nodal_cell_average_is_exact_for_a_linear_field():
    x = np.linspace(0.0, 1.0, 11)
    edges = np.array([0.0, 0.13, 0.5, 0.77, 1.0])
    avg = physics.nodal_cell_average(x, 3.0 * x + 1.0, edges)
    np.testing.assert_allclose(avg, 3.0 * 0.5 * (edges[1:] + edges[:-1]) + 1.0, rtol=1e-14)
    # beyond the nodes the interpolant runs linearly to 0 at the next edge: 1 on [0, 1], a ramp on [-1, 0]
    assert physics.nodal_cell_average(x, np.ones_like(x), np.array([-1.0, 1.0]))[0] == pytest.approx(0.75, rel=1e-14)


# ------------------------------------------------------------------ elastic constants
def test_combined_elastic():
    g, nu = physics.combined_elastic(STEEL, STEEL)
    assert (g, nu) == (pytest.approx(STEEL.shear_modulus, rel=1e-15), pytest.approx(STEEL.poisson_ratio, rel=1e-15))
    g, nu = physics.combined_elastic(Material(rigid=True), STEEL)       # a rigid body adds no compliance
    assert (g, nu) == (pytest.approx(2 * STEEL.shear_modulus, rel=1e-15),
                       pytest.approx(STEEL.poisson_ratio, rel=1e-15))
    soft = Material(shear_modulus=41e9, poisson_ratio=0.3)
    g, nu = physics.combined_elastic(STEEL, soft)
    assert g == pytest.approx(2 / (1 / 82e9 + 1 / 41e9), rel=1e-15)
    assert nu == pytest.approx(g * (0.28 / 82e9 + 0.3 / 41e9) / 2, rel=1e-15)
    with pytest.raises(ValueError, match="rigid"):
        physics.combined_elastic(Material(rigid=True), Material(rigid=True))
    assert railtherm.combined_elastic is physics.combined_elastic        # old import path kept


# ------------------------------------------------------------------ body speeds
def test_body_speeds():
    assert physics.body_speeds(30.0, 1.0, "full-sliding") == (31.0, 30.0)                  # seed eqs. 32-33
    assert physics.body_speeds(30.0, 1.0, "given") == (30.0, 30.0)
    assert physics.body_speeds(30.0, None, "creepage") == (30.0, 30.0)
    assert physics.body_speeds(30.0, 1.0, "creepage") == (30.0, 30.0)     # a wheelset that also gives v_s
    assert physics.body_speeds(30.0, -2.0, "full-sliding") == (28.0, 30.0)
    scene = railtherm.load_scene({"name": "s", "normal_force": 1e5,
                                  "contact": {"shape": "ellipse", "semi_axes": [5e-3, 5e-3]},
                                  "speed": 20.0, "sliding_speed": 0.5, "friction": 0.3})
    assert physics.body_speeds(scene.speed, scene.sliding_speed, scene.tangential) == (20.5, 20.0)


# ------------------------------------------------------------------ heat partition
def test_partition_ertz_knothe():
    """Blok's fraction for the E&K low-speed case: sqrt(31)/(sqrt(31)+sqrt(30)) = 0.5041 (test_green_steady)."""
    ek = _ek()
    c = ek["low_speed"]
    eps = physics.equal_temperature_partition(STEEL, STEEL, c["speed"] + c["sliding_speed"], c["speed"])
    assert eps == pytest.approx(math.sqrt(31) / (math.sqrt(31) + math.sqrt(30)), rel=1e-14)
    assert round(eps, 4) == 0.5041
    assert physics.equal_temperature_partition(STEEL, STEEL, 30.0, 30.0) == 0.5
    other = Material(conductivity=25.0)
    assert physics.equal_temperature_partition(STEEL, other, 30.0, 30.0) == pytest.approx(
        STEEL.effusivity / (STEEL.effusivity + other.effusivity), rel=1e-14)


@pytest.mark.parametrize("v_wheel, v_rail, expected", [
    (0.0, 30.0, 0.0),      # a locked wheel (v0 + v_s = 0) takes no heat: all of it goes to the rail
    (-5.0, 30.0, 0.0),     # a wheel surface moving backwards through the patch: clamped, no division by zero
    (30.0, 0.0, 1.0),
    (30.0, -1.0, 1.0),
    (0.0, 0.0, 0.5),       # neither surface moves: an even split, not 0/0
    (-1.0, -1.0, 0.5),
])
def test_partition_with_zero_or_negative_speed(v_wheel, v_rail, expected):
    eps = physics.equal_temperature_partition(STEEL, STEEL, v_wheel, v_rail)
    assert eps == expected and math.isfinite(eps)


def test_scene_partition():
    from railtherm.physics.partition import HeatPartition
    assert physics.scene_partition(HeatPartition.of(0.3), STEEL, STEEL, 31.0, 30.0) == 0.3
    assert physics.scene_partition(0.3, STEEL, STEEL, 31.0, 30.0) == 0.3                  # a scene value
    assert physics.scene_partition(HeatPartition("equal-temperature"), STEEL, STEEL, 31.0, 30.0) == (
        physics.equal_temperature_partition(STEEL, STEEL, 31, 30))


def test_heat_partition_is_resolved_once_with_one_meaning_per_rule():
    """A scene's heat_partition becomes a HeatPartition at load time: a number is that fraction,
    "equal-temperature" is Blok's fraction (exact: eq. of equal_temperature_partition) for every method, and
    "equal-mean-temperature" (the FEM's rule, which needs the temperatures) is refused by a fraction fixed
    before them, naming the rule and what to use instead."""
    from railtherm.input.scene import load_scene
    from railtherm.physics.partition import HeatPartition
    base = {"name": "hp", "speed": 30.0, "normal_force": 1e5, "contact": {"shape": "ellipse", "semi_axes": [6e-3, 1e-2]},
            "sliding_speed": 1.0, "friction": 0.3, "wheel": {"conductivity": 40.0}}
    fixed = load_scene({**base, "heat_partition": 0.3})
    assert fixed.partition == HeatPartition("fraction", 0.3) and fixed.heat_partition == 0.3
    blok = load_scene({**base, "heat_partition": "equal-temperature"})
    assert blok.partition == load_scene(base).partition == HeatPartition("equal-temperature")
    assert physics.scene_partition(blok.partition, blok.wheel, blok.rail, 31.0, 30.0) == (
        physics.equal_temperature_partition(blok.wheel, blok.rail, 31.0, 30.0)) != 0.5
    mean = load_scene({**base, "heat_partition": "equal-mean-temperature"})
    assert mean.heat_partition == "equal-mean-temperature" and mean.partition.needs_temperatures
    with pytest.raises(railtherm.Refused, match=r"scene 'hp': heat_partition = 'equal-mean-temperature'.*'fem'.*"
                                                r"'equal-temperature'") as err:
        physics.scene_partition(mean.partition, mean.wheel, mean.rail, 31.0, 30.0, scene_name=mean.name)
    assert err.value.kind == "validity"
    assert HeatPartition.of(mean.partition) is mean.partition
    with pytest.raises(ValueError, match="equal-mean-temperature"):
        HeatPartition.of("equal-temp")


# ------------------------------------------------------------------ thermal scales
def test_thermal_scales_ertz_knothe():
    """E&K low speed: Pe = V a/(2 kappa) ~ 6 200, thermal depth a/sqrt(Pe) ~ 75 um, contact time 0.39 ms."""
    a, v, kappa = 5.88e-3, 30.0, STEEL.diffusivity
    sc = physics.thermal_scales(a, v, kappa)
    assert isinstance(sc, physics.ThermalScales)
    assert sc.peclet == pytest.approx(v * a / (2 * kappa), rel=1e-15)
    assert 6000 < sc.peclet < 6400
    assert sc.thermal_depth == pytest.approx(a / math.sqrt(sc.peclet), rel=1e-14)
    assert sc.thermal_depth == pytest.approx(math.sqrt(2 * kappa * a / v), rel=1e-15)
    assert 70e-6 < sc.thermal_depth < 80e-6
    assert sc.contact_time == pytest.approx(2 * a / v, rel=1e-15)
    assert sc.wake_length == pytest.approx(a / sc.peclet, rel=1e-14)
    assert physics.peclet_number(v, a, kappa) == sc.peclet
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.peclet = 1.0
    with pytest.raises(ValueError, match="speed"):
        physics.thermal_scales(a, 0.0, kappa)


# ------------------------------------------------------------------ graded edges
def test_geometric_edges_nested_by_level():
    for level in range(4):
        e = physics.geometric_edges(1.0, 0.01, 1.3, level)
        assert e[0] == 0.0 and e[-1] == 1.0 and np.all(np.diff(e) > 0)
        np.testing.assert_allclose(np.diff(e)[1:] / np.diff(e)[:-1], 1.3 ** (1.0 / 2 ** level), rtol=1e-12)
        if level:
            np.testing.assert_allclose(e[::2], physics.geometric_edges(1.0, 0.01, 1.3, level - 1), rtol=1e-14)
    e0 = physics.geometric_edges(1.0, 0.01, 1.3, 0)
    n0 = math.ceil(math.log(1 + 1.0 * 0.3 / 0.01) / math.log(1.3))
    assert e0.size == n0 + 1 and np.diff(e0)[0] <= 0.01
    assert physics.geometric_edges(1.0, 2.0, 1.3, 1).size == 3          # first >= length: one cell at level 0
    with pytest.raises(ValueError):
        physics.geometric_edges(1.0, 0.01, 1.0, 0)


# ------------------------------------------------------------------ lumped wheel
@pytest.mark.parametrize("case", ["low_speed", "high_speed"])
def test_lumped_wheel_without_convection_matches_table_1(case):
    """Ertz & Knothe Table 1, steady rows without convection (182.6 / 105.4 degC; the radius does not
    enter): eps P / G_cond within 0.2 % (measured 0.11 % / 0.13 %), and theta_mean_inf = theta_mean +
    eps_c theta_inf reproduces the published mean row to its rounding."""
    ek = _ek()
    c = ek[case]
    vw, vr = c["speed"] + c["sliding_speed"], c["speed"]
    eps = physics.equal_temperature_partition(STEEL, STEEL, vw, vr)
    power = c["friction"] * c["sliding_speed"] * ek["normal_force"]
    st = physics.lumped_wheel(eps * power, c["mean_contact_temperature"], wheel=STEEL, rail=STEEL, speed_wheel=vw,
                              speed_rail=vr, a=ek["semi_axes"][0], b=ek["semi_axes"][1], radius=0.4926)
    theta_inf, theta_mean_inf = c["steady"]["0"]
    assert st.wheel_rise == pytest.approx(theta_inf, rel=2e-3)
    assert st.mean_contact_rise == pytest.approx(theta_mean_inf, abs=0.2)
    assert st.convection == 0.0 and st.conductance == st.conduction
    assert st.contact_fraction == eps


def test_lumped_wheel_convective_area_is_the_one_documented_choice():
    r, b = 0.4926, 10.54e-3
    assert physics.CONVECTIVE_AREA == "wheel"
    assert physics.convective_area(r, b) == pytest.approx(2 * math.pi * r ** 2 + 2 * math.pi * r * 2 * b, rel=1e-15)
    assert physics.convective_area(r, b, "tread") == pytest.approx(2 * math.pi * r * 2 * b, rel=1e-15)
    assert physics.convective_area(r, None) == physics.convective_area(r, None, "tread") == 2 * math.pi * r
    with pytest.raises(ValueError, match="roof"):
        physics.convective_area(r, b, "roof")
    st = physics.lumped_wheel(1000.0, 10.0, wheel=STEEL, rail=STEEL, speed_wheel=30.0, speed_rail=30.0, a=5e-3,
                              b=b, radius=r, heat_transfer=30.0)
    assert st.area == physics.convective_area(r, b)
    assert st.wheel_rise == pytest.approx(1000.0 / (st.conduction + 30.0 * st.area), rel=1e-15)
    # Table 1 implies A = 1.57-1.59 m^2 (test_green_steady); the disc of r = 0.4926 m is 1.59 m^2
    assert 1.57 < st.area < 1.60


def test_conduction_conductance_ellipse_width():
    from scipy.special import beta
    assert physics.ELLIPSE_SQRT_WIDTH == float(beta(0.5, 1.25))
    g_line = physics.conduction_conductance(STEEL.effusivity, 30.0, 0.5, 1e-3, None)
    assert g_line == pytest.approx(0.5 * STEEL.effusivity * math.sqrt(8 * 1e-3 * 30 / math.pi), rel=1e-15)
    assert physics.conduction_conductance(STEEL.effusivity, 30.0, 0.5, 1e-3, 2e-3) == pytest.approx(
        g_line * 2e-3 * physics.ELLIPSE_SQRT_WIDTH, rel=1e-15)


# ------------------------------------------------------------------ written once
#: functions that plugins used to define themselves (name in the plugin) -> the toolkit function
REMOVED_COPIES = {
    "blok_partition": "equal_temperature_partition", "blok_fraction": "equal_temperature_partition",
    "scene_body_speeds": "body_speeds", "scene_semi_axis": "scene_semi_axis", "peclet": "peclet_number",
    "thermal_scales": "thermal_scales", "thermal_layer": "thermal_scales", "geometric_edges": "geometric_edges",
    "_outer": "geometric_edges", "cell_average": "nodal_cell_average", "_hertz_cell_average": "cell_average",
    "hertz_patch_for": "rescale_hertz_patch", "hertz_pressure_grid": "hertz_pressure_grid",
    "conduction_conductance": "conduction_conductance", "convective_area": "convective_area",
    "steady_state": "lumped_wheel", "combined_elastic": "combined_elastic",
}


def _plugin_sources():
    files = sorted((ROOT / "plugins").glob("railtherm_*/*.py"))
    assert len(files) > 20
    return {f.relative_to(ROOT).as_posix(): f.read_text() for f in files}


def test_no_plugin_defines_its_own_copy_of_the_toolkit():
    names = set(REMOVED_COPIES) | {n for n in physics.__all__ if callable(getattr(physics, n))}
    found = []
    for path, text in _plugin_sources().items():
        for name in names:
            if re.search(rf"^\s*(def|class)\s+{re.escape(name)}\b", text, re.M):
                found.append(f"{path}: {name} (use railtherm.physics.{REMOVED_COPIES.get(name, name)})")
        if re.search(r"^\s*ELLIPSE_SQRT_WIDTH\s*=", text, re.M):
            found.append(f"{path}: ELLIPSE_SQRT_WIDTH")
    assert not found, "copies of railtherm.physics in plugins:\n" + "\n".join(found)


def test_plugins_import_only_the_public_api():
    """Plugins import railtherm, railtherm.physics and railtherm.references (no private names)."""
    bad = []
    for path, text in _plugin_sources().items():
        for mod in re.findall(r"^\s*(?:from|import)\s+(railtherm(?:\.[\w.]+)?)", text, re.M):
            parts = mod.split(".")
            if len(parts) == 1:
                continue
            if parts[1] not in ("physics", "references") or any(p.startswith("_") for p in parts[1:]):
                bad.append(f"{path}: {mod}")
        for names in re.findall(r"^\s*from\s+railtherm(?:\.[\w.]+)?\s+import\s+\(?([^)\n]+)", text, re.M):
            bad += [f"{path}: {n.strip()}" for n in names.split(",") if n.strip().startswith("_")]
    assert not bad, bad


def test_superposition_limits_name_each_reason_and_the_model():
    """One pass's response superposes over the passes only with a temperature-independent heat input, one bulk
    temperature and history outputs: each broken condition is named, with the model; otherwise None."""
    from types import SimpleNamespace as NS
    from railtherm.physics import superposition_limits
    law = lambda t: NS(depends_on_temperature=t)  # noqa: E731
    body = lambda t: NS(bulk_temperature=t)  # noqa: E731
    ok = dict(friction=law(False), heat_source=None, wheel=body(20.0), rail=body(20.0), outputs=("temperature_history",))
    assert superposition_limits(**ok, model="m") is None
    hot = {**ok, "friction": law(True)}
    assert "temperature-dependent friction law" in superposition_limits(**hot, model="m")
    assert "'m'" in superposition_limits(**hot, model="m")
    assert superposition_limits(**{**hot, "heat_source": object()}, model="m") is None   # a given source: no law
    assert superposition_limits(**{**ok, "friction": None}, model="m") is None            # no friction law
    assert "one bulk temperature" in superposition_limits(**{**ok, "rail": body(30.0)}, model="m")
    assert "'peak_temperature'" in superposition_limits(**{**ok, "outputs": ("peak_temperature",)}, model="m")
