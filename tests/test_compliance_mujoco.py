"""The K&C against MuJoCo (docs/compliance.md, "Checks"): the same corner exported as
MJCF (``tree_to_mjcf``), each body on bushings given three slide and three hinge joints
at its pivot's midpoint along the bushing's axes — MJCF joint ``stiffness`` the
bushings' combined rates there — in place of its pivot hinge; the spring held (an
equality on its tendon), the rack held. Its static equilibrium under the load is found
by Newton on MuJoCo's own quantities (``qfrc_spring``, ``mj_applyFT``, the equality
rows' ``efc_J``, the tendon's ``ten_J``), not on pin_susp's; the wheel centre's
deflection agrees within 1e-3 mm (measured: far closer)."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp.analyses.compliance import KC
from pin_susp.analyses.compliance_model import bushing_frame
from pin_susp.analyses.load_case import LoadCase
from pin_susp.analyses.statics import Statics
from pin_susp.model.mjcf import tree_to_mjcf
from pin_susp.subjects.subject import load_subject

LOWER = {"radial": 3000, "axial": 800, "torsional": 0.5, "conical": 2.0}
UPPER = {"radial": 2000, "axial": 500}
DEG = np.pi / 180


def _corner(tmp_path):
    data = yaml.safe_load((EXAMPLES / "pushrod_rocker.yaml").read_text())
    data["compliance"] = {"bushings": {
        "lower_wishbone_inboard_front": LOWER, "lower_wishbone_inboard_rear": LOWER,
        "upper_wishbone_inboard_front": UPPER, "upper_wishbone_inboard_rear": UPPER}}  # fmt: skip
    path = tmp_path / "corner.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_subject(path)


def _stiffnesses(rates, length):
    """A pair of equal bushings a pivot length apart, combined at its midpoint, along
    the bushing's axes: slides x, y radial, z axial; hinges x, y conical, z torsional."""
    kr, ka = rates["radial"] * 1e3, rates["axial"] * 1e3
    kt, kc = rates.get("torsional", 0.0) / DEG, rates.get("conical", 0.0) / DEG
    tilt = 2 * kc + 2 * kr * (length / 2) ** 2
    return [2 * kr, 2 * kr, 2 * ka], [tilt, tilt, 2 * kt]


def _mjcf(subject) -> str:
    root = ET.fromstring(tree_to_mjcf(subject.export_tree))
    equality = root.find("equality")
    equality = ET.SubElement(root, "equality") if equality is None else equality
    ET.SubElement(equality, "tendon", {"name": "spring_held", "tendon1": "spring"})
    root.find("option").set("gravity", "0 0 0")
    for tendon in root.iter("spatial"):
        tendon.set("stiffness", "0")
    p = subject.design_positions
    for body in root.iter("body"):
        name = body.get("name")
        if name not in ("lower_wishbone", "upper_wishbone"):
            continue
        a, b = p[f"{name}_inboard_front"], p[f"{name}_inboard_rear"]
        R = bushing_frame(b - a)
        slides, hinges = _stiffnesses(LOWER if name.startswith("lower") else UPPER,
                                      np.linalg.norm(b - a))  # fmt: skip
        pivot = body.find("joint")
        index = list(body).index(pivot)
        body.remove(pivot)
        mid = _text(0.5 * (b - a))  # the body's frame: at a, world-aligned
        joints = [("slide", R[:, i], slides[i]) for i in range(3)]
        joints += [("hinge", R[:, i], hinges[i]) for i in range(3)]
        for k, (kind, axis, stiffness) in enumerate(joints):
            spec = {"name": f"{name}_bushing_{k}", "type": kind, "pos": mid}
            spec |= {"axis": _text(axis), "stiffness": _text([stiffness])}
            j = ET.Element("joint", spec)
            body.insert(index + k, j)
    return ET.tostring(root, encoding="unicode")


def _text(values) -> str:
    return " ".join(f"{float(x):.17g}" for x in values)


