"""The steering wheel on a subject's rack (docs/sweep.md, "The steering wheel";
docs/results.md, "Steering"): what a corner, an axle and a vehicle answer alike.

- Its ``steering`` (model/steering.py): the c-factor its file gives and the rack's
  sense, read once.
- A ``steering_wheel`` target (deg, + turning left) — or a ``rack`` target (mm) — on a
  corner or an axle is the rack target it stands for (``steering_target``): the first
  corner's ``trackrod_inboard`` along y, relative, by angle / 360 × c-factor. So its
  sweep is that rack target's, step for step (a vehicle has both as its body's rows).
- Its columns (``steering_columns``): ``steering_wheel_angle`` from the rack's travel
  and ``steering_ratio``, d steering-wheel angle / d mean steer angle of its steered
  wheels, exact from their derivative columns along the rack (a corner: its own wheel).
- A corner with ``config.wheelbase`` and ``config.track`` (``partner_columns``): its
  mirrored partner (the
  corner mirrored in y = 0, at the same wheel-centre height, on the same rack: its own
  pose at the rack's opposite travel, solved) gives the track, the inner and outer
  wheels' steer, Ackermann and the turning radius, by the axle's and the vehicle's
  formulas.
"""

from __future__ import annotations

import numpy as np

from ..columns.metrics import metric_columns
from ..errors import InputError
from ..model.geometry import contact_patch, unit
from ..model.steering import (
    STRAIGHT,
    Steering,
    ackermann,
    c_factor_of,
    inner_outer,
    steer_sense,
    turning_radius,
)
from ..model.sweep import Sweep, Target
from ..solve.bulk import Frames, tree_of
from .elements import rack

STEERING_QUANTITIES = ("steering_wheel", "rack")
TOE = "roadwheel_angle"
PARTNER_POINTS = ("axle_inboard", "axle_outboard", "wheel_center", "contact_patch_center")
FRAMES = PARTNER_POINTS[:3]  # the contact patch follows from them (model/geometry.py)


