"""2D drawings of a corner, an axle and a whole car, with matplotlib (Agg, no display).

``subject_figure`` draws a subject as its views say: a corner's by
``drawing_figure``, an axle's by ``axle_drawing_figure``, a vehicle's by
``vehicle_drawing_figure``.

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

``axle_drawing_figure`` draws the axle in front view at design or at a pose
(``axle_pose``: a step of its results), with each side's FVIC construction and
the roll centre where the two contact-patch lines cross.

``vehicle_drawing_figure`` draws a whole car at its design on the road: its side
view (the left corners, the CG, each axle's SVIC and the lines from its contact patch
meeting at the pitch centre) over each axle's front view.

The instant-centre construction is ``drawing_centres.py``'s, the points' names
placed by ``drawing_labels.py``. The drawings build on the model (``axle.py``, the
links drawn between points in ``view_parts.py``); the report drawn from results is
``plots.py``, below them.
"""

from __future__ import annotations

from dataclasses import replace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..errors import InputError  # noqa: E402
from ..model.geometry import unit, wheel_down  # noqa: E402
from ..plots import ResultsFile  # noqa: E402
from ..subjects.assembly import Assembly  # noqa: E402
from .drawing_centres import (  # noqa: E402
    CONSTRUCTION,
    FRONT,
    SIDE,
    in_mm,
    instant_centres,
    pitch_centre_construction,
    roll_centre_construction,
)
from .drawing_centres import PARALLEL as PARALLEL  # noqa: E402 (its old address too)
from .drawing_labels import label_points  # noqa: E402


def subject_figure(subject, labels: bool = False, at=None, caption: str = "design state"):
    """The drawing of a subject (an Assembly) in its views (``Assembly.drawing_views``):
    a corner's front and side view at its design state (``drawing_figure``); an axle's
    front view (``axle_drawing_figure``) at design or, ``at`` = (ResultsFile, step), at
    a step of its results (``axle_pose``: for a subject ``drawn_at_steps``); a whole
    car's side view over its axles' front views (``vehicle_drawing_figure``)."""
    if "side" in subject.drawing_views:
        return drawing_figure(subject, labels=labels)
    if "car side" in subject.drawing_views:
        return vehicle_drawing_figure(subject, labels=labels)
    q = None
    if at is not None:
        q, caption = axle_pose(subject, *at)
    return axle_drawing_figure(subject, q, labels=labels, caption=caption)


def drawing_figure(corner, labels: bool = False):
    """Front view (y–z) and side view (x–z) of the corner at its (as-set) design state.

    With the instant-centre construction of the as-set corner (see the module
    docstring); ``labels``: each hardpoint's name next to it and a legend.
    """
    fig, (front, side) = plt.subplots(1, 2, figsize=(14, 6.5))
    corners = [(corner, 1.0, "-")]
    from .view_parts import as_drawn

    drawn = as_drawn(corner)
    if drawn is not None:
        corners.insert(0, (drawn, 0.3, "--"))
    views = ((front, FRONT), (side, SIDE))
    for c, alpha, style in corners:
        _rods(views, c.tree.visuals, c.tree.materials, alpha, style)
        _draw_corner(views, c, alpha, style)
    ground = in_mm(corner)["contact_patch_center"][2]
    for ax, title, xl in (
        (front, "Front view", "y [mm] (+ left)"),
        (side, "Side view", "x [mm] (+ forward)"),
    ):
        ax.axhline(ground, color="0.5", lw=0.8)
        _view_axes(ax, title, xl, centreline=ax is front)
    drawn, keep = instant_centres(front, side, corner)
    _fit_view(views, [c for c, _, _ in corners], keep)
    if corner.geometry.sign < 0:
        front.invert_xaxis()  # a right corner seen from the front: outboard to the left
    note = " (dashed: as drawn)" if len(corners) > 1 else ""
    fig.suptitle(f"{corner.geometry.name}{note}")
    if labels:
        _legend(fig, corner, ghost=len(corners) > 1, construction=bool(drawn))
    fig.tight_layout(rect=(0, 0.06 if labels else 0, 1, 1))
    if labels:
        label_points(fig, views, {n: in_mm(corner)[n] for n in corner.geometry.hardpoints})
    return fig


