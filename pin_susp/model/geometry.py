"""Geometry file → validated Geometry (SI units), and the derived-point formulas.

The file format is documented in ``docs/geometry.md`` (it is the one of
open-kinematics 0.4). Lengths arrive in mm and leave this module in metres;
nothing after it converts units.

The reader checks each key as the Geometry's field it fills, and the derived points
(wheel, contact patch, the kingpin's ends) are computed as the file is read; the
checks, the dataclass and the formulas change together when the file format does.
The checks that the hardpoints' positions decide are hardpoint_checks.py's (a study's
variant is checked by them alone).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import PlausibilityWarning
from ..io.yamlio import MAX_LENGTH_MM, Reader, load_yaml
from ..maths.vectors import COINCIDENT, direction, unit
from . import packaging
from .hardpoint_checks import check_points
from .packaging import Driveshaft, Limits
from .units import INCH as INCH
from .units import MM as MM
from .wheel import Wheel as Wheel
from .wheel import contact_patch as contact_patch
from .wheel import read_wheel
from .wheel import size as _size
from .wheel import wheel_down as wheel_down
from .wheel import wheel_points as wheel_points

# Points computed from the upright's hardpoints and the wheel (docs/geometry.md, "Derived
# points").
DERIVED_POINTS = (
    "axle_midpoint",
    "wheel_center",
    "wheel_inboard",
    "wheel_outboard",
    "contact_patch_center",
)

# Valid but implausible for a car (docs/geometry.md): a warning each, never an error.
# key path → (low, high, unit as written in the file)
PLAUSIBLE = {
    "config.wheel.tyre.rim_diameter": (8.0, 24.0, "in"),
    "config.wheel.tyre.section_width": (100.0, 400.0, "mm"),
    "config.wheel.tyre.aspect_ratio": (0.2, 0.9, ""),
    "config.wheel.offset": (-150.0, 150.0, "mm"),
    "tyre radius": (150.0, 500.0, "mm"),
    "config.wheelbase": (1000.0, 5000.0, "mm"),
    "config.cg_position.z": (100.0, 1500.0, "mm"),
    "config.front_brake_bias": (0.4, 0.85, ""),
    "distance from the wheel centre": (0.0, 2000.0, "mm"),
}


@dataclass(frozen=True)
class CamberShim:
    """Outboard camber shim stack (config.camber_shim), SI units."""

    point_a: np.ndarray
    point_b: np.ndarray
    normal: np.ndarray  # unit, from camber block to upright body
    design_thickness: float
    setup_thickness: float


@dataclass(frozen=True)
class Options:
    """The choices that decide a corner's hardpoints (a Geometry has them too)."""

    type: str
    side: str
    steering: str
    actuation: str
    actuation_mount: str
    spring: str


