"""Study files (TOML): [study] settings, [defaults], [[scene]] tables, sweeps.

Any scalar given as a list is swept (cartesian product over all swept keys of a scene); each swept
scene is named ``<name>--<key>=<value>[,<key>=<value>...]``.
"""
from __future__ import annotations

import copy
import itertools
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..contract.errors import SceneError
from ..contract.schema import VARIABLES
from .scene import MATERIAL_KEYS, SCENE_KEYS, SCHEMA_VERSION, Scene, Table, load_scene

STUDY_KEYS = {"name", "description", "methods", "levels", "reference", "options", "repeat", "timeout",
              "warmup", "tolerance", "published", "chains", "store", "keep_fields"}
#: result stores of a study (``[study] store``): one netCDF file per run, or one chunked Zarr store
STORES = ("files", "zarr")
#: values of ``[study] keep_fields`` (the Zarr store): every run's fields, none, or the finest level's
KEEP_FIELDS = (True, False, "finest")
#: without ``[study] store``, a study of at least this many runs whose scenes ask only scalar outputs
#: uses the Zarr store; any other study writes one file per run
AUTO_ZARR_RUNS = 1000
#: stages a study chain may name (plugin API 2)
CHAIN_STAGES = ("normal", "tangential", "heat_source", "temperature")
REFERENCES = ("analytic", "finest")
#: scenes one [[scene]] table may expand to
MAX_SWEEP = 1_000_000


@dataclass
class Study:
    """A parsed study: settings and the expanded list of scenes."""

    name: str
    scenes: list[Scene]
    methods: str | list[str] = "all"
    levels: list[int] = field(default_factory=lambda: [0, 1, 2, 3])
    reference: str = "analytic"
    options: dict[str, dict] = field(default_factory=dict)
    description: str = ""
    repeat: int = 3
    warmup: bool = True
    timeout: float = 600.0
    tolerance: float = 0.05
    #: published values to show beside ours: scene name -> {variable: value, "source": str}
    published: dict[str, dict] = field(default_factory=dict)
    path: str | None = None
    #: chains composed by the study, used like method names: name -> {stage: (model, ...)}
    chains: dict[str, dict[str, tuple[str, ...]]] = field(default_factory=dict)
    #: ``[study] store``: "files", "zarr", or None (chosen by :meth:`store_for`)
    store: str | None = None
    #: ``[study] keep_fields`` (Zarr store): True, False or "finest"
    keep_fields: bool | str = False

    def store_for(self, n_runs: int) -> str:
        """The result store of a run of ``n_runs`` runs: ``[study] store`` when given, else "zarr" for a
        study of at least :data:`AUTO_ZARR_RUNS` runs whose scenes ask only scalar outputs (or that
        sets ``keep_fields``), "files" otherwise."""
        if self.store is not None:
            return self.store
        if self.keep_fields is not False:
            return "zarr"
        scalar = all(VARIABLES[o].dims in ((), ("body",)) for s in self.scenes for o in s.outputs if o in VARIABLES)
        return "zarr" if n_runs >= AUTO_ZARR_RUNS and scalar else "files"

    def method_names(self, available) -> list[str]:
        """Methods to run: the study's list, or every available one and the study's chains for "all"
        (sorted)."""
        if self.methods == "all":
            return sorted(set(available) | set(self.chains))
        return list(self.methods)

    def scene(self, name: str) -> Scene:
        for s in self.scenes:
            if s.name == name:
                return s
        raise KeyError(name)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def _sweep_paths(scene: Mapping[str, Any]) -> list[tuple[tuple[str, ...], list]]:
    """(path, values) of every swept scalar in a scene mapping."""
    out = []
    for key, value in scene.items():
        check = SCENE_KEYS.get(key)
        if check is None:
            continue
        if isinstance(check, Table) and isinstance(value, Mapping):
            for sub, v in value.items():
                sc = check.keys.get(sub)
                if sc is not None and sc.sweepable and isinstance(v, list):
                    out.append(((key, sub), v))
        elif check.sweepable and isinstance(value, list):
            out.append(((key,), value))
    return out


#: what joins a swept scene's name to its sweep values (``base--k=v,...``)
SWEEP_SEPARATOR = "--"


