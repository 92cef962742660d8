"""The command line: validate rejects malformed studies by key, without a traceback; methods; run."""
import subprocess
import sys

import pytest

GOOD = """
schema_version = 1
[study]
name = "cli"
methods = "all"
levels = [0]
[[scene]]
name = "ek"
normal_force = 100e3
contact = { shape = "ellipse", semi_axes = [5.88e-3, 10.54e-3] }
speed = 30.0
sliding_speed = 1.0
friction = 0.3
"""


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "railtherm.cli", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=120)


@pytest.mark.parametrize("change,key", [
    (("friction = 0.3", "friction = -0.3"), "friction"),
    (("friction = 0.3", "friction = 0.3\nfricton = 0.2"), "fricton"),
    (("speed = 30.0", "speed = nan"), "speed"),
    (("speed = 30.0", 'speed = "fast"'), "speed"),
])
def test_validate_rejects_malformed(tmp_path, change, key):
    p = tmp_path / "bad.toml"
    p.write_text(GOOD.replace(*change))
    r = _cli("validate", str(p))
    assert r.returncode != 0
    assert f"'{key}'" in r.stderr and "Traceback" not in r.stderr + r.stdout


def test_validate_accepts_good_and_methods_lists(tmp_path):
    p = tmp_path / "good.toml"
    p.write_text(GOOD)
    r = _cli("validate", str(p))
    assert r.returncode == 0, r.stderr
    assert "ok" in r.stdout
    r = _cli("methods")
    assert r.returncode == 0


def test_run_reports_unknown_method_without_traceback(tmp_path):
    p = tmp_path / "good.toml"
    p.write_text(GOOD.replace('methods = "all"', 'methods = ["nope"]'))
    r = _cli("run", str(p), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "nope" in r.stderr and "Traceback" not in r.stderr
