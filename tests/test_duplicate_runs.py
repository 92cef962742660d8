"""No duplicate computations: a run whose executed stage models (class and resolved options) are another
study method's on the same scene computes that method's result, at most on another grid, and is refused
(validity) naming it (railtherm.solving.pipeline.duplicate_of, solve(..., peers=...)).

Reference: on a scene that gives its heat source, kalker runs no contact stage, only core's ``given`` and
green's temperature model; its 16-cell level 1 is green's 32-cell level 0 bit for bit."""
from __future__ import annotations

import numpy as np
import pytest

import railtherm
from railtherm import Capabilities, Method, Refused, TemperatureField, TemperatureModel, hookimpl
from railtherm.input.scene import load_scene
from railtherm.solving.pipeline import duplicate_of, solve
from railtherm.solving.plugins import get_host
from railtherm.testing import canonical
from studies import ELASTIC

GIVEN = canonical("ellipse-given-flux", outputs=["max_surface_temperature", "mean_contact_temperature"])
SLIDING = canonical("ellipse-full-sliding", outputs=["max_surface_temperature", "creep_force_x"])
CREEP = canonical("ellipse-creepage", outputs=["max_surface_temperature", "creep_force_x"])
STUDY = [("green", {}), ("kalker", {})]


@pytest.fixture
def green_kalker():
    if not {"green", "kalker"} <= set(get_host().methods):
        pytest.skip("methods 'green' and 'kalker' are not installed")


def test_kalker_on_a_given_heat_source_is_greens_computation(green_kalker):
    a = solve(GIVEN, "kalker", 1)
    b = solve(GIVEN, "green", 0)
    assert a.attrs["stages"] == b.attrs["stages"] == "heat_source:given temperature:green"
    np.testing.assert_array_equal(a.surface_temperature.values, b.surface_temperature.values)


def test_kalker_is_refused_where_it_would_repeat_green(green_kalker):
    why = duplicate_of(load_scene(GIVEN), "kalker", 0, STUDY)
    assert why.startswith("method 'kalker' runs no stage of its own on scene 'ellipse-given-flux'")
    assert why.endswith("its result is green's (method 'green' runs the same models)")
    with pytest.raises(Refused, match="runs no stage of its own.*its result is green's") as err:
        solve(GIVEN, "kalker", 0, peers=STUDY)
    assert err.value.kind == "validity"
    # green keeps the computation (its own temperature model), whatever the order of the study
    assert duplicate_of(load_scene(GIVEN), "green", 0, STUDY[::-1]) is None
    assert float(solve(GIVEN, "green", 0, peers=STUDY).max_surface_temperature.max()) > 0


def test_a_method_with_a_contact_stage_of_its_own_runs(green_kalker):
    for raw in (SLIDING, CREEP):
        assert duplicate_of(load_scene(raw), "kalker", 0, STUDY) is None
        assert duplicate_of(load_scene(raw), "green", 0, STUDY) is None


def test_a_study_chain_that_is_a_methods_chain_is_refused_and_options_tell_them_apart(green_kalker):
    if "fastsim" not in get_host().models:
        pytest.skip("model 'fastsim' is not installed")
    chain = {"name": "hertz-fastsim-green", "normal": "hertz", "tangential": "fastsim", "temperature": "green"}
    peers = [("green", {}), (chain, {})]
    sc = load_scene(CREEP)
    assert "its result is green's" in duplicate_of(sc, chain, 0, peers)
    assert duplicate_of(sc, "green", 0, peers) is None
    # another option of a model the chain runs: another computation, both run
    other = [("green", {"depth_points": 81}), (chain, {})]
    assert duplicate_of(sc, chain, 0, other) is None
    # on a full-sliding scene green runs full-sliding, the chain FASTSIM: different computations
    assert duplicate_of(load_scene(SLIDING), chain, 0, peers) is None


class Flat(TemperatureModel):
    """Test fake: surface rise proportional to the heat flux [K per W/m^2 x 1e-6]."""

    name = "flat-dup"
    description = "test fake: rise = 1e-6 x flux"
    capabilities = Capabilities(provides=frozenset({"surface_temperature", "max_surface_temperature"}))

    def compute_temperature(self, scene, source, level, options):
        q = np.stack([source.flux(0), source.flux(1)])
        return TemperatureField.from_surface(source.grid, 1e-6 * q)


class TwinPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [Flat]

    @hookimpl
    def railtherm_register_methods(self):
        return [Method(n, {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": ("flat-dup",)})
                for n in ("twin-a", "twin-b")]


def test_two_methods_of_one_plugin_with_the_same_models_run_once(railtherm_register):
    railtherm_register("twins", TwinPlugin())
    peers = [("twin-b", {}), ("twin-a", {})]
    sc = load_scene(SLIDING | {"outputs": ["max_surface_temperature"]})
    assert duplicate_of(sc, "twin-b", 0, peers) is None                    # first in the study's order
    why = duplicate_of(sc, "twin-a", 0, peers)
    assert why.startswith("method 'twin-a' runs the same stage models as method 'twin-b'")
    with pytest.raises(Refused, match="its result is twin-b's"):
        railtherm.solve(sc, "twin-a", 0, peers=peers)


def test_a_study_refuses_kalker_on_a_given_heat_source_and_does_not_score_it(green_kalker, tmp_path):
    study = tmp_path / "study.toml"
    study.write_text('''schema_version = 1
[study]
name = "dup"
methods = ["green", "kalker"]
levels = [0]
repeat = 1
''' + ELASTIC + '''[[scene]]
name = "given"
speed = 1.0
heat_source = { flux = 1e6, shape = "uniform", semi_axes = [4e-3, 4e-3] }
heat_partition = 0.0
outputs = ["max_surface_temperature"]
''')
    m = railtherm.run_study(railtherm.load_study(study), tmp_path / "out", report=False)
    status = dict(zip(m["method"].values.tolist(), m["status"].values.tolist()))
    assert status["kalker"] == "refused" and status["green"] != "refused"
    message = dict(zip(m["method"].values.tolist(), m["message"].values.tolist()))["kalker"]
    assert "runs no stage of its own" in message and "its result is green's" in message
