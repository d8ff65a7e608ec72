"""Elastokinematics (K&C compliance): at every step of a sweep and under every load case,
how far the wheel moves and turns on its bushings, links and tyre (docs/compliance.md);
``kc_results``' table of it. The model and its solves are ``compliance_model.py``'s.

Per wheel (an axle's suffixed ``_left``/``_right``), under each case: ``compliance_toe``
and ``compliance_camber`` (deg, the change from the kinematic pose; toe-in +, camber
as the sweep's), ``compliance_wheel_center_x/y/z`` (mm, world axes); the rates at the
pose (the linear compliance, the same for every case): ``lateral_force_steer`` and
``lateral_force_camber`` (deg/kN of the road's force on the tyre toward the car's
centreline, a cornering outer wheel's), ``aligning_torque_steer`` (deg per kN·m about
the vertical, + turning the wheel's front outboard), ``longitudinal_force_steer``
(deg/kN of braking force at the contact patch, rearward: outboard brakes),
``longitudinal_compliance`` (mm/kN: the wheel centre's rearward travel under it), the
same two with the braking force at the wheel centre (inboard brakes:
``..._wheel_center``); then each bushing's ``radial``, ``axial`` (mm) ``torsional``,
``conical`` (deg) deflection, each link's ``stretch`` (mm), the tyre's deflection.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import PinSuspError
from ..io.yamlio import Reader
from ..model.compliance import read_compliance
from ..model.sweep import Sweep
from .compliance_model import ComplianceModel

DEG = 180.0 / math.pi
METHODS = ("linear", "nonlinear")
KN = 1000.0  # N: the rates' unit load
RATES = (
    ("lateral_force_steer", "deg/kN"),
    ("lateral_force_camber", "deg/kN"),
    ("aligning_torque_steer", "deg/(kN·m)"),
    ("longitudinal_force_steer", "deg/kN"),
    ("longitudinal_compliance", "mm/kN"),
    ("longitudinal_force_steer_wheel_center", "deg/kN"),
    ("longitudinal_compliance_wheel_center", "mm/kN"),
)
MOTION = (
    ("compliance_toe", "deg"),
    ("compliance_camber", "deg"),
    ("compliance_wheel_center_x", "mm"),
    ("compliance_wheel_center_y", "mm"),
    ("compliance_wheel_center_z", "mm"),
)


def subject_compliance(subject) -> dict:
    """label → its corner's Compliance (model/compliance.py), from each corner's file."""
    out = {}
    for label, g in subject.corners.items():
        block = g.data.get("compliance") if isinstance(g.data, dict) else None
        if block is not None:
            out[label] = read_compliance(block, Reader(g.source))
    if not any(not c.empty for c in out.values()):
        raise PinSuspError(
            f"{subject.source}: no compliance: block (bushings, links, tyre): nothing is "
            "compliant, the K&C is zero (docs/compliance.md)"
        )
    return out


class KC:
    """A subject's K&C at its poses: ``linear(qs, W)`` and ``nonlinear(qs, W)`` give
    the columns (poses × cases per name); ``names``/``units`` list them."""

    def __init__(self, subject, compliances: dict | None = None):
        self.subject = subject
        compliances = subject_compliance(subject) if compliances is None else compliances
        self.model = ComplianceModel(subject, compliances)
        m = self.model
        self.labels = subject.labels
        ends = ("wheel_center", "axle_inboard", "axle_outboard")
        self.points = [
            tuple(subject.points[subject.prefix(label) + n] for n in ends) for label in self.labels
        ]
        self.signs = [subject.corners[label].sign for label in self.labels]
        names = []
        for label in self.labels:
            sfx = subject.suffix(label)
            names += [(n + sfx, u) for n, u in (*MOTION, *RATES)]
        label_of = {subject.suffix(label): label for label in self.labels}
        self.bushing_columns = []  # (stem, radial column, axial column, its point)
        for b in m.bodies:
            for name, *_, sfx in b.bushings:
                names += [(f"{name}_{p}{sfx}", u) for p, u in PARTS]
                point = subject.prefix(label_of[sfx]) + name.removeprefix("bushing_")
                self.bushing_columns.append(
                    (name + sfx, f"{name}_radial{sfx}", f"{name}_axial{sfx}", point)
                )
        for _, _, short, sfx in m.links.values():
            names.append((f"link_{short}_stretch{sfx}", "mm"))
        for label, *_ in m.tyres:
            sfx = subject.suffix(label)
            names += [
                (f"tyre_deflection_lateral{sfx}", "mm"),
                (f"tyre_deflection_vertical{sfx}", "mm"),
            ]
        self.names = [n for n, _ in names]
        self.units = dict(names)
        W = np.zeros((9 * len(self.labels), 4 * len(self.labels)))
        for k, s in enumerate(self.signs):  # each wheel's unit loads, the others' unloaded
            W[9 * k + 1, 4 * k] = -s * KN  # toward the centreline at the contact patch
            W[9 * k + 8, 4 * k + 1] = s * KN  # N·m: turning the front outboard
            W[9 * k + 0, 4 * k + 2] = -KN  # braking, at the contact patch
            W[9 * k + 3, 4 * k + 3] = -KN  # braking, at the wheel centre
        self.unit_loads = W

    def _observe(self):
        """Each wheel's (wc, toe, camber) at the model's state and their rows in x."""
        kin, out = self.model.kin, []
        for (wc, ai, ao), s in zip(self.points, self.signs, strict=True):
            P = [p.position(kin).copy() for p in (wc, ai, ao)]
            J = [p.jacobian(kin) for p in (wc, ai, ao)]
            a = P[2] - P[1]
            n = np.linalg.norm(a)
            u = a / n
            da = (np.eye(3) - np.outer(u, u)) @ (J[2] - J[1]) / n
            toe = math.atan2(u[0], s * u[1])
            camber = -math.atan2(u[2], s * u[1])
            dtoe = s * (u[1] * da[0] - u[0] * da[1]) / (u[0] ** 2 + u[1] ** 2)
            dcam = -s * (u[1] * da[2] - u[2] * da[1]) / (u[2] ** 2 + u[1] ** 2)
            out.append((P[0], toe, camber, J[0], dtoe, dcam))
        return out

    def linear(self, qs: list, W: np.ndarray, progress=None) -> np.ndarray:
        """Every column (poses × names × cases) by the first-order solve at each pose."""
        m, nc = self.model, W.shape[1]
        out = np.empty((len(qs), len(self.names), nc))
        loads = np.concatenate([W, self.unit_loads], axis=1)
        for i, q in enumerate(qs):
            dx, state = m.linear(q, loads)
            deflections = state[5]
            obs = self._observe()
            rows = []
            for k, (_, _, _, Jwc, dtoe, dcam) in enumerate(obs):
                motion = np.vstack([dtoe @ dx * DEG, dcam @ dx * DEG, Jwc @ dx * 1e3])
                rows += [r[:nc] for r in motion]
                rates = motion[:, nc:]  # 5 motions × 4 unit loads per wheel
                rows += [np.full(nc, x) for x in self._rates(rates, k)]
            out[i] = np.vstack([*rows, *self._parts(deflections, dx, nc, linear=True)])
            if progress is not None and (i + 1 == len(qs) or i % 10 == 0):
                progress(i + 1, len(qs))
        return out

    def _rates(self, motion: np.ndarray, k: int) -> list[float]:
        """Wheel k's rates from the motions (toe, camber, wc x/y/z) under the unit loads."""
        c = 4 * k
        return [
            motion[0, c], motion[1, c], motion[0, c + 1], motion[0, c + 2], -motion[2, c + 2],
            motion[0, c + 3], -motion[2, c + 3],
        ]  # fmt: skip

    def _parts(self, deflections: dict, dx, nc: int, linear: bool) -> list:
        """The bushings', links' and tyres' deflections (each a row over the cases)."""
        m, rows = self.model, []
        for b in m.bodies:
            for name, *_, sfx in b.bushings:
                d, D, cb = deflections[(name, sfx)]
                d = (D @ dx[cb : cb + 6])[:, :nc] if linear else d[:, None]
                rows += [
                    np.hypot(d[0], d[1]) * 1e3, d[2] * 1e3, d[5] * DEG, np.hypot(d[3], d[4]) * DEG
                ]  # fmt: skip
        for col, *_ in m.links.values():
            rows.append(dx[col, :nc] * 1e3 if linear else np.atleast_1d(dx[0][col - m._e0]) * 1e3)
        for _, col, *_ in m.tyres:
            if linear:
                rows += [dx[col, :nc] * 1e3, dx[col + 1, :nc] * 1e3]
            else:
                s = dx[1]
                rows += [
                    np.atleast_1d(s[col - m._s0]) * 1e3,
                    np.atleast_1d(s[col + 1 - m._s0]) * 1e3,
                ]
        return rows

    def nonlinear(self, qs: list, W: np.ndarray, progress=None) -> np.ndarray:
        """Every column by the loaded pose's own solve (the rates stay the linear ones)."""
        m, nc = self.model, W.shape[1]
        out = self.linear(qs, W)
        nw = len(self.labels)
        per = len(MOTION) + len(RATES)
        for i, q in enumerate(qs):
            m.at_pose(q)
            m.kin.update(q)
            before = self._observe()
            for c in range(nc):
                qq, T, e, s = m.nonlinear(q, W[:, c])
                deflections = m.evaluate(qq, T, e, s)[5]
                after = self._observe()
                for k in range(nw):
                    wc0, toe0, cam0 = before[k][:3]
                    wc1, toe1, cam1 = after[k][:3]
                    motion = [(toe1 - toe0) * DEG, (cam1 - cam0) * DEG, *((wc1 - wc0) * 1e3)]
                    out[i, k * per : k * per + len(MOTION), c] = motion
                parts = self._parts(deflections, (e, s), 1, linear=False)
                out[i, nw * per :, c] = np.concatenate(parts) if parts else []
            if progress is not None:
                progress(i + 1, len(qs))
        return out


