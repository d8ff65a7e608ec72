"""The report's x axis and the drawing: what an engineer reads off them.

Every check compares with a number worked out here from the input files, not
with what pin_susp computed: the instant centres by solving the two wishbone
planes and the view plane with numpy, the rack travel from the sweep file.
"""

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored

import pin_susp
from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.plots import ResultsFile, report_figure
from pin_susp.viz.drawing import PARALLEL, drawing_figure

ARMS = ("upper_wishbone", "lower_wishbone")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def sweep_file(tmp_path, name: str, wheel: float, rack: float, steps: int = 11) -> str:
    """A sweep from −value to +value of the wheel centre z and the rack (mm)."""
    path = tmp_path / name
    path.write_text(
        f"steps: {steps}\ntargets:\n"
        f"  - {{point: wheel_center, direction: {{axis: z}}, start: {-wheel}, stop: {wheel}}}\n"
        f"  - {{point: trackrod_inboard, direction: {{axis: y}}, start: {-rack}, stop: {rack}}}\n"
    )
    return str(path)


def results(tmp_path, name: str, wheel: float, rack: float) -> str:
    """`pin-susp sweep` of the double wishbone example; the CSV's path."""
    geometry = str(EXAMPLES / "double_wishbone.yaml")
    out = tmp_path / name
    sweep = sweep_file(tmp_path, name.replace(".csv", ".yaml"), wheel, rack)
    assert main(["sweep", geometry, sweep, "-o", str(out), "-q"]) == 0
    return str(out)


def set_rack_column(path: str, design_y: float | None) -> None:
    """Give the CSV a ``rack_displacement`` column (trackrod_inboard_y − design_y), or
    take it away (``design_y`` None: a file written before the column existed)."""
    lines = open(path).read().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    rows = [ln.split(",") for ln in lines if not ln.startswith("#")]
    header = rows[0]
    if "rack_displacement" in header:
        k = header.index("rack_displacement")
        rows = [r[:k] + r[k + 1 :] for r in rows]
        header = rows[0]
    if design_y is not None:
        y = header.index("trackrod_inboard_y")
        rows = [rows[0] + ["rack_displacement"]] + [
            r + [repr(float(r[y]) - design_y)] for r in rows[1:]
        ]
    open(path, "w").write("\n".join(comments + [",".join(r) for r in rows]) + "\n")


# --- the report's x axis ------------------------------------------------------------------------


def test_a_bump_and_a_steer_sweep_are_not_drawn_on_one_x_axis(tmp_path, capsys):
    steer = results(tmp_path, "steer.csv", wheel=0, rack=10)
    bump = results(tmp_path, "bump.csv", wheel=30, rack=0)
    with pytest.raises(InputError) as info:
        report_figure([ResultsFile(steer), ResultsFile(bump)])
    expected = f"{bump}: x is wheel travel but {steer}'s is rack travel: plot them separately"
    assert str(info.value) == expected
    assert main(["plot", steer, bump, "-o", str(tmp_path / "x.png")]) == 2
    out, err = capsys.readouterr()
    assert err == f"pin-susp: error: {expected}\n"
    assert not (tmp_path / "x.png").exists()
    # the same kind of sweep twice still overlays, one line each
    fig = report_figure([ResultsFile(bump), ResultsFile(bump, name="again.csv")])
    assert len(fig.axes[0].get_lines()) == 2


def test_a_steer_sweep_is_drawn_against_rack_travel_from_centre(tmp_path):
    steer = results(tmp_path, "steer.csv", wheel=0, rack=10)
    design_y = example("double_wishbone.yaml")["hardpoints"]["trackrod_inboard"]["y"]
    set_rack_column(steer, design_y)
    fig = report_figure([ResultsFile(steer)])
    camber = fig.axes[0]
    assert camber.get_xlabel() == "Rack position from centre (+ left) [mm]"
    x = np.asarray(camber.get_lines()[0].get_xdata())
    np.testing.assert_allclose(x, np.linspace(-10, 10, 11), atol=1e-9)


def test_an_old_steer_sweep_without_rack_displacement_says_absolute(tmp_path):
    steer = results(tmp_path, "steer.csv", wheel=0, rack=10)
    set_rack_column(steer, None)
    fig = report_figure([ResultsFile(steer)])
    assert fig.axes[0].get_xlabel() == "Rack position: trackrod inboard y (absolute) [mm]"
    x = np.asarray(fig.axes[0].get_lines()[0].get_xdata())
    np.testing.assert_allclose(x, np.linspace(190, 210, 11), atol=1e-9)


