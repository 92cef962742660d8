"""Command line: ``railtherm run | validate | methods | report | diff``.

User errors (invalid study or option, unknown method, a path that cannot be used, a bad command-line
value) print one ``railtherm: error: ...`` line and exit with status 2, without a traceback.
``railtherm run`` checks the whole study before the first run and exits 0 when no run failed (ok,
inaccurate, unverified and refused runs), 3 when a run failed. ``railtherm validate`` exits 1 on any
error; ``railtherm diff`` exits 1 when the two metrics files differ (like diff(1)). FiPy parses ``sys.argv`` when imported; the FiPy plugin shields it from our arguments,
and none of our options collides with FiPy's (``--petsc``, ``--scipy``, ``--trilinos``, ``--inline``).
"""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

from .contract.errors import SceneError
from .contract.options import check_study
from .input.study import load_study
from .output import store
#: run statuses (docs/verdicts.md), in the order they are counted
from .output.store import STATUSES
from .solving.plugins import get_host


class _UsageError(Exception):
    """A command-line usage error (argparse's), reported like every other user error."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse would print usage and exit; main() prints one line
        raise _UsageError(f"{self.prog}: {message}")


def _levels(text: str) -> list[int]:
    try:
        return [int(t) for t in text.replace(" ", "").split(",") if t]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--levels takes integers >= 0 separated by commas, got {text!r}") from None


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="railtherm", description="Compare numerical methods for thermoelastic "
                "wheel-rail rolling contact with friction.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("run", help="run a study and write runs/, metrics.nc and the report (exit 0: no run "
                       "failed; 3: a run failed; 2: invalid input)")
    r.add_argument("study", help="study TOML file")
    r.add_argument("--out", default=None, help="output folder (default: out/<study name>)")
    r.add_argument("--methods", default=None, help="comma-separated methods (default: the study's)")
    r.add_argument("--levels", type=_levels, default=None, help="comma-separated levels (default: the study's)")
    r.add_argument("--executor", choices=("auto", "serial", "processes", "dask"), default="auto",
                   help="auto (default): local worker processes, one per core; serial: this process")
    r.add_argument("--scheduler", default=None, help="dask.distributed scheduler address (with --executor dask)")
    r.add_argument("--workers", type=int, default=None, help="local workers >= 1 (processes / LocalCluster)")
    r.add_argument("--resume", action="store_true", help="skip runs already written for the same scene hash")
    r.add_argument("--no-report", action="store_true", help="do not write the report")
    v = sub.add_parser("validate", help="check a study without running it (exit 1 on any error)")
    v.add_argument("study", nargs="+")
    sub.add_parser("methods", help="list every method with its plugin, version, stages and capabilities")
    rp = sub.add_parser("report", help="write report.md, report.html and figures/ for a study output folder")
    rp.add_argument("out")
    rp.add_argument("--benchmarks", default=None, help="pytest-benchmark JSON file to include")
    d = sub.add_parser("diff", help="compare the metrics.nc of two output folders run by run (exit 1 if they "
                       "differ); wall times and memory are left out")
    d.add_argument("before")
    d.add_argument("after")
    d.add_argument("--rtol", type=float, default=1e-12, help="relative tolerance of equal numbers (default 1e-12)")
    d.add_argument("--atol", type=float, default=0.0, help="absolute tolerance in the variable's units (e.g. "
                   "1e-12 for relative errors near round-off; default 0)")
    d.add_argument("--machine", action="store_true", help="also compare wall times and memory")
    return p


def _error(message) -> int:
    print(f"railtherm: error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return _dispatch(args)
    except _UsageError as exc:
        return _error(f"{exc} (see railtherm --help)")
    except SceneError as exc:
        return _error(exc)
    except OSError as exc:  # a path the user gave: missing, a file for a folder, no permission
        where = f" {str(exc.filename)!r}" if exc.filename else ""
        return _error(f"{exc.strerror or exc}{where}")
    except KeyboardInterrupt:
        print("railtherm: interrupted; runs written so far are kept (use --resume)", file=sys.stderr)
        return 130


def _host():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return get_host()


def _validate(paths) -> int:
    host = _host()
    bad = 0
    for path in paths:
        try:
            st = load_study(path)
            check_study(st, host)
        except SceneError as exc:
            print(f"{path}: error: {exc}", file=sys.stderr)
            bad += 1
            continue
        # a wheelset on profiles that finds no contact loads (its own runs fail, not the study's): named here
        lost = [sc.profile_contact.failure() for sc in st.scenes if hasattr(sc.profile_contact, "failure")]
        for exc in lost:
            print(f"{path}: error: {exc}", file=sys.stderr)
        if lost:
            bad += 1
            continue
        print(f"{path}: ok: study {st.name!r}, {len(st.scenes)} scenes, methods {st.method_names(host.methods)}, "
              f"levels {st.levels}")
    return 1 if bad else 0


def _run(args) -> int:
    if args.workers is not None and args.workers < 1:
        raise SceneError(f"--workers {args.workers} is not allowed: an integer >= 1 (local worker processes)",
                         key="workers", value=args.workers, allowed="an integer >= 1")
    from .run.executors import resolve_executor, start_worker_server  # `railtherm run` only
    if resolve_executor(args.executor, args.workers, 2)[0] == "processes":
        start_worker_server(args.workers)  # its imports (~2 s) overlap the runner's import and the checks below
    from .run.runner import run_study  # the runner (~0.3 s with the report): `railtherm run` only
    methods = None
    if args.methods is not None:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        if not methods:
            raise SceneError(f"--methods {args.methods!r} names no method", key="methods", value=args.methods,
                             allowed="comma-separated method names")
    st = load_study(args.study)
    check_study(st, _host(), methods=methods, levels=args.levels)  # everything, before the first task
    out = Path(args.out or Path("out") / st.name)
    if out.exists() and not out.is_dir():
        raise SceneError(f"--out {str(out)!r} is an existing file, not a folder: name a folder (created if missing)",
                         key="out", value=str(out), allowed="a folder")
    m = run_study(st, out, executor=args.executor, scheduler=args.scheduler, methods=methods,
                  levels=args.levels, resume=args.resume, report=not args.no_report, workers=args.workers)
    status = [str(s) for s in m["status"].values]
    counts = {k: status.count(k) for k in STATUSES}
    other = len(status) - sum(counts.values())
    print(f"study {st.name!r}: {len(status)} runs: " + ", ".join(f"{v} {k}" for k, v in counts.items())
          + (f", {other} of unknown status" if other else "") + f"; results in {out}")
    return 3 if counts["failed"] or other else 0


def _report(args) -> int:
    # `railtherm report` only: the report and the executors (~0.3 s); worker_context is the fork server,
    # whose render workers start with matplotlib loaded
    from .report import write_report
    from .run.executors import worker_context
    out = Path(args.out)
    if not out.exists():
        raise SceneError(f"output folder {str(out)!r} does not exist: give the --out folder of `railtherm run`",
                         key="out", value=str(out), allowed="an output folder of railtherm run")
    if not out.is_dir():
        raise SceneError(f"{str(out)!r} is not a folder: give the --out folder of `railtherm run`",
                         key="out", value=str(out), allowed="an output folder of railtherm run")
    if not store.metrics_path(out).is_file():
        raise SceneError(f"folder {str(out)!r} holds no metrics.nc: run `railtherm run STUDY --out {out}` first",
                         key="out", value=str(out), allowed="an output folder of railtherm run")
    if args.benchmarks is not None and not Path(args.benchmarks).is_file():
        raise SceneError(f"--benchmarks {args.benchmarks!r} is not a file (a pytest-benchmark JSON file)",
                         key="benchmarks", value=args.benchmarks, allowed="a pytest-benchmark JSON file")
    for p in write_report(out, benchmarks=args.benchmarks, workers=os.cpu_count() or 1, context=worker_context()):
        print(p)
    return 0


def _dispatch(args) -> int:
    if args.command == "validate":
        return _validate(args.study)
    if args.command == "methods":
        host = _host()
        for name in sorted(host.methods):
            print(host.methods[name].describe())
        if host.problems:
            print("\nplugin problems:")
            for p in host.problems:
                print(f"  - {p}")
        return 0
    if args.command == "run":
        return _run(args)
    if args.command == "report":
        return _report(args)
    if args.command == "diff":
        return _diff(args)
    return 2


def _diff(args) -> int:
    from .analysis.metrics_diff import diff_metrics  # xarray (~1 s): `railtherm diff` only
    for path in (args.before, args.after):
        p = Path(path)
        if not (p.is_file() or (p / "metrics.nc").is_file()):
            raise SceneError(f"{path!r} is neither a metrics.nc nor an output folder holding one", key="diff",
                             value=path, allowed="a metrics.nc file or the --out folder of railtherm run")
    found = diff_metrics(args.before, args.after, rtol=args.rtol, atol=args.atol, include_machine=args.machine)
    for d in found:
        print(d.line())
    print(f"{len(found)} variables differ" if found else "the same numbers")
    return 1 if found else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
