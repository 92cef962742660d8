"""The Zarr result store (``[study] store = "zarr"``): vocabulary, values bit for bit equal to the run
files of the same study on every executor, lazy ``open_results``, chunk writes, a worker killed in the
middle of writing its chunk, ``--resume`` from the store itself, and fields kept on request.

Tiny sweeps of the fixture method ``flat`` (12 runs: 3 speeds x 2 sliding speeds x 2 levels, in 3 chunks of
2 scenes where a test asks for chunks) keep this fast; the serial pair of the same sweep (files and store) is computed once and is the reference of the
executor and fault tests.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import tomllib

import railtherm
from railtherm import SceneError
from railtherm.output import store, zarr_store
from railtherm.input.study import AUTO_ZARR_RUNS, parse_study

from test_executors import RAN, hosts, sweep  # noqa: F401 (hosts: the executors' fixture)

SCALAR_OUTPUTS = '["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "frictional_power"]'




#: the speeds of the default sweep here: with the 2 sliding speeds and 2 levels, 12 runs in 6 scenes
SPEEDS = [10.0, 11.0, 12.0]


def zsweep(path: Path, store_line='store = "zarr"', fields=True, **kw) -> Path:
    """The sweep of test_executors (speeds :data:`SPEEDS` unless given) with a store line in [study] (and
    without fields if asked)."""
    kw.setdefault("speeds", SPEEDS)
    p = sweep(path, **kw)
    text = p.read_text().replace("warmup = false", "warmup = false\n" + store_line)
    if not fields:
        text = text.replace(', "surface_temperature"', "")
    p.write_text(text)
    return p


def _doc(**study):
    """studies/sweep_10k.toml with two values per swept key (16 scenes): the store rules take the run count
    as an argument, so the full 10k expansion would only cost time."""
    p = Path(__file__).resolve().parents[1] / "studies" / "sweep_10k.toml"
    doc = tomllib.loads(p.read_text())
    doc["study"].update(study)
    sc = doc["scene"][0]
    for k, v in list(sc.items()):
        if isinstance(v, list) and k != "outputs":
            sc[k] = v[:2]
    return doc


# -- vocabulary ---------------------------------------------------------------------------------------
def test_store_and_keep_fields_vocabulary():
    assert parse_study(_doc(store="files")).store == "files"
    st = parse_study(_doc(store="zarr", keep_fields="finest"))
    assert st.store == "zarr" and st.keep_fields == "finest"
    with pytest.raises(SceneError, match=r"study.store.*'netcdf'.*\"files\".*\"zarr\""):
        parse_study(_doc(store="netcdf"))
    with pytest.raises(SceneError, match=r"study.keep_fields.*'all'.*true, false or \"finest\""):
        parse_study(_doc(keep_fields="all"))
    with pytest.raises(SceneError, match="study.keep_fields"):
        parse_study(_doc(keep_fields=1))
    with pytest.raises(SceneError, match=r"needs store = \"zarr\""):
        parse_study(_doc(store="files", keep_fields=True))


def test_default_store_rule():
    doc = _doc()
    doc["study"].pop("store", None)
    st = parse_study(doc)                       # scalar outputs only
    assert st.store is None
    assert st.store_for(AUTO_ZARR_RUNS) == "zarr" and st.store_for(AUTO_ZARR_RUNS - 1) == "files"
    doc["scene"][0]["outputs"] = ["max_surface_temperature", "surface_temperature"]   # a field
    assert parse_study(doc).store_for(10 * AUTO_ZARR_RUNS) == "files"
    doc["study"]["keep_fields"] = True
    assert parse_study(doc).store_for(1) == "zarr"
    assert parse_study(_doc(store="files")).store_for(10 ** 6) == "files"


def test_status_codes_are_the_store_statuses():
    assert zarr_store.STATUS_CODES == store.STATUSES


def test_chunks_are_whole_scenes_and_blocks_of_the_sweep():
    assert zarr_store.chunk_scenes(10_000, 1, (10, 10, 10, 10)) == 100       # 10k runs: 157 aimed at
    assert zarr_store.chunk_scenes(10 ** 6, 1, (100, 100, 100)) == 100       # at most 1000 runs
    assert zarr_store.chunk_scenes(50, 2, ()) == 1
    assert zarr_store.chunk_scenes(3, 4, ()) == 1
    cols = {"a": np.repeat([1.0, 2.0], 3), "b": np.tile([5.0, 6.0, 7.0], 2)}
    keys, values = zarr_store.cartesian(cols)
    assert keys == ["a", "b"] and [list(v) for v in values] == [[1.0, 2.0], [5.0, 6.0, 7.0]]
    assert zarr_store.cartesian({"a": np.array([1.0, 2.0, 1.0])}) is None
    assert zarr_store.cartesian({"a": cols["a"], "b": np.array([5.0, 6.0, 7.0, 5.0, 7.0, 6.0])}) is None


# -- values ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def pair(hosts, tmp_path_factory):
    """The same scalar sweep run serially into run files and into the Zarr store."""
    d = tmp_path_factory.mktemp("pair")
    files = railtherm.run_study(zsweep(d / "f.toml", "", fields=False), d / "files", report=False)
    zarr = railtherm.run_study(zsweep(d / "z.toml", fields=False), d / "zarr", report=False)
    assert not (d / "zarr" / "runs").exists() and zarr_store.is_zarr(d / "zarr")
    assert not zarr_store.is_zarr(d / "files")
    return d, files, zarr


def assert_same_values(a: Path, b: Path):
    """Every scalar, status and sweep coordinate of two output folders equal byte for byte."""
    x = railtherm.open_results(a, unstack=False).compute()
    y = railtherm.open_results(b, unstack=False).compute()
    assert sorted(x.data_vars) == sorted(y.data_vars) and x.sizes == y.sizes
    assert list(map(str, x["scene"].values)) == list(map(str, y["scene"].values))
    for name in x.data_vars:
        if name == "wall_time":
            continue
        vx, vy = x[name].values, y[name].values
        if vx.dtype.kind == "f":
            assert vx.tobytes() == vy.tobytes(), name
        else:
            assert list(map(str, vx.ravel())) == list(map(str, vy.ravel())), name
    for c in x.attrs["swept_parameters"].split():
        assert x[c].values.tobytes() == y[c].values.tobytes()
    return x


def test_zarr_store_matches_run_files_bit_for_bit(pair):
    d, files, zarr = pair
    x = assert_same_values(d / "files", d / "zarr")
    assert x.sizes["scene"] == 2 * len(SPEEDS) and set(x["status"].values.ravel()) == {"ok"}
    assert list(files["status"].values) == list(zarr["status"].values)          # metrics read the store alike
    for v in ("error_max_surface_temperature", "energy_balance", "headline_error"):
        assert files[v].values.tobytes() == zarr[v].values.tobytes(), v


def test_open_results_is_lazy_with_the_sweep_dimensions(pair):
    import dask.array as da
    d, *_ = pair
    ds = railtherm.open_results(d / "zarr")
    assert isinstance(ds["max_surface_temperature"].data, da.Array)
    assert ds["max_surface_temperature"].dims == ("speed", "sliding_speed", "method_name", "level", "body")
    t = ds.max_surface_temperature.sel(speed=11.0, sliding_speed=2.0, method_name="flat", level=1, body="wheel")
    f = railtherm.open_results(d / "files", unstack=True)
    ref = f.max_surface_temperature.sel(speed=11.0, sliding_speed=2.0, method_name="flat", level=1, body="wheel")
    assert float(t) == float(ref)
    assert str(ds["scene_name"].sel(speed=11.0, sliding_speed=2.0).values) == "map--speed=11,sliding_speed=2"
    # the data chunks hold under 1 kB per run, the metadata under 1 kB per array (12 runs, ~36 arrays)
    files = [p for p in (d / "zarr" / "results.zarr").rglob("*") if p.is_file()]
    meta = [p for p in files if p.name in (".zarray", ".zattrs", ".zgroup", ".zmetadata", "zarr.json")]
    arrays = sum(p.name in (".zarray", "zarr.json") for p in meta)
    data = sum(p.stat().st_size for p in files) - sum(p.stat().st_size for p in meta)
    assert data < 4 * len(SPEEDS) * 1024, data
    assert sum(p.stat().st_size for p in meta) < 1024 * arrays, (arrays, meta)


def test_store_runs_read_back_as_datasets(pair):
    d, *_ = pair
    ds = store.open_run(d / "zarr", "map--speed=12,sliding_speed=0.5", "flat", 0)
    ref = store.open_run(d / "files", "map--speed=12,sliding_speed=0.5", "flat", 0)
    for n in ("max_surface_temperature", "frictional_power", "normal_force"):
        assert ds[n].values.tobytes() == ref[n].values.tobytes() and ds[n].attrs["units"] == ref[n].attrs["units"]
    attrs = store.run_attributes(d / "zarr", "map--speed=12,sliding_speed=0.5", "flat", 0)
    assert attrs["stages"] == ref.attrs["stages"] and store.sweep_of(attrs) == {"speed": 12.0, "sliding_speed": 0.5}
    assert store.run_sweeps(d / "zarr")["map--speed=12,sliding_speed=0.5"] == {"speed": 12.0, "sliding_speed": 0.5}
    assert store.open_run(d / "zarr", "nope", "flat", 0) is None


@pytest.mark.parametrize("executor", ["processes", pytest.param("dask", marks=pytest.mark.slow)])
def test_executors_write_the_serial_store_bit_for_bit(pair, tmp_path, executor, monkeypatch):
    monkeypatch.setattr(zarr_store, "CHUNK_COUNT", len(SPEEDS))   # chunks of several scenes (2 of the 6)
    d, *_ = pair
    m = railtherm.run_study(zsweep(tmp_path / "z.toml", fields=False), tmp_path / "out", executor=executor,
                            workers=2, report=False)
    assert set(m["status"].values) <= RAN
    assert zarr_store.attrs(tmp_path / "out")["chunk_scenes"] > 1
    assert_same_values(d / "zarr", tmp_path / "out")


# -- faults and resume ---------------------------------------------------------------------------------
def _chunk_files(out: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in (out / "results.zarr").rglob("c/*") if p.is_file()}


def test_worker_killed_mid_write_then_resume(pair, tmp_path, monkeypatch):
    """The worker writing chunk 1 ends its process after the data and before the status, in both attempts:
    that chunk's runs are failed, no other chunk is touched, no temporary file is left, and resume
    (reading what is done from the store) completes the study without rewriting the other chunks; its
    values are those of the serial store of the same study (:func:`pair`)."""
    monkeypatch.setattr(zarr_store, "CHUNK_COUNT", len(SPEEDS))     # 3 chunks of 2 scenes
    study = zsweep(tmp_path / "z.toml", fields=False)
    out = tmp_path / "out"
    monkeypatch.setenv(zarr_store.FAULT_ENV, "4")
    m = railtherm.run_study(study, out, executor="processes", workers=2, report=False)
    assert zarr_store.attrs(out)["chunk"] == 4          # 2 scenes (the sliding speeds) x 2 levels
    failed = m["status"].values == "failed"
    assert np.flatnonzero(failed).tolist() == [4, 5, 6, 7]
    assert "worker process died" in str(m["message"].values[4])
    assert not list((out / "results.zarr").rglob("*.partial"))
    before = _chunk_files(out)
    monkeypatch.delenv(zarr_store.FAULT_ENV)
    m2 = railtherm.run_study(study, out, executor="processes", workers=2, resume=True, report=False)
    assert set(m2["status"].values) <= RAN
    after = _chunk_files(out)
    rewritten = {p.relative_to(out).as_posix() for p in set(before) | set(after) if after.get(p) != before.get(p)}
    assert rewritten and all(p.endswith("/c/1") or p.endswith("/c/1/0") for p in rewritten), rewritten
    assert_same_values(pair[0] / "zarr", out)
    third = _chunk_files(out)
    railtherm.run_study(study, out, resume=True, report=False)    # all done: nothing rewritten
    assert _chunk_files(out) == third


def test_run_killed_mid_chunk_is_retried_then_failed(hosts, tmp_path, monkeypatch):
    """A run whose worker dies (SIGKILL in the solve) takes its chunk's unwritten runs with it: they are
    retried once, then recorded failed; the other chunks are complete."""
    monkeypatch.setattr(zarr_store, "CHUNK_COUNT", len(SPEEDS))     # 3 chunks of 2 scenes
    study = zsweep(tmp_path / "z.toml", fields=False, methods='["sleepy"]',
                   options="[study.options.sleepy]\ndie_at_speed = 12.0\n")
    m = railtherm.run_study(study, tmp_path / "out", executor="processes", workers=2, report=False)
    st = m["status"].values
    assert np.flatnonzero(st == "failed").tolist() == [8, 9, 10, 11]   # the chunk of speed 12
    assert "worker process died" in str(m["message"].values[8])


# -- fields --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def field_files(hosts, tmp_path_factory):
    """Run files (with fields) of the two-speed sweep: the reference of both keep_fields cases."""
    d = tmp_path_factory.mktemp("fields")
    railtherm.run_study(zsweep(d / "f.toml", "", speeds=[10.0, 11.0]), d / "f", report=False)
    return d / "f"


@pytest.mark.parametrize("keep", ["true", '"finest"'])
def test_fields_kept_on_request(field_files, tmp_path, keep):
    study = zsweep(tmp_path / "z.toml", f'store = "zarr"\nkeep_fields = {keep}', speeds=[10.0, 11.0])
    railtherm.run_study(study, tmp_path / "z", report=False)
    s = "map--speed=11,sliding_speed=2"
    for level in (0, 1):
        got, ref = store.open_run(tmp_path / "z", s, "flat", level), store.open_run(field_files, s, "flat", level)
        if keep == "true" or level == 1:
            assert got["surface_temperature"].values.tobytes() == ref["surface_temperature"].values.tobytes()
            assert got["x"].values.tobytes() == ref["x"].values.tobytes()
        else:
            assert "surface_temperature" not in got
        assert got["max_surface_temperature"].values.tobytes() == ref["max_surface_temperature"].values.tobytes()


def test_without_keep_fields_no_field_is_stored(pair):
    d, *_ = pair
    assert not (d / "zarr" / "results.zarr" / "fields").exists()


# -- report ----------------------------------------------------------------------------------------------
def test_report_reads_the_store_and_draws_a_sweep_map(pair, tmp_path):
    """The report of a Zarr study (a copy of :func:`pair`'s store: 3 speeds x 2 sliding speeds): every run read
    through the store, one sweep map over the two swept keys whose cells are the worst status of the finest
    level (the flat fixture has no independent reference)."""
    import importlib
    L = importlib.import_module("railtherm.report.load")
    from railtherm.report import sweep_maps as S
    from railtherm.report import write_report
    d, *_ = pair
    shutil.copytree(d / "zarr", tmp_path / "z")
    write_report(tmp_path / "z", study=railtherm.load_study(d / "z.toml"))
    maps = list((tmp_path / "z" / "figures").glob("*-sweep-map-map.png"))
    assert len(maps) == 1 and "Sweep map of `map` over" in (tmp_path / "z" / "report.md").read_text()
    data = L.load(tmp_path / "z")
    assert data.run_attrs(data.scenes[0], "flat", 1)["stages"]
    kx, ky, vx, vy = S.axes_of(data, data.scenes)
    assert (kx, ky, vx, vy) == ("speed", "sliding_speed", SPEEDS, [0.5, 2.0])
    (kind, grid), = S.grids(data, data.scenes, kx, ky, vx, vy, ["flat"]).values()
    expect = np.full((2, 3), np.nan)
    for nm in data.scenes:
        sw = data.scene[nm].sweep
        expect[vy.index(sw[ky]), vx.index(sw[kx])] = S.STATUS_RANK[[r for r in data.runs_of(nm, "flat")
                                                                    if r.level == 1][0].status]
    assert kind == "status" and np.array_equal(grid, expect)


# -- every reference kind on a Zarr study -----------------------------------------------------------------
@pytest.mark.parametrize("reference", ["analytic", "finest", "flat"])
def test_every_reference_kind_scores_a_zarr_study(hosts, tmp_path, reference):
    """The store keeps no surface grid for a scalar sweep: the default reference ("analytic", whose exact fields
    are evaluated on the run's grid) raised KeyError 'x' in metrics and no metrics.nc was written."""
    p = zsweep(tmp_path / "s.toml", fields=False, speeds=[10.0, 20.0])
    p.write_text(p.read_text().replace('reference = "finest"', f'reference = "{reference}"'))
    m = railtherm.run_study(p, tmp_path / "out", report=False)
    assert zarr_store.is_zarr(tmp_path / "out") and store.metrics_path(tmp_path / "out").exists()
    assert m.sizes["run"] == 8 and set(m["status"].values) <= {"ok", "inaccurate", "unverified"}
    if reference == "analytic":   # flat's temperatures against the exact moving source: an independent check
        assert set(m["reference_max_surface_temperature"].values) == {"analytic:moving-source"}
        assert np.isfinite(m["headline_error"].values).all()
    assert "verdict_status" in m and m["verdict_status"].shape == (4, 1)