def _mujoco_deflection(text, subject, case, linear: bool):
    """The wheel centre's deflection in MuJoCo's static equilibrium (m): ``linear``, the
    first Newton step's from the design (the first-order KKT on MuJoCo's rows)."""
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "wheel_center")
    upright = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "upright")
    rack = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "rack_slide")]
    stiffness = np.zeros(m.nv)
    for j in range(m.njnt):
        stiffness[m.jnt_dofadr[j]] = m.jnt_stiffness[j]
    mujoco.mj_forward(m, d)
    wc0 = d.site_xpos[site].copy()
    # the contact patch as a material point of the upright: fixed in it at design
    statics = Statics(subject)
    subject.kin.update(subject.q_design)
    cp_world = subject.points["contact_patch_center"].position(subject.kin).copy()
    R0, x0 = d.xmat[upright].reshape(3, 3).copy(), d.xpos[upright].copy()
    cp_local = R0.T @ (cp_world - x0)
    del statics
    lam = None
    for _ in range(1 if linear else 40):
        mujoco.mj_forward(m, d)
        R, x = d.xmat[upright].reshape(3, 3), d.xpos[upright]
        cp = x + R @ cp_local
        f = np.zeros(m.nv)
        mujoco.mj_applyFT(m, d, case.contact_patch, case.moment, cp, upright, f)
        mujoco.mj_applyFT(m, d, case.wheel_center, np.zeros(3), d.site_xpos[site], upright, f)
        eq = d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        rows = d.efc_J.reshape(d.nefc, m.nv)[eq]
        c = d.efc_pos[: d.nefc][eq]
        hold = np.zeros((1, m.nv))
        hold[0, rack] = 1.0
        A = np.vstack([rows, hold])
        c = np.r_[
            c, d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "rack_slide")]]
        ]
        if lam is None:
            lam = np.zeros(len(c))
        residual = d.qfrc_spring + f - A.T @ lam
        M = np.block([[np.diag(stiffness), A.T], [A, np.zeros((len(c), len(c)))]])
        step = np.linalg.lstsq(M, np.r_[residual, -c], rcond=None)[0]
        if linear:  # the first-order deflection: the site's Jacobian times the step
            jacp = np.zeros((3, m.nv))
            mujoco.mj_jacSite(m, d, jacp, None, site)
            return jacp @ step[: m.nv]
        mujoco.mj_integratePos(m, d.qpos, step[: m.nv], 1.0)
        lam = lam + step[m.nv :]
        if np.abs(step[: m.nv]).max() < 1e-15:
            break
    mujoco.mj_forward(m, d)
    return d.site_xpos[site] - wc0


@pytest.mark.parametrize("size", [10.0, 200.0])
def test_kc_against_mujoco(tmp_path, size):
    subject = _corner(tmp_path)
    case = LoadCase("mixed", size * np.array([-0.6, -1.0, 0.3]), size * np.array([-0.2, 0, 0]),
                    size * np.array([0.0, 0.0, 0.05]))  # fmt: skip
    kc = KC(subject)
    W = Statics.loads_matrix(kc, [case])
    q0 = subject.q_design
    ours = kc.linear([q0], W)[0, 2:5, 0] * 1e-3  # m
    ours_nl = kc.nonlinear([q0], W)[0, 2:5, 0] * 1e-3
    text = _mjcf(subject)
    theirs_lin = _mujoco_deflection(text, subject, case, linear=True)
    theirs = _mujoco_deflection(text, subject, case, linear=False)
    assert np.linalg.norm(ours) > 1e-6 * size / 200  # a deflection to compare
    assert np.abs(theirs - ours_nl).max() < 1e-6  # 1e-3 mm
    # the first-order solves agree but for the MJCF text's last digits (its closures'
    # residual at design, ~1e-12 m)
    assert np.abs(theirs_lin - ours).max() < 1e-6 * np.abs(ours).max()
    print(
        f"F {size:g}: |MuJoCo − linear| {np.abs(theirs_lin - ours).max():.2e} m, "
        f"|MuJoCo − nonlinear| {np.abs(theirs - ours_nl).max():.2e} m, "
        f"deflection {np.abs(ours).max():.2e} m"
    )
