"""An axle: two corners on one chassis, one rack, one Pinocchio model (docs/axle.md).

Each corner's tree (its mechanism module's) is prefixed by its side — ``left_upright``,
``left_upper_ball_joint``, ``left_wheel_center`` — and both hang from one chassis with
one rack (compose.py); the shared elements — the anti-roll bar, the heave link — add
their parts, one module each (pin_susp/elements/). The model is parsed from the
composed URDF like a corner's (:class:`linkage.Built`). The axle file is read by
axle_file.py (its names are importable from here too).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import __version__
from .axle_file import (  # noqa: F401 (the axle file's names, as they were)
    ANTI_ROLL,
    AXLE_KEYS,
    CENTER,
    HEAVE_LINK,
    SIDE_EXTRAS,
    SIDES,
    VEHICLE_KEYS,
    AxleAssembly,
    AxleGeometry,
    AxleReader,
    load_axle,
    mirror_corner,
)
from .bulk import MIN_STEPS
from .compose import compose_tree, prefixed  # noqa: F401 (prefixed: as it was)
from .constraints import (
    JointTarget,
    PointTarget,
)
from .corner import Results
from .elements import elements_of, rack
from .elements.anti_roll_bar import AntiRollBar
from .elements.wheel_pair import WheelPair
from .errors import InputError
from .geometry import Geometry, summary_repr
from .linkage import Linkage
from .mechanisms import xml_name
from .solver import NewtonSolver
from .tree import Tree
from .vectors import roll_centre  # noqa: F401 (sensitivity's, as it was)


def axle_tree(left: Geometry, right: Geometry, name: str = "axle", elements=None) -> Tree:
    """Both corners' trees under one chassis, the rack shared (compose.compose_tree);
    ``elements`` (an AxleGeometry) adds the anti-roll bar and the heave link's points."""
    trees = {side: g.mechanism.tree(g) for side, g in zip(SIDES, (left, right), strict=True)}
    return compose_tree(trees, name, () if elements is None else elements_of(elements))


