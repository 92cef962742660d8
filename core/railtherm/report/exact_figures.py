"""Figures of the exact-contact section: the creep-force curve of the exact contact against a simplified
contact model (with the linear theory), and maps of traction, slip and power density side by side."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .figures import Palette, figure, save

__all__ = ["CreepCurve", "creep_curve_figure", "maps_figure"]


@dataclass
class CreepCurve:
    """Fx / (mu N) [1] over the longitudinal creepage, per method: [(creepage, ratio, level)]."""

    exact: str
    values: dict = field(default_factory=dict)
    linear: tuple | None = None   # (creepages, ratios, label) of the linear theory (NaN beyond saturation)
    labels: dict = field(default_factory=dict)   # method -> legend label
    ylabel: str = "Fx / (μ N) [1]"


def creep_curve_figure(curve: CreepCurve, palette: Palette, *, path: Path):
    """Left: Fx / (mu N) against the creepage; right: each method's relative error against the exact one."""
    fig = figure(10, 3.9)
    ax, ax2 = fig.subplots(1, 2)
    handles = []
    if curve.linear is not None:
        xs, ys, label = curve.linear
        handles += ax.plot(xs, ys, "--", color="0.35", lw=1.0, label=label)
    ex = sorted(curve.values.get(curve.exact, []))
    handles += ax.plot([p[0] for p in ex], [p[1] for p in ex], "-", color="black", marker="o", ms=4, lw=1.6,
                       label=f"{curve.exact} (exact contact)")
    ref = {p[0]: p[1] for p in ex}
    for m, pts in curve.values.items():
        if m == curve.exact:
            continue
        pts = sorted(pts)
        st = palette.style(m)
        handles += ax.plot([p[0] for p in pts], [p[1] for p in pts], **st, label=curve.labels.get(m, m))
        err = [(x, (v - ref[x]) / abs(ref[x])) for x, v, _ in pts if x in ref and ref[x]]
        if err:
            ax2.plot([e[0] for e in err], [100 * e[1] for e in err], **st)
    for s in (-1, 1):
        ax.axhline(s, color="0.45", lw=0.8, ls=":")
    ax.axhline(0, color="0.5", lw=0.6)
    lo = min((p[1] for pts in curve.values.values() for p in pts), default=-1.0)
    hi = max((p[1] for pts in curve.values.values() for p in pts), default=1.0)
    pad = 0.1 * max(hi - lo, 0.2)
    ax.set_ylim(min(lo, 0) - pad, max(hi, 0) + pad)
    ax.set_xlabel("longitudinal creepage ξ [1]")
    ax.set_ylabel(curve.ylabel)
    ax.set_title("creep force (finest successful level)", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax2.axhline(0, color="0.5", lw=0.6)
    ax2.set_xlabel("longitudinal creepage ξ [1]")
    ax2.set_ylabel(f"(Fx − Fx of {curve.exact}) / |Fx of {curve.exact}| [%]")
    ax2.set_title(f"error against the exact contact ({curve.exact})", fontsize=9)
    ax2.grid(True, alpha=0.3)
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle("Creep-force curve: exact contact against simplified contact", fontsize=10)
    return save(fig, path)


def _magnitude(ds, a: str, b: str):
    if a not in ds:
        return None
    v = np.asarray(ds[a].values, float) ** 2
    if b in ds:
        v = v + np.asarray(ds[b].values, float) ** 2
    return np.sqrt(v)


def _panels(ds, pressure: bool) -> list[tuple[str, np.ndarray | None, float, str]]:
    """(title, field (x, y), scale, colour map) of the maps of one run."""
    out = []
    if pressure:
        out.append(("pressure p [MPa]", np.asarray(ds["pressure"].values, float) if "pressure" in ds else None,
                    1e-6, "viridis"))
    out.append(("traction |q| [MPa]", _magnitude(ds, "traction_x", "traction_y"), 1e-6, "viridis"))
    if not pressure:
        out.append(("slip velocity |v_s| [m/s]", _magnitude(ds, "slip_velocity_x", "slip_velocity_y"), 1.0, "magma"))
    q = np.asarray(ds["heat_flux"].values, float).sum(axis=0) if "heat_flux" in ds and "body" in ds["heat_flux"].dims \
        else None
    out.append(("power density, both bodies [MW/m²]", q, 1e-6, "inferno"))
    return out


def maps_figure(maps: dict, title: str, *, path: Path, pressure: bool = False):
    """One row per method, one column per field (common colour scale per column, same axes)."""
    items = [(m, ds) for m, ds in maps.items() if ds is not None and "y" in ds.dims]
    if not items:
        return None
    ncol = len(_panels(items[0][1], pressure))
    nrow = len(items)
    fig = figure(10, 2.9 * nrow + 0.8)
    axes = fig.subplots(nrow, ncol, squeeze=False, sharex=True, sharey=True)
    vmax = [0.0] * ncol
    fields = []
    for _, ds in items:
        inside = np.asarray(ds["pressure"].values, float) > 0 if "pressure" in ds else None
        row = []
        for j, (label, f, scale, cmap) in enumerate(_panels(ds, pressure)):
            if f is not None:
                f = f * scale
                if inside is not None and f.shape == inside.shape:
                    f = np.ma.masked_where(~inside, f)
                vmax[j] = max(vmax[j], float(np.ma.max(f)) if np.ma.count(f) else 0.0)
            row.append((label, f, cmap))
        fields.append(row)
    for i, ((m, ds), row) in enumerate(zip(items, fields)):
        x, y = ds["x"].values * 1e3, ds["y"].values * 1e3
        lv = ds.attrs.get("level", "?")
        for j, (label, f, cmap) in enumerate(row):
            ax = axes[i][j]
            if f is None:
                ax.text(0.5, 0.5, "not in the run file", ha="center", va="center", transform=ax.transAxes,
                        color="0.4", fontsize=8)
            else:
                pc = ax.pcolormesh(x, y, np.ma.asarray(f).T, cmap=cmap, vmin=0.0, vmax=vmax[j] or 1.0,
                                   shading="nearest", rasterized=True)
                if i == nrow - 1 or nrow == 1:
                    fig.colorbar(pc, ax=[axes[k][j] for k in range(nrow)], label=label, shrink=0.85,
                                 location="bottom")
            ax.set_title(f"{m} (level {lv})", fontsize=9)
            ax.set_aspect("equal")
            ax.set_xlabel("x [mm]")
            ax.set_ylabel("y [mm]")
            ax.label_outer()
    fig.suptitle(title, fontsize=10)
    if not math.isfinite(sum(vmax)):
        return None
    return save(fig, path)
