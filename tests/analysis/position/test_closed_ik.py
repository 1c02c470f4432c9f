"""Inverse kinematics in closed form (issue 41) and the angle set a pose is written in.

Outside references: the leg lengths of the bundled Gough-Stewart platform by hand from the anchor
points its file describes (base circle of 0.5 m at 0/120/240 deg -+ 12 deg, platform circle of 0.3 m
at -+ 48 deg, drawn at (0.02, -0.01, 0.6) m turned by rpy (0.05, -0.04, 0.12)); the loops closed in
Pinocchio's own placements (the two frames of every loop joint at one point); Pinocchio's forward
kinematics of every arm solution; the PUMA's published count of 8 (Pieper 1968; Craig, Introduction to
Robotics, 4.7) on the PUMA 560's published Denavit-Hartenberg parameters.
"""

import os
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.ik import branches, inverse_kinematics
from screwkin.analysis.position.position import PositionSolver
from screwkin.model.leg_chains import leg_poses, platform_of, set_leg
from screwkin.model.limits import outside_limits

PHI = np.radians([0, 120, 240])
BASE = [0.5 * np.array([np.cos(t + s), np.sin(t + s), 0]) for t in PHI for s in np.radians([-12, 12])]
PLAT = [0.3 * np.array([np.cos(t + s), np.sin(t + s), 0]) for t in PHI for s in np.radians([-48, 48])]
R_HOME = pin.rpy.rpyToMatrix(np.array([0.05, -0.04, 0.12]))
C_HOME = np.array([0.02, -0.01, 0.6])


def stewart():
    return screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")


def platform_pose(c, R):
    """The platform link's frame (at leg 1's ball, world-aligned as drawn) for the centre at c turned by R."""
    p1 = C_HOME + R_HOME @ PLAT[0]
    Rm = R @ R_HOME.T
    return pin.SE3(Rm, c - Rm @ (C_HOME - p1))


def loops_closed(mech, q) -> float:
    """The largest distance between the two frames of a loop joint, in Pinocchio's own placements."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return max(np.linalg.norm(data.oMf[c.frame1].translation - data.oMf[c.frame2].translation) for c in mech.cuts)


def random_poses(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield C_HOME + rng.uniform(-0.05, 0.05, 3), pin.rpy.rpyToMatrix(rng.uniform(-0.12, 0.12, 3))


def test_stewart_ik_is_the_leg_lengths_in_closed_form_physical_first():
    mech = stewart()
    for c, R in random_poses(4, 41):
        res = inverse_kinematics(mech, "platform", platform_pose(c, R))
        assert res.modes.method == "closed form (legs)" and res.modes.found == 64
        first = res.solutions[0]
        assert first.physical and not outside_limits(mech, first.q)
        assert loops_closed(mech, first.q) < 1e-12
        for k in range(6):
            home = np.linalg.norm(C_HOME + R_HOME @ PLAT[k] - BASE[k])
            length = np.linalg.norm(c + R @ PLAT[k] - BASE[k])
            assert abs(first.joints[f"leg{k + 1}"] - (length - home)) < 1e-12
            # beside it: leg k reversed through its pivot (the other root of the same length), the rest alike
            other = res.solutions[k + 1]
            assert abs(other.joints[f"leg{k + 1}"] - (-length - home)) < 1e-12
            assert any(lab.startswith("legs reversed") for lab in other.labels)
            assert loops_closed(mech, other.q) < 1e-12
        count = branches(mech, res)
        assert count.complete and count.found == 64 and [m for _, _, m in count.legs] == [2] * 6


def test_planar_3rpr_lists_every_combination_of_its_legs():
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    home = data.oMf[mech.link_frame("platform")]
    pose = pin.SE3(pin.rpy.rpyToMatrix(np.array([0, 0, 0.1])), home.translation + np.array([0.01, -0.02, 0]))
    res = inverse_kinematics(mech, "platform", pose)
    assert res.modes.method == "closed form (legs)" and len(res.solutions) == 8
    first = res.solutions[0]
    assert first.physical and all(first.joints[f"leg{k}"] > -0.08 for k in (1, 2, 3))
    # each leg's value: the distance between its base pivot and its platform pivot, less the drawn one
    values = {tuple(np.round([s.joints[f"leg{k}"] for k in (1, 2, 3)], 9)) for s in res.solutions}
    assert len(values) == 8
    for s in res.solutions:
        assert loops_closed(mech, s.q) < 1e-12


def test_tsai_3upu_translation_in_closed_form():
    mech = screwkin.load(ROBOTS / "tsai_3upu.urdf")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    home = data.oMf[mech.link_frame("platform")]
    res = inverse_kinematics(mech, "platform", pin.SE3(home.rotation, home.translation + [0.01, -0.02, 0.03]))
    assert res.modes.method == "closed form (legs)"
    assert res.solutions[0].physical and loops_closed(mech, res.solutions[0].q) < 1e-12
    assert float(np.linalg.norm(mech.closure.residual(res.solutions[0].q))) < 1e-12


RPS = """<?xml version="1.0"?>
<robot name="rps3">
  <link name="base"/>
  {links}
  <link name="platform"/>
  {joints}
  {loops}
