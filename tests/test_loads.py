"""Member forces (docs/loads.md), against computations that share nothing with the
multipliers: the upright's free body written from the solved points, and virtual
work through a re-solved pose."""

import numpy as np
import pytest
from conftest import EXAMPLES

import pin_susp
from pin_susp.analyses.loads import LoadCase, Statics, load_cases
from pin_susp.constraints import DistanceClosure, JointTarget, Row
from pin_susp.errors import InputError, PinSuspError
from pin_susp.model.sweep import Sweep, Target
from pin_susp.solve.solver import NewtonSolver

CASES = [
    LoadCase("braking", np.array([-3000.0, 200.0, 2500.0]), np.zeros(3), np.zeros(3)),
    LoadCase("cornering", np.array([0.0, -4500.0, 2300.0]), np.array([150.0, 0.0, -80.0]),
             np.array([10.0, 60.0, -25.0])),
]  # fmt: skip
MEMBERS = {  # every member of the pushrod-rocker corner that ends on the upright
    "lower_wishbone_front": ("lower_wishbone_inboard_front", "lower_wishbone_outboard"),
    "lower_wishbone_rear": ("lower_wishbone_inboard_rear", "lower_wishbone_outboard"),
    "upper_wishbone_front": ("upper_wishbone_inboard_front", "upper_wishbone_outboard"),
    "upper_wishbone_rear": ("upper_wishbone_inboard_rear", "upper_wishbone_outboard"),
    "trackrod": ("trackrod_inboard", "trackrod_outboard"),
    "pushrod": ("pushrod_inboard", "pushrod_outboard"),
}


@pytest.fixture(scope="module")
def rocker():
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    sweep = Sweep(
        [
            Target("wheel_center", "z", [-25.0, 0.0, 30.0]),
            Target("trackrod_inboard", "y", [8.0, 0.0, -6.0]),
        ],
        "bump+steer",
    )
    return corner, Statics(corner), [s.q for s in corner.solve_steps(sweep)]


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_six_members_equal_the_free_body_of_the_upright(rocker, case):
    """Four wishbone legs, trackrod and pushrod all end on the upright: their six
    tensions are the one solution of the upright's 6×6 equilibrium with the load."""
    corner, statics, qs = rocker
    for q in qs:
        forces = statics.solve(q, case)
        corner.kin.update_positions(q)
        p = {n: corner.points[n].position(corner.kin).copy() for n in corner.points}
        A = np.zeros((6, 6))
        for i, (inboard, outboard) in enumerate(MEMBERS.values()):
            u = p[inboard] - p[outboard]  # a member in tension pulls the upright inboard
            u /= np.linalg.norm(u)
            A[:3, i], A[3:, i] = u, np.cross(p[outboard], u)
        cp, wc = p["contact_patch_center"], p["wheel_center"]
        load = np.r_[
            case.contact_patch + case.wheel_center,
            np.cross(cp, case.contact_patch) + np.cross(wc, case.wheel_center) + case.moment,
        ]
        tension = np.linalg.solve(A, -load)
        for (name, _), t in zip(MEMBERS.items(), tension, strict=True):
            assert forces[f"force_{name}"] == pytest.approx(t, rel=1e-9, abs=1e-6), name
        assert forces["loads_unbounded"] == 0.0


def test_virtual_work_of_a_member_lengthened_is_its_tension(rocker):
    """Lengthen one member by ±ε (every other closure rigid, the spring and the rack
    held) and re-solve: the load's work W·δx equals the member's tension × ε."""
    corner, statics, qs = rocker
    case = CASES[1]
    q0 = qs[2]
    forces = statics.solve(q0, case)
    Q = statics.generalized(q0, case)  # Σ J_pᵀ w_p at q0
    eps = 1e-6
    p = corner.points
    spring = DistanceClosure("spring", p["strut_top"], p["strut_bottom"], 0.0)
    corner.kin.update_positions(q0)
    for name in ("trackrod", "pushrod"):
        moved = []
        for sign in (1.0, -1.0):
            closures = [
                DistanceClosure(c.name, c.a, c.b, c.length + sign * eps) if c.name == name else c
                for c in corner.closures
            ]
            rack = JointTarget(corner.model, "rack_slide")
            rack.value = q0[rack.index_q]
            held = [_held(spring, corner, q0), rack]
            solver = NewtonSolver(corner.kin, closures, held)
            values = np.array([h.value for h in held])
            solution = solver.solve(q0, values, values)
            assert solution.converged
            moved.append(solution.q)
        dq = (moved[0] - moved[1]) / 2.0
        assert Q @ dq == pytest.approx(forces[f"force_{name}"] * eps, rel=1e-6), name


