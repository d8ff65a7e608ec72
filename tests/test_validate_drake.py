"""`pin-susp validate --engine drake` (and `--engine all`): the exported URDF parsed by
Drake's own parser into a MultibodyPlant, its loop closures and the sweep's targets as
constraints of Drake's InverseKinematics, every step solved by IPOPT from the design
configuration, every column compared with pin_susp's; and the forward kinematics of
every committed URDF in Drake, Pinocchio and yourdfpy at a solved pose.
"""

import logging
import os
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml
import yourdfpy
from conftest import EXAMPLES, ROOT, example
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JointIndex

import pin_susp
from pin_susp.cli import main
from pin_susp.errors import PinSuspError
from pin_susp.model.mjcf import tree_to_mjcf
from pin_susp.model.urdf import read_closures
from pin_susp.solve.rates import RATE_COLUMNS
from pin_susp.subjects.axle import AxleModel, load_axle
from pin_susp.validate import (
    CornerScope,
    DrakeCorner,
    drake_points,
    pointwise_points,
    quiet_drake,
    validate,
)

SOLVER = {"step_index", "solver_converged", "solver_max_residual", "solver_iterations"}


def _yaml(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def every_example() -> list[tuple[str, str]]:
    """Every example geometry (a corner, an axle, a vehicle) with every example sweep it
    can run: the sweeps whose targets it takes (pin_susp refuses the others — a corner
    an axle's, an axle a vehicle's)."""
    from pin_susp.subjects.subject import load_subject

    sweeps = sorted(p for p in EXAMPLES.glob("*.yaml") if "targets" in _yaml(p))
    pairs = []
    for geometry in sorted(EXAMPLES.glob("*.yaml")):
        data = _yaml(geometry)
        if "hardpoints" not in data and data.get("scope") not in ("axle", "vehicle"):
            continue
        subject = load_subject(geometry, warn=False)
        for path in sweeps:
            try:
                subject.solver_for(pin_susp.load_sweep(path).targets)
            except PinSuspError:
                continue
            pairs.append((geometry.name, path.name))
    return pairs


EVERY = every_example()
# `make drake` runs every pair (PIN_SUSP_DRAKE_ALL=1); `make test` a slice: a corner with
# a rack, a fixed toe link, the axle in roll and the FS car in roll (each mechanism's
# columns are checked on short sweeps below, both cars' in tests/test_vehicle_robotics.py)
SLICE = {
    ("double_wishbone.yaml", "bump_steer.yaml"),
    ("fixed_toe_link.yaml", "bump.yaml"),
    ("axle_front.yaml", "roll.yaml"),
    ("vehicle_fs.yaml", "vehicle_roll.yaml"),
}
RUN = EVERY if os.environ.get("PIN_SUSP_DRAKE_ALL") else [p for p in EVERY if p in SLICE]


def test_every_example_geometry_is_validated():
    """The list above is not empty by accident: each mechanism, the axle, each sweep."""
    geometries = {g for g, _ in EVERY}
    assert {
        "double_wishbone.yaml",
        "pushrod_rocker.yaml",
        "camber_shim.yaml",
        "fixed_toe_link.yaml",
        "macpherson.yaml",
        "multilink_front.yaml",
        "multilink_rear.yaml",
        "semi_trailing_arm.yaml",
        "axle_front.yaml",
        "vehicle_fs.yaml",
        "vehicle_saloon.yaml",
    } <= geometries
    assert {s for _, s in EVERY} >= {
        "bump.yaml",
        "bump_steer.yaml",
        "bump_rack_held.yaml",
        "roll.yaml",
        "heave_roll.yaml",
    } | {f"vehicle_{s}.yaml" for s in ("heave", "pitch", "roll", "warp", "steer", "combined")}
    cars = {(g, s) for g, s in EVERY if g.startswith("vehicle_")}
    assert len(cars) == 12 and all(s.startswith("vehicle_") for _, s in cars)


@pytest.mark.parametrize(("geometry", "sweep"), RUN, ids=[f"{g[:-5]}-{s[:-5]}" for g, s in RUN])
def test_validate_engine_drake_agrees_on_every_example(geometry, sweep, capsys):
    """Every step of the full sweep, every column within 1e-6 mm/deg (the instant
    centres within 1e-9 of their size); exit 0."""
    code = main(["validate", str(EXAMPLES / geometry), str(EXAMPLES / sweep), "--engine", "drake"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "drake: agrees within 1e-06" in out and "pointwise: agrees within 1e-06" in out
    assert "mujoco" not in out and "skipped" not in out and "warnings" not in out


# -- one example of each mechanism, a short sweep, column by column ---------------------


def short_sweep(corner, steps: int = 7) -> pin_susp.Sweep:
    """Bump from 35 mm droop to 45 mm bump, with the rack from -9 to +7 mm where there
    is one (both drivers move at every step)."""
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "start": -35, "stop": 45}]
    if corner.geometry.steering == "rack":
        inner = corner.geometry.steering_points[0]
        targets.append({"point": inner, "direction": {"axis": "y"}, "start": -9, "stop": 7})
    return pin_susp.load_sweep({"version": 1, "steps": steps, "targets": targets})


MECHANISMS = [
    "double_wishbone.yaml",
    "pushrod_rocker.yaml",
    "fixed_toe_link.yaml",
    "macpherson.yaml",
    "multilink_front.yaml",
    "multilink_rear.yaml",
    "semi_trailing_arm.yaml",
]


@pytest.mark.parametrize("geometry", MECHANISMS, ids=[g[:-5] for g in MECHANISMS])
def test_drake_compares_every_column_of_each_mechanism(geometry):
    """Every column pin_susp writes is compared (a fixed toe link's steer screw axis
    too: Drake changes a distance closure's length, which MuJoCo's rigid rod cannot),
    the points within 1e-9 mm, every other column within 1e-6 mm/deg."""
    corner = pin_susp.Corner(EXAMPLES / geometry)
    sweep = short_sweep(corner)
    results, (report,) = validate(corner, sweep, engines=("drake",))
    assert report.agrees, (report.note, report.failed_steps, report.disagree)
    assert report.warnings == 0 and not report.not_compared and not report.failed_steps
    written = {c for c in results.columns if c not in SOLVER and not np.isnan(results[c]).all()}
    points = {f"{p}_{a}" for p in corner.point_names for a in "xyz"}
    # the spring's force and rates need the second derivative along bump: no engine
    # compares them (MuJoCo's and the point-based solver's reports leave them out too)
    assert set(report.differences) == written - points - RATE_COLUMNS | {"points"}
    assert report.differences["points"] <= 1e-9
    centres = ("vic_", "vsa_length", "instant_center")  # far poles: relative (scopes.size)
    for name, difference in report.differences.items():
        if not any(c in name for c in centres):
            assert difference <= 1e-6, name
    if corner.geometry.steering == "none" and corner.geometry.steering_points:
        # the steer screw axis of a fixed toe link: along its length (MuJoCo: not compared)
        assert {"isa_caster", "isa_kpi", "isa_pitch"} <= set(report.differences)


def axle_sweep() -> pin_susp.Sweep:
    """Each wheel centre at its own height while the rack moves: bump, rebound, roll and
    steer at once."""

    def target(side, point, axis, values):
        return {"point": point, "side": side, "direction": {"axis": axis}, "values": values}

    return pin_susp.load_sweep(
        {
            "targets": [
                target("left", "wheel_center", "z", [-30.0, 0.0, 25.0, 40.0, 10.0]),
                target("right", "wheel_center", "z", [20.0, -10.0, 0.0, -35.0, 30.0]),
                target("left", "trackrod_inboard", "y", [-10.0, 5.0, 0.0, 12.0, -4.0]),
            ]
        }
    )


@pytest.mark.parametrize(
    "geometry",
    [EXAMPLES / "axle_front.yaml", ROOT / "tests" / "data" / "axle_t_bar.yaml"],
    ids=["u_bar", "t_bar"],
)
def test_drake_compares_every_axle_column(geometry):
    """An axle on independent wheel heights and the rack: every column of both sides,
    the axle's and the bar's, compared and within tolerance."""
    model = AxleModel(load_axle(geometry))
    results, (report,) = validate(model, axle_sweep(), engines=("drake",))
    assert report.agrees, (report.note, report.failed_steps, report.disagree)
    written = {c for c in results.columns if c not in SOLVER and not np.isnan(results[c]).all()}
    points = {f"{p}_{a}" for p in model.output_points for a in "xyz"}
    assert set(report.differences) == written - points | {"points"}
    assert report.differences["points"] <= 1e-9
    assert np.ptp(results["arb_twist"]) > 1.0  # the bar is wound: its droplinks worked


def test_drake_points_are_pin_susps_and_the_pointwise_solvers():
    """Drake's solved points against pin_susp's CSV columns and the point-based
    formulation's, step by step (an independent check of the comparison itself)."""
    corner = pin_susp.Corner(EXAMPLES / "macpherson.yaml")
    sweep = short_sweep(corner, steps=5)
    results = corner.run_sweep(sweep)
    theirs = drake_points(corner, sweep)
    reference = pointwise_points(corner, sweep)
    for i in range(sweep.steps):
        for name in corner.point_names:
            ours = [results[f"{name}_{a}"][i] for a in "xyz"]
            drake = theirs[i][name].val[0] * 1e3
            np.testing.assert_allclose(drake, ours, rtol=0, atol=1e-9, err_msg=name)
            np.testing.assert_allclose(drake, reference[i][name].val[0] * 1e3, rtol=0, atol=1e-9)
    # along hub z the wheel centre moves 1 in z, along the rack not in z: the held rows
    rates = theirs[2]["wheel_center"].der[:, 0]  # driver × xyz
    np.testing.assert_allclose(rates[0, 2], 1.0, atol=1e-12)
    np.testing.assert_allclose(rates[1, 2], 0.0, atol=1e-12)


# -- a URDF given with --urdf -----------------------------------------------------------


def write_sweep(tmp_path, steps: int = 5) -> Path:
    sweep = example("bump_steer.yaml")
    sweep["steps"] = steps
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(sweep))
    return path


