"""Hook specifications of railtherm (the whole plugin contract).

Plugins implement these hooks with :data:`railtherm.hookimpl` in a module registered under the
entry-point group ``railtherm.plugins``::

    [project.entry-points."railtherm.plugins"]
    myplugin = "my_package.plugin"

Hooks *register* things; they never do the numerical work. Every implementation of a hook is
called (there is no first-result-wins) and the host merges the returned lists, sorted by name:
the order of registration decides nothing. Hooks evolve only by adding optional arguments.
"""
from __future__ import annotations

import pluggy

PROJECT = "railtherm"

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


@hookspec
def railtherm_register_models() -> list:
    """Register stage models.

    Called once, when the plugin host is first built (the first call of ``railtherm.methods()``,
    ``railtherm.solve()``, ``railtherm run`` ...), for every loaded plugin.

    Returns
    -------
    list of type
        Subclasses of :class:`railtherm.NormalContactModel`, :class:`railtherm.HeatSourceModel`,
        :class:`railtherm.TemperatureModel` or :class:`railtherm.CoupledModel`, each with a unique
        ``name``. A name registered twice is reported and the later one is skipped.
    """


@hookspec
def railtherm_register_methods() -> list:
    """Register methods: named chains of stage models.

    Called once, after every plugin's :func:`railtherm_register_models`, so a method may chain
    models registered by other plugins (or by core: ``hertz``, ``full-sliding``, ``given``).

    Returns
    -------
    list of railtherm.Method
        Methods with unique names. A method naming a model that no plugin registered is
        reported and skipped.
    """
