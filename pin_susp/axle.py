"""An axle: two corners on one chassis, one rack, one Pinocchio model (docs/axle.md).

This first part composes the model. Each corner's tree (its mechanism
module's) is prefixed by its side — ``left_upright``, ``left_upper_ball_joint``,
``left_wheel_center`` — and both hang from one chassis; the rack is one body
on one prismatic joint that carries both trackrods' inboard ends. The model
is parsed from the composed URDF like a corner's (:class:`linkage.Built`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace

import numpy as np
import pinocchio as pin

from . import __version__
from .assembly import Assembly
from .bulk import MIN_STEPS, Frames, rows_of, solve_all, tree_of
from .constraints import (
    WORLD,
    ContactPatchPoint,
    HeaveTarget,
    JointTarget,
    PointTarget,
    RollTarget,
)
from .corner import Results
from .deadcentre import dead_centres, warn_dead_centres
from .errors import InputError
from .geometry import DERIVED_POINTS, MM, Geometry, summary_repr, unit
from .linkage import RACK_HELD, Built, FrameMotion, Linkage, closure_row
from .march import march
from .mechanisms import axis_foot, xml_name
from .solver import NewtonSolver
from .sweep import Target, check_held
from .tree import Body, Closure, Joint, Tree, Visual
from .vectors import roll_centre
from .yamlio import Reader, load_yaml

SIDES = ("left", "right")
SHARED = ("chassis", "rack")  # bodies both corners hang from


def _corner_point(name: str, point_names: dict) -> bool:
    side, _, rest = name.partition("_")
    return side in point_names and rest in point_names[side]


def prefixed(tree: Tree, side: str) -> Tree:
    """The corner's tree with every body, joint, point and closure named ``side_…``;
    the chassis and the rack stay shared."""

    def body(name: str) -> str:
        return name if name in SHARED else f"{side}_{name}"

    def point(name: str) -> str:
        return f"{side}_{name}"

    def link(name: str) -> str:  # a closure anchor sits on a point's link or a body
        return point(name) if name in tree.points else body(name)

    bodies = [
        Body(
            body(b.name),
            None if b.parent is None else body(b.parent),
            None
            if b.joint is None or b.name in SHARED
            else replace(b.joint, name=body(b.joint.name)),
        )
        if b.name not in SHARED
        else b
        for b in tree.bodies
    ]
    points = {point(n): (body(b), p) for n, (b, p) in tree.points.items()}
    closures = [
        replace(
            c,
            name=f"{side}_{c.name}",
            anchors=tuple((link(a), p) for a, p in c.anchors),
            points=tuple(point(n) for n in c.points),
            branch=tuple(point(n) for n in c.branch),
            branch_fallback=tuple(point(n) for n in c.branch_fallback),
        )
        for c in tree.closures
    ]
    visuals = [replace(v, body=body(v.body)) for v in tree.visuals]
    # the spring's ends (two points, or a torsion bar's joint) and the wheel's body
    springs = [
        replace(
            s,
            side=side,
            ends=tuple(point(e) if e in tree.points else body(e) for e in s.ends),
        )
        for s in tree.springs
    ]
    corners = [
        {**m, "wheel_link": body(m["wheel_link"])} if "wheel_link" in m else dict(m)
        for m in tree.corners
    ]
    return Tree(
        f"{side}_{tree.name}",
        bodies,
        points,
        closures,
        visuals,
        dict(tree.materials),
        density=tree.density,
        wheel_mass=tree.wheel_mass,
        spring=springs,
        metadata=corners,
    )


def axle_tree(left: Geometry, right: Geometry, name: str = "axle", elements=None) -> Tree:
    """Both corners' trees under one chassis, the rack shared; ``elements`` (an
    AxleGeometry) adds the anti-roll bar and the heave link's points."""
    trees = {
        side: prefixed(g.mechanism.tree(g), side)
        for side, g in zip(SIDES, (left, right), strict=True)
    }
    bodies, seen = [], set()
    for tree in trees.values():
        for b in tree.bodies:
            if b.name not in seen:  # the chassis, and the rack, once (the left's)
                bodies.append(b)
                seen.add(b.name)
    points, closures, visuals, materials = {}, [], [], {}
    springs, corners = [], []
    for tree in trees.values():
        points |= tree.points
        closures += tree.closures
        visuals += tree.visuals
        materials |= tree.materials
        springs += tree.springs
        corners += tree.corners
    if elements is not None:
        _add_elements(elements, bodies, points, closures, visuals, materials)
    # the masses: the left's density and wheel mass (config.inertia is the axle's, so the
    # sides' are the same); each side's spring and <pin_susp:corner>
    left_tree = trees["left"]
    return Tree(
        name,
        bodies,
        points,
        closures,
        visuals,
        materials,
        density=left_tree.density,
        wheel_mass=left_tree.wheel_mass,
        spring=springs,
        metadata=corners,
    )


