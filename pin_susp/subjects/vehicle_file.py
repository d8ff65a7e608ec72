"""Reading a vehicle file (``scope: vehicle``, docs/vehicle.md): its two axles (an axle
file each, a path relative to it or the axle inline; docs/axle.md) and
``vehicle_config`` — the wheelbase (a check of the axles' points), the CG, the masses,
the brakes and the drive, the steering's c-factor and the tyres' rates — validated with
one message per problem naming the file and the key. ``Vehicle`` (vehicle.py) is the
model built from it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.yamlio import Reader, load_yaml
from ..model.geometry import Geometry
from ..model.units import vehicle_in_mm
from .axle_file import AxleGeometry, load_axle

LABELS = ("fl", "fr", "rl", "rr")
AXLES = {"front": ("fl", "fr"), "rear": ("rl", "rr")}
CONFIG_KEYS = ("wheelbase", "cg", "masses", "brakes", "drive", "steering", "tyres")
WHEELBASE_CHECK = 1.0  # mm: vehicle_config.wheelbase against the axles' wheel centres
RIGID_BAR = (
    "a rigid anti-roll bar locks its axle's roll, so on the road the body could not roll "
    "as a vehicle's sweep sets it (heave, pitch, roll and each road height): give the bar "
    "its stiffness (N·m/deg) in a vehicle, or sweep the axle on its own"
)


@dataclass(frozen=True)
class VehicleGeometry:
    """A vehicle file as read: its two axles (AxleGeometry) and vehicle_config (mm and
    kg as given; ``cg`` (3,) m in the chassis frame)."""

    name: str
    front: AxleGeometry
    rear: AxleGeometry
    wheelbase: float  # mm
    cg: np.ndarray  # m, chassis frame (y 0)
    masses: dict
    brakes: dict
    drive: dict
    c_factor: float | None  # mm of rack per steering-wheel turn
    front_bias: float | None = None  # brakes: the front axle's share of the braking force
    brake_types: dict = field(default_factory=dict)  # front/rear → "outboard" | "inboard"
    drive_split: dict | None = None  # front/rear → share of the drive (sum 1)
    drive_types: dict = field(default_factory=dict)  # front/rear → "outboard" | "inboard"
    tyres: dict | None = None  # "f"/"r" → the tyre's vertical rate, N/mm (None: rigid)
    source: str = "<dict>"
    sha256: str | None = None
    data: dict = field(default_factory=dict, repr=False)

    def brake_share(self, end: str) -> float | None:
        """The share of the braking force on the front or rear axle (None: no bias given)."""
        if self.front_bias is None:
            return None
        return self.front_bias if end == "front" else 1.0 - self.front_bias

    def brake_reaction(self, end: str) -> str:
        """Where an axle's brake torque reacts: "outboard" (the upright: the contact
        patch's force) or "inboard" (the body: the force at the wheel centre)."""
        return self.brake_types.get(end, "outboard")

    def drive_share(self, end: str) -> float | None:
        """The share of the drive on the front or rear axle (None: no drive given)."""
        return None if self.drive_split is None else self.drive_split[end]

    def drive_reaction(self, end: str) -> str:
        """Where an axle's drive torque reacts: "inboard" (a body-mounted differential
        or motor, the default) or "outboard" (hub motors, a live axle)."""
        return self.drive_types.get(end, "inboard")

    def corner(self, label: str) -> Geometry:
        axle = self.front if label[0] == "f" else self.rear
        return axle.left if label[1] == "l" else axle.right


