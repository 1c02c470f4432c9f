"""Exports a simulator can run (issue 34, second part): the joints' own dynamics (armature, damping,
friction loss) kept from MJCF and URDF and written back, transmissions with reductions, ball and
universal joints in the tree, the minimal equality rows and the redundant ones named -- checked
against MuJoCo (its own readers, its constraint rows, its simulation), hand formulas and urdfdom's
check_urdf."""


import numpy as np
import pytest

import screwkin
from conftest import DATA, check_urdf
from test_published import simulate  # 1 s of mj_step with 0.05 N m on the motors: MuJoCo's warnings
from screwkin.analysis.forces.dynamics import dynamics
from screwkin.analysis.forces.statics import statics
from screwkin.cli import main

mujoco = pytest.importorskip("mujoco")
MJCF = DATA / "mjcf"
FINGER = MJCF / "finger_armature.xml"
DYNAMICS = ("armature", "damping", "frictionloss")


def _dof(m, name, what):
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
    return float(getattr(m, "dof_" + what)[m.jnt_dofadr[j]])


def same_bodies(original, q, m, d):
    """Every MuJoCo body of (m, d) where the original's Pinocchio forward kinematics at q puts its link."""
    import pinocchio as pin
    data = original.model.createData()
    pin.framesForwardKinematics(original.model, data, q)
    for b in range(1, m.nbody):
        M = data.oMf[original.link_frame(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b))]
        np.testing.assert_allclose(M.translation, d.xpos[b], rtol=0, atol=1e-12)
        np.testing.assert_allclose(M.rotation, d.xmat[b].reshape(3, 3), rtol=0, atol=1e-12)


# ------------------------------------------------------------------ armature, damping, friction loss
def test_joint_dynamics_are_read_as_mujoco_reads_them():
    """Each joint's armature, damping and frictionloss (from a default class, one overridden per joint)
    are MuJoCo's own dof_armature, dof_damping, dof_frictionloss of the file."""
    mech = screwkin.load(FINGER, warn=lambda w: None)
    m = mujoco.MjModel.from_xml_path(str(FINGER))
    joints = {j.name: j for j in mech.spec.joints}
    for name in ("base", "mid", "tip"):
        for what in DYNAMICS:
            assert getattr(joints[name], what) == _dof(m, name, what)
    assert (joints["mid"].damping, joints["tip"].armature) == (0.002, 0.005)
    res = dynamics(mech, "base", 1.0, 0.0, 0.5, 3, inputs=["base", "mid", "tip"], fixed={"mid": 0.0, "tip": 0.0})
    assert any("friction loss the file gives 3 joints" in n and "are in these efforts" in n for n in res.notes)
    # base turns at 1 rad/s, constant, no gravity, mid and tip held: only its dry friction (0.01 N m) remains
    np.testing.assert_allclose(res.efforts["base"], 0.01, rtol=0, atol=1e-12)
    assert any("where 'mid', 'tip' stand still the dry friction lies anywhere in +-frictionloss" in n
               for n in res.notes)


