"""Dead centres at design (docs/geometry.md, "Dead centres"): the check every command
makes when it reads a geometry, the motion ratio's way near over-centre, the sweep's
failure report and the loads' warning that name it, validate's branch report."""

import csv
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example

from pin_susp.cli import main

DEG = np.pi / 180


def write(path: Path, data) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def xyz(p) -> np.ndarray:
    return np.array([p["x"], p["y"], p["z"]], dtype=float)


def near_dead_centre(off_deg: float, arm_mm: float) -> dict:
    """The pushrod-rocker example with pushrod_inboard on the far side of the rocker
    axis from pushrod_outboard, ``arm_mm`` from the axis, turned ``off_deg`` about it
    off the line pushrod_outboard → axis: the pushrod all but through the axis."""
    g = example("pushrod_rocker.yaml")
    hp = g["hardpoints"]
    assert hp["rocker_axis_a"]["y"] == hp["rocker_axis_b"]["y"]  # the axis runs along x,
    assert hp["rocker_axis_a"]["z"] == hp["rocker_axis_b"]["z"]  # pushrod_outboard at x = 0
    axis, out = xyz(hp["rocker_axis_a"])[1:], xyz(hp["pushrod_outboard"])[1:]
    d = (axis - out) / np.linalg.norm(axis - out)  # in the y-z plane
    c, s = np.cos(off_deg * DEG), np.sin(off_deg * DEG)
    p = axis + arm_mm * np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
    hp["pushrod_inboard"] = {"x": 0.0, "y": float(p[0]), "z": float(p[1])}
    return g


def by_hand(g: dict, end: str, other: str, a: str = "rocker_axis_a", b: str = "rocker_axis_b"):
    """(transmission angle deg, miss mm) by vector algebra: the angle at ``end`` between
    the lever arm (from the axis, normal to it) and the link, both normal to the axis;
    the miss: the distance between the link's line and the axis's (skew lines)."""
    hp = g["hardpoints"]
    pa, pb, p, q = (xyz(hp[n]) for n in (a, b, end, other))
    u = (pb - pa) / np.linalg.norm(pb - pa)
    arm = (p - pa) - u * ((p - pa) @ u)
    rod = (q - p) - u * ((q - p) @ u)
    angle = np.degrees(np.arccos(arm @ rod / np.linalg.norm(arm) / np.linalg.norm(rod)))
    n = np.cross(u, (q - p) / np.linalg.norm(q - p))
    miss = abs((pa - p) @ n) / np.linalg.norm(n)
    return angle, miss


def dead_centre_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if "from dead centre at design (transmission" in line]


# the design and two steps of droop (bump steps fail at once at the user's 0.6°)
H = 1e-3  # mm
DESIGN = {
    "version": 1,
    "steps": 3,
    "targets": [
        {"point": "wheel_center", "direction": {"axis": "z"}, "mode": "relative"}
        | {"start": -2 * H, "stop": 0},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "mode": "relative"}
        | {"start": 0, "stop": 0},
    ],
}


def rows(path: Path) -> list[dict]:
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


COMMANDS = {
    "setup": lambda g, s, t: ["setup", g],
    "urdf": lambda g, s, t: ["urdf", g, "-o", t / "c.urdf"],
    "mjcf": lambda g, s, t: ["mjcf", g, "-o", t / "c.xml"],
    "draw": lambda g, s, t: ["draw", g, "-o", t / "d.png"],
    "sensitivity": lambda g, s, t: ["sensitivity", g, "-o", t / "s.csv"],
    "sweep": lambda g, s, t: ["sweep", g, s, "-o", t / "r.csv"],
    "loads": lambda g, s, t: ["loads", g, s, "--cases", EXAMPLES / "loads.yaml", "-o", t / "f.csv"],
    "validate": lambda g, s, t: ["validate", g, s, "--engine", "pointwise"],
    "view": lambda g, s, t: ["view", g, s, "--html", t / "v.html"],
}


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_warns_of_the_dead_centre_with_its_numbers(tmp_path, capsys, command):
    """The user's case: the pushrod line 0.38 mm from the rocker axis, 179.4°. Every
    command says so once, with the angle, the miss, the points and the way the motion
    ratio goes, and exits as it would without (0: the design's steps solve)."""
    g = near_dead_centre(0.6, 38.6)
    angle, miss = by_hand(g, "pushrod_inboard", "pushrod_outboard")
    assert 179.3 < angle < 179.5 and 0.37 < miss < 0.39  # the numbers
    path = write(tmp_path / "g.yaml", g)
    sweep = write(tmp_path / "s.yaml", DESIGN)
    argv = [str(a) for a in COMMANDS[command](path, sweep, tmp_path)]
    assert main(argv) == 0
    (line,) = dead_centre_lines(capsys.readouterr().err)
    assert line.startswith(f"pin-susp: warning: {path}: pushrod → rocker is ")
    assert f"is {180 - angle:.1f}° from dead centre at design" in line
    assert f"transmission angle {angle:.1f}°" in line
    assert f"passes {miss:.2f} mm from the rocker axis rocker_axis_a–rocker_axis_b" in line
    assert "rises toward infinity" in line and "move pushrod_inboard" in line


