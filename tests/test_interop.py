"""Other tools' files (issue 27, 7; docs/interop.md): `pin-susp import` of a Lotus
SHARK .shk, an OptimumK table (CSV, Excel) and an Adams/Car property file, and
`pin-susp export --format shk|optimumk`.

The fixtures are written here from the layouts docs/interop.md describes (no
binary file committed: the Excel one is made with openpyxl); the expected points
are written by hand in ISO axes (x forward, y left, z up), so the axis conversion
is checked against numbers that do not come from the converter.
"""

import warnings

import numpy as np
import pytest
from conftest import EXAMPLES

from pin_susp.cli import main
from pin_susp.model.geometry import load_geometry

INTEROP = EXAMPLES / "interop"
CORNERS = ("double_wishbone", "camber_shim", "fixed_toe_link", "macpherson", "pushrod_rocker")

# A right front corner as Lotus writes it: X rearward, Y outboard of the right
# wheel, Z up (mm) ...
LOTUS_RIGHT = [
    ("Lower wishbone front pivot", (-200, 250, 120)),
    ("Lower wishbone rear pivot", (220, 260, 110)),
    ("Lower wishbone outer ball joint", (5, 560, 115)),
    ("Upper wishbone front pivot", (-180, 300, 290)),
    ("Upper wishbone rear pivot", (200, 300, 280)),
    ("Upper wishbone outer ball joint", (-10, 540, 330)),
    ("Damper wishbone end", (0, 480, 130)),
    ("Damper body end", (20, 280, 420)),
    ("Outer track rod ball joint", (60, 550, 150)),
    ("Inner track rod ball joint", (70, 230, 160)),
    ("Upper spring pivot point", (20, 281, 419)),
    ("Wheel spindle point", (0, 520, 228.6)),
    ("Wheel centre point", (0, 600, 228.6)),
    ("Part 1 C of G", (30, 400, 200)),
]
# ... and the same corner in ISO axes, by hand (x = -X, y = -Y, z = Z), with a
# 10 mm wheel offset: the hub face 10 mm outboard of the wheel centre.
ISO_RIGHT = {
    "lower_wishbone_inboard_front": (200, -250, 120),
    "lower_wishbone_inboard_rear": (-220, -260, 110),
    "lower_wishbone_outboard": (-5, -560, 115),
    "upper_wishbone_inboard_front": (180, -300, 290),
    "upper_wishbone_inboard_rear": (-200, -300, 280),
    "upper_wishbone_outboard": (10, -540, 330),
    "strut_bottom": (0, -480, 130),
    "strut_top": (-20, -280, 420),
    "trackrod_outboard": (-60, -550, 150),
    "trackrod_inboard": (-70, -230, 160),
    "axle_inboard": (0, -520, 228.6),
    "axle_outboard": (0, -610, 228.6),
}
OPTIONS = ("--tyre", "180/50R13", "--offset", "10")


def shk(type_line: str, points, heading: bool = True) -> str:
    """A .shk as docs/interop.md describes it: a heading, the type line, then per
    point a name line, five definition lines (any text), the x y z line and lines
    of flags; a heading in capitals after the points."""
    lines = ["LOTUS SUSPENSION ANALYSIS", "FRONT SUSPENSION"] if heading else []
    lines.append(type_line)
    for name, xyz in points:
        lines += [name, "1", "Part 1 to part 2", "0 0 0", "-", "definition"]
        lines.append(xyz if isinstance(xyz, str) else "  ".join(str(v) for v in xyz))
        lines += ["0 0 0 0 0 0 0 0 0", "0 0 0 0 0 0 0"]
    lines += ["STATIC VALUES", "CAMBER ANGLE (deg): 0.00"]
    return "\n".join(lines) + "\n"


def quiet_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_geometry(path)


def assert_points(g, expected: dict, tol: float = 1e-9):
    assert set(g.hardpoints) == set(expected)
    for name, xyz in expected.items():
        assert np.max(np.abs(g.hardpoints_mm[name] - np.array(xyz, float))) <= tol, name


