"""Run one scene through one method at one level: plan the stages the outputs need, run them, build
and validate the result Dataset.

Planning (:func:`plan`): each requested output belongs to one of the four stages (normal,
tangential, heat source, temperature; :data:`railtherm.contract.schema.VARIABLES`); the stages up to the last
one needed run, no others. A scene that gives its heat source runs no normal or tangential stage
(core model "given" supplies the source, also to a coupled model).
"""
from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from .._version import __version__
from ..contract.errors import PluginError, Refused, SceneError, SolverError
from ..contract.grid import BASE_CELLS
from ..contract.options import check_options
from ..contract.results import ContactPatch
from ..contract.schema import (STAGE_OF_GROUP, VARIABLES, WHEELSET_VARIABLES, build_dataset, encode_sweep,
                               history_line, validate_dataset)
from ..contract.stages import STAGES, CoupledModel, StageModel, Upstream
from ..input.scene import LATERAL_OUTPUTS as LATERAL, Scene, load_scene
from ..models.sliding import GivenHeat
from .capabilities_check import refusal, source_refusal
from .friction_loop import needs_loop, solve_coupled
from .plugins import MethodInfo, PluginHost, get_host
from .wheelset_patches import solve_patches

__all__ = ["solve", "solve_time", "plan", "given_heat_source", "Plan", "duplicate_of"]




def check_level(level, *, where: str = "") -> int:
    """``level`` as an int, or :class:`railtherm.SceneError` unless it is a non-negative integer."""
    ok = (isinstance(level, (int, np.integer)) and not isinstance(level, bool)) or (
        isinstance(level, (float, np.floating)) and float(level).is_integer())
    if not ok or int(level) < 0:
        raise SceneError(f"{where}key 'level' = {level!r} is not allowed: an integer >= 0",
                         key="level", value=level, allowed="an integer >= 0")
    return int(level)


def _check_options(mi: MethodInfo, options, scene: str) -> dict:
    """Validate method options: unknown keys and bad values are :class:`railtherm.SceneError`."""
    try:
        return check_options(mi, dict(options or {}), method=mi.name)
    except SceneError as exc:
        if exc.scene is None and scene:
            raise SceneError(f"scene {scene!r}, method {mi.name!r}: {exc}", scene=scene, key=exc.key,
                             value=exc.value, allowed=exc.allowed) from None
        raise


def given_heat_source(scene: Scene, level: int, cells: int | None = None):
    """The :class:`railtherm.HeatSource` a scene gives, on the grid of ``level``."""
    return GivenHeat().compute_source(scene, None, level, {"cells": cells})


@dataclass
class Plan:
    """Models selected for a (scene, method, level) and the stages that will run."""

    method: MethodInfo
    stages: tuple[str, ...]
    models: dict[str, StageModel]

    def describe(self) -> str:
        return ", ".join(f"{s}={self.models[s].name}" for s in self.stages)


def _select(host: PluginHost, mi: MethodInfo, stage: str, scene: Scene, level: int) -> StageModel:
    reasons = []
    for name in mi.method.chain.get(stage, ()):
        model = host.model(name).for_stage(stage)()
        why = refusal(model, scene, level)
        if why is None:
            return model
        reasons.append(why)
    if not reasons:
        raise Refused(f"method {mi.name!r} has no {stage} model")
    raise Refused("; ".join(reasons))


