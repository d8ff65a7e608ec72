"""The whole car against a point-based formulation of its own (the whole-car issue's
acceptance check 5(b)): a pure heave, pitch or roll of the body, reproduced with no
Pinocchio.

tests/pointwise.py ``PointwiseVehicle``: every moving hardpoint of the four corners in
the road's frame as unknowns (and the rack's travel), the chassis points placed by the
body's pose (w = c + h·ẑ + R_y(θ)·R_x(φ)·(p − c)), each corner's rigid distances and
lines from pin_susp.analyses.pointwise, each wheel's lowest point on the road, the rack
at design (or at the steering wheel's travel), scipy least_squares to 1e-12 m. Its
points, brought back to the chassis frame, and the columns recomputed from them
(docs/results.md, docs/vehicle.md) must be pin_susp's to 1e-6 mm / deg.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pointwise import PointwiseVehicle

from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.vehicle import LABELS, Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CARS = {"fs": EXAMPLES / "vehicle_fs.yaml", "saloon": EXAMPLES / "vehicle_saloon.yaml"}
STEPS = 5
# motion → (heave mm, pitch deg, roll deg, steering wheel deg), a value or one per step
MOTIONS = {
    "heave": (np.linspace(-25, 25, STEPS), 0.0, 0.0, 0.0),
    "pitch": (0.0, np.linspace(-2, 2, STEPS), 0.0, 0.0),
    "roll": (0.0, 0.0, np.linspace(-2, 2, STEPS), 0.0),
    "roll_steered": (0.0, 0.0, np.linspace(-2, 2, STEPS), 30.0),
    # not pure: the body's pitch before its roll (R_y·R_x, not R_x·R_y)
    "heave_pitch_roll": (5.0, 1.0, np.linspace(-2, 2, STEPS), 0.0),
}
POINTS_MM = 1e-6  # every point, mm
ANGLES_DEG = 1e-6  # camber, camber to ground, roadwheel angle, deg
WHEELBASE_MM = 1e-6
CLOSED_M = 1e-12  # the point-based solve's max |residual|
Z = np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module", params=list(CARS), ids=list(CARS))
def car(request):
    return Vehicle(CARS[request.param])


@pytest.fixture(scope="module")
def by_points(car):
    return PointwiseVehicle(car.corners, car.vehicle.cg)


def sweep_of(heave, pitch, roll, steer) -> Sweep:
    full = [
        np.broadcast_to(np.asarray(v, dtype=float), (STEPS,)).copy()
        for v in (heave, pitch, roll, steer)
    ]
    quantities = ("heave", "pitch", "roll", "steering_wheel")
    return Sweep([Target(None, None, v, quantity=q) for q, v in zip(quantities, full, strict=True)])


def rack_travel(car, steer_deg: float) -> float:
    """The rack's travel (m) for a steering-wheel angle, as docs/vehicle.md says it:
    angle / 360 × c_factor, to the left (+y) for + when the trackrods are ahead of the
    wheel centre (the design points of the front left corner)."""
    hp = car.vehicle.corner("fl").design_points()
    ahead = hp["trackrod_outboard"][0] > hp["wheel_center"][0]
    return (1.0 if ahead else -1.0) * steer_deg / 360.0 * car.vehicle.c_factor * 1e-3


def chassis_lowest(centre: np.ndarray, spin: np.ndarray, radius: float) -> np.ndarray:
    """The wheel's lowest point along the chassis' own −z (a corner's contact patch,
    docs/geometry.md): the centre plus R along −ẑ laid into the wheel plane."""
    down = -Z + (spin @ Z) * spin
    return centre + radius * down / np.linalg.norm(down)


def solve_by_points(car, by_points, pose: np.ndarray) -> list[dict]:
    """Each step of the pose (heave m, pitch rad, roll rad, rack m), marched from the
    previous step's solution: the world points (mm), the chassis-frame points (mm: every
    point brought back by the body's pose, the contact patch the chassis' own lowest
    point as a corner writes it) and the solve's residual (m)."""
    out, x = [], None
    for heave, pitch, roll, rack in pose:
        x, residual = by_points.solve_pose(heave, pitch, roll, rack=rack, x0=x)
        world = by_points.points(x)
        chassis = {n: by_points.to_chassis(w) for n, w in world.items()}
        for label in LABELS:
            p = f"{label}_"
            spin = chassis[p + "axle_outboard"] - chassis[p + "axle_inboard"]
            chassis[p + "contact_patch_center"] = chassis_lowest(
                chassis[p + "wheel_center"],
                spin / np.linalg.norm(spin),
                car.corners[label].wheel.radius,
            )
        mm = lambda d: {n: v * 1e3 for n, v in d.items()}  # noqa: E731
        out.append({"world": mm(world), "chassis": mm(chassis), "residual": residual})
    return out


def columns_of(chassis: dict, world: dict) -> dict[str, float]:
    """camber, roadwheel_angle (docs/results.md, chassis frame), camber_to_ground
    (docs/vehicle.md: the camber of the spin axis in the road's frame) and the
    wheelbase per side (the world contact patches' x, front minus rear)."""
    out = {}
    for label in LABELS:
        s = 1.0 if label[1] == "l" else -1.0
        p = f"{label}_"
        a, w = (f[p + "axle_outboard"] - f[p + "axle_inboard"] for f in (chassis, world))
        a, w = a / np.linalg.norm(a), w / np.linalg.norm(w)
        camber = -np.degrees(np.arctan2(a[2], s * a[1]))
        out[f"camber_{label}"] = camber
        out[f"roadwheel_angle_{label}"] = np.degrees(np.arctan2(a[0], s * a[1]))
        out[f"camber_to_ground_{label}"] = -np.degrees(np.arctan2(w[2], s * w[1]))
    for side, (f, r) in (("left", ("fl", "rl")), ("right", ("fr", "rr"))):
        cp = "_contact_patch_center"
        out[f"wheelbase_{side}"] = world[f + cp][0] - world[r + cp][0]
    return out