def base_name(name: str) -> str:
    """The study's scene name a swept scene was generated from (``base--k=v,...`` -> ``base``; a scene that was
    not swept is its own base)."""
    return name.split(SWEEP_SEPARATOR, 1)[0]


def expand_sweeps(scene: Mapping[str, Any]) -> list[tuple[dict, dict]]:
    """Expand a scene mapping into (mapping, sweep) pairs, one per point of the cartesian product."""
    sweeps = _sweep_paths(scene)
    name = scene.get("name")
    for path, values in sweeps:
        if not values:
            raise SceneError(f"scene {name!r}: key {'.'.join(path)!r} is an empty list; a sweep needs values",
                             scene=name, key=".".join(path), value=values, allowed="a non-empty list")
    if not sweeps:
        return [(dict(scene), {})]
    n = math.prod(len(v) for _, v in sweeps)
    if n > MAX_SWEEP:
        keys = ",".join(".".join(p) for p, _ in sweeps)
        raise SceneError(f"scene {name!r}: the sweep over {keys} expands to {n} scenes (lengths "
                         f"{[len(v) for _, v in sweeps]}); at most {MAX_SWEEP} per [[scene]]: split the study "
                         "or sweep fewer values", scene=name, key=keys, value=n, allowed=f"<= {MAX_SWEEP} scenes")
    out = []
    for combo in itertools.product(*(v for _, v in sweeps)):
        m = copy.deepcopy(dict(scene))
        sweep = {}
        for (path, _), v in zip(sweeps, combo):
            target = m
            for p in path[:-1]:
                target = target[p]
            target[path[-1]] = v
            sweep[".".join(path)] = v
        if isinstance(name, str):
            m["name"] = name + SWEEP_SEPARATOR + ",".join(f"{k}={_fmt(v)}" for k, v in sweep.items())
        out.append((m, sweep))
    return out


def _merge_defaults(defaults: Mapping[str, Any], scene: Mapping[str, Any]) -> dict:
    out = copy.deepcopy(dict(defaults))
    for k, v in scene.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            merged = dict(out[k])
            merged.update(v)
            out[k] = merged
        else:
            out[k] = copy.deepcopy(v)
    return out


def parse_study(doc: Mapping[str, Any], *, path: str | None = None) -> Study:
    """Validate a study document (already parsed from TOML) and expand its scenes."""
    where = f"study {path}" if path else "study"
    known_top = {"schema_version", "study", "defaults", "scene"}
    for key in doc:
        if key not in known_top:
            raise SceneError(f"{where}: unknown top-level key {key!r}; allowed: {', '.join(sorted(known_top))}",
                             key=key, value=doc[key], allowed=", ".join(sorted(known_top)))
    ver = doc.get("schema_version", SCHEMA_VERSION)
    if ver != SCHEMA_VERSION:
        raise SceneError.bad_value(None, "schema_version", ver, f"{SCHEMA_VERSION} (this railtherm's study schema)")
    st = doc.get("study", {})
    if not isinstance(st, Mapping):
        raise SceneError.bad_value(None, "study", st, "a table [study]")
    for key in st:
        if key not in STUDY_KEYS:
            raise SceneError(f"{where}: unknown key 'study.{key}'; allowed: {', '.join(sorted(STUDY_KEYS))}",
                             key=f"study.{key}", value=st[key], allowed=", ".join(sorted(STUDY_KEYS)))
    kw = _study_settings(st, path)
    _run_settings(st, kw, where)
    kw["description"] = str(st.get("description", ""))
    scenes, names = _study_scenes(doc, where)
    for key in kw["published"]:
        if key not in names:
            raise SceneError(f"{where}: key 'study.published.{key}' names no scene; scenes: {sorted(names)}",
                             key=f"study.published.{key}", value=key, allowed=", ".join(sorted(names)))
    return Study(scenes=scenes, **kw)


