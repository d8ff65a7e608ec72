"""What a view of a corner or an axle draws beyond its tree's bodies, and where it
lies: the links between solved points (the loop closures — trackrod or toe link,
pushrod, an axle's droplinks — the coilover, an axle's heave link), the steering
axis down to the ground, the outline at design (points and tyres) and the camera's
framing of it, an axle's roll centre from its results, the ghost as drawn. The 3D
view (``viz.py``) and the 2D drawings (``drawing.py``) draw them; each takes an
Assembly (assembly.py) and reads its corners by their labels' prefixes.
"""

from __future__ import annotations

import numpy as np

ROOT = "pin_susp"  # the 3D scene's root node: its links are at ROOT/links/<name>
LINKS = {  # name: (ends, colour, radius); other distance closures (links) as LINK
    "trackrod": (("trackrod_inboard", "trackrod_outboard"), 0x2E9E4F, 0.006),
    "toe_link": (("toe_link_inboard", "toe_link_outboard"), 0x2E9E4F, 0.006),
    "pushrod": (("pushrod_outboard", "pushrod_inboard"), 0xB0B0B0, 0.007),
    "coilover": (("strut_top", "strut_bottom"), 0xD02828, 0.012),
    "droplink": ((), 0xD9BF26, 0.006),  # an axle's, from rocker to bar: the bar's gold
    "heave_link": (("left_heave_link_rocker", "right_heave_link_rocker"), 0xD02828, 0.012),
}
LINK = (0x1F6BD9, 0.007)  # a multilink's links: the wishbones' blue
VIEW = np.array([1.6, 0.35, 0.7])  # camera direction: front, outboard (y by side), above
FOV = 75.0  # degrees, vertical: meshcat's default camera (three.js PerspectiveCamera)
FILL = 0.8  # the corner's share of the view's height, or of its width ...
ASPECT = 4 / 3  # ... in a view at least this wide for its height


def sides(model) -> list[tuple[str, object]]:
    """(prefix of its points' names, Geometry) of each of an Assembly's corners: a
    corner's own (prefix ``""``), an axle's two (``"left_"``, ``"right_"``)."""
    return [(model.prefix(label), g) for label, g in model.corners.items()]


def _bare(model, name: str) -> str:
    """A name without its side's prefix (an axle's ``left_trackrod``: ``trackrod``)."""
    for prefix, _ in sides(model):
        if prefix and name.startswith(prefix):
            return name[len(prefix) :]
    return name