def load_vehicle(source) -> VehicleGeometry:
    """Read and validate a vehicle file (``scope: vehicle``, docs/vehicle.md): a path or
    a dict. Every problem raises InputError naming the file and the key."""
    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(
        data,
        "",
        required=("scope", "vehicle_config", "front", "rear"),
        optional=("name", "version", "units", "force_units", "clearance"),  # docs/clearance.md
    )
    r.choice(data["scope"], "scope", ("vehicle",))
    data = vehicle_in_mm(data, r)  # mm and N (model/units.py)
    config = r.mapping(
        data["vehicle_config"], "vehicle_config", required=("wheelbase", "cg"), optional=CONFIG_KEYS
    )
    here = Path(name).parent if not isinstance(source, dict) else Path(".")
    axles = {}
    for end in AXLES:
        axles[end] = _axle(data[end], end, here, name, r)
        position = axles[end].data.get("axle_config", {}).get("axle_position")
        if position != end:
            r.fail(f"{end}", f"its axle file says axle_position: {position}, not {end}")
    wheelbase = r.positive(config["wheelbase"], "vehicle_config.wheelbase")
    centres = {end: a.left.design_points()["wheel_center"][0] * 1e3 for end, a in axles.items()}
    drawn = centres["front"] - centres["rear"]
    if abs(drawn - wheelbase) > WHEELBASE_CHECK:
        r.fail(
            "vehicle_config.wheelbase",
            f"{wheelbase:g} mm, but the axles' wheel centres are {drawn:g} mm apart "
            "(the rear axle is placed by its own points: the wheelbase is a check)",
        )
    cg = r.mapping(config["cg"], "vehicle_config.cg", required=("z",), optional=("x", "x_mm"))
    if ("x" in cg) == ("x_mm" in cg):
        r.fail("vehicle_config.cg", "give exactly one of x (a fraction of the wheelbase) or x_mm")
    if "x" in cg:
        share = r.number(cg["x"], "vehicle_config.cg.x")
        if not 0.0 <= share <= 1.0:
            r.fail(
                "vehicle_config.cg.x",
                f"{share:g} is not a fraction of the wheelbase between 0 and 1 (x_mm: the CG's x)",
            )
        x = centres["front"] - share * wheelbase
    else:
        x = r.length(cg["x_mm"], "vehicle_config.cg.x_mm")
        if not centres["rear"] <= x <= centres["front"]:
            r.fail(
                "vehicle_config.cg.x_mm",
                f"{x:g} mm is not between the axles (their wheel centres at "
                f"{centres['rear']:g} and {centres['front']:g} mm)",
            )
    z = r.positive(cg["z"], "vehicle_config.cg.z")
    steering = r.mapping(
        config.get("steering", {}), "vehicle_config.steering", optional=("c_factor",)
    )
    c_factor = None
    if "c_factor" in steering:
        c_factor = r.positive(steering["c_factor"], "vehicle_config.steering.c_factor")
    dicts = {}
    for key in ("masses", "brakes", "drive"):  # read by the attitude and anti columns
        value = config.get(key, {})
        if not isinstance(value, dict):
            r.fail(f"vehicle_config.{key}", "expected a mapping")
        dicts[key] = dict(value)
    brakes, drive = _brakes_and_drive(dicts["brakes"], dicts["drive"], r)
    tyres = _tyres(config.get("tyres"), r)
    _masses(dicts["masses"], r)
    return VehicleGeometry(
        str(data.get("name", Path(name).stem)),
        axles["front"],
        axles["rear"],
        wheelbase,
        np.array([x, 0.0, z]) * 1e-3,
        dicts["masses"],
        dicts["brakes"],
        dicts["drive"],
        c_factor,
        *brakes,
        *drive,
        tyres,
        name,
        sha,
        data,
    )


MASSES = ("sprung", "unsprung_front", "unsprung_rear", "sprung_roll_inertia")


def _masses(masses: dict, r: Reader) -> None:
    """``vehicle_config.masses``: its keys known, each a number (kg, kg·m²), the sprung
    mass and the roll inertia positive, the unsprung ones not negative — checked as the
    file is read; the attitude asks for the ones it needs (analyses/attitude_file.py)."""
    key = "vehicle_config.masses"
    r.mapping(masses, key, optional=MASSES)
    for name, value in masses.items():
        if name in ("sprung", "sprung_roll_inertia"):
            r.positive(value, f"{key}.{name}")
        elif r.number(value, f"{key}.{name}") < 0:
            r.fail(f"{key}.{name}", f"{value:g} kg is negative")


def _tyres(given, r: Reader) -> dict | None:
    """``vehicle_config.tyres``: ``{vertical: N/mm}`` for all four, or ``{front: {vertical},
    rear: {vertical}}``; None (rigid tyres) when not given."""
    if given is None:
        return None
    key = "vehicle_config.tyres"
    r.mapping(given, key, optional=("vertical", "front", "rear"))
    if "vertical" in given:
        if "front" in given or "rear" in given:
            r.fail(key, "give vertical for all four tyres, or front and rear, not both")
        rate = r.positive(given["vertical"], f"{key}.vertical")
        return {"f": rate, "r": rate}
    out = {}
    for end in AXLES:
        if end not in given:
            r.fail(f"{key}.{end}", "give each axle's tyre rate (or vertical for all four)")
        axle = r.mapping(given[end], f"{key}.{end}", required=("vertical",))
        out[end[0]] = r.positive(axle["vertical"], f"{key}.{end}.vertical")
    return out


