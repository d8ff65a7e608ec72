"""A corner or an axle in meshcat: live view, animated sweeps, a self-contained HTML replay.

The bodies come from the URDF's own visuals through Pinocchio's
MeshcatVisualizer. What the URDF cannot show as bodies — the links that are
loop closures (trackrod or toe link, pushrod), the coilover, the steering
axis down to the ground and the contact patch — are drawn between their
solved points. A sweep becomes a meshcat animation with its play controls:
each frame is recorded by pointing the visualizer at the animation frame and
displaying the pose there.

At load the camera is framed on the corner: it looks from the front, a
little outboard and above, at a point near the middle of the corner's
bounding box (its design points and tyre), chosen so that the corner's
picture is centred, from far enough for the corner to fill most of the view.
meshcat orbits about the world origin, so the scene is moved to put that
point there. The ground (the contact patch's height at design, where scrub
and trail are measured) is drawn as a translucent square, with meshcat's
grid on it.

An axle (:class:`pin_susp.axle.AxleModel`) goes through the same scene: its
URDF holds both corners and the anti-roll bar's arms (their visuals), its
closures both corners' links and the droplinks; the coilovers, steering axes
and contact patches are drawn per side, and the heave link from rocker to
rocker. The roll centre is a marker, placed from an axle's results columns
(``roll_center_y``, ``roll_center_z``, in the front-view plane midway between
the contact patches) and hidden where they are blank. It is seen from the
left side, and the ground is widened to the axle's track.

Under a load case (``pin-susp view GEOMETRY SWEEP --cases LOADS --case NAME``)
the members are coloured by their force at each frame: the links drawn
between their ends and the coilover (its compression is the spring's
``force_spring``), and the URDF's rods that are two-force members (a
wishbone's legs, a multilink's tree link). The colour is matplotlib's
``coolwarm`` at 0.5 + 0.5·tension/scale: red in tension, blue in
compression, grey at zero, the scale being the largest |force| of any
coloured member over the sweep under that case; near-black at a toggle,
where the force is unbounded. A wishbone leg that is not a two-force member
(its arm carries a pushrod or a spring: its leg columns are blank) is
yellow-green, off the ramp. An axle's are both corners' and its droplinks,
under one scale; the bar's torque (``torque_arb``, N·m) is no force on that
scale, and the bar keeps its own colour. One replay shows one case: meshcat's
animation is one clip of poses and colours, and a selector would need
either a copy of every member per case or code reaching into meshcat's
player.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading

import numpy as np
import pinocchio as pin

ROOT = "pin_susp"
LINKS = {  # name: (ends, colour, radius); other distance closures (links) as LINK
    "trackrod": (("trackrod_inboard", "trackrod_outboard"), 0x2E9E4F, 0.006),
    "toe_link": (("toe_link_inboard", "toe_link_outboard"), 0x2E9E4F, 0.006),
    "pushrod": (("pushrod_outboard", "pushrod_inboard"), 0xB0B0B0, 0.007),
    "coilover": (("strut_top", "strut_bottom"), 0xD02828, 0.012),
    "droplink": ((), 0xD9BF26, 0.006),  # an axle's, from rocker to bar: the bar's gold
    "heave_link": (("left_heave_link_rocker", "right_heave_link_rocker"), 0xD02828, 0.012),
}
LINK = (0x1F6BD9, 0.007)  # a multilink's links: the wishbones' blue
AXIS_COLOUR, PATCH_COLOUR = 0xE8C020, 0xE83070
GHOST = [0.55, 0.55, 0.6, 0.35]
GROUND_COLOUR, GROUND_OPACITY = 0xB4B4A8, 0.3
GROUND_SIZE, GROUND_THICKNESS = 1.5, 0.002  # m: a square under the corner, its top at the CP
GROUND_SPAN = 1.2  # ... or this times the width of what is drawn, if wider (an axle)
MARKERS = {"roll_centre": (0x00D8F0, 0.025)}  # name: colour, radius (m)
FORCE_MAP = "coolwarm"  # matplotlib's: blue (compression) → grey (0) → red (tension)
UNBOUNDED = (0.1, 0.1, 0.1)  # a member at a toggle: its force has no bound
# a wishbone leg that is no two-force member (its arm carries a pushrod, say): no tension
# to colour, and none of the ramp's colours (its blue would read as compression)
NOT_TWO_FORCE = (0.6, 0.8, 0.2)  # yellow-green
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
    from .metrics import PointSet

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


def design_results(model):
    """A subject's results columns at its design state: one row, no sweep."""
    from .solver import Solution
    from .sweep import Sweep

    return model.sweep_results(Sweep([]), [Solution(model.q_design, True, 0, 0.0)])


