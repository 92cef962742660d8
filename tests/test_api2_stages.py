"""Plugin API 2: four stages, no stage rewrites another's result, a chain of other stages refused.

* a method naming a stage other than the four (the ``contact`` of plugin API 1) is a plugin problem
  naming the method, the stage and the allowed stages, and the method is not registered;
* a tangential model that returns the patch it was given, changes a normal field, or writes into the
  normal stage's arrays is a PluginError / fails at once;
* the heat source of a chain with tangential and temperature stages is core's ``frictional``: q = the
  tangential stage's dissipation, integrating to its frictional power.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import railtherm
from railtherm import Capabilities, Method, PluginError, TangentialContactModel, hookimpl
from railtherm.testing import canonical

FULL = {"normal": ("hertz",), "tangential": ("full-sliding",), "heat_source": ("frictional",),
        "temperature": ("green",)}


class Returns(TangentialContactModel):
    """Test fake: returns the patch it was given."""

    name = "api2-returns-input"
    description = "test fake: returns its input patch"
    capabilities = Capabilities(provides=frozenset({"traction_x"}))

    def compute_tangential(self, scene, patch, level, options):
        return patch


class Rescales(TangentialContactModel):
    """Test fake: returns a patch with a doubled pressure."""

    name = "api2-rescales"
    description = "test fake: changes the normal pressure"
    capabilities = Capabilities(provides=frozenset({"traction_x"}))

    def compute_tangential(self, scene, patch, level, options):
        import dataclasses
        return dataclasses.replace(patch, pressure=2 * patch.pressure)


class Writes(TangentialContactModel):
    """Test fake: writes into the normal stage's pressure array."""

    name = "api2-writes"
    description = "test fake: writes into the normal stage's pressure"
    capabilities = Capabilities(provides=frozenset({"traction_x"}))

    def compute_tangential(self, scene, patch, level, options):
        patch.pressure[...] = 0.0
        return patch.with_tangential(traction_x=np.zeros_like(patch.pressure))


class Plugin:
    @hookimpl
    def railtherm_register_models(self):
        return [Returns, Rescales, Writes]

    @hookimpl
    def railtherm_register_methods(self):
        return [Method("api2-green", FULL)] + [
            Method(m.name, {"normal": ("hertz",), "tangential": (m.name,), "heat_source": ("frictional",),
                            "temperature": ("green",)}) for m in (Returns, Rescales, Writes)]


@pytest.fixture
def host(railtherm_register):
    if "green" not in {m.name for m in railtherm.methods()}:
        pytest.skip("method 'green' is not installed")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        h = railtherm_register("api2", Plugin(), autoload=True)
    return h, caught


class StagePlugin:
    @hookimpl
    def railtherm_register_methods(self):
        return [Method("api1-chain", {"contact": ("hertz",), "heat_source": ("full-sliding",)}),
                Method("no-heat-source", {"normal": ("hertz",), "tangential": ("full-sliding",),
                                          "temperature": ("green",)})]


def test_a_chain_naming_another_stage_is_refused_one_without_heat_source_gets_frictional():
    from railtherm.solving.plugins import new_host
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        host = new_host([("stages", StagePlugin())], autoload=True, strict=False)
    if "green" not in host.models:
        pytest.skip("model 'green' is not installed")
    assert "api1-chain" not in host.methods
    assert any("method 'api1-chain' names stages ['contact']; allowed ('normal', 'tangential', 'heat_source', "
               "'temperature')" in p for p in host.problems), host.problems
    info = host.methods["no-heat-source"]
    assert info.method.chain == FULL
    assert [m.name for m in info.models] == ["hertz", "full-sliding", "frictional", "green"]
    with pytest.raises(PluginError, match="names stages \\['contact'\\]"):
        new_host([("stages", StagePlugin())], autoload=False, strict=True)


def test_frictional_heat_is_the_tangential_dissipation(host):
    """q = mu p |v_s| in full sliding; its grid integral is the frictional power, which equals the
    exact mu N |v_s| up to the cell averaging of the Hertz pressure (exact totals: round-off)."""
    sc = canonical("ellipse-full-sliding", outputs=["heat_flux", "frictional_power"])
    ds = railtherm.solve(sc, "api2-green", 1)
    scene = railtherm.load_scene(sc)
    from railtherm.physics import body_speeds
    vw, vr = body_speeds(scene.speed, scene.sliding_speed, scene.tangential)
    exact = scene.friction.nominal * scene.normal_force * abs(vw - vr)
    assert float(ds.frictional_power) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("name, message", [
    ("api2-returns-input", "returned the patch it was given"),
    ("api2-rescales", "changed the normal stage's 'pressure'"),
    ("api2-writes", "read-only"),
])
def test_a_tangential_model_never_rewrites_the_normal_result(host, name, message):
    sc = canonical("ellipse-full-sliding", outputs=["max_surface_temperature"])
    with pytest.raises((PluginError, ValueError), match=message):
        railtherm.solve(sc, name, 0)


# ---------------------------------------------------------------------------------------------
# one name, one class per stage (an exact contact method's normal and tangential "kalker")
class TwinNormal(railtherm.NormalContactModel):
    """Test fake: the normal half of a twin."""

    name = "twin"
    description = "test fake: normal model named twin"

    def compute_patch(self, scene, level, options):
        raise AssertionError("not run")


class TwinTangential(TangentialContactModel):
    """Test fake: the tangential half of a twin."""

    name = "twin"
    description = "test fake: tangential model named twin"

    def compute_tangential(self, scene, patch, level, options):
        raise AssertionError("not run")


class TwinPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [TwinNormal, TwinTangential]


class ClashPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [TwinTangential]


def test_one_name_may_serve_two_stages_of_one_plugin():
    from railtherm.solving.plugins import new_host
    host = new_host([("twins", TwinPlugin())], autoload=False, strict=True)
    info = host.models["twin"]
    assert info.stages == ("normal", "tangential") and not host.problems
    assert info.for_stage("normal") is TwinNormal and info.for_stage("tangential") is TwinTangential
    mi = host.compose({"normal": "twin", "tangential": "twin"})
    assert mi.method.chain == {"normal": ("twin",), "tangential": ("twin",)}


def test_a_second_class_of_a_name_from_another_plugin_is_refused():
    from railtherm.solving.plugins import new_host
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        host = new_host([("twins", TwinPlugin()), ("zclash", ClashPlugin())], autoload=False, strict=False)
    assert host.models["twin"].classes == (TwinNormal, TwinTangential)
    assert any("'twin' is already registered" in p for p in host.problems)
