"""Robot files as they are published (issue 34): MJCF written as MuJoCo Menagerie writes its robots
(tests/data/mjcf: our own models of the same forms -- a 2F-85-like four-bar gripper on a fixed tendon,
a Cassie-like leg with ref and closed loops, an xArm-like hand with unnamed equalities, a
WidowX-like gripper on a coupled joint, bodies without <inertial> from an <include> through a
<frame>), checked against MuJoCo itself; and dynamics of coupled joints (<mimic>, MJCF equalities,
tendons) against Pinocchio's RNEA on the uncoupled model and MuJoCo's inverse dynamics."""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import DATA, ROBOT_DATA, ROBOTS, check_urdf
from screwkin.analysis.forces.dynamics import dynamics
from screwkin.analysis.forces.statics import statics
from screwkin.cli import main
from test_mjcf import random_qpos, screwkin_q

mujoco = pytest.importorskip("mujoco")
MJCF = DATA / "mjcf"
PUBLISHED = {  # file -> MuJoCo's nv - rank (checked below against MuJoCo, not only this number)
    "gripper_4bar_tendon.xml": 1, "leg_ref_loop.xml": 9, "hand_unnamed_equality.xml": 3,
    "gripper_coupled_slides.xml": 5, "include_frame_geoms.xml": 2}


def _mj(path, bare=False):
    m = mujoco.MjModel.from_xml_path(str(path))
    if bare:  # no armature, damping, springs or friction loss: the rigid bodies' own dynamics
        m.dof_armature[:] = 0
        m.dof_damping[:] = 0
        m.jnt_stiffness[:] = 0
        m.dof_frictionloss[:] = 0
    return m, mujoco.MjData(m)


def _equality_rank(m, d):
    J = d.efc_J.reshape(d.nefc, m.nv)[:d.ne]
    return np.linalg.matrix_rank(J, tol=1e-9) if J.size else 0


def _coupling_map(mech, m, d=None):
    """G (MuJoCo's nv x screwkin's nv): MuJoCo's joint rates from screwkin's (couplings applied; a free
    joint's linear velocity in world axes in MuJoCo, in the body's in Pinocchio: d's rotation)."""
    G = np.zeros((m.nv, mech.nv))
    coupled = {c.joint: c for c in mech.couplings}
    for j in range(m.njnt):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
        dof, n = m.jnt_dofadr[j], {0: 6, 1: 3}.get(int(m.jnt_type[j]), 1)
        if name in coupled:
            c = coupled[name]
            G[dof, mech.coordinate(c.mimics).idx_v] = c.multiplier
        else:
            v = mech.coordinate(name).idx_v
            G[dof:dof + n, v:v + n] = np.eye(n)
            if n == 6 and d is not None:
                G[dof:dof + 3, v:v + 3] = d.xmat[m.jnt_bodyid[j]].reshape(3, 3)
    return G


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_published_forms_read_as_mujoco_reads_them(name):
    """Body positions at qpos0 and at random joint values (couplings kept) to 1e-12 m, mobility =
    MuJoCo's nv - rank of its equality rows, masses and inertias through the joint-space inertia
    matrix (MuJoCo's M against Pinocchio's CRBA, G^T M_mujoco G with couplings) to 1e-12."""
    mech = screwkin.load(MJCF / name, warn=lambda w: None)
    m, d = _mj(MJCF / name, bare=True)
    mujoco.mj_forward(m, d)
    assert m.nv - _equality_rank(m, d) == PUBLISHED[name] == mech.mobility().mobility
    rng = np.random.default_rng(11)
    for k in range(4):
        qpos = m.qpos0.copy() if k == 0 else random_qpos(m, rng)
        d.qpos[:] = qpos
        mujoco.mj_forward(m, d)
        q = screwkin_q(mech, m, qpos)
        if k == 0:
            np.testing.assert_allclose(q, mech.neutral(), rtol=0, atol=1e-12)  # qpos0 is the file's configuration
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, q)
        for b in range(1, m.nbody):
            M = data.oMf[mech.link_frame(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b))]
            np.testing.assert_allclose(M.translation, d.xpos[b], rtol=0, atol=1e-12)
            np.testing.assert_allclose(M.rotation, d.xmat[b].reshape(3, 3), rtol=0, atol=1e-12)
        M_mj = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M_mj)
        G = _coupling_map(mech, m, d)
        M_pin = pin.crba(mech.model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        scale = np.abs(M_pin).max()
        np.testing.assert_allclose(G.T @ M_mj @ G, M_pin, rtol=0, atol=1e-12 * scale)
    assert sum(m.body_mass) == pytest.approx(sum(lk.mass or 0.0 for lk in mech.spec.links.values()), rel=1e-12)


def test_tendon_input_is_named_and_used(capsys):
    """The 2F-85 form: the actuator's fixed tendon split = 0.5 right + 0.5 left driver, the right
    coupled to the left, is the left driver's angle; mobility says so, solve --set split= takes it,
    statics gives the tendon's force holding gravity and the joints' springs: MuJoCo's by virtual work
    along the one motion N its equality rows allow, F = dV / dL from its own potential energy V (gravity
    and springs) and tendon length L (central difference)."""
    path = MJCF / "gripper_4bar_tendon.xml"
    mech = screwkin.load(path, warn=lambda w: None)
    (t,) = mech.transmissions()
    assert (t.name, t.actuator, t.joint, t.scale, mech.actuated) == ("split", "fingers_actuator", "left_driver_joint",
                                                                    1.0, ["left_driver_joint"])
    assert main(["mobility", str(path)]) == 0
    assert "Input split = 0.5 right_driver_joint + 0.5 left_driver_joint = 1 left_driver_joint" in capsys.readouterr().out
    assert main(["solve", str(path), "--set", "split=0.3", "--json"]) == 0
    out = capsys.readouterr()
    assert "--set split is left_driver_joint = 0.3" in out.err and '"left_driver_joint": 0.3' in out.out
    q = mech.neutral()
    r = statics(mech, q, gravity=True)
    assert any("the springs of" in n for n in r.notes)  # the links' springs (stiffness, springref) are read
    m, d = _mj(path)
    d.qpos[:] = m.qpos0
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)[:d.ne]
    N = np.linalg.svd(J)[2][-1]  # the one motion the equalities allow
    m.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)

    def energy_and_length(x):  # MuJoCo's potential energy (gravity and the joints' springs), tendon length
        d.qpos[:] = m.qpos0 + x * N
        mujoco.mj_forward(m, d)
        return d.energy[0], d.ten_length[0]

    (e1, l1), (e0, l0) = energy_and_length(1e-6), energy_and_length(-1e-6)
    force = (e1 - e0) / (l1 - l0)  # virtual work: F dL = dV along the allowed motion
    assert r.actuator_efforts["fingers_actuator"] == pytest.approx(force, rel=1e-6)  # central difference
    assert r.efforts["left_driver_joint"] == r.actuator_efforts["fingers_actuator"]  # scale 1, gear 1