def test_a_closed_loops_joint_dynamics_are_their_virtual_work():
    """The MJCF four-bar with MuJoCo's joint dynamics on every hinge (armature 0.01 / 0.004 / 0.006 kg m^2,
    damping 0.002 / 0.003 / 0.001 N m s, frictionloss 0.005 / 0.002 / 0.004 N m), driven at 5 rad/s over a
    turn.  By virtual work the crank's effort grows by sum_i Q_i dq_i/dtheta, Q_i = armature_i qdd_i +
    damping_i qd_i + frictionloss_i sign(qd_i) the force on joint i, with qd_i = omega dq_i/dtheta and
    qdd_i = omega^2 d2q_i/dtheta2 -- the velocity ratios here by central finite differences of the
    joint angles along the motion (the sweep's positions only, not its rates)."""
    text = (MJCF / "fourbar.xml").read_text()
    given = {"crank_joint": (0.01, 0.002, 0.005), "coupler_joint": (0.004, 0.003, 0.002),
             "rocker_pin": (0.006, 0.001, 0.004)}
    for name, (arm, damp, fl) in given.items():
        text = text.replace(f'<joint name="{name}" ', f'<joint name="{name}" armature="{arm}" damping="{damp}" '
                                                      f'frictionloss="{fl}" ')
    import tempfile
    from pathlib import Path
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fourbar_dynamics.xml"
        path.write_text(text)
        with_dyn = screwkin.load(path)
    plain = screwkin.load(MJCF / "fourbar.xml")
    assert [getattr(j, "armature") for j in with_dyn.spec.joints if j.name in given] == [0.01, 0.004, 0.006]
    omega, n = 5.0, 720
    run = lambda mech: dynamics(mech, "crank_joint", omega, 0.0, 2 * np.pi, n)  # noqa: E731
    r1, r0 = run(with_dyn), run(plain)
    assert any("are in these efforts" in note for note in r1.notes)
    h = 2 * np.pi / n
    angles = np.unwrap(np.array([[with_dyn.joint_values(q)[j] for j in given] for q in r1.q]), axis=0)
    d1 = (angles[2:] - angles[:-2]) / (2 * h)
    d2 = (angles[2:] - 2 * angles[1:-1] + angles[:-2]) / h**2
    arm, damp, fl = (np.array([v[k] for v in given.values()]) for k in range(3))
    Q = arm * omega**2 * d2 + damp * omega * d1 + fl * np.sign(d1)
    extra = (Q * d1).sum(axis=1)
    moving = np.all(np.abs(d1) > 1e-2, axis=1)  # a step where a joint turns back: its dry friction is open
    assert moving.sum() > 0.9 * len(moving)
    got = (r1.efforts["crank_joint"] - r0.efforts["crank_joint"])[1:-1]
    # the second differences carry h^2 truncation and the positions' closure round-off over h^2: 4.3e-5 N m
    # here at most (1.7e-4 at 360 steps; finer grids get worse); the damping and friction terms are 1e-2
    np.testing.assert_allclose(got[moving], extra[moving], rtol=0, atol=1e-4)
    assert np.ptp(extra) > 0.05  # the armature's share is not negligible: the check has teeth
    assert np.abs((fl * np.abs(d1)).sum(axis=1)).min() > 1e-3  # nor is the friction's


def test_export_keeps_the_armature_and_simulates(tmp_path, capsys):
    """The finger's links weigh grams with inertias of 1e-9 kg m^2: without its joints' armature MuJoCo
    is unstable within 0.03 s under 0.05 N m (the published Allegro and OP3 exports failed so); the
    export keeps armature, damping and friction loss (MuJoCo's dof_* of the export equal the
    original's) and runs 1 s without a warning.  The URDF export writes damping and friction as
    <dynamics> (MuJoCo's own URDF reader finds them there), passes check_urdf, and says that the
    armature has no URDF form."""
    m = mujoco.MjModel.from_xml_path(str(FINGER))
    d = mujoco.MjData(m)
    m.dof_armature[:] = 0  # the instability the test model reproduces
    d.ctrl[:] = 0.05
    for _ in range(50):
        mujoco.mj_step(m, d)
    assert d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0
    out_x, out_u = tmp_path / "f.xml", tmp_path / "f.urdf"
    assert main(["export", str(FINGER), "--mjcf", str(out_x), "--urdf", str(out_u)]) == 0
    assert "armature of 3 joints ('base', 'mid', 'tip') has no URDF form" in capsys.readouterr().out
    assert simulate(out_x) == []
    original = mujoco.MjModel.from_xml_path(str(FINGER))
    written = mujoco.MjModel.from_xml_path(str(out_x))
    from_urdf = mujoco.MjModel.from_xml_path(str(out_u))
    for name in ("base", "mid", "tip"):
        for what in DYNAMICS:
            assert _dof(written, name, what) == _dof(original, name, what)
        for what in ("damping", "frictionloss"):
            assert _dof(from_urdf, name, what) == _dof(original, name, what)
    check_urdf(out_u)
    back = {j.name: j for j in screwkin.load(out_u, warn=lambda w: None).spec.joints}
    assert (back["mid"].damping, back["mid"].frictionloss, back["mid"].armature) == (0.002, 0.01, 0.0)


