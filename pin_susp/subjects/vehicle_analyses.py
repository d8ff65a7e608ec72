"""A vehicle's answers to what the analyses ask every subject (analyses_surface.py):
setup, loads and hardpoint sensitivities per corner, each corner's setup its axle's —
named, and written back, in that axle's file (docs/vehicle.md). Kept out of
vehicle.py, whose job is the car's model, its sweep and its columns.
"""

from __future__ import annotations

import copy
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import InputError, PinSuspError
from .assembly import Assembly
from .axle_file import AXLE_COLUMNS, AxleAssembly, AxleReader
from .elements.car_axle import car_column
from .vehicle_file import AXLES, LABELS, axle_key, load_vehicle

SIDE = {"fl": "left", "fr": "right", "rl": "left", "rr": "right"}  # its axle's side
END = {"fl": "front", "fr": "front", "rl": "rear", "rr": "rear"}
AXLE_STATIC = (("track", "track"), ("roll_center_y", "RC y"), ("roll_center_z", "RC z"))
# an axle's per-side rates along its wheels' roll: a vehicle's deriv_camber_wrt_roll_fl is
# along the body's roll on the road (vehicle.py), which its sensitivities do not hold
ROLL_RATES = tuple(f"deriv_{m}_wrt_roll_{s}" for m in ("camber", "roadwheel_angle")
                   for s in ("left", "right"))  # fmt: skip
ROLL_AXIS = ("roll_axis_inclination", "roll_axis_height_at_cg")
PITCH_CENTRE = ("pitch_center_x", "pitch_center_z")


