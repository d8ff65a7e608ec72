"""The ``clearance:`` key of a geometry file (docs/clearance.md): the bodies on the
chassis a tyre may hit — bodywork or a chassis tube as a triangle mesh (an STL file),
a box or a tube — read in the file's units and kept in metres, world axes at design
(the chassis frame then).

    clearance:
      bodies:
        - {name: side_pod, mesh: sidepod.stl}            # path relative to the file
        - {name: frame_tube, tube: {from: [x, y, z], to: [x, y, z], radius: 12.5}}
        - {name: diff, box: {center: [x, y, z], size: [dx, dy, dz], rotation: [rx, ry, rz]}}

A box's ``rotation`` (degrees, optional) turns it about the world x, then y, then z
axes through its centre. A mesh's coordinates are in the file's units too. Every
problem (a missing or unreadable STL, a key not known, a size not > 0) is one
InputError naming the file and the key.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io.yamlio import Reader
from .units import LENGTH_UNITS, MM

KINDS = ("mesh", "box", "tube")


@dataclass(frozen=True)
class ClearanceBody:
    """A body fixed to the chassis (m, world axes at design). ``kind``: ``mesh``
    (``vertices`` (n, 3), ``faces`` (m, 3) int), ``box`` (``center``, ``size`` (3,),
    ``rotation`` 3 × 3: box axes → world) or ``tube`` (a capsule: ``start``, ``end``,
    ``radius``)."""

    name: str
    kind: str
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    center: np.ndarray | None = None
    size: np.ndarray | None = None
    rotation: np.ndarray | None = None
    start: np.ndarray | None = None
    end: np.ndarray | None = None
    radius: float = 0.0


def read_clearance(value, r: Reader, folder: Path, mm_per_unit: float = 1.0) -> list:
    """The bodies of a ``clearance:`` mapping (None: no bodies)."""
    if value is None:
        return []
    value = r.mapping(value, "clearance", optional=("bodies",))
    bodies = value.get("bodies", [])
    if not isinstance(bodies, list):
        r.fail("clearance.bodies", "expected a list of bodies")
    out, names = [], set()
    for i, item in enumerate(bodies):
        key = f"clearance.bodies[{i}]"
        item = r.mapping(item, key, required=("name",), optional=KINDS)
        name = r.text(item["name"], f"{key}.name")
        if name in names:
            r.fail(f"{key}.name", f"{name!r} is given twice")
        names.add(name)
        kinds = [k for k in KINDS if k in item]
        if len(kinds) != 1:
            r.fail(key, f"expected exactly one of {', '.join(KINDS)}, got {len(kinds)}")
        kind = kinds[0]
        read = {"mesh": _mesh, "box": _box, "tube": _tube}[kind]
        out.append(read(name, item[kind], r, f"{key}.{kind}", folder, mm_per_unit * MM))
    return out


def load_clearance(path) -> list:
    """The ``clearance:`` bodies of a geometry file (a corner's, an axle's, a vehicle's)."""
    from ..io.yamlio import load_yaml

    data, source, _ = load_yaml(path)
    r = Reader(source)
    if not isinstance(data, dict):
        return []
    units = data.get("units", "millimeters")
    scale = LENGTH_UNITS.get(units, 1.0) if isinstance(units, str) else 1.0
    return read_clearance(data.get("clearance"), r, Path(source).parent, scale)


def check_clearance(path) -> None:
    """A file's ``clearance:`` bodies read, for their errors alone, wherever a command
    loads the file (``subjects.subject.load_subject``): a bad body is refused by every
    command, not only by ``pin-susp clearance``. A file without the key costs a look."""
    from ..io.yamlio import load_yaml

    try:
        data, _, _ = load_yaml(path)
    except Exception:  # the file's own reader names what is wrong with it
        return
    if isinstance(data, dict) and "clearance" in data:
        load_clearance(path)


def _point(value, r: Reader, key: str, m: float) -> np.ndarray:
    return r.point(value, key) * m


def _mesh(name, value, r: Reader, key: str, folder: Path, m: float) -> ClearanceBody:
    import trimesh

    path = folder / r.text(value, key)
    if not path.is_file():
        r.fail(key, f"{path}: no such file")
    try:
        mesh = trimesh.load_mesh(str(path), file_type="stl")
    except Exception as e:  # trimesh raises many kinds on a damaged file
        r.fail(key, f"{path}: not a readable STL ({type(e).__name__}: {e})")
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        r.fail(key, f"{path}: not a readable STL (no triangles)")
    vertices = np.asarray(mesh.vertices, dtype=float)
    if not np.all(np.isfinite(vertices)):
        r.fail(key, f"{path}: a vertex that is not finite")
    faces = np.asarray(mesh.faces, dtype=np.int64)
    return ClearanceBody(name, "mesh", vertices=vertices * m, faces=faces)


def _box(name, value, r: Reader, key: str, folder: Path, m: float) -> ClearanceBody:
    from scipy.spatial.transform import Rotation

    value = r.mapping(value, key, required=("center", "size"), optional=("rotation",))
    center = _point(value["center"], r, f"{key}.center", m)
    size = r.vector(value["size"], f"{key}.size")
    for axis, s in zip("xyz", size, strict=True):
        if s <= 0.0:
            r.fail(f"{key}.size", f"its {axis} size must be > 0, got {s:g}")
    angles = r.vector(value.get("rotation", [0.0, 0.0, 0.0]), f"{key}.rotation")
    rotation = Rotation.from_euler("xyz", angles, degrees=True).as_matrix()
    return ClearanceBody(name, "box", center=center, size=size * m, rotation=rotation)


def _tube(name, value, r: Reader, key: str, folder: Path, m: float) -> ClearanceBody:
    value = r.mapping(value, key, required=("from", "to", "radius"))
    start = _point(value["from"], r, f"{key}.from", m)
    end = _point(value["to"], r, f"{key}.to", m)
    radius = r.positive(value["radius"], f"{key}.radius") * m
    if np.linalg.norm(end - start) < 1e-9:
        r.fail(key, "from and to are the same point")
    return ClearanceBody(name, "tube", start=start, end=end, radius=radius)
