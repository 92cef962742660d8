"""The study report: ``report.md``, ``report.html`` and ``figures/*.png`` of a study output folder.

:func:`write_report` reads what ``railtherm run`` wrote (``metrics.nc``, ``study.json`` and the run
files ``runs/<scene>/<method>/level-<k>.nc``) and writes one section per scene:

* the reference each run was compared with, and the scene's physical inputs;
* every run: status (ok | inaccurate | refused | failed, with the message), wall time, peak memory,
  heat balance (integrated heat flux against frictional power) and its relative errors;
* a work-precision figure: relative error against the exact reference (x) and wall time (y) on
  log-log axes, one line per method, one marker per level; inaccurate runs hollow; refused and
  failed runs in a panel of their own (they have neither an error nor a time);
* the fitted convergence order of each method (slope of log error against log h, h = 2^-level);
* the cross-method difference matrices of the finest levels;
* surface temperature along y = 0 (and its difference from the analytic reference) and the depth
  profile through the hottest point, each method at its finest successful level, with the analytic
  reference where core has one (:func:`railtherm.analytic.reference_fields`; in depth, Jaeger's band
  or the moving surface source evaluated at z > 0);
* tangential traction and stick/slip of each method (maps for an ellipse, curves for a line
  contact, with Carter's solution where it applies).

Scenes swept over the longitudinal creepage or the sliding speed get creep-force curves, Fx/(mu N)
of each method at its finest level, against Carter's exact 2-D solution for line contacts and the
initial slope of Kalker's linear theory for ellipses. A study of many scenes keeps the report bounded: per-scene
sections for the first :data:`MAX_SCENE_SECTIONS` scenes, then one summary table. A pytest-benchmark
JSON file adds a benchmark table; a footer records package versions, CPU, thread settings and the
command line.

The report never raises for a problem of one figure: the problem is written into the report in its
place (and warned about), and the rest is written.
"""
from __future__ import annotations

import html
import json
import math
import os
import platform
import re
import shlex
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

import numpy as np

__all__ = ["write_report", "MAX_SCENE_SECTIONS"]

#: scenes beyond this number get a line in the summary table instead of a section with figures
MAX_SCENE_SECTIONS = 40
#: error metrics in the order the work-precision figure prefers them (at most WP_PANELS drawn)
METRIC_PRIORITY = ("max_surface_temperature", "surface_temperature_l2", "mean_contact_temperature",
                   "creep_force_x", "pressure_l2", "max_pressure", "semi_axis_a", "frictional_power",
                   "steady_wheel_temperature", "steady_mean_contact_temperature")
WP_PANELS = 2
METRIC_LABEL = {
    "max_surface_temperature": "max. surface temperature",
    "mean_contact_temperature": "mean contact temperature",
    "surface_temperature_l2": "surface temperature rise (L2)",
    "pressure_l2": "contact pressure (L2)",
    "max_pressure": "max. pressure",
    "semi_axis_a": "semi-axis a",
    "creep_force_x": "creep force Fx",
    "frictional_power": "frictional power",
    "steady_wheel_temperature": "steady wheel temperature",
    "steady_mean_contact_temperature": "steady mean contact temperature",
}
QUANTITY_LABEL = {"max_surface_temperature": "max. surface temperature",
                  "mean_contact_temperature": "mean contact temperature",
                  "creep_force_x": "creep force Fx", "max_pressure": "max. pressure"}
LEVEL_MARKERS = ("o", "s", "^", "D", "v", "P", "*", "X", "h", "<", ">", "p", "8")
STATUS_OK = ("ok", "inaccurate")
DPI = 110
PACKAGES = ("railtherm", "numpy", "scipy", "xarray", "netCDF4", "numba", "fipy", "scikit-fem", "matplotlib",
            "pluggy", "dask", "pytest-benchmark")
THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


# ----------------------------------------------------------------------------------------------
# document model: blocks rendered to Markdown and to HTML
# ----------------------------------------------------------------------------------------------
@dataclass
class _Doc:
    blocks: list[tuple] = field(default_factory=list)

    def h(self, level: int, text: str, anchor: str | None = None):
        self.blocks.append(("h", level, text, anchor))

    def p(self, text: str):
        self.blocks.append(("p", text))

    def ul(self, items: Iterable[str]):
        items = list(items)
        if items:
            self.blocks.append(("ul", items))

    def table(self, header: list[str], rows: list[list[Any]]):
        if rows:
            self.blocks.append(("table", header, [[_cell(v) for v in r] for r in rows]))

    def img(self, rel: str, alt: str):
        self.blocks.append(("img", rel, alt))

    # -- Markdown -----------------------------------------------------------------------------
    def markdown(self) -> str:
        out = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                out.append((f'<a id="{b[3]}"></a>\n\n' if b[3] else "") + "#" * b[1] + " " + b[2])
            elif kind == "p":
                out.append(b[1])
            elif kind == "ul":
                out.append("\n".join("- " + t for t in b[1]))
            elif kind == "table":
                header, rows = b[1], b[2]
                esc = lambda s: str(s).replace("|", "\\|").replace("\n", " ")
                lines = ["| " + " | ".join(esc(h) for h in header) + " |",
                         "|" + "|".join("---" for _ in header) + "|"]
                lines += ["| " + " | ".join(esc(c) for c in r) + " |" for r in rows]
                out.append("\n".join(lines))
            elif kind == "img":
                out.append(f"![{b[2]}]({b[1]})")
        return "\n\n".join(out) + "\n"

    # -- HTML ---------------------------------------------------------------------------------
    def html(self, title: str) -> str:
        body = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                anchor = f' id="{html.escape(b[3])}"' if b[3] else ""
                body.append(f"<h{b[1]}{anchor}>{_inline(b[2])}</h{b[1]}>")
            elif kind == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif kind == "ul":
                body.append("<ul>" + "".join(f"<li>{_inline(t)}</li>" for t in b[1]) + "</ul>")
            elif kind == "table":
                head = "".join(f"<th>{_inline(h)}</th>" for h in b[1])
                rows = "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>" for r in b[2])
                body.append(f'<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>')
            elif kind == "img":
                body.append(f'<figure><img src="{html.escape(b[1])}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{html.escape(b[2])}</figcaption></figure>")
        style = ("body{font-family:system-ui,sans-serif;max-width:1150px;margin:2em auto;padding:0 1em;color:#222}"
                 "table{border-collapse:collapse;margin:0.6em 0;font-size:0.86em}"
                 "th,td{border:1px solid #bbb;padding:2px 6px;text-align:left;vertical-align:top}"
                 "th{background:#eee}tr:nth-child(even) td{background:#f8f8f8}"
                 "img{max-width:100%;height:auto}figure{margin:0.8em 0}figcaption{font-size:0.8em;color:#555}"
                 "code{background:#f2f2f2;padding:0 3px}pre{background:#f4f4f4;padding:0.6em;overflow-x:auto}"
                 "h2{border-bottom:1px solid #ccc;margin-top:2em}")
        return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
                f"<style>{style}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n")


def _inline(text: str) -> str:
    """HTML-escape ``text``; `code` spans and [text](#anchor) links are kept."""
    parts = re.split(r"(`[^`]*`)", str(text))
    out = []
    for part in parts:
        if len(part) >= 2 and part.startswith("`") and part.endswith("`"):
            out.append(f"<code>{html.escape(part[1:-1])}</code>")
        else:
            esc = html.escape(part)
            esc = re.sub(r"\[([^\]]+)\]\((#[^)\s]+)\)", r'<a href="\2">\1</a>', esc)
            out.append(esc)
    return "".join(out)


def _cell(v) -> str:
    if v is None:
        return "–"
    if isinstance(v, (float, np.floating)):
        return _num(float(v))
    return str(v)


def _num(v: float, digits: int = 3) -> str:
    if v is None or not np.isfinite(v):
        return "–"
    if v == 0:
        return "0"
    return f"{v:.{digits}g}"


def _short(text: str, n: int = 160) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 1] + "…"


def _slug(text: str) -> str:
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("_.")
    return s[:80] or "scene"


# ----------------------------------------------------------------------------------------------
# inputs
# ----------------------------------------------------------------------------------------------
@dataclass
class _Run:
    scene: str
    method: str
    level: int
    status: str
    message: str
    reference: str
    wall_time: float
    peak_memory: float
    heat_balance: float
    errors: dict[str, float]


