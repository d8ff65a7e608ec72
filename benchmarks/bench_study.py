"""Studies' speed: variants per second, serially and on a LocalCluster of 1 and 2 workers.

A Monte Carlo of the example corner (every hardpoint coordinate within ±0.5 mm)
through a 21-step bump sweep with summaries (examples/bump_rack_held.yaml), each
way in turn in this process, so that the ratios compare like with like:

- serial: ``scheduler=None``, the batches one after another in this process —
  the baseline;
- LocalCluster with 1 and with 2 worker processes (127.0.0.1): the rate while the
  batches run (first batch done → last batch done), and end to end (the cluster's
  start, the variants' table and the files included);
- a 1 000-variant DOE (docs/studies.md's: two hardpoint heights, Latin hypercube)
  end to end, serially and on 2 workers;
- the optimisation of examples/study_bump_steer.yaml (4 starts, exact-sensitivity
  least squares) end to end, `pin-susp study --scheduler none` in a fresh process
  (the best of 3), against its time before issue 30;
- the 10 000-variant tolerance study of examples/study_tolerances.yaml end to end
  on 2 workers, as `pin-susp study` runs it (--full only);
- the DOE through `pin-susp study` in a fresh process, serially and on 2 workers (the
  interpreter's start and every import included);
- an axle's and a vehicle's variants, serially (each built and marched as its direct
  sweep is): Monte Carlos of examples/axle_front.yaml through examples/heave_roll.yaml
  and of examples/vehicle_fs.yaml through examples/vehicle_roll.yaml (every hardpoint
  within ±0.5 mm); against the baseline of the same variants each built and swept as a
  script would (``build``, ``run_sweep`` of the sweep and of its design state), in this
  process.

The imports a study pays once per process (scipy.stats for a DOE's sampler, matplotlib
for study.png, pyarrow, dask.distributed) are made and timed first, so that no run's
end to end includes them, as none includes pinocchio's or pin_susp's.

Each run's fixed costs are printed by name (``Outcome.seconds``: the variants' table,
the first-order prediction, the cluster's start and close, the part files, the
assembly, the summary, study.png, variants.parquet), with the time to the first batch
done and from the last one to the end.

Targets (issue 30): ≥ 1 500 variants/s end to end on 2 workers (the 10 000-variant
Monte Carlo and the 1 000-variant DOE), ≥ 800 variants/s serially; the optimisation
≥ 5× faster than before (OPTIMISE_BEFORE).

    python benchmarks/bench_study.py [--variants N] [--doe N] [--optimise-runs N] [--full]
        [--assemblies N] [--cli-runs N] [--json OUT.json]
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


# `pin-susp study examples/study_bump_steer.yaml --scheduler none` end to end (a fresh
# process, as below) at bf63458, before issue 30, on this 2-core machine: 26.5 s, then
# 21.1 and 21.5 s run in alternation with the code of after; the mean of those two
OPTIMISE_BEFORE = 21.3
TARGETS = {"serial": 800.0, "two workers": 1500.0, "optimise": 5.0}


def doe_file(folder: Path, samples: int) -> Path:
    """docs/studies.md's DOE: two hardpoint heights of the example corner."""
    data = {
        "version": 1,
        "geometry": str(EXAMPLES / "double_wishbone.yaml"),
        "sweep": str(EXAMPLES / "bump_rack_held.yaml"),
        "variables": [
            {"point": "trackrod_inboard", "axis": "z", "range": [-15, 15]},
            {"point": "upper_wishbone_outboard", "axis": "z", "range": [-10, 10]},
        ],
        "kind": "doe",
        "doe": {"method": "latin_hypercube", "samples": samples, "seed": 1},
        "summary": ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"],
    }
    path = folder / f"doe_{samples}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def optimise(out: Path, runs: int = 3) -> float:
    """`pin-susp study examples/study_bump_steer.yaml --scheduler none` end to end, in a
    fresh process as a user runs it (its imports included, as in OPTIMISE_BEFORE): the
    best of ``runs`` (the machine's other load only ever adds to a run)."""
    import subprocess
    import sys

    best = float("inf")
    for run in range(runs):
        study = str(EXAMPLES / "study_bump_steer.yaml")
        command = [sys.executable, "-m", "pin_susp", "study", study, "-o", str(out / f"{run}")]
        command += ["--scheduler", "none", "-q"]
        started = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        best = min(best, time.perf_counter() - started)
    return best


