"""Hostile scenes for every installed method (hypothesis): a result, or a clear error; never a crash,
a hang or a NaN stored as a result.

Each example is a scene of the study vocabulary with random and extreme values (loads from 0 to
1e9 N, speeds from 1e-6 to 1e4 m/s, conductivities over seven decades, zero friction, rigid wheels,
given heat sources, any outputs...), solved by ``railtherm.solve`` at level 0 under a time cap.
Allowed outcomes: a Dataset that passes the schema with every asked output finite, or
``SceneError`` (invalid input), ``Refused`` (outside the method's validity, with a reason) or
``SolverError`` (did not converge), each with a message. Anything else is a bug of the method's
plugin (or of core, for the stages core provides).

The default suite runs a few derandomized examples per method, without shrinking; a longer random
hunt that shrinks what it finds to a minimal example:
``RAILTHERM_HYPOTHESIS_EXAMPLES=500 python -m pytest tests/test_hypothesis_methods.py``.
"""
from __future__ import annotations

import math
import os
import time
import warnings

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, Phase, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import railtherm  # noqa: E402
from railtherm.run.timelimit import RunTimeout, _time_limit  # noqa: E402
from railtherm.contract.schema import VARIABLES  # noqa: E402

HUNT = int(os.environ.get("RAILTHERM_HYPOTHESIS_EXAMPLES", "0"))
#: seconds one solve at level 0 may take before it counts as a hang
CAP = float(os.environ.get("RAILTHERM_HYPOTHESIS_CAP", "20"))
#: examples per method in the default suite; a safety net: no new example starts after BUDGET seconds
#: (normally every example runs, so the default suite is deterministic)
EXAMPLES = {"green": 40, "fastsim-fdm": 25, "fipy": 12, "fem": 8}
BUDGET = float(os.environ.get("RAILTHERM_HYPOTHESIS_BUDGET", "15"))


def _methods():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from railtherm.solving.plugins import new_host
        return sorted(new_host().methods)


def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: float(10.0 ** e))


def extreme(lo, hi, *special, typical=None):
    """A wheel-rail value (log-uniform in ``typical``), any value in [lo, hi], or an edge value."""
    out = [log_uniform(lo, hi), st.sampled_from([lo, hi, *special])]
    if typical:
        out.insert(0, log_uniform(*typical))
    return st.one_of(*out)


MATERIAL = st.fixed_dictionaries({}, optional={
    "shear_modulus": extreme(1e6, 1e13, typical=(5e10, 1e11)),
    "poisson_ratio": st.one_of(st.floats(0.0, 0.499), st.sampled_from([0.0, 0.4999999])),
    "density": extreme(1.0, 1e5, typical=(7000.0, 8000.0)),
    "specific_heat": extreme(1.0, 1e5, typical=(400.0, 500.0)),
    "conductivity": extreme(1e-3, 1e4, typical=(20.0, 60.0)),
    "thermal_expansion": extreme(1e-9, 1e-3, 0.0, typical=(1e-5, 1.5e-5)),
    "bulk_temperature": st.one_of(st.floats(-273.0, 2000.0), st.sampled_from([-273.14, 0.0, 1e4])),
    "radius": extreme(1e-3, 10.0, typical=(0.3, 0.6)),
})
RIGID = st.one_of(st.just({}), st.just({"rigid": True}))
OUTPUT_NAMES = sorted(VARIABLES)


KINDS = ("ellipse-axes", "ellipse-curv", "line", "given-ellipse", "given-line")


