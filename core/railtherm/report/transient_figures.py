"""Figures of a transient scene (repeated passes, a schedule of the heat input): each method's finest
successful result against the exact history of ``references.nc`` where the scene has one.

* :func:`histories`: the temperature of the material point on the contact's centre line at the fixed
  section, one row per depth (the surface and the scene's history depths), over the whole history or,
  for many passes, over the first and the last few passes side by side (a 1,000-pass time axis shows
  nothing of one pass);
* :func:`per_pass`: the peak surface temperature of each pass, the residual rise left before the next
  pass, and the time above the scene's threshold per pass (when some pass exceeds it), one row per
  heated body.

The functions only select, thin and draw stored arrays; every exact value is ``references.nc``'s
(``exact_temperature_history``, ``exact_pass_peak_temperature``, ``exact_residual_rise``,
``exact_time_above``). A curve that is absent is not drawn.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import BODIES, REFERENCE_STYLE, Palette, figure, save

__all__ = ["histories", "per_pass", "windows", "history_depths", "thin", "exact_joined", "FEW_PASSES"]

MS = 1e3   # s -> ms
MM = 1e3   # m -> mm
#: more passes than this: the history is drawn over its first and last few passes only
FEW_PASSES = 8
FIRST_PASSES, LAST_PASSES = 3, 2
#: depths a history figure shows besides the surface [m] (the nearest stored depth to each)
HISTORY_DEPTHS = (1e-4, 5e-4, 1e-3)
#: points per drawn line at most (a 1,000-pass history holds 300,000 samples)
MAX_POINTS = 4000
#: an exact history whose median time step exceeds the coarsest method's by more than this is drawn as points
JOIN_RATIO = 20.0
#: the exact value of a scene with one pass (per-pass figure)
ONE_PASS_EXACT = {"color": "0.6", "ls": "none", "marker": "s", "ms": 14.0, "alpha": 0.5}
#: the exact history's samples when they are too coarse to be joined by a line
EXACT_SAMPLES = {"color": "0.55", "ls": "none", "marker": "o", "ms": 3.0, "alpha": 0.8}


def windows(t_end: float, count: int) -> list[tuple[float, float, str]]:
    """Time windows (start [s], end [s], title) of a history of ``count`` passes ending at ``t_end`` [s]
    (the last pass plus one interval): the whole history, or its first and last few passes."""
    if count <= FEW_PASSES:
        return [(0.0, t_end, f"passes 1–{count}" if count > 1 else "the pass")]
    step = t_end / count
    return [(0.0, FIRST_PASSES * step, f"passes 1–{FIRST_PASSES}"),
            ((count - LAST_PASSES) * step, t_end, f"passes {count - LAST_PASSES + 1}–{count}")]


def history_depths(z) -> list[int]:
    """Indices of the depths to draw: the surface (the first) and the stored depths nearest 0.1, 0.5 and
    1 mm (each once; all of them when there are at most four)."""
    z = np.asarray(z, float)
    if z.size <= 4:
        return list(range(z.size))
    picks = [0] + [int(np.argmin(np.abs(z - d))) for d in HISTORY_DEPTHS]
    return list(dict.fromkeys(picks))


def thin(t: np.ndarray, y: np.ndarray, n: int = MAX_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``n`` points of a line that keep each bin's lowest and highest sample (its peaks)."""
    if t.size <= n:
        return t, y
    k = int(np.ceil(2 * t.size / n))
    m = t.size // k * k
    yb = y[:m].reshape(-1, k)
    base = np.arange(0, m, k)
    lo = base + np.nanargmin(np.where(np.isfinite(yb), yb, np.inf), axis=1)
    hi = base + np.nanargmax(np.where(np.isfinite(yb), yb, -np.inf), axis=1)
    idx = np.unique(np.concatenate([lo, hi, np.arange(m, t.size)]))
    return t[idx], y[idx]


def _exact_history(curve, body: int, z: float):
    """(t [s], T [degC]) of the exact history of ``body`` at depth ``z`` [m], or None."""
    if curve is None or "exact_temperature_history" not in curve:
        return None
    da = curve["exact_temperature_history"]
    zz = np.asarray(curve["history_depth"].values, float)
    j = int(np.argmin(np.abs(zz - z)))
    if abs(zz[j] - z) > 1e-3 * max(z, 1e-6):
        return None
    y = np.asarray(da.isel(body=body, history_depth=j).values, float)
    if not np.isfinite(y).any():
        return None
    return np.asarray(curve["history_time"].values, float), y


