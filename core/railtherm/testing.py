"""Plugin conformance kit: a pytest plugin (entry point ``pytest11: railtherm``) and plain functions.

Any plugin, built-in or third-party, runs it against itself::

    from railtherm.testing import check_method
    def test_conformance(railtherm_register):
        railtherm_register("mine", my_package.plugin)        # inline registration, no entry point needed
        check_method("my-method")

:func:`check_method` checks the form of every result and the physics (solves at least one canonical
scene, within 10 % of core's exact reference on one, balances energy, keeps core's sign conventions).
Fixtures: ``railtherm_register(name, plugin_obj, autoload=False)`` installs a fresh plugin host holding
core and the given plugin for the test; ``canonical_scenes`` are the scenes every method should solve or
refuse with a reason.
"""
from __future__ import annotations

import copy
import inspect

import numpy as np

from .contract.capabilities import Capabilities
from .contract.errors import PluginError, Refused
from .contract.options import Option
from .contract.schema import VARIABLES, validate_dataset
from .contract.stages import (STAGES, CoupledModel, HeatSourceModel, NormalContactModel, StageModel,
                              TangentialContactModel, TemperatureModel)

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


# ---------------------------------------------------------------------------------------------
# Sign conventions of the tangential stage (docs/plugins.md, "Sign conventions"), checked on every
# tangential model a method declares: material flows towards -x through the patch; traction_x/y is the
# traction on the wheel [Pa]; slip_velocity_x/y the slip velocity of the wheel relative to the rail
# [m/s]; the dissipation -(traction . slip) [W/m^2] is >= 0 in every cell and is core's frictional heat.

