"""The fields of a result of several patches (a wheelset on profiles with ``wheelset.patch = "all"``), each patch
on its own grid (:mod:`railtherm.contract.patch_grid`): each patch's pressure is the chain's own solve of that
patch's scene, bit for bit, its cell-averaged pressure integrates to the patch's normal force (the share of the
wheel's load, 8.16 and 1.47 kN at A-2.2 position 11 right), the padding is NaN, and the result is written and
read back by :mod:`railtherm.output.store` unchanged and valid."""
from __future__ import annotations

import copy

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm import SceneError
from railtherm.analysis.errors import run_errors
from railtherm.contract.patch_grid import patch_field, patch_numbers
from railtherm.contract.schema import validate_dataset
from railtherm.input.scene import load_scene
from railtherm.input.wheelset_patch_scenes import patch_scenes
from railtherm.output import store, zarr_store

from manchester_cases import a22_scene

CHAIN = {"normal": "wheelset-profile", "tangential": "fastsim"}
OUTPUTS = ["normal_force", "max_pressure", "contact_angle", "pressure"]


def _all(position=11, side="right", outputs=OUTPUTS):
    s = copy.deepcopy(a22_scene(position, side))
    s["wheelset"].update(patch="all")
    s["outputs"] = list(outputs)
    return load_scene(s)


@pytest.fixture(scope="module")
def solved():
    scene = _all()
    return scene, railtherm.solve(scene, CHAIN, level=0)


def test_each_patch_keeps_the_pressure_of_its_own_solve(solved):
    """Position 11 right: two patches; each patch's field on its own grid is the chain's solve of that patch's
    scene (its gap, share of the load, creepages), values and grid bit for bit."""
    scene, r = solved
    assert patch_numbers(r) == [1, 2] and r["pressure"].dims == ("x", "y", "patch")
    for k, sub in enumerate(patch_scenes(scene, OUTPUTS), 1):
        one = railtherm.solve(sub, CHAIN, level=0)
        mine = patch_field(r, "pressure", k)
        assert mine.dims == ("x", "y")
        np.testing.assert_array_equal(mine["x"].values, one["x"].values)
        np.testing.assert_array_equal(mine["y"].values, one["y"].values)
        np.testing.assert_array_equal(mine.values, one["pressure"].values)
        assert mine["x"].attrs["units"] == "m" and mine.attrs["units"] == "Pa"


def test_each_patch_pressure_carries_its_share_of_the_load(solved):
    """The cell-averaged pressure times the cell area sums to the patch's normal force (1e-9): 8.16 kN on the
    flange root, 1.47 kN on the tread, not the wheel's 10 kN each."""
    _, r = solved
    forces = []
    for k in (1, 2):
        p = patch_field(r, "pressure", k)
        dx, dy = float(p["x"][1] - p["x"][0]), float(p["y"][1] - p["y"][0])
        force = float(p.sum()) * dx * dy
        assert force == pytest.approx(float(r["normal_force"].sel(patch=k)), rel=1e-9)
        forces.append(force)
    assert forces[0] == pytest.approx(8.16e3, abs=10) and forces[1] == pytest.approx(1.47e3, abs=10)


def test_the_padding_beyond_a_patch_is_nan(solved):
    """A patch's field and its grid coordinates are NaN beyond its cells and finite on them; the attribute
    nan_allowed names the padded field."""
    _, r = solved
    for d in ("x", "y"):
        c = r[f"patch_{d}"]
        assert c.dims == (d, "patch") and c.attrs["units"] == "m" and c.attrs["long_name"]
    for k in (1, 2):
        n = {d: int(np.isfinite(r[f"patch_{d}"].sel(patch=k)).sum()) for d in ("x", "y")}
        p = r["pressure"].sel(patch=k).values
        assert np.isfinite(p[:n["x"], :n["y"]]).all() and np.isnan(p[n["x"]:, :]).all() and np.isnan(
            p[:, n["y"]:]).all()
    assert r["pressure"].isnull().any() and "pressure" in r.attrs["nan_allowed"].split()


def test_written_and_read_back_through_the_store(solved, tmp_path):
    """The run file holds the padded field, its per-patch grid coordinates and their CF attributes; read back it
    is valid and each patch's field is the one written."""
    _, r = solved
    path = store.write_dataset_atomic(r, tmp_path / "level-0.nc")
    back = store.open_dataset(path)
    validate_dataset(back, "wheelset-profile+fastsim")
    assert set(back.coords) == {"patch", "patch_x", "patch_y", "body"} - ({"body"} - set(r.coords))
    for k in (1, 2):
        xr.testing.assert_identical(patch_field(back, "pressure", k), patch_field(r, "pressure", k))
    assert back["patch_x"].attrs == r["patch_x"].attrs and back["pressure"].attrs["units"] == "Pa"


def test_written_and_read_back_as_the_zarr_store_keeps_fields(solved, tmp_path):
    """``[study] store = "zarr"`` with ``keep_fields``: the run's fields group holds each patch's field and grid."""
    _, r = solved
    zarr_store.write_fields(tmp_path, 0, "chain", 0, r)
    back = zarr_store.read_fields(tmp_path, 0, "chain", 0)
    for k in (1, 2):
        xr.testing.assert_identical(patch_field(back, "pressure", k), patch_field(r, "pressure", k))


def test_patch_field_of_a_result_without_patches_and_of_a_missing_patch(solved):
    _, r = solved
    single = patch_field(r, "pressure", 2).to_dataset(name="pressure")
    xr.testing.assert_identical(patch_field(single, "pressure"), single["pressure"])
    assert "comment" not in single["pressure"].attrs          # the padding's comment is not the patch's
    with pytest.raises(ValueError, match=r"result field 'pressure': patch 3 is not one of its patches \[1, 2\]"):
        patch_field(r, "pressure", 3)


def test_a_field_of_several_patches_is_not_scored_as_one_grid(solved):
    """metrics: pressure_l2 of a result of several patches is not scored (each patch on its own grid), with a
    note, while its scalars are."""
    scene, r = solved
    notes = {}
    errs = run_errors(scene, r, {}, ref_ds=r, ref_tag="self:finest", notes=notes)
    assert "pressure_l2" not in errs and "each on its own grid" in notes["pressure_l2"]
    assert "max_pressure" in errs


def test_a_field_in_a_scene_of_several_patches_is_accepted():
    assert "pressure" in _all(outputs=["normal_force", "pressure", "surface_temperature"]).outputs
    with pytest.raises(SceneError, match=r"key 'outputs' = 'pass_peak_temperature' is not allowed"):
        _all(outputs=["normal_force", "pass_peak_temperature"])
