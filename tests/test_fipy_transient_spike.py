"""fipy's section under a short spike of the heat input: ``spike-10us`` of studies/transient.toml.

One pass of the Hertz band (a = 6 mm, 30 m/s, 1e8 W/m^2; contact duration 0.4 ms) whose heat input rises from
1 to 5 times and back within 10 us in the middle of the contact (schedule kinks at 195, 200 and 205 us). The
surface answers the spike within a few microseconds (diffusion length sqrt(kappa 5 us) = 8 um), so the history's
max-norm error is decided by how the time steps meet the schedule.

Exact reference: the moving band in time with the schedule (Carslaw & Jaeger 1959, 10.7;
:mod:`railtherm.references.transient`, doi:10.1093/oso/9780198533689.001.0001), scored by core's
:func:`railtherm.analysis.transient_metrics.transient_errors` as the study's metrics are.
"""
from __future__ import annotations

from pathlib import Path

import pytest

import railtherm
from railtherm.analysis.transient_metrics import transient_errors
from railtherm.input.study import load_study

STUDY = Path(__file__).resolve().parents[1] / "studies" / "transient.toml"


def _scene():
    return next(s for s in load_study(STUDY).scenes if s.name == "spike-10us")


@pytest.mark.xfail(strict=True, reason="history error 4.14 % at level 2: the time steps straddle the schedule's kinks")
def test_spike_10us_within_the_targets_at_level_2():
    """The targets against the exact band at level 2: history max-norm error within 3 %, pass peaks and residual
    rise within 2 %."""
    scene = _scene()
    errs = transient_errors(scene, railtherm.solve(scene, "fipy", level=2))
    assert errs["temperature_history"][0] < 0.03, errs
    assert errs["pass_peak_temperature"][0] < 0.02, errs
    assert errs["residual_rise"][0] < 0.02, errs
