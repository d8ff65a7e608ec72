"""The tyre's swept volume over a sweep (docs/clearance.md, ``pin-susp envelope``): one
closed triangle mesh, in mm, that contains the tyre at every solved step — for CAD, to
keep bodywork and chassis tubes out of it.

At each step the tyre is its outer cylinder (unloaded radius, section width) as a
prism: a polygon of SIDES sides circumscribed about each face's circle, so that it
contains the round tyre (by at most r·(1/cos(π/SIDES) − 1): 0.3 mm on a 313 mm
tyre). The convex hull of GROUP consecutive steps' prisms covers the tyre between
those steps too; the hulls are joined by a boolean union (manifold3d) where it is
installed — tighter than one hull round everything, which is what is written
without it (``method`` says which). Each corner's tyre is one closed part of the
mesh. An STL holds float32 coordinates and no vertex indices: the mesh is snapped to
float32 and any edge shorter than that collapses (its two faces dropped), so that
the file read back is as closed as the mesh.
"""

from __future__ import annotations

import numpy as np

from .clearance_shapes import Poses, wheel_rings

SIDES = 72
GROUP = 4  # steps in each hull; consecutive hulls share a step


def tyre_points(centre: np.ndarray, axis: np.ndarray, radius: float, half_width: float):
    """The tyre's prism at poses: (n, 2·SIDES, 3) vertices (m) about ``centre`` along
    ``axis`` (n, 3)."""
    from .clearance import frames_along

    R = frames_along(axis)
    angles = 2.0 * np.pi * np.arange(SIDES) / SIDES
    r = radius / np.cos(np.pi / SIDES)  # circumscribed: its sides touch the circle
    ring = np.column_stack([r * np.cos(angles), r * np.sin(angles), np.zeros(SIDES)])
    local = np.vstack([ring + [0, 0, -half_width], ring + [0, 0, half_width]])
    return np.einsum("kij,mj->kmi", R, local) + centre[:, None]


def union_available() -> bool:
    try:
        import manifold3d  # noqa: F401
    except ImportError:
        return False
    return True


def snapped(vertices: np.ndarray, faces: np.ndarray):
    """The mesh with its vertices at float32 (an STL's), those that meet there merged
    and the faces that lose an edge dropped (trimesh.Trimesh)."""
    import trimesh

    unique, inverse = np.unique(vertices.astype(np.float32), axis=0, return_inverse=True)
    f = inverse.reshape(-1)[faces]
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    return trimesh.Trimesh(unique.astype(float), f[keep], process=False)


def envelope(model, qs: list, hull_only: bool = False):
    """(the swept volume as a trimesh.Trimesh in mm, the method: ``union`` or ``hull``,
    the poses used) over the configurations ``qs`` (None: a step not solved)."""
    import trimesh

    solved = [q for q in qs if q is not None]
    if not solved:
        raise ValueError("no solved step")
    tyres = [ring for ring in wheel_rings(model) if ring.part == "tyre"]
    poses = Poses(model, sorted({t.body for t in tyres}), solved)
    union = not hull_only and union_available()
    parts = []
    for tyre in tyres:
        centre = poses.place(tyre.body, tyre.centre)
        axis = poses.turn(tyre.body, tyre.axis)
        points = 1e3 * tyre_points(centre, axis, tyre.outer, tyre.half_width)
        if not union:
            hull = trimesh.convex.convex_hull(points.reshape(-1, 3))
            parts.append(snapped(np.asarray(hull.vertices), np.asarray(hull.faces)))
            continue
        import manifold3d

        starts = range(0, max(len(solved) - 1, 1), GROUP - 1)
        hulls = [
            manifold3d.Manifold.hull_points(points[s : s + GROUP].reshape(-1, 3)) for s in starts
        ]
        joined = manifold3d.Manifold.batch_boolean(hulls, manifold3d.OpType.Add)
        mesh = joined.to_mesh()
        vertices = np.asarray(mesh.vert_properties, dtype=float)[:, :3]
        parts.append(snapped(vertices, np.asarray(mesh.tri_verts, dtype=np.int64)))
    mesh = trimesh.util.concatenate(parts) if len(parts) > 1 else parts[0]
    return mesh, "union" if union else "hull", len(solved)
