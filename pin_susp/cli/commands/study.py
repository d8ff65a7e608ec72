"""`pin-susp study`: many variants of a geometry on Dask (a design of experiments,
tolerances by Monte Carlo, an optimisation; docs/studies.md), resumable after an
interrupt."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

from ...errors import EXIT_NOT_CONVERGED, PinSuspError
from ..report import progress_bar
from ..run import Terminated

DESCRIPTION = (
    "Run the variants of STUDY (a design of experiments, manufacturing "
    "tolerances by Monte Carlo, or an optimisation to target values and curves; "
    "docs/studies.md) through its sweep on Dask, and write OUTDIR/variants.parquet "
    "(one row per variant), study.png, with --steps steps.parquet (every step), and "
    "for an optimisation best.yaml. Exit code 1 if a variant did not converge at "
    "every step (its row is flagged)."
)


def arguments(parser) -> None:
    parser.add_argument("study", metavar="STUDY", help="study YAML (geometry, sweep, variables)")
    parser.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUTDIR",
        help="a new or empty directory (or this study's unfinished one, with --resume)",
    )
    parser.add_argument(
        "--scheduler",
        default="local",
        metavar="ADDRESS",
        help="tcp://HOST:PORT of a running Dask scheduler; 'local' (default): a cluster on "
        "this machine (127.0.0.1); 'none': serially, in this process",
    )
    parser.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="the local cluster's worker processes (default: one per core)",
    )
    parser.add_argument(
        "--steps",
        action="store_true",
        help="also write every step of every variant (steps.parquet, a Parquet dataset)",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="finish an interrupted run in OUTDIR: only the batches not yet written are solved",
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def run(args) -> int:
    import time

    from ... import study as studies

    if args.workers is not None and args.workers < 1:
        raise PinSuspError(f"--workers must be 1 or more, got {args.workers}")
    scheduler = None if args.scheduler == "none" else args.scheduler
    if scheduler != "local" and args.workers is not None:
        raise PinSuspError(
            "--workers sizes the local cluster: a scheduler has its own workers, and "
            "--scheduler none runs in this process"
        )
    if args.output.strip() == "":
        raise PinSuspError("the output directory's path is empty: give -o OUTDIR")
    study = studies.load_study(args.study)
    out = Path(args.output)
    started = time.perf_counter()
    total = len(studies.batches(study))
    label = "starts" if study.kind == "optimise" else "batches"
    try:
        outcome = studies.run_study(
            study,
            out,
            scheduler=scheduler,
            workers=args.workers,
            steps=args.steps,
            resume=args.resume,
            progress=progress_bar(total, args.quiet, minimum=1, label=label),
            announce=None if args.quiet else print,
            warn=lambda text: args.quiet or print(f"pin-susp: warning: {text}", file=sys.stderr),
        )
    except (KeyboardInterrupt, Terminated) as exc:
        signal_number = exc.signal if isinstance(exc, Terminated) else signal.SIGINT
        kept = studies.finished_batches(out)
        if kept is None:
            print("pin-susp: interrupted, nothing written", file=sys.stderr)
        else:
            bar = not args.quiet and sys.stderr.isatty()  # end the progress bar's line
            print(
                f"{chr(10) if bar else ''}pin-susp: interrupted: {kept} of {total} batches "
                f"are kept in {out}; "
                "the same command with --resume solves the rest",
                file=sys.stderr,
            )
        return 128 + signal_number
    seconds = time.perf_counter() - started
    variants = outcome.variants
    written = [out / "variants.parquet"]
    written += [out / "steps.parquet"] if (out / "steps.parquet").exists() else []
    written += [p for p in (outcome.best, outcome.figure) if p is not None]
    if outcome.figure is None:
        print(f"pin-susp: no variant converged: {out / 'study.png'} not drawn", file=sys.stderr)
    if not args.quiet:
        for line in outcome.lines:
            print(line)
        resumed = outcome.batches - outcome.computed
        rate = len(variants) / seconds if not resumed and study.kind != "optimise" else None
        timing = f" in {seconds:.1f} s" + (f" ({rate:.0f} variants/s)" if rate else "")
        if resumed:
            timing += f"; {resumed} of {outcome.batches} batches were already done"
        print(f"solved{timing}")
        for path in written:
            print(f"wrote {path}")
    return EXIT_NOT_CONVERGED if not variants["converged"].all() else 0