def plan(scene: Scene, method: "str | Mapping[str, Any] | MethodInfo", level: int = 0,
         host: PluginHost | None = None) -> Plan:
    """Choose the models and the stages to run; raises :class:`railtherm.Refused` when impossible.

    Each output belongs to one stage (:data:`railtherm.contract.schema.VARIABLES`); the stages up to the last
    one an output needs run, no others, and the model selected for an output's stage must declare
    it in ``capabilities.provides``. A scene that gives its heat source runs no normal or
    tangential stage: core's ``given`` is its heat-source stage.
    """
    host = host or get_host()
    mi = method if isinstance(method, MethodInfo) else host.resolve(method)
    given = scene.heat_source is not None
    order = [s for s in STAGES if s in mi.method.chain]
    if given:
        order = [s for s in order if s not in ("normal", "tangential")]
        if "heat_source" not in order and "temperature" in order:
            order.insert(0, "heat_source")
    # the stages up to the last one an output needs, and no model chosen for any later stage (a model
    # of an unneeded stage must not refuse the scene)
    last = -1
    for out in scene.outputs:
        stage = STAGE_OF_GROUP[VARIABLES[out].stage]
        if stage not in order:
            extra = (" (the scene gives its heat source, so no normal or tangential stage runs)"
                     if given and stage in ("normal", "tangential") else "")
            raise Refused(f"method {mi.name!r} cannot compute output {out!r} for scene {scene.name!r}{extra}: "
                          f"it has no {stage} stage")
        last = max(last, order.index(stage))
    if needs_loop(scene.friction, scene.heat_source) and "tangential" in order[: last + 1]:
        # friction falling with temperature: the tangential stage needs the chain's temperatures
        if "temperature" not in order:
            raise Refused(f"method {mi.name!r} has no temperature stage, but the friction of scene {scene.name!r} "
                          f"depends on the surface temperature ({scene.friction.describe()}): use a method "
                          "or chain with a temperature model")
        last = order.index("temperature")
    models: dict[str, StageModel] = {}
    for stage in order[: last + 1]:
        models[stage] = host.model("given").cls() if given and stage == "heat_source" else \
            _select(host, mi, stage, scene, level)
    for out in scene.outputs:
        stage = STAGE_OF_GROUP[VARIABLES[out].stage]
        if out in WHEELSET_VARIABLES:   # the scene's contact search sets them, whatever the models
            continue
        if out not in models[stage].capabilities.provides:
            raise Refused(f"method {mi.name!r} cannot compute output {out!r} for scene {scene.name!r}: "
                          f"its {stage} model {models[stage].name!r}; its models provide: "
                          f"{sorted(set().union(*(m.capabilities.provides for m in models.values())))}")
    stages = tuple(order[: last + 1])
    return Plan(mi, stages, {s: models[s] for s in stages})


def _computation(pl: Plan, options: Mapping[str, Any] | None) -> tuple:
    """What a plan computes, grid resolution aside: per executed stage, the model's class and the options it
    resolves from ``options``. Two plans with equal computations differ at most in the cells of their grids
    (the same ladder of one model chain, level for level or shifted)."""
    return tuple((s, f"{type(m).__module__}.{type(m).__qualname__}",
                  json.dumps(m.resolve_options(options), sort_keys=True, default=str))
                 for s, m in ((s, pl.models[s]) for s in pl.stages))


def _own_stages(pl: Plan, host: PluginHost) -> tuple[str, ...]:
    """The executed stages whose model the method's own plugin registered (none for a study's chain)."""
    return tuple(s for s in pl.stages if host.models[pl.models[s].name].plugin == pl.method.plugin)


def duplicate_of(scene: Scene, method: "str | Mapping[str, Any] | MethodInfo", level: int,
                 peers, options: Mapping[str, Any] | None = None, host: PluginHost | None = None) -> str | None:
    """Why a run of ``method`` would repeat another method's computation on ``scene``, or None.

    Two methods whose executed stage models (class and resolved options, :func:`_computation`) are identical
    on a scene compute the same result, at most on another grid (``kalker`` on a given heat source runs only
    core's ``given`` and green's temperature model: green's result). One of them runs, the others are refused
    (validity): the one running a stage of its own plugin, else the first in ``peers``' order.

    Parameters
    ----------
    scene : Scene
    method : str, mapping or MethodInfo
        The method or study chain of the run.
    level : int
        The run's level (each peer is planned at the same level).
    peers : sequence of (method, options)
        The study's methods (names or chains) with their options, in study order; ``method`` may be among
        them (its position decides between two methods that both, or neither, run a stage of their own).
    options : mapping, optional
        The run's method options.

    Returns
    -------
    str or None
        The refusal's message, naming the method whose result this run would repeat.
    """
    host = host or get_host()
    scene = load_scene(scene)
    mi = method if isinstance(method, MethodInfo) else host.resolve(method)
    infos = [(host.resolve(spec), opts) for spec, opts in peers]
    order = [pi.name for pi, _ in infos]
    try:
        pl = plan(scene, mi, level, host)
    except Refused:
        return None
    mine = _computation(pl, options)

    def rank(p: Plan, name: str) -> tuple:
        return (0 if _own_stages(p, host) else 1, order.index(name) if name in order else len(order))

    for pi, opts in infos:
        if pi.name == mi.name:
            continue
        try:
            other = plan(scene, pi, level, host)
        except Refused:
            continue
        if _computation(other, opts) != mine or rank(other, pi.name) >= rank(pl, mi.name):
            continue
        own = _own_stages(pl, host)
        what = (f"runs no stage of its own on scene {scene.name!r} ({pl.describe()})" if not own else
                f"runs the same stage models as method {pi.name!r} on scene {scene.name!r} ({pl.describe()})")
        return f"method {mi.name!r} {what}; its result is {pi.name}'s (method {pi.name!r} runs the same models)"
    return None


