"""The sprung body on the road (docs/vehicle.md): what a vehicle's corners hang from.

The body is the chassis of the composed tree, placed on the road (the world, the
plane z = 0 at design) by three joints at the centre of gravity: ``body_heave``
(a slide along z), ``body_pitch`` (a turn about y, + nose down) and ``body_roll``
(a turn about x, + right side down), in that order — so heave, pitch and roll are
the body's own coordinates (ISO 8855 angles, yaw 0). Its x, y and yaw are held
(no joint: the contact patches slide on the road, as on a kinematics rig). At zero
the body is where its hardpoints put it: a point's chassis-frame position is its
world position with the three joints at zero.

Its sweep quantities — ``heave`` (mm, the CG's rise), ``pitch``, ``roll`` (deg),
``road_z`` (mm, under one corner: warp) and ``steering_wheel`` (deg, + turning
left, through the steering's c-factor to the rack: model/steering.py) — are each one
solver row:
the body's joint, the corner's contact patch on the road, or the rack's slide.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...constraints import JointTarget, PointTarget
from ...errors import InputError
from ...model.steering import Steering
from ...model.tree import Body, FloatingBase, Joint, Tree
from . import rack

JOINTS = ("body_heave", "body_pitch", "body_roll")
ROAD = "road"
CG = "cg"  # the exported model's frame at the CG, on the body (its sprung mass)
Z = np.array([0.0, 0.0, 1.0])


class BodyOnRoad:
    """The sprung body on three joints at its CG ``cg`` (3,), m; ``steering``: the
    steering wheel on the rack (model/steering.py: its c-factor, mm of rack per turn,
    None: no steering-wheel target, and the sense of the rack's travel that turns the
    car left)."""

    quantities = ("heave", "pitch", "roll", "road_z", "steering_wheel", "rack")

    def __init__(self, cg: np.ndarray, steering: Steering):
        self.cg = np.asarray(cg, dtype=float)
        self.steering = steering
        self.c_factor = steering.c_factor

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        """The road as the root and the body's three joints above the chassis."""
        at = self.cg
        chain = [
            Body(ROAD),
            Body(JOINTS[0], ROAD, Joint(JOINTS[0], "prismatic", at, Z.copy())),
            Body(JOINTS[1], JOINTS[0], Joint(JOINTS[1], "revolute", at, np.array([0.0, 1, 0]))),
        ]
        for i, b in enumerate(bodies):
            if b.name == "chassis":
                roll = Joint(JOINTS[2], "revolute", at, np.array([1.0, 0, 0]))
                bodies[i] = replace(b, parent=JOINTS[1], joint=roll)
        bodies[:0] = chain

    def check_targets(self, targets, source: str) -> None:
        """The body's heave, pitch and roll each given exactly once; a road height once
        per corner."""
        for quantity in JOINTS:
            name = quantity.removeprefix("body_")
            given = [t for t in targets if t.quantity == name]
            if len(given) != 1:
                raise InputError(
                    source,
                    "targets",
                    f"a vehicle's sweep gives the body's {name} exactly once "
                    f"(got {len(given)}): heave, pitch and roll fix the body on the road",
                )
        steering = [i for i, t in enumerate(targets) if t.quantity in ("steering_wheel", "rack")]
        if len(steering) > 1:
            raise InputError(
                source,
                f"targets[{steering[1]}]",
                f"repeats targets[{steering[0]}]'s steering (the steering wheel or the rack: "
                "one of them, once)",
            )
        seen = set()
        for i, t in enumerate(targets):
            if t.quantity == "road_z":
                if t.side in seen:
                    raise InputError(source, f"targets[{i}]", f"repeats road_z under {t.side}")
                seen.add(t.side)

    def row(self, model, i: int, t, source: str):
        """The solver's row of the quantity target ``targets[i]`` (its value set later)."""
        if t.quantity in ("heave", "pitch", "roll"):
            return JointTarget(model.model, f"body_{t.quantity}")
        if t.quantity == "road_z":
            if t.side not in model.labels:
                raise InputError(
                    source,
                    f"targets[{i}].corner",
                    f"road_z names its corner: one of {', '.join(model.labels)}",
                )
            return PointTarget(model.points[f"{t.side}_contact_patch_center"], Z)
        if not model.model.existJointName(rack.JOINT):
            raise InputError(source, f"targets[{i}]", f"{t.quantity}: this vehicle has no rack")
        if t.quantity == "rack":  # its travel in the chassis frame: the rack's joint
            return JointTarget(model.model, rack.JOINT)
        if self.c_factor is None:
            raise InputError(
                source,
                f"targets[{i}]",
                "steering_wheel needs vehicle_config.steering.c_factor (mm of rack per turn)",
            )
        return JointTarget(model.model, rack.JOINT)

    def value(self, t) -> np.ndarray:
        """A quantity target's values in SI: heave, road_z and the rack's travel m, pitch
        and roll rad, the steering wheel as the rack's travel (m)."""
        v = np.asarray(t.values, dtype=float)
        if t.quantity in ("heave", "road_z", "rack"):
            return v * 1e-3
        if t.quantity in ("pitch", "roll"):
            return np.radians(v)
        if self.c_factor is None:  # the wheel centred (row: any other is refused)
            return np.zeros_like(v)
        return self.steering.rack_travel(v) * 1e-3

    def steering_wheel_angle(self, travel: np.ndarray) -> np.ndarray:
        """The steering wheel's angle (deg, + turning left) for the rack's travel (m):
        ``value``'s inverse."""
        return self.steering.wheel_angle(travel * 1e3)

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """None of its own among the corners': the vehicle writes the body's (vehicle.py)."""
        return {}

    def to_world(self, p: np.ndarray, heave, pitch, roll) -> np.ndarray:
        """Chassis-frame points p (n, 3) in the road's frame at the body's pose (each (n,),
        m and rad): w = c + h·ẑ + R_y(θ)·R_x(φ)·(p − c)."""
        r = p - self.cg
        c, s = np.cos(roll), np.sin(roll)
        x, y, z = r[:, 0], c * r[:, 1] - s * r[:, 2], s * r[:, 1] + c * r[:, 2]  # R_x
        c, s = np.cos(pitch), np.sin(pitch)
        x, z = c * x + s * z, -s * x + c * z  # R_y
        return np.stack([x, y, z + heave], axis=1) + self.cg

    def placement(self, heave: float, pitch: float, roll: float) -> tuple:
        """The body's frame in the road's at its pose (m, rad): (R, t), w = R·p + t, with
        R = R_y(θ)·R_x(φ) and t = c + h·ẑ − R·c (``to_world``'s)."""
        c, s = np.cos(roll), np.sin(roll)
        rx = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
        c, s = np.cos(pitch), np.sin(pitch)
        ry = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        rotation = ry @ rx
        return rotation, self.cg + heave * Z - rotation @ self.cg

    def exported(self, tree: Tree, mass: float | None = None, inertia=None) -> Tree:
        """The tree as the URDF and MJCF export it (docs/urdf.md): without the road and
        the body's three joints — the chassis its root, floating (``Tree.floating``: a
        robotics tool's free-flyer, MuJoCo's freejoint) — and a point ``cg`` on it at the
        CG that carries the sprung ``mass`` (kg, None: none given) and ``inertia``."""
        ours = {ROAD, JOINTS[0], JOINTS[1]}
        bodies = [
            replace(b, parent=None, joint=None) if b.name == "chassis" else b
            for b in tree.bodies
            if b.name not in ours
        ]
        points = dict(tree.points) | {CG: ("chassis", self.cg.copy())}
        base = FloatingBase(CG, self.cg.copy(), mass, inertia)
        return replace(tree, bodies=bodies, points=points, floating=base)
