"""Position, velocity and acceleration analysis against closed forms and finite differences."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import A, B, C, G, fourbar, rocker_angles, world_angles
from screwkin.cli import main
from screwkin.analysis.position.position import PositionSolver

@pytest.fixture
def mech(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    return screwkin.load(p)


@pytest.mark.parametrize("theta_deg", [0, 35, 90, 160, 250])
def test_fourbar_both_circuits_match_the_closed_form(mech, theta_deg):
    theta = np.radians(theta_deg)
    solver = PositionSolver(mech, ["crank_joint"])
    res = solver.solve({"crank_joint": theta - np.pi / 2})  # the crank's joint zero is at 90 deg
    assert len(res.solutions) == 2
    rockers = []
    for s in res.solutions:
        crank, rocker = world_angles(mech, s)
        np.testing.assert_allclose(np.mod(crank - theta + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-12)
        rockers.append(rocker)
        assert s.residual < 1e-10 and not s.singular
    np.testing.assert_allclose(np.sort(rockers), rocker_angles(theta), atol=1e-9)


def test_rates_and_accelerations_against_finite_differences(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    t0, w, alpha, h = 0.3, 2.0, -1.5, 1e-3  # h: truncation O(h^2) against closure noise O(1e-13 / h^2)

    def crank(t):  # crank motion theta(t) = t0 + w t + alpha t^2 / 2
        return t0 + w * t + 0.5 * alpha * t * t

    near = None
    qs = []
    for t in (-h, 0.0, h):
        res = solver.solve({"crank_joint": crank(t)}, near=near)
        qs.append(res.solutions[0].q)
        near = res.solutions[0].joints
    mid = solver.solve({"crank_joint": t0}, near=near, rates={"crank_joint": w}, accels={"crank_joint": alpha})
    s = mid.solutions[0]
    v_fd = pin.difference(mech.model, qs[0], qs[2]) / (2 * h)
    a_fd = (pin.difference(mech.model, qs[1], qs[2]) - pin.difference(mech.model, qs[0], qs[1])) / h**2
    np.testing.assert_allclose(s.qdot, v_fd, atol=1e-6)
    np.testing.assert_allclose(s.qddot, a_fd, atol=2e-5)


def test_unreachable_input_is_reported_not_solved(tmp_path):
    """Non-Grashof four-bar (0.10, 0.07, 0.09, 0.08 would reach; here a coupler
    too short): an input rocker angle beyond its limit cannot be reached."""
    mech = screwkin.load(write(tmp_path, fourbar()))
    solver = PositionSolver(mech, ["rocker_joint"])
    # rocker 0.08 from D=(0.1,0): crank circle radius 0.04 at A=(0,0), coupler 0.12.
    # With the rocker pointing right (angle 0), C = (0.18, 0): |C - A| = 0.18 > 0.04 + 0.12: unreachable.
    rocker_zero = rocker_offset(mech)
    with pytest.raises(screwkin.AssemblyError) as err:
        solver.solve({"rocker_joint": -rocker_zero})
    assert err.value.residual > 1e-3
    assert "cannot be reached" in str(err.value)


def test_limit_position_is_flagged_singular(tmp_path):
    """Driving the rocker to the angle where crank and coupler are collinear
    (|AC| = A + B: a limit of the rocker) gives a double root: flagged."""
    mech = screwkin.load(write(tmp_path, fourbar()))
    solver = PositionSolver(mech, ["rocker_joint"])
    # rocker angle phi with |C - A| = 0.16: (G + C cos phi)^2 + (C sin phi)^2 = 0.16^2
    cos_phi = ((A + B) ** 2 - G**2 - C**2) / (2 * G * C)
    phi = np.arccos(cos_phi)
    res = solver.solve({"rocker_joint": phi - rocker_offset(mech)})
    assert res.solutions and all(s.singular for s in res.solutions)
    generic = solver.solve({"rocker_joint": phi + 0.3 - rocker_offset(mech)})
    assert not any(s.singular for s in generic.solutions)


def write(tmp_path, text):
    p = tmp_path / "m.urdf"
    p.write_text(text)
    return p


def rocker_offset(mech):
    """World angle of the rocker at joint value zero (read from the model)."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    R = data.oMf[mech.link_frame("rocker")].rotation
    return np.arctan2(R[1, 0], R[0, 0])