@dataclass(frozen=True)
class Geometry:
    """One suspension corner at its design condition, SI units, world frame.

    The model's numbers are in metres: ``hardpoints`` maps each point to its
    (x, y, z) in m. ``hardpoints_mm`` reads them back in the file's mm.
    """

    name: str
    side: str  # "left" | "right"
    steering: str  # "rack" | "none"
    actuation: str  # "direct" | "pushrod_rocker"
    actuation_mount: str  # "lower_wishbone" | "upright"
    spring: str  # "none" | "coilover" | "torsion_bar"
    hardpoints: dict[str, np.ndarray]
    wheel: Wheel
    cg_position: np.ndarray | None = None
    wheelbase: float | None = None
    axle_position: str | None = None
    front_brake_bias: float | None = None
    driven_axle: str | None = None
    camber_shim: CamberShim | None = None
    trackrod_length_delta: float = 0.0  # m, config.setup
    pushrod_length_delta: float = 0.0  # m, config.setup
    # Set on an as-set geometry (as_set.apply_setup): the geometry as drawn, and
    # the wheel's move relative to the chassis it caused (m, + = car higher).
    drawn: Geometry | None = None
    ride_height_change: float = 0.0
    type: str = "double_wishbone"  # the mechanism (pin_susp.model.mechanisms)
    strut: dict | None = None  # config.strut (MacPherson): rate N/mm, preload N
    # spring.rate (config.strut.rate for a MacPherson strut): N/mm, a torsion bar's
    # N·m/deg; spring.preload at design: N (N·m). None: no rate given (no rate columns)
    spring_rate: float | None = None
    spring_preload: float = 0.0
    opposite_axle_axis_height: float | None = None  # m, config (read, for the axle's pitch)
    # config.inertia, for the URDF's and MJCF's masses (None: the defaults, docs/urdf.md)
    density: float | None = None  # kg/m³ of the drawn links and joints
    wheel_mass: float | None = None  # kg: rim, tyre, hub and brake
    driveshaft: Driveshaft | None = None  # cv_inboard and config.driveshaft (packaging.py)
    limits: Limits | None = None  # config.limits: the damper's travel (packaging.py)
    source: str = "<dict>"
    sha256: str | None = None
    data: dict = field(default_factory=dict, repr=False)

    @property
    def sign(self) -> float:
        """s = +1 for a left corner, −1 for a right one (docs/results.md)."""
        return 1.0 if self.side == "left" else -1.0

    @property
    def mechanism(self):
        """The mechanism module of this corner's ``type`` (pin_susp.model.mechanisms)."""
        from . import mechanisms

        return mechanisms.get(self.type)

    @property
    def design_ride_height(self) -> float:
        """The wheel centre's height above the road at design (m): the tyre's loaded
        radius (docs/geometry.md, "The wheel by its centre") in the wheel plane."""
        p = self.design_points()
        return float(p["wheel_center"][2] - p["contact_patch_center"][2])

    @property
    def has_pushrod(self) -> bool:
        return self.actuation == "pushrod_rocker"

    @property
    def rated_spring(self) -> bool:
        """A spring with its rate given: its force and the wheel and ride rates exist."""
        return self.spring_rate is not None and self.spring != "none"

    @property
    def needs_setup(self) -> bool:
        """True when shims or adjusters move the corner away from its drawn state."""
        shim = self.camber_shim
        return self.drawn is None and (
            (shim is not None and shim.setup_thickness != shim.design_thickness)
            or self.trackrod_length_delta != 0.0
            or self.pushrod_length_delta != 0.0
        )

    @property
    def steering_points(self) -> tuple[str, str] | tuple[()]:
        """(inboard, outboard) of the trackrod, or of the fixed toe link; () for a
        mechanism without one (a trailing arm)."""
        return self.mechanism.steering_points(self)

    def design_points(self) -> dict[str, np.ndarray]:
        """Every hardpoint and derived point at the design condition (m); a driveshaft's
        outboard joint where its offset places it (packaging.py)."""
        points = dict(self.hardpoints)
        points.update(wheel_points(points["axle_inboard"], points["axle_outboard"], self.wheel))
        return points | packaging.placed_points(self.driveshaft, points)

    @property
    def hardpoints_mm(self) -> dict[str, np.ndarray]:
        """Each hardpoint's (x, y, z) in mm, as the file gives it (fresh arrays: the
        model's own ``hardpoints`` are in m). Rounded to 1e-10 mm, so that the file's
        numbers come back as written (m → mm alone is one ulp off for 1 % of them).
        An as-set geometry's are the as-set points (a camber shim moves the upright's,
        a length adjuster the trackrod's or pushrod's end); its ``drawn`` has the file's."""
        return {name: to_mm(p) for name, p in self.hardpoints.items()}

    def design_points_mm(self) -> dict[str, np.ndarray]:
        """Every hardpoint and derived point (wheel centre, contact patch, ...) at the
        design condition, in mm (as ``hardpoints_mm``)."""
        return {name: to_mm(p) for name, p in self.design_points().items()}

    def choices(self) -> tuple[str, ...]:
        """The choices that decide the mechanism, as the reprs list them (blank: the
        default left out): type, side, steering, pushrod-rocker, spring, as set."""
        return (
            self.type,
            self.side,
            self.steering,
            "pushrod_rocker" if self.actuation == "pushrod_rocker" else "",
            "" if self.spring == "none" else self.spring,
            "as set" if self.drawn is not None else "",
        )

    def __repr__(self) -> str:
        """One line: the file, the name and the choices that decide the mechanism."""
        return summary_repr(
            self,
            lambda: (
                self.source,
                self.name,
                *self.choices(),
                f"{len(self.hardpoints)} hardpoints",
            ),
        )


def to_mm(p_m: np.ndarray) -> np.ndarray:
    """A point (or points) in m, in mm to 1e-10 mm: a number of the file (up to 10
    decimals, within MAX_LENGTH_MM) comes back exactly as float() read it."""
    return np.round(np.asarray(p_m, dtype=float) / MM, 10)