def test_urdf_dynamics_are_read_and_exported(tmp_path, capsys):
    """URDF <dynamics damping friction>: the MJCF export's dof_damping and dof_frictionloss are those
    MuJoCo's own URDF reader gives the source file."""
    link = ('<link name="{n}"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="1e-3" iyy="1e-2" '
            'izz="1e-2" ixy="0" ixz="0" iyz="0"/></inertial></link>')
    src = tmp_path / "arm.urdf"
    src.write_text('<robot name="arm">' + "".join(link.format(n=n) for n in ("base", "upper", "fore")) +
                   '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>'
                   '<limit lower="-2" upper="2" effort="10" velocity="1"/><dynamics damping="0.7" friction="0.2"/></joint>'
                   '<joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/><origin xyz="0.2 0 0"/>'
                   '<axis xyz="0 0 1"/><dynamics damping="0.4"/></joint></robot>')
    out = tmp_path / "arm.xml"
    assert main(["export", str(src), "--mjcf", str(out)]) == 0
    capsys.readouterr()
    theirs, ours = mujoco.MjModel.from_xml_path(str(src)), mujoco.MjModel.from_xml_path(str(out))
    for name in ("shoulder", "elbow"):
        for what in ("damping", "frictionloss"):
            assert _dof(ours, name, what) == _dof(theirs, name, what)
    assert (_dof(ours, "shoulder", "damping"), _dof(ours, "shoulder", "frictionloss")) == (0.7, 0.2)


# ------------------------------------------------------------------ transmissions with reductions
ARM_LINK = ('<link name="{n}"><inertial><origin xyz="{c} 0 0"/><mass value="{m}"/><inertia ixx="1e-3" iyy="1e-2" '
            'izz="1e-2" ixy="0" ixz="0" iyz="0"/></inertial></link>')


def geared_arm(tmp_path, shoulder="<actuator name=\"shoulder_motor\"><mechanicalReduction>50</mechanicalReduction>"
               "</actuator>", extra=""):
    """A two-link arm in the vertical xz plane (joints about y), drawn horizontal: upper link 0.3 m, 2 kg
    at 0.15 m; forearm 1 kg at 0.1 m past the elbow.  The shoulder's transmission (ROS 1 form, its
    reduction under <actuator>) and the elbow's (the older PR2 form: type as an attribute, the
    reduction directly under <transmission>, -20: the motor turns the other way)."""
    f = tmp_path / "geared.urdf"
    f.write_text(
        '<robot name="geared">' + ARM_LINK.format(n="base", c=0, m=1) + ARM_LINK.format(n="upper", c=0.15, m=2)
        + ARM_LINK.format(n="fore", c=0.1, m=1)
        + '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>'
          '<limit lower="-3" upper="3" effort="10" velocity="1"/></joint>'
          '<joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.3 0 0"/>'
          '<axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>'
          '<transmission name="t_shoulder"><type>transmission_interface/SimpleTransmission</type><joint name="shoulder">'
          f'<hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>{shoulder}</transmission>'
          '<transmission name="t_elbow" type="pr2_mechanism_model/SimpleTransmission"><actuator name="elbow_motor"/>'
          f'<joint name="elbow"/><mechanicalReduction>-20</mechanicalReduction></transmission>{extra}</robot>')
    return f


def test_reductions_give_the_actuator_efforts(tmp_path, capsys):
    """Holding the arm horizontal against gravity g = 9.81 m/s^2 (joints about +y: a point at +x drops
    as the joint turns positive, V = -m g x sin q), the joints need dV/dq:
    shoulder -g (2 * 0.15 + 1 * (0.3 + 0.1)) = -6.867 N m, elbow -g * 1 * 0.1 = -0.981 N m; through the
    reductions (ROS SimpleTransmission: actuator effort = joint effort / n) the motors give
    -6.867 / 50 = -0.13734 N m and -0.981 / -20 = 0.04905 N m.  MuJoCo, on the export: the motors carry
    gear 50 and -20, and with those controls its actuator_force is them and the arm stays put (qacc 0)."""
    g = 9.81
    path = geared_arm(tmp_path)
    mech = screwkin.load(path)
    assert {t.actuator: (t.joint, t.gear) for t in mech.transmissions()} == {
        "shoulder_motor": ("shoulder", 50.0), "elbow_motor": ("elbow", -20.0)}
    r = statics(mech, mech.neutral(), gravity=True)
    assert r.efforts["shoulder"] == pytest.approx(-g * 0.7, abs=1e-12)
    assert r.efforts["elbow"] == pytest.approx(-g * 0.1, abs=1e-12)
    assert r.actuator_efforts == pytest.approx({"shoulder_motor": -g * 0.7 / 50, "elbow_motor": g * 0.1 / 20}, abs=1e-12)
    assert main(["statics", str(path), "--gravity"]) == 0
    assert "(joint of actuator 'shoulder_motor', mechanicalReduction 50)" in capsys.readouterr().out
    out_x, out_u = tmp_path / "geared.xml", tmp_path / "geared_back.urdf"
    assert main(["export", str(path), "--mjcf", str(out_x), "--urdf", str(out_u)]) == 0
    capsys.readouterr()
    m = mujoco.MjModel.from_xml_path(str(out_x))
    d = mujoco.MjData(m)
    ctrl = {"shoulder": r.actuator_efforts["shoulder_motor"], "elbow": r.actuator_efforts["elbow_motor"]}
    for a in range(m.nu):
        joint = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, m.actuator_trnid[a][0])
        assert m.actuator_gear[a][0] == {"shoulder": 50.0, "elbow": -20.0}[joint]
        d.ctrl[a] = ctrl[joint]
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.actuator_force, d.ctrl, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d.qacc, 0, rtol=0, atol=1e-9)
    check_urdf(out_u)
    back = screwkin.load(out_u)
    assert {t.joint: t.gear for t in back.transmissions()} == {"shoulder": 50.0, "elbow": -20.0}


