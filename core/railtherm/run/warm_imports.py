"""What railtherm's fork server imports once, so that every worker process forked from it starts with them.

A spawned worker imports numpy, scipy, xarray, netCDF4, numba and the plugins itself: about 2 s of CPU per
process, paid again by every pool (runs, scoring, figures) and every replacement of a worker that died. The
fork server (:func:`railtherm.run.executors.worker_context`) imports this module once; its workers are forks of
it. An import that fails here costs only its time saving: the worker imports it (and meets the error) itself.
numba's typing and target contexts are built here too (:func:`_numba_contexts`).
"""
from __future__ import annotations

import importlib
from importlib.metadata import entry_points

MODULES = ("numpy", "scipy.optimize", "scipy.sparse.linalg", "scipy.fft", "xarray", "netCDF4", "numba",
           "numba.core.event", "dask.array", "matplotlib", "matplotlib.figure", "matplotlib.backends.backend_agg",
           "railtherm.run.executors", "railtherm.run.runner", "railtherm.solving.pipeline",
           "railtherm.contract.schema", "railtherm.references.hertz", "railtherm.analysis.metrics",
           "railtherm.analysis.reference_curves")


def _warm() -> None:
    for name in MODULES:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - an optional library, or a broken install the worker will report
            pass
    for ep in entry_points(group="railtherm.plugins"):
        try:
            importlib.import_module(ep.value.split(":")[0])
        except Exception:  # noqa: BLE001 - a broken plugin: the worker's host loading reports it
            pass



def _numba_contexts() -> None:
    """Build numba's CPU typing and target contexts with every registration the imports above made (about
    0.4 s), which a worker would otherwise build at its first kernel, compiled or loaded from the disk cache.
    Building them starts no thread, so the forks inherit them safely."""
    try:
        from numba.core.registry import cpu_target  # numba is optional for core: imported above when installed
        cpu_target.typing_context.refresh()
        cpu_target.target_context.refresh()
    except Exception:  # noqa: BLE001 - numba missing or changed: each worker builds them itself
        pass


_warm()
_numba_contexts()
