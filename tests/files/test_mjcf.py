"""MJCF (MuJoCo) files as mechanisms, checked against MuJoCo itself: the bodies' world poses
at the same joint values, and the mobility against the rank of MuJoCo's constraint Jacobian
(nv - rank efc_J) at qpos0, where MuJoCo's equalities hold."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import DATA, screwkin_cli
from screwkin.cli import main

mujoco = pytest.importorskip("mujoco")
FREE, BALL, SLIDE, HINGE = (int(t) for t in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL,
                                             mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE))

MJCF = DATA / "mjcf"
FILES = ["fourbar.xml", "slider_crank.xml", "delta_rss.xml", "tilted_defaults.xml", "real_file_sections.xml"]


def _mj(path):
    m = mujoco.MjModel.from_xml_path(str(path))
    return m, mujoco.MjData(m)


def _name(m, kind, i):
    return mujoco.mj_id2name(m, kind, i)


def screwkin_q(mech, m, qpos):
    """screwkin's coordinates for MuJoCo's qpos (hinge and slide: the value; ball: the
    quaternion, (w, x, y, z) -> (x, y, z, w); free: the pose relative to the body's own)."""
    q = np.zeros(mech.nq)
    for j in range(m.njnt):
        name, adr, t = _name(m, mujoco.mjtObj.mjOBJ_JOINT, j), m.jnt_qposadr[j], int(m.jnt_type[j])
        if name in {c.joint for c in mech.spec.couplings}:
            continue
        c = mech.coordinate(name)
        if t in (HINGE, SLIDE):
            q[c.idx_q] = qpos[adr]
        elif t == BALL:
            w, x, y, z = qpos[adr:adr + 4]
            q[c.idx_q:c.idx_q + 4] = (x, y, z, w)
        else:
            b = m.jnt_bodyid[j]
            X0 = pin.XYZQUATToSE3(np.r_[m.body_pos[b], m.body_quat[b][[1, 2, 3, 0]]])
            W = pin.XYZQUATToSE3(np.r_[qpos[adr:adr + 3], qpos[adr + 4:adr + 7], qpos[adr + 3]])
            q[c.idx_q:c.idx_q + 7] = pin.SE3ToXYZQUAT(X0.inverse() * W)
    return q


def random_qpos(m, rng):
    """qpos0 moved by random joint values (quaternions kept unit), couplings respected."""
    qpos = m.qpos0.copy()
    for j in range(m.njnt):
        adr, t = m.jnt_qposadr[j], int(m.jnt_type[j])
        if t in (HINGE, SLIDE):
            qpos[adr] += rng.uniform(-0.5, 0.5) * (1 if t == HINGE else 0.05)
        else:
            k = 3 if t == FREE else 0
            qpos[adr:adr + k] += rng.uniform(-0.05, 0.05, k)
            quat = qpos[adr + k:adr + k + 4] + rng.uniform(-0.3, 0.3, 4)
            qpos[adr + k:adr + k + 4] = quat / np.linalg.norm(quat)
    for e in range(m.neq):  # joint1 = a0 + a1 joint2
        if m.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT:
            a1, a2 = m.jnt_qposadr[m.eq_obj1id[e]], m.jnt_qposadr[m.eq_obj2id[e]]
            qpos[a1] = m.eq_data[e][0] + m.eq_data[e][1] * qpos[a2]
    return qpos


@pytest.mark.parametrize("name", FILES)
def test_body_poses_equal_mujocos(name):
    mech = screwkin.load(MJCF / name, warn=lambda w: None)
    m, d = _mj(MJCF / name)
    rng = np.random.default_rng(7)
    for k in range(4):
        qpos = m.qpos0.copy() if k == 0 else random_qpos(m, rng)
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        q = screwkin_q(mech, m, qpos)
        pin.framesForwardKinematics(mech.model, mech.data, q)
        for b in range(1, m.nbody):
            M = mech.data.oMf[mech.link_frame(_name(m, mujoco.mjtObj.mjOBJ_BODY, b))]
            np.testing.assert_allclose(M.translation, d.xpos[b], rtol=0, atol=1e-9)
            np.testing.assert_allclose(M.rotation, d.xmat[b].reshape(3, 3), rtol=0, atol=1e-9)


def mujoco_mobility(path):
    """nv - rank of MuJoCo's equality-constraint Jacobian at qpos0 (a joint equality included)."""
    m, d = _mj(path)
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv) if d.nefc else np.zeros((0, m.nv))
    return m.nv - np.linalg.matrix_rank(J, tol=1e-9), m.nv


