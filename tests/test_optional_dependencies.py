"""The optional ``sweep`` extra (dask.distributed, zarr): a study that needs a missing one stops before its
first run with an error that names the key, its value and the command that installs the extra."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

import railtherm
from railtherm import SceneError
from studies import ELLIPSE_CURVATURES, ellipse_scene

SMALL = """
schema_version = 1
[study]
name = "small"
methods = ["green"]
levels = [0, 1]
reference = "analytic"
""" + ellipse_scene("ek-low", contact=ELLIPSE_CURVATURES) + """heat_partition = "equal-temperature"
outputs = ["max_surface_temperature", "surface_temperature"]
"""


def _small(tmp_path, line: str = "") -> Path:
    p = tmp_path / "small.toml"
    p.write_text(SMALL.replace('reference = "analytic"', 'reference = "analytic"\n' + line))
    return p


def _without(monkeypatch, module: str):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a, **k: None if name.split(".")[0] == module else real(name, *a, **k))


def test_dask_executor_without_distributed(monkeypatch, tmp_path):
    _without(monkeypatch, "distributed")
    with pytest.raises(SceneError, match=r"'executor' = 'dask' needs the optional package 'distributed'.*"
                                         r"pip install 'railtherm\[sweep\]'"):
        railtherm.run_study(_small(tmp_path), tmp_path / "out", executor="dask", report=False)
    assert not list((tmp_path / "out").glob("runs/*/*/*.nc"))


def test_zarr_store_without_zarr(monkeypatch, tmp_path):
    _without(monkeypatch, "zarr")
    with pytest.raises(SceneError, match=r"'study.store' = 'zarr' needs the optional package 'zarr'.*"
                                         r"pip install 'railtherm\[sweep\]'"):
        railtherm.run_study(_small(tmp_path, 'store = "zarr"'), tmp_path / "out", report=False)
    assert not (tmp_path / "out" / "results.zarr").exists()


def test_the_main_study_needs_neither(tmp_path):
    """The README's first command installs no extra: a study of the main study's kind (run files, an exact
    reference, local worker processes as the command line's default executor) runs and scores in a fresh
    interpreter where dask, distributed and zarr cannot be imported (a fresh one: xarray caches whether
    dask is there on first use)."""
    import subprocess
    import sys
    code = f"""
import importlib.util, sys
BLOCKED = ("dask", "distributed", "zarr")
real = importlib.util.find_spec
importlib.util.find_spec = lambda name, *a, **k: None if name.split(".")[0] in BLOCKED else real(name, *a, **k)
for name in BLOCKED:
    sys.modules[name] = None
import railtherm
m = railtherm.run_study({str(_small(tmp_path))!r}, {str(tmp_path / "out")!r}, executor="processes", workers=2,
                        report=False)
print("STATUSES", sorted(set(m["status"].values)))
print("LOADED", sorted(n for n in sys.modules if n.split(".")[0] in BLOCKED and sys.modules[n] is not None))
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "STATUSES ['ok']" in res.stdout and "LOADED []" in res.stdout, res.stdout
    assert (tmp_path / "out" / "metrics.nc").exists()