def _study_settings(st: Mapping[str, Any], path: str | None) -> dict[str, Any]:
    """Name, chains, methods, levels, reference, options and published values of a [study] table."""
    kw: dict[str, Any] = {"name": st.get("name") or (Path(path).stem if path else "study"), "path": path}
    if not isinstance(kw["name"], str) or "/" in kw["name"]:
        raise SceneError.bad_value(None, "study.name", kw["name"], "a string without '/'")
    kw["chains"] = _chains(st.get("chains", {}))
    methods = st.get("methods", "all")
    if not (methods == "all" or (isinstance(methods, list) and methods and all(isinstance(m, str) for m in methods))):
        raise SceneError.bad_value(None, "study.methods", methods, '"all" or a non-empty list of method names')
    kw["methods"] = methods
    levels = st.get("levels", [0, 1, 2, 3])
    if isinstance(levels, int) and not isinstance(levels, bool):
        levels = [levels]
    if not (isinstance(levels, list) and levels and all(isinstance(k, int) and not isinstance(k, bool) and 0 <= k <= 12
                                                        for k in levels)):
        raise SceneError.bad_value(None, "study.levels", levels, "a non-empty list of integers 0..12")
    kw["levels"] = sorted(set(levels))
    ref = st.get("reference", "analytic")
    if not isinstance(ref, str) or not ref:
        raise SceneError.bad_value(None, "study.reference", ref, '"analytic", "finest" or a method name')
    kw["reference"] = ref
    opts = st.get("options", {})
    if not isinstance(opts, Mapping) or not all(isinstance(v, Mapping) for v in opts.values()):
        raise SceneError.bad_value(None, "study.options", opts, "tables [study.options.<method>]")
    kw["options"] = {k: dict(v) for k, v in opts.items()}
    pub = st.get("published", {})
    if not isinstance(pub, Mapping) or not all(isinstance(v, Mapping) for v in pub.values()):
        raise SceneError.bad_value(None, "study.published", pub,
                                   'tables [study.published."<scene>"] of variable = value and source = "..."')
    kw["published"] = {k: dict(v) for k, v in pub.items()}
    return kw

def _run_settings(st: Mapping[str, Any], kw: dict[str, Any], where: str) -> None:
    """Tolerance, repeat, timeout, warm-up and store settings of a [study] table, into ``kw``."""
    if "tolerance" in st:
        v = st["tolerance"]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (0 < v < math.inf):
            raise SceneError.bad_value(None, "study.tolerance", v, "a number > 0 (relative error)")
        kw["tolerance"] = float(v)
    for key, lo in (("repeat", 1), ("timeout", 0)):
        if key in st:
            v = st[key]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= lo - (key == "repeat"):
                raise SceneError.bad_value(None, f"study.{key}", v, f"a number > {lo}" if key == "timeout" else "an integer >= 1")
            kw[key] = int(v) if key == "repeat" else float(v)
    if "warmup" in st:
        if not isinstance(st["warmup"], bool):
            raise SceneError.bad_value(None, "study.warmup", st["warmup"], "true or false")
        kw["warmup"] = st["warmup"]
    if "store" in st:
        if st["store"] not in STORES:
            raise SceneError(f"{where}: key 'study.store' is {st['store']!r}; allowed: \"files\" (one netCDF file "
                             "per run) or \"zarr\" (one chunked store for the study)", key="study.store",
                             value=st["store"], allowed='"files" or "zarr"')
        kw["store"] = st["store"]
    if "keep_fields" in st:
        v = st["keep_fields"]
        if not any(v is k or (isinstance(k, str) and v == k) for k in KEEP_FIELDS):
            raise SceneError(f"{where}: key 'study.keep_fields' is {v!r}; allowed: true, false or \"finest\" "
                             "(the finest level of each scene and method)", key="study.keep_fields", value=v,
                             allowed='true, false or "finest"')
        if kw.get("store") == "files":
            raise SceneError(f"{where}: key 'study.keep_fields' = {v!r} needs store = \"zarr\": the files store "
                             "keeps every field of every run", key="study.keep_fields", value=v,
                             allowed='keep_fields only with store = "zarr" (or without store)')
        kw["keep_fields"] = v

