"""The Drake engine (README, How it works): the exported URDF in Drake's own parser,
the closures and targets as constraints of its InverseKinematics, solved by IPOPT;
the URDF checked to be the subject's. A floating root (a vehicle's body: the URDF's
root link, which Drake puts on a floating joint) is held at each step's pose by
bounds on that joint's positions.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from ..analyses.pointwise import Along, as_target
from ..errors import PinSuspError
from ..model.tree import BodyPose
from ..model.urdf import NAMESPACE, read_closures, tree_to_urdf
from .engines import Warnings, richardson, target_rows, with_contact_patches
from .scopes import scope_of

# ---------------------------------------------------------------- Drake

# IPOPT's defaults stop near 1e-8 in its scaled error (SNOPT's near 1e-3 mm in
# the points): a validation at 1e-6 mm needs the constraints met to ~1e-14 m.
# Every example's steps converge within 8 iterations: 100 (not 3000) keeps a step
# that cannot converge (a target out of reach) from costing seconds.
IPOPT_OPTIONS = {"tol": 1e-14, "constr_viol_tol": 1e-14, "max_iter": 100, "print_level": 0}
# A pose is accepted when Drake's own plant has every closure and target this close
# (m, and rad for roll): what IPOPT's tight tolerance reaches, with margin.
DRAKE_RESIDUAL = 1e-12
# m: a frame this far from the origin is no suspension, and IPOPT's iterates on it
# overflow, where Drake aborts the whole process (a non-finite q): refused instead.
FAR = 1e6


class _DrakePoint:
    """A frame of Drake's plant as a point: position and (3 × nq) Jacobian in world."""

    def __init__(self, frame, offset=None):
        self.frame = frame
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)

    def position(self, engine: DrakeCorner) -> np.ndarray:
        p = engine.plant.CalcPointsPositions(engine.context, self.frame, self.offset, engine.world)
        return p[:, 0]

    def jacobian(self, engine: DrakeCorner) -> np.ndarray:
        return engine.plant.CalcJacobianTranslationalVelocity(
            engine.context, engine.wrt, self.frame, self.offset, engine.world, engine.world
        )


@dataclass(frozen=True)
class _DrakeClosure:
    """A loop closure read back from the URDF, its anchors as points of Drake's plant;
    ``length``: a distance closure's, from Drake's design pose."""

    name: str
    kind: str
    a: _DrakePoint
    b: _DrakePoint
    links: frozenset
    length: float = 0.0


class _Positions(dict):
    """The points' world positions at the engine's pose, each computed when first asked."""

    def __init__(self, engine: DrakeCorner):
        super().__init__()
        self.engine = engine

    def __missing__(self, name: str) -> np.ndarray:
        self[name] = position = self.engine.sites[name].position(self.engine)
        return position


