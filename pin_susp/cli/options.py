"""The arguments the commands share and their checks: the parser (usage errors on one
line), numbers, finite and positive values, counts, the GEOMETRY argument, a run's
GEOMETRY SWEEP -o OUT arguments, and the output paths checked before any work
(writable, each its own file, none of them an input)."""

from __future__ import annotations

import argparse
import math
import os
import re
import stat
from pathlib import Path

from ..errors import EXIT_INPUT, PinSuspError


class Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line (the usage is in --help), and values
    that start with a minus and a digit (``--trackrod -1,0,1``) read as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?[0-9]")

    def error(self, message: str):
        self.exit(EXIT_INPUT, f"pin-susp: error: {message} (see {self.prog} --help)\n")


def geometry_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("geometry", metavar="GEOMETRY", help="geometry YAML (hardpoints in mm)")


def numbers(text: str) -> list[float]:
    """Lengths in mm separated by commas: finite, within the 100 m limit of any car."""
    from ..io.yamlio import MAX_LENGTH_MM

    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected numbers separated by commas, got {text!r}"
        ) from None
    for x in values:
        if not math.isfinite(x) or abs(x) > MAX_LENGTH_MM:
            raise argparse.ArgumentTypeError(
                f"{x:g} mm is not a finite length within {MAX_LENGTH_MM / 1000:g} m"
            )
    return values


def finite(text: str, positive: bool = False) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(x) or (positive and x <= 0.0):
        bound = " > 0" if positive else ""
        raise argparse.ArgumentTypeError(f"expected a finite number{bound}, got {text!r}")
    return x


def positive(text: str) -> float:
    return finite(text, positive=True)


COUNT_LIMIT = 999_999  # --top: more entries than any table has hardpoint coordinates


def count(text: str) -> int:
    if not re.fullmatch(r"[0-9]{1,6}", text.strip()):
        raise argparse.ArgumentTypeError(
            f"expected a whole number from 0 to {COUNT_LIMIT}, got {text!r}"
        )
    return int(text)


def run_arguments(parser, output: str, plot: str, cases: bool = False) -> None:
    """GEOMETRY SWEEP [--cases] -o OUT.csv [-q] [--plot OUT.png]: a sweep's, a loads run's."""
    geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", help="sweep YAML (targets per step)")
    if cases:
        parser.add_argument(
            "--cases", required=True, metavar="LOADS.yaml", help="load cases (N, N·m, world axes)"
        )
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.csv", help=f"{output} (Parquet: OUT.parquet)"
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    parser.add_argument("--plot", metavar="OUT.png", help=plot)
    output_arguments(parser)


# io.conventions' names, said here so that --help imports nothing (a test keeps them one)
CONVENTIONS = ("iso", "sae", "lotus", "optimumk")
UNITS = ("mm", "in")


def output_arguments(parser, study: bool = False) -> None:
    """--convention and --units: the sign convention and units of the columns written
    (docs/results.md, "Output conventions and units"; the run itself is ISO, mm)."""
    given = "default: the study file's conventions:, else iso" if study else "default iso"
    parser.add_argument(
        "--convention",
        choices=tuple(CONVENTIONS),
        metavar="|".join(CONVENTIONS),
        help=f"the columns' sign convention and axes ({given}: x forward, y left, z up)",
    )
    parser.add_argument(
        "--units",
        choices=UNITS,
        metavar="mm|in",
        help="the columns' units: mm (default: mm, deg, N) or in (inches, deg, lbf: "
        "every length, force and rate converted)",
    )


def output_form(args, convention: str | None = None):
    """The Output (io.conventions) that --convention and --units ask for; ``convention``:
    the default when --convention is not given (a study file's)."""
    from ..io.conventions import DEFAULT, Output

    chosen = getattr(args, "convention", None) or convention or DEFAULT
    return Output(chosen, getattr(args, "units", None) or "mm")


def check_image(path) -> None:
    """An image output: a writable path with an extension matplotlib can write."""
    from ..io.atomic import check_output
    from ..plots import check_image_path

    check_output(path, "image")
    check_image_path(path)


def check_outputs(args, *paths) -> None:
    """Before any work: every output writable, each its own file, none of them an input."""
    from ..io.atomic import check_output

    inputs = [getattr(args, name, None) for name in ("geometry", "sweep", "mjcf", "cases")]
    inputs += list(getattr(args, "results", None) or ())
    for option in ("at", "from_results"):  # SWEEP:STEP, RESULTS.csv:STEP
        at = getattr(args, option, None)
        if at:
            inputs.append(at.rpartition(":")[0])
    inputs = [Path(p) for p in inputs if p]
    geometry = vars(args).get("geometry")
    if geometry:  # a vehicle's axle files are its inputs too
        from ..subjects.subject import referenced_files

        inputs += referenced_files(geometry)
    seen = {}
    for path in (p for p in paths if p is not None):
        target = _identity(check_output(path))
        for source in inputs:
            if target == _identity(source):
                raise PinSuspError(f"{path}: is an input of this command: writing it would lose it")
        if target in seen and target[0] != "stream":
            raise PinSuspError(f"{seen[target]} and {path} are one file: give each output its own")
        seen[target] = path


def _identity(path: Path) -> tuple:
    """What makes two paths one file: device and inode when it exists, else its real path."""
    try:
        st = Path(path).stat()
    except OSError:
        return ("path", os.path.realpath(path))
    if not stat.S_ISREG(st.st_mode):
        return ("stream", st.st_dev, st.st_ino)
    return ("file", st.st_dev, st.st_ino)