PARTS = (("radial", "mm"), ("axial", "mm"), ("torsional", "deg"), ("conical", "deg"))


def kc_results(subject, sweep, cases, method: str = "linear", solutions=None, results=None,
               compliances: dict | None = None, kc: KC | None = None, progress=None):  # fmt: skip
    """The K&C table (module docstring): a Results with one row per step and case —
    ``step_index``, ``load_case``, the K&C columns, then the sweep's own columns.
    ``cases``: LoadCases (analyses/load_case.py) or a load-case file; ``compliances``
    (label → Compliance) instead of the files' blocks; ``progress(done, total)``.

    >>> kc = kc_results(corner, "examples/bump_steer.yaml", "examples/kc.yaml")
    >>> kc.to_pandas()[["load_case", "compliance_toe", "lateral_force_steer"]]"""
    from ..model.sweep import load_sweep
    from ..subjects.corner import Results
    from .load_case import load_cases
    from .statics import Statics

    if method not in METHODS:
        raise PinSuspError(f"kc: method {method!r}: expected one of {', '.join(METHODS)}")
    if not isinstance(sweep, Sweep):
        sweep = load_sweep(sweep)
    if not isinstance(cases, list):
        cases = load_cases(cases, labels=subject.labels)
    kc = KC(subject, compliances) if kc is None else kc
    W = Statics.loads_matrix(kc, cases)  # the cases' loads, 9 per wheel (a column each)
    if solutions is None:
        solutions = subject.solve_steps(sweep)
    if results is None:
        results = subject.sweep_results(sweep, solutions)
    n, steps = len(cases), len(solutions)
    values = np.full((steps, len(kc.names), n), np.nan)
    done = [i for i, s in enumerate(solutions) if s.converged]
    if done:
        qs = [solutions[i].q for i in done]
        solve = kc.linear if method == "linear" else kc.nonlinear
        values[done] = solve(qs, W, progress)
    values = values.transpose(1, 0, 2).reshape(len(kc.names), steps * n)
    columns = {
        "step_index": np.repeat(results["step_index"], n),
        "load_case": np.array([c.name for c in cases] * steps, dtype=object),
    }
    units = {"step_index": "", "load_case": ""}
    for k, name in enumerate(kc.names):
        columns[name], units[name] = values[k], kc.units[name]
    for name, v in results.columns.items():
        if name != "step_index":
            columns[name], units[name] = np.repeat(v, n), results.units.get(name, "")
    return Results(columns, units, dict(results.meta, kc_method=method))