def _held(spring, corner, q):
    """The spring's length held at its value at q (a target row)."""

    class Length(Row):
        size, name = 1, "spring length"

        def __init__(self):
            corner.kin.update_positions(q)
            self.value = np.linalg.norm(
                spring.b.position(corner.kin) - spring.a.position(corner.kin)
            )

        def residual(self, kin):
            return np.array(
                [np.linalg.norm(spring.b.position(kin) - spring.a.position(kin)) - self.value]
            )

        def jacobian(self, kin):
            return spring.jacobian(kin)

    return Length()


def test_tree_joint_loads_equal_pinocchios_inverse_dynamics_at_rest(rocker):
    """Pinocchio's rnea (v = a = 0, no gravity) with the written member forces, ball
    loads, spring force and the case as external forces: every free joint carries no
    torque, the rack its force, and the force through the lower ball joint and each
    pivot is the written one."""
    import pinocchio as pin

    corner, statics, qs = rocker
    model, data = corner.model, corner.model.createData()
    model.gravity = pin.Motion.Zero()
    for q, case in zip(qs, CASES * 2, strict=False):
        f = statics.solve(q, case)
        corner.kin.update(q)
        p = {n: corner.points[n].position(corner.kin).copy() for n in corner.points}
        fext = [pin.Force.Zero() for _ in range(model.njoints)]

        def push(point, force, couple=None, on=None, fext=fext, p=p):
            """A force at a point's place, on the body of ``on`` (default: the point's)."""
            joint = model.frames[corner.points[on or point].frame_id].parentJoint
            if joint:
                moment = np.cross(p[point], force) + (0.0 if couple is None else couple)
                fext[joint] += corner.kin.data.oMi[joint].actInv(pin.Force(force, moment))

        for name, (inboard, outboard) in list(MEMBERS.items())[4:]:  # trackrod, pushrod
            u = (p[inboard] - p[outboard]) / np.linalg.norm(p[inboard] - p[outboard])
            push(outboard, f[f"force_{name}"] * u)
            push(inboard, -f[f"force_{name}"] * u)
        upper = np.array([f[f"load_upper_ball_joint_{a}"] for a in "xyz"])  # upright on arm
        push("upper_wishbone_outboard", upper)
        push("upper_wishbone_outboard", -upper, on="wheel_center")  # the arm on the upright
        u = p["strut_bottom"] - p["strut_top"]
        push("strut_bottom", f["force_spring"] * u / np.linalg.norm(u))
        r = p["contact_patch_center"] - p["wheel_center"]
        push("wheel_center", case.contact_patch + case.wheel_center,
             case.moment + np.cross(r, case.contact_patch))  # fmt: skip
        tau = pin.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv), fext)
        scale = np.abs(case.contact_patch).sum()
        for j in range(1, model.njoints):
            if model.names[j] == "rack_slide":
                assert tau[model.joints[j].idx_v] == pytest.approx(-f["force_rack"], rel=1e-9)
            else:
                assert abs(tau[model.joints[j].idx_v]) < 1e-9 * scale, model.names[j]

        def through(joint):  # the parent's force on the subtree, world axes
            i = model.getJointId(joint)
            return corner.kin.data.oMi[i].act(data.f[i])

        lbj = through("lower_ball_joint_x").linear
        np.testing.assert_allclose([f[f"load_lower_ball_joint_{a}"] for a in "xyz"], -lbj,
                                   atol=1e-9 * scale)  # fmt: skip
        for arm in ("lower_wishbone", "upper_wishbone"):
            bushings = sum(
                np.array([f[f"load_{arm}_{end}_bushing_{a}"] for a in "xyz"])
                for end in ("front", "rear")
            )
            np.testing.assert_allclose(bushings, -through(f"{arm}_pivot").linear, atol=1e-9 * scale)


def test_a_corner_without_a_spring_has_no_load_path():
    with pytest.raises(PinSuspError, match="spring.type: none"):
        Statics(pin_susp.Corner(EXAMPLES / "double_wishbone.yaml"))


