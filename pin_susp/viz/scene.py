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

An axle (:class:`pin_susp.subjects.axle.AxleModel`) goes through the same scene: its
URDF holds both corners and the anti-roll bar's arms (their visuals), its
closures both corners' links and the droplinks; the coilovers, steering axes
and contact patches are drawn per side, and the heave link from rocker to
rocker. The roll centre is a marker, placed from an axle's results columns
(``roll_center_y``, ``roll_center_z``, in the front-view plane midway between
the contact patches) and hidden where they are blank. It is seen from the
left side, and the ground is widened to the axle's track.

A vehicle (docs/vehicle.md) is drawn on the road, the world of its model: each pose
its full configuration, the body pitched and rolled as solved, its design (no sweep)
with every wheel on the road (the subject's ``q_rest``). Its markers are each axle's
roll centre, the pitch centre and the CG, from its results' columns put in the road's
frame by the body's pose (the subject's ``marker_places``).

Under a load case the members are coloured by their force (``force_colours.py``).
What is drawn between the solved points, and the framing, is ``view_parts.py``'s
(the 2D drawings draw them too); meshcat's server is ``meshcat_server.py``'s.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .force_colours import FORCE_MAP as FORCE_MAP  # the force colouring, by its old
from .force_colours import NOT_TWO_FORCE as NOT_TWO_FORCE  # address too
from .force_colours import UNBOUNDED as UNBOUNDED
from .force_colours import force_caption as force_caption
from .force_colours import force_colours, members, set_colour
from .force_colours import force_key as force_key
from .server import meshcat_visualizer, start_server, stop_server
from .server import signals_held as signals_held
from .view_parts import LINK as LINK  # what is drawn between points, by its old address
from .view_parts import LINKS as LINKS
from .view_parts import ROOT as ROOT
from .view_parts import as_drawn, framing, links, outline, segments, sides
from .view_parts import bounds as bounds
from .view_parts import roll_centres as roll_centres  # an axle's, by its old address

AXIS_COLOUR, PATCH_COLOUR = 0xE8C020, 0xE83070
GHOST = [0.55, 0.55, 0.6, 0.35]
GROUND_COLOUR, GROUND_OPACITY = 0xB4B4A8, 0.3
GROUND_SIZE, GROUND_THICKNESS = 1.5, 0.002  # m: a square under the corner, its top at the CP
GROUND_SPAN = 1.2  # ... or this times the width of what is drawn, if wider (an axle)
MARKERS = {  # name: colour, radius (m)
    "roll_centre": (0x00D8F0, 0.025),  # an axle's
    "roll_centre_front": (0x00D8F0, 0.025),  # a vehicle's axles'
    "roll_centre_rear": (0x00D8F0, 0.025),
    "pitch_centre": (0xA040F0, 0.03),
    "cg": (0x202020, 0.03),
}


def design_results(model):
    """A subject's results columns at its design state, one row (its own
    ``design_results``: a corner's and an axle's at q_design, a vehicle's on the road)."""
    return model.design_results()


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
        # the markers (an axle's roll centre; a vehicle's roll and pitch centres, its
        # CG): where its design results put them
        places = model.marker_places(model.design_results()) if model.markers else {}
        self.design_markers = {name: places[name][0] for name in model.markers}
        for name in self.design_markers:
            colour, radius = MARKERS[name]
            self.viewer[f"{ROOT}/{name}"].set_object(
                mg.Sphere(radius), mg.MeshLambertMaterial(color=colour)
            )
        self._frame([m for m, _ in self.robots])
        self.show()

    def _robot(self, model, name, colour):
        MeshcatVisualizer = meshcat_visualizer()
        visual = pin.buildGeomFromUrdfString(model.model, model.urdf, pin.GeometryType.VISUAL)
        viz = MeshcatVisualizer(model.model, visual, visual)
        viz.initViewer(viewer=self.viewer, loadModel=False)
        kwargs = {} if colour is None else {"visual_color": colour}
        viz.loadViewerModel(f"{ROOT}/{name}", **kwargs)
        viz.display(model.q_rest)
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

        rest = self.model.positions(self.model.q_rest)  # a vehicle's: on the road
        patches = [rest[f"{prefix}contact_patch_center"][2] for prefix, _ in sides(self.model)]
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

    def show(
        self, q: np.ndarray | None = None, viewer=None, markers=None, colours=None, places=None
    ) -> None:
        """Display the model at q (default: its design state), drawn on ``viewer``.

        ``markers``: {name: position (m)} of the markers (an axle's
        ``roll_centre``); a marker not given, or NaN, is hidden. By default
        at the design state, where the design results put them. ``colours``:
        {node: rgb (0 to 1)} of members coloured by their force; ``places``: {node:
        position (m)} of nodes moved to a point (the K&C replay's bushings)."""
        if q is None:
            q = self.model.q_rest
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
            set_colour(target[node], rgb)
        for node, p in (places or {}).items():
            place = np.eye(4)
            place[:3, 3] = p
            target[node].set_transform(place)

    def animate(
        self,
        qs: list[np.ndarray],
        fps: float = 10.0,
        play: bool = True,
        markers=None,
        colours=None,
        places=None,
    ) -> int:
        """Record the poses as a meshcat animation; returns the number of frames.

        ``markers``: {name: positions (m, one row per pose, NaN where hidden)};
        ``colours``: {node: rgb (one row per pose)}, from ``force_colours``;
        ``places``: {node: positions (m, one row per pose)}."""
        from meshcat.animation import Animation

        animation = Animation(default_framerate=fps)
        frames = 0
        for i, q in enumerate(qs):
            if q is None:  # a step that did not converge: no pose to show
                continue
            at = {name: rows[i] for name, rows in (markers or {}).items()}
            paint = {node: rows[i] for node, rows in (colours or {}).items()}
            moved = {node: rows[i] for node, rows in (places or {}).items()}
            with animation.at_frame(self.viewer, frames) as frame:
                self.show(q, viewer=frame, markers=at, colours=paint, places=moved)
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
        """Force column → the node drawing that member (force_colours.members)."""
        model, viz = self.robots[-1]
        return members(model, viz, columns)

    def force_colours(self, forces, case: str) -> tuple[dict[str, np.ndarray], float]:
        """Each member's colour at each step of ``forces`` under the load case ``case``,
        and the scale (force_colours.force_colours); ``self.not_two_force``: the legs
        that are no two-force member, coloured NOT_TWO_FORCE."""
        model, viz = self.robots[-1]
        out, scale, self.not_two_force = force_colours(model, viz, forces, case)
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
        stop_server(proc)


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


def _set_visible(node, visible: bool) -> None:
    """Show or hide a node of the scene, or of an animation frame (a boolean track)."""
    from meshcat.animation import AnimationFrameVisualizer

    if isinstance(node, AnimationFrameVisualizer):
        node.set_property("visible", "boolean", visible)
    else:
        node.set_property("visible", visible)


def rod_transform(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Place meshcat's unit cylinder (along its y axis) from p0 to p1 (m): what the
    scene's links are drawn with, and the clearance replay's closest pair."""
    return _rod_transform(p0, p1)


LastAnimation = _LastAnimation  # the animation command kept after the objects, by its name
