"""The analysis phase of a study, after its runs: metrics.nc and references.nc.

The runs' scoring (:func:`railtherm.analysis.metrics.compute_metrics`) and the exact reference curves
(:func:`railtherm.analysis.reference_curves.write_reference_curves`) go to one pool of local worker
processes when the runs used them: the scoring of each scene first, the curves right behind, so a worker
done with its share of the scoring takes curves instead of idling. A pool that breaks costs only the time:
the work is then done in this process.
"""
from __future__ import annotations

import contextlib
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from ..analysis.metrics import compute_metrics
from ..output import store
from .executors import host_spec, install_host, worker_context, worker_threads

#: a study scores its runs in the local worker processes when it has at least this many results
PARALLEL_METRICS_MIN_RUNS = 40


@contextlib.contextmanager
def _analysis_pool(executor: str, workers: int, scored: int):
    """Yield a ``map`` over ``workers`` local processes (spawned with this process's plugin host) for the
    scoring and the reference curves when the runs used local processes, else None (computed here)."""
    if executor != "processes" or workers < 2 or scored < PARALLEL_METRICS_MIN_RUNS:
        yield None
        return
    with worker_threads(workers):
        pool = ProcessPoolExecutor(workers, mp_context=worker_context(), initializer=install_host,
                                   initargs=(host_spec(),))
    with pool:
        yield pool.map


def _metrics(study, out, records, pmap, scored=None):
    """metrics.nc's Dataset, the scenes scored through ``pmap`` (:func:`_analysis_pool`; ``scored``: its
    results already submitted) or here; a pool that breaks costs only the time."""
    if pmap is not None:
        try:
            return compute_metrics(study, out, records, map=pmap, scored=scored)
        except Exception as exc:  # noqa: BLE001 - scored here instead
            warnings.warn(f"scoring in worker processes failed ({type(exc).__name__}: {exc}); scoring here",
                          RuntimeWarning, stacklevel=2)
    return compute_metrics(study, out, records)


def _reference_curves(study, out, pmap, pending=None) -> None:
    """references.nc, the scenes' curves computed through ``pmap`` (``pending``: the jobs and their results
    already submitted) or here (as :func:`_metrics`)."""
    from ..analysis.reference_curves import collect_curves, write_reference_curves  # xarray: ~1 s
    if pmap is not None:
        try:
            curves = collect_curves(*pending) if pending is not None else None
            write_reference_curves(study, out, map=pmap, curves=curves)
            return
        except Exception as exc:  # noqa: BLE001 - computed here instead
            warnings.warn(f"reference curves in worker processes failed ({type(exc).__name__}: {exc}); "
                          "computing them here", RuntimeWarning, stacklevel=2)
    write_reference_curves(study, out)


def _submit_analysis(study, records, pmap, curves: bool):
    """Submit the scoring of every scene and then the reference curves to the pool behind ``pmap``, so that a
    worker done with its share of the scoring takes a scene's curves instead of waiting for the others:
    (scored parts, (curve jobs, their results) or None). Nothing is submitted without a pool."""
    if pmap is None:
        return None, None
    # the pool's result thread unpickles the curves (xarray Datasets) while this thread scores: with xarray
    # not yet imported here, both would import it at once and deadlock on its module locks
    import xarray  # noqa: F401
    from ..analysis.metrics import submit_scoring
    from ..analysis.reference_curves import curve_jobs, scene_curves_job
    scored = submit_scoring(study, records, pmap)
    if not curves:
        return scored, None
    jobs = curve_jobs(study)
    return scored, (jobs, pmap(scene_curves_job, jobs))


def analyse(study, out: Path, records, executor: str, workers: int, kind: str):
    """Metrics of the runs (written to ``metrics.nc``) and the exact reference curves the report overlays."""
    # a scalar sweep in the Zarr store keeps no field to overlay exact curves on (they cost ~0.1 s per scene)
    curves = not (kind == "zarr" and not getattr(study, "keep_fields", False))
    with _analysis_pool(executor, workers, sum(r.status == "ok" for r in records)) as pmap:
        scored, pending = _submit_analysis(study, records, pmap, curves)
        metrics = _metrics(study, out, records, pmap, scored)
        metrics.attrs.update({"executor": executor, "workers": int(workers),
                              "workers_comment": "worker processes that shared the machine while runs were timed"})
        store.write_dataset_atomic(metrics, store.metrics_path(out))
        if not curves:
            store.write_references(store.references_path(out), {
                "Conventions": "CF-1.11", "title": f"railtherm reference curves of study {study.name}",
                "study": study.name, "scenes": 0,
                "comment": "not computed: the study keeps its runs in the Zarr store without fields"}, {})
        else:
            _reference_curves(study, out, pmap, pending)  # the exact curves the report overlays (it never recomputes physics)
    return metrics
