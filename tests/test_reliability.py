"""Hostile use: never a wrong pose with exit 0, never a damaged file, never a traceback.

One test (or a table of cases) per class of failure a hostile user found:
outputs onto things that are not regular files, poses on another assembly
branch, vector directions, unconverged steps with exit 0, non-finite numbers
in model files, tracebacks, leftovers, quieter wrongs.
"""

import os
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example

import pin_susp
from pin_susp.cli import main

DATA = Path(__file__).parent / "data"
GEOMETRY = str(EXAMPLES / "double_wishbone.yaml")
BUMP_STEER = str(EXAMPLES / "bump_steer.yaml")
TOE_LINK = str(EXAMPLES / "fixed_toe_link.yaml")
BUMP = str(EXAMPLES / "bump.yaml")


def run(argv, capsys):
    """main(argv): (exit code, stdout, stderr lines)."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, [line for line in err.splitlines() if line.strip()]


def one_line_error(argv, capsys, *needles):
    code, _, err = run(argv, capsys)
    assert code == 2, err
    assert len(err) == 1, err
    for needle in needles:
        assert needle in err[0], err[0]
    return err[0]


def files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def write_yaml(path: Path, data) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def sweep_file(tmp_path, targets, steps=None, name="s.yaml") -> Path:
    data = {"version": 1, "targets": targets}
    if steps is not None:
        data["steps"] = steps
    return write_yaml(tmp_path / name, data)


def chirality(points) -> float:
    """Signed volume of four points: which side of the plane of the first three the last is."""
    a, b, c, d = (np.asarray(p, dtype=float) for p in points)
    return float(np.linalg.det(np.array([b - a, c - a, d - a])))


def read_csv(path: Path) -> dict[str, np.ndarray]:
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    header = lines[0].split(",")
    rows = [ln.split(",") for ln in lines[1:]]
    out = {}
    for j, name in enumerate(header):
        cells = [r[j] for r in rows]
        if name == "solver_converged":
            out[name] = np.array([c == "True" for c in cells])
        else:
            out[name] = np.array([float(c) if c else np.nan for c in cells])
    return out


# -- 1. outputs onto things that are not regular files ------------------------------


def test_output_onto_a_fifo_is_written_as_a_stream(tmp_path, capsys):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    code, _, _ = run(
        ["sweep", TOE_LINK, BUMP, "-o", fifo, "-q", "--plot", tmp_path / "p.png"], capsys
    )
    reader.join(timeout=30)
    assert code == 0
    assert stat.S_ISFIFO(fifo.stat().st_mode)  # still a pipe, not replaced by a file
    assert received and received[0].count("\n") > 61  # comments, header and 61 rows
    assert (tmp_path / "p.png").stat().st_size > 0  # drawn from the text, not read back


@pytest.mark.skipif(os.geteuid() != 0, reason="making a device node needs root")
def test_output_onto_a_character_device_leaves_the_device(tmp_path, capsys):
    null = tmp_path / "null"  # a twin of /dev/null inside the test's own folder
    os.mknod(null, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    code, _, _ = run(["sweep", TOE_LINK, BUMP, "-o", null, "-q"], capsys)
    assert code == 0
    assert stat.S_ISCHR(null.stat().st_mode)
    assert files(tmp_path) == {"null"}  # no temporary file left beside it


def test_output_through_a_symlink_replaces_the_target_not_the_link(tmp_path, capsys):
    target = tmp_path / "real" / "results.csv"
    target.parent.mkdir()
    target.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    code, _, _ = run(["sweep", TOE_LINK, BUMP, "-o", link, "-q"], capsys)
    assert code == 0
    assert link.is_symlink() and link.resolve() == target.resolve()
    assert target.read_text().startswith("# pin_susp")
    assert files(tmp_path) == {"real", "real/results.csv", "link.csv"}


@pytest.mark.parametrize("bad", ["", ".", "DIR", "DIR/"])
def test_output_that_is_a_directory_is_refused_before_any_work(tmp_path, capsys, bad):
    (tmp_path / "DIR").mkdir()  # the working directory is tmp_path (conftest)
    before = files(tmp_path)
    started = time.perf_counter()
    one_line_error(["sweep", GEOMETRY, BUMP_STEER, "-o", bad], capsys)
    assert time.perf_counter() - started < 5.0
    for argv in (
        ["urdf", GEOMETRY, "-o", bad],
        ["mjcf", GEOMETRY, "-o", bad],
        ["draw", GEOMETRY, "-o", bad],
        ["view", GEOMETRY, "--html", bad],
        ["sensitivity", GEOMETRY, "-o", bad],
        ["setup", GEOMETRY, "--csv", bad],
    ):
        one_line_error(argv, capsys)
    assert files(tmp_path) == before


# -- 2. a pose on another assembly branch is never reported as converged -------------

FLIP = DATA / "branch_flip.yaml"  # its upper ball joint loop toggles 0.75 mm of rack from design
LOOP_POINTS = {
    "upper_ball_joint": (
        "upper_wishbone_inboard_front",
        "upper_wishbone_inboard_rear",
        "lower_wishbone_outboard",
        "upper_wishbone_outboard",
    ),
    "trackrod": (
        "lower_wishbone_outboard",
        "upper_wishbone_outboard",
        "trackrod_inboard",
        "trackrod_outboard",
    ),
}


def rack_sweep(tmp_path, rack_mm, steps):
    return sweep_file(
        tmp_path,
        [
            {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0.0] * steps},
            {
                "point": "trackrod_inboard",
                "direction": {"axis": "y"},
                "values": np.linspace(0.0, rack_mm, steps).tolist(),
            },
        ],
    )


def test_a_step_past_a_loop_toggle_is_flagged_branch_not_converged(tmp_path, capsys):
    out = tmp_path / "r.csv"
    sweep = rack_sweep(tmp_path, -2.0, 21)
    code, _, err = run(["sweep", FLIP, sweep, "-o", out, "-q"], capsys)
    assert code == 1
    assert len(err) == 1 and "branch" in err[0] and "upper_ball_joint" in err[0]
    r = read_csv(out)
    ok = r["solver_converged"]
    assert ok[:8].all() and not ok[8:].any()  # the toggle lies between -0.7 and -0.8 mm
    assert "steps 8, 9, 10" in err[0]
    design = yaml.safe_load(FLIP.read_text())["hardpoints"]
    for loop, names in LOOP_POINTS.items():
        sign = np.sign(chirality([[design[n][a] for a in "xyz"] for n in names]))
        for i in np.flatnonzero(ok):  # every accepted row: on the design side, exactly closed
            pts = [[r[f"{n}_{a}"][i] for a in "xyz"] for n in names]
            assert np.sign(chirality(pts)) == sign, (loop, i)
        assert (r["solver_max_residual"][ok] <= 1e-9).all()


@pytest.mark.filterwarnings("ignore::pin_susp.errors.PlausibilityWarning")  # a flipped upright
def test_without_the_branch_check_the_same_targets_give_a_flipped_upright():
    """The check is not vacuous: Newton alone meets the residual on the other branch."""
    corner = pin_susp.Corner(FLIP)
    targets = [
        pin_susp.Target("wheel_center", "z", 0.0),
        pin_susp.Target("trackrod_inboard", "y", -2.0),
    ]
    checked = corner.solve_pose(targets)
    assert not checked.converged
    corner.branches.clear()  # what the solver did before the check
    flipped = corner.solve_pose(targets)
    assert flipped.converged and flipped.max_residual < 1e-9
    names = LOOP_POINTS["upper_ball_joint"]
    design = [corner.design_positions[n] for n in names]
    assert chirality([flipped.points[n] for n in names]) * chirality(design) < 0


def test_five_steps_do_not_jump_the_toggle_that_many_steps_cannot_pass(tmp_path, capsys):
    five, many = tmp_path / "five.csv", tmp_path / "many.csv"
    run(["sweep", FLIP, rack_sweep(tmp_path, -2.0, 5), "-o", five, "-q"], capsys)
    run(["sweep", FLIP, rack_sweep(tmp_path, -2.0, 201), "-o", many, "-q"], capsys)
    assert read_csv(five)["solver_converged"][-1] == read_csv(many)["solver_converged"][-1]


def test_setup_refuses_an_as_set_corner_on_another_branch():
    from pin_susp.errors import InputError
    from pin_susp.solve.as_set import check_branches

    g = pin_susp.load_geometry(EXAMPLES / "double_wishbone.yaml")
    points = dict(g.hardpoints)
    # the trackrod's outer end mirrored through the plane (kingpin, trackrod inboard)
    a, b, c = (
        points[n]
        for n in ("lower_wishbone_outboard", "upper_wishbone_outboard", "trackrod_inboard")
    )
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    d = points["trackrod_outboard"]
    points["trackrod_outboard"] = d - 2 * ((d - a) @ n) * n
    with pytest.raises(InputError, match="trackrod loop flipped over"):
        check_branches(g, points, "config.setup.trackrod_length_delta")
    check_branches(g, g.hardpoints, "config.setup.trackrod_length_delta")  # design: fine


# -- 3. targets along a vector -------------------------------------------------------


def test_vector_directions_work_everywhere_and_equal_the_axis(tmp_path, capsys):
    sweep = example("bump_steer.yaml")
    sweep["targets"][0]["direction"] = {"vector": [0, 0, 2]}
    sweep["targets"][1]["direction"] = {"vector": [0.0, 1.0, 0.0]}
    vec = write_yaml(tmp_path / "vector.yaml", sweep)
    a, b = tmp_path / "axis.csv", tmp_path / "vector.csv"
    assert run(["sweep", GEOMETRY, BUMP_STEER, "-o", a, "-q"], capsys)[0] == 0
    assert run(["sweep", GEOMETRY, vec, "-o", b, "-q"], capsys)[0] == 0
    ra, rb = read_csv(a), read_csv(b)
    for name in ("camber", "roadwheel_angle", "deriv_camber_wrt_hub_z", "wheel_center_z"):
        np.testing.assert_allclose(rb[name], ra[name], rtol=0, atol=1e-9)
    for argv in (
        ["sensitivity", GEOMETRY, "--sweep", vec, "-q"],
        ["urdf", GEOMETRY, "-o", tmp_path / "o.urdf", "--at", f"{vec}:3"],
        ["view", GEOMETRY, vec, "--html", tmp_path / "v.html"],
    ):
        assert run(argv, capsys)[0] == 0, argv
    oblique = example("bump.yaml")
    oblique["targets"][0]["direction"] = {"vector": [0.1, 0.0, 1.0]}
    assert (
        run(["sweep", TOE_LINK, write_yaml(tmp_path / "ob.yaml", oblique), "-o", b, "-q"], capsys)[
            0
        ]
        == 0
    )


# -- 4. every command exits 1 and names the steps that did not converge ---------------


def out_of_reach(tmp_path):
    sweep = example("bump.yaml")
    del sweep["steps"]
    sweep["targets"][0] = {
        "point": "wheel_center",
        "direction": {"axis": "z"},
        "values": [0, 10, 900, 20],
    }
    return write_yaml(tmp_path / "reach.yaml", sweep)


@pytest.mark.parametrize(
    "command",
    [
        ["sweep", TOE_LINK, "SWEEP", "-o", "OUT/r.csv", "-q"],
        ["sensitivity", TOE_LINK, "--sweep", "SWEEP", "-o", "OUT/s.csv", "-q"],
        ["view", TOE_LINK, "SWEEP", "--html", "OUT/v.html"],
    ],
    ids=["sweep", "sensitivity", "view"],
)
def test_unconverged_steps_exit_1_and_are_named(tmp_path, capsys, command):
    sweep = out_of_reach(tmp_path)
    argv = [str(sweep) if a == "SWEEP" else a.replace("OUT", str(tmp_path)) for a in command]
    code, _, err = run(argv, capsys)
    assert code == 1
    assert any("steps 2 " in line and "did not converge" in line for line in err), err


# -- 5. no invalid number is written, and absurd coordinates are refused ---------------


def test_strut_bottom_on_the_rocker_axis_gives_finite_model_files(tmp_path, capsys):
    g = example("pushrod_rocker.yaml")
    g["hardpoints"]["strut_bottom"] = dict(g["hardpoints"]["rocker_axis_a"], x=0.0)
    path = write_yaml(tmp_path / "g.yaml", g)
    for command, out in (("urdf", "o.urdf"), ("mjcf", "o.xml")):
        assert run([command, path, "-o", tmp_path / out], capsys)[0] == 0
        text = (tmp_path / out).read_text().lower()
        assert "nan" not in text and "inf" not in text
    import pinocchio as pin

    pin.buildModelFromXML((tmp_path / "o.urdf").read_text())


@pytest.mark.parametrize("value", [1e20, 1e300, -2e5])
def test_coordinates_beyond_100_m_are_refused(tmp_path, capsys, value):
    g = example("double_wishbone.yaml")
    g["hardpoints"]["axle_outboard"]["x"] = value
    path = write_yaml(tmp_path / "g.yaml", g)
    one_line_error(
        ["sweep", path, BUMP_STEER, "-o", tmp_path / "r.csv"], capsys, "100 m", "axle_outboard.x"
    )
    assert not (tmp_path / "r.csv").exists()


# -- 6. no tracebacks ------------------------------------------------------------------


def test_image_extensions_are_checked_before_any_work(tmp_path, capsys):
    for argv in (
        ["sweep", GEOMETRY, BUMP_STEER, "-o", tmp_path / "r.csv", "--plot", tmp_path / "p.xyz"],
        ["draw", GEOMETRY, "-o", tmp_path / "d.bad"],
        ["draw", GEOMETRY, "-o", tmp_path / "noextension"],
    ):
        one_line_error(argv, capsys, "format")
    assert files(tmp_path) == set()  # all outputs or none: no r.csv either


def test_demo_onto_an_existing_file(tmp_path, capsys):
    existing = tmp_path / "file"
    existing.write_text("keep")
    one_line_error(["demo", "-o", existing], capsys, "folder")
    assert existing.read_text() == "keep"


@pytest.mark.parametrize(
    "steps, needle",
    [(10**9, "split the sweep"), (10**12, "split the sweep"), (10**400, "split the sweep")],
)
def test_sweeps_too_big_for_memory_are_refused(tmp_path, capsys, steps, needle):
    sweep = example("bump.yaml")
    sweep["steps"] = steps
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(sweep))
    one_line_error(["sweep", TOE_LINK, path, "-o", tmp_path / "r.csv"], capsys, needle)


@pytest.mark.parametrize("step", ["²", "1" * 4300, "-1", "", "3.0", "x"])
def test_urdf_at_with_a_bad_step(tmp_path, capsys, step):
    one_line_error(
        ["urdf", GEOMETRY, "-o", tmp_path / "o.urdf", "--at", f"{BUMP_STEER}:{step}"],
        capsys,
        "--at",
    )
    assert files(tmp_path) == set()


def test_urdf_at_a_step_past_the_end(tmp_path, capsys):
    one_line_error(
        ["urdf", GEOMETRY, "-o", tmp_path / "o.urdf", "--at", f"{BUMP_STEER}:41"], capsys, "0 to 40"
    )


def test_a_target_that_cannot_move_is_refused(tmp_path, capsys):
    sweep = example("bump_steer.yaml")
    sweep["targets"][1]["direction"] = {"axis": "x"}  # the rack slides along y only
    path = write_yaml(tmp_path / "s.yaml", sweep)
    for argv in (
        ["sensitivity", GEOMETRY, "--sweep", path],
        ["sweep", GEOMETRY, path, "-o", tmp_path / "r.csv"],
    ):
        one_line_error(argv, capsys, "do not fix the pose")


# -- 7. leftovers: all outputs or none ---------------------------------------------------


def test_urdf_with_an_unwritable_sidecar_writes_neither(tmp_path, capsys):
    (tmp_path / "o.pose.yaml").mkdir()  # the sidecar's path is taken by a folder
    one_line_error(["urdf", GEOMETRY, "-o", tmp_path / "o.urdf", "--at", f"{BUMP_STEER}:3"], capsys)
    assert files(tmp_path) == {"o.pose.yaml"}


def test_sigterm_during_a_write_leaves_no_temporary_file(tmp_path, capsys, monkeypatch):
    from pin_susp.io import tables

    real = tables._column_cells
    calls = []

    def slow(values):
        calls.append(values)
        if len(calls) == 30:  # part-way through the columns
            signal.raise_signal(signal.SIGTERM)
        return real(values)

    monkeypatch.setattr(tables, "_column_cells", slow)
    code = main(["sweep", GEOMETRY, BUMP_STEER, "-o", str(tmp_path / "r.csv"), "-q"])
    assert code == 128 + signal.SIGTERM
    assert files(tmp_path) == set()
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # handler restored


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(x) for x in path.read_text().split()] if path.exists() else []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and prctl")
@pytest.mark.parametrize("how", [signal.SIGTERM, signal.SIGKILL])
def test_a_killed_view_leaves_no_meshcat_server(tmp_path, how):
    proc = subprocess.Popen(
        [sys.executable, "-m", "pin_susp.cli", "view", GEOMETRY],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        assert "meshcat:" in proc.stdout.readline()
        servers = _children(proc.pid)
        assert servers
        proc.send_signal(how)
        proc.wait(timeout=20)
        deadline = time.time() + 10
        while time.time() < deadline and any(Path(f"/proc/{s}").exists() for s in servers):
            time.sleep(0.1)
        assert not any(Path(f"/proc/{s}").exists() for s in servers)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


# -- 8. quieter wrongs -------------------------------------------------------------------


def test_no_warning_lines_around_results_or_errors(tmp_path, capsys):
    g = example("double_wishbone.yaml")  # parallel arms: instant centres at infinity, NaN inside
    for arm in ("lower", "upper"):
        for end in ("inboard_front", "inboard_rear", "outboard"):
            g["hardpoints"][f"{arm}_wishbone_{end}"]["z"] = 200 if arm == "lower" else 500
    path = write_yaml(tmp_path / "g.yaml", g)
    code, _, err = run(["sweep", path, BUMP_STEER, "-o", tmp_path / "r.csv", "-q"], capsys)
    assert code == 0 and err == []


def test_a_bad_value_on_the_command_line_is_blamed_on_the_option(capsys):
    line = one_line_error(
        ["setup", str(EXAMPLES / "camber_shim.yaml"), "--shim", "5e4"], capsys, "--shim"
    )
    assert "setup_thickness" not in line


def test_long_output_names_up_to_the_file_system_limit(tmp_path, capsys):
    name = "r" * 251 + ".csv"  # 255 bytes
    assert run(["sweep", TOE_LINK, BUMP, "-o", tmp_path / name, "-q"], capsys)[0] == 0
    assert (tmp_path / name).exists()
    one_line_error(["sweep", TOE_LINK, BUMP, "-o", tmp_path / ("r" + name)], capsys, "too long")


@pytest.mark.parametrize(
    "argv",
    [
        ["view", GEOMETRY, "--fps", "nan"],
        ["view", GEOMETRY, "--fps", "0"],
        ["setup", GEOMETRY, "--thread-pitch", "nan"],
        ["setup", GEOMETRY, "--toe", "inf"],
        ["sensitivity", GEOMETRY, "--top", "-1"],
        ["sweep", GEOMETRY],
        ["nonsense"],
        ["validate", GEOMETRY, BUMP_STEER, "--tolerance", "nan"],
    ],
)
def test_bad_options_get_one_line(capsys, argv):
    one_line_error(argv, capsys, "pin-susp")


@pytest.mark.parametrize(
    "axle_outboard", [{"x": -20, "y": 650, "z": 308}, {"x": -20, "y": 800, "z": 500}]
)
def test_a_spin_axis_pointing_inboard_or_vertical_is_refused(tmp_path, capsys, axle_outboard):
    g = example("double_wishbone.yaml")
    g["hardpoints"]["axle_outboard"] = axle_outboard
    path = write_yaml(tmp_path / "g.yaml", g)
    one_line_error(["sweep", path, BUMP_STEER, "-o", tmp_path / "r.csv"], capsys, "spin axis")


def test_yaml_numbers_as_an_engineer_writes_them(tmp_path, capsys):
    text = (EXAMPLES / "double_wishbone.yaml").read_text()
    text = text.replace("x: 250,", "x: 0250,", 1).replace("z: 200}", "z: 2e2}", 1)
    path = tmp_path / "g.yaml"
    path.write_text(text)
    g = pin_susp.load_geometry(path)
    assert g.hardpoints["lower_wishbone_inboard_front"][0] == pytest.approx(0.250)
    assert g.hardpoints["lower_wishbone_inboard_front"][2] == pytest.approx(0.200)


def test_an_output_onto_an_input_is_refused(tmp_path, capsys):
    g = tmp_path / "g.yaml"
    g.write_text((EXAMPLES / "double_wishbone.yaml").read_text())
    before = g.read_text()
    link = tmp_path / "link.yaml"
    link.symlink_to(g)
    for out in (g, link):
        one_line_error(["sweep", g, BUMP_STEER, "-o", out], capsys, "is an input")
    one_line_error(["setup", g, "--toe", "0", "-o", g], capsys, "is an input")
    assert g.read_text() == before


def test_two_outputs_on_one_path_are_refused(tmp_path, capsys):
    out = tmp_path / "set.yaml"
    one_line_error(["setup", GEOMETRY, "--toe", "0", "-o", out, "--csv", out], capsys, "one file")
    assert files(tmp_path) == set()


@pytest.mark.parametrize("bad", ["", ".", "/"])
def test_urdf_at_with_an_empty_or_folder_output(tmp_path, capsys, bad):
    one_line_error(["urdf", GEOMETRY, "-o", bad, "--at", f"{BUMP_STEER}:0"], capsys)


# -- found by an independent review ---------------------------------------------------


@pytest.mark.parametrize("command", ["draw", "plot"])
def test_plot_and_draw_refuse_an_output_that_links_to_their_input(tmp_path, capsys, command):
    g = tmp_path / "g.yaml"
    g.write_text((EXAMPLES / "double_wishbone.yaml").read_text())
    source = g
    if command == "plot":
        source = tmp_path / "r.csv"
        assert run(["sweep", g, BUMP_STEER, "-o", source, "-q"], capsys)[0] == 0
    before = source.read_bytes()
    link = tmp_path / "link.png"
    link.symlink_to(source)
    argv = ["draw", g, "-o", link] if command == "draw" else ["plot", source, "-o", link]
    one_line_error(argv, capsys, "is an input")
    assert source.read_bytes() == before


def test_dev_stdout_into_a_pipe_or_a_file_is_a_stream(tmp_path):
    argv = [sys.executable, "-m", "pin_susp.cli", "sweep", TOE_LINK, BUMP, "-o", "/dev/stdout"]
    piped = subprocess.run(argv + ["-q"], capture_output=True, text=True, cwd=tmp_path)
    assert piped.returncode == 0, piped.stderr
    assert piped.stdout.startswith("# pin_susp") and piped.stdout.count("\n") == 66
    with open(tmp_path / "o.txt", "w") as out:  # stdout a regular file: appended, not replaced
        assert subprocess.run(argv, stdout=out, cwd=tmp_path).returncode == 0
    text = (tmp_path / "o.txt").read_text()
    assert text.startswith("# pin_susp") and "wrote /dev/stdout" in text


def test_a_reader_that_closes_early_is_an_error_and_nothing_else_is_written(tmp_path, capsys):
    fifo = tmp_path / "p.csv"
    os.mkfifo(fifo)

    def read_a_little():
        with open(fifo, "rb") as f:
            f.read(100)

    reader = threading.Thread(target=read_a_little)
    reader.start()
    long = example("bump.yaml")
    long["steps"] = 2000  # ~3 MB of CSV: far more than a pipe holds
    sweep = write_yaml(tmp_path / "s.yaml", long)
    code, _, err = run(["sweep", TOE_LINK, sweep, "-o", fifo, "--plot", tmp_path / "p.png"], capsys)
    reader.join(timeout=30)
    assert code == 2 and len(err) == 1 and "closed it before the end" in err[0]
    assert files(tmp_path) == {"p.csv", "s.yaml"}


@pytest.mark.parametrize("steps", [41, 12_000], ids=["held", "streamed"])
def test_a_full_disk_is_one_line_and_leaves_nothing(tmp_path, steps):
    """A write that runs out of room (here a file-size limit, as a full disk or a quota
    would): one line naming the file, exit 2, no file and no temporary left."""
    import resource

    sweep = example("bump_steer.yaml")
    sweep["steps"] = steps
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(sweep))

    def limit():  # Python ignores SIGXFSZ: the write raises EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    proc = subprocess.run(
        [sys.executable, "-m", "pin_susp.cli", "sweep", GEOMETRY, str(path), "-o", "r.csv", "-q"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        preexec_fn=limit,
        timeout=300,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "r.csv: cannot be written (File too large)" in lines[0], lines
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_an_interrupt_says_a_stream_output_is_incomplete(tmp_path):
    """-o onto a pipe: what was sent before an interrupt is out, and the message says so."""
    from argparse import Namespace

    from pin_susp.cli.run import unwritten as _unwritten

    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    assert "is a stream" in _unwritten(Namespace(output=str(pipe)))
    assert _unwritten(Namespace(output=str(tmp_path / "r.csv"))) == "nothing written"
    assert _unwritten(Namespace()) == "nothing written"
