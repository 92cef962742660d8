"""Relative errors of one result against its references (contract: ``docs/verdicts.md``).

Each error is relative and records what it was taken against: ``analytic:<tag>`` (core's exact
reference), ``method:<name>`` (another method's finest successful level) or ``self:finest`` (the run's
own method at its finest level: an estimate of discretisation error, never a verification).

An error is not taken at all when it would compare a computation with itself: a model of the run's chain
that *is* the exact reference (the Hertz patch against Hertz), or a reference method that runs the same
stage models up to the stage that produces the quantity (:func:`railtherm.analysis.verdicts.shares_stage`).
A metric is not scored where its reference is zero by symmetry or below its noise floor
(:func:`railtherm.analysis.verdicts.unscored`). A value that is not finite where its reference is finite
scores ``inf`` (the metric fails), and so does a field that cannot be put on the run's grid; the reason is
recorded in ``notes``.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..physics import body_speeds
from ..solving.plugins import get_host
from .analytic import _thermal_case, reference_fields
from .rises import bulk_of as _bulk, bulk_temperatures, rel_error, rel_l2
from .trace_metrics import TRACE_METRICS, trace_errors
from .verdicts import shares_stage, unscored, zero_by_symmetry

SCALARS = ("max_surface_temperature", "mean_contact_temperature", "max_pressure", "semi_axis_a",
           "creep_force_x", "frictional_power", "steady_wheel_temperature", "steady_mean_contact_temperature")
FIELDS = ("surface_temperature", "pressure")
METRICS = SCALARS + tuple(f + "_l2" for f in FIELDS)
#: cells at which an analytic field reference is evaluated per run (a regular subsample of the grid)
MAX_FIELD_POINTS = 1500


def signed_error(bulk, name: str, value, reference) -> float:
    """The signed version of :func:`rel_error` [1]: (value − reference) / max |reference| at the entry where
    |value − reference| is largest (its magnitude is :func:`rel_error`); temperatures on their rise above
    ``bulk``, the wheel's and the rail's bulk temperatures [degC]."""
    v, r = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    e = rel_error(bulk, name, v, r)
    if not math.isfinite(e) or e == 0:
        return e
    b = _bulk(bulk, name, v.shape)
    d = np.where(np.isfinite(r), (v - b) - (r - b), 0.0)
    return math.copysign(e, float(np.ravel(d)[int(np.argmax(np.abs(d)))]))


def _interp_to(ref, ds, name):
    """Field ``name`` of run ``ref`` on the grid of run ``ds`` (linear, extrapolating at the edges)."""
    da = ref[name]
    kw = {d: ds[d] for d in ("x", "y") if d in da.dims and d in ds.dims}
    return da.interp(kw, kwargs={"fill_value": "extrapolate"}).values


def chain_references(ds) -> set[str]:
    """Tags of core's exact references that a model of the run's chain reproduces by construction."""
    host = get_host()
    tags = set()
    for part in str(ds.attrs.get("stages", "")).split():
        stage, _, name = part.rpartition(":")
        info = host.models.get(name)
        cls = None
        if info is not None:
            try:
                cls = info.for_stage(stage) if stage else info.cls
            except KeyError:
                cls = info.cls
        tag = getattr(cls, "exact_reference", None)
        if tag:
            tags.add(tag)
    return tags


def _field_subsample(ds, values):
    """The cells of ``ds`` the exact fields are compared on: at most ~:data:`MAX_FIELD_POINTS` cells of a
    regular subsample; None when there is nothing exact or the result has no surface grid (a Zarr row)."""
    if not values or "x" not in ds.dims:
        return None
    n = ds.sizes["x"] * ds.sizes.get("y", 1)
    stride = max(1, int(math.ceil(math.sqrt(n / MAX_FIELD_POINTS))))
    return ds.isel({d: slice(stride // 2, None, stride) for d in ("x", "y") if d in ds.dims})


# whole scene: the metrics' entry for one run: it reads the scene's materials, kinematics, symmetry and source
def run_errors(scene, ds, ref_values: dict, ref_ds=None, *, ref_tag: str = "", sources: dict | None = None,
               notes: dict | None = None, signed: dict | None = None) -> dict[str, tuple[float, str]]:
    """Relative errors of one result: metric -> (error [1], reference tag).

    Parameters
    ----------
    scene : Scene
    ds : xarray.Dataset
        The result (a run file, or a row of the Zarr store without fields).
    ref_values : dict
        Exact values (:func:`railtherm.analysis.analytic.reference_values`); ``"_sources"`` (quantity -> tag)
        names them, or ``sources``.
    ref_ds : xarray.Dataset, optional
        A reference run for quantities without an exact value.
    ref_tag : str
        Tag of ``ref_ds`` (``method:<name>`` or ``self:finest``).
    notes : dict, optional
        Filled with metric -> why it is not scored (NaN error) or why it fails (``inf``).
    signed : dict, optional
        Filled with scalar metric -> its error with the sign of (value − reference) (:func:`signed_error`).
    """
    notes = {} if notes is None else notes
    signed = {} if signed is None else signed
    sources = dict(sources if sources is not None else ref_values.get("_sources", {}))
    values = {k: v for k, v in ref_values.items() if not k.startswith("_")}
    same = chain_references(ds) if values else set()
    if scene.heat_source is not None:  # every method takes a given source as it is
        same.add("given-source")
    sub = _field_subsample(ds, values)
    sub, fields = (ds, {}) if sub is None else (sub, reference_fields(scene, sub))
    bulk = bulk_temperatures(scene.wheel, scene.rail)
    zero = zero_by_symmetry(scene.creepage, scene.contact_shape, getattr(scene, "gap_coefficients", None),
                            scene.wheel, scene.rail, wheelset=scene.wheelset, heat_source=scene.heat_source)
    sc = _Scorer(bulk, zero, ds, ref_ds, ref_tag, sources, same, notes, signed)
    err = sc.err
    for name in SCALARS:
        if name not in ds:
            continue
        if name in values:
            tag = sc.exact(name)
            if tag:
                sc.score(name, ds[name].values, values[name], tag)
        elif ref_ds is not None and name in ref_ds and not sc.shared(name):
            sc.score(name, ds[name].values, ref_ds[name].values, ref_tag)
    for name in FIELDS:
        if name not in ds or name not in ds.data_vars or "x" not in ds[name].dims:
            continue
        if "patch" in ds[name].dims:   # each patch on its own grid (contract.patch_grid): its scalars are scored
            notes[name + "_l2"] = "not scored: a field of several patches, each on its own grid"
            continue
        if name in fields:
            tag = sc.exact(name)
            if tag:
                sc.score(name + "_l2", sub[name].values, fields[name], tag, l2=True)
        elif ref_ds is not None and name in ref_ds and not sc.shared(name + "_l2"):
            sc.score_against_run(name)
    if ref_ds is not None and any(n in ds for n in TRACE_METRICS) and sc.shared("peak_temperature"):
        ref_ds = None                       # the trace of the same temperature model: not a check
    speeds = body_speeds(scene.speed, scene.sliding_speed, scene.tangential)
    err.update(trace_errors(ds, fields, values, ref_ds, ref_tag, sc.exact, notes=notes, bulk=bulk, speeds=speeds,
                            wheel=scene.wheel, rail=scene.rail, case=functools.partial(_thermal_case, scene)))
    return err


@dataclass
class _Scorer:
    """What :func:`run_errors` needs to score one metric, built once per result: the bulk temperatures
    (wheel, rail) [degC] and the metrics zero by symmetry of the scene, the tags of its exact references,
    whether the reference run shares a stage model, and the errors, signed errors and notes filled in."""

    bulk: tuple
    zero: dict
    ds: Any
    ref_ds: Any
    ref_tag: str
    sources: dict
    same: set
    notes: dict
    signed: dict
    err: dict = field(default_factory=dict)

    def exact(self, name):
        """Tag ``analytic:<source>`` of the exact value of ``name``, None when the run computes it the same way."""
        tag = self.sources.get(name, "analytic")
        return None if tag in self.same else f"analytic:{tag}"

    def shared(self, name) -> bool:
        """The reference run computes ``name`` with the same stage model (noted: not independent)."""
        if self.ref_ds is None or not self.ref_tag.startswith("method:"):
            return False
        model = shares_stage(name, self.ds.attrs.get("stages", ""), self.ref_ds.attrs.get("stages", ""))
        if model:
            self.notes[name] = f"not independent: {self.ref_tag} runs the same {model} model"
        return bool(model)

    def score(self, name, value, reference, tag, l2=False):
        """Record the relative error (and the signed error of a scalar) of ``value``, or why it is not scored."""
        quantity = name.removesuffix("_l2")
        why = unscored(name, reference, _bulk(self.bulk, quantity, np.shape(reference)), self.zero)
        if why:
            self.notes[name] = why
            self.err[name] = (math.nan, tag)
            return
        e = (rel_l2 if l2 else rel_error)(self.bulk, quantity, value, reference)
        if math.isinf(e):
            self.notes[name] = "not finite where its reference is"
        elif not l2:
            self.signed[name] = signed_error(self.bulk, name, value, reference)
        self.err[name] = (e, tag)

    def score_against_run(self, name):
        """Score field ``name`` against the reference run's, put on the run's grid (a failure to do so fails it)."""
        ds, ref_tag = self.ds, self.ref_tag
        try:
            on_grid = _interp_to(self.ref_ds, ds, name)
            if on_grid.shape != ds[name].shape:
                raise ValueError(f"shape {on_grid.shape} on the run's grid, the run's is {ds[name].shape}")
        except Exception as exc:  # noqa: BLE001 - recorded: the metric fails, it does not drop out
            self.err[name + "_l2"] = (math.inf, ref_tag)
            self.notes[name + "_l2"] = f"the reference field could not be put on the run's grid ({exc})"
            return
        self.score(name + "_l2", ds[name].values, on_grid, ref_tag, l2=True)
