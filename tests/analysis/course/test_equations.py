"""screwkin equations and solve --start: the vector-loop equations in symbols checked against
numbers that do not come from them -- finite differences of the link angles along screwkin's
own solutions (PositionSolver.track), the limit positions the sweep locates, and a Newton step
computed by hand in this file."""

import json
from pathlib import Path

import numpy as np
import pytest
import sympy

from screwkin.analysis.course.equations import equations
from screwkin.analysis.course.vector_loops import VectorLoops
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main
from screwkin.model.loader import load

ROBOTS = Path(__file__).resolve().parents[3] / "robots"
PLANAR = ["fourbar_crank_rocker", "fourbar_non_grashof", "slider_crank_offset", "five_bar", "watt_sixbar",
          "stephenson_sixbar", "planar_3rrr", "planar_3rpr"]
_BUILT = {}


def built(name):
    if name not in _BUILT:
        mech = load(str(ROBOTS / f"{name}.urdf"))
        q = mech.assemble().q
        _BUILT[name] = (mech, q, VectorLoops(mech, q))
    return _BUILT[name]


def evaluate(text, values):
    """A string of the JSON (sympy syntax) evaluated at the symbol values."""
    expr = sympy.sympify(text)
    return float(expr.subs({sympy.Symbol(k): v for k, v in values.items()}))


def all_values(vl, q):
    out = {n: s.value for n, s in vl.symbol_info.items() if s.role == "constant"}
    out.update(vl.values(q))
    return out


def wrapped(d):
    return np.mod(d + np.pi, 2 * np.pi) - np.pi


@pytest.mark.parametrize("name", PLANAR)
def test_equations_close_and_their_matrices_are_the_numerical_jacobians(name):
    mech, q, vl = built(name)
    res = vl.result()
    vals = all_values(vl, q)
    # the loop equations (strings) vanish at the assembled configuration
    for loop in res.loops:
        for e in loop.equations:
            assert abs(evaluate(e, vals)) < 1e-12
    # A and B as strings evaluate to the numbers the command prints
    A = np.array([[evaluate(e, vals) for e in row] for row in res.A])
    B = np.array([[evaluate(e, vals) for e in row] for row in res.B])
    assert np.allclose(A, res.A_value, atol=1e-14) and np.allclose(B, res.B_value, atol=1e-14)
    assert evaluate(res.det_A, vals) == pytest.approx(np.linalg.det(A), rel=1e-9, abs=1e-16)
    # A dz/dq_j = B dw/dq_j, with dz/dq_j by central differences of screwkin's own solutions
    solver = PositionSolver(mech, list(res.input_joints[n][0] for n in res.inputs))
    h = 1e-6
    for k, sym in enumerate(res.inputs):
        joint, sigma = res.input_joints[sym]
        v0 = solver.joint_values(q)[joint]
        plus = vl.values(solver.track({joint: v0 + h}, q).q)
        minus = vl.values(solver.track({joint: v0 - h}, q).q)
        diff = {n: (wrapped(plus[n] - minus[n]) if vl.symbol_info[n].kind == "angle" else plus[n] - minus[n]) / (2 * h)
                for n in plus}
        dz = np.array([diff[n] for n in res.unknowns])
        dw = np.array([diff[n] for n in res.inputs])
        assert dw == pytest.approx(sigma * np.eye(len(res.inputs))[k], abs=1e-6)
        assert A @ dz == pytest.approx(B @ dw, abs=1e-7 * max(1.0, np.abs(B).max())), (name, joint)
        assert res.rates[:, k] * sigma == pytest.approx(dz, rel=1e-5, abs=1e-7)


@pytest.mark.parametrize("name", ["fourbar_crank_rocker", "slider_crank_offset", "watt_sixbar"])
def test_acceleration_terms_against_second_differences(name):
    mech, q, vl = built(name)
    res = vl.result()
    joint, sigma = res.input_joints[res.inputs[0]]
    solver = PositionSolver(mech, [joint])
    v0 = solver.joint_values(q)[joint]
    h = 1e-4
    at = {s: vl.values(solver.track({joint: v0 + s * h}, q).q) for s in (-1, 1)}
    mid = vl.values(q)

    def d(n, a, b):
        x = at[a][n] - (mid[n] if b == 0 else at[b][n])
        return wrapped(x) if vl.symbol_info[n].kind == "angle" else x

    # input turning at unit joint rate, no input acceleration: w' = sigma, w'' = 0
    zd = np.array([(d(n, 1, -1)) / (2 * h) for n in res.unknowns])
    zdd = np.array([(d(n, 1, 0) + d(n, -1, 0)) / h ** 2 for n in res.unknowns])
    c = vl.acceleration_terms(mid, zd, [sigma])
    assert res.A_value @ zdd == pytest.approx(c, rel=1e-5, abs=1e-8)
    # and the same c from the JSON strings
    vals = {**all_values(vl, q), **{f"{n}_d": v for n, v in zip(res.unknowns, zd, strict=True)}, f"{res.inputs[0]}_d": sigma}
    assert [evaluate(e, vals) for e in res.acceleration_terms] == pytest.approx(c, rel=1e-12, abs=1e-15)


