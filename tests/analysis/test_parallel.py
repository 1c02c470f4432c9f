"""Spatial and parallel mechanisms of robots/: closed forms from the literature.

- Bennett linkage: tan(t1/2) tan(t2/2) = sin((b+a)/2) / sin((b-a)/2), t3 = -t1, t4 = -t2 (Bennett 1903);
- Gough-Stewart: inverse kinematics = distances between attachment points; the rows of the inverse
  Jacobian are the legs' Pluecker lines; Fichter's singularity at +-90 deg about the vertical (Fichter 1986);
- 3-RPR: actuator singularity where the three leg lines meet in one point;
- 6R arm: wrist (theta5 = 0), elbow (arm stretched) and shoulder (wrist centre on axis 1) singularities;
- Tsai 3-UPU: constraint singularity with the legs in the base plane (the legs' constraint couples coplanar).
"""

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import brentq

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.ik import inverse_kinematics
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.screws import split_jacobians
from screwkin.analysis.singular import classify
from screwkin.analysis.motion.sweep import sweep


def load(name, **kw):
    return screwkin.load(ROBOTS / f"{name}.urdf", **kw)


# ------------------------------------------------------------------ Bennett
def dh_angles(mech, q):
    """DH joint angles from the world joint axes: the angle about axis i from the common
    normal of axes (i-1, i) to the common normal of axes (i, i+1)."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    axis = {j.name: np.array(j.axis) for j in mech.spec.joints}
    Z = [data.oMi[mech.model.getJointId(j)].rotation @ axis[j] for j in ("joint1", "joint2", "joint3")]
    cut = mech.cuts[0]
    Z.append(data.oMf[cut.frame1].rotation @ np.array(cut.axis))
    X = [np.cross(Z[i], Z[(i + 1) % 4]) for i in range(4)]
    X = [x / np.linalg.norm(x) for x in X]
    return [np.arctan2(np.cross(X[i - 1], X[i]) @ Z[i], X[i - 1] @ X[i]) for i in range(4)]


def test_bennett_input_output_relation():
    a, alpha, b = 0.10, np.radians(30), 0.15
    beta = np.arcsin(b / a * np.sin(alpha))
    k = np.sin((beta + alpha) / 2) / np.sin((beta - alpha) / 2)
    mech = load("bennett")
    res = sweep(PositionSolver(mech), "joint1", 0.0, 1.5, 30)
    assert res.stopped_at is None
    for q in res.q:
        t1, t2, t3, t4 = dh_angles(mech, q)
        assert abs(np.tan(t1 / 2) * np.tan(t2 / 2) - k) < 1e-8
        assert abs(np.mod(t1 + t3 + np.pi, 2 * np.pi) - np.pi) < 1e-9
        assert abs(np.mod(t2 + t4 + np.pi, 2 * np.pi) - np.pi) < 1e-9


# ------------------------------------------------------------------ Gough-Stewart
PHI = np.radians([0, 120, 240])
BASE = [0.5 * np.array([np.cos(t + s), np.sin(t + s), 0]) for t in PHI for s in np.radians([-12, 12])]
PLAT = [0.3 * np.array([np.cos(t + s), np.sin(t + s), 0]) for t in PHI for s in np.radians([-48, 48])]
R_HOME = pin.rpy.rpyToMatrix(np.array([0.05, -0.04, 0.12]))
C_HOME = np.array([0.02, -0.01, 0.6])


def platform_frame_pose(c, R):
    """Pose of the platform link frame (at leg 1's ball, world-aligned in the file) that puts the
    platform centre at c with orientation R relative to the design orientation."""
    p1_home = C_HOME + R_HOME @ PLAT[0]
    Rm = R @ R_HOME.T
    return pin.SE3(Rm, c - Rm @ (C_HOME - p1_home))


def test_stewart_file_matches_its_design():
    mech = load("gough_stewart_6ups")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    for k in range(6):
        b = data.oMi[mech.model.getJointId(f"base{k + 1}_a")].translation
        np.testing.assert_allclose(b, BASE[k], atol=1e-12)


@pytest.mark.slow  # about 4.6 s on 2 shared cores: out of the fast subset
@pytest.mark.parametrize("c, rpy", [((0.03, 0.02, 0.65), (0.1, 0.05, -0.1)), ((-0.05, 0.04, 0.55), (-0.08, 0.1, 0.3))])
def test_stewart_inverse_kinematics_is_leg_lengths(c, rpy):
    mech = load("gough_stewart_6ups")
    R = pin.rpy.rpyToMatrix(np.array(rpy))
    res = inverse_kinematics(mech, "platform", platform_frame_pose(np.array(c), R))
    s = res.solutions[0]
    assert s.residual < 1e-10
    for k in range(6):
        home = np.linalg.norm(C_HOME + R_HOME @ PLAT[k] - BASE[k])
        length = np.linalg.norm(np.array(c) + R @ PLAT[k] - BASE[k])
        assert abs(s.joints[f"leg{k + 1}"] - (length - home)) < 1e-9
    assert not s.outside_limits
    # other assemblies of the same pose have each leg either this length or passing back through
    # its universal joint (a negative extension: outside the joint limits, and listed so)
    for other in res.solutions[1:]:
        for k in range(6):
            home = np.linalg.norm(C_HOME + R_HOME @ PLAT[k] - BASE[k])
            length = np.linalg.norm(np.array(c) + R @ PLAT[k] - BASE[k])
            assert abs(abs(home + other.joints[f"leg{k + 1}"]) - length) < 1e-9
        assert other.outside_limits


def test_stewart_inverse_jacobian_rows_are_pluecker_lines():
    mech = load("gough_stewart_6ups")
    q = mech.assemble().q
    J = split_jacobians(mech, q, "platform")["inverse"]
    o = C_HOME + R_HOME @ PLAT[0]  # the platform frame origin: output twists are (v at o, w)
    for k in range(6):
        p = C_HOME + R_HOME @ PLAT[k]
        u = (p - BASE[k]) / np.linalg.norm(p - BASE[k])
        np.testing.assert_allclose(J[k], np.r_[u, np.cross(p - o, u)], atol=1e-9)


@pytest.mark.slow  # about 2.0 s on 2 shared cores: out of the fast subset
def test_stewart_forward_kinematics_finds_several_assembly_modes():
    mech = load("gough_stewart_6ups")
    res = PositionSolver(mech).solve({f"leg{k + 1}": 0.0 for k in range(6)}, starts=40)
    assert len(res.solutions) >= 2
    home = mech.assemble().q
    data = mech.model.createData()
    poses = []
    for s in res.solutions:
        assert s.residual < 1e-10
        assert all(abs(s.joints[f"leg{k + 1}"]) < 1e-12 for k in range(6))
        pin.framesForwardKinematics(mech.model, data, s.q)
        poses.append(data.oMf[mech.link_frame("platform")].homogeneous.copy())
    pin.framesForwardKinematics(mech.model, data, home)
    assert any(np.allclose(P, data.oMf[mech.link_frame("platform")].homogeneous, atol=1e-9) for P in poses)


def plucker_det(psi, h=0.6):
    R = np.array([[np.cos(psi), -np.sin(psi), 0], [np.sin(psi), np.cos(psi), 0], [0, 0, 1]])
    c = np.array([0, 0, h])
    rows = []
    for k in range(6):
        p = c + R @ PLAT[k]
        u = (p - BASE[k]) / np.linalg.norm(p - BASE[k])
        rows.append(np.r_[u, np.cross(p - c, u)])
    return np.linalg.det(np.array(rows))


@pytest.mark.slow  # about 4.5 s on 2 shared cores: out of the fast subset
def test_fichter_singularity():
    """Centred platform turned about the vertical: the closed-form Pluecker determinant vanishes
    at +-90 deg (Fichter 1986); screwkin finds an actuator singularity there and not 0.1 rad away."""
    psi = brentq(plucker_det, np.radians(80), np.radians(100), xtol=1e-14)
    assert abs(psi - np.pi / 2) < 1e-9
    mech = load("gough_stewart_6ups")
    for angle, singular in ((psi, True), (psi - 0.1, False)):
        R = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
        s = inverse_kinematics(mech, "platform", platform_frame_pose(np.array([0, 0, 0.6]), R)).solutions[0]
        rep = classify(mech, s.q, output="platform")
        assert rep.actuator is singular
        assert not rep.constraint


# ------------------------------------------------------------------ 3-RPR
@pytest.mark.slow  # about 5.3 s on 2 shared cores: out of the fast subset
def test_3rpr_concurrent_legs_are_an_actuator_singularity():
    mech = load("planar_3rpr")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    A = [data.oMi[mech.model.getJointId(f"base{k + 1}")].translation for k in range(3)]
    frame = data.oMf[mech.link_frame("platform")]
    C = [frame.translation] + [data.oMf[c.frame2].translation for c in mech.cuts]
    local = [frame.inverse() * c for c in C]

    def concurrency(phi, x=0.02, y=0.01):
        """Signed planar determinant of the leg lines (rows (u, p x u) about the platform origin)."""
        M = pin.SE3(pin.rpy.rpyToMatrix(np.array([0, 0, phi])), np.array([x, y, 0]) + frame.translation)
        rows = []
        for k in range(3):
            p = M * local[k]
            u = (p - A[k]) / np.linalg.norm(p - A[k])
            rows.append([u[0], u[1], np.cross(p - M.translation, u)[2]])
        return np.linalg.det(np.array(rows))

    grid = np.linspace(-1.5, 1.5, 301)
    vals = [concurrency(p) for p in grid]
    k = next(i for i in range(300) if np.sign(vals[i]) != np.sign(vals[i + 1]))
    phi = brentq(concurrency, grid[k], grid[k + 1], xtol=1e-14)
    for angle, singular in ((phi, True), (phi + 0.2, False)):
        pose = pin.SE3(pin.rpy.rpyToMatrix(np.array([0, 0, angle])), np.array([0.02, 0.01, 0]) + frame.translation)
        s = inverse_kinematics(mech, "platform", pose).solutions[0]
        assert classify(mech, s.q, output="platform").actuator is singular
    # and the three leg lines do meet in one point there
    pose = pin.SE3(pin.rpy.rpyToMatrix(np.array([0, 0, phi])), np.array([0.02, 0.01, 0]) + frame.translation)
    pts = [pose * local[k] for k in range(3)]
    lines = [(A[k][:2], (pts[k] - A[k])[:2]) for k in range(3)]
    (p0, d0), (p1, d1), (p2, d2) = lines
    t = np.linalg.solve(np.column_stack([d0, -d1]), p1 - p0)
    meet = p0 + t[0] * d0
    u = d2 / np.linalg.norm(d2)
    assert abs(u[0] * (meet - p2)[1] - u[1] * (meet - p2)[0]) < 1e-9


# ------------------------------------------------------------------ 6R arm
def arm_q(mech, values):
    q = mech.neutral()
    for k, v in enumerate(values):
        q[mech.coordinate(f"joint{k + 1}").idx_q] = v
    return q


def test_6r_wrist_elbow_shoulder_singularities():
    mech = load("arm_6r")
    generic = [0.3, -0.4, 0.5, 0.2, 0.7, -0.3]

    def serial(values):
        return classify(mech, arm_q(mech, values), output="flange").serial

    assert not serial(generic)
    assert serial([0.3, -0.4, 0.5, 0.2, 0.0, -0.3])  # wrist: theta5 = 0, axes 4 and 6 aligned
    # elbow: forearm (J3 to wrist centre, (0.4, 0, 0.02) at zero) in line with the upper arm (along z)
    assert serial([0.3, -0.4, np.arctan2(-0.4, 0.02), 0.2, 0.7, -0.3])
    # shoulder: the wrist centre on axis 1 (x = 0 in the arm plane), solved from the arm geometry
    th3 = 0.5
    fore = np.array([np.cos(th3) * 0.4 + np.sin(th3) * 0.02, -np.sin(th3) * 0.4 + np.cos(th3) * 0.02])  # (x, z) from J3
    th2 = brentq(lambda t: 0.05 + np.cos(t) * fore[0] + np.sin(t) * (0.4 + fore[1]), -3, -0.05)
    assert serial([0.3, th2, th3, 0.2, 0.7, -0.3])


# ------------------------------------------------------------------ Tsai 3-UPU
@pytest.mark.slow  # about 1.5 s on 2 shared cores: out of the fast subset
def test_tsai_3upu_constraint_singularity_in_the_base_plane():
    mech = load("tsai_3upu")
    frame0 = mech.model.createData()
    pin.framesForwardKinematics(mech.model, frame0, mech.neutral())
    home = frame0.oMf[mech.link_frame("platform")]
    # the platform centre from (0.01, 0.02, 0.3) to (0, 0, 0): every leg horizontal and radial
    flat = pin.SE3(home.rotation, home.translation - np.array([0.01, 0.02, 0.3]))
    s = inverse_kinematics(mech, "platform", flat).solutions[0]
    rep = classify(mech, s.q, output="platform")
    assert rep.constraint
    high = pin.SE3(home.rotation, home.translation + np.array([0.0, 0.0, 0.05]))
    assert not classify(mech, inverse_kinematics(mech, "platform", high).solutions[0].q, output="platform").constraint
