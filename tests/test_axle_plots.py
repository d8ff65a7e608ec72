"""The axle report and the axle's front-view drawing (`pin-susp plot`, `sweep --plot`,
`draw --at`): what an engineer reads off them.

The CSVs are read here with the csv module, not with pin_susp's reader; the roll
centre is checked against the crossing of the two contact-patch → FVIC lines solved
here with numpy from the CSV's own point and FVIC columns, and at design against the
mirror symmetry of the axle (on the centreline). A picture's panels are read off the
figure the command saved it from.
"""

import csv

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, main_saving, sweep_csv

from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.plots import AXLE_PANELS, ResultsFile, report_figure
from pin_susp.subjects.axle import AxleModel, load_axle
from pin_susp.viz.drawing import PARALLEL, axle_drawing_figure, axle_pose

SIDES = ("left", "right")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


TITLES = {names: title for title, names in AXLE_PANELS}
ACKERMANN_TITLE = "Ackermann"


def converging() -> dict:
    """examples/axle_front.yaml with arms that meet in front view (the example's are
    level: parallel, no instant centre at design) and a rocker-to-rocker heave link."""
    g = example("axle_front.yaml")
    hp = g["hardpoints"]["left"]
    for n in ("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear"):
        hp[n]["z"] = 460
    hp["lower_wishbone_inboard_rear"]["z"] = 215
    g["axle_config"]["heave_link"] = {"type": "rocker_to_rocker"}
    hp["heave_link_rocker"] = {"x": 0, "y": 330, "z": 420}
    return g


def sweep_text(steps: int, roll=(0, 0), heave=(0, 0), rack=(0, 0)) -> str:
    return yaml.safe_dump(
        {
            "steps": steps,
            "targets": [
                {"quantity": "roll", "start": roll[0], "stop": roll[1]},
                {"quantity": "heave", "start": heave[0], "stop": heave[1]},
                {
                    "point": "trackrod_inboard",
                    "side": "left",
                    "direction": {"axis": "y"},
                    "start": rack[0],
                    "stop": rack[1],
                },
            ],
        }
    )