def exported_urdf(tmp_path, geometry: str = "double_wishbone.yaml") -> Path:
    out = tmp_path / f"{geometry[:-5]}.urdf"
    assert main(["urdf", str(EXAMPLES / geometry), "-o", str(out)]) == 0
    return out


def test_validate_drake_fails_when_a_hardpoint_moved_after_export(tmp_path, capsys):
    exported = exported_urdf(tmp_path)
    moved = example("double_wishbone.yaml")
    moved["hardpoints"]["upper_wishbone_outboard"]["z"] += 2.0
    path = tmp_path / "moved.yaml"
    path.write_text(yaml.safe_dump(moved))
    sweep = write_sweep(tmp_path)
    capsys.readouterr()
    code = main(["validate", str(path), str(sweep), "--engine", "drake", "--urdf", str(exported)])
    out = capsys.readouterr().out
    assert code == 1
    assert "drake: DISAGREES" in out and "camber" in out.split("drake: DISAGREES")[1]
    assert "pointwise: agrees" in out
    # the same file against the geometry it was written from agrees
    code = main(
        [
            "validate",
            str(EXAMPLES / "double_wishbone.yaml"),
            str(sweep),
            "--engine",
            "drake",
            "--urdf",
            str(exported),
        ]
    )
    assert code == 0 and "drake: agrees within 1e-06" in capsys.readouterr().out


