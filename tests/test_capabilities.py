"""Declared is enforced (STYLE 19): core (:mod:`railtherm.solving.capabilities_check`, called by the
pipeline before a model's own ``supports``) checks every model's ``Capabilities`` -- contact shape,
heat source kind, tangential regime and, for temperature models, the scene's mode, its convection,
moving surfaces and each body's Péclet number, the last two again on the heat source right before the
temperature stage -- and no plugin re-checks a declared capability by hand."""
import ast
import re
import types
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import railtherm
from railtherm import Capabilities, Refused, TemperatureField, TemperatureModel
from railtherm.solving import capabilities_check
from railtherm.solving.capabilities_check import capability_refusal, refusal, source_refusal
from railtherm.testing import canonical

ROOT = Path(__file__).resolve().parents[1]
PROVIDES = frozenset({"surface_temperature", "max_surface_temperature", "mean_contact_temperature"})


class Flat(TemperatureModel):
    """Bulk temperatures everywhere (test fake); subclasses change only the capabilities."""

    name = "flat-caps"
    description = "test fake"
    capabilities = Capabilities(provides=PROVIDES)

    def compute_temperature(self, scene, source, level, options):
        shape = source.grid.shape
        bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
        surface = np.broadcast_to(bulk.reshape((2,) + (1,) * len(shape)), (2, *shape)).copy()
        return TemperatureField.from_surface(source.grid, surface)


def _with(**caps):
    return type("Fake", (Flat,), {"capabilities": Capabilities(provides=PROVIDES, **caps)})


def _plugin(*models):
    mod = types.ModuleType("caps_plugin")

    @railtherm.hookimpl
    def railtherm_register_models():
        return list(models)

    @railtherm.hookimpl
    def railtherm_register_methods():
        return [railtherm.Method(m.name, {"normal": ("hertz",), "tangential": ("full-sliding",),
                                          "temperature": (m.name,)}) for m in models]

    mod.railtherm_register_models = railtherm_register_models
    mod.railtherm_register_methods = railtherm_register_methods
    return mod