class VehicleAssembly(Assembly):
    """The analyses' questions to a Vehicle (``self.vehicle``, a VehicleGeometry):
    the corners a setup sets (``--side fl``, or an axle's two, ``--side front``; a
    mirrored axle's right corner takes its left's setup), the axle file and key each
    corner's setup is in, the files a solved setup writes, each axle's static columns,
    each axle's anti-roll bar for the loads, and the hardpoints' sensitivities per
    corner or mirrored per axle."""

    # setup: each axle's track and roll centre, as that axle's own (AxleAssembly's)
    static_columns = tuple(
        (f"{name}_{end}", f"{head} {end[0]}") for end in AXLES for name, head in AXLE_STATIC
    )
    static_heading = "each axle (both its sides as set in each row)"
    setup_unit = "corner"
    setup_sides = (*LABELS, *AXLES)

    @classmethod
    def as_drawn(cls, path, label: str | None = None) -> VehicleAssembly:
        if label is not None and label not in cls.setup_sides:  # before the file is read
            raise cls._unknown_side(label)
        drawn = cls.__new__(cls)  # no model built: the setup surface alone
        drawn.vehicle = vehicle = load_vehicle(path)
        drawn.source, drawn.name = vehicle.source, vehicle.name
        drawn.corners = {c: vehicle.corner(c) for c in LABELS}
        return drawn

    @staticmethod
    def _unknown_side(label: str) -> InputError:
        return InputError(
            "--side",
            "",
            f"unknown side {label!r} (a vehicle's corner, fl, fr, rl or rr, or an axle, "
            "front or rear)",
        )

    def _axle(self, label: str):
        return getattr(self.vehicle, END[label])

    def setup_labels(self, label: str | None = None) -> tuple[str, ...]:
        """Every corner, an axle's two (``front``, ``rear``) or one corner alone — refused
        where its axle is mirrored: one setup sets both its sides."""
        if label is None:
            return self.labels
        if label in AXLES:
            return AXLES[label]
        if label not in LABELS:
            raise self._unknown_side(label)
        axle = self._axle(label)
        if axle.mirrored:
            source, _ = axle_key(self.vehicle, END[label], "hardpoints")
            raise InputError(
                "--side",
                "",
                f"the {END[label]} axle ({source}) is mirrored (no hardpoints.right): its "
                "right corner takes the left's setup, so one setup sets both: give --side "
                f"{END[label]}, or the right corner's own points (hardpoints.right, with "
                "axle_config.right_setup) to set one corner alone",
            )
        return (label,)

    def setup_owner(self, label: str) -> str:
        """A mirrored axle's right corner takes its left's setup."""
        if SIDE[label] == "right" and self._axle(label).mirrored:
            return AXLES[END[label]][0]
        return label

    def file_key(self, label: str, key: str) -> str:
        """A corner's setup key as its axle's file names it (``axle_config.left_setup``;
        an inline axle's under ``front.``/``rear.`` in the vehicle file)."""
        side = SIDE[self.setup_owner(label)]
        try:
            AxleReader("", side).fail(key, "")
        except InputError as renamed:
            return axle_key(self.vehicle, END[label], renamed.key)[1]

    def setup_place(self, label: str) -> str:
        """Where a corner's setup is: its axle's file and key."""
        source, _ = axle_key(self.vehicle, END[label], "")
        return f"{source}: {self.file_key(label, 'config.setup')}"

    def setup_error(self, label: str, exc: InputError) -> InputError:
        """A corner's setup error as its axle's file names it (an inline axle's: in the
        vehicle file under front./rear.); the corner's label said."""
        axle = self._axle(label)
        if exc.source != axle.source:
            return InputError(exc.source, exc.key, f"{label} corner: {exc.problem}")
        source, _ = axle_key(self.vehicle, END[label], "")
        return InputError(source, self.file_key(label, exc.key), f"{label} corner: {exc.problem}")

    def setup_data(self, geometries: dict) -> dict:
        """The vehicle file's data with each axle a corner of which is set (label →
        Geometry) inline, its setup written in (``front.axle_config.left_setup``)."""
        data = copy.deepcopy(self.vehicle.data)
        for end, axle in self._set_axles(geometries).items():
            data[end] = axle
        return data

    def _set_axles(self, geometries: dict) -> dict:
        """end → that axle's file data with its set corners' setup written in."""
        from ..solve.as_set import axle_data

        out = {}
        for end, labels in AXLES.items():
            given = {SIDE[c]: geometries[c] for c in labels if c in geometries}
            if given:
                out[end] = axle_data(getattr(self.vehicle, end), given)
        return out

    def setup_files(self, geometries: dict, path) -> list[tuple[Path, dict]]:
        """The files a solved setup writes, (path, data): the vehicle file at ``path``
        and, for each axle set that is a file of its own, that axle's file beside it
        (``<stem>_front.yaml``, its setup in ``axle_config.<side>_setup``), which the
        vehicle file names; an axle not set is named where it is, an inline one stays
        inline."""
        from ..io.atomic import is_stream

        path = Path(path)
        data = copy.deepcopy(self.vehicle.data)
        here = Path(self.vehicle.source).parent
        out, set_axles = [], self._set_axles(geometries)
        for end in AXLES:
            given = self.vehicle.data[end]
            if isinstance(given, dict):
                data[end] = set_axles.get(end, given)
                continue
            if end not in set_axles:
                data[end] = os.path.relpath(here / given, path.parent.resolve())
                continue
            if is_stream(path):
                raise PinSuspError(
                    f"{path}: the vehicle's {end} axle is a file of its own: its setup is "
                    "written beside the vehicle file, so -o names a file"
                )
            axle_path = path.with_name(f"{path.stem}_{end}{path.suffix or '.yaml'}")
            inputs = {
                (here / self.vehicle.data[e]).resolve()
                for e in AXLES
                if not isinstance(self.vehicle.data[e], dict)
            }
            if axle_path.resolve() in inputs | {Path(self.vehicle.source).resolve()}:
                raise PinSuspError(
                    f"{axle_path}: the {end} axle's setup would be written over an input: "
                    "give -o another name"
                )
            data[end] = axle_path.name
            out.append((axle_path, set_axles[end]))
        return [(path, data), *out]

    def static_results(self, corners: dict) -> dict[str, float]:
        """Each axle's track and roll centre (``track_front``, mm) with its corners as
        given (label → Geometry with its setup values), as that axle's own at design."""
        from ..model.sweep import Sweep
        from ..solve.solver import Solution
        from .axle import AxleModel

        out = {}
        for end, (first, second) in AXLES.items():
            axle = getattr(self.vehicle, end)
            model = AxleModel(replace(axle, left=corners[first], right=corners[second]))
            solution = Solution(model.q_design, True, 0, 0.0)
            results = model.sweep_results(Sweep([], "<static state>"), [solution])
            for name, _ in AXLE_STATIC:
                out[f"{name}_{end}"] = float(results[name][0])
        return out

    # -- loads (statics.py) ------------------------------------------------------

    @property
    def shared_springs(self) -> tuple:
        """Each axle's anti-roll bar (the joints whose turn twists it, its stiffness in
        N·m/deg, its torque's name: ``arb_front``), as an axle's (AxleModel's): the
        loads' statics share each axle's wheel loads between its springs and its bar."""
        out = []
        for end, elements in self.axle_elements.items():
            bar = elements.bar
            if bar.kind == "none":
                continue
            if bar.kind == "u_bar":
                joints = tuple(f"{c}_arb_arm_pivot" for c in bar.labels)
            else:
                joints = (f"{end}_t_bar_pivot_b",)
            out.append((joints, bar.axle.anti_roll_stiffness, f"arb_{end}"))
        return tuple(out)

    # -- hardpoint sensitivities (sensitivity.py) ---------------------------------

    element_points = AxleAssembly.element_points  # its axles' bars and heave links
    sensitivity_pairs = tuple(AXLES.values())

    def sensitivity_move(self, label: str, one_sided: bool = False) -> tuple[str, bool]:
        """A corner's hardpoint P: its axle's ``front_P`` (both corners, the right
        mirrored), or ``one_sided`` its own ``fl_P``."""
        if one_sided:
            return f"{label}_", False
        return f"{END[label]}_", SIDE[label] == "right"

    def sensitivity_move_text(self, one_sided: bool = False) -> str:
        if one_sided:
            return "a one-sided move: fl_P, fr_P, rl_P and rr_P each move alone"
        return (
            "a mirrored move per axle: hardpoint front_P moves the fl P by (dx, dy, dz) and "
            "the fr P by (dx, -dy, dz), rear_P the rl and rr P"
        )

    def pair_column(self, pair: tuple[str, str], name: str) -> str | None:
        """An axle's column as the vehicle's sweep names it (``track_front``,
        ``deriv_roll_center_z_wrt_axle_roll_front``); none of what the vehicle measures on the
        road instead (camber to ground, the rates along the body's roll)."""
        if name in ROLL_RATES:
            return None
        return car_column(name, pair, END[pair[0]])

    @property
    def car_sensitivity_columns(self) -> tuple[str, ...]:
        """The roll axis, the pitch centre and each anti % with a share (vehicle_columns.py)."""
        return (*ROLL_AXIS, *PITCH_CENTRE, *(name for name, *_ in self._antis()))

    @property
    def sensitivity_columns(self) -> tuple[str, ...]:
        """Each axle's columns (``track_front``, ...), then the car's."""
        pairs = (self.pair_column(pair, n) for pair in self.sensitivity_pairs for n in AXLE_COLUMNS)
        return (*(n for n in pairs if n is not None), *self.car_sensitivity_columns)

    def _antis(self) -> list[tuple[str, str, float, str]]:
        """(column, end, share, reaction) of each anti % with a share (vehicle_columns.py's
        anti_columns)."""
        v = self.vehicle
        cases = (
            ("anti_dive_front", "front", v.brake_share("front"), v.brake_reaction("front")),
            ("anti_lift_rear", "rear", v.brake_share("rear"), v.brake_reaction("rear")),
            ("anti_squat_rear", "rear", v.drive_share("rear"), v.drive_reaction("rear")),
            ("anti_lift_front", "front", v.drive_share("front"), v.drive_reaction("front")),
        )
        return [c for c in cases if c[2]]

    def car_sensitivities(self, corners: dict, pairs: dict) -> dict:
        """The whole car's columns, as vehicle_columns.py computes them from the columns
        at a step, on Duals over the hardpoint coordinates (mm): the roll axis through
        both axles' roll centres, the pitch centre where each axle's line from its
        contact patch to its side-view instant centre (the mean of its two corners')
        meets the other's, each anti % (the mean of its axle's two corners)."""
        v = self.vehicle
        cp = {
            c: (p["contact_patch_center_x"], p["contact_patch_center_z"])
            for c, p in corners.items()
        }
        x = {end: (cp[a][0] + cp[b][0]) * 0.5 for end, (a, b) in AXLES.items()}
        rc = {end: pairs[labels]["roll_center_z"][0] for end, labels in AXLES.items()}
        rise, run = rc["front"] - rc["rear"], x["front"] - x["rear"]
        out = {
            "roll_axis_inclination": (np.arctan2(rise, run) * (180.0 / np.pi), "deg"),
            "roll_axis_height_at_cg": (rc["rear"] + rise * (v.cg[0] * 1e3 - x["rear"]) / run, "mm"),
        }
        sv = {}
        for end, (a, b) in AXLES.items():
            sv[end] = (
                (corners[a]["svic_x"] + corners[b]["svic_x"]) * 0.5,
                (corners[a]["svic_z"] + corners[b]["svic_z"]) * 0.5,
                (cp[a][0] + cp[b][0]) * 0.5,
                (cp[a][1] + cp[b][1]) * 0.5,
            )
        (xf, zf, pfx, pfz), (xr, zr, prx, prz) = sv["front"], sv["rear"]
        df, dr = (xf - pfx, zf - pfz), (xr - prx, zr - prz)
        cross = df[0] * dr[1] - df[1] * dr[0]
        s = ((prx - pfx) * dr[1] - (prz - pfz) * dr[0]) / cross
        out["pitch_center_x"] = (pfx + s * df[0], "mm")
        out["pitch_center_z"] = (pfz + s * df[1], "mm")
        for name, end, share, reaction in self._antis():
            per_corner = []
            for c in AXLES[end]:
                p = corners[c]
                at = p["contact_patch_center_x"], p["contact_patch_center_z"]
                if reaction != "outboard":
                    at = p["wheel_center_x"], p["wheel_center_z"]
                run = p["svic_x"] - at[0]
                if end == "front":
                    run = -run  # the SVIC behind the front axle, ahead of the rear
                tan = (p["svic_z"] - at[1]) / run
                height = v.cg[2] * 1e3 - p["contact_patch_center_z"]
                per_corner.append(tan * (100.0 * share * v.wheelbase) / height)
            out[name] = ((per_corner[0] + per_corner[1]) * 0.5, "%")
        return out

    def held_at(self, sweep, step: int) -> None:
        return None  # each wheel centre's chassis-frame height and the rack

    def sensitivities_hold(self, sweep) -> bool:
        return False  # its sweep holds the body and the road, not each wheel's height

    def sensitivity_held(self) -> str:
        return "each wheel centre's height in the chassis frame and the rack held (the body still)"

    def sensitivity_sweep(self, sweep) -> tuple[list, object]:
        from .corner import Results  # the solver's columns alone: what the report reads

        solutions = self.solve_steps(sweep)
        columns, units = Results.solver_columns(solutions)
        meta = Results.solver_meta(solutions, (self.source, self.sha256), sweep, self)
        return solutions, Results(columns, units, meta)

    def sensitivity_groups(self, columns: list[str]) -> list[tuple[str, list]]:
        """Each axle's columns, the car's, then each corner's that does not take another's
        setup (a mirrored axle's right corner mirrors its left: said once)."""
        own = set(self.sensitivity_columns)
        groups = []
        for end, pair in AXLES.items():
            names = [self.pair_column(pair, n) for n in AXLE_COLUMNS]
            groups.append((f"the {end} axle:", [n for n in names if n is not None]))
        groups.append(("the car:", list(self.car_sensitivity_columns)))
        groups += super().sensitivity_groups([n for n in columns if n not in own])
        for label in LABELS:
            owner = self.setup_owner(label)
            if owner != label:
                groups.append(
                    (f"the {label} corner's columns mirror the {owner}'s (a mirrored axle)", ())
                )
        return groups
