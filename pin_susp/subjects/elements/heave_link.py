"""The heave link (docs/axle.md): rocker to rocker, measured only — its ends are a
point on each side's rocker, its column the length between them."""

from __future__ import annotations

import numpy as np

SIDES = ("left", "right")


class HeaveLink:
    """An axle's heave link (``axle_config.heave_link``), or none."""

    def __init__(self, axle):
        self.kind = axle.heave_link
        self.side_points = axle.side_points

    quantities = ()  # no sweep target is its row

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """None of its own at this level: the axle's pair of corners (wheel_pair.py)
        writes its ``columns`` among the axle's, in the results' column order."""
        return {}

    def check_targets(self, targets, source: str) -> None:
        """Nothing: the link only measures."""

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        """Each end on its side's rocker (no body, no closure: it only measures)."""
        if self.kind == "none":
            return
        for side in SIDES:
            points[f"{side}_heave_link_rocker"] = (
                f"{side}_rocker",
                self.side_points[side]["heave_link_rocker"],
            )

    def columns(self, model, p: dict, d: dict) -> dict:
        """``heave_link_length`` (mm)."""
        if self.kind == "none":
            return {}
        length = np.linalg.norm(p["left_heave_link_rocker"] - p["right_heave_link_rocker"], axis=-1)
        return {"heave_link_length": (length * 1e3, "mm")}