</robot>"""


def rps_urdf():
    """A 3-RPS: revolutes on the base circle (0.3 m) with axes tangent to it, legs drawn upright, spherical
    joints on the platform circle (0.15 m) at 0.5 m: leg 1 closes through three revolutes, legs 2, 3 by loop
    spherical joints."""
    links, joints, loops = [], [], []
    for k, t in enumerate(np.radians([90, 210, 330]), 1):
        a = 0.3 * np.array([np.cos(t), np.sin(t), 0])
        b = 0.15 * np.array([np.cos(t), np.sin(t), 0.5 / 0.15])
        tangent = np.array([-np.sin(t), np.cos(t), 0])
        d = b - a
        u = d / np.linalg.norm(d)
        links += [f'<link name="cyl{k}"/>', f'<link name="pis{k}"/>']
        xyz = " ".join(f"{v:.15g}" for v in a)
        lim = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
        joints += [f'<joint name="rev{k}" type="revolute"><parent link="base"/><child link="cyl{k}"/>'
                   f'<origin xyz="{xyz}"/><axis xyz="{tangent[0]:.15g} {tangent[1]:.15g} 0"/>{lim}</joint>',
                   f'<joint name="leg{k}" type="prismatic"><parent link="cyl{k}"/><child link="pis{k}"/>'
                   f'<origin xyz="0 0 0"/><axis xyz="{u[0]:.15g} {u[1]:.15g} {u[2]:.15g}"/>'
                   '<limit lower="-0.2" upper="0.2" effort="1" velocity="1"/></joint>']
        dxyz = " ".join(f"{v:.15g}" for v in d)
        if k == 1:
            links += ['<link name="s1"/>', '<link name="s2"/>']
            chain = [("sx", "pis1", "s1", dxyz, "1 0 0"), ("sy", "s1", "s2", "0 0 0", "0 1 0"),
                     ("sz", "s2", "platform", "0 0 0", "0 0 1")]
            joints += [f'<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><origin xyz="{o}"/>'
                       f'<axis xyz="{ax}"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>'
                       for n, p, c, o, ax in chain]
            b1 = b
        else:
            pxyz = " ".join(f"{v:.15g}" for v in b - b1)
            loops.append(f'<loop_joint name="ball{k}" type="spherical"><link1 link="pis{k}" xyz="{dxyz}"/>'
                         f'<link2 link="platform" xyz="{pxyz}"/></loop_joint>')
    return RPS.format(links="".join(links), joints="".join(joints), loops="".join(loops))


def test_3rps_legs_positive_at_a_reachable_pose(tmp_path):
    path = tmp_path / "rps3.urdf"
    path.write_text(rps_urdf())
    mech = screwkin.load(path)
    mech.set_actuated(["leg1", "leg2", "leg3"])
    # a reachable pose: the mechanism closed with its legs at 0.03, -0.02, 0.05 m (Newton, outside ik)
    solver = PositionSolver(mech)
    q = solver.track({"leg1": 0.03, "leg2": -0.02, "leg3": 0.05}, mech.neutral()).q
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    res = inverse_kinematics(mech, "platform", pin.SE3(data.oMf[mech.link_frame("platform")]))
    assert res.modes.method == "closed form (legs)"
    first = res.solutions[0]
    assert first.physical
    np.testing.assert_allclose([first.joints[f"leg{k}"] for k in (1, 2, 3)], [0.03, -0.02, 0.05], atol=1e-10)
    assert loops_closed(mech, first.q) < 1e-12


# ------------------------------------------------------------------ serial arms: Pieper

def fk_error(mech, q, frame, pose) -> float:
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return float(np.linalg.norm(pin.log6(data.oMf[mech.link_frame(frame)].inverse() * pose).vector))


def distinct(qs) -> bool:
    Q = np.array(qs)
    d = np.abs(np.angle(np.exp(1j * (Q[:, None, :] - Q[None, :, :])))).max(axis=2)
    return bool((d + np.eye(len(Q)) * 10 > 1e-6).all())


def test_arm_6r_lists_every_joint_solution_in_closed_form():
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    rng = np.random.default_rng(7)
    eight = 0
    for _ in range(6):
        q0 = rng.uniform(-2.5, 2.5, mech.model.nq)
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, q0)
        pose = pin.SE3(data.oMf[mech.link_frame("flange")])
        res = inverse_kinematics(mech, "flange", pose)
        c = res.modes
        assert c.method == "closed form (Pieper)" and c.real == len(res.solutions) and c.real + c.complex == 8
        assert "meet at (0.45, 0, 0.82)" in c.certificate
        assert all(fk_error(mech, s.q, "flange", pose) < 1e-10 for s in res.solutions)
        assert distinct([s.q for s in res.solutions])
        # the configuration the pose came from is among them
        assert min(np.abs(np.angle(np.exp(1j * (s.q - q0)))).max() for s in res.solutions) < 1e-9
        eight += c.real == 8
    assert eight  # the PUMA-like arm's published 8, real at some of these poses


def puma560_urdf():
    """The PUMA 560 (Craig's DH: a2 = 0.4318, d3 = 0.15005, a3 = 0.0203, d4 = 0.4318 m, twists -90, 0, -90, 90,
    -90 deg): axes 1 and 2 meet, so the wrist-centre equations leave one in joint 3 alone."""
    dh = [(0, 0, 0), (-np.pi / 2, 0, 0), (0, 0.4318, 0.15005), (-np.pi / 2, 0.0203, 0.4318), (np.pi / 2, 0, 0),
          (-np.pi / 2, 0, 0)]  # (alpha_{i-1}, a_{i-1}, d_i), modified DH
    links = "".join(f'<link name="l{i}"/>' for i in range(7))
    joints = []
    for i, (al, a, d) in enumerate(dh, 1):
        R = pin.utils.rotate("x", al)
        p = np.array([a, 0, 0]) + R @ np.array([0, 0, d])
        rpy = " ".join(f"{v:.15g}" for v in pin.rpy.matrixToRpy(R))
        joints.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
                      f'<origin xyz="{p[0]:.15g} {p[1]:.15g} {p[2]:.15g}" rpy="{rpy}"/><axis xyz="0 0 1"/>'
                      '<limit lower="-3.1" upper="3.1" effort="1" velocity="1"/></joint>')
    return f'<?xml version="1.0"?><robot name="puma560">{links}{"".join(joints)}</robot>'


def test_puma_560_has_its_published_eight(tmp_path):
    path = tmp_path / "puma560.urdf"
    path.write_text(puma560_urdf())
    mech = screwkin.load(path)
    q0 = np.array([0.3, -0.6, 0.4, 0.5, 0.7, -0.2])
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q0)
    pose = pin.SE3(data.oMf[mech.link_frame("l6")])
    res = inverse_kinematics(mech, "l6", pose)
    assert res.modes.method == "closed form (Pieper)" and res.modes.real == 8 and len(res.solutions) == 8
    assert all(fk_error(mech, s.q, "l6", pose) < 1e-10 for s in res.solutions)
    assert distinct([s.q for s in res.solutions])


# ------------------------------------------------------------------ section 3: the angle set within the limits

def test_a_pose_is_within_the_limits_in_whichever_angle_set_it_was_found():
    """Every spelling of a platform pose (universal joints flipped with their legs spun, the spherical
    joint's other Euler set) is reported in the set within the limits, as physical, every joint centre
    where it was: the one place solutions are made (PositionSolver.solution)."""
    mech = stewart()
    solver = PositionSolver(mech, output="platform")
    platform = platform_of(mech, mech.model.frames[mech.link_frame("platform")].parentJoint)
    poses = [(C_HOME, R_HOME @ R_HOME.T)] + list(random_poses(3, 5))
    for c, R in poses:
        P = platform_pose(c, R)
        legs = [leg_poses(platform, leg, P)[0][0] for leg in platform.legs]
        spellings = 0
        for first in range(len(legs[0].sets)):  # leg 1 in each of its 4 sets, the others as found or flipped
            for rest in range(2):
                q = mech.neutral()
                for k, lp in enumerate(legs):
                    set_leg(mech.model, q, lp, lp.sets[first if k == 0 else rest])
                assert loops_closed(mech, q) < 1e-12
                sol = solver.solution(q, mech.closure.solve(q, frozen=solver.frozen))
                assert sol.physical and not sol.outside_limits, sol.labels
                assert np.allclose(solver.signature(sol.q), solver.signature(q), atol=1e-12)
                spellings += bool(outside_limits(mech, q))
        assert spellings  # some of them were written outside the limits


@pytest.mark.slow  # the full mode search: about 15 s on 2 shared cores
def test_bundled_6ups_file_configuration_is_a_physical_mode():
    mech = stewart()
    solver = PositionSolver(mech, output="platform")
    res = solver.solve({n: 0.0 for n in mech.actuated})
    ref = solver.signature(mech.neutral())
    mine = [s for s in res.solutions if np.max(np.abs(solver.signature(s.q) - ref)) < 1e-9]
    assert len(mine) == 1 and mine[0].physical and not mine[0].outside_limits
    assert res.solutions[0] is mine[0]


def test_arm_6r_at_its_drawn_pose_has_the_stretched_wrist_as_one_continuum():
    """At the file's configuration joint 5 is 0: joints 4 and 6 turn about one line (only their sum is
    fixed), so that solution is a continuum, said so, and the other position solutions keep their two
    wrist sets."""
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    pose = pin.SE3(data.oMf[mech.link_frame("flange")])
    res = inverse_kinematics(mech, "flange", pose)
    assert res.modes.method == "closed form (Pieper)" and res.modes.detail["stretched"] == 1
    cont = [s for s in res.solutions if s.continuum]
    assert len(cont) == 1 and np.allclose(cont[0].q, 0, atol=1e-12)
    assert all(fk_error(mech, s.q, "flange", pose) < 1e-10 for s in res.solutions)
    q = cont[0].q.copy()
    q[3], q[5] = 0.7, -0.7  # along the continuum: the flange stays
    assert fk_error(mech, q, "flange", pose) < 1e-12


def ups_floating_urdf(base=BASE, plat=PLAT, rng=None):
    """The bundled platform's geometry with the platform on a floating joint: six U-P legs, each closed by
    a spherical loop joint (the same anchors: BASE, PLAT at C_HOME turned by R_HOME); with ``rng`` the
    universal joints' axes at random angles (not perpendicular)."""
    BASE, PLAT = base, plat  # noqa: N806
    rpy = " ".join(f"{v:.15g}" for v in pin.rpy.matrixToRpy(R_HOME))
    parts = ['<link name="base"/><link name="platform"/>',
             f'<joint name="free" type="floating"><parent link="base"/><child link="platform"/>'
             f'<origin xyz="{C_HOME[0]} {C_HOME[1]} {C_HOME[2]}" rpy="{rpy}"/></joint>']
    for k in range(6):
        d = C_HOME + R_HOME @ PLAT[k] - BASE[k]
        u = d / np.linalg.norm(d)
        a = np.cross(u, [0, 0, 1.0]) if rng is None else rng.normal(size=3)  # random: skew to the leg
        a /= np.linalg.norm(a)
        b = np.cross(u, a)  # across the leg: the universal joint turns it toward any direction
        b /= np.linalg.norm(b)
        v = lambda x: " ".join(f"{c:.15g}" for c in x)  # noqa: E731
        lim = '<limit lower="-1.2" upper="1.2" effort="1" velocity="1"/>'
        parts += [f'<link name="u{k}"/><link name="c{k}"/><link name="p{k}"/>',
                  f'<joint name="base{k + 1}_a" type="revolute"><parent link="base"/><child link="u{k}"/>'
                  f'<origin xyz="{v(BASE[k])}"/><axis xyz="{v(a)}"/>{lim}</joint>',
                  f'<joint name="base{k + 1}_b" type="revolute"><parent link="u{k}"/><child link="c{k}"/>'
                  f'<axis xyz="{v(b)}"/>{lim}</joint>',
                  f'<joint name="leg{k + 1}" type="prismatic"><parent link="c{k}"/><child link="p{k}"/>'
                  f'<axis xyz="{v(u)}"/><limit lower="-0.3" upper="0.3" effort="1" velocity="1"/></joint>',
                  f'<loop_joint name="ball{k + 1}" type="spherical"><link1 link="p{k}" xyz="{v(d)}"/>'
                  f'<link2 link="platform" xyz="{v(PLAT[k])}"/></loop_joint>']
    return f'<?xml version="1.0"?><robot name="ups_floating">{"".join(parts)}</robot>'


