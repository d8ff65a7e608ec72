"""The vehicle report (`pin-susp sweep VEHICLE SWEEP --plot`, `pin-susp plot`): what an
engineer reads off it, for both example cars and every example sweep.

The CSVs are read here with the csv module, not with pin_susp's reader; the x axis is
checked against the sweep file's own targets (what it moved, over what range), and each
panel's lines against the CSV's columns, a line per corner (the front solid, the rear
dashed, the left and the right a colour each) or per axle (the front solid). A picture's
panels are read off the figure the command saved it from.
"""

import csv

import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, main_saving, sweep_csv

import pin_susp
from pin_susp.cli import main
from pin_susp.plots import ResultsFile, report_figure

CARS = ("fs", "saloon")
SWEEPS = ("heave", "pitch", "roll", "warp", "steer", "combined")
CORNERS = ("fl", "fr", "rl", "rr")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def sweep_argv(car: str, sweep: str, out) -> list[str]:
    """`pin-susp sweep` of an example car through an example sweep, quietly, to ``out``."""
    argv = ["sweep", str(EXAMPLES / f"vehicle_{car}.yaml")]
    return [*argv, str(EXAMPLES / f"vehicle_{sweep}.yaml"), "-o", str(out), "-q"]


class Runs(dict):
    """(car, sweep) → its CSV, swept when a test first asks for it (a test that needs two
    of them does not wait for all twelve; each test's report is drawn where it is read)."""

    def __init__(self, folder):
        super().__init__()
        self.folder = folder

    def __missing__(self, key):
        path = self.folder / "{}_{}.csv".format(*key)
        assert main(sweep_argv(*key, path)) == 0, key
        self[key] = path
        return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each example car's CSV of each example sweep."""
    return Runs(tmp_path_factory.mktemp("vehicle_plots"))


def sweep_plot(car: str, sweep: str, folder):
    """`pin-susp sweep --plot` of an example car through an example sweep: its CSV, its
    picture and the figure the picture was saved from."""
    path, png = folder / f"{car}_{sweep}.csv", folder / f"{car}_{sweep}.png"
    code, (fig,) = main_saving([*sweep_argv(car, sweep, path), "--plot", str(png)])
    assert code == 0, (car, sweep)
    return path, png, fig


def read(path) -> dict[str, np.ndarray]:
    """A results CSV as columns of floats (empty → NaN, True/False → 1/0)."""
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))

    def number(cell: str) -> float:
        special = {"": np.nan, "True": 1.0, "False": 0.0}
        return special[cell] if cell in special else float(cell)

    texts = ("limit_exceeded",)  # columns of names (docs/results.md): left out
    return {k: np.array([number(r[k]) for r in rows]) for k in rows[0] if not k.startswith(texts)}


def lines_of(fig) -> dict[str, list]:
    """Each visible panel's lines by the panel's title."""
    return {ax.get_title(): ax.get_lines() for ax in fig.axes if ax.get_visible()}


def visible(fig) -> list:
    return [ax for ax in fig.axes if ax.get_visible()]


def same(a, b) -> None:
    np.testing.assert_array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


def moved_targets(sweep: str) -> list[tuple[str, np.ndarray]]:
    """What the example sweep file moves, its values at each step: (target, values)."""
    data = yaml.safe_load((EXAMPLES / f"vehicle_{sweep}.yaml").read_text())
    out = []
    for t in data["targets"]:
        if t["start"] != t["stop"]:
            name = t["quantity"] + (f" {t['corner']}" if "corner" in t else "")
            out.append((name, np.linspace(t["start"], t["stop"], data["steps"])))
    return out