@pytest.mark.parametrize(
    ("text", "key"),
    [
        (
            "cases: [{name: a, contact_patch: {fx: lots, fy: 0, fz: 0}}]",
            "cases[0].contact_patch.fx",
        ),
        ("cases: [{contact_patch: {fx: 1}}]", "cases[0].name"),
        ("cases: [{name: a, contact_patch: {fw: 1}}]", "cases[0].contact_patch.fw"),
        ("cases: [{name: a, left: {contact_patch: {fx: 1}}}]", "cases[0].left"),
        ("cases: [{name: a}, {name: a}]", "cases[1].name"),
        ("cases: []", "cases"),
        ("cases: [{name: a, torque: 3}]", "cases[0].torque"),
        (
            "cases: [{name: a, contact_patch: {fx: 0, fy: 0, fz: 1e300}}]",
            "cases[0].contact_patch.fz",
        ),
        ("cases: [{name: a, contact_patch: {fx: 0, fy: 0}}]", "cases[0].contact_patch.fz"),
        ("cases: [{name: ' '}]", "cases[0].name"),
        ("version: 2\ncases: [{name: a}]", "version"),
    ],
)
def test_bad_load_case_names_its_key(tmp_path, text, key):
    path = tmp_path / "loads.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        load_cases(path)
    assert info.value.key == key and info.value.source == str(path)


def test_load_cases_read_with_defaults(tmp_path):
    path = tmp_path / "loads.yaml"
    path.write_text(
        "version: 1\ncases:\n  - name: bump\n    contact_patch: {fx: 0, fy: 0, fz: 5000}\n"
    )
    (case,) = load_cases(path)
    assert case.name == "bump"
    np.testing.assert_array_equal(case.contact_patch, [0.0, 0.0, 5000.0])
    np.testing.assert_array_equal(case.wheel_center, np.zeros(3))


def _read(path):
    lines = [x for x in path.read_text().splitlines() if not x.startswith("#")]
    header = lines[0].split(",")
    return header, [r.split(",") for r in lines[1:]]


def test_loads_through_the_cli_a_row_per_step_and_case(tmp_path, capsys):
    from pin_susp.cli import main

    cases = tmp_path / "loads.yaml"
    cases.write_text(
        "version: 1\ncases:\n  - name: braking\n    contact_patch: {fx: -3000, fy: 0, fz: 2500}\n"
        "  - name: bump\n    contact_patch: {fx: 0, fy: 0, fz: 6000}\n"
    )
    out = tmp_path / "forces.csv"
    code = main(["loads", str(EXAMPLES / "pushrod_rocker.yaml"), str(EXAMPLES / "bump_steer.yaml"),
                 "--cases", str(cases), "-o", str(out)])  # fmt: skip
    assert code == 0
    header, rows = _read(out)
    assert header[:3] == ["step_index", "load_case", "loads_unbounded"]
    assert len(rows) == 2 * 41 and [r[1] for r in rows[:2]] == ["braking", "bump"]
    i = header.index("force_spring")
    assert all(float(r[i]) > 0 for r in rows)  # the spring holds the car up: compression
    assert "camber" in header and "wheel_center_z" in header  # the sweep's own columns
    assert "force_pushrod" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("geometry", "cases", "words"),
    [
        (
            "pushrod_rocker.yaml",
            "cases: [{name: a, contact_patch: {fx: lots, fy: 0, fz: 0}}]",
            "cases[0].contact_patch.fx",
        ),
        ("pushrod_rocker.yaml", "cases: [{name: a, left: {}}]", "cases[0].left"),
        ("pushrod_rocker.yaml", "cases: [{name: a, wheel: {}}]", "cases[0].wheel"),
        ("double_wishbone.yaml", "cases: [{name: a}]", "spring.type: none"),
    ],
)
def test_bad_loads_input_one_line_exit_2_nothing_written(tmp_path, capsys, geometry, cases, words):
    from pin_susp.cli import main

    path = tmp_path / "loads.yaml"
    path.write_text(cases)
    out = tmp_path / "forces.csv"
    code = main(["loads", str(EXAMPLES / geometry), str(EXAMPLES / "bump_steer.yaml"),
                 "--cases", str(path), "-o", str(out)])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and words in err, err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["loads.yaml"]


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_what_the_chassis_and_rack_give_balances_the_load(rocker, case):
    """The free body of everything but the chassis and the rack: the bushing loads
    (written as forces on the chassis), the spring's top and the trackrod's pull at
    the rack, with the load, sum to zero force and moment."""
    corner, statics, qs = rocker
    for q in qs:
        f = statics.solve(q, case)
        corner.kin.update_positions(q)
        p = {n: corner.points[n].position(corner.kin).copy() for n in corner.points}
        total = np.zeros(6)

        def add(at, force, total=total):
            total[:3] += force
            total[3:] += np.cross(at, force)

        for pickup in ("lower_wishbone_inboard_front", "lower_wishbone_inboard_rear",
                       "upper_wishbone_inboard_front", "upper_wishbone_inboard_rear",
                       "rocker_axis_a", "rocker_axis_b"):  # fmt: skip
            name = pickup.replace("inboard_", "").replace("axis_", "")
            add(p[pickup], -np.array([f[f"load_{name}_bushing_{a}"] for a in "xyz"]))
        top, bottom = p["strut_top"], p["strut_bottom"]
        add(top, f["force_spring"] * (bottom - top) / np.linalg.norm(bottom - top))
        inner, outer = p["trackrod_inboard"], p["trackrod_outboard"]
        add(inner, f["force_trackrod"] * (inner - outer) / np.linalg.norm(inner - outer))
        add(p["contact_patch_center"], case.contact_patch)
        add(p["wheel_center"], case.wheel_center)
        total[3:] += case.moment
        scale = np.abs(case.contact_patch).sum()
        np.testing.assert_allclose(total[:3], 0.0, atol=1e-9 * scale)
        np.testing.assert_allclose(total[3:], 0.0, atol=1e-9 * scale)


