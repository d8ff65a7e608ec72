"""The steering wheel and the rack, said once (docs/sweep.md, "The steering wheel";
docs/loads.md): a corner's, an axle's and a vehicle's c-factor, a corner's track, and
the formulas of the steering's columns — the steering wheel's angle, the rack's travel
and force, the steering-wheel torque, Ackermann and the turning radius.

The c-factor is the rack's travel per steering-wheel revolution (mm/rev): a corner's
``config.steering.c_factor``, an axle's ``axle_config.steering.c_factor``, a
vehicle's ``vehicle_config.steering.c_factor``. The steering wheel's angle is + turning
left; its sense on the rack (``steer_sense``) is +1 where the rack's travel to the left
(+y) turns the wheels left — the trackrods ahead of the wheel centre — and −1 where
they are behind it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..io.yamlio import Reader

STRAIGHT = 1e-6  # m of rack travel: a straight-ahead step has no Ackermann nor turning radius
ACKERMANN_FROM = 0.5  # deg of the outer wheel's steer below which Ackermann is blank


@dataclass(frozen=True)
class Steering:
    """The steering wheel on the rack: ``c_factor`` mm of rack per revolution (None: not
    given, no steering-wheel target nor column), ``sense`` ±1 (``steer_sense``)."""

    c_factor: float | None
    sense: float = 1.0

    def rack_travel(self, angle) -> np.ndarray:
        """The rack's travel (mm, + left) for the steering wheel's angle (deg, + left):
        sense · angle / 360 · c_factor."""
        return self.sense * np.asarray(angle, dtype=float) / 360.0 * self.c_factor

    def wheel_angle(self, travel) -> np.ndarray:
        """The steering wheel's angle (deg, + left) for the rack's travel (mm): the
        inverse of ``rack_travel``."""
        return self.sense * np.asarray(travel, dtype=float) / self.c_factor * 360.0

    def wheel_rate(self) -> float:
        """d steering-wheel angle / d rack travel, deg/mm."""
        return self.sense * 360.0 / self.c_factor

    def rack_force(self, force_y) -> np.ndarray:
        """The trackrods' force on the rack (N) along the sense that turns the car left,
        from their force along +y (``force_rack``)."""
        return self.sense * np.asarray(force_y, dtype=float)

    def wheel_torque(self, rack_force) -> np.ndarray:
        """The torque (N·m, + turning left) the rack's force (N, ``rack_force``) puts on
        the steering wheel through an ideal gear: F · c / (2π), c in m per revolution."""
        return np.asarray(rack_force, dtype=float) * self.c_factor * 1e-3 / (2.0 * np.pi)


def steer_sense(points: dict) -> float:
    """+1 where the rack's travel to the left turns the wheels left (the trackrod's outer
    end ahead of the wheel centre, x forward), −1 where it is behind; design points (m)."""
    return 1.0 if points["trackrod_outboard"][0] > points["wheel_center"][0] else -1.0


def c_factor_of(geometry, key: str = "config.steering.c_factor", source=None) -> float | None:
    """A corner's c-factor (mm/rev) from its file's ``config.steering`` (an axle's
    corners have their ``axle_config.steering``'s: ``key`` says where, ``source`` in
    which file, default the corner's), checked > 0; None where none is given."""
    source = geometry.source if source is None else source
    config = geometry.data.get("config") if isinstance(geometry.data, dict) else None
    steering = config.get("steering") if isinstance(config, dict) else None
    if not isinstance(steering, dict) or "c_factor" not in steering:
        return None
    if geometry.steering != "rack":
        raise InputError(source, key, "a c-factor needs a rack (steering type: rack)")
    return Reader(source).positive(steering["c_factor"], key)


TRACK_CHECK = 1.0  # mm: config.track against the mirrored partner's contact patches


def track_of(geometry, check: bool = True) -> float | None:
    """A corner's ``config.track`` (m): the track it stands in, which asks for its steering
    with its mirrored partner (docs/results.md, "Steering"), checked > 0 and (``check``:
    the file's own corner, not a study's variant of it, whose moved points move its
    partner alike) against the partner's contact patch at design (the corner mirrored
    in y = 0, its own contact patch's 2·|y|), to TRACK_CHECK; None where none is given."""
    config = geometry.data.get("config") if isinstance(geometry.data, dict) else None
    if not isinstance(config, dict) or "track" not in config:
        return None
    r = Reader(geometry.source)
    track = r.positive(config["track"], "config.track")
    mirrored = 2.0 * abs(geometry.design_points()["contact_patch_center"][1]) * 1e3
    if check and abs(track - mirrored) > TRACK_CHECK:
        r.fail(
            "config.track",
            f"{track:g} mm, but the corner mirrored in y = 0 stands in a track of "
            f"{mirrored:.6g} mm (its contact patch's 2·|y|): more than {TRACK_CHECK:g} mm "
            "apart (the steering's mirrored partner is the corner mirrored through the "
            "car's centre line, y = 0)",
        )
    return track * 1e-3


def ackermann(steer: tuple, design: tuple, wheelbase, track, travel) -> np.ndarray:
    """Ackermann, % (docs/axle.md): 100·(δ_i − δ_o)/(δ_i* − δ_o), δ each wheel's steer
    angle's change from design (deg), δ_i* = atan2(L, L/tan δ_o − track) the inner
    wheel's angle on the outer one's turning circle. ``steer``, ``design``: the (left,
    right) steer angles (deg, + left); ``wheelbase`` m (None: blank); ``track`` (n,) m;
    ``travel``: the rack's (n,) m (None: no rack, blank). Blank for δ_o below
    ACKERMANN_FROM and with the rack at centre (bump or roll steer is not steering)."""
    n = len(track)
    if wheelbase is None or travel is None:
        return np.full(n, np.nan)
    inner, outer = inner_outer(steer, design)
    with np.errstate(invalid="ignore", divide="ignore"):
        o = np.radians(outer)
        ideal = np.degrees(np.arctan2(wheelbase, wheelbase / np.tan(o) - np.abs(track)))
        out = 100.0 * (inner - outer) / (ideal - outer)
    out = np.where(outer >= ACKERMANN_FROM, out, np.nan)
    out[np.abs(travel) < STRAIGHT] = np.nan
    return out


def inner_outer(steer: tuple, design: tuple) -> tuple:
    """(δ_i, δ_o), deg: the inner and the outer wheel's steer from design, unsigned —
    the inner wheel the left one where the two steer left on average."""
    delta = [np.abs(s - d) for s, d in zip(steer, design, strict=True)]
    left_inner = (steer[0] + steer[1]) > 0.0
    return np.where(left_inner, delta[0], delta[1]), np.where(left_inner, delta[1], delta[0])


def turning_radius(steer: tuple, design: tuple, wheelbase, travel) -> np.ndarray:
    """The turning radius (m, + turning left) of the rear axle's midpoint: the wheelbase
    (m, (n,) or one) over the tangent of the two front wheels' mean steer from design
    (``steer``, ``design``: (left, right), deg); blank with the rack at centre."""
    delta = np.radians(0.5 * (steer[0] - design[0] + steer[1] - design[1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = wheelbase / np.tan(delta)
    radius = np.array(radius, dtype=float)
    radius[np.abs(travel) < STRAIGHT] = np.nan
    return radius
