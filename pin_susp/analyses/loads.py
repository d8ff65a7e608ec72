"""Quasi-static loads: the force in every member and joint at a solved pose
(docs/loads.md), ``member_forces``' table of them at every step of a sweep under
every load case.

The load-case file is read by ``load_case.py``; the equilibrium at each pose — one
linear solve of the held rows' multipliers, each a member's force, and the tree
joints' forces from the subtrees' loads — is ``statics.py``'s ``Statics``; a
rated spring's rates are ``rates.py``'s (below the corner). Each is here too, by
its old address.
"""

from __future__ import annotations

import warnings
import weakref

import numpy as np

from ..errors import PinSuspError, PlausibilityWarning
from ..model.sweep import Sweep
from ..solve.rates import RATE_COLUMNS as RATE_COLUMNS  # the spring's rates (rates.py, below
from ..solve.rates import SpringRates as SpringRates  # the corner), by their old address too
from ..solve.rates import rate_columns as rate_columns
from .load_case import AxleLoadCase as AxleLoadCase  # the load-case file (load_case.py)
from .load_case import LoadCase as LoadCase
from .load_case import load_cases
from .road_loads import RoadLoads, has_accelerations
from .statics import TOGGLE as TOGGLE  # the equilibrium at a pose (statics.py)
from .statics import Statics


def member_forces(corner, sweep, cases: list, solutions=None, results=None, progress=None):
    """Every force column at every step of a sweep under every load case (docs/loads.md):
    a Results with one row per step and case — ``step_index``, ``load_case``,
    ``loads_unbounded`` (1 at a toggle: the forces there are blank, not huge), the
    forces, then the sweep's own columns. ``corner``: a Corner, an AxleModel (its
    columns suffixed _left/_right, the bar's ``torque_arb``) or a Vehicle (suffixed _fl
    …, measured in its chassis frame, the body held: docs/vehicle.md); ``sweep``: a
    Sweep, path or dict; ``cases``: LoadCases (AxleLoadCases, CornersLoadCases, a
    vehicle's AccelerationCases) or a load-case file.

    >>> forces = member_forces(corner, "examples/bump_steer.yaml", "examples/loads.yaml")
    >>> forces.to_pandas()  # a DataFrame, a row per step and case, as the CSV has it
    >>> forces.plot("forces.png")  # the force report, as `pin-susp loads --plot` draws it
    """
    from ..model.sweep import load_sweep
    from ..subjects.corner import Results

    if not isinstance(sweep, Sweep):
        sweep = load_sweep(sweep)
    if not isinstance(cases, list):
        cases = load_cases(cases, labels=corner.labels, accelerations=corner.on_road)
    if not cases:
        raise PinSuspError("member_forces: no load cases given")
    statics = _STATICS.get(corner) or _STATICS.setdefault(corner, Statics(corner))
    road = RoadLoads(corner, cases) if has_accelerations(cases) else None  # a vehicle's
    if solutions is None:
        solutions = corner.solve_steps(sweep)
    if results is None:
        results = corner.sweep_results(sweep, solutions)
    names = statics.names
    n, m = len(cases), len(solutions)
    values = np.full((m, len(names), n), np.nan)
    unbounded = np.full((m, n), np.nan)
    done = [i for i, solution in enumerate(solutions) if solution.converged]
    if done:  # every converged step at once, where its corners are measured (a
        # vehicle's: its chassis frame, the body held as a corner's chassis is)
        solved = [solutions[i].q for i in done]
        W = statics.loads_matrix(cases) if road is None else road.at(solved)
        poses, _ = corner.measured_at(solved, [None] * len(solved))
        at, toggles = statics.solve_poses(poses, W)
        values[done], unbounded[done] = at, toggles[:, None]
    if progress is not None:
        progress(m, m)
    values = values.transpose(1, 0, 2).reshape(len(names), m * n)  # rows: step, then case
    unbounded = unbounded.reshape(m * n)
    columns = {
        "step_index": np.repeat(results["step_index"], n),
        "load_case": np.array([c.name for c in cases] * m, dtype=object),
        "loads_unbounded": unbounded,
    }
    units = {"step_index": "", "load_case": "", "loads_unbounded": ""}
    for k, name in enumerate(names):
        columns[name] = values[k]
        units[name] = "N·m" if name.startswith("torque") else "N"
    for name, force in steering_columns(corner.steering, columns).items():
        columns[name], units[name] = force, "N·m" if name.endswith("torque") else "N"
    for name, values in results.columns.items():
        if name != "step_index":
            columns[name] = np.repeat(values, n)
            units[name] = results.units.get(name, "")
    bump_stops(corner, columns)
    _warn_dead_centre_share(corner, cases, columns)
    meta = dict(results.meta, not_two_force=statics.not_two_force())
    return Results(columns, units, meta)


