"""The standard kinematics report and 2D drawings, with matplotlib (Agg, no display).

``report_figure`` draws one panel per metric against what the sweep moved:
wheel travel for a bump sweep, rack travel from centre (the
``rack_displacement`` column) for a steer sweep, several results files as
several lines; labels and units come from the metric registry and the CSV's
own units. Results of older versions have no ``rack_displacement``: they are
plotted against the absolute ``trackrod_inboard_y`` and the axis says so.
Files whose sweeps moved different things (a bump sweep and a steer sweep)
are refused with an :class:`InputError` naming both: their lines cannot share
an x axis, and two reports say more than one squeezed figure.

``drawing_figure`` draws the corner in front and side view at its design
state, with the instant-centre construction of the as-set corner: front view,
each ball joint to the FVIC (the instant axis ∩ plane x = WC_x) and the line
from the contact patch through the FVIC to the car centreline, where it gives
the roll centre of a symmetric axle; side view, each ball joint to the SVIC
and the contact patch to the SVIC (the anti-dive/-lift line). An instant
centre at infinity (parallel arm planes) or further than 20 m is not drawn
but noted; the view stays on the corner and lines run off its edges. The
tyre is its silhouette: the two rim-edge circles, projected, cut at the road.
``labels=True`` names every hardpoint and adds a legend of the colours.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402

from .errors import InputError, PinSuspError  # noqa: E402
from .export import atomic_write  # noqa: E402
from .geometry import unit, wheel_down  # noqa: E402
from .metrics import (  # noqa: E402
    HUB_Z,
    METRIC_BY_NAME,
    RACK,
    STANDARD,
    Derivative,
    PointSet,
    X,
    Y,
)

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
    """A results CSV read back: columns as float arrays (empty cells → NaN), units.

    Anything that is not a results CSV pin_susp could have written (binary,
    empty, no rows, ragged rows, a corrupt ``# units:`` line, no numbers at
    all) is an :class:`InputError` naming the file; empty cells and empty
    columns are fine (a failed step, an undefined metric) and are not drawn.
    """

    def __init__(self, path: str | Path, name: str | Path | None = None, raw: bytes | None = None):
        """``name``: what messages and the legend call the file (default: ``path``);
        ``raw``: its contents when they are at hand (a CSV written to a stream)."""
        self.path = Path(path)
        self.source = source = str(path if name is None else name)
        self.label = Path(source).stem
        try:
            if raw is None:
                raw = self.path.read_bytes()
        except OSError as exc:
            raise InputError(source, "", f"cannot be read ({exc.strerror})") from None
        if not raw.strip():
            raise InputError(source, "", "is empty: not a pin_susp results CSV")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        if text is None or "\x00" in text:
            raise InputError(source, "", "is not a text file: not a pin_susp results CSV")
        comments, rows = [], []
        for number, line in enumerate(text.splitlines(), start=1):
            if line.startswith("#"):
                comments.append(line)
            elif line.strip():
                rows.append((number, line.split(",")))
        if not rows or "step_index" not in rows[0][1]:
            raise InputError(source, "", "not a pin_susp results CSV (no step_index column)")
        (_, header), body = rows[0], rows[1:]
        if not body:
            raise InputError(source, "", "no data rows (only a header)")
        seen: set[str] = set()
        twice = next((n for n in header if n in seen or seen.add(n)), None)
        if twice is not None:
            raise InputError(source, twice, "this column appears twice in the header")
        for number, row in body:
            if len(row) != len(header):
                raise InputError(
                    source,
                    f"line {number}",
                    f"{len(row)} cells, but the header has {len(header)} columns "
                    "(a damaged or hand-edited file)",
                )
        self.units = {}
        for line in comments:
            if line.startswith("# units:"):
                self.units = _units(source, line.removeprefix("# units:"))
        self.columns = {}
        for j, name in enumerate(header):
            try:
                self.columns[name] = np.array([_cell(row[j]) for _, row in body])
            except ValueError:
                raise InputError(source, name, "has a cell that is not a number") from None
        for needed in ("wheel_travel", "camber"):
            if needed not in self.columns:
                raise InputError(source, needed, "missing column: not a sweep results CSV")
        if not any(np.any(np.isfinite(c)) for c in self.columns.values()):
            raise InputError(source, "", "no numbers in it: every data cell is empty")
        if not np.any(np.isfinite(self.columns["wheel_travel"])):
            converged = self.columns.get("solver_converged")
            if converged is not None and not np.any(converged == 1.0):
                raise InputError(source, "", "no step of this sweep converged: nothing to plot")
            raise InputError(source, "wheel_travel", "no values: every cell is empty")

    def __getitem__(self, name):
        return self.columns[name]


def _cell(text: str) -> float:
    """A CSV cell as written by pin_susp: a number, empty (NaN), True or False."""
    text = text.strip()
    if text == "":
        return np.nan
    if text in ("True", "False"):
        return float(text == "True")
    return float(text)


def _units(source: str, text: str) -> dict[str, str]:
    """The ``# units:`` comment: a JSON object of column → unit."""
    try:
        units = json.loads(text)
    except ValueError as exc:
        raise InputError(source, "# units", f"not valid JSON ({exc})") from None
    if not isinstance(units, dict):
        raise InputError(source, "# units", f"expected a JSON object, got {type(units).__name__}")
    bad = next((k for k, v in units.items() if not isinstance(v, str)), None)
    if bad is not None:
        raise InputError(source, f"# units: {bad}", f"expected a unit string, got {units[bad]!r}")
    return units


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