# The contract (docs/vehicle.md, "The report"): a panel's title and its columns
PER_CORNER = {
    "Camber to ground": "camber_to_ground",
    "Camber (to the chassis)": "camber",
    "Toe: roadwheel angle (+ in)": "roadwheel_angle",
    "Wheel travel (+ bump, to the chassis)": "wheel_travel",
}
PER_AXLE = {
    "Roll centre height": "roll_center_z",
    "Roll centre lateral position (+ left)": "roll_center_y",
    "Track": "track",
    "Anti-roll bar twist (first − second corner's arm)": "arb_twist",
    "Roll stiffness": "roll_stiffness",
}
CAR = {
    "Roll axis height at the CG": ("roll_axis_height_at_cg",),
    "Roll axis inclination (+ front roll centre higher)": ("roll_axis_inclination",),
    "Pitch centre x (+ forward)": ("pitch_center_x",),
    "Pitch centre height": ("pitch_center_z",),
    "Anti geometry under braking": ("anti_dive_front", "anti_lift_rear"),
    "Anti geometry under drive": ("anti_lift_front", "anti_squat_rear"),
    "Wheelbase on the road": ("wheelbase_left", "wheelbase_right"),
}
STEER = "Steer angle (ISO yaw, + left)"
# x of a sweep that moved one thing: its column and its axis label
X = {
    "heave": ("heave", "Heave of the body at the CG (+ up) [mm]"),
    "pitch": ("pitch", "Pitch (+ nose down) [deg]"),
    "roll": ("roll", "Roll (+ right side down) [deg]"),
    "steer": ("steering_wheel_angle", "Steering wheel angle (+ turning left) [deg]"),
    "warp": ("contact_patch_road_z_fr", "Road height under fr and rl (+ up) [mm]"),
}
COMBINED_X = "Step (heave, pitch, roll and steering move together)"
LEFT, RIGHT, CAR_COLOUR = "C0", "C3", "0.15"  # one file's colours (docs/vehicle.md)


def expected_panels(columns: dict) -> dict[str, tuple[tuple[str, str, str], ...]]:
    """Each panel the CSV's values call for: (column, line style, side) per line, the
    columns with no value left out (a panel with none: no panel)."""
    out = {}
    for title, base in PER_CORNER.items():
        lines = [(f"{base}_{c}", "-" if c[0] == "f" else "--", c[1]) for c in CORNERS]
        out[title] = lines
    for title, base in PER_AXLE.items():
        out[title] = [(f"{base}_{a}", "-" if a == "front" else "--", "") for a in ("front", "rear")]
    for title, names in CAR.items():
        out[title] = [(n, "--" if n.endswith("_rear") else "-", "") for n in names]
    for title, lines in list(out.items()):
        out[title] = tuple(ln for ln in lines if np.any(np.isfinite(columns.get(ln[0], [np.nan]))))
    return {title: lines for title, lines in out.items() if lines}


