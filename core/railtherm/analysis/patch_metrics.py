"""Errors of a result with several patches (a wheelset on profiles with ``patch = "all"``: quantities with a
``patch`` dimension) scored patch by patch.

One relative max-norm over (body, patch) scales every patch's error by the largest patch's value, so a small
flange patch that is 50 % off hides behind a tread patch ten times hotter. Here each patch's error is taken
against the reference run's same patch (:func:`railtherm.analysis.rises.rel_error` over the bodies of that
patch, its own scale); the metric's error is the largest over the patches, and the patch it lies on is named
(``patch_of``; metrics.nc's ``headline_patch`` for the headline quantity, ``patch_errors_<metric>`` for all).
A patch whose reference is zero or below the noise floor (:func:`railtherm.analysis.verdicts.unscored`) is not
scored and noted; runs whose patches are not the reference's (another count) fail the metric (``inf``).
"""
from __future__ import annotations

import math

import numpy as np

from .errors import signed_error
from .rises import bulk_of, rel_error
from .verdicts import unscored

__all__ = ["patch_errors", "patch_columns", "PATCH_DIM"]

#: the dimension of a result's patches
PATCH_DIM = "patch"


def _per_patch(bulk, zero: dict, name: str, value, reference, patches) -> tuple[list, dict]:
    """[(patch, error, signed error)] of the scored patches and {patch: why} of those not scored; ``value`` and
    ``reference`` are DataArrays with the patch dimension; ``bulk`` and ``zero`` as :func:`patch_errors` takes
    them."""
    scored, skipped = [], {}
    for p in patches:
        v = np.asarray(value.sel({PATCH_DIM: p}).values, float)
        r = np.asarray(reference.sel({PATCH_DIM: p}).values, float)
        why = unscored(name, r, bulk_of(bulk, name, np.shape(r)), zero)
        if why:
            skipped[int(p)] = why
            continue
        e = rel_error(bulk, name, v, r)
        s = signed_error(bulk, name, v, r) if math.isfinite(e) and e != 0 else e
        scored.append((int(p), e, s))
    return scored, skipped


def patch_errors(bulk, ds, ref_ds, errs: dict, *, zero: dict | None = None, notes: dict | None = None,
                 signed: dict | None = None, row: dict | None = None, headline: str = "") -> dict:
    """Re-score the errors of ``errs`` whose quantity has a ``patch`` dimension, patch by patch (module docstring).

    Parameters
    ----------
    bulk : (float, float)
        The wheel's and the rail's bulk temperatures [degC] (temperatures are scored on their rise).
    ds, ref_ds : xarray.Dataset
        The run and its reference run (None: nothing is re-scored; an analytic reference has no patches).
    errs : dict
        metric -> (error [1], reference tag), as :func:`railtherm.analysis.errors.run_errors` returns them; the
        metrics of quantities with patches are replaced by the largest error over the patches.
    notes, signed : dict, optional
        Filled as by ``run_errors`` (why a patch is not scored; the signed error at the worst patch).
    row : dict, optional
        metrics.nc row: gets ``patch_errors_<metric>`` ("patch: error; ..." of every patch) and
        ``headline_patch`` (the patch of ``headline``'s error, 0 when it has none).
    headline : str
        The scene's headline quantity.
    zero : dict, optional
        The scene's metrics that are zero by symmetry, and why (:func:`railtherm.analysis.verdicts.zero_by_symmetry`).

    Returns
    -------
    dict
        metric -> patch [1] of its largest error, for the re-scored metrics.
    """
    notes = {} if notes is None else notes
    signed = {} if signed is None else signed
    patch_of: dict = {}
    if ref_ds is None or PATCH_DIM not in ds.dims:
        return patch_of
    for name, (_, tag) in list(errs.items()):
        if name not in ds or name not in ref_ds or PATCH_DIM not in ds[name].dims:
            continue
        mine = [int(p) for p in ds[PATCH_DIM].values]
        theirs = [int(p) for p in ref_ds[PATCH_DIM].values] if PATCH_DIM in ref_ds.dims else []
        if mine != theirs:
            errs[name] = (math.inf, tag)
            notes[name] = f"the run's patches {mine} are not the reference's {theirs}"
            continue
        scored, skipped = _per_patch(bulk, zero or {}, name, ds[name], ref_ds[name], mine)
        for p, why in skipped.items():
            notes[f"{name} patch {p}"] = why
        if row is not None:
            row[f"patch_errors_{name}"] = "; ".join(f"{p}: {e:.4g}" for p, e, _ in scored)
        if not scored:
            errs[name] = (math.nan, tag)
            notes[name] = "no patch scored: " + "; ".join(f"patch {p}: {w}" for p, w in skipped.items())
            signed.pop(name, None)
            continue
        p, e, s = max(scored, key=lambda t: -1.0 if math.isnan(t[1]) else t[1])
        errs[name] = (e, tag)
        signed[name] = s
        patch_of[name] = p
    if row is not None:
        row["headline_patch"] = int(patch_of.get(headline, 0))
    return patch_of


def patch_columns(table, rows: list) -> "object":
    """metrics.nc's per-run table ``table`` (dimension ``run``) with ``headline_patch`` and the
    ``patch_errors_<metric>`` columns of ``rows``, when a row has them (a study with several-patch scenes)."""
    cols = sorted({k for r in rows for k in r if k.startswith("patch_errors_")})
    if not cols and not any("headline_patch" in r for r in rows):
        return table
    table["headline_patch"] = ("run", np.array([int(r.get("headline_patch", 0)) for r in rows], dtype="int32"),
                               {"units": "1", "long_name": "patch of the headline error (the largest over the "
                                                           "patches; 0: the scene has no patch dimension)"})
    for c in cols:
        metric = c.removeprefix("patch_errors_")
        table[c] = ("run", np.array([r.get(c, "") for r in rows], dtype=object),
                    {"units": "1", "long_name": f"relative error of {metric} per patch against reference_{metric}: "
                                                "'patch: error; ...' (each patch on its own scale)"})
    return table