def _flat_diagnostics(prefix: str, diag: Mapping[str, Any], out: dict) -> None:
    for k, v in (diag or {}).items():
        key = f"{prefix}_{k}".replace(" ", "_")
        if isinstance(v, (bool, np.bool_)):
            out[key] = int(v)
        elif isinstance(v, (int, float, np.integer, np.floating, str)):
            out[key] = v.item() if hasattr(v, "item") else v
        elif isinstance(v, (list, tuple, np.ndarray)) and len(v) and all(isinstance(t, (int, float, np.number)) for t in v):
            out[key] = np.asarray(v, dtype=float)
        else:
            out[key] = str(v)


_NORMAL_FIELDS = ("grid", "normal_force", "a", "b", "max_pressure", "pressure", "creepage", "contact_area")


def _check_untouched(model: StageModel, before: ContactPatch, after: ContactPatch) -> None:
    """A tangential model returns a new patch and leaves the normal stage's fields as they were."""
    if after is before:
        raise PluginError(f"tangential model {model.name!r} returned the patch it was given; return "
                          "patch.with_tangential(...) (a new patch)")
    for name in _NORMAL_FIELDS:
        x, y = getattr(before, name), getattr(after, name)
        same = x is y or (np.array_equal(x, y) if isinstance(x, np.ndarray) else x == y)
        if not same:
            raise PluginError(f"tangential model {model.name!r} changed the normal stage's {name!r}; a stage "
                              "never rewrites another's result")


#: a heat source computed from the tangential stage may be negative by this fraction of its largest cell
#: value (round-off of an iterative tangential solve); beyond it the tangential model broke the sign convention
NEGATIVE_HEAT_ROUNDOFF = 1e-3


def _check_heat_sign(pl: Plan, source) -> None:
    """Frictional heat is dissipation, -(traction . slip) >= 0 in every cell: a heat source computed from a
    tangential stage with negative cells (a tangential model that returned traction x slip, or traction
    on the rail) is a :class:`railtherm.PluginError`, not a heat sink that cools the bodies below bulk."""
    if source is None or "tangential" not in pl.stages:
        return
    q = np.asarray(source.power_density, dtype=float)
    top = float(np.max(np.abs(q), initial=0.0))
    if float(np.min(q, initial=0.0)) < -NEGATIVE_HEAT_ROUNDOFF * top:
        raise PluginError(
            f"tangential model {pl.models['tangential'].name!r} gives a frictional power density of "
            f"{float(np.min(q)):.4g} W/m^2 in a cell (largest |value| {top:.4g}): traction acts on the wheel, slip is "
            "the wheel's relative to the rail, and the dissipation -(traction . slip) is >= 0 "
            "(docs/plugins.md, sign conventions)")


def _freeze(result) -> None:
    """Make the arrays of a stage's result read-only: a later stage that writes into them (instead of
    returning a new result) fails at once with numpy's "assignment destination is read-only"."""
    if result is None or not dataclasses.is_dataclass(result):
        return
    for f in dataclasses.fields(result):
        value = getattr(result, f.name)
        if isinstance(value, np.ndarray):
            value.flags.writeable = False


@dataclass
class StageRecord:
    """What one stage (or one coupled model) returned: the model and its diagnostics."""

    model: StageModel
    diagnostics: Mapping[str, Any]