@pytest.mark.parametrize("car", CARS)
@pytest.mark.parametrize("sweep", SWEEPS)
def test_each_panel_draws_its_csv_columns_against_what_the_sweep_moved(car, sweep, tmp_path):
    path, png, fig = sweep_plot(car, sweep, tmp_path)  # the figure of sweep --plot's picture
    image = matplotlib.image.imread(png)
    assert image.shape[0] > 1000 and image.shape[1] > 1500 and np.ptp(image) > 0.5
    columns = read(path)
    assert fig._suptitle.get_text() == f"pin_susp vehicle kinematics: {car}_{sweep}"
    panels = lines_of(fig)
    targets = moved_targets(sweep)
    steps = len(columns["step_index"])
    if sweep == "combined":
        xname, xlabel = "step_index", COMBINED_X
        # the inputs first, as the sweep file moved them
        inputs = visible(fig)[: len(targets)]
        assert [ax.get_title().split(": ")[1].split(" (")[0] for ax in inputs] == [
            "Heave of the body at the CG",
            "Pitch",
            "Roll",
            "Steering wheel angle",
        ]
        for ax, (_, values) in zip(inputs, targets, strict=True):
            (line,) = ax.get_lines()
            same(line.get_xdata(), np.arange(steps))
            np.testing.assert_allclose(line.get_ydata(), values, atol=1e-9)
    else:
        xname, xlabel = X[sweep]
        # the x axis is what the sweep file moved (warp: both corners' road, together)
        assert {name.split(" ")[0] for name, _ in targets} == {
            {"steer": "steering_wheel", "warp": "road_z"}.get(sweep, sweep)
        }
        np.testing.assert_allclose(columns[xname], targets[0][1], atol=1e-9)
    expected = expected_panels(columns)
    assert set(expected) <= set(panels)
    for title, lines in expected.items():
        drawn = panels[title]
        assert len(drawn) == len(lines), title
        for line, (name, style, _) in zip(drawn, lines, strict=True):
            same(line.get_xdata(), columns[xname])
            same(line.get_ydata(), columns[name])
            assert line.get_linestyle() == style, (title, name)
        if title in PER_CORNER:  # fl and rl one colour, fr and rr another, on every panel
            assert [ln.get_color() for ln in drawn] == [LEFT, RIGHT, LEFT, RIGHT], title
        elif title != "Wheelbase on the road":  # an axle's or the car's: one colour
            assert {ln.get_color() for ln in drawn} == {CAR_COLOUR}, title
        else:
            assert [ln.get_color() for ln in drawn] == [LEFT, RIGHT]
    # what the brief asked for is drawn for every car and sweep
    for title in ("Camber to ground", "Roll centre height", "Roll axis height at the CG"):
        assert title in panels
    assert {"Anti geometry under braking", "Wheelbase on the road", "Pitch centre height"} <= set(
        panels
    )
    assert len(panels["Camber to ground"]) == 4 and len(panels["Roll centre height"]) == 2
    assert (STEER in panels) == (sweep in ("steer", "combined"))
    for ax in visible(fig)[len(targets) if sweep == "combined" else 0 :]:
        assert ax.get_xlabel() == xlabel, ax.get_title()


@pytest.mark.parametrize(
    ("sweep", "along"), [("roll", "roll"), ("pitch", "pitch"), ("heave", "heave")]
)
def test_the_corners_rates_are_drawn_along_what_moved(runs, sweep, along):
    path = runs["fs", sweep]
    columns = read(path)
    panels = lines_of(report_figure([ResultsFile(path)]))
    unit = {"heave": "mm of heave", "pitch": "degree of pitch", "roll": "degree of roll"}
    for metric, title in (("camber", "Camber"), ("roadwheel_angle", "Toe")):
        for driver, words in unit.items():
            drawn = panels.get(f"{title} change per {words}")
            assert (drawn is not None) == (driver == along)
        lines = panels[f"{title} change per {unit[along]}"]
        for line, c in zip(lines, CORNERS, strict=True):
            same(line.get_ydata(), columns[f"deriv_{metric}_wrt_{along}_{c}"])
            same(line.get_xdata(), columns[along])


def test_a_warp_is_drawn_against_the_road_it_raised(runs, tmp_path):
    columns = read(runs["fs", "warp"])
    # the body held: heave, pitch and roll are not what moved
    for name in ("heave", "pitch", "roll", "rack_displacement"):
        assert np.ptp(columns[name]) < 1e-9
    fig = report_figure([ResultsFile(runs["fs", "warp"])])
    assert not [t for t in fig.texts if t.get_gid() == "combined_note"]
    (fl, fr, rl, rr) = lines_of(fig)["Wheel travel (+ bump, to the chassis)"]
    np.testing.assert_allclose(fr.get_xdata(), np.linspace(0, 20, 21), atol=1e-9)
    # the raised corners' wheels rise with the road under them, the others barely
    assert np.ptp(fr.get_ydata()) > 15 and np.ptp(rl.get_ydata()) > 15
    assert np.ptp(fl.get_ydata()) < 1 and np.ptp(rr.get_ydata()) < 1
    # two roads moved apart are two inputs: against the step, each its own panel
    sweep = tmp_path / "apart.yaml"
    data = yaml.safe_load((EXAMPLES / "vehicle_warp.yaml").read_text())
    data["steps"] = 5
    data["targets"][-1]["stop"] = -10  # the rear left's road falls as the front right's rises
    sweep.write_text(yaml.safe_dump(data))
    out = tmp_path / "apart.csv"
    assert main(["sweep", str(EXAMPLES / "vehicle_fs.yaml"), str(sweep), "-o", str(out), "-q"]) == 0
    fig = report_figure([ResultsFile(out)])
    axes = visible(fig)
    assert [ax.get_title() for ax in axes[:2]] == [
        "Input: Road height under fr (+ up)",
        "Input: Road height under rl (+ up)",
    ]
    np.testing.assert_allclose(axes[0].get_lines()[0].get_ydata(), np.linspace(0, 20, 5), atol=1e-9)
    np.testing.assert_allclose(
        axes[1].get_lines()[0].get_ydata(), np.linspace(0, -10, 5), atol=1e-9
    )
    assert {ax.get_xlabel() for ax in axes} == {
        "Step (road height (fr) and road height (rl) move together)"
    }


