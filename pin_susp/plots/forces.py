"""The force report (``pin-susp loads``): a panel per member and per joint, a line per
load case; a step at a toggle a gap, noted under the panels.
"""

from __future__ import annotations

import numpy as np

from .axes import (
    Panel,
    combined_note,
    grid,
    header,
    input_panels,
    lone_marker,
    x_axis,
)
from .results_file import ResultsFile

# ---------------------------------------------------------------- the force report

STYLES = ("-", "--", ":", "-.")  # several forces files: one line style each


def force_figure(results: list[ResultsFile]):
    """The force report of forces CSVs (``pin-susp loads``): ``force_panels`` on the
    report's grid, a legend of the load cases, and a note of the steps at a toggle."""
    xname, xlabel = x_axis(results)
    drawn = input_panels(results, xname) + force_panels(results, xname, xlabel)
    fig = grid(drawn)
    handles = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            if not line.get_label().startswith("_"):
                handles.setdefault(line.get_label(), line)
    notes = [n for n in (toggle_note(r, xname) for r in results) if n]
    if notes:
        fig.text(0.01, 0.01, "\n".join(notes), fontsize=8, va="bottom", gid="toggle_note")
    sign = "members: tension +, spring: compression +, joints: magnitude of the load"
    title = f"pin_susp forces ({sign}): " + ", ".join(r.label for r in results)
    bottom = (0.16 * len(notes) + 0.1) if notes else 0.0
    header(fig, title, combined_note(results, xname), list(handles.values()), bottom=bottom)
    return fig


def force_panels(results: list[ResultsFile], xname: str, xlabel: str) -> list[Panel]:
    """One panel per member (``force_<member>``, the spring, the rack) and per joint (the
    magnitude of ``load_<joint>_{x,y,z}``), a line per load case (per file and case for
    several files: a colour per case, a line style per file). A member or joint with no
    value anywhere has no panel; a toggle's rows (blank forces) are gaps, marked."""
    members, joints = force_columns(results)
    cases = list(dict.fromkeys(c for r in results for c in r["load_case"]))
    marks = sorted({x for r in results for x in toggles(r, xname)[1]})
    out = []
    for name in members + joints:
        column = f"load_{name}_x" if name in joints else name
        unit = next((r.units.get(column, "N") for r in results if column in r.columns), "N")
        if name in joints:
            title = f"{name.replace('_', ' ').capitalize()} load (magnitude)"
            ylabel = f"|load_{name}| [{unit}]"
        else:
            title, ylabel = _member_title(name), f"{name} [{unit}]" if unit else name
        panel = Panel(title, ylabel, xlabel, marks=marks, unit=unit)
        for k, r in enumerate(results):
            y_all = joint_load(r, name) if name in joints else r.columns.get(name)
            if y_all is None:
                continue
            for case in dict.fromkeys(r["load_case"]):
                rows = r["load_case"] == case
                who = f"{r.label}: {case}" if len(results) > 1 else str(case)
                colour = f"C{cases.index(case) % 10}"
                y = y_all[rows]
                style = STYLES[k % len(STYLES)]
                panel.lines.append((r[xname][rows], y, who, style, colour, lone_marker(y)))
        if any(np.any(np.isfinite(line[1])) for line in panel.lines):
            out.append(panel)
    if not out:  # every step at a toggle or failed: the members' panels, empty, and the note
        out = [Panel(_member_title(n), n, xlabel, marks=marks) for n in members]
    return out


def force_columns(results: list[ResultsFile]) -> tuple[list[str], list[str]]:
    """The members (the two-force members in the files' order, then the spring and the
    rack) and the joints (``load_<joint>_{x,y,z}`` → ``<joint>``) of forces files."""
    names = list(dict.fromkeys(n for r in results for n in r.columns))
    members = [n for n in names if n.startswith(("force_", "torque_"))]
    last = ("force_spring", "torque_spring", "force_rack")
    members = [n for n in members if n not in last] + [n for n in last if n in members]
    joints = [n[5:-2] for n in names if n.startswith("load_") and n.endswith("_x")]
    joints = [j for j in joints if all(f"load_{j}_{a}" in names for a in "yz")]
    return members, joints


def joint_load(r: ResultsFile, joint: str) -> np.ndarray | None:
    """|load_<joint>_{x,y,z}| at each row (N), or None when the file has no such joint."""
    names = [f"load_{joint}_{a}" for a in "xyz"]
    if not all(n in r.columns for n in names):
        return None
    return np.linalg.norm(np.column_stack([r[n] for n in names]), axis=1)


def _member_title(name: str) -> str:
    side = next((f" {s}" for s in ("left", "right") if name.endswith(f"_{s}")), "")
    base = name.removesuffix(side.replace(" ", "_"))
    if base == "force_spring":
        return f"Spring{side} (compression +)"
    if base == "torque_spring":
        return f"Torsion bar{side} torque"
    if base == "torque_arb":
        return "Anti-roll bar torque"
    if base == "force_rack":
        return "Rack (the trackrods' pull, + left)"
    return f"{base.removeprefix('force_').replace('_', ' ').capitalize()}{side} (tension +)"


def toggles(r: ResultsFile, xname: str) -> tuple[list[int], list[float]]:
    """The steps at a toggle (``loads_unbounded`` = 1: forces unbounded, blank) and their
    x values."""
    flag = r.columns.get("loads_unbounded")
    if flag is None:
        return [], []
    rows = np.flatnonzero(flag == 1.0)
    steps = dict.fromkeys(int(s) for s in r["step_index"][rows])
    xs = dict.fromkeys(float(x) for x in r[xname][rows] if np.isfinite(x))
    return list(steps), list(xs)


def toggle_note(r: ResultsFile, xname: str) -> str:
    """What the report says of a file's toggles and failed steps ('' when none)."""
    steps, xs = toggles(r, xname)
    parts = []
    if steps:
        at = ", ".join(f"{x:.4g}" for x in xs[:8]) + (" ..." if len(xs) > 8 else "")
        parts.append(
            f"forces unbounded (a toggle) at step(s) {_steps(steps)} "
            f"({xname.replace('_', ' ')} {at}): gaps, marked by dotted lines"
        )
    converged = r.columns.get("solver_converged")
    if converged is not None and np.any(converged != 1.0):
        failed = dict.fromkeys(int(s) for s in r["step_index"][converged != 1.0])
        parts.append(f"step(s) {_steps(list(failed))} did not converge: gaps")
    return f"{r.label}: " + "; ".join(parts) if parts else ""


def _steps(steps: list[int]) -> str:
    return ", ".join(map(str, steps[:10])) + (" ..." if len(steps) > 10 else "")
