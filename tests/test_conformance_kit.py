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
* the built-in methods (green, fastsim-fdm, fipy, fem) pass on the canonical scenes at level 0.
"""
from __future__ import annotations

import numpy as np
import pytest

from railtherm import Capabilities, Method, Refused, TemperatureField, TemperatureModel, hookimpl
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
        from railtherm.analytic import reference_values
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