def _inverse_at(mech, res, k, m, d, joints):
    """MuJoCo's inverse dynamics (mj_inverse on m, d) at step k of the dynamics result ``res``: the named
    one-coordinate joints at screwkin's q, rates and accelerations there."""
    for name in joints:
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        c = mech.coordinate(name)
        d.qpos[m.jnt_qposadr[j]] = res.q[k][c.idx_q]
        d.qvel[m.jnt_dofadr[j]] = res.rates[k][c.idx_v]
        d.qacc[m.jnt_dofadr[j]] = res.accelerations[k][c.idx_v]
    mujoco.mj_inverse(m, d)


def test_reductions_in_dynamics_against_mujoco_inverse_dynamics(tmp_path, capsys):
    """dynamics of the geared arm: at every step each motor's effort is MuJoCo's inverse dynamics on the
    export (qfrc_inverse at the joint, for screwkin's q, rates and accelerations) / the motor's gear."""
    path = geared_arm(tmp_path)
    mech = screwkin.load(path)
    res = dynamics(mech, "shoulder", 2.0, -0.6, 0.6, 5, inputs=["shoulder", "elbow"], fixed={"elbow": 0.4},
                   gravity=(0, 0, -9.81))
    out = tmp_path / "geared.xml"
    assert main(["export", str(path), "--mjcf", str(out)]) == 0
    capsys.readouterr()
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    for k in range(len(res.values)):
        _inverse_at(mech, res, k, m, d, ("shoulder", "elbow"))
        for a in range(m.nu):
            j = m.actuator_trnid[a][0]
            actuator = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) + "_motor"
            assert res.actuator_efforts[actuator][k] == pytest.approx(
                d.qfrc_inverse[m.jnt_dofadr[j]] / m.actuator_gear[a][0], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("old, new, warning", [
    ("<mechanicalReduction>50<", "<mechanicalReduction>0<", "has a reduction of 0 (it would exert nothing): not read"),
    ("<mechanicalReduction>50<", "<mechanicalReduction>x<", "is not 1 number"),
    ("SimpleTransmission</type><joint name=\"shoulder\"", "DifferentialTransmission</type><joint name=\"shoulder\"",
     "the reductions of 1 transmission of other types than SimpleTransmission (DifferentialTransmission: 't_shoulder') are not read"),
    ("<hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>",
     "<offset>0.1</offset></joint>", "the joint <offset> is not read"),
])
def test_reductions_that_cannot_be_used_are_said(tmp_path, old, new, warning):
    """A reduction of 0 or not a number, a reduction of another transmission type: a warning, the
    joint driven one to one; a joint offset (the actuator's position only): a warning."""
    path = geared_arm(tmp_path)
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    seen = []
    mech = screwkin.load(path, warn=seen.append)
    gears = {"elbow": -20.0} if "offset" not in new else {"shoulder": 50.0, "elbow": -20.0}
    assert {t.joint: t.gear for t in mech.transmissions()} == gears
    assert mech.actuated == ["shoulder", "elbow"]
    assert any(warning in w for w in seen), seen


# ------------------------------------------------------------------ ball and universal joints in the tree
def drift(path, seconds=1.0, effort=0.05):
    """The largest |efc_pos| of MuJoCo's equality rows over ``seconds`` of mj_step with ``effort`` on
    every motor, gravity on: of the point rows [m] and of the weld's rotation rows (2 x the quaternion's
    vector part: the angle [rad])."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    d.ctrl[:] = effort
    point = angle = 0.0
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
        start = {}
        for r, e in enumerate(d.efc_id[:d.ne]):
            k = r - start.setdefault(e, r)
            if int(m.eq_type[e]) == int(mujoco.mjtEq.mjEQ_WELD) and k >= 3:
                angle = max(angle, 2 * abs(d.efc_pos[r]))
            else:
                point = max(point, abs(d.efc_pos[r]))
    return point, angle


def _export_mjcf(tmp_path, capsys, path, name="out.xml"):
    out = tmp_path / name
    assert main(["export", str(path), "--mjcf", str(out), "--json"]) == 0
    import json
    return out, json.loads(capsys.readouterr().out)


def test_spherical_and_universal_compounds_are_ball_and_hinge_pairs(tmp_path, capsys):
    """The Delta's seven spherical joints of the tree (three revolutes through two massless links each)
    are seven MuJoCo ball joints, its 14 massless links gone (25 bodies -> 11); the Stewart platform's
    six universal joints are two hinges in one body each (its 6 massless crosses gone) and its tree
    spherical joint a ball.  Every export holds its loops at qpos0 and simulates 1 s without a warning;
    its constraint drift (|efc_pos| of the equality rows, 1 s, 0.05 N m on the motors, gravity on), measured
    before (hinge triples and crosses through default solids) and after: Delta 5.0e-3 -> 2.6e-3 m,
    Stewart 3.9e-3 -> 3.1e-3 m (tsai_3upu 0.15 m, 1.7 rad -> 3.2e-3 m, 0.22 rad, most of it the weld fix)."""
    delta, report = _export_mjcf(tmp_path, capsys, DATA.parent.parent / "robots" / "delta_parallelogram.urdf")
    m = mujoco.MjModel.from_xml_path(str(delta))
    balls = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)
             if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL]
    assert sorted(balls) == sorted(c["joint"] for c in report["compounds"]) and len(balls) == 7
    assert "rod1a_top[S]" in balls and m.nbody - 1 == 11 and m.nv == 24
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "rod1a_top_d1") == -1
    assert simulate(delta) == []
    assert drift(delta)[0] < 3e-3
    stewart, report = _export_mjcf(tmp_path, capsys, DATA.parent.parent / "robots" / "gough_stewart_6ups.urdf", "s.xml")
    m = mujoco.MjModel.from_xml_path(str(stewart))
    cyl = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "cylinder1")
    assert m.body_jntnum[cyl] == 2 and [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, m.body_jntadr[cyl] + k)
                                         for k in range(2)] == ["base1_a", "base1_b"]
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "ujoint1") == -1 and m.nbody - 1 == 14
    assert sorted(c["type"] for c in report["compounds"]) == ["spherical"] + ["universal"] * 6
    assert simulate(stewart) == []
    assert drift(stewart)[0] < 3.5e-3


def test_ball_values_map_back_to_the_original_joints(tmp_path, capsys):
    """After 0.3 s of MuJoCo on the Delta's export (the joints well away from zero), every joint read
    back to the original's coordinates -- a hinge: MuJoCo's qpos + its written value; a ball's three
    members: screwkin.model.placed.ball_values of its quaternion -- puts every link of the original
    (Pinocchio's forward kinematics of robots/delta_parallelogram.urdf) where MuJoCo has its body."""
    from screwkin.files.exporter import PlacedCompound
    from screwkin.model.placed import ball_values
    src = DATA.parent.parent / "robots" / "delta_parallelogram.urdf"
    out, report = _export_mjcf(tmp_path, capsys, src)
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    d.ctrl[:] = 0.05
    for _ in range(150):
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)  # the bodies where the last step's qpos puts them
    original = screwkin.load(src, warn=lambda w: None)
    q = original.neutral()
    balls = {c["joint"]: PlacedCompound(c["type"], c["joint"], tuple(c["members"]), tuple(c["links_left_out"]),
                                        c["body"], tuple(map(tuple, c["axes"])), tuple(c["values"]))
             for c in report["compounds"]}
    turned = 0.0
    for j in range(m.njnt):
        name, adr = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j), m.jnt_qposadr[j]
        if name in balls:
            for member, value in ball_values(balls[name], d.qpos[adr:adr + 4]).items():
                q[original.coordinate(member).idx_q] = value
                turned = max(turned, abs(value - report["configuration"][member]))
        else:
            q[original.coordinate(name).idx_q] = d.qpos[adr] + report["configuration"][name]
    assert turned > 0.05  # the balls have turned
    same_bodies(original, q, m, d)


