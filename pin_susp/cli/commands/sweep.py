"""`pin-susp sweep`: every step of a sweep on a corner or an axle, one row each, to CSV
or Parquet (and the standard report with --plot); a corner's sweep longer than
STREAM_STEPS is written as it is solved, a chunk at a time (docs/sweep.md,
docs/results.md)."""

from __future__ import annotations

import sys

from ..options import check_image, check_outputs, output_form, run_arguments
from ..report import (
    Digest,
    progress_bar,
    report_failures,
    report_limits,
    summary,
    sweep_summary,
    warn_driveshaft,
    warn_transmission,
)

DESCRIPTION = (
    "Solve every step of SWEEP on GEOMETRY (a corner, or an axle: scope: axle) "
    "and write the metrics (camber, toe, caster, KPI, scrub, trail, ...; an axle's per "
    "side, and its roll, roll centre, bar twist, ...) and every point to CSV. "
    "Exit code 1 if any step did not converge (its row is flagged) or is past a hard "
    "travel limit of config.limits (named in limit_exceeded)."
)


def arguments(parser) -> None:
    run_arguments(
        parser,
        "results CSV",
        "also draw the standard kinematics report (an axle's: camber, toe, steer, roll "
        "centre, bar twist, ... against roll, heave or rack; a vehicle's: each corner's "
        "camber to ground, camber and toe, the roll centres, roll axis, pitch centre, anti-dive, "
        "-lift and -squat, wheelbase, bar twist, ... against heave, pitch, roll, steering or road "
        "height)",
    )


# A corner's sweep longer than this (steps) is streamed to its file, a chunk at a time.
STREAM_STEPS = 10_000


def run(args) -> int:
    from ...errors import InputError

    check_outputs(args, args.output, args.plot)  # before the numerics are imported
    if args.plot is not None:
        check_image(args.plot)
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject, subject_class

    kind = subject_class(args.geometry) if args.plot is not None else None
    if kind is not None and not kind.reports:  # before any work
        raise InputError(str(args.geometry), "--plot", f"a {kind.noun}'s report is not built yet")
    subject = load_subject(args.geometry)  # a corner, or an axle: its columns per side
    sweep = load_sweep(args.sweep)
    subject.check_sweep(sweep)  # target errors before any work
    if subject.streams and sweep.steps > STREAM_STEPS and args.plot is None:
        return _sweep_streamed(args, subject, sweep)
    results = subject.run_sweep(sweep, progress=progress_bar(sweep.steps, args.quiet))
    digest = Digest.of(results)
    warn_transmission(digest)
    warn_driveshaft(digest)
    plot = write_results(args, results)
    if not args.quiet:
        suffixes = "/".join(subject.suffix(label) for label in subject.labels)
        sweep_summary(results, digest, args.output, subject.summary_columns, suffixes)
        if plot:
            print(f"wrote {args.plot}")
    return max(report_failures(digest), report_limits(digest))


def _sweep_streamed(args, corner, sweep) -> int:
    """A long sweep written as it is solved, a chunk of steps at a time: its memory does
    not grow with its length (the same rows as run_sweep's, to the solver's tolerance).
    A chunk is written by a second thread while the next one is solved (pyarrow's
    formatting and numpy leave the GIL): two chunks alive at most."""
    from concurrent.futures import ThreadPoolExecutor

    from ...io.tables import CsvStream, ParquetStream, is_parquet

    parts = corner.run_sweep_chunks(sweep, progress=progress_bar(sweep.steps, args.quiet))
    first = next(parts)
    digest = Digest.of(first)
    kind = ParquetStream if is_parquet(args.output) else CsvStream
    form = output_form(args)
    with (
        kind(args.output, first.units, first.meta, list(first.columns), sweep.steps, form) as out,
        ThreadPoolExecutor(1) as writer,
    ):
        pending = writer.submit(out.write, first)
        del first
        for part in parts:
            pending.result()
            pending = writer.submit(out.write, part)
            digest.add(part)
            del part
        pending.result()
    warn_transmission(digest)
    warn_driveshaft(digest)
    if not args.quiet:
        summary(digest, args.output)
    return max(report_failures(digest), report_limits(digest))


def write_results(args, results) -> bool:
    """The CSV (Parquet for an OUT ending .parquet; in --convention and --units) and,
    with --plot, the report (from the ISO, mm columns): both or neither; whether it was
    drawn."""
    from ...io.atomic import all_or_none, write_text
    from ...io.tables import csv_text, is_parquet, write_csv

    form = output_form(args)
    plot = args.plot is not None and results["solver_converged"].any()
    text = csv_text(results) if plot else None  # the report reads the CSV's text
    with all_or_none():
        if is_parquet(args.output):
            from ...io.tables import write_parquet

            write_parquet(results, args.output, form)
        elif text is None or not form.identity:
            write_csv(results, args.output, form)
        else:
            write_text(text, args.output)
        if plot:  # drawn from the ISO CSV's text: the output may be a stream
            from ...plots import ResultsFile, report_figure, save_figure

            written = ResultsFile(args.output, raw=text.encode())
            save_figure(report_figure([written]), args.plot)
    if args.plot is not None and not plot:
        print(f"pin-susp: no step converged: {args.plot} not drawn", file=sys.stderr)
    return plot
