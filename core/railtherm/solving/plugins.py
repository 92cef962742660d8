"""The plugin host: discovery through the entry-point group ``railtherm.plugins``, on pluggy.

Loading survives a broken plugin: each entry point is loaded and called in its own try/except; a
failure is reported by name (a warning, and in :attr:`PluginHost.problems`) and the others go on.
``RAILTHERM_DISABLE_PLUGIN_AUTOLOAD=1`` disables entry-point discovery (core models only); ``strict=True``
turns every problem into an exception (for tests).
"""
from __future__ import annotations

import importlib.metadata as md
import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import pluggy

from .._version import __version__
from ..contract import hookspec
from ..contract.errors import PluginError, SceneError
from ..contract.stages import STAGES, Method, StageModel
from ..models import core_plugin

GROUP = "railtherm.plugins"
DISABLE_ENV = "RAILTHERM_DISABLE_PLUGIN_AUTOLOAD"


@dataclass(frozen=True)
class ModelInfo:
    """A registered model name: its class, and the same-named classes of other stages of the same
    plugin (an exact contact method registers a normal and a tangential model both named ``kalker``)."""

    cls: type
    plugin: str
    version: str
    others: tuple[type, ...] = ()

    @property
    def name(self) -> str:
        return self.cls.name

    @property
    def classes(self) -> tuple[type, ...]:
        return (self.cls,) + self.others

    @property
    def stages(self) -> tuple[str, ...]:
        """Every stage the name implements (over its classes), in pipeline order."""
        have = {s for c in self.classes for s in c.stages}
        return tuple(s for s in STAGES if s in have)

    def for_stage(self, stage: str) -> type:
        """The class that implements ``stage`` (KeyError if none)."""
        for c in self.classes:
            if stage in c.stages:
                return c
        raise KeyError(f"model {self.name!r} does not implement stage {stage!r}")


@dataclass(frozen=True)
class MethodInfo:
    """A registered method with its provenance; returned by :func:`railtherm.methods`."""

    method: Method
    plugin: str
    version: str
    models: tuple[ModelInfo, ...] = ()

    @property
    def name(self) -> str:
        return self.method.name

    @property
    def stages(self) -> dict[str, tuple[str, ...]]:
        return {s: tuple(self.method.chain.get(s, ())) for s in STAGES if self.method.chain.get(s)}

    def describe(self) -> str:
        lines = [f"{self.name}  (plugin {self.plugin} {self.version})"]
        if self.method.description:
            lines.append(f"    {self.method.description}")
        for stage, names in self.stages.items():
            lines.append(f"    {stage}: {' | '.join(names)}")
        for m in self.models:
            for c in m.classes:
                lines.append(f"      - {m.name} ({'/'.join(c.stages)}) [{m.plugin} {m.version}]: {c.description}")
                lines.append(f"        {c.capabilities.describe()}")
        return "\n".join(lines)