def _add_elements(a: AxleGeometry, bodies, points, closures, visuals, materials) -> None:
    """The anti-roll bar (a U-bar: an arm per side turning on the bar's axis, or one
    rigid bar when ``stiffness: rigid``; a T-bar: the crossbar on its pivot), a rigid
    droplink per side from the rocker (or the named body) to the bar, and the heave
    link's ends (measured only)."""
    from .mechanisms import BALL, ROD, pivot

    materials.setdefault("bar", (0.85, 0.75, 0.15, 1.0))
    for name, p in a.center.items():
        points[name] = ("chassis", p)
    if a.anti_roll == "u_bar":
        axis = ("arb_u_bar_axis_a", "arb_u_bar_axis_b")
        for side in SIDES if not a.anti_roll_rigid else ("left",):
            arm = "arb_bar" if a.anti_roll_rigid else f"{side}_arb_arm"
            bodies.append(Body(arm, "chassis", pivot(f"{arm}_pivot", *axis, a.center)))
        for side in SIDES:
            arm = "arb_bar" if a.anti_roll_rigid else f"{side}_arb_arm"
            end = a.side_points[side]["droplink_u_bar"]
            _droplink(a, side, "droplink_u_bar", arm, axis, points, closures)
            foot = axis_foot(a.center[axis[0]], a.center[axis[1]], end)
            visuals.append(Visual(arm, "rod", "bar", foot, end, ROD))
            visuals.append(Visual(arm, "ball", "bar", end, radius=BALL))
        visuals.append(
            Visual("chassis", "rod", "bar", a.center[axis[0]], a.center[axis[1]], 1.5 * ROD)
        )
    if a.anti_roll == "t_bar":
        hub = a.center["arb_t_bar_pivot"]
        ends = {side: a.side_points[side]["droplink_t_bar"] for side in SIDES}
        middle = 0.5 * (ends["left"] + ends["right"])
        # the crossbar's midpoint stays in y = 0: the stem pitches about chassis y and
        # the crossbar twists about the stem (a universal joint: exactly the ball with
        # the midpoint held in the plane); a rigid bar only pitches
        y, stem = np.array([0.0, 1.0, 0.0]), unit(middle - hub)
        joint = (
            Joint("t_bar_pivot", "revolute", hub, y)
            if a.anti_roll_rigid
            else Joint("t_bar_pivot", "universal", hub, y, ("arb_t_bar_pivot",), stem)
        )
        bodies.append(Body("t_bar", "chassis", joint))
        for side in SIDES:
            other = f"{'right' if side == 'left' else 'left'}_droplink_t_bar"
            guard = ("arb_t_bar_pivot", other)
            _droplink(a, side, "droplink_t_bar", "t_bar", guard, points, closures)
            visuals.append(Visual("t_bar", "ball", "bar", ends[side], radius=BALL))
        visuals.append(Visual("t_bar", "rod", "bar", ends["left"], ends["right"], 1.5 * ROD))
        visuals.append(Visual("t_bar", "rod", "bar", hub, middle, 1.5 * ROD))
    if a.heave_link != "none":
        for side in SIDES:
            points[f"{side}_heave_link_rocker"] = (
                f"{side}_rocker",
                a.side_points[side]["heave_link_rocker"],
            )


def _droplink(a: AxleGeometry, side: str, lower: str, bar: str, guard, points, closures):
    """One side's rigid droplink: from the rocker (or the body ``anti_roll.mount``
    names) to the point ``lower`` on the bar's body; its assembly is kept by the sign
    of the volume of the two ``guard`` points and its ends."""
    sp = a.side_points[side]
    upper = "droplink_rocker" if "droplink_rocker" in sp else "droplink_lower"
    carrier = f"{side}_rocker" if upper == "droplink_rocker" else _mount(a, side)
    points[f"{side}_{lower}"] = (bar, sp[lower])
    points[f"{side}_{upper}"] = (carrier, sp[upper])
    ends = (f"{side}_{upper}", f"{side}_{lower}")
    closures.append(
        Closure(
            f"{side}_droplink",
            "distance",
            tuple((n, points[n][1]) for n in ends),
            ends,
            branch=(*guard, *ends),
        )
    )


def _mount(a: AxleGeometry, side: str) -> str:
    """The body that carries a droplink's lower end when there is no rocker."""
    return f"{side}_{_mount_body(a.corner(side), a.anti_roll_mount)}"


def _mount_body(g: Geometry, mount: str) -> str:
    """``anti_roll.mount`` as a body of the corner's tree ("arm": the wheel's body)."""
    return {"arm": g.mechanism.WHEEL_BODY}.get(mount, mount)


