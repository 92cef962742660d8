"""The report's figures (matplotlib, PNG at twice the CSS size for HiDPI screens).

Every method has one colour and marker in every figure: green is green, fipy blue,
fastsim-fdm orange, fem purple; other methods take colours of a neutral palette in sorted order.
Markers have one size for every method. Exact references are a wide light-grey band under the
methods' lines; stick/slip is drawn in grey and black, never in a method's colour.
"""
from __future__ import annotations

import contextlib
import math
import multiprocessing as mp
import pickle
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["METHOD_COLOURS", "Palette", "method_colour", "save", "CSS_DPI"]

METHOD_COLOURS = {"green": "#2ca02c", "fipy": "#1f77b4", "fastsim-fdm": "#ff7f0e", "fem": "#9467bd"}
NEUTRAL_COLOURS = ("#8c564b", "#17becf", "#7f7f7f", "#bcbd22", "#e377c2", "#393b79", "#637939", "#843c39")
METHOD_MARKERS = {"green": "o", "fipy": "s", "fastsim-fdm": "^", "fem": "D"}
OTHER_MARKERS = ("v", "P", "X", "h", "<", ">", "p", "*")
MARKER_SIZE = 5.5
LINE_WIDTH = 1.6
STICK_COLOUR, SLIP_COLOUR = "0.15", "0.78"
REFERENCE_STYLE = {"color": "0.6", "lw": 6.0, "alpha": 0.5, "solid_capstyle": "butt"}
#: CSS pixels per inch of figure; the PNG is written at twice this resolution
CSS_DPI = 96
PNG_DPI = 2 * CSS_DPI
#: zlib level of the PNGs: 3 encodes a report figure in 0.10 s instead of 0.18 s (the default 6) for
#: files about 10 % larger
PNG_OPTIONS = {"dpi": PNG_DPI, "pil_kwargs": {"compress_level": 3}}
BODIES = ("wheel", "rail")


class Palette:
    """Colour, marker and line style of each method (fixed for the four built-in methods)."""

    def __init__(self, methods=()):
        others = sorted(m for m in set(methods) if m not in METHOD_COLOURS)
        self._colour = dict(METHOD_COLOURS)
        self._marker = dict(METHOD_MARKERS)
        for i, m in enumerate(others):
            self._colour[m] = NEUTRAL_COLOURS[i % len(NEUTRAL_COLOURS)]
            self._marker[m] = OTHER_MARKERS[i % len(OTHER_MARKERS)]

    def colour(self, method: str) -> str:
        return self._colour.get(method, "#555555")

    def marker(self, method: str) -> str:
        return self._marker.get(method, "o")

    def line(self, method: str) -> str:
        """Solid for every method (dotted lines mean self-convergence in the work-precision figure)."""
        return "-"

    def style(self, method: str, filled: bool = True) -> dict:
        c = self.colour(method)
        return {"color": c, "marker": self.marker(method), "ms": MARKER_SIZE, "lw": LINE_WIDTH,
                "ls": self.line(method), "mec": c, "mfc": c if filled else "white", "mew": 1.2}


def method_colour(method: str, methods=()) -> str:
    """The colour of ``method`` in every figure of the report (hex)."""
    return Palette(methods).colour(method)


def figure(w: float, h: float):
    from matplotlib.figure import Figure   # matplotlib only where a figure is drawn (the report imports fast)
    fig = Figure(figsize=(w, h), layout="constrained")
    return fig


#: the pool that renders figures while the report goes on (:func:`rendering`), or None: render here
_RENDER = None
#: pixel size (width, height) of every PNG written by :func:`save`, known before the file is (the canvas is
#: the figure size times the resolution, as matplotlib's Agg canvas sizes it)
SIZES: dict = {}


def _render(blob: bytes, path: str) -> str:
    """Render a pickled figure to ``path`` (in a worker process of :func:`rendering`)."""
    pickle.loads(blob).savefig(path, **PNG_OPTIONS)
    return path