MARKED = {"roll_centre": roll_centres}  # a marker's place at each step, from the columns


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


# meshcat's own server, with its web server bound to loopback (meshcat 0.3.2's
# listens on every interface; its ZMQ socket is on 127.0.0.1 already). It asks
# Linux to end it when its parent (the pin-susp process, argv[1]) dies, even by
# SIGKILL: set here, after exec, not in a preexec_fn (unsafe in a threaded parent).
_SERVER = """
import os, signal, sys
if sys.platform.startswith("linux"):
    import ctypes
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    if os.getppid() != int(sys.argv[1]):  # the parent died before that: go now
        sys.exit(0)
import tornado.web
listen = tornado.web.Application.listen
tornado.web.Application.listen = lambda app, port, address="127.0.0.1", **kw: listen(
    app, port, address, **kw
)
sys.argv = ["meshcat-server"]
from meshcat.servers.zmqserver import main
main()
"""


@contextlib.contextmanager
def signals_held(signals=(signal.SIGINT, signal.SIGTERM, signal.SIGHUP)):
    """Inside, these signals wait; the first that came is handled once the block ends,
    as it would have been (Ctrl+C: KeyboardInterrupt). For code that must not lose one:
    an import that swallows KeyboardInterrupt (pinocchio.visualize imports trimesh,
    whose imports catch BaseException), a server being stopped. Main thread only."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came = []
    previous = {}
    for s in signals:
        if signal.getsignal(s) is not None:  # None: a handler Python did not install
            previous[s] = signal.signal(s, lambda number, _: came.append(number))
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if came:
            handler = previous[came[0]]
            if callable(handler):
                handler(came[0], None)  # raises, as it would have inside
            elif handler == signal.SIG_DFL:
                signal.raise_signal(came[0])


def _meshcat_visualizer():
    """Pinocchio's MeshcatVisualizer, imported with Ctrl+C held: its package imports
    trimesh, which swallows an interrupt that comes while it loads."""
    with signals_held():
        from pinocchio.visualize import MeshcatVisualizer
    return MeshcatVisualizer


def start_server() -> tuple[subprocess.Popen, str]:
    """A meshcat server on 127.0.0.1 that ends with this process (even on SIGKILL).

    Returns the process and its ZMQ URL.
    """
    from meshcat.servers.zmqserver import match_zmq_url

    proc = subprocess.Popen(
        [sys.executable, "-u", "-c", _SERVER, str(os.getpid())],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl+C is ours to handle: we stop it in close()
    )
    try:
        line = ""
        while "zmq_url" not in line:
            line = proc.stdout.readline().decode("utf-8", "replace")
            if not line and proc.poll() is not None:
                raise RuntimeError(f"the meshcat server exited at start (code {proc.returncode})")
        proc.stdout.readline()  # its web URL: the viewer asks for it over ZMQ
    except BaseException:  # an interrupt while it starts: it goes with us
        _stop(proc)
        raise
    return proc, match_zmq_url(line.strip())


def _stop(proc: subprocess.Popen) -> None:
    """End a server process, at once if it does not end within 10 s."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _rod_transform(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Place meshcat's unit cylinder (along its y axis) from p0 to p1."""
    d = p1 - p0
    length = float(np.linalg.norm(d))
    T = np.eye(4)
    if length < 1e-12:
        T[:3, :3] *= 0.0
        return T
    rot = pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), d / length).matrix()
    T[:3, :3] = rot @ np.diag([1.0, length, 1.0])
    T[:3, 3] = 0.5 * (p0 + p1)
    return T


