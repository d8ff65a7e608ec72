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

``elements_of(axle)`` lists an axle's elements in the order they add to the tree.
"""

from __future__ import annotations

from .anti_roll_bar import AntiRollBar
from .heave_link import HeaveLink


def elements_of(axle) -> list:
    """An AxleGeometry's elements that add to its tree, in their order: the anti-roll
    bar (its material and centre points even with none) and the heave link."""
    return [AntiRollBar(axle), HeaveLink(axle)]
