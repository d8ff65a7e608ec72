"""Elastokinematics (docs/compliance.md) against computations that share nothing with
its KKT solve: a bushing's deflection from the statics' leg force (a two-force member
to that pickup), the bushing's energy (Castigliano), the stiff limit, the loaded pose's
own nonlinear solve (its difference O(F²), its derivative at F → 0), mirror symmetry."""

import subprocess
import sys

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp.analyses.compliance import KC, kc_results
from pin_susp.analyses.compliance_model import ComplianceModel
from pin_susp.analyses.load_case import LoadCase
from pin_susp.analyses.statics import Statics
from pin_susp.errors import InputError, PinSuspError
from pin_susp.io.yamlio import Reader
from pin_susp.model.compliance import read_compliance
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.subject import load_subject

SWEEP = Sweep([Target("wheel_center", "z", [-25.0, 0.0, 30.0]),
               Target("trackrod_inboard", "y", [6.0, 0.0, -4.0])], "bump+steer")  # fmt: skip
LATERAL = LoadCase("lateral", np.array([0.0, -1000.0, 0.0]), np.zeros(3), np.zeros(3))
MIXED = LoadCase("mixed", np.array([-800.0, -1200.0, 300.0]), np.array([-200.0, 0, 0]),
                 np.array([0.0, 0.0, 60.0]))  # fmt: skip


@pytest.fixture(scope="module")
def fs():
    return load_subject(EXAMPLES / "kc_fs_corner.yaml")


@pytest.fixture(scope="module")
def saloon():
    return load_subject(EXAMPLES / "kc_saloon_corner.yaml")


def _comp(subject, block):
    return {"": read_compliance(block, Reader("test"), list(subject.points))}


def test_stiff_limit_compliance_scales_as_one_over_k(saloon):
    """Every stiffness × 1e6: every deflection × 1e-6 (the linear solve is exact in 1/k)."""
    kc = KC(saloon)
    stiff = KC(saloon, {"": kc.model and read_compliance(
        saloon.corners[""].data["compliance"], Reader("t")).scaled(1e6)})  # fmt: skip
    qs = [s.q for s in saloon.solve_steps(SWEEP)]
    W = Statics.loads_matrix(kc, [LATERAL, MIXED])
    a, b = kc.linear(qs, W), stiff.linear(qs, W)
    big = np.abs(a) > 1e-6 * np.abs(a).max()
    assert big.sum() > 50
    assert np.allclose(b[big] / a[big], 1e-6, rtol=1e-6)


def test_one_bushing_against_its_leg_force(fs):
    """Only the lower front pickup compliant (k in every translation, free to turn): its
    radial deflection is the front leg's tension's radial part over k — the load path
    through that two-force leg (the statics' force) — and the work of the load equals
    the bushing's energy ×2 (Castigliano), to 1e-9."""
    k = 5000.0  # N/mm
    comp = _comp(fs, {"bushings": {"lower_wishbone_inboard_front": {"radial": k, "axial": k}}})
    model = ComplianceModel(fs, comp)
    statics = Statics(fs)
    for q in [s.q for s in fs.solve_steps(SWEEP)]:
        for case in (LATERAL, MIXED):
            w = statics.loads_matrix([case])
            dx, state = model.linear(q, w)
            forces = statics.solve(q, case)
            tension = forces["force_lower_wishbone_front"]
            p = fs.design_positions
            a = p["lower_wishbone_inboard_front"]
            axis = p["lower_wishbone_inboard_rear"] - a
            axis /= np.linalg.norm(axis)
            fs.kin.update(q)
            leg = fs.points["lower_wishbone_outboard"].position(fs.kin) - a
            leg /= np.linalg.norm(leg)
            radial = tension * (leg - (leg @ axis) * axis)
            d, D, cb = state[5][("bushing_lower_wishbone_inboard_front", "")]
            deflection = D @ dx[cb : cb + 6, 0]
            assert np.linalg.norm(deflection[:3]) == pytest.approx(
                np.linalg.norm(radial) / (k * 1e3), rel=1e-9
            )
            assert abs(deflection[2]) < 1e-12 * np.linalg.norm(radial)  # axial: the rear's
            work = (state[4] @ w[:, 0]) @ dx[:, 0]
            assert work == pytest.approx(np.linalg.norm(radial) ** 2 / (k * 1e3), rel=1e-9)


