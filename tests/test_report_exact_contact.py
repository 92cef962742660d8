"""The report's exact-contact section: a small study (level 0) of Ertz & Knothe's ellipse with creepage,
measured against method "kalker" (reference = "kalker"), run by kalker, green (FASTSIM -> green) and fastsim-fdm
(FASTSIM -> fdm). Checks: the contact-model and thermal-model error columns are computed from the run files (one
cell recomputed here from the files), each names its reference, the contact-model error agrees with metrics.nc's
error against method:kalker, and the figures are written; on data built here, a result of several patches (a
wheelset on profiles) has rows for every patch, each with its own values and error."""
from __future__ import annotations

import re

import math
import textwrap
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import railtherm
from railtherm.output import store
from railtherm.contract.schema import variable_attrs
from railtherm.report.exact_contact import (ExactComparison, _split_summary, error_rows, exact_comparisons,
                                            relative_error)
from railtherm.report.format import pct
from railtherm.report.load import Run, SceneInfo, StudyData, load

STUDY = textwrap.dedent("""
    schema_version = 1
    [study]
    name = "exact-small"
    methods = ["kalker", "green", "fastsim-fdm"]
    levels = [0]
    tolerance = 0.05
    repeat = 1
    [defaults]
    heat_partition = 0.5
    convection = 0.0
    normal_force = 100e3
    speed = 30.0
    friction = 0.3
    reference = "kalker"
    outputs = ["max_surface_temperature", "mean_contact_temperature", "surface_temperature", "heat_flux",
               "frictional_power", "creep_force_x", "creep_force_y", "spin_moment", "normal_force", "pressure",
               "traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "stick"]
    [[scene]]
    name = "ek-combined"
    contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
    creepage = { longitudinal = -2e-3, lateral = 1e-3, spin = 0.2 }
    [[scene]]
    name = "ek-curve"
    contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
    creepage = { longitudinal = [-3e-4, -1e-3, -3e-3] }
    outputs = ["creep_force_x", "creep_force_y", "normal_force"]
    [[scene]]
    name = "ek-gap"
    contact = { shape = "gap", coefficients = { x2 = 1.015, y2 = 0.4215, y4 = 2.0e3 } }
    creepage = { longitudinal = -2e-3, lateral = 1e-3, spin = 0.2 }
""")


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    root = tmp_path_factory.mktemp("exact")
    path = root / "study.toml"
    path.write_text(STUDY)
    railtherm.run_study(str(path), out=root / "out")
    return root / "out"


def _run(out, scene, method, level=0):
    return xr.open_dataset(store.run_path(out, scene, method, level)).load()


def test_section_names_its_methods_and_references(out):
    md = (out / "report.md").read_text()
    assert "## Exact contact: contact model against thermal model" in md
    assert "contact-model error of green, reference kalker [%]" in md
    assert "thermal-model error of fastsim-fdm, reference green [%]" in md
    assert "total error of fastsim-fdm, reference kalker [%]" in md
    data = load(out)
    (comp,) = exact_comparisons(data)
    assert comp.exact == "kalker" and comp.contact == ["green"] and comp.thermal == {"fastsim-fdm": "green"}


def test_error_cells_recomputed_from_the_run_files(out):
    data = load(out)
    (comp,) = exact_comparisons(data)
    header, rows = error_rows(data, comp)
    assert {r[0] for r in rows} == {"`ek-combined`"}          # the gap scene has nothing to compare with
    col = {h: i for i, h in enumerate(header)}
    by_q = {r[1]: r for r in rows}
    k, g, f = (_run(out, "ek-combined", m) for m in ("kalker", "green", "fastsim-fdm"))
    # contact model: green against kalker, creep force
    row = by_q["creep force Fx [kN]"]                           # forces in kN, three significant digits
    assert row[col["kalker (exact contact) [unit]"]] == f"{float(k['creep_force_x']) / 1e3:.3g}"
    err = (float(g["creep_force_x"]) - float(k["creep_force_x"])) / abs(float(k["creep_force_x"]))
    assert str(row[col["contact-model error of green, reference kalker [%]"]]) == pct(err, signed=True, floor=1e-9)
    assert abs(err) > 0.01                                      # FASTSIM is visibly off the exact theory
    # thermal model: fastsim-fdm against green, maximum surface temperature of the wheel (rise above 0 degC)
    row = by_q["max. surface temperature (wheel) [°C]"]
    tg, tf = float(g["max_surface_temperature"][0]), float(f["max_surface_temperature"][0])
    assert str(row[col["thermal-model error of fastsim-fdm, reference green [%]"]]) == pct((tf - tg) / tg, signed=True,
                                                                                          floor=1e-9)
    tk = float(k["max_surface_temperature"][0])
    assert str(row[col["total error of fastsim-fdm, reference kalker [%]"]]) == pct((tf - tk) / tk, signed=True,
                                                                                   floor=1e-9)
    # the sentence above the (closed) table says the same split
    md = (out / "report.md").read_text()
    contact = pct((tg - tk) / tk, signed=True, floor=1e-9)
    thermal = pct((tf - tg) / tg, signed=True, floor=1e-9)
    assert (f"On the wheel's maximum surface temperature over its one scene: the contact model of `green` (against "
            f"`kalker`) {contact}; the thermal model of `fastsim-fdm` (against `green`) {thermal}") in md
    # the levels each error used are named in the row
    assert row[-1] == "kalker level 0, green level 0, fastsim-fdm level 0"


