"""The command line on user errors and run outcomes.

* every user error prints one ``railtherm: error: ...`` line naming what is wrong, exits 2 and
  prints no traceback: a study path that is a folder, not UTF-8 or missing; ``report`` on a folder
  without results; ``--out`` naming a file; negative or non-integral ``--levels``; ``--workers`` < 1;
  unknown ``--methods``; a bad option, reference or option table in the study (before any run);
* ``validate`` reports a bad option value (and does not then print "ok"), exit 1;
* ``run`` exits 0 when every run is ok / inaccurate / unverified / refused, 3 when a run failed, and
  prints the count of each of the five statuses.

Most tests call :func:`railtherm.cli.main` in this process with the fixture plugins (``flat_host``);
the ones whose old behaviour could hang run the command in a subprocess with a time limit.
"""
from __future__ import annotations

import subprocess
import sys

import pytest

from railtherm.cli import main
from studies import ELASTIC, ellipse_scene

STUDY = """
schema_version = 1
[study]
name = "clierr"
methods = {methods}
levels = [0]
repeat = 1
warmup = false
{extra}
{elastic}{scene}heat_partition = 0.5
outputs = ["max_surface_temperature", "surface_temperature", "heat_flux", "frictional_power"]
"""


def study_text(methods='["flat"]', speed="30.0", extra=""):
    return STUDY.format(methods=methods, extra=extra, elastic=ELASTIC, scene=ellipse_scene(speed=speed))


@pytest.fixture
def study(tmp_path):
    def write(methods='["flat"]', speed="30.0", extra="", name="s.toml"):
        p = tmp_path / name
        p.write_text(study_text(methods, speed, extra))
        return p
    return write