# --- the drawing --------------------------------------------------------------------------------


def geometry_file(tmp_path, geometry: dict, name: str = "g.yaml") -> str:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(geometry))
    return str(path)


def lines(ax, gid: str) -> list:
    return [ln for ln in ax.get_lines() if ln.get_gid() == gid]


def notes(ax) -> list[str]:
    return [t.get_text() for t in ax.texts if t.get_gid() == "ic_note"]


def wheel_centre(g: dict) -> np.ndarray:
    """wheel_center = axle_outboard − offset·â (mm), from the file."""
    hp = g["hardpoints"]
    inner, outer = (
        np.array([hp[n][k] for k in "xyz"], float) for n in ("axle_inboard", "axle_outboard")
    )
    a = (outer - inner) / np.linalg.norm(outer - inner)
    return outer - g["config"]["wheel"].get("offset", 0) * a


def instant_centre(g: dict, axis: int) -> np.ndarray:
    """The two wishbone planes and the plane through the wheel centre normal to ``axis``
    (0: front view, x = WC_x; 1: side view, y = WC_y) solved as one 3×3 system (mm)."""
    hp = {n: np.array([p[k] for k in "xyz"], float) for n, p in g["hardpoints"].items()}
    rows, rhs = [], []
    for arm in ARMS:
        front = hp[f"{arm}_inboard_front"]
        n = np.cross(hp[f"{arm}_inboard_rear"] - front, hp[f"{arm}_outboard"] - front)
        rows.append(n)
        rhs.append(n @ front)
    rows.append(np.eye(3)[axis])
    rhs.append(wheel_centre(g)[axis])
    return np.linalg.solve(np.array(rows), np.array(rhs))


def converging(side: str = "left") -> dict:
    """The double-wishbone example with arms that meet: upper pivots lowered, the lower
    arm's rear pivot raised (the example's arms are all level: parallel planes)."""
    g = example("double_wishbone.yaml")
    for n in ("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear"):
        g["hardpoints"][n]["z"] = 460
    g["hardpoints"]["lower_wishbone_inboard_rear"]["z"] = 215
    return g if side == "left" else mirrored(g)


@pytest.mark.parametrize("side", ["left", "right"])
def test_instant_centres_are_drawn_where_the_arm_planes_meet(tmp_path, side):
    g = converging(side)
    fig = drawing_figure(pin_susp.Corner(geometry_file(tmp_path, g)))
    front, side_view = fig.axes
    fvic, svic = instant_centre(g, 0), instant_centre(g, 1)
    assert np.linalg.norm(fvic - wheel_centre(g)) < 20_000  # drawn, not noted
    assert np.linalg.norm(svic - wheel_centre(g)) < 20_000
    for ax, ic, view, gid in (
        (front, fvic, [1, 2], "fvic_arm"),
        (side_view, svic, [0, 2], "svic_arm"),
    ):
        arms = lines(ax, gid)
        assert len(arms) == 2  # from each ball joint
        for arm, joint in zip(arms, ARMS, strict=True):
            start, end = np.column_stack([arm.get_xdata(), arm.get_ydata()])
            p = g["hardpoints"][f"{joint}_outboard"]
            np.testing.assert_allclose(
                start, [[p["x"], p["y"], p["z"]][k] for k in view], atol=1e-6
            )
            np.testing.assert_allclose(end, ic[view], atol=1e-6)
    # the contact patch → FVIC line meets the centreline at the roll centre
    (rc,) = lines(front, "roll_centre")
    rc = np.array([rc.get_xdata()[0], rc.get_ydata()[0]])
    assert rc[0] == pytest.approx(0.0, abs=1e-9)
    (cp_line,) = lines(front, "fvic_contact_patch")
    ends = np.column_stack([cp_line.get_xdata(), cp_line.get_ydata()])
    d = fvic[[1, 2]] - ends[0]
    for q in (rc, ends[1]):  # on the line CP → FVIC: zero cross product
        e = q - ends[0]
        assert abs(d[0] * e[1] - d[1] * e[0]) < 1e-6 * np.linalg.norm(d)
    assert any("RC (symmetric axle)" in t.get_text() for t in front.texts)
    assert front.xaxis_inverted() == (side == "right")  # outboard to the left on a right corner
    # the view is the corner, not the far instant centre
    for ax in fig.axes:
        assert all(abs(v) < 3000 for v in (*ax.get_xlim(), *ax.get_ylim()))


