"""The MuJoCo engine (README, How it works): the exported MJCF in MuJoCo, solved to
every step's targets by Newton on its own Jacobians, its warnings counted. A floating
root (a vehicle's body on its ``freejoint``) is placed at each step's pose by setting
the freejoint's ``qpos``, and held there while the rest is solved.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from ..analyses.pointwise import as_target
from ..errors import PinSuspError
from ..model.tree import BodyPose
from .engines import Warnings, richardson, target_rows, with_contact_patches
from .scopes import scope_of


class MujocoCorner:
    """The exported MJCF (a corner's or an axle's) in MuJoCo, solved to targets by
    Newton on its own Jacobians.

    Build and use it inside :func:`quiet_mujoco`: MuJoCo otherwise prints its
    warnings and appends them to ``MUJOCO_LOG.TXT`` in the working directory.
    """

    def __init__(self, mjcf_text: str, subject, source: str = "the MJCF"):
        import mujoco

        scope = scope_of(subject)
        self.mj = mujoco
        try:
            self.model = mujoco.MjModel.from_xml_string(mjcf_text)
        except ValueError as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo cannot load it: {detail}") from None
        self.data = mujoco.MjData(self.model)
        self.sites = with_contact_patches(
            {name: _Site(self, name, source) for name in scope.sites}, scope
        )
        m = self.model
        free = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
        # the floating root's qpos address (position, then quaternion w x y z) and the
        # dofs that move in a solve: every one but the floating root's
        self.base = int(m.jnt_qposadr[free[0]]) if free else None
        self.moving = np.ones(m.nv, dtype=bool)
        if free:
            self.moving[m.jnt_dofadr[free[0]] : m.jnt_dofadr[free[0]] + 6] = False
        self.source = source
        self.road = {}  # the points where the last solve put them
        self.moved = {}  # its tangent along each of the body's quantities there (dv)

    def _place(self, pose: BodyPose | None) -> None:
        """The floating root at ``pose`` (its qpos), or at its design place (None)."""
        if self.base is None:
            if pose is None:
                return
            raise PinSuspError(
                f"{self.source}: its root does not float (no freejoint): it is not the MJCF "
                "of this vehicle"
            )
        q = self.data.qpos
        if pose is None:
            q[self.base : self.base + 7] = self.model.qpos0[self.base : self.base + 7]
            return
        quat = np.zeros(4)
        self.mj.mju_mat2Quat(quat, np.ascontiguousarray(pose.rotation).ravel())
        q[self.base : self.base + 3] = pose.translation
        q[self.base + 3 : self.base + 7] = quat

    def _rows(self, targets) -> tuple[list, list]:
        """Each target's residual and its row of d residual / dv (chain rule through
        the sites' Jacobians)."""
        p = {name: site.position(self) for name, site in self.sites.items()}
        return target_rows(self, p, targets)

    def solve(self, targets, iterations: int = 30, moves: dict | None = None) -> dict | None:
        """Newton from the design state to the targets; a floating root held at the
        step's pose (its BodyPose). The points: where it solved them (``road``), and
        returned with the root put back at its design place, the joints kept (a
        vehicle's chassis frame). ``moves``: the step's targets with the body moved
        (Scope.step_moves), for the tangent along each (``moved``, ``along``)."""
        m, d, mj = self.model, self.data, self.mj
        pose = next((t for t in targets if isinstance(t, BodyPose)), None)
        targets = [t for t in targets if t is not pose]
        self.moved = {}
        d.qpos[:] = m.qpos0
        self._place(pose)
        for _ in range(iterations + 1):
            mj.mj_forward(m, d)
            eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
            errors, rows = self._rows(targets)
            r = np.concatenate([d.efc_pos[: d.nefc][eq], errors])
            if not np.all(np.isfinite(r)):
                return None  # diverged, or a NaN in the MJCF: lstsq would fail on it
            if np.max(np.abs(r)) < 1e-13:
                self.moved = self._moved(targets, moves or {})
                return self._points()
            jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
            J = np.vstack(jac + rows)
            if not np.all(np.isfinite(J)):
                return None
            dv = np.zeros(m.nv)
            dv[self.moving] = np.linalg.lstsq(J[:, self.moving], -r, rcond=None)[0]
            mj.mj_integratePos(m, d.qpos, dv, 1.0)
        return None

    def _moved(self, targets, moves: dict) -> dict:
        """At the solved pose: dv per unit of each of the body's quantities, the others
        held — J·dv = −∂r/∂s, the change of the targets' residuals as the floating root
        moves with the joints held (Richardson differences over the moved poses; the
        closures' rows do not change)."""
        if not moves:
            return {}
        m, d, mj = self.model, self.data, self.mj
        eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
        jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
        J = np.vstack(jac + self._rows(targets)[1])
        closures = int(np.count_nonzero(eq))
        q = d.qpos.copy()
        out = {}
        for quantity, (h, moved) in moves.items():
            residuals = []
            for step in moved:
                pose = next(t for t in step if isinstance(t, BodyPose))
                self._place(pose)
                mj.mj_kinematics(m, d)
                p = {name: s.position(self) for name, s in self.sites.items()}
                errors = [as_target(t).error(p) for t in step if t is not pose]
                residuals.append(np.r_[np.zeros(closures), errors])
            d.qpos[:] = q
            dv = np.zeros(m.nv)
            dv[self.moving] = np.linalg.lstsq(
                J[:, self.moving], -richardson(residuals, h), rcond=None
            )[0]
            out[quantity] = dv
        mj.mj_forward(m, d)
        return out

    def along(self, hubs: dict) -> dict:
        """Each wheel centre's z rate along the body's quantities (``moved``), at the
        current pose (the chassis frame): quantity → {label: m per m or rad}."""
        return {
            quantity: {
                label: float((self.sites[hub].jacobian(self) @ dv)[2])
                for label, hub in hubs.items()
            }
            for quantity, dv in self.moved.items()
        }

    def _points(self) -> dict:
        """Every point where solved (kept as ``road``), then with a floating root put
        back at its design place (the joints kept), as returned."""
        self.road = {name: s.position(self).copy() for name, s in self.sites.items()}
        if self.base is None:
            return self.road
        self._place(None)
        self.mj.mj_forward(self.model, self.data)
        return {name: s.position(self).copy() for name, s in self.sites.items()}

    def rates(self, held, k: int) -> dict[str, np.ndarray]:
        """At the solved pose: each point's rate along the first len(held) of k drivers,
        J·dv = e (equality rows and the held targets' rows, least squares), through
        the sites' Jacobians; NaN for a driver it cannot move (a toe link's length:
        its links are rigid bodies closed by connects). A floating root stays still."""
        m, d, mj = self.model, self.data, self.mj
        mj.mj_forward(m, d)
        eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
        jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
        J = np.vstack(jac + self._rows(held)[1])
        rhs = np.zeros((len(J), len(held)))
        rhs[len(J) - len(held) :] = np.eye(len(held))
        dv = np.zeros((m.nv, len(held)))
        dv[self.moving] = np.linalg.lstsq(J[:, self.moving], rhs, rcond=None)[0]
        out = {}
        for name, site in self.sites.items():
            out[name] = np.full((k, 3), np.nan)
            out[name][: len(held)] = (site.jacobian(self) @ dv).T
        return out


