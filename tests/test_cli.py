"""The command line as a user meets it: results files, and one clear line for bad input."""

import copy
import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, sweep_csv

import pin_susp
from pin_susp.cli import main


def write(path: Path, data) -> Path:
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def test_sweep_writes_the_spec_columns(tmp_path):
    out = sweep_csv(tmp_path, "double_wishbone.yaml", "bump_steer.yaml")
    lines = out.read_text().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    assert comments[0].startswith("# pin_susp ")
    assert any("sha256=" in line for line in comments)
    header = lines[len(comments)].split(",")
    assert header[:12] == [
        "step_index",
        "solver_converged",
        "solver_max_residual",
        "solver_iterations",
        "camber",
        "caster",
        "kpi",
        "roadwheel_angle",
        "scrub_radius",
        "mechanical_trail",
        "wheel_travel",
        "half_track",
    ]
    assert header[-3:] == [
        "contact_patch_center_x",
        "contact_patch_center_y",
        "contact_patch_center_z",
    ]
    rows = list(csv.DictReader(lines[len(comments) :]))
    assert len(rows) == 41 and {r["solver_converged"] for r in rows} == {"True"}
    assert float(rows[0]["wheel_travel"]) == pytest.approx(-40.0, abs=1e-12)
    assert float(rows[-1]["wheel_travel"]) == pytest.approx(60.0, abs=1e-12)
    # full precision: the text reads back to the very float the solver produced
    results = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").run_sweep(
        EXAMPLES / "bump_steer.yaml"
    )
    assert [float(r["camber"]) for r in rows] == list(results["camber"])
    units = json.loads(comments[-1].removeprefix("# units: "))
    assert units["camber"] == "deg" and units["half_track"] == "mm"


def test_unconverged_step_is_flagged_with_empty_cells_and_exit_1(tmp_path, capsys):
    sweep = write(
        tmp_path / "far.yaml",
        {
            "steps": 2,
            "targets": [
                {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0.0, 800.0]},
                {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0, 0.0]},
            ],
        },
    )
    out = tmp_path / "res.csv"
    assert (
        main(["sweep", str(EXAMPLES / "double_wishbone.yaml"), str(sweep), "-o", str(out), "-q"])
        == 1
    )
    err = capsys.readouterr().err
    assert "1 of 2 steps did not converge" in err and "steps 1" in err
    last = [line for line in out.read_text().splitlines() if not line.startswith("#")][-1]
    cells = last.split(",")
    assert cells[:2] == ["1", "False"] and float(cells[2]) > 1.0
    assert set(cells[4:]) == {""}


def test_demo_writes_results(tmp_path, capsys):
    assert main(["demo", "-o", str(tmp_path / "d")]) == 0
    for name in (
        "demo_results.csv",
        "demo_corner.urdf",
        "demo_report.png",
        "demo_drawing.png",
        "demo_replay.html",
    ):
        assert (tmp_path / "d" / name).stat().st_size > 1000, name
    out = capsys.readouterr().out
    assert "41 converged" in out and "demo_replay.html in a browser" in out


def test_embedded_demo_files_are_the_examples():
    data = Path(__file__).parent.parent / "pin_susp" / "data"
    assert (data / "demo_geometry.yaml").read_text() == (
        EXAMPLES / "double_wishbone.yaml"
    ).read_text()
    assert (data / "demo_sweep.yaml").read_text() == (EXAMPLES / "bump_steer.yaml").read_text()


def geometry_case(change):
    g = example("double_wishbone.yaml")
    change(g)
    return g


def shim(g, **kw):
    g["config"]["camber_shim"] = {
        "shim_face_point_a": {"x": -25.0, "y": 750.0, "z": 510.0},
        "shim_face_point_b": {"x": -25.0, "y": 750.0, "z": 490.0},
        "shim_face_normal": {"x": 0.0, "y": 1.0, "z": 0.0},
        "design_thickness": 30.0,
        "setup_thickness": 30.0,
        **kw,
    }


