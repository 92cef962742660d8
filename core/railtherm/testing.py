"""Plugin conformance kit: a pytest plugin (entry point ``pytest11: railtherm``) and plain functions.

Any plugin, built-in or third-party, runs it against itself::

    # tests/test_my_plugin.py of your distribution
    import pytest
    from railtherm.testing import check_method, check_model_class, CANONICAL_SCENES

    def test_conformance(railtherm_register):
        railtherm_register("mine", my_package.plugin)        # inline registration, no entry point needed
        check_method("my-method")

Fixtures
--------
railtherm_register
    ``railtherm_register(name, plugin_obj, autoload=False)`` installs a fresh plugin host holding core
    and the given plugin for the duration of the test (set ``autoload=True`` to keep entry points).
canonical_scenes
    Scenes every method should either solve or refuse with a reason.
"""
from __future__ import annotations

import copy

import numpy as np

from .errors import Refused

_MAT = {"shear_modulus": 82e9, "poisson_ratio": 0.28, "density": 7850.0, "specific_heat": 450.0,
        "conductivity": 50.0, "thermal_expansion": 12e-6, "bulk_temperature": 0.0}

#: scenes every method should solve or refuse (study vocabulary, materials included)
CANONICAL_SCENES = {
    "ellipse-full-sliding": {"name": "ellipse-full-sliding", "normal_force": 100e3,
                             "contact": {"shape": "ellipse", "semi_axes": [5.88e-3, 10.54e-3]}, "speed": 30.0,
                             "sliding_speed": 1.0, "friction": 0.3, "heat_partition": 0.5,
                             "wheel": _MAT, "rail": _MAT},
    "line-full-sliding": {"name": "line-full-sliding", "normal_force": 1e6,
                          "contact": {"shape": "line", "wheel_radius": 0.46}, "speed": 10.0, "sliding_speed": 0.5,
                          "friction": 0.3, "heat_partition": 0.5, "wheel": _MAT, "rail": _MAT},
    "ellipse-given-flux": {"name": "ellipse-given-flux", "speed": 1.0,
                           "heat_source": {"flux": 1e6, "shape": "uniform", "semi_axes": [4e-3, 4e-3]},
                           "heat_partition": 0.0, "wheel": _MAT, "rail": _MAT},
    "line-given-flux": {"name": "line-given-flux", "speed": 10.0,
                        "heat_source": {"flux": 1e7, "shape": "hertz", "half_width": 2e-3},
                        "heat_partition": 0.5, "wheel": _MAT, "rail": _MAT},
    "ellipse-creepage": {"name": "ellipse-creepage", "normal_force": 82e3,
                         "contact": {"shape": "ellipse", "semi_axes": [8e-3, 4e-3]}, "speed": 30.0,
                         "creepage": {"longitudinal": -1e-3, "lateral": 0.0, "spin": 0.0}, "friction": 0.3,
                         "heat_partition": 0.5, "wheel": _MAT, "rail": _MAT},
}


def canonical(name: str, **changes) -> dict:
    """A copy of a canonical scene with ``changes`` applied (top-level keys)."""
    s = copy.deepcopy(CANONICAL_SCENES[name])
    s.update(changes)
    return s


def check_model_class(cls) -> None:
    """Static checks of a stage-model class: name, description, stages, capabilities, options."""
    from .schema import VARIABLES
    from .stages import STAGES, Capabilities, Option, StageModel
    assert isinstance(cls, type) and issubclass(cls, StageModel), f"{cls!r} is not a StageModel"
    assert cls.name and isinstance(cls.name, str), f"{cls!r} has no name"
    assert cls.description, f"model {cls.name!r} has no description"
    assert cls.__doc__ and cls.__doc__.strip(), f"model {cls.name!r} has no docstring"
    assert cls.stages and all(s in STAGES for s in cls.stages), f"model {cls.name!r}: bad stages {cls.stages}"
    assert isinstance(cls.capabilities, Capabilities)
    unknown = set(cls.capabilities.provides) - set(VARIABLES)
    assert not unknown, f"model {cls.name!r} provides unknown variables {unknown}"
    for k, opt in cls.options.items():
        assert isinstance(opt, Option) and opt.doc, f"model {cls.name!r}: option {k!r} needs an Option with doc"


def check_method(method: str, scenes=None, level: int = 0) -> dict:
    """Run the conformance checks of ``method`` on the canonical scenes; return {scene: "ok"|reason}.

    For every scene the method either returns a valid result (schema validated, asked outputs present,
    finite, deterministic, energy conserved within 2 % where a heat flux is reported) or raises
    :class:`railtherm.Refused` with a non-empty message. A scene asking only for contact outputs must
    not run a temperature stage.
    """
    from .metrics import heat_balance
    from .pipeline import plan, solve
    from .plugins import get_host
    from .scene import load_scene
    from .schema import validate_dataset

    host = get_host()
    info = host.method(method)
    for m in info.models:
        check_model_class(m.cls)
    outcome = {}
    for raw in (scenes or CANONICAL_SCENES.values()):
        sc = load_scene(raw)
        try:
            ds = solve(sc, method, level)
        except Refused as exc:
            assert str(exc).strip(), f"method {method!r} refused scene {sc.name!r} without a reason"
            outcome[sc.name] = f"refused: {exc}"
            continue
        validate_dataset(ds, info.plugin)
        for out in sc.outputs:
            assert out in ds, f"method {method!r}: asked output {out!r} missing on scene {sc.name!r}"
        again = solve(sc, method, level, validate=False)
        for name in sc.outputs:
            np.testing.assert_array_equal(ds[name].values, again[name].values,
                                          err_msg=f"method {method!r} is not deterministic for {name!r}")
        hb = heat_balance(ds)
        if np.isfinite(hb):
            assert abs(hb) < 0.02, f"method {method!r}, scene {sc.name!r}: heat balance off by {hb:.3%}"
        outcome[sc.name] = "ok"
        if sc.heat_source is None:
            only = load_scene(dict(raw, outputs=["max_pressure"]))
            try:
                pl = plan(only, method, level)
            except Refused:
                continue
            assert "temperature" not in pl.stages, \
                f"method {method!r} would run a temperature stage for contact outputs only ({pl.describe()})"
    return outcome


# ---------------------------------------------------------------------------------------------
# pytest plugin
try:
    import pytest
except ImportError:  # pragma: no cover
    pytest = None

if pytest is not None:

    @pytest.fixture
    def railtherm_register():
        """Install a fresh plugin host with core plus inline plugins for one test."""
        from . import plugins as _p
        saved = _p._HOST

        def register(name, obj, autoload=False, strict=True):
            host = _p.new_host([(name, obj)], autoload=autoload, strict=strict)
            _p.set_host(host)
            return host

        yield register
        _p.set_host(saved)

    @pytest.fixture
    def canonical_scenes():
        """Canonical scenes (study vocabulary) keyed by name."""
        return copy.deepcopy(CANONICAL_SCENES)
