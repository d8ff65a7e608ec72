"""`pin-susp view`: the corner, axle or whole car (on the road) in meshcat, live or as a
self-contained HTML replay of its sweep, a corner's or an axle's members coloured by
force with --cases."""

from __future__ import annotations

import signal
import threading
from pathlib import Path

from ...errors import PinSuspError
from ..options import check_outputs, geometry_argument, positive
from ..report import print_warnings, progress_bar, report_failures, warn_transmission
from .loads import chosen_case, load_inputs, solve_forces

DESCRIPTION = (
    "Open GEOMETRY in a meshcat scene served locally (works offline) and print "
    "its URL; with SWEEP, play the solved motion as an animation. --html writes the scene "
    "and animation as one HTML file that opens in a browser with no server. An axle file "
    "shows both corners, the anti-roll bar and the roll centre (hidden where it is blank). "
    "A vehicle file shows the whole car on the road, pitched and rolled as solved, with "
    "each axle's roll centre, the pitch centre and the CG. "
    "With --cases (and SWEEP), the members are coloured by their force under one load "
    "case at every frame: red tension, blue compression, grey zero, full colour at the "
    "largest |force| over the sweep; one replay per case (--case)."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", nargs="?", help="sweep YAML to animate")
    parser.add_argument("--html", metavar="OUT.html", help="write a self-contained replay and exit")
    parser.add_argument("--fps", type=positive, default=10.0, help="animation frames per second")
    parser.add_argument(
        "--cases", metavar="LOADS.yaml", help="load cases: colour the members by their force"
    )
    parser.add_argument(
        "--case", metavar="NAME", help="the load case to colour by (default: the first)"
    )


def run(args) -> int:
    import contextlib
    import io
    import time

    from ...io.atomic import write_text
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject, subject_class
    from ...viz.scene import Scene, force_caption, force_key, signals_held

    check_outputs(args, args.html)
    if args.case is not None and args.cases is None:
        raise PinSuspError(f"--case {args.case}: needs --cases LOADS.yaml, the cases it names")
    if args.cases is not None and args.sweep is None:
        raise PinSuspError(f"--cases {args.cases}: needs a SWEEP, whose steps the forces are of")
    if args.cases is not None:
        kind = subject_class(args.geometry)  # a subject pin-susp loads takes
        if kind.commands is not None and "loads" not in kind.commands:
            raise PinSuspError(
                f"--cases {args.cases}: a {kind.noun}'s forces (pin-susp loads) are not built yet"
            )
    qs, results, markers, forces = None, None, None, None
    if args.cases is not None:  # a corner, its sweep and its forces under every case
        model, sweep, cases = load_inputs(args.geometry, args.sweep, args.cases)
        case = chosen_case(args.cases, cases, args.case)
        results, forces = solve_forces(model, sweep, cases, quiet=False)
        warn_transmission(results)
    else:
        model = load_subject(args.geometry)  # an axle's: both corners and the bar
    if args.sweep is not None and forces is None:
        sweep = load_sweep(args.sweep)
        progress = progress_bar(sweep.steps, False)
        model.check_sweep(sweep)  # target errors before any work
        results = model.run_sweep(sweep, progress=progress)
        warn_transmission(results)  # each corner's rocker and spring, as sweep warns
    if results is not None:
        qs = results.solved_configurations
    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet):  # meshcat announces its server on stdout
        scene = Scene(model)
    try:  # an interrupt before the scene is served is one as in every command: 130, 143
        if results is not None:  # the scene's markers (an axle's roll centre) at each step
            places = model.marker_places(results)
            markers = {name: places[name] for name in scene.design_markers}
        colours, caption = None, ""
        if forces is not None:
            colours, scale = scene.force_colours(forces, case)
            others = f"the first of {len(cases)}: --case NAME for another" * (
                args.case is None and len(cases) > 1
            )
            bent = bool(scene.not_two_force)
            print(force_key(case, scale, others, bent))
            caption = force_caption(case, scale, Path(args.cases).name, bent)
        frames = (
            scene.animate(qs, fps=args.fps, markers=markers, colours=colours)
            if qs is not None
            else 0
        )
        page = scene.html(caption) if args.html is not None else None
    except BaseException:
        with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl+C while it stops
            scene.close()
        raise
    if args.html is not None:
        with signals_held():  # a signal while the server stops: raised once it has
            scene.close()
        write_text(page, args.html)  # whole or not at all
        print(f"wrote {args.html}" + (f" ({frames} frames)" if frames else ""))
        return 0 if results is None else report_failures(results, "are not in the replay")
    try:
        print(
            f"meshcat: {scene.viewer.url()}"
            + (f"  ({frames} frames: press play in Open Controls > Animations)" if frames else "")
        )
        if results is not None:
            report_failures(results, "are not in the animation")
        print_warnings(args)
        # A process started in the background of a script inherits SIGINT ignored:
        # we say "press Ctrl+C", so Ctrl+C must stop us.
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.default_int_handler)
        print("serving; press Ctrl+C to stop", flush=True)
        while True:
            time.sleep(0.5)
    except KeyboardInterrupt:  # the way to stop a live scene: it was served, exit 0
        print("stopped")
        return 0
    finally:
        with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl+C while it stops
            scene.close()
