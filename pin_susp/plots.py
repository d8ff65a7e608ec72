"""The standard kinematics report and 2D drawings, with matplotlib (Agg, no display).

``report_figure`` draws one panel per metric against wheel travel (or rack
position for a steer sweep), several results files as several lines;
labels and units come from the metric registry and the CSV's own units.
``drawing_figure`` draws the corner in front and side view.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .errors import InputError, PinSuspError  # noqa: E402
from .export import atomic_write  # noqa: E402
from .metrics import HUB_Z, METRIC_BY_NAME, RACK, STANDARD, Derivative  # noqa: E402

EXTRA = (
    "svic_z",
    "fvic_z",
    "anti_dive",
    "anti_lift",
    "anti_squat",
    "rocker_angle",
    "damper_length",
    "motion_ratio",
)
DERIVED = ("camber", "roadwheel_angle")  # their derivative columns get panels


class ResultsFile:
    """A results CSV read back: columns as float arrays (empty cells → NaN), units.

    Anything that is not a results CSV pin_susp could have written (binary,
    empty, no rows, ragged rows, a corrupt ``# units:`` line, no numbers at
    all) is an :class:`InputError` naming the file; empty cells and empty
    columns are fine (a failed step, an undefined metric) and are not drawn.
    """

    def __init__(self, path: str | Path, name: str | Path | None = None):
        """``name``: what messages and the legend call the file (default: ``path``)."""
        self.path = Path(path)
        self.source = source = str(path if name is None else name)
        self.label = Path(source).stem
        try:
            raw = self.path.read_bytes()
        except OSError as exc:
            raise InputError(source, "", f"cannot be read ({exc.strerror})") from None
        if not raw.strip():
            raise InputError(source, "", "is empty: not a pin_susp results CSV")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        if text is None or "\x00" in text:
            raise InputError(source, "", "is not a text file: not a pin_susp results CSV")
        comments, rows = [], []
        for number, line in enumerate(text.splitlines(), start=1):
            if line.startswith("#"):
                comments.append(line)
            elif line.strip():
                rows.append((number, line.split(",")))
        if not rows or "step_index" not in rows[0][1]:
            raise InputError(source, "", "not a pin_susp results CSV (no step_index column)")
        (_, header), body = rows[0], rows[1:]
        if not body:
            raise InputError(source, "", "no data rows (only a header)")
        seen: set[str] = set()
        twice = next((n for n in header if n in seen or seen.add(n)), None)
        if twice is not None:
            raise InputError(source, twice, "this column appears twice in the header")
        for number, row in body:
            if len(row) != len(header):
                raise InputError(
                    source,
                    f"line {number}",
                    f"{len(row)} cells, but the header has {len(header)} columns "
                    "(a damaged or hand-edited file)",
                )
        self.units = {}
        for line in comments:
            if line.startswith("# units:"):
                self.units = _units(source, line.removeprefix("# units:"))
        self.columns = {}
        for j, name in enumerate(header):
            try:
                self.columns[name] = np.array([_cell(row[j]) for _, row in body])
            except ValueError:
                raise InputError(source, name, "has a cell that is not a number") from None
        for needed in ("wheel_travel", "camber"):
            if needed not in self.columns:
                raise InputError(source, needed, "missing column: not a sweep results CSV")
        if not any(np.any(np.isfinite(c)) for c in self.columns.values()):
            raise InputError(source, "", "no numbers in it: every data cell is empty")
        if not np.any(np.isfinite(self.columns["wheel_travel"])):
            converged = self.columns.get("solver_converged")
            if converged is not None and not np.any(converged == 1.0):
                raise InputError(source, "", "no step of this sweep converged: nothing to plot")
            raise InputError(source, "wheel_travel", "no values: every cell is empty")

    def __getitem__(self, name):
        return self.columns[name]


def _cell(text: str) -> float:
    """A CSV cell as written by pin_susp: a number, empty (NaN), True or False."""
    text = text.strip()
    if text == "":
        return np.nan
    if text in ("True", "False"):
        return float(text == "True")
    return float(text)


def _units(source: str, text: str) -> dict[str, str]:
    """The ``# units:`` comment: a JSON object of column → unit."""
    try:
        units = json.loads(text)
    except ValueError as exc:
        raise InputError(source, "# units", f"not valid JSON ({exc})") from None
    if not isinstance(units, dict):
        raise InputError(source, "# units", f"expected a JSON object, got {type(units).__name__}")
    bad = next((k for k, v in units.items() if not isinstance(v, str)), None)
    if bad is not None:
        raise InputError(source, f"# units: {bad}", f"expected a unit string, got {units[bad]!r}")
    return units


