"""`pin-susp loads`: a sweep's quasi-static member and joint forces under each load case
(README, Loads and rates), one row per step and case; the largest tension and
compression of each member printed. Its inputs and solve are shared with `view
--cases`."""

from __future__ import annotations

from ..options import check_image, check_outputs, run_arguments
from ..report import progress_bar, report_failures, report_limits
from .sweep import write_results

DESCRIPTION = (
    "Solve SWEEP on GEOMETRY (a corner, an axle or a vehicle) and, at every step, the "
    "quasi-static "
    "forces under each load case of CASES (README, Loads and rates; a vehicle's case "
    "may be a steady acceleration, ax and ay in g: docs/vehicle.md): the tension in every "
    "two-force member (wishbone legs, trackrod or toe link, pushrod, links), the "
    "spring's force, the rack's, and the load at every ball joint and pivot bushing "
    "(a wishbone's also along each leg: a wishbone carrying the pushrod is no "
    "two-force member, its legs blank and said so). "
    "One CSV row per step and case, then the sweep's own columns. Exit code 1 if a "
    "step did not converge."
)


def arguments(parser) -> None:
    run_arguments(
        parser,
        "forces CSV",
        "also draw the force report: each member's force and each joint's load "
        "against wheel travel (or rack), a line per load case",
        cases=True,
    )


def run(args) -> int:
    import numpy as np

    check_outputs(args, args.output, args.plot)
    if args.plot is not None:
        check_image(args.plot)
    if args.plot is not None:
        from ...errors import InputError
        from ...subjects.subject import subject_class

        kind = subject_class(args.geometry)
        if not kind.reports:  # before any work
            raise InputError(
                str(args.geometry), "--plot", f"a {kind.noun}'s report is not built yet"
            )
    corner, sweep, cases = load_inputs(args.geometry, args.sweep, args.cases)
    results, forces = solve_forces(corner, sweep, cases, args.quiet)
    plot = write_results(args, forces)
    if not args.quiet:
        unbounded = int(np.nansum(forces["loads_unbounded"]))
        print(
            f"wrote {args.output}: {len(results)} steps x {len(cases)} load cases"
            + (f"; {unbounded} row(s) at a toggle (forces unbounded: blank)" if unbounded else "")
        )
        for note in results.meta.get("notes", ()):
            print(f"  {note}")
        _force_summary(forces)
        if plot:
            print(f"wrote {args.plot}")
    return max(report_failures(results), report_limits(results))


def load_inputs(geometry, sweep, cases):
    """A corner, an axle or a vehicle, its sweep and load cases, every input error said
    before any work (a vehicle's steady accelerations: each one's equilibrium found)."""
    from ...analyses.loads import Statics, load_cases
    from ...analyses.road_loads import RoadLoads, has_accelerations
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject

    subject = load_subject(geometry)
    sweep = load_sweep(sweep)
    # a block per labelled corner; on the road, a steady acceleration too
    found = load_cases(cases, labels=subject.labels, accelerations=subject.on_road)
    subject.check_sweep(sweep)  # target errors before any work
    Statics(subject)  # no load path, or an anti-roll bar without its stiffness
    if has_accelerations(found):  # the attitude's inputs, and an equilibrium at each
        RoadLoads(subject, found, str(cases))
    return subject, sweep, found


def solve_forces(corner, sweep, cases, quiet: bool):
    """The sweep's results and, at every step and load case, the forces."""
    from ...analyses.loads import member_forces

    solutions, results = corner.solve_sweep(sweep, progress=progress_bar(sweep.steps, quiet))
    return results, member_forces(corner, sweep, cases, solutions, results)


def chosen_case(path, cases, name: str | None) -> str:
    """The load case to show: the one named (it must be in the file), else the first."""
    from ...errors import InputError

    names = [c.name for c in cases]
    if name is not None and name not in names:
        listed = ", ".join(repr(n) for n in names)
        raise InputError(str(path), "cases", f"no load case named {name!r} (it has {listed})")
    return names[0] if name is None else name


UNLOADED = 1e-6  # N, N·m: a member the case leaves unloaded, not listed in the summary


def _force_summary(forces) -> None:
    """The largest tension and compression of each member over the sweep, per case (one
    the case leaves unloaded left out: a corner it puts no load on); a
    wishbone that is not a two-force member (it carries a pushrod, say) by its bushing
    loads resolved along each leg, and said so."""
    import numpy as np

    bent = forces.meta.get("not_two_force", {})
    stand_in = {}  # a bent arm's blank leg → its bushing's load along the leg
    for _, legs, alongs in bent.values():
        stand_in.update(zip(legs, alongs, strict=True))
    names = [n for n in forces.columns if n.startswith(("force_", "torque_"))]
    names = [stand_in.get(n, n) for n in names]
    width = max([36, *(len(n) for n in names)])
    print(f"  {'member':{width}s} {'case':18s} {'min':>12s} {'max':>12s}")
    for case in dict.fromkeys(forces["load_case"]):
        rows = forces["load_case"] == case
        for name in names:
            values = forces[name][rows].astype(float)
            if np.isnan(values).all():
                continue
            if np.nanmax(np.abs(values)) < UNLOADED:  # a corner the case does not load
                continue
            unit = forces.units.get(name, "N")
            print(
                f"  {name:{width}s} {str(case)[:18]:18s} {np.nanmin(values):12.1f} "
                f"{np.nanmax(values):12.1f} {unit}"
            )
    for arm, (points, legs, alongs) in bent.items():
        print(
            f"  {arm}: not a two-force member (it also carries {', '.join(points)}): its "
            f"legs bend, {' and '.join(legs)} are blank; {' and '.join(alongs)} are its "
            "bushings' loads resolved along each leg (+ as a leg's tension)"
        )
