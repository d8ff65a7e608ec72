"""Each point's name on a drawing (``drawing.py``), placed after the layout where it
covers the fewest other labels and points; points that coincide in a view share
one label."""

from __future__ import annotations

import numpy as np
from matplotlib.transforms import Bbox

LABEL_PLACES = (  # offset (points), alignment: tried in this order, the first free one wins
    (4, 3, "left", "bottom"),
    (4, -3, "left", "top"),
    (-4, 3, "right", "bottom"),
    (-4, -3, "right", "top"),
    (0, 6, "center", "bottom"),
    (0, -6, "center", "top"),
    (4, 12, "left", "bottom"),  # a line further out, for crowded rows
    (4, -12, "left", "top"),
    (-4, 12, "right", "bottom"),
    (-4, -12, "right", "top"),
)


def label_points(fig, views, points: dict[str, np.ndarray]) -> None:
    """Each point's name (points: name → position, mm) next to it, where it covers the
    fewest other labels and points; points that coincide in a view share one label.
    After the layout: it measures the labels on the page."""
    renderer = fig.canvas.get_renderer()
    for ax, view in views:
        ax.apply_aspect()  # the box the equal aspect gives it, as drawn, not the layout's
        xy = {n: p[list(view)] for n, p in points.items()}
        dots = ax.transData.transform(np.array(list(xy.values())))
        taken = [Bbox.from_bounds(x - 3, y - 3, 6, 6) for x, y in dots]
        for group in _coincident(xy, 0.012 * float(np.ptp(ax.get_xlim()))):
            taken.append(_place_label(ax, renderer, "\n".join(group), xy[group[0]], taken))


def _coincident(xy: dict[str, np.ndarray], close: float) -> list[list[str]]:
    """The names grouped by position: closer than ``close`` to a group's first point."""
    groups: list[list[str]] = []
    for name, q in xy.items():
        group = next((g for g in groups if np.linalg.norm(xy[g[0]] - q) < close), None)
        if group is None:
            groups.append([name])
        else:
            group.append(name)
    return groups


def _place_label(ax, renderer, text: str, xy, taken: list) -> Bbox:
    """Annotate ``xy`` at the first of LABEL_PLACES that overlaps nothing taken and stays
    in the axes (else the least bad one); returns the label's box on the page."""
    frame = ax.get_window_extent(renderer)
    options = []
    for dx, dy, ha, va in LABEL_PLACES:
        label = ax.annotate(
            text,
            xy,
            xytext=(dx, dy),
            textcoords="offset points",
            ha=ha,
            va=va,
            fontsize=6,
            color="0.1",
            gid="point_label",
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.6, "pad": 0.5},
        )
        box = label.get_window_extent(renderer)
        outside = box.width * box.height - _area(Bbox.intersection(box, frame))
        options.append((sum(_area(Bbox.intersection(box, b)) for b in taken) + outside, label))
    best = min(options, key=lambda o: o[0])[1]  # ties: the earlier, preferred place
    for _, label in options:
        if label is not best:
            label.remove()
    return best.get_window_extent(renderer).padded(2)  # a gap between neighbours


def _area(box) -> float:
    return 0.0 if box is None else box.width * box.height
