"""Sweep maps: a study's verdict over two swept parameters as heat maps (report, sweep section).

For the scenes generated from one ``[[scene]]`` table (one base name) that sweep at least two numeric
study keys, each cell of a map is one pair of values of the two keys with the most values; the other
swept keys are reduced to their worst case (largest error or difference, worst status). Panels, for
each method with results (at most three): the relative error of the headline quantity against an
independent reference where there is one, else the status of its finest level; and, for two methods
or more, the relative difference of the headline quantity between the first two at their finest
levels (``cross_difference`` of ``metrics.nc``). Only metrics and the swept values are read (through
:mod:`.load`, which reads the output folder through the store): nothing is computed but maxima.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import figures as F
from .format import label, slug
from .load import StudyData

#: status -> rank (worse is higher) and colour of a verdict map
STATUS_RANK = {"ok": 0, "unverified": 1, "inaccurate": 2, "refused": 3, "failed": 4}
STATUS_COLOURS = ("#4daf4a", "#bdbdbd", "#ff7f00", "#377eb8", "#e41a1c")
MAX_METHODS = 3


def axes_of(data: StudyData, names: list[str]) -> tuple[str, str, list, list] | None:
    """(key x, key y, values x, values y): the two numeric swept keys of ``names`` with the most values."""
    values: dict[str, set] = {}
    for nm in names:
        for k, v in data.scene[nm].sweep.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                values.setdefault(k, set()).add(float(v))
    keys = [k for k in values if len(values[k]) >= 2]
    if len(keys) < 2:
        return None
    keys.sort(key=lambda k: -len(values[k]))
    kx, ky = keys[0], keys[1]
    return kx, ky, sorted(values[kx]), sorted(values[ky])


def grids(data: StudyData, names: list[str], kx: str, ky: str, vx: list, vy: list, methods: list[str]) -> dict:
    """Panel title -> (kind, 2-D array [y, x]): the worst over the other swept keys of each cell.

    kind "error" (relative error of the headline quantity), "status" (rank in :data:`STATUS_RANK`),
    "difference" (relative difference between two methods).
    """
    ix = {v: i for i, v in enumerate(vx)}
    iy = {v: i for i, v in enumerate(vy)}
    cell = {}
    for nm in names:
        sw = data.scene[nm].sweep
        try:
            cell[nm] = (iy[float(sw[ky])], ix[float(sw[kx])])
        except (KeyError, TypeError, ValueError):
            continue
    shape = (len(vy), len(vx))
    out = {}
    h = data.scene[names[0]].headline
    for m in methods:
        err, st = np.full(shape, np.nan), np.full(shape, np.nan)
        for nm, (i, j) in cell.items():
            r = data.finest_result(nm, m)
            runs = data.runs_of(nm, m)
            if runs:
                rank = max(STATUS_RANK.get(x.status, 4) for x in runs if x.level == max(y.level for y in runs))
                st[i, j] = rank if math.isnan(st[i, j]) else max(st[i, j], rank)
            if r is not None and math.isfinite(r.headline_error):
                err[i, j] = r.headline_error if math.isnan(err[i, j]) else max(err[i, j], r.headline_error)
        if np.isfinite(err).any():
            out[f"{m}: error of {label(h)}"] = ("error", err)
        elif np.isfinite(st).any():
            out[f"{m}: status"] = ("status", st)
    if len(methods) >= 2:
        a, b = methods[0], methods[1]
        diff = np.full(shape, np.nan)
        for nm, (i, j) in cell.items():
            q = data.cross.get(nm, {}).get(h)
            if q is None or a not in q[0] or b not in q[0]:
                continue
            v = float(q[1][q[0].index(a), q[0].index(b)])
            if math.isfinite(v):
                diff[i, j] = v if math.isnan(diff[i, j]) else max(diff[i, j], v)
        if np.isfinite(diff).any():
            out[f"|{a} − {b}| / |{b}| of {label(h)}"] = ("difference", diff)
    return out


def _ticks(ax, vx, vy, kx, ky):
    for setter, labels, vals in ((ax.set_xticks, ax.set_xticklabels, vx), (ax.set_yticks, ax.set_yticklabels, vy)):
        step = max(1, math.ceil(len(vals) / 10))
        setter(range(0, len(vals), step))
        labels([f"{v:g}" for v in vals[::step]])
    ax.set_xlabel(label(kx))
    ax.set_ylabel(label(ky))


def draw(panels: dict, kx: str, ky: str, vx: list, vy: list, tol: float | None, title: str, *, path: Path):
    """Heat maps of ``panels`` (from :func:`grids`) side by side; returns (path, CSS width) or None."""
    # matplotlib only where a figure is drawn (the report imports fast)
    from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
    if not panels:
        return None
    n = len(panels)
    fig = F.figure(4.2 * n + 0.6, 3.9)
    axes = np.atleast_1d(fig.subplots(1, n))
    for ax, (name, (kind, arr)) in zip(axes, panels.items()):
        if kind == "status":
            cmap = ListedColormap(STATUS_COLOURS)
            im = ax.imshow(arr, origin="lower", aspect="auto", cmap=cmap,
                           norm=BoundaryNorm(np.arange(-0.5, len(STATUS_COLOURS)), cmap.N), interpolation="nearest")
            cb = fig.colorbar(im, ax=ax, ticks=range(len(STATUS_RANK)))
            cb.ax.set_yticklabels(list(STATUS_RANK))
        else:
            pos = arr[np.isfinite(arr) & (arr > 0)]
            lo, hi = (float(pos.min()), float(pos.max())) if pos.size else (1e-16, 1.0)
            lo = min(lo, hi / 10)
            im = ax.imshow(np.where(arr > 0, arr, lo), origin="lower", aspect="auto", cmap="viridis",
                           norm=LogNorm(lo, hi), interpolation="nearest")
            cb = fig.colorbar(im, ax=ax)
            cb.set_label("relative " + ("error" if kind == "error" else "difference") + " [1]")
            if tol and kind == "error" and lo < tol < hi:
                cb.ax.axhline(tol, color="red", lw=1.2)
        _ticks(ax, vx, vy, kx, ky)
        ax.set_title(name, fontsize=9)
    fig.suptitle(title, fontsize=10)
    return F.save(fig, path)


def sweep_maps(doc, ctx, idx: int, base: str, methods: list[str]) -> None:
    """Add the sweep maps of every scene generated from ``base`` to the report, once per base."""
    done = ctx.__dict__.setdefault("_sweep_maps", set())
    if base in done:
        return
    done.add(base)
    names = [nm for nm in ctx.data.scenes if ctx.data.scene[nm].base == base]  # the whole sweep of the base
    ax = axes_of(ctx.data, names)
    if ax is None:
        return
    kx, ky, vx, vy = ax
    panels = grids(ctx.data, names, kx, ky, vx, vy, methods[:MAX_METHODS])
    if not panels:
        return
    others = sorted({k for nm in names for k in ctx.data.scene[nm].sweep} - {kx, ky})
    ctx.draw(doc, f"{idx:03d}-sweep-map-{slug(base)}",
             f"Sweep map of `{base}` over {label(kx)} × {label(ky)} ({len(names)} scenes)"
             + (f", the worst over {', '.join(label(k) for k in others)}" if others else "")
             + ": relative error of the headline quantity against an independent reference (red line on the "
               "colour bar: the tolerance), or the status of the finest level where there is none"
             + ("; right: the relative difference between two methods at their finest levels" if any(
                 k == "difference" for k, _ in panels.values()) else "") + ".",
             draw, panels, kx, ky, vx, vy, ctx.data.tolerance, f"{base}: {label(kx)} × {label(ky)}")
