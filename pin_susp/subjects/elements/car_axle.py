"""A vehicle's front or rear axle as a pair of its corners (docs/vehicle.md, Columns):
the axle's own columns (docs/axle.md) with the suffix ``_front`` or ``_rear``.

A vehicle's corners are labelled ``fl``, ``fr``, ``rl``, ``rr``; an axle's columns are
written for ``left`` and ``right``. ``AxleOfCar`` reads a vehicle's two corners of one
end as an axle would read its own (``AxleView``: the same names, the vehicle's
wheelbase) and writes the pair's columns (wheel_pair.py) — measured in the chassis
frame, as an axle on its rig measures them: the heave and roll of its wheel centres,
the roll centre, the track, the steer angles and Ackermann, the rates along the
axle's roll and, with the springs' rates, its roll stiffness. Per-side columns take
the corner's suffix (``steer_angle_fl``), the axle's the end's (``track_front``).
"""

from __future__ import annotations

from dataclasses import replace

from .anti_roll_bar import AntiRollBar
from .wheel_pair import SIDES, pair_columns, roll_rates

# the vehicle writes its own: the body's (camber to ground on the road) and the rack's
SKIPPED = ("camber_to_ground_left", "camber_to_ground_right", "rack_displacement")


class AxleView:
    """A vehicle's two corners of one end, named as an axle's (``left_…``, ``right_…``):
    what wheel_pair.py reads of an AxleModel."""

    def __init__(self, model, labels: tuple[str, str], wheelbase: float, bar=None):
        self.labels = dict(zip(SIDES, labels, strict=True))
        d = model.design_positions
        self.corners, self.corner_points, self.design_positions = {}, {}, {}
        self.design_steer = {}
        for side, label in self.labels.items():
            g = model.corners[label]
            self.corners[side] = replace(g, wheelbase=wheelbase)
            self.corner_points[side] = model.corner_points[label]
            for name, at in d.items():  # the corner's points and its bar's ends
                if name.startswith(f"{label}_"):
                    self.design_positions[side + name.removeprefix(label)] = at
            self.design_steer[side] = model.design_steer(label)
        self.bar = AntiRollBar(None) if bar is None else bar
        self.elements = []


class AxleOfCar:
    """The front (``end`` "front", labels fl, fr) or rear axle of a vehicle, as one of
    its shared elements: no part of the tree, no sweep quantity; its columns."""

    quantities = ()

    def __init__(self, end: str, labels: tuple[str, str]):
        self.end, self.labels = end, labels

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        """Nothing: the pair adds no part to the tree."""

    def check_targets(self, targets, source: str) -> None:
        """Nothing: its columns only."""

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """The axle's columns (wheel_pair.py) of this end's two corners, from every
        point's motion (``points``: name → {label: jet.Dual}) and each corner's
        columns (``sides``: label → its metric columns)."""
        axle = getattr(model.vehicle, self.end)
        bar = AntiRollBar(axle) if axle.anti_roll != "none" else None
        view = AxleView(model, self.labels, model.vehicle.wheelbase * 1e-3, bar)
        left, right = self.labels
        by_side = {"left": sides[left], "right": sides[right]}
        plain, own = {}, {}
        for side, label in view.labels.items():
            for name, motion in points.items():  # the corner's points and its bar's ends
                if name.startswith(f"{label}_"):
                    key = side + name.removeprefix(label)
                    plain[key] = motion[label].val
                    own[key] = {s: motion[at] for s, at in view.labels.items()}
        cps = {s: own[f"{s}_contact_patch_center"][s] for s in SIDES}
        out = pair_columns(view, plain, by_side, cps) | roll_rates(view, own, by_side)
        if model.corners[left].steering != "rack":
            out.pop("ackermann", None)
        return self.suffixed(out)

    def suffixed(self, columns: dict) -> dict:
        """An axle's column names as the vehicle's (``car_column``)."""
        out = {}
        for name, column in columns.items():
            named = car_column(name, self.labels, self.end)
            if named is not None:
                out[named] = column
        return out


def car_column(name: str, labels: tuple[str, str], end: str) -> str | None:
    """An axle's column as a vehicle names it: ``_left``/``_right`` → the corner's label
    (``steer_angle_fl``), the rest ``_<end>`` (``track_front``); a rate along the axle's
    own roll (its left wheel up, its right down, the body held) ``_wrt_axle_roll`` —
    ``_wrt_roll`` is the body's roll on the road (``deriv_camber_wrt_roll_fl``); None for
    what the vehicle writes itself (SKIPPED)."""
    if name in SKIPPED:
        return None
    if name.startswith("deriv_"):
        name = name.replace("_wrt_roll", "_wrt_axle_roll")
    for side, label in zip(SIDES, labels, strict=True):
        if name.endswith(f"_{side}"):
            return name.removesuffix(side) + label
    return f"{name}_{end}"