def test_contact_error_is_the_metrics_error_against_kalker(out):
    m = store.read_metrics(out)
    sel = [i for i in range(m.sizes["run"]) if str(m.scene.values[i]) == "ek-combined"
           and str(m.method.values[i]) == "green"]
    (i,) = sel
    assert str(m["reference_creep_force_x"].values[i]) == "method:kalker"
    k, g = _run(out, "ek-combined", "kalker"), _run(out, "ek-combined", "green")
    err = relative_error(float(g["creep_force_x"]), float(k["creep_force_x"]))
    assert float(m["error_creep_force_x"].values[i]) == pytest.approx(abs(err), rel=1e-9)


def test_figures_written_beside_the_report(out):
    md = (out / "report.md").read_text()
    for name in ("exact-creep-curve", "exact-maps", "exact-gap-maps"):
        png = out / "figures" / f"{name}.png"
        assert png.exists() and png.stat().st_size > 10_000, name
        assert f"figures/{name}.png" in md
    assert "Kalker linear theory" in md                         # the linear theory drawn from references.nc
    assert "Non-Hertzian contact `ek-gap`" in md and "2000 y^4" in md


def test_creep_curve_table_against_the_exact_contact(out):
    md = (out / "report.md").read_text()
    assert "Fx / (μ N) of kalker [1]" in md and "error, reference kalker [%]" in md
    k = _run(out, "ek-curve--creepage.longitudinal=-0.003", "kalker")
    ratio = float(k["creep_force_x"]) / (0.3 * float(k["normal_force"]))
    assert 0.9 < ratio <= 1.0 + 1e-9                             # near full slip at xi = -3e-3


def test_relative_error_signs_and_rise():
    assert relative_error(11.0, 10.0) == pytest.approx(0.1)
    assert relative_error(-11.0, -10.0) == pytest.approx(-0.1)
    assert relative_error(30.0, 20.0, bulk=10.0) == pytest.approx(1.0)
    assert math.isnan(relative_error(1.0, 0.0))
    assert np.isnan(relative_error(1.0, 5.0, bulk=5.0))


def test_contact_and_total_errors_are_read_from_metrics(out, tmp_path, monkeypatch):
    """The contact-model and total errors are metrics.nc's signed errors (the run table's number), not a second
    computation from the run files: a stored value that differs from the files' is the one shown. The second
    report is read for its tables only: its figures are left out as beyond the figure budget (the first report's
    figures are test_figures_written_beside_the_report's)."""
    import shutil

    from railtherm.report.sections import Context
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    m = store.read_metrics(copy).load()
    for meth, value in (("green", 0.5), ("fastsim-fdm", -0.25)):
        i = [k for k in range(m.sizes["run"]) if str(m.scene.values[k]) == "ek-combined"
             and str(m.method.values[k]) == meth]
        m["signed_error_creep_force_x"].values[i] = value
    member = [k for k in range(m.sizes["run"]) if str(m.scene.values[k]) == "ek-curve--creepage.longitudinal=-0.003"
              and str(m.method.values[k]) == "fastsim-fdm"]
    m["signed_error_creep_force_x"].values[member] = 0.75
    m.to_netcdf(copy / "metrics.nc", engine="netcdf4")
    data = load(copy)
    (comp,) = exact_comparisons(data)
    header, rows = error_rows(data, comp)
    row = next(r for r in rows if r[1] == "creep force Fx [kN]")
    assert str(row[header.index("contact-model error of green, reference kalker [%]")]) == "+50 %"
    assert str(row[header.index("total error of fastsim-fdm, reference kalker [%]")]) == "−25 %"
    from railtherm.report import write_report
    monkeypatch.setattr(Context, "draw", lambda self, doc, name, *args, **kwargs: self.left_out.append(name))
    md = write_report(copy)[0].read_text()                      # the creep curve's table: Fx's stored error
    assert re.search(r"^\| -0\.003 \| [^|]+ \| `fastsim-fdm` \| [^|]+ \| \+75 % \|$", md, flags=re.M)


