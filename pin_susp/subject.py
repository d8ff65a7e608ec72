"""The one place that reads which kind of subject a geometry file holds: a corner's
file, or an axle's (``scope: axle``, docs/axle.md), and builds it.

:func:`load_subject` returns a :class:`~pin_susp.corner.Corner` or an
:class:`~pin_susp.axle.AxleModel`, both an :class:`~pin_susp.assembly.Assembly`:
what takes one asks the Assembly's surface, not its kind.
"""

from __future__ import annotations

from .assembly import Assembly


def is_axle_file(path) -> bool:
    """Whether a geometry file is an axle's (``scope: axle``)."""
    from .yamlio import load_yaml

    data, _, _ = load_yaml(path)
    return is_axle_data(data)


def is_axle_data(data: dict) -> bool:
    """Whether a geometry file's data, as read, is an axle's (``scope: axle``)."""
    return data.get("scope") == "axle"


def subject_class(path) -> type[Assembly]:
    """The class a geometry file's subject is (Corner or AxleModel), before it is built:
    what it can do (``poses_at_steps``, ...) said before any work."""
    if is_axle_file(path):
        from .axle import AxleModel

        return AxleModel
    from .corner import Corner

    return Corner


def load_subject(path, warn: bool = True) -> Assembly:
    """The subject of a geometry file, set up: a Corner (its shim and adjusters applied)
    or an AxleModel (both corners as set, the axle's shared elements). ``warn``: a
    corner's PlausibilityWarning for each implausible design metric (Corner's)."""
    if is_axle_file(path):
        from .axle import AxleModel, load_axle

        return AxleModel(load_axle(path))
    from .corner import Corner
    from .geometry import load_geometry

    return Corner(load_geometry(path), warn=warn)