WHEEL_X = ("wheel_travel", "Wheel travel (+ bump) [mm]")
RACK_X = ("rack_displacement", "Rack position from centre (+ left) [mm]")
# results written before the rack_displacement column: the design position is unknown
RACK_ABSOLUTE_X = ("trackrod_inboard_y", "Rack position: trackrod inboard y (absolute) [mm]")


def sweeps(results: ResultsFile) -> str | None:
    """What the sweep moved: 'wheel travel', 'rack travel', or None (nothing: one step)."""
    if _varies(results["wheel_travel"]):
        return "wheel travel"
    for name in ("rack_displacement", "trackrod_inboard_y"):
        if name in results.columns and _varies(results[name]):
            return "rack travel"
    return None


def x_axis(results: ResultsFile | list[ResultsFile]) -> tuple[str, str]:
    """The x column and label: wheel travel, or rack travel for a steer sweep.

    Several files must have moved the same thing, else an InputError naming
    two that differ (a file where nothing moved goes with any).
    """
    files = [results] if isinstance(results, ResultsFile) else results
    moved = [(r, kind) for r in files if (kind := sweeps(r)) is not None]
    first, first_kind = moved[0] if moved else (None, None)
    for r, kind in moved[1:]:
        if kind != first_kind:
            raise InputError(
                r.source,
                "",
                f"x is {kind} but {first.source}'s is {first_kind}: plot them separately",
            )
    if first_kind in (None, "wheel travel"):
        return WHEEL_X
    if all("rack_displacement" in r.columns for r in files):
        return RACK_X
    return RACK_ABSOLUTE_X  # one old file: all absolute, so the lines stay comparable


def _varies(column: np.ndarray) -> bool:
    finite = column[np.isfinite(column)]
    return finite.size > 1 and float(np.ptp(finite)) > 1e-6


def panels(results: list[ResultsFile], xname: str) -> list[str]:
    driver = HUB_Z if xname == "wheel_travel" else RACK
    names = list(STANDARD) + list(EXTRA)
    names += [f"deriv_{m}_wrt_{driver}" for m in DERIVED]
    return [n for n in names if any(n in r.columns and np.any(np.isfinite(r[n])) for r in results)]


