"""Metrics as docs/results.md defines them: symmetry, invariance, hand values."""

import copy

import numpy as np
import pytest
from conftest import example, mirrored, translated

import pin_susp
from pin_susp.columns.metrics import METRICS

SIDE_FREE = (
    "camber",
    "caster",
    "kpi",
    "roadwheel_angle",
    "scrub_radius",
    "mechanical_trail",
    "wheel_travel",
    "half_track",
)


def mirrored_sweep(sweep: dict) -> dict:
    s = copy.deepcopy(sweep)
    for t in s["targets"]:
        if t["direction"].get("axis") == "y":
            for key in ("start", "stop"):
                t[key] = -t[key]
    return s


def test_right_corner_mirrored_from_left_gives_equal_metrics_and_mirrored_points():
    left_geo, sweep = example("double_wishbone.yaml"), example("bump_steer.yaml")
    left = pin_susp.Corner(left_geo).run_sweep(sweep)
    right = pin_susp.Corner(mirrored(left_geo)).run_sweep(mirrored_sweep(sweep))
    assert right["solver_converged"].all()
    for name in SIDE_FREE:
        np.testing.assert_allclose(right[name], left[name], atol=1e-9, err_msg=name)
    for name in pin_susp.Corner(left_geo).point_names:
        np.testing.assert_allclose(right[f"{name}_y"], -left[f"{name}_y"], atol=1e-9)
        np.testing.assert_allclose(right[f"{name}_x"], left[f"{name}_x"], atol=1e-9)
        np.testing.assert_allclose(right[f"{name}_z"], left[f"{name}_z"], atol=1e-9)
    # the rack steers the right wheel the other way in y, the same way in toe
    assert left["roadwheel_angle"][0] > 2.0 and right["roadwheel_angle"][0] > 2.0


def test_translating_every_hardpoint_changes_no_metric():
    geo, sweep = example("double_wishbone.yaml"), example("bump_steer.yaml")
    shift = (123.0, 45.0, -67.0)
    base = pin_susp.Corner(geo).run_sweep(sweep)
    moved = pin_susp.Corner(translated(geo, shift)).run_sweep(sweep)
    for name in (
        "camber",
        "caster",
        "kpi",
        "roadwheel_angle",
        "scrub_radius",
        "mechanical_trail",
        "wheel_travel",
    ):
        np.testing.assert_allclose(moved[name], base[name], atol=1e-9, err_msg=name)
    np.testing.assert_allclose(moved["half_track"], base["half_track"] + shift[1], atol=1e-9)
    np.testing.assert_allclose(
        moved["wheel_center_x"], base["wheel_center_x"] + shift[0], atol=1e-9
    )


def test_design_state_values_by_hand(corner):
    """The example corner at design, computed from its hardpoints with a calculator."""
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 0.0), pin_susp.Target("trackrod_inboard", "y", 0.0)]
    )
    m = pose.metrics
    # â ∝ (0, 150, 5); k ∝ UBJ − LBJ = (−25, −150, 300)
    assert m["camber"] == pytest.approx(-np.degrees(np.arctan2(5, 150)), abs=1e-12)
    assert m["roadwheel_angle"] == pytest.approx(0.0, abs=1e-12)
    assert m["caster"] == pytest.approx(np.degrees(np.arctan2(25, 300)), abs=1e-12)
    assert m["kpi"] == pytest.approx(np.degrees(np.arctan2(150, 300)), abs=1e-12)
    # R = (13·25.4 + 2·0.55·270)/2 = 313.6 mm; WC = axle_outboard (offset 0)
    a = np.array([0, 150, 5]) / np.hypot(150, 5)
    down = np.array([0, 0, -1]) + a[2] * a
    cp = np.array([-20, 950, 313.426]) + 313.6 * down / np.linalg.norm(down)
    np.testing.assert_allclose(pose.points["contact_patch_center"], cp, atol=1e-10)
    assert m["half_track"] == pytest.approx(cp[1], abs=1e-10)
    t = (cp[2] - 200.0) / 300.0  # LBJ z = 200, k_z = 300 (unnormalised)
    ground = np.array([0, 900, 200]) + t * np.array([-25, -150, 300])
    assert m["mechanical_trail"] == pytest.approx(ground[0] - cp[0], abs=1e-10)
    assert m["scrub_radius"] == pytest.approx(-(ground[1] - cp[1]), abs=1e-10)
    assert m["wheel_travel"] == 0.0


