"""The study runner: statuses, atomic writes, resume, time limit, metrics, units on every variable."""
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.output.store import run_path


def test_run_writes_every_run_with_units(flat_host, write_study, tmp_path):
    m = railtherm.run_study(write_study(), tmp_path / "out", report=False)
    assert list(m["status"].values).count("ok") + list(m["status"].values).count("inaccurate") == 4
    files = sorted((tmp_path / "out" / "runs").glob("*/flat/level-*.nc"))
    assert len(files) == 4
    for f in files:
        with xr.open_dataset(f) as ds:
            for name in list(ds.data_vars) + list(ds.coords):
                assert ds[name].attrs.get("units") and ds[name].attrs.get("long_name"), name
            assert ds.attrs["Conventions"] == "CF-1.11" and ds.attrs["wall_time"] > 0
            assert ds.attrs["method"] == "flat" and "railtherm" in ds.attrs["source"]
    with xr.open_dataset(tmp_path / "out" / "metrics.nc") as mm:
        assert mm["wall_time"].attrs["units"] == "s"
        # the energy check takes the computed surface temperature (Péclet > 100 here): the flat fixture
        # (temperature proportional to the flux, not physics) is caught by it beyond the tolerance
        assert set(mm["energy_reference"].values) == {"analytic:half-space-1d"}
        assert np.all(np.abs(mm["energy_balance"].values) > mm.attrs["tolerance"])
        assert set(mm["status"].values) == {"inaccurate"}


def test_failures_are_recorded_and_the_study_goes_on(flat_host, write_study, tmp_path):
    m = railtherm.run_study(write_study(methods='["broken", "flat"]', speed="[13.0, 14.0, 15.0, 30.0]", timeout=1.0),
                            tmp_path / "out", report=False)
    status = {(s, me, int(k)): (st, msg) for s, me, k, st, msg in zip(m["scene"].values, m["method"].values,
                                                                     m["level"].values, m["status"].values,
                                                                     m["message"].values)}
    assert status[("ek--speed=13", "broken", 0)][0] == "failed"
    assert "deliberate failure" in status[("ek--speed=13", "broken", 0)][1]
    assert status[("ek--speed=14", "broken", 0)][0] == "failed" and "NaN" in status[("ek--speed=14", "broken", 0)][1]
    assert status[("ek--speed=15", "broken", 0)][0] == "failed" and "time limit" in status[("ek--speed=15", "broken", 0)][1]
    assert status[("ek--speed=30", "broken", 0)][0] in ("ok", "inaccurate")
    assert all(status[(f"ek--speed={v}", "flat", 1)][0] in ("ok", "inaccurate") for v in (13, 14, 15, 30))
    assert not run_path(tmp_path / "out", "ek--speed=13", "broken", 0).exists()
    assert run_path(tmp_path / "out", "ek--speed=13", "broken", 0).with_name("level-0.status.json").exists()


def test_resume_skips_what_is_written(flat_host, write_study, tmp_path):
    out = tmp_path / "out"
    one = '[30.0]'      # one scene, two levels: the study is run three times
    railtherm.run_study(write_study(speed=one), out, report=False)
    files = sorted((out / "runs").glob("*/flat/level-*.nc"))
    f = run_path(out, "ek--speed=30", "flat", 1)
    assert len(files) == 2 and f in files
    before = {p: p.stat().st_mtime_ns for p in files}
    m = railtherm.run_study(write_study(speed=one), out, resume=True, report=False)
    assert {p: p.stat().st_mtime_ns for p in files} == before
    assert len(m["status"]) == 2
    # a changed scene (new hash) is recomputed even with --resume
    railtherm.run_study(_rewrite(write_study(speed=one), "friction = 0.3", "friction = 0.2"), out, resume=True,
                        report=False)
    assert all(p.stat().st_mtime_ns != t for p, t in before.items())


def _rewrite(path, old, new):
    path.write_text(path.read_text().replace(old, new))
    return path


KILL_SCRIPT = textwrap.dedent("""
    import sys, time
    sys.path.insert(0, {tests!r})
    from fixture_plugins import FlatPlugin, FlatTemperature
    from railtherm.solving import plugins
    import railtherm
    orig = FlatTemperature.compute_temperature
    def slow(self, *a, **k):
        time.sleep(0.4)
        return orig(self, *a, **k)
    FlatTemperature.compute_temperature = slow
    plugins.set_host(plugins.new_host([("flat", FlatPlugin())], autoload=False))
    st = railtherm.load_study({study!r})
    st.repeat = 0
    railtherm.run_study(st, {out!r}, resume=True, report=False)
""")


def test_killed_study_resumes_without_rewriting(flat_host, write_study, tmp_path):
    study = write_study(speed="[30.0, 40.0, 50.0, 60.0]")   # 8 runs of 0.4 s: killed after 3 are written
    out = tmp_path / "out"
    script = KILL_SCRIPT.format(tests=str(Path(__file__).parent), study=str(study), out=str(out))
    proc = subprocess.Popen([sys.executable, "-c", script], env={**os.environ, "RAILTHERM_DISABLE_PLUGIN_AUTOLOAD": "1"})
    deadline = time.time() + 60
    while time.time() < deadline and len(list(out.glob("runs/*/flat/level-*.nc"))) < 3:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = {f: f.stat().st_mtime_ns for f in out.glob("runs/*/flat/level-*.nc")}
    assert 3 <= len(done) < 8
    assert not list(out.glob("runs/**/.*.tmp"))  # atomic writes leave no partial files behind
    m = railtherm.run_study(railtherm.load_study(study), out, resume=True, report=False)
    assert len(m["status"]) == 8 and set(m["status"].values) <= {"ok", "inaccurate"}
    for f, t in done.items():
        assert f.stat().st_mtime_ns == t, f"{f} was rewritten"


def test_solve_result_holds_only_what_was_computed(flat_host):
    from railtherm.testing import canonical
    ds = railtherm.solve(canonical("ellipse-full-sliding", outputs=["max_pressure"]), "flat", 0)
    assert "max_pressure" in ds and "surface_temperature" not in ds and "heat_flux" not in ds
    assert ds.attrs["stages"] == "normal:hertz"
    ds = railtherm.solve(canonical("ellipse-given-flux", outputs=["max_surface_temperature"]), "flat", 0)
    assert "pressure" not in ds and ds.attrs["stages"].startswith("heat_source:given")


def test_refused_output_names_what_is_possible(flat_host):
    from railtherm.testing import canonical
    with pytest.raises(railtherm.Refused, match="cannot compute output 'pressure'"):
        railtherm.solve(canonical("ellipse-given-flux", outputs=["pressure"]), "flat", 0)


def test_validator_names_plugin_and_variable(flat_host):
    from railtherm.contract.schema import validate_dataset
    from railtherm.testing import canonical
    ds = railtherm.solve(canonical("ellipse-full-sliding"), "flat", 0)
    bad = ds.copy()
    bad["surface_temperature"].attrs.pop("units")
    with pytest.raises(railtherm.PluginError, match=r"plugin 'flat'.*'surface_temperature'.*units"):
        validate_dataset(bad, "flat")
    bad = ds.copy()
    bad["pressure"] = bad["pressure"].transpose("y", "x")
    with pytest.raises(railtherm.PluginError, match=r"'pressure' has dims"):
        validate_dataset(bad, "flat")


def test_conformance_kit_on_fixture(flat_host):
    from railtherm.testing import check_method
    # the flat fixture (temperature proportional to the flux) is not physics: the kit says so
    with pytest.raises(AssertionError, match="on no scene"):
        check_method("flat")
