"""railtherm.analysis.reference_curves: the exact curves the report overlays, written to out/references.nc."""
from __future__ import annotations

import numpy as np
import pytest

from studies import steel

STUDY = """
schema_version = 1
[study]
name = "curves"
methods = ["green"]
levels = [0]
reference = "analytic"

""" + steel("wheel", thermal=True, bulk_temperature=20.0) + steel("rail", thermal=True, bulk_temperature=20.0) + """
[[scene]]
name = "band"
speed = 30.0
heat_source = { flux = 1e8, shape = "hertz", half_width = 5e-3 }
heat_partition = 0.5

[[scene]]
name = "carter"
normal_force = 1.78896e5
contact = { shape = "line", wheel_radius = 0.5 }
speed = 10.0
creepage = { longitudinal = [-1e-4, -4e-4, -1e-3] }
friction = 0.3
outputs = ["creep_force_x", "traction_x", "stick"]

[[scene]]
name = "ellipse-creep"
normal_force = 100e3
contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
speed = 30.0
creepage = { longitudinal = -1e-4 }
friction = 0.3
outputs = ["creep_force_x"]

[[scene]]
name = "convective"
speed = 30.0
heat_source = { flux = 1e8, shape = "uniform", half_width = 5e-3 }
convection = 100.0
"""


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    from railtherm.input.study import load_study
    p = tmp_path_factory.mktemp("curves") / "study.toml"
    p.write_text(STUDY)
    return load_study(p)


def test_curves_carry_their_meaning(study):
    from railtherm.analysis.reference_curves import reference_curves
    curves = reference_curves(study)
    assert "convective" not in curves  # no exact reference with convection
    assert {"band", "ellipse-creep"} <= set(curves)
    for name, ds in curves.items():
        assert ds.attrs["scene"] == name and ds.attrs["reference"] and ds.attrs["Conventions"] == "CF-1.11"
        for k in list(ds.data_vars) + list(ds.coords):
            assert ds[k].attrs.get("units") and ds[k].attrs.get("long_name"), (name, k)
        for k in ds.data_vars:
            assert ds[k].attrs.get("reference"), (name, k)
    band = curves["band"]
    assert "Jaeger" in band.attrs["reference"]
    t = band["surface_temperature"].values
    assert t.shape == (2, band.sizes["x"]) and np.all(t >= 20.0 - 1e-9) and t.max() > 25.0
    assert band["temperature"].values[:, 0] == pytest.approx(t.max(axis=1), rel=0.02)  # z = 0 at the hottest point
    assert band["surface_temperature"].attrs["units"] == "degC"
    assert curves["ellipse-creep"]["kalker_linear_slope"].values < 0  # xi > 0 gives a negative force


def test_carter_curve_holds_the_swept_values(study):
    from railtherm.analysis.reference_curves import reference_curves
    from railtherm.references.carter import carter_2d
    curves = reference_curves(study)
    ds = curves["carter--creepage.longitudinal=-0.0004"]
    xs = ds["creepage"].values
    for v in (-1e-4, -4e-4, -1e-3):
        i = int(np.argmin(np.abs(xs - v)))
        assert xs[i] == v
        a = float(ds["semi_axis_a"])
        assert ds["creep_force_ratio"].values[i] == pytest.approx(carter_2d(v, a, 0.3, 0.5).force_ratio)
    assert set(np.unique(ds["carter_stick"].values)) == {0, 1}


def test_written_atomically_and_read_back(study, tmp_path):
    from railtherm.analysis.reference_curves import read_reference_curves, reference_curves, write_reference_curves
    path = write_reference_curves(study, tmp_path)
    assert path == tmp_path / "references.nc"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["references.nc"]  # no temporary file left
    back = read_reference_curves(path)
    want = reference_curves(study)
    assert set(back) == set(want)
    for name, ds in want.items():
        for k in ds.data_vars:
            np.testing.assert_allclose(back[name][k].values, ds[k].values)
        assert back[name]["surface_temperature" if "surface_temperature" in ds else
                          next(iter(ds.data_vars))].attrs["units"]