def report_figure(results: list[ResultsFile]):
    """One panel per metric against wheel travel (or rack), one line per results file."""
    if not results:
        raise PinSuspError("no results file to plot")
    xname, xlabel = x_axis(results)
    for r in results[1:]:
        if xname not in r.columns or not np.any(np.isfinite(r[xname])):
            raise InputError(
                r.source,
                xname,
                f"no values, but {results[0].label} is plotted against it: "
                "plot results of the same kind of sweep together",
            )
    names = panels(results, xname)
    if not names:
        files = ", ".join(r.source for r in results)
        raise InputError(files, "", "no metric column has a value to plot")
    ncols = 4
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.1 * nrows), squeeze=False)
    for ax, name in zip(axes.flat, names, strict=False):
        unit = next((r.units.get(name, "") for r in results if name in r.columns), "")
        for r in results:
            if name in r.columns:
                # a lone point (one row, or one step between failed ones) shows as a dot
                ax.plot(r[xname], r[name], label=r.label, linewidth=1.6, marker=_marker(r, name))
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


def _marker(r: ResultsFile, name: str) -> str | None:
    finite = np.isfinite(r[name])
    lone = finite & ~np.r_[False, finite[:-1]] & ~np.r_[finite[1:], False]
    return "o" if np.any(lone) else None


FRONT, SIDE = (1, 2), (0, 2)  # the world axes each view shows, in mm
IC_FAR = 20_000.0  # mm from the wheel centre: beyond this an instant centre is noted, not drawn
CONSTRUCTION = "#c2185b"  # instant-centre construction: a colour no body has
PARALLEL = "arms parallel: instant centre at infinity"


def drawing_figure(corner, labels: bool = False):
    """Front view (y–z) and side view (x–z) of the corner at its (as-set) design state.

    With the instant-centre construction of the as-set corner (see the module
    docstring); ``labels``: each hardpoint's name next to it and a legend.
    """
    fig, (front, side) = plt.subplots(1, 2, figsize=(14, 6.5))
    corners = [(corner, 1.0, "-")]
    if corner.geometry.drawn is not None:
        from .linkage import Linkage

        corners.insert(0, (Linkage(corner.geometry.drawn), 0.3, "--"))
    for c, alpha, style in corners:
        _draw_corner(front, side, c, alpha, style)
    ground = _mm(corner)["contact_patch_center"][2]
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
    front.axvline(0.0, color="0.5", lw=0.8, ls="-.")  # the car's centreline
    drawn, keep = _instant_centres(front, side, corner)
    _fit_view(front, side, [c for c, _, _ in corners], keep)
    if corner.geometry.sign < 0:
        front.invert_xaxis()  # a right corner seen from the front: outboard to the left
    note = " (dashed: as drawn)" if len(corners) > 1 else ""
    fig.suptitle(f"{corner.geometry.name}{note}")
    if labels:
        _legend(fig, corner, ghost=len(corners) > 1, construction=bool(drawn))
    fig.tight_layout(rect=(0, 0.06 if labels else 0, 1, 1))
    if labels:
        _label_points(fig, front, side, corner)
    return fig


def _mm(c) -> dict[str, np.ndarray]:
    return {k: v * 1e3 for k, v in c.design_positions.items()}


