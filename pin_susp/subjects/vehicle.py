"""The whole car: a front and a rear axle under one sprung body on the road
(docs/vehicle.md).

A vehicle file (``scope: vehicle``) names two axle files (docs/axle.md: a path
relative to it, or the axle inline) and ``vehicle_config``: the wheelbase (a check
of the axles' points), the CG, the masses, the brake and drive split and the
steering's c-factor. Its corners are labelled ``fl``, ``fr``, ``rl``, ``rr`` —
each corner's column gets that suffix (``camber_fl``), each point that prefix
(``fl_wheel_center``) — under one chassis that is the body on the road
(elements/body.py: heave, pitch and roll at the CG).

A sweep gives the body's heave, pitch and roll, the steering (``steering_wheel``,
or a rack target as on an axle; the rack held at design without one) and, where
the road is not flat, a corner's ``road_z``: the rows are every corner's closures,
its contact patch on the road and the targets. A corner's columns are its own
(metrics.py) in the chassis frame, with its exact rates along its own
wheel-centre height (the body and the other wheels held) and the rack — so they
equal that corner's own sweep at the same chassis-frame height and rack; the
points are written in the chassis frame too. Each axle's anti-roll bar and heave
link (``AxleElements``: the axle's own elements, named by its corners' labels and
its end) write theirs likewise, as that axle's own would. The body's pose and what
is seen from the road (camber to ground, the wheelbase on the road) follow.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .. import __version__
from ..errors import InputError
from ..maths.vectors import unit
from ..model.geometry import contact_patch, summary_repr
from ..model.mechanisms import xml_name
from ..model.steering import Steering, c_factor_of, steer_sense
from ..solve.linkage import RACK_HELD, Linkage
from .axle import AxleModel
from .axle_file import AxleGeometry
from .corner import Results
from .elements import elements_of, rack
from .elements.body import JOINTS, BodyOnRoad
from .elements.car_axle import AxleOfCar
from .vehicle_analyses import VehicleAssembly
from .vehicle_columns import vehicle_columns
from .vehicle_export import VehicleExport
from .vehicle_file import (  # noqa: F401 (the vehicle file's names, importable from here)
    AXLES,
    CONFIG_KEYS,
    LABELS,
    RIGID_BAR,
    WHEELBASE_CHECK,
    VehicleGeometry,
    axle_key,
    load_vehicle,
)
from .vehicle_tangents import VehicleTangents
from .vehicle_views import VehicleViews

DERIVED = ("camber", "roadwheel_angle")  # the corner columns rated along heave, pitch, roll
ON_ROAD = 1.0  # mm: a contact patch's height at design, at most


class AxleElements:
    """One axle's shared elements in a vehicle — its anti-roll bar and heave link
    (elements_of), named by its corners' labels and its end (``fl_arb_arm``,
    ``front_arb_u_bar_axis_a``, ``front_t_bar``) — as one of the vehicle's shared
    elements: their parts added to the tree, their columns (``arb_twist_front``,
    ``arb_arm_angle_fl``, ``heave_link_length_front``, ``deriv_arb_twist_wrt_hub_z_fl``)
    among the vehicle's, each element's own (an axle's pair of corners writes an
    axle's, wheel_pair.py)."""

    quantities = ()  # no sweep target is its row

    def __init__(self, axle: AxleGeometry, end: str):
        self.end = end
        self.bar, self.link = elements_of(axle, AXLES[end], f"{end}_")

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        for element in (self.bar, self.link):
            element.add_to(bodies, points, closures, visuals, materials)

    def check_targets(self, targets, source: str) -> None:
        """Nothing: a rigid bar, which would lock the body's roll, is refused in the file."""

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """The bar's and the heave link's columns and the bar's twist rate per corner's
        own hub z, from every point's motion (``points``: name → {label: jet.Dual},
        measured in the chassis frame)."""
        if self.bar.kind == "none" and self.link.kind == "none":
            return {}
        first = self.bar.labels[0]
        plain = {name: p[first].val for name, p in points.items()}
        d = {k: v[None] for k, v in model.design_positions.items()}
        out = self.bar.columns(model, plain, d) | self.link.columns(model, plain, d)
        return out | self.bar.rate_columns(model, points)


class Vehicle(VehicleExport, VehicleViews, VehicleTangents, VehicleAssembly):
    """Four corners under one sprung body on the road, one Pinocchio model
    (docs/vehicle.md): ``Vehicle("examples/vehicle_fs.yaml")`` or a VehicleGeometry.

    >>> car = pin_susp.Vehicle("examples/vehicle_fs.yaml")
    >>> results = car.run_sweep("examples/vehicle_roll.yaml")
    >>> results["roll"], results["camber_fl"], results["deriv_camber_wrt_roll_fl"]
    >>> results["arb_twist_front"], results["deriv_arb_twist_wrt_hub_z_fl"]  # its bars

    ``axle_elements``: ``front``/``rear`` → that axle's AxleElements (its bar, ``.bar``,
    and heave link, ``.link``).
    """

    labels = LABELS
    noun = "vehicle"
    commands = AxleModel.commands  # an axle's (docs/vehicle.md)
    reports = True
    on_road = True
    summary_columns = tuple(
        "heave pitch roll steering_wheel_angle camber_fl camber_fr camber_rl camber_rr "
        "camber_to_ground_fl camber_to_ground_fr camber_to_ground_rl camber_to_ground_rr "
        "roadwheel_angle_fl roadwheel_angle_fr roadwheel_angle_rl roadwheel_angle_rr "
        "wheel_travel_fl wheel_travel_rl wheelbase_left wheelbase_right arb_twist_front "
        "arb_twist_rear heave_link_length_front heave_link_length_rear".split()
    )
    held_joints = JOINTS  # a corner's rates: its own height with the body still
    c_factor_key = "vehicle_config.steering.c_factor"  # its c-factor, else its front
    front_c_factor = "axle_config.steering.c_factor"  # axle file's
    tangents_by_targets = True  # a sweep solved at once: its tangents, the body's rates
    needs = (
        "the body's heave, pitch and roll, and the steering (steering_wheel or a rack "
        "target); each road_z is 0 unless given"
    )

    def __init__(self, vehicle, visuals: bool = True):
        """``vehicle``: its file (a path or its data) or a VehicleGeometry; ``visuals``:
        the URDF's drawn shapes (a study's variant goes without)."""
        from ..solve.as_set import apply_setup

        if not isinstance(vehicle, VehicleGeometry):
            vehicle = load_vehicle(vehicle)
        self.vehicle, self.name, self.source = vehicle, vehicle.name, vehicle.source
        # each corner as set, the car's wheelbase, CG and brakes in place of any its
        # axle file gives (its anti columns: the whole car's, vehicle_columns.py)
        self.corners = {
            label: replace(
                apply_setup(vehicle.corner(label)),
                wheelbase=None,
                cg_position=None,
                front_brake_bias=None,
                driven_axle=None,
            )
            for label in LABELS
        }
        front, c = self.corners["fl"], vehicle.c_factor
        sense = 1.0
        if front.steering == "rack":  # the rack's travel left steers left where the
            sense = steer_sense(front.design_points())  # trackrods are ahead of the wheel
            if c is None:  # the front axle file's own, where the vehicle gives none
                c = c_factor_of(front, *axle_key(vehicle, "front", self.front_c_factor)[::-1])
        self.body = BodyOnRoad(vehicle.cg, Steering(c, sense))
        # each axle's bar and heave link, named by its corners' labels and its end
        self.axle_elements = {end: AxleElements(getattr(vehicle, end), end) for end in AXLES}
        self.elements = tuple(e for a in self.axle_elements.values() for e in (a.bar, a.link))
        ends = (AxleOfCar(end, labels) for end, labels in AXLES.items())
        self.shared = (self.body, *self.axle_elements.values(), *ends)  # each axle's columns
        comment = f"generated by pin_susp {__version__}: a vehicle"
        name = xml_name(self.name, "vehicle")
        self._compose(self.corners, self.shared, name, comment, visuals)
        self._drivers()
        self.kin.update(self.q_design)
        self._check_determined()
        self._check_on_road()
        self.spring_senses = {
            label: (Linkage(g).spring_sense if g.spring == "torsion_bar" else 1.0)
            for label, g in self.corners.items()
        }
        body = [self.model.joints[self.model.getJointId(j)] for j in JOINTS]
        self.body_q, self.body_v = [j.idx_q for j in body], [j.idx_v for j in body]

    def _check_on_road(self) -> None:
        """Each contact patch on the road (z = 0) as its file draws it, to ON_ROAD: else
        the wheel centres' heights and the tyres' sizes disagree (or the origin is not on
        the ground), and every sweep would start by moving the wheels to the road. (A
        setup — a shim, a trackrod's length — may then move the wheel off it: the sweep
        puts the car back on the road as set.)"""
        for end, labels in AXLES.items():
            for label in labels:
                g = self.vehicle.corner(label)  # as drawn
                p = g.design_points()
                spin = unit(p["axle_outboard"] - p["axle_inboard"])
                z = contact_patch(p["wheel_center"], spin, g.wheel.radius)[2] * 1e3
                if abs(z) > ON_ROAD:
                    where, key = axle_key(self.vehicle, end, "hardpoints")
                    raise InputError(
                        where,
                        key,
                        f"the {label} contact patch is {abs(z):.4g} mm "
                        f"{'above' if z > 0 else 'below'} the road (z = 0) at design: its "
                        "wheel centre's height and its tyre's radius disagree, or the "
                        "origin is not on the ground (ISO 8855: z = 0 on the road)",
                    )

    def _check_determined(self) -> None:
        """Each wheel's height, the rack and the body's joints must fix the pose at design
        (the closures with them of full rank, as an axle's: AxleModel._check_determined):
        else a part turns freely — a droplink square to its bar arm's motion (at dead
        centre), a bar axis along a droplink. The error names the axle file whose parts
        the free motion turns."""
        _, s, vt = np.linalg.svd(self.drive_rows_at_design())
        null = np.concatenate([s <= 1e-9 * s[0], np.ones(len(vt) - len(s), dtype=bool)])
        if not null.any():
            return
        free = np.abs(vt[null]).max(axis=0)  # how far each freedom moves in its null space
        moved = [
            name
            for joint, name in zip(self.model.joints[1:], self.model.names[1:], strict=True)
            if np.any(free[joint.idx_v : joint.idx_v + joint.nv] > 1e-6 * free.max())
        ]
        own = {e: (*(f"{label}_" for label in labels), f"{e}_") for e, labels in AXLES.items()}
        ends = [e for e in AXLES if any(n.startswith(own[e]) for n in moved)]
        end = ends[0] if ends else "front"
        source, key = axle_key(self.vehicle, end, "hardpoints")
        raise InputError(
            source,
            key,
            f"the wheels, the rack and the body do not fix the vehicle's {end} axle at "
            "design: a part turns freely (a droplink square to its bar arm's motion — at "
            f"dead centre — or in line with the bar's axis?): {', '.join(moved)}",
        )

    def with_corners(self, corners: dict):
        """The same car on other corners' Geometries, by label (the 3D view's ghost, as
        drawn): each axle's file with those corners, its bar and heave link kept."""
        from dataclasses import replace

        v = self.vehicle
        axles = {
            end: replace(getattr(v, end), left=corners[a], right=corners[b])
            for end, (a, b) in AXLES.items()
        }
        return Vehicle(replace(v, **axles))

    def __repr__(self) -> str:
        v = self.vehicle
        return summary_repr(
            self,
            lambda: (
                self.source,
                self.name,
                f"front {v.front.left.type}",
                f"rear {v.rear.left.type}",
                f"wheelbase {v.wheelbase:g} mm",
                f"{self.mobility} inputs",
            ),
        )

    @property
    def sha256(self) -> str | None:
        return self.vehicle.sha256

    @property
    def results_class(self) -> type:
        return VehicleResults

    def undetermined(self, targets) -> str:
        return "the targets do not fix the vehicle's pose at its design state"

    def target_rows(self, targets: list, source: str = "<targets>") -> list:
        """Assembly.target_rows, after the vehicle's own reading of what a target names:
        a quantity of the body, a point on a corner labelled fl, fr, rl or rr."""
        for i, t in enumerate(targets):
            if t.quantity is not None and t.quantity not in self.quantities:
                raise InputError(
                    source,
                    f"targets[{i}].quantity",
                    f"{t.quantity} is not a vehicle's: {', '.join(self.quantities)}",
                )
            if t.quantity is None and t.side not in LABELS:
                raise InputError(
                    source,
                    f"targets[{i}].side",
                    f"a vehicle's point targets name their corner (side: {'|'.join(LABELS)}), "
                    f"got {t.side}",
                )
        return super().target_rows(targets, source)

    def held_targets(self, targets: list) -> list:
        """Its sweep's targets, each corner's road height (0) where none is given, and the
        rack held at design where no steering target is (Composed.held_targets). The rack
        is held, or moved by a rack target as on an axle (``trackrod_inboard`` along y),
        by its joint: its travel in the chassis frame, not its end's in the road's,
        which the body's roll would move."""
        from ..model.sweep import Target

        targets = [self._rack_of(t) for t in self._on_flat_road(targets)]
        if any(t.quantity in ("steering_wheel", "rack") for t in targets):
            return targets
        held = super().held_targets(targets)
        if len(held) > len(targets):  # the rack held at design
            steps = len(targets[0].values)
            held[-1] = Target(None, None, np.zeros(steps), quantity="rack")
        return held

    def _rack_of(self, t):
        """A rack target as on an axle (``trackrod_inboard`` along y on fl or fr) as the
        rack's travel from design, mm: the vehicle's ``rack`` quantity."""
        from ..model.sweep import Target

        if t.quantity is not None or t.point != rack.INBOARD or t.side not in AXLES["front"]:
            return t
        if not np.allclose(t.unit_direction, (0.0, 1.0, 0.0)):
            return t
        travel = np.asarray(t.values, dtype=float)
        if t.mode == "absolute":
            travel = travel - self.design_positions[f"{t.side}_{rack.INBOARD}"][1] * 1e3
        return Target(None, None, travel, quantity="rack")

    def _on_flat_road(self, targets) -> list:
        """The targets with road_z 0 under each corner none names."""
        from ..model.sweep import Target

        targets = list(targets)
        if not targets:
            return targets
        steps = len(targets[0].values)
        given = {t.side for t in targets if t.quantity == "road_z"}
        return targets + [
            Target(None, None, np.zeros(steps), side=label, quantity="road_z")
            for label in LABELS
            if label not in given
        ]

    def sweep_notes(self, targets) -> list[str]:
        """The rack held at design where its sweep steers by neither the steering wheel
        nor a rack target (road heights at 0 go without saying)."""
        targets = self._on_flat_road(getattr(targets, "targets", targets))
        return [RACK_HELD] if len(self.held_targets(targets)) > len(targets) else []

    # ------------------------------------------------------------ results

    def chassis_configurations(self, qs: list) -> list:
        """Each configuration with the body's three joints at zero: the model's points
        then stand where they are in the chassis frame."""
        out = []
        for q in qs:
            if q is None:
                out.append(None)
                continue
            q = np.array(q, dtype=float)
            q[self.body_q] = 0.0
            out.append(q)
        return out

    def label_corner(self, label: str, plain: dict, qs: list) -> tuple:
        """A corner of its own for one label's rated spring and its configurations at
        ``qs`` (chassis frame): each its joints' values in the vehicle's configuration
        (the corner's joints are the vehicle's, prefixed by its label, and the shared
        rack; the body's at zero, its closures among the vehicle's: the pose at its
        wheel centre's height and the rack's travel, as a solve of its own would find it
        to the tolerance). Where a joint of its is not the vehicle's, solved at its
        wheel centre's height and the rack's travel, every step at once where the sweep
        is long (the corner's own march; an axle's label_corner solves one step after
        another). Each label's Corner is built once, at its first sweep."""
        from ..model.sweep import Sweep, Target
        from .corner import Corner

        g = self.corners[label]
        own = self.__dict__.setdefault("_own_corners", {})  # built once per label
        if label not in own:
            own[label] = Corner(g, apply_setup=False, warn=False, visuals=False)
        corner = own[label]
        solved = [i for i, q in enumerate(qs) if q is not None]
        poses = [None] * len(qs)
        if not solved:
            return corner, poses
        mapped = self._joints_in_vehicle(label, corner.model)
        if mapped is not None:
            own, theirs = mapped
            for i in solved:
                q = np.empty(corner.model.nq)
                q[own] = qs[i][theirs]
                poses[i] = q
            return corner, poses
        p = self.prefix(label)
        targets = [
            Target("wheel_center", "z", plain[p + "wheel_center"][solved, 2] * 1e3, "absolute")
        ]
        if g.steering == "rack":
            end = plain[p + rack.INBOARD][solved, 1] * 1e3
            targets.append(Target(rack.INBOARD, "y", end, "absolute"))
        for i, s in zip(solved, corner.solve_steps(Sweep(targets, "<corner>")), strict=True):
            poses[i] = s.q if s.converged else None
        return corner, poses

    def measured_at(self, qs: list, tangents: list) -> tuple[list, list | None]:
        """Its chassis frame: each configuration with the body's joints at zero, and
        the tangents per driver there (``drive_tangents``) where the sweep's solve kept
        its own per target at every solved step, else None (label_motion solves them)."""
        chassis = self.chassis_configurations(qs)
        return chassis, self.drive_tangents(qs, chassis, tangents)

    def own_columns(self, sweep, qs: list, plain: dict, columns: dict, tangents=None) -> dict:
        """The body's pose, what the road sees and the rates along the body
        (``body_columns``; ``tangents``: the sweep's per target, where it has them), and
        the steering ratio of its front wheels (steering_surface.py)."""
        out = self.body_columns(sweep, qs, plain, columns, tangents)
        return out | self.steering_ratio(columns)

    @property
    def steering(self) -> Steering | None:
        """The steering wheel on its rack: its body's (the vehicle's c-factor, else its
        front axle file's); None without a rack."""
        return self.body.steering if self.corners["fl"].steering == "rack" else None

    def body_columns(self, sweep, qs: list, plain: dict, columns: dict, tangents=None) -> dict:
        """The body's heave, pitch, roll and steering-wheel angle; each corner's camber
        to ground; the wheelbase on the road per side; and the exact rates of each
        corner's camber, toe and wheel-centre height along heave, pitch and roll
        (``body_rates``)."""
        pose = np.full((len(qs), 3), np.nan)
        solved = [i for i, q in enumerate(qs) if q is not None]
        if solved:
            pose[solved] = np.array([qs[i] for i in solved])[:, self.body_q]
        heave, pitch, roll = pose.T
        out = {
            "heave": (heave * 1e3, "mm"),
            "pitch": (np.degrees(pitch), "deg"),
            "roll": (np.degrees(roll), "deg"),
        }
        world = {}
        for label in LABELS:
            for k in ("wheel_center", "axle_inboard", "axle_outboard"):
                name = f"{label}_{k}"
                world[name] = self.body.to_world(plain[name], heave, pitch, roll)
        out |= self.seen_from_road(world, plain)
        out |= vehicle_columns(self, plain, columns | {k: v[0] for k, v in out.items()})
        out |= self.body_rates(sweep, qs, columns, tangents)
        return out

    def seen_from_road(self, world: dict, chassis: dict) -> dict:
        """What the road sees (name → (values (n,), unit)): the rack's travel and the
        steering-wheel angle from the chassis-frame points ``chassis``; each corner's
        camber to ground, the wheelbase on the road per side and each contact patch's
        height from its wheel centre and axle ends in the road's frame (``world``; both
        name → (n, 3), m)."""
        out = {}
        end = f"fl_{rack.INBOARD}"
        if end in chassis and self.corners["fl"].steering == "rack":
            travel = chassis[end][:, 1] - self.design_positions[end][1]  # along y
            out["rack_displacement"] = (travel * 1e3, "mm")
            if self.body.c_factor is not None:
                out["steering_wheel_angle"] = (self.body.steering_wheel_angle(travel), "deg")
        contact = {}
        for label in LABELS:
            p = f"{label}_"
            spin = unit(world[p + "axle_outboard"] - world[p + "axle_inboard"])
            s = self.corners[label].sign  # the corner's camber, of its spin axis on the road
            ground = -np.degrees(np.arctan2(spin[:, 2], s * spin[:, 1]))
            out[f"camber_to_ground_{label}"] = (ground, "deg")
            radius = self.corners[label].wheel.radius
            contact[label] = contact_patch(world[p + "wheel_center"], spin, radius)
        for side in ("left", "right"):
            f, r = ("fl", "rl") if side == "left" else ("fr", "rr")
            out[f"wheelbase_{side}"] = ((contact[f][:, 0] - contact[r][:, 0]) * 1e3, "mm")
        for label in LABELS:
            out[f"contact_patch_road_z_{label}"] = (contact[label][:, 2] * 1e3, "mm")
        return out

    def bar_energies(self) -> list:
        """Each anti-roll bar's (stiffness N·m/rad, twist(q, T) → (τ (n,) rad, dτ/du
        (n, k))) for the attitude's potential (analyses/attitude.py): a U-bar's twist is
        its first arm's turn less its second's, each arm's joint angle about the bar's
        axis. A T-bar's is not taken yet (an InputError naming its key)."""
        out = []
        for end, elements in self.axle_elements.items():
            bar = elements.bar
            if bar.kind == "none":
                continue
            if bar.kind != "u_bar":
                raise InputError(
                    *axle_key(self.vehicle, end, "axle_config.anti_roll.type"),
                    "the attitude takes U-bars so far (a T-bar's twist in its potential "
                    "is not built yet)",
                )
            if bar.axle.anti_roll_stiffness is None:
                raise InputError(
                    *axle_key(self.vehicle, end, "axle_config.anti_roll.stiffness"),
                    "the attitude needs the bar's stiffness (N·m/deg of its twist)",
                )
            names = [f"{c}_arb_arm_pivot" for c in bar.labels]
            joints = [self.model.joints[self.model.getJointId(n)] for n in names]
            (iq, jq), (iv, jv) = [j.idx_q for j in joints], [j.idx_v for j in joints]

            def twist(q, T, iq=iq, jq=jq, iv=iv, jv=jv):
                return q[:, iq] - q[:, jq], T[:, iv, :] - T[:, jv, :]

            out.append((bar.axle.anti_roll_stiffness * 180.0 / np.pi, twist))
        return out

    def design_steer(self, label: str) -> float:
        """A corner's steer angle at design (deg, + turning left), as its axle's
        ``steer_angle`` columns measure it."""
        d, g = self.design_positions, self.corners[label]
        a = d[f"{label}_axle_outboard"] - d[f"{label}_axle_inboard"]
        return -g.sign * np.degrees(np.arctan2(a[0], g.sign * a[1]))


class VehicleResults(Results):
    """Columns of a solved vehicle sweep (docs/vehicle.md), in output units."""