class Scene:
    """A corner or an axle (and, when shimmed or adjusted, its drawn geometry as a
    ghost) in meshcat; an axle with its roll-centre marker."""

    def __init__(self, model, viewer=None):
        import meshcat
        import meshcat.geometry as mg

        self.model = model
        self.server = self.viewer = None
        self.not_two_force: list[str] = []  # legs force_colours found no two-force member
        if viewer is None:
            self.server, zmq_url = start_server()
        try:
            if viewer is None:
                viewer = meshcat.Visualizer(zmq_url=zmq_url)
            self.viewer = viewer
            self._build(model, mg)
        except BaseException:  # an interrupt while it is built: the server goes with it
            self.close()
            raise

    def _build(self, model, mg) -> None:
        self.viewer[ROOT].delete()
        self.robots = []
        drawn = as_drawn(model)
        if drawn is not None:  # the geometry as drawn, translucent, under the as-set one
            self.robots.append(self._robot(drawn, "drawn", GHOST))
        self.robots.append(self._robot(model, "corner", None))

        present = segments(model, model.design_positions)
        for name, (_, colour, radius) in links(model).items():
            if name in present:
                self.viewer[f"{ROOT}/links/{name}"].set_object(
                    mg.Cylinder(1.0, radius), mg.MeshLambertMaterial(color=colour)
                )
        for prefix, _ in sides(model):
            if f"{prefix}steering_axis" in present:  # none on a trailing arm
                self.viewer[f"{ROOT}/links/{prefix}steering_axis"].set_object(
                    mg.Cylinder(1.0, 0.003), mg.MeshLambertMaterial(color=AXIS_COLOUR)
                )
            self.viewer[f"{ROOT}/{prefix}contact_patch"].set_object(
                mg.Sphere(0.018), mg.MeshLambertMaterial(color=PATCH_COLOUR)
            )
        # the markers (an axle's roll centre): where its design results put them
        design = design_results(model) if model.markers else None
        self.design_markers = {name: MARKED[name](design)[0] for name in model.markers}
        for name in self.design_markers:
            colour, radius = MARKERS[name]
            self.viewer[f"{ROOT}/{name}"].set_object(
                mg.Sphere(radius), mg.MeshLambertMaterial(color=colour)
            )
        self._frame([m for m, _ in self.robots])
        self.show()

    def _robot(self, model, name, colour):
        MeshcatVisualizer = _meshcat_visualizer()
        visual = pin.buildGeomFromUrdfString(model.model, model.urdf, pin.GeometryType.VISUAL)
        viz = MeshcatVisualizer(model.model, visual, visual)
        viz.initViewer(viewer=self.viewer, loadModel=False)
        kwargs = {} if colour is None else {"visual_color": colour}
        viz.loadViewerModel(f"{ROOT}/{name}", **kwargs)
        viz.display(model.q_design)
        return model, viz

    def _frame(self, models) -> None:
        """Put the models' middle on the orbit target, set the camera back, lay the ground.

        meshcat 0.3.2 orbits its camera about the world origin and cannot move
        that target (OrbitControls' target is not in the scene tree and there
        is no command for it; moving /Cameras/default moves the camera, but
        three.js's lookAt still aims it at the world origin), so the scene is
        moved instead: the point the camera looks at goes to the origin. The
        camera's position is written in meshcat's rotated camera frame
        (three.js: x, z up, −y). An axle is seen from its left side.
        """
        import meshcat.geometry as mg

        points = outline(*models)
        target, eye = framing(points, sides(self.model)[0][1].sign)
        shift = np.eye(4)
        shift[:3, 3] = -target
        self.viewer[ROOT].set_transform(shift)
        self.viewer["/Cameras/default/rotated/<object>"].set_property(
            "position", [float(eye[0]), float(eye[2]), float(-eye[1])]
        )
        self.viewer["/Axes"].set_property("visible", False)

        patches = [
            self.model.design_positions[f"{prefix}contact_patch_center"][2]
            for prefix, _ in sides(self.model)
        ]
        ground = float(np.mean(patches))
        low, high = points.min(axis=0), points.max(axis=0)
        size = max(GROUND_SIZE, GROUND_SPAN * float(np.max(high[:2] - low[:2])))
        self.viewer[f"{ROOT}/ground"].set_object(
            mg.Box([size, size, GROUND_THICKNESS]),
            mg.MeshLambertMaterial(
                color=GROUND_COLOUR, opacity=GROUND_OPACITY, transparent=True, depthWrite=False
            ),
        )
        plane = np.eye(4)  # its top face at the ground, centred under the corner
        plane[:2, 3] = 0.5 * (low + high)[:2]
        plane[2, 3] = ground - 0.5 * GROUND_THICKNESS
        self.viewer[f"{ROOT}/ground"].set_transform(plane)
        grid = shift.copy()  # meshcat's grid on the same ground, in the car's x and y
        grid[2, 3] = ground - target[2] - 0.5 * GROUND_THICKNESS
        self.viewer["/Grid"].set_transform(grid)

    def show(self, q: np.ndarray | None = None, viewer=None, markers=None, colours=None) -> None:
        """Display the model at q (default: its design state), drawn on ``viewer``.

        ``markers``: {name: position (m)} of the markers (an axle's
        ``roll_centre``); a marker not given, or NaN, is hidden. By default
        at the design state, where the design results put them. ``colours``:
        {node: rgb (0 to 1)} of members coloured by their force."""
        if q is None:
            q = self.model.q_design
            markers = self.design_markers if markers is None else markers
        target = self.viewer if viewer is None else viewer
        model, viz = self.robots[-1]
        saved = viz.viewer
        viz.viewer = target
        try:
            viz.display(q)
        finally:
            viz.viewer = saved
        positions = model.positions(q)
        for name, (p0, p1) in segments(model, positions).items():
            target[f"{ROOT}/links/{name}"].set_transform(_rod_transform(p0, p1))
        for prefix, _ in sides(model):
            patch = np.eye(4)
            patch[:3, 3] = positions[f"{prefix}contact_patch_center"]
            target[f"{ROOT}/{prefix}contact_patch"].set_transform(patch)
        for name in self.design_markers:
            p = np.asarray((markers or {}).get(name, np.nan), dtype=float)
            visible = bool(np.all(np.isfinite(p)))
            if visible:
                place = np.eye(4)
                place[:3, 3] = p
                target[f"{ROOT}/{name}"].set_transform(place)
            _set_visible(target[f"{ROOT}/{name}"], visible)
        for node, rgb in (colours or {}).items():
            _set_colour(target[node], rgb)

    def animate(
        self,
        qs: list[np.ndarray],
        fps: float = 10.0,
        play: bool = True,
        markers=None,
        colours=None,
    ) -> int:
        """Record the poses as a meshcat animation; returns the number of frames.

        ``markers``: {name: positions (m, one row per pose, NaN where hidden)};
        ``colours``: {node: rgb (one row per pose)}, from ``force_colours``."""
        from meshcat.animation import Animation

        animation = Animation(default_framerate=fps)
        frames = 0
        for i, q in enumerate(qs):
            if q is None:  # a step that did not converge: no pose to show
                continue
            at = {name: rows[i] for name, rows in (markers or {}).items()}
            paint = {node: rows[i] for node, rows in (colours or {}).items()}
            with animation.at_frame(self.viewer, frames) as frame:
                self.show(q, viewer=frame, markers=at, colours=paint)
            frames += 1
        self.viewer.window.send(_LastAnimation(animation, play=play, repetitions=0))
        self.frames = frames
        return frames

    def html(self, caption: str = "") -> str:
        """The scene (and animation) as one self-contained HTML page; ``caption``: an
        HTML block laid over its top left corner (a force colouring's key)."""
        page = self.viewer.static_html()
        if caption:
            page = page.replace("</body>", caption + "</body>", 1)
        return page

    def members(self, columns) -> dict[str, str]:
        """Force column → the node drawing that member (``pin-susp loads``' names): a link
        drawn between its ends (``force_trackrod``, a multilink's links; the coilover for
        ``force_spring``), else the as-set model's rod between the member's ends (a
        wishbone's legs ``force_<arm>_front``/``_rear``, a multilink's tree link). An
        axle's columns end with their side (``force_trackrod_left``: the link
        ``left_trackrod``; ``force_droplink_right``: ``right_droplink``)."""
        model, viz = self.robots[-1]
        drawn = segments(model, model.design_positions)
        data = model.model.createData()
        placed = viz.visual_model.createData()
        pin.updateGeometryPlacements(model.model, data, viz.visual_model, placed, model.q_design)
        middles = [
            (o, placed.oMg[i].translation) for i, o in enumerate(viz.visual_model.geometryObjects)
        ]
        p = model.design_positions
        out = {}
        for column in columns:
            name = column.removeprefix("force_")
            bare, _, label = name.rpartition("_")
            prefix = model.prefix(label) if label in model.labels else ""
            if prefix:  # an axle's: force_<member>_<side> is its side's <side>_<member>
                name = prefix + bare
            link = prefix + "coilover" if name == prefix + "spring" else name
            if not column.startswith("force_") or name == "rack":
                continue
            if link in drawn:
                out[column] = f"{ROOT}/links/{link}"
                continue
            arm, _, end = name.rpartition("_")
            for a, b in (
                (f"{name}_inboard", f"{name}_outboard"),
                (f"{arm}_inboard_{end}", f"{arm}_outboard"),
            ):
                if a in p and b in p:
                    middle = 0.5 * (p[a] + p[b])
                    rod = next((o for o, m in middles if np.linalg.norm(m - middle) < 1e-9), None)
                    if rod is not None:
                        out[column] = viz.getViewerNodeName(rod, pin.GeometryType.VISUAL)
        return out

    def force_colours(self, forces, case: str) -> tuple[dict[str, np.ndarray], float]:
        """Each member's colour at each step of ``forces`` (a Results or ResultsFile of
        ``pin-susp loads``) under the load case ``case``: {node: rgb rows}, and the scale
        (N): the largest |force| of a coloured member over the sweep. Tension red,
        compression blue, grey at zero (``FORCE_MAP``); UNBOUNDED where the force is
        blank (a toggle). A member whose column is blank at every other step (a leg of
        an arm that carries more than its ball joint: no two-force member) is
        NOT_TWO_FORCE, off the ramp; ``self.not_two_force`` lists those nodes."""
        import matplotlib

        rows = np.asarray(forces["load_case"]) == case
        bounded = np.asarray(forces["loads_unbounded"], dtype=float)[rows] == 0.0
        # a spring's column (each corner's) is its compression
        sign = {f"force_spring{self.model.suffix(label)}": -1.0 for label in self.model.labels}
        tension = {
            node: sign.get(column, 1.0) * np.asarray(forces[column], dtype=float)[rows]
            for column, node in self.members(forces.columns).items()
        }
        # a leg blank wherever the forces are bounded is no two-force member (its arm
        # carries the pushrod): NOT_TWO_FORCE, off the scale
        bent = [n for n, t in tension.items() if bounded.any() and not np.isfinite(t).any()]
        self.not_two_force = bent
        tension = {n: t for n, t in tension.items() if n not in bent}
        scale = max(
            (float(np.nanmax(np.abs(t), initial=0.0)) for t in tension.values()), default=0.0
        )
        ramp = matplotlib.colormaps[FORCE_MAP]
        out = {}
        for node, t in tension.items():
            share = t / scale if scale > 0.0 else np.zeros_like(t)
            rgb = ramp(0.5 + 0.5 * np.nan_to_num(share))[:, :3]
            rgb[~np.isfinite(t)] = UNBOUNDED
            out[node] = rgb
        for node in bent:
            rgb = np.tile(NOT_TWO_FORCE, (len(bounded), 1))
            rgb[~bounded] = UNBOUNDED
            out[node] = rgb
        return out, scale

    def close(self) -> None:
        """Stop the meshcat server this scene started.

        Our ZMQ socket goes first, with no linger: a request still queued for a
        server that is gone would otherwise hold the process at exit.
        """
        proc = self.server
        if proc is None:
            return
        window = getattr(self.viewer, "window", None)
        socket = getattr(window, "zmq_socket", None)
        if socket is not None and not socket.closed:
            socket.close(linger=0)
        _stop(proc)


