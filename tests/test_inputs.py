"""Inputs a user trips on (issue 24, point 6): the tyre's one key, a camber target
without a shim, the spring-unseating advice, a bump-only sweep on a rack corner."""

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example

from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.model.geometry import load_geometry

SIZE = {"aspect_ratio": 0.55, "section_width": 270, "rim_diameter": 13}


def write(path, data):
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def wheel(tmp_path, **blocks):
    """The pushrod-rocker example (its tyre has a rate) with config.wheel's tyre blocks
    replaced by ``blocks`` (tyre=..., tire=...)."""
    g = example("pushrod_rocker.yaml")
    w = g["config"]["wheel"]
    w.pop("tire"), w.pop("tyre")
    w.update(blocks)
    return write(tmp_path / "corner.yaml", g)


def read_error(path) -> str:
    with pytest.raises(InputError) as info:
        load_geometry(path)
    return str(info.value)


@pytest.mark.parametrize("key", ["tyre", "tire"])
def test_the_tyre_is_one_key_and_tire_its_synonym(tmp_path, key):
    """The size and the rate under tyre: (or tire:) read as the example's split form."""
    split = load_geometry(EXAMPLES / "pushrod_rocker.yaml").wheel
    one = load_geometry(wheel(tmp_path, **{key: {**SIZE, "rate": 120}})).wheel
    assert one == split
    assert one.tyre_rate == 120 and one.radius == pytest.approx(0.5 * 13 * 0.0254 + 0.55 * 0.27)


def test_a_value_under_both_tyre_and_tire_names_the_other(tmp_path):
    text = read_error(wheel(tmp_path, tire={**SIZE, "rate": 100}, tyre={"rate": 120}))
    assert "config.wheel.tire.rate: given also as config.wheel.tyre.rate" in text
    assert "synonym" in text


def test_the_rate_under_tire_and_the_size_under_tyre_are_read(tmp_path):
    """Either block takes every tyre value: no 'unknown key' for a rate under tire:."""
    g = load_geometry(wheel(tmp_path, tire={"rate": 120}, tyre=SIZE)).wheel
    assert g.tyre_rate == 120 and g.section_width == pytest.approx(0.27)


def test_a_missing_size_names_the_block_and_its_synonym(tmp_path):
    text = read_error(wheel(tmp_path, tyre={"rate": 120}))
    assert "config.wheel.tyre.aspect_ratio: missing key" in text and "tire:" in text
    text = read_error(wheel(tmp_path))
    assert "config.wheel.tire: missing key: the tyre, as tire: or tyre:" in text


def test_an_unknown_tyre_key_lists_the_size_and_the_rate(tmp_path):
    text = read_error(wheel(tmp_path, tire={**SIZE, "stiffness": 120}))
    assert "config.wheel.tire.stiffness: unknown key" in text
    assert "aspect_ratio, diameter, loaded_radius, rate, rim_diameter, section_width, width" in text


def test_a_bad_tyre_value_is_named_where_it_was_written(tmp_path):
    text = read_error(wheel(tmp_path, tyre={**SIZE, "section_width": 0}))
    assert "config.wheel.tyre.section_width: must be > 0" in text


@pytest.mark.filterwarnings("ignore:.*tyre radius")
def test_a_plausibility_warning_names_the_key_as_written(tmp_path):
    from pin_susp.errors import PlausibilityWarning

    with pytest.warns(PlausibilityWarning, match=r"config\.wheel\.tyre\.rim_diameter = 330"):
        load_geometry(wheel(tmp_path, tyre={**SIZE, "rim_diameter": 330}))
    with pytest.warns(PlausibilityWarning, match=r"config\.wheel\.tire\.rim_diameter = 330"):
        load_geometry(wheel(tmp_path, tire={**SIZE, "rim_diameter": 330}))


def test_an_axle_reads_its_tyre_under_one_key(tmp_path):
    from pin_susp.subjects.axle import load_axle

    data = example("axle_front.yaml")
    w = data["axle_config"]["wheel"]
    w["tyre"] = {**w.pop("tire"), "rate": 120}
    axle = load_axle(write(tmp_path / "axle.yaml", data))
    assert axle.left.wheel.tyre_rate == axle.right.wheel.tyre_rate == 120
    w["tire"] = {"rate": 100}
    with pytest.raises(InputError, match=r"axle_config\.wheel\.tire\.rate: given also as"):
        load_axle(write(tmp_path / "axle.yaml", data))


