"""The result schema: one xarray Dataset per scene x method x level, CF-1.11 attributes.

:data:`VARIABLES` is the one place where each result variable's dimensions, units and long name are
defined. :func:`build_dataset` turns stage results into a Dataset; :func:`validate_dataset` is run on
every result before it is stored and names the plugin and the variable that break the schema.
"""
from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass

import math

import numpy as np

from .errors import PluginError
from .grid import embed

SCHEMA_VERSION = 1
TEMP_ABS = "temperature: on_scale"


@dataclass(frozen=True)
class Var:
    dims: tuple[str, ...]
    units: str
    long_name: str
    stage: str  # stage that produces it: normal | tangential | heat_source | temperature | steady
    temperature: bool = False


#: name -> Var. ``y`` is dropped from dims for line contacts.
VARIABLES: dict[str, Var] = {
    "pressure": Var(("x", "y"), "Pa", "normal contact pressure", "normal"),
    "traction_x": Var(("x", "y"), "Pa", "tangential traction on the wheel, rolling direction", "tangential"),
    "traction_y": Var(("x", "y"), "Pa", "tangential traction on the wheel, lateral", "tangential"),
    "slip_velocity_x": Var(("x", "y"), "m s-1", "local slip velocity of wheel relative to rail, rolling direction", "tangential"),
    "slip_velocity_y": Var(("x", "y"), "m s-1", "local slip velocity of wheel relative to rail, lateral", "tangential"),
    "stick": Var(("x", "y"), "1", "stick indicator (1 stick, 0 slip, NaN outside the patch)", "tangential"),
    "heat_flux": Var(("body", "x", "y"), "W m-2", "frictional heat flux entering the body", "heat_source"),
    "surface_temperature": Var(("body", "x", "y"), "degC", "surface temperature", "temperature", True),
    "temperature": Var(("body", "x", "z"), "degC", "temperature at y = 0", "temperature", True),
    "normal_force": Var((), "N", "normal force (per unit width [N m-1] for a line contact)", "normal"),
    "semi_axis_a": Var((), "m", "contact semi-axis along the rolling direction", "normal"),
    "semi_axis_b": Var((), "m", "lateral contact semi-axis", "normal"),
    "max_pressure": Var((), "Pa", "maximum contact pressure", "normal"),
    "contact_area": Var((), "m2", "area of the contact patch (its length 2a [m] for a line contact)", "normal"),
    "creep_force_x": Var((), "N", "longitudinal creep force on the wheel", "tangential"),
    "creep_force_y": Var((), "N", "lateral creep force on the wheel", "tangential"),
    "spin_moment": Var((), "N m", "spin moment on the wheel", "tangential"),
    "frictional_power": Var((), "W", "frictional power (per unit width [W m-1] for a line contact)", "heat_source"),
    "heat_partition": Var((), "1", "fraction of the frictional heat entering the wheel", "heat_source"),
    "max_surface_temperature": Var(("body",), "degC", "maximum surface temperature", "temperature", True),
    "mean_contact_temperature": Var(("body",), "degC", "mean surface temperature over the contact patch", "temperature", True),
    "steady_wheel_temperature": Var((), "degC", "steady-state (long-term) wheel bulk temperature", "steady", True),
    "steady_mean_contact_temperature": Var((), "degC", "steady-state mean contact temperature", "steady", True),
    # the thermal trace (scene key ``field``; railtherm.physics.thermal_trace)
    "peak_temperature": Var(("body", "z"), "degC", "highest temperature a material point on the centre line "
                            "y = 0 reaches at depth z during the pass", "temperature", True),
    "cooling_rate": Var(("body", "z"), "K s-1", "fastest cooling -dT/dt = V dT/dx of a material point on the "
                        "centre line at depth z after its peak temperature", "temperature"),
    "heated_depth": Var(("body",), "m", "depth down to which the peak temperature exceeds field.threshold",
                        "temperature"),
    "time_above": Var(("body", "z"), "s", "time a material point on the centre line at depth z spends above "
                      "field.threshold", "temperature"),
    # transient scenes (mode = "transient"; railtherm.input.transient): the material point on the centre line
    # y = 0 at the fixed section, at the depths z of field.depth, over the passes
    "temperature_history": Var(("body", "time", "z"), "degC", "temperature of the material point on the centre "
                               "line y = 0 at the fixed section, at depth z, over the passes", "temperature", True),
    "pass_peak_temperature": Var(("body", "pass", "z"), "degC", "highest temperature of the material point at "
                                 "depth z during each pass", "temperature", True),
    "residual_rise": Var(("body", "pass"), "K", "surface temperature rise above the bulk temperature left by each "
                         "pass just before the next (after the last: one interval after it)", "temperature"),
    # a wheelset on real profiles (railtherm.input.wheelset_profile): the scene's patch as the contact search
    # placed it and the creepages it rolls with, the same for every chain
    "contact_position_rail": Var((), "m", "lateral position of the patch's reference point on the rail, in the "
                                 "rail profile's own coordinates", "normal"),
    "contact_angle": Var((), "rad", "angle of the patch's contact plane against the track plane", "normal"),
    "creepage_longitudinal": Var((), "1", "longitudinal creepage of the wheel relative to the rail", "normal"),
    "creepage_lateral": Var((), "1", "lateral creepage of the wheel relative to the rail, in the contact plane",
                            "normal"),
    "creepage_spin": Var((), "m-1", "spin creepage of the wheel relative to the rail", "normal"),
    # a wheelset on profiles with wheelset.patch = "all": the rail's force on the wheel summed over its patches,
    # in track axes (x rolling, y lateral, z up; the left wheel's y mirrored as its patches')
    "wheel_force_x": Var((), "N", "longitudinal force of the rail on the wheel, sum over its patches", "tangential"),
    "wheel_force_y": Var((), "N", "lateral force of the rail on the wheel in track axes, sum over its patches",
                         "tangential"),
    "wheel_force_z": Var((), "N", "vertical force of the rail on the wheel, sum over its patches", "tangential"),
}

