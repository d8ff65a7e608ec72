"""The clearance replay (docs/clearance.md, ``pin-susp clearance --view``): the sweep in
meshcat as ``pin-susp view --html`` draws it (scene.py), with the ``clearance:`` bodies
(translucent grey, moving with the chassis) and, at each frame, that step's closest
pair drawn red: a red ball at each of its two closest points (meshcat's animation
tracks move and turn a node but do not scale it: a rod between them could not follow
their distance)."""

from __future__ import annotations

import contextlib
import io

import numpy as np

from .scene import ROOT, LastAnimation, Scene, rod_transform

CLOSEST = 0xE01010
BODY_COLOUR, BODY_OPACITY = 0x8C8C8C, 0.45
MARK = 0.008  # m: the closest points' balls


def _bodies(scene: Scene, bodies, mg) -> dict:
    """Each clearance body drawn at design on the chassis: node → its design transform."""
    material = mg.MeshLambertMaterial(color=BODY_COLOUR, opacity=BODY_OPACITY, transparent=True)
    placed = {}
    for body in bodies:
        node = f"{ROOT}/clearance/{body.name}"
        T = np.eye(4)
        if body.kind == "box":
            scene.viewer[node].set_object(mg.Box(list(body.size)), material)
            T[:3, :3], T[:3, 3] = body.rotation, body.center
        elif body.kind == "tube":
            scene.viewer[node].set_object(mg.Cylinder(1.0, body.radius), material)
            T = rod_transform(body.start, body.end)
        else:
            mesh = mg.TriangularMeshGeometry(body.vertices, body.faces)
            scene.viewer[node].set_object(mesh, material)
        scene.viewer[node].set_transform(T)
        placed[node] = T
    return placed


def clearance_replay(model, results, measured, bodies, fps: float = 10.0) -> str:
    """The replay as one self-contained HTML page."""
    import meshcat.geometry as mg
    from meshcat.animation import Animation

    from ..analyses.clearance_shapes import Poses

    qs = results.solved_configurations
    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet):  # meshcat announces its server on stdout
        scene = Scene(model)
    try:
        placed = _bodies(scene, bodies, mg)
        red = mg.MeshLambertMaterial(color=CLOSEST)
        for end in ("wheel", "body"):
            scene.viewer[f"{ROOT}/clearance/closest_{end}"].set_object(mg.Sphere(MARK), red)
        solved = [q for q in qs if q is not None]
        chassis = Poses(model, ["chassis"], solved) if solved and bodies else None
        animation = Animation(default_framerate=fps)
        frames = 0
        for k, q in enumerate(qs):
            if q is None:
                continue
            with animation.at_frame(scene.viewer, frames) as frame:
                scene.show(q, viewer=frame)
                column = measured.distance[:, k]
                if np.isfinite(column).any():
                    i = int(np.nanargmin(column))
                    a, b = measured.on_wheel[i, k] * 1e-3, measured.on_body[i, k] * 1e-3
                    for end, p in (("wheel", a), ("body", b)):
                        T = np.eye(4)
                        T[:3, 3] = p
                        frame[f"{ROOT}/clearance/closest_{end}"].set_transform(T)
                if chassis is not None:
                    G = np.eye(4)
                    G[:3, :3] = chassis.rotation[frames, 0]
                    G[:3, 3] = chassis.translation[frames, 0]
                    for node, T in placed.items():
                        frame[node].set_transform(G @ T)
            frames += 1
        scene.viewer.window.send(LastAnimation(animation, play=True, repetitions=0))
        page = scene.viewer.static_html()
    finally:
        with contextlib.suppress(KeyboardInterrupt):
            scene.close()
    return page