def test_universal_and_cylindrical_pairs_move_as_the_original(tmp_path, capsys):
    """A body carrying two joints (MuJoCo composes them in order, each about its axis as the earlier
    ones leave it) moves as the original chain through its massless link: at random joint values of the
    export (hinge and slide values + their written ones in the original), every body is where the
    original's Pinocchio forward kinematics puts it -- the Stewart platform's universal joints, and an
    arm whose cylindrical joint (a revolute and a prismatic on one line, through a massless link, drawn
    off the base's axes) carries a link."""
    import pinocchio as pin
    arm = tmp_path / "cyl.urdf"
    link = ('<link name="{n}"><inertial><origin xyz="0.05 0.01 0.1"/><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" '
            'izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry><box size="0.1 0.1 0.1"/></geometry>'
            '</visual></link>')
    arm.write_text('<robot name="cyl">' + link.format(n="base") + '<link name="sleeve"/>' + link.format(n="rod")
                   + link.format(n="hand") + '<joint name="turn" type="revolute"><parent link="base"/><child link="sleeve"/>'
                   '<origin xyz="0.1 0.2 0.3" rpy="0.3 -0.2 0.5"/><axis xyz="0 0.6 0.8"/><limit lower="-2" upper="2" '
                   'effort="1" velocity="1"/></joint><joint name="slide" type="prismatic"><parent link="sleeve"/>'
                   '<child link="rod"/><origin xyz="0 0 0" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/><limit lower="-0.1" '
                   'upper="0.1" effort="1" velocity="1"/></joint><joint name="wrist" type="revolute"><parent link="rod"/>'
                   '<child link="hand"/><origin xyz="0 0.1 0.2"/><axis xyz="1 0 0"/><limit lower="-2" upper="2" '
                   'effort="1" velocity="1"/></joint></robot>')
    # the prismatic axis in the sleeve's frame, turned by its origin's rpy, must lie on the revolute's line
    R = pin.rpy.rpyToMatrix(0.1, 0.2, 0.3)
    arm.write_text(arm.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="{} {} {}"/>'.format(
        *(R.T @ np.array([0, 0.6, 0.8])))))
    rng = np.random.default_rng(3)
    for src, kind in ((arm, "cylindrical"), (DATA.parent.parent / "robots" / "gough_stewart_6ups.urdf", "universal")):
        out, report = _export_mjcf(tmp_path, capsys, src, src.stem + ".xml")
        assert kind in [c["type"] for c in report["compounds"]]
        original = screwkin.load(src, warn=lambda w: None)
        m = mujoco.MjModel.from_xml_path(str(out))
        d = mujoco.MjData(m)
        for _ in range(3):
            q = original.neutral()
            for j in range(m.njnt):
                if m.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
                    d.qpos[m.jnt_qposadr[j]] = rng.uniform(-0.5, 0.5) * (
                        0.1 if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE else 1)
                    q[original.coordinate(name).idx_q] = d.qpos[m.jnt_qposadr[j]] + report["configuration"][name]
            mujoco.mj_kinematics(m, d)
            if kind == "universal":  # the Stewart's tree ball joint stays at zero: its members at their values
                for c in [c for c in report["compounds"] if c["type"] == "spherical"]:
                    for member, value in zip(c["members"], c["values"]):
                        q[original.coordinate(member).idx_q] = value
            same_bodies(original, q, m, d)