class DrakeCorner:
    """The exported URDF (a corner's or an axle's) in Drake, solved to targets by
    Drake's InverseKinematics.

    Drake's own URDF parser builds the ``MultibodyPlant`` (the root link welded
    to the world); the loop closures are read back from the same text
    (:func:`pin_susp.model.urdf.read_closures`): a ball closure is a position
    constraint (one anchor at the other, in its link's frame), a distance
    closure a point-to-point distance constraint at the length Drake's plant
    has at the design configuration (all joints 0). A target along a direction
    is a position constraint in a frame whose x axis is that direction; an
    axle's heave and roll are constraints evaluated on the plant's points and
    Jacobians. Build and use it inside :func:`quiet_drake`.
    """

    def __init__(self, urdf_text: str, subject, source: str = "the URDF"):
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
        from pydrake.multibody.tree import FrameIndex, JacobianWrtVariable

        scope = scope_of(subject)
        root = next(b.name for b in scope.tree.bodies if b.parent is None)
        floating = scope.tree.floating is not None
        self.plant = plant = MultibodyPlant(0.0)
        try:
            Parser(plant).AddModelsFromString(urdf_text, "urdf")
            if not floating:  # the root is the world; else Drake floats it
                plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(root))
            plant.Finalize()
        except (RuntimeError, ValueError) as exc:
            detail = " ".join(str(exc).replace("<literal-string>.urdf:", "line ").split())
            raise PinSuspError(f"{source}: Drake cannot load it: {detail}") from None
        self.world = plant.world_frame()
        self.wrt = JacobianWrtVariable.kQDot
        self.context = plant.CreateDefaultContext()
        self.q_design = np.zeros(plant.num_positions())
        # the floating root's positions (quaternion w x y z, then x y z) and the rest
        self.base, self.moving = None, np.ones(plant.num_positions(), dtype=bool)
        if floating:
            body = plant.GetBodyByName(root)
            self.root = body
            if not body.is_floating_base_body():
                raise PinSuspError(f"{source}: its root {root} does not float in Drake")
            start = body.floating_positions_start()
            self.base = slice(start, start + 7)
            self.moving[self.base] = False
            self.q_design[start] = 1.0  # the identity quaternion: the design place
        plant.SetPositions(self.context, self.q_design)
        self.road = {}  # the points where the last solve put them
        self.moved = {}  # its tangent along each of the body's quantities there (dq)
        for i in range(plant.num_frames()):
            f = plant.get_frame(FrameIndex(i))
            where = f.CalcPoseInWorld(self.context).translation()
            if not np.all(np.abs(where) < FAR):
                raise PinSuspError(
                    f"{source}: frame {f.name()} is {np.max(np.abs(where)):g} m from the "
                    "origin at the design state: not a suspension"
                )

        def frame(name):
            if not plant.HasFrameNamed(name):
                raise PinSuspError(f"{source}: is not the URDF of this geometry: no link {name}")
            return plant.GetFrameByName(name)

        self.sites = with_contact_patches(
            {name: _DrakePoint(frame(name)) for name in scope.sites}, scope
        )
        self.closures = []
        try:
            specs = read_closures(urdf_text)
        except ValueError as exc:
            raise PinSuspError(f"{source}: its loop closures cannot be read: {exc}") from None
        for spec in specs:
            (link_a, offset_a), (link_b, offset_b) = spec.anchors
            a = _DrakePoint(frame(link_a), offset_a)
            b = _DrakePoint(frame(link_b), offset_b)
            with np.errstate(over="ignore", invalid="ignore"):
                length = float(np.linalg.norm(a.position(self) - b.position(self)))
            if not np.isfinite(length):  # Drake aborts the process on a NaN bound
                raise PinSuspError(
                    f"{source}: loop closure {spec.name}: its anchors are not a finite "
                    "distance apart"
                )
            links = frozenset((link_a, link_b))
            self.closures.append(_DrakeClosure(spec.name, spec.kind, a, b, links, length))

    def _target_constraint(self, target):
        """A target as a function of q for Drake's MathematicalProgram: its error, and
        for IPOPT's AutoDiff its gradient by the chain rule through the plant's
        Jacobians."""
        from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff

        def evaluate(q):
            values = q if q.dtype != object else ExtractValue(q)[:, 0]
            if not np.all(np.isfinite(values)):  # Drake aborts on a non-finite q
                errors, rows = [np.nan], np.full((1, len(values)), np.nan)
            else:
                self.plant.SetPositions(self.context, values)
                errors, rows = self._rows([target])
            if q.dtype != object:
                return np.array(errors)
            return InitializeAutoDiff(np.array(errors), np.array(rows) @ ExtractGradient(q))[:, 0]

        return evaluate

    def _rows(self, targets) -> tuple[list, list]:
        """Each target's residual and its row of d residual / dq (chain rule through
        the points' Jacobians), at the context's pose."""
        return target_rows(self, _Positions(self), targets)

    def _closure_residuals(self) -> np.ndarray:
        out = []
        for c in self.closures:
            d = c.a.position(self) - c.b.position(self)
            out.append(np.linalg.norm(d) if c.kind == "ball" else np.linalg.norm(d) - c.length)
        return np.array(out)

    def _placed(self, pose: BodyPose | None) -> np.ndarray:
        """The design configuration with a floating root at ``pose`` (None: its design
        place)."""
        q = self.q_design.copy()
        if pose is None or self.base is None:
            if pose is not None:
                raise PinSuspError("the URDF's root does not float: not this vehicle's")
            return q
        from pydrake.math import RigidTransform, RotationMatrix

        self.plant.SetPositions(self.context, q)
        self.plant.SetFreeBodyPose(
            self.context,
            self.root,
            RigidTransform(RotationMatrix(np.asarray(pose.rotation)), pose.translation),
        )
        return self.plant.GetPositions(self.context).copy()

    def program(self, targets, pose: BodyPose | None = None):
        """Drake's InverseKinematics of one step: the closures and the targets as its
        constraints (no cost: the system is square), joint limits left out as
        pin_susp's solver has none; a floating root's positions bounded to ``pose``."""
        from pydrake.math import RigidTransform, RotationMatrix
        from pydrake.multibody.inverse_kinematics import InverseKinematics

        ik = InverseKinematics(self.plant, with_joint_limits=False)
        if self.base is not None:
            held = self._placed(pose)[self.base]
            ik.prog().AddBoundingBoxConstraint(held, held, ik.q()[self.base])
        for c in self.closures:
            if c.kind == "ball":
                # anchor a, seen from b's link, is at anchor b
                ik.AddPositionConstraint(c.a.frame, c.a.offset, c.b.frame, c.b.offset, c.b.offset)
            elif c.kind == "distance":
                ik.AddPointToPointDistanceConstraint(
                    c.a.frame, c.a.offset, c.b.frame, c.b.offset, c.length, c.length
                )
            else:
                raise PinSuspError(f"loop closure {c.name}: Drake has no {c.kind!r} closure")
        free = np.array([-np.inf, -np.inf])
        for t in map(as_target, targets):
            site = self.sites.get(getattr(t, "point", None))
            if isinstance(t, Along) and isinstance(site, _DrakePoint):
                # the point's coordinate along the direction: x of a frame A whose x it is
                along = RigidTransform(
                    RotationMatrix.MakeFromOneVector(t.direction, 0), np.zeros(3)
                )
                ik.AddPositionConstraint(
                    site.frame,
                    site.offset,
                    self.world,
                    along,
                    np.r_[t.value, free],
                    np.r_[t.value, -free],
                )
            else:
                ik.prog().AddConstraint(self._target_constraint(t), [0.0], [0.0], ik.q())
        return ik

    def solve(self, targets, moves: dict | None = None) -> dict | None:
        """IPOPT from the design configuration; None unless it succeeds and Drake's
        plant has every closure and target within DRAKE_RESIDUAL at its answer. A
        floating root: its points where solved kept as ``road``, returned with the root
        back at its design place (the joints kept); ``moves``: the step's targets with
        the body moved (Scope.step_moves), for the tangent along each (``moved``)."""
        from pydrake.solvers import IpoptSolver, SolverOptions

        pose = next((t for t in targets if isinstance(t, BodyPose)), None)
        targets = [t for t in targets if t is not pose]
        self.moved = {}
        ik = self.program(targets, pose)
        solver = IpoptSolver()
        options = SolverOptions()
        for key, value in IPOPT_OPTIONS.items():
            options.SetOption(solver.solver_id(), key, value)
        result = solver.Solve(ik.prog(), self._placed(pose), options)
        q = result.GetSolution(ik.q())
        if not (result.is_success() and np.all(np.isfinite(q))):
            return None
        self.plant.SetPositions(self.context, q)
        residual = np.r_[self._closure_residuals(), self._rows(targets)[0]]
        if not np.max(np.abs(residual), initial=0.0) < DRAKE_RESIDUAL:
            return None
        self.road = {name: site.position(self).copy() for name, site in self.sites.items()}
        self.moved = self._moved(q, targets, moves or {})
        if self.base is None:
            return self.road
        q[self.base] = self.q_design[self.base]  # the root back at its design place
        self.plant.SetPositions(self.context, q)
        return {name: site.position(self).copy() for name, site in self.sites.items()}

    def _closure_rows(self) -> tuple[list, dict]:
        """The closures' rows of d residual / dq at the context's pose (a ball's three, a
        distance's one along the link), and each distance closure's row by its links."""
        rows, link_row = [], {}
        for c in self.closures:
            Ja, Jb = c.a.jacobian(self), c.b.jacobian(self)
            if c.kind == "ball":
                rows += list(Ja - Jb)
            else:
                d = c.a.position(self) - c.b.position(self)
                link_row[c.links] = len(rows)
                rows.append(d @ (Ja - Jb) / np.linalg.norm(d))
        return rows, link_row

    def _moved(self, q: np.ndarray, targets, moves: dict) -> dict:
        """At the solved pose q: dq per unit of each of the body's quantities, the others
        held — J·dq = −∂r/∂s, the change of the targets' residuals as the floating root
        moves with the joints held (Richardson differences over the moved poses; the
        closures' rows do not change)."""
        if not moves:
            return {}
        closures = self._closure_rows()[0]
        J = np.array(closures + self._rows(targets)[1])
        out = {}
        for quantity, (h, moved) in moves.items():
            residuals = []
            for step in moved:
                pose = next(t for t in step if isinstance(t, BodyPose))
                shifted = q.copy()
                shifted[self.base] = self._placed(pose)[self.base]
                self.plant.SetPositions(self.context, shifted)
                p = _Positions(self)
                errors = [as_target(t).error(p) for t in step if t is not pose]
                residuals.append(np.r_[np.zeros(len(closures)), errors])
            dq = np.zeros(len(q))
            dq[self.moving] = np.linalg.lstsq(
                J[:, self.moving], -richardson(residuals, h), rcond=None
            )[0]
            out[quantity] = dq
        self.plant.SetPositions(self.context, q)
        return out

    def along(self, hubs: dict) -> dict:
        """Each wheel centre's z rate along the body's quantities (``moved``), at the
        context's pose (the chassis frame): quantity → {label: m per m or rad}."""
        return {
            quantity: {
                label: float((self.sites[hub].jacobian(self) @ dq)[2])
                for label, hub in hubs.items()
            }
            for quantity, dq in self.moved.items()
        }

    def rates(self, held, links, k: int) -> dict[str, np.ndarray]:
        """At the solved pose: each point's rate along the k drivers, J·dq = e: the
        closures' rows (a ball's three, a distance's one along the link) and the held
        targets' rows; a driver that is a link's length (``links``: its two points)
        is a 1 on its distance closure's row. NaN for a link no closure joins."""
        rows, link_row = self._closure_rows()
        first = len(rows)
        rows += self._rows(held)[1]
        rhs = np.zeros((len(rows), k))
        rhs[first:, : len(held)] = np.eye(len(held))
        known = list(range(len(held)))
        for j, pair in enumerate(links, start=len(held)):
            if frozenset(pair) in link_row:
                rhs[link_row[frozenset(pair)], j] = 1.0
                known.append(j)
        dq = np.zeros((len(self.moving), k))  # a floating root stays still
        dq[self.moving] = np.linalg.lstsq(np.array(rows)[:, self.moving], rhs, rcond=None)[0]
        out = {}
        for name, site in self.sites.items():
            out[name] = np.full((k, 3), np.nan)
            out[name][known] = (site.jacobian(self) @ dq[:, known]).T
        return out