#: the patch quantities of a wheelset on profiles: set by the scene's contact search whatever the models
#: (no model declares them in ``provides``), only in a scene with a wheelset on profiles
WHEELSET_VARIABLES = ("contact_position_rail", "contact_angle", "creepage_longitudinal", "creepage_lateral",
                      "creepage_spin")

#: the wheel's totals over its patches (a wheelset on profiles with ``patch = "all"``, whose other variables
#: carry the dimension ``patch`` last)
WHEEL_TOTALS = ("wheel_force_x", "wheel_force_y", "wheel_force_z")

#: variables that are a temperature difference [K] (CF-1.11 ``units_metadata``)
TEMP_DIFF = "temperature: difference"
DIFFERENCE_VARIABLES = ("residual_rise",)

#: variables whose dims differ in a transient scene (the time above the threshold per pass)
TRANSIENT_DIMS = {"time_above": ("body", "pass", "z")}
TRANSIENT_LONG_NAMES = {"time_above": "time a material point on the centre line at depth z spends above "
                                      "field.threshold during each pass"}

#: the thermal-trace variables: NaN where the field is too short to tell (never a false peak)
TRACE_VARIABLES = ("peak_temperature", "cooling_rate", "heated_depth", "time_above")

COORDS = {
    "x": ("m", "rolling direction, origin at the patch centre, leading edge at +a"),
    "y": ("m", "lateral coordinate"),
    "z": ("m", "depth into the body"),
    "body": ("1", "body (wheel = body 1, rail = body 2)"),
    "time": ("s", "time since the first pass's leading edge reached the fixed section"),
    "pass": ("1", "pass over the fixed section (a revolution for the wheel), counted from 1"),
}

#: which pipeline stage produces the variables of each Var.stage group
STAGE_OF_GROUP = {"normal": "normal", "tangential": "tangential", "heat_source": "heat_source",
                  "temperature": "temperature", "steady": "temperature"}


def dims_for(name: str, line: bool, transient: bool = False, patched: bool = False) -> tuple[str, ...]:
    """The schema's dims of a variable (``y`` dropped for a line contact; a transient scene's per-pass
    dims where they differ, :data:`TRANSIENT_DIMS`; ``patch`` last in a result of several patches, but for
    the wheel's totals: ``max_surface_temperature(body, patch)``)."""
    dims = TRANSIENT_DIMS.get(name, VARIABLES[name].dims) if transient else VARIABLES[name].dims
    dims = tuple(d for d in dims if not (line and d == "y"))
    return dims + ("patch",) if patched and name not in WHEEL_TOTALS else dims


