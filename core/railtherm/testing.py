"""Plugin conformance kit: a pytest plugin (entry point ``pytest11: railtherm``) and plain functions.

Any plugin, built-in or third-party, runs it against itself::

    # tests/test_my_plugin.py of your distribution
    import pytest
    from railtherm.testing import check_method, check_model_class, CANONICAL_SCENES

    def test_conformance(railtherm_register):
        railtherm_register("mine", my_package.plugin)        # inline registration, no entry point needed
        check_method("my-method")

``check_method`` checks the form of every result and the physics: a method must solve at least one
canonical scene, be within 10 % of core's exact reference on at least one, and balance energy on its
computed temperature field (see :func:`check_method`).

Fixtures
--------
railtherm_register
    ``railtherm_register(name, plugin_obj, autoload=False)`` installs a fresh plugin host holding core
    and the given plugin for the duration of the test (set ``autoload=True`` to keep entry points).
canonical_scenes
    Scenes every method should either solve or refuse with a reason (and solve at least one).
"""
from __future__ import annotations

import copy

import numpy as np

from .contract.errors import Refused

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
    from .contract.schema import VARIABLES
    from .contract.stages import STAGES, Capabilities, Option, StageModel
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
    # plugin API 2: the model implements the compute method of its stage (a coupled model: compute
    # with the plan's Upstream)
    import inspect
    from .contract.stages import (CoupledModel, HeatSourceModel, NormalContactModel, TangentialContactModel,
                         TemperatureModel)
    for base, meth in ((CoupledModel, "compute"), (NormalContactModel, "compute_patch"),
                       (TangentialContactModel, "compute_tangential"), (HeatSourceModel, "compute_source"),
                       (TemperatureModel, "compute_temperature")):
        if issubclass(cls, base):
            assert getattr(cls, meth) is not getattr(base, meth), f"model {cls.name!r} does not implement {meth}"
            if base is CoupledModel:
                params = list(inspect.signature(cls.compute).parameters)
                assert len(params) >= 6, (f"coupled model {cls.name!r}: compute{tuple(params)} lacks the plan's "
                                          "'upstream' argument (plugin API 2: compute(scene, level, options, stages, "
                                          "upstream))")
            break


#: relative error of a scene's headline quantity (and of every scalar with an exact reference) within
#: which the kit counts the scene as verified: loose, it catches wrong physics, not coarse grids
TOLERANCE = 0.10
#: |energy balance| of the computed temperature field allowed on every scene that is not inaccurate
#: (a temperature that falls back to the bulk value where the flux ends is 13-20 % off, a field
#: flattened to its exact maximum 23-85 %; the README's 1-D Duhamel example about 0.1 %)
ENERGY_TOLERANCE = 0.10


def _flux_balance(ds) -> float:
    """(integrated heat flux into both bodies - frictional power) / frictional power [1], NaN if n/a."""
    if "heat_flux" not in ds or "frictional_power" not in ds:
        return float("nan")
    p = float(ds["frictional_power"])
    if p == 0:
        return float("nan")
    dx = float(np.diff(ds["x"].values).mean()) if ds.sizes["x"] > 1 else 1.0
    dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims and ds.sizes["y"] > 1 else 1.0
    return (float(ds["heat_flux"].sum()) * dx * dy - p) / p


def _headline(scene) -> str:
    from .analysis.metrics import headline
    return headline(scene)


def _exact_errors(scene, ds) -> dict[str, tuple[float, str]]:
    """Errors of scalar results against core's exact references: quantity -> (error, reference tag).

    Quantities that a model of the chain reproduces by construction (e.g. Hertz's pressure from the
    ``hertz`` model) are not errors (see :func:`railtherm.metrics.run_errors`).
    """
    from .analysis.analytic import reference_values
    from .analysis.metrics import SCALARS, run_errors
    ref = reference_values(scene)
    ref.pop("_names", None)
    out = {}
    for k, v in run_errors(scene, ds, ref).items():
        err, tag = v
        if k in SCALARS and np.isfinite(err) and str(tag).startswith("analytic"):
            out[k] = (float(err), str(tag))
    return out


