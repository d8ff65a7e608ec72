"""The elements labelled corners share, one module each (README, How it works;
docs/axle.md): the rack (``rack.py``), the anti-roll bar, a U-bar or a T-bar
(``anti_roll_bar.py``), the heave link (``heave_link.py``).

An element is built from the axle file's data (an AxleGeometry) and contributes:

- ``add_to(bodies, points, closures, visuals, materials)``: its bodies, joints,
  points and closures, added to the composed tree (compose.compose_tree);
- ``columns(model, p, d)``: its columns of the results (name → (values, unit)),
  from every point's positions ``p`` and the design's ``d`` (each (n, 3), m);
- where it has them, its rates (``rate_columns``) and its part in the roll
  stiffness (``anti_roll_bar``).

As one of an Assembly's ``shared`` elements (the axle's pair of corners,
``wheel_pair.py``, is one too) it also answers ``quantities`` (the sweep quantities
that are its rows: none, or heave and roll), ``check_targets(targets, source)`` and
``columns_of(model, points, sides)`` (its columns among the results').

``elements_of(axle)`` lists an axle's elements in the order they add to the tree,
named by its corners' labels and a prefix of their own: an axle's ``left``/``right``
and none; a vehicle's front axle's ``fl``/``fr`` and ``front_`` (docs/vehicle.md).
"""

from __future__ import annotations

from .anti_roll_bar import AntiRollBar
from .heave_link import HeaveLink


def elements_of(axle, labels: tuple[str, str] = ("left", "right"), prefix: str = "") -> list:
    """An AxleGeometry's elements that add to its tree, in their order: the anti-roll
    bar (its material and centre points even with none) and the heave link; ``labels``:
    its two corners' (its left side's first), ``prefix``: that of the elements' own
    names (a bar's centre points and body) and, as a suffix, of their own columns."""
    return [AntiRollBar(axle, labels, prefix), HeaveLink(axle, labels, prefix)]
