"""The figures of the report's section for wheelsets on real profiles (:mod:`.wheelset_section`):

* :func:`curves_figure`: per wheel side, each patch quantity against the wheelset's lateral shift, one curve per
  method (chain, by colour) and patch role (tread: solid line, filled markers; flange: dashed, open markers);
* :func:`shapes_figure`: the patches at :data:`~.wheelset_data.SHAPE_SHIFTS` on the rail profile (each patch's
  lateral extent on the section and its reference point) and seen from above (the reference method's cells in
  contact filled, the other methods' outlined dashed), each patch from its own pressure field.

They draw what :func:`curve_panels` and :func:`patch_shapes` read from the run files.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..output.store import patch_field, patch_numbers
from .figures import figure, save
from .format import num
from .load import StudyData
from .wheelset_data import FLASH, QUANTITIES, SHAPE_SHIFTS, patch_values, role_of

__all__ = ["curve_panels", "curves_figure", "Shape", "patch_shapes", "rail_of", "shapes_figure", "ROLE_STYLE"]

#: line style and marker fill of a patch role in the curves figure
ROLE_STYLE = {"tread": {"ls": "-", "filled": True}, "flange": {"ls": "--", "filled": False},
              "": {"ls": ":", "filled": True}}
SHAPE_COLOURS = ("#1f77b4", "#ff7f0e", "#d62728")


def curve_panels(data: StudyData, members, methods) -> dict:
    """quantity -> (method, role) -> [(shift [mm], value in the plotted unit)], by shift, from the finest
    successful run of each method on each contact ``members`` [(shift [m], scene)]."""
    out: dict = {q: {} for q, *_ in QUANTITIES}
    for m in methods:
        for x, s in members:
            for pv in patch_values(data, s, m):
                for q, factor, _ in QUANTITIES:
                    if q in pv.values:
                        out[q].setdefault((m, pv.role), []).append((x * 1e3, pv.values[q] * factor))
    return out


def _handles(methods, roles, palette):
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    hs = [Line2D([], [], **{**palette.style(m), "ls": "-"}, label=m) for m in methods]
    for role in roles:
        st = ROLE_STYLE[role]
        hs.append(Line2D([], [], color="0.35", ls=st["ls"], marker="o", ms=4, mfc="0.35" if st["filled"] else "white",
                         mec="0.35", label=f"{role} patch" if role else "patch (no contact angle)"))
    return hs


def _log_if_wide(ax, curves) -> None:
    """A logarithmic y axis when the values are all positive and span more than a factor 100 (flash temperatures
    from a tread patch's tenth of a degree to a flange patch's hundreds)."""
    v = np.array([p[1] for pts in curves.values() for p in pts], float)
    if v.size and np.all(v > 0) and v.max() > 100 * v.min():
        ax.set_yscale("log")


def curves_figure(panels, methods, palette, *, path: Path):
    """One column per wheel side, one row per quantity of :data:`QUANTITIES`, one curve per (method, patch
    role) against the lateral shift."""
    sides = list(panels)
    rows = [q for q in QUANTITIES if any(panels[s].get(q[0]) for s in sides)]
    fig = figure(9.5, 1.55 * len(rows) + 0.9)
    axes = np.asarray(fig.subplots(len(rows), len(sides), squeeze=False, sharex="col"))
    roles = set()
    for j, side in enumerate(sides):
        for i, (q, _, ylabel) in enumerate(rows):
            ax = axes[i, j]
            for (m, role), pts in sorted(panels[side].get(q, {}).items(), key=lambda kv: (methods.index(kv[0][0]),
                                                                                         kv[0][1])):
                st = {**palette.style(m, filled=ROLE_STYLE[role]["filled"]), "ls": ROLE_STYLE[role]["ls"]}
                ax.plot([p[0] for p in pts], [p[1] for p in pts], **{**st, "ms": 3.5, "lw": 1.1})
                roles.add(role)
            if q == FLASH:
                _log_if_wide(ax, panels[side][q])
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            if i == 0:
                ax.set_title(f"{side} wheel", fontsize=9)
            if i == len(rows) - 1:
                ax.set_xlabel("lateral shift of the wheelset [mm]", fontsize=8)
    fig.legend(handles=_handles(methods, [r for r in ROLE_STYLE if r in roles], palette), loc="outside lower center",
               ncol=4, fontsize=8, frameon=False)
    return save(fig, path)


# -- the patch shapes on the rail profile ---------------------------------------------------------------------
@dataclass(frozen=True)
class Shape:
    """One patch of one run at a shape shift: its cells with pressure on the rail (lateral y [m] in the rail
    profile's coordinates, x [m] rolling, ``inside`` over (x, y)), its reference point (y, z) on the rail [m],
    role, normal force [N] (NaN when the run has none) and whether that force is the patch's share of the wheel's
    (``shared``: a result of every patch) or the wheel's whole vertical force (a scene of one patch)."""

    shift: float
    patch: int
    role: str
    method: str
    point: tuple
    y: np.ndarray
    x: np.ndarray
    inside: np.ndarray
    normal_force: float
    shared: bool = False


def rail_of(data: StudyData, scene: str):
    """(y, z) [m] of the scene's rail profile in its own coordinates, as the scene keeps it (None without)."""
    section = getattr(getattr(data.scene[scene].scene, "profile_contact", None), "rail_section", None)
    if not section or not len(section[0]):
        return None
    return np.asarray(section[0], float), np.asarray(section[1], float)


def _one_shape(shift, method, pc, pressure, normal_force, shared) -> Shape | None:
    """The cells with pressure of one patch (contact search's patch ``pc``, its ``pressure`` on its own grid) in
    the rail profile's lateral coordinate y = y0 + s cos(delta0) (s across the contact plane, y0 and delta0 the
    plane's origin and angle) and x."""
    y = pc.plane_position_rail + np.asarray(pressure["y"].values, float) * math.cos(pc.plane_angle)
    inside = np.asarray(pressure.transpose("x", "y").values, float) > 0.0
    if not inside.any():
        return None
    return Shape(shift, int(getattr(pc, "patch", 1)), role_of(getattr(pc, "contact_angle", None)), method,
                 (pc.contact_position_rail, pc.contact_height_rail), y, np.asarray(pressure["x"].values, float),
                 inside, normal_force, shared)


def _shapes(data: StudyData, shift: float, scene: str, method: str) -> list[Shape]:
    """The method's patches of ``scene`` with their pressure field: every patch of a result of several patches
    (each on its own grid, :func:`railtherm.contract.patch_grid.patch_field`, with its own share of the load),
    or the one patch of a scene of one patch."""
    r = data.finest_result(scene, method)
    ds = data.run_file(scene, method, r.level) if r is not None else None
    if ds is None or "pressure" not in ds or "y" not in ds["pressure"].dims:
        return []
    pc = data.scene[scene].scene.profile_contact
    numbers = patch_numbers(ds)
    if not numbers:
        n = float(ds["normal_force"]) if "normal_force" in ds else getattr(pc, "normal_force", math.nan)
        one = _one_shape(shift, method, pc, ds["pressure"], n, False)
        return [one] if one is not None else []
    out = []
    for k in numbers:
        if k > len(getattr(pc, "contacts", ())):
            continue
        n = float(ds["normal_force"].sel(patch=k)) if "normal_force" in ds else pc.contacts[k - 1].normal_force
        one = _one_shape(shift, method, pc.contacts[k - 1], patch_field(ds, "pressure", k), n, True)
        if one is not None:
            out.append(one)
    return out


def patch_shapes(data: StudyData, groups, methods) -> dict[str, list[Shape]]:
    """side -> the patches of ``methods`` (the reference first) at :data:`SHAPE_SHIFTS`, by shift and patch: at
    each shift those of the first scene of ``groups`` (:func:`~.wheelset_data.shape_scenes`: every patch of the
    wheel before a scene of one patch) whose runs keep a pressure field."""
    out: dict[str, list] = {}
    for side, members in groups.items():
        for shift in SHAPE_SHIFTS:
            for x, s in members:
                if abs(x - shift) > 1e-9:
                    continue
                found = [sh for m in methods for sh in _shapes(data, shift, s, m)]
                if found:
                    out.setdefault(side, []).extend(found)
                    break
    return {side: sorted(v, key=lambda sh: (sh.shift, sh.patch, methods.index(sh.method)))
            for side, v in out.items()}


def _draw_side(top, plan, rail, shapes, reference):
    """The rail section with each patch of ``reference`` (lateral extent, reference point) on ``top``; the
    patches from above on ``plan``: ``reference``'s filled, the other methods' outlined dashed."""
    ry, rz = rail
    top.plot(ry * 1e3, rz * 1e3, color="0.3", lw=1.0)
    colour = {x: SHAPE_COLOURS[k % len(SHAPE_COLOURS)] for k, x in enumerate(SHAPE_SHIFTS)}
    for sh in shapes:
        c = colour[next(x for x in SHAPE_SHIFTS if abs(x - sh.shift) < 1e-9)]
        f = sh.inside.astype(float)
        if sh.method != reference:
            plan.contour(sh.y * 1e3, sh.x * 1e3, f, levels=[0.5], colors=[c], linewidths=0.9, linestyles="--")
            continue
        cols = sh.inside.any(axis=0)
        yy = np.linspace(sh.y[cols].min(), sh.y[cols].max(), 50)
        force = f", N = {num(sh.normal_force * 1e-3, 3)} kN" if math.isfinite(sh.normal_force) else ""
        top.plot(yy * 1e3, np.interp(yy, ry, rz) * 1e3, color=c, lw=4, solid_capstyle="butt",
                 label=f"{num(sh.shift * 1e3)} mm, {sh.role or 'patch'} {sh.patch}{force}")
        top.plot([sh.point[0] * 1e3], [sh.point[1] * 1e3], "o", color=c, ms=4)
        plan.contourf(sh.y * 1e3, sh.x * 1e3, f, levels=[0.5, 1.5], colors=[c], alpha=0.55)
        plan.annotate(sh.role or str(sh.patch), (sh.y[cols].mean() * 1e3, sh.x[sh.inside.any(axis=1)].max() * 1e3),
                      textcoords="offset points", xytext=(0, 3), ha="center", fontsize=8, color=c)


def shapes_figure(rails, shapes, reference, *, path: Path):
    """Per wheel side: the rail profile with each patch's lateral extent and reference point (top), and the
    patches seen from above on the rail head (bottom)."""
    from matplotlib.lines import Line2D   # matplotlib only where a figure is drawn (the report imports fast)
    sides = list(shapes)
    fig = figure(9.5, 6.4)
    axes = np.asarray(fig.subplots(2, len(sides), squeeze=False, height_ratios=[1, 1.4]))
    others = sorted({sh.method for v in shapes.values() for sh in v if sh.method != reference})
    for j, side in enumerate(sides):
        top, plan = axes[0, j], axes[1, j]
        _draw_side(top, plan, rails[side], shapes[side], reference)
        top.invert_yaxis()
        top.set_title(f"{side} wheel: rail profile (z down) and patches", fontsize=9)
        top.set_ylabel("z on the rail [mm]", fontsize=8)
        top.set_xlabel("lateral position on the rail [mm]", fontsize=8)
        plan.set_xlabel("lateral position on the rail, rail profile's coordinates [mm]", fontsize=8)
        plan.set_ylabel("x, rolling direction [mm]", fontsize=8)
        plan.set_xlim(top.get_xlim())
        for ax in (top, plan):
            ax.grid(True, alpha=0.3)
            ax.tick_params(labelsize=7)
        handles, _ = top.get_legend_handles_labels()
        handles += [Line2D([], [], color="0.3", ls="--", lw=0.9, label=f"{m} (outline)") for m in others]
        top.legend(handles=handles, fontsize=7.5, frameon=False, loc="lower left")
    return save(fig, path)