def summary_repr(obj, parts) -> str:
    """``<Kind 'file.yaml' 'name': part, part, ...>``, parts() giving (source, name,
    *parts): one line that never raises — the file by its name only, the name when it
    is not the file's, empty parts left out; ``<Kind>`` when parts() fails."""
    kind = type(obj).__name__
    try:
        source, name, *shown = parts()
        where = ""
        if source and not str(source).startswith("<"):
            where = f" {Path(str(source)).name!r}"
        if name and (not where or str(name) != Path(str(source)).stem):
            where += f" {str(name)!r}"
        return f"<{kind}{where}: " + ", ".join(str(p) for p in shown if p) + ">"
    except Exception:  # a repr never raises, even on a half-built object
        return f"<{kind}>"


def load_geometry(source: str | Path | dict) -> Geometry:
    """Read and validate a geometry file (path) or an already-loaded dict.

    Raises InputError naming the file, the key and the problem; warns
    (PlausibilityWarning) about valid values outside a car's plausible range, and
    about a link near dead centre at design (docs/geometry.md, "Dead centres").
    """
    data, name, sha = load_yaml(source)
    g = parse_geometry(data, Reader(name), sha)
    warn_implausible(g)
    warn_dead_centres(g)
    return g


def warn_dead_centres(g: Geometry, source: str | None = None) -> list:
    """A PlausibilityWarning for each link of the corner within a few degrees of dead
    centre at design (:mod:`pin_susp.model.deadcentre`), naming ``source`` (default: the
    geometry's); the ones found."""
    from . import deadcentre

    return deadcentre.warn_dead_centres(g.mechanism.tree(g), source or g.source)


def warn_implausible(g: Geometry) -> None:
    """A PlausibilityWarning for each value outside PLAUSIBLE (a unit slip, often)."""
    w = g.wheel
    values = {
        "config.wheel.tyre.rim_diameter": np.nan if w.diameter else w.rim_diameter / INCH,
        "config.wheel.tyre.section_width": w.section_width / MM,
        "config.wheel.tyre.aspect_ratio": np.nan if w.diameter else w.aspect_ratio,
        "config.wheel.offset": w.offset / MM,
        "tyre radius": w.unloaded_radius / MM,
    }
    if g.wheelbase is not None:
        values["config.wheelbase"] = g.wheelbase / MM
    if g.cg_position is not None:
        values["config.cg_position.z"] = g.cg_position[2] / MM
    if g.front_brake_bias is not None:
        values["config.front_brake_bias"] = g.front_brake_bias
    center = g.design_points()["wheel_center"]
    far = max(g.hardpoints, key=lambda n: np.linalg.norm(g.hardpoints[n] - center))
    values["distance from the wheel centre"] = np.linalg.norm(g.hardpoints[far] - center) / MM
    for key, value in values.items():
        what = f"hardpoints.{far}: {key}" if key.startswith("distance") else key
        if key.startswith("config.wheel.tyre."):  # as the file wrote it: tyre: or tire:
            what = w.key(key.rpartition(".")[2])
        warn_outside(f"{g.source}: {what}", value, *PLAUSIBLE[key])


def warn_outside(what: str, value: float, low: float, high: float, unit_text: str) -> None:
    """A PlausibilityWarning when ``value`` is outside low…high (NaN is not: undefined
    is not implausible)."""
    if value < low or value > high:
        warnings.warn(
            f"{what} = {value:.4g} {unit_text} is outside the plausible "
            f"{low:g}…{high:g} {unit_text} (a unit mistake?)".replace("  ", " "),
            PlausibilityWarning,
            stacklevel=3,
        )


# The scopes of a geometry file (docs/geometry.md), this reader's first; another's:
# what is said of its file, its own keys, what is said of them in a file without it.
OTHER_SCOPES = {
    "axle": (
        "an axle file: the commands read corner files only so far (the Python API "
        "reads axles: pin_susp.subjects.axle.load_axle)",
        ("axle_config", "vehicle_config"),
        "an axle's file (it has {key}) needs scope: axle",
    ),
}
SCOPES = ("corner", *OTHER_SCOPES)
CORNER_KEYS = ("type", "scope", "side", "name", "version", "units", "force_units")
CORNER_KEYS += ("actuation", "spring", "config", "compliance", "clearance")  # docs/clearance.md
CONFIG_KEYS = ("steering", "cg_position", "wheelbase", "track", "axle_position")
CONFIG_KEYS += ("front_brake_bias", "driven_axle", "camber_shim", "setup", "strut")
CONFIG_KEYS += ("opposite_axle_axis_height", "inertia", "driveshaft", "limits")