def level_arms(g: dict) -> dict:
    """Each arm's three points at one height: both arm planes horizontal, parallel."""
    for arm in ARMS:
        z = g["hardpoints"][f"{arm}_outboard"]["z"]
        for end in ("inboard_front", "inboard_rear", "outboard"):
            g["hardpoints"][f"{arm}_{end}"]["z"] = z
    return g


def test_parallel_arms_draw_no_instant_centre_and_keep_the_view(tmp_path):
    g = example("fixed_toe_link.yaml")
    assert lines(
        drawing_figure(pin_susp.Corner(EXAMPLES / "fixed_toe_link.yaml")).axes[0], "fvic_arm"
    )
    g = level_arms(g)
    with pytest.raises(np.linalg.LinAlgError):
        instant_centre(g, 0)  # the planes do not meet
    fig = drawing_figure(pin_susp.Corner(geometry_file(tmp_path, g)))
    for ax in fig.axes:
        gids = {ln.get_gid() for ln in ax.get_lines()}
        assert not gids & {"fvic_arm", "svic_arm", "fvic_contact_patch", "svic_contact_patch"}
        assert notes(ax) == [PARALLEL]
        assert all(abs(v) < 3000 for v in (*ax.get_xlim(), *ax.get_ylim()))


def test_a_far_instant_centre_is_noted_not_drawn():
    # the camber shim tilts the upper arm a little: the FVIC is 24 m away
    fig = drawing_figure(pin_susp.Corner(EXAMPLES / "camber_shim.yaml"))
    front = fig.axes[0]
    assert not lines(front, "fvic_arm")
    (note,) = notes(front)
    assert note.startswith("arms nearly parallel: FVIC") and "m away, not drawn" in note
    for ax in fig.axes:
        assert all(abs(v) < 3000 for v in (*ax.get_xlim(), *ax.get_ylim()))


def test_hardpoint_labels_and_legend_only_when_asked():
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    plain = drawing_figure(corner)
    assert not [t for ax in plain.axes for t in ax.texts if t.get_gid() == "point_label"]
    assert not plain.legends
    fig = drawing_figure(corner, labels=True)
    for ax in fig.axes:
        text = "\n".join(t.get_text() for t in ax.texts if t.get_gid() == "point_label")
        assert set(text.split("\n")) == set(corner.geometry.hardpoints)  # each once
    (legend,) = fig.legends
    names = [t.get_text() for t in legend.get_texts()]
    assert {"wishbone", "upright", "rocker", "pushrod", "coilover", "trackrod", "tyre"} <= set(
        names
    )