def test_linear_against_nonlinear_is_second_order(saloon):
    """|nonlinear − linear| of the wheel centre's and the bushings' motion scales as F²
    over a decade of F (ratio 100 ± 5 %)."""
    kc = KC(saloon)
    q = saloon.solve_steps(SWEEP)[1].q
    diffs = []
    for F in (200.0, 2000.0):
        W = Statics.loads_matrix(kc, [MIXED]) * (F / 1000.0)
        diffs.append(np.abs(kc.nonlinear([q], W) - kc.linear([q], W)).max())
    assert diffs[0] > 0
    assert diffs[1] / diffs[0] == pytest.approx(100.0, rel=0.05)


def test_linear_is_the_derivative_of_the_loaded_pose(fs):
    """Central differences of the nonlinear loaded pose in F (±h): the linear compliance
    to 1e-6."""
    kc = KC(fs)
    q = fs.solve_steps(SWEEP)[2].q
    W = Statics.loads_matrix(kc, [MIXED])
    h = 1e-2
    fd = (kc.nonlinear([q], W * h) - kc.nonlinear([q], -W * h)) / (2 * h)
    lin = kc.linear([q], W)
    motion = lin[0, :5, 0]  # the corner's motion columns
    assert np.allclose(fd[0, :5, 0], motion, rtol=1e-6, atol=1e-9 * np.abs(motion).max())


def test_axle_compliance_mirrors(tmp_path):
    """The example axle with bushings: a load and its mirror on the two wheels give
    mirrored compliances (toe, camber, x, z equal; y opposite) and equal rates."""
    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    data["compliance"] = {
        "bushings": {
            "lower_wishbone_inboard_front": {"radial": 3000, "axial": 800, "torsional": 1},
            "lower_wishbone_inboard_rear": {"radial": 1500, "axial": 500, "conical": 5},
            "upper_wishbone_inboard_front": {"radial": 2000, "axial": 500},
            "upper_wishbone_inboard_rear": {"radial": 2000, "axial": 500},
        },
        "links": {"trackrod": 20000, "pushrod": 30000},
    }  # fmt: skip
    path = tmp_path / "axle.yaml"
    path.write_text(yaml.safe_dump(data))
    axle = load_subject(path)
    cases = tmp_path / "cases.yaml"
    cases.write_text(yaml.safe_dump({"cases": [{"name": "mirrored", "left": {
        "contact_patch": {"fx": -700, "fy": -1200, "fz": 200},
        "moment": {"mx": 0, "my": 0, "mz": 50}},
        "right": {"contact_patch": {"fx": -700, "fy": 1200, "fz": 200},
                  "moment": {"mx": 0, "my": 0, "mz": -50}}}]}))  # fmt: skip
    sweep = {"steps": 3, "targets": [
        {"point": "wheel_center", "side": side, "direction": {"axis": "z"}, "mode": "relative",
         "start": -20, "stop": 20} for side in ("left", "right")]}  # fmt: skip
    table = kc_results(axle, sweep, str(cases))
    names = ("compliance_toe", "compliance_camber", "compliance_wheel_center_x",
             "compliance_wheel_center_z", "lateral_force_steer", "aligning_torque_steer",
             "longitudinal_compliance", "bushing_lower_wishbone_inboard_rear_radial")  # fmt: skip
    for name in names:
        left, right = table[f"{name}_left"], table[f"{name}_right"]
        assert np.abs(left).max() > 0
        assert np.allclose(left, right, rtol=1e-9, atol=1e-12)
    y = table["compliance_wheel_center_y_left"], table["compliance_wheel_center_y_right"]
    assert np.allclose(y[0], -y[1], rtol=1e-9, atol=1e-12)


def _geometry(tmp_path, block):
    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    data["compliance"] = block
    path = tmp_path / "g.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


