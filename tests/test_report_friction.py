"""The report's friction-law section (core/railtherm/report/friction_section.py): a small creepage sweep
under a slip-velocity law and under constant friction, run by kalker; the section's table holds each
curve's maximum as the run files give it, and the curve with falling friction is reported as falling.

Run: ``OPENBLAS_NUM_THREADS=1 MPLBACKEND=Agg python -m pytest -q tests/test_report_friction.py``
"""
from __future__ import annotations

import numpy as np

import railtherm
from railtherm.report import write_report

STUDY = """
schema_version = 1
[study]
name = "friction-mini"
methods = ["kalker"]
levels = [0]
reference = "kalker"
repeat = 1
[defaults]
normal_force = 100e3
contact = { shape = "ellipse", curvatures = [1.015, 0.4215] }
speed = 30.0
heat_partition = "equal-temperature"
outputs = ["creep_force_x", "max_surface_temperature"]
[[scene]]
name = "const"
creepage = { longitudinal = [-1e-3, -4e-3, -3.2e-2] }
friction = 0.3
[[scene]]
name = "slip"
creepage = { longitudinal = [-1e-3, -4e-3, -3.2e-2] }
friction = { law = "slip-velocity", static = 0.36, kinetic = 0.18, decay = 0.5 }
"""


def test_friction_section_reports_each_curves_maximum(tmp_path):
    path = tmp_path / "friction.toml"
    path.write_text(STUDY)
    out = tmp_path / "out"
    railtherm.run_study(path, out=out, report=False)
    write_report(out)                                  # the report once, as `railtherm report` writes it
    md = (out / "report.md").read_text()
    assert "## Friction laws: creep-force curves and flash temperatures" in md
    assert (out / "figures" / "friction-creep-curves.png").exists()
    assert (out / "figures" / "friction-flash-temperature.png").exists()
    ds = railtherm.open_results(out)
    fx = {s: abs(float(ds.creep_force_x.sel(scene=s, method_name="kalker", level=0))) / 100e3
          for s in ds.scene.values}
    slip_max = max(v for s, v in fx.items() if s.startswith("slip"))
    row = next(line for line in md.splitlines() if line.startswith("| `slip` |"))
    assert f"{slip_max:.4g}" in row and "yes," in row                       # falls after its maximum
    row = next(line for line in md.splitlines() if line.startswith("| `const` |"))
    assert "no (saturates)" in row
    assert np.isclose(max(v for s, v in fx.items() if s.startswith("const")), 0.3, rtol=1e-3)