def test_labels_on_a_crowded_row_do_not_overlap():
    fig = drawing_figure(pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml"), labels=True)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        boxes = [t.get_window_extent(renderer) for t in ax.texts if t.get_gid() == "point_label"]
        for i, a in enumerate(boxes):
            for b in boxes[i + 1 :]:
                assert not a.overlaps(b), (a, b)


def tilted(camber_deg: float) -> dict:
    """The double-wishbone example with the axle tilted to this camber (top inboard < 0)."""
    g = example("double_wishbone.yaml")
    hp = g["hardpoints"]
    run = hp["axle_outboard"]["y"] - hp["axle_inboard"]["y"]
    hp["axle_outboard"]["z"] = hp["axle_inboard"]["z"] - run * float(np.tan(np.radians(camber_deg)))
    return g


@pytest.mark.parametrize("side", ["left", "right"])
def test_a_cambered_tyre_stays_on_the_road(tmp_path, side):
    g = tilted(-3.0)
    g = g if side == "left" else mirrored(g)
    corner = pin_susp.Corner(geometry_file(tmp_path, g))
    a = corner.design_positions["axle_outboard"] - corner.design_positions["axle_inboard"]
    assert np.degrees(-np.arctan2(a[2], corner.geometry.sign * a[1])) == pytest.approx(-3.0)
    ground = corner.design_positions["contact_patch_center"][2] * 1e3
    fig = drawing_figure(corner)
    width = 270 * np.cos(np.radians(3))  # section width, seen from the front
    for ax, across in zip(fig.axes, (width, 2 * 313.6), strict=True):
        (tyre,) = lines(ax, "tyre")
        x, z = np.asarray(tyre.get_xdata()), np.asarray(tyre.get_ydata())
        assert z.min() >= ground - 1e-6  # nothing under the road
        assert z.min() == pytest.approx(ground, abs=1e-6)  # and it stands on it
        assert np.ptp(x) > across - 1.0  # the whole tyre, not a sliver


# --- what the report reads as (issue 24: colours, combined sweeps, noise, columns) ---------------


def swept(tmp_path, geometry: str, targets: str, name: str, steps: int = 5) -> str:
    """`pin-susp sweep` of an example with these target lines (YAML); the CSV's path."""
    sweep = tmp_path / name.replace(".csv", ".yaml")
    sweep.write_text(f"steps: {steps}\ntargets:\n{targets}")
    out = tmp_path / name
    assert main(["sweep", str(EXAMPLES / geometry), str(sweep), "-o", str(out), "-q"]) == 0
    return str(out)


def bump(wheel=(-30, 30), rack=(0, 0)) -> str:
    lines = (
        f"  - {{point: wheel_center, direction: {{axis: z}}, "
        f"start: {wheel[0]}, stop: {wheel[1]}}}\n"
    )
    if rack is not None:
        lines += (
            f"  - {{point: trackrod_inboard, direction: {{axis: y}}, "
            f"start: {rack[0]}, stop: {rack[1]}}}\n"
        )
    return lines


def read_columns(path) -> dict[str, np.ndarray]:
    """A results CSV read with the csv module: columns of floats (empty → NaN)."""
    import csv

    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    cell = lambda c: {"": np.nan, "True": 1.0, "False": 0.0}.get(c, None)  # noqa: E731
    return {
        k: np.array([float(r[k]) if cell(r[k]) is None else cell(r[k]) for r in rows])
        for k in rows[0]
    }


def visible(fig) -> list:
    return [ax for ax in fig.axes if ax.get_visible()]


def test_each_file_keeps_one_colour_on_every_panel_and_one_legend_entry(tmp_path):
    files = [
        swept(tmp_path, "double_wishbone.yaml", bump(), "a.csv"),
        swept(tmp_path, "multilink_rear.yaml", bump(rack=None), "multilink_rear.csv"),
        swept(tmp_path, "pushrod_rocker.yaml", bump(), "rocker.csv"),
    ]
    fig = report_figure([ResultsFile(f) for f in files])
    colours: dict[str, set] = {}
    for ax in visible(fig):
        for line in ax.get_lines():
            colours.setdefault(line.get_label(), set()).add(line.get_color())
    assert set(colours) == {"a", "multilink_rear", "rocker"}
    assert all(len(c) == 1 for c in colours.values()), colours  # one colour each, everywhere
    assert len({c for cs in colours.values() for c in cs}) == 3  # and three of them
    rocker = next(ax for ax in visible(fig) if ax.get_title() == "Rocker angle")
    (line,) = rocker.get_lines()  # only rocker.csv has a rocker: in rocker's colour, not a's
    assert line.get_label() == "rocker" and {line.get_color()} == colours["rocker"]
    (legend,) = fig.legends  # one legend of the files, each once, in its colour
    assert [t.get_text() for t in legend.get_texts()] == ["a", "multilink_rear", "rocker"]
    for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True):
        assert {handle.get_color()} == colours[text.get_text()]


