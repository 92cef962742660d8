"""The conformance kit (railtherm.testing.check_method) catches wrong physics, not only wrong shapes.

Inline fake methods, each one Hertz + full sliding + a fake temperature model:

* ``refuse-all`` refuses every canonical scene (with a reason): fails, a method must solve something;
* ``mute`` refuses one scene with an empty reason, ``oddkind`` with a reason kind outside
  {"validity", "budget"}: both fail;
* ``hot`` returns 1e6 degC everywhere (schema-valid, finite, deterministic): fails the accuracy check
  against core's exact references;
* ``plateau`` returns the exact maximum temperature everywhere on the patch, so its headline
  (maximum) is exact but the field is not: fails on the energy balance of the computed field (and
  on the mean temperature);
* ``wrong-sign`` is full sliding written with ``dissipation = traction x slip velocity`` (core's
  convention is -(traction . slip) >= 0): -30 kW of frictional power and temperatures below bulk on the
  full-sliding scene, while its temperature model (green's) is verified on the given-flux scenes; the
  kit's tangential check fails it, and solve() raises PluginError;
* ``pushes-slip`` puts the traction along the slip but reports a positive dissipation: the kit's cell
  check of -(traction . slip) fails it;
* ``flipped`` reverses both traction and slip (its dissipation stays positive): the slip and the creep
  force have the wrong direction against the scene's rigid slip, and the kit fails it;
* the built-in methods (green, fastsim-fdm, fipy, fem) pass on the canonical scenes at level 0.
"""
from __future__ import annotations

import numpy as np
import pytest

from railtherm import (Capabilities, Method, PluginError, Refused, TangentialContactModel, TemperatureField,
                       TemperatureModel, hookimpl)
from railtherm.testing import CANONICAL_SCENES, canonical, check_method

PROVIDES = frozenset({"surface_temperature", "max_surface_temperature", "mean_contact_temperature"})


class RefuseAll(TemperatureModel):
    """Test fake: refuses every scene."""

    name = "refuse-all"
    description = "test fake: refuses every scene"
    capabilities = Capabilities(provides=PROVIDES)

    def supports(self, scene, level):
        return f"model {self.name!r} refuses scene {scene.name!r} (test fake)"

    def compute_temperature(self, scene, source, level, options):
        raise AssertionError("never called: supports() refuses every scene")


class Hot(TemperatureModel):
    """Test fake: 1e6 degC everywhere."""

    name = "hot"
    description = "test fake: 1e6 degC everywhere"
    capabilities = Capabilities(provides=PROVIDES)

    def compute_temperature(self, scene, source, level, options):
        return TemperatureField.from_surface(source.grid, np.full((2, *source.grid.shape), 1e6))


class Plateau(TemperatureModel):
    """Test fake: the exact maximum temperature of each body everywhere."""

    name = "plateau"
    description = "test fake: exact maximum everywhere"
    capabilities = Capabilities(provides=PROVIDES)

    def compute_temperature(self, scene, source, level, options):
        from railtherm.analysis.analytic import reference_values
        tmax = reference_values(scene)["max_surface_temperature"]
        surface = np.stack([np.full(source.grid.shape, t) for t in tmax])
        return TemperatureField.from_surface(source.grid, surface)


class Mute(Hot):
    """Test fake: refuses line contacts with an empty reason (1e6 degC elsewhere)."""

    name = "mute"
    description = "test fake: refuses line contacts with an empty message"

    def compute_temperature(self, scene, source, level, options):
        if scene.contact_shape == "line":
            raise Refused("")
        return super().compute_temperature(scene, source, level, options)


class OddKind(Hot):
    """Test fake: a refusal whose kind is neither validity nor budget."""

    name = "oddkind"
    description = "test fake: a refusal of an unknown kind"

    def compute_temperature(self, scene, source, level, options):
        exc = Refused("line contacts are not handled (test fake)")
        exc.kind = "mood"
        raise exc


FAKES = {cls.name: cls for cls in (RefuseAll, Hot, Plateau, Mute, OddKind)}


