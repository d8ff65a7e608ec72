"""The standard kinematics report, drawn from results, with matplotlib (Agg, no display).

``report_figure`` draws one panel per metric against what the sweep moved:
wheel travel for a bump sweep, rack travel from centre (the
``rack_displacement`` column) for a steer sweep, several results files as
several lines (a colour per file, the same on every panel, and one legend of
the files); labels and units come from the metric registry and the CSV's
own units. Results of older versions have no ``rack_displacement``: they are
plotted against the absolute ``trackrod_inboard_y`` and the axis says so.
What moved is read from the results (an input held, like a rack at centre,
did not move). A sweep that moved two inputs (bump and steer together) has no
one x: every panel is drawn against the step, the inputs first as panels of
their own, and a note under the title says what moved over what range.
Files whose sweeps moved different things (a bump sweep and a steer sweep)
are refused with an :class:`InputError` naming both: their lines cannot share
an x axis, and two reports say more than one squeezed figure.

A panel's y axis spans at least its unit's MIN_SPAN (0.5 mm, 0.05°, ...):
solver noise and variations too small to matter are drawn flat, not blown up to
the panel's height; a column constant to 1 % of that span is labelled with its
value. A cell beyond ±1e300 (no axis can span it) is refused as it is read.

An axle's results (per-side columns, ``roll``, ``heave``) give the axle report
(``axle_panels``): a line per side (the right dashed) against roll, heave or
rack travel — what the sweep varied, the step when it varied several — and
Ackermann against the mean steer angle when the rack moved.

A vehicle's results (its corners labelled fl, fr, rl, rr; the body's ``heave``,
``pitch``, ``roll``) give the vehicle report (``vehicle_panels``, docs/vehicle.md): a
line per corner (the front solid, the rear dashed, the left and the right a colour
each) and per axle, and the whole car's roll axis, pitch centre, anti % and wheelbase,
against heave, pitch, roll, the steering wheel (the rack without a c-factor) or a road
height under some corners (warp) — the step when several moved. An attitude's results
(``pin-susp attitude``: a row per acceleration) are refused: their plot is its --plot.

A forces CSV (``pin-susp loads``: a ``load_case`` column, a row per step and
case) gives the force report (``force_figure``): a panel per member (the
two-force members, the spring, the rack) and per joint (the magnitude of its
load vector) on the same grid, a line per load case; a step at a toggle
(``loads_unbounded`` = 1, its forces blank) is a gap, marked by a dotted line
and noted under the panels. Forces and a sweep's results are refused together.

Everything here is drawn from a results table (its CSV text): no model is built or
imported, so ``Results.plot`` (corner.py) draws through this module and nothing here
reaches back. The drawings of a corner or an axle — front and side views with the
instant-centre construction — are ``drawing.py``.

The package: ``results_file`` (a results file read back), ``axes`` (what every
report's panels share: labels, the x axis, spans, grid, header), ``kinematics`` (the
kinematics report), ``axle_panels``, ``vehicle_panels``, ``forces`` (the force report),
``output`` (the image file).
"""

# ruff: noqa: E402, F401, F811 (the backend chosen first; the package's names, importable as before)
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np

from ..errors import PinSuspError
from .axes import (
    AXLE_X,
    CONSTANT_SHARE,
    LABELS,
    MIN_SPAN,
    RACK_ABSOLUTE_X,
    RACK_X,
    RELATIVE_SPAN,
    STEP_X,
    VEHICLE_X,
    WHEEL_X,
    Panel,
    combined_note,
    input_column,
    input_panels,
    label,
    lone_marker,
    min_span,
    moved,
    sweeps,
    x_axis,
)
from .axle_panels import ACKERMANN, AXLE_PANELS, axle_panels, mean_steer_angle
from .forces import (
    STYLES,
    force_columns,
    force_figure,
    force_panels,
    joint_load,
    toggle_note,
    toggles,
)
from .kinematics import panels, report_figure
from .output import check_image_path, save_figure
from .results_file import DERIVED, DRAWABLE, EXTRA, TEXT, VEHICLE_CORNERS, ResultsFile
from .vehicle_panels import VEHICLE_PANELS, vehicle_panels


def plot_results(results, path, label: str | None = None) -> None:
    """``Results.plot``: the standard report of a results table (a sweep's, an axle's, a
    vehicle's or member_forces') drawn from its CSV text, as ``pin-susp plot`` draws the file, into
    an image file (format from its ending). ``label``: the name in the title (default:
    the sweep file's). A PinSuspError when no step converged, before any drawing."""
    from ..io.tables import csv_text

    check_image_path(path)  # before any work
    if len(results) == 0 or not np.any(results.columns["solver_converged"]):
        raise PinSuspError(f"{path}: no step converged: nothing to plot")
    source = str(results.meta.get("sweep", ("",))[0] or "")
    name = "" if source.startswith("<") else Path(source).name
    written = ResultsFile(name or "results", raw=csv_text(results).encode())
    if label is not None:
        written.label = label
    save_figure(report_figure([written]), path)