FRONT = "lower_wishbone_inboard_front"
SKEW = (np.eye(6) + np.triu(np.ones((6, 6)), 1)).tolist()


@pytest.mark.parametrize(
    ("block", "key", "why"),
    [
        ({"bushings": {"nowhere": {"radial": 1, "axial": 1}}}, "bushings.nowhere", "unknown"),
        ({"bushings": {FRONT: {"radial": 0, "axial": 1}}}, "radial", "> 0"),
        ({"bushings": {FRONT: {"radial": 1, "axial": 1, "conical": -1}}}, "conical", ">= 0"),
        ({"bushings": {FRONT: {"k": [[1] * 6] * 5}}}, ".k", "6×6"),
        ({"bushings": {FRONT: {"k": SKEW}}}, ".k", "not symmetric"),
        ({"bushings": {FRONT: {"k": (-np.eye(6)).tolist()}}}, ".k", "not positive definite"),
        ({"links": {"trackrod": -5}}, "links.trackrod", "> 0"),
        ({"tyre": {"vertical": 100, "sideways": 3}}, "tyre.sideways", "unknown key"),
    ],
)  # fmt: skip
def test_bad_compliance_is_one_message(tmp_path, block, key, why):
    path = _geometry(tmp_path, block)
    with pytest.raises(InputError) as e:
        load_geometry(path)
    assert str(path) in str(e.value) and key in str(e.value) and why in str(e.value)


def test_a_bushing_off_a_pivot_and_an_unknown_link(tmp_path):
    for block, key in (
        ({"bushings": {"lower_wishbone_outboard": {"radial": 1, "axial": 1}}}, "outboard"),
        ({"links": {"toe_link": 5000}}, "links.toe_link"),
    ):  # fmt: skip
        subject = load_subject(_geometry(tmp_path, block))
        with pytest.raises(InputError, match=key):
            KC(subject)


def test_no_compliance_said(fs):
    """A corner without a compliance: block: said (nothing is compliant); a link alone is
    enough."""
    KC(fs, _comp(fs, {"links": {"trackrod": 1.0}}))
    with pytest.raises(PinSuspError, match="no compliance"):
        KC(load_subject(EXAMPLES / "pushrod_rocker.yaml"))