def test_moved_hardpoint_shows_in_the_columns_by_its_size():
    """2 mm of upper ball joint after the export: Drake solves the old corner, so its
    camber 30 mm up is the old corner's as pin_susp solves it, and the report's
    difference is what the move does to the camber there."""
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    moved = example("double_wishbone.yaml")
    moved["hardpoints"]["upper_wishbone_outboard"]["z"] += 2.0
    sweep = pin_susp.load_sweep(design_sweep("trackrod_inboard", z=30.0))
    results, (report,) = validate(
        pin_susp.Corner(moved), sweep, engines=("drake",), urdf_text=corner.urdf
    )
    old = corner.run_sweep(sweep)
    for name in ("camber", "caster", "kpi"):
        expected = abs(results[name][0] - old[name][0])
        assert expected > 0.01 and name in report.disagree
        assert report.differences[name] == pytest.approx(expected, abs=1e-9)


def design_sweep(rack: str | None, z: float = 0.0, y: float = 0.0) -> dict:
    """One step: the wheel centre z mm above design, the rack y mm (where ``rack``
    names its inner point)."""
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "values": [z]}]
    if rack is not None:
        targets.append({"point": rack, "direction": {"axis": "y"}, "values": [y]})
    return {"targets": [dict(t, mode="relative") for t in targets]}