def refused(capsys, tmp_path, argv, *said):
    """The command exits 2 with one line naming the problem, writes nothing."""
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and err.startswith("pin-susp: error: ") and "Traceback" not in err
    for text in said:
        assert text in err, (text, err)
    assert not (tmp_path / "out.yaml").exists()
    return err


# --------------------------------------------------------------------------- round trip


@pytest.mark.parametrize("name", CORNERS)
@pytest.mark.parametrize(
    "fmt, suffix", [("shk", ".shk"), ("optimumk", ".csv"), ("optimumk", ".xlsx")]
)
def test_import_of_export_is_the_corner(tmp_path, capsys, name, fmt, suffix):
    source = str(EXAMPLES / f"{name}.yaml")
    g = quiet_load(source)
    out = str(tmp_path / f"corner{suffix}")
    assert main(["export", source, "--format", fmt, "-o", out]) == 0
    back = str(tmp_path / "back.yaml")
    assert main(["import", out, "-o", back, "--template", source, "-q"]) == 0
    h = quiet_load(back)
    assert_points(h, g.hardpoints_mm)
    assert h.choices() == g.choices() and h.wheel == g.wheel and h.type == g.type
    assert h.spring_rate == g.spring_rate and (h.camber_shim is None) == (g.camber_shim is None)
    # without a template the choices come from the file and the options
    w = g.wheel
    tyre = f"{w.section_width * 1e3:g}/{w.aspect_ratio * 100:g}R{w.rim_diameter / 0.0254:g}"
    again = ["import", out, "-o", back, "--tyre", tyre, "--offset", f"{w.offset * 1e3!r}", "-q"]
    steering = ["--steering", "none"] if g.steering == "none" and fmt == "shk" else []
    assert main(again + steering) == 0
    h = quiet_load(back)
    assert_points(h, g.hardpoints_mm)
    assert h.choices() == g.choices() and h.actuation_mount == g.actuation_mount


def test_a_left_corner_imported_as_the_right_is_its_mirror(tmp_path):
    source = str(EXAMPLES / "pushrod_rocker.yaml")
    g = quiet_load(source)
    assert main(["export", source, "--format", "shk", "-o", "c.shk"]) == 0
    assert main(["import", "c.shk", "-o", "r.yaml", "--template", source, "--side", "right"]) == 0
    h = quiet_load("r.yaml")
    assert h.side == "right"
    assert_points(h, {k: v * np.array([1, -1, 1]) for k, v in g.hardpoints_mm.items()})


# ------------------------------------------------------------------------ Lotus SHARK


def test_lotus_axes_to_iso_on_a_hand_written_corner(tmp_path, capsys):
    (tmp_path / "car.shk").write_text(
        shk("TYPE 1 Double Wishbone, damper to lower wishbone", LOTUS_RIGHT)
    )
    assert main(["import", "car.shk", "-o", "out.yaml", *OPTIONS]) == 0
    g = quiet_load(tmp_path / "out.yaml")
    assert g.side == "right" and g.spring == "coilover" and g.actuation_mount == "lower_wishbone"
    assert_points(g, ISO_RIGHT)
    out = capsys.readouterr().out
    assert main(["import", "car.shk", "-o", "left.yaml", "--side", "left", *OPTIONS]) == 0
    left = quiet_load(tmp_path / "left.yaml")
    assert_points(left, {k: (x, -y, z) for k, (x, y, z) in ISO_RIGHT.items()})
    # what it used, as which point, and what it ignored, and why
    lines = out.splitlines()
    assert "used      Lower wishbone front pivot (line 4) as lower_wishbone_inboard_front" in lines
    assert "used      Damper body end (line 67) as strut_top" in lines
    assert "used      Wheel spindle point (line 103) as wheel_spindle" in lines
    assert (
        "ignored   Upper spring pivot point (line 94): strut_top is given by "
        "'Damper body end' (line 67)"
    ) in lines
    assert "ignored   Part 1 C of G (line 121): not a point pin_susp's corner has" in lines
    assert sum(line.startswith(("used ", "ignored ")) for line in lines) == len(LOTUS_RIGHT)
    assert any(line.startswith("default   config.steering.type = rack") for line in lines)
    assert lines[-1] == "wrote out.yaml"


