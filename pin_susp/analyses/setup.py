"""Setup options: camber shim, trackrod and pushrod adjusters, and their inverse.

Forward (``apply_setup``, in ``as_set.py`` below the corner, here by name too): the
shim assembly (``shim.py``) first, then the length adjusters on the main mechanism,
holding the static load path — the rocker at its design angle where there is a
pushrod-rocker (the spring keeps its static length), otherwise the wheel-centre
height — and the rack at its design position. The result, the as-set geometry, is
the design state of every later sweep; ``ride_height_change`` is −ΔCP_z from the
drawn design.

Exact sensitivities (``SetupModel``): a camber shim of Δt adds a rigid offset
−Δt·n₀ (in the upright's design frame) between the lower and upper ball
joints, because the datums A and B with aligned normals leave the block
and the body no relative rotation. So the drawn mechanism, with that offset
and the adjusted lengths as parameters p, reaches the as-set state in two
solves: q₁ (shim: lower wishbone, rack and rocker held) and q₂ (adjusters:
rack and rocker or wheel-centre height held). The implicit function theorem
through both gives dq₂/dp, and the metrics' exact derivatives follow.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..columns.metrics import METRIC_BY_NAME, STANDARD, PointSet
from ..constraints import DistanceClosure, JointTarget
from ..errors import InputError
from ..maths.jet import Dual
from ..model.geometry import MM, Geometry
from ..solve.as_set import PARAMETER_KEYS, as_geometry, static_holds
from ..solve.as_set import apply_setup as apply_setup  # the as-set geometry, by its old address
from ..solve.as_set import axle_data as axle_data  # the setup written back, by their old address
from ..solve.as_set import geometry_data as geometry_data
from ..solve.linkage import Linkage
from ..solve.solver import NewtonSolver

PARAMETERS = ("shim_thickness", "trackrod_length", "pushrod_length")


def setup_values(g: Geometry) -> np.ndarray:
    """p = (shim setup thickness, trackrod delta, pushrod delta), m."""
    shim = g.camber_shim
    return np.array(
        [
            shim.setup_thickness if shim is not None else 0.0,
            g.trackrod_length_delta,
            g.pushrod_length_delta,
        ]
    )


def with_setup(g: Geometry, p) -> Geometry:
    """The drawn geometry with setup values p (m), not yet applied."""
    g = g.drawn or g
    shim = g.camber_shim
    if shim is not None:
        shim = replace(shim, setup_thickness=float(p[0]))
    return replace(
        g, camber_shim=shim, trackrod_length_delta=float(p[1]), pushrod_length_delta=float(p[2])
    )


@dataclass
class SetupState:
    """Static metrics of an as-set corner (output units) and their exact derivatives.

    ``derivatives[metric]`` has one entry per PARAMETERS, in the metric's unit
    per mm (shim thickness, trackrod length, pushrod length).
    """

    setup: np.ndarray  # mm: shim thickness, trackrod delta, pushrod delta
    metrics: dict[str, float]
    derivatives: dict[str, np.ndarray]


class SetupModel:
    """The drawn corner with the setup p as parameters: static state and dq/dp."""

    def __init__(self, g):
        g = as_geometry(g)
        self.drawn = g.drawn or g
        self.corner = Linkage(self.drawn)
        c = self.corner
        self.links = {x.name: x for x in c.closures if isinstance(x, DistanceClosure)}
        self.link_name = next((n for n in ("trackrod", "toe_link") if n in self.links), None)
        shim = self.drawn.camber_shim
        # a camber shim (double wishbone): a rigid offset in the upper ball joint
        self.ball = None
        if shim is not None:
            self.ball = next(x for x in c.closures if x.name == "upper_ball_joint")
            self.normal = shim.normal
            self.t_design = shim.design_thickness
            anchor = c.model.frames[self.ball.b.frame_id]
            self.ubj_offset = anchor.placement.translation.copy()

    def _set_shim(self, thickness: float) -> None:
        """The upright's UBJ anchor moves by −Δt·n₀ in the upright's frame."""
        model = self.corner.model
        frame = model.frames[self.ball.b.frame_id]
        offset = self.ubj_offset - (thickness - self.t_design) * self.normal
        frame.placement = pin.SE3(frame.placement.rotation, offset)
        model.frames[self.ball.b.frame_id] = frame

    def state(self, p) -> SetupState:
        """Solve the static state at setup p (m) and differentiate it."""
        c = self.corner
        kin = c.kin
        p = np.asarray(p, dtype=float)
        nv = c.model.nv

        # q₁: the shim alone, lower wishbone, rack and rocker held.
        q1, dq1 = c.q_design, np.zeros((nv, 3))
        if self.ball is not None:
            self._set_shim(p[0])
            holds1 = [JointTarget(c.model, "lower_wishbone_pivot")]
            holds1 += [
                JointTarget(c.model, j)
                for j in ("rack_slide", "rocker_pivot")
                if c.model.existJointName(j)
            ]
            s1 = NewtonSolver(kin, [self.ball, self.links[self.link_name]], holds1, c.branches)
            q1 = self._solve(
                s1,
                c.q_design,
                PARAMETER_KEYS["shim_thickness"],
                "the shimmed upright does not assemble",
            )
            s1.evaluate(q1)
            f1_p = np.zeros((s1.nrows, 3))
            f1_p[:3, 0] = -kin.data.oMf[self.ball.b.frame_id].rotation @ self.normal
            dq1 = -np.linalg.solve(s1.jacobian.copy(), f1_p)
        kin.update(q1)
        length1 = pushrod_q1 = None
        if "pushrod" in self.links:
            pr = self.links["pushrod"]
            length1 = float(np.linalg.norm(pr.b.position(kin) - pr.a.position(kin)))
            pushrod_q1 = pr.jacobian(kin)[0]  # ∇_q of the pushrod length at q₁
        wc_q1 = c.points["wheel_center"].jacobian(kin)[2].copy()

        # q₂: the adjusters, the static load path held. Rows: the closures in the
        # corner's order (the adjusted links with their new lengths), then the holds.
        closures, rows = [], {}
        for x in c.closures:
            rows[x.name] = sum(y.size for y in closures)
            if x.name == self.link_name:
                x = DistanceClosure(x.name, x.a, x.b, x.length + p[1])
            elif x.name == "pushrod":
                x = DistanceClosure(x.name, x.a, x.b, length1 + p[2])
            closures.append(x)
        s2 = NewtonSolver(kin, closures, static_holds(c, q1), c.branches)
        key = PARAMETER_KEYS["pushrod_length" if p[2] else "trackrod_length"]
        q2 = self._solve(s2, q1, key, "the corner does not assemble with these lengths")
        s2.evaluate(q2)
        f2_p = np.zeros((s2.nrows, 3))
        f2_q1 = np.zeros((s2.nrows, nv))
        if self.ball is not None:
            ball = rows[self.ball.name]
            f2_p[ball : ball + 3, 0] = -kin.data.oMf[self.ball.b.frame_id].rotation @ self.normal
        if self.link_name is not None:
            f2_p[rows[self.link_name], 1] = -1.0
        if pushrod_q1 is not None:
            f2_p[rows["pushrod"], 2] = -1.0
            f2_q1[rows["pushrod"]] = -pushrod_q1
        else:
            f2_q1[-1] = -wc_q1
        dq2 = -np.linalg.solve(s2.jacobian.copy(), f2_p + f2_q1 @ dq1)
        return self._metrics(q2, dq2, p)

    def _solve(self, solver: NewtonSolver, q0, key: str, what: str) -> np.ndarray:
        solution = solver.newton(q0)
        if not solution.converged:
            raise InputError(
                self.drawn.source, key, f"{what} ({solution.why}): beyond the linkage's reach"
            )
        return solution.q

    def _metrics(self, q2, dq2, p) -> SetupState:
        """Static metrics at q₂ and their derivatives: point velocities through the metrics."""
        c = self.corner
        c.kin.update(q2)
        # Each point as a Dual: position (1, 3), rates (3 parameters, 1, 3).
        ps = PointSet(
            {
                n: Dual(
                    c.points[n].position(c.kin)[None],
                    (c.points[n].jacobian(c.kin) @ dq2).T[:, None],
                )
                for n in c.point_names
            },
            {k: v[None] for k, v in c.design_positions.items()},
            c.geometry,
        )
        metrics, derivatives = {}, {}
        for name in STANDARD:
            m = METRIC_BY_NAME[name]
            v = m.function(ps) * m.scale
            metrics[name] = float(v.val[0])
            derivatives[name] = v.der[:, 0] * MM  # per mm of each parameter
        cp = ps["contact_patch_center"]
        cp0 = c.design_positions["contact_patch_center"][2]
        metrics["ride_height_change"] = -(cp.val[0, 2] - cp0) / MM
        derivatives["ride_height_change"] = -cp.der[:, 0, 2]
        return SetupState(p / MM, metrics, derivatives)


@dataclass
class InverseResult:
    geometry: Geometry  # drawn geometry with the found setup values
    before: SetupState
    after: SetupState
    iterations: int


TARGET_PARAMETER = {"camber": 0, "roadwheel_angle": 1, "ride_height_change": 2}
# The CLI's option names, accepted by the API too.
TARGET_ALIASES = {"toe": "roadwheel_angle", "ride_height": "ride_height_change"}


def _targets(targets: dict[str, float]) -> dict[str, float]:
    """Target names as the CLI says them (``toe``, ``ride-height-change``) or as columns."""
    out = {}
    for name, value in targets.items():
        key = TARGET_ALIASES.get(str(name).replace("-", "_"), str(name).replace("-", "_"))
        if key not in TARGET_PARAMETER:
            raise InputError(
                "targets",
                str(name),
                "unknown setup target (valid: camber [deg], toe or roadwheel_angle [deg], "
                "ride_height_change [mm])",
            )
        if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
            raise InputError("targets", str(name), f"expected a finite number, got {value!r}")
        out[key] = float(value)
    return out


SHIM_DOCS = "docs/geometry.md#camber-shim-configcamber_shim-double-wishbone-only"


def _camber_alternatives(g) -> str:
    """What sets camber on a corner without a shim: the shim to add (a double
    wishbone's), else its points — with where to read on."""
    if g.type == "double_wishbone":
        return (
            f": add config.camber_shim (see {SHIM_DOCS}), or set camber by moving the "
            "upper ball joint (`pin-susp sensitivity` gives camber per mm of each hardpoint; "
            "a study finds the move, docs/studies.md)"
        )
    example = {
        "macpherson": "the strut top on a camber plate",
        "multilink": "a link's outboard pickup",
        "trailing_arm": "the arm's pivot axis",
    }.get(g.type, "a pickup")
    return (
        f" (a double-wishbone option, {SHIM_DOCS}): on a {g.type} corner camber is set "
        f"by its points, e.g. {example} (`pin-susp sensitivity` gives "
        "camber per mm of each hardpoint; a study finds the move, docs/studies.md)"
    )


def solve_setup(g, targets: dict[str, float], max_iterations: int = 25) -> InverseResult:
    """Find shim thickness, trackrod and pushrod deltas that hit the targets.

    ``g``: a geometry file's path, its dict, or a Geometry. ``targets`` maps
    camber (deg), toe (= roadwheel_angle, deg) and ride_height_change (mm)
    to their wanted static values; each moves its own adjuster (shim,
    trackrod, pushrod). Newton with exact sensitivities.
    """
    g = as_geometry(g)
    targets = _targets(targets)
    drawn = g.drawn or g
    for name in targets:
        if name == "camber" and drawn.camber_shim is None:
            raise InputError(
                drawn.source,
                "config.camber_shim",
                "a camber target needs a camber shim in the geometry" + _camber_alternatives(drawn),
            )
        if name == "roadwheel_angle" and not drawn.steering_points:
            raise InputError(
                drawn.source, "hardpoints", "a toe target needs a trackrod or toe link to adjust"
            )
        if name == "ride_height_change" and not drawn.has_pushrod:
            raise InputError(
                drawn.source,
                "actuation.type",
                "a ride-height target needs a pushrod (actuation pushrod_rocker)",
            )
    free = [TARGET_PARAMETER[n] for n in targets]
    goal = np.array(list(targets.values()))
    model = SetupModel(drawn)
    p = setup_values(g)
    before = state = model.state(p)
    for steps in range(max_iterations + 1):
        error = np.array([state.metrics[n] for n in targets]) - goal
        if np.max(np.abs(error)) <= 1e-11:
            break
        if steps == max_iterations:
            reached = ", ".join(f"{n} {state.metrics[n]:.4g}" for n in targets)
            raise _unreachable(
                drawn, targets, p, f"the adjusters stall (last: {reached} with {_describe(p)})"
            )
        jac = np.array([[state.derivatives[n][i] for i in free] for n in targets])
        try:
            step = np.linalg.solve(jac, -error) * MM
        except np.linalg.LinAlgError:
            raise _unreachable(
                drawn, targets, p, "the adjusters do not move these metrics independently here"
            ) from None
        p, state = _step_within_reach(model, p, free, step, drawn, targets)
    if drawn.camber_shim is not None and p[0] < 0.0:
        raise _unreachable(
            drawn, targets, p, f"it needs a shim stack of {p[0] / MM:.3f} mm, thinner than none"
        )
    return InverseResult(with_setup(drawn, p), before, state, steps)


def _step_within_reach(model, p, free, step, drawn, targets, halvings: int = 8):
    """Take the Newton step, halving it while the corner does not assemble."""
    for _ in range(halvings + 1):
        trial = p.copy()
        trial[free] += step
        try:
            return trial, model.state(trial)
        except InputError:
            step = 0.5 * step
    raise _unreachable(drawn, targets, trial, "the corner locks up on the way")


def _describe(p) -> str:
    names = ("shim stack", "trackrod delta", "pushrod delta")
    return ", ".join(f"{n} {v / MM:.3f} mm" for n, v in zip(names, p, strict=True) if v)


def _unreachable(g: Geometry, targets: dict, p, why: str) -> InputError:
    wanted = ", ".join(f"{k} {v:g}" for k, v in targets.items())
    return InputError(g.source, "targets", f"{wanted} not reachable: {why}")


def setup_sheet(
    g,
    shim: list[float] = (),
    trackrod: list[float] = (),
    pushrod: list[float] = (),
) -> list[SetupState]:
    """The as-set static state, then one state per listed value (mm) of one adjuster.

    ``g``: a geometry file's path, its dict, or a Geometry. ``shim`` lists
    fitted stack thicknesses; ``trackrod`` and ``pushrod`` list length deltas.
    Each row changes that one value from the file's setup.
    """
    g = as_geometry(g)
    drawn = g.drawn or g
    if shim and drawn.camber_shim is None:
        raise InputError(drawn.source, "config.camber_shim", "--shim needs a camber shim")
    if pushrod and not drawn.has_pushrod:
        raise InputError(
            drawn.source, "actuation.type", "--pushrod needs a pushrod (actuation pushrod_rocker)"
        )
    if trackrod and not drawn.steering_points:
        raise InputError(drawn.source, "hardpoints", "--trackrod needs a trackrod or toe link")
    if any(v < 0 for v in shim):
        raise InputError("--shim", "", "a shim stack cannot be thinner than 0 mm")
    model = SetupModel(drawn)
    p0 = setup_values(drawn)
    rows = [model.state(p0)]
    for index, (flag, values) in enumerate(
        (("--shim", shim), ("--trackrod", trackrod), ("--pushrod", pushrod))
    ):
        for value in values:
            p = p0.copy()
            p[index] = value * MM
            try:
                rows.append(model.state(p))
            except InputError as exc:  # the listed value is at fault, not the file
                raise InputError(flag, "", f"{value:g} mm: {exc.problem}") from None
    return rows


# ---------------------------------------------------------------- a subject
#
# Each labelled corner of a subject (a corner's one, an axle's left and right,
# docs/axle.md) is set up as a corner is, the rack held at design; with the rack held
# the corners share nothing else. So a subject's setup sheet, sensitivities and
# inverse solve are each corner's, by label; the subject adds its own static columns
# of its corners together (``Assembly.static_columns``: an axle's track, roll centre).
# A corner that takes another's setup (a mirrored axle's right side: the left's) is
# set with it (``Assembly.setup_owner``).


def on_corner(subject, label: str, work):
    """Run a corner's setup ``work()``; its errors as the subject reports them (an axle's
    name its file's key, ``axle_config.left_setup.camber_shim``, and the side)."""
    try:
        return work()
    except InputError as exc:
        raise subject.setup_error(label, exc) from None


def subject_setup_sheet(subject, shim=(), trackrod=(), pushrod=(), label=None) -> dict:
    """Per label (a corner's ``{"": rows}``, an axle's ``{"left": rows, "right": rows}``):
    the as-set state, then one row per listed value (mm) of one adjuster, as
    :func:`setup_sheet`. The values go to every corner, or to ``label``'s alone; a corner
    not set has its as-set row only."""
    chosen = subject.setup_labels(label)
    drawn = subject.drawn_corners
    out = {}
    for s in subject.labels:
        lists = (shim, trackrod, pushrod) if s in chosen else ()
        out[s] = on_corner(subject, s, lambda s=s, lists=lists: setup_sheet(drawn[s], *lists))
    return out


def solve_subject_setup(subject, targets: dict[str, float], label=None) -> dict:
    """Per label, the inverse solve of :func:`solve_setup` on that corner: its own shim,
    trackrod and pushrod for the targets (camber, toe, ride height), on every corner or
    on ``label``'s alone (the others: their setup as it is, 0 iterations). A corner that
    takes another's setup (a mirrored axle's right side) is that one's at the values
    found (0 iterations: it hits the same targets)."""
    chosen = subject.setup_labels(label)
    drawn = subject.drawn_corners
    found = {}
    for s in chosen:
        if subject.setup_owner(s) == s:
            found[s] = on_corner(subject, s, lambda s=s: solve_setup(drawn[s], targets))
    out = {}
    for s in subject.labels:
        if s in found:
            out[s] = found[s]
            continue
        g, owner = drawn[s], subject.setup_owner(s)
        p = setup_values(found[owner].geometry if owner in found else g)
        model = SetupModel(g)
        before = on_corner(subject, s, lambda g=g, model=model: model.state(setup_values(g)))
        after = on_corner(subject, s, lambda model=model, p=p: model.state(p))
        out[s] = InverseResult(with_setup(g, p), before, after, 0)
    return out


def static_state(subject, states: dict) -> dict[str, float]:
    """The subject's own static columns (``Assembly.static_columns``, mm) with each
    corner set as in its SetupState (label → state): the subject at its design state;
    none for a corner."""
    if not subject.static_columns:
        return {}
    drawn = subject.drawn_corners
    return subject.static_results(
        {s: with_setup(drawn[s], state.setup * MM) for s, state in states.items()}
    )


# an axle's, by their old names (the axle file as read: an AxleGeometry)


def _axle_model(axle):
    from ..subjects.axle import AxleModel

    return AxleModel(axle)


def axle_setup_sheet(axle, shim=(), trackrod=(), pushrod=(), side: str | None = None) -> dict:
    """:func:`subject_setup_sheet` of an axle file's model, per side."""
    return subject_setup_sheet(_axle_model(axle), shim, trackrod, pushrod, side)


def solve_axle_setup(axle, targets: dict[str, float], side: str | None = None) -> dict:
    """:func:`solve_subject_setup` of an axle file's model, per side."""
    return solve_subject_setup(_axle_model(axle), targets, side)