#: a cell's dissipation may fall below zero by this fraction of the largest cell value (round-off of an
#: iterative tangential solve); a sign error makes it -100 %
DISSIPATION_ROUNDOFF = 1e-3
#: |frictional power - integral of -(traction . slip)| allowed under full sliding, relative [1]: core's
#: frictional heat source integrates what the tangential model returns (1e-15 for the built-in models),
#: the FEM its own discretisation of the heat (0.3 % at level 0)
POWER_TOLERANCE = 0.02
#: canonical scenes with a computed contact on which every tangential model is checked
CONTACT_SCENES = ("ellipse-full-sliding", "line-full-sliding", "ellipse-creepage")
_TANGENTIAL_OUTPUTS = ("traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "creep_force_x")


def rigid_slip_x(scene) -> float:
    """The rigid slip velocity of the wheel relative to the rail along the rolling direction [m/s].

    With material flowing towards -x, the wheel surface passes the patch at V (1 - xi) and the rail at V
    (:func:`railtherm.physics.kinematics.creep_speeds`), so the wheel slips at V xi relative to the rail;
    full sliding at v_s is xi = -v_s / V, a slip of -v_s. Friction on the wheel opposes this slip.
    """
    if getattr(scene, "creepage", None) is not None:
        return float(scene.speed) * float(scene.creepage.longitudinal)
    return -float(getattr(scene, "sliding_speed", None) or 0.0)


def dissipation(ds) -> np.ndarray:
    """-(traction . slip velocity) per cell of a result [W/m^2] (0 where a field is NaN or absent)."""
    d = np.zeros(ds["traction_x"].shape)
    for t, v in (("traction_x", "slip_velocity_x"), ("traction_y", "slip_velocity_y")):
        if t in ds and v in ds:
            d = d - np.nan_to_num(ds[t].values) * np.nan_to_num(ds[v].values)
    return d


def check_tangential_result(where: str, scene, ds) -> None:
    """The sign conventions on one result of a tangential model (and of its heat source, when it ran).

    * -(traction . slip) >= 0 in every cell (within :data:`DISSIPATION_ROUNDOFF` of the largest cell);
    * the slip summed over the patch has the sign of the rigid slip :func:`rigid_slip_x`, and the creep
      force on the wheel the opposite sign (friction opposes the wheel's slip);
    * where a heat source ran: the heat flux into both bodies >= 0 in every cell, the frictional power
      >= 0, and under full sliding equal to the integral of -(traction . slip) within :data:`POWER_TOLERANCE`
      (under creepage a slip zone narrower than a cell makes the product of cell values differ from the
      cell's mean dissipation: FASTSIM's line contact at 16 cells, 1257 W against 2365 W, 1553 W at 256).

    Raises
    ------
    AssertionError
        Naming ``where``, the quantity, its value and the convention.
    """
    conv = ("(traction acts on the wheel, slip is the wheel's relative to the rail, material flows towards -x: "
            "dissipation = -traction . slip >= 0; docs/plugins.md, sign conventions)")
    d = dissipation(ds)
    top = float(np.max(np.abs(d)))
    assert float(d.min()) >= -DISSIPATION_ROUNDOFF * top, (
        f"{where}: -(traction . slip) = {float(d.min()):.4g} W/m^2 in a cell (largest |value| {top:.4g}) "
        f"{conv}")
    rigid = rigid_slip_x(scene)
    longitudinal = getattr(scene, "wheelset", None) is None and (
        scene.creepage is None or (scene.creepage.lateral == 0.0 and scene.creepage.spin == 0.0))
    if rigid != 0.0 and longitudinal:
        slip = float(np.nansum(ds["slip_velocity_x"].values))
        assert slip * rigid > 0.0, (f"{where}: the slip velocity along x sums to {slip:.4g} m/s over the patch, "
                                    f"against the rigid slip {rigid:.4g} m/s of the wheel relative to the rail {conv}")
        if "creep_force_x" in ds:
            fx = float(ds["creep_force_x"])
            assert fx * rigid < 0.0, (f"{where}: creep force on the wheel {fx:.4g} N has the sign of its rigid "
                                      f"slip {rigid:.4g} m/s; friction opposes the slip {conv}")
    if "frictional_power" not in ds:
        return
    q = ds["heat_flux"].sum("body").values
    assert float(np.nanmin(q)) >= -DISSIPATION_ROUNDOFF * float(np.nanmax(np.abs(q))), (
        f"{where}: the heat flux into the bodies is {float(np.nanmin(q)):.4g} W/m^2 in a cell: a heat sink that "
        f"cools the bodies below their bulk temperature {conv}")
    power, integral = float(ds["frictional_power"]), float(d.sum()) * _cell_area(ds)
    assert power >= 0.0, f"{where}: frictional power {power:.4g} W < 0 {conv}"
    if scene.creepage is None and getattr(scene, "wheelset", None) is None:
        # full sliding: every contact cell slips at v_s, so the cell values give the dissipation exactly (under
        # creepage the slip zone may be a fraction of a cell, and a product of cell values is not its mean)
        assert abs(power - integral) <= POWER_TOLERANCE * abs(integral), (
            f"{where}: frictional power {power:.4g} W, but the integral of -(traction . slip) is {integral:.4g} W "
            f"(allowed difference {POWER_TOLERANCE:.0%}) {conv}")


def _declared(info) -> list[tuple[str, str]]:
    """(stage, model name) of every candidate model of the method's chain, in pipeline order."""
    return [(stage, name) for stage, names in info.stages.items() for name in names]


def _tangential_chain(info, model: str) -> dict:
    """The method's chain up to its heat source with ``model`` its only tangential candidate."""
    chain = {s: tuple(v) for s, v in info.stages.items() if s in ("normal", "heat_source")}
    return {"name": f"{info.name}[tangential={model}]", **chain, "tangential": (model,)}


def check_tangential_models(method: str, raws, level: int = 0) -> dict[str, str]:
    """Run every tangential model ``method`` declares on every contact scene of ``raws`` and on
    :data:`CONTACT_SCENES` (up to the method's heat source) and check the sign conventions
    (:func:`check_tangential_result`). Returns {model: what was checked}.

    A declared model must run on at least one of these scenes, unless core's capability checks or its
    ``supports`` decline every one of them (the note says so).
    """
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .input.scene import LATERAL_OUTPUTS, load_scene
    from .solving.capabilities_check import refusal
    from .solving.pipeline import solve
    from .solving.plugins import get_host
    host = get_host()
    info = host.method(method)
    scenes = list(raws) + [CANONICAL_SCENES[n] for n in CONTACT_SCENES
                           if n not in {r.get("name") for r in raws}]
    notes = {}
    for stage, name in _declared(info):
        if stage != "tangential":
            continue
        cls = host.model(name).for_stage("tangential")
        lacking = {"traction_x", "slip_velocity_x"} - set(cls.capabilities.provides)
        assert not lacking, (f"method {method!r}: tangential model {name!r} does not provide {sorted(lacking)}; "
                             "core's frictional heat and the sign checks need the traction and the slip")
        outputs = [o for o in _TANGENTIAL_OUTPUTS if o in cls.capabilities.provides]
        chain = _tangential_chain(info, name)
        if "heat_source" in chain:
            outputs += ["frictional_power", "heat_flux"]
        ran, declined = [], []
        for raw in scenes:
            if load_scene(raw).heat_source is not None:
                continue
            line = load_scene(raw).contact_shape == "line"
            sc = load_scene(dict(raw, outputs=[o for o in outputs if not (line and o in LATERAL_OUTPUTS)]))
            try:
                ds = solve(sc, chain, level)
            except PluginError as exc:
                raise AssertionError(f"method {method!r}, tangential model {name!r}, scene {sc.name!r}, "
                                     f"level {level}: {exc}") from exc
            except Refused as exc:
                declined.append(f"{sc.name}: {exc}")
                continue
            check_tangential_result(f"method {method!r}, tangential model {name!r}, scene {sc.name!r}, "
                                    f"level {level}", sc, ds)
            ran.append(sc.name)
        assert ran or all(refusal(cls(), load_scene(r), level) for r in scenes if "heat_source" not in r), (
            f"method {method!r}: tangential model {name!r} ran on none of the contact scenes: " + "; ".join(declined))
        notes[name] = (f"sign conventions checked on {', '.join(ran)}" if ran
                       else f"not exercised: it declines every contact scene ({declined[0] if declined else ''})")
    return notes


def check_other_models(method: str, raws, level: int, ran: set) -> dict[str, str]:
    """Run every normal, heat-source and temperature model ``method`` declares that the method's own
    selection did not run on ``raws`` (``ran``: the (stage, model) pairs it ran), as the only candidate of
    its stage, and check the result's form. Returns {model: what was checked}.

    A declared model must run on at least one scene, unless core's capability checks or its ``supports``
    decline every one of them (a wheelset normal model on scenes without a wheelset: the note says so).
    """
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .input.scene import load_scene
    from .solving.capabilities_check import refusal
    from .solving.pipeline import solve
    from .solving.plugins import get_host
    host = get_host()
    info = host.method(method)
    scenes = list(raws) + [CANONICAL_SCENES[n] for n in CONTACT_SCENES if n not in {r.get("name") for r in raws}]
    notes = {}
    for stage, name in _declared(info):
        if stage == "tangential" or (stage, name) in ran:
            continue
        cls = host.model(name).for_stage(stage)
        chain = {"name": f"{method}[{stage}={name}]", **info.stages, stage: (name,)}
        done, declined = [], []
        for raw in scenes:
            sc = load_scene(raw)
            try:
                ds = solve(sc, chain, level)
            except Refused as exc:
                declined.append(f"{sc.name}: {exc}")
                continue
            validate_dataset(ds, info.plugin)
            if f"{stage}:{name}" in ds.attrs["stages"].split():
                done.append(sc.name)
        assert done or all(refusal(cls(), load_scene(r), level) for r in scenes), (
            f"method {method!r}: {stage} model {name!r} ran on none of the scenes: " + "; ".join(declined))
        notes[name] = (f"ran on {', '.join(done)}" if done
                       else f"not exercised: it declines every scene ({declined[0] if declined else ''})")
    return notes


#: relative error of a scene's headline quantity (and of every scalar with an exact reference) within
#: which the kit counts the scene as verified: loose, it catches wrong physics, not coarse grids
TOLERANCE = 0.10
#: |energy balance| of the computed temperature field allowed on every scene that is not inaccurate
#: (a temperature that falls back to the bulk value where the flux ends is 13-20 % off, a field
#: flattened to its exact maximum 23-85 %; the README's 1-D Duhamel example about 0.1 %)
ENERGY_TOLERANCE = 0.10


def _cell_area(ds) -> float:
    """Area of one surface cell of a result [m^2] (its length dx [m] for a line contact: per unit width)."""
    dx = float(np.diff(ds["x"].values).mean()) if ds.sizes["x"] > 1 else 1.0
    dy = float(np.diff(ds["y"].values).mean()) if "y" in ds.dims and ds.sizes["y"] > 1 else 1.0
    return dx * dy


def _flux_balance(ds) -> float:
    """(integrated heat flux into both bodies - frictional power) / frictional power [1], NaN if n/a."""
    if "heat_flux" not in ds or "frictional_power" not in ds:
        return float("nan")
    p = float(ds["frictional_power"])
    if p == 0:
        return float("nan")
    return (float(ds["heat_flux"].sum()) * _cell_area(ds) - p) / p


def _headline(scene) -> str:
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .analysis.metrics import headline
    return headline(scene.outputs)


def _exact_errors(scene, ds) -> dict[str, tuple[float, str]]:
    """Errors of scalar results against core's exact references: quantity -> (error, reference tag).

    Quantities that a model of the chain reproduces by construction (e.g. Hertz's pressure from the
    ``hertz`` model) are not errors (see :func:`railtherm.analysis.metrics.run_errors`).
    """
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .analysis.analytic import reference_values
    from .analysis.metrics import SCALARS, run_errors
    ref = reference_values(scene)
    ref.pop("_names", None)
    out = {}
    for k, v in run_errors(scene, ds, ref).items():
        err, tag = v
        # inf: a non-finite result against a finite reference, a failing error (never dropped); NaN: no score
        if k in SCALARS and not np.isnan(err) and str(tag).startswith("analytic"):
            out[k] = (float(err), str(tag))
    return out


class Outcome(dict):
    """{scene: "ok" | "refused: <reason>"} of :func:`check_method`, with ``models``: {model: what the kit
    checked on it} for every stage model the method declares."""

    models: dict


def check_method(method: str, scenes=None, level: int = 0, *, tolerance: float = TOLERANCE,
                 energy_tolerance: float = ENERGY_TOLERANCE) -> Outcome:
    """Run the conformance checks of ``method`` on the canonical scenes; return {scene: "ok"|"refused: ..."}.

    Form: for every scene the method either returns a valid result (schema validated, asked outputs
    present, finite, deterministic, the heat flux integrating to the frictional power within 2 %
    where both are reported) or raises :class:`railtherm.Refused` with a non-empty message and a
    kind in ``Refused.KINDS`` ("validity", "budget"). A scene asking only for a normal-contact output
    runs the normal stage only. The method's chain is plugin API 2 (stages normal, tangential,
    heat_source, temperature) and each model implements its stage's compute method and has a class
    docstring (:func:`check_model_class`).

    Every stage model the method declares runs on a scene where its stage runs: each tangential model on
    the contact scenes (a creepage scene among them), checked against the sign conventions
    (:func:`check_tangential_models`: -(traction . slip) >= 0 in every cell, slip and creep force
    against the rigid slip, heat flux >= 0, frictional power = the integral of -(traction . slip));
    each other candidate the method's selection did not run, as the only candidate of its stage
    (:func:`check_other_models`). A model that core's capability checks or its ``supports`` decline on
    every scene is noted, not run.

    Physics (on the results at ``level``):

    * the method solves at least one scene (refusing everything fails);
    * on at least one scene it is *verified*: the scene's headline quantity (docs/verdicts.md) has
      an exact reference in core (:func:`railtherm.analysis.analytic.reference_values`) and every scalar
      with an exact reference is within ``tolerance`` (10 %) of it;
    * on every verified scene, the energy balance of the computed temperature field
      (:func:`railtherm.analysis.metrics.energy_balance`) is within ``energy_tolerance`` (10 %) where it
      can be evaluated (a field right at its maximum but wrong elsewhere fails here). A scene whose
      headline is off by more than ``tolerance`` is reported, and tolerated, as long as another scene
      is verified (coarse levels may be inaccurate).

    Raises
    ------
    AssertionError
        Naming the method, the scene, the quantity, its error and the reference.
    """
    from .solving.plugins import get_host  # here: solving/ costs ~0.4 s; the kit is loaded by every pytest session

    info = get_host().method(method)
    for m in info.models:
        for cls in m.classes:
            check_model_class(cls)
    raws = list(scenes or CANONICAL_SCENES.values())
    outcome = Outcome()
    solved = _solve_scenes(info, raws, level, outcome)
    models = check_tangential_models(method, raws, level)
    _check_accuracy(method, solved, level, tolerance, energy_tolerance)
    ran = {tuple(s.split(":", 1)) for _, ds in solved for s in ds.attrs["stages"].split()}
    models.update({name: "ran in the method's chain" for stage, name in _declared(info)
                   if (stage, name) in ran and name not in models})
    models.update(check_other_models(method, raws, level, ran))
    outcome.models = models
    return outcome


def _solve_scenes(info, raws, level: int, outcome: dict) -> list:
    """Solve every scene with the method, check the form of each result (or refusal) and fill ``outcome``;
    returns [(scene, result)] of the solved ones (at least one, else AssertionError)."""
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .input.scene import load_scene
    from .solving.pipeline import plan, solve
    method = info.name
    solved, refusals = [], []
    for raw in raws:
        sc = load_scene(raw)
        try:
            ds = solve(sc, method, level)
        except PluginError as exc:   # core caught a broken contract (e.g. a negative frictional heat)
            raise AssertionError(f"method {method!r}, scene {sc.name!r}, level {level}: {exc}") from exc
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
    return solved


def _check_accuracy(method: str, solved, level: int, tolerance: float, energy_tolerance: float) -> None:
    """Verified on at least one scene, and the energy balance on every verified scene (:func:`check_method`)."""
    # here, not at the top: this kit is a pytest plugin that every pytest session loads, and solving/ and
    # analysis/ cost ~0.5 s to import
    from .analysis import metrics
    from .physics import body_speeds
    energy = getattr(metrics, "energy_balance", None)
    verified, notes = [], []
    for sc, ds in solved:
        errs = _exact_errors(sc, ds)
        head = _headline(sc)
        if head not in errs:
            # no exact reference: the heat source itself may be unresolved at this level (FASTSIM's
            # slip power in one trailing cell), so its energy balance measures resolution, not physics
            notes.append(f"scene {sc.name!r}: no exact reference for its headline {head!r}")
            continue
        worst = max(errs, key=lambda k: errs[k][0])
        if errs[worst][0] > tolerance:
            e, tag = errs[head]
            note = f"scene {sc.name!r}: {head} off by {e:.3g} against {tag}"
            if worst != head:
                note += f" ({worst} off by {errs[worst][0]:.3g})"
            notes.append(note)
            continue  # inaccurate at this level: its energy is not held against it
        verified.append(sc.name)
        if energy is not None:
            eb, ref = energy(ds, body_speeds(sc.speed, sc.sliding_speed, sc.tangential), sc.wheel, sc.rail)
            if np.isfinite(eb):
                assert abs(eb) <= energy_tolerance, (
                    f"method {method!r}, scene {sc.name!r}, level {level}: energy balance of the computed "
                    f"temperature field {eb:+.3g} ({ref}; heat entering through the surface vs frictional "
                    f"power) exceeds {energy_tolerance:.0%}")
    assert verified, (f"method {method!r} is within {tolerance:.0%} of core's exact references on no scene at "
                      f"level {level}: " + "; ".join(notes))


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
        from .solving import plugins as _p  # here: solving/ costs ~0.4 s, paid only by a test that uses this
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
