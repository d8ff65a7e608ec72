"""Clearance along a sweep (docs/clearance.md): at every step, the signed distance from
each corner's rim and tyre to the links and the ``clearance:`` bodies, with coal (the
collision library Pinocchio ships with) as the engine of record.

The wheel's parts are solids of revolution (clearance_shapes.Ring): not convex, and
their inner faces concave. coal measures against a convex piece of the ring, a
sector about the angle where the pair's closest point lies: its outer arc SECTOR
wide (a vertex every ARC, one on the angle), its inner arc 2·INNER (its chord within
r·INNER²/2 of the barrel: 0.08 µm on a 155 mm rim). The angle comes from the ring's
exact signed distance in numpy (a point's, from the rectangle its radius and axial
place make with the ring's section), minimised along a capsule's axis or over a box's
or a mesh's surface points; coal's closest point on the piece then re-centres it
until its angle holds (CENTRE_ITERATIONS). Each distance and both closest points
written are coal's (``coal.ComputeDistance``): negative where the shapes overlap,
their depth coal's penetration (EPA) into the ring's piece.
"""

from __future__ import annotations

import numpy as np

from .clearance_shapes import Pair, Poses, Ring, jointed, pairs

SECTOR = np.radians(10.0)  # the piece's outer arc
ARC = np.radians(0.25)  # its vertices' spacing on it
INNER = 1e-3  # rad: the piece's inner arc, ± about its angle
SAMPLES = 33  # points along a capsule's axis where the ring's distance is first looked at
REFINE = 24  # golden-section steps about the nearest of them
CENTRE_ITERATIONS = 4
ANGLE_TOLERANCE = 1e-7  # rad: the piece's angle holds


def ring_piece(ring: Ring):
    """The ring's convex piece about its local +x (z: the spin axis), coal's Convex."""
    import coal
    from scipy.spatial import ConvexHull

    half = 0.5 * SECTOR
    k = int(np.ceil(half / ARC))
    outer = np.linspace(-half, half, 2 * k + 1)
    inner = np.array([-INNER, 0.0, INNER])
    points = []
    for radius, angles in ((ring.outer, outer), (ring.inner, inner)):
        for s in (-ring.half_width, ring.half_width):
            points += [[radius * np.cos(a), radius * np.sin(a), s] for a in angles]
    points = np.array(points)
    hull = ConvexHull(points)
    used = np.unique(hull.simplices)
    index = {int(v): i for i, v in enumerate(used)}
    vertices, triangles = coal.StdVec_Vec3s(), coal.StdVec_Triangle()
    for p in points[used]:
        vertices.append(p)
    for a, b, c in hull.simplices:
        triangles.append(coal.Triangle(index[int(a)], index[int(b)], index[int(c)]))
    return coal.Convex(vertices, triangles)