def test_toe_and_camber_signs_follow_the_spec():
    """Toe-in and negative camber mean the same physical thing on both sides."""
    geo = example("double_wishbone.yaml")
    # Point the spin axis 1° forward in plan view (front of the wheel inboard: toe-in)
    # and 2° up in front view (outboard end higher: top of the wheel leans in).
    axis = np.array([np.tan(np.radians(1.0)), 1.0, np.tan(np.radians(2.0))])
    axis /= np.linalg.norm(axis)
    ai = np.array([-20.0, 800.0, 308.426])
    for name, p in (("axle_inboard", ai), ("axle_outboard", ai + 150 * axis)):
        geo["hardpoints"][name] = dict(zip("xyz", map(float, p), strict=True))
    for g in (geo, mirrored(geo)):
        pose = pin_susp.Corner(g).solve_pose(
            [
                pin_susp.Target("wheel_center", "z", 0.0),
                pin_susp.Target("trackrod_inboard", "y", 0.0),
            ]
        )
        assert pose.metrics["roadwheel_angle"] == pytest.approx(1.0, abs=1e-9)
        assert pose.metrics["camber"] == pytest.approx(-2.0, abs=1e-9)


def test_damper_length_is_strut_distance_and_only_with_a_coilover():
    corner = pin_susp.Corner(example("fixed_toe_link.yaml"))
    results = corner.run_sweep(example("bump.yaml"))
    top = np.column_stack([results[f"strut_top_{a}"] for a in "xyz"])
    bottom = np.column_stack([results[f"strut_bottom_{a}"] for a in "xyz"])
    np.testing.assert_allclose(
        results["damper_length"], np.linalg.norm(top - bottom, axis=1), atol=1e-12
    )
    assert np.all(np.diff(results["damper_length"]) < 0)  # bump compresses it
    rack = pin_susp.Corner(example("double_wishbone.yaml"))
    assert "damper_length" not in rack.run_sweep(example("bump_steer.yaml")).columns


def test_flat_steering_axis_leaves_scrub_and_trail_empty():
    from pin_susp.columns.metrics import PointSet, mechanical_trail, scrub_radius

    corner = pin_susp.Corner(example("double_wishbone.yaml"))
    p = {k: v[None].copy() for k, v in corner.design_positions.items()}
    p["upper_wishbone_outboard"][0, 2] = p["lower_wishbone_outboard"][0, 2]
    ps = PointSet(p, p, corner.geometry)
    assert np.isnan(scrub_radius(ps)[0]) and np.isnan(mechanical_trail(ps)[0])


def test_registry_gives_every_column_a_unit_and_label():
    assert len({m.name for m in METRICS}) == len(METRICS)
    for m in METRICS:
        assert m.unit in ("deg", "mm", "mm/rad", "%", "N") and m.label and m.function.__doc__


@pytest.mark.parametrize("side", ["left", "right"])
def test_every_metric_derivative_matches_central_differences(side):
    """d<metric> along arbitrary point velocities, against differences of the metric itself."""
    from pin_susp.columns.metrics import PointSet
    from pin_susp.maths.jet import Dual

    data = example("pushrod_rocker.yaml")
    data = mirrored(data) if side == "right" else data
    corner = pin_susp.Corner(data)
    s = 1.0 if side == "left" else -1.0
    pose = corner.solve_pose(
        [
            pin_susp.Target("wheel_center", "z", 35.0),
            pin_susp.Target("trackrod_inboard", "y", 7.0 * s),
        ]
    )
    points = {k: v[None] * 1e-3 for k, v in pose.points.items()}
    design = {k: v[None] for k, v in corner.design_positions.items()}
    rng = np.random.default_rng(7)
    rates = {k: rng.normal(size=(1, 3)) for k in points}
    h = 1e-7
    dual = {k: Dual(v, rates[k]) for k, v in points.items()}
    for m in METRICS:
        if not m.applies(corner.geometry) or m.rates:  # a twist: not a function of positions
            continue
        exact = m.function(PointSet(dual, design, corner.geometry)).der[0]
        plus = {k: v + h * rates[k] for k, v in points.items()}
        minus = {k: v - h * rates[k] for k, v in points.items()}
        fd = (
            m.function(PointSet(plus, design, corner.geometry))[0]
            - m.function(PointSet(minus, design, corner.geometry))[0]
        ) / (2 * h)
        assert exact == pytest.approx(fd, rel=1e-6, abs=1e-8), m.name