class AxleModel(AxleAssembly):
    """The composed model: its URDF, Pinocchio model, points (``left_…``, ``right_…``,
    contact patches included), closures and branches, at the design state.

    ``AxleModel(axle)`` for an axle file (a path or a dict, read by ``load_axle``) or
    an AxleGeometry (its bar and heave link included), or ``AxleModel(left, right)``
    for two corner Geometries. ``pin_susp.Axle`` is the same class.

    >>> axle = pin_susp.Axle("examples/axle_front.yaml")
    >>> axle
    <AxleModel 'axle_front.yaml' 'front axle with U-bar': double_wishbone, 2 corners, ...>
    >>> results = axle.run_sweep("examples/roll.yaml")
    >>> results["roll_center_z"], results["camber_left"]  # mm, deg: numpy arrays
    >>> results.to_pandas()  # a DataFrame, a row per step; results.plot("axle.png")

    ``axle.geometries["left"]`` is each side's as-set Geometry (m; its
    ``hardpoints_mm`` in mm), ``axle.axle`` the AxleGeometry (None for two corners).
    As an Assembly (assembly.py): labels ``left``, ``right``; ``corners`` the geometries.
    """

    labels = SIDES
    motion_at_once_from = MIN_STEPS  # linkage.Composed.label_motion
    kind = "axle"
    refuses = ("repeats",)
    checks_counts_first = False  # its counts checked when solved (after loads' own)
    tangents_by_drivers = True  # the numbers it always had

    @property
    def results_class(self) -> type:
        return AxleResults

    @property
    def needs(self) -> str:
        """What its sweep's targets must be, as its count's error says."""
        if self.anti_roll_rigid:
            return (
                "its anti-roll bar is rigid, so it only heaves: heave or one wheel height; "
                "and the rack"
            )
        return "a wheel height per side, or heave and roll; and the rack"

    def undetermined(self, targets) -> str:
        """The error of targets that do not fix its pose at design."""
        return "the targets do not fix the axle's pose at its design state"

    def __init__(self, left, right: Geometry | None = None, name: str = "axle"):
        elements = None
        if right is None and not isinstance(left, AxleGeometry):  # an axle file
            left = load_axle(left)
        if right is None:  # an AxleGeometry
            elements, name = left, left.name
            left, right = elements.left, elements.right
        self.axle, self.name = elements, name
        self.source = elements.source if elements is not None else "<geometries>"
        self.anti_roll_rigid = elements is not None and elements.anti_roll_rigid
        # shims and length adjusters first, per side: the as-set corners (as Corner does)
        from .as_set import apply_setup

        left, right = apply_setup(left), apply_setup(right)
        self.geometries = self.corners = dict(zip(SIDES, (left, right), strict=True))
        # the shared elements (pin_susp/elements/): the bar (none without one), the heave link
        self.elements = elements_of(elements) if elements is not None else []
        self.bar = self.elements[0] if self.elements else AntiRollBar(None)
        self.shared = (WheelPair(), *self.elements)  # what reads its sweep's targets
        comment = f"generated by pin_susp {__version__}: an axle"
        self._compose(self.geometries, self.elements, xml_name(name, "axle"), comment)
        self.point_names = self.corner_points
        self.frame_names = [n for n in self.output_points if "contact_patch_center" not in n]
        self._drivers()
        self.kin.update(self.q_design)
        if elements is not None:
            self._check_determined(elements.source)
        self.design_steer = {}
        for side, g in self.geometries.items():
            d = self.design_positions
            a = d[f"{side}_axle_outboard"] - d[f"{side}_axle_inboard"]
            self.design_steer[side] = -g.sign * np.degrees(np.arctan2(a[0], g.sign * a[1]))
        self.spring_sense = {
            side: (Linkage(g).spring_sense if g.spring == "torsion_bar" else 1.0)
            for side, g in self.geometries.items()
        }

    def __repr__(self) -> str:
        def parts():
            g = self.geometries["left"]
            a = self.axle
            return (
                self.source,
                self.name,
                g.type,
                f"{len(self.geometries)} corners",
                g.steering,
                "pushrod_rocker" if g.actuation == "pushrod_rocker" else "",
                "" if g.spring == "none" else g.spring,
                "" if a is None or a.anti_roll == "none" else f"anti-roll {a.anti_roll}",
                "" if a is None or a.heave_link == "none" else f"heave link {a.heave_link}",
                f"{self.mobility} inputs",
            )

        return summary_repr(self, parts)

    def held_sweep(self, sweep):
        """The sweep as its steps hold it (``held_targets``): the sweep itself where
        nothing is held."""
        targets = self.held_targets(sweep.targets)
        return sweep if len(targets) == len(sweep.targets) else replace(sweep, targets=targets)

    def _check_determined(self, source: str) -> None:
        """Both wheel heights and the rack must fix the pose at design (the closures
        with them of full rank): else a part turns freely — a droplink square to its
        bar arm's motion (dead centre), a bar axis along a droplink."""
        solver = NewtonSolver(self.kin, self.closures, _drive_rows(self), self.branches)
        solver.evaluate(self.q_design)
        s = np.linalg.svd(solver.jacobian, compute_uv=False)
        if s[-1] <= 1e-9 * s[0]:
            raise InputError(
                source,
                "hardpoints",
                "the wheels and the rack do not fix the axle's pose at design: a part turns "
                "freely (a droplink square to its bar arm's motion — at dead centre — or "
                "in line with the bar's axis?)",
            )

    def motion(self, qs: list, solutions: list | None = None) -> dict:
        """Every point (prefixed) at each configuration (None: NaN), as a jet.Dual per
        side: its rates along that side's hub z and the rack (or its toe link);
        ``solutions``: the sweep's, whose exact tangents spare a solve per step."""
        tangents = None if solutions is None else [s.drive_tangent for s in solutions]
        return self.label_motion(qs, tangents)

    def side_positions(self, q: np.ndarray, side: str) -> dict[str, np.ndarray]:
        """One corner's points at q, by their corner names."""
        all_points = self.positions(q)
        return {n: all_points[f"{side}_{n}"] for n in self.point_names[side]}

    def solve(self, wheel_center_z: dict[str, float], rack: float = 0.0, q0=None):
        """A pose with each wheel centre at a height (m, absolute) and the rack at a
        displacement (m): the heave/roll drivers."""
        targets = [
            PointTarget(self.points[f"{side}_wheel_center"], np.array([0.0, 0.0, 1.0]), value)
            for side, value in wheel_center_z.items()
        ]
        if self.model.existJointName("rack_slide"):
            targets.append(JointTarget(self.model, "rack_slide", rack))
        goal = np.array([t.value for t in targets])
        q = self.q_design if q0 is None else q0
        self.kin.update_positions(q)
        start = np.array([t.residual(self.kin)[0] + t.value for t in targets])  # at q
        solver = NewtonSolver(self.kin, self.closures, targets, self.branches)
        return solver.solve(q, start, goal)

    # Assembly surface for sweep: its summary's columns, the axle's and each side's main
    summary_columns = tuple(
        "heave roll body_roll camber_left camber_right camber_to_ground_left "
        "camber_to_ground_right roadwheel_angle_left roadwheel_angle_right roll_center_y "
        "roll_center_z track ride_height_change arb_twist heave_link_length ackermann "
        "roll_stiffness arb_wheel_rate".split()
    )

    # Assembly surface for loads, viz and drawing
    markers = ("roll_centre",)  # from roll_center_y, _z

    @property
    def spring_senses(self) -> dict[str, float]:
        return self.spring_sense

    @property
    def shared_springs(self) -> tuple:
        bar = self.axle
        if bar is None or bar.anti_roll == "none" or bar.anti_roll_rigid:
            return ()
        u_bar = ("left_arb_arm_pivot", "right_arb_arm_pivot")
        return (
            (u_bar if bar.anti_roll == "u_bar" else ("t_bar_pivot_b",), bar.anti_roll_stiffness),
        )

    def sweep_results(self, sweep, solutions: list, tangents=None, only=None) -> AxleResults:
        return axle_results(self, sweep, solutions)

    def with_corners(self, corners: dict[str, Geometry]) -> AxleModel:
        if self.axle is None:
            return AxleModel(corners["left"], corners["right"])
        return AxleModel(replace(self.axle, **corners))