def test_cli_solve_json_contract(mech, capsys):
    path = mech.path
    assert main(["solve", path, "--set", "crank_joint=20deg", "--rate", "crank_joint=1", "--json",
                 "--output", "rocker"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["inputs"] == {"crank_joint": pytest.approx(np.radians(20))}
    assert len(d["solutions"]) == 2
    for s in d["solutions"]:
        assert set(s) >= {"joints", "residual", "iterations", "singular", "rates", "accelerations"}
        # every coordinate, the loop joint too (issue 24: loop joints are coordinates under their names)
        assert set(s["joints"]) == {"crank_joint", "coupler_joint", "rocker_joint"} | set(s["loop_joints"])
        assert set(s["rates"]) == set(s["joints"]) == set(s["accelerations"])
        assert s["residual"] < 1e-10


def test_cli_trace_prints_iterations(mech, capsys):
    assert main(["solve", mech.path, "--set", "crank_joint=1.0", "--trace"]) == 0
    out = capsys.readouterr().out
    assert "iteration 1:" in out and "dq = [" in out and "K  =" in out


def test_near_selects_one_mode(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    both = solver.solve({"crank_joint": 0.5})
    for s in both.solutions:
        one = solver.solve({"crank_joint": 0.5}, near=s.joints)
        assert len(one.solutions) == 1
        np.testing.assert_allclose(one.solutions[0].joints["rocker_joint"], s.joints["rocker_joint"], atol=1e-9)


def test_track_follows_each_circuit_against_the_closed_form(mech):
    """track: Newton from the previous configuration, one crank degree at a time around a
    full turn, stays on the circuit it starts on (the crank-rocker's circuits never meet)."""
    solver = PositionSolver(mech, ["crank_joint"])
    start = solver.solve({"crank_joint": 0.0})
    for sol in start.solutions:
        q = sol.q
        side = None
        for deg in range(1, 361, 1):
            theta = np.pi / 2 + np.radians(deg)
            a = solver.track({"crank_joint": theta - np.pi / 2}, q)
            assert a.residual < 1e-10
            crank, rocker = world_angles(mech, a)
            np.testing.assert_allclose(np.mod(crank - theta + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-12)
            k = int(np.argmin(np.abs(np.mod(np.array(rocker_angles(theta)) - rocker + np.pi, 2 * np.pi) - np.pi)))
            side = k if side is None else side
            assert k == side  # the same root of the closed form all the way round
            np.testing.assert_allclose(np.mod(rocker - rocker_angles(theta)[k] + np.pi, 2 * np.pi) - np.pi, 0,
                                       atol=1e-9)
            q = a.q


def test_track_refuses_what_it_cannot_reach(tmp_path):
    mech = screwkin.load(write(tmp_path, fourbar()))
    solver = PositionSolver(mech, ["rocker_joint"])
    q = solver.solve({"rocker_joint": 0.0}).solutions[0].q
    with pytest.raises(screwkin.AssemblyError):  # rocker pointing right: C beyond the crank's reach (see above)
        solver.track({"rocker_joint": -rocker_offset(mech)}, q)
    with pytest.raises(screwkin.UsageError, match="not inputs: crank_joint"):
        solver.track({"crank_joint": 0.1}, q)


def test_outside_limits_compares_angles_modulo_a_turn(tmp_path):
    from conftest import LINK
    from screwkin.model.limits import outside_limits

    body = "".join(LINK.format(n=n) for n in ("a", "b", "c"))
    body += ('<joint name="r" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
             '<limit lower="1" upper="3" effort="1" velocity="1"/></joint>'
             '<joint name="p" type="prismatic"><parent link="b"/><child link="c"/><axis xyz="1 0 0"/>'
             '<limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>')
    mech = screwkin.load(write(tmp_path, f'<robot name="lim">{body}</robot>'))
    assert outside_limits(mech, np.array([2.0, 0.0])) == ()
    assert outside_limits(mech, np.array([2.0 - 2 * np.pi, 0.0])) == ()  # the same angle, a turn less
    assert outside_limits(mech, np.array([3.5, 0.0])) == ("r",)  # 3.5 - 2 pi = -2.8: outside either way
    assert outside_limits(mech, np.array([2.0, 0.5 + 2 * np.pi])) == ("p",)  # a length has no turns