def test_a_member_at_its_toggle_is_unbounded_not_a_huge_number():
    """The coilover's line through the rocker's axis: its end moves square to it, so
    it cannot turn the rocker, and no finite force holds the wheel up."""
    import yaml

    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    hp = data["hardpoints"]
    point = {k: np.array([hp[k][a] for a in "xyz"], dtype=float) for k in hp}
    foot = point["rocker_axis_a"] + (point["rocker_axis_b"] - point["rocker_axis_a"]) * (
        (point["strut_bottom"] - point["rocker_axis_a"])
        @ (point["rocker_axis_b"] - point["rocker_axis_a"])
    ) / np.sum((point["rocker_axis_b"] - point["rocker_axis_a"]) ** 2)
    top = point["strut_bottom"] + 6.0 * (point["strut_bottom"] - foot)
    hp["strut_top"] = dict(zip("xyz", top.tolist(), strict=True))
    corner = pin_susp.Corner(data)
    (forces,) = Statics(corner).solve_cases(corner.q_design, CASES[:1])
    assert forces["loads_unbounded"] == 1.0
    assert all(np.isnan(v) for k, v in forces.items() if k != "loads_unbounded")
    hp["strut_top"]["z"] += 30.0  # off the toggle: finite again
    corner = pin_susp.Corner(data)
    moved = Statics(corner).solve(corner.q_design, CASES[0])
    assert moved["loads_unbounded"] == 0.0 and np.isfinite(moved["force_spring"])


def _with_rate(name):
    import yaml

    source = "pushrod_rocker" if name == "torsion_bar" else name
    data = yaml.safe_load((EXAMPLES / f"{source}.yaml").read_text())
    if name == "macpherson":
        data["config"]["strut"] = {"rate": 30.0, "preload": 3000.0}
    elif name == "torsion_bar":
        data["spring"] = {"type": "torsion_bar", "rate": 40.0, "preload": 100.0}
        for k in ("strut_top", "strut_bottom"):
            data["hardpoints"].pop(k)
    else:
        data["spring"] = {"type": "coilover", "rate": 60.0, "preload": 1500.0}
    data["config"]["wheel"]["tyre"] = {"rate": 250.0}
    return data


