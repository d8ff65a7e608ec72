"""The axle file (``scope: axle``, docs/axle.md): both corners, each with its side's
setup, and the shared elements' points and options, read and checked (``load_axle``)
into an AxleGeometry; a right side drawn as the left mirrored (``mirror_corner``).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..io.yamlio import Reader, load_yaml
from ..model.compose import SHARED, compose_tree
from ..model.deadcentre import warn_dead_centres
from ..model.forms import canonical_axle
from ..model.geometry import MM, Geometry, summary_repr
from ..model.packaging import mirrored_driveshaft
from .assembly import Assembly
from .elements import elements_of
from .elements.anti_roll_bar import mount_body

SIDES = ("left", "right")
ANTI_ROLL = ("none", "u_bar", "t_bar")
HEAVE_LINK = ("none", "rocker_to_rocker")
# per-side points of the axle elements (not the corner's), by what needs them
SIDE_EXTRAS = {
    "u_bar": ("droplink_rocker", "droplink_u_bar"),
    "u_bar_direct": ("droplink_lower", "droplink_u_bar"),
    "t_bar": ("droplink_rocker", "droplink_t_bar"),
    "t_bar_direct": ("droplink_lower", "droplink_t_bar"),
    "rocker_to_rocker": ("heave_link_rocker",),
}
CENTER = {"u_bar": ("arb_u_bar_axis_a", "arb_u_bar_axis_b"), "t_bar": ("arb_t_bar_pivot",)}
# the axle's own sensitivity columns, after each side's (docs/axle.md's names)
AXLE_COLUMNS = (
    "body_roll",
    "camber_to_ground_left",
    "camber_to_ground_right",
    "track",
    "roll_center_y",
    "roll_center_z",
    "deriv_camber_wrt_roll_left",
    "deriv_camber_wrt_roll_right",
    "deriv_roadwheel_angle_wrt_roll_left",
    "deriv_roadwheel_angle_wrt_roll_right",
    "deriv_roll_center_y_wrt_roll",
    "deriv_roll_center_z_wrt_roll",
)
VEHICLE_KEYS = ("cg_position", "wheelbase", "front_brake_bias", "driven_axle")
AXLE_KEYS = (
    "axle_position",
    "steering",
    "wheel",
    "inertia",
    "actuation",
    "spring",
    "strut",
    "anti_roll",
    "heave_link",
    "left_setup",
    "right_setup",
    "driveshaft",
    "limits",
)


@dataclass(frozen=True)
class AxleGeometry:
    """Both corners (their Geometry as drawn, each with its side's setup: AxleModel
    applies it), the axle elements' points and options."""

    name: str
    left: Geometry
    right: Geometry
    anti_roll: str
    anti_roll_mount: str | None  # the body a droplink's lower end rides on (no rocker)
    anti_roll_stiffness: float | None  # N·m/deg (for loads); inf: a rigid (locked) bar
    heave_link: str
    side_points: dict  # side → {point: (3,) m}: droplinks, heave link ends
    center: dict  # point → (3,) m: the bar's axis or pivot
    mirrored: bool  # the right side drawn as the left mirrored
    source: str = "<dict>"
    sha256: str | None = None
    data: dict = field(default_factory=dict, repr=False)

    def corner(self, side: str) -> Geometry:
        return self.left if side == "left" else self.right

    def __repr__(self) -> str:
        return summary_repr(
            self,
            lambda: (
                self.source,
                self.name,
                self.left.type,
                self.left.steering,
                "" if self.anti_roll == "none" else f"anti-roll {self.anti_roll}",
                "" if self.heave_link == "none" else f"heave link {self.heave_link}",
                "right mirrored" if self.mirrored else "",
            ),
        )

    @property
    def anti_roll_rigid(self) -> bool:
        """A bar that does not twist: the axle cannot roll."""
        return self.anti_roll_stiffness is not None and np.isinf(self.anti_roll_stiffness)


