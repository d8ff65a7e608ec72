"""A car's K&C (docs/compliance.md, "A vehicle"): each corner's compliance from its axle
file's ``compliance:`` block, its columns suffixed by the corner (``_fl`` … ``_rr``).
With the body held (as ``pin-susp loads`` holds it), each axle of the car is held as
the axle alone is at the same wheel heights and rack travel: the car's K&C per corner
is the axle model's own (tests/vehicles.py ``axle_alone``), to 1e-9."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from vehicles import axle_alone, body_sweep

from pin_susp.analyses.compliance import KC, kc_results
from pin_susp.analyses.load_case import load_cases
from pin_susp.cli import main
from pin_susp.subjects.vehicle import AXLES, Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CAR = str(EXAMPLES / "vehicle_fs.yaml")
CP, WC, MZ = "contact_patch", "wheel_center", "moment"
LOADS = {  # a different load at each wheel, N and N·m (world axes)
    "fl": {CP: {"fx": -400, "fy": -900, "fz": 300}, MZ: {"mx": 0, "my": 0, "mz": 60}},
    "fr": {CP: {"fx": -300, "fy": 500, "fz": -200}},
    "rl": {WC: {"fx": -700, "fy": 0, "fz": 0}, CP: {"fx": 0, "fy": -300, "fz": 150}},
    "rr": {CP: {"fx": 200, "fy": 800, "fz": 400}, MZ: {"mx": 0, "my": 0, "mz": -40}},
}


def cases_file(path, blocks: dict) -> str:
    path.write_text(yaml.safe_dump({"version": 1, "cases": [{"name": "mixed", **blocks}]}))
    return str(path)


@pytest.fixture(scope="module")
def car_kc(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("kc_car")
    car = Vehicle(CAR)
    sweep = body_sweep(np.linspace(-20.0, 20.0, 5), 0.0, 0.0, np.linspace(-30.0, 30.0, 5))
    solutions = car.solve_steps(sweep)
    results = car.sweep_results(sweep, solutions)
    cases = load_cases(cases_file(tmp / "car.yaml", LOADS), labels=car.labels)
    table = kc_results(car, sweep, cases, solutions=solutions, results=results)
    return tmp, car, results, table


def test_a_cars_kc_per_corner_is_its_axles_alone(car_kc):
    tmp, car, results, table = car_kc
    names = KC(car).names
    assert any(n.startswith("bushing_") and n.endswith("_rr") for n in names)
    compared = 0
    for end, (a, b) in AXLES.items():
        model, sweep = axle_alone(car, end, results)
        blocks = {"left": LOADS[a], "right": LOADS[b]}
        cases = load_cases(cases_file(tmp / f"{end}.yaml", blocks), labels=model.labels)
        alone = kc_results(model, sweep, cases)
        assert np.all(alone["solver_converged"])
        for label, side in ((a, "left"), (b, "right")):
            own = [n for n in names if n.endswith(f"_{label}")]
            assert len(own) >= 12 + 4 * 4 + 2 + 2  # motions, rates, 4 bushings, links, tyre
            for name in own:
                theirs = name.removesuffix(f"_{label}") + f"_{side}"
                want = np.asarray(alone[theirs], dtype=float)
                assert np.abs(want).max() > 0.0, theirs  # the load moves every part
                np.testing.assert_allclose(table[name], want, rtol=0, atol=1e-9, err_msg=name)
                compared += 1
    assert compared == len(names)  # every column is a corner's


def test_pin_susp_kc_takes_a_vehicle(tmp_path, capsys):
    cases = cases_file(tmp_path / "cases.yaml", LOADS)
    out = tmp_path / "kc.csv"
    argv = ["kc", CAR, str(EXAMPLES / "vehicle_roll.yaml"), "--cases", cases, "-o", str(out)]
    assert main([*argv, "--plot", str(tmp_path / "kc.png")]) == 0
    columns = pd.read_csv(out, comment="#").columns
    for label in ("fl", "fr", "rl", "rr"):
        assert f"lateral_force_steer_{label}" in columns
        assert f"bushing_lower_wishbone_inboard_front_radial_{label}" in columns
    assert (tmp_path / "kc.png").stat().st_size > 0
    assert "lateral_force_steer_rr" in capsys.readouterr().out