@pytest.mark.filterwarnings("ignore::pin_susp.errors.PlausibilityWarning")
@pytest.mark.parametrize(
    "name", ["pushrod_rocker", "torsion_bar", "macpherson", "fixed_toe_link", "semi_trailing_arm"]
)
def test_wheel_rate_is_the_rate_of_spring_force_times_motion_ratio(name):
    """wheel_rate = d(F·MR)/dz, both terms, against central differences of the written
    F and MR over wheel travel (each side a full solve); the ride rate is the wheel
    and tyre rates in series."""
    corner = pin_susp.Corner(_with_rate(name))
    rack = corner.geometry.steering == "rack"

    def run(z):
        targets = [Target("wheel_center", "z", [z])]
        if rack:
            targets.append(Target("trackrod_inboard", "y", [3.0]))
        return corner.run_sweep(Sweep(targets, "x"))

    torque = corner.geometry.spring == "torsion_bar"
    force = "spring_torque" if torque else "spring_force"
    unit = np.pi / 180.0 * 1e3 if torque else 1.0  # N·m·deg/mm² → N/mm
    h = 0.01
    for z in (-20.0, 25.0):
        at, up, down = run(z), run(z + h), run(z - h)
        fd = (up[force][0] * up["motion_ratio"][0] - down[force][0] * down["motion_ratio"][0]) / (
            2 * h
        )
        assert at["wheel_rate"][0] == pytest.approx(fd * unit, rel=1e-7)
        # and the rate is not just its first term: the force times the ratio's change
        first = corner.geometry.spring_rate * at["motion_ratio"][0] ** 2 * unit  # rate·MR²
        assert abs(at["wheel_rate"][0] - first) > 1e-3 * abs(first)
        series = 1.0 / (1.0 / at["wheel_rate"][0] + 1.0 / 250.0)
        assert at["ride_rate"][0] == pytest.approx(series, rel=1e-12)


def test_rate_columns_appear_only_with_a_rate():
    corner = pin_susp.Corner(EXAMPLES / "fixed_toe_link.yaml")  # a coilover, no rate
    results = corner.run_sweep(EXAMPLES / "bump.yaml")
    assert not {"wheel_rate", "spring_force", "ride_rate"} & set(results.columns)
    rated = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml").run_sweep(
        EXAMPLES / "bump_steer.yaml"
    )
    assert {"wheel_rate", "spring_force", "ride_rate"} <= set(rated.columns)


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (lambda d: d.update(spring={"type": "none", "rate": 50}), "spring.rate"),
        (lambda d: d.update(spring={"type": "coilover", "preload": 50}), "spring.preload"),
        (lambda d: d.update(spring={"type": "coilover", "rate": -5}), "spring.rate"),
        (lambda d: d["config"]["wheel"].update(tyre={"rate": "soft"}), "config.wheel.tyre.rate"),
        (
            lambda d: d["config"]["wheel"].update(tyre={"stiffness": 3}),
            "config.wheel.tyre.stiffness",
        ),
    ],
)
def test_bad_rates_name_their_key(change, key):
    import yaml

    from pin_susp.model.geometry import load_geometry

    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    change(data)
    with pytest.raises(InputError) as info:
        load_geometry(data)
    assert info.value.key == key


# ---------------------------------------------------------------- an axle


def _axle(bar: str):
    import yaml

    from pin_susp.subjects.axle import AxleModel, load_axle

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    config = data["axle_config"]
    config["spring"] = {"type": "coilover", "rate": 175.0, "preload": 2600.0}
    if bar == "none":
        config["anti_roll"] = {"type": "none"}
        data["hardpoints"].pop("center")
        for k in ("droplink_rocker", "droplink_u_bar"):
            data["hardpoints"]["left"].pop(k)
    else:
        config["anti_roll"]["stiffness"] = 40.0 if bar == "u_bar" else "rigid"
    return AxleModel(load_axle(data)), data


def _axle_case(left, right):
    from pin_susp.analyses.loads import AxleLoadCase

    zero = np.zeros(3)
    return AxleLoadCase("case", LoadCase("case", np.asarray(left, float), zero, zero),
                        LoadCase("case", np.asarray(right, float), zero, zero))  # fmt: skip


def test_an_axle_without_a_bar_is_its_two_corners_sharing_the_rack():
    """Each side's forces are its corner's under that wheel's load at the same pose
    (the right corner the mirrored one); the rack takes both trackrods' pull."""
    import yaml
    from conftest import mirrored

    model, data = _axle("none")
    heights, rack = {"left": 0.012, "right": -0.008}, 0.004
    z = {s: model.design_positions[f"{s}_wheel_center"][2] + heights[s] for s in heights}
    q = model.solve(z, rack).q
    case = _axle_case([-1500.0, -2500.0, 2200.0], [800.0, -900.0, 1100.0])
    forces = Statics(model).solve(q, case)
    corner_data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    rack_total = 0.0
    for side, drawn in (("left", corner_data), ("right", mirrored(corner_data))):
        corner = pin_susp.Corner(drawn)
        targets = [Target("wheel_center", "z", [heights[side] * 1e3]),
                   Target("trackrod_inboard", "y", [rack * 1e3])]  # fmt: skip
        (solution,) = corner.solve_steps(Sweep(targets, "x"))
        own = getattr(case, side)
        theirs = Statics(corner).solve(solution.q, own)
        for name, value in theirs.items():
            if name in ("force_rack", "loads_unbounded"):
                continue
            assert forces[f"{name}_{side}"] == pytest.approx(value, rel=1e-8, abs=1e-6), name
        rack_total += theirs["force_rack"]
    assert forces["force_rack"] == pytest.approx(rack_total, rel=1e-9)