class SteeringSurface:
    """The steering of an Assembly (assembly.py): its c-factor, its steering-wheel
    target and columns. ``c_factor_key``: where its file gives the c-factor."""

    c_factor_key: str = "config.steering.c_factor"
    mirrored_track: float | None = None  # m: a corner's config.track (model/steering.py)

    @property
    def steering(self) -> Steering | None:
        """The steering wheel on its rack: its file's c-factor (``c_factor_key``; None:
        none given) and the rack's sense, its first corner's; None without a rack."""
        if "_steering" not in self.__dict__:
            first = self.corners[self.labels[0]]
            c = c_factor_of(first, self.c_factor_key)  # refused without a rack
            steering = None
            if self.model.existJointName(rack.JOINT):
                steering = Steering(c, steer_sense(first.design_points()))
            self.__dict__["_steering"] = steering
        return self.__dict__["_steering"]

    def steering_target(self, t):
        """A ``steering_wheel`` (deg) or ``rack`` (mm) target that no shared element has
        (a corner's, an axle's) as the rack target it is; any other as it is."""
        if t.quantity not in STEERING_QUANTITIES or t.quantity in self.quantities:
            return t
        steering = self.steering
        if steering is None or (t.quantity == "steering_wheel" and steering.c_factor is None):
            return t  # refused where its row is read (refuse_steering)
        travel = t.values if t.quantity == "rack" else steering.rack_travel(t.values)
        first = self.labels[0]
        return Target(rack.INBOARD, "y", travel, side=first or None)

    def held_targets(self, targets: list) -> list:
        """Its sweep's targets, a steering-wheel target as the rack's, then as the model
        holds them (Composed.held_targets: the rack at design where none steers it)."""
        return super().held_targets([self.steering_target(t) for t in targets])

    def refuse_steering(self, t, i: int, source: str) -> None:
        """The error of a steering target it cannot read: no c-factor, or no rack."""
        if t.quantity not in STEERING_QUANTITIES:
            return
        if self.steering is None:
            why = f"{t.quantity}: this {self.noun} has no rack"
        else:
            why = f"steering_wheel needs {self.c_factor_key} (mm of rack per revolution)"
        raise InputError(source, f"targets[{i}]", why)

    # ------------------------------------------------------------ columns

    def steering_columns(self, columns: dict) -> dict:
        """``steering_wheel_angle`` (deg, + turning left) and ``steering_ratio`` where a
        c-factor is given: name → (values, unit)."""
        steering = self.steering
        if steering is None or steering.c_factor is None or "rack_displacement" not in columns:
            return {}
        angle = steering.wheel_angle(columns["rack_displacement"])
        return {"steering_wheel_angle": (angle, "deg")} | self.steering_ratio(columns)

    def with_steering(self, columns: dict) -> dict:
        """The columns (name → (values, unit)) with the steering's computed from them (the
        validation engines': Assembly.metric_columns_of): the steering wheel's angle where
        they have the rack's travel, and the steering ratio."""
        values = {name: column[0] for name, column in columns.items()}
        return columns | self.steering_ratio(values) | self.steering_columns(values)

    def steering_ratio(self, columns: dict) -> dict:
        """``steering_ratio`` (deg/deg): d steering-wheel angle / d mean steer angle (+
        left) of its rack-steered wheels, each from its own derivative along the rack
        (−s · d roadwheel_angle / d rack, exact), the wheels' heights held; {} without
        a c-factor or those columns."""
        steering = self.steering
        if steering is None or steering.c_factor is None:
            return {}
        rates = []
        for label, g in self.corners.items():
            name = f"deriv_{TOE}_wrt_rack_displacement{self.suffix(label)}"
            if g.steering == "rack" and name in columns:
                rates.append(-g.sign * columns[name])  # deg of steer per mm of rack
        if not rates:
            return {}
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = steering.wheel_rate() / np.mean(rates, axis=0)
        return {"steering_ratio": (ratio, "deg/deg")}

    def partner_columns(self, qs: list, plain: dict, columns: dict) -> dict:
        """A corner's steering with its mirrored partner (with ``config.wheelbase``, its
        ``config.track``, ``mirrored_track``, and a rack): ``track`` (mm),
        ``steer_angle_inner``, ``steer_angle_outer`` (deg), ``ackermann`` (%) and
        ``turning_radius`` (m, + left). The partner is this corner
        mirrored in y = 0 at the same wheel-centre height on the same rack, so its pose
        is the mirror image of this corner's own at the rack's opposite travel: solved
        here at every step (``qs``: the solved configurations, None where a step failed;
        ``plain``: every point (n, 3) m; ``columns``: the columns so far)."""
        g = self.corners[self.labels[0]]
        steered = self.steering is not None and "rack_displacement" in columns
        if g.wheelbase is None or self.mirrored_track is None or not steered:
            return {}
        travel = columns["rack_displacement"] * 1e-3  # m
        centred = np.abs(travel) < STRAIGHT
        # at the rack's centre the partner is this corner's own pose, mirrored
        mate = {k: np.where(centred[:, None], plain[k], np.nan) for k in PARTNER_POINTS}
        solved = [i for i, q in enumerate(qs) if q is not None and not centred[i]]
        if solved:
            heights = plain["wheel_center"][solved, 2] * 1e3
            targets = [
                Target("wheel_center", "z", heights, "absolute"),
                Target(rack.INBOARD, "y", -travel[solved] * 1e3),
            ]
            steps = self.solve_steps(Sweep(targets, "<the mirrored partner>"))
            done = [i for i, step in zip(solved, steps, strict=True) if step.converged]
            if done:  # their points every step at once, on the model's tree
                tree = tree_of(self.kin)
                frames = Frames(tree, [self.points[k].frame_id for k in FRAMES])
                Q = np.array([step.q for step in steps if step.converged])
                at = dict(zip(FRAMES, frames.positions(*tree.placements(Q)), strict=True))
                spin = unit(at["axle_outboard"] - at["axle_inboard"])
                at["contact_patch_center"] = contact_patch(at["wheel_center"], spin, g.wheel.radius)
                for k in PARTNER_POINTS:
                    mate[k][done] = at[k]
        design = {k: self.design_positions[k][None] for k in PARTNER_POINTS}
        with np.errstate(invalid="ignore"):
            toe = metric_columns(g, mate, design, only={TOE})[TOE][0]
        toe0 = metric_columns(g, design, design, only={TOE})[TOE][0][0]
        s = g.sign  # its steer (+ left) −s·toe; the mirrored partner's +s·toe there
        own, partner = (-s * columns[TOE], -s * toe0), (s * toe, s * toe0)
        left, right = (own, partner) if s > 0 else (partner, own)
        steer, at_design = (left[0], right[0]), (left[1], right[1])
        track = s * (plain["contact_patch_center"][:, 1] + mate["contact_patch_center"][:, 1])
        inner, outer = inner_outer(steer, at_design)
        inner[centred] = outer[centred] = np.nan
        return {
            "track": (track * 1e3, "mm"),
            "steer_angle_inner": (inner, "deg"),
            "steer_angle_outer": (outer, "deg"),
            "ackermann": (ackermann(steer, at_design, g.wheelbase, track, travel), "%"),
            "turning_radius": (turning_radius(steer, at_design, g.wheelbase, travel), "m"),
        }
