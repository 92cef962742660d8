"""railtherm.output.store, the output folder's one owner: layout, atomic writes, reader, run and crash records."""
import json
from types import SimpleNamespace

import numpy as np
import xarray as xr

from railtherm.output import store


def test_layout(tmp_path):
    nc = store.run_path(tmp_path, "flat", "green", 2)
    assert nc == tmp_path / "runs" / "flat" / "green" / "level-2.nc"
    assert store.status_path(nc) == nc.with_name("level-2.status.json")
    assert store.metrics_path(tmp_path) == tmp_path / "metrics.nc"
    assert store.references_path(tmp_path) == tmp_path / "references.nc"
    assert store.study_path(tmp_path) == tmp_path / "study.json"
    assert store.figures_dir(tmp_path) == tmp_path / "figures"
    assert store.run_files(tmp_path) == [] and store.status_files(tmp_path) == []


def test_atomic_writes_leave_no_temporary_file(tmp_path):
    p = tmp_path / "a" / "b.txt"
    store.write_text_atomic(p, "héllo\n")
    assert p.read_text(encoding="utf-8") == "héllo\n"
    store.write_json_atomic(tmp_path / "s.json", {"x": 1}, indent=1)
    assert store.read_json(tmp_path / "s.json") == {"x": 1}

    def boom(tmp):
        tmp.write_bytes(b"half")
        raise RuntimeError("killed")
    try:
        store.write_atomic(p, boom)
    except RuntimeError:
        pass
    assert p.read_text(encoding="utf-8") == "héllo\n"  # the old file stays whole
    assert not list(p.parent.glob(".*.tmp"))


def test_dataset_round_trip_and_fast_readers(tmp_path):
    ds = xr.Dataset({"max_surface_temperature": (("body",), np.array([1.5, np.nan]), {"units": "K"}),
                     "normal_force": ((), 7.0, {"units": "N"}),
                     "profile": (("x",), np.arange(3.0), {"units": "K"})},
                    coords={"body": ("body", ["wheel", "rail"]), "x": ("x", np.arange(3.0))},
                    attrs={"scene": "flat", "method": "m", "level": 0, "sweep": store.encode_sweep({"friction": 0.3})})
    p = store.run_path(tmp_path, "flat", "m", 0)
    store.write_dataset_atomic(ds, p)
    assert store.read_attrs(p)["scene"] == "flat"
    back = store.open_run(tmp_path, "flat", "m", 0)
    xr.testing.assert_identical(back[["max_surface_temperature", "normal_force"]],
                                ds[["max_surface_temperature", "normal_force"]])
    assert store.open_run(tmp_path, "flat", "m", 1) is None
    attrs, vals = store.read_run_scalars(p)
    assert set(vals) == {"max_surface_temperature", "normal_force"} and attrs["level"] == 0
    assert store.run_files(tmp_path) == [p]
    assert store.run_sweeps(tmp_path) == {"flat": {"friction": 0.3}}


def test_crash_record_is_stored_and_read_back(tmp_path):
    task = SimpleNamespace(scene=SimpleNamespace(name="flat", hash="h", sweep={"friction": 0.3}), method="m",
                           level=1, path=store.run_path(tmp_path, "flat", "m", 1), run_hash="rh", run_id="id")
    rec = store.crash_record(task, "worker process died", "error")
    assert rec.status == "failed" and rec.reason_kind == "error"
    assert json.dumps(store.read_status(task.path).to_dict()) == json.dumps(rec.to_dict())  # NaN included
    assert store.status_files(tmp_path) == [store.status_path(task.path)]


def test_stale_temporary_files_are_removed(tmp_path):
    (tmp_path / ".level-0.nc.1.2.tmp").write_bytes(b"")
    (tmp_path / "level-0.nc").write_bytes(b"")
    store.remove_stale_tmp([tmp_path])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["level-0.nc"]


def test_reference_curves_file_written_in_one_session_reads_back_as_written(tmp_path):
    """write_references fills every group in one netCDF4 session (the per-group append of xarray reopened
    the file each time: 200 scenes took 51 s); each group reads back equal to its Dataset."""
    import xarray as xr
    from railtherm.output.store import read_references, write_references
    groups = {}
    for i in range(3):
        x = np.linspace(-1e-3, 1e-3, 5 + i)
        groups[f"s{i:04d}_scene_{i}"] = xr.Dataset(
            {"surface_temperature": (("body", "x"), np.vstack([x * 1e3 + i, x]), {"units": "degC"}),
             "peak": ((), 3.5 + i, {"units": "K"})},
            coords={"x": ("x", x, {"units": "m"}), "body": ("body", np.array(["wheel", "rail"]))},
            attrs={"scene": f"scene-{i}", "reference": "exact"})
    path = write_references(tmp_path / "references.nc", {"study": "t", "scenes": 3}, groups)
    back = read_references(path)
    assert sorted(back) == [f"scene-{i}" for i in range(3)]
    for name, ds in groups.items():
        xr.testing.assert_identical(back[ds.attrs["scene"]], ds)
