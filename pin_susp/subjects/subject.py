"""The one place that reads which kind of subject a geometry file holds: a corner's
file, or an axle's (``scope: axle``, docs/axle.md), and builds it.

:func:`load_subject` returns a :class:`~pin_susp.subjects.corner.Corner` or an
:class:`~pin_susp.subjects.axle.AxleModel`, both an :class:`~pin_susp.subjects.assembly.Assembly`:
what takes one asks the Assembly's surface, not its kind. :func:`kind_of` gives how a
subject is built from its file's data, as a study builds its design and its variants.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .assembly import Assembly


def is_axle_file(path) -> bool:
    """Whether a geometry file is an axle's (``scope: axle``)."""
    from ..io.yamlio import load_yaml

    data, _, _ = load_yaml(path)
    return is_axle_data(data)


def is_axle_data(data: dict) -> bool:
    """Whether a geometry file's data, as read, is an axle's (``scope: axle``)."""
    return data.get("scope") == "axle"


def is_vehicle_file(path) -> bool:
    """Whether a geometry file is a whole car's (``scope: vehicle``, docs/vehicle.md)."""
    from ..io.yamlio import load_yaml

    data, _, _ = load_yaml(path)
    return data.get("scope") == "vehicle"


def referenced_files(path) -> list[Path]:
    """The files a geometry file reads besides itself: a vehicle's axle files (its
    ``front`` and ``rear`` paths, relative to it, docs/vehicle.md); none for a corner or
    an axle, or for a file that cannot be read (its own error comes when it is loaded)."""
    from ..errors import PinSuspError
    from ..io.yamlio import load_yaml

    try:
        data, _, _ = load_yaml(path)
    except (PinSuspError, OSError):
        return []
    if not isinstance(data, dict) or data.get("scope") != "vehicle":
        return []
    here = Path(path).parent
    return [here / data[end] for end in ("front", "rear") if isinstance(data.get(end), str)]


def subject_class(path) -> type[Assembly]:
    """The class a geometry file's subject is (Corner, AxleModel or Vehicle), before it
    is built: what it can do (``poses_at_steps``, ...) said before any work."""
    if is_vehicle_file(path):
        from .vehicle import Vehicle

        return Vehicle
    if is_axle_file(path):
        from .axle import AxleModel

        return AxleModel
    from .corner import Corner

    return Corner


def load_subject(path, warn: bool = True) -> Assembly:
    """The subject of a geometry file, set up: a Corner (its shim and adjusters applied)
    or an AxleModel (both corners as set, the axle's shared elements). ``warn``: a
    corner's PlausibilityWarning for each implausible design metric (Corner's); a
    Vehicle (``scope: vehicle``)."""
    from ..model.clearance_bodies import check_clearance

    check_clearance(path)  # its bodies' errors for every command (docs/clearance.md)
    if is_vehicle_file(path):
        from .vehicle import Vehicle

        return Vehicle(path)
    if is_axle_file(path):
        from .axle import AxleModel, load_axle

        return AxleModel(load_axle(path))
    from ..model.geometry import load_geometry
    from .corner import Corner

    return Corner(load_geometry(path), warn=warn)


def load_drawn(path, label: str | None = None) -> Assembly:
    """The subject of a geometry file as the file draws it, for the setup analyses
    (``Assembly.as_drawn``): no model built, no setup applied; ``label``: a setup
    option's (``--side``), refused first where the kind has no such label."""
    return subject_class(path).as_drawn(path, label)


