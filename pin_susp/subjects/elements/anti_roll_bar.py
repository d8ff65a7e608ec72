"""The anti-roll bar (docs/axle.md): a U-bar — an arm per side turning on the bar's
axis, or one rigid bar (``stiffness: rigid``) — or a T-bar, the crossbar on its
pivot; a rigid droplink per side from the rocker (or the body ``anti_roll.mount``
names) to the bar. Its columns: the arms' angles and the bar's twist, the twist's
rate per side's hub z, and its part in the roll stiffness.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...maths.vectors import unit
from ...model.mechanisms import BALL, ROD, axis_foot, pivot
from ...model.tree import Body, Closure, Joint, Visual

SIDES = ("left", "right")
U_AXIS = ("arb_u_bar_axis_a", "arb_u_bar_axis_b")


def mount_body(g, mount: str) -> str:
    """``anti_roll.mount`` as a body of the corner's tree ("arm": the wheel's body)."""
    return {"arm": g.mechanism.WHEEL_BODY}.get(mount, mount)


class AntiRollBar:
    """An axle's anti-roll bar (``axle_config.anti_roll``), or none (``kind``; ``spec``,
    the AxleGeometry, None: two corners without an axle file)."""

    def __init__(self, spec=None):
        self.axle = spec
        self.kind = spec.anti_roll if spec else "none"
        self.rigid = bool(spec) and spec.anti_roll_rigid
        self.center = spec.center if spec else {}

    quantities = ()  # no sweep target is its row

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """None of its own at this level: the axle's pair of corners (wheel_pair.py)
        writes its ``columns`` among the axle's, in the results' column order."""
        return {}

    def check_targets(self, targets, source: str) -> None:
        """A rigid bar locks the corners together: a roll target refused."""
        for i, t in enumerate(targets):
            if self.rigid and t.quantity == "roll":
                raise InputError(
                    source,
                    f"targets[{i}]",
                    "roll is fixed by the rigid anti-roll bar (axle_config.anti_roll.stiffness: "
                    "rigid): the axle only heaves, so a roll target is unreachable or redundant; "
                    "give heave (or one wheel height) and the rack",
                )

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        """The bar's material and centre points (its axis or pivot), its bodies and
        joints, a droplink closure per side, its shapes."""
        a = self.axle
        materials.setdefault("bar", (0.85, 0.75, 0.15, 1.0))
        for name, p in a.center.items():
            points[name] = ("chassis", p)
        if self.kind == "u_bar":
            axis = U_AXIS
            for side in SIDES if not self.rigid else ("left",):
                arm = "arb_bar" if self.rigid else f"{side}_arb_arm"
                bodies.append(Body(arm, "chassis", pivot(f"{arm}_pivot", *axis, a.center)))
            for side in SIDES:
                arm = "arb_bar" if self.rigid else f"{side}_arb_arm"
                end = a.side_points[side]["droplink_u_bar"]
                self._droplink(side, "droplink_u_bar", arm, axis, points, closures)
                foot = axis_foot(a.center[axis[0]], a.center[axis[1]], end)
                visuals.append(Visual(arm, "rod", "bar", foot, end, ROD))
                visuals.append(Visual(arm, "ball", "bar", end, radius=BALL))
            visuals.append(
                Visual("chassis", "rod", "bar", a.center[axis[0]], a.center[axis[1]], 1.5 * ROD)
            )
        if self.kind == "t_bar":
            hub = a.center["arb_t_bar_pivot"]
            ends = {side: a.side_points[side]["droplink_t_bar"] for side in SIDES}
            middle = 0.5 * (ends["left"] + ends["right"])
            # the crossbar's midpoint stays in y = 0: the stem pitches about chassis y and
            # the crossbar twists about the stem (a universal joint: exactly the ball with
            # the midpoint held in the plane); a rigid bar only pitches
            y, stem = np.array([0.0, 1.0, 0.0]), unit(middle - hub)
            joint = (
                Joint("t_bar_pivot", "revolute", hub, y)
                if self.rigid
                else Joint("t_bar_pivot", "universal", hub, y, ("arb_t_bar_pivot",), stem)
            )
            bodies.append(Body("t_bar", "chassis", joint))
            for side in SIDES:
                other = f"{'right' if side == 'left' else 'left'}_droplink_t_bar"
                guard = ("arb_t_bar_pivot", other)
                self._droplink(side, "droplink_t_bar", "t_bar", guard, points, closures)
                visuals.append(Visual("t_bar", "ball", "bar", ends[side], radius=BALL))
            visuals.append(Visual("t_bar", "rod", "bar", ends["left"], ends["right"], 1.5 * ROD))
            visuals.append(Visual("t_bar", "rod", "bar", hub, middle, 1.5 * ROD))

    def _droplink(self, side: str, lower: str, bar: str, guard, points, closures) -> None:
        """One side's rigid droplink: from the rocker (or the body ``anti_roll.mount``
        names) to the point ``lower`` on the bar's body; its assembly is kept by the sign
        of the volume of the two ``guard`` points and its ends."""
        a = self.axle
        sp = a.side_points[side]
        upper = "droplink_rocker" if "droplink_rocker" in sp else "droplink_lower"
        if upper == "droplink_rocker":
            carrier = f"{side}_rocker"
        else:  # no rocker: the body anti_roll.mount names
            carrier = f"{side}_{mount_body(a.corner(side), a.anti_roll_mount)}"
        points[f"{side}_{lower}"] = (bar, sp[lower])
        points[f"{side}_{upper}"] = (carrier, sp[upper])
        ends = (f"{side}_{upper}", f"{side}_{lower}")
        closures.append(
            Closure(
                f"{side}_droplink",
                "distance",
                tuple((n, points[n][1]) for n in ends),
                ends,
                branch=(*guard, *ends),
            )
        )

    def columns(self, model, p: dict, d: dict) -> dict:
        """A U-bar's ``arb_arm_angle_left``/``_right`` and ``arb_twist`` (deg), a
        T-bar's ``arb_twist``."""
        out = {}
        if self.kind == "u_bar":
            axis = (self.center[U_AXIS[0]], self.center[U_AXIS[1]])
            angles = {}
            for side in SIDES:
                name = f"{side}_droplink_u_bar"
                angles[side] = turn(axis, d[name], p[name])
                out[f"arb_arm_angle_{side}"] = (angles[side], "deg")
            out["arb_twist"] = (angles["left"] - angles["right"], "deg")
        if self.kind == "t_bar":
            ends = (p["left_droplink_t_bar"], p["right_droplink_t_bar"])
            out["arb_twist"] = (np.degrees(self.t_bar_twist(model, *ends)), "deg")
        return out

    def rate_columns(self, model, points: dict) -> dict:
        """``deriv_arb_twist_wrt_hub_z_left``/``_right`` (deg/mm): the twist's rate
        along each side's own hub z (``points``: name → {side: jet.Dual})."""
        out = {}
        for side in SIDES if self.kind != "none" else ():
            sign = 1.0 if side == "left" else -1.0
            if self.kind == "u_bar":
                axis = (self.center[U_AXIS[0]], self.center[U_AXIS[1]])
                rate = turn_rate(axis, points[f"{side}_droplink_u_bar"][side], sign)
            else:
                ends = [points[f"{s}_droplink_t_bar"][side] for s in SIDES]
                rate = np.degrees(self.t_bar_twist(model, *ends).der[0]) * 1e-3
            out[f"deriv_arb_twist_wrt_hub_z_{side}"] = (rate, "deg/mm")
        return out

    def t_bar_twist(self, model, left, right):
        """The T-bar crossbar's twist (rad) about its stem from design, from its two ends
        (arrays (n, 3) or jet.Duals; right-hand rule about the design stem pivot →
        crossbar midpoint). The bar turns on a universal joint — a pitch θ of the stem
        about chassis y, then the twist about the stem — so undoing θ (read from the
        stem, which only pitches) leaves the crossbar turned by the twist alone."""
        d = model.design_positions
        hub = self.center["arb_t_bar_pivot"]
        s0 = 0.5 * (d["left_droplink_t_bar"] + d["right_droplink_t_bar"]) - hub
        c0 = d["left_droplink_t_bar"] - d["right_droplink_t_bar"]
        sx, sz = (
            0.5 * (left[..., 0] + right[..., 0]) - hub[0],
            0.5 * (left[..., 2] + right[..., 2]) - hub[2],
        )
        rho = np.sqrt((s0[0] * sx + s0[2] * sz) ** 2 + (s0[2] * sx - s0[0] * sz) ** 2)
        cos, sin = (s0[0] * sx + s0[2] * sz) / rho, (s0[2] * sx - s0[0] * sz) / rho
        cx, cy, cz = (left[..., i] - right[..., i] for i in range(3))
        c = (cx * cos - cz * sin, cy, cx * sin + cz * cos)  # the crossbar with θ undone
        u = s0 / np.linalg.norm(s0)
        w0 = c0 - (c0 @ u) * u
        along = c[0] * u[0] + c[1] * u[1] + c[2] * u[2]
        w = [c[i] - along * u[i] for i in range(3)]
        k = np.cross(u, w0)  # (w0 × w)·u = w·(u × w0)
        return np.arctan2(
            w[0] * k[0] + w[1] * k[1] + w[2] * k[2],
            w[0] * w0[0] + w[1] * w0[1] + w[2] * w0[2],
        )

    def roll_term(self, rates: dict, per_rad: dict) -> tuple | None:
        """The bar's part in the roll stiffness, ``(k·(dθ/dφ)², arb_wheel_rate)``, from
        its twist rates (``rate_columns``'s) and each side's hub z per radian of roll;
        None without a bar."""
        if self.kind == "none":
            return None
        k = self.axle.anti_roll_stiffness * 180.0 / np.pi  # N·m/rad
        twist = {s: np.radians(rates[f"deriv_arb_twist_wrt_hub_z_{s}"][0]) * 1e3 for s in SIDES}
        term = k * (twist["left"] * per_rad["left"] + twist["right"] * per_rad["right"]) ** 2
        wheel = (0.5 * k * (twist["left"] - twist["right"]) ** 2 * 1e-3, "N/mm")
        return term, wheel


def turn(axis, p0: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed rotation (deg) of a point about the axis a → b from p0 (right-hand rule)."""
    a, b = axis
    u = (b - a) / np.linalg.norm(b - a)
    w0, w = p0 - a, p - a
    w0 = w0 - np.outer(w0 @ u, u)
    w = w - np.outer(w @ u, u)
    return np.degrees(np.arctan2(np.cross(w0, w) @ u, np.sum(w0 * w, axis=-1)))


def turn_rate(axis, p, sign: float) -> np.ndarray:
    """d(arm angle)/d(own hub z) (deg/mm) of a point turning about the axis; the
    twist is left − right, so the right arm's rate counts negative."""
    a, b = axis
    u = (b - a) / np.linalg.norm(b - a)
    arm = p.val - a
    arm = arm - np.outer(arm @ u, u)
    velocity = p.der[0]
    rate = np.sum(np.cross(arm, velocity) * u, axis=-1) / np.sum(arm * arm, axis=-1)
    return sign * np.degrees(rate) * 1e-3
