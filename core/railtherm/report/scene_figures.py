"""Temperature figures of a scene's section: the surface temperature rise along the rolling direction and
the rise against depth, each method's finest level beside the reference.

Rises are above each body's bulk temperature [K]. An ellipse's line is the one through the hottest
surface point (a spin creepage heats the flanks, not y = 0); when the exact curve of ``references.nc``
exists (it lies on y = 0, where a symmetric source is hottest) the line is y = 0. A depth figure is drawn
only when there is a reference profile to show beside the methods: the exact one, or the reference
method's own depth field.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import BODIES, REFERENCE_STYLE, Palette, figure, save

__all__ = ["surface", "depth", "line_y"]


def line_y(ds, body: int) -> float | None:
    """y [m] of the hottest surface point of a run's body (None: the run has no y axis)."""
    da = ds["surface_temperature"].isel(body=body)
    if "y" not in da.dims:
        return None
    t = np.asarray(da.transpose("x", "y").values, float)
    if not np.isfinite(t).any():
        return 0.0
    _, j = np.unravel_index(int(np.nanargmax(t)), t.shape)
    return float(ds["y"].values[j])


def _line(ds, body: int, y0: float | None):
    da = ds["surface_temperature"].isel(body=body)
    if "y" in da.dims:
        da = da.sel(y=0.0 if y0 is None else y0, method="nearest")
    return np.asarray(da["x"].values, float), np.asarray(da.values, float)


def _heated(body: int, have: dict, var: str, ref) -> bool:
    """False when neither a method nor the exact curve has any temperature variation in ``body``."""
    vals = [np.asarray(ds[var].isel(body=body).values, float) for ds in have.values()]
    if ref is not None and var in ref:
        vals.append(np.asarray(ref[var].values[body], float))
    return any(np.nanmax(v) - np.nanmin(v) > 0 for v in vals if np.isfinite(v).any())


def _y_of_line(have: dict, body: int, exact: bool, ref_method: str) -> float | None:
    if exact or not any("y" in ds["surface_temperature"].dims for ds in have.values()):
        return 0.0 if any("y" in ds.dims for ds in have.values()) else None
    ds = have.get(ref_method) or next(iter(have.values()))
    return line_y(ds, body)