def _run(pl: Plan, scene: Scene, level: int, options: Mapping[str, Any]):
    patch = source = temp = None
    records: list[StageRecord] = []
    cells = options.get("cells") or pl.method.method.default_cells or BASE_CELLS
    done: set[int] = set()
    for stage in pl.stages:
        model = pl.models[stage]
        if id(model) in done:
            continue
        opts = {**model.resolve_options(options), "cells": cells}
        if isinstance(model, CoupledModel):
            same = tuple(s for s in pl.stages if type(pl.models[s]) is type(model))
            done.update(id(pl.models[s]) for s in same)
            out = model.compute(scene, level, opts, same, Upstream(patch=patch, source=source))
            p, s, t = out
            for obj in out:
                _freeze(obj)
            patch, source, temp = (p if p is not None else patch, s if s is not None else source,
                                   t if t is not None else temp)
            diag = {}
            for obj in (p, s, t):
                diag.update(getattr(obj, "diagnostics", None) or {})
            records.append(StageRecord(model, diag))
            continue
        if stage == "normal":
            if getattr(model, "uses_chain_tangential", False):   # its equilibrium solves the creep forces
                opts["chain_tangential"] = _chain_tangential(pl, scene, level, options, cells)
            patch = result = model.compute_patch(scene, level, opts)
        elif (stage == "tangential" and needs_loop(scene.friction, scene.heat_source)
              and not isinstance(pl.models["temperature"], CoupledModel)):
            patch, source, temp, loop_records = _friction_loop(pl, scene, patch, level, options, cells)
            records.extend(loop_records)
            done.update(id(pl.models[s]) for s in ("tangential", "heat_source", "temperature"))
            continue
        elif stage == "tangential":
            result = model.compute_tangential(scene, patch, level, opts)
            _check_untouched(model, patch, result)
            patch = result
        elif stage == "heat_source":
            source = result = model.compute_source(scene, patch, level, opts)
        else:
            temp = result = _temperature(model, scene, source, level, opts)
        _freeze(result)
        records.append(StageRecord(model, result.diagnostics or {}))
        done.add(id(model))
    _check_heat_sign(pl, source)
    return patch, source, temp, records


def _stage_name(pl: Plan, stage: str) -> str:
    """The model of ``stage`` as the result's ``stages`` attribute names it: a normal model whose equilibrium
    solves with the chain's creep forces (fastsim's ``wheelset``) is named with that tangential model, since two
    chains that share it but not their tangential models compute different contacts (not one computation)."""
    model = pl.models[stage]
    tangential = pl.models.get("tangential")
    if stage == "normal" and getattr(model, "uses_chain_tangential", False) and tangential is not None:
        return f"{model.name}[{tangential.name}]"
    return model.name


def _chain_tangential(pl: Plan, scene: Scene, level: int, options, cells):
    """The chain's tangential stage as ``patch -> patch`` (attributes ``model``: its name, ``options``: its
    resolved options), for a normal model whose equilibrium needs the chain's own creep forces (fastsim's
    ``wheelset``), also when no output needs the tangential stage; None when the chain has none for the scene, or
    a coupled one."""
    try:
        tm = pl.models.get("tangential") or _select(get_host(), pl.method, "tangential", scene, level)
    except Refused:
        return None
    if isinstance(tm, CoupledModel):   # it solves with other stages, not on a patch alone
        return None
    opts = {**tm.resolve_options(options), "cells": cells}

    def tangential(patch):
        return tm.compute_tangential(scene, patch, level, opts)

    tangential.model, tangential.options = tm.name, opts
    return tangential


def _temperature(model: StageModel, scene: Scene, source, level: int, opts):
    """The temperature stage on ``source``, after core's capability checks on the actual heat source
    (moving surfaces, Péclet range: :func:`~railtherm.solving.capabilities_check.source_refusal`)."""
    why = source_refusal(model, scene, source)
    if why is not None:
        raise Refused(why, kind="validity")
    return model.compute_temperature(scene, source, level, opts)


def _friction_loop(pl: Plan, scene: Scene, patch: ContactPatch, level: int, options, cells):
    """The tangential, heat-source and temperature stages around core's coupled friction loop
    (:mod:`railtherm.solving.friction_loop`); the loop's history goes into the tangential diagnostics."""
    tm, hm, km = (pl.models[s] for s in ("tangential", "heat_source", "temperature"))
    o_t, o_h, o_k = ({**m.resolve_options(options), "cells": cells} for m in (tm, hm, km))

    def tangential(p):
        result = tm.compute_tangential(scene, p, level, o_t)
        _check_untouched(tm, p, result)
        return result

    patch, source, temp, hist = solve_coupled(scene.friction, scene.wheel, scene.rail, patch, tangential,
                                              lambda p: hm.compute_source(scene, p, level, o_h),
                                              lambda src: _temperature(km, scene, src, level, o_k),
                                              scene_name=scene.name)
    for obj in (patch, source, temp):
        _freeze(obj)
    return patch, source, temp, [StageRecord(tm, {**(patch.diagnostics or {}), **hist.diagnostics()}),
                                 StageRecord(hm, source.diagnostics or {}), StageRecord(km, temp.diagnostics or {})]


