"""A wheelset on profiles with several patches (``wheelset.patch = "all"``): each loaded patch is solved by the
chain as a scene of its own (its gap, its share of the wheel's vertical force from one common approach, its
creepages; :func:`railtherm.input.wheelset_patch_scenes.patch_scenes`), and the results are stacked along the
dimension ``patch`` (1 = the closest; last: ``max_surface_temperature(body, patch)``) with the wheel's totals
added: ``wheel_force_x/y/z`` [N], the rail's force on the wheel in track axes (x rolling, y lateral, z up; the
left wheel's y mirrored as its patches'), from each patch's normal force N, creep forces Fx, Fy (on the wheel,
in its contact plane) and contact angle delta: Fx, Fy cos(delta) + N sin(delta), N cos(delta) - Fy sin(delta).
A field asked (``pressure(x, y)``, ``surface_temperature(body, x, y)``, ...) is kept per patch although each
patch has its own grid: CF's incomplete multidimensional representation, the grid dimensions ``x``, ``y``, ``z``
without an index (the cell's number), the auxiliary coordinates ``patch_x(x, patch)``, ``patch_y(y, patch)``,
``patch_z(z, patch)`` [m] giving each patch's own grid, and every patch padded with NaN beyond its cells (the
field's name in the attribute ``nan_allowed``); :func:`railtherm.contract.patch_grid.patch_field` returns one
patch's field on its own grid.
"""
from __future__ import annotations

import numpy as np

from ..contract.patch_grid import GRID_DIMS, PADDING_COMMENT, patch_coord_attrs
from ..contract.schema import WHEEL_TOTALS, validate_dataset, variable_attrs
from ..input.wheelset_patch_scenes import TOTALS_NEED, patch_scenes

__all__ = ["solve_patches", "wheel_totals"]


def wheel_totals(normal, creep_x, creep_y, angle) -> tuple[float, float, float]:
    """(Fx, Fy, Fz) [N] of the rail on the wheel in the wheel's track axes (z up) from its patches' normal forces
    [N], creep forces on the wheel in their contact planes [N] and contact angles [rad]."""
    n, fx, fy, d = (np.asarray(v, float) for v in (normal, creep_x, creep_y, angle))
    return (float(fx.sum()), float((fy * np.cos(d) + n * np.sin(d)).sum()),
            float((n * np.cos(d) - fy * np.sin(d)).sum()))


# whole scene: a solve driver above the stage hooks; it splits the scene into one scene per patch for solve_one
def solve_patches(scene, method, level, options, *, solve_one, validate: bool = True, **kw):
    """Solve every loaded patch of ``scene`` with ``solve_one(sub_scene, method, level, options, validate=...,
    **kw)`` (the pipeline's single-patch solve) and stack the results (module docstring)."""
    import xarray as xr  # here: about 0.5 s to import, paid only by a scene of every patch
    asked = [o for o in scene.outputs if o not in WHEEL_TOTALS]
    totals = [o for o in scene.outputs if o in WHEEL_TOTALS]
    need = asked + [o for o in (TOTALS_NEED if totals else ()) if o not in asked]
    results = [solve_one(sub, method, level, options, validate=validate, **kw) for sub in patch_scenes(scene, need)]
    kept = _padded([_kept(ds, asked) for ds in results])
    padded = sorted({v for part in kept for v, da in part.data_vars.items() if set(da.dims) & set(GRID_DIMS)})
    grids = [c for c in kept[0].coords if c.startswith("patch_")]
    out = xr.concat(kept, dim="patch", data_vars="all", coords=grids or "minimal", compat="override",
                    combine_attrs="override")
    out = out.transpose(..., "patch").assign_coords(
        patch=("patch", np.arange(1, len(kept) + 1), {"units": "1",
                                                      "long_name": "patch of the wheel (1 = the closest)"}))
    for name in out.data_vars:
        out[name].attrs = dict(results[0][name].attrs)
    for d in GRID_DIMS:
        if f"patch_{d}" in out.coords:
            out[f"patch_{d}"].attrs = patch_coord_attrs(d)
    if totals:
        mirror = 1.0 if scene.profile_contact.side == "right" else -1.0
        fx, fy, fz = wheel_totals(*(out[q].values for q in TOTALS_NEED))
        for name, value in zip(WHEEL_TOTALS, (fx, mirror * fy, fz)):
            out[name] = ((), value, variable_attrs(name))
    pc = scene.profile_contact
    out.attrs.update({
        "title": f"railtherm result: scene {scene.name}, method {out.attrs.get('method')}, level {level}",
        "scene": scene.name, "scene_hash": scene.hash, "outputs": " ".join(scene.outputs),
        "wall_time": float(sum(float(r.attrs.get("wall_time", 0.0)) for r in results)),
        "converged": int(min(int(r.attrs.get("converged", 1)) for r in results)),
        "wheelset_patch": "all", "wheelset_patches": len(results),
        "wheelset_approach": float(pc.approach),
        "wheelset_lateral_force_estimate": [float(c.lateral_force_estimate) for c in pc.contacts],
        "comment": "diagnostics (<model>_*) are the first patch's; every patch converged"
                   if all(int(r.attrs.get("converged", 1)) for r in results) else
                   "diagnostics (<model>_*) are the first patch's; a patch did not converge",
    })
    if padded:   # the fields' padding beyond each patch's cells
        have = set(str(out.attrs.get("nan_allowed", "")).split())
        out.attrs["nan_allowed"] = " ".join(sorted(have | set(padded)))
        for name in padded:
            out[name].attrs["comment"] = PADDING_COMMENT
    if validate:
        validate_dataset(out, str(out.attrs.get("method")))
    return out


def _kept(ds, asked):
    """What a patch's result keeps in the stack: its quantities without a grid and the fields asked, the grid's
    index coordinates ``x``, ``y``, ``z`` turned into the auxiliary coordinates ``patch_x``, ... (module
    docstring)."""
    keep = [v for v, da in ds.data_vars.items()
            if set(da.dims) <= {"body"} or (v in asked and set(da.dims) <= {"body", *GRID_DIMS})]
    part = ds[keep]
    grids = {f"patch_{d}": (d, np.asarray(ds[d].values, float)) for d in GRID_DIMS
             if d in part.dims and d in ds.coords}
    part = part.drop_vars([c for c in part.coords if c != "body"])
    return part.assign_coords(grids)


def _padded(parts):
    """The patches' parts padded with NaN to the largest grid of each dimension (fields and coordinates)."""
    size = {d: max(p.sizes.get(d, 0) for p in parts) for d in GRID_DIMS}
    out = []
    for p in parts:
        widths = {d: (0, size[d] - p.sizes[d]) for d in GRID_DIMS if d in p.dims and p.sizes[d] < size[d]}
        out.append(p.pad(widths, constant_values=np.nan) if widths else p)
    return out