Axle = AxleModel  # pin_susp.Axle, as pin_susp.Corner: an axle file → a model to sweep


# ---------------------------------------------------------------- sweeps

Z = np.array([0.0, 0.0, 1.0])


def axle_rows(model: AxleModel, targets, source: str = "<targets>") -> list:
    """The solver's rows for a sweep's targets on an axle (one value each, set later):
    ``model.target_rows`` (assembly.py)."""
    return model.target_rows(targets, source)


def target_values(model: AxleModel, targets) -> np.ndarray:
    """Each step's target values in SI: heave m, roll rad, points m (absolute):
    ``model.target_values``."""
    return model.target_values(targets)


def solve_axle_sweep(model: AxleModel, sweep, source: str | None = None, progress=None) -> list:
    """Solve every step in order, each from the last solution (halving on failure);
    the targets must fix the pose (as many as the axle's freedoms, independent).
    ``progress(done, total)`` is called after each step: ``model.solve_steps``."""
    if source is not None and source != sweep.source:
        sweep = replace(sweep, source=source)
    return model.solve_steps(sweep, progress)


def _drive_rows(model: AxleModel) -> list:
    """The drivers of the columns' rates: each wheel centre's z, and the rack."""
    drive = [PointTarget(model.points[f"{s}_wheel_center"], Z) for s in SIDES]
    if model.model.existJointName("rack_slide"):
        drive.append(JointTarget(model.model, "rack_slide"))
    return drive


# ---------------------------------------------------------------- columns


class AxleResults(Results):
    """Columns of a solved axle sweep (docs/axle.md, "Columns"), in output units; written
    as a corner's are (io.tables.csv_text): ``results["camber_left"]``,
    ``results.to_pandas()``, ``results.to_csv(path)``, ``results.plot(path)``."""