def test_tree_and_floating_forms_of_one_platform_agree(tmp_path):
    path = tmp_path / "ups_floating.urdf"
    path.write_text(ups_floating_urdf())
    floating = screwkin.load(path, actuated=[f"leg{k}" for k in range(1, 7)])
    tree = stewart()
    for c, R in random_poses(3, 17):
        target = pin.SE3(R, c)  # the floating platform's frame: at the centre, its points PLAT turned by R
        res_f = inverse_kinematics(floating, "platform", target)
        res_t = inverse_kinematics(tree, "platform", platform_pose(c, R))
        assert res_f.modes.method == res_t.modes.method == "closed form (legs)"
        assert "floating joint" in res_f.modes.certificate
        first = res_f.solutions[0]
        assert first.physical and loops_closed(floating, first.q) < 1e-12
        for k in range(1, 7):
            assert abs(first.joints[f"leg{k}"] - res_t.solutions[0].joints[f"leg{k}"]) < 1e-12
            home = np.linalg.norm(C_HOME + R_HOME @ PLAT[k - 1] - BASE[k - 1])
            assert abs(first.joints[f"leg{k}"] - (np.linalg.norm(c + R @ PLAT[k - 1] - BASE[k - 1]) - home)) < 1e-12


def random_wrist_arm_urdf(rng):
    """A 6R arm of random geometry (joints 1-3: random axes and offsets) with a wrist of three random axes
    through one point."""
    parts = ['<link name="l0"/>']
    for i in range(1, 7):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        xyz = rng.uniform(-0.3, 0.3, 3) if i <= 4 else np.zeros(3)
        rpy = rng.uniform(-np.pi, np.pi, 3)
        v = lambda x: " ".join(f"{c:.15g}" for c in x)  # noqa: E731
        parts.append(f'<link name="l{i}"/><joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
                     f'<child link="l{i}"/><origin xyz="{v(xyz)}" rpy="{v(rpy)}"/><axis xyz="{v(axis)}"/>'
                     '<limit lower="-3.2" upper="3.2" effort="1" velocity="1"/></joint>')
    parts.append('<link name="tool"/><joint name="t" type="fixed"><parent link="l6"/><child link="tool"/>'
                 '<origin xyz="0.1 0.02 0.05"/></joint>')
    return f'<?xml version="1.0"?><robot name="wrist6r">{"".join(parts)}</robot>'