CornerScene = Scene  # its name from before axles


class _LastAnimation:
    """meshcat's set_animation command, kept by its server after the scene's objects.

    The server keeps each command at its path and sends a new page (and the static
    HTML) its tree in that order; an animation kept at the root, meshcat's default,
    comes before the objects, and a colour track would bind to a placeholder where
    the member's mesh is not loaded yet. Kept at a path after ROOT's, it comes last
    (the page reads no path from this command)."""

    def __init__(self, animation, play: bool, repetitions: int):
        from meshcat.commands import SetAnimation

        self.command = SetAnimation(animation, play=play, repetitions=repetitions).lower()
        self.command["path"] = f"/meshcat/{ROOT}_animation"

    def lower(self) -> dict:
        return self.command


def _set_colour(node, rgb) -> None:
    """A member's colour (rgb, 0 to 1): of the node's mesh, or of an animation frame (a
    colour track on the mesh's material)."""
    from meshcat.animation import AnimationFrameVisualizer

    rgb = [float(c) for c in rgb]
    if isinstance(node, AnimationFrameVisualizer):
        node["<object>"].set_property("material.color", "color", rgb)
    else:
        node.set_property("color", [*rgb, 1.0])


def force_key(case: str, scale: float, note: str = "", bent: bool = False) -> str:
    """The colours' key, one line of text: the case, the scale, what red and blue are;
    ``bent``: some legs are no two-force members (their colour said too)."""
    return (
        f"members coloured by force under {case!r}{f' ({note})' if note else ''}: "
        f"red tension, blue compression, grey 0, full colour at {scale:.0f} N "
        "(the largest |force| over the sweep); near-black: unbounded (a toggle)"
        + (
            "; yellow-green: a wishbone leg that is not a two-force member (its arm "
            "carries more than its ball joint: see its *_bushing_along_leg columns)"
            if bent
            else ""
        )
    )