def _view_axes(ax, title: str, xlabel: str, centreline: bool) -> None:
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("z [mm]")
    if centreline:  # the car's, in front view
        ax.axvline(0.0, color="0.5", lw=0.8, ls="-.")


def _rods(views, visuals, materials, alpha, style) -> None:
    """The bodies: the URDF's rods (world positions, m), each in its material's colour."""
    colours = dict(materials)
    for v in visuals:
        if v.shape == "rod" and v.material != "tyre":
            colour = colours[v.material][:3]
            _segment(views, v.start, v.end, style, color=colour, alpha=alpha, lw=2)


def _draw_corner(views, c, alpha, style) -> None:
    """What a corner shows between its points (``c.design_positions``): links and
    steering axis, tyre, hardpoints, and in front view the wheel's centre plane."""
    from .view_parts import links, segments

    for name, (a, b) in segments(c, c.design_positions).items():
        axis = name == "steering_axis"
        colour = "goldenrod" if axis else f"#{links(c)[name][1]:06x}"
        _segment(views, a, b, ":" if axis else style, alpha=alpha, lw=1.5, color=colour)
    p = in_mm(c)
    for ax, view in views:
        outline = tyre_outline(c, view)
        ax.plot(*outline.T, style, color="0.15", alpha=alpha, lw=1.2, gid="tyre")
        pts = np.array([p[n][list(view)] for n in c.geometry.hardpoints])
        ax.plot(*pts.T, "o", color="0.2", ms=3, alpha=alpha)
        ax.plot(*p["wheel_center"][list(view)], "+", color="0.2", ms=8, alpha=alpha)
        if view == FRONT:
            # the wheel's centre plane, top of the rim to the contact patch: camber at a glance
            down = unit(p["contact_patch_center"] - p["wheel_center"])
            top = p["wheel_center"] - down * c.geometry.wheel.radius * 1e3
            line = np.array([top, p["contact_patch_center"]])[:, list(FRONT)]
            ax.plot(*line.T, "-.", color="0.4", alpha=alpha, lw=0.6)


def _segment(views, a, b, style, **kwargs) -> None:
    """A segment between two points (m) in each (axes, view), in mm."""
    for ax, view in views:
        ends = np.array([a, b])[:, list(view)] * 1e3
        ax.plot(*ends.T, style, **kwargs)


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

    p = in_mm(c)
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


def _fit_view(views, corners, keep) -> None:
    """Limits: the corners (and the centreline in front view) plus a margin; construction
    lines to a far instant centre run off the edge instead of shrinking the corner."""
    ground = in_mm(corners[-1])["contact_patch_center"][2]
    for ax, view in views:
        pts = [tyre_outline(c, view) for c in corners]
        pts += [np.array([q[list(view)] for q in in_mm(c).values()]) for c in corners]
        if view == FRONT:
            near = [q for q in keep if abs(q[1] - ground) < 1000.0]  # a roll centre near the road
            pts.append(np.array([[0.0, ground], *near]))
        pts = np.vstack(pts)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.06 * float(np.max(hi - lo)) + 30.0
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)