def surface(finest: dict, curve, palette: Palette, title: str, path: Path, bulk=(0.0, 0.0), ref_method: str = ""):
    """Surface temperature rise along x of both bodies on the line through the hottest point, with the exact
    curve and each method's difference from it (or, against a reference method, that method as the band)."""
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    have = {m: ds for m, ds in finest.items() if "surface_temperature" in ds}
    if not have:
        return None
    ref = curve if curve is not None and "surface_temperature" in curve else None
    if ref is not None:
        # scipy only where a curve is drawn (the report imports fast)
        from scipy.interpolate import PchipInterpolator
        xr_ = ref["x"].values
        # a body heated at rest under the contact (a locked wheel) has no steady exact curve (NaN): no band for it
        ref_at = [PchipInterpolator(xr_, ref["surface_temperature"].values[i])
                  if np.isfinite(ref["surface_temperature"].values[i]).all() else None for i in (0, 1)]
        fig = figure(10, 4.2)
        grid = fig.subplots(2, 2, sharex=True, height_ratios=[2.2, 1])
        axes, daxes = grid[0], grid[1]
    else:
        fig = figure(10, 2.9)
        axes, daxes = fig.subplots(1, 2), (None, None)
    a = next((float(ds["semi_axis_a"]) for ds in have.values() if "semi_axis_a" in ds), None)
    for body, (ax, dax) in enumerate(zip(axes, daxes)):
        if not _heated(body, have, "surface_temperature", ref):
            for a_ in (ax, dax):
                if a_ is not None:
                    a_.set_visible(False)
            ax.figure.text(0.27 + 0.5 * body, 0.5, f"{BODIES[body]}: not heated (no heat enters it)",
                           ha="center", color="0.4", fontsize=9)
            continue
        y0 = _y_of_line(have, body, ref is not None, ref_method)
        b0 = float(bulk[body]) if bulk else 0.0
        if ref is not None and ref_at[body] is not None:
            ax.plot(xr_ * 1e3, ref["surface_temperature"].values[body] - b0, "-", **REFERENCE_STYLE)
        elif ref is not None:
            dax.text(0.5, 0.5, "no steady exact curve: this body is heated at rest", transform=dax.transAxes,
                     ha="center", va="center", color="0.4", fontsize=8)
        for m, ds in have.items():
            x, t = _line(ds, body, y0)
            st = palette.style(m)
            if x.size > 40:
                st["marker"] = None
            if m == ref_method and ref is None:
                ax.plot(x * 1e3, t - b0, "-", **REFERENCE_STYLE)
                st["marker"] = None
            ax.plot(x * 1e3, t - b0, **st)
            if dax is not None and ref_at[body] is not None:
                inside = (x >= xr_[0]) & (x <= xr_[-1])
                dax.plot(x[inside] * 1e3, t[inside] - ref_at[body](x[inside]), **st)
        for a_ in (ax, dax):
            if a_ is None:
                continue
            if a:
                for s_ in (-a, a):
                    a_.axvline(s_ * 1e3, color="0.6", lw=0.8, ls=":")
            a_.grid(True, alpha=0.3)
        ax.set_ylabel("surface temperature rise [K]")
        where = "" if y0 is None else " (y = 0)" if y0 == 0 else f" (y = {y0 * 1e3:.3g} mm, through the hottest point)"
        ax.set_title(BODIES[body] + where, fontsize=10)
        last = ax
        if dax is not None:
            dax.axhline(0.0, color="0.4", lw=0.8)
            dax.set_ylabel("T − T$_{exact}$ [K]")
            last = dax
        last.set_xlabel("x [mm] (leading edge at +a)")
    handles = [Line2D([], [], **palette.style(m), label=f"{m} (level {int(ds.attrs.get('level', -1))})")
               for m, ds in have.items()]
    if ref is not None:
        handles.insert(0, Line2D([], [], **REFERENCE_STYLE, label="exact"))
    elif ref_method in have:
        handles.insert(0, Line2D([], [], **REFERENCE_STYLE, label=f"reference: {ref_method}"))
    if a:
        handles.append(Line2D([], [], color="0.6", lw=0.8, ls=":", label="patch edges x = ±a"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


def _heated_depth(z, t, bulk) -> float:
    """Depth [m] below which the temperature rise stays under 1 % of its maximum."""
    rise = np.abs(np.asarray(t, float) - bulk)
    if rise.size == 0 or not np.isfinite(rise).any() or np.nanmax(rise) == 0:
        return float(np.max(z)) if np.size(z) else 0.0
    above = np.nonzero(rise > 0.01 * np.nanmax(rise))[0]
    return float(z[min(above[-1] + 1, z.size - 1)])


def _profile(ds, body: int, x0: float, y0):
    da = ds["temperature"].isel(body=body)
    if "y" in da.dims:
        da = da.sel(y=0.0 if y0 is None else y0, method="nearest")
    da = da.sel(x=x0, method="nearest")
    return np.asarray(da["z"].values, float), np.asarray(da.values, float)


def depth(finest: dict, curve, bulk: tuple | None, palette: Palette, title: str, path: Path, ref_method: str = ""):
    """Temperature rise against depth through the hottest surface point, the reference (exact profile, or
    the reference method's) as a grey band beside the methods; None when there is no reference profile."""
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    have = {m: ds for m, ds in finest.items() if "temperature" in ds and "z" in ds.dims}
    exact = curve if curve is not None and "temperature" in curve and "hottest_x" in curve else None
    band = have.get(ref_method) if exact is None else None
    if not have or (exact is None and band is None):
        return None
    fig = figure(10, 3.2)
    axes = fig.subplots(1, 2)
    zmax = max(float(ds["z"].max()) for ds in have.values())
    for body, ax in enumerate(axes):
        if not _heated(body, have, "temperature", exact):
            ax.set_visible(False)
            fig.text(0.27 + 0.5 * body, 0.5, f"{BODIES[body]}: not heated", ha="center", color="0.4", fontsize=9)
            continue
        src = band if band is not None else next(iter(have.values()))
        y0 = line_y(src, body) if "surface_temperature" in src else None
        if exact is not None:
            x0 = float(exact["hottest_x"].values[body])
        else:
            t0 = src["temperature"].isel(body=body, z=0)
            if "y" in t0.dims:
                t0 = t0.sel(y=y0 or 0.0, method="nearest")
            x0 = float(t0["x"].values[int(np.nanargmax(t0.values))])
        b0 = float(bulk[body]) if bulk else 0.0
        profiles = {m: _profile(ds, body, x0, y0) for m, ds in have.items()}
        zlim = max(_heated_depth(z, t, b0) for z, t in profiles.values())
        zlim = min(1.3 * zlim, zmax) if zlim > 0 else zmax
        if exact is not None:
            zr = exact["z"].values
            sel = zr <= zlim * 1.001
            ax.plot(exact["temperature"].values[body][sel] - b0, zr[sel] * 1e3, "-", **REFERENCE_STYLE)
        for m, (z, t) in profiles.items():
            st = palette.style(m)
            if int(np.sum(z <= zlim)) > 30:
                st["marker"] = None
            if m == ref_method and exact is None:
                ax.plot(t - b0, z * 1e3, "-", **REFERENCE_STYLE)
                st["marker"] = None
            ax.plot(t - b0, z * 1e3, **st)
        ax.set_ylim(zlim * 1e3, 0.0)
        ax.set_xlabel("temperature rise [K]")
        ax.set_ylabel("depth z [mm]")
        where = "" if y0 is None else f", y = {y0 * 1e3:.3g} mm"
        ax.set_title(f"{BODIES[body]}: x = {x0 * 1e3:.3g} mm{where}", fontsize=10)
        ax.grid(True, alpha=0.3)
    handles = [Line2D([], [], **palette.style(m), label=f"{m} (level {int(ds.attrs.get('level', -1))})")
               for m, ds in have.items()]
    handles.insert(0, Line2D([], [], **REFERENCE_STYLE, label="exact" if exact is not None else
                             f"reference: {ref_method}"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)
