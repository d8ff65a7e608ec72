"""The standard kinematics report and 2D drawings, with matplotlib (Agg, no display).

``report_figure`` draws one panel per metric against wheel travel (or rack
position for a steer sweep), several results files as several lines;
labels and units come from the metric registry and the CSV's own units.
``drawing_figure`` draws the corner in front and side view.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .errors import InputError  # noqa: E402
from .export import atomic_write  # noqa: E402
from .metrics import HUB_Z, METRIC_BY_NAME, RACK, STANDARD, Derivative  # noqa: E402

EXTRA = (
    "svic_z",
    "fvic_z",
    "anti_dive",
    "anti_lift",
    "anti_squat",
    "rocker_angle",
    "damper_length",
    "motion_ratio",
)
DERIVED = ("camber", "roadwheel_angle")  # their derivative columns get panels


class ResultsFile:
    """A results CSV read back: columns as float arrays (empty cells → NaN), units."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.label = self.path.stem
        try:
            lines = self.path.read_text().splitlines()
        except OSError as exc:
            raise InputError(str(path), "", f"cannot be read ({exc.strerror})") from None
        comments = [ln for ln in lines if ln.startswith("#")]
        rows = [ln.split(",") for ln in lines if ln and not ln.startswith("#")]
        if not rows or "step_index" not in rows[0]:
            raise InputError(str(path), "", "not a pin_susp results CSV (no step_index column)")
        header, body = rows[0], rows[1:]
        self.units = {}
        for line in comments:
            if line.startswith("# units: "):
                self.units = json.loads(line.removeprefix("# units: "))
        self.columns = {}
        for j, name in enumerate(header):
            cells = [r[j] if j < len(r) else "" for r in body]
            try:
                self.columns[name] = np.array(
                    [
                        np.nan
                        if c == ""
                        else 1.0
                        if c == "True"
                        else 0.0
                        if c == "False"
                        else float(c)
                        for c in cells
                    ]
                )
            except ValueError:
                raise InputError(str(path), name, "has a cell that is not a number") from None
        for needed in ("wheel_travel", "camber"):
            if needed not in self.columns:
                raise InputError(str(path), needed, "missing column: not a sweep results CSV")

    def __getitem__(self, name):
        return self.columns[name]


def label(name: str) -> str:
    """Human label of a column, from the registry."""
    if name in METRIC_BY_NAME:
        return METRIC_BY_NAME[name].label
    if name == "motion_ratio":
        return "Motion ratio"
    if name.startswith("deriv_"):
        metric, driver = name.removeprefix("deriv_").split("_wrt_")
        return Derivative(METRIC_BY_NAME[metric], driver).label
    return name.replace("_", " ")


def x_axis(results: ResultsFile) -> tuple[str, str]:
    """Wheel travel when the wheel moves, else the rack position (a steer sweep)."""
    travel = results["wheel_travel"]
    if np.nanmax(travel) - np.nanmin(travel) > 1e-6 or "trackrod_inboard_y" not in results.columns:
        return "wheel_travel", "Wheel travel (+ bump) [mm]"
    return "trackrod_inboard_y", "Rack position (trackrod_inboard y) [mm]"


def panels(results: list[ResultsFile], xname: str) -> list[str]:
    driver = HUB_Z if xname == "wheel_travel" else RACK
    names = list(STANDARD) + list(EXTRA)
    names += [f"deriv_{m}_wrt_{driver}" for m in DERIVED]
    return [n for n in names if any(n in r.columns and np.any(np.isfinite(r[n])) for r in results)]


def report_figure(results: list[ResultsFile]):
    """One panel per metric against wheel travel (or rack), one line per results file."""
    xname, xlabel = x_axis(results[0])
    names = panels(results, xname)
    ncols = 4
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.1 * nrows), squeeze=False)
    for ax, name in zip(axes.flat, names, strict=False):
        unit = next((r.units.get(name, "") for r in results if name in r.columns), "")
        for r in results:
            if name in r.columns:
                ax.plot(r[xname], r[name], label=r.label, linewidth=1.6)
        ax.set_title(label(name), fontsize=10)
        ax.set_ylabel(f"{name} [{unit}]" if unit else name, fontsize=8)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
    for ax in list(axes.flat)[len(names) :]:
        ax.set_visible(False)
    if len(results) > 1:
        axes.flat[0].legend(fontsize=8)
    fig.suptitle("pin_susp kinematics: " + ", ".join(r.label for r in results), fontsize=12)
    fig.tight_layout()
    return fig