def test_pieper_on_random_arms_with_a_spherical_wrist(tmp_path):
    """Any 6R whose last three axes meet: every solution places the tool (Pinocchio), the configuration the
    pose came from is among them, and the real and complex ones make 8."""
    rng = np.random.default_rng(3)
    for k in range(4):
        path = tmp_path / f"w{k}.urdf"
        path.write_text(random_wrist_arm_urdf(rng))
        mech = screwkin.load(path, actuated=[f"j{i}" for i in range(1, 7)])
        q0 = rng.uniform(-3, 3, 6)
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, q0)
        pose = pin.SE3(data.oMf[mech.link_frame("tool")])
        res = inverse_kinematics(mech, "tool", pose)
        c = res.modes
        assert c.method == "closed form (Pieper)" and c.real + c.complex == 8 and c.real == len(res.solutions)
        assert all(fk_error(mech, s.q, "tool", pose) < 1e-10 for s in res.solutions)
        assert min(np.abs(np.angle(np.exp(1j * (s.q - q0)))).max() for s in res.solutions) < 1e-8
        assert distinct([s.q for s in res.solutions])


def test_random_platforms_in_closed_form(tmp_path):
    """Random anchors and universal joints whose first axis is skew to the leg: the first solution has every leg at the
    hand distance between its anchors, the loops closed in Pinocchio's placements."""
    rng = np.random.default_rng(23)
    for k in range(3):
        base = [np.array([*rng.uniform(-0.6, 0.6, 2), 0.0]) for _ in range(6)]
        plat = [np.array([*rng.uniform(-0.3, 0.3, 2), 0.0]) for _ in range(6)]
        path = tmp_path / f"p{k}.urdf"
        path.write_text(ups_floating_urdf(base, plat, rng))
        mech = screwkin.load(path, actuated=[f"leg{i}" for i in range(1, 7)])
        for c, R in random_poses(2, k):
            res = inverse_kinematics(mech, "platform", pin.SE3(R, c))
            assert res.modes.method == "closed form (legs)"
            first = res.solutions[0]
            assert loops_closed(mech, first.q) < 1e-12
            for i in range(6):
                home = np.linalg.norm(C_HOME + R_HOME @ plat[i] - base[i])
                assert abs(first.joints[f"leg{i + 1}"] - (np.linalg.norm(c + R @ plat[i] - base[i]) - home)) < 1e-12