GEOMETRY_ERRORS = {
    "missing point": (
        lambda g: g["hardpoints"].pop("axle_inboard"),
        "hardpoints.axle_inboard: missing point",
    ),
    "unknown key": (lambda g: g.update(sied="left"), "sied: unknown key"),
    "unknown hardpoint": (
        lambda g: g["hardpoints"].update(tie_rod={"x": 0, "y": 1, "z": 2}),
        "hardpoints.tie_rod: unknown hardpoint",
    ),
    "wrong type": (
        lambda g: g["hardpoints"]["axle_inboard"].update(x="ten"),
        "hardpoints.axle_inboard.x: expected a number, got text 'ten'",
    ),
    "non-finite": (
        lambda g: g["hardpoints"]["axle_inboard"].update(z=float("nan")),
        "hardpoints.axle_inboard.z: expected a finite number",
    ),
    "coincident axle": (
        lambda g: g["hardpoints"].update(axle_outboard=dict(g["hardpoints"]["axle_inboard"])),
        "hardpoints.axle_outboard: coincides with axle_inboard",
    ),
    "ball on pivot": (
        lambda g: g["hardpoints"].update(lower_wishbone_outboard={"x": 750, "y": 350, "z": 200}),
        "hardpoints.lower_wishbone_outboard: lies on the lower_wishbone pivot axis",
    ),
    "left with y < 0": (
        lambda g: g["hardpoints"]["axle_outboard"].update(y=-950),
        "hardpoints.axle_outboard: y = -950 mm on a left corner",
    ),
    "shim A = B": (
        lambda g: shim(g, shim_face_point_b={"x": -25.0, "y": 750.0, "z": 510.0}),
        "config.camber_shim.shim_face_point_b: coincides with shim_face_point_a",
    ),
    "shim zero normal": (
        lambda g: shim(g, shim_face_normal=[0, 0, 0]),
        "config.camber_shim.shim_face_normal: is the zero vector",
    ),
    "negative shim": (
        lambda g: shim(g, setup_thickness=-1.0),
        "config.camber_shim.setup_thickness: must be >= 0",
    ),
    "zero tyre": (
        lambda g: g["config"]["wheel"]["tire"].update(section_width=0),
        "config.wheel.tire.section_width: must be > 0",
    ),
    "bad side": (lambda g: g.update(side="middle"), "side: expected one of left, right"),
    "point as list of 2": (
        lambda g: g["hardpoints"].update(axle_inboard=[1, 2]),
        "hardpoints.axle_inboard: expected 3 coordinates",
    ),
    "trackrod on fixed toe link": (
        lambda g: g["config"].update(steering={"type": "none"}),
        "hardpoints.trackrod_inboard: not a point of a corner with",
    ),
}