class _DrakeLog(logging.Handler):
    """Drake's log records (pydrake sends them to the ``drake`` logger) to a counter."""

    def __init__(self, counter: Warnings):
        super().__init__(logging.WARNING)
        self.counter = counter

    def emit(self, record) -> None:
        self.counter(record.getMessage())


@contextmanager
def quiet_drake():
    """Drake's warnings (its parser's, its solvers') counted instead of printed.

    pydrake routes Drake's log to Python's ``drake`` logger: a counting handler
    stands in for its handlers and propagation while the engine runs; both are
    restored on the way out. Yields the :class:`Warnings` counter.
    """
    counter = Warnings()
    logger = logging.getLogger("drake")
    handlers, propagate = logger.handlers[:], logger.propagate
    logger.handlers, logger.propagate = [_DrakeLog(counter)], False
    try:
        yield counter
    finally:
        logger.handlers, logger.propagate = handlers, propagate


def drake_points(subject, sweep, urdf_text: str | None = None, source: str = "the URDF") -> list:
    """Drake's points at every step (None where it did not converge), quietly, as the
    subject's motion gives them; ``urdf_text`` defaults to the subject's own export."""
    scope = scope_of(subject)
    text = scope.subject.export_urdf if urdf_text is None else urdf_text
    return scope.as_motion(drake_run(scope, sweep, text, source)[0])