class AxleReader(Reader):
    """A Reader of a corner assembled from the axle file: each key it blames is named
    as it stands in the axle file (``config.wheel`` → ``axle_config.wheel``)."""

    def __init__(self, source: str, side: str):
        super().__init__(source)
        self.renames = [
            ("hardpoints", f"hardpoints.{side}"),
            ("config.camber_shim", f"axle_config.{side}_setup.camber_shim"),
            ("config.setup", f"axle_config.{side}_setup"),
            ("config.steering", "axle_config.steering"),
            ("config.wheel", "axle_config.wheel"),
            ("config.axle_position", "axle_config.axle_position"),
            *((f"config.{k}", f"vehicle_config.{k}") for k in VEHICLE_KEYS),
            ("actuation", "axle_config.actuation"),
            ("spring", "axle_config.spring"),
            ("config", "axle_config"),
        ]

    def fail(self, key: str, problem: str):
        for old, new in self.renames:
            if key == old or key.startswith(old + ".") or key.startswith(old + "["):
                key = new + key[len(old) :]
                break
        raise InputError(self.source, key, problem)


def load_axle(source, warn_as: str | None = None) -> AxleGeometry:
    """Read and validate an axle file (``scope: axle``, docs/axle.md): a path or a dict
    (``warn_as``: the file a dict came from, for the warnings; its errors say <dict>)."""
    from ..model.geometry import parse_geometry, warn_implausible

    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(
        data,
        "",
        required=("hardpoints", "axle_config"),
        optional=("type", "scope", "name", "version", "units", "force_units", "vehicle_config")
        + ("compliance", "clearance"),  # docs/compliance.md, docs/clearance.md
    )
    data = canonical_axle(data, r)  # mm and N, spindle points, rocker axes (model/forms.py)
    if r.choice(data.get("scope", "corner"), "scope", ("corner", "axle")) != "axle":
        r.fail("scope", "this is a corner file (scope: corner): load it with load_geometry")
    if "version" in data:
        r.text(data["version"], "version")
    vehicle = r.mapping(data.get("vehicle_config", {}), "vehicle_config", optional=VEHICLE_KEYS)
    config = r.mapping(
        data["axle_config"], "axle_config", required=("axle_position", "wheel"), optional=AXLE_KEYS
    )
    anti = r.mapping(
        config.get("anti_roll", {}),
        "axle_config.anti_roll",
        optional=("type", "mount", "stiffness"),
    )
    anti_roll = r.choice(anti.get("type", "none"), "axle_config.anti_roll.type", ANTI_ROLL)
    stiffness = _stiffness(anti, anti_roll, r)
    heave_map = r.mapping(
        config.get("heave_link", {}), "axle_config.heave_link", optional=("type",)
    )
    heave = r.choice(heave_map.get("type", "none"), "axle_config.heave_link.type", HEAVE_LINK)
    hp = r.mapping(
        data["hardpoints"], "hardpoints", required=("left",), optional=("right", "center")
    )
    mirrored = "right" not in hp
    if mirrored and "right_setup" in config:
        r.fail(
            "axle_config.right_setup",
            "a right_setup needs the right corner's own points (hardpoints.right): a "
            "mirrored right side takes the left's setup",
        )
    actuation = config.get("actuation", {})
    has_rocker = isinstance(actuation, dict) and actuation.get("type") == "pushrod_rocker"
    extras = ()
    if anti_roll != "none":
        extras += SIDE_EXTRAS[anti_roll if has_rocker else f"{anti_roll}_direct"]
    if heave != "none":
        if not has_rocker:
            r.fail(
                "axle_config.heave_link.type",
                "a rocker-to-rocker heave link needs pushrod_rocker actuation",
            )
        extras += SIDE_EXTRAS[heave]
    mount = None
    if anti_roll != "none" and not has_rocker:
        mount = r.text(anti.get("mount", "upright"), "axle_config.anti_roll.mount")
    elif "mount" in anti:
        r.fail("axle_config.anti_roll.mount", "the droplinks hang from the rockers here")

    corners, side_points = {}, {}
    for side in SIDES:
        points = hp["left"] if side == "left" or mirrored else hp["right"]
        key = "hardpoints.left" if side == "left" or mirrored else "hardpoints.right"
        if not isinstance(points, dict):
            r.fail(key, "expected a mapping of point name to {x, y, z}")
        for k in points:
            if any(k in names for names in CENTER.values()):
                r.fail(f"{key}.{k}", "a point of the anti-roll bar's: it goes in hardpoints.center")
            if k not in extras and any(k in names for names in SIDE_EXTRAS.values()):
                r.fail(
                    f"{key}.{k}",
                    f"a point of an anti-roll bar or heave link, which this axle does not have "
                    f"(axle_config.anti_roll.type: {anti_roll}, heave_link.type: {heave})",
                )
        corner_points = {k: v for k, v in points.items() if k not in extras}
        missing = [k for k in extras if k not in points]
        if missing:
            r.fail(
                f"{key}.{missing[0]}",
                "missing point (the axle's anti-roll bar or heave link needs it)",
            )
        setup = config.get("right_setup" if side == "right" and not mirrored else "left_setup", {})
        setup_key = f"axle_config.{'right' if side == 'right' and not mirrored else 'left'}_setup"
        setup = r.mapping(
            setup,
            setup_key,
            optional=("camber_shim", "trackrod_length_delta", "pushrod_length_delta"),
        )
        corner_config = {
            k: config[k]
            for k in ("steering", "wheel", "axle_position", "inertia", "strut", "limits")
            if k in config
        }
        if "driveshaft" in config:  # its inboard axis given for the left (packaging.py)
            shaft = config["driveshaft"]
            corner_config["driveshaft"] = mirrored_driveshaft(shaft) if side == "right" else shaft
        corner_config |= {k: vehicle[k] for k in VEHICLE_KEYS if k in vehicle}
        if "camber_shim" in setup:
            corner_config["camber_shim"] = setup["camber_shim"]
        adjusters = {
            k: setup[k] for k in ("trackrod_length_delta", "pushrod_length_delta") if k in setup
        }
        if adjusters:
            corner_config["setup"] = adjusters
        corner = {
            "type": data.get("type", "double_wishbone"),
            "side": "left",
            "name": f"{data.get('name', 'unnamed axle')} ({side})",
            "units": data.get("units", "millimeters"),
            "hardpoints": corner_points,
            "config": corner_config,
        }
        corner |= {k: config[k] for k in ("actuation", "spring") if k in config}
        corner |= {k: data[k] for k in ("compliance",) if k in data}
        if side == "right":
            corner["side"] = "right"
            if mirrored:
                corner = mirror_corner(corner)
        reader = AxleReader(name, "left" if side == "left" or mirrored else "right")
        corners[side] = parse_geometry(corner, reader, sha)
        sign = 1.0 if side == "left" else -1.0
        side_points[side] = {
            k: reader.point(points[k], f"{key}.{k}")
            * MM
            * np.array([1.0, sign if mirrored and side == "right" else 1.0, 1.0])
            for k in extras
        }
    for side in SIDES if anti_roll != "none" else ():
        sp = side_points[side]
        upper = "droplink_rocker" if "droplink_rocker" in sp else "droplink_lower"
        lower = "droplink_u_bar" if anti_roll == "u_bar" else "droplink_t_bar"
        if np.linalg.norm(sp[upper] - sp[lower]) < 1e-3:
            key = "hardpoints.left" if side == "left" or mirrored else "hardpoints.right"
            r.fail(f"{key}.{lower}", f"coincides with {upper}: the droplink has no length")
    center = {}
    wanted = CENTER.get(anti_roll, ())
    center_map = r.mapping(hp.get("center", {}), "hardpoints.center", optional=wanted)
    for k in wanted:
        if k not in center_map:
            r.fail(
                f"hardpoints.center.{k}", f"missing point (a {anti_roll} anti-roll bar needs it)"
            )
        center[k] = r.point(center_map[k], f"hardpoints.center.{k}") * MM
    if anti_roll == "t_bar":
        _check_t_bar(center["arb_t_bar_pivot"], side_points, mirrored, r)
    if anti_roll == "u_bar":
        a, b = center["arb_u_bar_axis_a"], center["arb_u_bar_axis_b"]
        if np.linalg.norm(b - a) < 1e-6:
            r.fail(
                "hardpoints.center.arb_u_bar_axis_b",
                "coincides with arb_u_bar_axis_a: the bar's axis needs two points",
            )
    if mount is not None:
        g = corners["left"]
        bodies = [b.name for b in g.mechanism.tree(g).bodies if b.name not in SHARED]
        if mount_body(g, mount) not in bodies:
            r.fail(
                "axle_config.anti_roll.mount",
                f"expected the body that carries the droplink: one of {', '.join(bodies)}",
            )
    if anti_roll == "u_bar":
        a, b = center["arb_u_bar_axis_a"], center["arb_u_bar_axis_b"]
        axis = (b - a) / np.linalg.norm(b - a)
        for side in SIDES:
            arm = side_points[side]["droplink_u_bar"] - a
            if np.linalg.norm(arm - axis * (arm @ axis)) < 1e-3:
                key = "hardpoints.left" if side == "left" or mirrored else "hardpoints.right"
                r.fail(
                    f"{key}.droplink_u_bar",
                    "lies on the bar's axis (within 1 mm): the droplink cannot turn the arm",
                )
    for g in corners.values():
        warn_implausible(g)
    axle = AxleGeometry(
        name=r.text(data.get("name", "unnamed axle"), "name"),
        left=corners["left"],
        right=corners["right"],
        anti_roll=anti_roll,
        anti_roll_mount=mount,
        anti_roll_stiffness=stiffness,
        heave_link=heave,
        side_points=side_points,
        center=center,
        mirrored=mirrored,
        source=name,
        sha256=sha,
        data=data,
    )
    # a mirrored right side repeats its left's: said once, for the left
    trees = {
        side: g.mechanism.tree(g) for side, g in zip(SIDES, (axle.left, axle.right), strict=True)
    }
    tree = compose_tree(trees, "axle", elements_of(axle))
    warn_dead_centres(tree, warn_as or name, mirrored)
    return axle