class SubjectKind:
    """How one kind of subject is built from its geometry file's data, as a study builds
    its design and its variants (docs/studies.md): ``build``, and ``variant_data`` (the
    data a variant's hardpoints are moved in)."""

    def build(self, data: dict, source: str, variant: bool = False) -> Assembly:
        """The subject of a geometry file's data (errors name ``source``). A
        ``variant``'s goes without the plausibility warnings (the design's were shown)
        and, a corner's, without the URDF's shapes (never drawn)."""
        raise NotImplementedError

    def variant_data(self, data: dict) -> dict:
        """A copy of the data in which each labelled corner's hardpoints are its own to
        move (``data["hardpoints"][label]``; a corner's one, unlabelled, at
        ``data["hardpoints"]``)."""
        return copy.deepcopy(data)

    def in_mm(self, data: dict, source: str) -> dict:
        """The data in mm and N, each wheel by its spindle points and each rocker by
        rocker_axis_a/b (model/forms.py): what its variants move (errors name ``source``)."""
        from ..io.yamlio import Reader
        from ..model.forms import canonical_corner

        return canonical_corner(data, Reader(source))

    def hardpoints(self, data: dict, label: str | None) -> dict:
        """The hardpoints of the corner ``label`` names in ``variant_data``'s copy (None:
        a corner's one)."""
        return data["hardpoints"][label] if label else data["hardpoints"]


class _CornerKind(SubjectKind):
    def variant_data(self, data: dict) -> dict:
        """A copy in which its hardpoints are its own (the rest is only read: shared)."""
        out = dict(data)
        out["hardpoints"] = {k: copy.copy(v) for k, v in data["hardpoints"].items()}
        return out

    def build(self, data: dict, source: str, variant: bool = False) -> Assembly:
        from ..io.yamlio import Reader
        from ..model.geometry import parse_geometry, warn_dead_centres
        from .corner import Corner

        geometry = parse_geometry(data, Reader("<dict>"), None)
        if not variant:  # a link near dead centre, as every command says
            warn_dead_centres(geometry, source)
        return Corner(geometry, warn=not variant, visuals=not variant)


class _AxleKind(SubjectKind):
    def build(self, data: dict, source: str, variant: bool = False) -> Assembly:
        from .axle import AxleModel, load_axle

        return AxleModel(load_axle(data, None if variant else source), visuals=not variant)

    def in_mm(self, data: dict, source: str) -> dict:
        from ..io.yamlio import Reader
        from ..model.forms import canonical_axle

        return canonical_axle(data, Reader(source))

    def variant_data(self, data: dict) -> dict:
        out = super().variant_data(data)
        points = out["hardpoints"]
        if "right" not in points or points["right"] is None:  # mirrored: made explicit
            from .axle_file import mirror_corner

            points["right"] = mirror_corner({"hardpoints": points["left"]})["hardpoints"]
        return out


class _VehicleKind(SubjectKind):
    """A vehicle's (docs/vehicle.md): its data with both axles inline, each in mm with its
    right side written out; a corner's label (fl, fr, rl, rr) names its axle and side."""

    def build(self, data: dict, source: str, variant: bool = False) -> Assembly:
        from .vehicle import Vehicle
        from .vehicle_file import load_vehicle

        return Vehicle(load_vehicle(data), visuals=not variant)

    def in_mm(self, data: dict, source: str) -> dict:
        """The vehicle file's data in mm and N with each axle inline, as its axle file
        gives it in mm (its own units) and canonical form, its right side written out;
        the file read first as every command reads it (its errors name its files)."""
        from ..io.yamlio import Reader, load_yaml
        from ..model.units import vehicle_in_mm
        from .vehicle_file import AXLES, load_vehicle

        load_vehicle(source)
        data = vehicle_in_mm(copy.deepcopy(data), Reader(source))
        for end in AXLES:
            given = data[end]
            path = str(Path(source).parent / given) if isinstance(given, str) else source
            axle = load_yaml(path)[0] if isinstance(given, str) else given
            data[end] = _AxleKind().variant_data(_AxleKind().in_mm(axle, path))
        return data

    def hardpoints(self, data: dict, label: str | None) -> dict:
        from .vehicle_file import AXLES

        end = next(e for e, labels in AXLES.items() if label in labels)
        return data[end]["hardpoints"]["left" if label == AXLES[end][0] else "right"]


def kind_of(data: dict) -> SubjectKind:
    """The kind of subject a geometry file's data, as read, holds (its ``scope``)."""
    if isinstance(data, dict) and data.get("scope") == "vehicle":
        return _VehicleKind()
    return _AxleKind() if is_axle_data(data) else _CornerKind()