def parse_geometry(data: dict, r: Reader, sha: str | None) -> Geometry:
    """The Geometry of a geometry file's data (mm) already read, its errors through
    ``r`` (naming the file and key); ``sha`` the file's hash. No plausibility
    warnings: :func:`load_geometry` adds them, and an axle's corners or a study's
    variants, read from data they hold, warn (or not) for themselves."""
    from . import compliance, mechanisms
    from .forms import canonical_corner

    for scope, (_, keys, needs) in OTHER_SCOPES.items() if isinstance(data, dict) else ():
        declared = r.choice(data.get("scope", "corner"), "scope", (*SCOPES, "vehicle"))
        for key in (k for k in keys if k in data and declared != scope):
            r.fail("scope", needs.format(key=key))
    r.mapping(data, "", required=("hardpoints",), optional=CORNER_KEYS)
    legacy = data.get("type")
    if isinstance(legacy, str) and legacy.endswith("_axle"):
        r.fail(
            "type",
            f"{legacy!r} is an older open-kinematics axle layout; 0.4's (read here) is "
            f"type: {legacy.removesuffix('_axle').removesuffix('_pushrod_rocker')} with "
            "scope: axle, vehicle_config, axle_config and hardpoints.left/right/center",
        )
    kind = r.choice(data.get("type", "double_wishbone"), "type", mechanisms.NAMES)
    mech = mechanisms.get(kind)
    scope = r.choice(data.get("scope", SCOPES[0]), "scope", SCOPES)
    if scope in OTHER_SCOPES:
        r.fail("scope", OTHER_SCOPES[scope][0])
    data = canonical_corner(data, r)  # mm and N, spindle points, rocker_axis_a/b (forms.py)
    side = r.choice(data.get("side", "left"), "side", ("left", "right"))
    name = r.text(data.get("name", "unnamed corner"), "name")
    if "version" in data:
        r.text(data["version"], "version")

    config = r.mapping(data.get("config"), "config", required=("wheel",), optional=CONFIG_KEYS)
    for key, why in mech.FORBIDDEN.items():
        top, _, sub = key.partition(".")
        if (sub in config) if top == "config" else (key in data):
            r.fail(key, f"not for a {kind} corner: {why}")

    act = r.mapping(data.get("actuation", {}), "actuation", optional=("type", "mount"))
    actuation = r.choice(act.get("type", mech.ACTUATION[0]), "actuation.type", mech.ACTUATION)
    mount = r.choice(act.get("mount", mech.MOUNTS[0]), "actuation.mount", mech.MOUNTS)
    spring_map = r.mapping(data.get("spring", {}), "spring", optional=("type", "rate", "preload"))
    spring = r.choice(spring_map.get("type", mech.SPRINGS[0]), "spring.type", mech.SPRINGS)
    rate, preload = _spring_rate(spring_map, spring, config.get("strut"), r)
    if spring == "torsion_bar" and actuation != "pushrod_rocker":
        r.fail("spring.type", "a torsion bar needs actuation type pushrod_rocker")

    steer_map = r.mapping(config.get("steering", {}), "config.steering", (), ("type", "c_factor"))
    steering = r.choice(
        steer_map.get("type", mech.STEERING[0]), "config.steering.type", mech.STEERING
    )
    wheel = read_wheel(config["wheel"], r)
    options = Options(kind, side, steering, actuation, mount, spring)
    names = mech.hardpoint_names(options) + packaging.cv_points(data["hardpoints"])
    hp_map = data["hardpoints"]
    if not isinstance(hp_map, dict):
        r.fail("hardpoints", "expected a mapping of point name to {x, y, z}")
    for key in hp_map:
        if key not in names:
            r.fail(f"hardpoints.{key}", _unknown_point_hint(key, options, names))
    hardpoints = {}
    for key in names:
        if key not in hp_map:
            r.fail(f"hardpoints.{key}", "missing point")
        hardpoints[key] = r.point(hp_map[key], f"hardpoints.{key}") * MM

    check_points(hardpoints, options, r)
    compliance.read_compliance(data["compliance"], r, names) if "compliance" in data else None
    driveshaft = packaging.read_driveshaft(config, hardpoints, side, r)
    adjusters = _setup_block(config.get("setup", {}), actuation, mech.steering_points(options), r)

    density, wheel_mass = _inertia(config.get("inertia", {}), r)
    cg, bias = config.get("cg_position"), config.get("front_brake_bias")
    height = config.get("opposite_axle_axis_height")
    return Geometry(
        name=name,
        side=side,
        steering=steering,
        actuation=actuation,
        actuation_mount=mount,
        spring=spring,
        hardpoints=hardpoints,
        wheel=wheel,
        cg_position=None if cg is None else r.point(cg, "config.cg_position") * MM,
        wheelbase=(
            None
            if "wheelbase" not in config
            else _size(config["wheelbase"], "config.wheelbase", r) * MM
        ),
        axle_position=(
            None
            if "axle_position" not in config
            else r.choice(config["axle_position"], "config.axle_position", ("front", "rear"))
        ),
        front_brake_bias=None if bias is None else _fraction(bias, r),
        driven_axle=(
            None
            if "driven_axle" not in config
            else r.choice(config["driven_axle"], "config.driven_axle", ("front", "rear"))
        ),
        camber_shim=(
            None if "camber_shim" not in config else _camber_shim(config["camber_shim"], r)
        ),
        trackrod_length_delta=adjusters[0],
        pushrod_length_delta=adjusters[1],
        type=kind,
        strut=None if "strut" not in config else _strut(config["strut"], r),
        spring_rate=rate,
        spring_preload=preload,
        opposite_axle_axis_height=(
            None if height is None else r.length(height, "config.opposite_axle_axis_height") * MM
        ),
        density=density,
        wheel_mass=wheel_mass,
        driveshaft=driveshaft,
        limits=packaging.read_limits(config, hardpoints, r),
        source=r.source,
        sha256=sha,
        data=data,
    )