@contextlib.contextmanager
def rendering(workers: int, context=None):
    """Within the block, :func:`save` hands each figure (pickled) to ``workers`` processes, which lay it
    out and write the PNG while the report goes on; leaving the block waits for every file. Drawing is
    most of a report's time (constrained layout draws each figure twice). ``context``: the multiprocessing
    context of the pool (the caller's fork server, whose workers start with matplotlib imported), else spawn.
    With ``workers`` < 2, a figure that cannot be pickled, or a pool whose worker died, the figure is written
    here."""
    global _RENDER
    if workers < 2:
        yield
        return
    pool, jobs = ProcessPoolExecutor(workers, mp_context=context or mp.get_context("spawn")), []
    _RENDER = (pool, jobs)
    try:
        yield
        for job, blob, path in jobs:
            try:
                job.result()
            except BrokenProcessPool:  # a render worker died: the figure is drawn here instead
                _render(blob, path)
    finally:
        _RENDER = None
        pool.shutdown(wait=True, cancel_futures=True)


def save(fig, path: Path) -> tuple[Path, int]:
    """Write ``fig`` as PNG at 2x (here, or by the pool of :func:`rendering`) and return (path, CSS width [px])."""
    path.parent.mkdir(parents=True, exist_ok=True)
    width = int(round(fig.get_figwidth() * CSS_DPI))
    SIZES[Path(path)] = (int(fig.get_figwidth() * PNG_DPI), int(fig.get_figheight() * PNG_DPI))
    blob = None
    if _RENDER is not None:
        try:
            blob = pickle.dumps(fig)
        except Exception:  # noqa: BLE001 - an unpicklable artist: written here
            blob = None
    job = None
    if blob is not None:
        try:
            job = _RENDER[0].submit(_render, blob, str(path))
        except (RuntimeError, OSError):  # the pool broke: written here. BrokenProcessPool is a RuntimeError;
            job = None                   # a submit that respawns a killed worker before the pool knows it is
                                         # broken fails on its closed queue with OSError ("handle is closed")
    if job is None:
        fig.savefig(path, **PNG_OPTIONS)
    else:
        _RENDER[1].append((job, blob, str(path)))
    # the caller drops ``fig``: no Figure.clear(), which re-initialises every axes before removing it (as
    # long as drawing them)
    return path, width


def _plain_number(v, _pos) -> str:
    return f"{v:g}"


def log_ticks(axis, lo: float, hi: float, compact: bool = False):
    """Readable ticks on a log axis: plain '%g' labels; 1-2-5 steps below about two decades.

    ``compact`` (small multiples about two inches wide): 1-2-5 steps only below 1.2 decades, so that
    labels such as 0.002, 0.005, 0.01 do not run together, and no minor ticks (each tick is an artist
    that the constrained layout measures: they were half of such a figure's drawing time)."""
    # matplotlib only where a figure is drawn (the report imports fast)
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter, NullLocator
    decades = math.log10(hi / lo) if lo > 0 and hi > 0 else 99
    subs = (1.0, 2.0, 5.0) if decades < (1.2 if compact else 2.2) else (1.0,)
    axis.set_major_locator(LogLocator(base=10.0, subs=subs))
    axis.set_major_formatter(FuncFormatter(_plain_number))
    axis.set_minor_formatter(NullFormatter())
    if compact:
        axis.set_minor_locator(NullLocator())


def pad_log(ax, compact: bool = False):
    """Widen log axes that span less than a decade (so that labelled ticks appear); ``compact`` as in
    :func:`log_ticks`."""
    for axis, get, set_ in ((ax.xaxis, ax.get_xlim, ax.set_xlim), (ax.yaxis, ax.get_ylim, ax.set_ylim)):
        lo, hi = get()
        if lo > 0 and hi > 0 and hi / lo < 12:
            mid = math.sqrt(lo * hi)
            lo, hi = mid / 3.5, mid * 3.5
            set_(lo, hi)
        log_ticks(axis, lo, hi, compact)


# ------------------------------------------------------------------------------------------------------
@dataclass
class Point:
    error: float
    time: float
    level: int
    status: str
    self_referenced: bool = False


@dataclass
class Panel:
    title: str
    series: dict = field(default_factory=dict)  # method -> [Point]
    note: str = ""


