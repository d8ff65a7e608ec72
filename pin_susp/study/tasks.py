"""One task of a study (docs/studies.md): a batch of variants solved, or one optimiser
start; its rows and steps as Arrow tables, carried back as IPC bytes.
"""

from __future__ import annotations

import json

import numpy as np

from .batch import solve_batch
from .data import Job
from .derivatives import objective_jacobian
from .variants import Variant, design_of


def run_batch(job: Job, index: int, ids: np.ndarray, table: np.ndarray, steps: bool) -> dict:
    """Solve one batch of variants: its summary rows and, with ``steps``, every step.

    Returns plain data (Arrow IPC bytes) so that any scheduler can carry it."""
    from ..model.sweep import load_sweep
    from ..solve.allocator import tune

    tune()  # (the batch's arrays: solve/allocator.py)

    sweep = load_sweep(job.sweep)
    rows, frames = [], []
    # (--steps writes each step as pin-susp sweep does: its solver's columns too, marched)
    guess = None if steps else guess_of(job, sweep)
    for vid, deltas, v in zip(
        ids, table, solve_batch(job, table, sweep, guess, steps), strict=True
    ):
        rows.append(_row(job, int(vid), deltas, v))
        if steps and v.results is not None:
            frames.append(_steps_table(v.results, int(vid)))
    return {"index": index, "variants": _ipc(_variants_table(rows)), "steps": _ipc_many(frames)}


def run_start(job: Job, index: int, ids: np.ndarray, table: np.ndarray, steps: bool) -> dict:
    """One optimiser start (a batch of one): scipy least_squares from ``table[0]``, with
    the exact hardpoint sensitivities as its Jacobian; the optimum's row."""
    from scipy.optimize import least_squares

    from ..model.sweep import load_sweep
    from ..solve.allocator import tune

    tune()  # (solve/allocator.py)

    sweep = load_sweep(job.sweep)
    low, high = job.bounds
    x0 = np.clip(table[0], low, high)
    # the start's variant and the last one asked for (least_squares asks for the
    # residuals and then the Jacobian at one x; the row reads the start's again)
    cache, first = {}, x0.tobytes()
    reuse = {}  # the sensitivity model, shared by the variants (derivatives.sensitivities)

    # (each evaluation marched as a sweep: the optimum to the last digit as before)

    def solved(x: np.ndarray) -> Variant:
        key = x.tobytes()
        if key not in cache:
            for old in [k for k in cache if k != first]:
                del cache[old]
            cache[key] = Variant(job, x, sweep, every_column=steps)
        return cache[key]

    def fun(x):
        return solved(x).residuals()

    def jac(x):
        return objective_jacobian(solved(x), sweep, reuse)

    fit = least_squares(
        fun,
        x0,
        jac=jac,
        bounds=(low, high),
        method="trf",
        x_scale=1.0,
        xtol=1e-10,
        ftol=1e-12,
        gtol=1e-10,
        max_nfev=job.max_evaluations,
    )
    best = solved(fit.x)
    row = _row(job, int(ids[0]), fit.x, best)
    row["objective"] = float(np.linalg.norm(fun(fit.x)))
    row["start_objective"] = float(np.linalg.norm(fun(x0)))
    row["evaluations"] = int(fit.nfev)
    frames = [_steps_table(best.results, int(ids[0]))] if steps and best.results else []
    return {"index": index, "variants": _ipc(_variants_table([row])), "steps": _ipc_many(frames)}


def guess_of(job: Job, sweep) -> np.ndarray | None:
    """The design variant's configuration at every step (None if some step failed):
    every variant's steps solved at once from it (Variant's ``guess``); worked out once
    per process that runs the job's tasks (variants.design_of)."""
    return design_of(job, sweep).solved


def _row(job: Job, vid: int, deltas, v: Variant) -> dict:
    row = {"variant_id": vid}
    row.update({var.name: float(d) for var, d in zip(job.variables, deltas, strict=True)})
    row["converged"] = v.converged
    row["steps_failed"] = v.steps_failed
    row.update(v.summary_row())
    row["error"] = v.error
    return row


def _steps_table(results, vid: int):
    import pyarrow as pa

    from ..io.tables import arrow_columns

    arrays = {"variant_id": pa.array(np.full(len(results), vid, dtype=np.int64))}
    arrays |= arrow_columns(results)
    units = {k: u for k, u in results.units.items() if u}
    return pa.table(arrays).replace_schema_metadata({"units": json.dumps(units)})


def _variants_table(rows: list[dict]):
    import pyarrow as pa

    from ..io.tables import arrow_column

    names = list(rows[0])
    return pa.table({k: arrow_column(np.array([r[k] for r in rows])) for k in names})


def _ipc(table) -> bytes:
    import pyarrow as pa

    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    return sink.getvalue().to_pybytes()


def _ipc_many(tables: list) -> bytes | None:
    if not tables:
        return None
    import pyarrow as pa

    return _ipc(pa.concat_tables(tables, promote_options="permissive"))


def from_ipc(data: bytes):
    import pyarrow as pa

    return pa.ipc.open_stream(data).read_all()
