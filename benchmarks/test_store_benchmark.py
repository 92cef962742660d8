"""Benchmark (opt-in: ``-m benchmark``): the 10k sweep (studies/sweep_10k.toml) with the Zarr store on 2 local
worker processes, against the per-file store in the same session.

Asserted: store size per run (< 1 kB) and in all (< 10 MB), chunk write time per run (< 1 ms), values identical
bit for bit to a serial per-file run (on the first 200 scenes, which the per-file store writes in the default
time). Recorded, not asserted (a wall time measures the machine's load as much as the code): the wall time of the
whole study (the benchmark's own timing, one round), with the load average before it, the CPU time and the phases
in ``extra_info`` (68 s on a 2-core machine: runs 41 s, metrics 23 s). The per-file store's wall time over the 10 000 runs
is measured too (``RAILTHERM_BENCH_FILES_10K=1``: 100 s more).

    OPENBLAS_NUM_THREADS=1 python -m pytest -m benchmark -s benchmarks/test_store_benchmark.py
"""
from __future__ import annotations

import json
import os
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

import railtherm
from railtherm.input.study import parse_study

SWEEP_FILE = Path(__file__).resolve().parents[1] / "studies" / "sweep_10k.toml"
pytestmark = pytest.mark.benchmark


def _study(store: str, **lists):
    doc = tomllib.loads(SWEEP_FILE.read_text())
    doc["study"]["store"] = store
    doc["scene"][0].update(lists)
    return parse_study(doc, path=str(SWEEP_FILE))


def _size(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def _run(study, out, executor="processes"):
    t0 = time.perf_counter()
    railtherm.run_study(study, out, executor=executor, workers=2, report=False)
    return time.perf_counter() - t0


def _green_or_skip():
    from railtherm.solving.plugins import get_host
    if "green" not in get_host().methods:
        pytest.skip("method 'green' is not installed")


def test_sweep_10k_zarr_store(tmp_path, benchmark):
    _green_or_skip()
    study = _study("zarr")
    assert len(study.scenes) == 10_000
    load = os.getloadavg()[0]
    wall = benchmark.pedantic(_run, args=(study, tmp_path / "zarr"), rounds=1, iterations=1)
    info = json.loads((tmp_path / "zarr" / "study.json").read_text())
    recs, timing = info["records"], info["timing"]
    assert {r["status"] for r in recs} == {"ok"} and timing["store"] == "zarr"
    write = np.array([r["phases"].get("write", np.nan) for r in recs])
    nbytes = np.array([r["phases"].get("bytes", np.nan) for r in recs])
    size = _size(tmp_path / "zarr" / "results.zarr")
    cpu = timing["cpu_main"] + timing["cpu_local_workers"]
    print(f"\nzarr store, 10k runs, 2 workers: wall {wall:.1f} s (runs {timing['runs']:.1f} s, metrics "
          f"{timing['metrics']:.1f} s; load average before {load:.2f}; CPU {cpu:.1f} s); store {size / 1e6:.2f} MB "
          f"= {size / len(recs):.0f} B/run (chunk files {np.nanmean(nbytes):.0f} B/run); chunk write "
          f"{1e3 * np.nanmean(write):.3f} ms/run (max {1e3 * np.nanmax(write):.3f})")
    ds = railtherm.open_results(tmp_path / "zarr")
    t = ds.max_surface_temperature.sel(speed=30.0, method_name="green", level=0, body="wheel")
    assert t.shape == (10, 10, 10) and np.isfinite(t.values).all()
    assert size / len(recs) < 1000 and size < 10e6
    assert np.nanmean(write) < 1e-3
    benchmark.extra_info.update(wall_s=wall, runs_s=timing["runs"], metrics_s=timing["metrics"], load_average=load,
                                cpu_s=cpu, bytes_per_run=size / len(recs), write_ms_per_run=1e3 * float(np.nanmean(write)))
    if os.environ.get("RAILTHERM_BENCH_FILES_10K"):
        wall_f = _run(_study("files"), tmp_path / "files")
        print(f"files store, 10k runs, 2 workers: wall {wall_f:.1f} s, "
              f"{_size(tmp_path / 'files' / 'runs') / 1e6:.0f} MB")


def test_zarr_equals_serial_files_bit_for_bit(tmp_path):
    """200 scenes: the Zarr store on 2 workers against a serial per-file run, every scalar byte for byte,
    and the per-file store's size and write time per run beside the Zarr store's."""
    _green_or_skip()
    lists = {"normal_force": [80e3, 120e3], "friction": [0.3]}
    wz = _run(_study("zarr", **lists), tmp_path / "zarr")
    wf = _run(_study("files", **lists), tmp_path / "files", executor="serial")
    x = railtherm.open_results(tmp_path / "zarr", unstack=False).compute()
    y = railtherm.open_results(tmp_path / "files")      # scenes sorted by name; the store keeps study order
    y = y.sel(scene=[str(s) for s in x["scene"].values])
    assert x.sizes["scene"] == y.sizes["scene"] == 200
    for name in ("max_surface_temperature", "mean_contact_temperature", "frictional_power", "normal_force"):
        assert x[name].values.tobytes() == y[name].values.tobytes(), name
    recs = json.loads((tmp_path / "files" / "study.json").read_text())["records"]
    wfile = np.mean([r["phases"]["write"] for r in recs])
    print(f"\n200 runs: zarr on 2 workers {wz:.1f} s, {_size(tmp_path / 'zarr' / 'results.zarr') / 200:.0f} B/run; "
          f"files serial {wf:.1f} s, {_size(tmp_path / 'files' / 'runs') / 200:.0f} B/run, write {1e3 * wfile:.2f} ms/run")
