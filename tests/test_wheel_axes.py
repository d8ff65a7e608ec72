"""Trail and scrub along the wheel's own heading (issue 24, point 8): mechanical_trail
is measured along world x, scrub_radius in the wheel's axes; trail_in_wheel_axes and
scrub_in_wheel_axes are both along the steered wheel's heading."""

import csv

import numpy as np
import pytest
from conftest import EXAMPLES, example, mirrored

import pin_susp
from pin_susp.cli import main
from pin_susp.model.sweep import Sweep, Target

RACK = np.linspace(-40.0, 40.0, 9)  # the example's rack from lock to lock, mm


def rack_sweep(rack, bump=0.0) -> Sweep:
    return Sweep(
        [
            Target("wheel_center", "z", np.full(len(rack), bump)),
            Target("trackrod_inboard", "y", rack),
        ]
    )


def by_hand(rows, s: float) -> dict[str, np.ndarray]:
    """From a results CSV's points alone: the steering axis through the two ball joints
    at the contact patch's height, G; the heading, the spin axis AI → AO turned a
    quarter turn about +z on the ground (+x at zero toe, either side); trail and scrub
    along it."""
    out = {"trail": [], "scrub": [], "world_x": []}
    for r in rows:
        p = {
            n: np.array([float(r[f"{n}_{a}"]) for a in "xyz"])
            for n in ("lower_wishbone_outboard", "upper_wishbone_outboard", "axle_inboard",
                      "axle_outboard", "contact_patch_center")
        }  # fmt: skip
        lbj, ubj, cp = (
            p["lower_wishbone_outboard"],
            p["upper_wishbone_outboard"],
            p["contact_patch_center"],
        )
        g = lbj + (ubj - lbj) * (cp[2] - lbj[2]) / (ubj[2] - lbj[2])
        a = p["axle_outboard"] - p["axle_inboard"]
        lateral = np.array([a[0], a[1], 0.0]) / np.hypot(a[0], a[1])  # outboard on the ground
        heading = s * np.cross(lateral, [0.0, 0.0, 1.0])
        out["trail"].append((g - cp) @ heading)
        out["scrub"].append(-(g - cp) @ lateral)
        out["world_x"].append(g[0] - cp[0])
    return {k: np.array(v) for k, v in out.items()}


def read(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


@pytest.mark.parametrize("side", ["left", "right"])
def test_trail_in_wheel_axes_against_the_points_of_the_csv(tmp_path, side):
    """At every steered step, from the CSV's own points; equal to mechanical_trail only
    where the wheel points along x (zero toe, the example's design)."""
    import yaml

    data = example("double_wishbone.yaml")
    rack = RACK
    if side == "right":
        data, rack = mirrored(data), -RACK  # the same steer, seen from the other side
    geometry = tmp_path / "corner.yaml"
    geometry.write_text(yaml.safe_dump(data))
    sweep = tmp_path / "rack.yaml"
    sweep.write_text(yaml.safe_dump({"targets": [
        {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0.0] * len(rack)},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": rack.tolist()},
    ]}))  # fmt: skip
    out = tmp_path / "r.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out), "-q"]) == 0
    rows = read(out)
    hand = by_hand(rows, 1.0 if side == "left" else -1.0)
    names = (
        "trail_in_wheel_axes",
        "scrub_in_wheel_axes",
        "scrub_radius",
        "mechanical_trail",
        "roadwheel_angle",
    )
    column = {k: np.array([float(r[k]) for r in rows]) for k in names}
    np.testing.assert_allclose(column["trail_in_wheel_axes"], hand["trail"], atol=1e-9)
    np.testing.assert_allclose(column["scrub_in_wheel_axes"], hand["scrub"], atol=1e-9)
    np.testing.assert_array_equal(column["scrub_in_wheel_axes"], column["scrub_radius"])
    np.testing.assert_allclose(column["mechanical_trail"], hand["world_x"], atol=1e-9)
    middle = len(rack) // 2  # the rack at centre: toe 0 at the example's design
    assert abs(column["roadwheel_angle"][middle]) < 1e-9
    assert column["trail_in_wheel_axes"][middle] == pytest.approx(
        column["mechanical_trail"][middle], abs=1e-9
    )
    # steered, the two differ by far more than any rounding (the point)
    assert abs(column["trail_in_wheel_axes"][0] - column["mechanical_trail"][0]) > 5.0


def test_the_example_at_full_lock():
    """The example's left corner at the rack's ±40 mm: world-x trail 6.70 / 60.75 mm,
    along the wheel's heading -3.12 / 72.16 mm (toe +14.6 / -13.2 deg)."""
    r = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").run_sweep(rack_sweep([-40.0, 40.0]))
    np.testing.assert_allclose(r["roadwheel_angle"], [14.559, -13.173], atol=1e-3)
    np.testing.assert_allclose(r["mechanical_trail"], [6.702, 60.747], atol=1e-3)
    np.testing.assert_allclose(r["trail_in_wheel_axes"], [-3.117, 72.156], atol=1e-3)


def test_the_long_batched_sweep_gives_the_same_new_columns():
    """A sweep of 200 steps or more is solved in one batch (bulk.py): its trail and scrub
    in wheel axes, and their derivatives, are those of a short sweep's steps."""
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    rack = np.linspace(-40.0, 40.0, 401)
    bump = np.linspace(-30.0, 30.0, 401)
    long = corner.run_sweep(
        Sweep([Target("wheel_center", "z", bump), Target("trackrod_inboard", "y", rack)])
    )
    few = np.arange(0, 401, 50)
    short = corner.run_sweep(
        Sweep([Target("wheel_center", "z", bump[few]), Target("trackrod_inboard", "y", rack[few])])
    )
    names = [n for n in long.columns if "in_wheel_axes" in n]
    assert len(names) == 6  # the two columns, each with its hub-z and rack derivatives
    for name in names:
        np.testing.assert_allclose(long[name][few], short[name], rtol=0, atol=1e-9, err_msg=name)


def test_the_rack_derivative_matches_a_central_difference():
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    h = 1e-3
    at = corner.run_sweep(rack_sweep([-30.0 - h, -30.0, -30.0 + h], bump=20.0))
    fd = (at["trail_in_wheel_axes"][2] - at["trail_in_wheel_axes"][0]) / (2 * h)
    exact = at["deriv_trail_in_wheel_axes_wrt_rack_displacement"][1]
    assert exact == pytest.approx(fd, rel=1e-6)
    assert abs(exact - at["deriv_mechanical_trail_wrt_rack_displacement"][1]) > 0.05