def _versions(pl: Plan, host: PluginHost) -> str:
    parts = [f"railtherm {__version__}", f"method {pl.method.name} from plugin {pl.method.plugin} {pl.method.version}"]
    seen = []
    for s in pl.stages:
        m = pl.models[s]
        if m.name not in seen:
            seen.append(m.name)
            info = host.models[m.name]
            parts.append(f"{m.name} ({info.plugin} {info.version})")
    return "; ".join(parts)


def _wheelset_solver(scene: Scene):
    """The solve of a wheelset on profiles beyond one patch at given motion, or None: a wheel that found no
    contact raises its error; ``pitch_velocity = "free"`` and ``roll_angle = "balance"`` (:mod:`.wheelset_equilibrium`)
    and ``patch = "all"`` (:mod:`.wheelset_patches`) solve their patches with :func:`solve`; normal forces still
    the estimate's are balanced with the chain's own creep forces (:mod:`.wheelset_vertical`)."""
    pc = scene.profile_contact
    if hasattr(pc, "failure"):
        raise pc.failure()
    if getattr(pc, "free_pitch", None) is not None:
        # the wheelset equilibrium imports here: it loads scipy.optimize (about 1.4 s), which only a scene
        # with a free pitch or a balanced roll needs
        from .wheelset_equilibrium import solve_free_pitch
        return solve_free_pitch
    # normal forces still the estimate's: balanced with the chain's own creep forces
    pending = pc is not None and getattr(pc, "vertical_balance", "") is None
    if getattr(pc, "patch", None) == "all" and not pending:
        return solve_patches
    if getattr(pc, "patch", None) != "all" and getattr(pc, "balanced_roll", None) is not None:
        # the roll with the chain's own normal approaches
        from .wheelset_equilibrium import solve_balanced_roll  # scipy.optimize, as above
        return solve_balanced_roll
    if pending:
        from .wheelset_vertical import solve_vertical_force  # imports the equilibrium, as above
        return solve_vertical_force
    return None


def solve(scene: Scene | Mapping[str, Any], method: "str | Mapping[str, Any]", level: int = 0,
          options: Mapping[str, Any] | None = None,
          *, host: PluginHost | None = None, validate: bool = True, peers=None):
    """Solve one scene with one method at one resolution level.

    Parameters
    ----------
    scene : Scene or mapping
        A :class:`railtherm.Scene`, or a mapping in the study vocabulary with materials included.
    method : str or mapping
        Method name (see :func:`railtherm.methods`), or a chain of stage models,
        ``{"normal": "kalker", "tangential": "kalker", "temperature": "fdm"}`` (each a model name or a
        list of candidates; ``heat_source`` left out: core's ``frictional``; optional ``name``: the
        method name in the result, default the models joined by ``+``).
    level : int
        Resolution level k >= 0 (each level halves the method's characteristic cell size).
    options : mapping, optional
        Method options (``[study.options.<method>]``), validated by the method's models.
    peers : sequence of (method, options), optional
        The other methods of a study with their options: a run that would repeat one of their
        computations is refused (:func:`duplicate_of`).

    Returns
    -------
    xarray.Dataset
        The result in the schema of docs/DESIGN.md ("Result schema") (CF-1.11 attributes), already validated.

    Raises
    ------
    railtherm.SceneError
        Invalid scene or option.
    railtherm.Refused
        The scene lies outside the method's validity; the message names the limit.
    railtherm.SolverError
        The solver did not converge or produced non-finite numbers.
    """
    host = host or get_host()
    scene = load_scene(scene)
    special = _wheelset_solver(scene)
    if special is not None:
        return special(scene, method, level, options, solve_one=solve, validate=validate, host=host, peers=peers)
    level = check_level(level, where=f"scene {scene.name!r}: ")
    mi = host.resolve(method)  # SceneError for an unknown method or a bad chain, naming what is allowed
    options = _check_options(mi, options, scene.name)
    pl = plan(scene, mi, level, host)
    if peers:
        why = duplicate_of(scene, mi, level, peers, options, host)
        if why:
            raise Refused(why, kind="validity")
    method = mi.name
    t0 = time.perf_counter()
    patch, source, temp, records = _run(pl, scene, level, options)
    wall = time.perf_counter() - t0
    grid = (source.grid if source is not None else patch.grid if patch is not None else None)
    if grid is None:
        raise PluginError(f"method {method!r}: no stage returned a result for scene {scene.name!r}")
    diag, converged = _stage_diagnostics(records)
    attrs = {
        "title": f"railtherm result: scene {scene.name}, method {method}, level {level}",
        "source": _versions(pl, host),
        "history": history_line(f"railtherm.solve(scene={scene.name!r}, method={method!r}, level={level})"),
        "references": "see the docstrings of the models named in 'source'",
        "method": method, "scene": scene.name, "scene_hash": scene.hash, "level": level,
        "stages": " ".join(f"{s}:{_stage_name(pl, s)}" for s in pl.stages),
        "outputs": " ".join(scene.outputs),
        "wall_time": wall, "converged": int(converged),
        "sweep": encode_sweep(scene.sweep),
        **diag,
    }
    ds = build_dataset(grid, patch, source, temp, outputs=scene.outputs, attrs=attrs,
                       wheelset=getattr(scene, "profile_contact", None))
    _check_result(ds, scene, pl, method, level, converged, diag, grid)
    if validate:
        validate_dataset(ds, pl.method.plugin)
    return ds


