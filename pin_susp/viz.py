"""The corner in meshcat: live view, animated sweeps, a self-contained HTML replay.

The bodies come from the URDF's own visuals through Pinocchio's
MeshcatVisualizer. What the URDF cannot show as bodies — the links that are
loop closures (trackrod or toe link, pushrod), the coilover, the steering
axis down to the ground and the contact patch — are drawn between their
solved points. A sweep becomes a meshcat animation with its play controls:
each frame is recorded by pointing the visualizer at the animation frame and
displaying the pose there.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import numpy as np
import pinocchio as pin

ROOT = "pin_susp"
LINKS = {  # name: (ends, colour, radius)
    "trackrod": (("trackrod_inboard", "trackrod_outboard"), 0x2E9E4F, 0.006),
    "toe_link": (("toe_link_inboard", "toe_link_outboard"), 0x2E9E4F, 0.006),
    "pushrod": (("pushrod_outboard", "pushrod_inboard"), 0xB0B0B0, 0.007),
    "coilover": (("strut_top", "strut_bottom"), 0xD02828, 0.012),
}
AXIS_COLOUR, PATCH_COLOUR = 0xE8C020, 0xE83070
GHOST = [0.55, 0.55, 0.6, 0.35]


def segments(corner, positions: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Lines that are not bodies of the tree: closure links, coilover, steering axis (m).

    The steering axis runs from the upper ball joint down to the ground
    (the contact patch's height), where scrub and trail are measured.
    """
    out = {}
    for name, ((a, b), _, _) in LINKS.items():
        if a in positions and b in positions:
            out[name] = (positions[a], positions[b])
    lbj, ubj = positions["lower_wishbone_outboard"], positions["upper_wishbone_outboard"]
    k = ubj - lbj
    ground = positions["contact_patch_center"][2]
    if abs(k[2]) > 1e-9:
        out["steering_axis"] = (ubj, lbj + (ground - lbj[2]) / k[2] * k)
    return out


# meshcat's own server, with its web server bound to loopback (meshcat 0.3.2's
# listens on every interface; its ZMQ socket is on 127.0.0.1 already).
_SERVER = """
import sys
import tornado.web
listen = tornado.web.Application.listen
tornado.web.Application.listen = lambda app, port, address="127.0.0.1", **kw: listen(
    app, port, address, **kw
)
sys.argv = ["meshcat-server"]
from meshcat.servers.zmqserver import main
main()
"""


def start_server() -> tuple[subprocess.Popen, str]:
    """A meshcat server on 127.0.0.1 that ends with this process (even on SIGKILL).

    Returns the process and its ZMQ URL.
    """
    from meshcat.servers.zmqserver import match_zmq_url

    proc = subprocess.Popen(
        [sys.executable, "-u", "-c", _SERVER],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl+C is ours to handle: we stop it in close()
        preexec_fn=_die_with_parent,
    )
    line = ""
    while "zmq_url" not in line:
        line = proc.stdout.readline().decode("utf-8", "replace")
        if not line and proc.poll() is not None:
            raise RuntimeError(f"the meshcat server exited at start (code {proc.returncode})")
    proc.stdout.readline()  # its web URL: the viewer asks for it over ZMQ
    return proc, match_zmq_url(line.strip())


def _die_with_parent() -> None:
    """In the child: SIGTERM when the parent dies (Linux prctl PR_SET_PDEATHSIG)."""
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)
        if os.getppid() == 1:  # the parent died before prctl: go now
            os._exit(0)


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


class CornerScene:
    """One corner (and, for a shimmed corner, its drawn geometry as a ghost) in meshcat."""

    def __init__(self, corner, viewer=None):
        import meshcat
        import meshcat.geometry as mg

        self.corner = corner
        self.server = None
        if viewer is None:
            self.server, zmq_url = start_server()
            viewer = meshcat.Visualizer(zmq_url=zmq_url)
        self.viewer = viewer
        self.viewer[ROOT].delete()
        self.robots = []
        drawn = corner.geometry.drawn
        if drawn is not None:  # the geometry as drawn, translucent, under the as-set one
            from .corner import Corner

            self.robots.append(self._robot(Corner(drawn, apply_setup=False), "drawn", GHOST))
        self.robots.append(self._robot(corner, "corner", None))

        present = segments(corner, corner.design_positions)
        for name, (_, colour, radius) in LINKS.items():
            if name in present:
                self.viewer[f"{ROOT}/links/{name}"].set_object(
                    mg.Cylinder(1.0, radius), mg.MeshLambertMaterial(color=colour)
                )
        self.viewer[f"{ROOT}/links/steering_axis"].set_object(
            mg.Cylinder(1.0, 0.003), mg.MeshLambertMaterial(color=AXIS_COLOUR)
        )
        self.viewer[f"{ROOT}/contact_patch"].set_object(
            mg.Sphere(0.018), mg.MeshLambertMaterial(color=PATCH_COLOUR)
        )
        self._camera()
        self.show()

    def _robot(self, corner, name, colour):
        from pinocchio.visualize import MeshcatVisualizer

        visual = pin.buildGeomFromUrdfString(corner.model, corner.urdf, pin.GeometryType.VISUAL)
        viz = MeshcatVisualizer(corner.model, visual, visual)
        viz.initViewer(viewer=self.viewer, loadModel=False)
        kwargs = {} if colour is None else {"visual_color": colour}
        viz.loadViewerModel(f"{ROOT}/{name}", **kwargs)
        viz.display(corner.q_design)
        return corner, viz

    def _camera(self) -> None:
        """Look at the corner from the front, a little outboard and above.

        The camera offset is written in meshcat's rotated camera frame
        (three.js: x, z up, −y), looking at the origin.
        """
        s = self.corner.geometry.sign
        self.viewer["/Cameras/default/rotated/<object>"].set_property(
            "position", [1.6, 0.7, -s * 0.35]
        )
        self.viewer["/Axes"].set_property("visible", False)

    def show(self, q: np.ndarray | None = None, viewer=None) -> None:
        """Display the corner at q (default: its design state), drawn on ``viewer``."""
        q = self.corner.q_design if q is None else q
        target = self.viewer if viewer is None else viewer
        corner, viz = self.robots[-1]
        saved = viz.viewer
        viz.viewer = target
        try:
            viz.display(q)
        finally:
            viz.viewer = saved
        positions = corner.positions(q)
        for name, (p0, p1) in segments(corner, positions).items():
            target[f"{ROOT}/links/{name}"].set_transform(_rod_transform(p0, p1))
        patch = np.eye(4)
        patch[:3, 3] = positions["contact_patch_center"]
        target[f"{ROOT}/contact_patch"].set_transform(patch)

    def animate(self, qs: list[np.ndarray], fps: float = 10.0, play: bool = True) -> int:
        """Record the poses as a meshcat animation; returns the number of frames."""
        from meshcat.animation import Animation

        animation = Animation(default_framerate=fps)
        frames = 0
        for q in qs:
            if q is None:  # a step that did not converge: no pose to show
                continue
            with animation.at_frame(self.viewer, frames) as frame:
                self.show(q, viewer=frame)
            frames += 1
        self.viewer.set_animation(animation, play=play, repetitions=0)
        self.frames = frames
        return frames

    def html(self) -> str:
        """The scene (and animation) as one self-contained HTML page."""
        return self.viewer.static_html()

    def close(self) -> None:
        """Stop the meshcat server this scene started."""
        proc = self.server
        if proc is not None and proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