def drawing_figure(corner):
    """Front view (y–z) and side view (x–z) of the corner at its (as-set) design state."""
    from .viz import LINKS, segments

    fig, (front, side) = plt.subplots(1, 2, figsize=(14, 6))
    corners = [(corner, 1.0, "-")]
    if corner.geometry.drawn is not None:
        from .corner import Corner

        corners.insert(0, (Corner(corner.geometry.drawn, apply_setup=False), 0.3, "--"))
    for c, alpha, style in corners:
        p = {k: v * 1e3 for k, v in c.design_positions.items()}
        colours = dict(c.tree.materials)
        for v in c.tree.visuals:
            if v.shape == "rod" and v.material != "tyre":
                _both(
                    front,
                    side,
                    v.start,
                    v.end,
                    style,
                    color=colours[v.material][:3],
                    alpha=alpha,
                    lw=2,
                )
        for name, (a, b) in segments(c, c.design_positions).items():
            axis = name == "steering_axis"
            _both(
                front,
                side,
                a,
                b,
                ":" if axis else style,
                alpha=alpha,
                lw=1.5,
                color="goldenrod" if axis else f"#{LINKS[name][1]:06x}",
            )
        _tyre(front, side, c, p, alpha, style)
        pts = np.array([p[n] for n in c.geometry.hardpoints])
        front.plot(pts[:, 1], pts[:, 2], "o", color="0.2", ms=3, alpha=alpha)
        side.plot(pts[:, 0], pts[:, 2], "o", color="0.2", ms=3, alpha=alpha)
    ground = corner.design_positions["contact_patch_center"][2] * 1e3
    for ax, title, xl in (
        (front, "Front view", "y [mm] (+ left)"),
        (side, "Side view", "x [mm] (+ forward)"),
    ):
        ax.axhline(ground, color="0.5", lw=0.8)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.set_title(title)
        ax.set_xlabel(xl)
        ax.set_ylabel("z [mm]")
    if corner.geometry.sign < 0:
        front.invert_xaxis()  # a right corner seen from the front: outboard to the left
    note = " (dashed: as drawn)" if len(corners) > 1 else ""
    fig.suptitle(f"{corner.geometry.name}{note}")
    fig.tight_layout()
    return fig


def _both(front, side, a, b, style, **kwargs) -> None:
    """A segment (m) in front view (y, z) and side view (x, z), in mm."""
    a, b = a * 1e3, b * 1e3
    front.plot([a[1], b[1]], [a[2], b[2]], style, **kwargs)
    side.plot([a[0], b[0]], [a[2], b[2]], style, **kwargs)


def _tyre(front, side, c, p, alpha, style) -> None:
    """The tyre's outline: a rectangle in front view, its circle in side view."""
    from .geometry import wheel_down

    wc = p["wheel_center"]
    a = (p["axle_outboard"] - p["axle_inboard"]) / np.linalg.norm(
        p["axle_outboard"] - p["axle_inboard"]
    )
    down, _ = wheel_down(a)
    r = c.geometry.wheel.radius * 1e3
    w = c.geometry.wheel.section_width * 1e3 / 2
    box = np.array(
        [
            wc + sa * w * a + sd * r * down
            for sa, sd in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))
        ]
    )
    front.plot(box[:, 1], box[:, 2], style, color="0.15", alpha=alpha, lw=1.2)
    t = np.linspace(0, 2 * np.pi, 120)
    side.plot(
        wc[0] + r * np.cos(t), wc[2] + r * np.sin(t), style, color="0.15", alpha=alpha, lw=1.2
    )


def save_figure(fig, path: str | Path) -> None:
    """Write the figure whole or not at all (format from the file's ending)."""
    path = Path(path)
    with atomic_write(path, binary=True) as f:
        fig.savefig(f, format=path.suffix.lstrip(".") or "png", dpi=110)
    plt.close(fig)