def test_cli_kc_writes_the_table(tmp_path):
    out = tmp_path / "kc.csv"
    run = subprocess.run(
        [sys.executable, "-m", "pin_susp", "kc", str(EXAMPLES / "kc_fs_corner.yaml"),
         str(EXAMPLES / "bump_steer.yaml"), "--cases", str(EXAMPLES / "kc.yaml"), "-o", str(out),
         "--plot", str(tmp_path / "kc.png")],
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "lateral_force_steer" in run.stdout and (tmp_path / "kc.png").stat().st_size > 10000
    import pandas as pd

    df = pd.read_csv(out, comment="#")
    assert len(df) == 41 * 4
    subject = load_subject(EXAMPLES / "kc_fs_corner.yaml")
    api = kc_results(subject, EXAMPLES / "bump_steer.yaml", EXAMPLES / "kc.yaml").to_pandas()
    for name in (
        "compliance_toe",
        "lateral_force_camber",
        "bushing_upper_wishbone_inboard_rear_radial",
    ):
        assert np.allclose(df[name], api[name], rtol=1e-6, atol=1e-9)


def test_a_full_6x6_is_the_rate_form(saloon):
    """{k: 6×6} diag(radial, radial, axial, conical, conical, torsional) (N/mm; N·m/rad)
    gives the rate form's K&C to the last digits."""
    deg = np.pi / 180
    rates = {"radial": 3000, "axial": 800, "torsional": 1.0, "conical": 10.0}
    diag = [3000, 3000, 800, 10.0 / deg, 10.0 / deg, 1.0 / deg]
    front = "lower_wishbone_inboard_front"
    a = KC(saloon, _comp(saloon, {"bushings": {front: rates}}))
    b = KC(saloon, _comp(saloon, {"bushings": {front: {"k": np.diag(diag).tolist()}}}))
    qs = [s.q for s in saloon.solve_steps(SWEEP)]
    W = Statics.loads_matrix(a, [MIXED])
    assert np.allclose(a.linear(qs, W), b.linear(qs, W), rtol=1e-12, atol=1e-15)


def test_cli_kc_nonlinear_to_parquet(tmp_path):
    """--method nonlinear, Parquet output: the compliances near the linear ones (1 kN on
    rubber: within 5 % and 1e-3, the braking cases' recession of ~2 mm the farthest),
    not equal to them, the rates the same."""
    import pandas as pd

    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(yaml.safe_dump({"steps": 3, "targets": [{"point": "wheel_center",
        "direction": {"axis": "z"}, "mode": "relative", "start": -20, "stop": 20}]}))  # fmt: skip
    tables = {}
    for method in ("linear", "nonlinear"):
        out = tmp_path / f"{method}.parquet"
        run = subprocess.run(
            [sys.executable, "-m", "pin_susp", "kc", str(EXAMPLES / "kc_saloon_corner.yaml"),
             str(sweep), "--cases", str(EXAMPLES / "kc.yaml"), "-o", str(out), "--method",
             method, "-q"],
            capture_output=True, text=True, cwd=tmp_path,
        )  # fmt: skip
        assert run.returncode == 0, run.stderr
        assert run.stdout == ""
        tables[method] = pd.read_parquet(out)
    lin, nl = tables["linear"], tables["nonlinear"]
    assert np.allclose(lin["lateral_force_steer"], nl["lateral_force_steer"], rtol=1e-12)
    for name in ("compliance_toe", "compliance_wheel_center_x"):
        assert not np.allclose(lin[name], nl[name], rtol=1e-9, atol=0)
        assert np.allclose(lin[name], nl[name], rtol=0.05, atol=1e-3)


def test_compliance_rates_follow_force_units(tmp_path):
    """force_units: lbf — the rates in lbf/in and lbf·in/deg (a 6×6's blocks in lbf/in,
    lbf/rad, lbf·in/rad), converted by hand here: the same SI stiffnesses."""
    from pin_susp.analyses.compliance import subject_compliance

    lbf, inch = 4.4482216152605, 25.4  # N, mm
    rate, moment = lbf / inch, lbf * inch / 1000.0  # N/mm per lbf/in, N·m per lbf·in
    data = yaml.safe_load((EXAMPLES / "kc_saloon_corner.yaml").read_text())
    k6 = np.diag([3000.0, 3000.0, 800.0, 600.0, 600.0, 60.0])
    k6[0, 4] = k6[4, 0] = 50.0  # a coupling term: N/rad
    data["compliance"]["bushings"]["lower_wishbone_inboard_rear"] = {"k": k6.tolist()}
    (tmp_path / "n.yaml").write_text(yaml.safe_dump(data))
    block = data["compliance"]
    front = block["bushings"]["lower_wishbone_inboard_front"]
    for k in ("radial", "axial"):
        front[k] /= rate
    for k in ("torsional", "conical"):
        front[k] /= moment
    per = np.full((6, 6), lbf)
    per[:3, :3], per[3:, 3:] = rate, moment
    block["bushings"]["lower_wishbone_inboard_rear"] = {"k": (k6 / per).tolist()}
    block["links"] = {n: v / rate for n, v in block["links"].items()}
    block["tyre"] = {n: v / rate for n, v in block["tyre"].items()}
    data["force_units"] = "lbf"
    (tmp_path / "lbf.yaml").write_text(yaml.safe_dump(data))
    (a,), (b,) = (
        subject_compliance(load_subject(tmp_path / n)).values() for n in ("n.yaml", "lbf.yaml")
    )
    assert a.bushings.keys() == b.bushings.keys() and a.links.keys() == b.links.keys()
    for name in a.bushings:
        np.testing.assert_allclose(b.bushings[name], a.bushings[name], rtol=1e-12)
    for name in a.links:
        assert b.links[name] == pytest.approx(a.links[name], rel=1e-12)
    assert b.tyre == pytest.approx(a.tyre, rel=1e-12)
