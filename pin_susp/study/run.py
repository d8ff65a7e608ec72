"""A study run (docs/studies.md): its batches solved here or on Dask, each written as
it finishes, the tables assembled, the summary, study.png and best.yaml; what a run
that stops leaves for ``resume``.
"""

from __future__ import annotations

import contextlib
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import __version__
from ..errors import NoRoom
from . import cluster, folder, tasks
from .derivatives import linear_prediction
from .spec import MANIFEST, PARTS, Study, batches, load_study
from .summary import summary_lines
from .variants import Variant, variant_table


@dataclass
class Outcome:
    """What a study run produced (paths in OUTDIR) and the figures for its summary."""

    study: Study
    outdir: Path
    variants: object  # pandas DataFrame
    computed: int  # batches solved in this run (the rest were resumed)
    batches: int
    lines: list[str] = field(default_factory=list)  # the summary printed
    best: Path | None = None  # best.yaml (optimise)
    figure: Path | None = None  # study.png (None when no variant converged)
    dashboard: str | None = None
    linear: dict | None = None  # Monte Carlo: the first-order prediction per column
    seconds: dict = field(default_factory=dict)  # phase → seconds it took (Clock)


def run_study(
    study: Study | str | Path,
    outdir: str | Path,
    scheduler: str | None = "local",
    workers: int | None = None,
    steps: bool = False,
    resume: bool = False,
    progress=None,
    announce=None,
    warn=None,
) -> Outcome:
    """Run a study into ``outdir`` (docs/studies.md); see the module's docstring.

    ``progress(done, total)`` after each batch; ``announce(text)`` for a line worth
    printing before the work (the Dask dashboard's address); ``warn(text)`` for a
    damaged part file that a resumed run solves again (default: warnings.warn).

    A run that stops (an interrupt, an error, a write that runs out of room) leaves
    OUTDIR with what ``resume`` needs — its study.json and the part files of the
    batches finished, each whole — or, before any batch is finished, as it found it
    (a new run's study.json and part folder removed). A write that runs out of room
    raises NoRoom saying which (docs/studies.md).
    """
    clock = Clock()
    if not isinstance(study, Study):
        study = load_study(study)
        clock.lap("study read")
    outdir = Path(outdir)
    folder.check_outdir(study, outdir, steps, resume)  # before any connection or file
    fresh = not outdir.exists()
    try:
        if scheduler is None or scheduler == "none":
            return _run(study, outdir, None, steps, resume, progress, None, warn, clock)
        early = {}
        forked = scheduler == "local" and cluster.start_forkserver()
        if scheduler == "local":  # what needs no worker, while the workers' server imports
            early["table"] = variant_table(study)
            clock.lap("variants' table")
            if study.kind == "monte_carlo":
                early["linear"] = _prediction(study, early["table"])
                clock.lap("first-order prediction")
            if forked:  # study.png's imports (matplotlib), on this core while the server's
                from ..plots import save_figure  # noqa: F401  (on the other) go on
                from .plots import study_figure  # noqa: F401

                clock.lap("study.png's imports")
        # a scheduler that answers, before any file
        with cluster.dask_client(scheduler, workers, forked) as client:
            clock.lap("cluster start")
            dashboard = cluster.dashboard(client, local=scheduler == "local")
            if announce is not None and dashboard:
                announce(f"Dask dashboard: {dashboard}")
            args = (steps, resume, progress, dashboard, warn, clock)
            outcome = _run(study, outdir, client, *args, **early)
        clock.lap("cluster close")
        return outcome
    except BaseException as exc:
        kept = _left(outdir, fresh, resume)
        if isinstance(exc, NoRoom):
            total = len(batches(study))
            left = (
                f"{kept} of {total} batches are kept in {outdir}: the same command with "
                "--resume continues (once there is room)"
                if kept
                else "nothing written"
            )
            raise NoRoom(exc.path, exc.why, left) from None
        raise


def _left(outdir: Path, fresh: bool, resume: bool) -> int:
    """After a run that stopped: the batches kept for --resume; with none, a new run's
    study.json and part folder go (and OUTDIR, made by it)."""
    kept = folder.finished_batches(outdir) or 0
    if kept or resume:  # a resumed run leaves the directory at least as it found it
        return kept
    parts = outdir / PARTS
    with contextlib.suppress(OSError):
        if parts.is_dir():
            for p in parts.iterdir():  # a batch's steps part, without its variants part
                p.unlink()
            parts.rmdir()
        (outdir / MANIFEST).unlink(missing_ok=True)
        if fresh:
            outdir.rmdir()  # only if empty
    return 0


class Clock:
    """The seconds of each phase of a run (``Outcome.seconds``), in the order first met:
    ``lap(phase)`` ends the phase that ran since the last lap."""

    def __init__(self):
        self.seconds, self.mark = {}, time.perf_counter()

    def lap(self, phase: str) -> None:
        now = time.perf_counter()
        self.seconds[phase] = self.seconds.get(phase, 0.0) + now - self.mark
        self.mark = now


def _prediction(study: Study, table: np.ndarray) -> dict | None:
    """Monte Carlo's first-order prediction from the variants' table, as from the
    assembled variants (their variables in the study's convention: the same numbers)."""
    import pyarrow as pa

    from ..io.conventions import Output

    names = pa.table({name: table[:, j] for j, name in enumerate(study.names)})
    variables = folder.in_convention(names, Output(study.convention)).to_pandas()
    return linear_prediction(study, variables)


