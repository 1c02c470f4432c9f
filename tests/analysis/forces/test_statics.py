"""Statics: actuator efforts, joint reactions and legs' wrenches, against closed forms (leg lines
of a Gough-Stewart platform, a four-bar's velocity ratio, a pendulum's weight) and reciprocity."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ARM, DATA, ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.forces.statics import legs, statics
from screwkin.cli import main
from screwkin.model.linalg import null_space


def load(name):
    return screwkin.load(ROBOTS / f"{name}.urdf")


W = np.array([10.0, -5.0, 100.0, 1.0, 2.0, -0.5])


def stewart_lines(mech, q):
    """Unit leg lines s_k through the platform attachment points p_k, and the platform origin o."""
    pin.framesForwardKinematics(mech.model, mech.data, q)
    o = mech.data.oMf[mech.link_frame("platform")].translation.copy()
    out = []
    for k in range(1, 7):
        b = mech.data.oMi[mech.model.getJointId(f"base{k}_a")].translation.copy()
        p = (mech.data.oMi[mech.model.getJointId("ball1_x")].translation if k == 1
             else mech.data.oMf[mech.model.getFrameId(f"ball{k}@F2")].translation).copy()
        out.append((p, (p - b) / np.linalg.norm(p - b)))
    return out, o


def test_stewart_leg_forces_are_the_inverse_of_the_leg_lines():
    """Equilibrium of the platform: sum_k f_k (s_k, (p_k - o) x s_k) + w = 0, so f = -L^-1 w
    (the columns of L are the legs' Pluecker lines); each prismatic actuator carries f_k."""
    mech = load("gough_stewart_6ups")
    for q in mech.generic_configurations()[1][:3]:
        lines, o = stewart_lines(mech, q)
        L = np.array([np.r_[s, np.cross(p - o, s)] for p, s in lines]).T
        f = -np.linalg.solve(L, W)
        r = statics(mech, q, output="platform", wrench=W)
        assert r.equilibrium and r.indeterminate == 0
        np.testing.assert_allclose([r.efforts[f"leg{k}"] for k in range(1, 7)], f, rtol=1e-9, atol=1e-9)
        assert all(x.determinate for x in r.reactions)
        # each leg's transmission wrench is its line: a pure force along s_k through p_k
        for leg, (p, s) in zip(legs(mech, q, "platform"), lines, strict=True):
            (screw,) = leg.transmission_screws
            assert leg.constraint_wrenches == () and screw.pitch == pytest.approx(0.0, abs=1e-9)
            assert abs(abs(np.dot(screw.direction, s)) - 1) < 1e-9
            assert np.linalg.norm(np.cross(np.asarray(screw.point) - p, s)) < 1e-9  # the line passes through p


def test_fourbar_input_torque_by_virtual_work():
    """A moment T about z on the rocker is held by the crank torque tau = -T d(t4)/d(t2), the
    velocity ratio taken by central differences of the closed-form rocker angle (circle
    intersection of the student four-bar, 5-7-9-6 in)."""
    mech = screwkin.load(DATA / "student" / "fourbar_5796.urdf")
    a, b, c, d = (x * 0.0254 for x in (5, 7, 9, 6))

    def rocker(t2):
        A = a * np.array([np.cos(t2), np.sin(t2)])
        D = np.array([d, 0.0])
        dist = np.linalg.norm(D - A)
        along = (b * b - c * c + dist * dist) / (2 * dist)
        B = A + along * (D - A) / dist + np.sqrt(b * b - along * along) * np.array([-(D - A)[1], (D - A)[0]]) / dist
        return np.arctan2(B[1] - D[1], B[0] - D[0])

    t2, h, T = np.radians(60), 1e-6, 2.5
    ratio = (rocker(t2 + h) - rocker(t2 - h)) / (2 * h)
    res = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": t2})
    q = next(s.q for s in res.solutions if abs(s.link_angles["rocker"] - rocker(t2)) < 1e-8)
    r = statics(mech, q, output="rocker", wrench=[0, 0, 0, 0, 0, T])
    assert r.efforts["crank_joint"] == pytest.approx(-T * ratio, rel=1e-7)
    assert r.units["crank_joint"] == "N m"
    # the rocker's pivot carries no moment about its axis (a passive pin), the crank's carries tau
    react = {x.joint: x.wrench for x in r.reactions}
    assert react["rocker_joint"][5] == pytest.approx(0.0, abs=1e-9)
    assert react["crank_joint"][5] == pytest.approx(r.efforts["crank_joint"], abs=1e-9)


def test_pendulum_weight():
    """A link of mass 2 kg with its centre 0.3 m from a pin about y: tau = m g l sin(t) (Pinocchio's
    gravity: -9.81 along z; the link hangs along -z at t = 0)."""
    text = ('<robot name="p"><link name="base"/><link name="bob"><inertial><origin xyz="0 0 -0.3"/><mass value="2"/>'
            '<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>'
            '<joint name="pin" type="continuous"><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/></joint>'
            '<transmission name="t"><joint name="pin"/></transmission></robot>')
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "p.urdf"
        p.write_text(text)
        mech = screwkin.load(p)
        for t in (0.3, 1.2, -2.0):
            r = statics(mech, np.array([t]), gravity=True)
            assert r.efforts["pin"] == pytest.approx(2 * 9.81 * 0.3 * np.sin(t), rel=1e-12)


def test_an_overconstrained_linkage_is_statically_indeterminate():
    """Bennett's linkage: 3 redundant constraints.  Its input torque follows from virtual work
    (determinate), but some components of its joints' reactions do not: they are reported as
    such, not as numbers."""
    mech = load("bennett")
    q = mech.generic_configurations()[1][0]
    r = statics(mech, q, output="link3", wrench=[1, 2, 3, 0.1, 0.2, 0.3])
    assert r.equilibrium and r.indeterminate == 3
    assert isinstance(r.efforts["joint1"], float)  # its value: test_oracles.py, by virtual work
    assert any(None in x.wrench for x in r.reactions)
    # a planar linkage: in-plane components determined, out-of-plane ones not
    r = statics(load("fourbar_crank_rocker"), load("fourbar_crank_rocker").generic_configurations()[1][0],
                output="rocker", wrench=[0.3, -0.2, 0, 0, 0, 0.1])
    for x in r.reactions:
        fx, fy, fz, mx, my, mz = x.wrench
        assert None not in (fx, fy, mz) and None in (fz, mx, my)


def test_near_a_limit_position_the_efforts_grow_without_bound():
    mech = screwkin.load(DATA / "student" / "fourbar_5796.urdf")
    limit = np.arccos((0.127**2 + 0.1524**2 - (0.2286 - 0.1778) ** 2) / (2 * 0.127 * 0.1524))
    near = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": limit + 1e-9}).solutions[0].q
    far = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": 1.0}).solutions[0].q
    r_near = statics(mech, near, output="rocker", wrench=[0, 0, 0, 0, 0, 1.0])
    r_far = statics(mech, far, output="rocker", wrench=[0, 0, 0, 0, 0, 1.0])
    assert r_near.singular and not r_far.singular
    assert r_near.amplification > 1e3 * r_far.amplification


def test_a_load_the_inputs_cannot_hold():
    mech = load("fourbar_crank_rocker")
    mech.set_actuated([])
    r = statics(mech, mech.generic_configurations()[1][0], inputs=[], output="rocker", wrench=[0, 0, 0, 0, 0, 1])
    assert not r.equilibrium and r.unbalanced > 1e-3


@pytest.mark.parametrize("name, motion", [("delta_parallelogram", "3T"), ("tsai_3upu", "3T"),
                                          ("planar_3rrr", "2T1R"), ("planar_3rpr", "2T1R")])
def test_the_platform_twists_are_reciprocal_to_the_legs_constraint_wrenches(name, motion):
    mech = load(name)
    q = mech.generic_configurations()[1][0]
    Ws = [np.array(c) for leg in legs(mech, q, "platform") for c in leg.constraint_wrenches]
    T = null_space(np.array(Ws), mech.tolerances, 6)
    mob = mech.mobility(output="platform")
    assert mob.output.label == motion
    twists = np.array(mob.output.twists).T
    assert T.shape[1] == twists.shape[1]
    assert np.linalg.matrix_rank(np.hstack([T, twists]), tol=1e-8) == T.shape[1]  # the same space
    # with every actuator locked, constraint and transmission wrenches span all wrenches (not singular)
    all_w = Ws + [np.array(c) for leg in legs(mech, q, "platform") for c in leg.transmission_wrenches]
    assert np.linalg.matrix_rank(np.array(all_w), tol=1e-8) == 6


def test_statics_command(capsys):
    path = str(ROBOTS / "gough_stewart_6ups.urdf")
    assert main(["statics", path, "--output", "platform", "--wrench", "10 -5 100 1 2 -0.5", "--json"]) == 0
    d = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    assert set(d) >= {"efforts", "units", "reactions", "legs", "equilibrium", "indeterminate", "singular"}
    assert d["units"]["leg1"] == "N" and len(d["legs"]) == 6
    assert main(["statics", path, "--wrench", "1 2 3"]) == 2
    assert "fx fy fz mx my mz" in capsys.readouterr().err
    assert main(["statics", str(ROBOTS / "bennett.urdf"), "--output", "link3", "--wrench", "1 2 3 0 0 0"]) == 0
    assert "not determined by statics" in capsys.readouterr().out


#: conftest's planar 2R arm with only its shoulder driven (a transmission on it).
ARM_SHOULDER_ONLY = ARM.replace("</robot>", """  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>
    <joint name="shoulder"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>
</robot>""")


def test_no_equilibrium_shows_no_reactions_as_a_solution(tmp_path, capsys):
    """Issue 43 item 4: a moment about z on the hand of a 2R arm whose elbow is passive: the elbow's generalized
    force (J^T w)_elbow = m_z = 2 N m has nothing to balance it, so there is no equilibrium, and the
    least-squares fit's reaction table (a 2 N m torque about the passive elbow's own axis) was printed as one."""
    path = tmp_path / "arm.urdf"
    path.write_text(ARM_SHOULDER_ONLY)
    args = ["statics", str(path), "--set", "shoulder=0.3", "--set", "elbow=1.1", "--output", "hand",
            "--wrench", "0 0 0 0 0 2"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "NO EQUILIBRIUM" in out and "unbalanced generalized force 2" in out
    assert "joint reactions:" not in out and "fx [N]" not in out  # no reaction table
    assert "actuator  effort" not in out and "-2 N m" not in out  # nor the fit's efforts
    assert main(args + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["equilibrium"] is False and d["least_squares_residual"] == pytest.approx(2.0, abs=1e-12)
    assert d["solution"].startswith("none") and "least-squares fit" in d["solution"]
    assert d["reactions"] and d["efforts"]  # kept, flagged by "solution"
    # the elbow actuated too: an equilibrium (efforts 2 and 2 N m, J^T w), its tables shown
    elbow = ('<transmission name="t2"><type>transmission_interface/SimpleTransmission</type><joint name="elbow">'
             '<hardwareInterface>EffortJointInterface</hardwareInterface></joint><actuator name="m2">'
             '<mechanicalReduction>1</mechanicalReduction></actuator></transmission>\n</robot>')
    path.write_text(ARM_SHOULDER_ONLY.replace("</robot>", elbow))
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "NO EQUILIBRIUM" not in out and "joint reactions:" in out and "actuator  effort" in out
    assert main(args + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["equilibrium"] is True and d["least_squares_residual"] is None and d["solution"] == "equilibrium"
    assert [abs(d["efforts"][n]) for n in ("shoulder", "elbow")] == pytest.approx([2.0, 2.0], abs=1e-12)