def stages_needed(outputs) -> set[str]:
    """Pipeline stages an output list needs (before any model is consulted)."""
    return {STAGE_OF_GROUP[VARIABLES[o].stage] for o in outputs}


def variable_attrs(name: str, transient: bool = False) -> dict:
    v = VARIABLES[name]
    attrs = {"units": v.units, "long_name": TRANSIENT_LONG_NAMES.get(name, v.long_name) if transient else v.long_name}
    if v.temperature:
        attrs["units_metadata"] = TEMP_ABS
    elif name in DIFFERENCE_VARIABLES:
        attrs["units_metadata"] = TEMP_DIFF
    return attrs


def coord_attrs(name: str) -> dict:
    units, long_name = COORDS[name]
    return {"units": units, "long_name": long_name}


def build_dataset(grid, patch=None, source=None, temperature=None, *, outputs=(), attrs=None, wheelset=None):
    """Assemble a result Dataset from the stage results that exist.

    Every variable a stage computed is included (what was asked and what was computed); nothing
    is invented for stages that did not run. When the temperature field lies on an extended grid
    (``temperature.grid``, a scene with ``field``), that grid is the result's: the contact and heat
    fields are put on it with zeros behind the patch (``stick`` NaN, :func:`railtherm.contract.grid.embed`).
    ``wheelset`` (a scene's :class:`railtherm.input.wheelset_profile.ProfileContact`) adds the
    :data:`WHEELSET_VARIABLES` of its patch, and the global attributes ``wheelset_side``, ``wheelset_patch``
    (which patch, 1 = the closest), ``wheelset_patches`` (distinct patches found) and
    ``wheelset_lateral_force_estimate`` [N] (the lateral force the normal force was balanced with).
    """
    import xarray as xr  # here: ~0.5 s to import, and `import railtherm` (a pytest plugin) loads none

    line = grid.line
    data: dict[str, tuple] = {}
    base = grid
    tgrid = getattr(temperature, "grid", None) if temperature is not None else None
    if tgrid is not None and tgrid.shape != grid.shape:
        grid = tgrid
    nan_ok: list[str] = []

    def put(name, value):
        if value is None:
            return
        arr = np.asarray(value, dtype=float)
        dims = dims_for(name, line)
        if grid is not base and "x" in dims and arr.shape[dims.index("x")] == base.x.size:   # a patch field
            arr = embed(arr, base, grid, fill=np.nan if name == "stick" else 0.0)
        data[name] = (dims, arr)

    if patch is not None:
        _put_patch(put, patch, line)
    reference = None
    if wheelset is not None and patch is not None:
        reference = _put_wheelset(put, wheelset, patch, attrs or {})
    if source is not None:
        _put_source(put, source)
    if temperature is not None:
        _put_temperature(put, data, temperature, nan_ok)

    coords, transient = _coords(grid, line, temperature, data)
    ds = xr.Dataset(data, coords=coords)
    for name in ds.data_vars:
        ds[name].attrs.update(variable_attrs(name, transient))
    for name in ds.coords:
        ds[name].attrs.update(coord_attrs(name))
    for name in nan_ok:
        ds[name].attrs["comment"] = ("NaN where the field is too short to tell: the peak (or the fastest cooling, "
                                     "or the time above the threshold) reaches the end of the field; see the "
                                     "temperature model's trace_* diagnostics")
    ds.attrs.update({"Conventions": "CF-1.11", "schema_version": SCHEMA_VERSION})
    ds.attrs.update(attrs or {})
    if wheelset is not None:
        ds.attrs.update({"wheelset_side": wheelset.side, "wheelset_patch": int(wheelset.patch),
                         "wheelset_patches": int(wheelset.patches),
                         "wheelset_lateral_force_estimate": float(wheelset.lateral_force_estimate)})
        if reference is not None:
            ds.attrs["wheelset_reference_point"] = reference
        if getattr(wheelset, "balanced_roll", None) is not None:   # roll_angle = "balance": the roll found
            ds.attrs["wheelset_roll_angle"] = float(wheelset.balanced_roll)
            ds.attrs["wheelset_roll_balance"] = str(getattr(wheelset, "roll_balance", ""))
    if nan_ok:
        ds.attrs["nan_allowed"] = " ".join(sorted(set(str(ds.attrs.get("nan_allowed", "")).split()) | set(nan_ok)))
    return ds



