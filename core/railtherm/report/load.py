"""Everything the report reads, in one place: ``metrics.nc``, ``study.json``, the study file, the run
files' attributes and ``references.nc``, all through :mod:`railtherm.output.store` (the output folder's owner).
The report is a pure reader: it computes no physics.

``metrics.nc`` is read as ``docs/verdicts.md`` describes it (one layout: each error with its own
``reference_<metric>``); a column a study did not produce is read as missing (NaN or "").
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..input.study import base_name, load_study
from ..output import store
from ..output.store import RESULT_STATUSES   # statuses of runs that produced a result

__all__ = ["RESULT_STATUSES", "Run", "Order", "SceneInfo", "StudyData", "body_bulk", "load"]


@dataclass
class Run:
    """One row of metrics.nc."""

    scene: str
    method: str
    level: int
    status: str
    message: str = ""
    reason_kind: str = ""
    wall_time: float = math.nan
    wall_time_median: float = math.nan
    timing_runs: float = math.nan
    memory: float = math.nan
    errors: dict = field(default_factory=dict)
    references: dict = field(default_factory=dict)
    energy_balance: float = math.nan
    energy_reference: str = ""
    headline_error: float = math.nan
    headline_reference: str = ""
    signed: dict = field(default_factory=dict)       # metric -> error with the sign of (value − reference)
    not_scored: dict = field(default_factory=dict)   # metric -> why it is not scored (its error is NaN)
    cooling_depth: float = math.nan                  # shallowest depth [m] at which the cooling rate is scored
    #: a result with several patches: metric -> {patch: error [1]} (metrics.nc's patch_errors_<metric>, each
    #: patch against the reference's same patch on its own scale) and the patch of the headline error (0: none)
    patch_errors: dict = field(default_factory=dict)
    headline_patch: int = 0

    @property
    def has_result(self) -> bool:
        return self.status in RESULT_STATUSES


@dataclass
class Order:
    """Convergence of one method's ladder on one metric of one scene."""

    method: str
    metric: str
    order: float
    theoretical: float = math.nan
    reference: str = ""
    richardson: float = math.nan
    richardson_uncertainty: float = math.nan


@dataclass
class SceneInfo:
    name: str
    headline: str = ""
    reference_kind: str = ""
    sweep: dict = field(default_factory=dict)
    base: str = ""
    scene: object = None  # railtherm Scene when the study is at hand
    published: dict = field(default_factory=dict)
    analytic: dict = field(default_factory=dict)


@dataclass
class StudyData:
    """What the report knows about one study output folder."""

    out: Path
    name: str
    tolerance: float | None
    runs: list[Run]
    scenes: list[str]
    methods: list[str]
    levels: list[int]
    info: dict
    study: object
    scene: dict[str, SceneInfo]
    orders: dict[str, list[Order]]
    cross: dict[str, dict]
    curves: dict | None
    memory_label: str = "peak RSS"   # metrics.nc's peak_rss: the peak resident set size of the run
    notes: list[str] = field(default_factory=list)
    _files: dict = field(default_factory=dict, repr=False)
    _attrs: dict = field(default_factory=dict, repr=False)
    _by_scene: dict | None = field(default=None, repr=False)   # runs_of's index, built on its first call

    def runs_of(self, scene: str, method: str | None = None) -> list[Run]:
        """The runs of ``scene`` (of ``method`` only, if given), in :attr:`runs` order; looked up in an index of
        the runs by scene, built on the first call (a report asks for every scene's)."""
        if self._by_scene is None:
            self._by_scene = {}
            for r in self.runs:
                self._by_scene.setdefault(r.scene, []).append(r)
        return [r for r in self._by_scene.get(scene, ()) if method is None or r.method == method]

    def finest_result(self, scene: str, method: str) -> Run | None:
        ok = [r for r in self.runs_of(scene, method) if r.has_result]
        return max(ok, key=lambda r: r.level) if ok else None

    def run_file(self, scene: str, method: str, level: int):
        """The run's Dataset (loaded, cached), or None when it has no file."""
        key = (scene, method, level)
        if key not in self._files:
            self._files[key] = _open_run(self.out, scene, method, level)
        return self._files[key]

    def run_attrs(self, scene: str, method: str, level: int) -> dict:
        """Global attributes of a run file ({} when there is none), read without loading the data."""
        key = (scene, method, level)
        if key not in self._attrs:
            attrs = {}
            try:  # a run file's attributes, or what the Zarr store records of the run
                attrs = store.run_attributes(self.out, scene, method, level)
            except Exception as exc:  # noqa: BLE001
                warnings.warn(f"railtherm report: cannot read run {scene}/{method}/level-{level} of {self.out}: "
                              f"{exc}", RuntimeWarning, stacklevel=2)
            self._attrs[key] = attrs
        return self._attrs[key]

    def stages(self, scene: str, method: str) -> dict[str, str]:
        """Stage -> model of the method's chain on this scene (from the run file's ``stages`` attribute)."""
        for r in sorted(self.runs_of(scene, method), key=lambda r: -r.level):
            if r.has_result:
                text = str(self.run_attrs(scene, method, r.level).get("stages", ""))
                if text:
                    return dict(part.split(":", 1) for part in text.split() if ":" in part)
        return {}