def test_mirrored_pushrod_rocker_corner_gives_the_same_rocker_and_damper():
    left_geo, sweep = example("pushrod_rocker.yaml"), example("bump_steer.yaml")
    left = pin_susp.Corner(left_geo).run_sweep(sweep)
    right = pin_susp.Corner(mirrored(left_geo)).run_sweep(mirrored_sweep(sweep))
    for name in SIDE_FREE + ("rocker_angle", "damper_length"):
        np.testing.assert_allclose(right[name], left[name], atol=1e-9, err_msg=name)
    assert abs(left["rocker_angle"][0]) > 1.0


# -- rocker transmission angle, rack travel, one motion-ratio convention -----------------


def _rocker_angle_by_hand(p: dict) -> float:
    """The angle at pushrod_inboard between rocker arm and pushrod, seen along the axis (deg)."""
    a, b = np.array(p["rocker_axis_a"]), np.array(p["rocker_axis_b"])
    u = (b - a) / np.linalg.norm(b - a)
    flat = lambda v: v - u * (u @ v)  # noqa: E731
    arm = flat(np.array(p["pushrod_inboard"]) - a)
    rod = flat(np.array(p["pushrod_outboard"]) - np.array(p["pushrod_inboard"]))
    return np.degrees(np.arccos(arm @ rod / np.linalg.norm(arm) / np.linalg.norm(rod)))


def test_rocker_transmission_angle_matches_the_angle_by_hand(tmp_path):
    corner = pin_susp.Corner(example("pushrod_rocker.yaml"))
    results = corner.run_sweep(example("bump_steer.yaml"))
    for i in (0, 20, 40):
        p = {n: [results[f"{n}_{a}"][i] for a in "xyz"] for n in corner.point_names}
        assert results["rocker_transmission_angle"][i] == pytest.approx(
            _rocker_angle_by_hand(p), abs=1e-9
        )


def test_rack_displacement_is_rack_travel_from_design():
    corner = pin_susp.Corner(example("double_wishbone.yaml"))
    results = corner.run_sweep(example("bump_steer.yaml"))
    np.testing.assert_allclose(results["rack_displacement"], np.linspace(-10, 10, 41), atol=1e-9)


def _torsion_bar(swap_axis: bool) -> dict:
    g = example("pushrod_rocker.yaml")
    g["spring"] = {"type": "torsion_bar"}
    for name in ("strut_top", "strut_bottom"):
        del g["hardpoints"][name]
    if swap_axis:
        hp = g["hardpoints"]
        hp["rocker_axis_a"], hp["rocker_axis_b"] = hp["rocker_axis_b"], hp["rocker_axis_a"]
    return g


def test_motion_ratio_has_one_sign_convention_for_coilover_and_torsion_bar():
    sweep = example("bump_steer.yaml")
    coil = pin_susp.Corner(example("pushrod_rocker.yaml")).run_sweep(sweep)
    bar = pin_susp.Corner(_torsion_bar(False)).run_sweep(sweep)
    swapped = pin_susp.Corner(_torsion_bar(True)).run_sweep(sweep)
    assert coil["motion_ratio"][16] > 0 and bar["motion_ratio"][16] > 0  # bump loads both
    np.testing.assert_allclose(swapped["motion_ratio"], bar["motion_ratio"], rtol=0, atol=1e-12)
    # the twist itself keeps its documented sign (docs/results.md), which the a→b order flips
    np.testing.assert_allclose(swapped["torsion_bar_twist"], -bar["torsion_bar_twist"], atol=1e-9)