def _load_metrics(out: Path):
    import xarray as xr
    path = out / "metrics.nc"
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: write it with `railtherm run STUDY.toml --out {out}` first")
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def _runs_from_metrics(m) -> list[_Run]:
    from .metrics import METRICS
    n = m.sizes.get("run", 0)
    runs = []
    col = lambda k: m[k].values if k in m else np.full(n, np.nan)
    errs = {k: col(f"error_{k}") for k in METRICS}
    scene, method, status = col("scene"), col("method"), col("status")
    message, reference = col("message"), col("reference")
    level, wall, mem, hb = col("level"), col("wall_time"), col("peak_memory"), col("heat_balance")
    for i in range(n):
        runs.append(_Run(str(scene[i]), str(method[i]), int(level[i]), str(status[i]),
                         "" if _isnan(message[i]) else str(message[i]),
                         "" if _isnan(reference[i]) else str(reference[i]),
                         float(wall[i]), float(mem[i]), float(hb[i]),
                         {k: float(v[i]) for k, v in errs.items()}))
    return runs


def _isnan(v) -> bool:
    return isinstance(v, float) and math.isnan(v)


def _load_info(out: Path) -> dict:
    p = out / "study.json"
    if p.exists():
        try:
            return json.loads(p.read_text())
        except Exception as exc:  # noqa: BLE001 - the report goes on without it
            warnings.warn(f"railtherm report: {p} is unreadable ({exc}); footer without the command line",
                          RuntimeWarning, stacklevel=3)
    return {}


def _load_study(info: dict, out: Path | None = None):
    path = info.get("path")
    if path and not Path(path).is_absolute() and not Path(path).exists() and out is not None:
        for base in (out.parent, out):  # a relative path recorded by a run started elsewhere
            if (base / path).exists():
                path = str(base / path)
                break
    if not path or not Path(path).exists():
        return None, f"study file {path!r} not found: scene inputs and analytic overlays are left out" if path else \
            "no study given and no study path in study.json: scene inputs and analytic overlays are left out"
    try:
        from .study import load_study
        return load_study(path), None
    except Exception as exc:  # noqa: BLE001
        return None, f"study file {path!r} could not be loaded ({exc}): scene inputs and analytic overlays are left out"


def _open_run(out: Path, scene: str, method: str, level: int):
    import xarray as xr
    p = out / "runs" / scene / method / f"level-{level}.nc"
    if not p.exists():
        return None
    try:
        with xr.open_dataset(p, engine="netcdf4") as ds:
            return ds.load()
    except Exception as exc:  # noqa: BLE001
        warnings.warn(f"railtherm report: cannot read {p}: {exc}", RuntimeWarning, stacklevel=3)
        return None


def _parse_sweep(name: str) -> tuple[str, dict]:
    """Base name and sweep of a scene name ``base--k=v,k=v`` (used when the study is not at hand)."""
    if "--" not in name:
        return name, {}
    base, rest = name.split("--", 1)
    sweep = {}
    for part in rest.split(","):
        if "=" in part:
            k, v = part.split("=", 1)
            try:
                sweep[k] = float(v)
            except ValueError:
                sweep[k] = v
    return base, sweep


# ----------------------------------------------------------------------------------------------
# figures
# ----------------------------------------------------------------------------------------------
def _figure(w: float, h: float):
    from matplotlib.figure import Figure
    return Figure(figsize=(w, h), layout="constrained")