def _study_scenes(doc: Mapping[str, Any], where: str) -> tuple[list[Scene], set[str]]:
    """The scenes of a study, [defaults] merged into every [[scene]] and sweeps expanded, and their names."""
    defaults = doc.get("defaults", {})
    if not isinstance(defaults, Mapping):
        raise SceneError.bad_value(None, "defaults", defaults, "a table [defaults]")
    for key in defaults:
        if key not in SCENE_KEYS or key == "name":
            raise SceneError(f"{where}: unknown key 'defaults.{key}'; allowed: any scene key but 'name' "
                             f"({', '.join(k for k in SCENE_KEYS if k != 'name')})", key=f"defaults.{key}",
                             value=defaults[key])
    raw_scenes = doc.get("scene", [])
    if not isinstance(raw_scenes, list) or not raw_scenes:
        raise SceneError(f"{where}: no [[scene]] tables; a study needs at least one scene", key="scene")
    scenes: list[Scene] = []
    names: set[str] = set()
    for i, raw in enumerate(raw_scenes):
        if not isinstance(raw, Mapping):
            raise SceneError.bad_value(None, f"scene[{i}]", raw, "a [[scene]] table")
        if "name" not in raw:
            raise SceneError(f"{where}: scene number {i + 1} has no 'name'", key="name", allowed="a name")
        merged = _merge_defaults(defaults, raw)
        for mapping, sweep in expand_sweeps(merged):
            sc = load_scene(mapping, sweep=sweep)
            if sc.name in names:
                raise SceneError(f"{where}: scene name {sc.name!r} is used twice; names must be unique",
                                 scene=sc.name, key="name", value=sc.name)
            names.add(sc.name)
            scenes.append(sc)
    return scenes, names

def load_study(path: str | Path) -> Study:
    """Read, validate and expand a study TOML file.

    Raises
    ------
    railtherm.SceneError
        On any invalid input (the message names the scene, key, value and what is allowed),
        including TOML syntax errors and a missing file.
    """
    p = Path(path)
    name = str(p)
    if p.is_dir():
        raise SceneError(f"study file {name!r} is a folder, not a study file: give the path of a .toml file",
                         key="study", value=name, allowed="a TOML file") from None
    try:
        with open(p, "rb") as fh:
            data = fh.read()
    except FileNotFoundError:
        raise SceneError(f"study file {name!r} does not exist", key="study", value=name,
                         allowed="an existing TOML file") from None
    except OSError as exc:  # permission denied, a folder on some systems, ...
        raise SceneError(f"study file {name!r} cannot be read: {exc.strerror or exc}", key="study", value=name,
                         allowed="a readable TOML file") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise SceneError(f"study file {name!r} is not UTF-8 text (byte {data[exc.start]:#04x} on line {line}); "
                         "TOML files must be UTF-8: save it as UTF-8", key="study", value=name,
                         allowed="a UTF-8 TOML file") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"study file {name!r} is not valid TOML: {exc}", key="study", value=name,
                         allowed="TOML syntax") from None
    return parse_study(doc, path=name)


def _chains(raw) -> dict[str, dict[str, tuple[str, ...]]]:
    """``[study.chains.<name>]`` tables: stage -> model name or list of names (form only; the plugin
    host checks that the models exist and implement their stages, :func:`railtherm.contract.options.check_study`)."""
    allowed = ("tables [study.chains.<name>] with keys " + ", ".join(CHAIN_STAGES)
               + ", each a model name or a list of them")
    if not isinstance(raw, Mapping):
        raise SceneError.bad_value(None, "study.chains", raw, allowed)
    out = {}
    for name, table in raw.items():
        key = f"study.chains.{name}"
        if not isinstance(name, str) or not name or "/" in name:
            raise SceneError.bad_value(None, key, name, "a chain name: a non-empty string without '/'")
        if not isinstance(table, Mapping) or not table:
            raise SceneError.bad_value(None, key, table, allowed)
        chain = {}
        for stage, value in table.items():
            if stage not in CHAIN_STAGES:
                raise SceneError(f"key '{key}.{stage}': unknown stage {stage!r}; allowed stages: "
                                 f"{', '.join(CHAIN_STAGES)}", key=f"{key}.{stage}", value=stage,
                                 allowed=", ".join(CHAIN_STAGES))
            names = [value] if isinstance(value, str) else value
            if not (isinstance(names, list) and names and all(isinstance(n, str) and n for n in names)):
                raise SceneError.bad_value(None, f"{key}.{stage}", value, "a model name or a non-empty list of them")
            chain[stage] = tuple(names)
        out[name] = chain
    return out