def _marks(t: np.ndarray, n: int = 8) -> list[int]:
    """Indices of about ``n`` markers evenly spaced in time (a thinned line is densest at its peaks)."""
    if t.size == 0:
        return []
    return sorted(set(np.searchsorted(t, np.linspace(t[0], t[-1], n)).clip(0, t.size - 1).tolist()))


def _step(t: np.ndarray) -> float:
    """The median spacing of a time axis [s] (inf when it has no two samples)."""
    return float(np.median(np.diff(t))) if t.size > 1 else np.inf


def _resolves(t_exact: np.ndarray, step: float) -> bool:
    """True when the exact history's axis is fine enough to join its samples by a line: its median step is
    within :data:`JOIN_RATIO` of the coarsest method's (a uniform axis over many passes, coarser than a
    contact, would cut each pass's peak; its samples are then drawn as points)."""
    return _step(t_exact) <= JOIN_RATIO * step


def exact_joined(finest: dict, curve) -> bool | None:
    """Whether :func:`histories` joins the exact history's samples by a line (None: there is no exact history)."""
    runs = [ds for ds in finest.values() if "temperature_history" in ds]
    if curve is None or "exact_temperature_history" not in curve or not runs:
        return None
    step = max(_step(np.asarray(ds["time"].values, float)) for ds in runs)
    return _resolves(np.asarray(curve["history_time"].values, float), step)


def _window(t, y, lo: float, hi: float):
    keep = (t >= lo) & (t <= hi)
    return thin(t[keep], y[keep])


def histories(finest: dict, curve, body: int, count: int, threshold: float, palette: Palette, title: str, *,
              path: Path):
    """The temperature history [degC] of ``body`` at the surface and the history depths, one row per depth,
    one column per time window (:func:`windows`); methods as lines, the exact history as a grey band."""
    runs = {m: ds for m, ds in finest.items() if "temperature_history" in ds}
    if not runs:
        return None
    first = next(iter(runs.values()))
    z = np.asarray(first["z"].values, float)
    rows = history_depths(z)
    t_end = max(float(np.max(ds["time"].values)) for ds in runs.values())
    wins = windows(t_end, count)
    fig = figure(10, 0.9 + 1.55 * len(rows))
    axes = np.atleast_2d(fig.subplots(len(rows), len(wins), squeeze=False, sharex="col"))
    method_step = max(_step(np.asarray(ds["time"].values, float)) for ds in runs.values())
    handles, reached = {}, False
    for i, j in enumerate(rows):
        exact = _exact_history(curve, body, z[j])
        for c, (lo, hi, what) in enumerate(wins):
            ax = axes[i, c]
            top = -np.inf
            if exact is not None:
                te, ye = _window(*exact, lo, hi)
                joined = _resolves(exact[0], method_step)
                handles.setdefault("exact", ax.plot(te * MS, ye, **(REFERENCE_STYLE if joined else EXACT_SAMPLES),
                                                    label="exact" if joined else "exact (samples, not joined)")[0])
                top = max(top, float(np.nanmax(ye, initial=-np.inf)))
            for m, ds in runs.items():
                t = np.asarray(ds["time"].values, float)
                y = np.asarray(ds["temperature_history"].isel(body=body, z=j).values, float)
                tw, yw = _window(t, y, lo, hi)
                st = dict(palette.style(m), ms=3.0, markevery=_marks(tw), lw=1.2)
                handles.setdefault(m, ax.plot(tw * MS, yw, **st, label=m)[0])
                top = max(top, float(np.nanmax(yw, initial=-np.inf)))
            if np.isfinite(top) and top >= threshold:
                ax.axhline(threshold, color="0.3", ls=":", lw=1.0)
                reached = True
            ax.grid(True, alpha=0.3)
            if i == 0:
                ax.set_title(what, fontsize=9)
            if i == len(rows) - 1:
                ax.set_xlabel("time [ms] (0: the first pass reaches the section)")
            if c == 0:
                ax.set_ylabel("surface [°C]" if z[j] == 0 else f"z = {z[j] * MM:.3g} mm [°C]", fontsize=9)
    fig.legend(handles=list(handles.values()), loc="outside lower center", ncol=min(len(handles), 5), fontsize=8,
               frameon=False)
    fig.suptitle(title + (f" (dotted: {threshold:g} °C)" if reached else ""), fontsize=10)
    return save(fig, path)


