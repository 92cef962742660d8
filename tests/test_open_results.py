"""railtherm.open_results: one Dataset of a study's scalar results, swept parameters as coordinates."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.output.store import run_path

STUDY = """
schema_version = 1
[study]
name = "maps"
methods = {methods}
levels = [0, 1]
reference = "finest"
repeat = 1
warmup = false
timeout = 5
[defaults.wheel]
shear_modulus = 82e9
[defaults.rail]
shear_modulus = 82e9
[[scene]]
name = "map"
normal_force = [80e3, 100e3]
contact = {{ shape = "ellipse", semi_axes = [5.88e-3, 10.54e-3] }}
speed = {speeds}
sliding_speed = 1.0
friction = 0.3
heat_partition = 0.5
wheel = {{ bulk_temperature = [0.0, 20.0] }}
outputs = ["max_surface_temperature", "mean_contact_temperature", "frictional_power"]
{extra}
"""

CREEP = """
[[scene]]
name = "creep"
normal_force = 80e3
contact = { shape = "ellipse", semi_axes = [5.88e-3, 10.54e-3] }
speed = 30.0
creepage = { longitudinal = -1e-3 }
friction = 0.3
"""


def run(tmp_path, methods='["flat"]', speeds="[30.0, 60.0]", extra=""):
    p = tmp_path / "study.toml"
    p.write_text(STUDY.format(methods=methods, speeds=speeds, extra=extra))
    out = tmp_path / "out"
    railtherm.run_study(p, out, report=False)
    return railtherm.load_study(p), out


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    """The default study of :func:`run` (8 scenes of flat, 16 runs), run once for the tests that only read it."""
    from fixture_plugins import FlatPlugin
    from railtherm.solving import plugins
    saved = plugins._HOST
    plugins.set_host(plugins.new_host([("flat", FlatPlugin())], autoload=False, strict=True))
    try:
        return run(tmp_path_factory.mktemp("maps"))
    finally:
        plugins.set_host(saved)


def test_sweep_becomes_coordinates(maps):
    study, out = maps
    ds = railtherm.open_results(out)
    assert dict(ds.sizes) == {"scene": 8, "method_name": 1, "level": 2, "body": 2}
    # swept keys as coordinates along scene, named by their dotted study key; a key that is also a result
    # variable gets the sweep_ prefix
    assert {"speed", "sweep_normal_force", "wheel.bulk_temperature"} <= set(ds.coords)
    assert ds.attrs["swept_parameters"].split() == ["sweep_normal_force", "speed", "wheel.bulk_temperature"]
    assert ds["speed"].attrs == {"units": "m s-1", "long_name": "swept study key 'speed'"}
    assert ds["sweep_normal_force"].attrs["units"] == "N"
    assert ds["wheel.bulk_temperature"].attrs == {"units": "degC",
                                                  "long_name": "swept study key 'wheel.bulk_temperature'"}
    for name in list(ds.data_vars) + list(ds.coords):
        assert ds[name].attrs.get("units") and ds[name].attrs.get("long_name"), name
    assert set(ds["status"].values.ravel()) == {"ok"}
    for sc in study.scenes:
        sel = ds.sel(scene=sc.name)
        assert float(sel["speed"]) == sc.speed and float(sel["sweep_normal_force"]) == sc.normal_force
        assert float(sel["wheel.bulk_temperature"]) == sc.wheel.bulk_temperature
        for k in (0, 1):
            with xr.open_dataset(run_path(out, sc.name, "flat", k)) as f:
                np.testing.assert_array_equal(sel["max_surface_temperature"].sel(method_name="flat", level=k).values,
                                              f["max_surface_temperature"].values)
                assert float(sel["normal_force"].sel(method_name="flat", level=k)) == float(f["normal_force"])
                assert float(sel["wall_time"].sel(method_name="flat", level=k)) == f.attrs["wall_time"]


def test_unstack_gives_one_dimension_per_swept_parameter(maps):
    _, out = maps
    g = railtherm.open_results(out, unstack=True)
    assert g["max_surface_temperature"].sizes == {"method_name": 1, "level": 2, "body": 2, "sweep_normal_force": 2,
                                                  "speed": 2, "wheel.bulk_temperature": 2}
    flat = railtherm.open_results(out)
    pick = (flat["speed"] == 60.0) & (flat["sweep_normal_force"] == 100e3) & (flat["wheel.bulk_temperature"] == 20.0)
    one = flat.isel(scene=int(np.flatnonzero(pick.values)[0]))
    np.testing.assert_array_equal(
        g["max_surface_temperature"].sel({"sweep_normal_force": 100e3, "speed": 60.0, "wheel.bulk_temperature": 20.0}).values,
        one["max_surface_temperature"].values)
    assert str(g["scene_name"].sel({"sweep_normal_force": 100e3, "speed": 60.0, "wheel.bulk_temperature": 20.0}).values) == \
        str(one["scene"].values)
    assert g["speed"].attrs["units"] == "m s-1"
    # the wheel heats more at the higher bulk temperature by exactly the bulk difference (flat model)
    d = (g["max_surface_temperature"].sel({"wheel.bulk_temperature": 20.0, "body": "wheel"})
         - g["max_surface_temperature"].sel({"wheel.bulk_temperature": 0.0, "body": "wheel"}))
    np.testing.assert_allclose(d.values, 20.0, rtol=0, atol=1e-9)


def test_refused_and_failed_runs_are_nan_with_their_status(flat_host, tmp_path):
    _, out = run(tmp_path, methods='["broken", "flat"]', speeds="[13.0, 30.0]", extra=CREEP)
    ds = railtherm.open_results(out)
    assert set(ds["method_name"].values) == {"broken", "flat"} and ds.sizes["scene"] == 9
    name = "map--wheel.bulk_temperature=0,normal_force=80000,speed={}"
    failed = ds.sel(scene=name.format(13), method_name="broken")
    assert set(failed["status"].values) == {"failed"}
    assert np.isnan(failed["max_surface_temperature"].values).all()
    assert float(failed["speed"]) == 13.0  # placed by the status record's sweep
    creep = ds.sel(scene="creep")
    assert set(creep["status"].values.ravel()) == {"refused"}
    assert np.isnan(creep["max_surface_temperature"].values).all() and np.isnan(float(creep["speed"]))
    ok = ds.sel(scene=name.format(30), method_name="flat")
    assert set(ok["status"].values) == {"ok"} and np.isfinite(ok["max_surface_temperature"].values).all()
    with pytest.raises(ValueError, match="unstack"):
        railtherm.open_results(out, unstack=True)  # the creep scene has no swept values


def test_variables_filter_and_missing_folder(maps, tmp_path):
    _, out = maps
    ds = railtherm.open_results(out, variables=["frictional_power"])
    assert set(ds.data_vars) == {"frictional_power", "wall_time", "status"}
    with pytest.raises(FileNotFoundError, match="railtherm run"):
        railtherm.open_results(tmp_path / "nowhere")


# ---------------------------------------------------------------------------------------------
# the sweep of studies/sweep_10k.toml: 18 of its scenes in the default suite, all 10 000 as a slow test
SWEEP_FILE = __import__("pathlib").Path(__file__).resolve().parents[1] / "studies" / "sweep_10k.toml"


def _sweep_study(**lists):
    import tomllib
    from railtherm.input.study import parse_study
    doc = tomllib.loads(SWEEP_FILE.read_text())
    doc["scene"][0].update(lists)
    return parse_study(doc, path=str(SWEEP_FILE))


def _green_or_skip():
    import warnings
    from railtherm.solving.plugins import get_host
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if "green" not in get_host().methods:
            pytest.skip("method 'green' is not installed")


def _check_sweep(out, study, shape):
    import json
    files = sorted(out.glob("runs/*/green/level-0.nc"))  # the runs/ layout of docs/DESIGN.md
    assert len(files) == len(study.scenes)
    recs = json.loads((out / "study.json").read_text())["records"]
    assert {r["status"] for r in recs} == {"ok"} and all(r["summary"] for r in recs)
    g = railtherm.open_results(out, unstack=True)
    assert tuple(g.sizes[k] for k in ("sweep_normal_force", "speed", "sliding_speed", "friction")) == shape
    t = g["max_surface_temperature"].sel(method_name="green", level=0, body="wheel")
    assert np.isfinite(t.values).all()
    # physics sanity across the map: at fixed load, speed and friction the flash temperature rises
    # with the sliding speed (frictional power mu N v_s)
    assert (t.diff("sliding_speed") > 0).all()
    p = g["frictional_power"].sel(method_name="green", level=0)
    expected = (g["friction"] * g["sweep_normal_force"] * g["sliding_speed"]).broadcast_like(p).transpose(*p.dims)
    np.testing.assert_allclose(p.values, expected.values, rtol=1e-12)
    return g


def test_sweep_of_18_scenes_on_two_processes(tmp_path):
    """A four-parameter map of the 10k sweep, cut to 2 x 3 x 3 x 1 scenes (its ends and a middle value), on
    two worker processes."""
    _green_or_skip()
    study = _sweep_study(normal_force=[80e3, 120e3], speed=[5.0, 20.0, 50.0],
                         sliding_speed=[0.1, 1.0, 5.0], friction=[0.3])
    assert len(study.scenes) == 18
    railtherm.run_study(study, tmp_path / "out", executor="processes", workers=2, report=False)
    _check_sweep(tmp_path / "out", study, (2, 3, 3, 1))


@pytest.mark.slow
def test_sweep_10k_within_3_minutes_on_2_cores(tmp_path):
    """The whole studies/sweep_10k.toml (10 000 runs of method green) on 2 worker processes.

    The requirement is 3 minutes on 2 cores. The CPU time of the study (main process and workers)
    divided by 2 is what 2 dedicated cores need; the wall time equals it only on an otherwise idle
    machine, so it is asserted only when the load average before the run was below 1.
    """
    import json
    import os
    import time
    _green_or_skip()
    study = railtherm.load_study(SWEEP_FILE)
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    railtherm.run_study(study, tmp_path / "out", executor="processes", workers=2, report=False)
    wall = time.perf_counter() - t0
    timing = json.loads((tmp_path / "out" / "study.json").read_text())["timing"]
    cpu = timing["cpu_main"] + timing["cpu_local_workers"]
    print(f"10k sweep: wall {wall:.1f} s (load average before {load:.2f}), CPU {cpu:.1f} s "
          f"(main {timing['cpu_main']:.1f}, workers {timing['cpu_local_workers']:.1f}) -> {cpu / 2:.1f} s on 2 cores")
    assert cpu / 2 <= 180.0
    if load < 1.0:
        assert wall <= 180.0
    t1 = time.perf_counter()
    _check_sweep(tmp_path / "out", study, (10, 10, 10, 10))
    print(f"open_results of 10 000 runs: {time.perf_counter() - t1:.1f} s")


# ---------------------------------------------------------------------------------------------
# one sweep encoding: the JSON attribute ``sweep`` of every run file (docs/DESIGN.md, result schema)

def test_run_file_carries_its_sweep_as_json(flat_host, tmp_path):
    import json
    study, out = run(tmp_path, speeds="[30.0]", extra=CREEP.replace("longitudinal = -1e-3",
                                                                     "longitudinal = [-1e-3, -2e-3]"))
    creep = [sc for sc in study.scenes if sc.name.startswith("creep")]
    assert len(creep) == 2
    for sc in study.scenes:
        for k in (0, 1):
            p = run_path(out, sc.name, "flat", k)
            if not p.exists():
                continue  # the flat model refuses creepage scenes
            with xr.open_dataset(p) as f:
                assert not any(a.startswith("sweep_") for a in f.attrs)
                assert json.loads(f.attrs["sweep"]) == dict(sc.sweep)
    m = study.scenes[0]
    with xr.open_dataset(run_path(out, m.name, "flat", 0)) as f:
        assert json.loads(f.attrs["sweep"]) == {"normal_force": m.normal_force, "speed": 30.0,
                                                 "wheel.bulk_temperature": m.wheel.bulk_temperature}


def test_sweep_json_round_trip():
    from railtherm.analysis.results import encode_sweep, sweep_of
    sw = {"creepage.longitudinal": -1e-3, "wheel.bulk_temperature": 20.0, "heat_partition": "equal-temperature"}
    assert sweep_of({"sweep": encode_sweep(sw)}) == sw
    assert sweep_of({"sweep": "{}"}) == {} and sweep_of({"scene": "x"}) == {}
    with pytest.raises(ValueError, match="not JSON"):
        sweep_of({"sweep": "creepage.longitudinal=-1e-3"})
    with pytest.raises(ValueError, match="not a JSON object"):
        sweep_of({"sweep": "[1, 2]"})


def test_open_results_names_a_dotted_sweep_coordinate(maps):
    ds = railtherm.open_results(maps[1])
    assert "wheel.bulk_temperature" in ds.coords and "wheel_bulk_temperature" not in ds.coords
    assert ds["wheel.bulk_temperature"].attrs["long_name"] == "swept study key 'wheel.bulk_temperature'"
