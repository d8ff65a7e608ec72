"""What the analyses ask every subject (README, How it works): the defaults of an
Assembly's answers to its exported model and the validation's engines, setup,
drawings and hardpoint sensitivities, for a corner; an
axle's own answers are in axle_file.AxleAssembly. Kept apart from assembly.py, whose
job is the subject's targets, sweep and columns.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import InputError


class AnalysesSurface:
    """The analyses' questions to an :class:`~pin_susp.subjects.assembly.Assembly`, with a
    corner's answers as the defaults (``labels``, ``corners``, ``source`` and
    ``solve_sweep`` are the Assembly's)."""

    # -- the exported model and the validation's engines (urdf, mjcf, validate) ---

    @property
    def export_tree(self):
        """The tree its URDF and MJCF are written from (docs/urdf.md): its model's own (a
        vehicle's: its body floating, without the road and the body's joints)."""
        return self.tree

    @property
    def export_urdf(self) -> str:
        """The URDF ``pin-susp urdf`` writes and the Drake engine reads: its model's own."""
        return self.urdf

    def engine_steps(self, sweep) -> list[list] | None:
        """Every step's targets as the validation's engines take them where its sweep's
        own are not (validate/scopes.py reads those: a point's, an axle's heave and
        roll): a vehicle's, its body's pose first (a BodyPose) and each target a
        (point, unit direction, value m) in the road's frame. None: its sweep's."""
        return None

    def engine_moves(self, sweep) -> list[dict]:
        """Every step's targets with each of its body's quantities moved a little (a
        vehicle's heave, pitch and roll: quantity → (h, the steps at −2h, −h, +h, +2h)),
        for the engines' rates along them: none."""
        return [{} for _ in range(sweep.steps)]

    def road_columns(self, road: dict, points: dict, columns: dict) -> dict:
        """Its columns an engine's points give beyond the metric columns (name → (values
        (1,), unit)), from ``road`` (the points where the engine solved them, m),
        ``points`` (a Dual per label, as its sweep measures them; ``points.along``: the
        wheel centres' rates along ``engine_moves``) and the metric ``columns``: none (a
        vehicle's body: what the road sees, the rates along the body)."""
        return {}

    # -- setup and sensitivity (setup.py, sensitivity.py, their commands) ----------

    @classmethod
    def as_drawn(cls, path, label: str | None = None):
        """The subject of a geometry file as the file draws it, for the setup analyses:
        its labels, its corners as drawn, its source, name and setup answers, but no
        model built and no setup applied (a setup that cannot be applied is the setup
        analysis's to report). ``label``: a setup option's (``--side``), refused here
        where the kind has no such label, before the file is read further."""
        raise NotImplementedError

    @property
    def drawn_corners(self) -> dict:
        """label → the corner's Geometry as drawn, with its setup values (its shim stack
        and length deltas as the file gives them): what the setup analyses vary."""
        return {label: g.drawn or g for label, g in self.corners.items()}

    def setup_labels(self, label: str | None = None) -> tuple[str, ...]:
        """The labels a setup option sets (``--side``): every corner's, or ``label``'s
        alone."""
        if label is None:
            return self.labels
        if label not in self.labels:
            known = " or ".join(self.labels)
            raise InputError("--side", "", f"unknown side {label!r} ({known})")
        return (label,)

    def setup_owner(self, label: str) -> str:
        """The label whose setup a corner takes: its own (a mirrored axle's right side:
        the left's)."""
        return label

    def file_key(self, label: str, key: str) -> str:
        """A key of a corner's setup as the subject's file names it (a corner's own file:
        as it is)."""
        return key

    def setup_error(self, label: str, exc: InputError) -> InputError:
        """A corner's setup error as the subject reports it: a labelled corner's names its
        label, and its file's key as the file spells it."""
        if not label:
            return exc
        key = self.file_key(label, exc.key) if exc.source == self.source else exc.key
        return InputError(exc.source, key, f"{label} corner: {exc.problem}")

    # what a setup sheet is per where the subject has labelled corners (an axle's sides)
    setup_unit: str = "side"

    def setup_place(self, label: str) -> str:
        """Where a labelled corner's setup is, as its setup sheet says: its file's key."""
        return self.file_key(label, "config.setup")

    def setup_data(self, geometries: dict) -> dict:
        """The subject's file data with each given corner's setup (label → Geometry)
        written in."""
        raise NotImplementedError

    def setup_files(self, geometries: dict, path) -> list[tuple]:
        """The files a solved setup writes, (path, data): the subject's file at ``path``
        (``setup_data``; a vehicle's axle files beside it too)."""
        return [(path, self.setup_data(geometries))]

    # the heading of its own static columns in a setup sheet (``static_columns``)
    static_heading: str = "axle (both sides as set in each row)"

    def static_results(self, corners: dict) -> dict[str, float]:
        """Its own static columns (``static_columns``, mm) with its corners as given
        (label → Geometry with its setup values): the subject at its design state."""
        from ..model.sweep import Sweep
        from ..solve.solver import Solution

        model = self.with_corners(corners)
        solution = Solution(model.q_design, True, 0, 0.0)
        results = model.sweep_results(Sweep([], "<static state>"), [solution])
        return {name: float(results[name][0]) for name, _ in self.static_columns}

    # -- drawings (drawing.py, pin-susp draw) ----------------------------------------

    # the views its drawing shows: a corner's front and side; the front alone where its
    # corners stand side by side on one road (an axle's: the roll centre where each
    # contact patch's line through its instant centre crosses the other)
    drawing_views: tuple[str, ...] = ("front", "side")
    # whether it is drawn at a step of its sweep results too (draw --from-results), not
    # only at its design state
    drawn_at_steps: bool = False

    # -- the 3D view and the drawings at rest (scene.py, drawing.py) ---------------

    def design_results(self):
        """Its results (every column) at its design state, one row: a corner's and an
        axle's at ``q_design``, no sweep solved (a vehicle's on the road: its own)."""
        from ..model.sweep import Sweep
        from ..solve.solver import Solution

        return self.sweep_results(Sweep([]), [Solution(self.q_design, True, 0, 0.0)])

    @property
    def q_rest(self):
        """The configuration its view shows and its drawing draws at design: its
        ``q_design`` (a vehicle's: its body on the road at heave, pitch and roll 0)."""
        return self.q_design

    def marker_places(self, results) -> dict:
        """Where each of its markers (``markers``) is at every step of its results: name
        → (n, 3) m in the world's frame (the road's, for a body on it), NaN where blank.
        A corner has none."""
        return {}

    # -- hardpoint sensitivities (sensitivity.py, its command) ---------------------

    # the points its shared elements add (an axle's bar and heave link), no corner's
    # hardpoints: their sensitivities are not computed
    element_points: frozenset[str] = frozenset()
    # its own columns of its corners together that its sensitivities give, after each
    # corner's (an axle's track, roll centre, ...; a corner: none)
    sensitivity_columns: tuple[str, ...] = ()

    # the pairs of its corners whose own columns (an axle's track, roll centre, ...) its
    # sensitivities give, each (its left's label, its right's): an axle's one pair
    sensitivity_pairs: tuple[tuple[str, str], ...] = ()
    # its columns of the whole car its sensitivities give after the pairs' (a vehicle's
    # pitch centre, anti %, roll axis; ``car_sensitivities``)
    car_sensitivity_columns: tuple[str, ...] = ()

    def sensitivity_move(self, label: str, one_sided: bool = False) -> tuple[str, bool]:
        """How a labelled corner's hardpoint P is named among its sensitivities'
        directions, and whether it moves mirrored (its y reversed): an axle's P moves
        both sides' P, the right mirrored; ``one_sided``, each side's alone (left_P)."""
        if one_sided:
            return self.prefix(label), False
        return "", label == "right"

    def sensitivity_move_text(self, one_sided: bool = False) -> str | None:
        """What its sensitivities' move is, as its table and CSV say it (None: an axle's
        symmetric or one-sided move, sensitivity.py's words)."""
        return None

    def pair_column(self, pair: tuple[str, str], name: str) -> str | None:
        """An axle's column of one pair of its corners (``track``,
        ``camber_to_ground_left``) as its sensitivities name it (None: not given)."""
        return name

    def car_sensitivities(self, corners: dict, pairs: dict) -> dict:
        """Its columns of the whole car (``car_sensitivity_columns``), name → (Dual over
        the hardpoint coordinates, unit), from each corner's contact patch, wheel centre
        and side-view instant centre (``corners``: label → name → Dual, mm) and each
        pair's columns (``pairs``): none."""
        return {}

    def corner_linkage(self, label: str):
        """The Linkage of a labelled corner alone, as set: its sensitivities' model."""
        from ..solve.linkage import Linkage

        return Linkage(self.corners[label])

    def sensitivity_sweep(self, sweep) -> tuple[list, object]:
        """A sweep solved for its sensitivities: its steps' solutions, and the results the
        failure report reads (the steps without sensitivities): here every column."""
        return self.solve_sweep(sweep)

    def held_at(self, sweep, step: int) -> list | None:
        """What its sensitivities hold at a sweep's step: the sweep's targets there (None:
        each corner's wheel-centre height and rack as solved there)."""
        return [replace(t, values=t.values[step]) for t in sweep.targets]

    def sensitivities_hold(self, sweep) -> bool:
        """Whether its hardpoint sensitivities at a sweep's steps hold what the sweep
        holds: a corner's hold the sweep's own targets (``held_at``) (an axle's, each
        wheel centre's height and the rack alone)."""
        return True

    def sensitivity_held(self) -> str | None:
        """What its sensitivities hold, as its table and CSV say it (None: the sweep's
        targets, or the design's, unsaid)."""
        return None

    def sensitivity_groups(self, columns: list[str]) -> list[tuple[str, list]]:
        """The printed table's groups, (heading, columns): each labelled corner's own
        (a corner's one: every column, no heading); a corner that takes another's setup
        (a mirrored axle's right side) mirrors it, and is left out."""
        groups = []
        for label in self.labels:
            if self.setup_owner(label) == label:
                suffix = self.suffix(label)
                names = [n for n in columns if n.endswith(suffix)]
                heading = f"the {label} corner (columns suffixed {suffix}):" if label else ""
                groups.append((heading, names))
        return groups

    # -- studies (study/) -----------------------------------------------------------

    # a study's variants may be solved together (solve/stacked.py: a corner's)
    solves_stacked = False

    def sweep_and_design(self, sweep, only=None, guess=None) -> tuple[object, dict]:
        """A sweep's results and its design state's columns (name → a one-value array),
        each solved as ``pin-susp sweep`` solves it (the design: every target at its
        design value); ``only``: the columns wanted (a subject may give every one): a
        study's variant; ``guess``: a corner's (marched here, as a sweep)."""
        from ..model.sweep import Sweep

        design = Sweep([t.at_design() for t in sweep.targets], sweep.source, sweep.sha256)
        tangents, at_design = [], []
        steps = self.solve_steps(sweep, tangents=tangents)
        start = self.solve_steps(design, tangents=at_design)
        if not _alike(at_design, tangents):  # (each pass's columns by its own route)
            static = self.sweep_results(design, start, at_design or None, only).columns
            return self.sweep_results(sweep, steps, tangents or None, only), static
        # one pass of the columns over the design state and the steps: each row's numbers
        # those of a pass of its own (every column is worked out step by step; _alike)
        given = [*at_design, *tangents] or None
        return self._design_and_steps(self.sweep_results(sweep, [*start, *steps], given, only))

    @staticmethod
    def _design_and_steps(both) -> tuple[object, dict]:
        """The results of one pass over the design state (its first row) and the steps:
        the steps' results (their step_index from 0, their q and reasons theirs) and
        the design state's columns (name → a one-value array)."""
        columns = {name: v[1:] for name, v in both.columns.items()}
        columns["step_index"] = np.arange(len(both.meta["q"]) - 1)
        meta = dict(both.meta, q=both.meta["q"][1:], why=both.meta["why"][1:])
        return type(both)(columns, both.units, meta), {k: v[:1] for k, v in both.columns.items()}


def _alike(first: list, then: list) -> bool:
    """Whether two solves' tangent lists (solve_steps') take one route through
    sweep_results together: both empty, or in both each step's given, or none (each
    step's then worked out from its Jacobian, as in a pass of its own: a vehicle's rates
    along its body, solved for every row at once, to the last digit or so)."""
    if not first or not then:
        return not first and not then
    given = [t is not None for t in [*first, *then]]
    return all(given) or not any(given)
