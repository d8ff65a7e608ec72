"""The kinematics report: a panel per metric against what the sweep moved, several
results files as several lines; an axle's, a vehicle's and a forces file's reports
chosen here.
"""

from __future__ import annotations

import numpy as np

from ..columns.metrics import HUB_Z, RACK, STANDARD
from ..errors import InputError, PinSuspError
from .axes import (
    STEP_X,
    Panel,
    all_of,
    colour,
    combined_note,
    grid,
    has_values,
    header,
    input_panels,
    label,
    marker_for,
    x_axis,
)
from .axle_panels import axle_panels
from .forces import force_figure
from .results_file import DERIVED, EXTRA, ResultsFile
from .vehicle_panels import vehicle_panels


def panels(results: list[ResultsFile], xname: str) -> list[str]:
    """The corner report's metric columns with a value in some file, in order: the
    standard metrics, EXTRA, and the derivatives of DERIVED along what the sweep moved
    (bump and steer both for a combined sweep, drawn against the step)."""
    drivers = {"wheel_travel": (HUB_Z,), STEP_X[0]: (HUB_Z, RACK)}.get(xname, (RACK,))
    names = list(STANDARD) + list(EXTRA)
    names += [f"deriv_{m}_wrt_{d}" for d in drivers for m in DERIVED]
    return [n for n in names if any(has_values(r, n) for r in results)]


def report_figure(results: list[ResultsFile]):
    """One panel per metric against what the sweep moved, one line (and one colour) per
    results file, a legend of the files; a sweep that moved several inputs against the
    step, its inputs drawn first. An axle's results: the axle report (``axle_panels``); a
    vehicle's: the vehicle report (``vehicle_panels``)."""
    if not results:
        raise PinSuspError("no results file to plot")
    if all_of(results, "forces", "a sweep's results", "holds forces (pin-susp loads)"):
        return force_figure(results)
    odd = next((r for r in results if not r.vehicle), results[0])
    vehicle = all_of(results, "vehicle", f"{odd.kind} results", "is a vehicle's")
    axle = all_of(results, "axle", "a corner's results", "is an axle's")
    xname, xlabel = x_axis(results)
    for r in results[1:]:
        if xname not in r.columns or not np.any(np.isfinite(r[xname])):
            raise InputError(
                r.source,
                xname,
                f"no values, but {results[0].label} is plotted against it: "
                "plot results of the same kind of sweep together",
            )
    if vehicle:
        drawn = vehicle_panels(results, xname, xlabel)
        title = "pin_susp vehicle kinematics: "
    elif axle:
        drawn = axle_panels(results, xname, xlabel)
        title = "pin_susp axle kinematics: "
    else:
        drawn = [_corner_panel(results, name, xname, xlabel) for name in panels(results, xname)]
        title = "pin_susp kinematics: "
    if not drawn:
        files = ", ".join(r.source for r in results)
        raise InputError(files, "", "no metric column has a value to plot")
    drawn = input_panels(results, xname) + drawn
    fig = grid(drawn)
    handles = []
    if not (axle or vehicle) and len(results) > 1:  # theirs name file and side themselves
        from matplotlib.lines import Line2D

        handles = [
            Line2D([], [], color=colour(k), lw=1.6, label=r.label) for k, r in enumerate(results)
        ]
    header(fig, title + ", ".join(r.label for r in results), combined_note(results, xname), handles)
    return fig


def _corner_panel(results: list[ResultsFile], name: str, xname: str, xlabel: str) -> Panel:
    unit = next((r.units.get(name, "") for r in results if name in r.columns), "")
    panel = Panel(label(name), f"{name} [{unit}]" if unit else name, xlabel, unit=unit)
    for k, r in enumerate(results):
        if name in r.columns:  # a file's colour by its place in the list, on every panel
            panel.lines.append((r[xname], r[name], r.label, "-", colour(k), marker_for(r, name)))
    return panel