def test_study_warns_of_the_dead_centre_of_its_design(tmp_path):
    """What `pin-susp study` builds its design with, naming the study's geometry (a
    corner's variants stay quiet; an axle's, read by load_axle, are silenced by the
    study as its other plausibility warnings are)."""
    from pin_susp.errors import PlausibilityWarning
    from pin_susp.study import build

    for axle, data in ((False, near_dead_centre(0.6, 38.6)), (True, example("axle_front.yaml"))):
        if axle:
            data["hardpoints"]["left"]["droplink_u_bar"] = {"x": 0.5, "y": 300, "z": 220}
        for variant in (False,) if axle else (False, True):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", PlausibilityWarning)
                build(data, "study.yaml", variant=variant)
            said = [str(w.message) for w in caught if "from dead centre" in str(w.message)]
            if variant:
                assert not said
            else:
                (line,) = said
                assert line.startswith("study.yaml: ")
                assert ("droplink → left arb arm" if axle else "pushrod → rocker is 0.6°") in line


def test_no_committed_example_is_near_a_dead_centre():
    from pin_susp.model.deadcentre import DEAD_CENTRE, transmissions
    from pin_susp.model.geometry import load_geometry
    from pin_susp.subjects.axle import axle_tree, load_axle

    checked = 0
    for path in sorted(EXAMPLES.glob("*.yaml")):
        data = yaml.safe_load(path.read_text())
        if "hardpoints" not in data:
            continue
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if data.get("scope") == "axle":
                a = load_axle(path)
                tree = axle_tree(a.left, a.right, "axle", a)
            else:
                g = load_geometry(path)
                tree = g.mechanism.tree(g)
        assert not [w for w in caught if "dead centre" in str(w.message)], path
        for t in transmissions(tree):
            assert t.margin > DEAD_CENTRE, (path, t)
            checked += 1
    assert checked >= 10  # pushrods, coilovers on rockers, wishbones and arms, droplinks


def _motion_ratio(tmp_path: Path, g: dict) -> float:
    """|d damper length / d wheel-centre z| at design by a second-order one-sided
    difference of the sweep's damper_length (steps of 1 µm): not its motion_ratio."""
    path = write(tmp_path / "g.yaml", g)
    out = tmp_path / "r.csv"
    assert main(["sweep", str(path), str(write(tmp_path / "s.yaml", DESIGN)), "-o", str(out)]) == 0
    f = [float(r["damper_length"]) for r in rows(out)]  # at -2H, -H, 0
    return abs(3 * f[2] - 4 * f[1] + f[0]) / (2 * H)


def test_the_motion_ratio_goes_the_way_the_warning_says(tmp_path, capsys):
    """Pushrod at the rocker's dead centre: the rocker drives the damper ever faster,
    the ratio rises toward infinity. Coilover's line through the rocker axis: the
    rocker barely works it, the ratio falls toward zero. Both by the numbers."""
    normal = _motion_ratio(tmp_path, example("pushrod_rocker.yaml"))
    capsys.readouterr()
    assert 0.2 < normal < 1.0
    assert _motion_ratio(tmp_path, near_dead_centre(1.0, 40.0)) > 10 * normal
    (line,) = dead_centre_lines(capsys.readouterr().err)
    assert "pushrod → rocker" in line and "rises toward infinity" in line

    g = example("pushrod_rocker.yaml")
    g["hardpoints"]["strut_top"] = {"x": 0, "y": 640, "z": 455}  # along the rocker's arm
    angle, miss = by_hand(g, "strut_bottom", "strut_top")
    angle = min(angle, 180 - angle)  # the coilover's line on the arm's side: near 0°
    assert _motion_ratio(tmp_path, g) < 0.1 * normal
    (line,) = dead_centre_lines(capsys.readouterr().err)
    assert f"rocker → coilover is {angle:.1f}° from dead centre" in line
    assert f"passes {miss:.2f} mm" in line and "falls toward zero" in line
    assert "move strut_bottom" in line