run_path = store.run_path  # re-export: the home of run_path is railtherm.output.store


def _open_run(out: Path, scene: str, method: str, level: int):
    """A run's Dataset through the store (a run file, or the run's row and kept fields of the Zarr store)."""
    try:
        return store.open_run(out, scene, method, level)
    except Exception as exc:  # noqa: BLE001
        warnings.warn(f"railtherm report: cannot read run {scene}/{method}/level-{level} of {out}: {exc}",
                      RuntimeWarning, stacklevel=3)
        return None


def _str(v) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    s = str(v)
    return "" if s == "nan" else s


def _float(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _sweeps(out: Path, names, scenes_obj: dict, info: dict) -> dict:
    """Scene name -> sweep ({dotted study key: value}), never guessed from the scene name.

    In order: the study's scene, the JSON attribute ``sweep`` of the scene's run files (railtherm 0.1
    files: their ``sweep_<key>`` attributes), the run records of ``study.json``.
    """
    out_sweeps = {nm: dict(getattr(scenes_obj[nm], "sweep", {}) or {}) for nm in names if nm in scenes_obj}
    rest = [nm for nm in names if nm not in out_sweeps]
    if rest:
        files = store.run_sweeps(out)
        records = {rec.get("scene"): rec.get("sweep") for rec in info.get("records", []) if isinstance(rec, dict)}
        for nm in rest:
            sweep = files.get(nm)
            if sweep is None:
                sweep = records.get(nm)
            out_sweeps[nm] = dict(sweep or {})
    return out_sweeps


def independent(reference: str) -> bool:
    """True for an error against something other than the run's own method (analytic or another method)."""
    return bool(reference) and not reference.startswith("self")


# ------------------------------------------------------------------------------------------------------
def load_metrics(out: Path):
    return store.read_metrics(out)


def _runs(m, metrics: list[str]) -> list[Run]:
    n = m.sizes.get("run", 0)

    def col(k, default=math.nan):
        return m[k].values if k in m else np.full(n, default, dtype=object)

    scene, method, status, level = col("scene"), col("method"), col("status"), col("level", 0)
    message, reason = col("message", ""), col("reason_kind", "")
    wall, median, nruns = col("wall_time"), col("wall_time_median"), col("timing_runs")
    mem, energy = col("peak_rss"), col("energy_balance")
    energy_ref = col("energy_reference", "")
    h_err, h_ref = col("headline_error"), col("headline_reference", "")
    errs = {k: col(f"error_{k}") for k in metrics}
    refs = {k: col(f"reference_{k}", "") for k in metrics}
    signs = {k: m[f"signed_error_{k}"].values for k in metrics if f"signed_error_{k}" in m}
    unscored, depth = col("not_scored", ""), col("cooling_rate_depth")
    per_patch = {k: m[f"patch_errors_{k}"].values for k in metrics if f"patch_errors_{k}" in m}
    hpatch = col("headline_patch", 0)
    runs = []
    for i in range(n):
        # inf is kept: a value that is not finite where its reference is fails the metric (docs/verdicts.md)
        errors = {k: _float(v[i]) for k, v in errs.items() if not math.isnan(_float(v[i]))}
        references = {k: _str(refs[k][i]) for k in errors}
        runs.append(Run(str(scene[i]), str(method[i]), int(level[i]), str(status[i]), _str(message[i]),
                        _str(reason[i]), _float(wall[i]), _float(median[i]), _float(nruns[i]), _float(mem[i]),
                        errors, references, _float(energy[i]), _str(energy_ref[i]), _float(h_err[i]),
                        _str(h_ref[i]), {k: _float(v[i]) for k, v in signs.items() if not math.isnan(_float(v[i]))},
                        not_scored_reasons(_str(unscored[i]), metrics), _float(depth[i]),
                        {k: patch_errors(_str(v[i])) for k, v in per_patch.items() if _str(v[i])},
                        int(_float(hpatch[i])) if math.isfinite(_float(hpatch[i])) else 0))
    return runs


def patch_errors(text: str) -> dict[int, float]:
    """metrics.nc's ``patch_errors_<metric>`` text ("1: 0.1047; 2: 0.01498") as {patch: error [1]}."""
    out = {}
    for part in text.split(";"):
        k, sep, v = part.partition(":")
        if sep:
            out[int(k)] = _float(v)
    return out


def not_scored_reasons(text: str, metrics) -> dict[str, str]:
    """metrics.nc's ``not_scored`` text ("creep force x: zero by symmetry ...; cooling rate, z ≥ 26 µm: ...")
    as metric -> reason; a part that names no metric continues the reason before it."""
    out: dict[str, str] = {}
    last = None
    for part in (text.split("; ") if text else []):
        name, sep, why = part.partition(": ")
        k = next((k for k in metrics if sep and _stored_words(k, name)), None)
        if k is not None:
            out[k], last = why, k
        elif last is not None:
            out[last] += "; " + part
    return out


def _stored_words(metric: str, name: str) -> bool:
    """True when ``name`` is how metrics.nc's ``not_scored`` names ``metric``."""
    if metric == "cooling_rate":
        return name == "cooling rate" or name.startswith("cooling rate, z ≥")
    if metric == "cooling_rate_all_depths":
        return name == "cooling rate, all depths"
    return name == metric.replace("_", " ")


class _PerScene:
    """metrics.nc's per-scene variables, each transposed once to (scene, ...) as a numpy array and read by the
    scene's position: a report on 10 000 scenes spent most of its time in an xarray selection per scene and
    variable."""

    def __init__(self, m):
        self.m = m
        names = m["scene_name"].values if "scene_name" in m.coords else ()
        self.pos = {str(n): i for i, n in enumerate(names)}
        self._arrays: dict = {}

    def dims(self, var: str) -> tuple:
        """The dimensions of ``var`` after ``scene_name`` (empty when it is not per scene)."""
        if var not in self.m or "scene_name" not in self.m[var].dims:
            return ()
        return tuple(d for d in self.m[var].dims if d != "scene_name")

    def get(self, var: str, scene: str, dims: tuple | None = None):
        """``m[var]`` of ``scene`` as a numpy array with dimensions ``dims`` (default: as stored), or None (no
        such variable, not per scene, or no such scene)."""
        if var not in self.m or "scene_name" not in self.m[var].dims or scene not in self.pos:
            return None
        dims = tuple(dims) if dims is not None else self.dims(var)
        key = (var, dims)
        if key not in self._arrays:
            self._arrays[key] = self.m[var].transpose("scene_name", *dims).values
        return self._arrays[key][self.pos[scene]]

    def coord(self, name: str) -> list[str]:
        return [str(x) for x in self.m[name].values]


def _orders(ps: _PerScene, scene: str) -> list[Order]:
    dims = ("method_name", "metric")
    order = ps.get("convergence_order", scene, dims)
    if order is None:
        return []
    rich, theory = ps.get("richardson_error", scene, dims), ps.get("theoretical_order", scene, dims)
    ref, unc = ps.get("order_reference", scene, dims), ps.get("richardson_uncertainty", scene, dims)
    out = []
    for i, meth in enumerate(ps.coord("method_name")):
        for j, met in enumerate(ps.coord("metric")):
            o = _float(order[i, j])
            r = _float(rich[i, j]) if rich is not None else math.nan
            if not math.isfinite(o) and not math.isfinite(r):
                continue
            out.append(Order(meth, met, o, _float(theory[i, j]) if theory is not None else math.nan,
                             _str(ref[i, j]) if ref is not None else "", r,
                             _float(unc[i, j]) if unc is not None else math.nan))
    return out


def _cross(ps: _PerScene, scene: str) -> dict:
    cd = ps.get("cross_difference", scene, ("quantity", "method_name", "other_method"))
    if cd is None:
        return {}
    methods = ps.coord("method_name")
    out = {}
    for k, q in enumerate(ps.coord("quantity")):
        mat = np.asarray(cd[k], float)
        off = mat.copy()
        np.fill_diagonal(off, np.nan)
        keep = [i for i in range(len(methods)) if np.isfinite(off[i]).any() or np.isfinite(off[:, i]).any()]
        if len(keep) >= 2:
            out[q] = ([methods[i] for i in keep], mat[np.ix_(keep, keep)])
    return out


def _load_info(out: Path) -> dict:
    p = store.study_path(out)
    if p.exists():
        try:
            return store.read_json(p)
        except Exception as exc:  # noqa: BLE001 - the report goes on without it
            warnings.warn(f"railtherm report: {p} is unreadable ({exc})", RuntimeWarning, stacklevel=3)
    return {}


def _load_study(info: dict, out: Path):
    path = info.get("path")
    if path and not Path(path).is_absolute() and not Path(path).exists():
        for base in (out.parent, out):  # a relative path recorded by a run started elsewhere
            if (base / path).exists():
                path = str(base / path)
                break
    if not path or not Path(path).exists():
        return None, (f"study file {path!r} not found: scene inputs and published values are left out" if path else
                      "no study given and no study path in study.json: scene inputs and published values are left out")
    try:
        return load_study(path), None
    except Exception as exc:  # noqa: BLE001
        return None, f"study file {path!r} could not be loaded ({exc}): scene inputs and published values are left out"


def _load_curves(out: Path):
    FILE_NAME = store.REFERENCES
    p = store.references_path(out)
    if not p.exists():
        return None, (f"`{FILE_NAME}` not found in the output folder: the exact reference curves are not drawn "
                      "(`railtherm run` writes it)")
    try:
        return store.read_references(p), None
    except Exception as exc:  # noqa: BLE001
        return None, f"`{FILE_NAME}` could not be read ({exc}): the exact reference curves are not drawn"


def load(out, study=None) -> StudyData:
    """Read a study output folder for the report."""
    out = Path(out)
    m = load_metrics(out)
    info = _load_info(out)
    notes = []
    if study is None:
        study, note = _load_study(info, out)
        if note:
            notes.append(note)
    metrics = [k[len("error_"):] for k in m.data_vars if k.startswith("error_")]
    runs = _runs(m, metrics)

    scenes_obj = {s.name: s for s in study.scenes} if study is not None else {}
    names = list(scenes_obj)
    seen = set(names)
    for nm in (list(map(str, m["scene_name"].values)) if "scene_name" in m.coords else []) + [r.scene for r in runs]:
        if nm not in seen:
            names.append(nm)
            seen.add(nm)
    present = {r.scene for r in runs}
    names = [n for n in names if n in present]
    sweeps = _sweeps(out, names, scenes_obj, info)
    published = getattr(study, "published", None) or {}

    ps = _PerScene(m)
    analytic = [v for v in m.data_vars if v.startswith("analytic_")]
    scene_info = {}
    for nm in names:
        sc = scenes_obj.get(nm)
        si = SceneInfo(nm, sweep=sweeps[nm], base=base_name(nm), scene=sc, published=dict(published.get(nm, {})))
        h = ps.get("headline", nm)
        si.headline = _str(getattr(h, "item", lambda: h)()) if h is not None else ""
        rk = ps.get("reference_kind", nm)
        si.reference_kind = _str(getattr(rk, "item", lambda: rk)()) if rk is not None else ""
        for var in analytic:
            da = ps.get(var, nm)
            if da is not None:
                si.analytic[var[len("analytic_"):]] = np.asarray(da, float)
        scene_info[nm] = si
    curves, note = _load_curves(out)
    if note:
        notes.append(note)
    tol = float(m.attrs["tolerance"]) if "tolerance" in m.attrs else getattr(study, "tolerance", None)
    return StudyData(
        out=out, name=str(info.get("study") or m.attrs.get("study") or getattr(study, "name", out.name)),
        tolerance=tol, runs=runs, scenes=names, methods=sorted({r.method for r in runs}),
        levels=sorted({r.level for r in runs}), info=info, study=study, scene=scene_info,
        orders={nm: _orders(ps, nm) for nm in names}, cross={nm: _cross(ps, nm) for nm in names},
        curves=curves, notes=notes)


def body_bulk(data: StudyData, scene: str, body: int) -> float:
    """The bulk temperature [degC] of ``body`` (0 wheel, 1 rail) in ``scene`` of a loaded study; 0 when the study
    file (and so the scene) is not available."""
    sc = data.scene[scene].scene
    try:
        return float(sc.body(body).bulk_temperature)
    except AttributeError:
        return 0.0
