"""Figures of the thermal-trace section (the seed paper's Figs 2-7 kinds of plot): each method's finest
result against the exact trace of ``references.nc``.

* :func:`trace`: :func:`along_x` above :func:`in_depth`, one figure per heated body;
* :func:`along_x`: temperature along the rolling direction (y = 0) on the surface and at the depth z*
  of the reference, reaching the trace behind the patch (seed Fig. 3);
* :func:`in_depth`: temperature against depth at the hottest surface point (seed Fig. 2), the peak
  temperature each depth reaches and the cooling rate after it;
* :func:`maps`: the surface temperature over the patch and its trace, one panel per method and the
  exact one, on one colour scale (seed Figs 4-7).

Temperatures are drawn as rises above the body's bulk temperature [K] (the threshold isotherm is named
in °C). The functions only read and interpolate stored arrays; every exact value is ``references.nc``'s.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .figures import REFERENCE_STYLE, Palette, figure, save

__all__ = ["trace", "along_x", "in_depth", "maps", "surface_line", "depth_line", "at_depth"]

MM = 1e3   # m -> mm


def surface_line(ds, body: int):
    """(x [m], T [degC]) of a run's surface temperature along y = 0, or None."""
    if ds is None or "surface_temperature" not in ds:
        return None
    da = ds["surface_temperature"].isel(body=body)
    if "y" in da.dims:
        da = da.isel(y=int(np.argmin(np.abs(ds["y"].values))))
    return np.asarray(ds["x"].values, float), np.asarray(da.values, float)


def at_depth(ds, body: int, z: float):
    """(x [m], T [degC]) of a run's depth field ``temperature(body, x, z)`` linearly interpolated to depth
    ``z`` [m], or None (no field, or z outside it)."""
    if ds is None or "temperature" not in ds or "z" not in ds["temperature"].dims:
        return None
    zz = np.asarray(ds["z"].values, float)
    if not (zz.min() <= z <= zz.max()):
        return None
    t = np.asarray(ds["temperature"].isel(body=body).transpose("x", "z").values, float)
    return np.asarray(ds["x"].values, float), np.array([np.interp(z, zz, row) for row in t])


def depth_line(ds, body: int, x0: float):
    """(z [m], T [degC]) of a run's depth field at the grid column nearest ``x0`` [m], or None."""
    if ds is None or "temperature" not in ds or "z" not in ds["temperature"].dims:
        return None
    i = int(np.argmin(np.abs(np.asarray(ds["x"].values, float) - x0)))
    return np.asarray(ds["z"].values, float), np.asarray(ds["temperature"].isel(body=body, x=i).values, float)


def _profile(ds, name: str, body: int):
    if ds is None or name not in ds or "z" not in ds[name].dims:
        return None
    return np.asarray(ds["z"].values, float), np.asarray(ds[name].isel(body=body).values, float)


def _patch(ax, curve, vertical: bool = True):
    a = float(np.max(curve["x"].values))
    ax.axvspan(-a * MM, a * MM, color="0.92", zorder=0, lw=0)


def _legend(fig, handles):
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 5), fontsize=8, frameon=False)


def _along_x(fig, finest: dict, curve, body: int, palette: Palette, bulk: float) -> list:
    """Left: surface temperature rise along x (y = 0) with the trace; right: the same at depth z*."""
    ax1, ax2 = fig.subplots(1, 2)
    zs = float(curve["trace_depth"].values)
    handles = []
    x = np.asarray(curve["x"].values, float) * MM
    handles += ax1.plot(x, curve["surface_temperature"].values[body] - bulk, **REFERENCE_STYLE, label="exact")
    if "trace_temperature" in curve:
        ax2.plot(x, curve["trace_temperature"].values[body] - bulk, **REFERENCE_STYLE)
    for m, ds in finest.items():
        st = dict(palette.style(m), ms=3.5, markevery=0.08)
        line = surface_line(ds, body)
        if line is not None:
            handles += ax1.plot(line[0] * MM, line[1] - bulk, **st, label=m)
        d = at_depth(ds, body, zs)
        if d is not None:
            ax2.plot(d[0] * MM, d[1] - bulk, **st)
    for ax, what in ((ax1, "on the surface, y = 0"), (ax2, f"at depth z* = {zs * MM:.3g} mm, y = 0")):
        _patch(ax, curve)
        ax.set_xlabel("x [mm] (patch shaded; the material moves to −x)")
        ax.set_ylabel("temperature rise [K]")
        ax.set_title(what, fontsize=9)
        ax.grid(True, alpha=0.3)
    return handles


