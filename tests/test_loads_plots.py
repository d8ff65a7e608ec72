"""What people look at of the loads: the force report and the viewer coloured by force.

Every number is checked against the forces CSV of `pin-susp loads` on the same
files, read here with the csv module: the report's lines are its columns (a
joint's, the length of its x, y, z), a step at a toggle is a gap; the replay's
member colours follow the sign and size of the members' forces at each frame,
in the HTML's animation and as the browser paints them.
"""

import csv
import os
import signal
import subprocess

import matplotlib
import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, sweep_csv
from test_viz import CHROMIUM, _commands

from pin_susp.cli import main
from pin_susp.plots import ResultsFile, report_figure

GEOMETRY = str(EXAMPLES / "pushrod_rocker.yaml")
SWEEP = str(EXAMPLES / "bump_steer.yaml")
CASES = str(EXAMPLES / "loads.yaml")
CASE_NAMES = [c["name"] for c in yaml.safe_load(open(CASES))["cases"]]
VISUALS = "/meshcat/pin_susp/corner/visuals/"
LEGS = {  # the wishbones' legs: the URDF's rods between these points
    "force_lower_wishbone_front": ("lower_wishbone_inboard_front", "lower_wishbone_outboard"),
    "force_lower_wishbone_rear": ("lower_wishbone_inboard_rear", "lower_wishbone_outboard"),
    "force_upper_wishbone_front": ("upper_wishbone_inboard_front", "upper_wishbone_outboard"),
    "force_upper_wishbone_rear": ("upper_wishbone_inboard_rear", "upper_wishbone_outboard"),
}
LINKS = {  # drawn between their ends: column, node
    "force_trackrod": "/meshcat/pin_susp/links/trackrod",
    "force_pushrod": "/meshcat/pin_susp/links/pushrod",
    "force_spring": "/meshcat/pin_susp/links/coilover",
}


def read_csv(path) -> dict[str, list[str]]:
    """A CSV's columns as its cells (text), the comment lines left out."""
    with open(path, newline="") as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return {name: [r[j] for r in rows[1:]] for j, name in enumerate(rows[0])}


def numbers(cells: list[str]) -> np.ndarray:
    return np.array([float(c) if c else np.nan for c in cells])


def case_rows(columns, case: str) -> np.ndarray:
    return np.array([c == case for c in columns["load_case"]])


@pytest.fixture(scope="module")
def forces(tmp_path_factory):
    """`pin-susp loads … --plot` of the pushrod-rocker corner: the CSV and the PNG."""
    tmp = tmp_path_factory.mktemp("forces")
    out, png = tmp / "forces.csv", tmp / "forces.png"
    assert (
        main(["loads", GEOMETRY, SWEEP, "--cases", CASES, "-o", str(out), "--plot", str(png)]) == 0
    )
    return out, png


@pytest.fixture(scope="module")
def toggle(tmp_path_factory):
    """The corner with its coilover's line through the rocker's axis at design (no force
    holds the wheel up there), swept through design: the CSV of `pin-susp loads`."""
    tmp = tmp_path_factory.mktemp("toggle")
    data = example("pushrod_rocker.yaml")
    hp = data["hardpoints"]
    p = {k: np.array([hp[k][a] for a in "xyz"], dtype=float) for k in hp}
    a, b = p["rocker_axis_a"], p["rocker_axis_b"]
    foot = a + (b - a) * ((p["strut_bottom"] - a) @ (b - a)) / ((b - a) @ (b - a))
    top = p["strut_bottom"] + 6.0 * (p["strut_bottom"] - foot)
    hp["strut_top"] = dict(zip("xyz", top.tolist(), strict=True))
    geometry, sweep, out = tmp / "toggle.yaml", tmp / "sweep.yaml", tmp / "toggle.csv"
    geometry.write_text(yaml.safe_dump(data))
    sweep.write_text(
        "steps: 9\ntargets:\n"
        "  - {point: wheel_center, direction: {axis: z}, start: -20, stop: 20}\n"
        "  - {point: trackrod_inboard, direction: {axis: y}, start: 0, stop: 0}\n"
    )
    assert main(["loads", str(geometry), str(sweep), "--cases", CASES, "-o", str(out), "-q"]) == 0
    return out, geometry, sweep


def panel_lines(fig) -> dict[str, dict[str, np.ndarray]]:
    """The report's panels by their y label: {case: (x, y)} of each line."""
    return {
        ax.get_ylabel(): {
            line.get_label(): line.get_xydata()
            for line in ax.get_lines()
            if line.get_gid() != "toggle"
        }
        for ax in fig.axes
        if ax.get_visible()
    }