def test_over_centre_band_says_the_way_of_the_motion_ratio_by_the_numbers():
    """The sweep's band warning: 'rises toward infinity' where |motion ratio| at the
    worst angle is above it at the angle nearest 90°, else 'falls toward zero'."""
    from pin_susp.cli.report import Digest
    from pin_susp.cli.report import warn_transmission as _warn_transmission
    from pin_susp.errors import PlausibilityWarning

    class Part:
        def __init__(self, columns):
            self.columns, self.units = columns, dict.fromkeys(columns, "")
            self.meta = {"why": [""] * len(columns["step_index"])}

        def __getitem__(self, key):
            return self.columns[key]

    angle = np.array([90.0, 120.0, 160.0, 175.0])
    for ratio, way in (
        ([0.4, 0.6, 2.0, 9.0], "rises toward infinity"),
        ([1, 0.8, 0.1, 0.01], "falls toward zero"),
    ):
        columns = {
            "step_index": np.arange(4),
            "solver_converged": np.ones(4, bool),
            "solver_max_residual": np.zeros(4),
            "solver_iterations": np.ones(4, int),
            "rocker_transmission_angle": angle,
            "motion_ratio": -np.array(ratio),
        }
        digest = Digest()
        for cut in (slice(0, 1), slice(1, 4)):  # the angle nearest 90° in its own chunk
            digest.add(Part({k: v[cut] for k, v in columns.items()}))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PlausibilityWarning)
            _warn_transmission(digest)
        (w,) = caught
        assert way in str(w.message), str(w.message)
        assert f"|{ratio[-1]:.3g}| there, |{ratio[0]:.3g}| at 90 deg" in str(w.message)


def test_sweep_failure_report_names_the_dead_centre(tmp_path, capsys):
    path = write(tmp_path / "g.yaml", near_dead_centre(0.6, 38.6))
    code = main(
        ["sweep", str(path), str(EXAMPLES / "bump_rack_held.yaml"), "-o", str(tmp_path / "r.csv")]
    )
    assert code == 1
    err = capsys.readouterr().err
    (report,) = [line for line in err.splitlines() if "did not converge" in line]
    assert "out of the mechanism's reach" in report
    assert "at a dead centre at design (pushrod → rocker 0.6° from dead centre" in report
    assert "its motion ratio rises toward infinity" in err  # the band warning, the right way