def _draw_corner(front, side, c, alpha, style) -> None:
    """Bodies (the URDF's rods), links and steering axis, tyre, hardpoints."""
    from .viz import links, segments

    colours = dict(c.tree.materials)
    for v in c.tree.visuals:
        if v.shape == "rod" and v.material != "tyre":
            colour = colours[v.material][:3]
            _both(front, side, v.start, v.end, style, color=colour, alpha=alpha, lw=2)
    for name, (a, b) in segments(c, c.design_positions).items():
        axis = name == "steering_axis"
        colour = "goldenrod" if axis else f"#{links(c)[name][1]:06x}"
        _both(front, side, a, b, ":" if axis else style, alpha=alpha, lw=1.5, color=colour)
    p = _mm(c)
    for ax, view in ((front, FRONT), (side, SIDE)):
        outline = tyre_outline(c, view)
        ax.plot(*outline.T, style, color="0.15", alpha=alpha, lw=1.2, gid="tyre")
        pts = np.array([p[n][list(view)] for n in c.geometry.hardpoints])
        ax.plot(*pts.T, "o", color="0.2", ms=3, alpha=alpha)
        ax.plot(*p["wheel_center"][list(view)], "+", color="0.2", ms=8, alpha=alpha)
    # the wheel's centre plane, top of the rim to the contact patch: camber at a glance
    down = unit(p["contact_patch_center"] - p["wheel_center"])
    top = p["wheel_center"] - down * c.geometry.wheel.radius * 1e3
    line = np.array([top, p["contact_patch_center"]])[:, list(FRONT)]
    front.plot(*line.T, "-.", color="0.4", alpha=alpha, lw=0.6)


def _both(front, side, a, b, style, **kwargs) -> None:
    """A segment (m) in front view (y, z) and side view (x, z), in mm."""
    a, b = a * 1e3, b * 1e3
    front.plot([a[1], b[1]], [a[2], b[2]], style, **kwargs)
    side.plot([a[0], b[0]], [a[2], b[2]], style, **kwargs)


def tyre_outline(c, view: tuple[int, int]) -> np.ndarray:
    """The tyre's silhouette in a view (mm, closed polygon): what the eye sees of it.

    The tyre is taken as the cylinder between its two rim-edge circles (radius
    R about wheel_inboard and wheel_outboard, in planes normal to the spin
    axis); its outline is the convex hull of their projections. A cambered
    tyre's lower edge circle dips below the contact patch (the lowest point of
    the centre plane's circle, the road): a real tyre deflects there, so the
    outline is cut at the road.
    """
    from scipy.spatial import ConvexHull

    p = _mm(c)
    spin = unit(p["axle_outboard"] - p["axle_inboard"])
    down, _ = wheel_down(spin)
    t = np.linspace(0.0, 2.0 * np.pi, 241)[:, None]
    ring = c.geometry.wheel.radius * 1e3 * (np.cos(t) * down + np.sin(t) * np.cross(spin, down))
    edges = np.vstack([p["wheel_inboard"] + ring, p["wheel_outboard"] + ring])[:, list(view)]
    hull = edges[ConvexHull(edges).vertices]
    return _above(hull, p["contact_patch_center"][2])


def _above(polygon: np.ndarray, ground: float) -> np.ndarray:
    """A convex polygon (k, 2) cut at z = ground, keeping what is above; closed."""
    out = []
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        if a[1] >= ground:
            out.append(a)
        if (a[1] - ground) * (b[1] - ground) < 0:  # this edge crosses the road
            out.append([a[0] + (ground - a[1]) * (b[0] - a[0]) / (b[1] - a[1]), ground])
    out = np.roll(out, -int(np.argmin(np.array(out)[:, 1])), axis=0)  # the seam at a corner
    return np.array([*out, out[0]])