def test_an_axles_bar_and_springs_share_by_stiffness():
    """Statically indeterminate: the springs' and the bar's deflections (force/rate)
    must be those of one motion of the axle — written from the sweep's own rates
    (damper length and bar twist per wheel height), not from the solver."""
    from pin_susp.subjects.axle import axle_results, solve_axle_sweep

    model, _ = _axle("u_bar")
    sweep = _sweep_of(ROLL)
    solutions = solve_axle_sweep(model, sweep)
    results = axle_results(model, sweep, solutions)
    statics = Statics(model)
    sides = ("left", "right")
    cases = (_axle_case([0, -2700, 1800], [0, -900, 600]), _axle_case([0, 0, 2000], [0, 0, 2000]))
    for i in (0, 3, 6):
        for case in cases:
            f = statics.solve(solutions[i].q, case)
            spring = [-f[f"force_spring_{s}"] / 175.0 for s in sides]  # shortened by F/k, mm
            twist = -f["torque_arb"] / (40.0 * 180 / np.pi)  # rad
            motion = [results[f"deriv_damper_length_wrt_hub_z_{s}"][i] for s in sides]
            rate = [np.radians(results[f"deriv_arb_twist_wrt_hub_z_{s}"][i]) for s in sides]
            span = np.array([[motion[0], 0.0, rate[0]], [0.0, motion[1], rate[1]]]).T
            deflection = np.array([*spring, twist])
            fit = span @ np.linalg.lstsq(span, deflection, rcond=None)[0]
            np.testing.assert_allclose(fit, deflection, rtol=1e-7, atol=1e-12)
        assert abs(statics.solve(solutions[i].q, cases[0])["torque_arb"]) > 1.0  # it works


def test_a_rigid_bar_compresses_both_springs_alike():
    """A locked bar on a mirrored axle in heave: the wheels move as one, so both
    springs deflect alike — the same force on each side, whichever wheel is loaded."""
    from pin_susp.subjects.axle import solve_axle_sweep

    model, _ = _axle("rigid")
    solutions = solve_axle_sweep(model, _sweep_of(HEAVE))
    statics = Statics(model)
    for solution in solutions:
        f = statics.solve(solution.q, _axle_case([0, -2700, 1800], [0, -900, 600]))
        assert f["force_spring_left"] == pytest.approx(f["force_spring_right"], rel=1e-9)


RACK_HELD = {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"}, "start": 0,
             "stop": 0}  # fmt: skip
ROLL = [{"quantity": "roll", "start": -2, "stop": 2}, {"quantity": "heave", "start": 5, "stop": 5}]
HEAVE = [{"quantity": "heave", "start": -15, "stop": 15}]


def _sweep_of(targets):
    from pin_susp.model.sweep import load_sweep

    return load_sweep({"steps": 7, "targets": [*targets, RACK_HELD]})


def test_a_bar_without_rates_says_what_it_needs():
    import yaml

    from pin_susp.subjects.axle import AxleModel, load_axle

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    with pytest.raises(PinSuspError, match="share the load by their stiffnesses"):
        Statics(AxleModel(load_axle(data)))