def test_an_imported_corner_sweeps_as_the_one_it_came_from(tmp_path):
    source, bump = str(EXAMPLES / "double_wishbone.yaml"), str(EXAMPLES / "bump.yaml")
    shk_file = str(INTEROP / "fs_front.shk")
    assert main(["import", shk_file, "-o", "g.yaml", "--template", source, "-q"]) == 0
    assert main(["sweep", "g.yaml", bump, "-o", "a.csv", "-q"]) == 0
    assert main(["sweep", source, bump, "-o", "b.csv", "-q"]) == 0
    import pandas as pd

    a, b = (pd.read_csv(p, comment="#", skiprows=0) for p in ("a.csv", "b.csv"))
    numbers = a.select_dtypes("number").columns
    assert len(a) > 5 and "camber" in numbers
    assert np.allclose(
        a[numbers].to_numpy(float), b[numbers].to_numpy(float), atol=1e-9, equal_nan=True
    )


@pytest.mark.parametrize(
    "change, said",
    [
        (("type", "Semi Trailing Arm"), ["car.shk: line 3: suspension type 'Semi Trailing Arm'"]),
        (
            ("drop", "Upper wishbone rear pivot"),
            [
                "car.shk: missing point for a double_wishbone corner",
                "'Upper wishbone rear pivot' (upper_wishbone_inboard_rear)",
            ],
        ),
        (
            ("drop", "Wheel centre point"),
            ["car.shk: missing point", "'Wheel centre point' (wheel_center)"],
        ),
        (
            ("number", "Lower wishbone outer ball joint"),
            [
                "car.shk: line 28: 'Lower wishbone outer ball joint': "
                "expected x y z (three numbers, mm), got '5 five 115'"
            ],
        ),
    ],
)
def test_lotus_refusals(tmp_path, capsys, change, said):
    kind, what = change
    points = [
        (n, "5 five 115" if kind == "number" and n == what else xyz) for n, xyz in LOTUS_RIGHT
    ]
    points = [p for p in points if not (kind == "drop" and p[0] == what)]
    type_line = what if kind == "type" else "Double Wishbone, damper to lower wishbone"
    (tmp_path / "car.shk").write_text(shk(type_line, points))
    refused(capsys, tmp_path, ["import", "car.shk", "-o", "out.yaml", *OPTIONS], *said)


def test_what_the_files_do_not_carry_is_asked_for(tmp_path, capsys):
    (tmp_path / "car.shk").write_text(shk("Double Wishbone, damper to lower wishbone", LOTUS_RIGHT))
    refused(
        capsys, tmp_path, ["import", "car.shk", "-o", "out.yaml"], "car.shk: the tyre", "--tyre"
    )


# --------------------------------------------------------------------------- OptimumK


def optimumk_rows(scale: float = 1.0):
    """The Lotus corner's rows in X rearward, Y right (mm · scale), OptimumK-style names."""
    names = {
        "Lower wishbone front pivot": "Lower Wishbone Front Pivot",
        "Lower wishbone rear pivot": "Lower Wishbone Rear Pivot",
        "Lower wishbone outer ball joint": "Lower Ball Joint",
        "Upper wishbone front pivot": "Upper Wishbone Front Pivot",
        "Upper wishbone rear pivot": "Upper Wishbone Rear Pivot",
        "Upper wishbone outer ball joint": "Upper Ball Joint",
        "Damper wishbone end": "Damper Wishbone",
        "Damper body end": "Damper Inboard",
        "Outer track rod ball joint": "Tie Rod Outboard",
        "Inner track rod ball joint": "Tie Rod Inboard",
        "Wheel spindle point": "Spindle Point",
        "Wheel centre point": "Wheel Center",
        "Part 1 C of G": "Mystery Bracket",
    }
    return [(names[n], *(v * scale for v in xyz)) for n, xyz in LOTUS_RIGHT if n in names]