def _legend(fig, corner, ghost: bool, construction: bool, tree=None, more=()) -> None:
    """The colours: bodies (of ``tree``, default the corner's), links, steering axis,
    tyre, construction; ``more``: other lines' handles."""
    from matplotlib.lines import Line2D

    from .view_parts import links, segments

    tree = corner.tree if tree is None else tree
    colours = dict(tree.materials)
    bodies = dict.fromkeys(
        v.material for v in tree.visuals if v.shape == "rod" and v.material != "tyre"
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
    handles += list(more)
    if construction:
        handles.append(
            Line2D([], [], color=CONSTRUCTION, ls="--", lw=0.9, label="instant-centre construction")
        )
    if ghost:
        handles.append(Line2D([], [], color="0.5", ls="--", lw=1.2, label="as drawn"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 8), fontsize=8)


def axle_drawing_figure(model, q=None, labels: bool = False, caption: str = "design state"):
    """Front view of an axle (both corners, the bar) at configuration ``q`` (default:
    its as-set design state), seen from the front (+y, the car's left, to the right).

    The road is the line through both contact patches. Each side: its kingpin's
    ends to its FVIC (dashed) and its contact patch through the FVIC (dash-dot);
    where the two contact-patch lines cross, the roll centre (docs/axle.md's
    ``roll_center_y``, ``roll_center_z``). An FVIC at infinity or further than 20 m
    is not drawn but noted (its contact-patch line still is, towards it); so is a
    roll centre further than that. ``labels``: the left corner's hardpoints and the
    bar's points named (the right corner is its mirror image), and a legend.
    """
    fig, front = plt.subplots(figsize=(15, 7.5))
    drawn, named = axle_front_view(front, model, q, caption)
    fig.suptitle(model.name)
    if labels:
        more = [h for h in front.get_lines() if h.get_gid() == "heave_link"][:1]
        left = _AxleSide(model, "left", model.positions(model.q_design if q is None else q))
        _legend(fig, left, ghost=False, construction=drawn, tree=model.tree, more=more)
    fig.tight_layout(rect=(0, 0.06 if labels else 0, 1, 1))
    if labels:
        label_points(fig, ((front, FRONT),), named)
    return fig


def axle_front_view(front, model, q=None, caption: str = "design state"):
    """An axle's front view (``axle_drawing_figure``'s) drawn on the axes ``front`` at
    ``q`` (default: its design state): whether its construction was drawn, and the
    points (mm) its labels name (its left corner's hardpoints, the bar's points)."""
    from ..subjects.axle import SIDES

    q = model.q_design if q is None else q
    positions = model.positions(q)
    sides = {s: _AxleSide(model, s, positions) for s in SIDES}
    views = ((front, FRONT),)
    _rods(views, _posed_visuals(model, q), model.tree.materials, 1.0, "-")
    for c in sides.values():
        _draw_corner(views, c, 1.0, "-")
    _axle_links(views, model, positions, sides)
    corner_points = {f"{s}_{n}" for s in SIDES for n in model.point_names[s]}
    extras = {n: positions[n] * 1e3 for n in model.output_points if n not in corner_points}
    if extras:  # the bar's and the heave link's points
        front.plot(*np.array([p[list(FRONT)] for p in extras.values()]).T, "o", color="0.2", ms=3)
    road = [in_mm(c)["contact_patch_center"][list(FRONT)] for c in sides.values()]
    front.axline(*road, color="0.5", lw=0.8, gid="road")
    _view_axes(front, f"Front view: {caption}", "y [mm] (+ left, seen from the front)", True)
    drawn, keep = roll_centre_construction(front, model, q, sides)
    _fit_view(views, list(sides.values()), keep)
    named = {n: in_mm(sides["left"])[n] for n in sides["left"].geometry.hardpoints}
    named |= {n.removeprefix("left_"): p for n, p in extras.items() if n[:6] != "right_"}
    return drawn, named


def _axle_links(views, model, positions, sides, heave_link: bool = True) -> None:
    """The links its corners share: the bar's droplinks (its distance closures that are
    no corner's) of the corners drawn (``sides``: label → the corner drawn), and the
    heave link between the rockers (thin: it only measures)."""
    from .view_parts import LINK

    own = {
        f"{model.prefix(label)}{c.name}"
        for label, g in model.corners.items()
        for c in g.mechanism.tree(g).closures
    }
    drawn = tuple(model.prefix(label) for label in sides)
    bar = model.tree.materials.get("bar", (0.85, 0.75, 0.15, 1.0))[:3]
    for c in model.tree.closures:
        if c.kind == "distance" and c.name not in own and c.name.startswith(drawn):
            a, b = (positions[n] for n in c.points)
            _segment(views, a, b, "-", color=bar, lw=1.5, gid="droplink")
    ends = [f"{s}_heave_link_rocker" for s in sides]
    if heave_link and all(n in positions for n in ends):
        colour = f"#{LINK[0]:06x}"
        a, b = (positions[n] for n in ends)
        _segment(views, a, b, "--", color=colour, lw=1.0, gid="heave_link", label="heave link")


def vehicle_drawing_figure(car, labels: bool = False):
    """A whole car at its design state on the road: its side view over each axle's
    front view.

    The side view (x–z, + forward to the right) draws the corners of its left side,
    their wheels and the CG, each axle's SVIC and the line from its contact patch
    through it; where the two meet, the pitch centre (``pitch_centre_construction``:
    the car's ``pitch_center_x``, ``_z`` at design). Each axle's front view is its
    axle drawing (``axle_front_view``) of that axle on its own posed at the car's
    design step (``Vehicle.axles_at_design``): its roll centre is the car's. ``labels``:
    the side view's hardpoints (prefixed by their corner) and each front view's left
    corner named, and a legend."""
    results = car.design_results()
    positions = car.positions(car.q_rest)
    fig = plt.figure(figsize=(16, 12))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.0, 1.1))
    side = fig.add_subplot(grid[0, :])
    left = {label: _AxleSide(car, label, positions) for label in car.labels}
    left = {label: c for label, c in left.items() if c.geometry.sign > 0}
    named = {}
    for label, c in left.items():
        named |= {f"{label}_{n}": in_mm(c)[n] for n in c.geometry.hardpoints}
    keep = _car_side(side, car, positions, left, results)
    panels = [((side, SIDE), named)]
    drawn = False
    for i, (end, (axle, q)) in enumerate(car.axles_at_design().items()):
        front = fig.add_subplot(grid[1, i])
        construction, own = axle_front_view(front, axle, q, f"the {end} axle at design")
        drawn |= construction
        panels.append(((front, FRONT), own))
    side_view = (side, SIDE)
    _fit_car(side_view, list(left.values()), keep, car)
    fig.suptitle(f"{car.name}: side view (the left corners) and each axle's front view")
    if labels:
        first, more = _corners_legend(left.values())
        _legend(fig, first, ghost=False, construction=True, tree=car.tree, more=more)
    fig.tight_layout(rect=(0, 0.04 if labels else 0, 1, 1))
    if labels:
        for view, points in panels:
            label_points(fig, (view,), points)
    return fig