def axle_results(model: AxleModel, sweep, solutions: list) -> AxleResults:
    """Every corner column per side (suffix ``_left``/``_right``, derivatives along
    that side's wheel-centre z and the rack, the other wheel held), the axle's
    columns, then the points (``left_…``, ``right_…``, the bar's).

    >>> results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    >>> results.to_pandas()  # a DataFrame, a row per step (model.run_sweep does both)
    """
    columns, units = AxleResults.solver_columns(solutions)
    qs = [s.q if s.converged else None for s in solutions]
    points = model.motion(qs, solutions)
    for name, (values, column_unit) in axle_metric_columns(model, points).items():
        columns[name], units[name] = values, column_unit
    plain = {k: v["left"].val for k, v in points.items()}
    for name, (values, column_unit) in _side_rates(model, plain, qs).items():
        columns[name], units[name] = values, column_unit
    for name in model.output_points:
        for i, axis in enumerate("xyz"):
            columns[f"{name}_{axis}"] = plain[name][:, i] * 1e3
            units[f"{name}_{axis}"] = "mm"
    source, sha = model.source, model.axle.sha256 if model.axle is not None else None
    meta = AxleResults.solver_meta(solutions, (source, sha), sweep, model)
    meta["notes"] = model.sweep_notes(sweep)
    return AxleResults(columns, units, meta)


def _side_rates(model: AxleModel, plain: dict, qs: list) -> dict:
    """Each side's spring force and wheel and ride rates where its rate is given (the
    corner's, rates.SpringRates, along its own hub z with the rack held: its corner
    posed at the side's wheel-centre height and the rack's travel at each step)."""
    from .rates import rate_columns

    out = {}
    rack = model.model.existJointName("rack_slide")
    index = model.model.joints[model.model.getJointId("rack_slide")].idx_q if rack else None
    for side, g in model.geometries.items():
        if not g.rated_spring:
            continue
        corner = Linkage(g)
        targets = [PointTarget(corner.points["wheel_center"], Z)]
        if rack:
            targets.append(JointTarget(corner.model, "rack_slide"))
        solver = NewtonSolver(corner.kin, corner.closures, targets, corner.branches)
        poses, q = [], corner.q_design
        for i, at in enumerate(qs):
            if at is None:
                poses.append(None)
                continue
            goal = [plain[f"{side}_wheel_center"][i, 2]] + ([at[index]] if rack else [])
            corner.kin.update_positions(q)
            start = np.array([t.residual(corner.kin)[0] + t.value for t in targets])
            solution = solver.solve(q, start, np.array(goal))
            q = solution.q if solution.converged else q
            poses.append(solution.q if solution.converged else None)
        for name, (values, unit_) in rate_columns(corner, poses).items():
            out[f"{name}_{side}"] = (values, unit_)
    return out


def axle_metric_columns(model: AxleModel, points: dict) -> dict:
    """name → (values, unit): each side's corner columns (suffixed), the axle's, and
    the roll derivatives, from the points of ``AxleModel.motion`` (or any engine's
    points with their rates in that form)."""
    from .metrics import metric_columns

    sides = {}
    for side, g in model.geometries.items():
        design = {k: model.design_positions[f"{side}_{k}"][None] for k in model.point_names[side]}
        own = {k: points[f"{side}_{k}"][side] for k in model.point_names[side]}
        sides[side] = metric_columns(g, own, design, model.spring_sense[side])
    out = {f"{name}_{side}": c for side, cols in sides.items() for name, c in cols.items()}
    plain = {k: v["left"].val for k, v in points.items()}
    return out | _axle_metrics(model, plain, sides) | _roll_rates(model, points, sides)


