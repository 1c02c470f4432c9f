"""Velocity and force ellipsoids (issue 15 part 4) against closed forms.

singularities --ellipsoids: the numbers of screwkin.analysis.singularities.ellipsoids on the command line,
checked on a planar 2R arm against the singular values of its closed-form Jacobian."""

import json
import math

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ARM, LINK, ROBOTS, fourbar, rev, screwkin_cli
from screwkin.analysis.singularities.ellipsoids import ellipsoids, ellipsoids_of
from screwkin.analysis.position.position import PositionSolver
from screwkin.errors import UsageError

L1, L2 = 0.3, 0.2


def arm_2r(tmp_path):
    body = "".join(LINK.format(n=n) for n in ("base", "l1", "l2", "tip"))
    body += rev("j1", "base", "l1") + rev("j2", "l1", "l2", xyz=f"{L1} 0 0")
    body += f'<joint name="tip_weld" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="{L2} 0 0"/></joint>'
    path = tmp_path / "arm_2r.urdf"
    path.write_text(f'<robot name="arm_2r">{body}</robot>')
    return screwkin.load(path)


def closed_form(t1, t2):
    """The planar 2R arm's tip Jacobian (vx, vy) over (t1', t2')."""
    s1, c1, s12, c12 = math.sin(t1), math.cos(t1), math.sin(t1 + t2), math.cos(t1 + t2)
    return np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])


@pytest.mark.parametrize("t1, t2", [(0.3, 0.9), (-1.2, 2.0), (0.0, 0.4)])
def test_planar_2r_arm_tip_ellipsoids_match_the_closed_form(tmp_path, t1, t2):
    arm = arm_2r(tmp_path)
    q = np.array([t1, t2])
    Jc = closed_form(t1, t2)
    U, s, _ = np.linalg.svd(Jc)
    for length in (1.0, None):
        e = ellipsoids(arm, q, "tip", point=True, length=length)
        L = length or arm.length
        assert e.length == pytest.approx(L) and e.inputs == ("j1", "j2") and e.rank == 2
        np.testing.assert_allclose(e.velocity.semi_axes[:2], s / L, rtol=1e-12)
        assert e.velocity.semi_axes[2] == 0.0  # no velocity along z
        np.testing.assert_allclose(e.force.semi_axes[:2], L / s, rtol=1e-12)  # reciprocal
        assert e.force.semi_axes[2] == math.inf
        for k in range(2):  # same principal axes (up to sign), in the plane
            axis = e.velocity.axes[:, k]
            assert abs(axis[:2] @ U[:, k]) == pytest.approx(1.0, abs=1e-12) and abs(axis[2]) < 1e-12
            np.testing.assert_array_equal(e.force.axes[:, k], axis)
    # the full twist: wz = t1' + t2' adds a row, the pure function gives the same as the mechanism's
    full = ellipsoids(arm, q, "tip", length=0.5)
    J6 = np.zeros((6, 2))
    J6[:2] = Jc
    J6[5] = 1.0
    ref = ellipsoids_of(J6, length=0.5)
    np.testing.assert_allclose(full.velocity.semi_axes, ref.velocity.semi_axes, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(full.jacobian, ref.jacobian, atol=1e-14)


@pytest.fixture
def four_bar(tmp_path):
    path = tmp_path / "fourbar.urdf"
    path.write_text(fourbar())
    return screwkin.load(path)


def test_closed_loop_ellipsoid_is_the_rate_map_through_the_loop(four_bar):
    # one input (the crank): the velocity ellipsoid of the coupler's twist (v / L, w) is a segment
    # along it, of half-length |(v / L, w)| per unit crank rate; the twist by finite differences
    # of the closed-loop poses (the coupler turns at a rate the loop sets), independent of K q' = 0
    mech = four_bar
    solver = PositionSolver(mech, ["crank_joint"])
    q0 = solver.solve({"crank_joint": 1.2}).solutions[0].q
    e = ellipsoids(mech, q0, "coupler", inputs=["crank_joint"])
    h = 1e-6
    fid = mech.link_frame("coupler")
    poses = []
    for value in (1.2 + h, 1.2 - h):
        q = solver.track({"crank_joint": value}, q0).q
        pin.framesForwardKinematics(mech.model, mech.data, q)
        poses.append(mech.data.oMf[fid].copy())
    v = (poses[0].translation - poses[1].translation) / (2 * h)
    w = pin.log3(poses[0].rotation @ poses[1].rotation.T) / (2 * h)
    assert abs(w[2]) > 0.1 and abs(w[2] - 1.0) > 0.1  # the coupler turns, not with the crank
    t = np.concatenate([v / mech.length, w])
    assert e.rank == 1
    assert e.velocity.semi_axes[0] == pytest.approx(np.linalg.norm(t), rel=1e-6)
    assert abs(e.velocity.axes[:, 0] @ t / np.linalg.norm(t)) == pytest.approx(1.0, abs=1e-6)
    assert e.force.semi_axes[0] == pytest.approx(1 / np.linalg.norm(t), rel=1e-6)
    assert np.all(e.velocity.semi_axes[1:] == 0) and np.all(np.isinf(e.force.semi_axes[1:]))


def test_an_open_configuration_and_unknown_inputs_are_refused(four_bar):
    with pytest.raises(UsageError, match="does not close the loops"):
        ellipsoids(four_bar, four_bar.neutral() + 0.3, "coupler", inputs=["crank_joint"])
    q = PositionSolver(four_bar, ["crank_joint"]).solve({"crank_joint": 1.0}).solutions[0].q
    with pytest.raises(UsageError, match="no moving joint named"):
        ellipsoids(four_bar, q, "coupler", inputs=["nothing"])


# ---------------------------------------------------------------- folded in from test_ellipsoids_cli.py


def test_planar_2r_point_ellipsoid_against_closed_form(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    t1, t2 = 0.3, 1.1
    out = screwkin_cli("singularities", str(path), "--set", f"shoulder={t1}", "--set", f"elbow={t2}", "--output", "hand",
              "--point", "--ellipsoids", "--length", "0.5", "--json")
    assert out.returncode == 0, out.stderr
    e = json.loads(out.stdout)["ellipsoids"]
    l1, l2, L = 0.4, 0.25, 0.5
    J = np.array([[-l1 * np.sin(t1) - l2 * np.sin(t1 + t2), -l2 * np.sin(t1 + t2)],
                  [l1 * np.cos(t1) + l2 * np.cos(t1 + t2), l2 * np.cos(t1 + t2)]]) / L
    s = np.linalg.svd(J, compute_uv=False)
    assert e["rank"] == 2
    assert np.allclose(sorted(e["velocity_semi_axes"])[-2:], sorted(s), rtol=1e-9)
    finite = [f for f in e["force_semi_axes"] if f != "inf"]  # the z direction loads no input: "inf"
    assert e["force_semi_axes"].count("inf") == 1
    assert np.allclose(sorted(finite), sorted(1 / s), rtol=1e-9)
    assert e["isotropy"] == pytest.approx(0.0)  # the z direction is not reached: rank 2 of 3
    text = screwkin_cli("singularities", str(path), "--set", f"shoulder={t1}", "--set", f"elbow={t2}", "--output", "hand",
               "--point", "--ellipsoids", "--length", "0.5")
    assert "velocity and force ellipsoids" in text.stdout and "inf" in text.stdout


def test_ellipsoids_need_an_output():
    out = screwkin_cli("singularities", str(ROBOTS / "gough_stewart_6ups.urdf"), "--ellipsoids")
    assert out.returncode == 2 and "--output" in out.stderr and len(out.stderr.strip().splitlines()) == 1