def _corners_legend(corners) -> tuple:
    """The legend's corner (the first) and the handles of the links the others have and
    it has not (a rear's toe link): ``_legend``'s corner and ``more``."""
    from matplotlib.lines import Line2D

    from .view_parts import links, segments

    first, *others = corners
    seen = set(segments(first, first.design_positions))
    more = []
    for c in others:
        for name in segments(c, c.design_positions):
            if name not in seen and name != "steering_axis":
                seen.add(name)
                colour = f"#{links(c)[name][1]:06x}"
                more.append(Line2D([], [], color=colour, lw=1.5, label=name.replace("_", " ")))
    return first, more


def _car_side(ax, car, positions, corners, results) -> list[np.ndarray]:
    """The car's side view: the corners drawn (label → _AxleSide), their bars'
    droplinks, the road, the CG and the pitch-centre construction; the points (mm)
    the view should keep."""
    views = ((ax, SIDE),)
    prefixes = tuple(car.prefix(label) for label in corners)
    visuals = [v for v in _posed_visuals(car, car.q_rest) if v.body.startswith(prefixes)]
    _rods(views, visuals, car.tree.materials, 1.0, "-")
    for c in corners.values():
        _draw_corner(views, c, 1.0, "-")
    _axle_links(views, car, positions, corners, heave_link=False)
    ground = float(np.mean([in_mm(c)["contact_patch_center"][2] for c in corners.values()]))
    ax.axhline(ground, color="0.5", lw=0.8, gid="road")
    cg = car.body.cg * 1e3
    ax.plot(cg[0], cg[2], "o", mfc="white", mec="0.1", ms=9, mew=1.5, gid="cg")
    ax.plot(cg[0], cg[2], "+", color="0.1", ms=9, mew=1.5)
    ax.annotate("CG", cg[[0, 2]], xytext=(7, 5), textcoords="offset points", fontsize=8)
    _view_axes(ax, "Side view: design state", "x [mm] (+ forward)", centreline=False)
    return [cg[[0, 2]], *pitch_centre_construction(ax, results, car.axle_labels)]


def _fit_car(view, corners, keep, car) -> None:
    """The side view's limits: the corners' tyres and points and the CG, with the pitch
    centre where it is within a wheelbase of them; a line to a far SVIC runs off the
    edge."""
    ax, v = view
    pts = np.vstack(
        [tyre_outline(c, v) for c in corners]
        + [np.array([p[list(v)] for p in in_mm(c).values()]) for c in corners]
    )
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    reach = float(hi[0] - lo[0])
    near = [q for q in keep if np.all(q > lo - reach) and np.all(q < hi + reach)]
    pts = np.vstack([pts, *near]) if near else pts
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.04 * float(np.max(hi - lo)) + 30.0
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)