def _stiffness(anti: dict, anti_roll: str, r: Reader) -> float | None:
    """``anti_roll.stiffness``: N·m/deg (> 0), or ``rigid`` (or .inf) for a locked bar."""
    if "stiffness" not in anti:
        return None
    key = "axle_config.anti_roll.stiffness"
    if anti_roll == "none":
        r.fail(key, "there is no anti-roll bar (anti_roll.type: none)")
    value = anti["stiffness"]
    if value == "rigid" or (isinstance(value, float) and value == np.inf):
        return np.inf
    if isinstance(value, str):
        r.fail(key, f"expected N·m/deg (a number > 0) or rigid, got {value!r}")
    return r.positive(value, key)


def _check_t_bar(hub: np.ndarray, side_points: dict, mirrored: bool, r: Reader) -> None:
    """The T-bar's pivot on the centreline, its crossbar's midpoint in y = 0 and its
    stem (pivot → midpoint) of some length: the universal joint it turns on."""
    if abs(hub[1]) > 1e-6:
        r.fail("hardpoints.center.arb_t_bar_pivot", "must lie on the centreline (y = 0)")
    ends = [side_points[s]["droplink_t_bar"] for s in SIDES]
    key = "hardpoints.left" if mirrored else "hardpoints.right"
    if abs(ends[0][1] + ends[1][1]) > 2e-5:
        r.fail(
            f"{key}.droplink_t_bar",
            "the crossbar's ends must be mirror images in y (its midpoint on y = 0)",
        )
    if np.linalg.norm(0.5 * (ends[0] + ends[1]) - hub) < 1e-3:
        r.fail(
            "hardpoints.center.arb_t_bar_pivot",
            "lies on the crossbar's midpoint (within 1 mm): the T-bar needs a stem",
        )