def test_roll_stiffness_is_the_second_derivative_of_the_stored_energy():
    """At design (no preload), roll_stiffness = d²E/dφ² with E = Σ ½k·Δℓ² + ½k_bar·θ²
    read from a fine roll sweep's damper lengths and bar twist (central differences);
    arb_wheel_rate is the bar's share at each wheel: ½·k_bar·(dθ/dh)²."""
    import yaml

    from pin_susp.model.sweep import load_sweep
    from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    data["axle_config"]["spring"] = {"type": "coilover", "rate": 175.0}
    data["axle_config"]["anti_roll"]["stiffness"] = 40.0
    model = AxleModel(load_axle(data))
    h = 0.02  # deg
    sweep = load_sweep({"targets": [
        {"quantity": "roll", "values": [-h, 0.0, h]},
        {"quantity": "heave", "values": [0.0, 0.0, 0.0]},
        {k: v for k, v in RACK_HELD.items() if k not in ("start", "stop")} | {"values": [0, 0, 0]},
    ]})  # fmt: skip
    r = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    energy = 0.5 * 40.0 * 180 / np.pi * np.radians(r["arb_twist"]) ** 2  # N·m
    for s in ("left", "right"):
        energy += 0.5 * 175e3 * ((r[f"damper_length_{s}"] - r[f"damper_length_{s}"][1]) * 1e-3) ** 2
    # the moment is dE/dφ per radian: N·m/deg = d²E/dφ_deg² · 180/π
    second = (energy[0] - 2 * energy[1] + energy[2]) / h**2 * 180 / np.pi
    assert r["roll_stiffness"][1] == pytest.approx(second, rel=1e-5)
    # the bar's share per wheel, from the sweep's twist rates: ½ k (dθ/dz_L − dθ/dz_R)²
    rate = np.radians(
        r["deriv_arb_twist_wrt_hub_z_left"][1] - r["deriv_arb_twist_wrt_hub_z_right"][1]
    )
    assert r["arb_wheel_rate"][1] == pytest.approx(
        0.5 * 40.0 * 180 / np.pi * rate**2 * 1e3, rel=1e-9
    )


def test_loads_of_an_axle_through_the_cli(tmp_path, capsys):
    import yaml

    from pin_susp.cli import main

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    geometry = tmp_path / "axle.yaml"
    cases = tmp_path / "cases.yaml"
    cases.write_text(
        "cases:\n  - name: turn\n    left: {contact_patch: {fx: 0, fy: -2700, fz: 1800}}\n"
        "    right: {contact_patch: {fx: 0, fy: -900, fz: 600}}\n"
    )
    out = tmp_path / "forces.csv"
    args = ["loads", str(geometry), str(EXAMPLES / "heave_roll.yaml"), "--cases", str(cases)]
    geometry.write_text(yaml.safe_dump(data))  # a bar without its stiffness: refused
    assert main([*args, "-o", str(out)]) == 2
    assert "stiffnesses" in capsys.readouterr().err and not out.exists()
    data["axle_config"]["spring"] = {"type": "coilover", "rate": 175.0}
    data["axle_config"]["anti_roll"]["stiffness"] = 40.0
    geometry.write_text(yaml.safe_dump(data))
    assert main([*args, "-o", str(out), "-q"]) == 0
    header, rows = _read(out)
    for name in ("force_spring_left", "force_spring_right", "torque_arb", "force_droplink_left",
                 "force_rack", "load_lower_ball_joint_x_right", "roll_stiffness"):  # fmt: skip
        assert name in header, name
    assert len(rows) == 31
    cases.write_text(
        "cases: [{name: flat, contact_patch: {fx: 0, fy: 0, fz: 1}}]\n"
    )  # no side blocks
    assert main([*args, "-o", str(out)]) == 2
    assert "left: and right:" in capsys.readouterr().err


def test_a_plain_wishbones_bushings_take_their_legs_pull(rocker):
    """An arm loaded at its ball joint alone: each bush carries its leg's tension along
    the leg (pickup → ball), the leg forces and the bush loads in one row agreeing."""
    corner, statics, qs = rocker
    f = statics.solve(qs[0], CASES[0])
    corner.kin.update_positions(qs[0])
    for arm in ("lower_wishbone", "upper_wishbone"):
        ball = corner.points[f"{arm}_outboard"].position(corner.kin)
        for end in ("front", "rear"):
            pickup = corner.design_positions[f"{arm}_inboard_{end}"]
            u = (ball - pickup) / np.linalg.norm(ball - pickup)
            load = np.array([f[f"load_{arm}_{end}_bushing_{a}"] for a in "xyz"])
            np.testing.assert_allclose(load, f[f"force_{arm}_{end}"] * u, atol=1e-9 * 5000)