@pytest.mark.parametrize("name, expected", [("fourbar.xml", 1), ("slider_crank.xml", 1), ("delta_rss.xml", 9),
                                            ("tilted_defaults.xml", 3), ("real_file_sections.xml", 4)])
def test_mobility_equals_mujocos_constraint_rank(name, expected):
    r = screwkin.load(MJCF / name, warn=lambda w: None).mobility()
    free, nv = mujoco_mobility(MJCF / name)
    assert r.mobility == free == expected
    # screwkin's coordinates are MuJoCo's velocities, less one per coupled joint
    assert r.coordinates == nv - len(r.topology.couplings)


def test_what_is_read():
    mech = screwkin.load(MJCF / "tilted_defaults.xml", warn=lambda w: None)
    assert mech.spec.format == "mjcf"
    assert [c.name for c in mech.spec.cut_joints] == ["pivot"] and mech.spec.cut_joints[0].frame2 == "world"
    assert [(c.joint, c.mimics, c.multiplier) for c in mech.spec.couplings] == [
        ("finger_b_slide", "finger_a_slide", -1.0)]
    assert (mech.actuated, mech.actuation_source) == (["crank_joint", "wrist", "finger_a_slide"], "mjcf actuator")
    i = mech.coordinate("wrist").idx_q  # range="-90 90" in degrees
    assert (mech.model.lowerPositionLimit[i], mech.model.upperPositionLimit[i]) == pytest.approx((-np.pi / 2,
                                                                                                  np.pi / 2))
    delta = screwkin.load(MJCF / "delta_rss.xml", warn=lambda w: None)
    assert {c.type for c in delta.spec.cut_joints} == {"spherical"}
    assert delta.model.joints[delta.coordinate("elbow0").joint_id].shortname() == "JointModelSpherical"