def _put_patch(put, patch, line) -> None:
    """The contact patch's fields and scalars (no lateral ones on a line contact)."""
    put("pressure", patch.pressure)
    for k in ("traction_x", "traction_y", "slip_velocity_x", "slip_velocity_y", "stick",
              "creep_force_x", "creep_force_y", "spin_moment"):
        if line and k in ("traction_y", "slip_velocity_y", "creep_force_y", "spin_moment"):
            continue
        put(k, getattr(patch, k))
    put("normal_force", patch.normal_force)
    put("semi_axis_a", patch.a)
    if not line:
        put("semi_axis_b", patch.b)
    put("max_pressure", patch.max_pressure)
    if patch.contact_area is not None:
        put("contact_area", patch.contact_area)
    elif patch.a is not None:
        put("contact_area", 2.0 * patch.a if line else math.pi * patch.a * patch.b)


def _put_wheelset(put, wheelset, patch, attrs) -> str:
    """The wheelset patch's position, contact angle and creepages at its reference point
    (:meth:`railtherm.input.wheelset_profile.ProfileContact.reported_reference`): the CONTACT program's at the
    approach of a normal stage that solved the patch's sampled gap (its diagnostics ``sampled_gap`` and
    ``approach`` among the result's ``attrs``), else the contact search's. Returns how it was found (the result
    attribute ``wheelset_reference_point``)."""
    stages = dict(part.split(":", 1) for part in str(attrs.get("stages", "")).split() if ":" in part)
    normal = stages.get("normal")
    approach = attrs.get(f"{normal}_approach") if normal and attrs.get(f"{normal}_sampled_gap") else None
    ref = wheelset.reported_reference(approach)
    put("contact_position_rail", ref["y_rail"])
    put("contact_angle", ref["angle"])
    xi, eta, phi = patch.creepage if patch.creepage is not None else ref["creepage"]
    put("creepage_longitudinal", xi)
    put("creepage_lateral", eta)
    put("creepage_spin", phi)
    return ref["how"]


def _put_source(put, source) -> None:
    """The heat flux into both bodies, the frictional power and a uniform heat partition."""
    put("heat_flux", np.stack([source.flux(0), source.flux(1)]))
    put("frictional_power", source.frictional_power)
    eps = np.asarray(source.heat_partition, dtype=float)
    if eps.ndim == 0:
        put("heat_partition", eps)


def _put_temperature(put, data, temperature, nan_ok) -> None:
    """The temperature fields and scalars, the pass history of a transient scene or the thermal trace (its
    variables that are not finite everywhere are listed in ``nan_ok``)."""
    put("surface_temperature", temperature.surface_temperature)
    put("max_surface_temperature", temperature.max_surface_temperature)
    put("mean_contact_temperature", temperature.mean_contact_temperature)
    if temperature.temperature is not None and temperature.z is not None:
        put("temperature", temperature.temperature)
    put("steady_wheel_temperature", temperature.steady_wheel_temperature)
    put("steady_mean_contact_temperature", temperature.steady_mean_contact_temperature)
    history = getattr(temperature, "history", None)
    if history is not None:
        _put_history(data, history)
    elif temperature.z is not None:
        for name in TRACE_VARIABLES:
            value = getattr(temperature, name, None)
            put(name, value)
            if value is not None and not np.all(np.isfinite(np.asarray(value, dtype=float))):
                nan_ok.append(name)


def _coords(grid, line, temperature, data):
    """The result's coordinates (x, body, y, z; time, z and pass of a pass history) and whether it is transient."""
    coords = {"x": ("x", grid.x), "body": ("body", np.array(["wheel", "rail"]))}
    if not line:
        coords["y"] = ("y", grid.y)
    if temperature is not None and temperature.z is not None and (
            "temperature" in data or any(n in data for n in TRACE_VARIABLES)):
        coords["z"] = ("z", np.asarray(temperature.z, dtype=float))
    transient = temperature is not None and getattr(temperature, "history", None) is not None
    if transient:
        h = temperature.history
        coords.update({"time": ("time", np.asarray(h.time, dtype=float)), "z": ("z", np.asarray(h.z, dtype=float)),
                       "pass": ("pass", np.arange(1, np.asarray(h.residual).shape[1] + 1))})
    return coords, transient