def test_a_torsion_bars_torque_resists_bump_whichever_way_its_axis_is_written():
    import yaml

    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    data["spring"] = {"type": "torsion_bar", "rate": 20.0, "preload": 150.0}
    for k in ("strut_top", "strut_bottom"):
        data["hardpoints"].pop(k)
    bump = LoadCase("bump", np.array([0.0, 0.0, 2100.0]), np.zeros(3), np.zeros(3))
    torques = []
    for swap in (False, True):
        if swap:
            hp = data["hardpoints"]
            hp["rocker_axis_a"], hp["rocker_axis_b"] = hp["rocker_axis_b"], hp["rocker_axis_a"]
        corner = pin_susp.Corner(data)
        torques.append(Statics(corner).solve(corner.q_design, bump)["torque_spring"])
    assert torques[0] > 0.0  # a bump load winds the bar: it resists, + as the sweep's
    assert torques[1] == pytest.approx(torques[0], rel=1e-9)


def test_each_side_of_an_axle_has_its_corners_rates():
    """An axle with rated springs writes each side's spring force and wheel and ride
    rates: its corner's, at that side's wheel height and the rack (the corner's own
    rates are checked against central differences above)."""
    import yaml
    from conftest import mirrored

    from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    data["axle_config"]["spring"] = {"type": "coilover", "rate": 175.0, "preload": 2600.0}
    data["axle_config"]["wheel"]["tyre"] = {"rate": 120.0}
    data["axle_config"]["anti_roll"]["stiffness"] = 40.0
    model = AxleModel(load_axle(data))
    sweep = _sweep_of(ROLL)
    r = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    corner_data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    for side, drawn in (("left", corner_data), ("right", mirrored(corner_data))):
        corner = pin_susp.Corner(drawn)
        design = corner.design_positions["wheel_center"][2] * 1e3
        heights = r[f"{side}_wheel_center_z"] - design
        targets = [Target("wheel_center", "z", heights), Target("trackrod_inboard", "y", [0] * 7)]
        own = corner.run_sweep(Sweep(targets, "x"))
        for name in ("spring_force", "wheel_rate", "ride_rate"):
            np.testing.assert_allclose(r[f"{name}_{side}"], own[name], rtol=1e-9, err_msg=name)


def test_a_spring_below_zero_force_is_warned_of(tmp_path, capsys):
    """With too little preload for the droop, the rated spring's force goes negative:
    the sweep says at which steps (a coilover would unseat there)."""
    import yaml

    from pin_susp.cli import main

    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    data["spring"]["preload"] = 1000.0
    geometry = tmp_path / "corner.yaml"
    geometry.write_text(yaml.safe_dump(data))
    out = tmp_path / "out.csv"
    assert main(["sweep", str(geometry), str(EXAMPLES / "bump_steer.yaml"), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "spring force below zero at steps 0," in err
    header, rows = _read(out)
    force = [float(r[header.index("spring_force")]) for r in rows]
    assert force[0] < 0.0 < force[-1]


def test_a_load_case_file_is_read_by_the_subjects_labels(tmp_path):
    """``load_cases(path, labels=subject.labels)``: a corner's loads at each case's top
    (labels ``""``), an axle's in a block per labelled corner — as ``axle=`` reads them."""
    from pin_susp.analyses.loads import AxleLoadCase

    corner = load_cases(EXAMPLES / "loads.yaml", labels=("",))
    flat = load_cases(EXAMPLES / "loads.yaml")
    assert [c.name for c in corner] == [c.name for c in flat]
    for a, b in zip(corner, flat, strict=True):
        assert all(list(getattr(a, k)) == list(getattr(b, k)) for k in ("contact_patch", "moment"))
    assert all(c.wheel("") is c for c in corner)
    path = tmp_path / "axle_loads.yaml"
    path.write_text(
        "cases:\n  - name: bump\n    left: {contact_patch: {fx: 0, fy: 0, fz: 3000}}\n"
        "    right: {moment: {mx: 5, my: 0, mz: 0}}\n"
    )
    (case,) = load_cases(path, labels=("left", "right"))
    (same,) = load_cases(path, axle=True)
    assert isinstance(case, AxleLoadCase) and case.name == same.name == "bump"
    for label in ("left", "right"):
        for part in ("contact_patch", "wheel_center", "moment"):
            assert list(getattr(case.wheel(label), part)) == list(getattr(same.wheel(label), part))
    assert list(case.wheel("left").contact_patch) == [0.0, 0.0, 3000.0]
    assert list(case.wheel("right").moment) == [5.0, 0.0, 0.0]