def work_precision(panels: list[Panel], palette: Palette, tol: float | None, *, path: Path, methods: list[str]):
    """Small multiples: headline error (x) against wall time (y), log-log, one panel per scene."""
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    n = len(panels)
    ncol = min(5, n)          # five across keeps a 20-scene study at four rows on one screen width
    nrow = math.ceil(n / ncol)
    fig = figure(10.0, 1.9 * nrow + 0.8)
    axes = np.atleast_1d(fig.subplots(nrow, ncol, squeeze=False)).ravel()
    used_self = used_hollow = used_zero = False
    drawn = set()
    for ax, panel in zip(axes, panels):
        pos = [p.error for pts in panel.series.values() for p in pts if math.isfinite(p.error) and p.error > 0]
        floor = min(pos) / 10.0 if pos else 1e-6
        any_pt = False
        for meth in methods:
            pts = [p for p in panel.series.get(meth, []) if math.isfinite(p.error) and math.isfinite(p.time)]
            for self_ref in (False, True):
                sel = sorted((p for p in pts if p.self_referenced == self_ref), key=lambda p: p.level)
                if not sel:
                    continue
                st = palette.style(meth)
                if self_ref:
                    st.update(ls=":", lw=1.1)
                    used_self = True
                ex = [max(p.error, floor) for p in sel]
                ax.plot(ex, [p.time for p in sel], **{**st, "marker": None})
                for p, e in zip(sel, ex):
                    hollow = p.status != "ok"
                    used_hollow |= hollow and not self_ref
                    if p.error <= 0:
                        used_zero = True
                    ax.plot([e], [p.time], ls="", **{k: v for k, v in palette.style(meth, not hollow).items()
                                                   if k not in ("ls", "lw")})
                any_pt = True
                drawn.add(meth)
        if tol is not None and math.isfinite(tol) and any_pt:
            ax.axvline(tol, color="firebrick", lw=0.9, ls="--")
        ax.set_title(panel.title, fontsize=8)
        if any_pt:
            ax.set_xscale("log")
            ax.set_yscale("log")
            pad_log(ax, compact=True)
            ax.grid(True, which="major", alpha=0.3)
        else:
            ax.set_xticks([])
            ax.set_yticks([])
            ax.text(0.5, 0.5, panel.note or "no error against a reference", ha="center", va="center",
                    fontsize=8, color="0.4", wrap=True, transform=ax.transAxes)
        ax.tick_params(labelsize=7.5)
    for ax in axes[n:]:
        ax.set_visible(False)
    for i, ax in enumerate(axes[:n]):
        if i + ncol >= n:              # nothing below it: the bottom of its column
            ax.set_xlabel("headline error [1]", fontsize=8)
        if ax.get_subplotspec().is_first_col():
            ax.set_ylabel("wall time [s]", fontsize=8)
    handles = [Line2D([], [], **{**palette.style(m), "ls": palette.line(m)}, label=m) for m in methods if m in drawn]
    handles.append(Line2D([], [], ls="", marker="o", mfc="white", mec="0.3", ms=MARKER_SIZE,
                          label="hollow: inaccurate / unverified"))
    if used_self:
        handles.append(Line2D([], [], color="0.3", ls=":", lw=1.1, label="dotted: self-convergence (no reference)"))
    if tol is not None and math.isfinite(tol):
        handles.append(Line2D([], [], color="firebrick", lw=0.9, ls="--", label=f"tolerance {tol:g}"))
    if used_zero:
        handles.append(Line2D([], [], ls="", label="error 0: drawn at a tenth of the smallest"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    return save(fig, path)


# ------------------------------------------------------------------------------------------------------
# ------------------------------------------------------------------------------------------------------
def traction(finest: dict, curve, friction: float | None, palette: Palette, title: str, path: Path):
    have = {m: ds for m, ds in finest.items() if "traction_x" in ds or "stick" in ds}
    if not have:
        return None
    if all("y" not in ds.dims for ds in have.values()):
        return _traction_line(have, curve, friction, palette, title, path)
    return _traction_maps({m: ds for m, ds in have.items() if "y" in ds.dims}, title, path)


def _bands(ax, x, stick, row: int):
    dx = float(np.median(np.diff(x))) if x.size > 1 else 1.0
    for val, col in ((1.0, STICK_COLOUR), (0.0, SLIP_COLOUR)):
        sel = np.isfinite(stick) & (np.abs(stick - val) < 0.5)
        ax.broken_barh([(xi - dx / 2, dx) for xi in x[sel]], (row - 0.35, 0.7), facecolors=col, edgecolor="none")


def _traction_line(have: dict, curve, mu, palette: Palette, title: str, path: Path):
    # matplotlib only where a figure is drawn (the report imports fast)
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    car = curve if curve is not None and "carter_traction_x" in curve else None
    rows = [(m, ds) for m, ds in have.items() if "stick" in ds]
    fig = figure(10, 4.0)
    ax, ax2 = fig.subplots(1, 2, width_ratios=[3, 2]) if rows else (fig.subplots(), None)
    handles = []
    if car is not None:
        xp = car["x_patch"].values
        handles += ax.plot(xp * 1e3, car["carter_traction_x"].values / 1e6, "-", **REFERENCE_STYLE,
                           label="Carter (exact)")
    for m, ds in have.items():
        if "traction_x" in ds:
            st = palette.style(m)
            if ds.sizes["x"] > 40:
                st["marker"] = None
            handles += ax.plot(ds["x"].values * 1e3, ds["traction_x"].values / 1e6, **st,
                               label=f"{m} (level {int(ds.attrs.get('level', -1))})")
    ds0 = next(iter(have.values()))
    if mu and "pressure" in ds0:
        bound = mu * ds0["pressure"].values / 1e6
        handles += ax.plot(ds0["x"].values * 1e3, bound, ":", color="0.35", lw=1, label="±μ p (traction bound)")
        ax.plot(ds0["x"].values * 1e3, -bound, ":", color="0.35", lw=1)
    ax.set_xlabel("x [mm] (leading edge at +a)")
    ax.set_ylabel("traction on the wheel $q_x$ [MPa]")
    ax.set_title("tangential traction", fontsize=10)
    ax.grid(True, alpha=0.3)
    if ax2 is not None:
        labels = []
        for i, (m, ds) in enumerate(rows):
            _bands(ax2, ds["x"].values * 1e3, ds["stick"].values, i)
            labels.append(f"{m} (level {int(ds.attrs.get('level', -1))})")
        if car is not None and "carter_stick" in car:
            _bands(ax2, car["x_patch"].values * 1e3, car["carter_stick"].values.astype(float), len(labels))
            labels.append("Carter (exact)")
        ax2.set_yticks(range(len(labels)))
        ax2.set_yticklabels(labels, fontsize=8)
        ax2.set_ylim(len(labels) - 0.5, -0.5)
        ax2.set_xlim(ax.get_xlim())
        ax2.set_xlabel("x [mm] (leading edge at +a)")
        ax2.set_title("stick / slip", fontsize=10)
        handles += [Patch(color=STICK_COLOUR, label="stick"), Patch(color=SLIP_COLOUR, label="slip")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


def _traction_maps(have: dict, title: str, path: Path):
    """Ellipse: traction q_x and stick/slip maps of each method (finest level)."""
    # matplotlib only where a figure is drawn (the report imports fast)
    from matplotlib.colors import BoundaryNorm, ListedColormap
    items = list(have.items())[:4]
    if not items:
        return None
    n = len(items)
    ds0 = items[0][1]
    span = lambda v: float(v.max() - v.min()) or 1.0
    asp = span(ds0["y"].values) / span(ds0["x"].values)
    w = 9.0 / n
    h = min(w * asp, 3.6)
    fig = figure(10, 2 * (h + 0.7) + 0.5)
    grid = fig.subplots(2, n, squeeze=False, sharex=True, sharey=True)
    tmax = max((float(np.nanmax(np.abs(ds["traction_x"].values))) for _, ds in items if "traction_x" in ds),
               default=0.0) / 1e6 or 1.0
    cmap_st = ListedColormap([SLIP_COLOUR, STICK_COLOUR])
    pc = pc2 = None
    for i, (m, ds) in enumerate(items):
        ax, ax2 = grid[0][i], grid[1][i]
        x, y = ds["x"].values * 1e3, ds["y"].values * 1e3
        lv = int(ds.attrs.get("level", -1))
        if "traction_x" in ds:
            t = ds["traction_x"].values / 1e6
            inside = ds["pressure"].values > 0 if "pressure" in ds else np.ones(t.shape, bool)
            pc = ax.pcolormesh(x, y, np.ma.masked_where(~inside, t).T, cmap="RdBu_r", vmin=-tmax, vmax=tmax,
                               shading="nearest", rasterized=True)
        ax.set_title(f"{m} (level {lv}): $q_x$", fontsize=9)
        if "stick" in ds:
            st = ds["stick"].values
            pc2 = ax2.pcolormesh(x, y, np.ma.masked_invalid(st).T, cmap=cmap_st,
                                 norm=BoundaryNorm([-0.5, 0.5, 1.5], 2), shading="nearest", rasterized=True)
            ax2.set_title(f"{m}: stick / slip", fontsize=9)
        for a_ in (ax, ax2):
            a_.set_aspect("equal")
            a_.set_xlabel("x [mm]")
            a_.set_ylabel("y [mm]")
            a_.label_outer()
    if pc is not None:
        fig.colorbar(pc, ax=list(grid[0]), label="$q_x$ on the wheel [MPa]", shrink=0.9)
    if pc2 is not None:
        cb = fig.colorbar(pc2, ax=list(grid[1]), ticks=[0, 1], shrink=0.9)
        cb.ax.set_yticklabels(["slip", "stick"])
    fig.suptitle(title, fontsize=10)
    return save(fig, path)


# ------------------------------------------------------------------------------------------------------
@dataclass
class SweepSeries:
    """Per method: swept value -> (headline value, headline error, status)."""

    key: str
    quantity_label: str
    values: dict = field(default_factory=dict)  # method -> [(x, value, error, status)]
    reference: tuple | None = None  # (xs, ys, label, linear?)


def sweep(series: SweepSeries, palette: Palette, tol: float | None, title: str, *, path: Path, methods: list[str]):
    """A sweep: the headline quantity (left) and its error (right) against the swept value."""
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    fig = figure(10, 3.9)
    ax, ax2 = fig.subplots(1, 2)
    handles = []
    if series.reference is not None:
        xs, ys, label, linear = series.reference
        if linear:
            handles += ax.plot(xs, ys, "--", color="black", lw=1.1, label=label)
        else:
            handles += ax.plot(xs, ys, "-", **REFERENCE_STYLE, label=label)
    any_err = False
    for m in methods:
        pts = sorted(series.values.get(m, []))
        if not pts:
            continue
        st = palette.style(m)
        handles += ax.plot([p[0] for p in pts], [p[1] for p in pts], **st, label=m)
        e = [(p[0], p[2], p[3]) for p in pts if math.isfinite(p[2]) and p[2] > 0]
        if e:
            any_err = True
            ax2.plot([p[0] for p in e], [p[1] for p in e], **{**st, "marker": None})
            for x, err, status in e:
                ax2.plot([x], [err], ls="", **{k: v for k, v in palette.style(m, status == "ok").items()
                                             if k not in ("ls", "lw")})
    if series.key in ("creepage.longitudinal", "longitudinal creepage"):
        for s in (-1, 1):
            ax.axhline(s, color="0.45", lw=0.8, ls=":")
        ax.axhline(0, color="0.5", lw=0.6)
    ax.set_xlabel(series.key)
    ax.set_ylabel(series.quantity_label)
    ax.grid(True, alpha=0.3)
    ax.set_title("value (finest successful level)", fontsize=9)
    if any_err:
        ax2.set_yscale("log")
        if tol is not None and math.isfinite(tol):
            ax2.axhline(tol, color="firebrick", lw=0.9, ls="--")
            handles.append(Line2D([], [], color="firebrick", lw=0.9, ls="--", label=f"tolerance {tol:g}"))
        lo, hi = ax2.get_ylim()
        log_ticks(ax2.yaxis, lo, hi)
    else:
        ax2.text(0.5, 0.5, "no error against a reference", ha="center", va="center", transform=ax2.transAxes,
                 color="0.4")
    ax2.set_xlabel(series.key)
    ax2.set_ylabel("relative error [1]")
    ax2.set_title("error against the reference (hollow: > tolerance)", fontsize=9)
    ax2.grid(True, alpha=0.3)
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    return save(fig, path)