class AxleModel(Assembly):
    """The composed model: its URDF, Pinocchio model, points (``left_…``, ``right_…``,
    contact patches included), closures and branches, at the design state.

    ``AxleModel(axle)`` for an axle file (a path or a dict, read by ``load_axle``) or
    an AxleGeometry (its bar and heave link included), or ``AxleModel(left, right)``
    for two corner Geometries. ``pin_susp.Axle`` is the same class.

    >>> axle = pin_susp.Axle("examples/axle_front.yaml")
    >>> axle
    <AxleModel 'axle_front.yaml' 'front axle with U-bar': double_wishbone, 2 corners, ...>
    >>> results = axle.run_sweep("examples/roll.yaml")
    >>> results["roll_center_z"], results["camber_left"]  # mm, deg: numpy arrays
    >>> results.to_pandas()  # a DataFrame, a row per step; results.plot("axle.png")

    ``axle.geometries["left"]`` is each side's as-set Geometry (m; its
    ``hardpoints_mm`` in mm), ``axle.axle`` the AxleGeometry (None for two corners).
    As an Assembly (assembly.py): labels ``left``, ``right``; ``corners`` the geometries.
    """

    labels = SIDES

    def __init__(self, left, right: Geometry | None = None, name: str = "axle"):
        elements = None
        if right is None and not isinstance(left, AxleGeometry):  # an axle file
            left = load_axle(left)
        if right is None:  # an AxleGeometry
            elements, name = left, left.name
            left, right = elements.left, elements.right
        self.axle, self.name = elements, name
        self.source = elements.source if elements is not None else "<geometries>"
        self.anti_roll_rigid = elements is not None and elements.anti_roll_rigid
        # shims and length adjusters first, per side: the as-set corners (as Corner does)
        from .as_set import apply_setup

        left, right = apply_setup(left), apply_setup(right)
        self.geometries = self.corners = dict(zip(SIDES, (left, right), strict=True))
        self.tree = axle_tree(left, right, xml_name(name, "axle"), elements)
        built = Built(self.tree, f"generated by pin_susp {__version__}: an axle")
        self.urdf, self.model, self.kin = built.urdf, built.model, built.kin
        self.points = dict(built.points)
        self.closures, self.branches = built.closures, built.branches
        self.dead_centres = dead_centres(self.tree)  # for the failure report
        self.q_design = built.q_design
        self.point_names = {}
        for side, g in self.geometries.items():
            p = lambda n, side=side: f"{side}_{n}"  # noqa: E731
            self.points[p("contact_patch_center")] = ContactPatchPoint(
                p("contact_patch_center"),
                self.points[p("wheel_center")],
                self.points[p("axle_inboard")],
                self.points[p("axle_outboard")],
                g.wheel.radius,
                f"{side}_{g.mechanism.WHEEL_BODY}",
            )
            self.point_names[side] = tuple(g.hardpoints) + DERIVED_POINTS
        self.mobility = self.model.nv - sum(c.size for c in self.closures)
        # the points written: each corner's, then the bar's and heave link's
        extras = [n for n in self.tree.points if not _corner_point(n, self.point_names)]
        self.output_points = []  # left's points, then right's (the bar's by side), centre's
        for side, names in self.point_names.items():
            self.output_points += [f"{side}_{n}" for n in names]
            self.output_points += [n for n in extras if n.startswith(f"{side}_")]
        self.output_points += [n for n in extras if not n.startswith(SIDES)]
        self.frame_names = [n for n in self.output_points if "contact_patch_center" not in n]
        self.kin.update(self.q_design)
        self.design_positions = self.positions(self.q_design)
        if elements is not None:
            self._check_determined(elements.source)
        self.design_steer = {}
        for side, g in self.geometries.items():
            d = self.design_positions
            a = d[f"{side}_axle_outboard"] - d[f"{side}_axle_inboard"]
            self.design_steer[side] = -g.sign * np.degrees(np.arctan2(a[0], g.sign * a[1]))
        self.spring_sense = {
            side: (Linkage(g).spring_sense if g.spring == "torsion_bar" else 1.0)
            for side, g in self.geometries.items()
        }

    def __repr__(self) -> str:
        def parts():
            g = self.geometries["left"]
            a = self.axle
            return (
                self.source,
                self.name,
                g.type,
                f"{len(self.geometries)} corners",
                g.steering,
                "pushrod_rocker" if g.actuation == "pushrod_rocker" else "",
                "" if g.spring == "none" else g.spring,
                "" if a is None or a.anti_roll == "none" else f"anti-roll {a.anti_roll}",
                "" if a is None or a.heave_link == "none" else f"heave link {a.heave_link}",
                f"{self.mobility} inputs",
            )

        return summary_repr(self, parts)

    def held_sweep(self, sweep):
        """The sweep as its steps hold it: on an axle with a rack whose sweep gives every
        target but the rack's (heave and roll, or a wheel height per side), the rack held
        at design (rack_displacement 0; the summary says so), as a corner's is
        (Linkage.held_targets). Any other sweep as given (solve_axle_sweep checks it)."""
        targets = sweep.targets
        if "left_trackrod_inboard" not in self.points or len(targets) != self.mobility - 1:
            return sweep
        if any(t.point == "trackrod_inboard" for t in targets):
            return sweep
        rack = Target("trackrod_inboard", "y", np.zeros(sweep.steps), side="left")
        return replace(sweep, targets=[*targets, rack])

    def sweep_notes(self, sweep) -> list[str]:
        """What the summary says of how the sweep's targets were read."""
        return [RACK_HELD] if self.held_sweep(sweep) is not sweep else []

    def run_sweep(self, sweep, progress=None) -> AxleResults:
        """Solve every step of an axle sweep (a path, a dict or a Sweep: heave, roll,
        wheel heights, the rack; docs/axle.md) and compute every column.

        >>> results = axle.run_sweep("examples/roll.yaml")
        >>> results["camber_left"], results["roll_center_z"]  # deg, mm
        >>> results.to_pandas()  # the CSV's columns as a DataFrame; results.plot(path)

        ``progress(done, total)``: called after each step."""
        from .sweep import Sweep, load_sweep

        if not isinstance(sweep, Sweep):
            sweep = load_sweep(sweep)
        return self.solve_sweep(sweep, progress)[1]

    def solve_sweep(self, sweep, progress=None) -> tuple[list, AxleResults]:
        """Every step solved: the solutions and their results (run_sweep's)."""
        solutions = solve_axle_sweep(self, sweep, progress=progress)
        return solutions, axle_results(self, sweep, solutions)

    def check_sweep(self, sweep) -> None:
        """The sweep's target errors, before any work (as its solve finds them first)."""
        check_held(sweep)
        axle_rows(self, self.held_sweep(sweep).targets, sweep.source)

    def _check_determined(self, source: str) -> None:
        """Both wheel heights and the rack must fix the pose at design (the closures
        with them of full rank): else a part turns freely — a droplink square to its
        bar arm's motion (dead centre), a bar axis along a droplink."""
        solver = NewtonSolver(self.kin, self.closures, _drive_rows(self), self.branches)
        solver.evaluate(self.q_design)
        s = np.linalg.svd(solver.jacobian, compute_uv=False)
        if s[-1] <= 1e-9 * s[0]:
            raise InputError(
                source,
                "hardpoints",
                "the wheels and the rack do not fix the axle's pose at design: a part turns "
                "freely (a droplink square to its bar arm's motion — at dead centre — or "
                "in line with the bar's axis?)",
            )

    def positions(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """World position (m) of every named point (prefixed) at configuration q."""
        pin.framesForwardKinematics(self.model, self.kin.data, q)
        return {n: self.points[n].position(self.kin).copy() for n in self.output_points}

    def motion(self, qs: list, solutions: list | None = None) -> dict:
        """Every point (prefixed) at each configuration (None: NaN), as a jet.Dual per
        side: its rates along that side's hub z and the rack (or its toe link);
        ``solutions``: the sweep's, whose exact tangents spare a solve per step."""
        return _motion(self, qs, solutions)

    def side_positions(self, q: np.ndarray, side: str) -> dict[str, np.ndarray]:
        """One corner's points at q, by their corner names."""
        all_points = self.positions(q)
        return {n: all_points[f"{side}_{n}"] for n in self.point_names[side]}

    def solve(self, wheel_center_z: dict[str, float], rack: float = 0.0, q0=None):
        """A pose with each wheel centre at a height (m, absolute) and the rack at a
        displacement (m): the heave/roll drivers."""
        targets = [
            PointTarget(self.points[f"{side}_wheel_center"], np.array([0.0, 0.0, 1.0]), value)
            for side, value in wheel_center_z.items()
        ]
        if self.model.existJointName("rack_slide"):
            targets.append(JointTarget(self.model, "rack_slide", rack))
        goal = np.array([t.value for t in targets])
        q = self.q_design if q0 is None else q0
        self.kin.update_positions(q)
        start = np.array([t.residual(self.kin)[0] + t.value for t in targets])  # at q
        solver = NewtonSolver(self.kin, self.closures, targets, self.branches)
        return solver.solve(q, start, goal)

    # Assembly surface for loads, viz and drawing
    markers = ("roll_centre",)  # from roll_center_y, _z

    @property
    def spring_senses(self) -> dict[str, float]:
        return self.spring_sense

    @property
    def shared_springs(self) -> tuple:
        bar = self.axle
        if bar is None or bar.anti_roll == "none" or bar.anti_roll_rigid:
            return ()
        u_bar = ("left_arb_arm_pivot", "right_arb_arm_pivot")
        return (
            (u_bar if bar.anti_roll == "u_bar" else ("t_bar_pivot_b",), bar.anti_roll_stiffness),
        )

    def solve_steps(self, sweep, progress=None) -> list:
        return solve_axle_sweep(self, sweep, progress=progress)

    def sweep_results(self, sweep, solutions: list) -> AxleResults:
        return axle_results(self, sweep, solutions)

    def with_corners(self, corners: dict[str, Geometry]) -> AxleModel:
        if self.axle is None:
            return AxleModel(corners["left"], corners["right"])
        return AxleModel(replace(self.axle, **corners))


Axle = AxleModel  # pin_susp.Axle, as pin_susp.Corner: an axle file → a model to sweep


# ---------------------------------------------------------------- the axle file

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
VEHICLE_KEYS = ("cg_position", "wheelbase", "front_brake_bias", "driven_axle")
AXLE_KEYS = (
    "axle_position",
    "steering",
    "wheel",
    "inertia",
    "actuation",
    "spring",
    "anti_roll",
    "heave_link",
    "left_setup",
    "right_setup",
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
    from .geometry import parse_geometry, warn_implausible

    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(
        data,
        "",
        required=("hardpoints", "axle_config"),
        optional=("type", "scope", "name", "version", "units", "vehicle_config"),
    )
    if r.choice(data.get("scope", "corner"), "scope", ("corner", "axle")) != "axle":
        r.fail("scope", "this is a corner file (scope: corner): load it with load_geometry")
    if "version" in data:
        r.text(data["version"], "version")
    r.choice(data.get("units", "millimeters"), "units", ("millimeters",))
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
            k: config[k] for k in ("steering", "wheel", "axle_position", "inertia") if k in config
        }
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
        if _mount_body(g, mount) not in bodies:
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
    tree = axle_tree(axle.left, axle.right, "axle", axle)
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


# ---------------------------------------------------------------- sweeps

Z = np.array([0.0, 0.0, 1.0])


def axle_rows(model: AxleModel, targets, source: str = "<targets>") -> list:
    """The solver's rows for a sweep's targets on an axle (one value each, set later)."""
    rows, seen = [], {}
    p = model.points
    d = model.design_positions
    for i, t in enumerate(targets):
        if t.quantity is not None:
            what = t.quantity
        elif t.point == "trackrod_inboard":
            what = "the rack"  # one freedom, whichever side names it
        else:
            what = (t.side, t.point, tuple(np.round(t.unit_direction, 12)))
        if what in seen:
            also = " (the rack is one freedom: target it on one side)" if what == "the rack" else ""
            raise InputError(source, f"targets[{i}]", f"repeats targets[{seen[what]}]{also}")
        seen[what] = i
        if t.quantity == "roll" and np.any(np.abs(np.asarray(t.values, dtype=float)) >= 90.0):
            raise InputError(
                source,
                f"targets[{i}]",
                "roll is an angle over the track: it lies within ±90 deg (got "
                f"{np.abs(np.asarray(t.values, dtype=float)).max():g})",
            )
        if t.quantity == "heave":
            z0 = 0.5 * (d["left_wheel_center"][2] + d["right_wheel_center"][2])
            rows.append(HeaveTarget(p["left_wheel_center"], p["right_wheel_center"], z0))
        elif t.quantity == "roll":
            z0 = d["left_wheel_center"][2] - d["right_wheel_center"][2]
            wheels = (p["left_wheel_center"], p["right_wheel_center"])
            radii = [model.geometries[s].wheel.radius for s in SIDES]
            spin = [unit(d[f"{s}_axle_outboard"] - d[f"{s}_axle_inboard"]) for s in SIDES]
            model.kin.update_positions(model.q_design)
            rows.append(RollTarget(wheels, radii, model.kin, z0, spin=spin))
        else:
            if t.side is None:
                raise InputError(
                    source,
                    f"targets[{i}].side",
                    "missing: an axle's point targets name their corner (side: left|right)",
                )
            name = f"{t.side}_{t.point}"
            if name not in p:
                known = ", ".join(model.point_names[t.side])
                raise InputError(
                    source, f"targets[{i}].point", f"unknown point {t.point!r} (points: {known})"
                )
            rows.append(PointTarget(p[name], t.unit_direction))
    return rows


def target_values(model: AxleModel, targets) -> np.ndarray:
    """Each step's target values in SI: heave m, roll rad, points m (absolute)."""
    cols = []
    for t in targets:
        v = np.asarray(t.values, dtype=float)
        if t.quantity == "heave":
            cols.append(v * 1e-3)
        elif t.quantity == "roll":
            cols.append(np.radians(v))
        else:
            v = v * 1e-3
            if t.mode == "relative":
                v = v + model.design_positions[f"{t.side}_{t.point}"] @ t.unit_direction
            cols.append(v)
    return np.column_stack(cols)


def solve_axle_sweep(model: AxleModel, sweep, source: str | None = None, progress=None) -> list:
    """Solve every step in order, each from the last solution (halving on failure);
    the targets must fix the pose (as many as the axle's freedoms, independent).
    ``progress(done, total)`` is called after each step."""
    source = source or sweep.source
    check_held(sweep)
    sweep = model.held_sweep(sweep)
    rows = axle_rows(model, sweep.targets, source)
    rigid = model.anti_roll_rigid
    for i, t in enumerate(sweep.targets):
        if rigid and t.quantity == "roll":
            raise InputError(
                source,
                f"targets[{i}]",
                "roll is fixed by the rigid anti-roll bar (axle_config.anti_roll.stiffness: "
                "rigid): the axle only heaves, so a roll target is unreachable or redundant; "
                "give heave (or one wheel height) and the rack",
            )
    if len(rows) != model.mobility:
        need = (
            "its anti-roll bar is rigid, so it only heaves: heave or one wheel height"
            if rigid
            else "a wheel height per side, or heave and roll"
        )
        raise InputError(
            source,
            "targets",
            f"{len(rows)} target(s) given, this axle needs exactly {model.mobility} "
            f"({need}; and the rack)",
        )
    solver = NewtonSolver(model.kin, model.closures, rows, model.branches)
    solver.evaluate(model.q_design)
    if np.linalg.cond(solver.jacobian) > 1e10:
        raise InputError(
            source, "targets", "the targets do not fix the axle's pose at its design state"
        )
    values = target_values(model, sweep.targets)
    model.kin.update_positions(model.q_design)
    previous = np.array([row.residual(model.kin)[0] for row in rows]) + np.array(
        [getattr(row, "value", 0.0) for row in rows]
    )
    solver.keep_jacobian = True  # exact tangents: a better prediction, and the columns' rates
    drive = _drive_rows(model)
    found = []

    data, frames = model.kin.data, [model.points[f"{s}_wheel_center"].frame_id for s in SIDES]
    rack = (
        model.model.joints[model.model.getJointId("rack_slide")].idx_v if len(drive) > 2 else None
    )

    def per_driver(tangent: np.ndarray) -> tuple | list | None:
        """The drivers' rows times the tangent at the solution, J_drive·T (each wheel
        centre's z and the rack; the inverse is taken for all steps at once below). A
        rigid bar has fewer freedoms than drivers: its per-side rates stay blank. Every
        step's tangent at once (the sweep solved at once): J_drive·T left to below."""
        if tangent.shape[-1] != len(drive):
            return None if tangent.ndim == 2 else [None] * len(tangent)
        if tangent.ndim == 3:
            return [(t, None) for t in tangent]
        rows = [pin.getFrameJacobian(model.model, data, f, WORLD)[2] @ tangent for f in frames]
        if rack is not None:
            rows.append(tangent[rack])
        return tangent, np.array(rows)

    solutions = march(
        solver,
        values,
        model.q_design,
        previous,
        progress,
        tangents=found,
        keep=per_driver,
        bulk=True,
    )
    at_once = [i for i, f in enumerate(found) if f is not None and f[1] is None]
    if at_once:  # J_drive·T of every step solved at once, on the model's tree
        Q = np.array([solutions[i].q for i in at_once])
        _, J = Frames(tree_of(model.kin), frames).evaluate(Q)
        T = np.array([found[i][0] for i in at_once])
        rows = [np.einsum("nv,nvk->nk", Jf[:, 2], T) for Jf in J]
        if rack is not None:
            rows.append(T[:, rack])
        across = np.stack(rows, axis=1)
        for i, t, a in zip(at_once, T, across, strict=True):
            found[i] = (t, a)
    # dq per driver from dq per target, T·(J_drive·T)⁻¹, every step's in one call
    kept = [i for i, f in enumerate(found) if f is not None]
    if kept:
        across = np.array([found[i][1] for i in kept])
        ok = np.abs(np.linalg.det(across)) > 0.0
        inverse = np.full_like(across, np.nan)
        inverse[ok] = np.linalg.inv(across[ok])
        per_target = np.array([found[i][0] for i in kept])
        for i, tangent in zip(kept, per_target @ inverse, strict=True):
            found[i] = tangent
    for solution, tangent in zip(solutions, found, strict=True):
        solution.drive_tangent = tangent
    return solutions


def _drive_rows(model: AxleModel) -> list:
    """The drivers of the columns' rates: each wheel centre's z, and the rack."""
    drive = [PointTarget(model.points[f"{s}_wheel_center"], Z) for s in SIDES]
    if model.model.existJointName("rack_slide"):
        drive.append(JointTarget(model.model, "rack_slide"))
    return drive


# ---------------------------------------------------------------- columns


class AxleResults(Results):
    """Columns of a solved axle sweep (docs/axle.md, "Columns"), in output units; written
    as a corner's are (io.tables.csv_text): ``results["camber_left"]``,
    ``results.to_pandas()``, ``results.to_csv(path)``, ``results.plot(path)``."""


def axle_results(model: AxleModel, sweep, solutions: list) -> AxleResults:
    """Every corner column per side (suffix ``_left``/``_right``, derivatives along
    that side's wheel-centre z and the rack, the other wheel held), the axle's
    columns, then the points (``left_…``, ``right_…``, the bar's).

    >>> results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    >>> results.to_pandas()  # a DataFrame, a row per step (model.run_sweep does both)
    """
    columns, units = AxleResults.solver_columns(solutions)
    qs = [s.q if s.converged else None for s in solutions]
    points = model.motion(qs, solutions)
    for name, (values, column_unit) in axle_metric_columns(model, points).items():
        columns[name], units[name] = values, column_unit
    plain = {k: v["left"].val for k, v in points.items()}
    for name, (values, column_unit) in _side_rates(model, plain, qs).items():
        columns[name], units[name] = values, column_unit
    for name in model.output_points:
        for i, axis in enumerate("xyz"):
            columns[f"{name}_{axis}"] = plain[name][:, i] * 1e3
            units[f"{name}_{axis}"] = "mm"
    source, sha = model.source, model.axle.sha256 if model.axle is not None else None
    meta = AxleResults.solver_meta(solutions, (source, sha), sweep, model)
    meta["notes"] = model.sweep_notes(sweep)
    return AxleResults(columns, units, meta)


def _side_rates(model: AxleModel, plain: dict, qs: list) -> dict:
    """Each side's spring force and wheel and ride rates where its rate is given (the
    corner's, rates.SpringRates, along its own hub z with the rack held: its corner
    posed at the side's wheel-centre height and the rack's travel at each step)."""
    from .rates import rate_columns

    out = {}
    rack = model.model.existJointName("rack_slide")
    index = model.model.joints[model.model.getJointId("rack_slide")].idx_q if rack else None
    for side, g in model.geometries.items():
        if not g.rated_spring:
            continue
        corner = Linkage(g)
        targets = [PointTarget(corner.points["wheel_center"], Z)]
        if rack:
            targets.append(JointTarget(corner.model, "rack_slide"))
        solver = NewtonSolver(corner.kin, corner.closures, targets, corner.branches)
        poses, q = [], corner.q_design
        for i, at in enumerate(qs):
            if at is None:
                poses.append(None)
                continue
            goal = [plain[f"{side}_wheel_center"][i, 2]] + ([at[index]] if rack else [])
            corner.kin.update_positions(q)
            start = np.array([t.residual(corner.kin)[0] + t.value for t in targets])
            solution = solver.solve(q, start, np.array(goal))
            q = solution.q if solution.converged else q
            poses.append(solution.q if solution.converged else None)
        for name, (values, unit_) in rate_columns(corner, poses).items():
            out[f"{name}_{side}"] = (values, unit_)
    return out


def axle_metric_columns(model: AxleModel, points: dict) -> dict:
    """name → (values, unit): each side's corner columns (suffixed), the axle's, and
    the roll derivatives, from the points of ``AxleModel.motion`` (or any engine's
    points with their rates in that form)."""
    from .metrics import metric_columns

    sides = {}
    for side, g in model.geometries.items():
        design = {k: model.design_positions[f"{side}_{k}"][None] for k in model.point_names[side]}
        own = {k: points[f"{side}_{k}"][side] for k in model.point_names[side]}
        sides[side] = metric_columns(g, own, design, model.spring_sense[side])
    out = {f"{name}_{side}": c for side, cols in sides.items() for name, c in cols.items()}
    plain = {k: v["left"].val for k, v in points.items()}
    return out | _axle_metrics(model, plain, sides) | _roll_rates(model, points, sides)


def _motion(model: AxleModel, qs: list, solutions: list | None = None) -> dict:
    """Every point (prefixed) at every step, as a Dual per side: that side's rates along
    its wheel-centre z (the other wheel centre and the rack held) and the rack. A
    step that did not converge is NaN."""
    from .geometry import contact_patch
    from .jet import Dual

    drive = _drive_rows(model)
    rack = len(drive) == 3
    solver = NewtonSolver(model.kin, model.closures, drive, model.branches)
    # each side's columns: its hub z, then the rack, or its fixed toe link's length (the
    # steer of a toe-link corner: a column of 1 on that closure's row, as Linkage's)
    rhs, columns = solver.unit_rhs, {}
    for c, (side, g) in enumerate(model.geometries.items()):
        columns[side] = [c, 2] if rack else [c]
        if g.steering == "none" and g.steering_points:
            row = closure_row(model.closures, f"{side}_toe_link")
            toe = np.zeros((solver.nrows, 1))
            toe[row] = 1.0
            columns[side].append(rhs.shape[1])
            rhs = np.hstack([rhs, toe])

    def tangent_at(i: int, q: np.ndarray) -> np.ndarray:
        known = None if solutions is None else solutions[i].drive_tangent
        if known is not None and known.shape[1] == rhs.shape[1]:
            model.kin.update(q)
            return known
        solver.evaluate(q)
        return solver.tangent(rhs)

    def at_once(Q: np.ndarray, steps: list, placed: tuple) -> np.ndarray | None:
        """dq per driver at every solved step at once: the sweep's where it has them
        all, else solved here on the model's tree (bulk.Rows)."""
        known = [None if solutions is None else solutions[i].drive_tangent for i in steps]
        if all(t is not None and t.shape[1] == rhs.shape[1] for t in known):
            return np.array(known)
        batched = rows_of(solver)
        if not batched.supported or batched.nrows != model.model.nv:
            return None
        zero = np.zeros((len(Q), len(drive)))
        _, J = batched.evaluate(Q, zero, placed=placed)
        return solve_all(J, rhs)

    # a long sweep's steps evaluated at once (as its solve, march.solve_sweep); a short
    # one's one Pinocchio call after another (the numbers it always had, to the last bit)
    many = at_once if len(qs) >= MIN_STEPS else None
    motion = FrameMotion(model.kin, model.frame_names, model.points, model.design_positions)
    pos, rates = motion(qs, tangent_at, rhs.shape[1], many)
    out = {}
    # each side's drivers' rates, point by point: (m, k, n, 3), each point's contiguous
    own = {side: np.ascontiguousarray(np.moveaxis(rates[columns[side]], 2, 0)) for side in SIDES}
    for j, name in enumerate(model.frame_names):
        out[name] = {side: Dual(pos[:, j], own[side][j]) for side in SIDES}
    for side, g in model.geometries.items():
        p = {k: out[f"{side}_{k}"] for k in ("wheel_center", "axle_inboard", "axle_outboard")}
        out[f"{side}_contact_patch_center"] = {
            s: contact_patch(
                p["wheel_center"][s],
                unit(p["axle_outboard"][s] - p["axle_inboard"][s]),
                g.wheel.radius,
            )
            for s in SIDES
        }
    return out


def _roll_rates(model: AxleModel, points: dict, sides: dict) -> dict:
    """Exact derivatives along roll: the left wheel centre up and the right one down
    equally, the rack held (docs/axle.md): camber and toe per side (deg/deg), the
    U-bar's twist per side's hub z, and the roll centre's migration (mm/deg).

    With h the antisymmetric wheel-centre move, roll = atan2(a, b), a = Δz_L − Δz_R,
    b = CP_y,L − CP_y,R, so dθ/dh = (2b − a·(ḃ_L + ḃ_R)) / (a² + b²), where ḃ_side
    is that side's contact patch y rate along its own hub z (the sides meet only at
    the rack). A side's metric then moves at ±(d metric/d hub z) / (dθ/dh).
    """
    from .jet import Dual
    from .metrics import PointSet, fvic_y, fvic_z

    cp = {s: points[f"{s}_contact_patch_center"][s] for s in SIDES}
    wc = {s: points[f"{s}_wheel_center"][s].val[:, 2] for s in SIDES}
    d = model.design_positions
    a = (wc["left"] - d["left_wheel_center"][2]) - (wc["right"] - d["right_wheel_center"][2])
    b = cp["left"].val[:, 1] - cp["right"].val[:, 1]
    rate = {s: cp[s].der[0][:, 1] for s in SIDES}  # d CP_y / d own hub z
    dtheta = (2.0 * b - a * (rate["left"] - rate["right"] * -1.0)) / (a * a + b * b)
    # per side: m of its own hub z per radian of roll (+ left, − right)
    per_rad = {"left": 1.0 / dtheta, "right": -1.0 / dtheta}
    deg = np.pi / 180.0
    out = {}
    for side in SIDES:
        for name in ("camber", "roadwheel_angle"):
            gain = sides[side][f"deriv_{name}_wrt_hub_z"][0] * 1e3  # deg per m
            out[f"deriv_{name}_wrt_roll_{side}"] = (gain * per_rad[side] * deg, "deg/deg")
    # the roll centre as a function of both sides' CP and FVIC, pushed along roll
    parts = []
    for s in SIDES:
        g = model.geometries[s]
        own = {k: points[f"{s}_{k}"][s] for k in model.point_names[s]}
        design = {k: d[f"{s}_{k}"][None] for k in model.point_names[s]}
        ps = PointSet(own, design, g)
        with np.errstate(invalid="ignore", divide="ignore"):
            values = (cp[s][..., 1], cp[s][..., 2], fvic_y(ps), fvic_z(ps))
        # Dual over one direction, roll (rad): d/dθ = d/d(own hub z) · per_rad
        parts.append(tuple(Dual(v.val * 1e3, v.der[0] * per_rad[s] * 1e3) for v in values))
    with np.errstate(invalid="ignore", divide="ignore"):
        rc = roll_centre(parts)
    out["deriv_roll_center_y_wrt_roll"] = (rc[0].der * deg, "mm/deg")
    out["deriv_roll_center_z_wrt_roll"] = (rc[1].der * deg, "mm/deg")
    bar = model.axle.anti_roll if model.axle is not None else "none"
    for side in SIDES if bar != "none" else ():
        sign = 1.0 if side == "left" else -1.0
        if bar == "u_bar":
            c = model.axle.center
            axis = (c["arb_u_bar_axis_a"], c["arb_u_bar_axis_b"])
            rate = _turn_rate(axis, points[f"{side}_droplink_u_bar"][side], sign)
        else:
            ends = [points[f"{s}_droplink_t_bar"][side] for s in SIDES]
            rate = np.degrees(_t_bar_twist(model, *ends).der[0]) * 1e-3
        out[f"deriv_arb_twist_wrt_hub_z_{side}"] = (rate, "deg/mm")
    return out | _roll_stiffness(model, sides, out, per_rad)


def _roll_stiffness(model: AxleModel, sides: dict, rates: dict, per_rad: dict) -> dict:
    """Where the springs' rates (and a bar's stiffness) are given: ``roll_stiffness``
    (N·m/deg) = Σ springs' k·(dℓ/dφ)² + the bar's k·(dθ/dφ)², and ``arb_wheel_rate``
    (N/mm), the bar's rate at each wheel in roll (one up, the other down): ½·k·(dθ/dh)²."""
    axle = model.axle
    if any(model.geometries[s].spring_rate is None for s in SIDES):
        return {}
    if axle is not None and axle.anti_roll != "none":
        if axle.anti_roll_rigid or axle.anti_roll_stiffness is None:
            return {}  # a locked bar does not roll; without its stiffness: unknown
    total, out = 0.0, {}
    for side in SIDES:
        g = model.geometries[side]
        if g.spring == "torsion_bar":  # wind-up rate deg/mm → rad/m, k N·m/deg → N·m/rad
            turn = np.radians(sides[side]["deriv_torsion_bar_twist_wrt_hub_z"][0]) * 1e3
            k = g.spring_rate * 180.0 / np.pi
        else:  # length rate mm/mm, k N/mm → N/m
            turn, k = sides[side]["deriv_damper_length_wrt_hub_z"][0], g.spring_rate * 1e3
        total = total + k * (turn * per_rad[side]) ** 2
    if axle is not None and axle.anti_roll != "none":
        k = axle.anti_roll_stiffness * 180.0 / np.pi  # N·m/rad
        twist = {s: np.radians(rates[f"deriv_arb_twist_wrt_hub_z_{s}"][0]) * 1e3 for s in SIDES}
        total = (
            total + k * (twist["left"] * per_rad["left"] + twist["right"] * per_rad["right"]) ** 2
        )
        out["arb_wheel_rate"] = (0.5 * k * (twist["left"] - twist["right"]) ** 2 * 1e-3, "N/mm")
    out["roll_stiffness"] = (total * np.pi / 180.0, "N·m/deg")
    return out


def _turn_rate(axis, p, sign: float) -> np.ndarray:
    """d(arm angle)/d(own hub z) (deg/mm) of a point turning about the axis; the
    twist is left − right, so the right arm's rate counts negative."""
    a, b = axis
    u = (b - a) / np.linalg.norm(b - a)
    arm = p.val - a
    arm = arm - np.outer(arm @ u, u)
    velocity = p.der[0]
    rate = np.sum(np.cross(arm, velocity) * u, axis=-1) / np.sum(arm * arm, axis=-1)
    return sign * np.degrees(rate) * 1e-3


def _axle_metrics(model: AxleModel, p: dict, sides: dict) -> dict:
    """heave, roll, body_roll, camber to ground, ride height, track, roll centre, rack,
    steer angles and Ackermann, the U-bar's arm angles and twist, the heave link."""
    d = {k: v[None] for k, v in model.design_positions.items()}
    dz = {s: p[f"{s}_wheel_center"][:, 2] - d[f"{s}_wheel_center"][:, 2] for s in SIDES}
    cp = {s: p[f"{s}_contact_patch_center"] for s in SIDES}
    track = cp["left"][:, 1] - cp["right"][:, 1]
    out = {
        "heave": (0.5 * (dz["left"] + dz["right"]) * 1e3, "mm"),
        "roll": (np.degrees(np.arctan2(dz["left"] - dz["right"], track)), "deg"),
    }
    body_roll = np.degrees(np.arctan2(cp["right"][:, 2] - cp["left"][:, 2], track))
    out["body_roll"] = (body_roll, "deg")
    for side, s in (("left", 1.0), ("right", -1.0)):
        camber = sides[side]["camber"][0]
        out[f"camber_to_ground_{side}"] = (camber - s * body_roll, "deg")
    cp0 = {s: d[f"{s}_contact_patch_center"][:, 2] for s in SIDES}
    change = -0.5 * ((cp["left"][:, 2] - cp0["left"]) + (cp["right"][:, 2] - cp0["right"]))
    out["ride_height_change"] = (change * 1e3, "mm")
    out["track"] = (np.abs(track) * 1e3, "mm")
    rc = roll_centre(
        [
            (cp[s][:, 1] * 1e3, cp[s][:, 2] * 1e3, sides[s]["fvic_y"][0], sides[s]["fvic_z"][0])
            for s in SIDES
        ]
    )
    out["roll_center_y"], out["roll_center_z"] = (rc[0], "mm"), (rc[1], "mm")
    if "left_trackrod_inboard" in p:
        rack = p["left_trackrod_inboard"][:, 1] - d["left_trackrod_inboard"][:, 1]
        out["rack_displacement"] = (rack * 1e3, "mm")
    steer = {}
    for side, s in (("left", 1.0), ("right", -1.0)):
        steer[side] = -s * sides[side]["roadwheel_angle"][0]
        out[f"steer_angle_{side}"] = (steer[side], "deg")
    ackermann = _ackermann(model, steer, track)
    if "left_trackrod_inboard" not in p:  # no rack: no steering input
        ackermann[:] = np.nan
    else:  # bump or roll steer alone is not steering: blank with the rack at centre
        ackermann[np.abs(rack) < 1e-6] = np.nan
    out["ackermann"] = (ackermann, "%")
    a = model.axle
    if a is not None and a.anti_roll == "u_bar":
        axis = (a.center["arb_u_bar_axis_a"], a.center["arb_u_bar_axis_b"])
        angles = {}
        for side in SIDES:
            name = f"{side}_droplink_u_bar"
            angles[side] = _turn(axis, d[name], p[name])
            out[f"arb_arm_angle_{side}"] = (angles[side], "deg")
        out["arb_twist"] = (angles["left"] - angles["right"], "deg")
    if a is not None and a.anti_roll == "t_bar":
        ends = (p["left_droplink_t_bar"], p["right_droplink_t_bar"])
        out["arb_twist"] = (np.degrees(_t_bar_twist(model, *ends)), "deg")
    if a is not None and a.heave_link != "none":
        length = np.linalg.norm(p["left_heave_link_rocker"] - p["right_heave_link_rocker"], axis=-1)
        out["heave_link_length"] = (length * 1e3, "mm")
    return out


def _turn(axis, p0: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed rotation (deg) of a point about the axis a → b from p0 (right-hand rule)."""
    a, b = axis
    u = (b - a) / np.linalg.norm(b - a)
    w0, w = p0 - a, p - a
    w0 = w0 - np.outer(w0 @ u, u)
    w = w - np.outer(w @ u, u)
    return np.degrees(np.arctan2(np.cross(w0, w) @ u, np.sum(w0 * w, axis=-1)))


def _t_bar_twist(model: AxleModel, left, right):
    """The T-bar crossbar's twist (rad) about its stem from design, from its two ends
    (arrays (n, 3) or jet.Duals; right-hand rule about the design stem pivot →
    crossbar midpoint). The bar turns on a universal joint — a pitch θ of the stem
    about chassis y, then the twist about the stem — so undoing θ (read from the
    stem, which only pitches) leaves the crossbar turned by the twist alone."""
    d = model.design_positions
    hub = model.axle.center["arb_t_bar_pivot"]
    s0 = 0.5 * (d["left_droplink_t_bar"] + d["right_droplink_t_bar"]) - hub
    c0 = d["left_droplink_t_bar"] - d["right_droplink_t_bar"]
    sx, sz = (
        0.5 * (left[..., 0] + right[..., 0]) - hub[0],
        0.5 * (left[..., 2] + right[..., 2]) - hub[2],
    )
    rho = np.sqrt((s0[0] * sx + s0[2] * sz) ** 2 + (s0[2] * sx - s0[0] * sz) ** 2)
    cos, sin = (s0[0] * sx + s0[2] * sz) / rho, (s0[2] * sx - s0[0] * sz) / rho
    cx, cy, cz = (left[..., i] - right[..., i] for i in range(3))
    c = (cx * cos - cz * sin, cy, cx * sin + cz * cos)  # the crossbar with θ undone
    u = s0 / np.linalg.norm(s0)
    w0 = c0 - (c0 @ u) * u
    along = c[0] * u[0] + c[1] * u[1] + c[2] * u[2]
    w = [c[i] - along * u[i] for i in range(3)]
    k = np.cross(u, w0)  # (w0 × w)·u = w·(u × w0)
    return np.arctan2(
        w[0] * k[0] + w[1] * k[1] + w[2] * k[2],
        w[0] * w0[0] + w[1] * w0[1] + w[2] * w0[2],
    )


def _ackermann(model: AxleModel, steer: dict, track: np.ndarray) -> np.ndarray:
    """100·(δ_i − δ_o)/(δ_i* − δ_o) from the steer angles' change from design; blank for
    |δ_o| < 0.5° or without a wheelbase."""
    wheelbase = model.geometries["left"].wheelbase
    n = len(track)
    if wheelbase is None:
        return np.full(n, np.nan)
    design = model.design_steer
    delta = {s: np.abs(steer[s] - design[s]) for s in SIDES}
    left_inner = (steer["left"] + steer["right"]) > 0.0
    inner = np.where(left_inner, delta["left"], delta["right"])
    outer = np.where(left_inner, delta["right"], delta["left"])
    with np.errstate(invalid="ignore", divide="ignore"):
        o = np.radians(outer)
        ideal = np.degrees(np.arctan2(wheelbase, wheelbase / np.tan(o) - np.abs(track)))
        out = 100.0 * (inner - outer) / (ideal - outer)
    return np.where(outer >= 0.5, out, np.nan)
