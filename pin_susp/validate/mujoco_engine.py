"""The MuJoCo engine (README, How it works): the exported MJCF in MuJoCo, solved to
every step's targets by Newton on its own Jacobians, its warnings counted.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from ..errors import PinSuspError
from .engines import Warnings, target_rows, with_contact_patches
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

    def _rows(self, targets) -> tuple[list, list]:
        """Each target's residual and its row of d residual / dv (chain rule through
        the sites' Jacobians)."""
        p = {name: site.position(self) for name, site in self.sites.items()}
        return target_rows(self, p, targets)

    def solve(self, targets, iterations: int = 30) -> dict | None:
        """Newton from the design state to the targets."""
        m, d, mj = self.model, self.data, self.mj
        d.qpos[:] = m.qpos0
        for _ in range(iterations + 1):
            mj.mj_forward(m, d)
            eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
            errors, rows = self._rows(targets)
            r = np.concatenate([d.efc_pos[: d.nefc][eq], errors])
            if not np.all(np.isfinite(r)):
                return None  # diverged, or a NaN in the MJCF: lstsq would fail on it
            if np.max(np.abs(r)) < 1e-13:
                return {name: s.position(self).copy() for name, s in self.sites.items()}
            jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
            J = np.vstack(jac + rows)
            if not np.all(np.isfinite(J)):
                return None
            dv = np.linalg.lstsq(J, -r, rcond=None)[0]
            mj.mj_integratePos(m, d.qpos, dv, 1.0)
        return None

    def rates(self, held, k: int) -> dict[str, np.ndarray]:
        """At the solved pose: each point's rate along the first len(held) of k drivers,
        J·dv = e (equality rows and the held targets' rows, least squares), through
        the sites' Jacobians; NaN for a driver it cannot move (a toe link's length:
        its links are rigid bodies closed by connects)."""
        m, d, mj = self.model, self.data, self.mj
        mj.mj_forward(m, d)
        eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
        jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
        J = np.vstack(jac + self._rows(held)[1])
        rhs = np.zeros((len(J), len(held)))
        rhs[len(J) - len(held) :] = np.eye(len(held))
        dv = np.linalg.lstsq(J, rhs, rcond=None)[0]
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
            for targets in scope.step_targets(sweep):
                at = engine.solve(targets)
                if at is None:
                    points.append(None)
                    continue
                rates = engine.rates(scope.held(at), scope.drivers)
                points.append(scope.duals(at, rates))
        except (mujoco.FatalError, mujoco.UnexpectedError) as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo failed on it: {detail}") from None
    return points, counter
