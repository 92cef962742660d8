"""The fields of a result of several patches (a wheelset on profiles with ``wheelset.patch = "all"``), each patch
on its own grid: CF's incomplete multidimensional representation. The grid dimensions ``x``, ``y``, ``z`` have no
index (a cell's number); the auxiliary coordinates ``patch_x(x, patch)``, ``patch_y(y, patch)``,
``patch_z(z, patch)`` [m] give each patch's own grid, and a patch's field and coordinates are NaN beyond its
cells. :func:`patch_field` returns one patch's field on its own grid, the layout of a result of one patch.
"""
from __future__ import annotations

import numpy as np

from .schema import coord_attrs

__all__ = ["GRID_DIMS", "PATCH_DIM", "PADDING_COMMENT", "patch_coord_attrs", "patch_field", "patch_numbers"]

#: the grid dimensions of a field, padded patch by patch
GRID_DIMS = ("x", "y", "z")
#: the dimension of a result's patches
PATCH_DIM = "patch"
#: the ``comment`` attribute of a padded field
PADDING_COMMENT = "each patch on its own grid (patch_x, patch_y, patch_z); NaN beyond that patch's cells"


def patch_coord_attrs(dim: str) -> dict:
    """CF ``units`` and ``long_name`` of the auxiliary coordinate ``patch_<dim>`` (each patch's grid along
    ``dim``, one of :data:`GRID_DIMS`)."""
    attrs = coord_attrs(dim)
    return {"units": attrs["units"], "long_name": f"{attrs['long_name']}, each patch's own grid (NaN beyond its "
                                                  "cells)"}


def patch_numbers(ds) -> list[int]:
    """The patch numbers [1] of a result (``[]`` for a result without a ``patch`` dimension)."""
    return [int(p) for p in ds[PATCH_DIM].values] if PATCH_DIM in ds.dims else []


def patch_field(ds, name: str, patch: int | None = None):
    """Field ``name`` of patch ``patch`` [1] on that patch's own grid: its padding dropped and ``patch_x``,
    ``patch_y``, ``patch_z`` [m] made the index coordinates ``x``, ``y``, ``z`` again (with their CF attributes).
    A result without a ``patch`` dimension gives its field as it is (``patch`` ignored).

    Parameters
    ----------
    ds : xarray.Dataset
        A result (docs/DESIGN.md "Result schema").
    name : str
        A field of it, e.g. ``"pressure"``.
    patch : int, optional
        The patch number (1 = the closest); required when the result has patches.
    """
    da = ds[name]
    if PATCH_DIM not in da.dims:
        return da
    if patch is None or patch not in patch_numbers(ds):
        raise ValueError(f"result field {name!r}: patch {patch!r} is not one of its patches {patch_numbers(ds)}")
    da = da.sel({PATCH_DIM: patch})
    for d in GRID_DIMS:
        c = f"patch_{d}"
        if d not in da.dims or c not in da.coords:
            continue
        values = np.asarray(da[c].values, float)
        n = int(np.isfinite(values).sum())
        da = da.isel({d: slice(0, n)}).drop_vars(c).assign_coords({d: (d, values[:n], coord_attrs(d))})
    da = da.drop_vars([c for c in da.coords if c == PATCH_DIM or c.startswith("patch_")])
    if str(da.attrs.get("comment", "")).startswith(PADDING_COMMENT):
        da.attrs = {k: v for k, v in da.attrs.items() if k != "comment"}
    return da