def _exact_pass(curve, name: str, body: int):
    """The exact per-pass curve ``name`` of ``body`` (at the surface where it has depths), or None."""
    if curve is None or name not in curve:
        return None
    da = curve[name].isel(body=body)
    if "history_depth" in da.dims:
        da = da.isel(history_depth=int(np.argmin(np.abs(np.asarray(curve["history_depth"].values, float)))))
    y = np.asarray(da.values, float)
    return y if np.isfinite(y).any() else None


def _above_anywhere(finest: dict, curve, bodies) -> bool:
    vals = [np.asarray(ds["time_above"].isel(body=b, z=0).values, float) for ds in finest.values()
            if "time_above" in ds for b in bodies]
    vals += [y for b in bodies for y in [_exact_pass(curve, "exact_time_above", b)] if y is not None]
    return any(np.nanmax(v, initial=0.0) > 0 for v in vals)


def per_pass(finest: dict, curve, bodies: list[int], threshold: float, palette: Palette, title: str, *,
             path: Path):
    """Per pass: the surface peak temperature [degC], the residual rise [K] and (when some pass exceeds the
    threshold) the time above it at the surface [ms]; one row per heated body, exact as a grey band."""
    runs = {m: ds for m, ds in finest.items() if "pass_peak_temperature" in ds}
    if not runs or not bodies:
        return None
    cols = [("pass_peak_temperature", "exact_pass_peak_temperature", "peak surface temperature [°C]", 1.0),
            ("residual_rise", "exact_residual_rise", "residual rise before the next pass [K]", 1.0)]
    if _above_anywhere(runs, curve, bodies):
        cols.append(("time_above", "exact_time_above", f"time above {threshold:g} °C at the surface [ms]", MS))
    fig = figure(10, 0.9 + 2.3 * len(bodies))
    axes = np.atleast_2d(fig.subplots(len(bodies), len(cols), squeeze=False, sharex=True))
    handles = {}
    for i, b in enumerate(bodies):
        for c, (name, exact_name, what, scale) in enumerate(cols):
            ax = axes[i, c]
            ye = _exact_pass(curve, exact_name, b)
            if ye is not None:   # one pass: a wide grey marker (a line of one point is not drawn)
                handles.setdefault("exact", ax.plot(np.arange(1, ye.size + 1), ye * scale,
                                                    **(REFERENCE_STYLE if ye.size > 1 else ONE_PASS_EXACT),
                                                    label="exact")[0])
            for m, ds in runs.items():
                if name not in ds:
                    continue
                da = ds[name].isel(body=b)
                if "z" in da.dims:
                    da = da.isel(z=0)
                y = np.asarray(da.values, float) * scale
                n = np.asarray(ds["pass"].values) if "pass" in ds.coords else np.arange(1, y.size + 1)
                st = dict(palette.style(m), ms=3.5, lw=1.2)
                if y.size > 40:
                    st["markevery"] = max(1, y.size // 20)
                handles.setdefault(m, ax.plot(n, y, **st, label=m)[0])
            ax.grid(True, alpha=0.3)
            if i == 0:
                ax.set_title(what, fontsize=9)
            if i == len(bodies) - 1:
                ax.set_xlabel("pass (the wheel: revolution)" if b == 0 else "pass")
            if c == 0:
                ax.set_ylabel(BODIES[b], fontsize=9)
    single = max(ds.sizes.get("pass", 1) for ds in runs.values()) == 1
    for ax in axes.ravel():   # the axes share x: set once each, after every line is drawn
        if single:            # one pass: one tick, room around it
            ax.set_xlim(0.5, 1.5)
            ax.set_xticks([1])
        else:
            ax.locator_params(axis="x", integer=True)
    fig.legend(handles=list(handles.values()), loc="outside lower center", ncol=min(len(handles), 5), fontsize=8,
               frameon=False)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)
