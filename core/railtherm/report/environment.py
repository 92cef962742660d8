"""The report's last sections: benchmarks, the files of the output folder, and the environment with the
code that produced the results (commit id, railtherm's and every plugin's version)."""
from __future__ import annotations

import importlib.metadata as md
import json
import os
import platform
import re
import shlex
import subprocess
import time
from pathlib import Path

from .document import Document
from .format import duration, num, pct, short
from .load import StudyData

__all__ = ["benchmark_section", "environment_section", "files_line", "code_versions", "commit_id"]

PACKAGES = ("railtherm", "numpy", "scipy", "xarray", "netCDF4", "numba", "fipy", "scikit-fem", "matplotlib",
            "pluggy", "dask", "pytest-benchmark")
THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
#: files of the output folder a reader may want beside the report: (name, what it holds)
DATA_FILES = (("metrics.nc", "every run's status, errors and timings"),
              ("references.nc", "the exact reference curves drawn here"),
              ("study.json", "the run records and the study's path"))


def files_line(out: Path) -> str:
    """A sentence linking the data files of the output folder that exist (relative links)."""
    have = [(n, what) for n, what in DATA_FILES if (Path(out) / n).exists()]
    if not have:
        return ""
    return "Data: " + "; ".join(f"[{n}]({n}) ({what})" for n, what in have) + "."


def commit_id() -> str:
    """``git describe`` of the installed railtherm package when it is a git checkout, else ''."""
    here = Path(__file__).resolve().parent
    try:
        res = subprocess.run(["git", "describe", "--always", "--dirty", "--tags"], cwd=here, capture_output=True,
                             text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return ""
    return res.stdout.strip() if res.returncode == 0 else ""


def code_versions(data: StudyData) -> tuple[str, list[str]]:
    """(railtherm's installed version, ['green 0.2.0', ...]): the plugins and versions named in the run
    files' ``source`` attribute (what produced the results), else the installed plugins' distributions."""
    try:
        version = md.version("railtherm")
    except md.PackageNotFoundError:
        version = "unknown (railtherm is not installed as a distribution)"
    found: dict[str, str] = {}
    seen = set()
    for r in data.runs:
        if not r.has_result or (r.method in seen):
            continue
        seen.add(r.method)
        src = str(data.run_attrs(r.scene, r.method, r.level).get("source", ""))
        for name, ver in re.findall(r"plugin (\S+) ([0-9][^\s;,)]*)", src):
            found[name] = ver
        m = re.match(r"railtherm ([0-9][^\s;]*)", src)
        if m:
            found.setdefault("railtherm", m.group(1))
    if not any(k != "railtherm" for k in found):
        try:
            for ep in md.entry_points(group="railtherm.plugins"):
                found[ep.name] = f"{ep.dist.version} ({ep.dist.name})" if ep.dist else "?"
        except Exception:  # noqa: BLE001 - versions are informative only
            pass
    return version, [f"{k} {v}" for k, v in sorted(found.items())]


def benchmark_section(doc: Document, path: Path):
    doc.heading(2, "Benchmarks", "benchmarks")
    try:
        data = json.loads(Path(path).read_text())
    except Exception as exc:  # noqa: BLE001
        doc.paragraph(f"Benchmark file `{path}` could not be read: {exc}.")
        return
    mi = data.get("machine_info", {})
    cpu = mi.get("cpu", {}) if isinstance(mi.get("cpu"), dict) else {}
    when = data.get("datetime", "")
    rows = []
    for b in data.get("benchmarks", []):
        st = b.get("stats", {})
        extra = b.get("extra_info", {}) or {}
        info = ", ".join(f"{k}={num(v, 4) if isinstance(v, (int, float)) and not isinstance(v, bool) else v}"
                         for k, v in extra.items())
        rows.append([b.get("name", b.get("fullname", "?")), duration(st.get("mean")), duration(st.get("min")),
                     duration(st.get("stddev")), str(st.get("rounds", "–")), short(info, 160)])
    if not doc.table(f"pytest-benchmark results from `{path}`" + (f", {when}" if when else "")
                     + (f", CPU {cpu.get('brand_raw')}" if cpu.get("brand_raw") else "")
                     + "; `extra_info` holds the error of the timed run.",
                     ["benchmark", "mean", "min", "stddev", "rounds", "extra_info"], rows):
        doc.paragraph("The file holds no benchmarks.")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _run_items(data: StudyData) -> list[str]:
    info = data.info
    items = []
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
    study_path = info.get("path") or getattr(data.study, "path", None)
    items.append(f"Study `{data.name}`, file `{study_path or 'unknown'}`; tolerance "
                 f"{pct(data.tolerance) if data.tolerance is not None else 'unknown'}")
    argv = info.get("argv")
    if argv:
        items.append("Command line of the run: `" + " ".join(shlex.quote(str(a)) for a in argv) + "`")
    return items


def environment_section(doc: Document, data: StudyData, notes: list[str]):
    """Where the results came from: the code (commit id, railtherm's and every plugin's version), the
    packages, the machine, the run, and the data files."""
    doc.heading(2, "Environment and code", "environment")
    version, plugins = code_versions(data)
    commit = commit_id()
    items = [f"railtherm {version}" + (f", commit `{commit}` (git describe of the installed package)" if commit
                                       else " (not a git checkout: no commit id)"),
             "Plugins and versions that produced the runs: " + (", ".join(plugins) or "none recorded")]
    line = files_line(data.out)
    if line:
        items.append(line)
    versions = []
    for pkg in PACKAGES:
        try:
            versions.append(f"{pkg} {md.version(pkg)}")
        except md.PackageNotFoundError:
            versions.append(f"{pkg} (not installed)")
    items += [f"Python {platform.python_version()} on {platform.platform()}",
              "Packages: " + ", ".join(versions),
              f"CPU: {_cpu_model()}; os.cpu_count() = {os.cpu_count()}"
              + (f"; usable by this process: {len(os.sched_getaffinity(0))}" if hasattr(os, "sched_getaffinity")
                 else "")]
    items += _run_items(data)
    items += notes
    items.append(f"Report written {time.strftime('%Y-%m-%d %H:%M:%S %Z')} by railtherm.report.write_report")
    doc.bullets(items)
