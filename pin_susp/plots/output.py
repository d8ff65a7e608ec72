"""A report's image file: its path checked before any work, the figure saved whole."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

from ..errors import PinSuspError
from ..io.atomic import FULL, atomic_write


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


def _laid_out(fig) -> None:
    """A figure laid out once already (fig.tight_layout() leaves matplotlib's placeholder
    engine behind) is left with no engine: savefig then draws it once, not a dry run
    first for an engine that has nothing to do (the same picture, a third faster)."""
    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
        # None is the rc file's default layout unless it sets one: none, here
        no_default = {"figure.autolayout": False, "figure.constrained_layout.use": False}
        with matplotlib.rc_context(no_default):
            fig.set_layout_engine(None)


def save_figure(fig, path: str | Path) -> None:
    """Write the figure whole or not at all (format from the file's ending)."""
    try:
        check_image_path(path)
        path = Path(path)
        _laid_out(fig)
        with atomic_write(path, binary=True) as f:
            try:
                fig.savefig(f, format=_extension(path), dpi=110)
            except OSError as exc:
                if exc.errno in FULL:  # the disk, a quota, ulimit -f: as atomic_write says it
                    raise
                raise PinSuspError(f"{path}: cannot write ({exc.strerror or exc})") from None
            except (ValueError, OverflowError) as exc:  # e.g. a cell of 1e308: no axis scale
                raise PinSuspError(f"{path}: cannot draw these values ({exc})") from None
    finally:
        plt.close(fig)