def _readme_plugin():
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(# my_plugin/plugin.py\n.*?)```", text, re.S).group(1)
    mod = types.ModuleType("my_plugin_plugin")
    exec(compile(code, "README-plugin", "exec"), mod.__dict__)
    return mod


def _given(pe: float, **kw):
    """The canonical given-flux ellipse (a = 4 mm) at the speed that gives both bodies Péclet ``pe``."""
    scene = canonical("ellipse-given-flux", **kw)
    kappa = railtherm.load_scene(scene).rail.diffusivity
    scene["speed"] = pe * 2.0 * kappa / 4e-3
    return scene


# -- convection ----------------------------------------------------------------------------------
def test_readme_crude_flash_refused_on_a_convection_scene_by_core(railtherm_register):
    mod = _readme_plugin()
    railtherm_register("crude", mod)
    crude = mod.CrudeFlash()
    assert "supports" not in vars(mod.CrudeFlash) or "super().supports" in (ROOT / "README.md").read_text()
    scene = canonical("ellipse-full-sliding", convection=20.0)
    assert crude.supports(railtherm.load_scene(scene), 0) is None      # the plugin's hook: no own limit here
    why = capability_refusal(crude, railtherm.load_scene(scene))
    assert why is not None and refusal(crude, railtherm.load_scene(scene), 0) == why
    assert "'crude-flash'" in why and "convection = 20 W/m^2K" in why and "convection=yes" in why
    with pytest.raises(Refused, match="ignores convection") as info:
        railtherm.solve(scene, "crude", level=0)
    assert info.value.kind == "validity"
    assert capability_refusal(crude, railtherm.load_scene(canonical("ellipse-full-sliding"))) is None


def test_third_party_model_without_convection_is_refused(railtherm_register):
    NoConv = _with(convection=False)
    railtherm_register("caps", _plugin(NoConv))
    scene = canonical("line-full-sliding", convection=50.0)
    with pytest.raises(Refused, match=r"model 'flat-caps' ignores convection .* convection = 50 W/m\^2K"):
        railtherm.solve(scene, "flat-caps", level=0)
    assert railtherm.solve(canonical("line-full-sliding"), "flat-caps", level=0) is not None
    for honours in (True, "long-term"):
        assert capability_refusal(_with(convection=honours)(), railtherm.load_scene(scene)) is None


# -- Péclet range ----------------------------------------------------------------------------------
def test_peclet_below_the_declared_range_is_refused_with_the_number():
    model = _with(peclet=(10.0, float("inf")))()
    why = capability_refusal(model, railtherm.load_scene(_given(5.0)))
    assert why is not None
    assert "Péclet number of the wheel" in why and "= 5 is below 10" in why and "10..inf" in why
    assert "use a model whose declared Péclet range contains 5" in why
    assert capability_refusal(model, railtherm.load_scene(_given(50.0))) is None


def test_peclet_above_the_declared_range_is_refused(railtherm_register):
    High = _with(peclet=(0.0, 100.0))
    railtherm_register("caps", _plugin(High))
    scene = _given(400.0)
    why = capability_refusal(High(), railtherm.load_scene(scene))
    assert why is not None and "= 400 is above 100" in why and "0..100" in why


def test_peclet_from_the_heat_source_after_the_contact_stage():
    model = _with(peclet=(10.0, float("inf")))()
    loaded = railtherm.load_scene(_given(5.0))
    src = railtherm.given_heat_source(loaded, 0)
    why = source_refusal(model, loaded, src)
    assert why is not None and "= 5 is below 10" in why
    assert source_refusal(_with()(), loaded, src) is None


def test_the_pipeline_checks_the_heat_source_before_the_temperature_stage(railtherm_register, monkeypatch):
    """With the semi-axis unknown before the contact stage, the Péclet refusal comes from the heat source."""
    Low = _with(peclet=(1e6, float("inf")))
    railtherm_register("caps", _plugin(Low))
    monkeypatch.setattr(capabilities_check, "_given_semi_axis", lambda scene: None)
    scene = railtherm.load_scene(canonical("ellipse-full-sliding"))
    assert capability_refusal(Low(), scene) is None
    with pytest.raises(Refused, match=r"model 'flat-caps': Péclet number of the wheel .* is below 1e\+06") as info:
        railtherm.solve(scene, "flat-caps", level=0)
    assert info.value.kind == "validity"


def test_supports_is_the_plugins_hook_only():
    """The contract's default ``supports`` has no limits; the declared capabilities are core's to check."""
    transient = railtherm.load_scene(canonical("ellipse-full-sliding", mode="transient"))
    assert _with()().supports(transient, 0) is None
    assert capability_refusal(_with()(), transient) is not None
    assert not hasattr(railtherm.StageModel, "supports_source")


def test_declared_advice_is_appended():
    model = _with(peclet=(10.0, float("inf")), advice={"peclet": "use method 'fipy'"})()
    why = capability_refusal(model, railtherm.load_scene(_given(5.0)))
    assert why.endswith("use method 'fipy'")
    with pytest.raises(ValueError, match="unknown keys"):
        Capabilities(advice={"pecelt": "typo"})
    with pytest.raises(ValueError, match="convection"):
        Capabilities(convection="sometimes")


# -- modes and moving surfaces -------------------------------------------------------------------------
def test_modes_are_enforced_for_temperature_models():
    transient = railtherm.load_scene(canonical("ellipse-full-sliding", mode="transient"))
    why = capability_refusal(_with()(), transient)
    assert why is not None and "mode 'transient'" in why and "steady" in why
    assert capability_refusal(_with(modes=frozenset({"steady", "transient"}))(), transient) is None
    only_transient = _with(modes=frozenset({"transient"}))()
    why = capability_refusal(only_transient, railtherm.load_scene(canonical("ellipse-full-sliding")))
    assert why is not None and "not the scene's mode 'steady'" in why
    # contact and heat-source models are not temperature models: their modes are not checked
    from railtherm.models.hertz import HertzContact
    assert capability_refusal(HertzContact(), transient) is None


def test_moving_surface_is_enforced():
    scene = SimpleNamespace(name="still", contact_shape="ellipse", heat_source=None, tangential="full-sliding",
                            speed=0.0, sliding_speed=0.0, convection=0.0, mode="steady",
                            wheel=railtherm.Material(), rail=railtherm.Material())
    why = capability_refusal(_with(moving_surface=True)(), scene)
    assert why is not None and "wheel moves at 0 m/s" in why and "speed > 0" in why
    assert capability_refusal(_with()(), scene) is None


def test_methods_lists_what_core_enforces():
    text = _with(convection="long-term", peclet=(10.0, float("inf")), moving_surface=True).capabilities.describe()
    for part in ("enforced by core", "contacts=", "sources=", "tangential=", "modes=steady",
                 "convection=long-term", "Peclet 10..inf", "moving surfaces needed=yes"):
        assert part in text


def test_built_in_declarations():
    from railtherm_fem.model import FemModel
    from railtherm_fipy.model import FipyTemperature
    from railtherm_green.model import GreenTemperature
    from railtherm_green.validity import PECLET_MIN
    assert GreenTemperature.capabilities.convection == "long-term"   # only the lumped steady wheel
    assert GreenTemperature.capabilities.peclet == (PECLET_MIN, float("inf"))
    assert GreenTemperature.capabilities.moving_surface
    assert FipyTemperature.capabilities.moving_surface and FemModel.capabilities.moving_surface


# -- meta-test: no plugin re-checks a declared capability --------------------------------------------
#: what the plugins' supports() used to re-check by hand, now enforced by core
RECHECKS = {
    "mode": re.compile(r"\bscene\.mode\b|getattr\(scene,\s*['\"]mode['\"]"),
    "convection": re.compile(r"\bconvection\b"),
    "peclet": re.compile(r"peclet|Péclet|refusal\(", re.I),
    "moving surface": re.compile(r"\bspeed\b\s*(is None|>|<|==)|body_speeds|\.body_speed\b"),
    "capabilities": re.compile(r"capabilities\.(modes|convection|peclet|moving_surface)"),
}


def _supports_methods():
    for path in sorted((ROOT / "plugins").glob("*/**/*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef) and node.name == "supports":
                yield path, node, ast.get_source_segment(path.read_text(), node)


def test_no_plugin_supports_rechecks_a_declared_capability():
    found = list(_supports_methods())
    assert found, "no supports() found in plugins/"
    offences = []
    for path, node, src in found:
        body = ast.get_docstring(node)
        code = src.replace(body, "") if body else src
        for what, pattern in RECHECKS.items():
            if pattern.search(code):
                offences.append(f"{path.relative_to(ROOT)}:{node.lineno} re-checks {what}")
    assert not offences, offences


def test_no_plugin_hand_rolls_the_peclet_or_moving_surface_refusal():
    # the refusals come from core (railtherm.solving.capabilities_check); a plugin keeps only its own limits
    for path in sorted((ROOT / "plugins").glob("*/**/*.py")):
        text = path.read_text()
        assert "def refusal(" not in text, path
        assert "supports_source" not in text, path
        assert "needs its surface to move through the patch" not in text, path


def test_no_plugin_re_resolves_its_options():
    # core's pipeline hands compute methods the options resolved by StageModel.resolve_options
    for path in sorted((ROOT / "plugins").glob("*/**/*.py")):
        text = path.read_text()
        assert "resolve_options(" not in text and ".default for" not in text, path