def run_main(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def user_error(capsys, *args, expect=()):
    code, out, err = run_main(capsys, *args)
    assert code == 2, (code, out, err)
    assert err.startswith("railtherm: error: "), err
    for e in expect:
        assert e in err, (e, err)
    return err


# ---------------------------------------------------------------------------------------------
# the study path
def test_run_study_path_is_a_folder(capsys, tmp_path):
    user_error(capsys, "run", tmp_path, "--out", tmp_path / "o", expect=(str(tmp_path), "folder"))


def test_run_study_path_not_utf8(capsys, tmp_path):
    p = tmp_path / "latin.toml"
    p.write_bytes(b'[study]\nname = "caf\xe9"\n')
    user_error(capsys, "run", p, "--out", tmp_path / "o", expect=("latin.toml", "UTF-8"))


def test_run_study_path_missing(capsys, tmp_path):
    user_error(capsys, "run", tmp_path / "none.toml", expect=("none.toml", "does not exist"))


def test_validate_folder_and_missing_file(capsys, tmp_path, flat_host, study):
    good = study()
    code, out, err = run_main(capsys, "validate", tmp_path, good, tmp_path / "none.toml")
    assert code == 1
    assert "folder" in err and "does not exist" in err
    assert f"{good}: ok" in out


# ---------------------------------------------------------------------------------------------
# report
def test_report_on_a_missing_folder(capsys, tmp_path):
    user_error(capsys, "report", tmp_path / "nowhere", expect=("nowhere", "does not exist"))


def test_report_on_a_folder_without_metrics(capsys, tmp_path):
    user_error(capsys, "report", tmp_path, expect=("metrics.nc",))


def test_report_on_a_file(capsys, tmp_path, study):
    user_error(capsys, "report", study(), expect=("not a folder",))


# ---------------------------------------------------------------------------------------------
# run options
def test_out_naming_an_existing_file(capsys, tmp_path, flat_host, study):
    f = tmp_path / "taken"
    f.write_text("x")
    user_error(capsys, "run", study(), "--out", f, "--no-report", expect=("--out", "taken", "file"))
    assert f.read_text() == "x"


@pytest.mark.parametrize("levels", ["-1", "0,-2", "1.5", "x"])
def test_bad_levels(capsys, tmp_path, flat_host, study, levels):
    err = user_error(capsys, "run", study(), "--out", tmp_path / "o", f"--levels={levels}", "--no-report",
                     expect=("level",))
    assert levels.split(",")[-1] in err
    assert not (tmp_path / "o" / "runs").exists()


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_workers_below_one(capsys, tmp_path, flat_host, study, workers):
    user_error(capsys, "run", study(), "--out", tmp_path / "o", "--workers", workers, "--executor", "processes",
               "--no-report", expect=("--workers", workers, ">= 1"))
    assert not (tmp_path / "o" / "runs").exists()


def test_workers_minus_one_with_processes_does_not_hang(tmp_path):
    """Before: ``--workers -1 --executor processes`` looped for ever (a pool of no worker)."""
    p = tmp_path / "s.toml"
    p.write_text(study_text(methods='"all"'))
    r = subprocess.run([sys.executable, "-m", "railtherm.cli", "run", str(p), "--out", str(tmp_path / "o"),
                        "--workers", "-1", "--executor", "processes", "--no-report"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "railtherm: error: " in r.stderr and "--workers" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr


def test_unknown_methods_option(capsys, tmp_path, flat_host, study):
    user_error(capsys, "run", study(), "--out", tmp_path / "o", "--methods", "flat,falt", "--no-report",
               expect=("'falt'", "broken, flat"))
    assert not (tmp_path / "o" / "runs").exists()


@pytest.mark.parametrize("extra,expect", [
    ("[study.options.flat]\nscale = -1.0\n", ("study.options.flat.scale", "-1.0")),
    ("[study.options.flat]\nscael = 1.0\n", ("study.options.flat.scael", "allowed: cells, scale")),
    ("[study.options.falt]\nscale = 1.0\n", ("study.options.falt", "broken, flat")),
    ('reference = "analytical"\n', ("study.reference", "'analytical'", '"analytic", "finest"')),
])
def test_run_rejects_a_bad_study_before_any_run(capsys, tmp_path, flat_host, study, extra, expect):
    user_error(capsys, "run", study(extra=extra), "--out", tmp_path / "o", "--no-report", expect=expect)
    assert not (tmp_path / "o" / "runs").exists()


# ---------------------------------------------------------------------------------------------
# validate
@pytest.mark.parametrize("extra,expect", [
    ("[study.options.flat]\nscale = -1.0\n", "study.options.flat.scale"),
    ("[study.options.flat]\nscael = 1.0\n", "study.options.flat.scael"),
    ("[study.options.flat]\ncells = 0\n", "study.options.flat.cells"),
    ("[study.options.falt]\nscale = 1.0\n", "study.options.falt"),
    ('reference = "analytical"\n', "study.reference"),
])
def test_validate_reports_bad_options_and_does_not_say_ok(capsys, flat_host, study, extra, expect):
    p = study(extra=extra)
    code, out, err = run_main(capsys, "validate", p)
    assert code == 1
    assert expect in err and str(p) in err
    assert "ok" not in out, out


def test_validate_good_study(capsys, flat_host, study):
    p = study(extra="[study.options.flat]\nscale = 2e-6\n")
    code, out, err = run_main(capsys, "validate", p)
    assert code == 0 and f"{p}: ok" in out, err


# ---------------------------------------------------------------------------------------------
# run: exit status and counts
def test_run_exit_0_and_counts_of_the_five_statuses(capsys, tmp_path, flat_host, study):
    code, out, err = run_main(capsys, "run", study(speed="[30.0, 60.0]"), "--out", tmp_path / "o", "--no-report")
    assert code == 0, err
    line = out.strip().splitlines()[-1]
    assert "2 runs" in line
    for status in ("ok", "inaccurate", "unverified", "refused", "failed"):
        assert f" {status}" in line, line
    assert "0 failed" in line


def test_run_exit_3_when_a_run_failed(capsys, tmp_path, flat_host, study):
    """Before: exit 0 although a run failed (the broken fixture raises at speed 13)."""
    code, out, err = run_main(capsys, "run", study(methods='["broken"]', speed="[13.0, 30.0]"),
                              "--out", tmp_path / "o", "--no-report")
    assert code == 3, (out, err)
    assert "1 failed" in out
