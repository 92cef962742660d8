"""Chains composed from stage models: ``[study.chains.<name>]`` in a study and a
mapping as ``method`` in railtherm.solve; unknown stages or models are SceneErrors naming the key."""
from __future__ import annotations

import textwrap

import pytest

import railtherm
from railtherm import SceneError
from railtherm.output import store
from railtherm.solving.plugins import get_host
from railtherm.testing import canonical

STUDY = textwrap.dedent('''
    schema_version = 1
    [study]
    name = "chains"
    methods = ["green", "hertz-fastsim-green"]
    levels = [0]
    [study.options.green]
    cells = 8
    depth_points = 81     # another temperature computation than the chain's (41): not a duplicate of green
    [study.chains.hertz-fastsim-green]
    normal = "hertz"
    tangential = ["fastsim"]
    temperature = "green"
    [[scene]]
    name = "ek"
    contact = { shape = "ellipse", semi_axes = [8e-3, 4e-3] }
    speed = 30.0
    normal_force = 5e4
    creepage = { longitudinal = -2e-3 }
    friction = 0.3
    outputs = ["max_surface_temperature", "creep_force_x"]
''')


@pytest.fixture
def needs_green_fastsim():
    have = get_host().models
    if not {"green", "fastsim"} <= set(have):
        pytest.skip("models 'green' and 'fastsim' are not installed")


def test_a_mapping_is_a_method(needs_green_fastsim):
    sc = canonical("ellipse-creepage", outputs=["max_surface_temperature", "creep_force_x"])
    a = railtherm.solve(sc, {"normal": "hertz", "tangential": "fastsim", "temperature": "green"}, 0)
    assert a.attrs["method"] == "hertz+fastsim+frictional+green"
    assert a.attrs["stages"] == "normal:hertz tangential:fastsim heat_source:frictional temperature:green"
    b = railtherm.solve(sc, "green", 0, {"cells": 8})   # the registered method with the same models and grid
    assert float(a.creep_force_x) == float(b.creep_force_x)
    assert float(a.max_surface_temperature.max()) == float(b.max_surface_temperature.max())


@pytest.mark.parametrize("chain, key, text", [
    ({"normal": "nope"}, "method.normal", "model 'nope' is not registered; normal models: "),
    ({"normall": "hertz"}, "method.normall", "unknown stage 'normall'; allowed stages: normal, tangential"),
    ({"normal": "green"}, "method.normal", "model 'green' implements ['temperature'], not 'normal'"),
    ({"normal": []}, "method.normal", "a model name or a list of them"),
    ({}, "method", "an empty chain"),
])
def test_a_bad_chain_is_a_scene_error(needs_green_fastsim, chain, key, text):
    with pytest.raises(SceneError) as err:
        railtherm.solve(canonical("ellipse-creepage"), chain, 0)
    assert err.value.key == key and text in str(err.value)


def test_a_study_runs_its_chains(needs_green_fastsim, tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    st = railtherm.load_study(path)
    assert st.chains == {"hertz-fastsim-green": {"normal": ("hertz",), "tangential": ("fastsim",),
                                                 "temperature": ("green",)}}
    m = railtherm.run_study(st, tmp_path / "out", report=False)
    assert sorted(m["method"].values.tolist()) == ["green", "hertz-fastsim-green"]
    runs = {r: store.open_run(tmp_path / "out", "ek", r, 0) for r in ("green", "hertz-fastsim-green")}
    assert runs["hertz-fastsim-green"].attrs["method"] == "hertz-fastsim-green"
    assert float(runs["green"].creep_force_x) == float(runs["hertz-fastsim-green"].creep_force_x)


@pytest.mark.parametrize("table, key", [
    ('[study.chains.x]\nnormall = "hertz"\n', "study.chains.x.normall"),
    ('[study.chains.x]\nnormal = 3\n', "study.chains.x.normal"),
    ('[study.chains.x]\nnormal = "nope"\n', "study.chains.x.normal"),
    ('[study.chains.green]\nnormal = "hertz"\n', "study.chains.green"),
])
def test_bad_study_chains_name_the_key(needs_green_fastsim, tmp_path, table, key):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("[[scene]]", table + "[[scene]]", 1).replace(
        'methods = ["green", "hertz-fastsim-green"]', 'methods = ["green"]').replace(
        '[study.chains.hertz-fastsim-green]\nnormal = "hertz"\ntangential = ["fastsim"]\ntemperature = "green"\n', ""))
    with pytest.raises(SceneError) as err:
        railtherm.run_study(railtherm.load_study(path), tmp_path / "out", report=False)
    assert err.value.key == key


def test_a_chains_run_hash_changes_with_its_plugins_versions(needs_green_fastsim, monkeypatch):
    """``--resume`` re-runs a study's chain when a plugin whose model it runs has a new version."""
    import dataclasses

    from railtherm.input.scene import load_scene
    from railtherm.run.runner import code_versions, run_hash
    sc = load_scene(canonical("ellipse-creepage"))
    chain = {"name": "c", "normal": ("hertz",), "tangential": ("fastsim",), "temperature": ("green",)}
    before = run_hash(sc, chain, 0, {})
    host = get_host()
    for model in ("fastsim", "green"):
        info = host.models[model]
        assert f"{info.plugin} {info.version} {model}" in code_versions(chain)
        with monkeypatch.context() as mp:
            mp.setitem(host.models, model, dataclasses.replace(info, version=info.version + ".post1"))
            assert run_hash(sc, chain, 0, {}) != before, model
    assert run_hash(sc, chain, 0, {}) == before