def _brakes_and_drive(brakes: dict, drive: dict, r: Reader) -> tuple[tuple, tuple]:
    """``vehicle_config.brakes`` (front_bias 0…1; front, rear: outboard | inboard) and
    ``drive`` (front, rear: shares summing to 1; front_type, rear_type: outboard |
    inboard), read for the anti columns and the attitude."""
    r.mapping(brakes, "vehicle_config.brakes", optional=("front_bias", "front", "rear"))
    r.mapping(drive, "vehicle_config.drive", optional=("front", "rear", "front_type", "rear_type"))
    bias = None
    if "front_bias" in brakes:
        bias = r.number(brakes["front_bias"], "vehicle_config.brakes.front_bias")
        if not 0.0 <= bias <= 1.0:
            r.fail("vehicle_config.brakes.front_bias", f"{bias:g} is not a share between 0 and 1")
    where = ("outboard", "inboard")
    brake_types = {
        e: r.choice(brakes[e], f"vehicle_config.brakes.{e}", where) for e in AXLES if e in brakes
    }
    split = None
    if "front" in drive or "rear" in drive:
        split = {}
        for end in AXLES:
            share = r.number(drive.get(end, 0.0), f"vehicle_config.drive.{end}")
            if not 0.0 <= share <= 1.0:
                r.fail(f"vehicle_config.drive.{end}", f"{share:g} is not a share between 0 and 1")
            split[end] = share
        if abs(split["front"] + split["rear"] - 1.0) > 1e-9:
            r.fail(
                "vehicle_config.drive",
                f"front {split['front']:g} and rear {split['rear']:g} do not add up to 1",
            )
    drive_types = {}
    for end in AXLES:
        key = f"{end}_type"
        if key in drive:
            drive_types[end] = r.choice(drive[key], f"vehicle_config.drive.{key}", where)
    return (bias, brake_types), (split, drive_types)


def _axle(given, end: str, here: Path, name: str, r: Reader) -> AxleGeometry:
    """The front or rear axle: a file relative to the vehicle's, or inline (its errors
    then named in the vehicle file, under ``front.``/``rear.``). A rear rack is refused
    before the axle is read, a rigid anti-roll bar after (RIGID_BAR)."""
    if isinstance(given, str):
        path = here / given
        if not path.is_file():
            r.fail(end, f"no axle file {given!r} (paths are relative to {name})")
        raw, where, prefix = load_yaml(path)[0], str(path), ""
    elif isinstance(given, dict):
        raw, where, prefix = given, name, f"{end}."
    else:
        r.fail(end, "expected an axle file's path or the axle inline (a mapping)")
    scope = raw.get("scope", "corner") if isinstance(raw, dict) else None
    if isinstance(raw, dict) and scope != "axle":
        what = f"{given!r} is" if isinstance(given, str) else "the axle inline is"
        r.fail(
            end,
            f"{what} not an axle file (scope: {scope}): a vehicle's front and rear are "
            "axle files (scope: axle, docs/axle.md)",
        )
    config = raw.get("axle_config") if isinstance(raw, dict) else None  # (load_axle: the rest)
    position = config.get("axle_position") if isinstance(config, dict) else None
    if position in AXLES and position != end:  # before what the other end may not have
        r.fail(end, f"its axle file says axle_position: {position}, not {end}")
    if isinstance(config, dict) and end == "rear":
        steering = config.get("steering", {})
        if isinstance(steering, dict) and steering.get("type") == "rack":
            raise InputError(
                where, f"{prefix}axle_config.steering", "rear steer (a rear rack) is not supported"
            )
    try:
        axle = load_axle(path if isinstance(given, str) else given)
    except InputError as exc:
        if prefix:  # inline: named in the vehicle file
            raise InputError(name, f"{prefix}{exc.key}", exc.problem) from None
        raise
    if axle.anti_roll_rigid:
        raise InputError(where, f"{prefix}axle_config.anti_roll.stiffness", RIGID_BAR)
    return axle


def axle_key(vehicle: VehicleGeometry, end: str, key: str) -> tuple[str, str]:
    """Where an axle's ``key`` is: (its file, the key), or for an axle inline the vehicle
    file and the key under ``front.``/``rear.``."""
    if isinstance(vehicle.data.get(end), dict):
        return vehicle.source, f"{end}.{key}"
    return getattr(vehicle, end).source, key
