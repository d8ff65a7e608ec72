"""Hostile files: results CSVs for plot, image names, MJCF for validate, MuJoCo's noise.

Every mistake is one PinSuspError line naming the file and what is wrong;
nothing is written outside tmp_path (MuJoCo's MUJOCO_LOG.TXT included).
"""

import ctypes
import json

import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pytest
from conftest import EXAMPLES, example, sweep_csv

import pin_susp
from pin_susp.cli import main
from pin_susp.errors import InputError, PinSuspError
from pin_susp.model.mjcf import check_mjcf, tree_to_mjcf
from pin_susp.plots import ResultsFile, check_image_path, report_figure, save_figure
from pin_susp.validate import validate


@pytest.fixture(autouse=True)
def _in_tmp_path(tmp_path, monkeypatch):
    """Run in tmp_path: a stray MUJOCO_LOG.TXT or image would land there, not in the checkout."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="module")
def results_csv(tmp_path_factory):
    """A real results CSV (fixed toe link, bump): its comment lines, header and rows."""
    path = sweep_csv(tmp_path_factory.mktemp("csv"), "fixed_toe_link.yaml", "bump.yaml")
    lines = path.read_text().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    rows = [ln for ln in lines if not ln.startswith("#")]
    return comments, rows[0], rows[1:]


def write(tmp_path, name, content) -> str:
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return str(path)


def results_error(path) -> str:
    with pytest.raises(InputError) as info:
        ResultsFile(path)
    return str(info.value)


def one_error_line(capsys, argv) -> str:
    """Run the CLI: exit code 2, nothing on stdout, exactly one line on stderr."""
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    return err


# --- A. results CSVs for pin-susp plot ----------------------------------------------------------


def test_binary_csv(tmp_path, capsys):
    path = write(tmp_path, "r.csv", b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe step_index")
    assert results_error(path) == f"{path}: is not a text file: not a pin_susp results CSV"
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "out.png")])
    assert err == f"pin-susp: error: {path}: is not a text file: not a pin_susp results CSV\n"
    assert not (tmp_path / "out.png").exists()


def test_zero_byte_csv(tmp_path, capsys):
    path = write(tmp_path, "r.csv", b"")
    assert results_error(path) == f"{path}: is empty: not a pin_susp results CSV"
    assert "r.csv: is empty" in one_error_line(
        capsys, ["plot", path, "-o", str(tmp_path / "o.png")]
    )


def test_header_only_csv(tmp_path, results_csv, capsys):
    comments, header, _ = results_csv
    path = write(tmp_path, "r.csv", "\n".join([*comments, header]) + "\n")
    assert results_error(path) == f"{path}: no data rows (only a header)"
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "o.png")])
    assert "r.csv: no data rows (only a header)" in err


@pytest.mark.parametrize(
    ("units", "problem"),
    [
        ('{"camber": "deg"', "# units: not valid JSON"),
        ("not json at all", "# units: not valid JSON"),
        ('["deg", "mm"]', "# units: expected a JSON object, got list"),
        ('{"camber": 1}', "# units: camber: expected a unit string, got 1"),
    ],
    ids=["truncated", "garbage", "a list", "a number"],
)
def test_corrupt_units_line(tmp_path, results_csv, capsys, units, problem):
    comments, header, rows = results_csv
    comments = [c if not c.startswith("# units:") else f"# units: {units}" for c in comments]
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *rows]) + "\n")
    assert results_error(path).startswith(f"{path}: {problem}")
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "o.png")])
    assert f"r.csv: {problem}" in err


def test_every_data_cell_empty(tmp_path, results_csv, capsys):
    comments, header, rows = results_csv
    empty = ",".join([""] * len(header.split(",")))
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, empty, empty]) + "\n")
    assert results_error(path) == f"{path}: no numbers in it: every data cell is empty"
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "o.png")])
    assert "r.csv: no numbers in it: every data cell is empty" in err


def test_no_step_converged(tmp_path, results_csv):
    comments, header, rows = results_csv
    names = header.split(",")
    failed = [
        ",".join(
            str(i) if n == "step_index" else "False" if n == "solver_converged" else ""
            for n in names
        )
        for i in range(3)
    ]
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *failed]) + "\n")
    assert results_error(path) == f"{path}: no step of this sweep converged: nothing to plot"


@pytest.mark.parametrize("change", [-1, +1], ids=["short row", "long row"])
def test_ragged_rows(tmp_path, results_csv, capsys, change):
    comments, header, rows = results_csv
    cells = rows[3].split(",")
    rows = [*rows[:3], ",".join(cells[:-1] if change < 0 else [*cells, "1.0"]), *rows[4:]]
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *rows]) + "\n")
    n = len(cells)
    line = len(comments) + 1 + 4  # comments, header, then the fourth data row
    assert results_error(path) == (
        f"{path}: line {line}: {n + change} cells, but the header has {n} columns "
        "(a damaged or hand-edited file)"
    )
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "o.png")])
    assert f"r.csv: line {line}: {n + change} cells" in err


def test_a_column_twice(tmp_path, results_csv):
    comments, header, rows = results_csv
    path = write(tmp_path, "r.csv", "\n".join([header + ",camber", *(r + ",1" for r in rows)]))
    assert results_error(path) == f"{path}: camber: this column appears twice in the header"


def test_empty_columns_are_plotted_around(tmp_path, results_csv):
    """Some columns wholly empty (and some cells): usable, plotted without them."""
    comments, header, rows = results_csv
    names = header.split(",")
    blank = {names.index(n) for n in ("caster", "kpi", "scrub_radius")}
    cut = [
        ",".join(
            "" if j in blank or (i == 5 and n == "camber") else c
            for j, (n, c) in enumerate(zip(names, r.split(","), strict=True))
        )
        for i, r in enumerate(rows)
    ]
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *cut]) + "\n")
    results = ResultsFile(path)
    assert np.isnan(results["camber"][5]) and np.all(np.isnan(results["caster"]))
    fig = report_figure([results])
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible()]
    assert "Camber" in titles and "Caster" not in titles and "Kingpin inclination" not in titles
    out = tmp_path / "o.png"
    save_figure(fig, out)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_report_of_a_single_row(tmp_path, results_csv):
    comments, header, rows = results_csv
    path = write(tmp_path, "one.csv", "\n".join([*comments, header, rows[10]]) + "\n")
    fig = report_figure([ResultsFile(path)])
    camber = next(ax for ax in fig.axes if ax.get_title() == "Camber")
    (line,) = camber.get_lines()
    assert line.get_marker() == "o"  # one point: a dot, not an invisible line
    assert camber.get_xlabel().startswith("Wheel travel")
    save_figure(fig, tmp_path / "one.png")
    assert (tmp_path / "one.png").stat().st_size > 1000


def test_report_of_results_without_any_metric_value(tmp_path, results_csv, capsys):
    """Only the bookkeeping and the x axis have numbers: nothing to draw, said so."""
    comments, header, rows = results_csv
    names = header.split(",")
    keep = {"step_index", "solver_converged", "wheel_travel"}
    bare = [
        ",".join(c if n in keep else "" for n, c in zip(names, r.split(","), strict=True))
        for r in rows
    ]
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *bare]) + "\n")
    with pytest.raises(InputError, match="r.csv: no metric column has a value to plot"):
        report_figure([ResultsFile(path)])
    err = one_error_line(capsys, ["plot", path, "-o", str(tmp_path / "o.png")])
    assert "r.csv: no metric column has a value to plot" in err
    with pytest.raises(PinSuspError, match="no results file"):
        report_figure([])


def test_units_line_is_still_read(tmp_path, results_csv):
    comments, header, rows = results_csv
    path = write(tmp_path, "r.csv", "\n".join([*comments, header, *rows]) + "\n")
    units = json.loads(next(c for c in comments if c.startswith("# units:"))[8:])
    assert ResultsFile(path).units == units


def test_results_of_another_kind_of_sweep(tmp_path, results_csv):
    """A steer sweep (plotted against the rack) with a corner that has no rack."""
    steer = tmp_path / "steer.yaml"
    steer.write_text(
        "steps: 5\ntargets:\n"
        "  - {point: wheel_center, direction: {axis: z}, start: 0, stop: 0}\n"
        "  - {point: trackrod_inboard, direction: {axis: y}, start: -10, stop: 10}\n"
    )
    out = tmp_path / "steer.csv"
    assert (
        main(["sweep", str(EXAMPLES / "double_wishbone.yaml"), str(steer), "-o", str(out), "-q"])
        == 0
    )
    comments, header, rows = results_csv
    rear = write(tmp_path, "rear.csv", "\n".join([*comments, header, *rows]) + "\n")
    with pytest.raises(InputError) as info:
        report_figure([ResultsFile(out), ResultsFile(rear)])
    assert str(info.value) == (
        f"{rear}: x is wheel travel but {out}'s is rack travel: plot them separately"
    )


def test_results_file_named_otherwise(tmp_path, results_csv):
    """Read from a staging file, named (in messages and the legend) as its destination."""
    comments, header, _ = results_csv
    staging = write(tmp_path, ".tmp123", "\n".join([*comments, header]) + "\n")
    with pytest.raises(InputError) as info:
        ResultsFile(staging, name="out/r.csv")
    assert str(info.value) == "out/r.csv: no data rows (only a header)"
    comments, header, rows = results_csv
    staging = write(tmp_path, ".tmp456", "\n".join([*comments, header, *rows]) + "\n")
    assert ResultsFile(staging, name="out/r.csv").label == "r"


# --- B. image file names ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("OUT.xyz", "OUT.xyz: unsupported image format 'xyz' (use png, pdf, svg, ...)"),
        ("out", "out: no file ending to tell the image format (use png, pdf, svg, ...)"),
        ("out.", "out.: no file ending to tell the image format (use png, pdf, svg, ...)"),
        ("report.csv", "report.csv: unsupported image format 'csv' (use png, pdf, svg, ...)"),
    ],
)
def test_unsupported_image_name(tmp_path, name, message):
    with pytest.raises(PinSuspError) as info:
        check_image_path(name)
    assert str(info.value) == message
    fig = plt.figure()
    with pytest.raises(PinSuspError) as info:
        save_figure(fig, tmp_path / name)
    assert str(info.value) == f"{tmp_path / name}: {message.split(': ', 1)[1]}"
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_image_endings_are_matplotlibs_and_case_insensitive(tmp_path):
    from matplotlib.backend_bases import FigureCanvasBase

    from pin_susp.viz.drawing import drawing_figure

    for ext in ("png", "PNG", "Pdf", "svg", "jpeg"):
        check_image_path(f"out.{ext}")
    assert "png" in FigureCanvasBase.get_supported_filetypes()
    drawing = drawing_figure(pin_susp.Corner(EXAMPLES / "double_wishbone.yaml"))
    save_figure(drawing, tmp_path / "d.PNG")
    assert (tmp_path / "d.PNG").read_bytes()[:4] == b"\x89PNG"


def test_check_image_path_touches_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    check_image_path(tmp_path / "missing" / "dir" / "out.svg")
    with pytest.raises(PinSuspError):
        check_image_path("out.xyz")
    assert list(tmp_path.iterdir()) == []


# --- C. the MJCF given to validate ---------------------------------------------------------


@pytest.fixture(scope="module")
def sweep():
    return pin_susp.load_sweep(EXAMPLES / "bump_steer.yaml")


def mjcf_error(corner, sweep, text) -> str:
    with pytest.raises(PinSuspError) as info:
        validate(corner, sweep, text, mjcf_source="corner.xml")
    return str(info.value)


def test_empty_mjcf(corner, sweep):
    assert mjcf_error(corner, sweep, "") == (
        "corner.xml: is empty: expected the MJCF written by pin-susp mjcf"
    )
    assert mjcf_error(corner, sweep, " \n\t") == mjcf_error(corner, sweep, "")


def test_binary_mjcf(corner, sweep):
    text = b"\x7fELF\x02\x01\x01\x00\x00\x00".decode("latin-1")
    assert mjcf_error(corner, sweep, text) == (
        "corner.xml: is not a text file: expected the MJCF (XML) written by pin-susp mjcf"
    )


def test_malformed_mjcf(corner, sweep):
    text = tree_to_mjcf(corner.tree)[:-40]  # cut short
    message = mjcf_error(corner, sweep, text)
    assert message.startswith("corner.xml: is not valid XML (")
    assert "line" in message and "\n" not in message


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ('<robot name="corner"><link name="a"/></robot>', "is not MJCF (a URDF?): its root"),
        ("<html><body/></html>", "is not MJCF: its root element is <html>, not <mujoco>"),
        ("<mujoco/>", "is not the MJCF of this geometry (example_corner): missing site"),
    ],
    ids=["urdf", "html", "empty mujoco"],
)
def test_xml_that_is_not_this_mjcf(corner, sweep, text, problem):
    assert mjcf_error(corner, sweep, text).startswith(f"corner.xml: {problem}")


def test_mjcf_of_another_corner_via_the_cli(tmp_path, capsys):
    exported = tmp_path / "pushrod.xml"
    assert main(["mjcf", str(EXAMPLES / "pushrod_rocker.yaml"), "-o", str(exported)]) == 0
    capsys.readouterr()
    err = one_error_line(
        capsys,
        [
            "validate",
            str(EXAMPLES / "double_wishbone.yaml"),
            str(EXAMPLES / "bump_steer.yaml"),
            "--mjcf",
            str(exported),
        ],
    )
    assert err.startswith(f"pin-susp: error: {exported}: is not the MJCF of this geometry")
    assert "has a site rocker_axis_a this model does not have" in err
    assert "agrees" not in err


def test_mjcf_of_another_corner_the_other_way(sweep):
    pushrod = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    text = tree_to_mjcf(pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").tree)
    with pytest.raises(
        PinSuspError, match="pushrod.xml: is not the MJCF of this geometry .*missing site"
    ):
        check_mjcf(text, pushrod.tree, "pushrod.xml")


def test_mjcf_with_a_changed_joint_or_constraint(corner, sweep):
    text = tree_to_mjcf(corner.tree)
    weld = text.replace('<connect name="trackrod"', '<weld name="trackrod"')
    assert "equality constraint trackrod is weld, not connect" in mjcf_error(corner, sweep, weld)


def test_mjcf_mujoco_cannot_load(corner, sweep):
    text = tree_to_mjcf(corner.tree).replace('mass="0.001"', 'mass="0"')
    message = mjcf_error(corner, sweep, text)
    assert message.startswith("corner.xml: MuJoCo cannot load it: Error: mass and inertia")
    assert "\n" not in message


def test_mjcf_of_this_corner_still_agrees_and_moved_hardpoints_still_disagree(corner, sweep):
    _, reports = validate(corner, sweep, tree_to_mjcf(corner.tree), mjcf_source="corner.xml")
    assert all(r.agrees for r in reports) and reports[1].warnings == 0
    moved = example("double_wishbone.yaml")
    moved["hardpoints"]["upper_wishbone_outboard"]["z"] += 2.0
    _, reports = validate(pin_susp.Corner(moved), sweep, tree_to_mjcf(corner.tree))
    assert reports[0].agrees and not reports[1].agrees and "camber" in reports[1].disagree


# --- D. MuJoCo's noise -------------------------------------------------------------------


def c_output(capfd) -> tuple[str, str]:
    """What reached file descriptors 1 and 2, C stdio buffers included."""
    ctypes.CDLL(None).fflush(None)
    return capfd.readouterr()


def assert_mujoco_restored(before_warning, before_config) -> None:
    assert mujoco.get_mju_user_warning() is before_warning
    after = mujoco.MjLogConfig.get()
    assert (after.logto_console, after.logto_file) == (
        before_config.logto_console,
        before_config.logto_file,
    )


def test_absurd_geometry_fails_steps_quietly(tmp_path, monkeypatch, capfd):
    """Hardpoints hundreds of mm off and a long sweep: steps fail, nothing is logged."""
    monkeypatch.chdir(tmp_path)
    geometry = example("double_wishbone.yaml")
    geometry["hardpoints"]["upper_wishbone_outboard"]["z"] += 300
    geometry["hardpoints"]["trackrod_outboard"]["y"] -= 300
    sweep = example("bump_steer.yaml")
    sweep["targets"][0]["start"], sweep["targets"][0]["stop"] = -400, 600
    before = mujoco.get_mju_user_warning(), mujoco.MjLogConfig.get()
    _, reports = validate(pin_susp.Corner(geometry), pin_susp.load_sweep(sweep))
    assert reports[1].failed_steps and not reports[1].agrees
    out, err = c_output(capfd)
    assert len(out) + len(err) < 200
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT
    assert_mujoco_restored(*before)


def test_mujoco_warnings_are_counted_not_printed_nor_logged(tmp_path, monkeypatch, capfd):
    """An MJCF whose ball joint is 10^10 m away: MuJoCo warns tens of thousands of times."""
    monkeypatch.chdir(tmp_path)
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    text = tree_to_mjcf(corner.tree)
    anchor = text.split('<connect name="upper_ball_joint"')[1].split('anchor="')[1].split('"')[0]
    text = text.replace(f'anchor="{anchor}"', 'anchor="1e10 0 0"')
    sweep = pin_susp.load_sweep(EXAMPLES / "bump_steer.yaml")
    before = mujoco.get_mju_user_warning(), mujoco.MjLogConfig.get()
    _, reports = validate(corner, sweep, text, mjcf_source="far.xml")
    engine = reports[1]
    assert engine.warnings > 1000 and "singular" in engine.first_warning
    assert len(engine.failed_steps) == sweep.steps and not engine.agrees
    out, err = c_output(capfd)
    assert "WARNING" not in out + err and len(out) + len(err) < 200
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT
    assert_mujoco_restored(*before)


def test_nan_in_the_mjcf_is_not_logged_either(tmp_path, monkeypatch, capfd, corner, sweep):
    monkeypatch.chdir(tmp_path)
    text = tree_to_mjcf(corner.tree)
    site = text.split('<site name="wheel_center" pos="')[1].split(" ")[0]
    text = text.replace(
        f'<site name="wheel_center" pos="{site}', '<site name="wheel_center" pos="nan'
    )
    _, reports = validate(corner, sweep, text, mjcf_source="nan.xml")
    assert "NaN" in reports[1].first_warning and len(reports[1].failed_steps) == sweep.steps
    out, err = c_output(capfd)
    assert len(out) + len(err) < 200
    assert list(tmp_path.iterdir()) == []


def test_validate_keeps_working_for_old_callers(corner, sweep):
    """Positional (corner, sweep, mjcf_text, tolerance) as before."""
    _, reports = validate(corner, sweep, None, 1e-6)
    assert [r.engine for r in reports] == ["pointwise", "mujoco"]