def kinds_of(method: str) -> tuple[str, ...]:
    """Scene kinds worth drawing for a method: the contact shapes all its models handle (others are
    refused at once; a few of them are still drawn to check that)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from railtherm.solving.plugins import new_host
        info = new_host().methods[method]
    shapes = set.intersection(*(set(m.cls.capabilities.contacts) for m in info.models))
    keep = tuple(k for k in KINDS if ("line" in k and "line" in shapes) or ("line" not in k and "ellipse" in shapes))
    return keep or KINDS


@st.composite
def scenes(draw, kinds=KINDS):
    sc: dict = {"name": "h"}
    kind = draw(st.one_of(st.sampled_from(kinds), st.sampled_from(KINDS)) if kinds != KINDS else st.sampled_from(KINDS))
    if kind.startswith("given"):
        hs = {"flux": draw(extreme(1.0, 1e12, 0.0, typical=(1e6, 1e10))), "shape": draw(st.sampled_from(["uniform", "hertz"]))}
        if kind == "given-ellipse":
            hs["semi_axes"] = [draw(extreme(1e-6, 1.0, typical=(1e-3, 2e-2))), draw(extreme(1e-6, 1.0, typical=(1e-3, 2e-2)))]
        else:
            hs["half_width"] = draw(extreme(1e-6, 1.0, typical=(1e-3, 2e-2)))
        sc["heat_source"] = hs
        if kind == "given-line" and draw(st.booleans()):
            sc["contact"] = {"shape": "line", "wheel_radius": draw(extreme(1e-3, 10.0, typical=(0.3, 0.6)))}
    else:
        if kind == "ellipse-axes":
            sc["contact"] = {"shape": "ellipse", "semi_axes": [draw(extreme(1e-6, 1.0, typical=(1e-3, 2e-2))), draw(extreme(1e-6, 1.0, typical=(1e-3, 2e-2)))]}
        elif kind == "ellipse-curv":
            sc["contact"] = {"shape": "ellipse", "curvatures": [draw(extreme(1e-3, 1e4, typical=(0.2, 10.0))), draw(extreme(1e-3, 1e4, typical=(0.2, 10.0)))]}
        else:
            sc["contact"] = {"shape": "line", "wheel_radius": draw(extreme(1e-3, 10.0, typical=(0.3, 0.6)))}
        if kind == "ellipse-curv" and draw(st.booleans()):
            sc["penetration"] = draw(extreme(1e-9, 1e-2, typical=(1e-5, 1e-4)))
        else:
            sc["normal_force"] = draw(extreme(1e-3, 1e9, 0.0, typical=(1e4, 2e5)))
        if draw(st.booleans()):
            sc["sliding_speed"] = draw(extreme(1e-6, 1e2, 0.0, typical=(0.1, 5.0)))
        else:
            sc["creepage"] = draw(st.fixed_dictionaries({}, optional={
                "longitudinal": st.one_of(st.floats(-1.0, 1.0), st.sampled_from([0.0, -1.0, 1.0, 1e-9])),
                "lateral": st.one_of(st.floats(-1.0, 1.0), st.sampled_from([0.0, 1e-9])),
                "spin": st.one_of(st.floats(-1e3, 1e3), st.sampled_from([0.0]))}))
        sc["friction"] = draw(st.one_of(st.floats(0.0, 2.0), st.sampled_from([0.0, 1e-9, 1.0])))
    sc["speed"] = draw(extreme(1e-6, 1e4, typical=(5.0, 100.0)))
    sc["heat_partition"] = draw(st.one_of(st.floats(0.0, 1.0), st.sampled_from([0.0, 1.0, "equal-temperature"])))
    if draw(st.booleans()):
        sc["convection"] = draw(extreme(1e-3, 1e6, 0.0, typical=(10.0, 1000.0)))
    sc["wheel"] = {**draw(MATERIAL), **draw(RIGID)}
    sc["rail"] = draw(MATERIAL)
    if draw(st.booleans()):
        sc["outputs"] = draw(st.lists(st.sampled_from(OUTPUT_NAMES), min_size=1, max_size=4, unique=True))
    mode = draw(st.sampled_from(["default", "default", "default", "steady", "transient"]))
    if mode != "default":
        sc["mode"] = mode
    return sc


def solve_or_clear_error(scene, method):
    """Solve under the time cap; assert the outcome is a valid result or one of the clear errors."""
    t0 = time.perf_counter()
    try:
        with _time_limit(CAP):
            ds = railtherm.solve(scene, method, 0)
    except (railtherm.SceneError, railtherm.Refused, railtherm.SolverError) as exc:
        assert str(exc).strip(), f"{type(exc).__name__} without a message"
        return type(exc).__name__
    except RunTimeout:
        raise AssertionError(f"method {method!r} did not finish within {CAP:g} s at level 0 (a hang?) on {scene!r}")
    elapsed = time.perf_counter() - t0
    asked = ds.attrs["outputs"].split()
    for name in asked:
        assert name in ds, f"asked output {name!r} missing"
    nan_ok = set(str(ds.attrs.get("nan_allowed", "")).split()) | {"stick"}
    for name, da in ds.data_vars.items():
        if name in nan_ok or not np.issubdtype(da.dtype, np.floating):
            continue
        assert np.all(np.isfinite(da.values)), f"{name!r} holds NaN/inf in a returned result"
    return f"ok ({elapsed:.2f} s)"


@pytest.mark.parametrize("method", _methods())
def test_method_entry_with_hostile_scenes(method):
    n = HUNT or EXAMPLES.get(method, 10)
    outcomes = []
    start = time.perf_counter()
    state = {"failed": False}

    # the default suite reports the first failing example as generated (shrinking would re-run a
    # slow method many times); the hunt shrinks it to a minimal one
    phases = list(Phase) if HUNT else [Phase.explicit, Phase.reuse, Phase.generate]

    @settings(max_examples=n, deadline=None, derandomize=not HUNT, database=None, phases=phases,
              suppress_health_check=list(HealthCheck))
    @given(scenes(kinds_of(method)))
    def run(scene):
        if not HUNT and not state["failed"] and time.perf_counter() - start > BUDGET:
            return  # the default suite bounds each method's time (a failure is still replayed)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                outcomes.append(solve_or_clear_error(scene, method))
        except BaseException:
            state["failed"] = True
            raise
        if os.environ.get("RAILTHERM_HYPOTHESIS_VERBOSE"):
            print(method, outcomes[-1], scene if os.environ["RAILTHERM_HYPOTHESIS_VERBOSE"] == "2" else "")

    run()
    assert outcomes