# -- a result of several patches (a wheelset on profiles, wheelset.patch = "all"), on data built here -----------
def _patched(fx, temps) -> xr.Dataset:
    """A result of two patches: creep force Fx [N] and the bodies' max. surface temperatures [degC] per patch."""
    ds = xr.Dataset({"creep_force_x": (("patch",), fx),
                     "max_surface_temperature": (("body", "patch"), [temps, [t - 1.0 for t in temps]])},
                    coords={"body": ["wheel", "rail"], "patch": [1, 2]}, attrs={"wheelset_patch": "all"})
    for v in ds.data_vars:
        ds[v].attrs.update(variable_attrs(v))
    return ds


def _patched_study(tmp_path, stored: bool):
    """kalker (the exact contact) and a Hertz chain on one scene of two patches; metrics.nc's errors per patch
    (``patch_errors_<q>``, magnitudes) when ``stored``, its signed error the worst patch's."""
    scene = SimpleNamespace(profile_contact=SimpleNamespace(patch="all"), wheel=SimpleNamespace(bulk_temperature=0.0))
    q = "max_surface_temperature"
    runs = [Run("w", "kalker", 2, "unverified"),
            Run("w", "hertz", 2, "inaccurate", references={q: "method:kalker"} if stored else {},
                signed={q: 0.55} if stored else {}, patch_errors={q: {1: 0.12, 2: 0.55}} if stored else {})]
    data = StudyData(out=tmp_path, name="fake", tolerance=0.05, runs=runs, scenes=["w"], methods=["kalker", "hertz"],
                     levels=[2], info={}, study=None, scene={"w": SceneInfo("w", reference_kind="kalker", scene=scene)},
                     orders={}, cross={}, curves=None)
    data._files["w", "kalker", 2] = _patched([100.0, 20.0], [50.0, 4.0])
    data._files["w", "hertz", 2] = _patched([90.0, 30.0], [45.0, 6.0])
    return data, ExactComparison("kalker", ["w"], contact=["hertz"])


@pytest.mark.parametrize("stored", [True, False])
def test_every_patch_of_a_result_of_several_patches_has_its_rows(tmp_path, stored):
    """A row per patch and quantity with that patch's values (not patch 1's for both) and its own error: metrics.nc's
    per-patch error signed by the difference where stored (12 % and 55 %, over both bodies), else
    (value - reference) / |reference - bulk| of the wheel's values (10 % and 50 %)."""
    data, comp = _patched_study(tmp_path, stored)
    _, rows = error_rows(data, comp)
    got = {(r[0], r[1].split(" [")[0]): r for r in rows}
    assert sorted({r[0] for r in rows}) == ["`w` patch 1", "`w` patch 2"]
    fx2 = got["`w` patch 2", "creep force Fx"]
    assert fx2[2] == "0.02" and fx2[3] == "0.03" and fx2[4].text == pct(0.5, signed=True)   # kN; (30 - 20) / 20
    t1, t2 = got["`w` patch 1", "max. surface temperature (wheel)"], got["`w` patch 2", "max. surface temperature (wheel)"]
    assert (t1[2], t1[3], t2[2], t2[3]) == ("50", "45", "4", "6")
    e1, e2 = (0.12, 0.55) if stored else (0.1, 0.5)
    assert t1[4].text == pct(-e1, signed=True) and t2[4].text == pct(e2, signed=True)


def test_the_summary_counts_the_patches(tmp_path):
    data, comp = _patched_study(tmp_path, True)
    text = _split_summary(data, comp)
    assert "over its one scene (2 patches: each patch of a wheelset on profiles on its own)" in text
    assert f"{pct(-0.12, signed=True)} to {pct(0.55, signed=True)}" in text