def test_optimumk_csv_in_metres_with_its_axes(tmp_path, capsys):
    rows = ["Name,X (m),Y (m),Z (m)"] + [
        ",".join([n, *map(repr, v)]) for n, *v in optimumk_rows(1e-3)
    ]
    (tmp_path / "car.csv").write_text("\n".join(rows) + "\n")
    assert (
        main(["import", "car.csv", "-o", "out.yaml", "--axes", "rearward,right,up", *OPTIONS]) == 0
    )
    assert_points(quiet_load(tmp_path / "out.yaml"), ISO_RIGHT, tol=1e-9)
    out = capsys.readouterr().out
    assert "used      Damper Wishbone (row 8) as strut_bottom" in out
    assert "ignored   Mystery Bracket (row 14): not a point pin_susp's corner has" in out
    assert "m (from the header)" in out.splitlines()[0]


def test_optimumk_excel_written_with_openpyxl(tmp_path, capsys):
    import openpyxl

    book = openpyxl.Workbook()
    sheet = book.active
    sheet.append(["Front suspension, right"])  # a title above the header
    sheet.append(["Point", "X", "Y", "Z"])
    for name, x, y, z in optimumk_rows():  # in ISO axes: the default --axes x,y,z
        sheet.append([name, -x, -y, z])
    book.save(tmp_path / "car.xlsx")
    assert main(["import", "car.xlsx", "-o", "out.yaml", *OPTIONS]) == 0
    assert_points(quiet_load(tmp_path / "out.yaml"), ISO_RIGHT)
    out = capsys.readouterr().out
    assert "used      Lower Ball Joint (row 5) as lower_wishbone_outboard" in out
    assert "mm (the header gives no unit; give --units)" in out


def test_optimumk_refusals(tmp_path, capsys):
    rows = ["Name,X,Y,Z"] + [",".join([n, *map(str, v)]) for n, *v in optimumk_rows()]
    rows[3] = "Lower Ball Joint,5,56O,115"  # a letter O for a zero
    (tmp_path / "car.csv").write_text("\n".join(rows) + "\n")
    refused(
        capsys,
        tmp_path,
        ["import", "car.csv", "-o", "out.yaml", *OPTIONS],
        "car.csv: row 4 ('Lower Ball Joint'): Y: expected a number, got '56O'",
    )
    argv = ["import", "car.csv", "-o", "out.yaml", "--map", "Lower Ball Joint=lbj", *OPTIONS]
    refused(capsys, tmp_path, argv, "--map Lower Ball Joint=lbj: 'lbj' is not a pin_susp point")
    del rows[3]
    (tmp_path / "car.csv").write_text("\n".join(rows) + "\n")
    refused(
        capsys,
        tmp_path,
        ["import", "car.csv", "-o", "out.yaml", *OPTIONS],
        "car.csv: missing point",
        "'Lower Ball Joint' (lower_wishbone_outboard)",
    )


# -------------------------------------------------------------------------- Adams/Car


def test_adams_example_is_the_example_corner(tmp_path, capsys):
    source = str(INTEROP / "fs_front_adams.sub")
    assert main(["import", source, "-o", "out.yaml", "--tyre", "270/55R13"]) == 0
    g, h = quiet_load(EXAMPLES / "double_wishbone.yaml"), quiet_load(tmp_path / "out.yaml")
    assert_points(
        h,
        {k: v for k, v in g.hardpoints_mm.items() if k != "axle_inboard"}
        | {"axle_inboard": h.hardpoints_mm["axle_inboard"]},
    )
    axis = h.hardpoints_mm["axle_outboard"] - h.hardpoints_mm["axle_inboard"]
    assert np.allclose(
        axis / np.linalg.norm(axis), np.array([0, 150, 5]) / np.hypot(150, 5), atol=1e-12
    )
    out = capsys.readouterr().out
    assert "ignored   hpr_lca_front (line 29): the right side's" in out
    assert "ignored   hps_rack_house_mount (line 38): a single (centreline) point" in out
    assert "from file static camber = -1.90915 deg" in out
    assert main(["sweep", "out.yaml", str(EXAMPLES / "bump.yaml"), "-o", "b.csv", "-q"]) == 0


