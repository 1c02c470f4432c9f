"""analysis.singularities.mode_connect on the five-bar (robots/five_bar.urdf), whose two assembly modes at
given motor angles are the two intersections of the distal circles: det K_p of opposite signs (the tip on
either side of the line of the elbows, by Pinocchio's placements), and the path check refusing a path that
jumps from one mode to the other while passing one that moves the motors by small steps."""

import numpy as np
import pinocchio as pin
from conftest import ROBOTS

import screwkin
from screwkin.analysis.singularities.mode_connect import check_path, connect_modes


def _five_bar():
    mech = screwkin.load(ROBOTS / "five_bar.urdf")
    solver = screwkin.PositionSolver(mech)
    values = {"motor1": 0.3, "motor2": -0.2}
    res = solver.solve(values, method="auto")
    return mech, solver, values, [s.q for s in res.solutions]


def test_five_bar_modes_are_proved_apart_by_det_signs():
    mech, solver, values, qs = _five_bar()
    assert len(qs) == 2
    conns = connect_modes(solver, values, qs)
    assert sorted(conns.signs) == [-1, 1]
    (c,) = conns.connections
    assert c.modes == (0, 1) and not c.joined and c.proved and c.path is None
    data = mech.model.createData()
    sides = []
    for q in qs:
        pin.framesForwardKinematics(mech.model, data, q)
        B1, B2, P = (data.oMf[mech.model.getFrameId(n)].translation[:2] for n in ("distal1", "distal2", "tip"))
        e, f = B2 - B1, P - B1
        sides.append(np.sign(e[0] * f[1] - e[1] * f[0]))
    assert sides[0] == -sides[1]
    # the sign follows the side: the same product for both modes
    assert conns.signs[0] * sides[0] == conns.signs[1] * sides[1]


def test_the_path_check_refuses_a_jump_and_passes_small_steps():
    mech, solver, values, qs = _five_bar()
    plane = ("motor1", "motor2")
    xy = np.array([[values["motor1"], values["motor2"]]] * 2)
    ok, _, why = check_path(solver, plane, {}, xy, np.array(qs))
    assert not ok and "jumps" in why
    steps = np.column_stack([np.linspace(0.3, 0.35, 26), np.full(26, -0.2)])
    Q = [qs[0]]
    for x, y in steps[1:]:
        Q.append(solver.track({"motor1": x, "motor2": y}, Q[-1]).q)
    ok, smallest, why = check_path(solver, plane, {}, steps, np.array(Q))
    assert ok, why
    assert 1e-4 < smallest <= 1.0
    bad = steps.copy()
    bad[5, 0] += 1e-3  # an input off its value
    ok, _, why = check_path(solver, plane, {}, bad, np.array(Q))
    assert not ok and "motor1" in why