def drake_run(scope, sweep, urdf_text: str, source: str):
    """(points, a Dual per label; warnings counter); Drake's errors as PinSuspError
    naming ``source``."""
    with quiet_drake() as counter:
        engine = DrakeCorner(urdf_text, scope, source)
        points = []
        for targets, moves in zip(scope.step_targets(sweep), scope.step_moves(sweep), strict=True):
            try:
                at = engine.solve(targets, moves)
            except RuntimeError as exc:
                detail = " ".join(str(exc).split())
                raise PinSuspError(f"{source}: Drake failed on it: {detail}") from None
            if at is None:
                points.append(None)
                continue
            rates = engine.rates(scope.held(at), scope.links, scope.drivers)
            points.append(scope.duals(at, rates, engine.road, engine.along(scope.hubs)))
    return points, counter


def check_urdf(text: str, tree, source: str = "URDF") -> None:
    """Raise PinSuspError unless ``text`` is the URDF :func:`pin_susp.model.urdf.tree_to_urdf`
    writes for ``tree``: XML with a ``<robot>`` root holding the same links, the same
    joints (type, parent, child) and the same loop closures (type, the links of their
    frames). Positions and axes are not compared: the URDF of a corner whose hardpoints
    moved since the export passes, and the comparison of the solutions shows it."""
    problem = _urdf_problem(text, tree)
    if problem:
        raise PinSuspError(f"{source}: {problem}")