class FakePlugin:
    @hookimpl
    def railtherm_register_models(self):
        return list(FAKES.values())

    @hookimpl
    def railtherm_register_methods(self):
        return [Method(n, {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": (n,)})
                for n in FAKES]


@pytest.fixture
def fakes(railtherm_register):
    return railtherm_register("fakes", FakePlugin())


SOLVABLE = [CANONICAL_SCENES[n] for n in ("ellipse-full-sliding", "line-full-sliding", "line-given-flux")]


def test_a_method_refusing_every_scene_fails(fakes):
    with pytest.raises(AssertionError, match=r"'refuse-all' refused every one of the 5 scenes.*refuses scene"):
        check_method("refuse-all")


def test_a_refusal_needs_a_reason(fakes):
    with pytest.raises(AssertionError, match=r"'mute' refused scene 'line-full-sliding' without a reason"):
        check_method("mute")


def test_a_refusal_needs_a_known_kind(fakes):
    with pytest.raises(AssertionError, match=r"'oddkind'.*kind 'mood'.*validity.*budget"):
        check_method("oddkind", scenes=SOLVABLE)


def test_a_method_at_1e6_degrees_fails(fakes):
    with pytest.raises(AssertionError) as e:
        check_method("hot")
    msg = str(e.value)
    assert "'hot'" in msg and "10%" in msg and "max_surface_temperature" in msg
    assert "ellipse-full-sliding" in msg and "analytic:" in msg, msg


def test_a_right_maximum_on_a_wrong_field_fails(fakes):
    with pytest.raises(AssertionError, match=r"'plateau'.*scene 'ellipse-full-sliding'"):
        check_method("plateau")


def test_energy_is_checked_on_the_computed_field(fakes):
    """Even when the accuracy check looks only at the maximum, the energy balance catches the plateau."""
    with pytest.raises(AssertionError, match=r"'plateau'.*energy balance.*half-space"):
        check_method("plateau", scenes=[CANONICAL_SCENES["ellipse-full-sliding"]], tolerance=10.0)


@pytest.mark.parametrize("module,method,solved", [
    ("railtherm_green.plugin", "green", 4),      # creepage needs the fastsim plugin
    ("railtherm_fastsim.plugin", "fastsim-fdm", 5),
    ("railtherm_fipy.plugin", "fipy", 4),
    ("railtherm_fem.plugin", "fem", 2),        # line contacts only
])
def test_builtin_methods_pass(railtherm_register, module, method, solved):
    plugin = pytest.importorskip(module)
    if method == "fastsim-fdm":                   # the method names plugin fdm's temperature model
        host = railtherm_register("fdm", pytest.importorskip("railtherm_fdm.plugin"))
        host.add_plugin(plugin, method)
        host.build()
    else:
        railtherm_register(method, plugin)
    out = check_method(method)
    assert sum(v == "ok" for v in out.values()) == solved, out
    assert all(v == "ok" or v.startswith("refused: ") for v in out.values())


def test_kit_still_checks_the_schema_of_a_plain_result(fakes):
    """The physics checks come after the old ones: a valid result of a custom scene still runs."""
    with pytest.raises(AssertionError):
        check_method("hot", scenes=[canonical("line-given-flux")])


class WrongSign(TangentialContactModel):
    """Test fake: full sliding with the dissipation written as traction x slip velocity (negative)."""

    name = "wrong-sign"
    description = "test fake: full sliding, dissipation = traction x slip (sign error)"
    capabilities = Capabilities(tangential=frozenset({"full-sliding"}), sources=frozenset({"computed"}),
                                provides=frozenset({"traction_x", "slip_velocity_x", "creep_force_x"}))

    def compute_tangential(self, scene, patch, level, options):
        vs = scene.sliding_speed
        traction = np.sign(vs) * scene.friction.nominal * patch.pressure          # on the wheel, against its slip
        slip = np.where(patch.pressure > 0, -vs, 0.0)                     # wheel relative to rail
        return patch.with_tangential(traction_x=traction, slip_velocity_x=slip,
                                     creep_force_x=np.sign(vs) * scene.friction.nominal * patch.normal_force,
                                     dissipation=traction * slip, diagnostics={"converged": True})


class Flipped(WrongSign):
    """Test fake: traction and slip both reversed; the dissipation -(traction . slip) stays positive."""

    name = "flipped"
    description = "test fake: full sliding with traction and slip reversed"

    def compute_tangential(self, scene, patch, level, options):
        vs = scene.sliding_speed
        traction = -np.sign(vs) * scene.friction.nominal * patch.pressure
        slip = np.where(patch.pressure > 0, vs, 0.0)
        return patch.with_tangential(traction_x=traction, slip_velocity_x=slip,
                                     creep_force_x=-np.sign(vs) * scene.friction.nominal * patch.normal_force,
                                     dissipation=-traction * slip, diagnostics={"converged": True})


class PushesSlip(WrongSign):
    """Test fake: traction along the slip (on the rail, not the wheel) with a positive dissipation mu p |v_s|."""

    name = "pushes-slip"
    description = "test fake: full sliding with the traction along the slip"

    def compute_tangential(self, scene, patch, level, options):
        vs = scene.sliding_speed
        traction = -np.sign(vs) * scene.friction.nominal * patch.pressure
        slip = np.where(patch.pressure > 0, -vs, 0.0)
        return patch.with_tangential(traction_x=traction, slip_velocity_x=slip,
                                     creep_force_x=-np.sign(vs) * scene.friction.nominal * patch.normal_force,
                                     dissipation=np.abs(traction * slip), diagnostics={"converged": True})


SIGN_FAKES = (WrongSign, Flipped, PushesSlip)


class SignPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return list(SIGN_FAKES)

    @hookimpl
    def railtherm_register_methods(self):
        return [Method(c.name, {"normal": ("hertz",), "tangential": (c.name,), "heat_source": ("frictional",),
                                "temperature": ("green",)}) for c in SIGN_FAKES]


@pytest.fixture
def sign_fakes(railtherm_register):
    host = railtherm_register("green", pytest.importorskip("railtherm_green.plugin"))
    host.add_plugin(SignPlugin(), "signs")
    return host.build()


def test_a_tangential_model_with_the_dissipation_sign_error_fails_the_kit(sign_fakes, monkeypatch):
    with pytest.raises(AssertionError, match=r"'wrong-sign', scene 'ellipse-full-sliding'.*frictional power density "
                                             r"of -.*-\(traction \. slip\) is >= 0"):
        check_method("wrong-sign")
    # the kit's own check, should core's pipeline let the heat sink through
    from railtherm.solving import pipeline
    monkeypatch.setattr(pipeline, "_check_heat_sign", lambda pl, source: None)
    with pytest.raises(AssertionError, match=r"tangential model 'wrong-sign', scene 'ellipse-full-sliding'.*heat flux "
                                             r"into the bodies is -.*dissipation = -traction \. slip >= 0"):
        check_method("wrong-sign")


def test_solve_refuses_a_negative_frictional_heat_source(sign_fakes, monkeypatch):
    """What the sign error does when nothing stops it: -30 kW of frictional power (mu N v_s = 0.3 x 100 kN x
    1 m/s, negated), a heat sink that cools the surface below bulk (0 degC); core's pipeline raises instead."""
    from railtherm.solving import pipeline
    sc = canonical("ellipse-full-sliding", outputs=["frictional_power", "mean_contact_temperature"])
    with pytest.raises(PluginError, match=r"'wrong-sign'.*-\(traction \. slip\) is >= 0"):
        pipeline.solve(sc, "wrong-sign", 0)
    monkeypatch.setattr(pipeline, "_check_heat_sign", lambda pl, source: None)
    ds = pipeline.solve(sc, "wrong-sign", 0)
    assert float(ds.frictional_power) == pytest.approx(-30e3, rel=1e-12)
    assert float(ds.mean_contact_temperature.max()) < 0.0


def test_a_traction_along_the_slip_fails_even_with_a_positive_dissipation(sign_fakes):
    with pytest.raises(AssertionError, match=r"'pushes-slip'.*-\(traction \. slip\) = -.* in a cell"):
        check_method("pushes-slip")


def test_reversed_traction_and_slip_fail_on_the_slip_direction(sign_fakes):
    with pytest.raises(AssertionError, match=r"'flipped'.*slip velocity along x sums to .* against the rigid slip"):
        check_method("flipped")


def test_the_kit_exercises_every_declared_model(railtherm_register):
    """green declares normal (wheelset | hertz) and tangential (full-sliding | fastsim) candidates: each tangential
    model is checked on the contact scenes (fastsim on the creepage scene), the wheelset model declines every
    scene without a wheelset and is noted as such."""
    host = railtherm_register("green", pytest.importorskip("railtherm_green.plugin"), strict=False)
    host.add_plugin(pytest.importorskip("railtherm_fastsim.plugin"), "fastsim")
    with pytest.warns(RuntimeWarning):     # fastsim-fdm names plugin fdm's model, not registered here
        host.build()
    out = check_method("green", scenes=[CANONICAL_SCENES["ellipse-given-flux"]])
    assert set(out.models) == {"wheelset", "hertz", "full-sliding", "fastsim", "frictional", "green"}
    assert out.models["full-sliding"].startswith("sign conventions checked on ellipse-full-sliding, line-full-sliding")
    assert "ellipse-creepage" in out.models["fastsim"] and "checked" in out.models["fastsim"]
    assert out.models["wheelset"].startswith("not exercised: it declines every scene")
    assert out.models["hertz"].startswith("ran on ")