def test_a_combined_sweep_is_drawn_against_the_step_with_its_inputs(tmp_path, capsys):
    path = swept(tmp_path, "double_wishbone.yaml", bump((-40, 60), (-10, 10)), "both.csv")
    fig = report_figure([ResultsFile(path)])
    axes = visible(fig)
    steps = np.arange(5.0)
    # the inputs first, as the sweep file moved them (linear in the step)
    wheel, rack = axes[:2]
    assert wheel.get_title() == "Input: Wheel travel (+ bump)"
    assert rack.get_title() == "Input: Rack position from centre (+ left)"
    for ax, (start, stop) in ((wheel, (-40, 60)), (rack, (-10, 10))):
        (line,) = ax.get_lines()
        np.testing.assert_allclose(line.get_xdata(), steps)
        np.testing.assert_allclose(line.get_ydata(), np.linspace(start, stop, 5), atol=1e-9)
    for ax in axes:  # every panel against the step, none against wheel travel
        assert ax.get_xlabel() == "Step (wheel travel and rack travel move together)"
        for line in ax.get_lines():
            np.testing.assert_array_equal(line.get_xdata(), steps)
    titles = [ax.get_title() for ax in axes]
    assert "Camber" in titles
    assert {"d Camber / d hub z", "d Camber / d rack"} <= set(titles)  # gains along each
    (note,) = [t.get_text() for t in fig.texts if t.get_gid() == "combined_note"]
    assert note.startswith(
        "A combined sweep: wheel travel -40 → 60 mm and rack travel -10 → 10 mm move together"
    )
    # a pure bump (the rack held) stays against wheel travel, with no input panel
    held = report_figure([ResultsFile(swept(tmp_path, "double_wishbone.yaml", bump(), "b.csv"))])
    assert visible(held)[0].get_title() == "Camber"
    assert {ax.get_xlabel() for ax in visible(held)} == {"Wheel travel (+ bump) [mm]"}
    assert not [t for t in held.texts if t.get_gid() == "combined_note"]
    # a combined and a pure bump sweep do not share an x axis
    assert main(["plot", path, str(tmp_path / "b.csv"), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pin-susp: error: {tmp_path / 'b.csv'}: x is wheel travel but {path}'s is "
        "wheel travel and rack travel: plot them separately\n"
    )


def test_an_axle_rolled_while_it_steers_is_drawn_against_the_step(tmp_path):
    targets = (
        "  - {quantity: roll, start: -2, stop: 2}\n"
        "  - {quantity: heave, start: 0, stop: 0}\n"
        "  - {point: trackrod_inboard, side: left, direction: {axis: y}, start: -20, stop: 20}\n"
    )
    fig = report_figure([ResultsFile(swept(tmp_path, "axle_front.yaml", targets, "rs.csv"))])
    axes = visible(fig)
    assert [ax.get_title() for ax in axes[:2]] == [
        "Input: Roll (+ left wheel up relative to the chassis)",
        "Input: Rack position from centre (+ left)",
    ]
    np.testing.assert_allclose(axes[0].get_lines()[0].get_ydata(), np.linspace(-2, 2, 5))
    for ax in axes:
        if ax.get_title() != "Ackermann":  # read against the mean steer angle, as ever
            assert ax.get_xlabel() == "Step (roll and rack travel move together)"


def test_noise_is_drawn_flat_and_a_constant_column_is_labelled(tmp_path):
    """A heave of a mirrored axle: the roll centre stays on the centreline and the bar
    does not twist, to rounding; drawn flat about the value, not blown up."""
    targets = (
        "  - {quantity: roll, start: 0, stop: 0}\n"
        "  - {quantity: heave, start: -20, stop: 20}\n"
        "  - {point: trackrod_inboard, side: left, direction: {axis: y}, start: 0, stop: 0}\n"
    )
    path = swept(tmp_path, "axle_front.yaml", targets, "heave.csv")
    columns = read_columns(path)
    by_title = {ax.get_title(): ax for ax in visible(report_figure([ResultsFile(path)]))}
    for title, name, unit, least in (
        ("Roll centre lateral position (+ left)", "roll_center_y", "mm", 0.5),
        ("Anti-roll bar twist (left − right arm)", "arb_twist", "deg", 0.05),
    ):
        values = columns[name][np.isfinite(columns[name])]
        assert 0 < np.ptp(values) < 1e-9 and abs(values).max() < 1e-9  # noise about zero
        ax = by_title[title]
        lo, hi = ax.get_ylim()
        assert hi - lo >= least and lo < values.min() and values.max() < hi
        assert abs(0.5 * (lo + hi)) < 1e-9  # centred on the value
        notes = [t.get_text() for t in ax.texts if t.get_gid() == "constant_note"]
        decimals = {"mm": 2, "deg": 3}[unit]
        assert notes == [f"constant {0:.{decimals}f} {unit}"]
    # a column that varies, a little (0.05 mm) or a lot: drawn as it is, not labelled
    results = ResultsFile(swept(tmp_path, "double_wishbone.yaml", bump(), "bump.csv"))
    wiggle = -39.5 + 0.025 * np.sin(np.arange(5.0) * 2.0)
    results.columns["scrub_radius"] = wiggle
    by_title = {ax.get_title(): ax for ax in visible(report_figure([results]))}
    scrub = by_title["Scrub radius"]
    lo, hi = scrub.get_ylim()
    assert hi - lo == pytest.approx(0.55) and 0.5 * (lo + hi) == pytest.approx(
        np.mean([wiggle.min(), wiggle.max()])
    )
    np.testing.assert_array_equal(scrub.get_lines()[0].get_ydata(), wiggle)
    assert not [t for t in scrub.texts if t.get_gid() == "constant_note"]
    camber = by_title["Camber"]
    span = np.ptp(results["camber"])
    assert span > 0.05 and np.ptp(camber.get_ylim()) < 1.2 * span  # autoscaled to the data


def test_the_report_draws_the_rates_and_ic_heights_the_results_hold(tmp_path):
    path = swept(tmp_path, "pushrod_rocker.yaml", bump(), "rocker.csv")
    columns = read_columns(path)
    by_ylabel = {ax.get_ylabel(): ax for ax in visible(report_figure([ResultsFile(path)]))}
    for name, unit in (
        ("spring_force", "N"),
        ("wheel_rate", "N/mm"),
        ("ride_rate", "N/mm"),
        ("fvic_z", "mm"),
        ("svic_z", "mm"),
        ("motion_ratio", "mm/mm"),
    ):
        assert np.any(np.isfinite(columns[name])), name  # the results hold it
        (line,) = by_ylabel[f"{name} [{unit}]"].get_lines()
        np.testing.assert_array_equal(line.get_ydata(), columns[name])
    # an axle with its rates: per side, and the axle's own
    g = example("axle_front.yaml")
    g["axle_config"]["spring"] = {"type": "coilover", "rate": 100, "preload": 2000}
    g["axle_config"]["anti_roll"]["stiffness"] = 300
    geometry = geometry_file(tmp_path, g, "axle.yaml")
    sweep = tmp_path / "roll.yaml"
    sweep.write_text(
        "steps: 5\ntargets:\n  - {quantity: roll, start: -2, stop: 2}\n"
        "  - {quantity: heave, start: 0, stop: 0}\n"
        "  - {point: trackrod_inboard, side: left, direction: {axis: y}, start: 0, stop: 0}\n"
    )
    out = tmp_path / "axle.csv"
    assert main(["sweep", geometry, str(sweep), "-o", str(out), "-q"]) == 0
    columns = read_columns(out)
    panels = {ax.get_title(): ax for ax in visible(report_figure([ResultsFile(out)]))}
    for title, names in (
        ("Roll centre height", ["roll_center_z"]),
        ("Front-view IC height", ["fvic_z_left", "fvic_z_right"]),
        ("Side-view IC height", ["svic_z_left", "svic_z_right"]),
        ("Spring force (compression +)", ["spring_force_left", "spring_force_right"]),
        ("Wheel rate", ["wheel_rate_left", "wheel_rate_right"]),
        ("Roll stiffness", ["roll_stiffness"]),
        ("Anti-roll bar wheel rate", ["arb_wheel_rate"]),
    ):
        lines = panels[title].get_lines()
        assert len(lines) == len(names), title
        for line, name in zip(lines, names, strict=True):
            assert np.any(np.isfinite(columns[name])), name
            np.testing.assert_array_equal(line.get_ydata(), columns[name])


@pytest.mark.parametrize("where", ["camber", "wheel_travel"])
def test_a_cell_no_axis_can_hold_is_one_line(tmp_path, capsys, where):
    path = swept(tmp_path, "double_wishbone.yaml", bump(), "r.csv")
    lines = open(path).read().splitlines()
    header = next(ln for ln in lines if not ln.startswith("#")).split(",")
    k, first = header.index(where), lines.index(",".join(header)) + 1
    for i in range(first, len(lines)):  # ±1e308, alternating: a span past the float range
        cells = lines[i].split(",")
        cells[k] = "1e308" if i % 2 else "-1e308"
        lines[i] = ",".join(cells)
    open(path, "w").write("\n".join(lines) + "\n")
    png = tmp_path / "o.png"
    assert main(["plot", path, "-o", str(png)]) == 2
    out, err = capsys.readouterr()
    sign = "1e+308" if first % 2 else "-1e+308"
    assert err == (
        f"pin-susp: error: {path}: {where}: line {first + 1}: {sign}: beyond ±1e+300 no plot "
        "axis can hold it (pin_susp writes nothing that large: a damaged or hand-edited file)\n"
    )
    assert out == "" and not png.exists()
