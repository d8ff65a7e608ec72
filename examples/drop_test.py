"""Drop test: the exported MJCF settles a corner under a static load where pin_susp's
statics put it.

The corner's MJCF exactly as `pin-susp mjcf` writes it, in MuJoCo: the chassis is
fixed (it is the world), the rack is held at design by the file's `steering` actuator
(ctrl 0), and gravity is switched off — pin_susp's statics have no mass, so the load is
the only force. A vertical force of LOAD newtons pushes up at the contact patch (each
step, the lowest point of the tyre disc, applied to the wheel's body) against the
spring tendon (the geometry's rate and preload) and its damper, until the corner stops.

pin_susp's static solve of the same load: the wheel travel at which the spring force
that holds the load (`loads.Statics`, the rack held) is the force the spring has there
(preload + rate × compression, `rates.SpringRates`).

    python examples/drop_test.py [GEOMETRY.yaml] [--load N]
"""

import argparse
from pathlib import Path

import mujoco
import numpy as np
from scipy.optimize import brentq

import pin_susp
from pin_susp.analyses.loads import LoadCase, Statics
from pin_susp.model.mjcf import tree_to_mjcf
from pin_susp.solve.rates import SpringRates

HERE = Path(__file__).resolve().parent
SETTLED = 1e-7  # m/s and rad/s: every joint's speed below this is at rest
MAX_TIME = 10.0  # s of simulated time


def static_travel(corner, load: float, step: float = 5.0) -> float:
    """pin_susp's wheel travel (mm, + up) under a vertical contact-patch load (N): where
    the spring force the load needs equals the spring's own force, the rack at design."""
    statics, rates = Statics(corner), SpringRates(corner)
    case = LoadCase("corner load", np.array([0.0, 0.0, load]), np.zeros(3), np.zeros(3))
    name = "torque" if corner.geometry.spring == "torsion_bar" else "force"
    rack = corner.geometry.steering == "rack"

    def imbalance(z: float) -> float:
        targets = [pin_susp.Target("wheel_center", "z", z)]
        if rack:
            targets.append(pin_susp.Target(corner.geometry.steering_points[0], "y", 0.0))
        pose = corner.solve_pose(targets)
        if not pose.converged:
            raise RuntimeError(f"no pose at {z:g} mm of wheel travel")
        need = statics.solve(pose.q, case)[f"{name}_spring"]
        have = rates.columns([pose.q])[f"spring_{name}"][0][0]
        return need - have

    # from design, in steps toward the side the load pushes, to the first change of sign
    start = imbalance(0.0)
    up = 1.0 if start > 0.0 else -1.0
    z = 0.0
    while imbalance(z + up * step) * start > 0.0:
        z += up * step
    return brentq(imbalance, z, z + up * step, xtol=1e-9)


def contact_patch(data, sites, radius: float) -> np.ndarray:
    """The lowest point of the tyre disc (docs/geometry.md) from the MJCF's sites."""
    centre, inboard, outboard = (
        data.site_xpos[sites[n]] for n in ("wheel_center", "axle_inboard", "axle_outboard")
    )
    spin = (outboard - inboard) / np.linalg.norm(outboard - inboard)
    down = spin * spin[2] - np.array([0.0, 0.0, 1.0])
    return centre + radius * down / np.linalg.norm(down)


def settle(corner, load: float, mjcf_text: str | None = None) -> tuple[float, float]:
    """MuJoCo's settled wheel travel (mm) under the load, and the simulated time (s)."""
    model = mujoco.MjModel.from_xml_string(mjcf_text or tree_to_mjcf(corner.tree))
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    site = lambda name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)  # noqa: E731
    sites = {n: site(n) for n in ("wheel_center", "axle_inboard", "axle_outboard")}
    wheel = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, corner.mechanism.WHEEL_BODY)
    mujoco.mj_forward(model, data)
    design = data.site_xpos[sites["wheel_center"]][2]
    force = np.array([0.0, 0.0, load])
    for _ in range(round(MAX_TIME / model.opt.timestep)):
        mujoco.mj_step1(model, data)  # positions: where the contact patch is now
        data.qfrc_applied[:] = 0.0
        point = contact_patch(data, sites, corner.geometry.wheel.radius)
        mujoco.mj_applyFT(model, data, force, np.zeros(3), point, wheel, data.qfrc_applied)
        mujoco.mj_step2(model, data)
        if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:  # MuJoCo reset the state
            raise RuntimeError(f"the simulation went unstable at {data.time:.3f} s")
        if data.time > 0.1 and np.max(np.abs(data.qvel)) < SETTLED:
            break
    else:
        raise RuntimeError(f"not settled after {MAX_TIME:g} s")
    mujoco.mj_forward(model, data)
    return (data.site_xpos[sites["wheel_center"]][2] - design) * 1e3, float(data.time)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("geometry", nargs="?", default=HERE / "pushrod_rocker.yaml")
    parser.add_argument("--load", type=float, default=1500.0, help="N, up at the contact patch")
    args = parser.parse_args(argv)
    corner = pin_susp.Corner(args.geometry)
    ours = static_travel(corner, args.load)
    theirs, time = settle(corner, args.load)
    print(f"{Path(args.geometry).name}: {args.load:g} N up at the contact patch")
    print(f"  pin_susp statics: wheel travel {ours:.4f} mm")
    print(f"  MuJoCo (settled after {time:.2f} s): {theirs:.4f} mm")
    print(f"  difference: {theirs - ours:+.4f} mm")


if __name__ == "__main__":
    main()