@pytest.mark.slow  # about 2.0 s on 2 shared cores: out of the fast subset
def test_cli_mobility_and_solve(capsys):
    assert main(["mobility", str(MJCF / "fourbar.xml"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mobility"] == 1
    assert main(["solve", str(MJCF / "slider_crank.xml"), "--set", "crank_joint=90deg", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    # crank 0.05 at 90 deg from (0.03, 0.04) turned: A = (-0.04, 0.03); rod 0.12649 (A to B at qpos0)
    A = np.array([-0.04, 0.03])
    rod = np.hypot(0.12, 0.04)
    x = A[0] + np.sqrt(rod**2 - A[1] ** 2)
    values = [s["joints"] for s in out["solutions"]]
    assert any(abs(v["guide"] - (x - 0.15)) < 1e-9 for v in values)


def test_what_is_not_read_is_said(capsys):
    assert main(["info", str(MJCF / "delta_rss.xml")]) == 0
    assert "have geoms but no <inertial>" not in capsys.readouterr().err  # each body with geoms has one
    assert main(["info", str(MJCF / "real_file_sections.xml")]) == 0
    err = capsys.readouterr().err
    assert "no <inertial>" not in err  # their mass is their capsules' (test_mass_from_geoms_as_mujoco)
    assert "joint 'bj' (ball) has a range: its cone of rotation is not read" in err


BAD = [
    ('<body name="a"><joint name="j" type="hinge"/><body name="b"><joint name="k"/></body></body>',
     '<equality><tendon tendon1="t"/></equality>', "<equality><tendon> is not supported"),
    ('<body name="a"><joint name="j"/></body>', '<equality><joint joint1="j" joint2="j2"/></equality>',
     "joint2 'j2' is not a joint of the file"),
    ('<body name="a"><joint name="j"/><body name="b"><joint name="k"/></body></body>',
     '<equality><joint joint1="k" joint2="j" polycoef="0 1 0.5 0 0"/></equality>', "is not linear"),
    ('<body name="a"><joint name="j"/></body>', '<equality><connect body1="a" body2="nobody" anchor="0 0 0"/>'
     '</equality>', "body2 'nobody' is not a body of the file"),
    ('<body name="a"><joint name="j"/><composite type="grid" count="2 2 1"/></body>', "",
     "has a <composite> element: not supported"),
    ('<body name="a"><joint name="j" type="hinge" limited="yes" range="0 1"/></body>', "",
     "limited='yes': MuJoCo's keywords are true, false and auto"),
    ('<body name="a"><joint name="j"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 3"/></body>', "",
     "break the triangle inequality A + B >= C"),
    ('<body name="a"><joint name="j"/><inertial pos="0 0 0" mass="1" fullinertia="1 1 1 2 0 0"/></body>', "",
     "an inertia tensor that is not positive"),
    ('<body name="a" quat="1 0 0 0" euler="0 0 1"><joint name="j"/></body>', "", "more than one orientation"),
    ('<body name="a"><joint name="j"/></body>', '<actuator><motor tendon="t"/></actuator>',
     "names tendon 't', which is not in the file"),
    ('<body name="a"><joint name="j"/></body>', '<include file="other.xml"/>', "<include file='other.xml'>: no such"),
    ('<body name="a"><joint name="j"/></body>', '<include file="../other.xml"/>', "is outside the folder of"),
    ('<body name="a"><joint name="j" class="nope"/></body>', "", "names default class 'nope', which is not defined"),
    ('<body name="a"><joint name="j"/></body>', '<equality><joint joint1="j"/></equality>',
     "has no joint2: locking a joint at a value is not supported"),
]


@pytest.mark.parametrize("body, extra, message", BAD)
def test_unsupported_elements_are_one_line_errors(tmp_path, capsys, body, extra, message):
    f = tmp_path / "bad.xml"
    f.write_text(f"<mujoco><worldbody>{body}</worldbody>{extra}</mujoco>")
    assert main(["mobility", str(f)]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and str(f) in err


INLINE = [  # (worldbody, equality): mobility checked against MuJoCo's nv - rank
    # a weld to the world (body2 omitted, relpose from qpos0) locks a hinged bar
    ('<body name="a" euler="10 20 30"><joint name="j" axis="0 1 1"/><inertial pos="0.1 0 0" mass="1" '
     'diaginertia="1 1 1"/></body>', '<weld body1="a" anchor="0.1 0 0"/>'),
    # a slider on a rail welded to a hinged arm through two joints in one body (joint pos off the origin)
    ('<body name="arm" pos="0 0 0.1"><joint name="h1" pos="0.02 0 0" axis="0 0 1"/><joint name="h2" '
     'pos="0 0.03 0" axis="1 0 0"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>'
     '<body name="rail" pos="0.1 0 0.1"><joint name="s" type="slide" axis="1 0 0"/><inertial pos="0 0 0" '
     'mass="1" diaginertia="1 1 1"/></body>', '<connect body1="arm" body2="rail" anchor="0.1 0 0"/>'),
]


@pytest.mark.parametrize("bodies, equality", INLINE)
def test_inline_models_against_mujoco(tmp_path, bodies, equality):
    f = tmp_path / "m.xml"
    f.write_text(f"<mujoco><worldbody>{bodies}</worldbody><equality>{equality}</equality></mujoco>")
    free, _ = mujoco_mobility(f)
    mech = screwkin.load(f, warn=lambda w: None)
    assert mech.mobility().mobility == free
    m, d = _mj(f)
    rng = np.random.default_rng(3)
    for _ in range(3):
        qpos = random_qpos(m, rng)
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        pin.framesForwardKinematics(mech.model, mech.data, screwkin_q(mech, m, qpos))
        for b in range(1, m.nbody):
            M = mech.data.oMf[mech.link_frame(_name(m, mujoco.mjtObj.mjOBJ_BODY, b))]
            np.testing.assert_allclose(M.translation, d.xpos[b], rtol=0, atol=1e-9)


def test_sizes_are_bounded(tmp_path, capsys):
    from screwkin.files.description import LIMITS
    f = tmp_path / "many.xml"
    bodies = "".join(f'<body name="b{k}"><joint name="j{k}"/></body>' for k in range(LIMITS.links + 1))
    f.write_text(f"<mujoco><worldbody>{bodies}</worldbody></mujoco>")
    assert main(["info", str(f)]) == 1
    assert f"screwkin reads at most {LIMITS.links}" in capsys.readouterr().err


@pytest.mark.parametrize("compiler", ['<compiler eulerseq="zXy"/>', '<compiler eulerseq="XYZ" angle="radian"/>'])
def test_euler_sequences_as_mujoco(tmp_path, compiler):
    f = tmp_path / "e.xml"
    f.write_text(f'<mujoco>{compiler}<worldbody><body name="a" pos="0.1 0.2 0.3" euler="0.3 -0.7 1.1">'
                 '<joint name="j" axis="0 1 0"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
                 '<body name="b" pos="0.1 0 0" euler="1 2 3" xyaxes="1 1 0 0 1 1">'
                 '</body></body></worldbody></mujoco>')
    assert main(["info", str(f)]) == 1  # two orientations on b
    f.write_text(f.read_text().replace(' xyaxes="1 1 0 0 1 1"', ""))
    mech = screwkin.load(f, warn=lambda w: None)
    m, d = _mj(f)
    mujoco.mj_kinematics(m, d)
    pin.framesForwardKinematics(mech.model, mech.data, mech.neutral())
    for name in ("a", "b"):
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
        np.testing.assert_allclose(mech.data.oMf[mech.link_frame(name)].rotation, d.xmat[b].reshape(3, 3), atol=1e-12)


def test_weld_relpose_is_read_as_mujocos_engine_reads_it(tmp_path):
    """A weld with both an anchor and a relpose: MuJoCo's engine holds body1's point relpose[:3] on
    body2's anchor (engine_core_constraint.c), not body2's origin.  Here relpose is written where the
    bodies are drawn: b at (0.3, 0.1) turned 90 deg about z, anchor (0.2, 0.05) on b is at
    (0.3, 0.1) + (-0.05, 0.2) = (0.25, 0.3) in a; quaternion (cos 45, 0, 0, sin 45).  MuJoCo's residual
    at qpos0 is zero, and so is screwkin's closure residual at the configuration the file draws."""
    f = tmp_path / "weld.xml"
    h = "0.7071067811865476"
    f.write_text('<mujoco><worldbody><body name="a"><joint name="ja" axis="0 0 1"/><inertial pos="0.1 0 0" '
                 'mass="1" diaginertia="1 1 1"/></body><body name="b" pos="0.3 0.1 0" euler="0 0 90"><joint '
                 'name="jb" axis="0 0 1"/><inertial pos="0.1 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody>'
                 f'<equality><weld body1="a" body2="b" anchor="0.2 0.05 0" relpose="0.25 0.3 0 {h} 0 0 {h}"/>'
                 '</equality></mujoco>')
    m, d = _mj(f)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.efc_pos[:d.ne], 0, rtol=0, atol=1e-12)
    mech = screwkin.load(f, warn=lambda w: None)
    np.testing.assert_allclose(mech.closure.residual(mech.neutral()), 0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("second, words", [
    ('joint1="j2" joint2="j1" polycoef="0 0.5 0 0 0"', "go round in a circle"),
    ('joint1="j1" joint2="j2" polycoef="0 3 0 0 0"', "is coupled by two <equality><joint> elements"),
])
def test_equality_joint_cycles_and_doubles_are_refused(tmp_path, second, words):
    """Two <equality><joint> that go round (j1 = 2 j2, j2 = 0.5 j1) were resolved into j1 mimicking
    j1 and Pinocchio's own error; one joint coupled twice kept the last silently.  Both are a one-line
    error naming the joint, exit 1."""
    path = tmp_path / "cycle.xml"
    path.write_text('<mujoco><worldbody><body><joint name="j1" type="hinge"/><geom size=".1" mass="1"/><body>'
                    '<joint name="j2" type="hinge"/><geom size=".1" mass="1"/></body></body></worldbody><equality>'
                    f'<joint joint1="j1" joint2="j2" polycoef="0 2 0 0 0"/><joint {second}/></equality></mujoco>')
    done = screwkin_cli("mobility", str(path))
    assert done.returncode == 1 and words in done.stderr and "'j1'" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