def segments(model, positions: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Lines that are not bodies of the tree: closure links, coilover, steering axis (m).

    The steering axis runs from the upper ball joint down to the ground
    (the contact patch's height), where scrub and trail are measured. An
    axle's are per side, named with the side's prefix (``left_steering_axis``).
    """
    out = {}
    for name, ((a, b), _, _) in links(model).items():
        if a in positions and b in positions:
            out[name] = (positions[a], positions[b])
    from ..columns.metrics import PointSet

    for prefix, g in sides(model):
        own = {k[len(prefix) :]: v[None] for k, v in positions.items() if k.startswith(prefix)}
        ps = PointSet(own, {}, g)
        with np.errstate(invalid="ignore", divide="ignore"):
            ends = ps.kingpin()
        if ends is not None:
            lower, upper = ends[0][0], ends[1][0]
            k = upper - lower
            ground = own["contact_patch_center"][0, 2]
            if abs(k[2]) > 1e-9 and np.all(np.isfinite(k)):
                out[f"{prefix}steering_axis"] = (upper, lower + (ground - lower[2]) / k[2] * k)
    return out


def links(model) -> dict[str, tuple[tuple[str, str], int, float]]:
    """The links drawn between their ends: the distance closures (an axle's droplinks
    too), a coilover per corner, an axle's heave link."""
    out = {}
    for c in model.tree.closures:
        if c.kind == "distance":
            out[c.name] = (c.points, *LINKS.get(_bare(model, c.name), (None, *LINK))[1:])
    for prefix, g in sides(model):
        if "strut_top" in g.hardpoints:
            (a, b), colour, radius = LINKS["coilover"]
            out[f"{prefix}coilover"] = ((prefix + a, prefix + b), colour, radius)
    if all(end in model.design_positions for end in LINKS["heave_link"][0]):
        out["heave_link"] = LINKS["heave_link"]
    return out


def outline(*models) -> np.ndarray:
    """Points (m, N×3) around what is drawn of the corners (or axles) at design.

    Their design points, the rack's end on the car's centre plane, and the
    tyre's two rims: circles of the wheel's radius at its inboard and
    outboard faces.
    """
    points = []
    angles = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
    for model in models:
        p = model.design_positions
        points += list(p.values())
        for prefix, g in sides(model):
            points += _tyre(g, prefix, p, angles)
    return np.array(points)


def _tyre(g, prefix: str, p: dict, angles: np.ndarray) -> list[np.ndarray]:
    """A corner's rack end on the centre plane, and its tyre's two rims (m)."""
    points = []
    if g.steering == "rack":  # the rack is drawn to the centre plane (y = 0)
        points.append(p[prefix + g.steering_points[0]] * np.array([1.0, 0.0, 1.0]))
    a, b = p[prefix + "wheel_inboard"], p[prefix + "wheel_outboard"]
    axis = (b - a) / np.linalg.norm(b - a)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    rim = g.wheel.radius * (np.outer(np.cos(angles), e1) + np.outer(np.sin(angles), e2))
    return [*points, *(a + rim), *(b + rim)]


def bounds(*models) -> tuple[np.ndarray, np.ndarray]:
    """The box (lowest, highest corner, m) around what is drawn of the corners at design."""
    points = outline(*models)
    return points.min(axis=0), points.max(axis=0)


def roll_centres(results) -> np.ndarray:
    """An axle's roll centre at each step (m, N×3; NaN where blank), from its results
    columns: y and z from ``roll_center_y``/``_z``, x midway between the contact
    patches (the front view the roll centre is found in)."""
    x = 0.5 * (results["left_contact_patch_center_x"] + results["right_contact_patch_center_x"])
    return 1e-3 * np.column_stack([x, results["roll_center_y"], results["roll_center_z"]])


def as_drawn(model):
    """The model as drawn, without its shims and adjusters (a ghost under the as-set
    one); None when it is set as drawn."""
    from dataclasses import replace

    def drawn(g):  # its setup at the design values: the model sets up nothing more
        g = g.drawn or g
        shim = g.camber_shim
        if shim is not None:
            shim = replace(shim, setup_thickness=shim.design_thickness)
        return replace(g, camber_shim=shim, trackrod_length_delta=0.0, pushrod_length_delta=0.0)

    if all(g.drawn is None for g in model.corners.values()):
        return None
    return model.with_corners({label: drawn(g) for label, g in model.corners.items()})


def framing(points: np.ndarray, sign: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Where the camera looks and where it sits from there (m, world frame) to frame the points.

    It looks along ``VIEW`` (outboard on the side ``sign``), z up, at a point
    near the points' bounding-box centre, moved across the view until the
    points' picture is centred; it is set back until every point is within
    ``FILL`` of the view's half-height, and across within that of a view of
    aspect ``ASPECT``.
    """
    u = VIEW * np.array([1.0, sign, 1.0])
    u = u / np.linalg.norm(u)
    right = np.cross(-u, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -u)
    points = np.asarray(points, dtype=float)
    reach = FILL * np.tan(np.radians(FOV / 2)) * np.array([ASPECT, 1.0])
    target = 0.5 * (points.min(axis=0) + points.max(axis=0))
    for _ in range(30):
        c = points - target
        # c is in view when |c·right|, |c·up| <= reach·(distance - c·u)
        across = np.abs(np.stack([c @ right, c @ up], axis=1)) / reach
        distance = float(np.max(c @ u + across.max(axis=1)))
        seen = np.stack([c @ right, c @ up], axis=1) / (distance - c @ u)[:, None]
        middle = 0.5 * (seen.min(axis=0) + seen.max(axis=0))
        if np.abs(middle).max() < 1e-5:
            break
        target = target + distance * (middle[0] * right + middle[1] * up)
    return target, distance * u
