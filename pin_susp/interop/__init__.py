"""Other tools' hardpoint files (docs/interop.md): Lotus SHARK ``.shk``, an
OptimumKinematics hardpoint table (CSV or Excel) and an Adams/Car property file in,
a pin_susp geometry out (``pin-susp import``); and a geometry written back as a
``.shk`` or an OptimumK table (``pin-susp export``).

Each reader turns its file into a :class:`pin_susp.interop.corner.Source` — every
named point of the file, in ISO axes and mm, with the pin_susp point it stands for
(or none) — and :func:`pin_susp.interop.corner.build` makes the corner of it, saying
which points it used and which it ignored.
"""

from __future__ import annotations

FORMATS = {
    "shk": "pin_susp.interop.lotus",
    "optimumk": "pin_susp.interop.optimumk",
    "adams": "pin_susp.interop.adams",
}


def reader(fmt: str):
    """The module that reads (and, for shk and optimumk, writes) the format ``fmt``."""
    import importlib

    return importlib.import_module(FORMATS[fmt])
