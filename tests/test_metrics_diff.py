"""railtherm diff: two metrics.nc compared run by run (matched by scene, method, level, not by index),
machine measurements left out, tolerances as documented, exit status like diff(1)."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from railtherm.analysis.metrics_diff import diff_metrics
from railtherm.cli import main


def _metrics(path, order=(0, 1, 2), t=(1.0, 2.0, 3.0), err=(1e-3, 2e-3, np.nan), msg=("", "", "x"), wall=(1, 2, 3)):
    scenes, methods, levels = ["a", "a", "b"], ["m", "n", "m"], [0, 0, 1]
    o = list(order)
    ds = xr.Dataset({
        "scene": ("run", np.array(scenes, dtype=object)[o]), "method": ("run", np.array(methods, dtype=object)[o]),
        "level": ("run", np.array(levels)[o]), "max_t": ("run", np.array(t)[o]),
        "error_max_t": ("run", np.array(err)[o]), "message": ("run", np.array(msg, dtype=object)[o]),
        "wall_time": ("run", np.array(wall, dtype=float)[o])})
    ds.to_netcdf(path)
    return path


def test_the_same_numbers_in_another_run_order_and_on_another_machine(tmp_path):
    a = _metrics(tmp_path / "a.nc")
    b = _metrics(tmp_path / "b.nc", order=(2, 0, 1), wall=(9, 9, 9))
    assert diff_metrics(a, b) == []
    assert [d.variable for d in diff_metrics(a, b, include_machine=True)] == ["wall_time"]
    assert main(["diff", str(a), str(b)]) == 0


def test_each_kind_of_difference_is_named(tmp_path):
    a = _metrics(tmp_path / "a.nc")
    b = _metrics(tmp_path / "b.nc", t=(1.0, 2.0 * (1 + 1e-9), 3.0), err=(1e-3, np.nan, np.nan), msg=("", "", "y"))
    found = {d.variable: d for d in diff_metrics(a, b)}
    assert found["max_t"].kind == "values" and found["max_t"].count == 1
    assert found["max_t"].max_rel == pytest.approx(1e-9, rel=1e-3) and "run=a|n|0" in found["max_t"].example
    assert found["error_max_t"].kind == "finite in one only" and found["error_max_t"].count == 1
    assert found["message"].kind == "text"
    assert diff_metrics(a, b, rtol=1e-8, atol=0)[0].variable != "max_t"
    assert main(["diff", str(a), str(b)]) == 1


def test_a_missing_file_is_a_user_error(tmp_path, capsys):
    assert main(["diff", str(tmp_path / "nope"), str(tmp_path)]) == 2
    assert "neither a metrics.nc nor an output folder" in capsys.readouterr().err


def test_a_metric_that_goes_from_not_scored_to_failing_is_a_difference(tmp_path):
    """metrics.nc's NaN (not scored) and inf (a value not finite where its reference is: the metric fails) are
    different results; both non-finite, they compared equal."""
    import warnings
    a = _metrics(tmp_path / "a.nc", err=(1e-3, np.inf, np.nan))
    b = _metrics(tmp_path / "b.nc", err=(1e-3, np.nan, np.inf))
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # inf - inf is never evaluated
        found = {d.variable: d for d in diff_metrics(a, b)}
        assert diff_metrics(a, a) == []
    assert found["error_max_t"].kind == "finite in one only" and found["error_max_t"].count == 2
