"""Use a pin_susp URDF with no pin_susp at all: Pinocchio, yourdfpy and the XML.

Loads urdf/double_wishbone.urdf (or the file given) in Pinocchio and in
yourdfpy, reads the loop closures from its <pin_susp:loop_closure> elements,
solves one pose — wheel centre 20 mm up, rack at 0 where there is one — by
Newton on the closures, and checks yourdfpy's forward kinematics at those
joint values. Works for every mechanism's URDF (urdf/*.urdf).

    python examples/urdf_without_pin_susp.py [corner.urdf]
"""

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import yourdfpy

NS = {"pin_susp": "https://github.com/pin-susp/pin_susp/urdf"}
WORLD = pin.LOCAL_WORLD_ALIGNED


def load(path):
    """The Pinocchio model, with one frame per closure anchor, and the closures."""
    text = Path(path).read_text()
    model = pin.buildModelFromXML(text)
    closures = []
    for el in ET.fromstring(text).findall("pin_susp:loop_closure", NS):
        frames = []
        for i, f in enumerate(el.findall("pin_susp:frame", NS)):
            link = model.frames[model.getFrameId(f.get("link"))]
            offset = np.array([float(x) for x in f.get("xyz").split()])
            placement = link.placement * pin.SE3(np.eye(3), offset)
            name = f"{el.get('name')}/{i}"
            frames.append(
                model.addFrame(pin.Frame(name, link.parentJoint, placement, pin.OP_FRAME))
            )
        closures.append((el.get("name"), el.get("type"), frames))
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    lengths = {
        name: np.linalg.norm(data.oMf[b].translation - data.oMf[a].translation)
        for name, kind, (a, b) in closures
        if kind == "distance"
    }
    return model, closures, lengths


def solve_pose(model, closures, lengths, wheel_center_dz=0.02, rack=0.0):
    """Newton: ball closures (3 rows), distance closures (1 row), wheel-centre z, and
    the rack where the model has one."""
    data = model.createData()
    q = pin.neutral(model)
    wc = model.getFrameId("wheel_center")
    pin.framesForwardKinematics(model, data, q)
    wc_goal = data.oMf[wc].translation[2] + wheel_center_dz
    has_rack = model.existJointName("rack_slide")
    rack_v = model.joints[model.getJointId("rack_slide")].idx_v if has_rack else None
    for _ in range(20):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        rows, jac = [], []
        for name, kind, (a, b) in closures:
            d = data.oMf[b].translation - data.oMf[a].translation
            J = (  # (a model with one joint returns a 6-vector: reshaped)
                pin.getFrameJacobian(model, data, b, WORLD).reshape(6, -1)[:3]
                - pin.getFrameJacobian(model, data, a, WORLD).reshape(6, -1)[:3]
            )
            if kind == "ball":
                rows.extend(d)
                jac.extend(J)
            else:
                rows.append(np.linalg.norm(d) - lengths[name])
                jac.append(d / np.linalg.norm(d) @ J)
        rows.append(data.oMf[wc].translation[2] - wc_goal)
        jac.append(pin.getFrameJacobian(model, data, wc, WORLD).reshape(6, -1)[2])
        if has_rack:
            rows.append(q[rack_v] - rack)
            jac.append(np.eye(model.nv)[rack_v])
        r = np.array(rows)
        if np.max(np.abs(r)) < 1e-13:
            return q
        q = pin.integrate(model, q, np.linalg.solve(np.array(jac), -r))
    raise RuntimeError("did not converge")


def yourdfpy_frames(path, joint_values, names):
    robot = yourdfpy.URDF.load(str(path), load_meshes=False)
    assert robot.validate()
    robot.update_cfg({j: joint_values[j] for j in robot.actuated_joint_names})
    return {n: robot.get_transform(n, "chassis")[:3, 3] for n in names}


def main(path):
    model, closures, lengths = load(path)
    q = solve_pose(model, closures, lengths)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    values = {model.names[j]: q[model.joints[j].idx_q] for j in range(1, model.njoints)}
    names = ["wheel_center", "axle_inboard", "axle_outboard"]
    frames = yourdfpy_frames(path, values, names)
    ai = data.oMf[model.getFrameId("axle_inboard")].translation
    ao = data.oMf[model.getFrameId("axle_outboard")].translation
    a = (ao - ai) / np.linalg.norm(ao - ai)
    a[1] = abs(a[1])  # a right corner's spin axis points to −y: its side's sign
    print(f"{Path(path).name}: {len(closures)} loop closures, {model.nv} joints")
    print(
        f"wheel centre 20 mm up: camber {-np.degrees(np.arctan2(a[2], a[1])):.4f} deg, "
        f"toe {np.degrees(np.arctan2(a[0], a[1])):.4f} deg"
    )
    for n in names:
        p = data.oMf[model.getFrameId(n)].translation
        print(
            f"  {n:26} {np.round(p * 1e3, 3)} mm; yourdfpy differs by "
            f"{np.max(np.abs(frames[n] - p)) * 1e3:.1e} mm"
        )


if __name__ == "__main__":
    main(
        sys.argv[1]
        if len(sys.argv) > 1
        else Path(__file__).resolve().parent.parent / "urdf" / "double_wishbone.urdf"
    )
