"""How fast pin_susp writes a sweep's results, per row, against today's repr writer.

    python benchmarks/bench_writer.py [--rounds N] [--steps N] [--chunks N ...] [--json OUT.json]

On the example corner's bump + steer sweep (examples/double_wishbone.yaml, wheel centre
z −40…120 mm and rack −40…40 mm; 2 001 steps, 108 columns by default) it times, in
alternation, several rounds (the machine drifts: figures are p10 / median / p90):

- ``repr``: tables.write_csv in the repr style (numpy's str of each float);
- ``fast``: tables.write_csv in the compiled style (pyarrow's cast to string);
- ``fast_text``: tables.csv_text in the compiled style (a str, what the CLI holds);
- ``parquet``: tables.write_parquet;
- ``stream_N``: tables.CsvStream, chunks of N rows (--chunks: 101 and 1 001);
- ``parquet_stream_N``: tables.ParquetStream, chunks of N rows;

each as µs per row and as a ratio to ``repr`` in the same round (target: the CSV
≤ 8 µs per row). Then the import of pyarrow and its kernels (tables._compute: what the
compiled style costs a process that has not imported them; fresh interpreters) and where that
cost is paid back: rows of this table, and cells, against tables.FAST_CELLS.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import pin_susp
from pin_susp.io import tables
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.corner import Results

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
NEVER = 10**18  # FAST_CELLS that no table reaches: the repr style


def table(steps: int) -> Results:
    corner = pin_susp.Corner(str(EXAMPLES / "double_wishbone.yaml"))
    sweep = Sweep(
        [
            Target("wheel_center", "z", np.linspace(-40, 120, steps)),
            Target("trackrod_inboard", "y", np.linspace(-40, 40, steps)),
        ],
        "bench_writer",
    )
    return corner.run_sweep(sweep)


def chunks(results: Results, size: int) -> list[Results]:
    n = len(results)
    return [
        Results(
            {k: v[i : i + size] for k, v in results.columns.items()}, results.units, results.meta
        )
        for i in range(0, n, size)
    ]


def writers(results: Results, folder: Path, sizes: list[int]) -> dict:
    names = list(results.columns)

    def styled(cells, function):
        def run():
            tables.FAST_CELLS, kept = cells, tables.FAST_CELLS
            try:
                function()
            finally:
                tables.FAST_CELLS = kept

        return run

    def stream(kind, path, size):
        parts = chunks(results, size)

        def run():
            with kind(path, results.units, results.meta, names, len(results)) as out:
                for part in parts:
                    out.write(part)

        return run

    out = {
        "repr": styled(NEVER, lambda: tables.write_csv(results, folder / "repr.csv")),
        "fast": styled(0, lambda: tables.write_csv(results, folder / "fast.csv")),
        "fast_text": styled(0, lambda: tables.csv_text(results)),
        "parquet": lambda: tables.write_parquet(results, folder / "r.parquet"),
    }
    for size in sizes:
        out[f"stream_{size}"] = styled(0, stream(tables.CsvStream, folder / f"{size}.csv", size))
    for size in sizes:
        path = folder / f"{size}.parquet"
        out[f"parquet_stream_{size}"] = stream(tables.ParquetStream, path, size)
    return out


def timings(results: Results, rounds: int, sizes: list[int]) -> dict:
    rows = len(results)
    with tempfile.TemporaryDirectory() as folder:
        runs = writers(results, Path(folder), sizes)
        for run in runs.values():  # warm-up: imports, first calls
            run()
        per_row = {name: [] for name in runs}
        for _ in range(rounds):
            for name, run in runs.items():
                t0 = time.perf_counter()
                run()
                per_row[name].append((time.perf_counter() - t0) / rows * 1e6)
        files = [Path(folder) / name for name in ("fast.csv", *(f"{n}.csv" for n in sizes))]
        csv_same = len({f.read_bytes() for f in files}) == 1
        files = [Path(folder) / name for name in ("r.parquet", *(f"{n}.parquet" for n in sizes))]
        parquet_same = len({f.read_bytes() for f in files}) == 1
    out = {}
    for name, samples in per_row.items():
        p10, p50, p90 = np.percentile(samples, [10, 50, 90])
        ratios = [a / b for a, b in zip(samples, per_row["repr"], strict=True)]
        out[name] = {
            "us_per_row": {"p10": p10, "median": p50, "p90": p90},
            "ratio_to_repr": statistics.median(ratios),
        }
    out["streams_equal_whole"] = {"csv": csv_same, "parquet": parquet_same}
    return out


def import_cost(times: int) -> list[float]:
    """Seconds to import what the compiled style needs in a fresh interpreter (numpy and
    pin_susp.io.tables in): pyarrow and its kernels (tables._compute)."""
    code = (
        "import time, numpy; from pin_susp.io import tables; t = time.perf_counter(); "
        "tables._compute(); print(time.perf_counter() - t)"
    )
    root = str(Path(__file__).resolve().parent.parent)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([root, os.environ.get("PYTHONPATH", "")]))
    run = [sys.executable, "-c", code]
    return [
        float(subprocess.run(run, capture_output=True, text=True, env=env).stdout)
        for _ in range(times)
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9, help="rounds of every writer")
    parser.add_argument("--steps", type=int, default=2001, help="sweep steps (table rows)")
    parser.add_argument(
        "--chunks", type=int, nargs="+", default=[101, 1001], help="rows per streamed chunk"
    )
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    args = parser.parse_args()

    results = table(args.steps)
    rows, columns = len(results), len(results.columns)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}")
    print(f"table: {rows} rows x {columns} columns, {args.rounds} rounds in alternation\n")
    figures = timings(results, args.rounds, args.chunks)
    print(f"{'writer':<22}{'us/row p10':>12}{'median':>9}{'p90':>9}{'x repr':>9}")
    for name, entry in figures.items():
        if name == "streams_equal_whole":
            continue
        t = entry["us_per_row"]
        ratio = entry["ratio_to_repr"]
        print(f"{name:<22}{t['p10']:>12.1f}{t['median']:>9.1f}{t['p90']:>9.1f}{ratio:>9.3f}")
    same = figures["streams_equal_whole"]
    print(f"\nstreams' files = the whole table's, byte for byte: {same}")
    target = figures["fast"]["us_per_row"]["median"]
    print(f"fast CSV: {target:.1f} us/row median (target <= 8)")

    imports = import_cost(7)
    seconds = statistics.median(imports)
    saved = figures["repr"]["us_per_row"]["median"] - figures["fast"]["us_per_row"]["median"]
    even_rows = seconds * 1e6 / saved
    print(
        f"\nimport pyarrow + its kernels (tables._compute): {min(imports) * 1e3:.0f}-"
        f"{max(imports) * 1e3:.0f} ms (median {seconds * 1e3:.0f} ms)"
    )
    print(
        f"paid back from {even_rows:.0f} rows of this table = {even_rows * columns:.0f} cells"
        f" (tables.FAST_CELLS = {tables.FAST_CELLS})"
    )
    figures["import_s"] = imports
    figures["break_even"] = {"rows": even_rows, "cells": even_rows * columns}
    figures["table"] = {"rows": rows, "columns": columns, "chunks": args.chunks}
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()