def expected_panels(columns) -> dict[str, np.ndarray]:
    """y label → the values it must draw: each force column with a value, each joint's
    |load| = √(x² + y² + z²) from its three columns."""
    out = {}
    for name, cells in columns.items():
        if name.startswith(("force_", "torque_")) and any(cells):
            out[f"{name} [N]"] = numbers(cells)
        if name.startswith("load_") and name.endswith("_x"):
            joint = name[:-2]
            xyz = [numbers(columns[f"{joint}_{a}"]) for a in "xyz"]
            out[f"|{joint}| [N]"] = np.sqrt(sum(v * v for v in xyz))
    return out


def test_each_panel_draws_its_csv_column_per_load_case(forces):
    path, png = forces
    columns = read_csv(path)
    fig = report_figure([ResultsFile(path)])
    drawn, expected = panel_lines(fig), expected_panels(columns)
    # bump_steer moves the wheel and the rack: against the step, the two inputs first
    inputs = {"wheel_travel [mm]": "wheel_travel", "rack_displacement [mm]": "rack_displacement"}
    assert set(drawn) == set(expected) | set(inputs)
    assert len(drawn) == 16 + 2  # 6 members, spring, rack; 2 ball joints, 6 bushings; inputs
    travel = numbers(columns["step_index"])
    first = case_rows(columns, CASE_NAMES[0])
    for ylabel, column in inputs.items():
        (xy,) = drawn[ylabel].values()  # the steps once, not once per case
        expected_xy = np.column_stack([travel, numbers(columns[column])])[first]
        np.testing.assert_array_equal(xy, expected_xy)
    for ylabel, values in expected.items():
        assert set(drawn[ylabel]) == set(CASE_NAMES), ylabel
        for case in CASE_NAMES:
            rows = case_rows(columns, case)
            assert rows.sum() == 41
            np.testing.assert_array_equal(drawn[ylabel][case][:, 0], travel[rows])
            np.testing.assert_allclose(drawn[ylabel][case][:, 1], values[rows], rtol=1e-12)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend == CASE_NAMES
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_plot_command_draws_the_same_report_from_the_csv(forces, tmp_path, capsys):
    path, png = forces
    again = tmp_path / "again.png"
    assert main(["plot", str(path), "-o", str(again)]) == 0
    assert capsys.readouterr().out == f"wrote {again}\n"
    assert again.read_bytes() == png.read_bytes()  # the report drawn with the CSV


def test_a_step_at_a_toggle_is_a_gap_and_is_noted(toggle):
    toggle, _, _ = toggle
    columns = read_csv(toggle)
    flagged = numbers(columns["loads_unbounded"]) == 1.0
    steps = {int(s) for s, f in zip(columns["step_index"], flagged, strict=True) if f}
    assert steps == {4}  # wheel travel 0: the design, where the coilover's line meets the axis
    assert all(numbers(columns["force_spring"])[~flagged] != 0)
    fig = report_figure([ResultsFile(toggle)])
    for ylabel, lines in panel_lines(fig).items():
        for case, xy in lines.items():
            assert np.isnan(xy[4, 1]), (ylabel, case)  # the toggle: no point, a gap
            assert np.all(np.isfinite(np.delete(xy[:, 1], 4))), (ylabel, case)
    for ax in (ax for ax in fig.axes if ax.get_visible()):
        (mark,) = [line for line in ax.get_lines() if line.get_gid() == "toggle"]
        assert mark.get_xdata()[0] == 0.0  # a dotted line where the toggle is
    (note,) = [t.get_text() for t in fig.texts if t.get_gid() == "toggle_note"]
    assert note == (
        "toggle: forces unbounded (a toggle) at step(s) 4 (wheel travel 0): gaps, "
        "marked by dotted lines"
    )


@pytest.fixture(scope="module")
def replay(forces, tmp_path_factory):
    """The replay coloured by '2g cornering' (the pushrod's force sweeps the most there),
    its meshcat commands, and the CSV's columns."""
    html = tmp_path_factory.mktemp("replay") / "forces.html"
    argv = ["view", GEOMETRY, SWEEP, "--cases", CASES, "--case", "2g cornering"]
    assert main([*argv, "--html", str(html)]) == 0
    return html, _commands(html.read_text()), read_csv(forces[0])


def colour_tracks(commands) -> dict[str, dict[int, list[float]]]:
    """Node → {frame: rgb} of every colour track of the animation."""
    (animation,) = [c for c in commands if c["type"] == "set_animation"]
    out = {}
    for a in animation["animations"]:
        for track in a["clip"]["tracks"]:
            if track["name"] == ".material.color":
                node = a["path"].removesuffix("/<object>")
                out[node] = {k["time"]: k["value"] for k in track["keys"]}
    return out


