"""What the engines need from a subject (README, How it works): its points, drivers,
targets and columns, as one :class:`Scope` over the Assembly's labelled corners (a
corner's one, labelled ``""``: its names unprefixed, its columns unsuffixed; an axle's
``left`` and ``right``; a vehicle's ``fl`` … ``rr``); the engines only see points and
targets. A subject whose exported root floats (a vehicle's body, docs/vehicle.md) has
each step's body pose first among its targets (a BodyPose): the engines place their
floating base there, and read its points back in the body's frame.
"""

from __future__ import annotations

import numpy as np

from ..analyses.pointwise import Along, PointwiseLinkage, Y, Z, labelled, sweep_values, targets_at
from ..columns.metrics import METRICS
from ..maths.jet import Dual
from ..maths.jet import value as plain
from .floating import in_body_frame

RATE_METRICS = {m.name for m in METRICS if m.rates}


def step_targets(subject, sweep) -> list[list]:
    """Every step's targets as point-based targets (:mod:`pin_susp.analyses.pointwise`): a
    point's coordinate along a direction (absolute, m), an axle's heave and roll."""
    return scope_of(subject).step_targets(sweep)


def held_drivers(subject, points: dict) -> list[tuple[str, np.ndarray, float]]:
    """The drivers as targets held where the engine's pose is, (point, unit direction,
    value m): each wheel centre's z, and the rack (a trackrod_inboard's y) where there
    is one."""
    return [(t.point, t.direction, t.value) for t in scope_of(subject).held(points)]