def _put_history(data: dict, history) -> None:
    """The transient variables of a :class:`railtherm.contract.transient.TransientHistory` into ``data``."""
    data["temperature_history"] = (VARIABLES["temperature_history"].dims, np.asarray(history.temperature, float))
    data["pass_peak_temperature"] = (VARIABLES["pass_peak_temperature"].dims, np.asarray(history.peak, float))
    data["residual_rise"] = (VARIABLES["residual_rise"].dims, np.asarray(history.residual, float))
    if history.time_above is not None:
        data["time_above"] = (TRANSIENT_DIMS["time_above"], np.asarray(history.time_above, float))


def history_line(text: str) -> str:
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    return f"{now} {text}"


REQUIRED_ATTRS = ("Conventions", "title", "source", "history", "method", "scene", "scene_hash", "level")


def _all_finite(values: np.ndarray) -> bool:
    """True when no element is NaN or inf: the sum is finite unless one is (or the sum overflows, then the
    elements are checked one by one), without an array of booleans per field."""
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(np.sum(values)):
            return True
    return bool(np.all(np.isfinite(values)))


def validate_dataset(ds, plugin: str = "?", *, check_attrs: bool = True) -> None:
    """Check a result against the schema; raise :class:`railtherm.PluginError` naming plugin and variable.

    Checks: every variable is known, has the schema's dims, ``units`` and ``long_name``; temperatures
    carry ``units_metadata``; coordinates carry units; global attributes are present; no variable
    holds NaN where the schema does not allow it (only ``stick`` may be NaN outside the patch, and
    fields may be NaN outside their body's domain when the model says so in ``nan_allowed``).
    """
    line = "y" not in ds.dims
    transient = "pass" in ds.dims
    patched = "patch" in ds.dims
    nan_ok = set(str(ds.attrs.get("nan_allowed", "")).split()) | {"stick"}
    for name, da in ds.data_vars.items():
        if name not in VARIABLES:
            raise PluginError(f"plugin {plugin!r}: result variable {name!r} is not in the result schema "
                              f"(known: {', '.join(VARIABLES)})")
        want = dims_for(name, line, transient, patched)
        if tuple(da.dims) != want:
            raise PluginError(f"plugin {plugin!r}: variable {name!r} has dims {tuple(da.dims)}, the schema wants {want}")
        for key in ("units", "long_name"):
            if not da.attrs.get(key):
                raise PluginError(f"plugin {plugin!r}: variable {name!r} has no {key!r} attribute")
        if da.attrs["units"] != VARIABLES[name].units:
            raise PluginError(f"plugin {plugin!r}: variable {name!r} has units {da.attrs['units']!r}, "
                              f"the schema wants {VARIABLES[name].units!r}")
        if VARIABLES[name].temperature and not da.attrs.get("units_metadata"):
            raise PluginError(f"plugin {plugin!r}: temperature {name!r} has no 'units_metadata'")
        if name not in nan_ok and np.issubdtype(da.dtype, np.floating) and not _all_finite(da.values):
            raise PluginError(f"plugin {plugin!r}: variable {name!r} holds NaN or inf")
    for name, da in ds.coords.items():
        if not da.attrs.get("units") or not da.attrs.get("long_name"):
            raise PluginError(f"plugin {plugin!r}: coordinate {name!r} lacks 'units' or 'long_name'")
    if check_attrs:
        missing = [a for a in REQUIRED_ATTRS if a not in ds.attrs]
        if missing:
            raise PluginError(f"plugin {plugin!r}: result lacks global attributes {missing}")


#: global attribute of a run file holding its sweep as JSON
SWEEP_ATTR = "sweep"


def encode_sweep(sweep) -> str:
    """The ``sweep`` attribute of a run file: JSON of the swept study keys (dotted) and their values."""
    def plain(v):
        return v.item() if hasattr(v, "item") else v
    return json.dumps({str(k): plain(v) for k, v in dict(sweep or {}).items()}, separators=(", ", ": "))