NOT_YET = object()  # (the first-order prediction may be None: a vehicle's, an unsolved design)


def _run(
    study, outdir, client, steps, resume, progress, dashboard, warn, clock, **early
) -> Outcome:
    table = early.get("table")
    if table is None:
        table = variant_table(study)
        clock.lap("variants' table")
    parts = folder.prepare(study, outdir, steps, resume)
    cut = batches(study)
    if resume:  # a part cut short or damaged since (a disk error, an editor): solved again
        for i in range(len(cut)):
            why = folder.damaged(parts, i, cut[i], steps)
            if why is not None:
                for what in ("variants", "steps"):
                    (parts / f"{what}-{i:06d}.parquet").unlink(missing_ok=True)
                message = f"{why}: batch {i} is solved again"
                warnings.warn(message, stacklevel=2) if warn is None else warn(message)
    todo = [i for i in range(len(cut)) if not (parts / f"variants-{i:06d}.parquet").exists()]
    job = study.job()
    clock.lap("folder")
    task = tasks.run_start if study.kind == "optimise" else tasks.run_batch
    done = len(cut) - len(todo)
    if progress is not None and done:
        progress(done, len(cut))

    written = {}  # batch → its variants as written (assembled without reading them back)

    def finished(result: dict) -> None:
        nonlocal done
        clock.lap("batches")
        written[result["index"]] = folder.write_part(parts, result)
        clock.lap("part files")
        done += 1
        if progress is not None:
            progress(done, len(cut))

    if todo and client is None:
        for i in todo:
            finished(task(job, i, cut[i], table[cut[i]], steps))
    elif todo:
        cluster.on_dask(client, task, job, cut, table, todo, steps, finished)
    clock.lap("batches")
    table = folder.assemble(study, outdir, parts, len(cut), steps, written)
    variants = table.to_pandas()
    outcome = Outcome(study, outdir, variants, len(todo), len(cut), dashboard=dashboard)
    outcome.seconds = clock.seconds
    clock.lap("assembled")
    if study.kind == "monte_carlo":
        outcome.linear = early.get("linear", NOT_YET)
        if outcome.linear is NOT_YET:
            outcome.linear = linear_prediction(study, variants)
            clock.lap("first-order prediction")
    if outcome.linear:  # beside each sampled column, its first-order prediction
        import pyarrow as pa

        for name, values in outcome.linear.items():
            table = table.append_column(f"{name}_linear", pa.array(values, from_pandas=True))
        outcome.variants = variants = table.to_pandas()
    curves = comment = None
    if study.kind == "optimise" and variants["converged"].any():
        row = best_row(variants)
        best = np.array([row[v.name] for v in study.variables], dtype=float)
        comment = (
            f"generated by pin_susp {__version__}: the best of {len(variants)} starts of "
            f"{Path(study.source).name} (objective {float(row['objective']):.6g}, start "
            f"{int(row['variant_id'])})\n"
            + "".join(f"{v.name} = {float(row[v.name])!r} mm\n" for v in study.variables)
        )
        outcome.best = outdir / "best.yaml"
        curves = curves_of(study, best)
    outcome.lines = summary_lines(study, variants, outcome.linear, curves)
    clock.lap("summary")
    from ..io.atomic import all_or_none

    with all_or_none():  # best.yaml, study.png, variants.parquet: together, or none of them
        if outcome.best is not None:
            folder.write_geometry(study, best, outcome.best, comment.rstrip())
        if variants["converged"].any():
            from ..plots import save_figure
            from .plots import study_figure

            outcome.figure = outdir / "study.png"
            save_figure(study_figure(study, variants, outcome.linear, curves), outcome.figure)
            clock.lap("study.png")
        folder.write_parquet(table, outdir / "variants.parquet")  # last: it marks the run finished
    folder.drop_parts(parts)
    clock.lap("variants.parquet")
    return outcome


def best_row(variants):
    """The converged start with the least objective."""
    return variants[variants["converged"]].sort_values("objective").iloc[0]


def curves_of(study: Study, deltas) -> list[dict]:
    """Per objective term: the metric over the sweep before (design) and after (the
    variables at ``deltas``), and the target — for the figure."""
    from ..model.sweep import load_sweep

    job = study.job()
    sweep = load_sweep(study.sweep_data)
    before = Variant(job, np.zeros(len(study.variables)), sweep)
    after = Variant(job, deltas, sweep)
    out = []
    lead = sweep.targets[0]
    for t in study.terms:
        entry = {"metric": t.metric, "relative": t.relative}
        for label, v in (("before", before), ("after", after)):
            if v.results is None:
                entry[label] = None
                continue
            y = np.asarray(v.results[t.metric], dtype=float)
            if t.relative:
                y = y - float(v.static[t.metric][0])
            x_name = t.curve_x or _x_column(lead, v.results)
            entry[label] = (np.asarray(v.results[x_name], dtype=float), y)
            entry["x"] = x_name
            entry[f"{label}_target"] = (
                np.full(len(y), t.target)
                if t.curve is None
                else t.goal(np.asarray(v.results[x_name], dtype=float))
            )
        out.append(entry)
    return out


def _x_column(target, results) -> str:
    """The column that the sweep's first target drives, for a curve's x axis."""
    if target.quantity is not None:
        return target.quantity if target.quantity in results.columns else "step_index"
    if target.point == "wheel_center" and "wheel_travel" in results.columns:
        return "wheel_travel"
    name = f"{target.point}_{target.direction}" if isinstance(target.direction, str) else ""
    return name if name in results.columns else "step_index"