def written_points(results, label: str) -> set[str]:
    """The points the results write for a corner (``<label>_<point>_x|y|z``), its
    anti-roll bar's droplink ends aside (a bar adds a joint and a droplink: it leaves
    the corners' motion as it is; tests/test_vehicle_bars.py checks its points)."""
    p = f"{label}_"
    bar = ("droplink_rocker", "droplink_lower", "droplink_u_bar", "droplink_t_bar")
    return {
        k[:-2]
        for k in results.keys()
        if k.startswith(p) and k.endswith("_x") and k[len(p) : -2] not in bar
    }


@pytest.mark.parametrize("motion", list(MOTIONS))
def test_a_body_motion_is_the_point_based_cars(car, by_points, motion):
    """Each step of the motion: the point-based car closes to 1e-12 m with every contact
    patch on the road; each point pin_susp writes (chassis frame) is its point to 1e-6
    mm; camber, camber to ground, roadwheel angle and the wheelbases recomputed from its
    points are pin_susp's to 1e-6 deg / mm; the rack is where the steering wheel puts it."""
    heave, pitch, roll, steer = MOTIONS[motion]
    results = car.run_sweep(sweep_of(heave, pitch, roll, steer))
    assert results["solver_converged"].all()
    pose = np.column_stack(
        [
            np.broadcast_to(np.asarray(heave, dtype=float) * 1e-3, (STEPS,)),
            np.broadcast_to(np.radians(pitch), (STEPS,)),
            np.broadcast_to(np.radians(roll), (STEPS,)),
            np.full(STEPS, rack_travel(car, steer)),
        ]
    )
    np.testing.assert_allclose(results["heave"], pose[:, 0] * 1e3, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.radians(results["pitch"]), pose[:, 1], rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.radians(results["roll"]), pose[:, 2], rtol=0, atol=1e-15)
    solved = solve_by_points(car, by_points, pose)
    for step, own in enumerate(solved):
        assert own["residual"] <= CLOSED_M, (motion, step)
        for label in LABELS:
            # every contact patch on the road, and every point pin_susp writes is one of ours
            assert abs(own["world"][f"{label}_contact_patch_center"][2]) <= CLOSED_M * 1e3
            names = written_points(results, label)
            assert names and names <= set(own["chassis"]), names - set(own["chassis"])
            for name in names:
                theirs = np.array([results[f"{name}_{a}"][step] for a in "xyz"])
                np.testing.assert_allclose(
                    theirs,
                    own["chassis"][name],
                    rtol=0,
                    atol=POINTS_MM,
                    err_msg=f"{motion} {step} {name}",
                )
        for column, value in columns_of(own["chassis"], own["world"]).items():
            atol = WHEELBASE_MM if column.startswith("wheelbase") else ANGLES_DEG
            assert results[column][step] == pytest.approx(value, rel=0, abs=atol), (
                motion,
                step,
                column,
            )
    # the rack where the steering wheel puts it, in the chassis frame
    travel = (
        solved[0]["chassis"]["fl_trackrod_inboard"][1]
        - car.vehicle.corner("fl").design_points()["trackrod_inboard"][1] * 1e3
    )
    assert travel == pytest.approx(rack_travel(car, steer) * 1e3, abs=1e-9)


def test_the_signs_of_pitch_and_roll(car, by_points):
    """+ pitch is nose down and + roll right side down (ISO 8855): on the point-based
    car the front (right) chassis points go down in the world, so pin_susp's front
    (right) wheels rise into bump in the chassis frame, the rear (left) ones drop."""
    design = {
        label: car.vehicle.corner(label).design_points()["wheel_center"][2] * 1e3
        for label in LABELS
    }
    angle = np.radians(1.5)
    for quantity, pose, down in (
        ("pitch", (0.0, angle, 0.0), "f"),
        ("roll", (0.0, 0.0, angle), "r"),
    ):
        by_points.place(*pose)
        results = car.run_sweep(
            Sweep(
                [
                    Target(None, None, [0.0], quantity="heave"),
                    Target(None, None, [np.degrees(pose[1])], quantity="pitch"),
                    Target(None, None, [np.degrees(pose[2])], quantity="roll"),
                    Target(None, None, [0.0], quantity="steering_wheel"),
                ]
            )
        )
        for label in LABELS:
            first = label[0] if quantity == "pitch" else label[1]
            sign = -1.0 if first == down else 1.0  # world z of a pickup: lower where it goes down
            pickup = f"{label}_axle_outboard"  # a point of the body at its design position
            moved = by_points.hp[pickup][2] - by_points.chassis[pickup][2]
            assert sign * moved > 1e-3, (quantity, label, pickup, moved)  # > 1 mm
            travel = results[f"{label}_wheel_center_z"][0] - design[label]
            assert -sign * travel > 1.0, (quantity, label, travel)  # mm: bump where it goes down