def test_failed_steps_leave_gaps(tmp_path, runs):
    # a heave beyond the car's reach: its last steps fail, the report is still drawn
    sweep = tmp_path / "far.yaml"
    data = yaml.safe_load((EXAMPLES / "vehicle_heave.yaml").read_text())
    data["steps"] = 9
    data["targets"][0].update(start=-60, stop=400)
    sweep.write_text(yaml.safe_dump(data))
    out, png = tmp_path / "far.csv", tmp_path / "far.png"
    argv = ["sweep", str(EXAMPLES / "vehicle_fs.yaml"), str(sweep), "-o", str(out)]
    code, (fig,) = main_saving([*argv, "--plot", str(png), "-q"])
    assert code == 1
    assert matplotlib.image.imread(png).ndim == 3
    columns = read(out)
    failed = columns["solver_converged"] == 0.0
    assert 0 < failed.sum() < 9
    panels = lines_of(fig)
    for title in ("Camber to ground", "Roll centre height", "Pitch centre height"):
        for line in panels[title]:
            y = np.asarray(line.get_ydata(), dtype=float)
            assert np.all(np.isnan(y[failed])) and np.all(np.isfinite(y[~failed]))
    # a step failed mid-sweep, written as pin_susp writes it (its cells empty): a gap
    lines = open(runs["fs", "roll"]).read().splitlines()
    k = next(j for j, ln in enumerate(lines) if ln.startswith("step_index"))
    cells = lines[k + 1 + 10].split(",")
    lines[k + 1 + 10] = ",".join(cells[:1] + ["False"] + [""] * (len(cells) - 2))
    gap = tmp_path / "gap.csv"
    gap.write_text("\n".join(lines) + "\n")
    code, (fig,) = main_saving(["plot", str(gap), "-o", str(tmp_path / "gap.png")])
    assert code == 0
    (line, *_) = lines_of(fig)["Camber to ground"]
    x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
    assert np.isnan(x[10]) and np.isnan(y[10])
    assert np.all(np.isfinite(np.delete(y, 10))) and line.get_marker() in ("None", None, "")


def test_pin_susp_plot_draws_a_vehicles_csv(runs, tmp_path, capsys):
    out = tmp_path / "roll.png"
    assert main(["plot", str(runs["fs", "roll"]), "-o", str(out)]) == 0
    assert capsys.readouterr().out == f"wrote {out}\n"
    assert matplotlib.image.imread(out).shape[2] in (3, 4)
    # two cars' rolls: a hue per file, its left dark and its right light
    fig = report_figure([ResultsFile(runs["fs", "roll"]), ResultsFile(runs["saloon", "roll"])])
    drawn = lines_of(fig)["Camber to ground"]
    assert [ln.get_label() for ln in drawn] == [
        f"{car}_roll {c}" for car in ("fs", "saloon") for c in CORNERS
    ]
    colours = [ln.get_color() for ln in drawn]
    assert colours[0] == colours[2] != colours[1] == colours[3]
    assert not set(colours[:4]) & set(colours[4:])
    same(drawn[5].get_ydata(), read(runs["saloon", "roll"])["camber_to_ground_fr"])


