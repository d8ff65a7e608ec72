"""What the engines need from a subject (README, How it works): a corner's or an axle's
points, drivers, targets and columns, as a scope (:class:`CornerScope`,
:class:`AxleScope`); the engines only see points and targets.
"""

from __future__ import annotations

import numpy as np

from ..axle import (
    SIDES,
    AxleModel,
    axle_metric_columns,
    axle_results,
    solve_axle_sweep,
    target_values,
)
from ..jet import Dual
from ..jet import value as plain
from ..metrics import METRICS, TOE_LINK, metric_columns
from ..pointwise import Along, PointwiseAxle, PointwiseCorner, Y, Z, axle_targets

RATE_METRICS = {m.name for m in METRICS if m.rates}


def step_targets(subject, sweep) -> list[list]:
    """Every step's targets: (point, unit direction, absolute value m) for a corner;
    point-based targets (:mod:`pin_susp.pointwise`) for an axle."""
    return scope_of(subject).step_targets(sweep)


def held_drivers(corner, points: dict) -> list[tuple[str, np.ndarray, float]]:
    """The drivers as targets held where the engine's pose is: wheel-centre z, and the
    rack (trackrod_inboard y) on a rack corner."""
    held = [("wheel_center", Z, float(points["wheel_center"][2]))]
    g = corner.geometry
    if g.steering == "rack":
        inner = g.steering_points[0]
        held.append((inner, Y, float(points[inner][1])))
    return held


class CornerScope:
    """What the engines need from a corner: its points and drivers, the sweep as
    targets, the columns computed from an engine's points (name → Dual)."""

    kind = "corner"

    def __init__(self, corner):
        self.subject = corner
        self.tree = corner.tree
        self.drivers = len(corner.drivers)
        g = corner.geometry
        # a driver no target holds: the fixed toe link's length (a link of the engine)
        self.links = [g.steering_points] if TOE_LINK in corner.drivers else []
        self.wheels = {"": (g.wheel.radius, corner.mechanism.WHEEL_BODY)}
        self.sites = [n for n in corner.point_names if n != "contact_patch_center"]

    def results(self, sweep):
        return self.subject.run_sweep(sweep)

    def pointwise(self) -> PointwiseCorner:
        return PointwiseCorner(self.subject.geometry)

    def step_targets(self, sweep) -> list[list]:
        held = self.subject.held_targets(sweep.targets)  # the rack at design if not given
        values = self.subject.target_values(held)
        return [
            [(t.point, t.unit_direction, float(v[k])) for k, t in enumerate(held)] for v in values
        ]

    def held(self, points: dict) -> list:
        return held_drivers(self.subject, points)

    def duals(self, points: dict, rates: dict) -> dict[str, Dual]:
        return {name: Dual(p[None], rates[name][:, None]) for name, p in points.items()}

    def columns(self, points: dict) -> dict:
        c = self.subject
        design = {k: v[None] for k, v in c.design_positions.items()}
        return metric_columns(c.geometry, points, design, c.spring_sense)

    def positions(self, points: dict) -> dict[str, np.ndarray]:
        return {name: points[name].val[0] for name in self.subject.point_names}

    def stalled(self, points: dict) -> bool:
        return bool(np.isnan(plain(points["wheel_center"].der)).any())

    def from_rates(self, name: str) -> bool:
        return name in RATE_METRICS

    def size(self, name: str, results, i: int) -> float:
        """What the column's RELATIVE tolerance is a fraction of: its own value."""
        return abs(results[name][i])


