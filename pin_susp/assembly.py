"""What every subject answers alike, a corner or an axle (README, How it works).

A subject is labelled corners and the elements they share (an axle's rack, anti-roll
bar, heave link). ``labels`` names its corners — a corner's one, ``""``; an axle's,
``"left"`` and ``"right"`` — and ``corners`` maps each label to its as-set Geometry.
A column of one corner takes its label as a suffix (``camber_left``), a point as a
prefix (``left_wheel_center``); a corner's empty label adds neither. Code that takes
a subject asks these, never which kind it holds (tests/test_one_subject.py counts the
places that still do).
"""

from __future__ import annotations

from .errors import InputError


class Assembly:
    """The surface :class:`~pin_susp.corner.Corner` and
    :class:`~pin_susp.axle.AxleModel` share.

    ``labels``: the corners' labels, in the order their columns are written;
    ``corners``: label → the as-set Geometry; ``source``: the file it was read from;
    ``name``: its name in the file; ``anti_roll_rigid``: whether an anti-roll bar locks
    the corners together (then each wheel's own height is no driver); ``streams``:
    whether a long sweep can be solved and written a chunk at a time
    (``run_sweep_chunks``); ``poses_at_steps``: whether ``pin-susp urdf --at`` can
    write the joint values of one of its sweep's steps; ``summary_columns``: the
    columns a sweep's printed summary shows, in order (None: every metric column);
    ``spring_senses``: label → the
    sense of its corner's spring (``Linkage.spring_sense``); ``shared_springs``: the
    elastic elements its corners share, each (the joints whose turn twists it, its
    stiffness in N·m/deg or None) — an axle's anti-roll bar, unless rigid;
    ``markers``: what the 3D view marks from its results' columns (an axle's
    ``roll_centre``); ``static_columns``: the columns of its corners together a setup
    sheet adds to each row (an axle's track and roll centre); ``elements``: the elements
    its corners share (pin_susp/elements/: an axle's anti-roll bar and heave link; none
    for a corner), the point-based formulation's too (pointwise.ELEMENTS); ``noun``:
    what a message calls it (``corner``, ``axle``).

    Both are a :class:`~pin_susp.linkage.Composed` too: ``tree``, ``urdf``,
    ``output_points`` (every point written, each prefixed by its label),
    ``design_positions``, ``corner_points`` (label → its corner's point names,
    unprefixed), ``driver_columns`` (label → the columns of its drivers: its hub z, the
    rack, its toe link).
    """

    labels: tuple[str, ...]
    corners: dict
    source: str
    name: str
    anti_roll_rigid: bool = False
    summary_columns: tuple[str, ...] | None = None
    streams: bool = False
    poses_at_steps: bool = False
    spring_senses: dict
    shared_springs: tuple = ()
    markers: tuple[str, ...] = ()
    # setup and sensitivity: the subject's own static columns of its corners set
    # together, (column, heading) in mm (an axle's track and roll centre; a corner: none)
    static_columns: tuple[tuple[str, str], ...] = ()
    elements: tuple = ()
    noun: str = "assembly"
    tree: object
    urdf: str
    output_points: list[str]
    design_positions: dict
    corner_points: dict
    driver_columns: dict

    @staticmethod
    def suffix(label: str) -> str:
        """A column's suffix for a corner's label: ``"_left"``; none for ``""``."""
        return f"_{label}" if label else ""

    @staticmethod
    def prefix(label: str) -> str:
        """A point's prefix for a corner's label: ``"left_"``; none for ``""``."""
        return f"{label}_" if label else ""

    @property
    def blocks(self) -> tuple[str, ...]:
        """The blocks an input given per corner is in (a load case's ``left:``,
        ``right:``): one per labelled corner; none for a corner's one, unlabelled (its
        inputs at the top)."""
        return tuple(label for label in self.labels if label)

    def check_sweep(self, sweep) -> None:
        """A sweep's target errors (an InputError naming its file), before any work."""
        raise NotImplementedError

    def solve_sweep(self, sweep, progress=None) -> tuple[list, object]:
        """Every step of a Sweep solved: the solutions and the results (run_sweep's)."""
        raise NotImplementedError

    def held_sweep(self, sweep):
        """The sweep as its steps hold it: its targets, and the rack's at design where it
        gives every other (``sweep_notes`` says so)."""
        raise NotImplementedError

    def metric_columns_of(self, points: dict) -> dict:
        """Every metric column (name → (values, unit)) from its points with their rates
        along the drivers (name → {label: jet.Dual}, as ``label_motion`` gives them, or
        an engine's): each corner's columns, suffixed by its label (an axle adds its
        own)."""
        from .metrics import metric_columns

        out = {}
        for label, g in self.corners.items():
            p, design = self.prefix(label), self.design_positions
            own = {n: points[p + n][label] for n in self.corner_points[label]}
            at = {n: design[p + n][None] for n in self.corner_points[label]}
            columns = metric_columns(g, own, at, self.spring_senses[label])
            out.update({name + self.suffix(label): c for name, c in columns.items()})
        return out

    def motion_points(self, by_label: dict) -> dict:
        """Points with a Dual per label (name → {label: Dual}, ``label_motion``'s) in the
        form its ``motion`` gives them: as they are (a corner's: its one Dual each)."""
        return by_label

    def solve_steps(self, sweep, progress=None) -> list:
        """Every step of a Sweep solved in order: the solutions (no columns)."""
        raise NotImplementedError

    def sweep_results(self, sweep, solutions: list):
        """The results (every column) of a sweep's solved steps."""
        raise NotImplementedError

    def sweep_and_design(self, sweep, only=None) -> tuple[object, dict]:
        """A sweep's results and its design state's columns (name → a one-value array),
        each solved as ``pin-susp sweep`` solves it (the design: every target at its
        design value); ``only``: the columns wanted (a subject may give every one): a
        study's variant."""
        from .sweep import Sweep

        design = Sweep([t.at_design() for t in sweep.targets], sweep.source, sweep.sha256)
        return self.solve_sweep(sweep)[1], self.solve_sweep(design)[1].columns

    def with_corners(self, corners: dict):
        """The same subject on other corners' Geometries, by label (its shared elements
        kept; each corner set up as its Geometry says): the drawings' and the 3D view's
        ghost, as drawn, under the as-set one."""
        raise NotImplementedError

    # -- setup and sensitivity (setup.py, sensitivity.py, their commands) ----------

    @classmethod
    def as_drawn(cls, path, label: str | None = None) -> Assembly:
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

    def setup_data(self, geometries: dict) -> dict:
        """The subject's file data with each given corner's setup (label → Geometry)
        written in."""
        raise NotImplementedError

    # -- drawings (drawing.py, pin-susp draw) ----------------------------------------

    # the views its drawing shows: a corner's front and side; the front alone where its
    # corners stand side by side on one road (an axle's: the roll centre where each
    # contact patch's line through its instant centre crosses the other)
    drawing_views: tuple[str, ...] = ("front", "side")
    # whether it is drawn at a step of its sweep results too (draw --from-results), not
    # only at its design state
    drawn_at_steps: bool = False

    # -- hardpoint sensitivities (sensitivity.py, its command) ---------------------

    # the points its shared elements add (an axle's bar and heave link), no corner's
    # hardpoints: their sensitivities are not computed
    element_points: frozenset[str] = frozenset()
    # its own columns of its corners together that its sensitivities give, after each
    # corner's (an axle's track, roll centre, ...; a corner: none)
    sensitivity_columns: tuple[str, ...] = ()

    def corner_linkage(self, label: str):
        """The Linkage of a labelled corner alone, as set: its sensitivities' model."""
        from .linkage import Linkage

        return Linkage(self.corners[label])

    def sensitivity_sweep(self, sweep) -> tuple[list, object]:
        """A sweep solved for its sensitivities: its steps' solutions, and the results the
        failure report reads (the steps without sensitivities): here every column."""
        return self.solve_sweep(sweep)

    def held_at(self, sweep, step: int) -> list | None:
        """What its sensitivities hold at a sweep's step: the sweep's targets there (None:
        each corner's wheel-centre height and rack as solved there)."""
        from dataclasses import replace

        return [replace(t, values=t.values[step]) for t in sweep.targets]

    def sensitivities_hold(self, sweep) -> bool:
        """Whether its hardpoint sensitivities at a sweep's steps hold what the sweep
        holds: a corner's hold the sweep's own targets (``held_at``) (an axle's, each wheel centre's
        height and the rack alone)."""
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
