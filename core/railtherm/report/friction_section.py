"""The report's friction-law section: creep-force curves and flash temperatures under friction laws.

Shown when a study sweeps the longitudinal creepage of scenes whose ``friction`` is a law (slip-velocity,
Polach, temperature; :mod:`railtherm.physics.friction`). For every such sweep (and the constant-friction
sweeps beside them) at each method's finest successful level:

* the creep-force curves |Fx| / N against |xi| of every method, one panel per sweep, with the law's own
  bounds (dotted: mu at zero slip / reference temperature, and its least value);
* the flash temperature (maximum surface temperature of the wheel) against |xi|;
* a table of each curve's maximum |Fx| / N and the creepage where it lies, the difference of every method's
  maximum (and of its creepage) against the study's reference method, and whether the curve falls after its
  maximum (by how much at the largest creepage): falling friction makes the creep curve fall after its peak,
  constant friction saturates at mu N.

The report computes no physics: every value is a run file's.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .document import Document
from .exact_contact import _value
from .figures import figure, save
from .format import num, pct
from .load import StudyData

__all__ = ["friction_sweeps", "friction_section"]

SWEPT = "creepage.longitudinal"


def friction_sweeps(data: StudyData) -> dict[str, list[tuple[float, str]]]:
    """Scene base -> [(|xi|, scene)] of the longitudinal-creepage sweeps, when one of them has a friction law."""
    groups: dict[str, list] = {}
    laws = False
    for s in data.scenes:
        info = data.scene[s]
        sw = info.sweep
        if SWEPT not in sw or len(sw) != 1 or info.scene is None:
            continue
        groups.setdefault(info.base, []).append((abs(float(sw[SWEPT])), s))
        laws = laws or info.scene.friction.kind != "constant"
    if not laws:
        return {}
    return {k: sorted(v) for k, v in groups.items() if len(v) >= 3}


def _curve(data: StudyData, members, method: str, q: str, norm: bool):
    pts = []
    for xi, s in members:
        v = _value(data, s, method, q)
        if v is None:
            continue
        y = abs(v[0])
        if norm:
            n = _value(data, s, method, "normal_force")
            if n is None or not n[0]:
                continue
            y /= n[0]
        pts.append((xi, y))
    return pts


def _peak(pts):
    """(max, creepage at max, relative drop from the max to the last point) of a curve."""
    if not pts:
        return None
    k = int(np.argmax([p[1] for p in pts]))
    mx, at = pts[k][1], pts[k][0]
    drop = (mx - pts[-1][1]) / mx if mx else 0.0
    return mx, at, drop, k < len(pts) - 1


def _figure(panels, methods, palette, quantity: str, *, path: Path):
    """One panel per sweep: the quantity against |xi| (log axis) for every method."""
    n = len(panels)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig = figure(10, 2.9 * rows + 0.6)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    handles = {}
    for ax, (title, curves, bounds) in zip(axes, panels):
        for m in methods:
            pts = curves.get(m)
            if not pts:
                continue
            (h,) = ax.plot([p[0] for p in pts], [p[1] for p in pts], **palette.style(m), label=m)
            handles.setdefault(m, h)
        for b in bounds:
            ax.axhline(b, color="0.45", lw=0.8, ls=":")
        ax.set_xscale("log")
        ax.set_title(title, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("|ξ| [1]", fontsize=8)
        ax.set_ylabel(quantity, fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.legend(handles=list(handles.values()), loc="outside lower center", ncol=min(len(handles), 4), fontsize=8,
               frameon=False)
    return save(fig, path)


def friction_section(doc: Document, ctx):
    """Write the section (nothing when no creepage sweep has a friction law)."""
    data = ctx.data
    sweeps = friction_sweeps(data)
    if not sweeps:
        return
    methods = [m for m in data.methods if any(data.finest_result(s, m) for v in sweeps.values() for _, s in v)]
    ref = data.scene[next(iter(sweeps.values()))[0][1]].reference_kind
    ref = ref if ref in methods else None
    doc.heading(2, "Friction laws: creep-force curves and flash temperatures", "friction-laws")
    doc.paragraph("Each longitudinal-creepage sweep at each method's finest successful level. Friction laws apply "
                  "cell by cell; a temperature law is iterated with the chain's temperatures (core's coupled loop). "
                  "Falling friction makes the creep curve fall after its maximum; constant friction saturates at μ N."
                  + (f" Differences are against the study's reference method `{ref}`." if ref else ""))
    force_panels, temp_panels, rows, laws = [], [], [], {}
    for base, members in sweeps.items():
        law = data.scene[members[0][1]].scene.friction
        sc = data.scene[members[0][1]].scene
        title = f"{base}: {law.kind}, {sc.speed:g} m/s"
        laws.setdefault(law.describe(), []).append(base)
        forces = {m: _curve(data, members, m, "creep_force_x", True) for m in methods}
        temps = {m: _curve(data, members, m, "max_surface_temperature", False) for m in methods}
        force_panels.append((title, forces, sorted(set(law.bounds))))
        temp_panels.append((title, temps, []))
        peaks = {m: _peak(p) for m, p in forces.items()}
        for m in methods:
            pk = peaks.get(m)
            if pk is None:
                continue
            mx, at, drop, interior = pk
            rp = peaks.get(ref) if ref else None
            d_max = pct((mx - rp[0]) / rp[0], signed=True) if rp and m != ref and rp[0] else "–"
            d_at = pct((at - rp[1]) / rp[1], signed=True) if rp and m != ref and rp[1] else "–"
            falls = f"yes, {pct(drop)} below its maximum at |ξ| = {num(forces[m][-1][0], 3)}" if interior and drop > 1e-3 \
                else "no (saturates)"
            tmax = temps[m][-1][1] if temps.get(m) else math.nan
            rows.append([f"`{base}`", law.kind, f"`{m}`", num(mx, 4), num(at, 3), d_max, d_at, falls,
                         num(tmax, 4)])
    doc.table("Maximum of each creep curve |Fx| / N [1], the creepage |ξ| [1] where it lies, their differences "
              f"against {f'`{ref}`' if ref else 'the reference'} [%], whether the curve falls after its maximum, and "
              "the flash temperature (max. surface temperature of the wheel) at the largest creepage [°C].",
              ["sweep", "law", "method", "max |Fx| / N [1]", "at |ξ| [1]", "Δ max [%]", "Δ |ξ| of max [%]",
               "falls after the max", "T_max at largest |ξ| [°C]"], rows)
    doc.paragraph("Friction laws: " + "; ".join(f"{', '.join(f'`{b}`' for b in bases)}: {d}" for d, bases in laws.items())
                  + ".")
    ctx.draw(doc, "friction-creep-curves", "Creep-force curves |Fx| / N against |ξ| under each friction law (dotted: "
             "the law's bounds on μ).", _figure, force_panels, methods, ctx.palette, "|Fx| / N [1]")
    ctx.draw(doc, "friction-flash-temperature", "Flash temperature (maximum surface temperature of the wheel) "
             "against |ξ| under each friction law.", _figure, temp_panels, methods, ctx.palette, "T_max [°C]")
