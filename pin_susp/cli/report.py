"""The report every command prints through: a sweep's summary (a corner's and an
axle's), the Digest it is drawn from (gathered a chunk at a time, so a streamed sweep
keeps no rows), step lists, the plausibility warnings (a rocker near over-centre, a
spring that would unseat), the failure report and its exit code, the progress bar, and
the warnings printed after a run.

Numpy and the package's modules are imported inside the functions that use them:
importing this module costs no numerics (tests/test_startup.py).
"""

from __future__ import annotations

import math
import sys
import warnings

from ..errors import EXIT_LIMIT, EXIT_NOT_CONVERGED, PlausibilityWarning

# Instant-centre columns: past this (mm) the arms are all but parallel and the
# centre is better described as "at infinity" than by a number.
FAR = 1e5


CENTRES = ("svic_x", "svic_z", "fvic_y", "fvic_z", "svsa_length", "fvsa_length")


# Rocker transmission angle outside this band (deg): the rocker nears over-centre.
TRANSMISSION_BAND = (30.0, 150.0)


# Beyond the metrics, the columns the summary shows where a sweep has them.
SUMMARY_EXTRA = (
    "deriv_camber_wrt_hub_z",
    "deriv_roadwheel_angle_wrt_hub_z",
    "motion_ratio",
    "spring_force",
    "spring_torque",
    "wheel_rate",
    "ride_rate",
    "steering_wheel_angle",
    "steering_ratio",
    "ackermann",
    "turning_radius",
)


SIDES = (("", ""), ("_left", "left "), ("_right", "right "))


class Steps:
    """Step numbers as a report names them: the first few, and how many in all (a sweep
    of millions of steps keeps no more)."""

    SHOWN = 10

    def __init__(self):
        self.first: list[int] = []
        self.count = 0

    def add(self, steps) -> None:
        room = self.SHOWN + 1 - len(self.first)  # one more than shown: "..." follows
        if room > 0:
            self.first += [int(i) for i in steps[:room]]
        self.count += len(steps)

    def __str__(self) -> str:
        return step_list(self.first)

    def __eq__(self, other) -> bool:
        return isinstance(other, Steps) and (self.first, self.count) == (other.first, other.count)