def _instant_centres(front, side, corner) -> tuple[list[str], list[np.ndarray]]:
    """Draw the FVIC and SVIC constructions; which were drawn, and the points (mm) the
    view should keep."""
    from .jet import value

    design = {k: v[None] for k, v in corner.design_positions.items()}
    # with the rates at design: a mechanism's instant centres may come from its twist
    ps = PointSet(corner.motion([corner.q_design]), design, corner.geometry)
    with np.errstate(invalid="ignore", divide="ignore"):
        ends = ps.kingpin()
    if ends is None:  # no kingpin (a trailing arm): the chassis points of the wheel's body
        names = corner.mechanism.upright_points(corner.geometry)
        ends = [design[n] for n in names if corner.body_of(n) == "chassis"][:2]
    rays = [value(e)[0] * 1e3 for e in reversed(ends)]  # upper first
    p = _mm(corner)
    drawn, keep = [], []
    for ax, axis, view, name in ((front, X, FRONT, "FVIC"), (side, Y, SIDE, "SVIC")):
        with np.errstate(invalid="ignore", divide="ignore"):
            ic = np.array([value(x)[0] for x in ps.instant_axis_point(axis)], dtype=float) * 1e3
        far = float(np.linalg.norm(ic - p["wheel_center"][list(view)]))
        if not np.all(np.isfinite(ic)):
            _note(ax, PARALLEL)
        elif far > IC_FAR:
            _note(ax, f"arms nearly parallel: {name} {far / 1e3:.0f} m away, not drawn")
        else:
            keep += _construction(ax, p, rays, view, ic, name)
            drawn.append(name)
    return drawn, keep


def _construction(ax, p, rays, view, ic, name) -> list[np.ndarray]:
    """From the kingpin's ends (ball joints, virtual or the top mount) to the IC
    (dashed), the contact patch through it; front view: on to the centreline, the roll
    centre of a symmetric axle. Returns the roll centre, if any."""
    v = list(view)
    for end in rays:
        line = np.array([end[v], ic])
        ax.plot(*line.T, "--", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_arm")
    ax.plot(*ic, "o", color=CONSTRUCTION, ms=4, gid=name.lower())
    ax.annotate(
        name, ic, xytext=(4, -9), textcoords="offset points", fontsize=7, color=CONSTRUCTION
    )
    cp = p["contact_patch_center"][v]
    text = f"{name}: {'y' if name == 'FVIC' else 'x'} = {ic[0]:.0f} mm, z = {ic[1]:.0f} mm"
    ends, keep = [0.0, 1.0], []  # along the line from CP (0) through the IC (1)
    if name == "FVIC":
        t = _roll_centre(cp, ic)
        if t is None:
            text += "\nRC (symmetric axle): further than 20 m, not drawn"
        else:
            ends.append(t)
            keep.append(rc := cp + t * (ic - cp))
            ax.plot(*rc, "D", color=CONSTRUCTION, ms=5, gid="roll_centre")
            ax.annotate(
                "RC (symmetric axle)",
                rc,
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=7,
                color=CONSTRUCTION,
            )
            text += f"\nRC (symmetric axle): z = {rc[1]:.0f} mm"
    line = np.array([cp + t * (ic - cp) for t in (min(ends), max(ends))])
    ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_contact_patch")
    _note(ax, text)
    return keep


def _roll_centre(cp: np.ndarray, ic: np.ndarray) -> float | None:
    """Where the line CP → FVIC meets the centreline y = 0, as a multiple of FVIC − CP;
    None when that is further than IC_FAR (an FVIC straight above the patch)."""
    run = ic[0] - cp[0]
    if abs(run) * IC_FAR <= abs(cp[0]) * float(np.linalg.norm(ic - cp)):
        return None
    return -cp[0] / run


def _note(ax, text: str) -> None:
    ax.text(
        0.02,
        0.98,
        text,
        transform=ax.transAxes,
        va="top",
        fontsize=8,
        gid="ic_note",
        bbox={"facecolor": "white", "edgecolor": "0.7", "alpha": 0.85},
    )


def _fit_view(front, side, corners, keep) -> None:
    """Limits: the corner (and the centreline in front view) plus a margin; construction
    lines to a far instant centre run off the edge instead of shrinking the corner."""
    ground = _mm(corners[-1])["contact_patch_center"][2]
    for ax, view in ((front, FRONT), (side, SIDE)):
        pts = [tyre_outline(c, view) for c in corners]
        pts += [np.array([q[list(view)] for q in _mm(c).values()]) for c in corners]
        if ax is front:
            near = [q for q in keep if abs(q[1] - ground) < 1000.0]  # a roll centre near the road
            pts.append(np.array([[0.0, ground], *near]))
        pts = np.vstack(pts)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.06 * float(np.max(hi - lo)) + 30.0
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)


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