class _AxleSide(Assembly):
    """One labelled corner of an axle or a vehicle at a pose, read as the drawing reads a
    corner (an Assembly of one corner, labelled ""): its geometry (as set), its own tree
    (the links drawn between its points) and, as ``design_positions``, the pose's points
    (m) by the corner's names."""

    labels = ("",)

    def __init__(self, model, side: str, positions: dict[str, np.ndarray]):
        g = model.corners[side]
        self.geometry, self.tree = g, g.mechanism.tree(g)
        self.corners = {"": g}
        prefix = model.prefix(side)
        self.design_positions = {n: positions[prefix + n] for n in model.corner_points[side]}


def _posed_visuals(model, q) -> list:
    """The axle's visuals (placed at design, m) carried by their bodies to ``q``."""
    import pinocchio as pin

    design, posed = model.model.createData(), model.model.createData()
    pin.framesForwardKinematics(model.model, design, model.q_design)
    pin.framesForwardKinematics(model.model, posed, q)
    out = []
    for v in model.tree.visuals:
        frame = model.model.getFrameId(v.body)
        move = posed.oMf[frame] * design.oMf[frame].inverse()
        end = None if v.end is None else move.act(v.end)
        out.append(replace(v, start=move.act(v.start), end=end))
    return out


def axle_pose(model, results: ResultsFile, step: int) -> tuple[np.ndarray, str]:
    """The axle's configuration at a step of its results, and a caption: solved to that
    row's wheel-centre heights and rack, then checked against the row's points (they
    must be this axle's: results of another geometry are refused)."""
    from ..subjects.axle import SIDES

    if not results.axle:
        raise InputError(
            results.source, "", f"{results.kind} results: an axle is drawn at a step of its own"
        )
    rows = np.flatnonzero(results["step_index"] == step)
    if rows.size == 0:
        last = int(np.nanmax(results["step_index"]))
        raise InputError(results.source, f"step {step}", f"no such step (steps 0 to {last})")
    i = int(rows[0])
    if results.columns.get("solver_converged", np.ones(i + 1))[i] != 1.0:
        raise InputError(results.source, f"step {step}", "did not converge: it has no pose to draw")
    needed = [f"{s}_wheel_center_z" for s in SIDES]
    if model.model.existJointName("rack_slide"):
        needed.append("rack_displacement")
    for name in needed:
        if name not in results.columns or not np.isfinite(results[name][i]):
            raise InputError(results.source, name, f"no value at step {step}: the pose is unknown")
    z = {s: results[f"{s}_wheel_center_z"][i] * 1e-3 for s in SIDES}
    rack = results["rack_displacement"][i] * 1e-3 if "rack_displacement" in needed else 0.0
    solution = model.solve(z, rack)
    if not solution.converged:
        raise InputError(
            results.source, f"step {step}", f"this axle does not reach that pose ({solution.why})"
        )
    solved = model.positions(solution.q)
    names = [(n, k) for n in model.output_points for k in range(3)]
    names = [(n, k) for n, k in names if f"{n}_{'xyz'[k]}" in results.columns]
    offs = [abs(solved[n][k] * 1e3 - results[f"{n}_{'xyz'[k]}"][i]) for n, k in names]
    j = int(np.argmax(np.nan_to_num(offs, nan=np.inf)))
    off, worst = offs[j], f"{names[j][0]}_{'xyz'[names[j][1]]}"
    if not off <= 1e-3:  # mm; NaN too
        raise InputError(
            results.source,
            worst,
            f"{off:.3g} mm from this axle's point at step {step}: results of another geometry?",
        )
    shown = [("heave", "heave", "mm", 1), ("roll", "roll", "°", 2)]
    shown += [("rack", "rack_displacement", "mm", 1)] * ("rack_displacement" in results.columns)
    values = ", ".join(
        f"{word} {np.round(results[name][i], digits) + 0.0:.{digits}f} {unit}"
        for word, name, unit, digits in shown
    )
    return solution.q, f"step {step} of {results.label} ({values})"