@dataclass
class PluginHost:
    """Registry of stage models and methods built from all plugins."""

    pm: pluggy.PluginManager
    models: dict[str, ModelInfo] = field(default_factory=dict)
    methods: dict[str, MethodInfo] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    strict: bool = False
    autoload: bool = True
    extra: list = field(default_factory=list)
    _versions: dict[str, str] = field(default_factory=dict)

    # -- registration -----------------------------------------------------------------
    def _problem(self, msg: str, exc: BaseException | None = None) -> None:
        if self.strict:
            raise PluginError(msg) from exc
        self.problems.append(msg)
        warnings.warn(msg, RuntimeWarning, stacklevel=3)

    def add_plugin(self, plugin: Any, name: str, version: str = "0") -> bool:
        """Register a plugin object (module or instance with hookimpls); False if it was refused."""
        try:
            self.pm.register(plugin, name=name)
        except Exception as exc:  # noqa: BLE001 - a broken plugin must not stop the others
            self._problem(f"plugin {name!r} could not be registered: {exc}", exc)
            return False
        self._versions[name] = version
        return True

    def build(self) -> "PluginHost":
        """Call the registration hooks of every plugin, one plugin at a time, and index the results."""
        self.models.clear()
        self.methods.clear()
        pending_methods: list[tuple[str, Any]] = []
        for name, plugin in sorted(self.pm.list_name_plugin(), key=lambda t: t[0]):
            for hook, sink in (("railtherm_register_models", "models"), ("railtherm_register_methods", "methods")):
                impl = getattr(plugin, hook, None)
                if impl is None:
                    continue
                try:
                    result = list(impl() or [])
                except Exception as exc:  # noqa: BLE001
                    self._problem(f"plugin {name!r}: hook {hook} raised {type(exc).__name__}: {exc}", exc)
                    continue
                if sink == "models":
                    for cls in result:
                        self._add_model(name, cls)
                else:
                    pending_methods.extend((name, m) for m in result)
        for name, m in sorted(pending_methods, key=lambda t: (getattr(t[1], "name", ""), t[0])):
            self._add_method(name, m)
        return self

    def _add_model(self, plugin: str, cls: Any) -> None:
        if not (isinstance(cls, type) and issubclass(cls, StageModel)) or not getattr(cls, "name", ""):
            self._problem(f"plugin {plugin!r} registered {cls!r}, which is not a named StageModel subclass")
            return
        if not cls.stages or any(s not in STAGES for s in cls.stages):
            self._problem(f"plugin {plugin!r}: model {cls.name!r} declares stages {cls.stages}, allowed {STAGES}")
            return
        if cls.name in self.models:
            have = self.models[cls.name]
            if have.plugin == plugin and not set(have.stages) & set(cls.stages):
                # one name for one method's models of different stages (normal and tangential "kalker")
                self.models[cls.name] = ModelInfo(have.cls, have.plugin, have.version, have.others + (cls,))
                return
            self._problem(f"plugin {plugin!r}: model {cls.name!r} is already registered by plugin "
                          f"{have.plugin!r} for stages {list(have.stages)}; skipped (one name may serve "
                          "several stages only within one plugin, one class per stage)")
            return
        self.models[cls.name] = ModelInfo(cls, plugin, cls.version or self._versions.get(plugin, "0"))

    def _add_method(self, plugin: str, m: Any) -> None:
        if not isinstance(m, Method):
            self._problem(f"plugin {plugin!r} registered {m!r}, which is not a railtherm.Method")
            return
        if m.name in self.methods:
            self._problem(f"plugin {plugin!r}: method {m.name!r} is already registered by plugin "
                          f"{self.methods[m.name].plugin!r}; skipped")
            return
        raw = {k: tuple(v) for k, v in dict(m.chain).items()}
        unknown = sorted(set(raw) - set(STAGES))
        if unknown:
            self._problem(f"plugin {plugin!r}: method {m.name!r} names stages {unknown}; allowed {STAGES}; "
                          "method skipped")
            return
        if "tangential" in raw and "temperature" in raw and "heat_source" not in raw:
            raw["heat_source"] = ("frictional",)       # traction x slip, core's heat source
        chain = {}
        used = []
        for stage in STAGES:
            names = tuple(raw.get(stage, ()))
            known = tuple(n for n in names if n in self.models)
            if names and not known:
                self._problem(f"plugin {plugin!r}: method {m.name!r} names {stage} models {list(names)}, "
                              "none of which is registered; method skipped")
                return
            for n in known:
                if stage not in self.models[n].stages:
                    self._problem(f"plugin {plugin!r}: method {m.name!r} uses model {n!r} for stage {stage!r}, "
                                  f"but that model implements {self.models[n].stages}; method skipped")
                    return
            if known:
                chain[stage] = known
                used.extend(k for k in known if k not in used)
        if not chain:
            self._problem(f"plugin {plugin!r}: method {m.name!r} has an empty chain; skipped")
            return
        method = Method(m.name, chain, m.description, m.default_cells, dict(getattr(m, "orders", {}) or {}))
        self.methods[m.name] = MethodInfo(method, plugin, self._versions.get(plugin, "0"),
                                          tuple(self.models[n] for n in used))

    # -- chains composed by a study or a caller ------------------------------------------
    def compose(self, chain: Mapping[str, Any], name: str | None = None, where: str = "method") -> MethodInfo:
        """A method from stage models: ``{"normal": "kalker", "tangential": "kalker", "temperature": "fdm"}``.

        Parameters
        ----------
        chain : mapping
            Stage -> model name or list of candidate model names (the first that supports a scene
            runs); the optional key ``name`` names the method in results. Without ``heat_source``, a
            chain with tangential and temperature stages gets core's ``frictional``.
        name : str, optional
            Method name (default: the chain's ``name``, else its models joined by ``+``).
        where : str
            Key prefix for error messages (``study.chains.<name>``).

        Raises
        ------
        railtherm.SceneError
            An unknown stage, a model that is not registered or does not implement its stage, an
            empty chain; the message names the key, the value and what is allowed.
        """
        chain = dict(chain)
        name = name or chain.pop("name", None)
        chain.pop("name", None)
        if not chain:
            raise SceneError(f"{where}: an empty chain; give models for the stages {', '.join(STAGES)}",
                             key=where, value={}, allowed=", ".join(STAGES))
        out: dict[str, tuple[str, ...]] = {}
        for stage, value in chain.items():
            key = f"{where}.{stage}"
            if stage not in STAGES:
                raise SceneError(f"key {key!r}: unknown stage {stage!r}; allowed stages: {', '.join(STAGES)}",
                                 key=key, value=stage, allowed=", ".join(STAGES))
            names = (value,) if isinstance(value, str) else tuple(value) if isinstance(value, (list, tuple)) else ()
            fits = sorted(n for n, m in self.models.items() if stage in m.stages)
            if not names or not all(isinstance(n, str) for n in names):
                raise SceneError.bad_value(None, key, value, f"a model name or a list of them ({', '.join(fits)})")
            for n in names:
                if n not in self.models or stage not in self.models[n].stages:
                    why = "is not registered" if n not in self.models else \
                        f"implements {list(self.models[n].stages)}, not {stage!r}"
                    raise SceneError(f"key {key!r}: model {n!r} {why}; {stage} models: {', '.join(fits)}",
                                     key=key, value=n, allowed=", ".join(fits))
            out[stage] = names
        if "tangential" in out and "temperature" in out and "heat_source" not in out:
            out["heat_source"] = ("frictional",)
        out = {s: out[s] for s in STAGES if s in out}
        name = name or "+".join(dict.fromkeys(n for names in out.values() for n in names[:1]))
        used = list(dict.fromkeys(n for names in out.values() for n in names))
        return MethodInfo(Method(name, out, f"chain composed by the study: {out}"), "study", __version__,
                          tuple(self.models[n] for n in used))

    def resolve(self, method: "str | Mapping[str, Any]") -> MethodInfo:
        """The :class:`MethodInfo` of a method name, or of a chain mapping (see :meth:`compose`)."""
        if isinstance(method, Mapping):
            return self.compose(method)
        return self.method(method)

    # -- lookup -----------------------------------------------------------------------
    def method(self, name: str) -> MethodInfo:
        try:
            return self.methods[name]
        except KeyError:
            allowed = ", ".join(sorted(self.methods)) or "none"
            raise SceneError(f"unknown method {name!r}; installed methods: {allowed}"
                             + (f" (plugin problems: {'; '.join(self.problems)})" if self.problems else ""),
                             key="method", value=name, allowed=allowed) from None

    def model(self, name: str) -> ModelInfo:
        return self.models[name]