class AxleScope:
    """An axle's (docs/axle.md): the drivers are each wheel centre's z and the rack
    (or each side's fixed toe link); a point is a Dual per side (its rates along
    that side's hub z, the other wheel and the rack held, and along the rack or its
    toe link's length), as axle_results takes them."""

    kind = "axle"
    # the roll centre's columns: name → the vector it is a coordinate of
    ROLL_CENTRE = {
        name: pair
        for pair in (
            ("roll_center_y", "roll_center_z"),
            ("deriv_roll_center_y_wrt_roll", "deriv_roll_center_z_wrt_roll"),
        )
        for name in pair
    }

    def __init__(self, model: AxleModel):
        self.subject = model
        self.tree = model.tree
        self.rack = model.geometries["left"].steering == "rack"
        held = len(SIDES) + self.rack
        # each side's drivers: its hub z, the rack, or its fixed toe link's length
        # (a driver no target holds: a link of the engine), as axle_results orders them
        self.side_drivers, self.links = {}, []
        for c, (side, g) in enumerate(model.geometries.items()):
            self.side_drivers[side] = [c, len(SIDES)] if self.rack else [c]
            if g.steering == "none" and g.steering_points:
                self.side_drivers[side].append(held + len(self.links))
                self.links.append(tuple(f"{side}_{n}" for n in g.steering_points))
        self.drivers = held + len(self.links)
        self.wheels = {
            f"{side}_": (g.wheel.radius, f"{side}_{g.mechanism.WHEEL_BODY}")
            for side, g in model.geometries.items()
        }
        self.sites = [n for n in model.output_points if not n.endswith("contact_patch_center")]

    def results(self, sweep):
        model = self.subject
        return axle_results(model, sweep, solve_axle_sweep(model, sweep))

    def pointwise(self) -> PointwiseAxle:
        return PointwiseAxle(self.subject.axle, self.subject.geometries)

    def step_targets(self, sweep) -> list[list]:
        model = self.subject
        targets = model.held_sweep(sweep).targets  # the rack at design if not given
        values = target_values(model, targets)
        return [axle_targets(targets, v, model.design_positions) for v in values]

    def held(self, points: dict) -> list:
        held = [Along(f"{s}_wheel_center", Z, float(points[f"{s}_wheel_center"][2])) for s in SIDES]
        if self.rack:
            inner = f"left_{self.subject.geometries['left'].steering_points[0]}"
            held.append(Along(inner, Y, float(points[inner][1])))
        return held

    def duals(self, points: dict, rates: dict) -> dict[str, dict[str, Dual]]:
        """Each side's rates; for a rigid bar none along a wheel's own height, as the
        sweep writes none (one wheel cannot move with the other held)."""
        hub = np.array([np.nan if self.subject.anti_roll_rigid else 1.0])
        scale = {s: np.r_[hub, np.ones(len(self.side_drivers[s]) - 1)][:, None] for s in SIDES}
        return {
            name: {
                s: Dual(p[None], rates[name][self.side_drivers[s]][:, None] * scale[s])
                for s in SIDES
            }
            for name, p in points.items()
        }

    def columns(self, points: dict) -> dict:
        """Every metric column, computed from the points as axle_results computes them
        (with its own pieces: the per-side columns, the axle's, the roll rates)."""
        return axle_metric_columns(self.subject, points)

    def positions(self, points: dict) -> dict[str, np.ndarray]:
        return {name: points[name]["left"].val[0] for name in self.subject.output_points}

    def stalled(self, points: dict) -> bool:
        if self.subject.anti_roll_rigid:
            return False  # no rates by design (duals): compared as blank, like the sweep's
        return any(np.isnan(plain(points[f"{s}_wheel_center"][s].der)).any() for s in SIDES)

    def from_rates(self, name: str) -> bool:
        return name.removesuffix("_left").removesuffix("_right") in RATE_METRICS

    def size(self, name: str, results, i: int) -> float:
        """What the column's RELATIVE tolerance is a fraction of: its own value; for the
        roll centre and its rates, the vector's length times |RC| / track at least 1.

        The roll centre crosses two lines from contact patches a track apart; when
        they are nearly parallel (instant centres a hundred metres out) it lies at
        |RC| ≫ track, and a rounding δ in a line's slope moves it by (|RC|²/track)·δ:
        a relative error |RC|/track times larger than its inputs', in either
        coordinate and in its rates alike.
        """
        if name not in self.ROLL_CENTRE:
            return abs(results[name][i])
        rc = np.hypot(results["roll_center_y"][i], results["roll_center_z"][i])
        lever = max(1.0, rc / results["track"][i])
        return np.hypot(*(results[n][i] for n in self.ROLL_CENTRE[name])) * lever


def scope_of(subject) -> CornerScope | AxleScope:
    if isinstance(subject, CornerScope | AxleScope):
        return subject
    return AxleScope(subject) if isinstance(subject, AxleModel) else CornerScope(subject)