# ------------------------------------------------------------------ its speed: nothing computed it does not need

def _ik_cases():
    """(mechanism file, output link, a pose of it off the drawn one): the bundled platforms and the 6R arm."""
    moved = [("gough_stewart_6ups.urdf", "platform", [0.01, -0.02, 0.015], [0.03, 0.05, -0.04]),
             ("planar_3rpr.urdf", "platform", [0.01, -0.02, 0.0], [0.0, 0.0, 0.1]),
             ("tsai_3upu.urdf", "platform", [0.01, -0.02, 0.03], [0.0, 0.0, 0.0])]
    for name, link, dx, rpy in moved:
        mech = screwkin.load(ROBOTS / name)
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, mech.neutral())
        home = data.oMf[mech.link_frame(link)]
        yield name, link, pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)) @ home.rotation, home.translation + dx)
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, np.array([0.3, -0.6, 0.4, 0.5, 0.7, -0.2]))
    yield "arm_6r.urdf", "flange", pin.SE3(data.oMf[mech.link_frame("flange")])


def test_closed_form_singularity_measures_are_those_of_the_full_generic_search():
    """The closed form takes the generic ranks at the physical solution and samples near it, without the
    random starts (its branches are all in the closed form): every solution's measures are those
    singular.measures gives with the ranks of the mechanism's own full search (random starts included)."""
    from screwkin.analysis.singular import Generic, measures

    for name, link, pose in _ik_cases():
        mech = screwkin.load(ROBOTS / name)
        res = inverse_kinematics(mech, link, pose)
        assert res.modes.method.startswith("closed form")
        other = screwkin.load(ROBOTS / name)
        full = Generic(other, list(other.actuated), link, configurations=other.generic_configurations()[1])
        for s in res.solutions:
            m = measures(other, s.q, full)
            assert set(m) == set(s.sigmas), name
            for key, v in m.items():
                assert abs(v - s.sigmas[key]) < 1e-12, (name, key)