def test_four_bar_equations_are_the_textbook_ones():
    mech, q, vl = built("fourbar_crank_rocker")
    res = vl.result()
    assert res.unknowns == ("theta3", "theta4") and res.inputs == ("theta2",)
    assert sympy.simplify(sympy.sympify(res.det_A) - sympy.sympify("r3*r4*sin(theta3 - theta4)")) == 0
    assert res.singular_conditions == ("sin(theta3 - theta4) = 0: theta3 = theta4 or theta4 + pi",)
    # the angles are solve's link_angles, the lengths the file's (comment: crank 0.04, coupler 0.12, rocker 0.08)
    angles = PositionSolver(mech)._link_angles(q)
    for n in ("theta2", "theta3", "theta4"):
        s = res.symbols[n]
        assert s.value == pytest.approx(angles[s.link], abs=1e-12)
    assert [res.symbols[n].value for n in ("r2", "r3", "r4", "r1")] == pytest.approx([0.04, 0.12, 0.08, 0.1])


def test_det_A_vanishes_at_the_limit_positions_the_sweep_locates():
    mech, q, vl = built("fourbar_non_grashof")
    solver = PositionSolver(mech)
    joint = mech.actuated[0]
    v0 = solver.joint_values(q)[joint]
    res = sweep(solver, joint, v0, v0 + 2 * np.pi, 200)
    assert res.limits, "a triple rocker's input meets a limit position"
    r = vl.result()
    scale = r.symbols["r3"].value * r.symbols["r4"].value
    for lim in res.limits:
        A, _ = vl.matrices(vl.values(lim.q))
        assert abs(np.linalg.det(A)) < 1e-6 * scale
        vals = all_values(vl, lim.q)
        assert abs(evaluate(r.det_A, vals)) < 1e-6 * scale
    # away from it det A is not small
    assert abs(r.det_A_value) > 1e-2 * scale


def test_slider_crank_dead_centre_condition():
    """det A = r3 cos(theta3): zero where the rod stands perpendicular to the slide, i.e. at
    theta2 = +-90 deg when the offset is zero -- evaluated at the solved configuration there."""
    mech, q, vl = built("slider_crank_offset")
    r = vl.result()
    assert sympy.simplify(sympy.sympify(r.det_A) - sympy.sympify("r3*cos(theta3)")) == 0
    e, r2, r3 = (r.symbols[n].value for n in ("e4", "r2", "r3"))
    # cos(theta3) = 0 with r2 sin(theta2) + r3 sin(theta3) = e: sin(theta2) = (e - r3) / r2 only if |.| <= 1
    assert abs((e - r3) / r2) > 1 and abs((e + r3) / r2) > 1  # this crank never reaches it: det A never 0
    assert abs(r.det_A_value) > 0.5 * r3


SLIDER_CRANK = """<?xml version="1.0"?>
<!-- slider-crank: crank 0.1 m, rod 0.2 m, slide on the x axis through the crank pivot; drawn at
     theta2 = 60 deg: A = (0.05, 0.0866), B = (0.05 + 0.2 cos(theta3), 0) with sin(theta3) = -0.1 sin 60 / 0.2 -->
<robot name="slider_crank_course">
  <link name="ground"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="crank"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="rod"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="slider"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="rod_joint" type="continuous"><parent link="crank"/><child link="rod"/>
    <origin xyz="{ax} {ay} 0"/><axis xyz="0 0 1"/></joint>
  <joint name="slider_joint" type="prismatic"><parent link="ground"/><child link="slider"/>
    <origin xyz="{bx} 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <loop_joint name="rod_slider" type="revolute">
    <link1 link="rod" xyz="{rx} {ry} 0"/><link2 link="slider" xyz="0 0 0"/><axis xyz="0 0 1"/></loop_joint>
  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>
    <joint name="crank_joint"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>
</robot>
"""