def test_coupled_joint_actuator_and_mujoco_inverse_dynamics():
    """The WidowX form: the gripper actuator on the coupled finger (left = -right) is an input on the
    right finger with scale -1; dynamics' efforts are MuJoCo's qfrc_inverse (constraints off; it holds
    the joints' armature and damping) plus the joints' dry friction, projected on screwkin's
    coordinates, G^T qfrc_inverse, at every step; the coupled finger's effort is MuJoCo's own at that
    joint."""
    path = MJCF / "gripper_coupled_slides.xml"
    mech = screwkin.load(path, warn=lambda w: None)
    assert mech.actuated == ["waist", "shoulder", "elbow", "wrist", "right_finger"]
    (t,) = mech.transmissions()
    assert (t.name, t.joint, t.scale, t.kind) == ("left_finger", "right_finger", -1.0, "coupled joint")
    fixed = {"waist": 0.2, "elbow": 0.4, "wrist": -0.3, "right_finger": -0.02}
    res = dynamics(mech, "shoulder", 2.0, -0.5, 0.5, 5, inputs=mech.actuated, fixed=fixed, gravity=(0, 0, -9.81))
    m, d = _mj(path)  # with the file's armature (0.1) and friction loss (0.1), as MuJoCo reads them
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    G = _coupling_map(mech, m)
    _gripper_efforts_are_mujocos(mech, res, m, d, G)
    for k in range(len(res.values)):
        assert res.actuator_efforts["gripper"][k] == pytest.approx(-res.efforts["right_finger"][k])


def _gripper_efforts_are_mujocos(mech, res, m, d, G):
    """At every step of ``res`` (dynamics of the WidowX-form gripper): each input's effort is G^T of
    MuJoCo's qfrc_inverse (constraints off) plus the dry friction MuJoCo applies as a constraint
    (frictionloss x sign(qvel), added), and the coupled finger's effort is that force at its own dof.
    Returns the coupled finger's dof (d is left at the last step's configuration)."""
    left = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "left_finger")]
    for k in range(len(res.values)):
        for j in range(m.njnt):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
            d.qpos[m.jnt_qposadr[j]] = (mech.coupled_values(res.q[k])[name] if name == "left_finger"
                                        else res.q[k][mech.coordinate(name).idx_q])
        d.qvel[:] = G @ res.rates[k]
        d.qacc[:] = G @ res.accelerations[k]
        mujoco.mj_inverse(m, d)
        full = d.qfrc_inverse + m.dof_frictionloss * np.sign(d.qvel)
        tau = G.T @ full
        for name in mech.actuated:
            assert res.efforts[name][k] == pytest.approx(tau[mech.coordinate(name).idx_v], rel=1e-9, abs=1e-12)
        assert res.coupled_efforts["left_finger"][k] == pytest.approx(full[left], rel=1e-9, abs=1e-12)
    return left