def test_closed_form_ik_imports_no_more_of_numpy():
    """numpy.random, numpy.ma (numpy.unique's first call) and numpy.fft take 2 to 20 ms each to import: more
    than the closed form itself.  The command's answer (its text and JSON) needs none of them."""
    code = ("import sys, io, contextlib\nfrom screwkin import cli\nnew = set()\n"
            "for argv in %r:\n"
            "    args = cli._parser(argv).parse_args(argv)\n"
            "    mech = cli.load(args.file)\n"
            "    before = set(sys.modules)\n"
            "    with contextlib.redirect_stdout(io.StringIO()):\n"
            "        cli.command_module('ik').run(mech, args)\n"
            "    new |= set(sys.modules) - before\n"
            "print(sorted(m for m in new if m.startswith('numpy')))")
    runs = []
    for name, link, pose in _ik_cases():
        xyz, rpy = pose.translation, pin.rpy.matrixToRpy(pose.rotation)
        text = " ".join(f"{v:.15g}" for v in [*xyz, *rpy])
        runs += [["ik", str(ROBOTS / name), "--output", link, "--pose", text],
                 ["ik", str(ROBOTS / name), "--output", link, "--pose", text, "--json"]]
    root = ROBOTS.parent
    out = subprocess.run([sys.executable, "-c", code % (runs,)], capture_output=True, text=True, cwd=root,
                         env={**os.environ, "PYTHONPATH": str(root)}, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
