"""Scenes: the physical case every method runs on, parsed and validated from the study vocabulary.

A scene is given as a mapping in the vocabulary of docs/DESIGN.md (TOML tables, SI units, temperatures in
degC). :func:`load_scene` validates it and returns a frozen :class:`Scene`; every error is a
:class:`railtherm.SceneError` naming the scene, the key, the value and what is allowed.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from typing import Any, Mapping

from ..contract.errors import SceneError
from ..contract.schema import VARIABLES, WHEEL_TOTALS, WHEELSET_VARIABLES
from ..physics.friction import FrictionLaw, friction_law
from ..physics.partition import HeatPartition
from .checks import (Check, Choice, Either, FieldDepth, Flag, Friction, GapCoefficients, Int, Names, Num, Numbers,
                     Pair, ProfileSpec, Table, Text, gap_powers, quadratic_curvatures, variable_names)
from .kinematics import Creepage, Kinematics
from .materials import Material
from .profiles import is_profile_wheelset
from .transient import Transient, scene_transient

SCHEMA_VERSION = 1

#: outputs that only a 3-D (ellipse) contact has
LATERAL_OUTPUTS = frozenset({"traction_y", "slip_velocity_y", "creep_force_y", "spin_moment", "semi_axis_b"})

#: outputs asked when a scene names none
DEFAULT_OUTPUTS = ("max_surface_temperature", "mean_contact_temperature", "surface_temperature",
                   "heat_flux", "frictional_power")


POS = Num(0, lo_open=True, unit="m")
NONNEG = Num(0)

MATERIAL_KEYS = {
    "shear_modulus": Num(0, lo_open=True, unit="Pa"),
    "youngs_modulus": Num(0, lo_open=True, unit="Pa"),
    "poisson_ratio": Num(0, 0.5, hi_open=True),
    "density": Num(0, lo_open=True, unit="kg m-3"),
    "specific_heat": Num(0, lo_open=True, unit="J kg-1 K-1"),
    "conductivity": Num(0, lo_open=True, unit="W m-1 K-1"),
    "thermal_expansion": Num(0, unit="K-1"),
    "bulk_temperature": Num(-273.15, lo_open=True, unit="degC"),
    "radius": Num(0, lo_open=True, unit="m"),
    "rigid": Flag(),
}

SCENE_KEYS: dict[str, Check] = {
    "name": Text(),
    "normal_force": Num(0, unit="N", note="N m-1 for a line contact: force per unit length"),
    "penetration": Num(0, lo_open=True, unit="m"),
    "contact": Table({"shape": Choice("ellipse", "line", "gap"),
                      "coefficients": GapCoefficients(),
                      "semi_axes": Pair(Num(0, lo_open=True, unit="m")),
                      "curvatures": Pair(Num(0, lo_open=True, unit="m-1")),
                      "wheel_radius": Num(0, lo_open=True, unit="m")}),
    "speed": Num(0, lo_open=True, unit="m s-1"),
    "sliding_speed": Num(unit="m s-1", note=">= -speed: the wheel's surface moves at speed + sliding_speed; -speed is "
                         "a locked wheel"),
    "creepage": Table({"longitudinal": Num(-1, 1), "lateral": Num(-1, 1), "spin": Num(unit="m-1")}),
    "friction": Friction(),
    "heat_partition": Either(Num(0, 1), Choice(*HeatPartition.RULES)),
    "convection": Num(0, unit="W m-2 K-1"),
    "outputs": Names(variable_names),
    "heat_source": Table({"flux": Num(0, unit="W m-2"), "shape": Choice("uniform", "hertz"),
                          "semi_axes": Pair(Num(0, lo_open=True, unit="m")),
                          "half_width": Num(0, lo_open=True, unit="m")}),
    "wheel": Table(MATERIAL_KEYS),
    "rail": Table(MATERIAL_KEYS),
    "strip": Table({"length": POS, "depth": POS}),
    "numerics": Table({"time_step": Num(0, lo_open=True, unit="s"),
                       "scheme": Choice("auto", "explicit", "implicit", "steady"),
                       "regularization": Num(0, lo_open=True),
                       "revolutions": Num(0, lo_open=True),
                       "duration": Num(0, lo_open=True, unit="s")}),
    "wheelset": Table({"conicity": Num(0, 1), "lateral_shift": Num(-0.1, 0.1, unit="m"),
                       "yaw_angle": Num(-0.1, 0.1, unit="rad"), "vertical_load": Num(0, lo_open=True, unit="N"),
                       "wheel_radius": Num(0, lo_open=True, unit="m"), "gauge": Num(0, lo_open=True, unit="m"),
                       "contact": Choice(1, 2),
                       # a wheelset on real profiles (railtherm.input.wheelset_profile); checked in full by
                       # railtherm.input.profiles.wheelset_geometry_from_table
                       "wheel_profile": ProfileSpec(), "rail_profile": ProfileSpec(),
                       "rail_inclination": Num(-0.1, 0.1, unit="rad"), "gauge_height": Num(0, 0.03, unit="m"),
                       "flange_back_distance": Num(0, lo_open=True, unit="m"),
                       "flange_back_position": Num(-0.2, 0.2, unit="m"),
                       "nominal_radius": Num(0, lo_open=True, unit="m"),
                       "roll_angle": Either(Num(-0.1, 0.1, unit="rad"), Choice("balance")),
                       "pitch_velocity": Either(Num(-1e4, 1e4, unit="rad s-1"), Choice("free")),
                       "vertical_force": Num(0, unit="N"), "side": Choice("right", "left"),
                       "patch": Choice(1, 2, 3, "all")}),
    "mode": Choice("steady", "transient"),
    "reference": Text(),
    "passes": Table({"count": Int(1), "interval": Num(0, lo_open=True, unit="s")}),
    "schedule": Table({"time": Numbers("s", "strictly increasing times"), "factor": Numbers("1", "factors >= 0")}),
    "field": Table({"behind": Num(0, unit="m", note="distance beyond the trailing edge"),
                    "depth": FieldDepth(),
                    "threshold": Num(-273.15, lo_open=True, unit="degC")}),
}

#: outputs of the thermal trace (need the scene key ``field``): what a material point on the centre line
#: lives through as it passes the contact (docs/DESIGN.md "Result schema")
TRACE_OUTPUTS = ("peak_temperature", "cooling_rate", "heated_depth", "time_above")


def _flatten(keys: Mapping[str, Check], prefix: str = "") -> dict[str, Check]:
    out = {}
    for k, check in keys.items():
        if isinstance(check, Table):
            out.update(_flatten(check.keys, f"{prefix}{k}."))
        else:
            out[prefix + k] = check
    return out


#: every study key of a scene, dotted (``creepage.longitudinal``, ``wheel.conductivity``), with the
#: checker that validates it: the one table behind the scene parser, swept coordinates and their units
KEY_TABLE: dict[str, Check] = _flatten(SCENE_KEYS)


def key_units(key: str) -> str | None:
    """UDUNITS-2 units of a dotted study key (``"m s-1"`` for ``speed``, ``"1"`` for ``friction``), None
    for a key without units (text, flags) or one that is not a study key."""
    check = KEY_TABLE.get(key)
    return None if check is None else check.unit



# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GivenHeatSource:
    """A heat source given by the scene (paper section 6.4)."""

    flux: float
    shape: str = "uniform"
    semi_axes: tuple[float, float] | None = None
    half_width: float | None = None


@dataclass(frozen=True)
class Strip:
    length: float | None = None
    depth: float | None = None


@dataclass(frozen=True)
class Field:
    """Where temperatures are reported (scene key ``field``): the thermal trace behind the patch and in depth.

    Attributes
    ----------
    behind : float
        Distance [m] beyond the trailing edge that the temperature fields reach: x runs from +a down to
        -a - behind (rounded up to whole cells of the surface grid). Default 0: the patch only.
    depth : float or None
        Depth [m] the depth field ``temperature(body, x, z)`` reaches. Default None: the temperature
        model's own depth (green: ``depth_layers`` thermal layers).
    threshold : float
        Temperature [degC] for ``heated_depth`` and ``time_above``. Default 727 degC (the eutectoid
        temperature of rail steel, above which austenite forms: white etching layers).
    """

    behind: float = 0.0
    depth: float | None = None
    threshold: float = 727.0


@dataclass(frozen=True)
class Wheelset:
    conicity: float = 0.0
    lateral_shift: float = 0.0
    yaw_angle: float = 0.0
    vertical_load: float = 100e3
    wheel_radius: float = 0.46
    gauge: float = 1.5
    #: which of the two contacts the scene is (1: the scene's wheel, the outer wheel in the curve; 2: the
    #: other); both come from one equilibrium (seed section 6.1)
    contact: int = 1


@dataclass(frozen=True)
class Scene:
    """A validated scene. Build with :func:`load_scene`; attributes in SI units.

    See docs/DESIGN.md "Scene vocabulary" for the meaning of every key.
    """

    name: str
    #: rolling speed, sliding speed and creepages (keys ``speed``, ``sliding_speed``, ``creepage``)
    kinematics: Kinematics
    normal_force: float | None = None
    penetration: float | None = None
    contact_shape: str = "ellipse"
    semi_axes: tuple[float, float] | None = None
    curvatures: tuple[float, float] | None = None
    gap_coefficients: Mapping[tuple[int, int], float] | None = None
    line_wheel_radius: float | None = None
    #: the law of key ``friction`` (None without it), resolved once at load time; its ``nominal`` is the
    #: one coefficient [1] of models and metrics that take a number
    friction: FrictionLaw | None = None
    #: key ``heat_partition`` resolved once (default Blok's equal-temperature fraction)
    partition: HeatPartition = HeatPartition("equal-temperature")
    convection: float = 0.0
    outputs: tuple[str, ...] = DEFAULT_OUTPUTS
    heat_source: GivenHeatSource | None = None
    wheel: Material = field(default_factory=Material)
    rail: Material = field(default_factory=Material)
    strip: Strip | None = None
    numerics: Mapping[str, Any] = field(default_factory=dict)
    wheelset: Wheelset | None = None
    #: a wheelset on profiles (``[scene.wheelset]`` with profile keys): the patch whose gap, load and
    #: creepages the scene carries (:class:`railtherm.input.wheelset_profile.ProfileContact`)
    profile_contact: Any = None
    mode: str = "steady"
    reference: str | None = None
    #: the mapping the scene was parsed from (after defaults and sweep expansion)
    source: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    #: swept parameters of this scene, key -> value
    sweep: Mapping[str, Any] = field(default_factory=dict, compare=False)
    #: temperatures behind the patch and in depth (key ``field``); None: on the patch only
    #: (declared last: the name shadows ``dataclasses.field`` in the class body)
    field: Field | None = None
    #: passes, schedule, history depths and threshold of a scene with ``mode = "transient"`` (the
    #: interval resolved: the wheel's revolution period 2 pi wheel_radius / speed unless given); None
    #: for a steady scene
    transient: Transient | None = None

    @property
    def speed(self) -> float:
        """Rolling speed V [m/s] (:attr:`kinematics`)."""
        return self.kinematics.speed

    @property
    def sliding_speed(self) -> float | None:
        """Full sliding speed [m/s], None when rolling with creepage (:attr:`kinematics`)."""
        return self.kinematics.sliding_speed

    @property
    def creepage(self) -> Creepage | None:
        """Creepages of the wheel relative to the rail, None in full sliding (:attr:`kinematics`)."""
        return self.kinematics.creepage

    @property
    def heat_partition(self) -> float | str:
        """The scene's value of ``heat_partition``: the fraction entering the wheel [1], or the rule's name
        (:attr:`partition` is the resolved :class:`~railtherm.physics.partition.HeatPartition`)."""
        return self.partition.value

    @property
    def wheel_radius(self) -> float:
        """Wheel radius [m]: the line contact's ``wheel_radius``, else ``wheel.radius``."""
        return self.line_wheel_radius if self.line_wheel_radius is not None else self.wheel.radius

    @property
    def tangential(self) -> str:
        """"full-sliding" or "creepage" (or "given" when the scene gives its heat source)."""
        if self.heat_source is not None:
            return "given"
        return "creepage" if (self.creepage is not None or self.wheelset is not None) else "full-sliding"

    @property
    def hash(self) -> str:
        """Stable hash of the physical content (name excluded): sha256 of canonical JSON, 16 hex digits."""
        payload = {k: v for k, v in self.source.items() if k != "name"}
        text = json.dumps(payload, sort_keys=True, default=_jsonable, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def body(self, i: int | str) -> Material:
        """Material of body ``i`` (0/"wheel" or 1/"rail")."""
        return self.wheel if i in (0, "wheel") else self.rail

    def to_dict(self) -> dict:
        """The scene as a mapping in the study vocabulary (round-trips through :func:`load_scene`)."""
        return json.loads(json.dumps(self.source, default=_jsonable))


def _jsonable(v):
    if isinstance(v, tuple):
        return list(v)
    raise TypeError(type(v))


def _material(scene: str, key: str, table: Mapping[str, Any]) -> Material:
    t = dict(table)
    if "youngs_modulus" in t:
        if "shear_modulus" in t:
            raise SceneError(f"scene {scene!r}: key '{key}' gives both 'shear_modulus' and 'youngs_modulus'; "
                             "give one of them", scene=scene, key=key)
        nu = t.get("poisson_ratio", Material.poisson_ratio)
        t["shear_modulus"] = t.pop("youngs_modulus") / (2.0 * (1.0 + nu))
    return Material(**t)


def load_scene(mapping: Mapping[str, Any] | "Scene", *, name: str | None = None,
               sweep: Mapping[str, Any] | None = None) -> Scene:
    """Validate a scene mapping (study vocabulary, defaults already merged) and return a :class:`Scene`.

    Parameters
    ----------
    mapping : mapping or Scene
        Scene keys as in docs/DESIGN.md. Lists are not expanded here (see :func:`railtherm.input.study.expand_sweeps`):
        a list where a scalar belongs is an error.
    name : str, optional
        Scene name when the mapping has none.

    Raises
    ------
    railtherm.SceneError
        On an unknown or missing key, or a value outside what is allowed.
    """
    if isinstance(mapping, Scene):
        return mapping
    if not isinstance(mapping, Mapping):
        raise SceneError(f"a scene must be a table of keys, got {type(mapping).__name__}: {mapping!r}")
    raw = dict(mapping)
    sname = raw.get("name", name)
    label = sname if isinstance(sname, str) else None
    if sname is None:
        raise SceneError("a scene has no 'name': give each [[scene]] a name = \"...\"", key="name")
    clean: dict[str, Any] = {}
    for key, value in raw.items():
        if key not in SCENE_KEYS:
            raise SceneError(f"scene {label!r}: unknown key {key!r} (value {value!r}); allowed keys: "
                             f"{', '.join(SCENE_KEYS)}", scene=label, key=key, value=value,
                             allowed=", ".join(SCENE_KEYS))
        check = SCENE_KEYS[key]
        if isinstance(value, list) and check.sweepable:
            raise SceneError(f"scene {label!r}: key {key!r} = {value!r} is a list; lists are sweeps and are "
                             "expanded by the study (use railtherm.load_study or expand_sweeps)",
                             scene=label, key=key, value=value, allowed="a single value")
        clean[key] = check(label, key, value)
    return _build(label, clean, raw, sweep or {})


def _require(scene, cond, key, msg):
    if not cond:
        raise SceneError(f"scene {scene!r}: {msg}", scene=scene, key=key, allowed=msg)


def _profile_wheelset(name: str, c: dict):
    """A wheelset on profiles: the contact search's patch as the scene's gap, load and creepages
    (:mod:`railtherm.input.wheelset_profile`); those keys must not be given as well."""
    # imported here: the contact search pulls in core's references, which a reader of results (the report)
    # never needs
    from .wheelset_profile import NoContact, NoContactError, profile_contact
    given = [k for k in ("contact", "normal_force", "penetration", "creepage", "sliding_speed") if k in c]
    if given:
        raise SceneError.bad_value(name, given[0], c[given[0]],
                                   "nothing: a wheelset on profiles sets the contact, normal force and creepage")
    law = friction_law(c["friction"]) if "friction" in c else None
    try:
        pc = profile_contact(name, c["wheelset"], speed=c["speed"], wheel=_material(name, "wheel", c.get("wheel", {})),
                             rail=_material(name, "rail", c.get("rail", {})),
                             friction=None if law is None else law.nominal)
    except NoContactError as exc:   # the scene's own runs fail with it (solve raises it), not the study
        return NoContact(side=c["wheelset"].get("side", "right"), message=str(exc), key=exc.key, value=exc.value)
    c["contact"] = {"shape": "gap", "coefficients": pc.gap_coefficients}
    c["normal_force"] = pc.normal_force
    xi, eta, phi = pc.creepage
    c["creepage"] = {"longitudinal": xi, "lateral": eta, "spin": phi}
    return pc


def _build(name: str, c: dict, raw: Mapping, sweep) -> Scene:
    given = c.get("heat_source")
    kw: dict[str, Any] = {"name": name}
    _require(name, "speed" in c, "speed", "key 'speed' (rolling speed V [m/s], > 0) is missing")
    kw["speed"] = c["speed"]
    if given is not None:
        _given_heat_source(name, c, given, kw)
    else:
        if is_profile_wheelset(c.get("wheelset")):
            kw["profile_contact"] = _profile_wheelset(name, c)
        if hasattr(kw.get("profile_contact"), "failure"):
            # no contact found: no gap, no load, no slip (exact references see an unloaded patch); solve raises
            # the failure
            kw.update(contact_shape="gap", normal_force=0.0, creepage=Creepage())
        else:
            _contact(name, c, kw)
            _load_and_slip(name, c, kw)
    if "friction" in c:
        kw["friction"] = friction_law(c["friction"])
    if "heat_partition" in c:
        kw["partition"] = HeatPartition.of(c["heat_partition"])
    for k in ("convection", "outputs", "mode", "reference"):
        if k in c:
            kw[k] = c[k]
    _check_outputs(name, kw)
    kw["wheel"] = _material(name, "wheel", c.get("wheel", {}))
    kw["rail"] = _material(name, "rail", c.get("rail", {}))
    _require(name, not kw["rail"].rigid, "rail.rigid", "the rail cannot be rigid (only the wheel, paper section 4)")
    if "strip" in c:
        kw["strip"] = Strip(**c["strip"])
    if "wheelset" in c and "profile_contact" not in kw:
        kw["wheelset"] = Wheelset(**c["wheelset"])
    kw["transient"] = scene_transient(name, c, raw, kw)
    if "field" in c and kw["transient"] is None:
        _require(name, not isinstance(c["field"].get("depth"), list), "field.depth",
                 "one depth [m] > 0 in a steady scene (a list of depths belongs to mode = \"transient\")")
        kw["field"] = Field(**c["field"])
    trace = [o for o in kw.get("outputs", ()) if o in TRACE_OUTPUTS and not (kw["transient"] and o == "time_above")]
    if trace and "field" not in c:
        raise SceneError.bad_value(name, "outputs", trace[0],
                                   "a thermal-trace output (" + ", ".join(TRACE_OUTPUTS) + ") only with the "
                                   "key field = { behind = <m>, depth = <m>, threshold = <degC> } (each optional)")
    kw["numerics"] = dict(c.get("numerics", {}))
    source = json.loads(json.dumps(dict(raw), default=_jsonable))
    source["name"] = name
    kw["kinematics"] = Kinematics(kw.pop("speed"), kw.pop("sliding_speed", None), kw.pop("creepage", None))
    return Scene(**kw, source=source, sweep=dict(sweep))


def _given_heat_source(name: str, c: dict, given: Mapping, kw: dict) -> None:
    """A scene that gives its heat source: the source, its contact shape and the keys it excludes, into ``kw``."""
    _require(name, "flux" in given, "heat_source.flux", "heat_source needs 'flux' [W/m^2]")
    has_axes, has_hw = "semi_axes" in given, "half_width" in given
    _require(name, has_axes != has_hw, "heat_source",
             "heat_source needs exactly one of 'semi_axes' [m] (ellipse) or 'half_width' [m] (line)")
    kw["heat_source"] = GivenHeatSource(given["flux"], given.get("shape", "uniform"),
                                        given.get("semi_axes"), given.get("half_width"))
    kw["contact_shape"] = "ellipse" if has_axes else "line"
    if has_axes:
        kw["semi_axes"] = given["semi_axes"]
    for k in ("creepage", "sliding_speed"):
        _require(name, k not in c, k, f"key {k!r} does not apply when the scene gives its heat_source")
    if "contact" in c and c["contact"].get("shape") == "line":
        kw["line_wheel_radius"] = c["contact"].get("wheel_radius")


def _contact(name: str, c: dict, kw: dict) -> None:
    """The contact table: ellipse (semi-axes or curvatures), gap (coefficients) or line (wheel radius), into ``kw``."""
    _require(name, "contact" in c, "contact",
             "key 'contact' is missing: give contact = { shape = \"ellipse\", semi_axes = [a, b] } "
             "(or curvatures, or shape = \"line\" with wheel_radius), or a heat_source")
    ct = c["contact"]
    shape = ct.get("shape", "ellipse")
    kw["contact_shape"] = shape
    if shape == "ellipse":
        _require(name, ("semi_axes" in ct) != ("curvatures" in ct), "contact",
                 "an ellipse contact needs exactly one of 'semi_axes' [m] or 'curvatures' [1/m]")
        _require(name, "wheel_radius" not in ct, "contact.wheel_radius",
                 "'wheel_radius' belongs to line contacts; give wheel = { radius = ... } for an ellipse")
        kw["semi_axes"] = ct.get("semi_axes")
        kw["curvatures"] = ct.get("curvatures")
        _require(name, "coefficients" not in ct, "contact.coefficients",
                 "'coefficients' belong to contact = { shape = \"gap\", coefficients = {...} }")
    elif shape == "gap":
        _require(name, "coefficients" in ct, "contact.coefficients",
                 "a gap contact needs 'coefficients' (h = sum c_ij x^i y^j [m], SI), e.g. "
                 "{ x2 = 1.015, y2 = 0.4215, y4 = 2.0e3 }")
        _require(name, not ({"semi_axes", "curvatures", "wheel_radius"} & set(ct)), "contact",
                 "a gap contact takes 'coefficients' only (no semi_axes, curvatures or wheel_radius)")
        gap = gap_powers(ct["coefficients"])
        kw["gap_coefficients"] = gap
        quad = quadratic_curvatures(gap)
        if quad is not None:   # a Hertzian gap: an ellipse given by its curvatures
            kw["contact_shape"], kw["curvatures"] = "ellipse", quad
    else:
        _require(name, "wheel_radius" in ct, "contact.wheel_radius",
                 "a line contact needs 'wheel_radius' [m]")
        _require(name, not ({"semi_axes", "curvatures", "coefficients"} & set(ct)), "contact",
                 "a line contact takes 'wheel_radius' only (no semi_axes/curvatures/coefficients)")
        kw["line_wheel_radius"] = ct["wheel_radius"]


def _load_and_slip(name: str, c: dict, kw: dict) -> None:
    """Normal force or penetration (a wheelset may set the force), sliding speed or creepage, into ``kw``."""
    ws = None if "profile_contact" in kw else c.get("wheelset")
    if ws is not None and "normal_force" not in c and "penetration" not in c:
        # seed 6.1: the wheelset's kinematics sets the normal force; half the axle load starts it
        c["normal_force"] = Wheelset(**ws).vertical_load / 2.0
    _require(name, ("normal_force" in c) != ("penetration" in c), "normal_force",
             "give exactly one of 'normal_force' [N] ([N/m] for a line) or 'penetration' [m]")
    if "penetration" in c and kw.get("semi_axes") is not None:
        raise SceneError(f"scene {name!r}: key 'penetration' cannot be combined with contact.semi_axes "
                         "(the semi-axes fix the load): give normal_force, or curvatures",
                         scene=name, key="penetration", value=c["penetration"])
    _require(name, ("sliding_speed" in c) != ("creepage" in c) or (ws is not None and "sliding_speed" not in c),
             "sliding_speed",
             "give exactly one of 'sliding_speed' [m/s] (full sliding) or 'creepage' (a table)"
             + ("; with a wheelset both may be left out (the kinematics give the creepages)" if ws else ""))
    _require(name, "friction" in c, "friction", "key 'friction' (a coefficient >= 0 or a friction-law table) is missing")
    if "sliding_speed" in c and "speed" in c and c["sliding_speed"] < -c["speed"]:
        raise SceneError.bad_value(name, "sliding_speed", c["sliding_speed"],
                                   f"a number >= -speed = {-c['speed']:g} [m s-1] (the wheel's surface moves at speed + "
                                   "sliding_speed, not backwards; -speed: a locked wheel)")
    if "creepage" in c:
        kw["creepage"] = Creepage(**c["creepage"])
    for k in ("normal_force", "penetration", "sliding_speed"):
        if k in c:
            kw[k] = c[k]


def _check_outputs(name: str, kw: dict) -> None:
    """Refuse outputs the scene cannot have: lateral ones of a line contact, wheelset patch quantities without profiles."""
    if kw["contact_shape"] == "line" and "outputs" in kw:
        lateral = [o for o in kw["outputs"] if o in LATERAL_OUTPUTS]
        if lateral:
            raise SceneError.bad_value(name, "outputs", lateral[0],
                                       "a variable of a 2-D (line) contact: it has no lateral direction, so not "
                                       + ", ".join(sorted(LATERAL_OUTPUTS)))
    pc = kw.get("profile_contact")
    if pc is not None and not hasattr(pc, "failure"):
        # imported here, as in _profile_wheelset: the contact search pulls in scipy and core's references
        from .wheelset_patch_scenes import PATCH_DEFAULT_OUTPUTS, check_patch_outputs
        if "outputs" not in kw and pc.patch == "all":
            kw["outputs"] = PATCH_DEFAULT_OUTPUTS
        check_patch_outputs(name, kw.get("outputs", DEFAULT_OUTPUTS), pc, lambda o: VARIABLES[o].dims)
    placed = [o for o in kw.get("outputs", ()) if o in WHEELSET_VARIABLES + WHEEL_TOTALS]
    if placed and "profile_contact" not in kw:
        raise SceneError.bad_value(name, "outputs", placed[0],
                                   "a patch quantity of a wheelset on profiles (" + ", ".join(WHEELSET_VARIABLES)
                                   + ") only in a scene whose wheelset names wheel_profile and rail_profile")
