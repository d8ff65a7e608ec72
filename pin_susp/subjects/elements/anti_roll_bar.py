"""The anti-roll bar (docs/axle.md): a U-bar — an arm per side turning on the bar's
axis, or one rigid bar (``stiffness: rigid``) — or a T-bar, the crossbar on its
pivot; a rigid droplink per side from the rocker (or the body ``anti_roll.mount``
names) to the bar. Its columns: the arms' angles and the bar's twist, the twist's
rate per side's hub z, and its part in the roll stiffness.

Its names are its two corners' labels and its own prefix: an axle's, ``left`` and
``right`` and none (``left_arb_arm``, ``left_droplink_u_bar``, ``arb_u_bar_axis_a``,
``t_bar``; columns ``arb_arm_angle_left``, ``arb_twist``); a vehicle's front axle's,
``fl`` and ``fr`` and ``front_`` (``fl_arb_arm``, ``front_arb_u_bar_axis_a``,
``front_t_bar``; columns ``arb_arm_angle_fl``, ``arb_twist_front``: docs/vehicle.md).
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


def own_suffix(prefix: str) -> str:
    """The suffix of an element's own columns for the prefix of its own names:
    ``"front_"`` → ``"_front"``; none for none."""
    return f"_{prefix.removesuffix('_')}" if prefix else ""


class AntiRollBar:
    """An axle's anti-roll bar (``axle_config.anti_roll``), or none (``kind``; ``spec``,
    the AxleGeometry, None: two corners without an axle file). ``labels``: its two
    corners' labels, the axle's left side's first; ``prefix``: that of its own names
    (its centre points, a T-bar's or a rigid bar's body), whose suffix its own columns
    take (``own_suffix``)."""

    def __init__(self, spec=None, labels: tuple[str, str] = SIDES, prefix: str = ""):
        self.axle = spec
        self.kind = spec.anti_roll if spec else "none"
        self.rigid = bool(spec) and spec.anti_roll_rigid
        self.labels, self.prefix, self.suffix = tuple(labels), prefix, own_suffix(prefix)
        self.sides = dict(zip(self.labels, SIDES, strict=True))  # label → the axle's side
        # its centre points by their names in the model (the prefix's)
        self.center = {prefix + k: p for k, p in spec.center.items()} if spec else {}
        self.u_axis = tuple(prefix + n for n in U_AXIS)
        self.pivot = f"{prefix}arb_t_bar_pivot"

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
        a, first, second = self.axle, *self.labels
        materials.setdefault("bar", (0.85, 0.75, 0.15, 1.0))
        for name, p in self.center.items():
            points[name] = ("chassis", p)
        if self.kind == "u_bar":
            axis = self.u_axis
            for label in self.labels if not self.rigid else (first,):
                arm = self._arm(label)
                bodies.append(Body(arm, "chassis", pivot(f"{arm}_pivot", *axis, self.center)))
            for label in self.labels:
                arm = self._arm(label)
                end = a.side_points[self.sides[label]]["droplink_u_bar"]
                self._droplink(label, "droplink_u_bar", arm, axis, points, closures)
                foot = axis_foot(self.center[axis[0]], self.center[axis[1]], end)
                visuals.append(Visual(arm, "rod", "bar", foot, end, ROD))
                visuals.append(Visual(arm, "ball", "bar", end, radius=BALL))
            visuals.append(
                Visual(
                    "chassis", "rod", "bar", self.center[axis[0]], self.center[axis[1]], 1.5 * ROD
                )
            )
        if self.kind == "t_bar":
            body = f"{self.prefix}t_bar"
            hub = self.center[self.pivot]
            ends = {
                label: a.side_points[self.sides[label]]["droplink_t_bar"] for label in self.labels
            }
            middle = 0.5 * (ends[first] + ends[second])
            # the crossbar's midpoint stays in y = 0: the stem pitches about chassis y and
            # the crossbar twists about the stem (a universal joint: exactly the ball with
            # the midpoint held in the plane); a rigid bar only pitches
            y, stem = np.array([0.0, 1.0, 0.0]), unit(middle - hub)
            joint = (
                Joint(f"{body}_pivot", "revolute", hub, y)
                if self.rigid
                else Joint(f"{body}_pivot", "universal", hub, y, (self.pivot,), stem)
            )
            bodies.append(Body(body, "chassis", joint))
            for label in self.labels:
                other = f"{second if label == first else first}_droplink_t_bar"
                guard = (self.pivot, other)
                self._droplink(label, "droplink_t_bar", body, guard, points, closures)
                visuals.append(Visual(body, "ball", "bar", ends[label], radius=BALL))
            visuals.append(Visual(body, "rod", "bar", ends[first], ends[second], 1.5 * ROD))
            visuals.append(Visual(body, "rod", "bar", hub, middle, 1.5 * ROD))

    def _arm(self, label: str) -> str:
        """The body a U-bar's side turns: its own arm, or the one rigid bar."""
        return f"{self.prefix}arb_bar" if self.rigid else f"{label}_arb_arm"

    def _droplink(self, label: str, lower: str, bar: str, guard, points, closures) -> None:
        """One side's rigid droplink: from the rocker (or the body ``anti_roll.mount``
        names) to the point ``lower`` on the bar's body; its assembly is kept by the sign
        of the volume of the two ``guard`` points and its ends."""
        a, side = self.axle, self.sides[label]
        sp = a.side_points[side]
        upper = "droplink_rocker" if "droplink_rocker" in sp else "droplink_lower"
        if upper == "droplink_rocker":
            carrier = f"{label}_rocker"
        else:  # no rocker: the body anti_roll.mount names
            carrier = f"{label}_{mount_body(a.corner(side), a.anti_roll_mount)}"
        points[f"{label}_{lower}"] = (bar, sp[lower])
        points[f"{label}_{upper}"] = (carrier, sp[upper])
        ends = (f"{label}_{upper}", f"{label}_{lower}")
        closures.append(
            Closure(
                f"{label}_droplink",
                "distance",
                tuple((n, points[n][1]) for n in ends),
                ends,
                branch=(*guard, *ends),
            )
        )

    def columns(self, model, p: dict, d: dict) -> dict:
        """A U-bar's ``arb_arm_angle_<label>`` per corner and ``arb_twist`` (deg, the
        first corner's arm's angle less the second's), a T-bar's ``arb_twist``; the
        twist with its own suffix (``arb_twist_front``)."""
        out = {}
        if self.kind == "u_bar":
            axis = (self.center[self.u_axis[0]], self.center[self.u_axis[1]])
            angles = {}
            for label in self.labels:
                name = f"{label}_droplink_u_bar"
                angles[label] = turn(axis, d[name], p[name])
                out[f"arb_arm_angle_{label}"] = (angles[label], "deg")
            first, second = self.labels
            out[f"arb_twist{self.suffix}"] = (angles[first] - angles[second], "deg")
        if self.kind == "t_bar":
            ends = (p[f"{label}_droplink_t_bar"] for label in self.labels)
            out[f"arb_twist{self.suffix}"] = (np.degrees(self.t_bar_twist(model, *ends)), "deg")
        return out

    def rate_columns(self, model, points: dict) -> dict:
        """``deriv_arb_twist_wrt_hub_z_<label>`` per corner (deg/mm): the twist's rate
        along each corner's own hub z (``points``: name → {label: jet.Dual})."""
        out = {}
        for label in self.labels if self.kind != "none" else ():
            sign = 1.0 if label == self.labels[0] else -1.0
            if self.kind == "u_bar":
                axis = (self.center[self.u_axis[0]], self.center[self.u_axis[1]])
                rate = turn_rate(axis, points[f"{label}_droplink_u_bar"][label], sign)
            else:
                ends = [points[f"{s}_droplink_t_bar"][label] for s in self.labels]
                rate = np.degrees(self.t_bar_twist(model, *ends).der[0]) * 1e-3
            out[f"deriv_arb_twist_wrt_hub_z_{label}"] = (rate, "deg/mm")
        return out

    def t_bar_twist(self, model, left, right):
        """The T-bar crossbar's twist (rad) about its stem from design, from its two ends
        (the first corner's, then the second's: arrays (n, 3) or jet.Duals; right-hand
        rule about the design stem pivot → crossbar midpoint). The bar turns on a
        universal joint — a pitch θ of the stem about chassis y, then the twist about
        the stem — so undoing θ (read from the stem, which only pitches) leaves the
        crossbar turned by the twist alone."""
        d = model.design_positions
        first, second = (d[f"{label}_droplink_t_bar"] for label in self.labels)
        hub = self.center[self.pivot]
        s0 = 0.5 * (first + second) - hub
        c0 = first - second
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
        its twist rates (``rate_columns``'s) and each corner's hub z per radian of roll
        (by label); None without a bar."""
        if self.kind == "none":
            return None
        first, second = self.labels
        k = self.axle.anti_roll_stiffness * 180.0 / np.pi  # N·m/rad
        twist = {
            s: np.radians(rates[f"deriv_arb_twist_wrt_hub_z_{s}"][0]) * 1e3 for s in self.labels
        }
        term = k * (twist[first] * per_rad[first] + twist[second] * per_rad[second]) ** 2
        wheel = (0.5 * k * (twist[first] - twist[second]) ** 2 * 1e-3, "N/mm")
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
