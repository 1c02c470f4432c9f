"""URDF <mimic> joints are couplings, not degrees of freedom: against Pinocchio's own mimic
model, closed-form gear ratios, and real robot files when example-robot-data is installed."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOT_DATA, ROBOTS
from screwkin.model._pin import compute_frame_jacobian
from screwkin.cli import main
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep

GRIPPER = ROBOTS / "gripper_arm_mimic.urdf"


def test_gripper_matches_pinocchios_mimic_model():
    mech = screwkin.load(GRIPPER)
    ref = pin.buildModelFromXML(GRIPPER.read_text(), mimic=True)
    assert (mech.nq, mech.nv) == (ref.nq, ref.nv) == (4, 4)
    data = ref.createData()
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = rng.uniform(-1, 1, 4) * np.array([1, 1, 1, 0.04])
        pin.framesForwardKinematics(mech.model, mech.data, q)
        pin.framesForwardKinematics(ref, data, q)
        for link in ("finger_left", "finger_right", "hand"):
            a = mech.data.oMf[mech.link_frame(link)]
            b = data.oMf[ref.getFrameId(link, pin.FrameType.BODY)]
            np.testing.assert_allclose(a.homogeneous, b.homogeneous, atol=1e-14)
        J = pin.computeFrameJacobian(mech.model, mech.data, q, mech.link_frame("finger_right"), pin.LOCAL_WORLD_ALIGNED)
        Jr = pin.computeFrameJacobian(ref, data, q, ref.getFrameId("finger_right", pin.FrameType.BODY),
                                      pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(J, Jr, atol=1e-14)


def test_gripper_counts_and_report(capsys):
    r = screwkin.load(GRIPPER).mobility(output="hand")
    t = r.topology
    assert (t.n_links, t.n_joints, len(t.couplings)) == (6, 5, 1)
    assert t.gruebler == 3 * (6 - 1 - 5) + 5 - 1 == r.mobility == 4
    assert r.classification.startswith("constrained")
    assert main(["mobility", str(GRIPPER)]) == 0
    text = capsys.readouterr().out
    assert "finger_right_joint = 1 x finger_left_joint + 0" in text and "sum f - C" in text
    assert main(["mobility", str(GRIPPER), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["couplings"] == [{"joint": "finger_right_joint", "mimics": "finger_left_joint", "multiplier": 1.0,
                               "offset": 0.0}]


def test_coupled_joints_are_reported_not_set(capsys):
    arm = {"shoulder": 0.0, "elbow": 0.0, "wrist": 0.0}  # no loop passes through them: inputs too (issue 33)
    res = PositionSolver(screwkin.load(GRIPPER), [*arm, "finger_left_joint"]).solve({**arm, "finger_left_joint": 0.03})
    assert res.solutions[0].coupled == {"finger_right_joint": pytest.approx(0.03, abs=1e-15)}
    code = main(["solve", str(GRIPPER), "--set", "finger_right_joint=0.01"])
    err = capsys.readouterr().err
    assert code == 2 and "mimics 'finger_left_joint'" in err


def gear_train(tmp_path, idler_type="continuous"):
    """Three gears on the ground (radii 0.05, 0.03, 0.08 m), written as people write gear trains:
    the idler mimics the input (-r1/r2), the output mimics the idler (-r2/r3)."""
    r1, r2, r3 = 0.05, 0.03, 0.08
    def gear(name, r):
        return (f'<link name="{name}"><visual><geometry><cylinder radius="{r}" length="0.01"/></geometry></visual>'
                '</link>')
    body = '<link name="frame"/>' + gear("input", r1) + gear("idler", r2) + gear("output", r3)
    body += ('<joint name="j_in" type="continuous"><parent link="frame"/><child link="input"/><axis xyz="0 0 1"/>'
             '</joint>')
    body += (f'<joint name="j_idler" type="{idler_type}"><parent link="frame"/><child link="idler"/>'
             f'<origin xyz="{r1 + r2} 0 0"/><axis xyz="0 0 1"/><limit lower="-1e3" upper="1e3" effort="1" velocity="1"/>'
             f'<mimic joint="j_in" multiplier="{-r1 / r2!r}"/></joint>')
    body += (f'<joint name="j_out" type="continuous"><parent link="frame"/><child link="output"/>'
             f'<origin xyz="{r1 + 2 * r2 + r3} 0 0"/><axis xyz="0 0 1"/>'
             f'<mimic joint="j_idler" multiplier="{-r2 / r3!r}" offset="0.1"/></joint>')
    body += '<transmission name="t"><joint name="j_in"/></transmission>'
    p = tmp_path / "gears.urdf"
    p.write_text(f'<robot name="gears">{body}</robot>')
    return p, (r1, r2, r3)


@pytest.mark.parametrize("idler_type", ["continuous", "revolute"])
def test_a_chain_of_mimics_is_the_gear_ratio(tmp_path, idler_type):
    """output = -r2/r3 (-r1/r2 input) + 0.1 = (r1/r3) input + 0.1, also where a continuous joint
    mimics a revolute one (Pinocchio alone refuses to mix them)."""
    path, (r1, r2, r3) = gear_train(tmp_path, idler_type)
    mech = screwkin.load(path)
    assert mech.nv == 1
    (c_idler, c_out) = sorted(mech.couplings, key=lambda c: c.joint)
    assert (c_out.mimics, c_out.multiplier, c_out.offset) == ("j_in", pytest.approx(r1 / r3), pytest.approx(0.1))
    r = mech.mobility()
    assert r.mobility == 1 and r.topology.count_in_motion_space == 3 * (4 - 1 - 3) + 3 - 2 == 1
    # speed ratio from the kinematics: the output's angular velocity over the input's
    q = np.array([0.7])
    J = compute_frame_jacobian(mech.model, mech.data, q, mech.link_frame("output"), pin.LOCAL_WORLD_ALIGNED)
    assert J[5, 0] == pytest.approx(r1 / r3, abs=1e-14)
    # three turns of the input turn the output by 3 r1/r3 turns: angles count turns
    res = sweep(PositionSolver(mech, ["j_in"]), "j_in", 0.0, 6 * np.pi, 12)
    out = res.coupled["j_out"]
    np.testing.assert_allclose(np.unwrap(out), (r1 / r3) * res.values + 0.1, atol=1e-12)


def test_a_mimic_that_couples_nothing_is_a_warning(tmp_path):
    """Real files carry <mimic> leftovers (TALOS's reduced models put one on a fixed joint, Alex's
    hands name a joint that is not there): the joint then moves on its own, and a warning says so."""
    path, _ = gear_train(tmp_path)
    text = path.read_text()
    for bad, word, coordinates in (
            (text.replace('mimic joint="j_in"', 'mimic joint="nowhere"'), "'nowhere', which is not a joint", 2),
            (text.replace('mimic joint="j_in"', 'mimic joint="j_idler"'), "mimics itself", 2),
            (text.replace('mimic joint="j_in"', 'mimic joint="j_out"'), "circle", 3)):
        path.write_text(bad)
        seen = []
        mech = screwkin.load(path, warn=seen.append)
        assert any(word in w for w in seen), seen
        assert mech.nv == coordinates


def test_a_transmission_of_a_mimic_joint_is_a_warning(tmp_path):
    text = GRIPPER.read_text().replace('</robot>', '<transmission name="t_right"><joint name="finger_right_joint"/>'
                                                   '</transmission></robot>')
    p = tmp_path / "g.urdf"
    p.write_text(text)
    seen = []
    mech = screwkin.load(p, warn=seen.append)
    assert "finger_right_joint" not in mech.actuated
    assert any("mimics 'finger_left_joint'" in w for w in seen)


# ------------------------------------------------------------------ real robots (optional data package)


@pytest.mark.skipif(ROBOT_DATA is None, reason="example-robot-data is not installed (pip install example-robot-data)")
@pytest.mark.parametrize("name, path, dof", [
    ("panda", "panda_description/urdf/panda.urdf", 8),  # 7 arm joints + one finger (the other mimics it)
])
def test_real_robots_with_mimic_joints(name, path, dof):
    mech = screwkin.load(ROBOT_DATA / path, warn=lambda m: None)
    r = mech.mobility()
    assert r.mobility == dof and len(r.topology.couplings) >= 1


@pytest.mark.skipif(ROBOT_DATA is None, reason="example-robot-data is not installed (pip install example-robot-data)")
def test_talos_has_no_phantom_gripper_dofs():
    """TALOS: 32 transmissions for 32 DOF once its 12 gripper <mimic> joints are couplings (it was
    'under-actuated: 32 inputs for 44 DOF').  Pinocchio's own mimic=True parser refuses this file
    (its mimicked joints come after their mimics); the reference is its plain model less the
    <mimic> elements of the file."""
    path = ROBOT_DATA / "talos_data/robots/talos_full_v2.urdf"
    mech = screwkin.load(path, warn=lambda m: None)
    plain = pin.buildModelFromXML(path.read_text())
    mimics = path.read_text().count("<mimic ")
    r = mech.mobility()
    assert mimics == 12 == len(r.topology.couplings)
    assert r.mobility == mech.nv == plain.nv - mimics == 32
    assert len(r.actuated) == 32 and r.classification.startswith("constrained")


@pytest.mark.skipif(ROBOT_DATA is None, reason="example-robot-data is not installed (pip install example-robot-data)")
def test_meshes_of_pip_installed_description_packages_are_found(tmp_path):
    """issue 24 item 9: the Panda's package://example-robot-data/robots/... meshes are found where pip put them
    (cmeel.prefix/share), without --package-dir: no 'mesh file(s) not found' warning."""
    seen = []
    screwkin.load(str(ROBOT_DATA / "panda_description" / "urdf" / "panda.urdf"), warn=seen.append)
    assert not any("not found" in w for w in seen), seen[:1]