def label(name: str) -> str:
    """Human label of a column, from the registry."""
    if name in METRIC_BY_NAME:
        return METRIC_BY_NAME[name].label
    if name == "motion_ratio":
        return "Motion ratio"
    if name.startswith("deriv_"):
        metric, driver = name.removeprefix("deriv_").split("_wrt_")
        return Derivative(METRIC_BY_NAME[metric], driver).label
    return name.replace("_", " ")


def x_axis(results: ResultsFile) -> tuple[str, str]:
    """Wheel travel when the wheel moves, else the rack position (a steer sweep)."""
    rack = results.columns.get("trackrod_inboard_y")
    if _varies(results["wheel_travel"]) or rack is None or not _varies(rack):
        return "wheel_travel", "Wheel travel (+ bump) [mm]"
    return "trackrod_inboard_y", "Rack position (trackrod_inboard y) [mm]"


def _varies(column: np.ndarray) -> bool:
    finite = column[np.isfinite(column)]
    return finite.size > 1 and float(np.ptp(finite)) > 1e-6


def panels(results: list[ResultsFile], xname: str) -> list[str]:
    driver = HUB_Z if xname == "wheel_travel" else RACK
    names = list(STANDARD) + list(EXTRA)
    names += [f"deriv_{m}_wrt_{driver}" for m in DERIVED]
    return [n for n in names if any(n in r.columns and np.any(np.isfinite(r[n])) for r in results)]


def report_figure(results: list[ResultsFile]):
    """One panel per metric against wheel travel (or rack), one line per results file."""
    if not results:
        raise PinSuspError("no results file to plot")
    xname, xlabel = x_axis(results[0])
    for r in results[1:]:
        if xname not in r.columns or not np.any(np.isfinite(r[xname])):
            raise InputError(
                r.source,
                xname,
                f"no values, but {results[0].label} is plotted against it: "
                "plot results of the same kind of sweep together",
            )
    names = panels(results, xname)
    if not names:
        files = ", ".join(r.source for r in results)
        raise InputError(files, "", "no metric column has a value to plot")
    ncols = 4
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.1 * nrows), squeeze=False)
    for ax, name in zip(axes.flat, names, strict=False):
        unit = next((r.units.get(name, "") for r in results if name in r.columns), "")
        for r in results:
            if name in r.columns:
                # a lone point (one row, or one step between failed ones) shows as a dot
                ax.plot(r[xname], r[name], label=r.label, linewidth=1.6, marker=_marker(r, name))
        ax.set_title(label(name), fontsize=10)
        ax.set_ylabel(f"{name} [{unit}]" if unit else name, fontsize=8)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
    for ax in list(axes.flat)[len(names) :]:
        ax.set_visible(False)
    if len(results) > 1:
        axes.flat[0].legend(fontsize=8)
    fig.suptitle("pin_susp kinematics: " + ", ".join(r.label for r in results), fontsize=12)
    fig.tight_layout()
    return fig


def _marker(r: ResultsFile, name: str) -> str | None:
    finite = np.isfinite(r[name])
    lone = finite & ~np.r_[False, finite[:-1]] & ~np.r_[finite[1:], False]
    return "o" if np.any(lone) else None