def test_a_coupled_joints_spring_reaches_its_leader(tmp_path):
    """The WidowX-form gripper with a spring on the coupled finger (left = -right: stiffness 40 N/m towards
    left = 0.03 m) and the right finger moving: the right finger's effort holds the left's spring through
    the coupling, G^T (MuJoCo's qfrc_inverse with the spring, constraints off, plus its dry friction) at
    every step, and the coupled finger's effort is MuJoCo's own there."""
    text = (MJCF / "gripper_coupled_slides.xml").read_text().replace(
        '<joint name="left_finger" ', '<joint name="left_finger" stiffness="40" springref="0.03" ')
    path = tmp_path / "gripper_spring.xml"
    path.write_text(text)
    mech = screwkin.load(path, warn=lambda w: None)
    fixed = {"waist": 0.2, "shoulder": 0.1, "elbow": 0.4, "wrist": -0.3}
    res = dynamics(mech, "right_finger", 0.05, -0.035, -0.017, 4, inputs=mech.actuated, fixed=fixed,
                   gravity=(0, 0, -9.81))
    assert any("the springs of 'left_finger'" in n for n in res.notes)
    m, d = _mj(path)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    G = _coupling_map(mech, m)
    left = _gripper_efforts_are_mujocos(mech, res, m, d, G)  # its qpos is res.q[-1]'s after it
    assert abs(40 * (mech.coupled_values(res.q[0])["left_finger"] - 0.03)) > 0.1  # the spring matters here
    st = statics(mech, res.q[-1], gravity=True)  # at rest: MuJoCo's qfrc_inverse with v = a = 0 (no friction)
    d.qvel[:] = 0
    d.qacc[:] = 0
    mujoco.mj_inverse(m, d)
    tau = G.T @ d.qfrc_inverse
    for name in mech.actuated:
        assert st.efforts[name] == pytest.approx(tau[mech.coordinate(name).idx_v], rel=1e-9, abs=1e-12)
    assert st.coupled_efforts["left_finger"] == pytest.approx(d.qfrc_inverse[left], rel=1e-9, abs=1e-12)


@pytest.mark.skipif(ROBOT_DATA is None, reason="example-robot-data is not installed (pip install example-robot-data)")
@pytest.mark.parametrize("path", ["panda_description/urdf/panda.urdf", None])
def test_mimic_dynamics_is_rnea_of_the_uncoupled_model(path):
    """dynamics of a file with <mimic> joints (the Panda's finger, the gripper's): at every step the
    efforts are G^T RNEA(q_full, G v, G a) of Pinocchio's model of the same file without the mimic
    law (the coupled joints set by it), and each coupled joint's effort is that model's torque there."""
    file = ROBOT_DATA / path if path else ROBOTS / "gripper_arm_mimic.urdf"
    mech = screwkin.load(file, warn=lambda w: None)
    full = pin.buildModelFromUrdf(str(file))
    full.gravity = pin.Motion(np.array([0.0, 0.0, -9.81]), np.zeros(3))
    inputs = [c.joint for c in mech.coordinates]
    first = inputs[0]
    rng = np.random.default_rng(5)
    fixed = {n: float(rng.uniform(-0.5, 0.5)) if not mech.translational[mech.coordinate(n).idx_v] else 0.01
             for n in inputs[1:]}
    res = dynamics(mech, first, 1.5, -0.4, 0.4, 4, inputs=inputs, fixed=fixed, gravity=(0, 0, -9.81))
    coupled = {c.joint: c for c in mech.couplings}
    assert coupled
    fdata = full.createData()
    for k in range(len(res.values)):
        q, v, a = res.q[k], res.rates[k], res.accelerations[k]
        G = np.zeros((full.nv, mech.nv))
        qf = pin.neutral(full)
        for j in range(1, full.njoints):
            name = full.names[j]
            if name in coupled:
                c = coupled[name]
                p = mech.coordinate(c.mimics)
                G[full.idx_vs[j], p.idx_v] = c.multiplier
                qf[full.idx_qs[j]] = c.multiplier * q[p.idx_q] + c.offset
            else:
                p = mech.coordinate(name)
                G[full.idx_vs[j]:full.idx_vs[j] + full.nvs[j], p.idx_v:p.idx_v + p.nv] = np.eye(p.nv)
                qf[full.idx_qs[j]:full.idx_qs[j] + full.nqs[j]] = q[p.idx_q:p.idx_q + p.nq]
        vf = G @ v
        # the <dynamics damping friction> of the file (Pinocchio reads them), as ROS and MuJoCo apply them
        tau = pin.rnea(full, fdata, qf, vf, G @ a) + full.damping * vf + full.friction * np.sign(vf)
        scale = max(1.0, float(np.abs(tau).max()))
        for name in inputs:
            assert res.efforts[name][k] == pytest.approx((G.T @ tau)[mech.coordinate(name).idx_v], abs=1e-9 * scale)
        for name in coupled:
            assert res.coupled_efforts[name][k] == pytest.approx(tau[full.idx_vs[full.getJointId(name)]],
                                                                 abs=1e-9 * scale)