# beyond these a value is a unit slip, not a part: kg/m³ (osmium is 22 590), kg
INERTIA_LIMITS = {"density": 30000.0, "wheel_mass": 1000.0}


def _inertia(value, r: Reader) -> tuple[float | None, float | None]:
    """config.inertia: the density (kg/m³) of the drawn links and joints and the wheel's
    mass (kg), each None when not given (the exports' defaults then)."""
    s = r.mapping(value, "config.inertia", optional=tuple(INERTIA_LIMITS))
    out = []
    for name, limit in INERTIA_LIMITS.items():
        key = f"config.inertia.{name}"
        x = None if name not in s else r.positive(s[name], key)
        if x is not None and x > limit:
            unit_text = "kg/m³" if name == "density" else "kg"
            r.fail(key, f"{x:g} {unit_text} is beyond {limit:g} {unit_text}: a unit slip?")
        out.append(x)
    return out[0], out[1]


def _strut(value, r: Reader) -> dict:
    """config.strut: the MacPherson strut's spring (rate N/mm, preload N), for loads."""
    s = r.mapping(value, "config.strut", optional=("rate", "preload"))
    out = {}
    if "rate" in s:
        out["rate"] = r.positive(s["rate"], "config.strut.rate")
    if "preload" in s:
        out["preload"] = r.number(s["preload"], "config.strut.preload")
    return out


def _spring_rate(spring_map: dict, spring: str, strut, r: Reader) -> tuple:
    """(rate, preload) in the file's units from spring.{rate, preload} or, for a
    MacPherson strut, config.strut; (None, 0) without a rate."""
    if strut is not None:
        strut = _strut(strut, r)
        if "preload" in strut and "rate" not in strut:
            r.fail("config.strut.preload", "a preload needs the strut's rate (config.strut.rate)")
        return strut.get("rate"), strut.get("preload", 0.0)
    given = [k for k in ("rate", "preload") if k in spring_map]
    if given and spring == "none":
        r.fail(f"spring.{given[0]}", "a rate needs a spring: spring.type is none")
    if "preload" in spring_map and "rate" not in spring_map:
        r.fail("spring.preload", "a preload needs the spring's rate (spring.rate)")
    if "rate" not in spring_map:
        return None, 0.0
    return (
        r.positive(spring_map["rate"], "spring.rate"),
        r.number(spring_map.get("preload", 0.0), "spring.preload"),
    )


