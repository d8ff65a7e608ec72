"""An unreachable step fails in about the work a reachable one takes (issue 24, 11):
counted in residual evaluations, not timed.

`pin-susp validate` of an axle rolled to 89° took 78 s: the point-based reference
(scipy's Levenberg-Marquardt) ran each unreachable step to scipy's own limit, 100
evaluations per unknown (6100 on an axle). Pinocchio's march is bounded by its
continuation: a Newton solve per halving, each of a bounded number of iterations.
"""

import numpy as np
import pytest
from conftest import EXAMPLES

import pin_susp
from pin_susp.analyses import pointwise
from pin_susp.model.sweep import load_sweep
from pin_susp.solve import solver
from pin_susp.subjects.axle import AxleModel, load_axle, solve_axle_sweep
from pin_susp.validate import scope_of

# The sweep: examples/roll.yaml to 89° over 11 steps (steps 1–10 out of reach).
ROLL_89 = {
    "version": 1,
    "steps": 11,
    "targets": [
        {"quantity": "roll", "start": 0, "stop": 89},
        {"quantity": "heave", "start": 0, "stop": 0},
        {
            "point": "trackrod_inboard",
            "side": "left",
            "direction": {"axis": "y"},
            "start": 0,
            "stop": 0,
        },
    ],
}
# A corner's bump far beyond the wishbones' reach, and within it.
BUMP = {
    "version": 1,
    "steps": 11,
    "targets": [
        {"point": "wheel_center", "direction": {"axis": "z"}, "start": 0, "stop": 2000},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": 0, "stop": 0},
    ],
}


def counted(model, monkeypatch):
    """The pointwise model's residual evaluations, per solve."""
    counts = []
    residual = model.residual

    def count(x, targets):
        counts[-1] += 1
        return residual(x, targets)

    monkeypatch.setattr(model, "residual", count)
    return counts


def pointwise_solves(subject, sweep, monkeypatch):
    scope = scope_of(subject)
    model = scope.pointwise()
    counts = counted(model, monkeypatch)
    residuals = []
    for targets in scope.step_targets(load_sweep(sweep)):
        counts.append(0)
        residuals.append(model.solve(targets)[1])
    return np.array(residuals), np.array(counts)


@pytest.mark.parametrize("subject", ["axle", "corner"])
def test_the_pointwise_reference_gives_up_on_an_unreachable_step_within_its_budget(
    subject, monkeypatch
):
    if subject == "axle":
        model, sweep = AxleModel(load_axle(EXAMPLES / "axle_front.yaml")), ROLL_89
    else:
        model, sweep = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml"), BUMP
    residuals, counts = pointwise_solves(model, sweep, monkeypatch)
    reached = residuals < 1e-12
    assert reached[0] and (~reached).sum() >= 7  # the design, then out of reach
    assert counts[reached].max() <= 10  # a reachable step: a handful
    assert counts.max() <= 100 == pointwise.MAX_EVALUATIONS  # an unreachable one: bounded


def test_pointwise_still_solves_every_reachable_step_of_a_wide_roll(monkeypatch):
    """Within the roll the axle reaches (±4°), every step solves as the march does."""
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    sweep = {**ROLL_89, "targets": [{**ROLL_89["targets"][0], "start": -4, "stop": 4}]}
    sweep["targets"] += ROLL_89["targets"][1:]
    residuals, counts = pointwise_solves(model, sweep, monkeypatch)
    assert np.all(residuals < 1e-12) and counts.max() <= 10
    ours = solve_axle_sweep(model, load_sweep(sweep))
    assert all(s.converged for s in ours)


def newton_evaluations(monkeypatch):
    counts = [0]
    evaluate = solver.NewtonSolver.evaluate

    def count(self, q, jacobian=True):
        counts[0] += 1
        return evaluate(self, q, jacobian)

    monkeypatch.setattr(solver.NewtonSolver, "evaluate", count)
    return counts


# A failed step: the predicted start's Newton, the first solve, then at most two
# Newton solves per halving along the way to the reach limit, each of at most
# MAX_ITERATIONS + 1 iterations of two evaluations (residual alone, then J).
PER_FAILED_STEP = (2 + 2 * solver.SUBDIVISIONS) * (solver.MAX_ITERATIONS + 1) * 2


@pytest.mark.parametrize("subject", ["axle", "corner"])
def test_the_march_fails_an_unreachable_step_within_the_continuations_bound(subject, monkeypatch):
    if subject == "axle":
        model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
        counts = newton_evaluations(monkeypatch)
        solutions = solve_axle_sweep(model, load_sweep(ROLL_89))
    else:
        corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
        counts = newton_evaluations(monkeypatch)
        solutions = corner.solve_steps(load_sweep(BUMP))
    failed = sum(not s.converged for s in solutions)
    assert failed >= 7
    assert counts[0] <= failed * PER_FAILED_STEP + (len(solutions) - failed) * 10 + 20
    assert all(s.iterations <= PER_FAILED_STEP // 2 for s in solutions)
