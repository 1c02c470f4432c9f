"""The kinematic state (model/state.py) and what solve reports from it: loop-joint coordinates and
absolute link motion, against closed forms written here (issue 24 items 1-2, issue 23 item 1).

* offset slider-crank closed by a prismatic <loop_joint> (docs/format.md's example, its guide
  moved off the crank pivot): x = a cos t + sqrt(b^2 - (e - a sin t)^2), and its derivatives by sympy;
* four-bar: positions by circle intersection, omega_3, omega_4 and alpha_3, alpha_4 from the
  derivatives of the vector loop a e^(i t2) + b e^(i t3) - c e^(i t4) - d = 0 solved by hand (2x2).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

from conftest import ROBOTS, circles
from screwkin import load
from screwkin.analysis.position import PositionSolver
from screwkin.cli import main
from screwkin.model.state import KinematicState

A_X, A_Y = 0.03, 0.04  # crank O -> A as written
B_REL = (0.12, -0.04)  # rod A -> B as written
E = 0.02  # the guide: the line y = E (its F1 on the ground at (0, E))

SLIDER = f"""<?xml version="1.0"?>
<robot name="slider_crank">
  <link name="ground"/> <link name="crank"/> <link name="rod"/> <link name="slider"/>
  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="pin_A" type="continuous"><parent link="crank"/><child link="rod"/>
    <origin xyz="{A_X} {A_Y} 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="pin_B" type="continuous"><parent link="rod"/><child link="slider"/>
    <origin xyz="{B_REL[0]} {B_REL[1]} 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>
  <loop_joint name="guide" type="prismatic">
    <link1 link="ground" xyz="0 {E} 0"/>
    <link2 link="slider" xyz="0 0 0"/>
    <axis xyz="1 0 0"/>
  </loop_joint>