def one_error_line(capsys, argv) -> str:
    """Run the CLI: exit code 2, nothing on stdout, exactly one line on stderr."""
    capsys.readouterr()
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    return err


def test_urdf_of_another_geometry_is_refused(tmp_path, capsys):
    exported = exported_urdf(tmp_path, "pushrod_rocker.yaml")
    err = one_error_line(
        capsys,
        [
            "validate",
            str(EXAMPLES / "double_wishbone.yaml"),
            str(write_sweep(tmp_path)),
            "--engine",
            "all",
            "--urdf",
            str(exported),
        ],
    )
    assert err.startswith(f"pin-susp: error: {exported}: is not the URDF of this geometry")
    assert "has a link rocker this model does not have" in err


def test_urdf_option_is_for_drake_and_mjcf_for_mujoco(tmp_path, capsys):
    sweep = str(write_sweep(tmp_path))
    geometry = str(EXAMPLES / "double_wishbone.yaml")
    err = one_error_line(capsys, ["validate", geometry, sweep, "--urdf", "x.urdf"])
    assert err == (
        "pin-susp: error: --urdf: only drake reads it; add --engine drake (or --engine all)\n"
    )
    err = one_error_line(
        capsys, ["validate", geometry, sweep, "--engine", "drake", "--mjcf", "x.xml"]
    )
    assert "--mjcf: only mujoco reads it" in err
    err = one_error_line(
        capsys, ["validate", geometry, sweep, "--engine", "drake", "--urdf", "missing.urdf"]
    )
    assert err == "pin-susp: error: missing.urdf: cannot be read (No such file or directory)\n"
    (tmp_path / "binary.urdf").write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    err = one_error_line(
        capsys, ["validate", geometry, sweep, "--engine", "drake", "--urdf", "binary.urdf"]
    )
    assert err == "pin-susp: error: binary.urdf: not a text file (URDF is XML)\n"


@pytest.fixture(scope="module")
def dw():
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    return corner, short_sweep(corner, steps=3)


def urdf_error(dw, text) -> str:
    corner, sweep = dw
    with pytest.raises(PinSuspError) as info:
        validate(corner, sweep, engines=("drake",), urdf_text=text, urdf_source="c.urdf")
    assert "\n" not in str(info.value)
    return str(info.value)


def test_urdf_that_is_not_this_geometrys(dw):
    corner, _ = dw
    assert urdf_error(dw, " \n") == "c.urdf: is empty: expected the URDF written by pin-susp urdf"
    assert urdf_error(dw, corner.urdf[:-30]).startswith("c.urdf: is not valid XML (")
    assert urdf_error(dw, tree_to_mjcf(corner.tree)).startswith(
        "c.urdf: is not URDF (an MJCF?): its root element is <mujoco>, not <robot>"
    )
    weld = corner.urdf.replace('name="trackrod" type="distance"', 'name="trackrod" type="ball"')
    assert "loop closure trackrod is ball between trackrod_inboard trackrod_outboard, " in (
        urdf_error(dw, weld)
    )
    slide = corner.urdf.replace(
        '<joint name="lower_wishbone_pivot" type="revolute"',
        '<joint name="lower_wishbone_pivot" type="prismatic"',
    )
    assert "joint lower_wishbone_pivot is prismatic from chassis" in urdf_error(dw, slide)


