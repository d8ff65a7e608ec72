"""`pin-susp kc`: a sweep's elastokinematics (K&C compliance) under each load case
(docs/compliance.md): how far the wheel steers, cambers and moves on its bushings,
links and tyre, the classic K&C rates and each bushing's deflection, one row per step
and case; the rates' range and each case's compliance printed."""

from __future__ import annotations

from ..options import check_image, check_outputs, run_arguments
from ..report import progress_bar, report_failures, report_limits
from .loads import chosen_case

DESCRIPTION = (
    "Solve SWEEP on GEOMETRY (a corner or an axle with a compliance: block: bushings, "
    "links, tyre; a vehicle, its axle files' blocks) and, at every step and load case "
    "of CASES, the compliant wheel's "
    "motion (docs/compliance.md): compliance_toe/camber (deg), compliance_wheel_center_"
    "x/y/z (mm), the K&C rates (lateral force steer and camber, aligning torque steer, "
    "braking steer, recession) and every bushing's, link's and tyre's deflection. "
    "One CSV row per step and case, then the sweep's own columns; --view writes a "
    "replay with the bushings coloured by their deflection under one case. Exit code 1 "
    "if a step did not converge."
)


def arguments(parser) -> None:
    run_arguments(
        parser,
        "K&C CSV",
        "also draw the K&C report: lateral force steer and camber, braking steer and "
        "recession against wheel travel",
        cases=True,
    )
    parser.add_argument(
        "--method",
        choices=("linear", "nonlinear"),
        default="linear",
        help="linear: the first-order compliance at each pose (default); nonlinear: "
        "the loaded pose solved with the bushings as springs",
    )
    parser.add_argument(
        "--view",
        metavar="OUT.html",
        help="also write a self-contained replay of the sweep, a sphere at each bushing "
        "coloured by its deflection under one case (pale yellow 0, dark red the largest)",
    )
    parser.add_argument(
        "--case", metavar="NAME", help="the load case the replay shows (default: the first)"
    )


def run(args) -> int:
    import numpy as np

    from ...analyses.compliance import KC, kc_results
    from ...analyses.load_case import load_cases
    from ...errors import PinSuspError
    from ...io.atomic import all_or_none, write_text
    from ...io.tables import is_parquet, write_csv
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject
    from ..options import output_form

    check_outputs(args, args.output, args.plot, args.view)
    if args.plot is not None:
        check_image(args.plot)
    if args.case is not None and args.view is None:
        raise PinSuspError(f"--case {args.case}: is the replay's: give --view OUT.html")
    subject = load_subject(args.geometry)
    sweep = load_sweep(args.sweep)
    cases = load_cases(args.cases, labels=subject.labels)
    case = chosen_case(args.cases, cases, args.case)
    subject.check_sweep(sweep)
    kc = KC(subject)  # the compliance's errors before any work
    solutions, results = subject.solve_sweep(sweep, progress=progress_bar(sweep.steps, args.quiet))
    table = kc_results(
        subject, sweep, cases, args.method, solutions, results, kc=kc,
        progress=progress_bar(sweep.steps, args.quiet, label=f"K&C {args.method}"),
    )  # fmt: skip
    form = output_form(args)
    page = None
    if args.view is not None:
        page, frames = _replay(subject, kc, table, results, case, args.cases)
    with all_or_none():
        if is_parquet(args.output):
            from ...io.tables import write_parquet

            write_parquet(table, args.output, form)
        else:
            write_csv(table, args.output, form)
        if args.plot is not None:
            from ...plots import save_figure
            from ...plots.kc import kc_figure

            save_figure(kc_figure(table, subject.labels, subject.suffix), args.plot)
        if page is not None:
            write_text(page, args.view)
    if not args.quiet:
        print(
            f"wrote {args.output}: {len(results)} steps x {len(cases)} load cases "
            f"({args.method} K&C)"
        )
        _summary(table, subject, np)
        if args.plot is not None:
            print(f"wrote {args.plot}")
        if page is not None:
            print(f"wrote {args.view} ({frames} frames, bushings coloured under {case!r})")
    return max(report_failures(results), report_limits(results))


def _replay(subject, kc, table, results, case: str, cases_path) -> tuple[str, int]:
    """The replay's page (viz/kc_colours.py) and its frames."""
    import contextlib
    import io
    from pathlib import Path

    from ...viz.kc_colours import kc_replay
    from ...viz.scene import Scene

    qs = results.solved_configurations
    with contextlib.redirect_stdout(io.StringIO()):  # meshcat announces its server
        scene = Scene(subject)
    try:
        page, frames, _ = kc_replay(
            scene, subject, table, kc.bushing_columns, qs, case, Path(cases_path).name
        )
    finally:
        scene.close()
    return page, frames


RATES = (
    ("lateral_force_steer", "deg/kN"),
    ("lateral_force_camber", "deg/kN"),
    ("aligning_torque_steer", "deg/kN·m"),
    ("longitudinal_force_steer", "deg/kN"),
    ("longitudinal_compliance", "mm/kN"),
)
MOTION = ("compliance_toe", "compliance_camber", "compliance_wheel_center_x")
MOTION += ("compliance_wheel_center_y", "compliance_wheel_center_z")


def _summary(table, subject, np) -> None:
    """Each rate's range over the sweep, then each case's compliance range, per wheel."""
    first = table["load_case"] == table["load_case"][0]
    print(f"  {'rate':40s} {'min':>10s} {'max':>10s}")
    for label in subject.labels:
        s = subject.suffix(label)
        for name, unit in RATES:
            v = np.asarray(table[name + s][first], dtype=float)
            print(f"  {name + s:40s} {np.nanmin(v):10.4f} {np.nanmax(v):10.4f} {unit}")
    print(f"  {'compliance':40s} {'case':18s} {'min':>10s} {'max':>10s}")
    for case in dict.fromkeys(table["load_case"]):
        rows = table["load_case"] == case
        for label in subject.labels:
            s = subject.suffix(label)
            for name in MOTION:
                v = np.asarray(table[name + s][rows], dtype=float)
                unit = "deg" if name.endswith(("toe", "camber")) else "mm"
                print(
                    f"  {name + s:40s} {str(case)[:18]:18s} {np.nanmin(v):10.4f} "
                    f"{np.nanmax(v):10.4f} {unit}"
                )