def drawing_figure(corner):
    """Front view (y–z) and side view (x–z) of the corner at its (as-set) design state."""
    from .viz import LINKS, segments

    fig, (front, side) = plt.subplots(1, 2, figsize=(14, 6))
    corners = [(corner, 1.0, "-")]
    if corner.geometry.drawn is not None:
        from .corner import Corner

        corners.insert(0, (Corner(corner.geometry.drawn, apply_setup=False), 0.3, "--"))
    for c, alpha, style in corners:
        p = {k: v * 1e3 for k, v in c.design_positions.items()}
        colours = dict(c.tree.materials)
        for v in c.tree.visuals:
            if v.shape == "rod" and v.material != "tyre":
                _both(
                    front,
                    side,
                    v.start,
                    v.end,
                    style,
                    color=colours[v.material][:3],
                    alpha=alpha,
                    lw=2,
                )
        for name, (a, b) in segments(c, c.design_positions).items():
            axis = name == "steering_axis"
            _both(
                front,
                side,
                a,
                b,
                ":" if axis else style,
                alpha=alpha,
                lw=1.5,
                color="goldenrod" if axis else f"#{LINKS[name][1]:06x}",
            )
        _tyre(front, side, c, p, alpha, style)
        pts = np.array([p[n] for n in c.geometry.hardpoints])
        front.plot(pts[:, 1], pts[:, 2], "o", color="0.2", ms=3, alpha=alpha)
        side.plot(pts[:, 0], pts[:, 2], "o", color="0.2", ms=3, alpha=alpha)
    ground = corner.design_positions["contact_patch_center"][2] * 1e3
    for ax, title, xl in (
        (front, "Front view", "y [mm] (+ left)"),
        (side, "Side view", "x [mm] (+ forward)"),
    ):
        ax.axhline(ground, color="0.5", lw=0.8)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.set_title(title)
        ax.set_xlabel(xl)
        ax.set_ylabel("z [mm]")
    if corner.geometry.sign < 0:
        front.invert_xaxis()  # a right corner seen from the front: outboard to the left
    note = " (dashed: as drawn)" if len(corners) > 1 else ""
    fig.suptitle(f"{corner.geometry.name}{note}")
    fig.tight_layout()
    return fig


def _both(front, side, a, b, style, **kwargs) -> None:
    """A segment (m) in front view (y, z) and side view (x, z), in mm."""
    a, b = a * 1e3, b * 1e3
    front.plot([a[1], b[1]], [a[2], b[2]], style, **kwargs)
    side.plot([a[0], b[0]], [a[2], b[2]], style, **kwargs)


def _tyre(front, side, c, p, alpha, style) -> None:
    """The tyre's outline: a rectangle in front view, its circle in side view."""
    from .geometry import wheel_down

    wc = p["wheel_center"]
    a = (p["axle_outboard"] - p["axle_inboard"]) / np.linalg.norm(
        p["axle_outboard"] - p["axle_inboard"]
    )
    down, _ = wheel_down(a)
    r = c.geometry.wheel.radius * 1e3
    w = c.geometry.wheel.section_width * 1e3 / 2
    box = np.array(
        [
            wc + sa * w * a + sd * r * down
            for sa, sd in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))
        ]
    )
    front.plot(box[:, 1], box[:, 2], style, color="0.15", alpha=alpha, lw=1.2)
    t = np.linspace(0, 2 * np.pi, 120)
    side.plot(
        wc[0] + r * np.cos(t), wc[2] + r * np.sin(t), style, color="0.15", alpha=alpha, lw=1.2
    )


def check_image_path(path: str | Path) -> None:
    """Raise PinSuspError unless matplotlib can write an image with this file's ending.

    Cheap, and the output path is not touched (nothing created, opened or
    checked): meant for every image output before any work starts. The
    formats are matplotlib's own list; the ending is matched case-insensitively
    (``OUT.PNG`` is a PNG). Only 'pgf' looks further: for its TeX program.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    supported = FigureCanvasBase.get_supported_filetypes()
    ext = _extension(path)
    hint = f"(use {', '.join(f for f in ('png', 'pdf', 'svg') if f in supported)}, ...)"
    if not ext:
        raise PinSuspError(f"{path}: no file ending to tell the image format {hint}")
    if ext not in supported:
        raise PinSuspError(f"{path}: unsupported image format {ext!r} {hint}")
    if ext == "pgf":  # matplotlib lists it, but writes it only with a TeX installation
        import shutil

        tex = matplotlib.rcParams["pgf.texsystem"]
        if shutil.which(tex) is None:
            raise PinSuspError(f"{path}: image format 'pgf' needs {tex}, which is not installed")


def _extension(path: str | Path) -> str:
    return Path(path).suffix.removeprefix(".").lower()


def save_figure(fig, path: str | Path) -> None:
    """Write the figure whole or not at all (format from the file's ending)."""
    try:
        check_image_path(path)
        path = Path(path)
        with atomic_write(path, binary=True) as f:
            try:
                fig.savefig(f, format=_extension(path), dpi=110)
            except OSError as exc:
                raise PinSuspError(f"{path}: cannot write ({exc.strerror or exc})") from None
    finally:
        plt.close(fig)