def test_urdf_drake_cannot_load_or_solve(dw):
    corner, _ = dw
    text = corner.urdf
    start = text.index('<joint name="lower_wishbone_pivot"')
    axis = text.index("<axis xyz=", start)
    end = text.index("/>", axis)
    zero = text[:axis] + '<axis xyz="0 0 0" ' + text[end:]
    assert urdf_error(dw, zero).startswith("c.urdf: Drake cannot load it: line ")
    assert "axis is zero" in urdf_error(dw, zero)
    # a frame a million km out: refused before IPOPT overflows on it (Drake would
    # abort the whole process on a non-finite iterate)
    origin = text.index('<origin xyz="', text.index('<joint name="upright_to_wheel_center"'))
    end = text.index('"', origin + len('<origin xyz="'))
    far = text[:origin] + '<origin xyz="1e200 0 0' + text[end:]
    assert urdf_error(dw, far) == (
        "c.urdf: frame wheel_center is 1e+200 m from the origin at the design state: "
        "not a suspension"
    )


def test_drake_warnings_are_counted_not_printed(dw, capfd):
    """A joint with friction: Drake's parser warns (the exported URDF gives none)."""
    corner, sweep = dw
    text = corner.urdf.replace(
        '<joint name="lower_wishbone_pivot" type="revolute">',
        '<joint name="lower_wishbone_pivot" type="revolute"><dynamics friction="3"/>',
    )
    logger = logging.getLogger("drake")
    before = logger.handlers[:], logger.propagate
    _, (report,) = validate(corner, sweep, engines=("drake",), urdf_text=text)
    assert report.agrees and report.warnings == 1 and "friction" in report.first_warning
    assert (logger.handlers, logger.propagate) == before
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    _, (report,) = validate(corner, sweep, engines=("drake",))
    assert report.agrees and report.warnings == 0  # the pin_susp: elements are quiet


def test_unknown_engine(dw):
    corner, sweep = dw
    with pytest.raises(PinSuspError, match="unknown engine 'bullet': expected one of"):
        validate(corner, sweep, engines=("bullet",))


# -- --engine all, and without Drake ----------------------------------------------------


# every engine on the fixed-toe-link corner's bump sweep
ALL_ENGINES = [
    "validate",
    str(EXAMPLES / "fixed_toe_link.yaml"),
    str(EXAMPLES / "bump.yaml"),
    "--engine",
    "all",
]


def test_engine_all_runs_the_three_engines(tmp_path, capsys):
    code = main(ALL_ENGINES)
    out = capsys.readouterr().out
    assert code == 0
    header = out.splitlines()[1].split()
    assert header[-3:] == ["pointwise", "mujoco", "drake"]
    for engine in ("pointwise", "mujoco", "drake"):
        assert f"{engine}: agrees within 1e-06" in out
    # MuJoCo's rigid toe link cannot give the rates along its length; Drake's can
    assert "mujoco: isa_caster, isa_kpi, isa_pitch not compared" in out
    assert "drake: " in out and "drake: isa" not in out
    row = next(line for line in out.splitlines() if line.strip().startswith("isa_kpi "))
    pointwise, mujoco, drake = row.split()[2:]
    assert mujoco == "-" and float(pointwise) < 1e-6 and float(drake) < 1e-6


