"""A result with several patches (``wheelset.patch = "all"``, a ``patch`` dimension) is scored patch by patch
(railtherm.analysis.patch_metrics): each patch's error on its own scale, the metric's error the largest over the
patches, the patch named; metrics.nc carries ``headline_patch`` and ``patch_errors_<metric>``."""
from __future__ import annotations

import copy
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.analysis.errors import run_errors
from railtherm.analysis.patch_metrics import patch_errors
from railtherm.output import store

from manchester_cases import a22_scene

BULK = 20.0
SCENE = SimpleNamespace(name="p", wheel=SimpleNamespace(bulk_temperature=BULK),
                        rail=SimpleNamespace(bulk_temperature=BULK), creepage=None, wheelset=None, heat_source=None,
                        contact_shape="gap", speed=30.0, sliding_speed=None, tangential="creepage")
#: the bulk temperatures (wheel, rail) [degC] the patch errors take the rises above
BULKS = (BULK, BULK)


def _result(temps, fx, patches=(1, 2), stages="normal:a tangential:b"):
    """A stand-in result: max_surface_temperature(body, patch) [degC] and creep_force_x(patch) [N]."""
    return xr.Dataset({"max_surface_temperature": (("body", "patch"), np.asarray(temps, float)),
                       "creep_force_x": (("patch",), np.asarray(fx, float))},
                      coords={"body": ["wheel", "rail"], "patch": list(patches)},
                      attrs={"stages": stages})


def test_a_small_patch_off_by_half_is_not_hidden_by_a_large_one():
    """Tread patch rise 200 K exact, flange patch rise 20 K computed as 30 K: one max-norm over (body, patch)
    gives 10 / 200 = 5 %; per patch the flange patch is 50 % off, and that is the metric's error, on patch 2."""
    ref = _result([[BULK + 200, BULK + 20], [BULK + 150, BULK + 15]], [1000.0, 100.0])
    run = _result([[BULK + 200, BULK + 30], [BULK + 150, BULK + 15]], [1000.0, 100.0])
    errs = {"max_surface_temperature": (0.05, "method:k")}
    signed, row = {}, {}
    patch_of = patch_errors(BULKS, run, ref, errs, signed=signed, row=row, headline="max_surface_temperature")
    assert errs["max_surface_temperature"] == (pytest.approx(0.5), "method:k")
    assert signed["max_surface_temperature"] == pytest.approx(0.5)
    assert patch_of == {"max_surface_temperature": 2} and row["headline_patch"] == 2
    assert row["patch_errors_max_surface_temperature"] == "1: 0; 2: 0.5"


def test_the_per_patch_scores_replace_run_errors_max_norm():
    """run_errors (one max-norm over (body, patch)) and then patch_errors on the same runs: creep force 5 % off
    on the small patch is 0.5 % of the large patch's force; per patch it is 5 %, signed negative."""
    ref = _result([[BULK + 200, BULK + 20], [BULK + 150, BULK + 15]], [1000.0, 100.0],
                  stages="normal:kalker tangential:kalker heat_source:frictional temperature:green")
    run = _result([[BULK + 200, BULK + 20], [BULK + 150, BULK + 15]], [1000.0, 95.0],
                  stages="normal:wheelset-profile tangential:fastsim heat_source:frictional temperature:fdm")
    notes, signed = {}, {}
    errs = run_errors(SCENE, run, {}, ref, ref_tag="method:k", notes=notes, signed=signed)
    assert errs["creep_force_x"][0] == pytest.approx(0.005)
    patch_errors(BULKS, run, ref, errs, notes=notes, signed=signed, headline="max_surface_temperature")
    assert errs["creep_force_x"] == (pytest.approx(0.05), "method:k")
    assert signed["creep_force_x"] == pytest.approx(-0.05)
    assert errs["max_surface_temperature"][0] == 0.0


def test_a_patch_with_a_zero_reference_is_noted_and_the_others_scored():
    ref = _result([[BULK + 200, BULK], [BULK + 150, BULK]], [1000.0, 0.0])
    run = _result([[BULK + 210, BULK + 1], [BULK + 150, BULK]], [1000.0, 3.0])
    notes, row = {}, {}
    errs = {"max_surface_temperature": (0.05, "method:k"), "creep_force_x": (0.003, "method:k")}
    patch_errors(BULKS, run, ref, errs, notes=notes, row=row, headline="max_surface_temperature")
    assert errs["max_surface_temperature"][0] == pytest.approx(0.05)
    assert errs["creep_force_x"][0] == 0.0 and row["headline_patch"] == 1
    assert "reference is zero" in notes["creep_force_x patch 2"]
    assert "reference is zero" in notes["max_surface_temperature patch 2"]


