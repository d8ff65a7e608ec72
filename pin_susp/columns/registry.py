"""What a metric column is: :class:`Metric`, the registry's entry (docs/results.md).

The registry itself, ``METRICS`` in metrics.py, lists the entries in the CSV's order;
an entry sits in the module of the function it names (metrics.py, other_tools.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..model.geometry import Geometry

HUB_Z, RACK = "hub_z", "rack_displacement"
BOTH = (HUB_Z, RACK)
STEERING_AXIS_FLAT = 1e-6  # |k_z| below this: the axis never meets a horizontal plane


def _always(g: Geometry) -> bool:
    return True


@dataclass(frozen=True)
class Metric:
    """A column: name, output unit, label, function; ``drivers`` it has derivatives for.

    ``applies`` says whether the metric is defined for a corner; ``always_written``
    columns appear (empty) even where it is not, as docs/results.md asks.
    """

    name: str
    unit: str  # "deg", "mm", "mm/rad", "%" or "N"
    label: str
    function: Callable  # PointSet (metrics.py) → (n,) array in SI, NaN where undefined
    applies: Callable[[Geometry], bool] = field(default=_always)
    drivers: tuple[str, ...] = ()
    always_written: bool = False
    written: bool = True  # False: a point coordinate, already a column, for its derivative
    needs: str = ""  # the inputs an always-written column needs to have values
    plausible: tuple[float, float] | None = None  # at design, in output units (a warning)
    rates: bool = False  # computed from the points' rates (a twist), not positions alone

    @property
    def scale(self) -> float:
        """SI → output unit."""
        return {"deg": 180.0 / np.pi, "mm": 1e3, "mm/rad": 1e3, "%": 1.0, "N": 1.0}[self.unit]
