"""A geometry file's ``compliance:`` block (docs/compliance.md): the bushings at the
pivots' chassis pickups, the links' axial rates and the tyre's, read and validated
into SI stiffnesses.

- ``bushings: {<pickup>: {radial, axial, torsional, conical}}`` (N/mm, N/mm,
  N·m/deg, N·m/deg; torsional and conical may be 0: free to turn, as a spherical
  bearing) or ``{<pickup>: {k: 6×6}}`` in the bushing's frame — x radial, y radial,
  z axial, then the rotations about them — the translational block in N/mm, the
  rotational one in N·m/rad and the coupling blocks in N/rad (symmetric, positive
  definite);
- ``links: {<link>: N/mm}``: each compliant two-force link's axial rate;
- ``tyre: {vertical, lateral}`` (N/mm) at the contact patch.

The values arrive in N/mm and N·m/deg (model/units.py converts a file in lbf).
Which pickups hold a pivot and which links exist is the subject's (the model's
tree): ``analyses/compliance.py`` checks those against it with the same messages.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..io.yamlio import Reader

RATE_KEYS = ("radial", "axial", "torsional", "conical")
TYRE_KEYS = ("vertical", "lateral")
MAX_RATE = 1e9  # N/mm or N·m/deg: far beyond any part (a unit slip)
DEG = math.pi / 180.0


@dataclass(frozen=True)
class Compliance:
    """SI stiffnesses: ``bushings`` pickup → 6×6 (N/m, N/rad, N·m/rad) in the bushing's
    frame (x, y radial, z axial; then rotations), ``links`` name → N/m, ``tyre``
    {vertical, lateral} → N/m (a direction not given: rigid, left out)."""

    bushings: dict = field(default_factory=dict)
    links: dict = field(default_factory=dict)
    tyre: dict = field(default_factory=dict)
    source: str = "<dict>"

    def scaled(self, factor: float) -> Compliance:
        """Every stiffness times ``factor`` (the stiff-limit check: compliance ∝ 1/k)."""
        return Compliance(
            {k: v * factor for k, v in self.bushings.items()},
            {k: v * factor for k, v in self.links.items()},
            {k: v * factor for k, v in self.tyre.items()},
            self.source,
        )

    @property
    def empty(self) -> bool:
        return not (self.bushings or self.links or self.tyre)


def read_compliance(block, r: Reader, points=None, key: str = "compliance") -> Compliance:
    """The ``compliance:`` block's stiffnesses; ``points``: the corner's hardpoint names
    (a bushing at another name: an unknown pickup)."""
    block = r.mapping(block, key, optional=("bushings", "links", "tyre"))
    bushings = {}
    for name, value in _named(block.get("bushings", {}), f"{key}.bushings", r).items():
        where = f"{key}.bushings.{name}"
        if points is not None and name not in points:
            r.fail(where, "unknown pickup (a bushing sits at a hardpoint of a pivot)")
        bushings[str(name)] = _bushing(value, where, r)
    links = {}
    for name, value in _named(block.get("links", {}), f"{key}.links", r).items():
        links[str(name)] = _rate(value, f"{key}.links.{name}", r) * 1e3
    tyre_block = r.mapping(block.get("tyre", {}), f"{key}.tyre", optional=TYRE_KEYS)
    tyre = {k: _rate(v, f"{key}.tyre.{k}", r) * 1e3 for k, v in tyre_block.items()}
    return Compliance(bushings, links, tyre, r.source)


def _named(value, key: str, r: Reader) -> dict:
    """A mapping of names (pickups, links) to their values."""
    if not isinstance(value, dict):
        r.fail(key, f"expected a mapping of names to stiffnesses, got {type(value).__name__}")
    return value


def _rate(value, key: str, r: Reader, zero: bool = False) -> float:
    x = r.number(value, key)
    if x < 0.0 or (x == 0.0 and not zero):
        r.fail(key, f"a stiffness must be {'>= 0' if zero else '> 0'}, got {x:g}")
    if x > MAX_RATE:
        r.fail(key, f"{x:g} is beyond {MAX_RATE:g}: no part is that stiff (a unit slip?)")
    return x


def _bushing(value, key: str, r: Reader) -> np.ndarray:
    """A bushing's 6×6 (SI, its own frame) from its four rates or its full matrix."""
    if isinstance(value, dict) and "k" in value:
        r.mapping(value, key, required=("k",))
        return _matrix(value["k"], f"{key}.k", r)
    rates = r.mapping(value, key, required=("radial", "axial"), optional=RATE_KEYS)
    radial = _rate(rates["radial"], f"{key}.radial", r) * 1e3  # N/m
    axial = _rate(rates["axial"], f"{key}.axial", r) * 1e3
    torsional = _rate(rates.get("torsional", 0.0), f"{key}.torsional", r, zero=True) / DEG
    conical = _rate(rates.get("conical", 0.0), f"{key}.conical", r, zero=True) / DEG
    return np.diag([radial, radial, axial, conical, conical, torsional])


def _matrix(value, key: str, r: Reader) -> np.ndarray:
    """A full 6×6: symmetric, positive definite; SI (the translational block ×1e3)."""
    if not isinstance(value, list) or len(value) != 6:
        r.fail(key, "expected a 6×6 matrix: a list of 6 rows of 6 numbers")
    rows = []
    for i, row in enumerate(value):
        if not isinstance(row, list) or len(row) != 6:
            r.fail(f"{key}[{i}]", "expected a row of 6 numbers")
        rows.append([r.number(x, f"{key}[{i}][{j}]") for j, x in enumerate(row)])
    k = np.array(rows)
    if not np.allclose(k, k.T, rtol=1e-9, atol=1e-12 * np.abs(k).max()):
        i, j = np.unravel_index(np.argmax(np.abs(k - k.T)), k.shape)
        r.fail(key, f"not symmetric: k[{i}][{j}] = {k[i, j]:g} but k[{j}][{i}] = {k[j, i]:g}")
    k = 0.5 * (k + k.T)
    k[:3, :3] *= 1e3  # N/mm → N/m; the coupling (N/rad) and rotational (N·m/rad) as given
    if np.linalg.eigvalsh(k).min() <= 0.0:
        r.fail(key, "not positive definite: some deflection of the bushing would store no energy")
    return k
