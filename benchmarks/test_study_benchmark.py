"""The main study end to end, as a new user runs it (``railtherm run studies/seed_paper.toml``).

Records (pytest-benchmark ``extra_info``): the wall time of the whole study, the sum of the runs'
best solve times, the solving overhead ``wall x workers / sum(best)`` (1 would be a study that costs
only its answers; the target is <= 2), the mean number of solves per run (warm-ups, timed solves,
solves that compiled) and the executor's worker count. One round: the study takes minutes.

Run: ``python -m pytest benchmarks/test_study_benchmark.py -m benchmark --benchmark-enable -n 0``.
"""
from __future__ import annotations

import json
import math
import time
from pathlib import Path

import pytest

import railtherm

STUDY = Path(__file__).resolve().parents[1] / "studies" / "seed_paper.toml"


def study_costs(out: Path, wall: float) -> dict:
    """Overhead figures of a finished study folder ``out`` whose run took ``wall`` seconds."""
    info = json.loads((out / "study.json").read_text())
    recs = [r for r in info["records"] if r["status"] == "ok" and math.isfinite(r["wall_time"])]
    workers = int(info["timing"]["workers"] or 1)
    best = sum(r["wall_time"] for r in recs)
    solves = [r["phases"].get("solves", math.nan) for r in recs]
    return {"wall_time": wall, "runs": len(info["records"]), "runs_ok": len(recs), "workers": workers,
            "executor": info["timing"]["executor"], "sum_best_solve": best,
            "overhead": wall * workers / best if best else math.nan,
            "runs_phase": info["timing"]["runs"],
            "overhead_runs_phase": info["timing"]["runs"] * workers / best if best else math.nan,
            "solves_per_run": sum(solves) / len(solves) if solves else math.nan}


@pytest.mark.benchmark
def test_main_study_end_to_end(benchmark, tmp_path):
    out = tmp_path / "seed_paper"

    def run():
        t0 = time.perf_counter()
        railtherm.run_study(STUDY, out, executor="auto")
        return time.perf_counter() - t0
    wall = benchmark.pedantic(run, rounds=1, iterations=1)
    info = study_costs(out, wall)
    benchmark.extra_info.update(info)
    assert info["runs"] == 600 and info["solves_per_run"] >= 1.0
