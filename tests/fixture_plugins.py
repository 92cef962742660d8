"""Small plugins used by the core tests (fixtures, not methods)."""
from __future__ import annotations

import os
import signal
import time

import numpy as np

import railtherm
from railtherm import Capabilities, Method, TemperatureField, TemperatureModel, hookimpl


class FlatTemperature(TemperatureModel):
    """Test model: surface temperature = bulk + flux * scale (a fixture, not physics)."""

    name = "flat"
    description = "test fixture: temperature proportional to the local flux"
    capabilities = Capabilities(provides=frozenset({"surface_temperature", "max_surface_temperature",
                                                    "mean_contact_temperature"}))
    options = {"scale": railtherm.Option(1e-6, "K per W/m^2", minimum=0.0)}

    def compute_temperature(self, scene, source, level, options):
        bulk = np.array([scene.wheel.bulk_temperature, scene.rail.bulk_temperature])
        surf = np.stack([source.flux(0), source.flux(1)]) * options["scale"]
        surf = surf + bulk.reshape((2,) + (1,) * (surf.ndim - 1))
        return TemperatureField.from_surface(source.grid, surf, diagnostics={"iterations": 1, "converged": True})


class BrokenTemperature(FlatTemperature):
    """Test model that raises, returns NaN or hangs depending on the scene's speed."""

    name = "broken"
    description = "test fixture: raises (speed 13), NaN (speed 14), sleeps (speed 15)"

    def compute_temperature(self, scene, source, level, options):
        if scene.speed == 13.0:
            raise RuntimeError("deliberate failure")
        if scene.speed == 14.0:
            f = super().compute_temperature(scene, source, level, options)
            f.max_surface_temperature[:] = np.nan
            return f
        if scene.speed == 15.0:
            time.sleep(30)
        return super().compute_temperature(scene, source, level, options)


class SleepyTemperature(FlatTemperature):
    """Test fixture: the flat temperature after a pause; can end its own process or ignore signals.

    Defined here rather than in the executor tests: worker processes import the module that defines a
    plugin sent to them, and this one imports only numpy and railtherm (not pytest, xarray or distributed).
    """

    name = "sleepy"
    description = "test fixture: flat temperature after a pause; dies or hangs at chosen speeds"
    options = {**FlatTemperature.options,
               "sleep": railtherm.Option(0.0, "pause before computing [s]", minimum=0.0),
               "die_at_speed": railtherm.Option(-1.0, "SIGKILL its own process at this speed [m/s]"),
               "stuck_at_speed": railtherm.Option(-1.0, "block SIGALRM and sleep 60 s at this speed [m/s]")}

    def compute_temperature(self, scene, source, level, options):
        if scene.speed == options["die_at_speed"]:
            os.kill(os.getpid(), signal.SIGKILL)
        if scene.speed == options["stuck_at_speed"]:
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})  # like a long C call
            time.sleep(60)
        time.sleep(options["sleep"])
        return super().compute_temperature(scene, source, level, options)


class SleepyPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [SleepyTemperature]

    @hookimpl
    def railtherm_register_methods(self):
        return [Method("sleepy", {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": ("sleepy",)})]


class NoUnits(FlatTemperature):
    """Fixture whose results are spoiled after the fact (see tests)."""

    name = "nounits"
    description = "test fixture"


class FlatPlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [FlatTemperature, BrokenTemperature]

    @hookimpl
    def railtherm_register_methods(self):
        return [Method("flat", {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": ("flat",)},
                       description="Hertz, full sliding, flat temperature (test fixture)"),
                Method("broken", {"normal": ("hertz",), "tangential": ("full-sliding",), "temperature": ("broken",)})]


class RaisingPlugin:
    @hookimpl
    def railtherm_register_models(self):
        raise RuntimeError("this plugin is broken on purpose")


class DuplicatePlugin:
    @hookimpl
    def railtherm_register_models(self):
        return [FlatTemperature]

    @hookimpl
    def railtherm_register_methods(self):
        return [Method("flat", {"temperature": ("flat",)}), Method("ghost", {"temperature": ("nowhere",)})]
