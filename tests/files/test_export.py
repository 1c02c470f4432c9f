"""screwkin export --mjcf / --urdf: round trips of robots/ mechanisms, read back by screwkin and
by MuJoCo: the same mobility (MuJoCo's nv - rank of its constraint Jacobian), the same link
poses for the same inputs, and MuJoCo's equalities satisfied there."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS, ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main

mujoco = pytest.importorskip("mujoco")

CASES = [  # file, inputs for the round trip, --set for the written configuration
    ("fourbar_crank_rocker.urdf", {"crank_joint": 1.1}, "crank_joint=30deg"),
    ("slider_crank_offset.urdf", {"crank_joint": 2.0}, "crank_joint=40deg"),
    ("delta_parallelogram.urdf", {"arm1": 0.2, "arm2": -0.1, "arm3": 0.15}, None),
]


def _export(tmp_path, name, setting, capsys):
    out_x, out_u = tmp_path / "out.xml", tmp_path / "out.urdf"
    argv = ["export", str(ROBOTS / name), "--mjcf", str(out_x), "--urdf", str(out_u), "--json"]
    assert main(argv + (["--set", setting] if setting else [])) == 0
    report = json.loads(capsys.readouterr().out)
    return out_x, out_u, report["configuration"], report["compounds"]


def _in_export(original, back, q, written_at, compounds):
    """The original's configuration q in the coordinates of its MJCF export: a hinge or slide minus its
    written value; a ball (a compound spherical joint) the quaternion R(a1, d1) R(a2, d2) R(a3, d3) of
    its members' turns d from their written values, about their axes in the ball's body."""
    qb = pin.neutral(back.model)
    balls = {c["joint"]: c for c in compounds if c["type"] == "spherical"}
    for c in back.coordinates:
        if c.joint in balls:
            b = balls[c.joint]
            R = np.eye(3)
            for member, axis, value in zip(b["members"], b["axes"], b["values"]):
                R = R @ pin.exp3(np.asarray(axis) * (q[original.coordinate(member).idx_q] - value))
            qb[c.idx_q:c.idx_q + 4] = pin.Quaternion(R).coeffs()  # (x, y, z, w)
        else:
            qb[c.idx_q] = q[original.coordinate(c.joint).idx_q] - written_at[c.joint]
    return qb


def _poses(mech, q, links):
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return {lk: data.oMf[mech.link_frame(lk)].homogeneous.copy() for lk in links}


def _solutions(mech, values):
    return [s.q for s in PositionSolver(mech, list(values)).solve(values).solutions]


@pytest.mark.parametrize("name, inputs, setting", CASES)
def test_round_trip(tmp_path, capsys, name, inputs, setting):
    original = screwkin.load(ROBOTS / name, warn=lambda w: None)
    out_x, out_u, written_at, compounds = _export(tmp_path, name, setting, capsys)
    dummies = set(original.topology().dummy_links)  # inside compound joints: the MJCF leaves them out
    links = [lk for lk in original.spec.links if lk not in dummies]
    shifted = {k: v - written_at[k] for k, v in inputs.items()}  # the written file's zero is written_at
    modes = _solutions(original, inputs)
    expected = [_poses(original, q, links) for q in modes]
    M = original.mobility().mobility
    for path in (out_x, out_u):
        back = screwkin.load(path, warn=lambda w: None)
        assert back.mobility().mobility == M
        if path == out_x and compounds:  # ball joints (other coordinates): each mode of the original, in the
            for q, e in zip(modes, expected):  # export's coordinates, closes its loops and places every link alike
                qb = _in_export(original, back, q, written_at, compounds)
                assert np.abs(back.closure.residual(qb)).max() < 1e-9  # the solver's closure tolerance
                g = _poses(back, qb, links)
                assert max(np.abs(e[lk] - g[lk]).max() for lk in links) < 1e-12  # the same forward kinematics
            continue
        got = [_poses(back, q, links) for q in _solutions(back, shifted)]
        assert len(got) == len(expected) >= 1
        for e in expected:  # every assembly mode of the original is one of the file read back
            err = min(max(np.abs(e[lk] - g[lk]).max() for lk in links) for g in got)
            assert err < 1e-8
    # MuJoCo: the same mobility, the file's qpos0 the written configuration, and at the read-back
    # solutions the equalities hold (MuJoCo's constraint residual) and the bodies are where screwkin puts them
    m = mujoco.MjModel.from_xml_path(str(out_x))
    d = mujoco.MjData(m)
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)
    assert m.nv - np.linalg.matrix_rank(J, tol=1e-9) == M
    # inertias (Pinocchio's, of each moving joint's body, in its child link's frame) and actuators
    for j in original.spec.joints:
        if j.type == "fixed" or not original.model.existJointName(j.name):
            continue
        inertia = original.model.inertias[original.model.getJointId(j.name)]
        if inertia.mass == 0:
            continue
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, j.child)
        assert m.body_mass[b] == pytest.approx(inertia.mass, rel=1e-12)
        np.testing.assert_allclose(m.body_ipos[b], inertia.lever, atol=1e-12)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, m.body_iquat[b])
        R = R.reshape(3, 3)
        np.testing.assert_allclose(R @ np.diag(m.body_inertia[b]) @ R.T, inertia.inertia, atol=1e-12)
    driven = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, m.actuator_trnid[a][0]) for a in range(m.nu)]
    assert driven == list(original.actuated)
    back = screwkin.load(out_x, warn=lambda w: None)
    solutions = _solutions(back, shifted)
    assert solutions and d.ne >= 3
    for q in solutions:
        for j in range(m.njnt):
            c = back.coordinate(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j))
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:  # Pinocchio's (x, y, z, w), MuJoCo's (w, x, y, z)
                x, y, z, w = q[c.idx_q:c.idx_q + 4]
                d.qpos[m.jnt_qposadr[j]:m.jnt_qposadr[j] + 4] = (w, x, y, z)
            else:
                d.qpos[m.jnt_qposadr[j]] = q[c.idx_q]
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(d.efc_pos[:d.ne], 0, atol=1e-9)
        for lk in links:
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, lk)
            pose = _poses(back, q, [lk])[lk]
            np.testing.assert_allclose(d.xpos[b], pose[:3, 3], atol=1e-9)


def test_the_loops_are_closed_in_the_mjcf_file(tmp_path, capsys):
    """MuJoCo takes a connect's point on body2 from qpos0: it must be the cut joint's F2."""
    out_x, _, _, _ = _export(tmp_path, "slider_crank_offset.urdf", "crank_joint=40deg", capsys)
    m = mujoco.MjModel.from_xml_path(str(out_x))
    cut = screwkin.load(ROBOTS / "slider_crank_offset.urdf").spec.cut_joints[0]
    e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, cut.name)
    assert mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, m.eq_obj2id[e]) == cut.frame2
    np.testing.assert_allclose(m.eq_data[e][3:6], cut.xyz2, atol=1e-12)


def test_prismatic_cut_and_mjcf_source(tmp_path, capsys):
    """A prismatic loop joint becomes a body with a slide welded to link2; an MJCF file with a
    ball joint and a weld exports and reads back with the same mobility."""
    urdf = (ROBOTS / "slider_crank_offset.urdf").read_text()
    assert "rod_slider" in urdf
    src = tmp_path / "guide.urdf"
    src.write_text(urdf.replace('<loop_joint name="rod_slider" type="revolute">',
                                '<loop_joint name="rod_slider" type="cylindrical">'))
    out = tmp_path / "g.xml"
    assert main(["export", str(src), "--mjcf", str(out)]) == 0
    assert "rod_slider~F1" in capsys.readouterr().out
    assert screwkin.load(out, warn=lambda w: None).mobility().mobility == screwkin.load(src).mobility().mobility
    data = ROBOTS.parent / "tests" / "data" / "mjcf"
    for name in ("delta_rss.xml", "slider_crank.xml"):
        assert main(["export", str(data / name), "--mjcf", str(out)]) == 0
        m = mujoco.MjModel.from_xml_path(str(out))
        d = mujoco.MjData(m)
        mujoco.mj_forward(m, d)
        M = screwkin.load(data / name, warn=lambda w: None).mobility().mobility
        assert screwkin.load(out, warn=lambda w: None).mobility().mobility == M
        assert m.nv - np.linalg.matrix_rank(d.efc_J.reshape(d.nefc, m.nv), tol=1e-9) == M


def test_what_cannot_be_written(tmp_path, capsys):
    assert main(["export", str(ROBOTS / "friction_wheels.urdf"), "--mjcf", str(tmp_path / "x.xml")]) == 1
    assert "rolling pair: MJCF cannot express it" in capsys.readouterr().err
    data = ROBOTS.parent / "tests" / "data" / "mjcf" / "delta_rss.xml"
    assert main(["export", str(data), "--urdf", str(tmp_path / "x.urdf")]) == 1
    assert "ball joint: URDF has none" in capsys.readouterr().err
    assert main(["export", str(ROBOTS / "fourbar_crank_rocker.urdf")]) == 2
    assert "export needs --mjcf" in capsys.readouterr().err
    planar = tmp_path / "planar.urdf"
    planar.write_text('<robot name="p"><link name="g"/><link name="b"/><joint name="pj" type="planar">'
                      '<parent link="g"/><child link="b"/><axis xyz="0 0 1"/></joint></robot>')
    assert main(["export", str(planar), "--mjcf", str(tmp_path / "p.xml")]) == 1
    assert "joint 'pj' is a planar tree joint" in capsys.readouterr().err


@pytest.mark.parametrize("path", [ROBOTS / "tsai_3upu.urdf",  # universal cut joints: bodies with two hinges
                                  ROBOTS.parent / "tests" / "data" / "student" / "rrpr.urdf",  # prismatic cut
                                  ROBOTS / "gripper_arm_mimic.urdf",  # <mimic>: <equality><joint>
                                  ROBOTS / "gough_stewart_6ups.urdf",
                                  # Extended-URDF sidecars: 6d and 3d closures between frames, empty limits
                                  CORPUS / "robot_delta" / "robot.urdf", CORPUS / "cassie_like" / "robot.urdf"])
def test_mobility_survives_export(tmp_path, path):
    out_x, out_u = tmp_path / "o.xml", tmp_path / "o.urdf"
    assert main(["export", str(path), "--mjcf", str(out_x), "--urdf", str(out_u), "--json"]) == 0
    original = screwkin.load(path, warn=lambda w: None)
    M = original.mobility().mobility
    for out in (out_x, out_u):
        back = screwkin.load(out, warn=lambda w: None)
        assert back.mobility().mobility == M
        assert [(c.joint, c.mimics, c.multiplier) for c in back.spec.couplings] == [
            (c.joint, c.mimics, c.multiplier) for c in original.spec.couplings]
    m = mujoco.MjModel.from_xml_path(str(out_x))
    d = mujoco.MjData(m)
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    mujoco.mj_forward(m, d)
    assert m.nv - np.linalg.matrix_rank(d.efc_J.reshape(d.nefc, m.nv), tol=1e-9) == M
    # the loops are closed in the file as MuJoCo's engine reads it (a weld's relpose: the anchor's place)
    np.testing.assert_allclose(d.efc_pos[:d.ne], 0, rtol=0, atol=1e-12)