def ring_distance(ring: Ring, points: np.ndarray, centre: np.ndarray, axis: np.ndarray):
    """The ring's signed distance (m) at points (..., 3) and each point's unit radial
    direction, the ring at ``centre`` along ``axis`` (broadcast against the points)."""
    d = points - centre
    s = np.sum(d * axis, axis=-1)
    radial = d - s[..., None] * axis
    rho = np.linalg.norm(radial, axis=-1)
    mid, half_r = 0.5 * (ring.inner + ring.outer), 0.5 * (ring.outer - ring.inner)
    qx, qy = np.abs(rho - mid) - half_r, np.abs(s) - ring.half_width
    outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
    inside = np.minimum(np.maximum(qx, qy), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = radial / rho[..., None]
    return outside + inside, direction


def locate_capsule(ring: Ring, A, B, centre, axis, radius: float):
    """Where along each segment A → B (n, 3) the ring is nearest: (distance m of the
    capsule's surface, the ring's radial direction there)."""
    t = np.linspace(0.0, 1.0, SAMPLES)
    P = A[:, None] + t[None, :, None] * (B - A)[:, None]
    d, _ = ring_distance(ring, P, centre[:, None], axis[:, None])
    best = np.argmin(d, axis=1)
    step = 1.0 / (SAMPLES - 1)
    lo = np.clip(t[best] - step, 0.0, 1.0)
    hi = np.clip(t[best] + step, 0.0, 1.0)
    golden = 0.5 * (np.sqrt(5.0) - 1.0)
    D = B - A
    both_centre, both_axis = centre[:, None], axis[:, None]
    for _ in range(REFINE):
        x = np.stack([hi - golden * (hi - lo), lo + golden * (hi - lo)], axis=1)
        pair = ring_distance(ring, A[:, None] + x[..., None] * D[:, None], both_centre, both_axis)[
            0
        ]
        left = pair[:, 0] <= pair[:, 1]
        hi, lo = np.where(left, x[:, 1], hi), np.where(left, lo, x[:, 0])
    x = 0.5 * (lo + hi)
    better = (
        ring_distance(ring, A + x[:, None] * D, centre, axis)[0] <= d[np.arange(len(best)), best]
    )
    x = np.where(better, x, t[best])
    d, direction = ring_distance(ring, A + x[:, None] * (B - A), centre, axis)
    return d - radius, direction


def locate_points(ring: Ring, points, centre, axis):
    """The nearest of each configuration's surface points (n, m, 3): (distance m, the
    ring's radial direction there)."""
    d, direction = ring_distance(ring, points, centre[:, None], axis[:, None])
    best = np.argmin(d, axis=1)
    rows = np.arange(len(best))
    return d[rows, best], direction[rows, best]


def frames_along(z: np.ndarray) -> np.ndarray:
    """Rotations (n, 3, 3) whose third column is each unit z (n, 3)."""
    helper = np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    return np.stack([x, np.cross(z, x), z], axis=2)


def perpendicular(axis: np.ndarray) -> np.ndarray:
    """A unit direction square to each axis (n, 3)."""
    return frames_along(axis)[:, :, 0]


class Clearance:
    """The pairs of a subject (clearance_shapes.pairs) and their distances at
    configurations. ``skipped``: (pair, why) — those not measured, and those that
    overlap at the design state where the shape is jointed to the wheel (drawn through
    it: they touch by construction)."""

    def __init__(self, model, bodies=()):
        self.model = model
        measured, self.skipped = pairs(model, bodies)
        self.pairs = measured
        design = self.measure([model.q_design], measured)
        kept = []
        for pair, d in zip(measured, design["distance"][:, 0], strict=True):
            if d < 0.0 and jointed(model.tree, pair.shape, pair.ring.body):
                why = f"overlaps at design ({1e3 * d:.1f} mm), where it is jointed to the wheel"
                self.skipped.append((pair.name, why))
            else:
                kept.append(pair)
        self.pairs = kept

    def measure(self, qs: list, pairs: list[Pair] | None = None) -> dict:
        """``distance`` (P, n) m and the closest points ``on_wheel``, ``on_body`` (P, n, 3)
        of each pair at each configuration (NaN where q is None)."""
        import coal

        pairs = self.pairs if pairs is None else pairs
        ok = [q is not None for q in qs]
        solved = [q for q in qs if q is not None]
        n, P = len(qs), len(pairs)
        distance = np.full((P, n), np.nan)
        on_wheel, on_body = np.full((P, n, 3), np.nan), np.full((P, n, 3), np.nan)
        if not solved or not pairs:
            return {"distance": distance, "on_wheel": on_wheel, "on_body": on_body}
        bodies = sorted({p.ring.body for p in pairs} | {b for p in pairs for b in p.shape.bodies})
        poses = Poses(self.model, bodies, solved)
        columns = np.flatnonzero(ok)
        request = coal.DistanceRequest()
        request.gjk_tolerance = 1e-10
        pieces = {}
        for i, pair in enumerate(pairs):
            ring, shape = pair.ring, pair.shape
            key = (ring.inner, ring.outer, ring.half_width)
            if key not in pieces:
                pieces[key] = ring_piece(ring)
            piece = pieces[key]
            centre = poses.place(ring.body, ring.centre)
            axis = poses.turn(ring.body, ring.axis)
            placements, geometry, fixed = self._placements(shape, poses, coal)
            # a shape on the wheel's own body keeps its distance: measured once
            still = shape.bodies == (ring.body, ring.body)
            rows = slice(0, 1) if still else slice(None)
            if shape.kind == "capsule":
                A = poses.place(shape.bodies[0], shape.a)[rows]
                B = poses.place(shape.bodies[1], shape.b)[rows]
                _, found = locate_capsule(ring, A, B, centre[rows], axis[rows], shape.radius)
            else:
                samples = poses.place(shape.bodies[0], shape.samples)[rows]
                _, found = locate_points(ring, samples, centre[rows], axis[rows])
            direction = np.zeros_like(centre)
            direction[rows] = found
            bad = ~np.all(np.isfinite(direction), axis=1)
            direction[bad] = perpendicular(axis[bad])
            compute = coal.ComputeDistance(piece, geometry) if fixed else None
            steps = np.arange(1 if still else len(solved))
            todo = steps
            d = np.empty(len(solved))
            near, far = np.empty((len(solved), 3)), np.empty((len(solved), 3))
            for _ in range(CENTRE_ITERATIONS):
                e = direction[todo]
                u = axis[todo]
                R = np.stack([e, np.cross(u, e), u], axis=2)
                for j, k in enumerate(todo):
                    T2, shape_k = placements(k)
                    T1 = coal.Transform3s(R[j], centre[k])
                    result = coal.DistanceResult()
                    if compute is not None:
                        d[k] = compute(T1, T2, request, result)
                    else:
                        d[k] = coal.distance(piece, T1, shape_k, T2, request, result)
                    near[k] = result.getNearestPoint1()
                    far[k] = result.getNearestPoint2()
                # re-centred where coal's closest point is off the piece's angle
                w = near[todo] - centre[todo]
                radial = w - np.sum(w * u, axis=1)[:, None] * u
                length = np.linalg.norm(radial, axis=1)
                turned = radial / np.maximum(length, 1e-300)[:, None]
                cosine = np.clip(np.sum(turned * e, axis=1), -1.0, 1.0)
                off = (length > 1e-12) & (np.arccos(cosine) > ANGLE_TOLERANCE)
                if not off.any():
                    break
                direction[todo[off]] = turned[off]
                todo = todo[off]
            if still:
                d[:], near[:], far[:] = d[0], near[0], far[0]
            distance[i, columns] = d
            on_wheel[i, columns] = near
            on_body[i, columns] = far
        return {"distance": distance, "on_wheel": on_wheel, "on_body": on_body}

    @staticmethod
    def _placements(shape, poses: Poses, coal):
        """(k → (coal placement, geometry) at the k-th configuration, the geometry
        when it is the same at every one, whether it is)."""
        if shape.kind == "capsule":
            A = poses.place(shape.bodies[0], shape.a)
            B = poses.place(shape.bodies[1], shape.b)
            d = B - A
            length = np.linalg.norm(d, axis=1)
            z = np.where(
                length[:, None] > 1e-12, d / np.maximum(length, 1e-300)[:, None], [0, 0, 1]
            )
            R = frames_along(z)
            middle = 0.5 * (A + B)
            fixed = bool(np.ptp(length) < 1e-9)
            one = coal.Capsule(shape.radius, float(length[0])) if fixed else None

            def at(k):
                geometry = one if fixed else coal.Capsule(shape.radius, float(length[k]))
                return coal.Transform3s(R[k], middle[k]), geometry

            return at, one, fixed
        body = shape.bodies[0]
        R = poses.rotations(body)
        origin = poses.place(body, shape.a)

        def placed(k):
            return coal.Transform3s(R[k] @ shape.rotation, origin[k]), shape.geometry

        return placed, shape.geometry, True


class ClearanceRun:
    """A sweep's clearance: ``pairs`` (names), ``skipped`` ((pair, why)), ``steps``
    (n), and the measure's arrays in mm (``distance`` (P, n), ``on_wheel``,
    ``on_body`` (P, n, 3)); NaN at a step that did not converge."""

    def __init__(self, clearance: Clearance, qs: list, sweep=None):
        measured = clearance.measure(qs)
        self.pairs = [p.name for p in clearance.pairs]
        self.wheels = [p.ring.name for p in clearance.pairs]
        self.bodies = [p.shape.name for p in clearance.pairs]
        self.skipped = list(clearance.skipped)
        self.steps = len(qs)
        self.sweep = sweep
        self.distance = 1e3 * measured["distance"]
        self.on_wheel = 1e3 * measured["on_wheel"]
        self.on_body = 1e3 * measured["on_body"]

    def table(self):
        """One row per step and pair (pandas): step, pair, wheel, body, distance (mm,
        negative: overlap) and the closest points (mm, world): wheel_x … body_z."""
        import pandas as pd

        P, n = self.distance.shape
        columns = {
            "step": np.tile(np.arange(n), P),
            "pair": np.repeat(self.pairs, n),
            "wheel": np.repeat(self.wheels, n),
            "body": np.repeat(self.bodies, n),
            "distance": self.distance.ravel(),
        }
        for side, points in (("wheel", self.on_wheel), ("body", self.on_body)):
            for i, axis in enumerate("xyz"):
                columns[f"{side}_{axis}"] = points[:, :, i].ravel()
        frame = pd.DataFrame(columns)
        return frame.sort_values(["step"], kind="stable").reset_index(drop=True)

    def worst(self) -> tuple[int, int] | None:
        """(pair index, step) of the smallest distance, None if nothing was measured."""
        if not np.isfinite(self.distance).any():
            return None
        flat = int(np.nanargmin(self.distance))
        return divmod(flat, self.distance.shape[1])

    def overlaps(self) -> tuple[int, int, int]:
        """(pairs that overlap at some step, steps with an overlap, pair-steps)."""
        with np.errstate(invalid="ignore"):
            hit = self.distance < 0.0
        return int(hit.any(axis=1).sum()), int(hit.any(axis=0).sum()), int(hit.sum())

    def step_text(self, step: int) -> str:
        """What the sweep holds at a step: each target's value (``wheel_center z
        +30 mm``)."""
        if self.sweep is None:
            return ""
        parts = []
        for t in self.sweep.targets:
            what = t.quantity if t.quantity is not None else f"{t.point} {_along(t)}"
            parts.append(f"{what} {t.values[step]:+g}")
        return ", ".join(parts)

    def summary(self, top: int = 5) -> list[str]:
        """The printed summary: the pairs and steps, the closest pair and its step, the
        overlaps, each pair's closest (the ``top`` nearest), what was skipped."""
        P, n = self.distance.shape
        lines = [f"clearance: {P} pairs at {n} steps ({len(self.skipped)} skipped, below)"]
        worst = self.worst()
        if worst is None:
            return [*lines, "no step converged: nothing measured"]
        i, k = worst
        where = self.step_text(k)
        lines.append(
            f"closest: {self.pairs[i]} {self.distance[i, k]:.2f} mm at step {k}"
            + (f" ({where})" if where else "")
        )
        pairs, steps, both = self.overlaps()
        lines.append(
            f"overlaps: {pairs} pairs at {steps} steps ({both} pair-steps)"
            if both
            else "overlaps: none"
        )
        nearest = np.nanmin(self.distance, axis=1)
        order = np.argsort(np.where(np.isfinite(nearest), nearest, np.inf))[:top]
        lines.append(f"the {len(order)} closest pairs (their smallest distance, its step):")
        width = max(len(self.pairs[j]) for j in order)
        for j in order:
            step = int(np.nanargmin(self.distance[j]))
            lines.append(f"  {self.pairs[j]:<{width}}  {nearest[j]:9.2f} mm  step {step}")
        for name, why in self.skipped:
            lines.append(f"skipped: {name} ({why})")
        return lines


def _along(t) -> str:
    d = t.direction
    return d if isinstance(d, str) else "[" + ", ".join(f"{x:g}" for x in d) + "]"


def sweep_clearance(model, sweep, results, bodies=()) -> ClearanceRun:
    """The clearance of a subject's solved sweep (``results``: its run_sweep)."""
    qs = results.solved_configurations
    return ClearanceRun(Clearance(model, bodies), qs, sweep)