def force_caption(case: str, scale: float, source: str = "", bent: bool = False) -> str:
    """The key as an HTML block over the replay: a colour bar from −scale to +scale
    (``bent``: and the colour of a leg that is no two-force member)."""
    import html

    import matplotlib

    ramp = matplotlib.colormaps[FORCE_MAP]
    stops = ", ".join(matplotlib.colors.to_hex(ramp(t)) for t in np.linspace(0.0, 1.0, 9))
    black = matplotlib.colors.to_hex(UNBOUNDED)
    return (
        '<div id="force_key" style="position:fixed;left:8px;top:8px;z-index:10;'
        "font:12px sans-serif;background:rgba(255,255,255,0.85);padding:6px 8px;"
        f'border-radius:4px">Load case <b>{html.escape(case)}</b>'
        f"{html.escape(f' ({source})') if source else ''}<br>"
        f'<div style="width:220px;height:10px;margin:4px 0;background:linear-gradient('
        f'to right, {stops})"></div>'
        f'<div style="display:flex;justify-content:space-between;width:220px">'
        f"<span>−{scale:.0f} N</span><span>0</span><span>+{scale:.0f} N</span></div>"
        f"compression ← → tension; "
        f'<span style="color:{black}">■</span> unbounded (toggle)'
        + (
            f'<br><span style="color:{matplotlib.colors.to_hex(NOT_TWO_FORCE)}">■</span> '
            "not a two-force member (no tension: its arm carries more than its ball joint)"
            if bent
            else ""
        )
        + "</div>"
    )


def _set_visible(node, visible: bool) -> None:
    """Show or hide a node of the scene, or of an animation frame (a boolean track)."""
    from meshcat.animation import AnimationFrameVisualizer

    if isinstance(node, AnimationFrameVisualizer):
        node.set_property("visible", "boolean", visible)
    else:
        node.set_property("visible", visible)