def leg_nodes(commands) -> dict[str, str]:
    """Each wishbone leg's visual: the URDF rod whose design transform puts its middle at
    the middle of the leg's ends in the geometry file."""
    hp = example("pushrod_rocker.yaml")["hardpoints"]
    point = {k: np.array([v[a] for a in "xyz"]) * 1e-3 for k, v in hp.items()}
    placed = {
        c["path"]: np.array(c["matrix"]).reshape(4, 4).T[:3, 3]
        for c in commands
        if c["type"] == "set_transform" and c["path"].startswith(VISUALS)
    }
    out = {}
    for column, (a, b) in LEGS.items():
        middle = 0.5 * (point[a] + point[b])
        (node,) = [n for n, p in placed.items() if np.linalg.norm(p - middle) < 1e-9]
        out[column] = node
    return out


def tensions(columns, case: str) -> dict[str, np.ndarray]:
    """Each coloured member's tension (N) at each step: the spring's column negated
    (it is its compression)."""
    rows = case_rows(columns, case)
    out = {}
    for column in [*LEGS, *LINKS]:
        sign = -1.0 if column == "force_spring" else 1.0
        out[column] = sign * numbers(columns[column])[rows]
    return out


def test_members_are_coloured_by_the_sign_and_size_of_their_csv_force(replay):
    _, commands, columns = replay
    tracks = colour_tracks(commands)
    nodes = {**LINKS, **leg_nodes(commands)}
    assert set(tracks) == set(nodes.values())  # those seven, nothing else
    t = tensions(columns, "2g cornering")
    scale = max(np.abs(v).max() for v in t.values())
    assert scale == pytest.approx(np.abs(t["force_pushrod"]).max())  # its 4194 N
    assert_coloured_by(tracks, nodes, t, scale)
    ramp = matplotlib.colormaps["coolwarm"]
    strongest = np.argmax(np.abs(t["force_pushrod"]))  # in compression: the ramp's end
    np.testing.assert_allclose(tracks[nodes["force_pushrod"]][strongest], ramp(0.0)[:3])


def assert_coloured_by(tracks, nodes, t, scale) -> None:
    """Each member's colour at every frame (one per step) is red where its tension ``t``
    is positive, blue where negative, further from grey as |t| grows in either:
    coolwarm's 0.5 + 0.5·t/scale."""
    ramp = matplotlib.colormaps["coolwarm"]
    grey = np.array(ramp(0.5)[:3])
    for column, node in nodes.items():
        force = t[column]
        rgb = np.array([tracks[node][k] for k in range(len(force))])  # a frame per step
        red, blue = rgb[:, 0] - rgb[:, 2], rgb[:, 2] - rgb[:, 0]
        assert np.all((red > 0) == (force > 0)) and np.all((blue > 0) == (force < 0)), column
        away = np.linalg.norm(rgb - grey, axis=1)  # from grey (zero) as |force| grows,
        for same in (force >= 0, force < 0):  # on each side of it (coolwarm's sides differ)
            order = np.argsort(np.abs(force[same]))
            assert np.all(np.diff(away[same][order]) >= -1e-12), column
        np.testing.assert_allclose(rgb, ramp(0.5 + 0.5 * force / scale)[:, :3], atol=1e-12)


def test_at_a_toggle_the_members_are_near_black_in_the_replay(toggle, tmp_path):
    path, geometry, sweep = toggle
    html = tmp_path / "toggle.html"
    argv = ["view", str(geometry), str(sweep), "--cases", CASES, "--case", "3g bump"]
    assert main([*argv, "--html", str(html)]) == 0
    tracks = colour_tracks(_commands(html.read_text()))
    assert len(tracks) == 7
    flagged = numbers(read_csv(path)["loads_unbounded"])[case_rows(read_csv(path), "3g bump")]
    for node, track in tracks.items():
        for frame, rgb in track.items():
            assert (rgb == [0.1, 0.1, 0.1]) == (flagged[frame] == 1.0), (node, frame)


