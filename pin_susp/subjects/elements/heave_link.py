"""The heave link (docs/axle.md): rocker to rocker, measured only — its ends are a
point on each side's rocker, its column the length between them.

Its names are its two corners' labels and its own prefix, as the anti-roll bar's
(anti_roll_bar.py): an axle's ``left_heave_link_rocker`` and ``heave_link_length``; a
vehicle's front axle's ``fl_heave_link_rocker`` and ``heave_link_length_front``.
"""

from __future__ import annotations

import numpy as np

from .anti_roll_bar import SIDES, own_suffix


class HeaveLink:
    """An axle's heave link (``axle_config.heave_link``), or none; ``labels``: its two
    corners' labels (the axle's left side's first), ``prefix``: its own names'."""

    def __init__(self, axle, labels: tuple[str, str] = SIDES, prefix: str = ""):
        self.kind = axle.heave_link
        self.labels, self.suffix = tuple(labels), own_suffix(prefix)
        self.side_points = {
            label: axle.side_points[s] for label, s in zip(labels, SIDES, strict=True)
        }

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
        for label in self.labels:
            points[f"{label}_heave_link_rocker"] = (
                f"{label}_rocker",
                self.side_points[label]["heave_link_rocker"],
            )

    def columns(self, model, p: dict, d: dict) -> dict:
        """``heave_link_length`` (mm), with its own suffix (``heave_link_length_front``)."""
        if self.kind == "none":
            return {}
        first, second = (p[f"{label}_heave_link_rocker"] for label in self.labels)
        length = np.linalg.norm(first - second, axis=-1)
        return {f"heave_link_length{self.suffix}": (length * 1e3, "mm")}