def mirror_corner(corner: dict) -> dict:
    """A corner dict mirrored through y = 0: points' y and the shim normal's y negated."""
    out = copy.deepcopy(corner)

    def flip(p):
        if isinstance(p, dict) and "y" in p:
            p["y"] = (
                -p["y"]
                if isinstance(p["y"], int | float) and not isinstance(p["y"], bool)
                else p["y"]
            )
        elif isinstance(p, list) and len(p) == 3 and isinstance(p[1], int | float):
            p[1] = -p[1]

    for p in out["hardpoints"].values():
        flip(p)
    shim = out.get("config", {}).get("camber_shim")
    if isinstance(shim, dict):
        for k in ("shim_face_point_a", "shim_face_point_b", "shim_face_normal"):
            if k in shim:
                flip(shim[k])
    return out


# Assembly surface for setup and sensitivity (AxleModel's; kept out of axle.py, at its cap)
def holds_wheels(sweep) -> bool:
    """Whether an axle's sweep holds what its sensitivities hold: each wheel centre's
    height and the rack (its roll and heave targets hold other quantities)."""
    keys = set()
    for t in sweep.targets:
        if t.quantity is not None:
            return False
        d = tuple(t.unit_direction.tolist())
        if (t.point, d) == ("wheel_center", (0.0, 0.0, 1.0)):
            keys.add(t.side)
        elif t.point != "trackrod_inboard":
            return False
    return keys == set(SIDES)