def test_the_replay_keys_its_colours(replay):
    html, _, _ = replay
    text = html.read_text()
    assert 'id="force_key"' in text
    assert "Load case <b>2g cornering</b> (loads.yaml)" in text
    assert "−4194 N" in text and "+4194 N" in text


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package chromium)")
def test_the_browser_paints_the_members_in_their_frame_colours(replay, tmp_path):
    """Paused at frames 0, 20 and 40, each member's material in the page has its colour
    track's value (the tracks bind to the members' meshes once they are loaded)."""
    html, commands, _ = replay
    tracks = colour_tracks(commands)
    frames = (0, 20, 40)
    nodes = [n.strip("/").split("/") + ["<object>"] for n in tracks]
    probe = (
        "<script>setTimeout(function () {"
        "  var a = viewer.animator, out = [];"
        "  a.pause();"
        f"  {list(frames)}.forEach(function (k) {{"
        "    a.seek(k / 10);"
        f"    out.push({nodes}.map(function (p) {{"
        "      var c = viewer.scene_tree.find(p).object.material.color;"
        "      return [c.r, c.g, c.b]; }));"
        "  });"
        "  document.title = 'probe:' + JSON.stringify(out);"
        "}, 2500);</script></body>"
    )
    page = tmp_path / "probe.html"
    page.write_text(html.read_text().replace("</body>", probe, 1))
    painted = np.array(_probe(page, tmp_path))
    expected = np.array([[tracks[n][k] for n in tracks] for k in frames])
    np.testing.assert_allclose(painted, expected, atol=1e-6)


def _probe(page, tmp_path) -> list:
    """The JSON a page leaves in its title (prefixed 'probe:'), from headless chromium."""
    import json
    import re

    for attempt in range(3):  # headless chromium now and then hangs on start-up
        proc = subprocess.Popen(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
             "--enable-unsafe-swiftshader", "--disable-dev-shm-usage", "--no-first-run",
             "--disable-extensions", "--virtual-time-budget=5000",
             f"--user-data-dir={tmp_path / f'profile-{attempt}'}", "--dump-dom", page.as_uri()],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, start_new_session=True,
        )  # fmt: skip
        try:
            dom, _ = proc.communicate(timeout=60)
            break
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    found = re.search(r"<title>probe:(.*?)</title>", dom)
    assert found, "the page left no probe in its title"
    return json.loads(found.group(1))


# --- an axle: both corners' members and the droplinks ------------------------------------------

AXLE_SWEEP = str(EXAMPLES / "heave_roll.yaml")  # roll ±3° at 10 mm of heave, 31 steps
AXLE_CASES = (  # cornering to the right: the left (outer) wheel loaded three times the right
    "version: 1\ncases:\n"
    "  - {name: turn, left: {contact_patch: {fx: 0, fy: -2700, fz: 1800}},\n"
    "     right: {contact_patch: {fx: 0, fy: -900, fz: 600}}}\n"
)


@pytest.fixture(scope="module")
def axle_replay(tmp_path_factory):
    """examples/axle_front.yaml with spring and bar rates (the bar shares the load by
    stiffness): its forces CSV and its replay under 'turn', with the files."""
    tmp = tmp_path_factory.mktemp("axle")
    data = example("axle_front.yaml")
    data["axle_config"]["spring"] = {"type": "coilover", "rate": 175, "preload": 2600}
    data["axle_config"]["anti_roll"]["stiffness"] = 40
    geometry, cases = tmp / "axle.yaml", tmp / "cases.yaml"
    geometry.write_text(yaml.safe_dump(data))
    cases.write_text(AXLE_CASES)
    out, html = tmp / "forces.csv", tmp / "axle.html"
    argv = [str(geometry), AXLE_SWEEP, "--cases", str(cases)]
    assert main(["loads", *argv, "-o", str(out), "-q"]) == 0
    assert main(["view", *argv, "--html", str(html)]) == 0
    return geometry, cases, _commands(html.read_text()), read_csv(out)


def axle_nodes(commands) -> dict[str, str]:
    """Each side's members: the links by their side's prefix, the wishbones' legs the
    URDF rods whose middles are their ends' (the right corner the left mirrored)."""
    hp = example("axle_front.yaml")["hardpoints"]["left"]
    left = {k: np.array([v[a] for a in "xyz"]) * 1e-3 for k, v in hp.items()}
    point = {
        **{f"left_{k}": p for k, p in left.items()},
        **{f"right_{k}": p * [1.0, -1.0, 1.0] for k, p in left.items()},
    }
    placed = {
        c["path"]: np.array(c["matrix"]).reshape(4, 4).T[:3, 3]
        for c in commands
        if c["type"] == "set_transform" and c["path"].startswith(VISUALS)
    }
    out = {}
    for side in ("left", "right"):
        for member in ("trackrod", "pushrod", "droplink"):
            out[f"force_{member}_{side}"] = f"/meshcat/pin_susp/links/{side}_{member}"
        out[f"force_spring_{side}"] = f"/meshcat/pin_susp/links/{side}_coilover"
        for column, (a, b) in LEGS.items():
            middle = 0.5 * (point[f"{side}_{a}"] + point[f"{side}_{b}"])
            (node,) = [n for n, p in placed.items() if np.linalg.norm(p - middle) < 1e-9]
            out[f"{column}_{side}"] = node
    return out