</robot>
"""


def _slider_closed_form():
    t, w = sp.symbols("t w", real=True)
    a, b = sp.sqrt(A_X**2 + A_Y**2), sp.sqrt(B_REL[0] ** 2 + B_REL[1] ** 2)
    T = sp.Function("T")(sp.Symbol("tau"))
    x = a * sp.cos(T) + sp.sqrt(b**2 - (E - a * sp.sin(T)) ** 2)
    phi = sp.atan2(E - a * sp.sin(T), x - a * sp.cos(T))  # the rod's absolute angle, A -> B
    tau = sp.Symbol("tau")

    def derivatives(f):
        f1 = sp.diff(f, tau)
        f2 = sp.diff(f1, tau)
        sub = {sp.Derivative(T, (tau, 2)): 0, sp.Derivative(T, tau): w}
        return [sp.lambdify((t, w), g.subs(sub).subs(T, t)) for g in (f, f1, f2)]

    return derivatives(x), derivatives(phi)


@pytest.mark.parametrize("theta_deg", [20.0, 75.0, 140.0, 250.0])
def test_slider_position_rate_and_acceleration_of_a_prismatic_loop_joint(theta_deg, tmp_path):
    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    mech = load(str(path))
    theta0 = np.arctan2(A_Y, A_X)  # the crank's absolute angle as written
    theta, omega = np.radians(theta_deg), 7.0
    res = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": theta - theta0}, rates={"crank_joint": omega})
    (x, xd, xdd), (phi, phid, phidd) = _slider_closed_form()
    sol = max(res.solutions, key=lambda s: s.loop_joints["guide"])  # the slider to the right of the crank
    assert sol.loop_joints["guide"] == pytest.approx(x(theta, omega), abs=1e-10)
    assert sol.loop_rates["guide"] == pytest.approx(xd(theta, omega), abs=1e-9)
    assert sol.loop_accelerations["guide"] == pytest.approx(xdd(theta, omega), abs=1e-8)
    rod = sol.links["rod"]
    assert np.mod(rod["angle"] - phi(theta, omega) + np.pi, 2 * np.pi) - np.pi == pytest.approx(0, abs=1e-10)
    assert rod["omega"] == pytest.approx(phid(theta, omega), abs=1e-9)
    assert rod["alpha"] == pytest.approx(phidd(theta, omega), abs=1e-8)
    # the slider translates: no rotation; its origin (the pin B) moves along the guide at x'
    assert sol.links["slider"]["omega"] == pytest.approx(0, abs=1e-12)
    assert sol.links["slider"]["velocity"] == pytest.approx([xd(theta, omega), 0, 0], abs=1e-9)
    assert sol.links["crank"]["omega"] == pytest.approx(omega, abs=1e-12)


def _fourbar_rates(a, b, c, t2, t3, t4, w2):
    """omega_3, omega_4, alpha_3, alpha_4 of a e2 + b e3 - c e4 - d = 0 (alpha_2 = 0), by hand."""
    J = np.array([[-b * np.sin(t3), c * np.sin(t4)], [b * np.cos(t3), -c * np.cos(t4)]])
    w3, w4 = np.linalg.solve(J, [a * w2 * np.sin(t2), -a * w2 * np.cos(t2)])
    rhs = (a * w2**2 * np.array([np.cos(t2), np.sin(t2)]) + b * w3**2 * np.array([np.cos(t3), np.sin(t3)])
           - c * w4**2 * np.array([np.cos(t4), np.sin(t4)]))
    a3, a4 = np.linalg.solve(J, rhs)
    return w3, w4, a3, a4


@pytest.mark.parametrize("crank_deg", [10.0, 95.0, 200.0, 300.0])
def test_four_bar_absolute_omega_and_alpha_against_the_vector_loop(crank_deg):
    a, b, c, d = 0.04, 0.12, 0.08, 0.1  # robots/fourbar_crank_rocker.urdf: crank, coupler, rocker, ground
    mech = load(str(ROBOTS / "fourbar_crank_rocker.urdf"))
    solver = PositionSolver(mech, ["crank_joint"])
    t0 = solver.solve({"crank_joint": 0.0}).solutions[0].link_angles["crank"]  # crank's angle at joint value 0
    t2, w2 = np.radians(crank_deg), 3.0
    res = solver.solve({"crank_joint": t2 - t0}, rates={"crank_joint": w2})
    B, D = a * np.array([np.cos(t2), np.sin(t2)]), np.array([d, 0.0])
    for sol in res.solutions:
        t3, t4 = sol.links["coupler"]["angle"], sol.links["rocker"]["angle"]
        C = B + b * np.array([np.cos(t3), np.sin(t3)])
        assert min(np.linalg.norm(C - P) for P in circles(B, b, D, c)) < 1e-10  # a closed-form position
        assert np.linalg.norm(C - D - c * np.array([np.cos(t4), np.sin(t4)])) < 1e-10
        w3, w4, a3, a4 = _fourbar_rates(a, b, c, t2, t3, t4, w2)
        assert sol.links["coupler"]["omega"] == pytest.approx(w3, abs=1e-9)
        assert sol.links["rocker"]["omega"] == pytest.approx(w4, abs=1e-9)
        assert sol.links["coupler"]["alpha"] == pytest.approx(a3, abs=1e-8)
        assert sol.links["rocker"]["alpha"] == pytest.approx(a4, abs=1e-8)
        # the revolute loop joint C (F1 on the coupler, F2 on the rocker): its rate is omega_4 - omega_3
        assert sol.loop_rates["coupler_rocker"] == pytest.approx(w4 - w3, abs=1e-9)


def test_a_state_owns_its_data_and_points_move_rigidly():
    """Two states of one mechanism do not disturb each other (their own Data); a point's velocity
    is the central difference of its positions along the motion."""
    mech = load(str(ROBOTS / "fourbar_crank_rocker.urdf"))
    solver = PositionSolver(mech, ["crank_joint"])
    h, w2 = 1e-6, 1.0
    sols = [solver.solve({"crank_joint": 0.7 + k * h}, rates={"crank_joint": w2}).solutions[0] for k in (-1, 0, 1)]
    states = [KinematicState(mech, s.q, s.qdot, s.qddot) for s in sols]
    local = (0.05, 0.02, 0.0)  # a coupler point off the line of centres
    p = [st.point("coupler", local).position for st in states]
    mid = states[1].point("coupler", local)
    assert mid.velocity == pytest.approx((p[2] - p[0]) / (2 * h), abs=1e-6)
    assert mid.acceleration == pytest.approx((p[2] - 2 * p[1] + p[0]) / h**2, abs=2e-3)
    assert states[0].point("coupler", local).position == pytest.approx(p[0], abs=0)  # unchanged by the others


def test_solve_json_and_text_report_loop_joints_and_links(tmp_path, capsys):
    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    assert main(["solve", str(path), "--set", "crank_joint=30deg", "--rate", "crank_joint=10", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    sol = d["solutions"][0]
    assert set(sol["loop_joints"]) == {"guide"} and set(sol["loop_rates"]) == {"guide"}
    assert set(sol["links"]) == {"crank", "rod", "slider"}
    assert set(sol["links"]["rod"]) == {"position", "velocity", "acceleration", "omega", "alpha", "angle"}
    assert main(["solve", str(path), "--set", "crank_joint=30deg", "--rate", "crank_joint=10"]) == 0
    out = capsys.readouterr().out
    assert "guide (loop)" in out and "absolute link motion" in out and "omega [rad/s]" in out
