"""Input validation before anything runs: method options (railtherm.contract.options.check_options), a whole
study (check_study: methods, option tables, keys and values, references, levels) and the study file
itself (load_study: a folder, a non-UTF-8 or missing file, a TOML syntax error). Every error is a
railtherm.SceneError whose message names the key, the value and what is allowed."""
from __future__ import annotations

import pytest

import railtherm
from railtherm import SceneError
from railtherm.contract.options import check_options, check_study
from railtherm.input.study import load_study, parse_study
from railtherm.testing import canonical

STUDY = {
    "schema_version": 1,
    "study": {"name": "v", "methods": ["flat"], "levels": [0, 1]},
    "defaults": {"wheel": {"shear_modulus": 82e9}, "rail": {"shear_modulus": 82e9}},
    "scene": [{"name": "ek", "normal_force": 100e3, "contact": {"shape": "ellipse", "semi_axes": [5.88e-3, 10.54e-3]},
               "speed": 30.0, "sliding_speed": 1.0, "friction": 0.3}],
}


def study(**changes):
    import copy
    doc = copy.deepcopy(STUDY)
    scene = changes.pop("scene", None)
    doc["study"].update(changes)
    if scene:
        doc["scene"][0].update(scene)
    return parse_study(doc)


# ---------------------------------------------------------------------------------------------
# check_options
def test_unknown_option_names_key_method_and_sorted_allowed(flat_host):
    mi = flat_host.methods["flat"]
    with pytest.raises(SceneError) as e:
        check_options(mi, {"scael": 2e-6}, method="flat")
    msg = str(e.value)
    assert "'scael'" in msg and "'flat'" in msg and "allowed: cells, scale" in msg, msg
    assert e.value.key == "scael" and e.value.value == 2e-6


def test_option_values_are_validated_by_the_models(flat_host):
    mi = flat_host.methods["flat"]
    with pytest.raises(SceneError, match=r"'scale'.*-1"):
        check_options(mi, {"scale": -1.0})
    assert check_options(mi, {"scale": 2e-6}) == {"scale": 2e-6}
    assert check_options(mi, None) == {}


@pytest.mark.parametrize("cells", [0, -4, 2.5, True, "8", float("nan")])
def test_cells_must_be_a_positive_integer(flat_host, cells):
    with pytest.raises(SceneError, match=r"'cells'.*an integer >= 1"):
        check_options(flat_host.methods["flat"], {"cells": cells})


def test_cells_accepts_integers(flat_host):
    assert check_options(flat_host.methods["flat"], {"cells": 8})["cells"] == 8
    assert check_options(flat_host.methods["flat"], {"cells": 8.0})["cells"] == 8


def test_where_prefixes_the_key(flat_host):
    with pytest.raises(SceneError) as e:
        check_options(flat_host.methods["flat"], {"scale": -1.0}, where="study.options.flat")
    assert e.value.key == "study.options.flat.scale" and "'study.options.flat.scale'" in str(e.value)


def test_solve_rejects_an_unknown_option(flat_host):
    """Before: an unknown option was silently ignored by railtherm.solve."""
    with pytest.raises(SceneError, match=r"'scael'.*allowed: cells, scale"):
        railtherm.solve(canonical("ellipse-full-sliding"), "flat", 0, options={"scael": 1.0})


def test_builtin_green_options(railtherm_register):
    pytest.importorskip("railtherm_green")
    import railtherm_green.plugin as green_plugin
    host = railtherm_register("green", green_plugin)
    with pytest.raises(SceneError, match=r"unknown option 'patition'.*'green'.*allowed: .*partition"):
        check_options(host.methods["green"], {"patition": "x"})
    assert check_options(host.methods["green"], {"cells": 16}) == {"cells": 16}


# ---------------------------------------------------------------------------------------------
# check_study
def test_a_good_study_passes(flat_host):
    check_study(study(), flat_host)
    check_study(study(reference="finest"), flat_host)
    check_study(study(reference="broken", options={"flat": {"scale": 2e-6, "cells": 8}}), flat_host)
    check_study(study(scene={"reference": "flat"}), flat_host, methods=["flat", "broken"], levels=[0, 2])


@pytest.mark.parametrize("changes,methods,levels,key,value", [
    ({"methods": ["flat", "falt"]}, None, None, "study.methods", "falt"),
    ({}, ["flat", "nope"], None, "methods", "nope"),
    ({"options": {"gren": {"cells": 8}}}, None, None, "study.options.gren", "gren"),
    ({"options": {"flat": {"scael": 1.0}}}, None, None, "study.options.flat.scael", 1.0),
    ({"options": {"flat": {"scale": -1.0}}}, None, None, "study.options.flat.scale", -1.0),
    ({"options": {"flat": {"cells": 0}}}, None, None, "study.options.flat.cells", 0),
    ({"reference": "analytical"}, None, None, "study.reference", "analytical"),
    ({"scene": {"reference": "analytical"}}, None, None, "reference", "analytical"),
    ({}, None, [-1], "levels", -1),
    ({}, None, [0, 1.5], "levels", 1.5),
    ({}, None, [], "levels", []),
])
def test_study_errors_name_key_value_and_allowed(flat_host, changes, methods, levels, key, value):
    st = study(**changes)
    with pytest.raises(SceneError) as e:
        check_study(st, flat_host, methods=methods, levels=levels)
    assert e.value.key == key and e.value.value == value, (e.value.key, e.value.value, str(e.value))
    msg = str(e.value)
    assert f"'{key}'" in msg
    if key.startswith("study.options.gren") or "methods" in key or "reference" in key:
        assert "broken, flat" in msg, msg  # the installed methods are listed
    if "reference" in key:
        assert '"analytic", "finest"' in msg
        if key == "reference":
            assert "scene 'ek'" in msg


def test_study_levels_are_checked_when_built_by_hand(flat_host):
    st = study()
    st.levels = [0, -2]
    with pytest.raises(SceneError, match=r"'study.levels'.*-2"):
        check_study(st, flat_host)


# ---------------------------------------------------------------------------------------------
# load_study on unusable paths and bad TOML
GOOD_TOML = """
schema_version = 1
[study]
name = "t"
[[scene]]
name = "a"
normal_force = 1e5
contact = { shape = "ellipse", semi_axes = [5e-3, 5e-3] }
speed = 30.0
sliding_speed = 1.0
friction = 0.3
"""


def test_load_study_of_a_folder(tmp_path):
    with pytest.raises(SceneError, match=r"is a folder, not a study file"):
        load_study(tmp_path)


def test_load_study_of_a_non_utf8_file(tmp_path):
    p = tmp_path / "latin1.toml"
    p.write_bytes(GOOD_TOML.replace('"t"', '"caf\u00e9"').encode("latin-1"))
    with pytest.raises(SceneError, match=r"latin1.toml.*not UTF-8"):
        load_study(p)


def test_load_study_of_a_missing_file(tmp_path):
    with pytest.raises(SceneError, match=r"nothere.toml.*does not exist"):
        load_study(tmp_path / "nothere.toml")


def test_load_study_toml_syntax_error_names_the_line(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(GOOD_TOML.replace("speed = 30.0", "speed = = 30.0"))
    with pytest.raises(SceneError, match=r"bad.toml.*not valid TOML.*line 9"):
        load_study(p)


def test_load_study_good_file(tmp_path):
    p = tmp_path / "good.toml"
    p.write_text(GOOD_TOML)
    assert load_study(p).name == "t"