def check_method(method: str, scenes=None, level: int = 0, *, tolerance: float = TOLERANCE,
                 energy_tolerance: float = ENERGY_TOLERANCE) -> dict:
    """Run the conformance checks of ``method`` on the canonical scenes; return {scene: "ok"|"refused: ..."}.

    Form: for every scene the method either returns a valid result (schema validated, asked outputs
    present, finite, deterministic, the heat flux integrating to the frictional power within 2 %
    where both are reported) or raises :class:`railtherm.Refused` with a non-empty message and a
    kind in ``Refused.KINDS`` ("validity", "budget"). A scene asking only for a normal-contact output
    runs the normal stage only. The method's chain is plugin API 2 (stages normal, tangential,
    heat_source, temperature) and each model implements its stage's compute method.

    Physics (on the results at ``level``):

    * the method solves at least one scene (refusing everything fails);
    * on at least one scene it is *verified*: the scene's headline quantity (docs/verdicts.md) has
      an exact reference in core (:func:`railtherm.analytic.reference_values`) and every scalar
      with an exact reference is within ``tolerance`` (10 %) of it;
    * on every verified scene, the energy balance of the computed temperature field
      (:func:`railtherm.metrics.energy_balance`) is within ``energy_tolerance`` (10 %) where it
      can be evaluated (a field right at its maximum but wrong elsewhere fails here). A scene whose headline is off by more than ``tolerance`` is reported, and
      tolerated, as long as another scene is verified (coarse levels may be inaccurate).

    Raises
    ------
    AssertionError
        Naming the method, the scene, the quantity, its error and the reference.
    """
    from .analysis import metrics
    from .solving.pipeline import plan, solve
    from .solving.plugins import get_host
    from .input.scene import load_scene
    from .contract.schema import validate_dataset

    host = get_host()
    info = host.method(method)
    assert not info.api1, (f"method {method!r} is registered with a plugin API 1 chain ({'; '.join(info.api1)}); "
                           "name the stages normal, tangential, heat_source, temperature (docs/plugins.md)")
    for m in info.models:
        for cls in m.classes:
            check_model_class(cls)
    outcome = {}
    solved = []
    refusals = []
    raws = list(scenes or CANONICAL_SCENES.values())
    for raw in raws:
        sc = load_scene(raw)
        try:
            ds = solve(sc, method, level)
        except Refused as exc:
            assert str(exc).strip(), f"method {method!r} refused scene {sc.name!r} without a reason"
            kind = getattr(exc, "kind", None)
            assert kind in Refused.KINDS, (f"method {method!r} refused scene {sc.name!r} with reason kind "
                                           f"{kind!r}; allowed: {', '.join(Refused.KINDS)}")
            outcome[sc.name] = f"refused: {exc}"
            refusals.append(f"{sc.name}: {exc}")
            continue
        validate_dataset(ds, info.plugin)
        for out in sc.outputs:
            assert out in ds, f"method {method!r}: asked output {out!r} missing on scene {sc.name!r}"
        again = solve(sc, method, level, validate=False)
        for name in sc.outputs:
            np.testing.assert_array_equal(ds[name].values, again[name].values,
                                          err_msg=f"method {method!r} is not deterministic for {name!r}")
        hb = _flux_balance(ds)
        if np.isfinite(hb):
            assert abs(hb) < 0.02, (f"method {method!r}, scene {sc.name!r}: the heat flux integrates to the "
                                    f"frictional power {hb:+.3%} off (allowed: 2 %)")
        outcome[sc.name] = "ok"
        solved.append((sc, ds))
        if sc.heat_source is None:
            only = load_scene(dict(raw, outputs=["max_pressure"]))
            try:
                pl = plan(only, method, level)
            except Refused:
                continue
            assert pl.stages == ("normal",), \
                f"method {method!r} would run {pl.stages} for a normal-contact output only ({pl.describe()})"

    assert solved, (f"method {method!r} refused every one of the {len(raws)} scenes it was given at level "
                    f"{level}; a method must solve at least one: " + "; ".join(refusals))

    energy = getattr(metrics, "energy_balance", None)
    verified, notes = [], []
    for sc, ds in solved:
        errs = _exact_errors(sc, ds)
        head = _headline(sc)
        if head in errs:
            worst = max(errs, key=lambda k: errs[k][0])
            if errs[worst][0] <= tolerance:
                verified.append(sc.name)
            else:
                e, tag = errs[head]
                note = f"scene {sc.name!r}: {head} off by {e:.3g} against {tag}"
                if worst != head:
                    note += f" ({worst} off by {errs[worst][0]:.3g})"
                notes.append(note)
                continue  # inaccurate at this level: its energy is not held against it
        else:
            # no exact reference: the heat source itself may be unresolved at this level (FASTSIM's
            # slip power in one trailing cell), so its energy balance measures resolution, not physics
            notes.append(f"scene {sc.name!r}: no exact reference for its headline {head!r}")
            continue
        if energy is not None:
            eb, ref = energy(sc, ds)
            if np.isfinite(eb):
                assert abs(eb) <= energy_tolerance, (
                    f"method {method!r}, scene {sc.name!r}, level {level}: energy balance of the computed "
                    f"temperature field {eb:+.3g} ({ref}; heat entering through the surface vs frictional "
                    f"power) exceeds {energy_tolerance:.0%}")
    assert verified, (f"method {method!r} is within {tolerance:.0%} of core's exact references on no scene at "
                      f"level {level}: " + "; ".join(notes))
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
        from .solving import plugins as _p
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