def test_loads_says_the_spring_is_bypassed_at_a_dead_centre(tmp_path, capsys):
    """The issue's 7.9 N from 2 000 N: the spring's share of the tyre's vertical load is
    about 1 / motion ratio (virtual work, the design's MR by differences); at a dead
    centre each load case says so."""
    g = near_dead_centre(0.6, 38.6)
    ratio = _motion_ratio(tmp_path, g)
    capsys.readouterr()
    path, sweep = tmp_path / "g.yaml", tmp_path / "s.yaml"
    out = tmp_path / "f.csv"
    cases = EXAMPLES / "loads.yaml"
    assert main(["loads", str(path), str(sweep), "--cases", str(cases), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    bump = [abs(float(r["force_spring"])) for r in rows(out) if r["load_case"] == "3g bump"]
    # at design the spring sees Fz / MR; the rocker turns ~0.1° over the 2 µm of droop,
    # which near its dead centre is a sixth of its margin, so the most is more than that
    assert bump[-1] == pytest.approx(2100 / ratio, rel=0.01)
    force = max(bump)
    (line,) = [x for x in err.splitlines() if "load case '3g bump'" in x]
    assert f"the spring takes at most {force:.3g} N of the 2100 N vertical load" in line
    assert "pushrod → rocker is 0.6° from dead centre" in line and "bypasses the spring" in line
    assert len([x for x in err.splitlines() if "load case '" in x]) == 3  # each case


def test_no_loads_warning_without_a_dead_centre(tmp_path, capsys):
    sweep = write(tmp_path / "s.yaml", DESIGN)
    geometry = str(EXAMPLES / "pushrod_rocker.yaml")
    cases = str(EXAMPLES / "loads.yaml")
    assert (
        main(["loads", geometry, str(sweep), "--cases", cases, "-o", str(tmp_path / "f.csv")]) == 0
    )
    assert "dead centre" not in capsys.readouterr().err


def test_validate_reports_another_branch_and_marks_what_it_says(tmp_path, capsys):
    """Near dead centre the point-based solve mirrors the rocker at some steps (its
    distances allow it): validate says 'lands on another assembly branch' for them —
    checked here by the handedness of the rocker's four points against pin_susp's —
    and its closing line says 'marked !' only when a cell is marked."""
    from pin_susp import Corner
    from pin_susp.model.sweep import load_sweep
    from pin_susp.validate import pointwise_points

    g = near_dead_centre(0.6, 38.6)
    path = write(tmp_path / "g.yaml", g)
    sweep = EXAMPLES / "bump_rack_held.yaml"
    assert main(["validate", str(path), str(sweep), "--engine", "pointwise"]) == 1
    out = capsys.readouterr().out
    table = [line for line in out.splitlines() if re.match(r"  \w+ +\S+ +\S+[! ]$", line)]
    marked = sorted(line.split()[0] for line in table if line.endswith("!"))
    verdict = [line for line in out.splitlines() if line.startswith("  pointwise: ")]
    disagree = [line for line in verdict if "DISAGREES" in line]
    if marked:
        (line,) = disagree
        assert line.endswith(f"DISAGREES on {', '.join(marked)} (marked !)")
    else:
        assert not disagree and "marked !" not in out
    (branch,) = [line for line in verdict if "lands on another assembly branch" in line]
    steps = [int(s) for s in branch.split("at steps ")[1].split(" (")[0].split(", ")]
    assert "the rocker mirrored" in branch and "pushrod → rocker 0.6° from dead centre" in branch

    corner = Corner(path)
    results = corner.run_sweep(load_sweep(sweep))
    points = pointwise_points(corner, load_sweep(sweep))
    names = ("rocker_axis_a", "rocker_axis_b", "pushrod_inboard", "strut_bottom")

    def volume(p):
        a, b, c, d = (np.asarray(p[n]) for n in names)
        return np.linalg.det(np.array([b - a, c - a, d - a]))

    design = volume({n: xyz(g["hardpoints"][n]) for n in names})
    for i, at in enumerate(points):
        if at is None or not results["solver_converged"][i]:
            continue
        theirs = {n: at[n].val[0] for n in names}
        ours = {n: [float(results[f"{n}_{a}"][i]) * 1e-3 for a in "xyz"] for n in names}
        assert np.sign(volume(ours)) == np.sign(design)  # pin_susp keeps the design's
        assert (np.sign(volume(theirs)) != np.sign(design)) == (i in steps), i


def test_axle_droplink_near_the_bars_dead_centre_warns_once(tmp_path):
    """A U-bar's droplink all but through the bar's axis: the droplink drives the bar's
    arm (toward infinity), said for the left with the mirrored right."""
    from pin_susp.errors import PlausibilityWarning
    from pin_susp.subjects.axle import load_axle

    a = example("axle_front.yaml")
    a["hardpoints"]["left"]["droplink_u_bar"] = {"x": 0.5, "y": 300, "z": 220}
    path = write(tmp_path / "a.yaml", a)
    hp = a["hardpoints"]["left"] | a["hardpoints"]["center"]
    angle, miss = by_hand(
        {"hardpoints": hp},
        "droplink_u_bar",
        "droplink_rocker",
        "arb_u_bar_axis_a",
        "arb_u_bar_axis_b",
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PlausibilityWarning)
        load_axle(path)
    (line,) = [str(w.message) for w in caught if "dead centre" in str(w.message)]
    assert line.startswith(f"{path}: left droplink → left arb arm is {180 - angle:.1f}° from")
    assert (
        f"passes {miss:.2f} mm from the left arb arm axis arb_u_bar_axis_a–arb_u_bar_axis_b" in line
    )
    assert "rises toward infinity" in line and line.endswith("(the mirrored right side likewise)")


def test_mujoco_landing_on_the_other_rocker_branch_is_said_so(tmp_path):
    """The issue's MuJoCo: from the design state, near the rocker's dead centre, its
    Newton lands some steps on the pushrod loop's other assembly. Those steps are the
    ones whose MuJoCo points have the pushrod loop's chirality (rocker axis, pushrod
    ends: signed volume) opposite to the design's; none of them is compared."""
    pytest.importorskip("mujoco")
    from pin_susp import Corner
    from pin_susp.model.mjcf import tree_to_mjcf
    from pin_susp.model.sweep import load_sweep
    from pin_susp.validate import mujoco_points, validate

    g = near_dead_centre(0.6, 38.6)
    corner = Corner(write(tmp_path / "g.yaml", g))
    sweep = load_sweep(EXAMPLES / "bump_rack_held.yaml")
    results, (report,) = validate(corner, sweep, engines=("mujoco",))
    assert report.branch_steps and report.flipped == {"the pushrod loop"}
    assert not report.disagree and not report.agrees
    names = ("rocker_axis_a", "rocker_axis_b", "pushrod_outboard", "pushrod_inboard")

    def volume(p):
        a, b, c, d = (np.asarray(p[n], dtype=float) for n in names)
        return np.linalg.det(np.array([b - a, c - a, d - a]))

    design = np.sign(volume({n: xyz(g["hardpoints"][n]) for n in names}))
    points = mujoco_points(corner, sweep, tree_to_mjcf(corner.tree))
    other = [
        i
        for i, at in enumerate(points)
        if at is not None
        and results["solver_converged"][i]
        and np.sign(volume({n: at[n].val[0] for n in names})) != design
    ]
    assert other == report.branch_steps