# ------------------------------------------------------------------ exports that simulate
ROUND_TRIPS = [ROBOTS / n for n in ("fourbar_crank_rocker.urdf", "slider_crank_offset.urdf", "delta_parallelogram.urdf",
                                    "gough_stewart_6ups.urdf", "bennett.urdf", "tsai_3upu.urdf")] + [MJCF / n for n in sorted(PUBLISHED)]


def simulate(path, seconds=1.0, effort=0.05):
    """1 s of MuJoCo (mj_step at the file's timestep) with ``effort`` on every motor: the warnings raised."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    d.ctrl[:] = effort
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
    warned = [mujoco.mjtWarning(k).name for k in range(len(d.warning)) if d.warning[k].number]
    assert np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
    return warned


@pytest.mark.parametrize("path", ROUND_TRIPS, ids=lambda p: p.name)
def test_export_simulates_and_keeps_its_counts(tmp_path, capsys, path):
    """Every export runs 1 s in MuJoCo with 0.05 N m (N) on its motors without a warning; read back by
    screwkin it has the original's mobility, Gruebler count and overconstraint (a revolute loop joint
    written as two <connect>s is read back as one revolute); the URDF export passes urdfdom's
    check_urdf where it is installed and reads back with the same mobility."""
    out_x, out_u = tmp_path / "out.xml", tmp_path / "out.urdf"
    argv = ["export", str(path), "--mjcf", str(out_x)]
    has_ball = path.name in ("leg_ref_loop.xml",)  # a ball joint: URDF has none
    if not has_ball:
        argv += ["--urdf", str(out_u)]
    assert main(argv) == 0
    capsys.readouterr()
    assert simulate(out_x) == []
    original = screwkin.load(path, warn=lambda w: None).mobility()
    for out in [out_x] + ([] if has_ball else [out_u]):
        back = screwkin.load(out, warn=lambda w: None).mobility()
        assert (back.mobility, back.gruebler, back.overconstraint, back.topology.motion_space) == (
            original.mobility, original.gruebler, original.overconstraint, original.topology.motion_space)
    if not has_ball:
        check_urdf(out_u)


def test_export_of_a_ball_joint_to_both_formats_writes_neither(tmp_path, capsys):
    """--mjcf and --urdf of a model with a ball joint: the URDF cannot hold it, so nothing is written
    (not the MJCF alone with exit 1)."""
    out_x, out_u = tmp_path / "o.xml", tmp_path / "o.urdf"
    assert main(["export", str(MJCF / "delta_rss.xml"), "--mjcf", str(out_x), "--urdf", str(out_u)]) == 1
    assert "ball joint: URDF has none" in capsys.readouterr().err
    assert not out_x.exists() and not out_u.exists()
    assert main(["export", str(MJCF / "fourbar.xml"), "--mjcf", str(out_x), "--urdf", str(out_x)]) == 2


def test_export_names_never_collide_and_comments_stay_well_formed(tmp_path, capsys):
    """A loop joint named so that export's helpers (B~axis, B~F1, crank_joint_motor) already exist, and
    names holding '--' and a final '-': the export loads in MuJoCo and in screwkin."""
    text = (ROBOTS / "slider_crank_offset.urdf").read_text()
    assert 'name="rod_slider"' in text
    text = text.replace('"rod_slider" type="revolute"', '"rod--slider-" type="cylindrical"')
    text = text.replace('<link name="rod">', '<link name="rod--slider-~F1">').replace('link="rod"', 'link="rod--slider-~F1"')
    src = tmp_path / "clash.urdf"
    src.write_text(text)
    out = tmp_path / "clash.xml"
    assert main(["export", str(src), "--mjcf", str(out)]) == 0
    capsys.readouterr()
    mujoco.MjModel.from_xml_path(str(out))
    import xml.etree.ElementTree as ET
    ET.parse(out)  # the comment is well-formed
    assert screwkin.load(out, warn=lambda w: None).mobility().mobility == screwkin.load(src).mobility().mobility
