"""How long `pin-susp sweep` takes from the shell, against `python -c "import pinocchio"`.

    python benchmarks/bench_startup.py [--rounds N] [--json OUT.json]

The 41-step example (examples/double_wishbone.yaml through examples/bump_steer.yaml,
copied into a temporary folder, the CSV written there) is run as a new process
each time, in alternation with the baseline, a process that imports Pinocchio
(and so numpy) and nothing else: the part of the start-up that no change to
pin_susp can remove. It prints, for each, the median wall time and its range
over the rounds, then the ratio and the difference of the medians (target 4 of
issue 17: the sweep in <= 0.35 s).

Two settings of Python's bytecode cache, each measured the same way:

- as this shell has it (PYTHONDONTWRITEBYTECODE=1 makes Python compile
  pin_susp's own modules from source at every start);
- with a bytecode cache (a temporary PYTHONPYCACHEPREFIX, filled by a first
  run), as an installed package or an editable one that may write __pycache__ has.

Last, the largest entries of `python -X importtime` for the same sweep, by
each module's own time, with their cumulative time (microseconds).

Timing lives here, never in the tests (tests/test_startup.py checks which
modules a command imports).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
GEOMETRY, SWEEP = "double_wishbone.yaml", "bump_steer.yaml"
TARGET = 0.35  # s, the sweep's wall time


def sweep_command() -> list[str]:
    """The console script beside this Python (as a user runs it), else its module."""
    script = Path(sys.executable).with_name("pin-susp")
    if script.exists():
        return [str(script)]
    return [sys.executable, "-m", "pin_susp.cli"]


def wall(command: list[str], cwd: Path, env: dict) -> float:
    """Seconds from start to exit of one process (which must succeed)."""
    started = time.perf_counter()
    proc = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(command)} exited {proc.returncode}:\n{proc.stderr}")
    return seconds


def summary(samples: list[float]) -> dict:
    return {"median": statistics.median(samples), "min": min(samples), "max": max(samples)}


def measure(rounds: int, cwd: Path, env: dict) -> dict:
    """The sweep and the baseline, alternating, ``rounds`` times each (after one of each
    to warm the disk cache and, where enabled, the bytecode cache)."""
    sweep = [*sweep_command(), "sweep", GEOMETRY, SWEEP, "-o", "out.csv", "-q"]
    baseline = [sys.executable, "-c", "import pinocchio"]
    wall(sweep, cwd, env), wall(baseline, cwd, env)
    times = {"sweep": [], "baseline": []}
    for i in range(rounds):
        order = ("sweep", "baseline") if i % 2 == 0 else ("baseline", "sweep")
        for name in order:
            times[name].append(wall(sweep if name == "sweep" else baseline, cwd, env))
    out = {name: summary(samples) for name, samples in times.items()}
    s, b = out["sweep"]["median"], out["baseline"]["median"]
    out["ratio"], out["difference_s"] = s / b, s - b
    return out


def show(label: str, m: dict) -> None:
    print(label)
    for name, what in (("sweep", "pin-susp sweep (41 steps)"), ("baseline", "import pinocchio")):
        t = m[name]
        print(f"  {what:28} median {t['median']:6.3f} s   range {t['min']:.3f} … {t['max']:.3f} s")
    print(
        f"  sweep / baseline {m['ratio']:.2f}x, sweep − baseline {m['difference_s'] * 1e3:.0f} ms"
        f"   (target: sweep <= {TARGET:g} s)"
    )


def importtime(cwd: Path, env: dict, top: int) -> list[dict]:
    """The largest -X importtime entries of one sweep, by self time."""
    code = (
        "import sys; from pin_susp.cli import main; "
        f"sys.exit(main(['sweep', {GEOMETRY!r}, {SWEEP!r}, '-o', 'out.csv', '-q']))"
    )
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", code],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
    )
    if proc.returncode != 0:
        raise SystemExit(f"the sweep under -X importtime exited {proc.returncode}:\n{proc.stderr}")
    entries = []
    for line in proc.stderr.splitlines():
        if not line.startswith("import time:") or "self [us]" in line:
            continue
        own, cumulative, name = line.removeprefix("import time:").split("|")
        entries.append(
            {"module": name.strip(), "self_us": int(own), "cumulative_us": int(cumulative)}
        )
    total = sum(e["self_us"] for e in entries)
    print(f"-X importtime of the sweep: {len(entries)} modules, {total / 1e3:.0f} ms in all")
    print(f"  {'module':44}{'self ms':>9}{'cumulative ms':>15}")
    largest = sorted(entries, key=lambda e: -e["self_us"])[:top]
    for e in largest:
        print(f"  {e['module']:44}{e['self_us'] / 1e3:9.1f}{e['cumulative_us'] / 1e3:15.1f}")
    ours = [e for e in entries if e["module"].split(".")[0] == "pin_susp"]
    print(
        f"  pin_susp's own modules: {len(ours)}, "
        f"{sum(e['self_us'] for e in ours) / 1e3:.0f} ms self: "
        + ", ".join(e["module"].removeprefix("pin_susp.") for e in ours)
    )
    return largest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=10, help="runs of each (default 10)")
    parser.add_argument("--top", type=int, default=20, help="-X importtime entries shown")
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    args = parser.parse_args()
    report = {"machine": {"python": platform.python_version(), "rounds": args.rounds}}
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        for name in (GEOMETRY, SWEEP):
            shutil.copy(EXAMPLES / name, work / name)
        as_is = dict(os.environ)
        cached = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        cached["PYTHONPYCACHEPREFIX"] = str(work / "pycache")
        dont = "PYTHONDONTWRITEBYTECODE=1" if os.environ.get("PYTHONDONTWRITEBYTECODE") else ""
        settings = (
            ("as_is", as_is, f"bytecode cache as this shell has it {dont or '(enabled)'}"),
            ("cached", cached, "with a bytecode cache (temporary PYTHONPYCACHEPREFIX)"),
        )
        for key, env, label in settings:
            report[key] = measure(args.rounds, work, env)
            show(label.strip(), report[key])
        report["importtime"] = importtime(work, as_is, args.top)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
