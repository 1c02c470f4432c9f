"""Singularities at configurations and along motions, against textbook closed forms."""

import json

import numpy as np
import pytest

import screwkin
from screwkin.present.report import map_csv
from conftest import A, B, C, G, fourbar, planar_3r, slider_crank
from screwkin.cli import main
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import classify
from screwkin.analysis.motion.singular_points import locate_singularities
from screwkin.analysis.motion.sweep import sweep


def load(tmp_path, text, **kw):
    p = tmp_path / "m.urdf"
    p.write_text(text)
    return screwkin.load(p, **kw)


@pytest.mark.parametrize("theta2, singular", [(0.0, True), (np.pi, True), (np.pi / 2, False), (1.0, False)])
def test_planar_3r_elbow(tmp_path, theta2, singular):
    """Planar 3R: det J = l1 l2 sin(theta2): singular at theta2 = 0 and pi, whatever theta1, theta3."""
    mech = load(tmp_path, planar_3r())
    q = np.array([0.4, theta2, -0.7])
    rep = classify(mech, q, inputs=["j1", "j2", "j3"], output="l3")
    assert rep.serial is singular
    assert not rep.actuator and not rep.constraint
    if singular:
        # the lost direction: the end of l2 cannot move along the stretched arm
        assert rep.singular_twists[0].kind == "serial"


def crank_dead_centres():
    """Crank angles where crank and coupler are collinear (|AC| = A + B or B - A), both circuits."""
    out = []
    for dist, sign in ((A + B, 1), (B - A, -1)):
        cos_cad = (dist**2 + G**2 - C**2) / (2 * dist * G)
        for s in (1, -1):
            ang = s * np.arccos(cos_cad)  # angle of AC from AD
            out.append(np.mod(ang + (0 if sign > 0 else np.pi) + np.pi, 2 * np.pi) - np.pi)
    return out


def test_four_bar_output_limits_located_along_a_sweep(tmp_path):
    mech = load(tmp_path, fourbar(), actuated=["crank_joint"])
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", -np.pi, np.pi, 72)
    found = locate_singularities(solver, res, output="rocker")
    assert [f.kind for f in found] == ["serial", "serial"]
    expected = [x - np.pi / 2 for x in crank_dead_centres()]  # crank joint zero is at 90 deg
    for f in found:
        err = min(abs(np.mod(f.input - e + np.pi, 2 * np.pi) - np.pi) for e in expected)
        assert err < 1e-9


def test_four_bar_rocker_input_dead_centre_is_an_actuator_singularity(tmp_path):
    from screwkin.analysis.motion.planar import identify

    mech = load(tmp_path, fourbar(), actuated=["rocker_joint"])
    q = mech.assemble().q
    lo, hi = identify(mech, mech.topology(q), q, "rocker_joint").input_range
    solver = PositionSolver(mech, ["rocker_joint"])
    at = solver.solve({"rocker_joint": lo}).solutions[0]
    rep = classify(mech, at.q, output="crank")
    assert rep.actuator and not rep.constraint
    moving = rep.singular_twists[0].joint_rates
    assert set(moving) == {"crank_joint", "coupler_joint"}
    assert not classify(mech, solver.solve({"rocker_joint": 0.5 * (lo + hi)}).solutions[0].q, output="crank").actuator


def test_slider_crank_dead_centres(tmp_path):
    """Offset slider-crank (a = 0.05, b = 0.15, e = 0.02): the slider stops where crank and
    rod are collinear: crank angles atan2(e, sqrt((b +- a)^2 - e^2)) (+ pi when folded)."""
    a, b, e = 0.05, 0.15, 0.02
    mech = load(tmp_path, slider_crank(a, b, e), actuated=["crank_joint"])
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", -np.pi, np.pi, 90)
    assert res.stopped_at is None
    found = locate_singularities(solver, res, output="slider")
    theta0 = np.radians(60)
    ext = np.arctan2(e, np.sqrt((a + b) ** 2 - e**2))
    fold = np.arctan2(e, np.sqrt((b - a) ** 2 - e**2)) + np.pi
    expected = sorted(np.mod(np.array([ext, fold]) - theta0 + np.pi, 2 * np.pi) - np.pi)
    assert [f.kind for f in found] == ["serial", "serial"]
    np.testing.assert_allclose(sorted(f.input for f in found), expected, atol=1e-9)
    for f in found:
        assert "slider_joint" in classify(mech, f.q, output="slider").stationary_joints