class Digest:
    """What the summary, the warnings and the failure report need from a sweep's
    results, gathered a chunk at a time (``add``): a streamed sweep keeps no rows.
    Steps are the results' ``step_index``."""

    def __init__(self):
        self.steps = self.converged = 0
        self.max_residual = math.nan
        self.iterations = []  # how many steps took each count of iterations
        self.units: dict[str, str] = {}
        # name → [first, last, min, max, far step, |far|, blank steps]
        self.stats: dict[str, list] = {}
        # Steps are kept as Steps: the first few, and how many (a report names no more).
        self.short = Steps()  # out of reach or past a lock-up
        self.worst_short = 0.0  # their largest residual, mm
        self.flipped = Steps()  # on another assembly branch
        self.loops: set[str] = set()  # the loops that flipped
        # side → [Steps outside, worst step, its angle, |motion ratio| there (None: no
        # ratio)]; side → [the angle nearest 90°, |motion ratio| there]: which way the
        # ratio goes as the rocker nears over-centre
        self.band: dict[str, list] = {}
        self.nearest: dict[str, list] = {}
        self.dead: list = []  # the links near dead centre at design (deadcentre.Transmission)
        # side → [Steps below zero, least force, those in droop (or at design), in bump,
        # extending in bump (past over-centre)]
        self.unseat: dict[str, list] = {}
        self.notes: list[str] = []  # how the sweep's targets were read (the rack held)
        # (limit, corner suffix) → [Steps past it, worst |value| there (the driveshaft's)],
        # from limit_exceeded (docs/results.md, "Travel limits"); steps past a hard one
        self.limits: dict[tuple, list] = {}
        self.past_hard = Steps()

    @classmethod
    def of(cls, results) -> Digest:
        if isinstance(results, Digest):
            return results
        digest = cls()
        digest.add(results)
        return digest

    def add(self, results) -> None:
        import numpy as np

        from ..columns.metrics import METRICS

        steps = np.asarray(results["step_index"])
        ok = np.asarray(results["solver_converged"], dtype=bool)
        residual = np.asarray(results["solver_max_residual"], dtype=float)
        self.steps += len(steps)
        self.converged += int(ok.sum())
        if len(steps):
            self.max_residual = np.nanmax(np.r_[self.max_residual, residual])
        counts = np.bincount(np.asarray(results["solver_iterations"], dtype=int)).tolist()
        self.iterations += [0] * (len(counts) - len(self.iterations))
        for i, count in enumerate(counts):
            self.iterations[i] += count
        for note in results.meta.get("notes", ()):
            if note not in self.notes:
                self.notes.append(note)
        why = results.meta["why"]
        if not self.dead:
            self.dead = list(results.meta.get("dead_centres", ()))
        for i in np.flatnonzero(~ok):
            if "branch" in why[i]:
                self.flipped.add([int(steps[i])])
                self.loops.add(why[i].rpartition(" of ")[2])
            else:
                self.short.add([int(steps[i])])
                self.worst_short = max(self.worst_short, float(residual[i]))
        names = [m.name for m in METRICS if m.written] + list(SUMMARY_EXTRA)
        for name in names:
            if name in results.columns and len(steps):
                self._column(name, np.asarray(results[name], dtype=float), steps)
                self.units[name] = results.units[name]
        low, high = TRANSMISSION_BAND
        for suffix, side in SIDES:
            angle = results.columns.get(f"rocker_transmission_angle{suffix}")
            if angle is not None:
                ratio = results.columns.get(f"motion_ratio{suffix}")

                def at(i, ratio=ratio):
                    return None if ratio is None or np.isnan(ratio[i]) else abs(float(ratio[i]))

                off = np.abs(angle - 90.0)
                solved = np.flatnonzero(~np.isnan(off))
                if len(solved):
                    best = solved[np.argmin(off[solved])]
                    near = self.nearest.get(side)
                    if near is None or off[best] < abs(near[0] - 90.0):
                        self.nearest[side] = [float(angle[best]), at(best)]
                outside = np.flatnonzero((angle < low) | (angle > high))
                if len(outside):
                    worst = outside[np.argmax(off[outside])]
                    band = self.band.setdefault(side, [Steps(), None, 90.0, None])
                    band[0].add(steps[outside])
                    if off[worst] > abs(band[2] - 90.0):
                        band[1:4] = int(steps[worst]), float(angle[worst]), at(worst)
            force = results.columns.get(f"spring_force{suffix}")
            if force is not None and np.nanmin(force, initial=np.inf) < 0.0:
                unseat = self.unseat.setdefault(side, [Steps(), np.inf, Steps(), Steps(), False])
                below = force < 0.0
                unseat[0].add(steps[np.flatnonzero(below)])
                unseat[1] = min(unseat[1], float(np.nanmin(force)))
                travel = results.columns.get(f"wheel_travel{suffix}")
                bump = below & (travel > 0.0) if travel is not None else np.zeros_like(below)
                unseat[2].add(steps[np.flatnonzero(below & ~bump)])  # droop, or at design
                unseat[3].add(steps[np.flatnonzero(bump)])
                ratio = results.columns.get(f"motion_ratio{suffix}")
                if ratio is not None:  # extending in bump: past over-centre
                    unseat[4] |= bool(np.any(bump & (ratio <= 0.0)))

        self._limits(results, steps)

    def _limits(self, results, steps) -> None:
        """The steps past each limit a ``limit_exceeded`` column names (each corner's)."""
        import numpy as np

        from ..columns.packaging import HARD_LIMITS, LIMIT_COLUMN, SOFT_LIMITS, exceeded

        hard = np.zeros(len(steps), dtype=bool)
        for name, column in results.columns.items():
            if not name.startswith(LIMIT_COLUMN):
                continue
            suffix, cells = name[len(LIMIT_COLUMN) :], exceeded(column)
            for limit in HARD_LIMITS + SOFT_LIMITS:
                hit = np.array([limit in c for c in cells], dtype=bool)
                if not hit.any():
                    continue
                entry = self.limits.setdefault((limit, suffix), [Steps(), 0.0])
                entry[0].add(steps[hit])
                if limit in SOFT_LIMITS:
                    v = np.abs(np.asarray(results[limit + suffix], dtype=float)[hit])
                    entry[1] = max(entry[1], float(np.nanmax(v)))
                else:
                    hard |= hit
        self.past_hard.add(steps[hard])

    def hard_limits(self) -> list[str]:
        """Each hard limit a step is past, with its corner's suffix and the steps:
        ``damper_stroke_min_left at 2 steps (39, 40)``."""
        from ..columns.packaging import HARD_LIMITS

        return [
            f"{limit}{suffix} at {steps.count} step{'s' * (steps.count != 1)} ({steps})"
            for (limit, suffix), (steps, _) in self.limits.items()
            if limit in HARD_LIMITS
        ]

    def _column(self, name: str, v, steps) -> None:
        import numpy as np

        stat = self.stats.get(name)
        if stat is None:
            stat = self.stats[name] = [v[0], v[-1], np.nan, np.nan, None, 0.0, 0]
        stat[1] = v[-1]
        stat[6] += int(np.isnan(v).sum())  # the CSV's empty cells
        if not np.isnan(v).all():
            stat[2] = np.nanmin(np.r_[stat[2], v])
            stat[3] = np.nanmax(np.r_[stat[3], v])
        far = np.flatnonzero(np.abs(v) > FAR)
        if len(far):
            i = far[np.argmax(np.abs(v[far]))]
            if abs(v[i]) > stat[5]:
                stat[4], stat[5] = int(steps[i]), abs(v[i])

    @property
    def failed(self) -> int:
        return self.short.count + self.flipped.count

    @property
    def iterations_median(self) -> float:
        import numpy as np

        total = np.cumsum(self.iterations)
        n = int(total[-1]) if len(total) else 0
        if not n:
            return float("nan")
        middle = np.searchsorted(total, [(n - 1) // 2 + 1, n // 2 + 1])
        return float(np.mean(middle))


def summary(results, path) -> None:
    from ..columns.metrics import METRIC_BY_NAME

    d = Digest.of(results)
    print(
        f"wrote {path}: {d.steps} steps, {d.converged} converged, "
        f"max residual {d.max_residual:.1e} mm, "
        f"{d.iterations_median:g} iterations per step (median)"
    )
    for note in d.notes:
        print(f"  {note}")
    # a cell the CSV leaves empty (a step that did not converge, a value undefined
    # there) is blank here too, and a column with blanks says at how many steps
    some = any(0 < stat[6] < d.steps for stat in d.stats.values())
    head = f"{'first':>13}{'last':>13}{'min':>13}{'max':>13}" + (f"{'blank':>8}" * some)
    print(f"  {'metric':<32}{'unit':>7}{head}")
    blank = []
    for name, (first, last, low, high, far, _, empty) in d.stats.items():
        if empty == d.steps:  # NaN at every step
            blank.append(name)
            continue
        line = f"  {name:<32}{d.units[name]:>7}{cell(first)}{cell(last)}"
        if name in CENTRES and far is not None:
            line += f"   at infinity (instant axis parallel to the view) near step {far}"
        else:
            line += f"{cell(low)}{cell(high)}" + (f"{empty or '':>8}" if some else "")
        print(line)
    for name in blank:
        m = METRIC_BY_NAME.get(name)
        why = f"needs {m.needs}" if m is not None and m.needs else "undefined at every step"
        print(f"  {name:<32}{d.units[name]:>7}   (blank: {why})")
    if d.failed:
        print(
            f"  (blank: an empty cell in the CSV; {d.failed} of {d.steps} steps did not "
            "converge, and their metrics are blank)"
        )
    limits_line(d)
    print("  (every column, derivatives included, is in the CSV)")


def limits_line(d: Digest) -> None:
    """The summary's line on the steps past a hard travel limit (limit_exceeded), if any."""
    if d.past_hard.count:
        print(
            f"  {d.past_hard.count} of {d.steps} steps past a hard travel limit: "
            f"{'; '.join(d.hard_limits())} (named in limit_exceeded; exit code 1)"
        )


def sweep_summary(
    results, digest: Digest, path, columns: tuple[str, ...] | None, suffixes: str = "_left/_right"
) -> None:
    """A sweep's printed summary: every metric column (``columns`` None), or those the
    subject names (Assembly.summary_columns: an axle's own and each side's main);
    ``suffixes``: its corners' column suffixes, as the last line names them."""
    if columns is None:
        summary(digest, path)
    else:
        columns_summary(results, digest, path, columns, suffixes)


def columns_summary(
    results, digest: Digest, path, columns: tuple[str, ...], suffixes: str = "_left/_right"
) -> None:
    """Its steps and notes, then first, last, min and max of ``columns`` (every column
    is in the CSV, each corner's with its suffix)."""
    import numpy as np

    ok = results["solver_converged"]
    print(
        f"wrote {path}: {len(results)} steps, {int(ok.sum())} converged, "
        f"max residual {np.nanmax(results['solver_max_residual']):.1e} mm"
    )
    for note in digest.notes:
        print(f"  {note}")
    shown = [
        (name, np.asarray(results[name], dtype=float))
        for name in columns
        if name in results.columns and not np.all(np.isnan(results[name]))
    ]
    some = any(np.isnan(v).any() for _, v in shown)  # a blank cell: say at how many steps
    head = f"{'first':>13}{'last':>13}{'min':>13}{'max':>13}" + (f"{'blank':>8}" * some)
    print(f"  {'column':<28}{'unit':>7}{head}")
    for name, v in shown:
        empty = int(np.isnan(v).sum())
        print(
            f"  {name:<28}{results.units[name]:>7}{cell(v[0])}{cell(v[-1])}"
            f"{cell(np.nanmin(v))}{cell(np.nanmax(v))}" + (f"{empty or '':>8}" * some)
        )
    failed = len(results) - int(ok.sum())
    if failed:
        print(
            f"  (blank: an empty cell in the CSV; {failed} of {len(results)} steps did not "
            "converge, and their columns are blank)"
        )
    limits_line(digest)
    corners = "both corners" if suffixes.count("/") == 1 else "every corner"
    print(f"  (every column of {corners}, suffixed {suffixes}, is in the CSV)")


def cell(value: float, width: int = 13) -> str:
    """A summary figure; an undefined one (NaN) blank, as the CSV's cell."""
    return f"{'':>{width}}" if value != value else f"{value:>{width}.6g}"


def warn_transmission(results) -> None:
    """Name the steps where a rocker transmission angle leaves its band (an axle's
    per side), and where a rated spring's force goes below zero (it would unseat)."""
    d = Digest.of(results)
    low, high = TRANSMISSION_BAND
    for _, side in SIDES:
        if side in d.band:
            steps, worst, angle, ratio = d.band[side]
            best, best_ratio = d.nearest[side]
            warnings.warn(
                f"{side}rocker transmission angle outside {low:g}…{high:g} deg at steps "
                f"{steps} (worst {angle:.1f} deg at step {worst}): the rocker nears "
                f"over-centre, {_ratio_trend(ratio, best, best_ratio)}",
                PlausibilityWarning,
                stacklevel=2,
            )
        if side in d.unseat:
            steps, least, droop, bump, over_centre = d.unseat[side]
            advice = []
            if droop.count:  # it extends as the wheel drops: the preload runs out
                where = f" in droop (steps {droop})" if bump.count else ""
                advice.append(f"{where}: more preload, or limit the droop travel (a droop limiter)")
            if bump.count:
                where = f"; in bump (steps {bump})" if droop.count else " (in bump)"
                if over_centre:  # it should compress in bump: its motion ratio has turned
                    why = (
                        "the spring extends as the wheel rises there (motion_ratio <= 0: a "
                        "rocker past over-centre, or one that works the spring the wrong "
                        "way; check the pushrod and rocker) — droop is not the cause"
                    )
                else:  # compressing, yet below zero: it starts below zero (the preload)
                    why = "more preload: the spring compresses in bump here, it starts too low"
                advice.append(f"{where}: {why}")
            warnings.warn(
                f"{side}spring force below zero at steps {steps} "
                f"(least {least:.0f} N): the spring would unseat there" + "".join(advice),
                PlausibilityWarning,
                stacklevel=2,
            )


def warn_driveshaft(results) -> None:
    """Name the first step (and how many) where a driveshaft's plunge or joint angle is
    past config.driveshaft.max_plunge / max_cv_angle (each corner's; limit_exceeded)."""
    from ..columns.packaging import SOFT_LIMITS

    d = Digest.of(results)
    for (limit, suffix), (steps, worst) in d.limits.items():
        if limit not in SOFT_LIMITS:
            continue
        plunge = limit == "driveshaft_plunge"
        key, unit_text = ("max_plunge", "mm") if plunge else ("max_cv_angle", "deg")
        warnings.warn(
            f"{limit}{suffix} past config.driveshaft.{key} at {steps.count} step"
            f"{'s' * (steps.count != 1)}, first at step {steps.first[0]} (worst "
            f"{worst:.4g} {unit_text}): the driveshaft is out of its range there",
            PlausibilityWarning,
            stacklevel=2,
        )


def report_limits(results) -> int:
    """Name the steps past a hard travel limit on stderr (docs/results.md, "Travel
    limits"); the exit code: 1 (EXIT_LIMIT) if any, else 0."""
    d = Digest.of(results)
    if not d.past_hard.count:
        return 0
    print(
        f"pin-susp: warning: {d.past_hard.count} of {d.steps} steps are past a hard travel "
        f"limit: {'; '.join(d.hard_limits())}. Their rows are flagged in limit_exceeded.",
        file=sys.stderr,
    )
    return EXIT_LIMIT


def _ratio_trend(ratio: float | None, best: float, best_ratio: float | None) -> str:
    """Which way the motion ratio goes as the pushrod nears the rocker's dead centre, by
    the numbers: |ratio| at the worst step against it where the angle is nearest 90°
    (as the geometry says, it rises: the rocker turns ever faster per mm of pushrod
    travel — unless the spring's side of the rocker nears its own dead centre too).
    Without a motion ratio (no spring), the geometry's word alone."""
    if ratio is None or best_ratio is None:
        return "the rocker turns ever faster per mm of wheel travel and can flip over"
    way = "rises toward infinity" if ratio > best_ratio else "falls toward zero"
    return (
        f"its motion ratio {way} (|{ratio:.3g}| there, |{best_ratio:.3g}| at "
        f"{best:.0f} deg) and can flip"
    )


def _dead_centre_cause(d: Digest) -> str:
    """The failure report's cause for steps out of reach or on another branch: a link
    that drives its body near dead centre at design (its warning is printed too)."""
    driven = [t for t in d.dead if t.driven]
    if not driven:
        return ""
    said = ", ".join(f"{t.flow} {t.margin:.1f}° from dead centre" for t in driven)
    return f" — the mechanism is at a dead centre at design ({said}: see the dead-centre warning)"


def report_failures(
    results, consequence: str = "are flagged solver_converged=False with empty cells"
) -> int:
    """Name the steps that did not converge, and why, on stderr; the exit code."""
    d = Digest.of(results)
    if not d.failed:
        return 0
    reasons = []
    if d.short.count:
        reasons.append(
            f"steps {d.short} out of the mechanism's reach or past a lock-up "
            f"(residual up to {d.worst_short:.3g} mm)"
        )
    if d.flipped.count:
        reasons.append(
            f"steps {d.flipped} reach the targets only on another assembly branch "
            f"({', '.join(sorted(d.loops))} flipped over: not the design's mechanism)"
        )
    print(
        f"pin-susp: warning: {d.failed} of {d.steps} steps did not converge: "
        f"{'; '.join(reasons)}{_dead_centre_cause(d)}. Their rows {consequence}.",
        file=sys.stderr,
    )
    return EXIT_NOT_CONVERGED


def step_list(steps: list[int]) -> str:
    return ", ".join(map(str, steps[:10])) + (" ..." if len(steps) > 10 else "")


def progress_bar(total: int, quiet: bool, minimum: int = 50, label: str = "solving"):
    """A one-line progress bar on a terminal; nothing in logs or pipes."""
    if quiet or total < minimum or not sys.stderr.isatty():
        return None
    width = 30

    def show(done: int, total: int) -> None:
        filled = width * done // total
        end = "\n" if done == total else ""
        sys.stderr.write(
            f"\r  {label} [{'#' * filled}{'.' * (width - filled)}] {done}/{total}{end}"
        )
        sys.stderr.flush()

    return show


def wrote(*paths) -> None:
    for path in paths:
        if path is not None:
            print(f"wrote {path}")


def print_warnings(args) -> None:
    """The implausible values seen so far, one line each (not with --quiet)."""
    seen = list(dict.fromkeys(str(w.message) for w in args.warnings))
    args.warnings.clear()
    if not getattr(args, "quiet", False):
        for message in seen:
            print(f"pin-susp: warning: {message}", file=sys.stderr)
