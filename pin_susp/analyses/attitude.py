"""The car's attitude under a steady acceleration (docs/vehicle.md, "Attitude"): for
each (ax, ay) in g, the body's heave, pitch and roll at which the springs, the bars
and the tyres hold the inertial load, the four wheels' vertical loads and the
lateral load transfer per axle, split into its elastic, geometric and unsprung parts.

The equilibrium is the principle of virtual work on the vehicle's own model. Its
coordinates are the vehicle sweep's targets: the body's heave h, pitch θ and roll φ
and each contact patch's height on the road z_c (the rack held at design). At a pose,
the tangents dq/du of the closed linkage (one solve with the rows' Jacobian, as every
sweep has) give every point's motion along each coordinate, and with them each
force's generalised force:

- each spring's force F = F₀ + k·(ℓ₀ − ℓ) (compression +) along dℓ/du, F₀ the
  preload that holds the static corner weights at design;
- each anti-roll bar's torque −k·τ along dτ/du (its twist τ);
- the sprung mass's weight at the CG (the body's joints stand there: it moves
  with h alone); each unsprung mass's weight and inertial force −m·a at its wheel
  centre;
- the tyres' longitudinal and lateral forces at the contact patches: the lateral
  force m·ay·g split front to rear by the moment about the car's CG and left to right
  in proportion to the wheels' loads; the longitudinal m·ax·g by the brake bias
  (ax < 0) or the drive split (ax > 0), half a side. An inboard brake or drive acts
  at the wheel centre with its torque on the body (the wheel turns with the body's
  pitch), an outboard one at the contact patch.

The body's three generalised forces vanish; each wheel's vertical load is the
generalised force along its own z_c (the road pushes the contact patch); with a tyre
rate, z_c = −(F_z − F_z,design)/k_t. Solved by Newton's method with the springs',
bars' and tyres' stiffness matrix as its Jacobian (the preload's geometric stiffness
left out: it converges in a few more steps).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .attitude_file import (  # noqa: F401 (its inputs' names, importable from here)
    Accelerations,
    check_splits,
    load_accelerations,
    masses_of,
    tyre_rates_of,
)

G = 9.80665  # m/s², one g
ENDS = {"front": ("fl", "fr"), "rear": ("rl", "rr")}
TOLERANCE = 1e-7  # N and N·m: the body's force balance; m: the tyre's deflection × k
MAX_ITERATIONS = 30
STEP = 1e-7  # m, rad: the Jacobian's differences
MAX_STEP = 0.05  # m, rad: a Newton step's largest move
SHARES = 60  # the lateral force's share by the wheels' loads: its passes at most
HELD = "the steering held straight (the rack at design); the tyres' forces as docs/vehicle.md says"
CHUNK = 256  # accelerations solved together (a batch's arrays grow with it)
CONTINUATION = (0.25, 0.5, 0.75, 1.0)  # a point that failed from design, on the way to it
FRAMES = ("wheel_center", "axle_inboard", "axle_outboard", "strut_top", "strut_bottom")
SMALL = 0.01  # g: the gradients' difference step


class Attitude:
    """The quasi-static attitude of a Vehicle (docs/vehicle.md): ``solve(ax, ay)`` for
    one acceleration, ``run(accelerations)`` for a list, with the sweep's columns at
    each equilibrium and the loads'. Needs each corner's spring rate,
    ``vehicle_config.masses`` (sprung, unsprung_front, unsprung_rear) and, for a
    compliant tyre, ``vehicle_config.tyres`` (N/mm)."""

    def __init__(self, car):
        from ..solve.bulk import Frames, rows_of, tree_of
        from ..subjects.vehicle_file import axle_key

        self.car = car
        v = car.vehicle
        source = v.source
        self.masses = masses_of(v)
        self.tyre_rates = tyre_rates_of(v)
        for label, g in car.corners.items():
            end = "front" if label[0] == "f" else "rear"  # its axle's file, or inline
            if not g.rated_spring:
                key = "strut.rate" if g.type == "macpherson" else "spring.rate"
                raise InputError(
                    *axle_key(v, end, f"axle_config.{key}"),
                    f"the attitude needs every spring's rate: the {label} corner has none",
                )
            if g.spring != "coilover":
                raise InputError(
                    *axle_key(v, end, "axle_config.spring.type"),
                    f"the attitude takes coilovers so far (the {label} corner's is {g.spring})",
                )
        from ..model.sweep import Target

        labels = car.labels
        targets = [Target(None, None, [0.0], quantity=q) for q in ("heave", "pitch", "roll")]
        targets += [Target(None, None, [0.0], side=c, quantity="road_z") for c in labels]
        self.solver = car.solver_for(targets, source)
        self.rows = rows_of(self.solver)
        self.values0 = car.values_at(self.solver, car.q_design)  # the rack's, held
        self.nu = 3 + len(labels)  # the coordinates: h, θ, φ, z per corner
        names = []
        for c in labels:  # per corner: FRAMES
            names += [f"{c}_{name}" for name in FRAMES]
        self.tree = tree_of(car.kin)
        self.frames = Frames(self.tree, [car.points[n].frame_id for n in names])
        self.bars = car.bar_energies()
        self.radius = {c: car.points[f"{c}_contact_patch_center"].radius for c in labels}
        self.k = np.array([car.corners[c].spring_rate * 1e3 for c in labels])  # N/m
        self._design()

    # ------------------------------------------------------------ the model

    def _at(self, u: np.ndarray, q0: np.ndarray):
        """The linkage at coordinates u (n, 7) from q0 (n, nq): q, tangents (n, nv, 7),
        the frames' positions and Jacobians, and where it closed (n,) — elsewhere q0
        and NaN tangents."""
        from ..solve.bulk import newton_all
        from ..solve.solver import TOLERANCE as CLOSE

        values = np.repeat(self.values0[None], len(u), axis=0)
        values[:, : self.nu] = u
        q, T, _, _ = newton_all(self.rows, q0, values, CLOSE)
        ok = np.ones(len(u), dtype=bool)
        if q is None:  # one at a time, halving from its start
            q, T, ok = self._one_by_one(q0, values)
        return (q, T[:, :, : self.nu], *self._frames(q), ok)

    def _frames(self, q: np.ndarray) -> tuple[list, list, list]:
        """Every frame's position (n, 3), linear and angular Jacobians (n, 3, nv)."""
        return self.frames.evaluate(q, angular=True)

    def _one_by_one(self, q0: np.ndarray, values: np.ndarray):
        """The batch's linkages one at a time (the solver's halving from each start):
        q, tangents and where each closed."""
        from ..solve.bulk import solve_all

        qs, Ts, ok = q0.copy(), np.full((len(q0), self.tree.nv, values.shape[1]), np.nan), []
        rhs = np.zeros((self.rows.nrows, values.shape[1]))
        rhs[self.rows.first_target :] = np.eye(values.shape[1])
        for i, (q, goal) in enumerate(zip(q0, values, strict=True)):
            start = self.car.values_at(self.solver, q)
            s = self.solver.solve(q, start, goal)
            T = None
            if s.converged:
                _, Jr = self.rows.evaluate(s.q[None], goal[None])
                T = solve_all(Jr, rhs)
            ok.append(T is not None)
            if T is not None:
                qs[i], Ts[i] = s.q, T[0]
        return qs, Ts, np.array(ok)

    def _forces(self, at, ax, ay, Fz_guess):
        """The body's generalised forces (n, 3), each wheel's vertical load (n, 4) and its
        parts, and the springs' and bars' (stiffness, gradient) pairs, at the pose ``at``
        under (ax, ay) g; ``Fz_guess``: the loads that share each axle's lateral force."""
        q, T, P, J, W, _ = at
        n, nf = len(q), len(FRAMES)
        labels = self.car.labels
        m = self.masses
        # each frame's velocity and angular velocity along the coordinates: (n, 3, 7)
        V = [np.einsum("nkv,nvu->nku", Jf, T) for Jf in J]
        gen = {part: np.zeros((n, self.nu)) for part in ("elastic", "unsprung")}
        gradients = []
        for i in range(len(labels)):
            top, bottom = nf * i + 3, nf * i + 4
            axis = P[top] - P[bottom]
            length = np.linalg.norm(axis, axis=1)
            e = axis / length[:, None]
            dl = np.einsum("nk,nku->nu", e, V[top] - V[bottom])  # dℓ/du
            force = self.preload[i] + self.k[i] * (self.length0[i] - length)
            gen["elastic"] += force[:, None] * dl
            gradients.append((self.k[i], dl))
        for k, twist in self.bars:
            tau, dtau = twist(q, T)
            gen["elastic"] -= (k * tau)[:, None] * dtau
            gradients.append((k, dtau))
        body = self._body_turn(q)  # (n, 3, 7): the body's angular velocity
        along = []  # per corner: its contact patch's x and y rates (n, 7), the tyre's
        for i, c in enumerate(labels):
            wc, ai, ao = nf * i, nf * i + 1, nf * i + 2
            mu = m["unsprung"][c]
            inertia = mu * G * np.stack([-ax, -ay, -np.ones(n)], axis=1)
            gen["unsprung"] += np.einsum("nk,nku->nu", inertia, V[wc])
            # the tyre's material point at the contact patch: the wheel centre's motion
            # and the wheel's turn, which is the upright's about every axis but its spin
            # axis, and about that the upright's (outboard) or the body's (inboard)
            spin = P[ao] - P[ai]
            spin /= np.linalg.norm(spin, axis=1)[:, None]
            down = spin * spin[:, 2:3] - np.array([0.0, 0.0, 1.0])
            down /= np.linalg.norm(down, axis=1)[:, None]
            arm = self.radius[c] * down  # WC → CP
            upright = np.einsum("nkv,nvu->nku", W[wc], T)
            end = "front" if c[0] == "f" else "rear"
            inboard = np.where(ax < 0, self.brakes_in[end], self.drive_in[end])
            own = np.einsum("nk,nku->nu", spin, upright)
            about = own
            if inboard.any():
                about = np.where(inboard[:, None], np.einsum("nk,nku->nu", spin, body), own)
            wheel = upright + spin[:, :, None] * (about - own)[:, None, :]
            v_cp = V[wc] + np.cross(wheel, arm[:, :, None], axisa=1, axisb=1, axisc=1)
            along.append((v_cp[:, 0], v_cp[:, 1]))
        sprung = np.zeros((n, self.nu))
        sprung[:, 0] = -m["sprung"] * G  # the CG rises with the heave alone
        base = gen["elastic"] + gen["unsprung"] + sprung
        # the tyres' forces: the lateral one shared in proportion to the wheels' loads,
        # which it changes (its jacking): shared until the loads it gives are its own
        Fz = np.array(Fz_guess, dtype=float)
        for _ in range(SHARES):
            fx, fy = self._tyre_forces(ax, ay, Fz)
            geometric = sum(
                fx[:, i, None] * gx + fy[:, i, None] * gy for i, (gx, gy) in enumerate(along)
            )
            loads = -(base + geometric)[:, 3:]  # the road's push along each z_c
            if np.abs(loads - Fz).max() <= 1e-9:
                break
            Fz = loads
        gen["geometric"] = geometric
        total = base + geometric
        parts = {k: -g[:, 3:] for k, g in gen.items()}
        return total[:, :3], loads, parts, gradients

    def _body_turn(self, q: np.ndarray) -> np.ndarray:
        """The body's angular velocity along the coordinates (n, 3, 7): its pitch about
        y, its roll about the pitched x (the joints' order: heave, pitch, roll)."""
        theta = q[:, self.car.body_q[1]]
        out = np.zeros((len(q), 3, self.nu))
        out[:, 1, 1] = 1.0
        out[:, 0, 2], out[:, 2, 2] = np.cos(theta), -np.sin(theta)
        return out

    def _tyre_forces(self, ax, ay, Fz):
        """Each contact patch's longitudinal and lateral force (n, 4), N."""
        m, n = self.masses, len(ax)
        total = m["total"] * G
        fx, fy = np.zeros((n, 4)), np.zeros((n, 4))
        for end, (left, right) in ENDS.items():
            i, j = self.car.labels.index(left), self.car.labels.index(right)
            lateral = total * ay * self.lateral_share[end]
            share = np.where(ax < 0, self.brake_share[end], self.drive_share[end])
            longitudinal = total * ax * share
            both = Fz[:, i] + Fz[:, j]
            with np.errstate(invalid="ignore", divide="ignore"):
                left_share = np.where(both > 0, Fz[:, i] / both, 0.5)
            fy[:, i], fy[:, j] = lateral * left_share, lateral * (1.0 - left_share)
            fx[:, i] = fx[:, j] = 0.5 * longitudinal
        return fx, fy

    # ------------------------------------------------------------ design

    def _design(self) -> None:
        """The static corner weights, the springs' lengths and preloads at design, the
        axles' shares of the lateral force and of the brakes and the drive."""
        car, v, m = self.car, self.car.vehicle, self.masses
        labels = car.labels
        d = car.design_positions
        x = {c: d[f"{c}_wheel_center"][0] for c in labels}  # the road holds the wheel there
        xw = {c: d[f"{c}_wheel_center"][0] for c in labels}
        xf = 0.5 * (x["fl"] + x["fr"])
        xr = 0.5 * (x["rl"] + x["rr"])
        xg = v.cg[0]
        # the whole car's CG: the sprung mass at its CG, each unsprung at its wheel centre
        xt = (m["sprung"] * xg + sum(m["unsprung"][c] * xw[c] for c in labels)) / m["total"]
        front = (xt - xr) / (xf - xr)
        self.lateral_share = {"front": front, "rear": 1.0 - front}
        # static weights: left = right per axle; vertical and pitch balance (exact)
        moment = sum(m["unsprung"][c] * G * (xw[c] - xg) for c in labels)
        A = np.array([[2.0, 2.0], [2.0 * (xf - xg), 2.0 * (xr - xg)]])
        wf, wr = np.linalg.solve(A, [m["total"] * G, moment])
        self.static = np.array([wf, wf, wr, wr])
        self.brake_share = {e: v.brake_share(e) or 0.0 for e in ENDS}
        self.drive_share = {e: v.drive_share(e) or 0.0 for e in ENDS}
        self.brakes_in = {e: v.brake_reaction(e) == "inboard" for e in ENDS}
        self.drive_in = {e: v.drive_reaction(e) == "inboard" for e in ENDS}
        u0 = np.zeros((1, self.nu))
        at = self._at(u0, car.q_design[None])
        P, nf = at[2], len(FRAMES)
        self.length0 = np.array(
            [np.linalg.norm(P[nf * i + 3][0] - P[nf * i + 4][0]) for i in range(len(labels))]
        )
        self.preload = np.zeros(len(labels))
        zero = np.zeros(1)
        _, loads, _, gradients = self._forces(at, zero, zero, self.static[None])
        # each spring's preload: its wheel's static weight along its own z_c
        for i in range(len(labels)):
            rate = gradients[i][1][0, 3 + i]
            self.preload[i] = (self.static[i] - loads[0, i]) / -rate
        # then the least change of them that makes the design an exact equilibrium (the
        # weights above put each wheel's load under its wheel centre; the road holds the
        # lowest point of a wheel with toe and camber a fraction of a mm away)
        body, *_ = self._forces(at, zero, zero, self.static[None])
        lever = np.array([g[0, :3] for _, g in gradients[: len(labels)]]).T  # (3, 4)
        self.preload -= np.linalg.pinv(lever) @ body[0]
        _, loads, _, _ = self._forces(at, zero, zero, self.static[None])
        self.static = loads[0]
        self.q_design = car.q_design

    # ------------------------------------------------------------ solving

    def solve(self, ax, ay, start: dict | None = None) -> dict:
        """The equilibria at accelerations ax, ay (g, arrays): every one at once, each
        Newton step for all (its Jacobian by differences of the coordinates, all in one
        batch), a step halved where it would not lower the residual or the linkage would
        not close there. A dict: u (n, 7: h m, θ, φ rad, z_c m), q, the wheel loads
        (n, 4) N and their parts, converged (n,), iterations, residual (N, N·m)."""
        ax, ay = np.atleast_1d(ax).astype(float), np.atleast_1d(ay).astype(float)
        n, free = len(ax), self.free
        if start is None:  # from the design
            u = np.zeros((n, self.nu))
            q = np.repeat(self.q_design[None], n, axis=0)
            Fz = np.repeat(self.static[None], n, axis=0)
        else:
            u, q, Fz = start["u"].copy(), start["q"], start["loads"]
        now = self._linearised(u, q, ax, ay, Fz)
        norm = np.abs(now[0]).max(axis=1)
        step, alpha = self._step(now), np.ones(n)
        done = norm <= TOLERANCE
        iterations = 0
        while not done.all() and iterations < MAX_ITERATIONS:
            iterations += 1
            trial = u.copy()
            trial[:, free] += alpha[:, None] * step
            new = self._linearised(trial, now[2], ax, ay, now[3])
            trial_norm = np.where(new[5], np.abs(new[0]).max(axis=1), np.inf)
            better = ~done & (trial_norm < norm * (1.0 - 1e-4 * alpha))
            better |= ~done & (trial_norm <= TOLERANCE)
            if better.any():
                u[better] = trial[better]
                now = tuple(
                    np.where(better.reshape((-1,) + (1,) * (a.ndim - 1)), b, a)
                    if isinstance(a, np.ndarray)
                    else {k: np.where(better[:, None], b[k], a[k]) for k in a}
                    for a, b in zip(now, new, strict=True)
                )
                norm = np.where(better, trial_norm, norm)
                fresh = self._step(now)
                step[better], alpha[better] = fresh[better], 1.0
            worse = ~done & ~better
            alpha[worse] *= 0.5
            done |= norm <= TOLERANCE
            done |= alpha < 1e-6  # no step lowers it: given up (not converged)
        return {
            "u": u,
            "q": now[2],
            "loads": now[3],
            "parts": now[4],
            "converged": norm <= TOLERANCE,
            "iterations": iterations,
            "residual": norm,
        }

    @staticmethod
    def _step(now) -> np.ndarray:
        """Newton's step from a linearisation (NaN where its Jacobian is singular), no
        larger than MAX_STEP in any coordinate."""
        R0, Jac = now[0], now[1]
        step = np.full(R0.shape, np.nan)
        good = np.isfinite(Jac).all(axis=(1, 2)) & np.isfinite(R0).all(axis=1)
        if good.any():
            with np.errstate(all="ignore"):
                try:
                    step[good] = np.linalg.solve(Jac[good], -R0[good][:, :, None])[:, :, 0]
                except np.linalg.LinAlgError:
                    pass
        largest = np.maximum(np.abs(step).max(axis=1), 1e-300)
        return step * np.minimum(1.0, MAX_STEP / largest)[:, None]

    @property
    def free(self) -> list[int]:
        """The coordinates solved for: the body's three, and each z_c with a tyre rate."""
        return list(range(self.nu if self.tyre_rates is not None else 3))

    def _linearised(self, u, q, ax, ay, Fz):
        """The rows at u and their Jacobian along the free coordinates by differences
        (every point's and every perturbation's linkage in one batch): (R (n, f),
        J (n, f, f), q, the loads, their parts, ok (n,): where the linkage closed)."""
        n, free = len(u), self.free
        f = len(free)
        U = np.concatenate([u] + [u + STEP * np.eye(self.nu)[k] for k in free])
        tile = (f + 1, 1)
        R, at, loads, parts, ok = self._residual(
            U, np.tile(q, tile), np.tile(ax, f + 1), np.tile(ay, f + 1), np.tile(Fz, tile)
        )
        R0 = R[:n, free]
        Jac = np.stack([(R[(k + 1) * n : (k + 2) * n, free] - R0) / STEP for k in range(f)], axis=2)
        ok = ok.reshape(f + 1, n).all(axis=0)
        return R0, Jac, at[0][:n], loads[:n], {k: v[:n] for k, v in parts.items()}, ok

    def _residual(self, u, q, ax, ay, Fz):
        """The rows at coordinates u (n, 7): the body's generalised forces (N, N·m) and,
        for compliant tyres, each tyre's load against its deflection (N); the linkage,
        the loads and their parts, and where the linkage closed (NaN rows elsewhere)."""
        at = self._at(u, q)
        ok = at[-1]
        body, loads, parts, _ = self._forces(at, ax, ay, Fz)
        R = np.zeros((len(u), self.nu))
        R[:, :3] = body
        if self.tyre_rates is not None:
            R[:, 3:] = u[:, 3:] * self.tyre_rates + (loads - self.static)
        R[~ok] = np.nan
        return R, at, loads, parts, ok

    def equilibria(self, ax, ay, progress=None) -> dict:
        """``solve`` for every acceleration, and where one does not converge from the
        design, again along the way to it (a quarter of it, a half, ...: each from the
        last). ``why`` per point: '' where converged, else the reason; a wheel whose
        load falls below zero has lifted: not an equilibrium on four wheels."""
        ax, ay = np.asarray(ax, dtype=float), np.asarray(ay, dtype=float)
        check_splits(self.car.vehicle, ax)
        parts = [self.solve(ax[k : k + CHUNK], ay[k : k + CHUNK]) for k in range(0, len(ax), CHUNK)]
        s = {key: np.concatenate([p[key] for p in parts]) for key in ("u", "q", "loads")}
        s |= {key: np.concatenate([p[key] for p in parts]) for key in ("residual", "converged")}
        s["parts"] = {k: np.concatenate([p["parts"][k] for p in parts]) for k in parts[0]["parts"]}
        failed = np.flatnonzero(~s["converged"])
        if failed.size:
            part = None
            for fraction in CONTINUATION:
                part = self.solve(fraction * ax[failed], fraction * ay[failed], part)
            for key in ("u", "q", "loads", "residual", "converged"):
                s[key][failed] = part[key]
            for key in s["parts"]:
                s["parts"][key][failed] = part["parts"][key]
        why = []
        for i in range(len(ax)):
            lifted = [c for c, load in zip(self.car.labels, s["loads"][i], strict=True) if load < 0]
            if not s["converged"][i]:
                light = int(np.argmin(s["loads"][i]))
                why.append(
                    "no equilibrium found (residual "
                    f"{s['residual'][i]:.3g} N): past the linkage's reach or a wheel's lift-off "
                    f"(the {self.car.labels[light]} wheel the lightest, "
                    f"{s['loads'][i][light]:.0f} N, at the last step)"
                )
            elif lifted:
                why.append(
                    f"the {', '.join(lifted)} wheel lifts (a load below zero): not on four wheels"
                )
                s["converged"][i] = False
            else:
                why.append("")
        s["why"] = why
        if progress is not None:
            progress(len(ax), len(ax))
        return s

    def run(self, accelerations: Accelerations, progress=None):
        """The attitude at every acceleration (docs/vehicle.md): the vehicle sweep's
        columns at each equilibrium (VehicleResults), with the accelerations, the wheel
        loads, the lateral load transfer per axle and its parts, the TLLTD, the
        gradients and the ride (and roll) frequencies."""
        from ..model.sweep import Sweep, Target

        a = accelerations
        s = self.equilibria(a.ax, a.ay, progress)
        ok = s["converged"]
        u = np.where(ok[:, None], s["u"], 0.0)  # a failed point: the design, blanked below
        targets = [
            Target(None, None, u[:, 0] * 1e3, quantity="heave"),
            Target(None, None, np.degrees(u[:, 1]), quantity="pitch"),
            Target(None, None, np.degrees(u[:, 2]), quantity="roll"),
        ]
        for i, c in enumerate(self.car.labels):
            targets.append(Target(None, None, u[:, 3 + i] * 1e3, side=c, quantity="road_z"))
        sweep = Sweep(targets, a.source, a.sha256)
        results = self.car.run_sweep(sweep)
        columns, units = results.columns, results.units
        converged = columns["solver_converged"] & ok
        first = {"ax": (a.ax, "g"), "ay": (a.ay, "g")}
        first |= {"equilibrium_residual": (s["residual"], "N")}
        first |= self.load_columns(s)
        constants = self.gradients() | self.frequencies()
        unit = {"roll_gradient": "deg/g", "pitch_gradient_braking": "deg/g"}
        unit |= {"pitch_gradient_traction": "deg/g"}
        n = len(a)
        for name, value in constants.items():
            first[name] = (np.full(n, float(value)), unit.get(name, "Hz"))
        solver = [k for k in columns if k.startswith(("step_index", "solver_"))]
        out_columns = {k: columns[k] for k in solver}
        out_units = {k: units[k] for k in solver}
        for name, (values, column_unit) in first.items():
            out_columns[name], out_units[name] = np.asarray(values, dtype=float), column_unit
        for k in columns:
            if k not in out_columns:
                out_columns[k], out_units[k] = columns[k], units[k]
        out_columns["solver_converged"] = converged
        keep = set(solver) | {"ax", "ay", "equilibrium_residual"}
        for k, values in out_columns.items():  # a point with no equilibrium: blank
            if k not in keep and values.dtype.kind == "f":
                values[~converged] = np.nan
        meta = dict(results.meta)
        meta["why"] = [w or why for w, why in zip(s["why"], meta["why"], strict=True)]
        meta["notes"] = [HELD]
        return type(results)(out_columns, out_units, meta)

    def load_columns(self, s: dict) -> dict:
        """wheel_load_<corner> (N, vertical), lateral_load_transfer_<end> (N, half the
        right wheel's load less the left's: + onto the right, as a left turn gives) and
        its _elastic, _geometric and _unsprung parts, longitudinal_load_transfer (N,
        onto the front axle from design) and tlltd (%, the front's share of the total
        lateral transfer; blank with none)."""
        labels, loads, parts = self.car.labels, s["loads"], s["parts"]
        out = {f"wheel_load_{c}": (loads[:, i], "N") for i, c in enumerate(labels)}
        transfer = {}
        for end, (left, right) in ENDS.items():
            i, j = labels.index(left), labels.index(right)
            transfer[end] = 0.5 * (loads[:, j] - loads[:, i])
            out[f"lateral_load_transfer_{end}"] = (transfer[end], "N")
            for part in ("elastic", "geometric", "unsprung"):
                p = parts[part]
                out[f"lateral_load_transfer_{part}_{end}"] = (0.5 * (p[:, j] - p[:, i]), "N")
        front = labels.index("fl"), labels.index("fr")
        design = self.static[list(front)].sum()
        out["longitudinal_load_transfer"] = (loads[:, list(front)].sum(axis=1) - design, "N")
        total = transfer["front"] + transfer["rear"]
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(
                np.abs(total) > 1e-9 * self.masses["total"] * G,
                100.0 * transfer["front"] / total,
                np.nan,
            )
        out["tlltd"] = (share, "%")
        return out

    def gradients(self) -> dict:
        """roll_gradient (deg/g, at ay → 0), pitch_gradient_braking and
        _traction (deg/g, + nose down per g of braking, of forward acceleration), the
        differences of the equilibria at ±SMALL g (second order one-sided for the pitch:
        the brake and drive splits differ). A pitch gradient is blank (NaN) where its
        split is not given: without it the tyres' longitudinal force is unknown."""
        h = SMALL
        ax = np.array([0.0, 0.0, -h, -2 * h, h, 2 * h, 0.0])
        ay = np.array([h, -h, 0.0, 0.0, 0.0, 0.0, 0.0])
        s = self.solve(ax, ay)
        roll = np.degrees(s["u"][:, 2])
        pitch = np.degrees(s["u"][:, 1])
        p0 = pitch[6]
        v = self.car.vehicle
        braking = (4 * pitch[2] - pitch[3] - 3 * p0) / (2 * h)
        traction = -(4 * pitch[4] - pitch[5] - 3 * p0) / (2 * h)
        return {
            "roll_gradient": (roll[0] - roll[1]) / (2 * h),
            "pitch_gradient_braking": np.nan if v.front_bias is None else braking,
            "pitch_gradient_traction": np.nan if v.drive_split is None else traction,
        }

    def frequencies(self) -> dict:
        """``ride_frequency_front``/``_rear`` (Hz): each axle's ride rate — its wheels
        raised together with the body held, the wheel rate's progression under the
        static load included, the tyre in series — on the sprung mass its corners carry;
        ``roll_frequency`` (Hz, with ``masses.sprung_roll_inertia``): the body's roll
        stiffness with the heave, pitch and tyres free, on that inertia."""
        n = np.zeros(1)
        u, q = np.zeros((1, self.nu)), self.q_design[None]
        Fz = self.static[None]
        out = {}
        # the wheels' loads along the road heights, the body held: dF_z/dz_c
        U = np.concatenate([u] + [u + STEP * np.eye(self.nu)[k] for k in range(3, self.nu)])
        got = self._residual(
            U, np.repeat(q, len(U), axis=0), *(np.zeros(len(U)),) * 2, np.repeat(Fz, len(U), axis=0)
        )
        loads = got[2]
        dF = (loads[1:] - loads[0]) / STEP  # row k: along z_k; column: the wheel
        for end, (left, right) in ENDS.items():
            i, j = self.car.labels.index(left), self.car.labels.index(right)
            rate = dF[i, i] + dF[j, i]  # wheel i's load as both wheels rise
            if self.tyre_rates is not None:
                kt = self.tyre_rates[i]
                rate = rate * kt / (rate + kt)
            mass = self.static[i] / G - self.masses["unsprung"][left]
            out[f"ride_frequency_{end}"] = np.sqrt(rate / mass) / (2 * np.pi)
        inertia = self.masses["roll_inertia"]
        if inertia is not None:
            R0, Jac, *_ = self._linearised(u, q, n, n, Fz)
            moment = np.zeros(len(self.free))
            moment[2] = 1.0  # a unit roll moment on the body
            turn = np.linalg.solve(Jac[0], -moment)[2]
            out["roll_frequency"] = np.sqrt(1.0 / turn / inertia) / (2 * np.pi)
        return out