def test_slider_input_at_dead_centre_is_an_actuator_singularity(tmp_path):
    a, b, e = 0.05, 0.15, 0.02
    mech = load(tmp_path, slider_crank(a, b, e), actuated=["slider_joint"])
    x_ext = np.sqrt((a + b) ** 2 - e**2)
    solver = PositionSolver(mech, ["slider_joint"])
    x0 = mech.spec.joints[2].xyz[0]
    at = solver.solve({"slider_joint": x_ext - x0}).solutions[0]
    assert classify(mech, at.q, output="crank").actuator


def test_cli_singularities_json_keys(tmp_path, capsys):
    mech = load(tmp_path, fourbar())
    assert main(["singularities", mech.path, "--actuated", "crank_joint", "--set", "crank_joint=0.3",
                 "--output", "rocker", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert set(d) >= {"serial", "actuator", "constraint", "stationary_joints", "sigma_min", "condition",
                      "singular_twists"}
    assert d["serial"] is False and d["actuator"] is False and d["constraint"] is False


def test_five_bar_map_finds_the_folded_legs(tmp_path):
    """Five-bar (ground pivots (0,0), (0.1,0), proximal 0.1, distal 0.15, motors drawn at 120 and
    60 deg): its serial singularities are where a leg is folded or stretched, |O_i P| = 0.05 or
    0.25 m.  Every grid point the map marks singular (sigma < 10^-2.5) lies next to such a point."""
    from conftest import ROBOTS
    from screwkin.analysis.singularities.maps import singularity_map

    mech = screwkin.load(ROBOTS / "five_bar.urdf")
    solver = PositionSolver(mech)
    m = singularity_map(solver, "motor1", np.linspace(1.2, 2.8, 25), "motor2", np.linspace(-0.6, 1.2, 25),
                        output="distal1")
    assert np.isfinite(m.log_sigma).all()
    marked = np.argwhere(m.log_sigma < -2.5)
    assert len(marked) >= 5
    for j, i in marked:
        t1, t2 = np.radians(120) + m.xs[i], np.radians(60) + m.ys[j]
        data = mech.model.createData()
        import pinocchio as pin

        pin.framesForwardKinematics(mech.model, data, m.q[j, i])  # the assembly mode the map follows
        P = data.oMf[mech.cuts[0].frame1].translation[:2]
        sines = []
        for O, t in (((0.0, 0.0), t1), ((0.1, 0.0), t2)):
            A = np.asarray(O) + 0.1 * np.array([np.cos(t), np.sin(t)])
            u, v = (A - O) / 0.1, (P - A) / np.linalg.norm(P - A)
            sines.append(abs(u[0] * v[1] - u[1] * v[0]))  # |sin| of the elbow angle
        assert min(sines) < 0.05  # a leg folded or stretched, within the grid's resolution
    assert map_csv(m).count("\n") == 25 * 25 + 1


def test_serial_measures_do_not_depend_on_where_the_world_origin_is(tmp_path):
    """The same 6R arm on a base moved 5 m and turned: the same relative singular value,
    condition and manipulability (from the twist of the output frame's origin), and at a
    wrist singularity (theta5 = 0) the lost direction's screw axis moves with the arm."""
    import pinocchio as pin
    from conftest import ROBOTS

    text = (ROBOTS / "arm_6r.urdf").read_text()
    moved = text.replace("<robot name=\"arm_6r\">", "<robot name=\"arm_6r\"><link name=\"world\"/>"
                         "<joint name=\"mount\" type=\"fixed\"><parent link=\"world\"/><child link=\"base\"/>"
                         "<origin xyz=\"5 -3 2\" rpy=\"0.3 -0.2 1.1\"/></joint>", 1)
    assert moved != text
    (tmp_path / "moved.urdf").write_text(moved)
    here, there = screwkin.load(ROBOTS / "arm_6r.urdf"), screwkin.load(tmp_path / "moved.urdf")
    M = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 1.1), np.array([5.0, -3.0, 2.0]))
    for q in (np.array([0.3, -0.5, 0.8, 0.2, 0.7, -0.4]), np.array([0.3, -0.5, 0.8, 0.2, 0.0, -0.4])):
        a = classify(here, q, inputs=[], output="flange", length=0.3)
        b = classify(there, q, inputs=[], output="flange", length=0.3)
        assert a.serial == b.serial
        np.testing.assert_allclose([b.sigmas["serial"], b.manipulability], [a.sigmas["serial"], a.manipulability],
                                   rtol=1e-9, atol=1e-13)
        if a.serial:  # the lost twist's axis, mapped by the base motion
            ta, tb = (np.array(r.singular_twists[0].twist) for r in (a, b))
            moved_twist = M.toActionMatrix() @ ta
            assert min(np.abs(moved_twist - tb).max(), np.abs(moved_twist + tb).max()) < 1e-9
