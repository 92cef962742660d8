"""Exceptions of railtherm's public API."""
from __future__ import annotations


class RailthermError(Exception):
    """Base class of railtherm's own errors."""


class SceneError(RailthermError, ValueError):
    """Invalid study or scene input.

    The message names the scene, the key, the value and what is allowed, e.g.
    ``scene 'low-speed': key 'friction' = -0.3 is not allowed: a number >= 0``.
    """

    def __init__(self, message: str, *, scene: str | None = None, key: str | None = None,
                 value: object = None, allowed: str | None = None):
        self.scene, self.key, self.value, self.allowed = scene, key, value, allowed
        super().__init__(message)

    @classmethod
    def bad_value(cls, scene: str | None, key: str, value: object, allowed: str) -> "SceneError":
        where = f"scene {scene!r}: " if scene else ""
        return cls(f"{where}key {key!r} = {value!r} is not allowed: {allowed}",
                   scene=scene, key=key, value=value, allowed=allowed)


class Refused(RailthermError):
    """A scene lies outside a model's validity.

    The message names the limit (e.g. the Péclet number) and what would work instead.
    A refused run is recorded with status ``refused``; it is not an error of the study.

    Parameters
    ----------
    message : str
        The limit and what would work instead.
    kind : {"validity", "budget"}
        ``validity``: the scene lies outside the model's physics or numerics (Péclet number, shape);
        ``budget``: the model could compute it but the work (cells, memory, estimated time) exceeds
        the budget that core or the model sets, so it is refused before it starts.
    """

    KINDS = ("validity", "budget")

    def __init__(self, message: str = "", *, kind: str = "validity"):
        if kind not in self.KINDS:
            raise ValueError(f"Refused kind must be one of {self.KINDS}, got {kind!r}")
        self.kind = kind
        super().__init__(message)

    def __reduce__(self):  # picklable with its kind (processes and dask executors)
        return (_refused, (str(self), self.kind))


class PluginError(RailthermError):
    """A plugin broke its contract (bad registration or a result that fails the schema)."""


class SolverError(RailthermError):
    """A solver did not converge or produced non-finite numbers; the run is recorded as failed."""


def _refused(message: str, kind: str) -> Refused:
    return Refused(message, kind=kind)