def timed(study, folder: Path, name: str, scheduler, workers=None) -> dict:
    """One run: end-to-end seconds, and the rate between the first and last batch."""
    from pin_susp.study import batches, run_study

    marks = []
    started = time.perf_counter()
    outcome = run_study(
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
    phases = dict(outcome.seconds)
    phases["(to the first batch done)"] = first - started
    phases["(after the last batch done)"] = started + total - last
    return {
        "seconds": total,
        "end_to_end": n / total,
        "running": running,
        "variants": n,
        "phases": phases,
    }


def imports() -> dict:
    """The imports a study pays once per process, before any run here: each run's end to
    end then leaves them out, as it leaves out pinocchio's and pin_susp's (else only the
    first run of a kind would pay them: the DOE's sampler, the first study.png)."""
    seconds = {}
    for name, statement in (
        ("scipy.stats (a DOE's sampler)", "import scipy.stats"),
        ("matplotlib (study.png)", "import pin_susp.study.plots, pin_susp.plots"),
        ("pyarrow.parquet (the tables)", "import pyarrow.parquet"),
        ("dask.distributed (a cluster)", "import distributed"),
    ):
        started = time.perf_counter()
        exec(statement, {})
        seconds[name] = time.perf_counter() - started
    return seconds


def cli(folder: Path, study: Path, scheduler: str, runs: int = 2) -> float:
    """`pin-susp study STUDY` in a fresh process as a user runs it, its imports and the
    interpreter's start included: the best of ``runs``."""
    import subprocess
    import sys

    best = float("inf")
    for run in range(runs):
        out = folder / f"cli_{study.stem}_{scheduler}_{run}"
        command = [sys.executable, "-m", "pin_susp", "study", str(study), "-o", str(out), "-q"]
        started = time.perf_counter()
        subprocess.run([*command, "--scheduler", scheduler], check=True, capture_output=True)
        best = min(best, time.perf_counter() - started)
    return best


ASSEMBLIES = {  # name → (geometry, sweep): the example axle's roll at a ride height
    "axle": ("axle_front.yaml", "heave_roll.yaml"),
    "vehicle": ("vehicle_fs.yaml", "vehicle_roll.yaml"),
}


def assembly_file(folder: Path, name: str, samples: int) -> Path:
    """A Monte Carlo of ASSEMBLIES[name]: every hardpoint coordinate of every corner
    within ±0.5 mm."""
    geometry, sweep = ASSEMBLIES[name]
    data = {
        "version": 1,
        "geometry": str(EXAMPLES / geometry),
        "sweep": str(EXAMPLES / sweep),
        "variables": {"all_hardpoints": {"tolerance": 0.5}},
        "kind": "monte_carlo",
        "monte_carlo": {"samples": samples, "seed": 1, "distribution": "normal"},
    }
    path = folder / f"{name}_{samples}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def scripted(study, count: int) -> float:
    """Seconds a variant of ``study`` takes built and swept as a script would: its
    subject from its data, ``run_sweep`` of the sweep, then of its design state (the
    mean over the first ``count`` variants)."""
    import warnings

    from pin_susp.model.sweep import load_sweep
    from pin_susp.study.variants import at_design, build, variant_data, variant_table

    sweep = load_sweep(study.sweep_data)
    design = at_design(sweep)
    table = variant_table(study)[:count]
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for deltas in table:
            subject = build(variant_data(study.geometry_data, study.variables, deltas), "v")
            subject.run_sweep(sweep)
            subject.run_sweep(design)
    return (time.perf_counter() - started) / count


def assemblies(folder: Path, samples: int) -> dict:
    """An axle's and a vehicle's variants per second, serially, and the scripted
    baseline's (``scripted``)."""
    from pin_susp.study import load_study

    out = {}
    for name in ASSEMBLIES:
        study = load_study(assembly_file(folder, name, samples))
        run = timed(study, folder, f"{name}_serial", None)
        run["scripted"] = scripted(study, min(study.samples, 20))
        out[name] = run
    return out


def run(
    variants: int,
    full: bool,
    doe_variants: int = 1000,
    optimise_runs: int = 3,
    assembly_variants: int = 100,
    cli_runs: int = 2,
) -> dict:
    from pin_susp.study import load_study

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        report = {"cores": os.cpu_count(), "variants": variants, "ways": {}}
        report["cli_runs"] = cli_runs
        report["imports"] = imports()
        study = load_study(study_file(folder, variants))
        report["doe_variants"] = doe_variants
        report["ways"]["serial"] = timed(study, folder, "serial", None)
        report["ways"]["local, 1 worker"] = timed(study, folder, "one", "local", 1)
        report["ways"]["local, 2 workers"] = timed(study, folder, "two", "local", 2)
        doe = load_study(doe_file(folder, doe_variants))
        report["doe"] = {
            "serial": timed(doe, folder, "doe_serial", None),
            "local, 2 workers": timed(doe, folder, "doe_two", "local", 2),
        }
        report["assemblies"] = assemblies(folder, assembly_variants)
        report["doe_cli"] = {  # (none with --cli-runs 0)
            way: cli(folder, doe_file(folder, doe_variants), way, cli_runs)
            for way in ("none", "local")
            if cli_runs
        }
        report["optimise_seconds"] = optimise(folder / "optimise", optimise_runs)
        if full:
            tolerance = load_study(study_file(folder, 10_000))
            report["ten_thousand"] = timed(tolerance, folder, "ten_thousand", "local", 2)
    ways = report["ways"]
    report["two_over_one"] = (
        ways["local, 2 workers"]["running"] / ways["local, 1 worker"]["running"]
    )
    return report


def show(report: dict) -> None:
    base = report["ways"]["serial"]["end_to_end"]
    print(
        f"study: {report['variants']} variants of double_wishbone.yaml, 21-step bump sweep "
        f"with summaries, {report['cores']} cores"
    )
    print(f"  {'':26s} {'running':>12s} {'end to end':>12s} {'vs serial':>10s} {'target':>12s}")

    def line(name, w, target=None):
        goal = f">= {target:.0f} v/s" if target else ""
        ok = "" if not target else ("  met" if w["end_to_end"] >= target else "  NOT met")
        print(
            f"  {name:26s} {w['running']:8.0f} v/s {w['end_to_end']:8.0f} v/s "
            f"{w['end_to_end'] / base:9.2f}x {goal:>12s}{ok}"
        )

    for name, w in report["ways"].items():
        target = {"serial": TARGETS["serial"], "local, 2 workers": TARGETS["two workers"]}
        line(name, w, target.get(name))
    for name, w in report["doe"].items():
        target = TARGETS["serial"] if name == "serial" else TARGETS["two workers"]
        line(f"DOE {report['doe_variants']}, {name}", w, target)
    if "ten_thousand" in report:
        line("tolerances 10 000, 2 workers", report["ten_thousand"], TARGETS["two workers"])
        print(
            "  examples/study_tolerances.yaml (10 000 variants, 2 workers) end to end: "
            f"{report['ten_thousand']['seconds']:.1f} s"
        )
    print(f"  2 workers over 1 (running): {report['two_over_one']:.2f}x")
    print("  imports paid once per process, before the runs above (in no run's end to end):")
    for name, seconds in report["imports"].items():
        print(f"    {name:36s} {seconds:6.3f} s")
    cli = report["doe_cli"]
    if cli:
        print(
            f"  `pin-susp study` of the DOE {report['doe_variants']} in a fresh process (its "
            f"imports, the interpreter's start): {cli['none']:.2f} s serially, "
            f"{cli['local']:.2f} s on 2 workers (best of {report['cli_runs']})"
        )
    for name, w in report["assemblies"].items():
        per = w["phases"]["batches"] / w["variants"]
        print(
            f"  {name} ({w['variants']} variants, serially): {w['end_to_end']:.0f} v/s end to "
            f"end, {per * 1e3:.1f} ms a variant in its batch; built and swept as a script "
            f"would: {w['scripted'] * 1e3:.1f} ms ({w['scripted'] / per:.2f}x)"
        )
    show_phases(report)
    seconds = report["optimise_seconds"]
    gain = OPTIMISE_BEFORE / seconds
    print(
        f"  examples/study_bump_steer.yaml (optimise, --scheduler none): {seconds:.1f} s, "
        f"{gain:.1f}x faster than before issue 30 ({OPTIMISE_BEFORE} s; target >= "
        f"{TARGETS['optimise']:.0f}x: {'met' if gain >= TARGETS['optimise'] else 'NOT met'})"
    )


def show_phases(report: dict) -> None:
    """Where each run's time went, phase by phase (seconds): the batches, and the fixed
    costs around them."""
    doe = f"DOE {report['doe_variants']}"
    runs = {**report["ways"], **{f"{doe}, {k}": w for k, w in report["doe"].items()}}
    if "ten_thousand" in report:
        runs["tolerances 10 000, 2 workers"] = report["ten_thousand"]
    short = {
        "serial": "serial",
        "local, 1 worker": "1 worker",
        "local, 2 workers": "2 workers",
        f"{doe}, serial": "DOE ser.",
        f"{doe}, local, 2 workers": "DOE 2 w.",
        "tolerances 10 000, 2 workers": "10k 2 w.",
    }
    # in the order of the run with the most phases (a cluster's: its start and close too)
    fullest = sorted(runs.values(), key=lambda w: -len(w["phases"]))
    names = list(dict.fromkeys(k for w in fullest for k in w["phases"]))
    print("  where the time went (s):")
    print(f"    {'':28s}" + "".join(f"{short.get(r, r)[:9]:>10s}" for r in runs))
    for name in [*names, "end to end"]:
        cells = [
            w["seconds"] if name == "end to end" else w["phases"].get(name) for w in runs.values()
        ]
        print(
            f"    {name:28s}"
            + "".join(f"{c:10.3f}" if c is not None else f"{'':10s}" for c in cells)
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", type=int, default=2000, help="variants per way")
    parser.add_argument("--doe", type=int, default=1000, help="the DOE's variants")
    parser.add_argument("--full", action="store_true", help="also the 10 000-variant study")
    parser.add_argument("--optimise-runs", type=int, default=3, help="best of N optimisations")
    parser.add_argument("--assemblies", type=int, default=100, help="an axle's, a car's")
    parser.add_argument("--cli-runs", type=int, default=2, help="best of N DOEs by the CLI")
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    args = parser.parse_args()
    report = run(
        args.variants, args.full, args.doe, args.optimise_runs, args.assemblies, args.cli_runs
    )
    show(report)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