def run_bad(tmp_path, capsys, geometry, sweep=None):
    gpath = write(tmp_path / "corner.yaml", geometry)
    spath = write(tmp_path / "sweep.yaml", sweep or example("bump_steer.yaml"))
    out = tmp_path / "out.csv"
    code = main(["sweep", str(gpath), str(spath), "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 2
    assert not out.exists() and not list(tmp_path.glob(".out.csv*"))
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in captured.err
    return lines[0]


@pytest.mark.parametrize("case", GEOMETRY_ERRORS, ids=str)
def test_bad_geometry_gets_one_clear_line(tmp_path, capsys, case):
    change, message = GEOMETRY_ERRORS[case]
    line = run_bad(tmp_path, capsys, geometry_case(change))
    assert line.startswith(f"pin-susp: error: {tmp_path / 'corner.yaml'}: ")
    assert message in line


def sweep_case(change):
    s = example("bump_steer.yaml")
    change(s)
    return s


SWEEP_ERRORS = {
    "too few targets": (
        lambda s: s["targets"].pop(0),  # the rack alone (a wheel target alone holds it)
        "targets: 1 target(s) given, this corner needs exactly 2",
    ),
    "too many targets": (
        lambda s: s["targets"].append(copy.deepcopy(s["targets"][0])),
        "3 target(s) given",
    ),
    "unknown point": (
        lambda s: s["targets"][0].update(point="wheel_centre"),
        "targets[0].point: unknown point 'wheel_centre'",
    ),
    "chassis point": (
        lambda s: s["targets"][0].update(point="upper_wishbone_inboard_front"),
        "targets[0].point: upper_wishbone_inboard_front is fixed to the chassis",
    ),
    "no rack target": (
        lambda s: s["targets"][1].update(point="wheel_center", direction={"axis": "x"}),
        "needs exactly one target on the rack",
    ),
    "values and start": (
        lambda s: s["targets"][1].update(values=[0.0, 1.0]),
        "targets[1]: give either values or start/stop, not both",
    ),
    "lengths differ": (
        lambda s: (
            s.clear()
            or s.update(
                targets=[
                    {
                        "point": "wheel_center",
                        "direction": {"axis": "z"},
                        "values": [0.0, 1.0, 2.0],
                    },
                    {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0, 1.0]},
                ]
            )
        ),
        "targets: every target needs the same number of values (targets[0]: 3, targets[1]: 2)",
    ),
    "values vs steps": (
        lambda s: (
            [s["targets"][1].pop(k) for k in ("start", "stop")]
            and s["targets"][1].update(values=[0.0, 1.0])
        ),
        "targets[1].values: has 2 values but steps is 41",
    ),
    "zero vector": (
        lambda s: s["targets"][0].update(direction={"vector": [0, 0, 0]}),
        "targets[0].direction.vector: is the zero vector",
    ),
    "bad mode": (
        lambda s: s["targets"][0].update(mode="relatve"),
        "targets[0].mode: expected one of relative, absolute",
    ),
    "steps zero": (lambda s: s.update(steps=0), "steps: expected a whole number >= 1"),
}


@pytest.mark.parametrize("case", SWEEP_ERRORS, ids=str)
def test_bad_sweep_gets_one_clear_line(tmp_path, capsys, case):
    change, message = SWEEP_ERRORS[case]
    line = run_bad(tmp_path, capsys, example("double_wishbone.yaml"), sweep_case(change))
    assert f"{tmp_path / 'sweep.yaml'}: " in line
    assert message in line


def test_missing_file_and_broken_yaml(tmp_path, capsys):
    assert "corner.yaml: not valid YAML at line 2" in run_bad(tmp_path, capsys, "a: 1\n b: [\n")
    code = main(
        [
            "sweep",
            str(tmp_path / "nope.yaml"),
            str(EXAMPLES / "bump_steer.yaml"),
            "-o",
            str(tmp_path / "o.csv"),
        ]
    )
    assert code == 2 and "nope.yaml: file not found" in capsys.readouterr().err


def test_console_script_reports_without_traceback(tmp_path):
    bad = write(tmp_path / "corner.yaml", geometry_case(GEOMETRY_ERRORS["missing point"][0]))
    out = tmp_path / "out.csv"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pin_susp.cli",
            "sweep",
            str(bad),
            str(EXAMPLES / "bump_steer.yaml"),
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip() == (
        f"pin-susp: error: {bad}: hardpoints.axle_inboard: missing point"
    )
    assert not out.exists()


# -- what a new user tripped over on a first afternoon ------------------------------------


def test_chassis_points_may_cross_the_centreline(tmp_path, capsys):
    g = example("pushrod_rocker.yaml")
    g["hardpoints"]["strut_top"]["y"] = -50.0  # a cross-car damper
    path = write(tmp_path / "g.yaml", g)
    assert (
        main(
            [
                "sweep",
                str(path),
                str(EXAMPLES / "bump_steer.yaml"),
                "-o",
                str(tmp_path / "r.csv"),
                "-q",
            ]
        )
        == 0
    )
    g["hardpoints"]["strut_top"]["y"] = 400.0
    g["hardpoints"]["trackrod_outboard"]["y"] = -800.0  # rides with the wheel: still refused
    write(tmp_path / "g.yaml", g)
    assert (
        main(["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(tmp_path / "r.csv")])
        == 2
    )
    assert "trackrod_outboard" in capsys.readouterr().err


def test_implausible_values_warn_one_line_each_and_still_run(tmp_path, capsys):
    g = example("double_wishbone.yaml")
    g["config"]["wheel"]["tire"]["rim_diameter"] = 330  # mm written for inches
    path = write(tmp_path / "g.yaml", g)
    out = tmp_path / "r.csv"
    assert main(["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(out)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert any("rim_diameter = 330 in" in line and "plausible" in line for line in err)
    assert any("scrub_radius" in line for line in err)
    assert all(line.startswith("pin-susp: warning:") for line in err)
    assert out.exists()
    assert main(["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(out), "-q"]) == 0
    assert capsys.readouterr().err == ""  # --quiet: nothing but errors
    assert main(["sweep", str(path), str(tmp_path / "missing.yaml"), "-o", str(out)]) == 2
    assert len(capsys.readouterr().err.splitlines()) == 1  # an error stays one line


def test_summary_says_what_a_blank_column_needs_and_where_centres_go_to_infinity(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert (
        main(
            [
                "sweep",
                str(EXAMPLES / "double_wishbone.yaml"),
                str(EXAMPLES / "bump_steer.yaml"),
                "-o",
                str(out),
            ]
        )
        == 0
    )
    lines = capsys.readouterr().out.splitlines()
    dive = next(line for line in lines if line.strip().startswith("anti_dive"))
    assert "needs config.axle_position: front, front_brake_bias" in dive
    fvic = next(line for line in lines if line.strip().startswith("fvic_y"))
    assert "at infinity" in fvic
    # where the centre really passes infinity: a sign change between neighbours, both far
    with open(out) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    y = [float(r["fvic_y"]) for r in rows]
    k = int(fvic.split("near step")[1])
    assert abs(y[k]) > 1e5 and any(np.sign(y[i]) != np.sign(y[i + 1]) for i in (k - 1, k))


def test_rocker_going_over_centre_is_warned(tmp_path, capsys):
    g = example("pushrod_rocker.yaml")
    g["hardpoints"]["pushrod_inboard"] = {"x": 0, "y": 290, "z": 440}  # arm almost along the rod
    path = write(tmp_path / "g.yaml", g)
    code = main(
        ["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(tmp_path / "r.csv")]
    )
    err = capsys.readouterr().err
    assert code in (0, 1)
    assert "rocker transmission angle" in err and "over-centre" in err


def test_sensitivity_ranks_the_points_a_designer_moves(capsys):
    path = str(EXAMPLES / "double_wishbone.yaml")
    assert main(["sensitivity", path, "--top", "3"]) == 0
    table = capsys.readouterr().out
    ranked = [ln.split()[0] for ln in table.splitlines() if "/mm " in ln and "move" in ln]
    assert ranked and "axle_inboard" not in ranked and "axle_outboard" not in ranked
    assert "not the spindle points" in table
    assert main(["sensitivity", path, "--points", "chassis", "--top", "3"]) == 0
    table = capsys.readouterr().out
    ranked = [ln.split()[0] for ln in table.splitlines() if "/mm " in ln and "move" in ln]
    assert ranked and all("inboard" in name for name in ranked)  # chassis pickups only
    assert main(["sensitivity", path, "--points", "nonsense"]) == 2


def test_demo_help_lists_every_output(capsys):
    with pytest.raises(SystemExit):
        pin_susp.cli._parser().parse_args(["demo", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for name in (
        "demo_results.csv",
        "demo_report.png",
        "demo_drawing.png",
        "demo_replay.html",
        "demo_corner.urdf",
        "demo_geometry.yaml",
        "demo_sweep.yaml",
    ):
        assert name in text