def test_adams_units_and_right_side(tmp_path, capsys):
    """A right corner in metres: Adams' axes are Lotus' (x rearward, y right, z up)."""
    adams = {
        "Lower wishbone front pivot": "lca_front",
        "Lower wishbone rear pivot": "lca_rear",
        "Lower wishbone outer ball joint": "lca_outer",
        "Upper wishbone front pivot": "uca_front",
        "Upper wishbone rear pivot": "uca_rear",
        "Upper wishbone outer ball joint": "uca_outer",
        "Damper wishbone end": "lower_strut",
        "Damper body end": "top_mount",
        "Outer track rod ball joint": "tierod_outer",
        "Inner track rod ball joint": "tierod_inner",
        "Wheel centre point": "wheel_center",
    }
    lines = [
        "[UNITS]",
        " LENGTH = 'meter'",
        "[HARDPOINT]",
        "{hardpoint_name x_value y_value z_value}",
    ]
    for name, xyz in LOTUS_RIGHT:
        if name in adams:
            lines.append(f" 'hpr_{adams[name]}' " + " ".join(repr(v / 1000) for v in xyz))
    (tmp_path / "car.sub").write_text("\n".join(lines) + "\n")
    argv = ["import", "car.sub", "-o", "ok.yaml", "--side", "right", "--camber", "0", "--toe", "0"]
    assert main(argv + list(OPTIONS)) == 0
    want = dict(ISO_RIGHT, axle_inboard=(0, -610 + 50, 228.6))  # 50 mm inboard along the axis
    assert_points(quiet_load(tmp_path / "ok.yaml"), want)
    lines[1] = " LENGTH = 'furlong'"
    (tmp_path / "car.sub").write_text("\n".join(lines) + "\n")
    refused(
        capsys,
        tmp_path,
        ["import", "car.sub", "-o", "out.yaml", *OPTIONS],
        "car.sub: line 2: [UNITS] LENGTH 'furlong'",
    )


# ---------------------------------------------------------------------- the examples


@pytest.mark.parametrize(
    "fmt, name", [("shk", "fs_front.shk"), ("optimumk", "fs_front_optimumk.csv")]
)
def test_committed_examples_are_what_the_exporter_writes(tmp_path, fmt, name):
    """examples/interop is kept in sync: regenerate with the command in docs/interop.md."""
    out = tmp_path / name
    assert (
        main(["export", str(EXAMPLES / "double_wishbone.yaml"), "--format", fmt, "-o", str(out)])
        == 0
    )
    assert out.read_bytes() == (INTEROP / name).read_bytes()