# ------------------------------------------------------------------ the redundant equality rows, named
def _equality_rank(path):
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT) | int(mujoco.mjtDisableBit.mjDSBL_LIMIT)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    J = d.efc_J[:d.nefc * m.nv].reshape(d.nefc, m.nv)[:d.ne]
    return d.ne, (np.linalg.matrix_rank(J, tol=1e-9) if d.ne else 0)


def test_planar_fourbar_redundant_rows_are_named(tmp_path, capsys):
    """The four-bar, drawn in the xy plane with every axis along z, closed by two connects on the loop
    joint's axis: no point of it moves along z, so the z rows of both connects do no work; and in a
    planar motion two points of one body on a line along z move alike, so the second connect's x and
    y rows repeat the first's.  4 of the 6 rows are redundant: MuJoCo's 6 - rank(efc_J) = 6 - 2."""
    out, report = _export_mjcf(tmp_path, capsys, DATA.parent.parent / "robots" / "fourbar_crank_rocker.urdf")
    rows = {r["equality"]: r for r in report["redundant_rows"]}
    assert rows["coupler_rocker"]["idle"] == ["the force along z"] and rows["coupler_rocker"]["repeated"] == []
    second = rows["coupler_rocker~axis"]
    assert (second["idle"], second["repeated"], second["repeats"]) == (
        ["the force along z"], ["the force along x", "the force along y"], ["connect 'coupler_rocker'"])
    assert _equality_rank(out) == (6, 2)
    assert any(n.startswith("4 of MuJoCo's 6 equality rows are redundant") and "connect 'coupler_rocker~axis': "
               "the forces along x, y (repeating connect 'coupler_rocker'); the force along z (nothing moves along "
               "it)" in n for n in report["notes"])