def _roll_rates(model: AxleModel, points: dict, sides: dict) -> dict:
    """Exact derivatives along roll: the left wheel centre up and the right one down
    equally, the rack held (docs/axle.md): camber and toe per side (deg/deg), the
    U-bar's twist per side's hub z, and the roll centre's migration (mm/deg).

    With h the antisymmetric wheel-centre move, roll = atan2(a, b), a = Δz_L − Δz_R,
    b = CP_y,L − CP_y,R, so dθ/dh = (2b − a·(ḃ_L + ḃ_R)) / (a² + b²), where ḃ_side
    is that side's contact patch y rate along its own hub z (the sides meet only at
    the rack). A side's metric then moves at ±(d metric/d hub z) / (dθ/dh).
    """
    from .jet import Dual
    from .metrics import PointSet, fvic_y, fvic_z

    cp = {s: points[f"{s}_contact_patch_center"][s] for s in SIDES}
    wc = {s: points[f"{s}_wheel_center"][s].val[:, 2] for s in SIDES}
    d = model.design_positions
    a = (wc["left"] - d["left_wheel_center"][2]) - (wc["right"] - d["right_wheel_center"][2])
    b = cp["left"].val[:, 1] - cp["right"].val[:, 1]
    rate = {s: cp[s].der[0][:, 1] for s in SIDES}  # d CP_y / d own hub z
    dtheta = (2.0 * b - a * (rate["left"] - rate["right"] * -1.0)) / (a * a + b * b)
    # per side: m of its own hub z per radian of roll (+ left, − right)
    per_rad = {"left": 1.0 / dtheta, "right": -1.0 / dtheta}
    deg = np.pi / 180.0
    out = {}
    for side in SIDES:
        for name in ("camber", "roadwheel_angle"):
            gain = sides[side][f"deriv_{name}_wrt_hub_z"][0] * 1e3  # deg per m
            out[f"deriv_{name}_wrt_roll_{side}"] = (gain * per_rad[side] * deg, "deg/deg")
    # the roll centre as a function of both sides' CP and FVIC, pushed along roll
    parts = []
    for s in SIDES:
        g = model.geometries[s]
        own = {k: points[f"{s}_{k}"][s] for k in model.point_names[s]}
        design = {k: d[f"{s}_{k}"][None] for k in model.point_names[s]}
        ps = PointSet(own, design, g)
        with np.errstate(invalid="ignore", divide="ignore"):
            values = (cp[s][..., 1], cp[s][..., 2], fvic_y(ps), fvic_z(ps))
        # Dual over one direction, roll (rad): d/dθ = d/d(own hub z) · per_rad
        parts.append(tuple(Dual(v.val * 1e3, v.der[0] * per_rad[s] * 1e3) for v in values))
    with np.errstate(invalid="ignore", divide="ignore"):
        rc = roll_centre(parts)
    out["deriv_roll_center_y_wrt_roll"] = (rc[0].der * deg, "mm/deg")
    out["deriv_roll_center_z_wrt_roll"] = (rc[1].der * deg, "mm/deg")
    out |= model.bar.rate_columns(model, points)
    return out | _roll_stiffness(model, sides, out, per_rad)


def _roll_stiffness(model: AxleModel, sides: dict, rates: dict, per_rad: dict) -> dict:
    """Where the springs' rates (and a bar's stiffness) are given: ``roll_stiffness``
    (N·m/deg) = Σ springs' k·(dℓ/dφ)² + the bar's k·(dθ/dφ)², and ``arb_wheel_rate``
    (N/mm), the bar's rate at each wheel in roll (one up, the other down): ½·k·(dθ/dh)²."""
    axle = model.axle
    if any(model.geometries[s].spring_rate is None for s in SIDES):
        return {}
    if axle is not None and axle.anti_roll != "none":
        if axle.anti_roll_rigid or axle.anti_roll_stiffness is None:
            return {}  # a locked bar does not roll; without its stiffness: unknown
    total, out = 0.0, {}
    for side in SIDES:
        g = model.geometries[side]
        if g.spring == "torsion_bar":  # wind-up rate deg/mm → rad/m, k N·m/deg → N·m/rad
            turn = np.radians(sides[side]["deriv_torsion_bar_twist_wrt_hub_z"][0]) * 1e3
            k = g.spring_rate * 180.0 / np.pi
        else:  # length rate mm/mm, k N/mm → N/m
            turn, k = sides[side]["deriv_damper_length_wrt_hub_z"][0], g.spring_rate * 1e3
        total = total + k * (turn * per_rad[side]) ** 2
    bar = model.bar.roll_term(rates, per_rad)
    if bar is not None:
        total = total + bar[0]
        out["arb_wheel_rate"] = bar[1]
    out["roll_stiffness"] = (total * np.pi / 180.0, "N·m/deg")
    return out