def test_a_vehicle_is_not_plotted_with_a_corner_an_axle_or_another_sweep(runs, tmp_path, capsys):
    vehicle = str(runs["fs", "roll"])
    corner = str(sweep_csv(tmp_path, "double_wishbone.yaml", "bump_steer.yaml", "corner.csv"))
    axle = str(sweep_csv(tmp_path, "axle_front.yaml", "roll.yaml", "axle.csv"))
    out = tmp_path / "x.png"
    for files, odd, kind in (
        ([vehicle, corner], corner, "a corner's"),
        ([corner, vehicle], corner, "a corner's"),
        ([vehicle, axle], axle, "an axle's"),
    ):
        assert main(["plot", *files, "-o", str(out)]) == 2
        assert capsys.readouterr().err == (
            f"pin-susp: error: {odd}: {kind} results, but {vehicle} is a vehicle's: "
            "plot them separately\n"
        )
        assert not out.exists()
    # a roll and a heave of the car do not share an x axis
    heave = str(runs["fs", "heave"])
    assert main(["plot", vehicle, heave, "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"pin-susp: error: {heave}: x is heave but {vehicle}'s is roll: plot them separately\n"
    )
    # an axle is not drawn at a vehicle's step
    argv = ["draw", str(EXAMPLES / "axle_front.yaml"), "-o", str(out)]
    assert main([*argv, "--from-results", f"{vehicle}:3"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pin-susp: error: {vehicle}: a vehicle's results: an axle is drawn at a step of its own\n"
    )
    assert not out.exists()


def test_an_attitudes_csv_is_pointed_to_its_own_plot(tmp_path, capsys):
    accelerations = tmp_path / "a.yaml"
    accelerations.write_text("version: 1\naccelerations:\n  - {ax: 0, ay: 0.5}\n")
    attitude = tmp_path / "attitude.csv"
    argv = ["attitude", str(EXAMPLES / "vehicle_fs.yaml"), str(accelerations)]
    assert main([*argv, "-o", str(attitude), "-q"]) == 0
    out = tmp_path / "x.png"
    assert main(["plot", str(attitude), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "an attitude's results" in err and "pin-susp attitude --plot" in err
    assert err.count("\n") == 1 and not out.exists()


def test_results_plot_draws_the_vehicle_report(tmp_path):
    sweep = tmp_path / "roll.yaml"
    data = yaml.safe_load((EXAMPLES / "vehicle_roll.yaml").read_text())
    data["steps"] = 5
    sweep.write_text(yaml.safe_dump(data))
    results = pin_susp.Vehicle(EXAMPLES / "vehicle_fs.yaml").run_sweep(sweep)
    out = tmp_path / "roll.png"
    results.plot(out)
    assert matplotlib.image.imread(out).ndim == 3


def test_the_fs_cars_roll_in_docs_vehicle_md(runs):
    """docs/vehicle.md's reading of the report's picture, at 2 deg of roll (step 20)."""
    columns = read(runs["fs", "roll"])
    assert columns["roll"][20] == pytest.approx(2.0)
    told = {
        "camber_to_ground_fr": (-0.40, 0.005),  # the outer front wheel
        "camber_to_ground_fl": (-3.45, 0.005),
        "roll_center_z_front": (8.4, 0.05),
        "roll_center_z_rear": (30.4, 0.05),
        "roll_axis_height_at_cg": (18.7, 0.05),
        "roll_center_y_front": (583, 0.5),
        "arb_twist_front": (20.2, 0.05),
        "arb_twist_rear": (23.2, 0.05),
    }
    for name, (value, within) in told.items():
        assert abs(columns[name][20] - value) <= within, name
    assert columns["camber_to_ground_fr"][10] == pytest.approx(-1.91, abs=0.005)
    for side in ("left", "right"):
        assert 0.4 < abs(columns[f"wheelbase_{side}"][20] - columns[f"wheelbase_{side}"][10]) < 0.7