def _in_depth(fig, finest: dict, curve, body: int, palette: Palette, bulk: float):
    """Rise against depth at the hottest surface point; the peak rise of each depth; the cooling rate after it."""
    ax1, ax2, ax3 = fig.subplots(1, 3, sharey=True)
    x0 = float(curve["hottest_x"].values[body])
    zr = np.asarray(curve["z"].values, float) * MM
    zt = np.asarray(curve["z_trace"].values, float) * MM
    thr = float(curve["trace_threshold"].values)
    hd = float(curve["trace_heated_depth"].values[body])
    ax1.plot(curve["temperature"].values[body] - bulk, zr, **REFERENCE_STYLE, label="exact")
    ax2.plot(curve["trace_peak_temperature"].values[body] - bulk, zt, **REFERENCE_STYLE)
    ax3.plot(curve["trace_cooling_rate"].values[body], zt, **REFERENCE_STYLE)
    for m, ds in finest.items():
        st = dict(palette.style(m), ms=3.5)
        for ax, line, rise in ((ax1, depth_line(ds, body, x0), True), (ax2, _profile(ds, "peak_temperature", body), True),
                               (ax3, _profile(ds, "cooling_rate", body), False)):
            if line is not None:
                ax.plot(line[1] - (bulk if rise else 0.0), line[0] * MM, **st, label=m)
    ax2.axvline(thr - bulk, color="0.3", ls=":", lw=1.0)
    if 0 < hd < math.inf:
        for ax in (ax2, ax3):
            ax.axhline(hd * MM, color="0.3", ls="--", lw=0.8)
    if "trace_cooling_depth" in curve:          # the depths metrics.nc does not score (log-singular rate)
        zc = float(curve["trace_cooling_depth"].values[body])
        if zc > 0:
            ax3.axhspan(0.0, zc * MM, color="0.85", alpha=0.6, lw=0)
    rates = np.asarray(curve["trace_cooling_rate"].values[body], float)
    if np.any(rates > 0):
        ax3.set_xscale("log")
    ax1.set_ylim(max(zr.max(), zt.max()), 0.0)
    ax1.set_ylabel("depth z [mm]")
    ax1.set_xlabel("temperature rise [K]")
    ax1.set_title(f"at the hottest surface point x = {x0 * MM:.3g} mm", fontsize=9)
    ax2.set_xlabel("peak temperature rise [K]")
    ax2.set_title(f"peak over the pass (dotted: the {thr:g} °C isotherm;\ndashed: its exact depth)", fontsize=9)
    ax3.set_xlabel("cooling rate after the peak [K/s]")
    ax3.set_title("fastest cooling after the peak\n(shaded: not scored, z < √(κa/4V))"
                  if "trace_cooling_depth" in curve else "fastest cooling after the peak", fontsize=9)
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)


def trace(finest: dict, curve, body: int, palette: Palette, title: str, *, path: Path, bulk: float = 0.0):
    """The thermal trace of one body in one figure: along x on the surface and at depth z* (top), and in
    depth: rise at the hottest point, peak rise per depth and the cooling rate after it (bottom)."""
    fig = figure(10, 4.7)
    top, bottom = fig.subfigures(2, 1, height_ratios=[1.0, 1.15])
    handles = _along_x(top, finest, curve, body, palette, bulk)
    _in_depth(bottom, finest, curve, body, palette, bulk)
    _legend(fig, handles)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


def along_x(finest: dict, curve, body: int, palette: Palette, title: str, *, path: Path, bulk: float = 0.0):
    """Temperature rise along the rolling direction on the surface and at depth z* (one figure)."""
    fig = figure(10, 3.8)
    _legend(fig, _along_x(fig, finest, curve, body, palette, bulk))
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


def in_depth(finest: dict, curve, body: int, palette: Palette, title: str, *, path: Path, bulk: float = 0.0):
    """Temperature rise, peak rise and cooling rate against depth (one figure)."""
    fig = figure(10, 4.0)
    _in_depth(fig, finest, curve, body, palette, bulk)
    handles = [h for h in fig.axes[0].get_lines() if not h.get_label().startswith("_")]
    _legend(fig, handles)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


def _surface_map(ds, body: int):
    if ds is None or "surface_temperature" not in ds or "y" not in ds["surface_temperature"].dims:
        return None
    t = np.asarray(ds["surface_temperature"].isel(body=body).transpose("x", "y").values, float)
    return np.asarray(ds["x"].values, float), np.asarray(ds["y"].values, float), t


def maps(finest: dict, curve, body: int, title: str, *, path: Path, bulk: float = 0.0):
    """Surface temperature maps x-y: the exact one and one per method, one colour scale."""
    panels = []
    if "surface_map" in curve:
        panels.append(("exact", np.asarray(curve["x_map"].values, float), np.asarray(curve["y_map"].values, float),
                       np.asarray(curve["surface_map"].values[body], float)))
    for m, ds in finest.items():
        s = _surface_map(ds, body)
        if s is not None:
            panels.append((m,) + s)
    if len(panels) < 2:
        return None
    vmin = min(float(np.nanmin(p[3])) for p in panels)
    vmax = max(float(np.nanmax(p[3])) for p in panels)
    n = len(panels)
    ncol = min(n, 3)
    nrow = math.ceil(n / ncol)
    x0, y0 = panels[0][1], panels[0][2]
    aspect = float(np.ptp(y0)) / max(float(np.ptp(x0)), 1e-12)   # panel height / width (equal axes)
    fig = figure(10, min(0.9 + nrow * (0.5 + 8.4 / ncol * aspect), 12.0))
    axes = np.atleast_1d(fig.subplots(nrow, ncol, sharex=True, sharey=True, squeeze=False)).ravel()
    a = float(np.max(curve["x"].values))
    b = float(np.max(np.abs(curve["y_map"].values))) if "y_map" in curve else None
    im = None
    for ax, (name, x, y, t) in zip(axes, panels):
        im = ax.pcolormesh(x * MM, y * MM, t.T - bulk, shading="nearest", cmap="inferno", vmin=vmin - bulk,
                           vmax=vmax - bulk)
        if b:
            th = np.linspace(0, 2 * np.pi, 181)
            ax.plot(a * MM * np.cos(th), b * MM * np.sin(th), color="white", lw=0.8, ls="--")
        ax.set_title(name, fontsize=9)
        ax.set_aspect("equal")
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    for ax in axes[-ncol:]:
        ax.set_xlabel("x [mm]")
    for ax in axes[::ncol]:
        ax.set_ylabel("y [mm]")
    fig.colorbar(im, ax=list(axes[:len(panels)]), label="surface temperature rise [K]", shrink=0.9)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)