def _label_points(fig, front, side, corner) -> None:
    """Each hardpoint's name next to it, where it covers the fewest other labels and
    points; points that coincide in a view share one label. After the layout: it
    measures the labels on the page."""
    renderer = fig.canvas.get_renderer()
    p = _mm(corner)
    names = list(corner.geometry.hardpoints)
    for ax, view in ((front, FRONT), (side, SIDE)):
        ax.apply_aspect()  # the box the equal aspect gives it, as drawn, not the layout's
        xy = {n: p[n][list(view)] for n in names}
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


def _legend(fig, corner, ghost: bool, construction: bool) -> None:
    """The colours: bodies, links, steering axis, tyre, construction."""
    from matplotlib.lines import Line2D

    from .viz import links, segments

    colours = dict(corner.tree.materials)
    bodies = dict.fromkeys(
        v.material for v in corner.tree.visuals if v.shape == "rod" and v.material != "tyre"
    )
    handles = [Line2D([], [], color=colours[m][:3], lw=2, label=m) for m in bodies]
    for name in segments(corner, corner.design_positions):
        if name != "steering_axis":
            colour = f"#{links(corner)[name][1]:06x}"
            handles.append(Line2D([], [], color=colour, lw=1.5, label=name.replace("_", " ")))
    handles += [
        Line2D([], [], color="goldenrod", ls=":", lw=1.5, label="steering axis"),
        Line2D([], [], color="0.15", lw=1.2, label="tyre"),
        Line2D([], [], color="0.2", marker="o", ms=3, ls="", label="hardpoint"),
    ]
    if construction:
        handles.append(
            Line2D([], [], color=CONSTRUCTION, ls="--", lw=0.9, label="instant-centre construction")
        )
    if ghost:
        handles.append(Line2D([], [], color="0.5", ls="--", lw=1.2, label="as drawn"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 8), fontsize=8)


def check_image_path(path: str | Path) -> None:
    """Raise PinSuspError unless matplotlib can write an image with this file's ending.

    Cheap, and the output path is not touched (nothing created, opened or
    checked): meant for every image output before any work starts. The
    formats are matplotlib's own list; the ending is matched case-insensitively
    (``OUT.PNG`` is a PNG). Only 'pgf' looks further: for its TeX program.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    supported = FigureCanvasBase.get_supported_filetypes()
    ext = _extension(path)
    hint = f"(use {', '.join(f for f in ('png', 'pdf', 'svg') if f in supported)}, ...)"
    if not ext:
        raise PinSuspError(f"{path}: no file ending to tell the image format {hint}")
    if ext not in supported:
        raise PinSuspError(f"{path}: unsupported image format {ext!r} {hint}")
    if ext == "pgf":  # matplotlib lists it, but writes it only with a TeX installation
        import shutil

        tex = matplotlib.rcParams["pgf.texsystem"]
        if shutil.which(tex) is None:
            raise PinSuspError(f"{path}: image format 'pgf' needs {tex}, which is not installed")


def _extension(path: str | Path) -> str:
    return Path(path).suffix.removeprefix(".").lower()


def save_figure(fig, path: str | Path) -> None:
    """Write the figure whole or not at all (format from the file's ending)."""
    try:
        check_image_path(path)
        path = Path(path)
        with atomic_write(path, binary=True) as f:
            try:
                fig.savefig(f, format=_extension(path), dpi=110)
            except OSError as exc:
                raise PinSuspError(f"{path}: cannot write ({exc.strerror or exc})") from None
            except (ValueError, OverflowError) as exc:  # e.g. a cell of 1e308: no axis scale
                raise PinSuspError(f"{path}: cannot draw these values ({exc})") from None
    finally:
        plt.close(fig)
