"""The plugin host: discovery, broken plugins, duplicates, order independence, documented hooks."""
import inspect
import warnings

import pytest

import railtherm
from railtherm.contract import hookspec
from railtherm.solving import plugins
from fixture_plugins import DuplicatePlugin, FlatPlugin, RaisingPlugin


def test_core_models_and_fixture_method(flat_host):
    assert {"hertz", "full-sliding", "given", "flat"} <= set(flat_host.models)
    info = flat_host.method("flat")
    assert info.stages == {"normal": ("hertz",), "tangential": ("full-sliding",), "heat_source": ("frictional",),
                           "temperature": ("flat",)}
    assert "flat" in info.describe() and "Peclet" in info.describe()


def test_broken_plugin_is_reported_and_skipped():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        host = plugins.new_host([("raising", RaisingPlugin()), ("flat", FlatPlugin())], autoload=False)
    assert "flat" in host.methods
    assert any("raising" in p and "broken on purpose" in p for p in host.problems)
    assert any("raising" in str(x.message) for x in w)
    with pytest.raises(railtherm.PluginError, match="raising"):
        plugins.new_host([("raising", RaisingPlugin())], autoload=False, strict=True)


def test_duplicates_and_unknown_models_reported():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        host = plugins.new_host([("a", FlatPlugin()), ("b", DuplicatePlugin())], autoload=False)
    assert host.models["flat"].plugin == "a"
    assert any("already registered" in p for p in host.problems)
    assert any("ghost" in p and "none of which is registered" in p for p in host.problems)


def test_order_of_registration_decides_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        h1 = plugins.new_host([("a", FlatPlugin()), ("b", DuplicatePlugin())], autoload=False)
        h2 = plugins.new_host([("b", DuplicatePlugin()), ("a", FlatPlugin())], autoload=False)
    assert sorted(h1.methods) == sorted(h2.methods)
    assert {k: v.plugin for k, v in h1.models.items()} == {k: v.plugin for k, v in h2.models.items()}


def test_entry_point_failure_does_not_stop_others(monkeypatch):
    import importlib.metadata as md

    class EP:
        def __init__(self, name, value, obj=None):
            self.name, self.value, self._obj, self.dist = name, value, obj, None

        def load(self):
            if self._obj is None:
                raise ImportError("no such module")
            return self._obj

    monkeypatch.setattr(md, "entry_points", lambda group=None: [EP("zz-broken", "nowhere.plugin"),
                                                                EP("flat", "x", FlatPlugin())])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        host = plugins.new_host(autoload=True)
    assert "flat" in host.methods
    assert any("zz-broken" in p and "failed to import" in p for p in host.problems)


def test_autoload_can_be_disabled(monkeypatch):
    monkeypatch.setenv(plugins.DISABLE_ENV, "1")
    host = plugins.new_host()
    assert set(host.models) == {"hertz", "wheelset-profile", "full-sliding", "frictional", "given"} and not host.problems


HOOKS = [name for name, f in inspect.getmembers(hookspec, inspect.isfunction) if name.startswith("railtherm_")]


@pytest.mark.parametrize("hook", HOOKS)
def test_every_hook_is_documented(hook):
    doc = inspect.getdoc(getattr(hookspec, hook)) or ""
    assert "Called" in doc and "Returns" in doc, f"hook {hook} must say when it is called and what it returns"


@pytest.mark.parametrize("hook", HOOKS)
def test_every_hook_is_tested(hook):
    """Each hook is implemented by a fixture plugin that the tests above exercise."""
    from pathlib import Path
    tested = Path(__file__).with_name("fixture_plugins.py").read_text()
    assert f"def {hook}(" in tested


def test_methods_api_lists_builtins():
    names = [m.name for m in railtherm.methods()]
    assert names == sorted(names)