def test_an_axles_members_are_coloured_by_their_sided_csv_forces(axle_replay):
    _, _, commands, columns = axle_replay
    tracks = colour_tracks(commands)
    nodes = axle_nodes(commands)
    assert len(set(nodes.values())) == 16  # each side's 4 links and 4 legs, no other
    assert set(tracks) == set(nodes.values())  # the bar (torque_arb, N·m) keeps its colour
    rows = case_rows(columns, "turn")
    assert rows.sum() == 31
    t = {
        c: (-1.0 if c.startswith("force_spring") else 1.0) * numbers(columns[c])[rows]
        for c in nodes
    }
    assert np.all(np.isfinite(np.concatenate(list(t.values()))))
    # the outer (left) side's droplink pushes, the inner's pulls: a side swapped would fail
    assert np.all(t["force_droplink_left"] < 0) and np.all(t["force_droplink_right"] > 0)
    scale = max(np.abs(v).max() for v in t.values())
    assert scale == pytest.approx(np.abs(t["force_pushrod_left"]).max())  # the outer pushrod
    assert_coloured_by(tracks, nodes, t, scale)


def test_an_axles_replay_bad_input_writes_nothing(axle_replay, tmp_path, capsys):
    geometry, cases, _, _ = axle_replay
    html = tmp_path / "out.html"
    argv = ["view", str(geometry), AXLE_SWEEP, "--html", str(html)]
    err = one_error_line(capsys, [*argv, "--cases", str(cases), "--case", "brake"])
    assert err == f"pin-susp: error: {cases}: cases: no load case named 'brake' (it has 'turn')\n"
    err = one_error_line(capsys, [*argv, "--cases", CASES])  # a corner's cases
    assert err == (
        f"pin-susp: error: {CASES}: cases[0].contact_patch: an axle's loads go in left: and "
        "right: blocks\n"
    )
    unrated = str(EXAMPLES / "axle_front.yaml")  # the bar's share needs the rates
    err = one_error_line(capsys, ["view", unrated, *argv[2:], "--cases", str(cases)])
    assert "give each spring's rate (spring.rate) and the bar's" in err
    assert not html.exists()


# --- bad input: one line, exit 2, nothing written ---------------------------------------------


def one_error_line(capsys, argv) -> str:
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    return err


def test_an_unknown_case_is_named_with_the_cases_the_file_has(tmp_path, capsys):
    html = tmp_path / "out.html"
    argv = ["view", GEOMETRY, SWEEP, "--cases", CASES, "--case", "4g landing"]
    err = one_error_line(capsys, [*argv, "--html", str(html)])
    assert err == (
        f"pin-susp: error: {CASES}: cases: no load case named '4g landing' "
        "(it has '1.5g braking', '2g cornering', '3g bump')\n"
    )
    assert not html.exists()


def test_a_case_without_cases_and_cases_without_a_sweep(tmp_path, capsys):
    html = tmp_path / "out.html"
    err = one_error_line(capsys, ["view", GEOMETRY, SWEEP, "--case", "x", "--html", str(html)])
    assert err == "pin-susp: error: --case x: needs --cases LOADS.yaml, the cases it names\n"
    err = one_error_line(capsys, ["view", GEOMETRY, "--cases", CASES, "--html", str(html)])
    assert "needs a SWEEP" in err
    assert not html.exists()


def test_forces_and_a_sweep_are_not_plotted_together(forces, tmp_path, capsys):
    path, _ = forces
    sweep = sweep_csv(tmp_path, "pushrod_rocker.yaml", "bump_steer.yaml", "sweep.csv")
    out = tmp_path / "mixed.png"
    for files in ([str(sweep), str(path)], [str(path), str(sweep)]):
        err = one_error_line(capsys, ["plot", *files, "-o", str(out)])
        assert err == (
            f"pin-susp: error: {sweep}: a sweep's results, but {path} holds forces "
            "(pin-susp loads): plot them separately\n"
        )
    assert not out.exists()


def test_loads_with_a_bad_plot_name_writes_neither(tmp_path, capsys):
    out, png = tmp_path / "f.csv", tmp_path / "f.bmpx"
    argv = ["loads", GEOMETRY, SWEEP, "--cases", CASES, "-o", str(out), "--plot", str(png)]
    err = one_error_line(capsys, argv)
    assert "f.bmpx: unsupported image format 'bmpx'" in err
    assert not out.exists() and not png.exists()