class Scope:
    """What the engines need from a subject (an Assembly): its points and drivers, the
    sweep as targets, the columns computed from an engine's points.

    The drivers are each corner's wheel-centre z, the rack (one, shared) where there
    is one, and each toe-link corner's toe link length (a driver no target holds: a link
    of the engine), in the order of the subject's ``driver_columns``; a point is a Dual
    per label (its rates along that corner's hub z, the others held, and along the rack
    or its toe link's length), as the subject's ``metric_columns_of`` takes them.
    """

    # the roll centre's columns: name → the vector it is a coordinate of
    ROLL_CENTRE = {
        name: pair
        for pair in (
            ("roll_center_y", "roll_center_z"),
            ("deriv_roll_center_y_wrt_roll", "deriv_roll_center_z_wrt_roll"),
            ("kinematic_roll_center_y", "kinematic_roll_center_z"),
        )
        for name in pair
    }
    KINEMATIC_IC = ("kinematic_instant_center_y", "kinematic_instant_center_z")

    def __init__(self, subject):
        self.subject = subject
        self.kind = subject.noun
        self.tree = subject.export_tree  # the exported model's, which the engines load
        # the drivers' columns, counted without the subject's joints no driver moves (a
        # vehicle's body: held in its rates, Composed.held_joints)
        used = sorted(set().union(*subject.driver_columns.values()))
        rank = {c: i for i, c in enumerate(used)}
        self.driver_columns = {
            label: [rank[c] for c in columns] for label, columns in subject.driver_columns.items()
        }
        self.drivers = len(used)
        self.links, self.wheels, self.racks = [], {}, []
        for label, g in subject.corners.items():
            p = subject.prefix(label)
            if g.steering == "none" and g.steering_points:
                self.links.append(tuple(p + n for n in g.steering_points))
            if g.steering == "rack":
                self.racks.append(p + g.steering_points[0])
            self.wheels[p] = (g.wheel.radius, p + g.mechanism.WHEEL_BODY)
        self.hubs = {label: f"{subject.prefix(label)}wheel_center" for label in subject.labels}
        self.sites = [n for n in subject.output_points if not n.endswith("contact_patch_center")]

    def results(self, sweep):
        return self.subject.solve_sweep(sweep)[1]

    def pointwise(self) -> PointwiseLinkage:
        return PointwiseLinkage(*labelled(self.subject.corners, self.subject.elements))

    def step_targets(self, sweep) -> list[list]:
        """Every step's targets, as its sweep holds them (the rack at design if not
        given): a point's by its label's prefix, its values absolute (m, rad); where the
        exported root floats, the body's pose first (Assembly.engine_steps)."""
        steps = self.subject.engine_steps(sweep)
        if steps is not None:
            return steps
        targets = self.subject.held_sweep(sweep).targets
        design = self.subject.design_positions
        return [targets_at(targets, v, design) for v in sweep_values(targets, design)]

    def step_moves(self, sweep) -> list[dict]:
        """Every step's targets with the body's quantities moved (Assembly.engine_moves):
        quantity → (h, the steps at −2h, −h, +h, +2h); none but a vehicle's."""
        return self.subject.engine_moves(sweep)

    def fixed_root_targets(self, targets: list) -> tuple[list, object]:
        """One step's targets for an engine without a floating base (the point-based
        one): in the body's frame where they place a floating body, with its pose
        (floating.in_body_frame); else as they are, and None."""
        radii = {prefix: radius for prefix, (radius, _) in self.wheels.items()}
        return in_body_frame(targets, radii)

    def held(self, points: dict) -> list:
        """The drivers that targets hold, where the engine's pose is: each wheel
        centre's z, then the rack's inboard end along y (one rack, shared)."""
        held = [Along(hub, Z, float(points[hub][2])) for hub in self.hubs.values()]
        held += [Along(inner, Y, float(points[inner][1])) for inner in self.racks[:1]]
        return held

    def duals(
        self, points: dict, rates: dict, road: dict | None = None, along: dict | None = None
    ) -> StepPoints:
        """Each label's rates; for a rigid anti-roll bar none along a wheel's own height,
        as the sweep writes none (one wheel cannot move with the other held). ``road``:
        the points where the engine solved them (default: ``points``); ``along``: each
        wheel centre's rate along the body's quantities (``step_moves``)."""
        hub = np.array([np.nan if self.subject.anti_roll_rigid else 1.0])
        scale = {
            label: np.r_[hub, np.ones(len(columns) - 1)][:, None]
            for label, columns in self.driver_columns.items()
        }
        duals = {
            name: {
                label: Dual(p[None], rates[name][columns][:, None] * scale[label])
                for label, columns in self.driver_columns.items()
            }
            for name, p in points.items()
        }
        return StepPoints(duals, points if road is None else road, along or {})

    def as_motion(self, points_per_step: list) -> list:
        """Every step's points (a Dual per label) as the subject's motion gives them
        (Assembly.motion_points); None stays None."""
        own = self.subject.motion_points
        return [None if points is None else own(points) for points in points_per_step]

    def columns(self, points: StepPoints) -> dict:
        """Every metric column, computed from the points as the subject's sweep computes
        them (Assembly.metric_columns_of), then what the points where the engine solved
        them give (Assembly.road_columns: a vehicle's camber to ground, ...)."""
        columns = self.subject.metric_columns_of(points)
        return columns | self.subject.road_columns(points.road, points, columns)

    def positions(self, points: dict) -> dict[str, np.ndarray]:
        first = self.subject.labels[0]
        return {name: points[name][first].val[0] for name in self.subject.output_points}

    def stalled(self, points: dict) -> bool:
        if self.subject.anti_roll_rigid:
            return False  # no rates by design (duals): compared as blank, like the sweep's
        return any(
            np.isnan(plain(points[hub][label].der)).any() for label, hub in self.hubs.items()
        )

    def from_rates(self, name: str) -> bool:
        suffixes = {self.subject.suffix(label) for label in self.subject.labels}
        return any(name.removesuffix(s) in RATE_METRICS for s in suffixes)

    def size(self, name: str, results, i: int) -> float:
        """What the column's RELATIVE tolerance is a fraction of: its own value; for the
        roll centre and its rates, the vector's length times |RC| / track at least 1.

        The roll centre crosses two lines from contact patches a track apart; when
        they are nearly parallel (instant centres a hundred metres out) it lies at
        |RC| ≫ track, and a rounding δ in a line's slope moves it by (|RC|²/track)·δ:
        a relative error |RC|/track times larger than its inputs', in either
        coordinate and in its rates alike. A corner's kinematic instant centre, the pole
        v/ω_x of its bump twist, likewise: its vector's length times |IC| / half track.
        """
        for base in self.KINEMATIC_IC:
            if name.startswith(base):
                suffix = name.removeprefix(base)
                ic = np.hypot(*(results[f"{b}{suffix}"][i] for b in self.KINEMATIC_IC))
                return ic * max(1.0, ic / results[f"half_track{suffix}"][i])
        if name not in self.ROLL_CENTRE:
            return abs(results[name][i])
        kind = "kinematic_" if name.startswith("kinematic_") else ""
        rc = np.hypot(results[f"{kind}roll_center_y"][i], results[f"{kind}roll_center_z"][i])
        lever = max(1.0, rc / results["track"][i])
        return np.hypot(*(results[n][i] for n in self.ROLL_CENTRE[name])) * lever


class StepPoints(dict):
    """An engine's points at one step: name → {label: Dual}, in the subject's frame as
    its sweep measures them (a vehicle's chassis frame); ``road``: name → (3,) m, where
    the engine solved them (the road's frame; a corner's and an axle's the same);
    ``along``: quantity → {label: its wheel centre's z rate along it, m per m or rad},
    the body's quantities held by the engine's own tangent (a vehicle's; else none)."""

    def __init__(self, points: dict, road: dict, along: dict | None = None):
        super().__init__(points)
        self.road = road
        self.along = along or {}


# the names the scopes had, one per kind of subject: now one Scope for every subject
CornerScope = AxleScope = Scope


def scope_of(subject) -> Scope:
    """A subject's scope (a Scope given: itself)."""
    return subject if isinstance(subject, Scope) else Scope(subject)