def bump_stops(subject, columns: dict) -> None:
    """The bump stop in the loads (docs/loads.md, "Bump stops"): it pushes along the
    damper beside the spring, so of the force the equilibrium puts along that line,
    ``bump_stop_force`` (the sweep's column: rate · max(0, compression − gap) at the
    pose) is the stop's and ``force_spring`` the rest, the spring's. The joints' and
    the other members' loads are the line's force's either way."""
    for suffix in map(subject.suffix, subject.labels):
        stop, spring = f"bump_stop_force{suffix}", f"force_spring{suffix}"
        if stop in columns and spring in columns:
            columns[spring] = columns[spring] - np.asarray(columns[stop], dtype=float)


def steering_columns(steering, columns: dict) -> dict:
    """``rack_force`` (N): the trackrods' force on the rack along its axis, + in the sense
    that turns the car left (``force_rack`` is along +y); ``steering_wheel_torque`` (N·m,
    with a c-factor): the torque it puts on the steering wheel through an ideal gear,
    rack_force · c / (2π), + turning left — the driver holds it with the opposite
    (docs/loads.md). None without a rack (``steering``: the subject's, model/steering.py)."""
    if steering is None or "force_rack" not in columns:
        return {}
    out = {"rack_force": steering.rack_force(columns["force_rack"])}
    if steering.c_factor is not None:
        out["steering_wheel_torque"] = steering.wheel_torque(out["rack_force"])
    return out


# A spring's share of the tyre's vertical load outside this band (spring force over
# |Fz|): a car's is about 1/motion ratio, 0.5…3 — this far off, a lever at dead centre.
SPRING_SHARE = (0.1, 10.0)


def _warn_dead_centre_share(subject, cases: list, columns: dict) -> None:
    """Where the model has a link near dead centre at design (deadcentre.py, warned
    when its file was read), a PlausibilityWarning for each load case whose spring
    takes a share of the tyre's vertical load outside SPRING_SHARE: the forces are
    the dead centre's lever, not the car's (7.9 N in the spring from a 2 kN bump)."""
    dead = list(getattr(subject, "dead_centres", ()))
    if not dead:
        return
    low, high = SPRING_SHARE
    for label in subject.labels:
        spring = columns.get(f"force_spring{subject.suffix(label)}")
        here = [t for t in dead if t.body.startswith(subject.prefix(label))]
        if spring is None or not here:
            continue
        cause = ", ".join(f"{t.flow} is {t.margin:.1f}° from dead centre" for t in here)
        source = subject.corners[label].source
        for k, case in enumerate(cases):
            if not hasattr(case, "wheel"):  # a steady acceleration's: its loads per step
                continue
            c = case.wheel(label)
            fz = abs(float(c.contact_patch[2] + c.wheel_center[2]))
            force = np.abs(np.asarray(spring[k :: len(cases)], dtype=float))
            if not fz > 0.0 or np.isnan(force).all():
                continue
            share = float(np.nanmax(force)) / fz
            if low <= share <= high:
                continue
            body = here[0].body.replace("_", " ")
            why = (
                f"so the load bypasses the spring into the {body}'s pivot"
                if share < low
                else f"so the {body} multiplies the load as a lever near dead centre"
            )
            warnings.warn(
                f"{source}: load case {case.name!r}: the {label + ' ' if label else ''}spring "
                f"takes {'at most' if share < low else 'up to'} {share * fz:.3g} N of the "
                f"{fz:.0f} N vertical load on the tyre "
                f"(a car's takes about the load over its motion ratio): {cause} at design "
                f"(see the dead-centre warning), {why}",
                PlausibilityWarning,
                stacklevel=3,
            )


_STATICS = weakref.WeakKeyDictionary()  # a subject's plan, made once (it is fixed by its tree)