SWEEPS = {  # name: (steps, what it moves); roll at a ride height, a steer, a heave
    "roll": sweep_text(7, roll=(-3, 3), heave=(10, 10)),
    "steer": sweep_text(9, rack=(-40, 40)),  # step 4: the design state
    "heave": sweep_text(5, heave=(-30, 30)),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The converging axle's file, and each sweep's CSV and report (sweep --plot); the
    figure each report was saved from by ("report", sweep) (read by the tests, never
    changed)."""
    folder = tmp_path_factory.mktemp("axle_plots")
    geometry = folder / "axle.yaml"
    geometry.write_text(yaml.safe_dump(converging()))
    out = {"geometry": str(geometry)}
    for name, text in SWEEPS.items():
        sweep = folder / f"{name}.yaml"
        sweep.write_text(text)
        csv_path, png = folder / f"{name}.csv", folder / f"{name}.png"
        argv = ["sweep", str(geometry), str(sweep), "-o", str(csv_path), "--plot", str(png)]
        code, (fig,) = main_saving(argv)
        assert code == 0 and png.stat().st_size > 10_000
        out[name], out["report", name] = str(csv_path), fig
    return out


@pytest.fixture(scope="module")
def model(runs):
    return AxleModel(load_axle(runs["geometry"]))


def read(path) -> dict[str, np.ndarray]:
    """A results CSV as columns of floats (empty → NaN, True/False → 1/0)."""
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))

    def number(cell: str) -> float:
        special = {"": np.nan, "True": 1.0, "False": 0.0}
        return special[cell] if cell in special else float(cell)

    return {k: np.array([number(r[k]) for r in rows]) for k in rows[0]}


def lines_of(fig) -> dict[str, list]:
    """Each visible panel's lines by the panel's title."""
    return {ax.get_title(): ax.get_lines() for ax in fig.axes if ax.get_visible()}


def same(a, b) -> None:
    np.testing.assert_array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


# --- the report ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("sweep", "x"), [("roll", "roll"), ("heave", "heave"), ("steer", "rack_displacement")]
)
def test_each_panel_draws_its_csv_columns_against_what_the_sweep_moved(runs, sweep, x):
    columns = read(runs[sweep])
    fig = runs["report", sweep]
    panels = lines_of(fig)
    expected = {
        TITLES[names]: names
        for names in TITLES
        if any(np.any(np.isfinite(columns.get(n, [np.nan]))) for n in names)
    }
    assert set(expected) <= set(panels)
    for title, names in expected.items():
        assert [ln.get_linestyle() for ln in panels[title]] == ["-", "--"][: len(names)]
        for line, name in zip(panels[title], names, strict=True):
            same(line.get_xdata(), columns[x])
            same(line.get_ydata(), columns[name])
    # the panels an engineer asked for: roll camber and steer, roll centre, bar twist
    for name in ("camber_left", "camber_to_ground_right", "steer_angle_left", "roll_center_z"):
        assert any(name in names for names in expected.values())
    assert {"Anti-roll bar twist (left − right arm)", "Heave link length"} <= set(panels)
    word = {"roll": "Roll", "heave": "Heave", "rack_displacement": "Rack"}[x]
    for ax in fig.axes:
        if ax.get_visible() and ax.get_title() != ACKERMANN_TITLE:
            assert ax.get_xlabel().startswith(word)


def test_ackermann_is_drawn_against_the_mean_steer_angle_when_the_sweep_steers(runs):
    columns = read(runs["steer"])
    assert np.isfinite(columns["ackermann"]).sum() >= 6  # blank only near straight ahead
    (line,) = lines_of(runs["report", "steer"])[ACKERMANN_TITLE]
    same(line.get_xdata(), 0.5 * (columns["steer_angle_left"] + columns["steer_angle_right"]))
    same(line.get_ydata(), columns["ackermann"])
    # no steer, no Ackermann panel
    assert ACKERMANN_TITLE not in lines_of(runs["report", "roll"])


def without(path, out, drop=(), blank=()) -> str:
    """The CSV with columns dropped and others emptied."""
    lines = open(path).read().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    rows = [ln.split(",") for ln in lines if not ln.startswith("#")]
    keep = [j for j, n in enumerate(rows[0]) if n not in drop]
    emptied = {rows[0].index(n) for n in blank}
    body = [rows[0]] + [["" if j in emptied else r[j] for j in range(len(r))] for r in rows[1:]]
    out.write_text("\n".join(comments + [",".join(r[j] for j in keep) for r in body]) + "\n")
    return str(out)


def test_absent_or_blank_columns_leave_their_panel_out(runs, tmp_path):
    full = lines_of(runs["report", "roll"])
    gone = ("Anti-roll bar twist (left − right arm)", "Heave link length", "Roll centre height")
    assert set(gone) <= set(full)
    path = without(
        runs["roll"],
        tmp_path / "less.csv",
        drop=("arb_twist", "heave_link_length"),
        blank=("roll_center_z",),
    )
    fewer = lines_of(report_figure([ResultsFile(path)]))
    assert set(fewer) == set(full) - set(gone)
    # one side's column gone: its panel keeps the other side
    path = without(runs["roll"], tmp_path / "one.csv", drop=("camber_right",))
    (line,) = lines_of(report_figure([ResultsFile(path)]))["Camber (to the chassis)"]
    same(line.get_ydata(), read(runs["roll"])["camber_left"])


def test_two_axle_files_are_two_colours_each_side_its_style(runs, tmp_path):
    other = tmp_path / "other.csv"
    other.write_text(open(runs["roll"]).read())
    panels = lines_of(report_figure([ResultsFile(runs["roll"]), ResultsFile(other)]))
    camber = panels["Camber (to the chassis)"]
    assert [ln.get_label() for ln in camber] == [
        "roll left",
        "roll right",
        "other left",
        "other right",
    ]
    assert camber[0].get_color() == camber[1].get_color() != camber[2].get_color()


@pytest.fixture(scope="module")
def corner(tmp_path_factory):
    """A corner's results CSV."""
    return sweep_csv(tmp_path_factory.mktemp("corner"), "double_wishbone.yaml", "bump_steer.yaml")


def test_an_axle_and_a_corner_are_not_plotted_together(runs, corner, tmp_path, capsys):
    out = tmp_path / "x.png"
    assert main(["plot", runs["roll"], str(corner), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pin-susp: error: {corner}: a corner's results, but {runs['roll']} is an axle's: "
        "plot them separately\n"
    )
    assert not out.exists()
    assert main(["plot", runs["roll"], runs["steer"], "-o", str(out)]) == 2
    assert "x is rack travel but" in capsys.readouterr().err
    assert not out.exists()


def test_sweep_plot_with_a_bad_image_name_writes_nothing(runs, tmp_path, capsys):
    sweep = tmp_path / "s.yaml"
    sweep.write_text(SWEEPS["heave"])
    out = tmp_path / "a.csv"
    code = main(["sweep", runs["geometry"], str(sweep), "-o", str(out), "--plot", "r.xyz", "-q"])
    assert code == 2
    assert "unsupported image format 'xyz'" in capsys.readouterr().err
    assert not out.exists()


# --- the front view and the roll centre ---------------------------------------------------------


def crossing(columns: dict, i: int) -> np.ndarray:
    """Where the lines CP_L → FVIC_L and CP_R → FVIC_R cross (y, z), from the CSV."""
    cp, d = {}, {}
    for s in SIDES:
        cp[s] = np.array([columns[f"{s}_contact_patch_center_{a}"][i] for a in "yz"])
        d[s] = np.array([columns[f"fvic_y_{s}"][i], columns[f"fvic_z_{s}"][i]]) - cp[s]
    t = np.linalg.solve(np.column_stack([d["left"], -d["right"]]), cp["right"] - cp["left"])
    return cp["left"] + t[0] * d["left"]


def marker(ax, gid: str) -> np.ndarray:
    (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    return np.array([line.get_xdata()[0], line.get_ydata()[0]])


def notes(ax) -> str:
    return "\n".join(t.get_text() for t in ax.texts if t.get_gid() == "ic_note")


@pytest.mark.parametrize(("sweep", "step"), [("roll", 0), ("roll", 5), ("steer", 8), ("heave", 0)])
def test_the_roll_centre_drawn_is_where_the_contact_patch_lines_cross(runs, model, sweep, step):
    columns = read(runs[sweep])
    expected = crossing(columns, step)
    q, caption = axle_pose(model, ResultsFile(runs[sweep]), step)
    assert caption.startswith(f"step {step} of {sweep} (heave ")
    (front,) = axle_drawing_figure(model, q).axes
    np.testing.assert_allclose(marker(front, "roll_centre"), expected, atol=1e-6)
    np.testing.assert_allclose(
        expected, [columns["roll_center_y"][step], columns["roll_center_z"][step]], atol=1e-6
    )
    assert f"RC: y = {expected[0]:.0f} mm, z = {expected[1]:.0f} mm" in notes(front)
    for s in SIDES:
        fvic = [columns[f"fvic_y_{s}"][step], columns[f"fvic_z_{s}"][step]]
        np.testing.assert_allclose(marker(front, f"fvic_{s}"), fvic, atol=1e-6)
        # the side's line runs from its contact patch through its FVIC to the roll centre
        (line,) = [ln for ln in front.get_lines() if ln.get_gid() == f"fvic_contact_patch_{s}"]
        ends = np.column_stack([line.get_xdata(), line.get_ydata()])
        cp = [columns[f"{s}_contact_patch_center_{a}"][step] for a in "yz"]
        assert min(np.linalg.norm(ends - cp, axis=1)) < 1e-6
        d = ends[1] - ends[0]
        for p in (fvic, expected):
            e = np.asarray(p) - ends[0]
            assert abs(d[0] * e[1] - d[1] * e[0]) < 1e-9 * np.linalg.norm(d) * np.linalg.norm(e)
        # from each ball joint to the FVIC
        arms = [ln for ln in front.get_lines() if ln.get_gid() == f"fvic_arm_{s}"]
        for arm, joint in zip(arms, ("upper", "lower"), strict=True):
            start, end = np.column_stack([arm.get_xdata(), arm.get_ydata()])
            ball = [columns[f"{s}_{joint}_wishbone_outboard_{a}"][step] for a in "yz"]
            np.testing.assert_allclose(start, ball, atol=1e-6)
            np.testing.assert_allclose(end, fvic, atol=1e-6)


def test_at_design_the_roll_centre_is_on_the_centreline_as_at_the_designs_step(runs, model):
    columns = read(runs["steer"])
    assert columns["rack_displacement"][4] == 0.0 and columns["heave"][4] == pytest.approx(0.0)
    (front,) = axle_drawing_figure(model).axes
    rc = marker(front, "roll_centre")
    assert rc[0] == pytest.approx(0.0, abs=1e-9)  # a mirrored axle: on its plane of symmetry
    np.testing.assert_allclose(rc, crossing(columns, 4), atol=1e-6)
    assert front.get_title() == "Front view: design state"


def test_parallel_arms_draw_no_roll_centre_but_say_why(tmp_path):
    # the example's arms are level: both FVICs at infinity at design
    (front,) = axle_drawing_figure(AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))).axes
    assert not [ln for ln in front.get_lines() if ln.get_gid() in ("roll_centre", "fvic_left")]
    assert notes(front) == (
        f"left: {PARALLEL}\nright: {PARALLEL}\nRC: no front-view instant centre on left and right"
    )
    assert all(abs(v) < 3000 for v in (*front.get_xlim(), *front.get_ylim()))


def test_draw_at_a_step_writes_the_picture(runs, tmp_path, capsys):
    out = tmp_path / "front.png"
    assert (
        main(["draw", runs["geometry"], "-o", str(out), "--at", f"{runs['roll']}:3", "--labels"])
        == 0
    )
    assert capsys.readouterr().out == f"wrote {out}\n"
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def converged_false(path, out, step: int) -> str:
    lines = open(path).read().splitlines()
    k = next(j for j, ln in enumerate(lines) if ln.startswith("step_index"))
    cells = lines[k + 1 + step].split(",")
    cells[1] = "False"
    lines[k + 1 + step] = ",".join(cells)
    out.write_text("\n".join(lines) + "\n")
    return str(out)


def test_bad_draw_input_is_one_line_and_exit_2(runs, corner, tmp_path, capsys):
    geometry, roll = runs["geometry"], runs["roll"]
    failed = converged_false(roll, tmp_path / "failed.csv", 2)
    cases = [
        (geometry, f"{roll}", f"--at {roll}: expected RESULTS.csv:STEP, e.g. axle.csv:15"),
        (geometry, f"{roll}:7", f"{roll}: step 7: no such step (steps 0 to 6)"),
        (
            geometry,
            f"{corner}:0",
            f"{corner}: a corner's results: an axle is drawn at a step of its own",
        ),
        (geometry, f"{failed}:2", f"{failed}: step 2: did not converge: it has no pose to draw"),
        (
            str(EXAMPLES / "double_wishbone.yaml"),
            f"{roll}:0",
            "is a corner, drawn at its design state only",
        ),
        (
            str(EXAMPLES / "axle_front.yaml"),
            f"{roll}:1",
            "mm from this axle's point at step 1: results of another geometry?",
        ),
        (geometry, f"{tmp_path / 'none.csv'}:0", "cannot be read"),
    ]
    out = tmp_path / "front.png"
    for g, at, message in cases:
        assert main(["draw", g, "-o", str(out), "--at", at]) == 2, at
        err = capsys.readouterr().err
        assert err.startswith("pin-susp: error: ") and err.count("\n") == 1, err
        assert message in err, err
        assert not out.exists()
    # the points check names the column that is off
    with pytest.raises(InputError) as info:
        axle_pose(AxleModel(load_axle(EXAMPLES / "axle_front.yaml")), ResultsFile(roll), 1)
    assert info.value.key.startswith(("left_", "right_")) and info.value.key[-2:] in (
        "_x",
        "_y",
        "_z",
    )
