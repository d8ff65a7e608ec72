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

from .. import __version__
from ..constraints import JointTarget, PointTarget
from ..errors import InputError
from ..maths.vectors import roll_centre  # noqa: F401 (sensitivity's, as it was)
from ..model.compose import compose_tree, prefixed  # noqa: F401 (prefixed: as it was)
from ..model.geometry import Geometry, summary_repr
from ..model.mechanisms import xml_name
from ..model.tree import Tree
from ..solve.bulk import MIN_STEPS
from ..solve.linkage import Linkage
from ..solve.solver import NewtonSolver
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
from .corner import Results
from .elements import elements_of
from .elements.anti_roll_bar import AntiRollBar
from .elements.wheel_pair import WheelPair


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

    c_factor_key = "axle_config.steering.c_factor"  # docs/axle.md

    labels = SIDES
    # every command but export, which writes one corner's points (docs/interop.md); a
    # vehicle takes these too (Vehicle.commands)
    commands = (
        "sweep",
        "attitude",
        "urdf",
        "mjcf",
        "validate",
        "view",
        "draw",
        "loads",
        "setup",
        "sensitivity",
        "study",
        "clearance",
        "envelope",
        "kc",
    )
    motion_at_once_from = MIN_STEPS  # linkage.Composed.label_motion
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

    def __init__(
        self, left, right: Geometry | None = None, name: str = "axle", visuals: bool = True
    ):
        """An axle file (a path or its data), an AxleGeometry, or two corners' geometries;
        ``visuals``: the URDF's drawn shapes (a study's variant goes without)."""
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
        from ..solve.as_set import apply_setup

        left, right = apply_setup(left), apply_setup(right)
        self.geometries = self.corners = dict(zip(SIDES, (left, right), strict=True))
        # the shared elements (pin_susp/elements/): the bar (none without one), the heave link
        self.elements = elements_of(elements) if elements is not None else []
        self.bar = self.elements[0] if self.elements else AntiRollBar(None)
        self.shared = (WheelPair(), *self.elements)  # what reads its sweep's targets
        comment = f"generated by pin_susp {__version__}: an axle"
        self._compose(self.geometries, self.elements, xml_name(name, "axle"), comment, visuals)
        self.point_names = self.corner_points
        self.frame_names = [n for n in self.output_points if "contact_patch_center" not in n]
        self._drivers()
        self.kin.update(self.q_design)
        if elements is not None:
            self._check_determined(elements.source)
        self.steering  # noqa: B018 (its c-factor checked as its file is read)
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

    @property
    def sha256(self) -> str | None:
        return self.axle.sha256 if self.axle is not None else None

    def _check_determined(self, source: str) -> None:
        """Both wheel heights and the rack must fix the pose at design (the closures
        with them of full rank): else a part turns freely — a droplink square to its
        bar arm's motion (dead centre), a bar axis along a droplink."""
        s = np.linalg.svd(self.drive_rows_at_design(), compute_uv=False)
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


# ---------------------------------------------------------------- columns


class AxleResults(Results):
    """Columns of a solved axle sweep (docs/axle.md, "Columns"), in output units; written
    as a corner's are (io.tables.csv_text): ``results["camber_left"]``,
    ``results.to_pandas()``, ``results.to_csv(path)``, ``results.plot(path)``."""


def axle_results(model: AxleModel, sweep, solutions: list) -> AxleResults:
    """Every corner column per side (suffix ``_left``/``_right``, derivatives along
    that side's wheel-centre z and the rack, the other wheel held), the axle's
    columns, then the points (``left_…``, ``right_…``, the bar's):
    ``model.sweep_results`` (assembly.py).

    >>> results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    >>> results.to_pandas()  # a DataFrame, a row per step (model.run_sweep does both)
    """
    return model.sweep_results(sweep, solutions)