@pytest.mark.parametrize(
    "name, alternative",
    [("double_wishbone.yaml", "add config.camber_shim"), ("macpherson.yaml", "strut top")],
)
def test_a_camber_target_without_a_shim_names_the_alternatives(tmp_path, capsys, name, alternative):
    """The error says what sets camber instead, and where the docs say more: a link
    into docs/ that exists (the heading's anchor as GitHub makes it)."""
    import re

    out = tmp_path / "s.yaml"
    assert main(["setup", str(EXAMPLES / name), "--camber", "-2", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a camber target needs a camber shim" in err
    assert alternative in err and "pin-susp sensitivity" in err
    doc, anchor = re.search(r"(docs/[a-z]+\.md)#([a-z0-9_-]+)", err).groups()
    headings = (EXAMPLES.parent / doc).read_text().splitlines()
    slugs = {
        re.sub(r"[^\w\- ]", "", h.lstrip("#").strip().lower()).replace(" ", "-")
        for h in headings
        if h.startswith("#")
    }
    assert anchor in slugs
    assert not out.exists()


def unseat_warning(tmp_path, capsys, change) -> str:
    """The spring-unseating warning of `pin-susp sweep` on the pushrod-rocker example
    (coilover 175 N/mm) changed by ``change``, over bump_steer.yaml (-40 … +60 mm)."""
    g = example("pushrod_rocker.yaml")
    change(g)
    path = write(tmp_path / "corner.yaml", g)
    main(["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(tmp_path / "r.csv")])
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "spring force below zero" in x]
    return line


def test_a_spring_unseating_in_droop_is_told_to_limit_the_droop(tmp_path, capsys):
    line = unseat_warning(tmp_path, capsys, lambda g: g["spring"].update(preload=1000.0))
    assert line.endswith("more preload, or limit the droop travel (a droop limiter)")
    assert "bump" not in line


def test_a_spring_extending_in_bump_is_not_told_less_droop(tmp_path, capsys):
    """A rocker that extends the coilover in bump (motion_ratio < 0): the force falls
    below zero in bump (about 20 mm up), where less droop would change nothing."""

    def over_centre(g):
        g["hardpoints"]["pushrod_inboard"] = {"x": 0, "y": 290, "z": 440}

    line = unseat_warning(tmp_path, capsys, over_centre)
    assert "(in bump): the spring extends as the wheel rises" in line
    assert "motion_ratio <= 0" in line and "droop is not the cause" in line
    assert "limit the droop" not in line


def test_a_spring_below_zero_in_droop_and_bump_gets_advice_for_each(tmp_path, capsys):
    """A negative preload: below zero from full droop to past design, compressing all
    the way (motion_ratio > 0): more preload on both sides, each side's steps named."""
    line = unseat_warning(tmp_path, capsys, lambda g: g["spring"].update(preload=-500.0))
    droop, bump = line.split(" in droop (steps ")[1].split("; in bump (steps ")
    assert droop.startswith("0, 1, 2,")
    assert "more preload: the spring compresses in bump here" in bump
    assert "over-centre" not in line


def doc_commands():
    """Every `pin-susp ...` command line the README and docs/ give with arguments: code
    spans (a span may wrap across lines), `$ pin-susp` lines and lines of a shell
    block. A synopsis' [optional] parts are left out; `a|b` alternatives and a bare
    `pin-susp COMMAND` (naming the command, not running it) are no command line."""
    import re

    root = EXAMPLES.parent
    out = []
    for path in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
        text = path.read_text()
        found = [m.group(1) for m in re.finditer(r"`(pin-susp [^`]+)`", text)]
        found += re.findall(r"^\$ (pin-susp .+)$", text, re.M)
        found += re.findall(r"^(pin-susp .+?)(?:\s+#.*)?$", text, re.M)
        for line in found:
            line = " ".join(re.sub(r"\[[^\]]*\]", "", line).split())
            words = line.split()
            if len(words) > 2 and "|" not in words[1] and words[1].islower():
                out.append((path.name, line))
    return out


def test_every_command_line_in_the_docs_parses():
    """A user copies a command from the README: it must at least parse (the README's
    `pin-susp sweep bump_steer/best.yaml examples/bump_rack_held.yaml` lacked -o)."""
    import contextlib
    import io
    import shlex

    from pin_susp.cli import _parser

    commands = doc_commands()
    assert len(commands) > 40
    assert any("bump_steer/best.yaml" in line for _, line in commands)
    bad = []
    for name, line in commands:
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                _parser().parse_args(shlex.split(line)[1:])
        except SystemExit as exc:
            if exc.code:
                bad.append(f"{name}: {line}: {err.getvalue().strip()}")
    assert not bad, "\n".join(bad)


def bump_only(steps: int) -> dict:
    return {"steps": steps, "targets": [
        {"point": "wheel_center", "direction": {"axis": "z"}, "start": -30, "stop": 30}
    ]}  # fmt: skip


def rack_held(steps: int) -> dict:
    s = bump_only(steps)
    s["targets"].append(
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": 0, "stop": 0}
    )
    return s


@pytest.mark.parametrize("steps", [21, 400])  # step by step, and the batched long sweep
def test_a_bump_only_sweep_on_a_rack_corner_holds_the_rack_at_design(corner, steps):
    """The same rows as the sweep that holds the rack at 0 itself, on both solve paths."""
    own = corner.run_sweep(bump_only(steps))
    held = corner.run_sweep(rack_held(steps))
    assert own.columns.keys() == held.columns.keys()
    for name, values in held.columns.items():
        np.testing.assert_allclose(own[name], values, rtol=0, atol=1e-9, err_msg=name)
    assert np.all(own["rack_displacement"] == 0.0) and own["solver_converged"].all()
    assert own.meta["notes"] == ["rack held at design (the sweep gives no rack target)"]
    assert held.meta["notes"] == []


def test_the_summary_says_the_rack_was_held(tmp_path, capsys):
    sweep = write(tmp_path / "bump.yaml", bump_only(11))
    out = tmp_path / "r.csv"
    geometry = str(EXAMPLES / "double_wishbone.yaml")
    assert main(["sweep", geometry, str(sweep), "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "  rack held at design (the sweep gives no rack target)"
    assert main(["sweep", geometry, str(EXAMPLES / "bump_rack_held.yaml"), "-o", str(out)]) == 0
    assert "rack held" not in capsys.readouterr().out
    cases = str(EXAMPLES / "loads.yaml")
    rocker = str(EXAMPLES / "pushrod_rocker.yaml")
    assert main(["loads", rocker, str(sweep), "--cases", cases, "-o", str(out)]) == 0
    assert "  rack held at design (the sweep gives no rack target)" in capsys.readouterr().out


def test_a_bump_only_sweep_validates_and_differentiates_with_the_rack_held(corner):
    """The pointwise re-solve (scipy on the points) holds the rack too and agrees; the
    hardpoint sensitivities are those with the rack's own target."""
    from pin_susp.analyses.sensitivity import hardpoint_sensitivities
    from pin_susp.model.sweep import load_sweep
    from pin_susp.validate import validate

    results, (report,) = validate(corner, load_sweep(bump_only(5)), engines=("pointwise",))
    assert not report.note and not report.failed_steps and not report.disagree
    assert report.differences["roadwheel_angle"] < 1e-9
    # every column within 1e-6 mm or deg but the kinematic instant centre, a pole v/ω_x
    # tens of km out here (ω_x near 0): compared relative to |IC|²/half track (above)
    near = {k: d for k, d in report.differences.items() if "kinematic_instant" not in k}
    assert max(near.values()) < 1e-6, near
    np.testing.assert_array_equal(results["rack_displacement"], 0.0)
    sa = hardpoint_sensitivities(corner, bump_only(3))
    sb = hardpoint_sensitivities(corner, rack_held(3))
    for x, y in zip(sa, sb, strict=True):
        for name, v in y.values.items():
            np.testing.assert_allclose(x.values[name], v, atol=1e-12, err_msg=name)


def test_a_rack_corner_still_refuses_a_sweep_of_the_rack_alone(tmp_path, corner):
    steer = {"steps": 3, "targets": [
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": -5, "stop": 5}
    ]}  # fmt: skip
    with pytest.raises(InputError, match="a wheel target alone holds the rack at design"):
        corner.run_sweep(steer)


def test_an_axle_sweep_of_heave_and_roll_alone_holds_the_rack_at_design(tmp_path, capsys):
    """An axle too: roll.yaml without its rack target gives roll.yaml's rows (which hold
    the rack at 0 themselves), through sweep, validate and sensitivity, and says so."""
    explicit = yaml.safe_load((EXAMPLES / "roll.yaml").read_text())
    assert explicit["targets"][-1]["point"] == "trackrod_inboard"
    alone = write(tmp_path / "roll_only.yaml", dict(explicit, targets=explicit["targets"][:2]))
    import pandas as pd

    axle = str(EXAMPLES / "axle_front.yaml")
    rows = {}
    for name, sweep in (("alone", alone), ("explicit", EXAMPLES / "roll.yaml")):
        out = tmp_path / f"{name}.csv"
        assert main(["sweep", axle, str(sweep), "-o", str(out)]) == 0
        said = capsys.readouterr().out
        assert ("rack held at design (the sweep gives no rack target)" in said) == (name == "alone")
        rows[name] = pd.read_csv(out, comment="#")
    assert list(rows["alone"].columns) == list(rows["explicit"].columns)
    for column in rows["explicit"].columns:
        np.testing.assert_allclose(
            rows["alone"][column].astype(float),
            rows["explicit"][column].astype(float),
            rtol=0,
            atol=1e-9,
            err_msg=column,
        )
    assert main(["validate", axle, str(alone), "--engine", "pointwise"]) == 0
    assert main(["sensitivity", axle, "--sweep", str(alone), "-o", str(tmp_path / "s.csv")]) == 0
