"""Studies' speed: variants per second, serially and on a LocalCluster of 1 and 2 workers.

A Monte Carlo of the example corner (every hardpoint coordinate within ±0.5 mm)
through a 21-step bump sweep with summaries (examples/bump_rack_held.yaml), each
way in turn in this process, so that the ratios compare like with like:

- serial: ``scheduler=None``, the batches one after another in this process —
  the baseline;
- LocalCluster with 1 and with 2 worker processes (127.0.0.1): the rate while the
  batches run (first batch done → last batch done), and end to end (the cluster's
  start, the variants' table and the files included);
- the 10 000-variant tolerance study of examples/study_tolerances.yaml end to end
  on 2 workers, as `pin-susp study` runs it (--full only: about a minute).

Targets (issue 15): ≥ 150 variants/s on 2 cores, ≥ 1.7× from 1 to 2 workers, the
10 000-variant study in ≤ 90 s.

    python benchmarks/bench_study.py [--variants N] [--full] [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def study_file(folder: Path, samples: int) -> Path:
    data = yaml.safe_load((EXAMPLES / "study_tolerances.yaml").read_text())
    data["geometry"] = str(EXAMPLES / data["geometry"])
    data["sweep"] = str(EXAMPLES / data["sweep"])
    data["monte_carlo"]["samples"] = samples
    path = folder / f"study_{samples}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def timed(study, folder: Path, name: str, scheduler, workers=None) -> dict:
    """One run: end-to-end seconds, and the rate between the first and last batch."""
    from pin_susp.study import batches, run_study

    marks = []
    started = time.perf_counter()
    run_study(
        study,
        folder / name,
        scheduler=scheduler,
        workers=workers,
        progress=lambda done, total: marks.append((done, time.perf_counter())),
    )
    total = time.perf_counter() - started
    n = study.samples
    per_batch = n / len(batches(study))
    (first_done, first), (last_done, last) = marks[0], marks[-1]
    running = (last_done - first_done) * per_batch / (last - first) if last > first else n / total
    return {"seconds": total, "end_to_end": n / total, "running": running, "variants": n}


def run(variants: int, full: bool) -> dict:
    from pin_susp.study import load_study

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        study = load_study(study_file(folder, variants))
        report = {"cores": os.cpu_count(), "variants": variants, "ways": {}}
        report["ways"]["serial"] = timed(study, folder, "serial", None)
        report["ways"]["local, 1 worker"] = timed(study, folder, "one", "local", 1)
        report["ways"]["local, 2 workers"] = timed(study, folder, "two", "local", 2)
        if full:
            tolerance = load_study(study_file(folder, 10_000))
            started = time.perf_counter()
            timed(tolerance, folder, "ten_thousand", "local", 2)
            report["ten_thousand_seconds"] = time.perf_counter() - started
    ways = report["ways"]
    report["two_over_one"] = (
        ways["local, 2 workers"]["running"] / ways["local, 1 worker"]["running"]
    )
    return report


def show(report: dict) -> None:
    base = report["ways"]["serial"]["running"]
    print(
        f"study: {report['variants']} variants of double_wishbone.yaml, 21-step bump sweep "
        f"with summaries, {report['cores']} cores"
    )
    print(f"  {'':18s} {'running':>12s} {'end to end':>12s} {'vs serial':>10s}")
    for name, w in report["ways"].items():
        print(
            f"  {name:18s} {w['running']:8.0f} v/s {w['end_to_end']:8.0f} v/s "
            f"{w['running'] / base:9.2f}x"
        )
    print(
        f"  2 workers over 1: {report['two_over_one']:.2f}x (target >= 1.7x); "
        f"2 workers: {report['ways']['local, 2 workers']['running']:.0f} variants/s "
        "(target >= 150)"
    )
    if "ten_thousand_seconds" in report:
        print(
            f"  examples/study_tolerances.yaml (10 000 variants, 2 workers) end to end: "
            f"{report['ten_thousand_seconds']:.1f} s (target <= 90 s)"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", type=int, default=2000, help="variants per way")
    parser.add_argument("--full", action="store_true", help="also the 10 000-variant study")
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    args = parser.parse_args()
    report = run(args.variants, args.full)
    show(report)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