class AxleAssembly(Assembly):
    """An axle's answers to what takes an Assembly (AxleModel's, from its file
    ``self.axle``, an AxleGeometry): its own static columns of both sides together, the
    sides a setup sets (a mirrored axle: both, from the left's), the keys its file names
    and the setup written back into it."""

    axle: AxleGeometry | None
    static_columns = (("track", "track"), ("roll_center_y", "RC y"), ("roll_center_z", "RC z"))
    noun = "axle"  # validate's messages
    element_points = frozenset(n for ns in (*SIDE_EXTRAS.values(), *CENTER.values()) for n in ns)
    sensitivity_columns = AXLE_COLUMNS
    sensitivity_pairs = (SIDES,)
    drawing_views = ("front",)
    drawn_at_steps = True

    def marker_places(self, results) -> dict:
        """Its roll centre at each step (m, (n, 3); NaN where blank): y and z from the
        ``roll_center_y``/``_z`` columns, x midway between the contact patches (the
        front view it is found in)."""
        x = 0.5 * (results["left_contact_patch_center_x"] + results["right_contact_patch_center_x"])
        columns = [x, results["roll_center_y"], results["roll_center_z"]]
        return {"roll_centre": 1e-3 * np.column_stack(columns)}

    @classmethod
    def as_drawn(cls, path, label: str | None = None) -> AxleAssembly:
        drawn = cls.__new__(cls)  # no model built: the setup surface alone
        drawn.axle = axle = load_axle(path)
        drawn.source, drawn.name = axle.source, axle.name
        drawn.corners = {"left": axle.left, "right": axle.right}
        return drawn

    def setup_labels(self, label: str | None = None) -> tuple[str, ...]:
        chosen = super().setup_labels(label)
        if label is not None and self.setup_owner("right") != "right":
            raise InputError(
                "--side",
                "",
                f"{self.source} is a mirrored axle (no hardpoints.right): its right side takes "
                "the left's setup, so one setup sets both sides; give the right corner's own "
                "points (hardpoints.right, with axle_config.right_setup) to set one side alone",
            )
        return chosen

    def setup_owner(self, label: str) -> str:
        mirrored = self.axle is not None and self.axle.mirrored
        return "left" if mirrored and label == "right" else label

    def file_key(self, label: str, key: str) -> str:
        try:
            AxleReader(self.source, self.setup_owner(label)).fail(key, "")
        except InputError as renamed:
            return renamed.key

    def setup_data(self, geometries: dict[str, Geometry]) -> dict:
        from ..solve.as_set import axle_data

        return axle_data(self.axle, geometries)

    def sensitivity_sweep(self, sweep) -> tuple[list, object]:
        from .corner import Results  # the solver's columns alone: what the report reads

        solutions = self.solve_steps(sweep)
        columns, units = Results.solver_columns(solutions)
        source = (self.axle.source, self.axle.sha256) if self.axle else ("<geometries>", None)
        meta = Results.solver_meta(solutions, source, sweep, self)
        return solutions, Results(columns, units, meta)

    def held_at(self, sweep, step: int) -> None:
        return None  # each wheel centre's height and the rack: the sides share nothing else

    def sensitivities_hold(self, sweep) -> bool:
        return holds_wheels(sweep)

    def sensitivity_held(self) -> str:
        rack = " and the rack" if self.model.existJointName("rack_slide") else ""
        return f"each wheel centre's height{rack} held"

    def sensitivity_groups(self, columns: list[str]) -> list[tuple[str, list]]:
        own = [n for n in columns if n not in self.sensitivity_columns]
        groups = [("the axle:", self.sensitivity_columns), *super().sensitivity_groups(own)]
        if self.setup_owner("right") != "right":
            groups.append(("the right corner's columns mirror the left's (a mirrored axle)", ()))
        return groups