def test_export_refuses_other_mechanisms(tmp_path, capsys):
    argv = ["export", str(EXAMPLES / "multilink_rear.yaml"), "--format", "shk", "-o", "o.shk"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "type multilink: these formats carry double_wishbone and macpherson corners" in err
    assert not (tmp_path / "o.shk").exists()


@pytest.mark.parametrize("subject", ["axle_front.yaml", "vehicle_fs.yaml"])
def test_export_refuses_an_axle_or_a_car_naming_its_kind(tmp_path, capsys, subject):
    argv = ["export", str(EXAMPLES / subject), "--format", "optimumk", "-o", "o.csv"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "export is not built yet" in err
    assert ("an axle takes" if subject.startswith("axle") else "a vehicle takes") in err
    assert not (tmp_path / "o.csv").exists()


def test_lotus_report_layout_and_a_damper_on_the_upper_wishbone(tmp_path, capsys):
    """Lotus' printed report: x y z before each name; a type pin_susp reads but whose
    damper it has no place for (on the upper wishbone): its points ignored, said."""
    lines = ["LOTUS SUSPENSION ANALYSIS v5.01", "TYPE 6 Double Wishbone, damper to upper wishbone"]
    lines += ["X Y Z", "(mm) (mm) (mm)"]
    for i, (name, xyz) in enumerate(LOTUS_RIGHT, start=1):
        lines.append(f"{xyz[0]:.2f} {xyz[1]:.2f} {xyz[2]:.2f} POINT:{i} {name}")
    lines += ["0.00 0.00 0.00 POINT:0", "STATIC VALUES", "Camber Angle (deg): 0.00"]
    (tmp_path / "report.txt").write_text("\n".join(lines) + "\n")
    assert main(["import", "report.txt", "--format", "shk", "-o", "out.yaml", *OPTIONS]) == 0
    g = quiet_load(tmp_path / "out.yaml")
    assert g.spring == "none"
    assert_points(g, {k: v for k, v in ISO_RIGHT.items() if not k.startswith("strut_")})
    out = capsys.readouterr().out
    why = "pin_susp has no damper or pushrod on the upper wishbone"
    assert f"ignored   Damper wishbone end (line 11): {why}" in out
    assert f"ignored   Upper spring pivot point (line 15): {why}" in out
    assert "used      Wheel centre point (line 17) as wheel_center" in out


@pytest.mark.parametrize(
    "axes, said",
    [
        ("up,left,forward", "--axes: up,left,forward is a left-handed frame"),
        ("up,up,up", "--axes: X, Y, Z must point along three different axes"),
        ("-x,y,z", "--axes: expected where X, Y, Z point"),
    ],
)
def test_optimumk_axes_that_are_no_car_frame(tmp_path, capsys, axes, said):
    argv = ["import", str(INTEROP / "fs_front_optimumk.csv"), "-o", "out.yaml", f"--axes={axes}"]
    refused(capsys, tmp_path, argv + list(OPTIONS), said)


# ------------------------------------------------------- a new user's files (review)

CSV = (INTEROP / "fs_front_optimumk.csv").read_text()


def example_points():
    return quiet_load(EXAMPLES / "double_wishbone.yaml").hardpoints_mm


@pytest.mark.parametrize("sep", [",", ";"])
def test_a_table_with_title_lines_above_its_header(tmp_path, capsys, sep):
    """Title rows (one cell; or empty cells) are skipped; the header's separator is the
    table's; the unit from x [m]; the row numbers are the file's lines."""
    head, *rows = CSV.splitlines()
    body = [
        sep.join([r.split(",")[0], *(repr(float(v) / 1e3) for v in r.split(",")[1:])]) for r in rows
    ]
    text = ["My car", sep * 3, sep.join(["Name", "x [m]", "y [m]", "z [m]"]), *body]
    (tmp_path / "t.csv").write_text("\n".join(text) + "\n")
    assert (
        main(
            [
                "import",
                "t.csv",
                "-o",
                "out.yaml",
                "--template",
                str(EXAMPLES / "double_wishbone.yaml"),
            ]
        )
        == 0
    )
    assert_points(quiet_load(tmp_path / "out.yaml"), example_points(), tol=1e-9)
    out = capsys.readouterr().out
    assert "used      Lower Wishbone Front Pivot (row 4) as lower_wishbone_inboard_front" in out
    assert "m (from the header)" in out


def test_pin_susp_own_names_with_the_axle_points_are_read_as_they_are(tmp_path, capsys):
    g = example_points()
    rows = ["name,X,Y,Z"] + [",".join([n, *map(repr, map(float, v))]) for n, v in g.items()]
    (tmp_path / "own.csv").write_text("\n".join(rows) + "\n")
    assert main(["import", "own.csv", "-o", "out.yaml", "--tyre", "270/55R13"]) == 0
    assert_points(quiet_load(tmp_path / "out.yaml"), g)
    row = list(g).index("axle_inboard") + 2  # the header is row 1
    assert f"used      axle_inboard (row {row}) as axle_inboard" in capsys.readouterr().out


def adams_with(tmp_path, angle_unit: str | None, camber: str) -> str:
    text = (INTEROP / "fs_front_adams.sub").read_text()
    lines = text.splitlines()
    at = next(i for i, t in enumerate(lines) if "LENGTH" in t)
    if angle_unit:
        lines.insert(at + 1, f" ANGLE   =  '{angle_unit}'")
    lines = [(t.rsplit(None, 1)[0] + "  " + camber) if "'camber_angle'" in t else t for t in lines]
    (tmp_path / "car.sub").write_text("\n".join(lines) + "\n")
    return "car.sub"


def test_adams_camber_in_radians_is_converted(tmp_path, capsys):
    camber = -np.degrees(np.arctan2(5, 150))  # the example's spin axis (0, 150, 5) mm
    adams_with(tmp_path, "radians", repr(float(np.radians(camber))))
    assert main(["import", "car.sub", "-o", "rad.yaml", "--tyre", "270/55R13"]) == 0
    h = quiet_load(tmp_path / "rad.yaml").hardpoints_mm
    axis = h["axle_outboard"] - h["axle_inboard"]
    assert np.allclose(axis / np.linalg.norm(axis), np.array([0, 150, 5]) / np.hypot(150, 5))
    assert f"from file static camber = {camber:g} deg" in capsys.readouterr().out
    adams_with(tmp_path, "grads", "0.1")
    refused(
        capsys,
        tmp_path,
        ["import", "car.sub", "-o", "out.yaml", "--tyre", "270/55R13"],
        "car.sub: line 12: [UNITS] ANGLE 'grads': expected one of degrees",
    )


@pytest.mark.parametrize(
    "file, argv, said",
    [
        (
            "fs_front.shk",
            ["--camber", "1"],
            "--camber: the file gives the spin axis ('Wheel spindle point', line 60)",
        ),
        (
            "fs_front_optimumk.csv",
            ["--toe", "0"],
            "--toe: the file gives the spin axis ('Spindle Point', row 10)",
        ),
        ("fs_front.shk", ["--units", "m"], "--units: "),
        ("fs_front.shk", ["--axes", "rearward,right,up"], "--axes: "),
        ("fs_front_adams.sub", ["--map", "x=strut_top"], "--map: "),
        ("fs_front_adams.sub", ["--camber", "60"], "--camber 60: 60° is beyond ±45°"),
        ("fs_front_optimumk.csv", ["--units", "m"], "--units m: the X, Y, Z headers say mm"),
        (
            "fs_front.shk",
            ["--type", "macpherson"],
            "the file's type line says a double_wishbone corner ('Double Wishbone, damper to "
            "lower wishbone'); --type macpherson",
        ),
        (
            "fs_front.shk",
            ["--template", str(EXAMPLES / "axle_front.yaml")],
            "the template must be a corner file",
        ),
    ],
)
def test_an_option_the_file_does_not_take_is_refused(tmp_path, capsys, file, argv, said):
    base = ["import", str(INTEROP / file), "-o", "out.yaml"]
    tyre = [] if "--template" in argv else ["--tyre", "270/55R13"]
    err = refused(capsys, tmp_path, base + tyre + argv, said)
    assert "is for an OptimumK table" in err or not said.endswith(": ")


def test_an_absurd_camber_in_the_file_is_refused(tmp_path, capsys):
    adams_with(tmp_path, None, "89")
    refused(
        capsys,
        tmp_path,
        ["import", "car.sub", "-o", "out.yaml", "--tyre", "270/55R13"],
        "car.sub: line 42 ('camber_angle'): 89° is beyond ±45° (degrees, at design)",
    )


def test_a_point_given_twice(tmp_path, capsys):
    lines = CSV.splitlines()
    (tmp_path / "same.csv").write_text("\n".join([*lines, lines[3]]) + "\n")
    argv = ["import", "same.csv", "-o", "same.yaml", "--tyre", "270/55R13"]
    assert main(argv) == 0
    assert (
        "ignored   Lower Ball Joint (row 12): lower_wishbone_outboard is given by "
        "'Lower Ball Joint' (row 4) at the same position"
    ) in capsys.readouterr().out
    (tmp_path / "two.csv").write_text("\n".join([*lines, "Lower Ball Joint,1.0,901,200"]) + "\n")
    refused(
        capsys,
        tmp_path,
        ["import", "two.csv", "-o", "out.yaml", "--tyre", "270/55R13"],
        "two.csv: 'Lower Ball Joint' (row 12) and 'Lower Ball Joint' (row 4) are both "
        "lower_wishbone_outboard, at different positions",
    )


@pytest.mark.parametrize(
    "fmt, name, said",
    [
        ("optimumk", "x.xls", "x.xls: --format optimumk writes .csv or .xlsx files, not .xls"),
        ("optimumk", "x.txt", "x.txt: --format optimumk writes .csv or .xlsx files, not .txt"),
        ("shk", "x.csv", "x.csv: --format shk writes .shk files, not .csv"),
    ],
)
def test_export_refuses_a_suffix_its_format_does_not_write(tmp_path, capsys, fmt, name, said):
    argv = ["export", str(EXAMPLES / "double_wishbone.yaml"), "--format", fmt, "-o", name]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err
    assert not (tmp_path / name).exists()


def shk_lines():
    return (INTEROP / "fs_front.shk").read_text().splitlines()


@pytest.mark.parametrize(
    "change, said",
    [
        (
            "wheel centre across",
            "fs.shk: the file's points are on both sides of the car: its wheel "
            "centre 'Wheel centre point' (line 67) on the right (ISO y < 0), 'Lower wishbone outer "
            "ball joint' (line 18) on the left",
        ),
        (
            "no type line",
            "fs.shk: line 3: no suspension type line: 'Lower wishbone front pivot' "
            "starts a point's block",
        ),
        ("binary", "fs.shk: not a text file (binary data): a Lotus .shk is text"),
        ("empty", "fs.shk: the file is empty"),
    ],
)
def test_lotus_files_that_are_not_what_they_seem(tmp_path, capsys, change, said):
    lines = shk_lines()
    if change == "wheel centre across":
        lines[72] = " ".join(
            str(-float(v)) if i == 1 else v for i, v in enumerate(lines[72].split())
        )
    elif change == "no type line":
        del lines[2]
    data = "\n".join(lines).encode() + b"\n"
    data = {"binary": bytes(range(256)) * 4, "empty": b"\n\n"}.get(change, data)
    (tmp_path / "fs.shk").write_bytes(data)
    err = refused(
        capsys, tmp_path, ["import", "fs.shk", "-o", "out.yaml", "--tyre", "270/55R13"], said
    )
    assert "\\x" not in err


@pytest.mark.parametrize(
    "name, data, said",
    [
        ("e.csv", b"", "e.csv: the file is empty"),
        ("e.xlsx", b"", "e.xlsx: the file is empty"),
        ("j.xlsx", bytes(range(256)) * 8, "j.xlsx: not an Excel workbook (.xlsx, .xlsm)"),
        ("b.csv", bytes(range(256)) * 8, "b.csv: not a text table (binary data)"),
    ],
)
def test_tables_that_are_no_tables(tmp_path, capsys, name, data, said):
    (tmp_path / name).write_bytes(data)
    err = refused(capsys, tmp_path, ["import", name, "-o", "out.yaml", "--tyre", "270/55R13"], said)
    assert "engine" not in err and "\\" not in err


def test_an_excel_formula_without_a_saved_value(tmp_path, capsys):
    import openpyxl

    book = openpyxl.Workbook()
    sheet = book.active
    for i, row in enumerate(CSV.splitlines()):
        cells = row.split(",")
        sheet.append(cells[:1] + ([float(v) for v in cells[1:]] if i else cells[1:]))
    sheet["C4"] = "=C3*2"  # openpyxl saves no value for it, as a script would
    book.save(tmp_path / "f.xlsx")
    refused(
        capsys,
        tmp_path,
        ["import", "f.xlsx", "-o", "out.yaml", "--tyre", "270/55R13"],
        "f.xlsx: row 4 ('Lower Ball Joint'): Y (mm): the cell is a formula (=C3*2) without a "
        "saved value: save the workbook in Excel",
    )


def test_camber_and_toe_give_the_spin_axis_of_those_angles(tmp_path):
    """With toe, the axis still has the camber asked for, by pin_susp's definition
    (docs/results.md): camber = −atan2(â_z, s·â_y), toe = atan2(â_x, s·â_y)."""
    argv = ["import", str(INTEROP / "fs_front_adams.sub"), "-o", "out.yaml", "--tyre", "270/55R13"]
    assert main([*argv, "--camber", "-2.5", "--toe", "1.5"]) == 0
    h = quiet_load(tmp_path / "out.yaml").hardpoints_mm
    a = h["axle_outboard"] - h["axle_inboard"]  # a left corner: s = +1
    assert np.degrees(-np.arctan2(a[2], a[1])) == pytest.approx(-2.5, abs=1e-9)  # 1e-10 mm on 50 mm
    assert np.degrees(np.arctan2(a[0], a[1])) == pytest.approx(1.5, abs=1e-9)