def _fraction(value, r: Reader) -> float:
    x = r.number(value, "config.front_brake_bias")
    if not 0.0 <= x <= 1.0:
        r.fail("config.front_brake_bias", f"must be between 0 and 1, got {x:g}")
    return x


def _camber_shim(value, r: Reader) -> CamberShim:
    key = "config.camber_shim"
    s = r.mapping(
        value,
        key,
        required=(
            "shim_face_point_a",
            "shim_face_point_b",
            "shim_face_normal",
            "design_thickness",
            "setup_thickness",
        ),
    )
    a = r.point(s["shim_face_point_a"], f"{key}.shim_face_point_a") * MM
    b = r.point(s["shim_face_point_b"], f"{key}.shim_face_point_b") * MM
    n = direction(r.vector(s["shim_face_normal"], f"{key}.shim_face_normal"))
    if np.linalg.norm(b - a) < COINCIDENT:
        r.fail(f"{key}.shim_face_point_b", "coincides with shim_face_point_a (A and B must differ)")
    if n is None:
        r.fail(f"{key}.shim_face_normal", "is the zero vector (it needs a direction)")
    ab = unit(b - a)
    if np.linalg.norm(np.cross(ab, n)) < 1e-6:
        r.fail(
            f"{key}.shim_face_point_b",
            "A→B runs along the shim face normal: A and B must clock the face (lie across it)",
        )
    design = r.number(s["design_thickness"], f"{key}.design_thickness", 0.0, limit=MAX_LENGTH_MM)
    setup = r.number(s["setup_thickness"], f"{key}.setup_thickness", 0.0, limit=MAX_LENGTH_MM)
    design, setup = design * MM, setup * MM
    return CamberShim(a, b, n, design, setup)


def _setup_block(value, actuation: str, link: tuple, r: Reader) -> tuple[float, float]:
    key = "config.setup"
    s = r.mapping(value, key, optional=("trackrod_length_delta", "pushrod_length_delta"))
    trackrod = r.length(s.get("trackrod_length_delta", 0.0), f"{key}.trackrod_length_delta")
    pushrod = r.length(s.get("pushrod_length_delta", 0.0), f"{key}.pushrod_length_delta")
    if trackrod != 0.0 and not link:
        r.fail(f"{key}.trackrod_length_delta", "this corner has no trackrod or toe link")
    if pushrod != 0.0 and actuation != "pushrod_rocker":
        r.fail(
            f"{key}.pushrod_length_delta",
            f"this corner has no pushrod (actuation type {actuation})",
        )
    return trackrod * MM, pushrod * MM


def _unknown_point_hint(key: str, o: Options, names: tuple[str, ...]) -> str:
    """Why ``key`` is not a point of this corner: another option of its mechanism
    (steering, spring, actuation) would have it, or another mechanism does."""
    from . import mechanisms

    def points(mech, kind: str, **change) -> set[str]:
        every = set()
        for steering in change.get("steering", mech.STEERING):
            for actuation in change.get("actuation", mech.ACTUATION):
                for spring in change.get("spring", mech.SPRINGS):
                    options = Options(kind, o.side, steering, actuation, mech.MOUNTS[0], spring)
                    every |= set(mech.hardpoint_names(options))
        return every

    mech = mechanisms.get(o.type)
    if key in points(mech, o.type, actuation=[o.actuation], spring=[o.spring]):
        other = "rack" if o.steering == "none" else "none"
        return (
            f"not a point of a corner with config.steering.type {o.steering}"
            f" (it belongs to {other})"
        )
    if key in points(mech, o.type, actuation=[o.actuation], steering=[o.steering]):
        return "not a point of this corner (strut points need spring type coilover)"
    if key in points(mech, o.type):
        return (
            "not a point of this corner (pushrod and rocker points need actuation pushrod_rocker)"
        )
    if key in mechanisms.STEERING_POINTS["rack"] + mechanisms.STEERING_POINTS["none"]:
        return f"not a point of a {o.type} corner (it has no trackrod or toe link)"
    for other in mechanisms.NAMES:
        if other != o.type and key in points(mechanisms.get(other), other):
            return f"not a point of a {o.type} corner (it is a {other} point; check 'type')"
    return f"unknown hardpoint (this corner has: {', '.join(names)})"