def _urdf_problem(text: str, tree) -> str | None:
    from ..model.urdf import model_file_root, not_this_model

    root, problem = model_file_root(text, "URDF")
    if problem:
        return problem
    ours, theirs = _urdf_elements(ET.fromstring(tree_to_urdf(tree))), _urdf_elements(root)
    kinds = ("link", "joint", "loop closure")
    return not_this_model(
        "URDF",
        tree.name,
        {k: ours[k] for k in kinds},
        theirs,
        name=lambda n: n or "(unnamed)",
    )


def _urdf_elements(root) -> dict[str, dict[str, tuple[str, ...]]]:
    """Named elements by kind, each with what must match: a joint's type, parent and
    child; a loop closure's type and its frames' links."""
    ns = {"pin_susp": NAMESPACE}
    found = {
        "link": {el.get("name", ""): () for el in root.findall("link")},
        "joint": {},
        "loop closure": {},
    }
    for el in root.findall("joint"):
        ends = [
            (el.find(end).get("link", "") if el.find(end) is not None else "")
            for end in ("parent", "child")
        ]
        found["joint"].setdefault(
            el.get("name", ""), (el.get("type", "?"), "from", ends[0] or "?", "to", ends[1] or "?")
        )
    for el in root.findall("pin_susp:loop_closure", ns):
        links = [f.get("link", "?") for f in el.findall("pin_susp:frame", ns)]
        found["loop closure"].setdefault(
            el.get("name", ""), (el.get("type", "?"), "between", *links)
        )
    return found