@pytest.fixture
def course_file(tmp_path):
    a, b, t2 = 0.1, 0.2, np.radians(60)
    A = a * np.array([np.cos(t2), np.sin(t2)])
    t3 = -np.arcsin(A[1] / b)
    B = A + b * np.array([np.cos(t3), np.sin(t3)])
    path = tmp_path / "slider_crank_course.urdf"
    path.write_text(SLIDER_CRANK.format(ax=A[0], ay=A[1], bx=B[0], rx=B[0] - A[0], ry=B[1] - A[1]))
    return str(path)


def run_cli(args, capsys):
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_one_newton_step_from_the_course_estimates_is_the_hand_computation(course_file, capsys):
    code, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start",
                              "theta3=65deg,x4=0.15", "--iterations", "1", "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    # by hand: r2 + r3 - x4 = 0 with r2 = 0.1, r3 = 0.2 along x: F = (r2 cos t2 + r3 cos t3 - x4, r2 sin t2 + r3 sin t3)
    t2, t3, x4, r2, r3 = np.radians(60), np.radians(65), 0.15, 0.1, 0.2
    F = np.array([r2 * np.cos(t2) + r3 * np.cos(t3) - x4, r2 * np.sin(t2) + r3 * np.sin(t3)])
    J = np.array([[-r3 * np.sin(t3), -1.0], [r3 * np.cos(t3), 0.0]])
    step = np.linalg.solve(J, -F)
    (it,) = d["trace"]
    assert it["residual"] == pytest.approx(F.tolist(), abs=1e-12)
    assert np.allclose(it["jacobian"], J, atol=1e-12, rtol=0)
    assert it["step"] == pytest.approx(step.tolist(), abs=1e-12)
    assert it["values"]["theta3"] == pytest.approx(t3 + step[0], abs=1e-12)
    assert it["values"]["x4"] == pytest.approx(x4 + step[1], abs=1e-12)
    # the y row alone gives d theta3 = -(r2 sin t2 + r3 sin t3) / (r3 cos t3) = -3.1691 rad = -181.58 deg
    assert np.degrees(step[0]) == pytest.approx(-181.576, abs=1e-3)
    assert d["closes"] is False and d["converged"] is False
    # the text says so too: an iterate is never presented as a solution
    code, out, _ = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start",
                            "theta3=65deg,x4=150mm", "--iterations", "1"], capsys)
    assert code == 0 and "do NOT close the loops" in out and "-181.576 deg" in out and "mm" in out


def test_newton_to_convergence_reports_the_assembled_solution(course_file, capsys):
    code, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start",
                              "rod=-20deg,x4=0.2", "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    t3 = -np.arcsin(0.1 * np.sin(np.radians(60)) / 0.2)
    assert d["newton"]["closes"] and d["newton"]["converged"]
    assert d["newton"]["values"]["theta3"] == pytest.approx(t3, abs=1e-9)
    assert d["newton"]["values"]["x4"] == pytest.approx(0.05 + 0.2 * np.cos(t3), abs=1e-9)
    (sol,) = d["solutions"]
    assert sol["residual"] < 1e-10
    assert sol["link_angles"]["rod"] == pytest.approx(t3, abs=1e-9)
    # the other assembly mode from an estimate near it (theta3 = 180 deg - t3)
    code, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start",
                              "theta3=200deg,x4=-0.1"], capsys)
    assert code == 0, err
    assert "solution 1" in out and "Newton on the vector-loop equations" in out


def test_start_from_joint_values(course_file, capsys):
    code, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start",
                              "rod_joint=-80deg,slider_joint=0", "--iterations", "2", "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    assert len(d["trace"]) == 2
    # rod_joint turns the rod from where the file draws it (theta3 = -asin(0.1 sin 60 / 0.2)), the crank held
    drawn = -np.arcsin(0.1 * np.sin(np.radians(60)) / 0.2)
    assert d["start"]["theta3"] == pytest.approx(drawn - np.radians(80), abs=1e-9)
    # slider_joint = 0: the slider where the file draws it, x4 = 0.05 + 0.2 cos(theta3)
    assert d["start"]["x4"] == pytest.approx(0.05 + 0.2 * np.cos(drawn), abs=1e-9)