def test_without_drake_says_how_to_install_and_runs_the_rest(monkeypatch, capsys):
    for name in [n for n in sys.modules if n == "pydrake" or n.startswith("pydrake.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "pydrake", None)
    code = main(ALL_ENGINES)
    out = capsys.readouterr().out
    assert code == 0
    assert (
        "drake: skipped — Drake is not installed: pip install 'pin_susp[validate]' "
        "(or pip install drake)" in out
    )
    assert "pointwise: agrees within 1e-06" in out and "mujoco: agrees within 1e-06" in out


# -- forward kinematics of every committed URDF -----------------------------------------


COMMITTED = sorted(p.stem for p in (ROOT / "urdf").glob("*.urdf"))


def drake_plant(text: str):
    plant = MultibodyPlant(0.0)
    with quiet_drake() as counter:
        Parser(plant).AddModelsFromString(text, "urdf")
    assert counter.count == 0
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("chassis"))
    plant.Finalize()
    return plant


@pytest.mark.parametrize("name", COMMITTED)
def test_forward_kinematics_of_drake_pinocchio_and_yourdfpy_agree(name):
    """At a pose Drake's IK solved from the committed file (wheel centre 25 mm up, the
    rack 6 mm where there is one), every link of the file is within 1e-12 m in
    Drake, Pinocchio and yourdfpy, the joint values set by name in each."""
    path = ROOT / "urdf" / f"{name}.urdf"
    text = path.read_text()
    corner = pin_susp.Corner(EXAMPLES / f"{name}.yaml")
    g = corner.geometry
    rack = g.steering_points[0] if g.steering == "rack" else None
    sweep = pin_susp.load_sweep(design_sweep(rack, z=25.0, y=6.0))
    scope = CornerScope(corner)
    (targets,) = scope.step_targets(sweep)
    with quiet_drake():
        engine = DrakeCorner(text, scope, str(path))
        assert engine.solve(targets) is not None
    plant, context = engine.plant, engine.context
    joints = {}
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        if joint.num_positions() == 1:
            joints[joint.name()] = float(plant.GetPositions(context)[joint.position_start()])
    assert max(map(abs, joints.values())) > 0.01  # not the design pose
    # the pose closes every loop in Drake's own forward kinematics
    assert np.max(np.abs(engine._closure_residuals()), initial=0.0) < 1e-12

    # Drake, again, from a plant of its own with the joint values set by name
    fresh = drake_plant(text)
    ctx = fresh.CreateDefaultContext()
    q = np.zeros(fresh.num_positions())
    for joint_name, value in joints.items():
        q[fresh.GetJointByName(joint_name).position_start()] = value
    fresh.SetPositions(ctx, q)
    model = pin.buildModelFromXML(text)
    data = model.createData()
    q_pin = pin.neutral(model)
    for j in range(1, model.njoints):
        q_pin[model.joints[j].idx_q] = joints[model.names[j]]
    pin.framesForwardKinematics(model, data, q_pin)
    robot = yourdfpy.URDF.load(str(path), load_meshes=False)
    assert set(robot.actuated_joint_names) == set(joints)
    robot.update_cfg({j: joints[j] for j in robot.actuated_joint_names})
    links = [link.name for link in robot.robot.links]
    assert len(links) >= 12
    for link in links:
        drake = fresh.GetFrameByName(link).CalcPoseInWorld(ctx).translation()
        pinocchio = data.oMf[model.getFrameId(link)].translation
        urdfpy = robot.get_transform(link, "chassis")[:3, 3]
        np.testing.assert_allclose(drake, pinocchio, rtol=0, atol=1e-12, err_msg=link)
        np.testing.assert_allclose(drake, urdfpy, rtol=0, atol=1e-12, err_msg=link)
    # and the loop closures read back from the file hold in Pinocchio's frames too
    for spec in read_closures(text):
        (a, pa), (b, pb) = spec.anchors
        wa = data.oMf[model.getFrameId(a)].act(pa)
        wb = data.oMf[model.getFrameId(b)].act(pb)
        if spec.kind == "ball":
            assert np.linalg.norm(wa - wb) < 1e-12