def solve_time(scene: Scene | Mapping[str, Any], method: "str | Mapping[str, Any]", level: int = 0,
               options: Mapping[str, Any] | None = None, *, host: PluginHost | None = None) -> float:
    """The solving time [s] of one more solve with arguments :func:`solve` has already solved and checked.

    What the result's ``wall_time`` measures (the stage models, from the plan on), without assembling, checking
    or validating a result that would equal the checked one: the study runner's repeated timings of a run.
    A wheelset on profiles, which solves its patches through :func:`solve`, takes its full solve's
    ``wall_time``.

    Parameters are those of :func:`solve`; it raises what :func:`solve` raises on them.
    """
    host = host or get_host()
    scene = load_scene(scene)
    if _wheelset_solver(scene) is not None:
        return float(solve(scene, method, level, options, host=host, validate=False).attrs["wall_time"])
    level = check_level(level, where=f"scene {scene.name!r}: ")
    mi = host.resolve(method)
    options = _check_options(mi, options, scene.name)
    pl = plan(scene, mi, level, host)
    t0 = time.perf_counter()
    _run(pl, scene, level, options)
    return time.perf_counter() - t0


def _check_result(ds, scene: Scene, pl, method: str, level: int, converged: bool, diag: dict, grid) -> None:
    """Refuse a result that did not converge, lacks a declared output or holds NaN/inf where the schema
    does not allow it."""
    if not converged:
        raise SolverError(f"method {method!r} did not converge on scene {scene.name!r} at level {level}: "
                          + ", ".join(f"{k}={v}" for k, v in diag.items() if "resid" in k or "iter" in k))
    missing = [o for o in scene.outputs if o not in ds and not (grid.line and o in LATERAL)]
    if missing:
        raise PluginError(f"method {method!r} ({pl.describe()}) declared but did not return {missing} "
                          f"for scene {scene.name!r}")
    # NaN is a failure except where the schema allows it: stick outside the patch, and the trace outputs
    # a model flags (a peak at the end of the field is NaN with a note, never a peak)
    nan_ok = set(str(ds.attrs.get("nan_allowed", "")).split()) | {"stick"}
    for name in scene.outputs:
        if name in ds and np.issubdtype(ds[name].dtype, np.floating) and not np.all(np.isfinite(ds[name].values)) \
                and name not in nan_ok:
            raise SolverError(f"method {method!r} returned NaN/inf for {name!r} on scene {scene.name!r}")


def _stage_diagnostics(records) -> tuple[dict[str, Any], bool]:
    """Every stage model's diagnostics flattened to ``<model>_<key>`` attributes, and whether all converged."""
    diag: dict[str, Any] = {}
    converged = True
    for rec in records:
        _flat_diagnostics(rec.model.name, rec.diagnostics, diag)
        if "converged" in rec.diagnostics and not bool(rec.diagnostics["converged"]):
            converged = False
    return diag, converged