def test_runs_with_other_patches_than_the_reference_fail_the_metric():
    ref = _result([[BULK + 200], [BULK + 150]], [1000.0], patches=(1,))
    run = _result([[BULK + 200, BULK + 20], [BULK + 150, BULK + 15]], [1000.0, 100.0])
    notes = {}
    errs = {"creep_force_x": (0.0, "method:k")}
    patch_errors(BULKS, run, ref, errs, notes=notes)
    assert math.isinf(errs["creep_force_x"][0]) and "[1, 2]" in notes["creep_force_x"]


def test_a_result_without_patches_is_left_as_it_is():
    ds = xr.Dataset({"creep_force_x": ((), 5.0)})
    errs = {"creep_force_x": (0.01, "method:k")}
    row = {}
    assert patch_errors(BULKS, ds, ds, errs, row=row) == {} and errs == {"creep_force_x": (0.01, "method:k")}
    assert "headline_patch" not in row


def test_a_study_of_several_patches_scores_them_patch_by_patch(tmp_path):
    """A-2.2 position 11 right, patch = "all" (two patches), Hertz + FASTSIM against kalker's exact chain at
    level 0: metrics.nc's creep-force error is the larger of the two patches' own errors (recomputed here from the
    run files), its patch is named, and both patches' errors are listed."""
    s = copy.deepcopy(a22_scene(11, "right"))
    s["wheelset"].update(patch="all")
    ws = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in s["wheelset"].items())
    study = tmp_path / "patches.toml"
    study.write_text(f'schema_version = 1\n[study]\nname = "patches"\nmethods = ["equivalent", "exact"]\n'
                     f'levels = [0]\nrepeat = 1\nwarmup = false\nreference = "exact"\n'
                     f'[study.chains.equivalent]\nnormal = "wheelset-profile"\ntangential = "fastsim"\n'
                     f'[study.chains.exact]\nnormal = "kalker"\ntangential = "kalker"\n'
                     f'[[scene]]\nname = "p11"\nspeed = {s["speed"]}\nfriction = {s["friction"]}\n'
                     f'outputs = ["normal_force", "max_pressure", "creep_force_x", "creep_force_y"]\n'
                     f'wheel = {{ shear_modulus = 82e9, poisson_ratio = 0.28 }}\n'
                     f'rail = {{ shear_modulus = 82e9, poisson_ratio = 0.28 }}\nwheelset = {{ {ws} }}\n')
    out = tmp_path / "out"
    railtherm.run_study(str(study), out=out, executor="serial", report=False)
    recs = {r["method"]: r for r in json.loads(store.study_path(out).read_text())["records"]}
    assert recs["equivalent"]["status"] != "failed" and recs["exact"]["status"] != "failed", recs
    with xr.open_dataset(out / "runs" / "p11" / "equivalent" / "level-0.nc") as run, \
            xr.open_dataset(out / "runs" / "p11" / "exact" / "level-0.nc") as ref:
        assert run.sizes["patch"] == ref.sizes["patch"] == 2
        own = [abs(float(run.creep_force_x[k]) / float(ref.creep_force_x[k]) - 1) for k in range(2)]
        whole = float(np.max(np.abs(run.creep_force_x - ref.creep_force_x)) / np.max(np.abs(ref.creep_force_x)))
    m = store.read_metrics(out)
    i = [str(v) for v in m.method.values].index("equivalent")
    assert float(m["error_creep_force_x"].values[i]) == pytest.approx(max(own), rel=1e-9)
    assert max(own) != pytest.approx(whole, rel=1e-3)         # the per-patch score is not the max-norm's
    assert int(m["headline_patch"].values[i]) == 1 + int(np.argmax(own))   # headline: creep_force_x
    listed = str(m["patch_errors_creep_force_x"].values[i])
    assert [float(t.split(": ")[1]) for t in listed.split("; ")] == pytest.approx(own, rel=1e-3)
