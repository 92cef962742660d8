"""Command line: ``railtherm run | validate | methods | report``.

User errors (invalid study, unknown method) print one message and exit with status 2, without a
traceback. FiPy parses ``sys.argv`` when imported; the FiPy plugin shields it from our arguments,
and none of our options collides with FiPy's (``--petsc``, ``--scipy``, ``--trilinos``, ``--inline``).
"""
from __future__ import annotations

import argparse
import sys
import warnings

from .errors import SceneError


def _levels(text: str) -> list[int]:
    try:
        return [int(t) for t in text.replace(" ", "").split(",") if t]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--levels takes integers separated by commas, got {text!r}") from None


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="railtherm", description="Compare numerical methods for thermoelastic "
                                "wheel-rail rolling contact with friction.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a study and write runs/, metrics.nc and the report")
    r.add_argument("study", help="study TOML file")
    r.add_argument("--out", default=None, help="output folder (default: out/<study name>)")
    r.add_argument("--methods", default=None, help="comma-separated methods (default: the study's)")
    r.add_argument("--levels", type=_levels, default=None, help="comma-separated levels (default: the study's)")
    r.add_argument("--executor", choices=("serial", "processes", "dask"), default="serial")
    r.add_argument("--scheduler", default=None, help="dask.distributed scheduler address (with --executor dask)")
    r.add_argument("--workers", type=int, default=None, help="local workers (processes / LocalCluster)")
    r.add_argument("--resume", action="store_true", help="skip runs already written for the same scene hash")
    r.add_argument("--no-report", action="store_true", help="do not write the report")
    v = sub.add_parser("validate", help="check a study without running it (exit 1 on any error)")
    v.add_argument("study", nargs="+")
    sub.add_parser("methods", help="list every method with its plugin, version, stages and capabilities")
    rp = sub.add_parser("report", help="write report.md, report.html and figures/ for a study output folder")
    rp.add_argument("out")
    rp.add_argument("--benchmarks", default=None, help="pytest-benchmark JSON file to include")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return _dispatch(args)
    except SceneError as exc:
        print(f"railtherm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("railtherm: interrupted; runs written so far are kept (use --resume)", file=sys.stderr)
        return 130


def _dispatch(args) -> int:
    if args.command == "validate":
        from .plugins import get_host
        from .study import load_study
        bad = 0
        for path in args.study:
            try:
                st = load_study(path)
            except SceneError as exc:
                print(f"{path}: error: {exc}", file=sys.stderr)
                bad += 1
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                host = get_host()
            names = st.method_names(host.methods)
            unknown = [m for m in names if m not in host.methods]
            if unknown:
                print(f"{path}: error: key 'study.methods': unknown method(s) {unknown}; installed: "
                      f"{sorted(host.methods)}", file=sys.stderr)
                bad += 1
                continue
            for m in names:  # options are validated by the method's models
                opts = st.options.get(m, {})
                for s in host.methods[m].models:
                    try:
                        s.cls.resolve_options(opts)
                    except SceneError as exc:
                        print(f"{path}: error: study.options.{m}: {exc}", file=sys.stderr)
                        bad += 1
            print(f"{path}: ok: study {st.name!r}, {len(st.scenes)} scenes, methods {names}, levels {st.levels}")
        return 1 if bad else 0
    if args.command == "methods":
        from .plugins import get_host
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            host = get_host()
        for name in sorted(host.methods):
            print(host.methods[name].describe())
        if host.problems:
            print("\nplugin problems:")
            for p in host.problems:
                print(f"  - {p}")
        return 0
    if args.command == "run":
        from pathlib import Path

        from .runner import run_study
        from .study import load_study
        st = load_study(args.study)
        out = Path(args.out or Path("out") / st.name)
        methods = [m.strip() for m in args.methods.split(",")] if args.methods else None
        m = run_study(st, out, executor=args.executor, scheduler=args.scheduler, methods=methods,
                      levels=args.levels, resume=args.resume, report=not args.no_report, workers=args.workers)
        status = [str(s) for s in m["status"].values]
        counts = {k: status.count(k) for k in ("ok", "inaccurate", "refused", "failed")}
        print(f"study {st.name!r}: {len(status)} runs: " + ", ".join(f"{v} {k}" for k, v in counts.items())
              + f"; results in {out}")
        return 0
    if args.command == "report":
        from .report import write_report
        paths = write_report(args.out, benchmarks=args.benchmarks)
        for p in paths:
            print(p)
        return 0
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