def new_host(plugins: Iterable[tuple[str, Any]] = (), *, autoload: bool | None = None,
             strict: bool = False) -> PluginHost:
    """Build a host: core models, then entry points (unless disabled), then ``plugins`` (name, obj) pairs."""
    pm = pluggy.PluginManager(hookspec.PROJECT)
    pm.add_hookspecs(hookspec)
    host = PluginHost(pm, strict=strict)
    plugins = list(plugins)
    host.extra = plugins  # how the host was built: executors rebuild it on workers
    host.add_plugin(core_plugin, "railtherm", __version__)
    if autoload is None:
        autoload = not os.environ.get(DISABLE_ENV)
    host.autoload = autoload
    if autoload:
        for ep in sorted(md.entry_points(group=GROUP), key=lambda e: e.name):
            try:
                module = ep.load()
            except Exception as exc:  # noqa: BLE001 - report by name, skip
                host._problem(f"plugin {ep.name!r} ({ep.value}) failed to import: {type(exc).__name__}: {exc}", exc)
                continue
            dist = getattr(ep, "dist", None)
            version = dist.version if dist is not None else "0"
            host.add_plugin(module, ep.name, version)
    for name, obj in plugins:
        host.add_plugin(obj, name, getattr(obj, "__version__", "0"))
    return host.build()


_HOST: PluginHost | None = None


def get_host() -> PluginHost:
    """The process-wide host, built on first use."""
    global _HOST
    if _HOST is None:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            _HOST = new_host()
    return _HOST


def set_host(host: PluginHost | None) -> None:
    """Replace the process-wide host (tests, the conformance kit); None rebuilds on next use."""
    global _HOST
    _HOST = host


def methods() -> list[MethodInfo]:
    """Every registered method with its plugin, version, stages and models, sorted by name."""
    host = get_host()
    return [host.methods[k] for k in sorted(host.methods)]