@pytest.mark.parametrize("args,code,words", [
    (["--start", "theta9=1"], 2, "no unknown, link or joint named 'theta9'"),
    (["--start", "theta3=65deg"], 2, "no estimate of x4"),
    (["--start", "crank_joint=1"], 2, "is an input"),
    (["--iterations", "1"], 2, "--iterations needs --start"),
    (["--start", "theta3=65deg,x4=0.15", "--iterations", "0"], 2, "--iterations must be 1 or more"),
])
def test_bad_starts_are_one_line_usage_errors(course_file, capsys, args, code, words):
    got, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", *args], capsys)
    assert got == code and words in err and _error_lines(err) == 1 and "Traceback" not in err


def test_newton_that_does_not_converge_is_an_error_not_a_solution(course_file, capsys):
    # theta3 = 90 deg: A = [[-r3, -1], [0, 0]] is singular at the first iteration
    got, out, err = run_cli(["solve", course_file, "--set-angle", "crank=60deg", "--start", "theta3=90deg,x4=0.1"],
                            capsys)
    assert got == 1 and "did not converge" in err and "singular" in err and err.count("\n") == 1


def test_equations_json_contract(capsys):
    code, out, err = run_cli(["equations", str(ROBOTS / "slider_crank_offset.urdf"), "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    for key in ("loops", "symbols", "unknowns", "velocity_matrix_A", "velocity_matrix_B", "det_A",
                "singular_conditions"):
        assert key in d
    assert d["unknowns"] == ["theta3", "x4"]
    assert d["symbols"]["theta3"] == {**d["symbols"]["theta3"], "link": "rod", "kind": "angle", "role": "unknown"}
    assert d["symbols"]["x4"]["kind"] == "slider" and d["symbols"]["r3"]["value"] == pytest.approx(0.15)
    assert d["symbols"]["e4"]["value"] == pytest.approx(0.02)
    # every constant has its value; the CLI's numbers are the Python API's
    mech, q, vl = built("slider_crank_offset")
    assert np.allclose(d["at_configuration"]["A"], vl.result().A_value)
    vals = {n: s["value"] for n, s in d["symbols"].items()}
    A = np.array([[evaluate(e, vals) for e in row] for row in d["velocity_matrix_A"]])
    assert np.allclose(A, d["at_configuration"]["A"], atol=1e-14)
    assert d["singular_conditions"] == ["cos(theta3) = 0: theta3 = pi/2 or -pi/2"]


def test_equations_at_set_inputs_and_the_text(capsys):
    code, out, err = run_cli(["equations", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=30deg"],
                             capsys)
    assert code == 0, err
    assert "sin(θ3 - θ4) = 0: θ3 = θ4 or θ4 + π" in out and "unknowns: θ3, θ4" in out


def test_spatial_mechanisms_get_the_structure_equations(capsys):
    code, out, err = run_cli(["equations", str(ROBOTS / "bennett.urdf"), "--json"], capsys)
    assert code == 0, err
    d = json.loads(out)
    assert d["motion_space"] == "spatial" and d["chains"]
    K = d["constraint_jacobian"]
    assert K["rank"] == K["generic_rank"] and K["singular"] is False
    mech = load(str(ROBOTS / "bennett.urdf"))
    res = equations(mech, mech.assemble().q)
    assert res.rows == len(mech.closure.jacobian(mech.assemble().q))


@pytest.mark.parametrize("robot,code,words", [
    ("cam_followers", 1, "is a contact pair"),
    ("quick_return_slot", 1, "is a contact pair"),
    ("gripper_arm_mimic", 1, "<mimic>"),
])
def test_planar_mechanisms_beyond_the_vector_loops_are_one_line_errors(capsys, robot, code, words):
    # rolling and gear pairs are taken now: tests/analysis/course/test_course_rolling.py
    got, out, err = run_cli(["equations", str(ROBOTS / f"{robot}.urdf")], capsys)
    assert got == code and words in err and _error_lines(err) == 1


def test_bad_input_joint_is_a_usage_error(capsys):
    got, out, err = run_cli(["equations", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--input", "nope"], capsys)
    assert got == 2 and _error_lines(err) == 1
    got, out, err = run_cli(["equations", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--input", "coupler_joint"],
                            capsys)
    assert got == 2 and "joins two moving links" in err


def _error_lines(err: str) -> int:
    """The lines of stderr that are not notes (a note says what the command chose, e.g. the file's configuration)."""
    return sum(1 for line in err.splitlines() if not line.startswith("note: "))
