"""The command line: validate rejects malformed studies by key, without a traceback; methods; run.

The commands are called in this process through :func:`railtherm.cli.main` (what ``python -m railtherm.cli``
runs, with its return value as the exit status); one test runs the module as a command in a subprocess, so
that its exit status and output are those a shell sees.
"""
import subprocess
import sys

import pytest

from railtherm.cli import main
from studies import ellipse_scene

GOOD = """
schema_version = 1
[study]
name = "cli"
methods = "all"
levels = [0]
""" + ellipse_scene()


def _cli(*args, cwd=None):
    """The command in a subprocess: (exit status, stdout, stderr)."""
    r = subprocess.run([sys.executable, "-m", "railtherm.cli", *args], capture_output=True, text=True, cwd=cwd,
                       timeout=120)
    return r.returncode, r.stdout, r.stderr


def _main(capsys, *args):
    """The command in this process: (exit status, stdout, stderr); an exception would fail the test."""
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("change,key", [
    (("friction = 0.3", "friction = -0.3"), "friction"),
    (("friction = 0.3", "friction = 0.3\nfricton = 0.2"), "fricton"),
    (("speed = 30.0", "speed = nan"), "speed"),
    (("speed = 30.0", 'speed = "fast"'), "speed"),
])
def test_validate_rejects_malformed(tmp_path, capsys, change, key):
    p = tmp_path / "bad.toml"
    p.write_text(GOOD.replace(*change))
    code, out, err = _main(capsys, "validate", p)
    assert code != 0
    assert f"'{key}'" in err and "Traceback" not in err + out


def test_validate_accepts_good_and_methods_lists(tmp_path, capsys):
    p = tmp_path / "good.toml"
    p.write_text(GOOD)
    code, out, err = _main(capsys, "validate", p)
    assert code == 0, err
    assert "ok" in out
    code, out, err = _main(capsys, "methods")
    assert code == 0


def test_run_reports_unknown_method_without_traceback(tmp_path):
    """As a shell runs it: ``python -m railtherm.cli`` in a subprocess, its exit status and stderr."""
    p = tmp_path / "good.toml"
    p.write_text(GOOD.replace('methods = "all"', 'methods = ["nope"]'))
    code, out, err = _cli("run", str(p), "--out", str(tmp_path / "o"))
    assert code == 2 and "nope" in err and "Traceback" not in err