@pytest.mark.parametrize("name", ["bennett.urdf", "sarrus.urdf", "planar_3rrr.urdf", "spherical_fourbar.urdf",
                                  "gough_stewart_6ups.urdf", "tsai_3upu.urdf", "strider.urdf"])
def test_redundant_rows_count_mujocos_left_null_space(tmp_path, capsys, name):
    """However they are worded, the rows named redundant are as many as MuJoCo's left null space of its
    equality rows holds, rows - rank(efc_J) at qpos0 (plus the rows MuJoCo writes none of, a zero
    Jacobian: the spherical four-bar's connect at the sphere's centre, which no joint moves)."""
    out, report = _export_mjcf(tmp_path, capsys, DATA.parent.parent / "robots" / name)
    ne, rank = _equality_rank(out)
    named = report["redundant_rows"]
    assert sum(r["redundant"] for r in named if not r["dropped"]) == ne - rank
    if name == "spherical_fourbar.urdf":
        assert [r["equality"] for r in named if r["dropped"]] == ["coupler_rocker"]


def test_without_mujoco_the_rows_are_not_named_and_it_is_said(tmp_path, capsys, monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "mujoco", None)  # import mujoco raises ImportError
    out, report = _export_mjcf(tmp_path, capsys, DATA.parent.parent / "robots" / "fourbar_crank_rocker.urdf")
    assert report["redundant_rows"] is None
    assert "the redundant equality rows are not named: MuJoCo is not installed (pip install mujoco)" in report["notes"]