def _axle_metrics(model: AxleModel, p: dict, sides: dict) -> dict:
    """heave, roll, body_roll, camber to ground, ride height, track, roll centre, rack,
    steer angles and Ackermann, the U-bar's arm angles and twist, the heave link."""
    d = {k: v[None] for k, v in model.design_positions.items()}
    dz = {s: p[f"{s}_wheel_center"][:, 2] - d[f"{s}_wheel_center"][:, 2] for s in SIDES}
    cp = {s: p[f"{s}_contact_patch_center"] for s in SIDES}
    track = cp["left"][:, 1] - cp["right"][:, 1]
    out = {
        "heave": (0.5 * (dz["left"] + dz["right"]) * 1e3, "mm"),
        "roll": (np.degrees(np.arctan2(dz["left"] - dz["right"], track)), "deg"),
    }
    body_roll = np.degrees(np.arctan2(cp["right"][:, 2] - cp["left"][:, 2], track))
    out["body_roll"] = (body_roll, "deg")
    for side, s in (("left", 1.0), ("right", -1.0)):
        camber = sides[side]["camber"][0]
        out[f"camber_to_ground_{side}"] = (camber - s * body_roll, "deg")
    cp0 = {s: d[f"{s}_contact_patch_center"][:, 2] for s in SIDES}
    change = -0.5 * ((cp["left"][:, 2] - cp0["left"]) + (cp["right"][:, 2] - cp0["right"]))
    out["ride_height_change"] = (change * 1e3, "mm")
    out["track"] = (np.abs(track) * 1e3, "mm")
    rc = roll_centre(
        [
            (cp[s][:, 1] * 1e3, cp[s][:, 2] * 1e3, sides[s]["fvic_y"][0], sides[s]["fvic_z"][0])
            for s in SIDES
        ]
    )
    out["roll_center_y"], out["roll_center_z"] = (rc[0], "mm"), (rc[1], "mm")
    travel = rack.travel(p, d)
    out |= rack.columns(travel)
    steer = {}
    for side, s in (("left", 1.0), ("right", -1.0)):
        steer[side] = -s * sides[side]["roadwheel_angle"][0]
        out[f"steer_angle_{side}"] = (steer[side], "deg")
    ackermann = _ackermann(model, steer, track)
    if travel is None:  # no rack: no steering input
        ackermann[:] = np.nan
    else:  # bump or roll steer alone is not steering: blank with the rack at centre
        ackermann[np.abs(travel) < 1e-6] = np.nan
    out["ackermann"] = (ackermann, "%")
    for element in model.elements:
        out |= element.columns(model, p, d)
    return out


def _ackermann(model: AxleModel, steer: dict, track: np.ndarray) -> np.ndarray:
    """100·(δ_i − δ_o)/(δ_i* − δ_o) from the steer angles' change from design; blank for
    |δ_o| < 0.5° or without a wheelbase."""
    wheelbase = model.geometries["left"].wheelbase
    n = len(track)
    if wheelbase is None:
        return np.full(n, np.nan)
    design = model.design_steer
    delta = {s: np.abs(steer[s] - design[s]) for s in SIDES}
    left_inner = (steer["left"] + steer["right"]) > 0.0
    inner = np.where(left_inner, delta["left"], delta["right"])
    outer = np.where(left_inner, delta["right"], delta["left"])
    with np.errstate(invalid="ignore", divide="ignore"):
        o = np.radians(outer)
        ideal = np.degrees(np.arctan2(wheelbase, wheelbase / np.tan(o) - np.abs(track)))
        out = 100.0 * (inner - outer) / (ideal - outer)
    return np.where(outer >= 0.5, out, np.nan)