@contextmanager
def quiet_mujoco(mj):
    """MuJoCo's warnings counted instead of printed and logged to MUJOCO_LOG.TXT.

    Installs a counting ``mju_user_warning`` handler (MuJoCo then neither
    prints nor logs a warning) and, where MuJoCo has it (3.4+), switches the
    default log handler's console and file output off as well; both are
    restored on the way out. Yields the :class:`Warnings` counter.
    """
    counter = Warnings()
    set_warning = getattr(mj, "set_mju_user_warning", None)
    log_config = getattr(mj, "MjLogConfig", None)
    old_warning = mj.get_mju_user_warning() if set_warning else None
    old_config = log_config.get() if log_config else None
    try:
        if set_warning:
            set_warning(counter)
        if log_config:
            config = log_config.get()
            config.logto_console = False
            config.logto_file = False
            config.set()
        yield counter
    finally:
        if set_warning:
            set_warning(old_warning)
        if old_config is not None:
            old_config.set()


class _Site:
    """A MuJoCo site as a point: position and (3 × nv) Jacobian."""

    def __init__(self, engine: MujocoCorner, name: str, source: str = "the MJCF"):
        self.name = name
        self.id = engine.mj.mj_name2id(engine.model, engine.mj.mjtObj.mjOBJ_SITE, name)
        if self.id < 0:
            raise PinSuspError(f"{source}: is not the MJCF of this geometry: missing site {name}")

    def position(self, engine: MujocoCorner) -> np.ndarray:
        return engine.data.site_xpos[self.id]

    def jacobian(self, engine: MujocoCorner) -> np.ndarray:
        jacp = np.zeros((3, engine.model.nv))
        engine.mj.mj_jacSite(engine.model, engine.data, jacp, None, self.id)
        return jacp


def mujoco_points(subject, sweep, mjcf_text: str, source: str = "the MJCF") -> list:
    """MuJoCo's points at every step (None where it did not converge), quietly, as the
    subject's motion gives them."""
    scope = scope_of(subject)
    return scope.as_motion(mujoco_run(scope, sweep, mjcf_text, source)[0])


def mujoco_run(scope, sweep, mjcf_text: str, source: str):
    """(points, a Dual per label; warnings counter); MuJoCo's errors as PinSuspError
    naming ``source``."""
    import mujoco

    with quiet_mujoco(mujoco) as counter:
        try:
            engine = MujocoCorner(mjcf_text, scope, source)
            points = []
            steps = zip(scope.step_targets(sweep), scope.step_moves(sweep), strict=True)
            for targets, moves in steps:
                at = engine.solve(targets, moves=moves)
                if at is None:
                    points.append(None)
                    continue
                rates = engine.rates(scope.held(at), scope.drivers)
                along = engine.along(scope.hubs)
                points.append(scope.duals(at, rates, engine.road, along))
        except (mujoco.FatalError, mujoco.UnexpectedError) as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo failed on it: {detail}") from None
    return points, counter