# ------------------------------------------------------------------ the physical-inertia check, any format's
def test_inertia_problem_takes_any_descriptions_inertial():
    """screwkin.files.inertia.inertia_problem takes the tensor or the six numbers a URDF <inertia>
    (or MJCF fullinertia) writes, with the same answer: principal moments 1, 1, 3 break A + B >= C
    (1 + 1 < 3); a thin rod (0, 1, 1) is the limit and passes; a tensor with a negative moment, or a
    negative mass, is named; MuJoCo refuses the first and accepts the rod's limit alike."""
    from screwkin.files.inertia import inertia_problem
    bad = (1.0, 1.0, 3.0, 0.0, 0.0, 0.0)
    assert "break the triangle inequality" in inertia_problem(2.0, bad)
    assert inertia_problem(2.0, bad) == inertia_problem(2.0, np.diag([1.0, 1.0, 3.0]))
    R = np.array([[0.0, -0.6, 0.8], [1.0, 0.0, 0.0], [0.0, 0.8, 0.6]])  # the same tensor in other axes
    I = R @ np.diag([1.0, 1.0, 3.0]) @ R.T
    assert "break the triangle inequality" in inertia_problem(2.0, (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
    assert inertia_problem(1.0, (1e-9, 1e-3, 1e-3, 0, 0, 0)) is None
    assert "not positive" in inertia_problem(1.0, (1.0, 1.0, 1.0, 2.0, 0.0, 0.0))
    assert "negative mass" in inertia_problem(-1.0, (1.0, 1.0, 1.0, 0.0, 0.0, 0.0))
    body = '<mujoco><worldbody><body><joint/><inertial pos="0 0 0" mass="2" fullinertia="{}"/></body></worldbody></mujoco>'
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(body.format("1 1 3 0 0 0"))
    mujoco.MjModel.from_xml_string(body.format("1e-9 1e-3 1e-3 0 0 0"))


def _finger_with_springs(tmp_path):
    """The finger with MuJoCo joint springs: mid pulled towards 17.19 deg (0.3 rad written in degrees:
    the compiler's unit) with 0.05 N m/rad, tip towards -0.2 rad with 0.02 N m/rad."""
    text = FINGER.read_text().replace('<compiler angle="radian"/>', '<compiler angle="degree"/>')
    text = text.replace('range="-1.6 1.6"', 'range="-91.67 91.67"')
    text = text.replace('<joint name="mid" ', f'<joint name="mid" stiffness="0.05" springref="{float(np.degrees(0.3))!r}" ')
    text = text.replace('<joint name="tip" ', f'<joint name="tip" stiffness="0.02" springref="{float(np.degrees(-0.2))!r}" ')
    path = tmp_path / "finger_springs.xml"
    path.write_text(text)
    return path


def test_joint_springs_are_mujocos_inverse_dynamics(tmp_path):
    """A hinge's stiffness and springref (MuJoCo's qpos_spring, the compiler's angle unit converted): the
    efforts of dynamics, the finger's base turning at 2 rad/s with mid and tip held away from their
    springs' rest angles under gravity, are MuJoCo's qfrc_inverse (constraints off: it holds armature,
    damping and the springs) plus the dry friction MuJoCo applies as a constraint, at every step; the
    potential energy holds the springs' 1/2 k (x - springref)^2."""
    path = _finger_with_springs(tmp_path)
    mech = screwkin.load(path, warn=lambda w: None)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    spec = {j.name: j for j in mech.spec.joints}
    for name in ("mid", "tip"):
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        assert spec[name].stiffness == m.jnt_stiffness[j]
        assert spec[name].springref == pytest.approx(m.qpos_spring[m.jnt_qposadr[j]], abs=1e-15)
    fixed = {"mid": 0.7, "tip": -0.6}
    res = dynamics(mech, "base", 2.0, -0.5, 0.5, 6, inputs=["base", "mid", "tip"], fixed=fixed, gravity=(0, 0, -9.81))
    assert any("the springs of 'mid', 'tip'" in n for n in res.notes)
    for k in range(len(res.values)):
        _inverse_at(mech, res, k, m, d, ("base", "mid", "tip"))
        full = d.qfrc_inverse + m.dof_frictionloss * np.sign(d.qvel)
        for name in ("base", "mid", "tip"):
            dof = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]
            assert res.efforts[name][k] == pytest.approx(full[dof], rel=1e-9, abs=1e-12), (name, k)
    mujoco.mj_energyPos(m, d)  # gravity and springs (0.5 0.05 0.4^2 + 0.5 0.02 0.4^2 = 0.0056 J), MuJoCo's own
    assert res.potential_energy[-1] == pytest.approx(d.energy[0], abs=1e-12)


def test_joint_springs_are_exported_about_the_written_configuration(tmp_path, capsys):
    """export --mjcf writes each spring with its rest angle moved with the joint's zero (the export draws
    the configuration given, qpos0 = 0 there): MuJoCo's qpos_spring of the export is springref - value;
    the URDF export says the spring has no URDF form."""
    path = _finger_with_springs(tmp_path)
    out_x, out_u = tmp_path / "out.xml", tmp_path / "out.urdf"
    assert main(["export", str(path), "--set", "base=0.1,mid=0.5,tip=-0.1", "--mjcf", str(out_x),
                 "--urdf", str(out_u)]) == 0
    assert "the spring of 2 joints ('mid', 'tip') has no URDF form" in capsys.readouterr().out
    m = mujoco.MjModel.from_xml_path(str(out_x))
    for name, k, rest in (("mid", 0.05, 0.3 - 0.5), ("tip", 0.02, -0.2 + 0.1)):
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        assert m.jnt_stiffness[j] == k
        assert m.qpos_spring[m.jnt_qposadr[j]] == pytest.approx(rest, abs=1e-12)
        assert m.qpos0[m.jnt_qposadr[j]] == 0.0