def _save(fig, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    fig.clear()
    return path


class _Style:
    """One colour per method, the same in every figure of the report."""

    def __init__(self, methods: Iterable[str]):
        import matplotlib
        cmap = matplotlib.colormaps["tab10"]
        self.color = {m: cmap(i % 10) for i, m in enumerate(sorted(set(methods)))}

    def __call__(self, method: str):
        return self.color.get(method, "0.3")

    def lw(self, method: str) -> float:
        """Line width, thinner for later methods: coinciding curves stay visible as nested lines."""
        j = sorted(self.color).index(method) if method in self.color else 0
        return max(3.2 - 0.7 * j, 1.0)

    def ms(self, method: str) -> float:
        j = sorted(self.color).index(method) if method in self.color else 0
        return max(8.0 - 1.5 * j, 3.0)


def _finite_pos(v) -> bool:
    return v is not None and np.isfinite(v) and v > 0


def _fig_work_precision(runs: list[_Run], scene: str, style: _Style, path: Path, tol: float | None) -> Path | None:
    from matplotlib.lines import Line2D

    good = [r for r in runs if r.status in STATUS_OK]
    bad = [r for r in runs if r.status not in STATUS_OK]
    metrics = [k for k in METRIC_PRIORITY
               if any(np.isfinite(r.errors.get(k, np.nan)) and np.isfinite(r.wall_time) for r in good)][:WP_PANELS]
    if not good and not bad:
        return None
    panels = len(metrics) if metrics else (1 if good else 0)
    ncol = panels + (1 if bad else 0)
    widths = [4.2] * panels + ([2.6] if bad else [])
    fig = _figure(sum(widths) + 0.6, 4.4)
    axes = fig.subplots(1, ncol, width_ratios=widths, squeeze=False)[0]
    methods = sorted({r.method for r in runs})
    levels = sorted({r.level for r in runs})
    marker = {k: LEVEL_MARKERS[i % len(LEVEL_MARKERS)] for i, k in enumerate(levels)}
    # later methods get smaller markers: coinciding points show as concentric rings
    ms = {m: max(10.0 - 1.6 * j, 4.0) for j, m in enumerate(methods)}
    zero_drawn = False
    drawn: set = set()  # (method, level) drawn in some panel
    for ax, met in zip(axes[:panels], metrics or [None]):
        if met is None:  # runs, but no error against any reference: wall time against level
            for m in methods:
                sel = sorted((r for r in good if r.method == m and np.isfinite(r.wall_time)), key=lambda r: r.level)
                if sel:
                    ax.plot([r.level for r in sel], [r.wall_time for r in sel], "-", color=style(m), lw=1.3)
                    for r in sel:
                        drawn.add((r.method, r.level))
                        ax.plot(r.level, r.wall_time, marker[r.level], color=style(m), ms=ms[m],
                                mfc="white" if r.status == "inaccurate" else style(m))
            ax.set_yscale("log")
            ax.set_xlabel("level [1]")
            ax.set_ylabel("wall time [s]")
            ax.set_title("no error against a reference:\nwall time by level", fontsize=10)
            ax.set_xticks(levels)
            ax.grid(True, which="both", alpha=0.3)
            lo, hi = ax.get_ylim()
            _log_ticks(ax.yaxis, lo, hi)
            continue
        vals = [r.errors.get(met, np.nan) for r in good]
        pos = [v for v in vals if _finite_pos(v)]
        floor = (min(pos) / 10.0) if pos else 1e-16
        for m in methods:
            sel = sorted((r for r in good if r.method == m and np.isfinite(r.errors.get(met, np.nan))
                          and np.isfinite(r.wall_time)), key=lambda r: r.level)
            if not sel:
                continue
            ex = [max(r.errors[met], floor) for r in sel]
            ax.plot(ex, [r.wall_time for r in sel], "-", color=style(m), lw=1.3, alpha=0.85)
            for r, e in zip(sel, ex):
                drawn.add((r.method, r.level))
                ax.plot(e, r.wall_time, marker[r.level], color=style(m), ms=ms[m], mec=style(m), mew=1.3,
                        mfc="white" if r.status == "inaccurate" else style(m))
                if not r.errors[met] > 0:
                    zero_drawn = True
                    ax.annotate("0", (e, r.wall_time), textcoords="offset points", xytext=(-9, 0), fontsize=7,
                                ha="right", va="center")
        if zero_drawn:
            ax.axvline(floor, color="0.6", lw=0.8, ls=":")
        if tol is not None and np.isfinite(tol):
            ax.axvline(tol, color="firebrick", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"relative error of {METRIC_LABEL.get(met, met)} [1]")
        ax.set_ylabel("wall time [s]")
        ax.set_title(METRIC_LABEL.get(met, met), fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        _pad_log(ax)
    if bad:
        ax = axes[-1]
        for r in bad:
            j = methods.index(r.method)
            if r.status == "failed":
                ax.plot(j, r.level, "X", color="crimson", ms=10)
            else:
                ax.plot(j, r.level, "s", mfc="none", mec="0.35", ms=10, mew=1.5)
        ax.set_xticks(range(len(methods)))
        ax.set_xticklabels(methods, rotation=30, ha="right", fontsize=8)
        ax.set_xlim(-0.6, len(methods) - 0.4)
        ax.set_yticks(levels)
        ax.set_ylim(min(levels) - 0.5, max(levels) + 0.5)
        ax.set_ylabel("level [1]")
        ax.set_xlabel("method")
        ax.set_title("runs without a result", fontsize=10)
        ax.grid(True, alpha=0.3)
    handles = [Line2D([], [], color=style(m), lw=2, label=m) for m in methods if any(d[0] == m for d in drawn)]
    handles += [Line2D([], [], ls="", marker=marker[k], color="0.25", label=f"level {k}") for k in levels
                if any(d[1] == k for d in drawn)]
    if any(r.status == "inaccurate" for r in good):
        handles.append(Line2D([], [], ls="", marker="o", mfc="white", mec="0.25", label="inaccurate (> tolerance)"))
    if metrics and tol is not None and np.isfinite(tol):
        handles.append(Line2D([], [], color="firebrick", lw=0.8, ls="--", label=f"tolerance {tol:g}"))
    if zero_drawn:
        handles.append(Line2D([], [], color="0.6", lw=0.8, ls=":", label="error 0, drawn at the dotted line"))
    if any(r.status == "failed" for r in bad):
        handles.append(Line2D([], [], ls="", marker="X", color="crimson", label="failed"))
    if any(r.status == "refused" for r in bad):
        handles.append(Line2D([], [], ls="", marker="s", mfc="none", mec="0.35", mew=1.5, label="refused"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 6), fontsize=8, frameon=False)
    fig.suptitle(f"{scene}: " + ("error against run time" if metrics else "run time (no error against a reference)"),
                 fontsize=11)
    return _save(fig, path)


def _log_ticks(axis, lo: float, hi: float):
    """Readable ticks on a log axis: plain '%g' labels (no mathtext: faster), 1-2-5 steps when the
    axis spans less than about two decades, powers of ten otherwise."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    decades = math.log10(hi / lo) if lo > 0 and hi > 0 else 99
    subs = (1.0, 2.0, 5.0) if decades < 2.2 else (1.0,)
    axis.set_major_locator(LogLocator(base=10.0, subs=subs))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _pad_log(ax):
    """Widen log axes that span less than a decade (so that labelled ticks appear) and set readable ticks."""
    for axis, get, set_ in ((ax.xaxis, ax.get_xlim, ax.set_xlim), (ax.yaxis, ax.get_ylim, ax.set_ylim)):
        lo, hi = get()
        if lo > 0 and hi > 0 and hi / lo < 12:
            mid = math.sqrt(lo * hi)
            lo, hi = mid / 3.5, mid * 3.5
            set_(lo, hi)
        _log_ticks(axis, lo, hi)


def _fig_cross(cross: dict[str, np.ndarray], methods: list[str], scene: str, path: Path) -> Path | None:
    import matplotlib
    from matplotlib.colors import LogNorm
    def off(mat):
        o = np.array(mat, float)
        np.fill_diagonal(o, np.nan)
        return o
    qs = [q for q, mat in cross.items() if np.nanmax(np.abs(off(mat)), initial=0.0) > 0]
    if not qs:
        return None
    cross = {q: off(cross[q]) for q in qs}
    n = len(methods)
    size = 1.2 + 0.55 * n
    fig = _figure(min(size * len(qs) + 1.0, 15), size + 0.9)
    axes = fig.subplots(1, len(qs), squeeze=False)[0]
    allv = np.concatenate([cross[q][np.isfinite(cross[q]) & (cross[q] > 0)] for q in qs])
    lo = max(float(allv.min()) / 1.2 if allv.size else 1e-6, 1e-12)
    hi = max(float(allv.max()) * 1.2 if allv.size else 1.0, lo * 4)
    norm = LogNorm(vmin=lo, vmax=hi)
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.9")
    im = None
    for ax, q in zip(axes, qs):
        mat = np.where(cross[q] > 0, cross[q], np.nan)
        im = ax.imshow(np.ma.masked_invalid(mat), norm=norm, cmap=cmap)
        for i in range(n):
            for j in range(n):
                v = cross[q][i, j]
                txt = "" if i == j else "–" if not np.isfinite(v) else ("0" if v == 0 else f"{v:.2g}")
                shade = norm(v) if np.isfinite(v) and v > 0 else 1.0
                ax.text(j, i, txt, ha="center", va="center", fontsize=7 if n > 4 else 8,
                        color="white" if shade < 0.5 else "black")
        ax.set_xticks(range(n))
        ax.set_xticklabels(methods, rotation=35, ha="right", fontsize=8)
        ax.set_yticks(range(n))
        ax.set_yticklabels(methods, fontsize=8)
        ax.set_xlabel("compared with")
        ax.set_ylabel("method")
        ax.set_title(QUANTITY_LABEL.get(q, q), fontsize=10)
    cb = fig.colorbar(im, ax=list(axes), label="relative difference [1]", shrink=0.85)
    _log_ticks(cb.ax.yaxis, lo, hi)
    fig.suptitle(f"{scene}: difference between methods at their finest levels", fontsize=11)
    return _save(fig, path)


def _line_y0(da):
    """A (body, x) array along y = 0 (nearest y) of a (body, x[, y]) DataArray."""
    if "y" in da.dims:
        da = da.sel(y=0.0, method="nearest")
    return da


def _reference_surface(scene, x, line: bool):
    """Analytic surface temperature (2, nx) along y = 0 [degC] at ``x``, or None."""
    import xarray as xr
    from .analytic import reference_fields
    if line:
        ds = xr.Dataset({"surface_temperature": (("body", "x"), np.zeros((2, x.size)))}, coords={"x": x})
    else:
        ds = xr.Dataset({"surface_temperature": (("body", "x", "y"), np.zeros((2, x.size, 1)))},
                        coords={"x": x, "y": np.array([0.0])})
    f = reference_fields(scene, ds).get("surface_temperature")
    if f is None:
        return None
    return np.asarray(f).reshape(2, x.size)


def _reference_depth(scene, body: int, x0: float, z):
    """Analytic temperature [degC] at (x0, y = 0, z) of ``body``, or None where core has no reference."""
    from .analytic import _thermal_case
    case = _thermal_case(scene)
    if case is None:
        return None
    a, b, shape, q, speeds, eps = case
    share = eps if body == 0 else 1.0 - eps
    mat = scene.body(body)
    z = np.asarray(z, float)
    xs = np.full_like(z, x0)
    if share == 0 or q == 0:
        return np.full_like(z, mat.bulk_temperature)
    if b is None:
        from .references.jaeger import jaeger_band_temperature
        rise = jaeger_band_temperature(xs, z, a, speeds[body], mat, share * q, shape)
    else:
        from .references.moving_source import moving_source_temperature
        rise = moving_source_temperature(xs, np.zeros_like(z), z, (a, b), speeds[body], mat, share * q, shape)
    return mat.bulk_temperature + np.asarray(rise, float)


def _half_width(finest: dict):
    for ds in finest.values():
        if "semi_axis_a" in ds:
            return float(ds["semi_axis_a"])
    return None


def _fig_surface(finest: dict, scene_obj, scene: str, style: _Style, path: Path, notes: list) -> tuple[Path | None, dict]:
    """Surface temperature along y = 0 of both bodies; returns the path and the x of the hottest point per body."""
    have = {m: ds for m, ds in finest.items() if "surface_temperature" in ds}
    if not have:
        return None, {}
    line = all("y" not in ds.dims for ds in have.values())
    xmin = min(float(ds["x"].min()) for ds in have.values())
    xmax = max(float(ds["x"].max()) for ds in have.values())
    ref = None
    # Chebyshev-spaced (dense at the patch edges, where the field has square-root behaviour)
    xr_ = 0.5 * (xmin + xmax) - 0.5 * (xmax - xmin) * np.cos(np.linspace(0.0, np.pi, 161 if line else 81))
    if scene_obj is not None:
        try:
            ref = _reference_surface(scene_obj, xr_, line)
        except Exception as exc:  # noqa: BLE001
            notes.append(f"analytic surface temperature not drawn: {type(exc).__name__}: {_short(exc, 200)}")
    if ref is not None:  # a second row: difference from the reference (PCHIP: no overshoot at the edges)
        from scipy.interpolate import PchipInterpolator
        ref_at = [PchipInterpolator(xr_, ref[i]) for i in (0, 1)]
        fig = _figure(10, 6.2)
        grid = fig.subplots(2, 2, sharex=True, height_ratios=[2.2, 1])
        axes, daxes = grid[0], grid[1]
    else:
        fig = _figure(10, 4.2)
        axes, daxes = fig.subplots(1, 2), (None, None)
    hot = {}
    a = _half_width(finest)
    for body, (ax, dax) in enumerate(zip(axes, daxes)):
        if ref is not None:
            ax.plot(xr_ * 1e3, ref[body], "-", color="0.75", lw=6.5, label="analytic reference")
            hot[body] = float(xr_[np.argmax(ref[body])])
        for m, ds in have.items():
            da = _line_y0(ds["surface_temperature"]).isel(body=body)
            lv = int(ds.attrs.get("level", -1))
            x = da["x"].values
            mk = "." if da.size <= 40 else None
            ax.plot(x * 1e3, da.values, "-", color=style(m), lw=style.lw(m), label=f"{m} (level {lv})", marker=mk)
            if dax is not None:
                inside = (x >= xr_[0]) & (x <= xr_[-1])
                dax.plot(x[inside] * 1e3, da.values[inside] - ref_at[body](x[inside]), "-",
                         color=style(m), lw=1.4, marker=mk)
        if ref is None:
            da = _line_y0(next(iter(have.values()))["surface_temperature"]).isel(body=body)
            hot[body] = float(da["x"].values[int(np.argmax(da.values))])
        for a_ in (ax, dax):
            if a_ is None:
                continue
            if a:
                for s_ in (-a, a):
                    a_.axvline(s_ * 1e3, color="0.6", lw=0.8, ls=":")
            a_.grid(True, alpha=0.3)
        ax.set_ylabel("surface temperature [°C]")
        ax.set_title(["wheel", "rail"][body] + ("" if line else " (y = 0)"), fontsize=10)
        last = ax
        if dax is not None:
            dax.axhline(0.0, color="0.4", lw=0.8)
            dax.set_ylabel("T − T$_{ref}$ [K]")
            last = dax
        last.set_xlabel("x [mm] (leading edge at +a)")
    handles, labels = axes[0].get_legend_handles_labels()
    if a:
        from matplotlib.lines import Line2D
        handles.append(Line2D([], [], color="0.6", lw=0.8, ls=":"))
        labels.append("patch edges x = ±a")
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 4), fontsize=8, frameon=False)
    fig.suptitle(f"{scene}: surface temperature" + (" and its difference from the reference" if ref is not None
                                                      else ""), fontsize=11)
    return _save(fig, path), hot


def _heated_depth(z, t, bulk) -> float:
    """Depth [m] below which the temperature rise of profile ``t`` stays under 1 % of its maximum."""
    rise = np.abs(np.asarray(t, float) - bulk)
    if rise.size == 0 or not np.isfinite(rise).any() or np.nanmax(rise) == 0:
        return float(np.max(z)) if np.size(z) else 0.0
    above = np.nonzero(rise > 0.01 * np.nanmax(rise))[0]
    return float(z[min(above[-1] + 1, z.size - 1)])


def _fig_depth(finest: dict, scene_obj, scene: str, hot: dict, style: _Style, path: Path, notes: list) -> Path | None:
    """Temperature against depth through the hottest surface point; the depth axis ends a little below
    the heated layer (1 % of the surface rise), whatever depth each method's mesh reaches."""
    have = {m: ds for m, ds in finest.items() if "temperature" in ds and "z" in ds.dims}
    if not have:
        return None
    fig = _figure(10, 4.4)
    axes = fig.subplots(1, 2)
    zmax = max(float(ds["z"].max()) for ds in have.values())
    for body, ax in enumerate(axes):
        x0 = hot.get(body)
        if x0 is None:
            ds0 = next(iter(have.values()))
            t0 = ds0["temperature"].isel(body=body, z=0)
            x0 = float(t0["x"].values[int(np.argmax(t0.values))])
        profiles = {}
        zlim = 0.0
        for m, ds in have.items():
            da = ds["temperature"].isel(body=body).sel(x=x0, method="nearest")
            z, t = da["z"].values, da.values
            bulk = scene_obj.body(body).bulk_temperature if scene_obj is not None else float(t[np.argmax(z)])
            profiles[m] = (z, t)
            zlim = max(zlim, _heated_depth(z, t, bulk))
        zlim = min(1.3 * zlim, zmax) if zlim > 0 else zmax
        if scene_obj is not None:
            try:
                z = np.linspace(0.0, zlim, 41)
                ref = _reference_depth(scene_obj, body, x0, z)
                if ref is not None:
                    ax.plot(ref, z * 1e6, "-", color="0.75", lw=6.5, label="analytic reference")
            except Exception as exc:  # noqa: BLE001
                if body == 0:
                    notes.append(f"analytic depth profile not drawn: {type(exc).__name__}: {_short(exc, 200)}")
        for m, (z, t) in profiles.items():
            n_vis = int(np.sum(z <= zlim))
            ax.plot(t, z * 1e6, "-", color=style(m), lw=style.lw(m), label=f"{m} (level {int(have[m].attrs.get('level', -1))})",
                    marker="." if n_vis <= 30 else None, ms=4)
        ax.set_ylim(zlim * 1e6, 0.0)
        ax.set_xlabel("temperature [°C]")
        ax.set_ylabel("depth z [µm]")
        ax.set_title(f"{['wheel', 'rail'][body]}: x = {x0 * 1e3:.3g} mm, y = 0", fontsize=10)
        ax.grid(True, alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 4), fontsize=8, frameon=False)
    fig.suptitle(f"{scene}: depth profile through the hottest surface point (heated layer)", fontsize=11)
    return _save(fig, path)


def _carter_for(scene_obj):
    """Carter's solution for a line-contact scene with pure longitudinal creepage, or None."""
    if scene_obj is None or scene_obj.contact_shape != "line" or scene_obj.creepage is None:
        return None
    c = scene_obj.creepage
    if c.lateral != 0 or c.spin != 0 or not scene_obj.friction or scene_obj.friction <= 0:
        return None
    w, r = scene_obj.wheel, scene_obj.rail  # Carter: quasi-identical elastic bodies
    if w.rigid or r.rigid or w.shear_modulus != r.shear_modulus or w.poisson_ratio != r.poisson_ratio:
        return None
    from .models.hertz import hertz_geometry
    from .references.carter import carter_2d
    a_, _, p0, n = hertz_geometry(scene_obj)
    return carter_2d(c.longitudinal, a_, scene_obj.friction, scene_obj.wheel_radius, max_pressure=p0), a_, p0, n


def _kalker_slope(sc):
    """d(Fx / mu N)/d(xi) of Kalker's linear theory for an elliptic Hertz contact with pure
    longitudinal creepage [1], or None (line contact, rigid body, no creepage).

    Combined elastic constants of two bodies (Kalker 1990): 1/G = (1/G1 + 1/G2)/2,
    nu = G (nu1/G1 + nu2/G2)/2.
    """
    if sc is None or sc.contact_shape != "ellipse" or sc.creepage is None or not sc.friction:
        return None
    c = sc.creepage
    w, r = sc.wheel, sc.rail
    if w.rigid or r.rigid or c.lateral != 0 or c.spin != 0:
        return None
    from .models.hertz import hertz_geometry
    from .references.kalker import kalker_linear_forces
    a, b, _, n = hertz_geometry(sc)
    g = 2.0 / (1.0 / w.shear_modulus + 1.0 / r.shear_modulus)
    nu = 0.5 * g * (w.poisson_ratio / w.shear_modulus + r.poisson_ratio / r.shear_modulus)
    fx, _, _ = kalker_linear_forces(a, b, g, nu, 1.0, 0.0, 0.0)
    return fx / (sc.friction * n)


def _fig_traction(finest: dict, scene_obj, scene: str, style: _Style, path: Path, notes: list) -> Path | None:
    have = {m: ds for m, ds in finest.items() if "traction_x" in ds or "stick" in ds}
    if not have:
        return None
    line = all("y" not in ds.dims for ds in have.values())
    if line:
        return _traction_line(have, scene_obj, scene, style, path, notes)
    return _traction_maps({m: ds for m, ds in have.items() if "y" in ds.dims}, scene, path, notes)


def _traction_line(have: dict, scene_obj, scene: str, style: _Style, path: Path, notes: list) -> Path:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    mu = getattr(scene_obj, "friction", None) if scene_obj is not None else None
    try:
        car = _carter_for(scene_obj)
    except Exception as exc:  # noqa: BLE001
        car = None
        notes.append(f"Carter's traction not drawn: {type(exc).__name__}: {_short(exc, 200)}")
    rows = [(m, ds) for m, ds in have.items() if "stick" in ds]
    fig = _figure(10.5, 4.6)
    if rows:
        ax, ax2 = fig.subplots(1, 2, width_ratios=[3, 2])
    else:
        ax, ax2 = fig.subplots(), None
    handles = []
    ref_x = None
    if car is not None:
        c, a, p0, _ = car
        ref_x = np.linspace(-a, a, 401)
        handles += ax.plot(ref_x * 1e3, c.traction(ref_x) / 1e6, "-", color="0.75", lw=6.5, label="Carter (exact)")
    for m, ds in have.items():
        if "traction_x" in ds:
            handles += ax.plot(ds["x"].values * 1e3, ds["traction_x"].values / 1e6, "-", color=style(m), lw=style.lw(m),
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
    if ax2 is not None:  # stick/slip as bands, one row per method (+ Carter)
        labels = []
        for i, (m, ds) in enumerate(rows):
            x = ds["x"].values * 1e3
            st = ds["stick"].values
            dx = float(np.median(np.diff(x))) if x.size > 1 else 1.0
            for val, col in ((1.0, "tab:blue"), (0.0, "tab:orange")):
                sel = np.isfinite(st) & (np.abs(st - val) < 0.5)
                ax2.broken_barh([(xi - dx / 2, dx) for xi in x[sel]], (i - 0.35, 0.7), facecolors=col,
                                edgecolor="none")
            labels.append(f"{m} (level {int(ds.attrs.get('level', -1))})")
        if car is not None:
            c = car[0]
            stick = c.stick(ref_x)
            dx = (ref_x[1] - ref_x[0]) * 1e3
            for sel, col in ((stick, "tab:blue"), (~stick, "tab:orange")):
                ax2.broken_barh([(xi * 1e3 - dx / 2, dx) for xi in ref_x[sel]], (len(labels) - 0.35, 0.7),
                                facecolors=col, edgecolor="none")
            labels.append("Carter (exact)")
        ax2.set_yticks(range(len(labels)))
        ax2.set_yticklabels(labels, fontsize=8)
        ax2.set_ylim(len(labels) - 0.5, -0.5)
        ax2.set_xlim(ax.get_xlim())
        ax2.set_xlabel("x [mm] (leading edge at +a)")
        ax2.set_title("stick / slip", fontsize=10)
        handles += [Patch(color="tab:blue", label="stick"), Patch(color="tab:orange", label="slip")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8, frameon=False)
    fig.suptitle(f"{scene}: traction and stick/slip", fontsize=11)
    return _save(fig, path)


def _traction_maps(have: dict, scene: str, path: Path, notes: list) -> Path | None:
    """Ellipse: traction q_x and stick/slip maps of each method (finest level)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    items = list(have.items())[:6]
    if not items:
        return None
    if len(have) > len(items):
        notes.append(f"traction maps of the first {len(items)} of {len(have)} methods")
    n = len(items)
    ds0 = items[0][1]
    span = lambda v: float(v.max() - v.min()) or 1.0
    asp = span(ds0["y"].values) / span(ds0["x"].values)
    columns = asp > 1.2 or n <= 3  # methods side by side (traction row, stick/slip row)
    if columns:
        w = min(4.2 * n, 13.0) / n
        h = min(w * asp, 5.0)
        fig = _figure(w * n + 1.8, 2 * (h + 0.75) + 0.7)
        grid = fig.subplots(2, n, squeeze=False, sharex=True, sharey=True)
        pairs = [(grid[0][i], grid[1][i]) for i in range(n)]
    else:  # many methods on a long patch: a row per method
        w = 4.0
        h = max(w * asp, 1.4)
        fig = _figure(2 * w + 2.4, n * (h + 0.75) + 0.7)
        grid = fig.subplots(n, 2, squeeze=False, sharex=True, sharey=True)
        pairs = [(grid[i][0], grid[i][1]) for i in range(n)]
    tmax = max((float(np.nanmax(np.abs(ds["traction_x"].values))) for _, ds in items if "traction_x" in ds),
               default=0.0) / 1e6 or 1.0
    cmap_st = ListedColormap(["tab:orange", "tab:blue"])
    pc = pc2 = None
    for (m, ds), (ax, ax2) in zip(items, pairs):
        x, y = ds["x"].values * 1e3, ds["y"].values * 1e3
        lv = int(ds.attrs.get("level", -1))
        if "traction_x" in ds:
            t = ds["traction_x"].values / 1e6
            inside = ds["pressure"].values > 0 if "pressure" in ds else np.ones(t.shape, bool)
            pc = ax.pcolormesh(x, y, np.ma.masked_where(~inside, t).T, cmap="RdBu_r", vmin=-tmax, vmax=tmax,
                               shading="nearest", rasterized=True)
        else:
            ax.text(0.5, 0.5, "no traction", transform=ax.transAxes, ha="center")
        ax.set_title(f"{m} (level {lv}):\ntraction $q_x$", fontsize=9)
        if "stick" in ds:
            st = ds["stick"].values
            pc2 = ax2.pcolormesh(x, y, np.ma.masked_invalid(st).T, cmap=cmap_st,
                                 norm=BoundaryNorm([-0.5, 0.5, 1.5], 2), shading="nearest", rasterized=True)
            n_st = int(np.sum(st > 0.5))
            n_sl = int(np.sum((st < 0.5) & np.isfinite(st)))
            ax2.set_title(f"{m}: stick / slip\n({n_st} stick, {n_sl} slip cells)", fontsize=9)
        else:
            ax2.text(0.5, 0.5, "no stick/slip field", transform=ax2.transAxes, ha="center")
        for a_ in (ax, ax2):
            a_.set_aspect("equal")
            a_.set_xlabel("x [mm]")
            a_.set_ylabel("y [mm]")
            a_.label_outer()
    t_axes = [p[0] for p in pairs]
    s_axes = [p[1] for p in pairs]
    if pc is not None:
        fig.colorbar(pc, ax=t_axes, label="$q_x$ on the wheel [MPa]", shrink=0.9 if columns else 0.5)
    if pc2 is not None:
        cb = fig.colorbar(pc2, ax=s_axes, ticks=[0, 1], shrink=0.9 if columns else 0.3)
        cb.ax.set_yticklabels(["slip", "stick"])
    fig.suptitle(f"{scene}: traction and stick/slip (x rolling direction, leading edge at +a)", fontsize=11)
    return _save(fig, path)


def _fig_creep(group: list, style: _Style, key: str, title: str, path: Path, notes: list) -> tuple[Path | None, list]:
    """Creep-force curve of a group [(value, scene_name, scene_obj, {method: ds})]; also returns table rows."""
    methods = sorted({m for _, _, _, f in group for m, ds in f.items() if "creep_force_x" in ds})
    if not methods:
        return None, []
    fig = _figure(8, 4.8)
    ax = fig.subplots()
    rows = []
    for m in methods:
        pts = []
        for val, _, sc, f in group:
            ds = f.get(m)
            if ds is None or "creep_force_x" not in ds:
                continue
            n = float(ds["normal_force"]) if "normal_force" in ds else getattr(sc, "normal_force", None)
            mu = getattr(sc, "friction", None)
            if not n or not mu:
                continue
            pts.append((val, float(ds["creep_force_x"]) / (mu * n)))
        pts.sort()
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "-o", color=style(m), ms=style.ms(m), lw=style.lw(m),
                    zorder=3,
                    label=f"{m} (finest level)")
    # Carter, line contacts with longitudinal creepage only
    if key == "creepage.longitudinal":
        sc0 = group[0][2]
        try:
            car0 = _carter_for(sc0)
        except Exception as exc:  # noqa: BLE001
            car0 = None
            notes.append(f"Carter's curve not drawn: {type(exc).__name__}: {_short(exc, 200)}")
        vals = [g[0] for g in group]
        lo, hi = min(vals), max(vals)
        if car0 is not None:
            from .references.carter import carter_2d
            _, a, _, _ = car0
            xs = np.unique(np.concatenate([np.linspace(lo, hi, 301), [0.0] if lo < 0 < hi else []]))
            ys = [carter_2d(v, a, sc0.friction, sc0.wheel_radius).force_ratio for v in xs]
            ax.plot(xs, ys, "-", color="0.75", lw=6.5, zorder=1, label="Carter (exact, 2-D)")
        else:
            try:
                slope = _kalker_slope(sc0)
            except Exception as exc:  # noqa: BLE001
                slope = None
                notes.append(f"Kalker's linear theory not drawn: {type(exc).__name__}: {_short(exc, 200)}")
            if slope:
                lim = 1.0 / abs(slope)  # the linear law reaches |Fx| = mu N here
                xs = np.linspace(max(lo, -lim), min(hi, lim), 3)
                ax.plot(xs, slope * xs, "--", color="black", lw=1.2, zorder=2,
                        label="Kalker linear theory (small creepage, no saturation)")
    for val, name, sc, f in group:
        row = [_num(val, 4)]
        for m in methods:
            ds = f.get(m)
            n = float(ds["normal_force"]) if ds is not None and "normal_force" in ds else getattr(sc, "normal_force", None)
            mu = getattr(sc, "friction", None)
            row.append(_num(float(ds["creep_force_x"]) / (mu * n)) if ds is not None and "creep_force_x" in ds
                       and n and mu else "–")
        rows.append(row)
    ax.axhline(0, color="0.5", lw=0.6)
    for s in (-1, 1):
        ax.axhline(s, color="0.45", lw=0.8, ls=":", label="full sliding |Fx| = μ N" if s == 1 else None)
    sc0 = group[0][2]
    if sc0 is not None:
        try:
            unit = "N/m" if sc0.contact_shape == "line" else "N"
            title += (f"\n{sc0.contact_shape} contact, N = {sc0.normal_force:.3g} {unit}, μ = {sc0.friction:.3g}, "
                      f"V = {sc0.speed:.3g} m/s")
        except (TypeError, AttributeError):
            pass
    ax.set_xlabel("longitudinal creepage ξ [1]" if key == "creepage.longitudinal" else "sliding speed $v_s$ [m/s]")
    ax.set_ylabel("creep force $F_x$ / (μ N) [1]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return _save(fig, path), [["value"] + methods] + rows


# ----------------------------------------------------------------------------------------------
# sections
# ----------------------------------------------------------------------------------------------
def _describe_scene(sc) -> str:
    if sc is None:
        return ""
    parts = []
    try:
        if sc.heat_source is not None:
            hs = sc.heat_source
            size = (f"semi-axes {hs.semi_axes[0] * 1e3:.3g} × {hs.semi_axes[1] * 1e3:.3g} mm" if hs.semi_axes is not None
                    else f"half-width {hs.half_width * 1e3:.3g} mm")
            parts.append(f"given heat source {hs.shape}, flux {hs.flux:.3g} W/m², {size}")
        else:
            geo = sc.contact_shape
            if sc.semi_axes is not None:
                geo += f", semi-axes {sc.semi_axes[0] * 1e3:.4g} × {sc.semi_axes[1] * 1e3:.4g} mm"
            elif sc.curvatures is not None:
                geo += f", curvatures {sc.curvatures[0]:.4g}, {sc.curvatures[1]:.4g} 1/m"
            elif sc.contact_shape == "line":
                geo += f", wheel radius {sc.wheel_radius:.3g} m"
            parts.append(geo)
            if sc.normal_force is not None:
                parts.append(f"normal force {sc.normal_force:.4g} {'N/m' if sc.contact_shape == 'line' else 'N'}")
            elif sc.penetration is not None:
                parts.append(f"penetration {sc.penetration:.3g} m")
            if sc.creepage is not None:
                c = sc.creepage
                parts.append(f"creepage ξ = {c.longitudinal:.4g}, η = {c.lateral:.4g}, φ = {c.spin:.4g} 1/m")
            elif sc.sliding_speed is not None:
                parts.append(f"sliding speed {sc.sliding_speed:.4g} m/s")
            if sc.friction is not None:
                parts.append(f"μ = {sc.friction:.3g}")
        parts.append(f"speed {sc.speed:.4g} m/s")
        hp = sc.heat_partition
        parts.append(f"heat partition {hp if isinstance(hp, str) else format(hp, '.3g')}")
        if sc.convection:
            parts.append(f"convection {sc.convection:.3g} W/(m² K)")
        if sc.wheel.rigid:
            parts.append("rigid wheel")
        if sc.mode != "steady":
            parts.append(f"mode {sc.mode}")
    except Exception:  # noqa: BLE001 - a description is optional
        pass
    return "; ".join(parts)


def _run_table(doc: _Doc, runs: list[_Run]):
    mets = [k for k in METRIC_PRIORITY if any(np.isfinite(r.errors.get(k, np.nan)) for r in runs)]
    header = (["method", "level", "status", "wall time [s]", "peak memory [MB]", "heat balance [1]"]
              + [f"err {k}" for k in mets] + ["message"])
    rows = []
    ordered = sorted(runs, key=lambda r: (r.method, r.level))
    i = 0
    while i < len(ordered):
        r = ordered[i]
        j = i
        if r.status in ("refused", "failed"):  # one row for consecutive levels refused for the same reason
            while (j + 1 < len(ordered) and ordered[j + 1].method == r.method and ordered[j + 1].status == r.status
                   and ordered[j + 1].message == r.message):
                j += 1
        level = str(r.level) if j == i else f"{r.level}–{ordered[j].level}"
        rows.append([r.method, level, r.status, r.wall_time, r.peak_memory / 1e6 if np.isfinite(r.peak_memory)
                     else np.nan, r.heat_balance] + [r.errors.get(k, np.nan) for k in mets] + [_short(r.message, 220)])
        i = j + 1
    doc.table(header, rows)


def _order_table(doc: _Doc, m, scene: str, levels: list[int]):
    if "convergence_order" not in m or scene not in list(m["scene_name"].values):
        return
    co = m["convergence_order"].sel(scene_name=scene)
    mets = [str(k) for k in co["metric"].values]
    mets = [k for k in METRIC_PRIORITY if k in mets and np.isfinite(co.sel(metric=k).values).any()]
    if not mets:
        doc.p("Convergence order: not available (fewer than two levels with a finite, non-zero error).")
        return
    rows = [[str(meth)] + [float(co.sel(method_name=meth, metric=k)) for k in mets]
            for meth in co["method_name"].values if np.isfinite(co.sel(method_name=meth).values).any()]
    doc.p("Fitted convergence order (slope of log error against log h, h = 2^-level; levels "
          f"{', '.join(map(str, levels))}):")
    doc.table(["method"] + mets, rows)


def _cross_tables(m, scene: str) -> tuple[dict, list[str]]:
    if "cross_difference" not in m or scene not in list(m["scene_name"].values):
        return {}, []
    cd = m["cross_difference"].sel(scene_name=scene)
    methods = [str(x) for x in cd["method_name"].values]
    out = {}
    for q in cd["quantity"].values:
        mat = np.asarray(cd.sel(quantity=q).values, float)
        off = mat.copy()
        np.fill_diagonal(off, np.nan)
        if np.isfinite(off).any():
            out[str(q)] = mat
    if out:  # keep only methods with at least one finite entry
        keep = [i for i in range(len(methods)) if any(np.isfinite(mat[i]).any() for mat in out.values())]
        methods = [methods[i] for i in keep]
        out = {q: mat[np.ix_(keep, keep)] for q, mat in out.items()}
    return out, methods


def _published_table(doc: _Doc, published: dict, finest: dict):
    """Published values beside each method's finest result, with the formulas the results name."""
    pub = {k: v for k, v in published.items() if k != "source"}
    methods = sorted(finest)
    rows = []
    for var, value in pub.items():
        row = [f"`{var}`", value]
        for meth in methods:
            ds = finest[meth]
            if var in ds:
                vals = np.atleast_1d(np.asarray(ds[var].values, float))
                row.append(" / ".join(_num(v, 4) for v in vals) + (" (wheel / rail)" if vals.size == 2 else ""))
            else:
                row.append("")
        rows.append(row)
    doc.p("Published values beside ours (finest successful level of each method). Source: "
          + str(published.get("source", "not given")) + ".")
    doc.table(["quantity", "published"] + methods, rows)
    formulas = sorted({f"{meth}: {k} = {v}" for meth, ds in finest.items() for k, v in ds.attrs.items()
                       if k.endswith("_formula")})
    if formulas:
        doc.p("Formulas used: " + "; ".join(formulas) + ".")


def _scene_section(doc: _Doc, idx: int, scene: str, sc, runs: list[_Run], m, out: Path, fig_dir: Path,
                   style: _Style, tol, figures: list[Path], published: dict | None = None):
    anchor = f"scene-{idx}"
    doc.h(2, f"{idx}. Scene `{scene}`", anchor)
    desc = _describe_scene(sc)
    if desc:
        doc.p(desc + ".")
    if sc is not None and getattr(sc, "sweep", None):
        doc.p("Swept: " + ", ".join(f"`{k}` = {v}" for k, v in sc.sweep.items()) + ".")
    refs = []
    for r in runs:
        for part in (r.reference or "").split("; "):
            if part and part not in refs:
                refs.append(part)
    if refs:
        doc.p("Reference: " + "; ".join(refs) + ".")
    else:
        doc.p("Reference: none (no run of this scene was compared with a reference).")
    _run_table(doc, runs)
    base = f"{idx:03d}-{_slug(scene)}"
    notes: list[str] = []

    def draw(kind: str, fn, *args):
        t0 = time.perf_counter()
        try:
            res = fn(*args)
        except Exception as exc:  # noqa: BLE001 - one figure never stops the report
            msg = f"figure '{kind}' could not be drawn: {type(exc).__name__}: {_short(exc, 300)}"
            warnings.warn(f"railtherm report, scene {scene!r}: {msg}", RuntimeWarning, stacklevel=2)
            doc.p(msg)
            return None
        p = res[0] if isinstance(res, tuple) else res
        if p is not None:
            figures.append(p)
            doc.img(f"figures/{p.name}", f"{scene}: {kind}")
        if time.perf_counter() - t0 > 20:
            notes.append(f"figure '{kind}' took {time.perf_counter() - t0:.0f} s")
        return res

    draw("error against run time", _fig_work_precision, runs, scene, style, fig_dir / f"{base}-work-precision.png", tol)
    _order_table(doc, m, scene, sorted({r.level for r in runs}))
    cross, cmethods = _cross_tables(m, scene)
    if cross:
        doc.p("Cross-method relative differences |q_method − q_other| / |q_other| at the finest successful levels:")
        same = []
        for q, mat in cross.items():
            o = np.array(mat, float)
            np.fill_diagonal(o, np.nan)
            if np.nanmax(np.abs(o)) == 0:
                same.append(q)
                continue
            doc.table([f"{q}: method \\ compared with"] + cmethods,
                      [[cmethods[i]] + ["" if i == j else float(v) for j, v in enumerate(mat[i])]
                       for i in range(len(cmethods))])
        if same:
            doc.p("Identical in every method that computed it (difference 0, e.g. the same core model): "
                  + ", ".join(f"`{q}`" for q in same) + ".")
        draw("difference between methods", _fig_cross, cross, cmethods, scene, fig_dir / f"{base}-cross.png")
    else:
        doc.p("Cross-method differences: fewer than two methods with results.")
    # finest successful run of each method
    finest = {}
    for meth in sorted({r.method for r in runs}):
        ok = sorted((r for r in runs if r.method == meth and r.status in STATUS_OK), key=lambda r: -r.level)
        for r in ok:
            ds = _open_run(out, scene, meth, r.level)
            if ds is not None:
                finest[meth] = ds
                break
    if published:
        _published_table(doc, published, finest)
    if finest:
        res = draw("surface temperature", _fig_surface, finest, sc, scene, style, fig_dir / f"{base}-surface.png", notes)
        hot = res[1] if isinstance(res, tuple) else {}
        draw("depth profile", _fig_depth, finest, sc, scene, hot, style, fig_dir / f"{base}-depth.png", notes)
        draw("traction and stick/slip", _fig_traction, finest, sc, scene, style, fig_dir / f"{base}-traction.png",
             notes)
    for n in notes:
        doc.p("Note: " + n + ".")
    return finest


def _creep_groups(scene_names: list[str], scenes: dict) -> dict:
    """(base, key, other sweep items) -> [(value, scene name)] for creepage / sliding-speed sweeps."""
    groups: dict = {}
    for name in scene_names:
        sc = scenes.get(name)
        sweep = dict(getattr(sc, "sweep", {}) or {}) if sc is not None else _parse_sweep(name)[1]
        base = _parse_sweep(name)[0]
        for key in ("creepage.longitudinal", "sliding_speed"):
            if key in sweep:
                try:
                    val = float(sweep[key])
                except (TypeError, ValueError):
                    continue
                others = tuple(sorted((k, str(v)) for k, v in sweep.items() if k != key))
                groups.setdefault((base, key, others), []).append((val, name))
                break
    return {k: sorted(v) for k, v in groups.items() if len(v) >= 2}


def _benchmark_section(doc: _Doc, path: Path):
    try:
        data = json.loads(Path(path).read_text())
    except Exception as exc:  # noqa: BLE001
        doc.h(2, "Benchmarks", "benchmarks")
        doc.p(f"Benchmark file `{path}` could not be read: {exc}.")
        return
    doc.h(2, "Benchmarks", "benchmarks")
    mi = data.get("machine_info", {})
    cpu = mi.get("cpu", {}) if isinstance(mi.get("cpu"), dict) else {}
    when = data.get("datetime", "")
    doc.p(f"From `{path}`" + (f", {when}" if when else "") + (f", CPU {cpu.get('brand_raw')}" if cpu.get("brand_raw") else "")
          + ". Times are pytest-benchmark statistics over the rounds; `extra_info` holds the error of the timed run.")
    rows = []
    for b in data.get("benchmarks", []):
        st = b.get("stats", {})
        extra = b.get("extra_info", {}) or {}
        info = ", ".join(f"{k}={_num(v, 4) if isinstance(v, (int, float)) and not isinstance(v, bool) else v}"
                         for k, v in extra.items())
        rows.append([b.get("name", b.get("fullname", "?")), st.get("mean", np.nan), st.get("min", np.nan),
                     st.get("stddev", np.nan), st.get("rounds", "–"), _short(info, 240)])
    if rows:
        doc.table(["benchmark", "mean [s]", "min [s]", "stddev [s]", "rounds", "extra_info (error of the timed run)"],
                  rows)
    else:
        doc.p("The file holds no benchmarks.")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _footer(doc: _Doc, info: dict, provenance: list[str]):
    import importlib.metadata as md
    doc.h(2, "Environment", "environment")
    versions = []
    for pkg in PACKAGES:
        try:
            versions.append(f"{pkg} {md.version(pkg)}")
        except md.PackageNotFoundError:
            versions.append(f"{pkg} (not installed)")
    items = [f"Python {platform.python_version()} on {platform.platform()}",
             "Packages: " + ", ".join(versions),
             f"CPU: {_cpu_model()}; os.cpu_count() = {os.cpu_count()}"
             + (f"; usable by this process: {len(os.sched_getaffinity(0))}" if hasattr(os, "sched_getaffinity") else ""),
             ]
    env = info.get("environment") if isinstance(info.get("environment"), dict) else None
    if env:
        items.append("Threads during the run: " + ", ".join(f"{k}={env.get(k) or 'unset'}" for k in THREAD_ENV))
    else:
        items.append("Threads (of the process writing this report; the run did not record its own): "
                     + ", ".join(f"{k}={os.environ.get(k, 'unset')}" for k in THREAD_ENV))
    timing = info.get("timing") if isinstance(info.get("timing"), dict) else {}
    if timing:
        parts = [f"executor {timing.get('executor', '?')}"]
        if timing.get("workers"):
            parts.append(f"{timing['workers']} workers")
        for k in ("setup", "runs", "metrics"):
            if isinstance(timing.get(k), (int, float)):
                parts.append(f"{k} {timing[k]:.3g} s")
        items.append("Study run: " + ", ".join(parts))
    argv = info.get("argv")
    if argv:
        items.append("Command line of the run: `" + " ".join(shlex.quote(str(a)) for a in argv) + "`")
    if provenance:
        items.append("Result sources: " + " | ".join(provenance))
    items.append(f"Report written {time.strftime('%Y-%m-%d %H:%M:%S %Z')} by railtherm.report.write_report")
    doc.ul(items)


# ----------------------------------------------------------------------------------------------
def write_report(out, study=None, benchmarks=None) -> list[Path]:
    """Write ``report.md``, ``report.html`` and ``figures/*.png`` for a study output folder.

    Parameters
    ----------
    out : path
        Output folder of ``railtherm run`` (holds ``metrics.nc``, ``study.json`` and ``runs/``).
    study : railtherm.study.Study, optional
        The study that was run; when None it is re-loaded from the path recorded in
        ``study.json`` (if that file still exists). It supplies the scene inputs, the sweeps and
        the analytic overlays; without it the report is written from the output folder alone.
    benchmarks : path, optional
        A pytest-benchmark JSON file (``--benchmark-json``); ``out/benchmarks.json`` is used when
        it exists and none is given.

    Returns
    -------
    list of pathlib.Path
        ``report.md``, ``report.html`` and every figure written.

    Raises
    ------
    FileNotFoundError
        When ``out/metrics.nc`` does not exist.
    """
    out = Path(out)
    t_start = time.perf_counter()
    m = _load_metrics(out)
    info = _load_info(out)
    study_note = None
    if study is None:
        study, study_note = _load_study(info, out)
    runs = _runs_from_metrics(m)
    fig_dir = out / "figures"
    fig_dir.mkdir(parents=True, exist_ok=True)
    for old in fig_dir.glob("*.png"):  # figures of an earlier report of this folder
        old.unlink()
    scenes = {s.name: s for s in study.scenes} if study is not None else {}
    names = [s.name for s in study.scenes] if study is not None else []
    for nm in (list(map(str, m["scene_name"].values)) if "scene_name" in m.coords else []) + [r.scene for r in runs]:
        if nm not in names:
            names.append(nm)
    by_scene: dict[str, list[_Run]] = {}
    for r in runs:
        by_scene.setdefault(r.scene, []).append(r)
    names = [n for n in names if n in by_scene]
    methods = sorted({r.method for r in runs})
    levels = sorted({r.level for r in runs})
    style = _Style(methods)
    tol = float(m.attrs["tolerance"]) if "tolerance" in m.attrs else getattr(study, "tolerance", None)
    study_name = info.get("study") or m.attrs.get("study") or getattr(study, "name", out.name)

    doc = _Doc()
    doc.h(1, f"railtherm report: study `{study_name}`")
    counts = {s: sum(r.status == s for r in runs) for s in ("ok", "inaccurate", "refused", "failed")}
    doc.p(f"{len(runs)} runs of {len(names)} scenes × {len(methods)} methods ({', '.join(methods) or 'none'}) × "
          f"levels {', '.join(map(str, levels)) or 'none'}: " + ", ".join(f"{v} {k}" for k, v in counts.items()) + ". "
          f"Study file: `{info.get('path') or getattr(study, 'path', None) or 'unknown'}`; "
          f"reference: {getattr(study, 'reference', 'unknown')}; tolerance on relative errors: "
          f"{_num(tol) if tol is not None else 'unknown'}. Output folder: `{out}`.")
    if getattr(study, "description", ""):
        doc.p(study.description)
    if study_note:
        doc.p("Note: " + study_note + ".")
    doc.p("Status: ok = ran and within the tolerance of its reference; inaccurate = ran, error above the "
          "tolerance; refused = outside the method's validity (message says why); failed = error, time-out or "
          "NaN. Errors are relative to the reference named in each section; heat balance = (integrated heat "
          "flux − frictional power) / frictional power.")
    # overview by method
    rows = []
    for meth in methods:
        mr = [r for r in runs if r.method == meth]
        wt = [r.wall_time for r in mr if np.isfinite(r.wall_time)]
        rows.append([meth] + [sum(r.status == s for r in mr) for s in ("ok", "inaccurate", "refused", "failed")]
                    + [float(np.sum(wt)) if wt else np.nan])
    doc.h(2, "Overview", "overview")
    doc.table(["method", "ok", "inaccurate", "refused", "failed", "total wall time [s]"], rows)
    shown = names[:MAX_SCENE_SECTIONS]
    doc.ul([f"[{i + 1}. {n}](#scene-{i + 1})" for i, n in enumerate(shown)])
    if len(names) > len(shown):
        doc.p(f"{len(names) - len(shown)} further scenes are listed in the [summary table](#summary) only.")

    figures: list[Path] = []
    finest_all: dict[str, dict] = {}
    provenance: list[str] = []
    for i, name in enumerate(shown, start=1):
        fin = _scene_section(doc, i, name, scenes.get(name), by_scene[name], m, out, fig_dir, style, tol, figures,
                             published=(getattr(study, "published", None) or {}).get(name))
        for ds in fin.values():
            src = str(ds.attrs.get("source", ""))
            if src and src not in provenance:
                provenance.append(src)
        finest_all[name] = {k: _scalars_only(v) for k, v in fin.items()}

    # creep-force curves over sweeps
    groups = _creep_groups(names, scenes)
    if groups:
        doc.h(2, "Creep-force curves", "creep-force")
        doc.p("Creep force on the wheel over the swept creepage or sliding speed, each method at its finest "
              "successful level, normalised by μ N; Carter's exact 2-D solution for line contacts.")
        for gi, ((base, key, others), members) in enumerate(groups.items(), start=1):
            group = []
            for val, nm in members:
                f = finest_all.get(nm)
                if f is None:
                    f = {}
                    for meth in methods:
                        ok = sorted((r for r in by_scene[nm] if r.method == meth and r.status in STATUS_OK),
                                    key=lambda r: -r.level)
                        if ok:
                            ds = _open_run(out, nm, meth, ok[0].level)
                            if ds is not None:
                                f[meth] = _scalars_only(ds)
                group.append((val, nm, scenes.get(nm), f))
            title = f"{base}" + (f" ({', '.join(f'{k}={v}' for k, v in others)})" if others else "")
            doc.h(3, f"`{title}`: creep force against {key}")
            notes: list[str] = []
            try:
                p, table = _fig_creep(group, style, key, title, fig_dir / f"creep-{gi:02d}-{_slug(title)}.png", notes)
            except Exception as exc:  # noqa: BLE001
                p, table = None, []
                doc.p(f"figure 'creep force' could not be drawn: {type(exc).__name__}: {_short(exc, 300)}")
            if p is not None:
                figures.append(p)
                doc.img(f"figures/{p.name}", f"{title}: creep force")
                if len(table) - 1 <= 30:
                    doc.table([f"{key}"] + table[0][1:], table[1:])
            elif not table:
                doc.p("No method computed a creep force for these scenes.")
            for n in notes:
                doc.p("Note: " + n + ".")

    # summary of the scenes without a section
    if len(names) > len(shown):
        doc.h(2, "Summary of further scenes", "summary")
        doc.p("Each method at its finest successful level (errors relative to the scene's reference).")
        rows = []
        for name in names[len(shown):]:
            for meth in methods:
                rr = [r for r in by_scene[name] if r.method == meth]
                if not rr:
                    continue
                ok = sorted((r for r in rr if r.status in STATUS_OK), key=lambda r: -r.level)
                st = ", ".join(f"{sum(r.status == s for r in rr)} {s}" for s in ("ok", "inaccurate", "refused", "failed")
                               if any(r.status == s for r in rr))
                if ok:
                    r = ok[0]
                    errs = [(k, r.errors.get(k, np.nan)) for k in METRIC_PRIORITY if np.isfinite(r.errors.get(k, np.nan))]
                    err = ", ".join(f"{k} {_num(v)}" for k, v in errs[:2]) or "–"
                    rows.append([name, meth, r.level, st, err, r.wall_time, r.heat_balance])
                else:
                    msg = next((r.message for r in rr if r.message), "")
                    rows.append([name, meth, "–", st, _short(msg, 120) or "–", np.nan, np.nan])
        doc.table(["scene", "method", "finest level", "runs", "errors at the finest level", "wall time [s]",
                   "heat balance [1]"], rows)

    bench = Path(benchmarks) if benchmarks else (out / "benchmarks.json")
    if benchmarks or bench.exists():
        _benchmark_section(doc, bench)
    _footer(doc, info, provenance)
    doc.p(f"Report generated in {time.perf_counter() - t_start:.1f} s.")

    md_path, html_path = out / "report.md", out / "report.html"
    from .runner import write_atomic_bytes
    write_atomic_bytes(md_path, doc.markdown().encode())
    write_atomic_bytes(html_path, doc.html(f"railtherm report: {study_name}").encode())
    return [md_path, html_path] + figures


def _scalars_only(ds):
    """A light copy of a result holding its scalar variables (kept for the creep-force curves)."""
    return ds[[k for k, v in ds.data_vars.items() if v.ndim == 0]].copy()
