"""Rolling, gear and rack-and-pinion pairs in the vector-loop equations and Newton (issue 25,
items 2 and 3).  Against what the test writes itself: the no-slip law from the radii of the
files (docs/format.md 2b), gear ratios, central differences of screwkin's solved
configurations, and one Newton step computed by hand with numpy."""

import json

import numpy as np
import pytest

from screwkin import load
from screwkin.analysis.course.vector_loops import VectorLoops
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main

WHEELS, RACK, GEARS = "robots/friction_wheels.urdf", "robots/rack_pinion.urdf", "robots/gear_train_idler.urdf"
# friction_wheels.urdf: disc 2 (radius 0.02) pinned at the origin, its centre at (0.008, 0.008); disc 3 (radius 0.01)
# on a slider along x, its centre drawn at x = 0.008 + sqrt(0.03^2 - 0.008^2)
R2, R3, C2 = 0.02, 0.01, np.array([0.008, 0.008])
X0 = 0.008 + np.sqrt(0.03 ** 2 - 0.008 ** 2)


def built(path, inputs):
    mech = load(path)
    q0 = mech.generic_configurations()[0].q
    return mech, q0, VectorLoops(mech, q0, inputs), PositionSolver(mech, inputs)


def solved(mech, solver, name, value, q0):
    """screwkin's solution at the input value, the mode nearest the file's configuration."""
    res = solver.solve({name: value}, near=mech.joint_values(q0))
    return res.solutions[0].q


def turns_of_disc3(arc):
    """``arc`` [m] less whole turns of disc 3 (rho3 2 pi): solve reports disc 3's joint within a turn, the pose is
    the same"""
    turn = 2 * np.pi * R3
    return arc - turn * np.round(arc / turn)


def coord(mech, q, name):
    return float(q[mech.coordinate(name).idx_q])


@pytest.fixture(scope="module")
def wheels():
    return built(WHEELS, ["wheel2_joint"])


def test_the_equations_of_friction_wheels_name_the_mechanisms_own_unknowns(wheels):
    mech, q0, loops, _ = wheels
    res = loops.result()
    assert res.unknowns == ("theta3", "x4") and res.inputs == ("theta2",)
    (pair,) = res.pairs
    assert pair.kind == "external" and pair.links == ("wheel2", "wheel3")
    assert "rho2*(theta2 - theta23)" in pair.law and "rho3*(theta3 - theta23)" in pair.law
    assert res.symbols["rho2"].value == R2 and res.symbols["rho3"].value == R3
    assert res.A_value.shape == (2, 2) and res.det_A_value is not None


@pytest.mark.parametrize("deg", [-50.0, -10.0, 30.0, 75.0])
def test_no_slip_and_the_loop_vanish_at_screwkins_solutions(wheels, deg):
    mech, q0, loops, solver = wheels
    q = solved(mech, solver, "wheel2_joint", np.radians(deg), q0)
    assert np.abs(loops.residual(loops.values(q))).max() < 1e-10
    # the no-slip law written here: rho2 (theta2 - theta_k) + rho3 (theta3 - theta_k) is constant, theta_k the
    # line of centres; disc 2 turns with its joint, disc 3 with its own (the slider does not turn)
    def law(qq):
        t2 = coord(mech, qq, "wheel2_joint")
        c2 = np.array([[np.cos(t2), -np.sin(t2)], [np.sin(t2), np.cos(t2)]]) @ C2
        c3 = np.array([X0 + coord(mech, qq, "slide"), 0.0])
        tk = np.arctan2(*(c3 - c2)[::-1])
        return R2 * (t2 - tk) + R3 * (coord(mech, qq, "wheel3_joint") - tk)
    assert turns_of_disc3(law(q) - law(q0)) == pytest.approx(0.0, abs=1e-10)


def test_velocity_equations_match_central_differences_of_solutions(wheels):
    mech, q0, loops, solver = wheels
    t, h = np.radians(20.0), 1e-5
    q, qp, qm = (solved(mech, solver, "wheel2_joint", v, q0) for v in (t, t + h, t - h))
    dz = np.array([coord(mech, qp, "wheel3_joint") - coord(mech, qm, "wheel3_joint"),
                   coord(mech, qp, "slide") - coord(mech, qm, "slide")]) / (2 * h)
    A, B = loops.matrices(loops.values(q))
    assert A @ dz == pytest.approx((B @ [1.0]).tolist(), abs=1e-8)


def _hand_newton_step():
    """(F, J, dz, theta3) of one Newton step by hand on friction_wheels from wheel2_joint = 60 deg and the
    estimates theta3 = -100 deg, x4 = 0.035 m.  theta2 is the angle of O2 -> disc 2's centre (45 deg at
    joint 0), theta3 disc 3's frame x axis (0 as drawn); the line of centres theta_k = (rho2 theta2 +
    rho3 theta3 - c) / (rho2 + rho3), c from the drawing; the loop x4 u - R e_k - r2 e2 = 0 (ground ->
    slider -> disc 3 -> disc 2 -> ground)."""
    t2_0, t3_0 = np.radians(45.0), 0.0
    tk_0 = np.arctan2(-0.008, X0 - 0.008)
    c = R2 * (t2_0 - tk_0) + R3 * (t3_0 - tk_0)
    r2, R = np.hypot(0.008, 0.008), R2 + R3
    t2, t3, x4 = np.radians(60.0 + 45.0), np.radians(-100.0), 0.035
    tk = (R2 * t2 + R3 * t3 - c) / R
    F = np.array([x4 - r2 * np.cos(t2) - R * np.cos(tk), -r2 * np.sin(t2) - R * np.sin(tk)])
    J = np.array([[R3 * np.sin(tk), 1.0], [-R3 * np.cos(tk), 0.0]])
    return F, J, np.linalg.solve(J, -F), t3


def test_one_newton_step_on_friction_wheels_is_the_hand_computation(capsys):
    code = main(["solve", WHEELS, "--set", "wheel2_joint=60deg", "--start", "theta3=-100deg,x4=0.035",
                 "--iterations", "1", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    (it,) = json.loads(out)["trace"]
    F, J, dz, t3 = _hand_newton_step()
    assert it["residual"] == pytest.approx(F.tolist(), abs=1e-12)
    assert np.array(it["jacobian"]) == pytest.approx(J, abs=1e-12)
    assert it["step"] == pytest.approx(dz.tolist(), abs=1e-10)
    assert it["values"]["theta3"] == pytest.approx(t3 + dz[0], abs=1e-10)


def test_newton_to_convergence_lands_on_screwkins_solution(wheels, capsys):
    mech, q0, loops, solver = wheels
    code = main(["solve", WHEELS, "--set", "wheel2_joint=60deg", "--start", "theta3=-100deg,x4=0.035", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    q = solved(mech, solver, "wheel2_joint", np.radians(60.0), q0)
    assert d["newton"]["values"]["x4"] == pytest.approx(X0 + coord(mech, q, "slide"), abs=1e-10)


def test_rack_and_pinion_moves_the_rack_by_rho_theta():
    mech, q0, loops, solver = built(RACK, ["pinion_joint"])
    res = loops.result()
    assert res.unknowns == ("x3",) and res.pairs[0].kind == "rack"
    for deg in (-120.0, 40.0, 100.0):
        t = np.radians(deg)
        q = solved(mech, solver, "pinion_joint", t, q0)
        assert np.abs(loops.residual(loops.values(q))).max() < 1e-10
        # the pinion (pitch radius 0.04) under the rack: turned +t, the rack goes -0.04 t along x
        assert coord(mech, q, "rack_joint") == pytest.approx(-0.04 * t, abs=1e-10)
        A, B = loops.matrices(loops.values(q))
        # x3 runs from the pinion's centre to the rack's joint, drawn at -x: dx3/dt = +0.04
        assert A @ [0.04] == pytest.approx((B @ [1.0]).tolist(), abs=1e-12)


def test_gear_train_no_slip_laws_are_the_equations():
    mech, q0, loops, solver = built(GEARS, ["input_joint"])
    res = loops.result()
    assert res.unknowns == ("theta3", "theta4") and all(p.in_system for p in res.pairs)
    for deg in (-60.0, 35.0, 90.0):  # the idler within half a turn: screwkin solve counts its turns there
        q = solved(mech, solver, "input_joint", np.radians(deg), q0)
        assert np.abs(loops.residual(loops.values(q))).max() < 1e-10
        A, B = loops.matrices(loops.values(q))
        # pitch radii 0.05 (input), 0.03 (idler), 0.08 (output): idler -5/3, output +5/8 of the input's rate
        assert A @ [-0.05 / 0.03, 0.05 / 0.08] == pytest.approx((B @ [1.0]).tolist(), abs=1e-12)


def test_equations_cli_text_and_json_for_rolling_pairs(capsys):
    assert main(["equations", WHEELS, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["unknowns"] == ["theta3", "x4"] and d["det_A"] is not None
    assert d["pairs"][0]["substitution"].startswith("theta23 = ")
    assert main(["equations", GEARS]) == 0
    out = capsys.readouterr().out
    assert "no slip: rho2*θ2 + rho3*θ3 = 0" in out.replace("ρ", "rho")


def test_a_cam_pair_is_still_refused_in_one_line(capsys):
    assert main(["equations", "robots/cam_followers.urdf"]) == 1
    err = capsys.readouterr().err
    errors = [line for line in err.strip().splitlines() if not line.startswith("note: ")]  # notes: what it chose
    assert "the vector-loop equations take revolute and prismatic joints" in err and len(errors) == 1


@pytest.fixture(scope="module")
def inside(tmp_path_factory):
    """friction_wheels.urdf with disc 3 rolling inside a ring of radius 0.04 on link 2 (internal contact, centre
    distance 0.04 - 0.01 = 0.03 as before): F2's x axis along the line of centres as drawn, as F1's."""
    text = open(WHEELS).read()
    text = text.replace('<rolling radius1="0.02" radius2="0.01" contact="external"/>',
                        '<rolling radius1="0.04" radius2="0.01" contact="internal"/>')
    text = text.replace('<link2 link="wheel3" xyz="0 0 0" rpy="0 0 2.87165985775639"/>',
                        '<link2 link="wheel3" xyz="0 0 0" rpy="0 0 -0.269932795833403"/>')
    path = tmp_path_factory.mktemp("inside") / "ring_wheel.urdf"
    path.write_text(text)
    return built(str(path), ["wheel2_joint"])


@pytest.mark.parametrize("deg", [-40.0, 25.0, 70.0])
def test_internal_rolling_law_and_velocities(inside, deg):
    mech, q0, loops, solver = inside
    (pair,) = loops.result().pairs
    assert pair.kind == "internal" and "rho2*(theta2 - theta23) - rho3*(theta3 - theta23)" in pair.law
    # h: screwkin's solutions close to ~3e-11 m, with det A ~ 0.01 m a 1e-5 step would measure that noise
    t, h = np.radians(deg), 1e-3
    q, qp, qm = (solved(mech, solver, "wheel2_joint", v, q0) for v in (t, t + h, t - h))
    assert np.abs(loops.residual(loops.values(q))).max() < 1e-10

    def law(qq):  # inside: rho2 (theta2 - theta_k) - rho3 (theta3 - theta_k) is constant
        t2 = coord(mech, qq, "wheel2_joint")
        c2 = np.array([[np.cos(t2), -np.sin(t2)], [np.sin(t2), np.cos(t2)]]) @ C2
        tk = np.arctan2(*(np.array([X0 + coord(mech, qq, "slide"), 0.0]) - c2)[::-1])
        return 0.04 * (t2 - tk) - R3 * (coord(mech, qq, "wheel3_joint") - tk)
    assert turns_of_disc3(law(q) - law(q0)) == pytest.approx(0.0, abs=1e-10)
    dz = np.array([coord(mech, qp, "wheel3_joint") - coord(mech, qm, "wheel3_joint"),
                   coord(mech, qp, "slide") - coord(mech, qm, "slide")]) / (2 * h)
    A, B = loops.matrices(loops.values(q))
    assert A @ dz == pytest.approx((B @ [1.0]).tolist(), rel=1e-6, abs=1e-9)  # O(h^2) = 1e-8 off


PLANETARY = """<?xml version="1.0"?>
<robot name="planetary">
  <link name="ground"/>
  <link name="arm"><inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="planet"><inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="arm_joint" type="continuous">
    <parent link="ground"/><child link="arm"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="planet_joint" type="continuous">
    <parent link="arm"/><child link="planet"/><origin xyz="0.03 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <loop_joint name="ring" type="gear">
    <link1 link="ground" xyz="0 0 0"/>
    <link2 link="planet" xyz="0 0 0"/>
    <axis xyz="0 0 1"/>
    <gear radius1="0.05" radius2="0.02" contact="internal"/>
  </loop_joint>
  <transmission name="t"><joint name="arm_joint"/></transmission>
</robot>
"""


def test_planet_on_an_arm_inside_a_fixed_ring(tmp_path, capsys):
    """A planet (pitch radius 0.02) on an arm of 0.03 inside a fixed ring (0.05): the loop fixes the line of centres
    to the arm, and the law 0.05 (0 - theta_arm) - 0.02 (theta_p - theta_arm) = 0 gives theta_p = -1.5 theta_arm."""
    path = tmp_path / "planetary.urdf"
    path.write_text(PLANETARY)
    mech, q0, loops, solver = built(str(path), ["arm_joint"])
    res = loops.result()
    assert res.unknowns == ("theta3",) and res.pairs[0].in_system and res.A_value.shape == (1, 1)
    for deg in (-70.0, 50.0):
        q = solved(mech, solver, "arm_joint", np.radians(deg), q0)
        assert np.abs(loops.residual(loops.values(q))).max() < 1e-10
        A, B = loops.matrices(loops.values(q))
        assert A @ [-1.5] == pytest.approx((B @ [1.0]).tolist(), abs=1e-12)
    # one Newton step by hand: F = 0.05 (0 - t2) - 0.02 (t3 - t2), linear in t3: one step lands on -1.5 t2
    assert main(["solve", str(path), "--set", "arm_joint=40deg", "--start", "theta3=10deg", "--iterations", "1",
                 "--json"]) == 0
    (it,) = json.loads(capsys.readouterr().out)["trace"]
    t2, t3 = np.radians(40.0), np.radians(10.0)
    F = 0.05 * (0 - t2) - 0.02 * (t3 - t2)
    assert it["residual"] == pytest.approx([F], abs=1e-12) and it["jacobian"][0] == pytest.approx([-0.02], abs=1e-15)
    assert it["values"]["theta3"] == pytest.approx(-1.5 * t2, abs=1e-12)


def test_acceleration_terms_match_second_differences_of_solutions(wheels):
    """A z'' = B w'' + c with the crank turning uniformly (w' = 1, w'' = 0): z'' from second central differences
    of screwkin's solutions (h = 0.01 rad: its solutions close to ~1e-11 m, O(h^2) ~ 1e-4 relative)."""
    mech, q0, loops, solver = wheels
    t, h = np.radians(20.0), 1e-2
    qs = [solved(mech, solver, "wheel2_joint", v, q0) for v in (t - h, t, t + h)]
    z = np.array([[coord(mech, q, "wheel3_joint"), coord(mech, q, "slide")] for q in qs])
    zd, zdd = (z[2] - z[0]) / (2 * h), (z[2] - 2 * z[1] + z[0]) / h ** 2
    values = loops.values(qs[1])
    A, _ = loops.matrices(values)
    c = loops.acceleration_terms(values, np.linalg.solve(A, loops.matrices(values)[1] @ [1.0]), [1.0])
    assert A @ zdd == pytest.approx(c.tolist(), rel=1e-3, abs=1e-7)
    assert np.linalg.solve(A, loops.matrices(values)[1] @ [1.0]) == pytest.approx(zd.tolist(), rel=1e-3)


def test_newton_on_the_rack_beyond_a_turn_reports_the_rack_where_the_law_puts_it(capsys):
    assert main(["solve", RACK, "--set", "pinion_joint=400deg", "--start", "x3=0.1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    # x3 from the pinion's centre to the rack's joint (drawn at 0.15 along -x): 0.15 + 0.04 t; the rack joint -0.04 t
    assert d["newton"]["values"]["x3"] == pytest.approx(0.15 + 0.04 * np.radians(400.0), abs=1e-12)
    assert d["solutions"][0]["joints"]["rack_joint"] == pytest.approx(-0.04 * np.radians(400.0), abs=1e-10)


def _sympy(text):
    """A formula as screwkin writes it (sympy syntax), its symbols real."""
    import sympy as sp
    names = {n: sp.Symbol(n, real=True) for n in ("rho2", "rho3", "c23", "theta2", "theta3", "x4")}
    return sp.sympify(text, locals=names), names


def test_symbolic_gram_cofactors_of_friction_wheels_are_the_hand_formulas(capsys):
    """singularities --symbolic takes the rolling pair (it refused it): the pair is a revolute at the contact point
    (no slip: the instantaneous centre).  By hand, origin at O2, t = theta23 the line of centres: twists (y, -x, 1)
    of O2 (0, 0), of disc 3's centre (x4, 0) and of the contact (x4 - rho3 cos t, -rho3 sin t), the slide's (1, 0, 0);
    C_i = det(S without column i)^2."""
    import sympy as sp
    assert main(["singularities", WHEELS, "--symbolic", "--json"]) == 0
    (loop,) = json.loads(capsys.readouterr().out)["gram_symbolic"]
    assert sorted(loop["joints"]) == ["slide", "wheel2_joint", "wheel3_joint", "wheels"]
    _, s = _sympy("0")
    t = (s["rho2"] * s["theta2"] + s["rho3"] * s["theta3"] - s["c23"]) / (s["rho2"] + s["rho3"])
    hand = {"wheel2_joint": s["rho3"] ** 2 * sp.cos(t) ** 2,
            "slide": s["rho3"] ** 2 * s["x4"] ** 2 * sp.sin(t) ** 2,
            "wheel3_joint": (s["x4"] - s["rho3"] * sp.cos(t)) ** 2,
            "wheels": s["x4"] ** 2}
    for joint, formula in hand.items():
        got, _ = _sympy(loop["cofactors"][joint])
        assert sp.simplify(got - formula) == 0, (joint, loop["cofactors"][joint])
    assert loop["zero_when"]["wheels"] == ["x4 = 0"]


def test_report_writes_the_rolling_pairs_equations_and_a_hand_newton_step(tmp_path, capsys):
    """report's Equations and Newton sections take the rolling pair through the equations' one path: det A is
    rho3 cos theta23 by hand (A = dF/d(theta3, x4) of the loop below) and one Newton step from the estimates given
    is the hand step of test_one_newton_step_on_friction_wheels_is_the_hand_computation."""
    import sympy as sp
    md = tmp_path / "f.md"
    code = main(["report", WHEELS, "--md", str(md), "--no-view", "--set", "wheel2_joint=60deg",
                 "--start", "theta3=-100deg,x4=0.035", "--iterations", "1", "--steps", "36"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "vector-loop equations take" not in out + err
    text = md.read_text()
    assert "## Equations" in text and "## Newton iterations" in text
    assert "no slip ρ2*(θ2 - θ23) + ρ3*(θ3 - θ23) = c23" in text
    data = json.loads((tmp_path / "f_files" / "data.json").read_text())
    det, s = _sympy(data["equations"]["det_A"])
    t = (s["rho2"] * s["theta2"] + s["rho3"] * s["theta3"] - s["c23"]) / (s["rho2"] + s["rho3"])
    assert sp.simplify(det - s["rho3"] * sp.cos(t)) == 0
    F, J, dz, _ = _hand_newton_step()
    (it,) = data["newton"]["trace"]
    # report builds the equations at the solved configuration (closed to the closure tolerance, ~1e-12 m here): c23
    # is measured there, so the residual agrees to that and the step to it over sigma_min(J) ~ 0.01
    assert it["residual"] == pytest.approx(F.tolist(), abs=1e-10)
    assert it["step"] == pytest.approx(dz.tolist(), abs=1e-8)


def test_symbolic_gram_cofactors_of_gear_loops_are_the_hand_formulas(capsys):
    """A loop of two gears pinned to one frame has three joints but one freedom (the contact on the line of
    centres, Kennedy): its cofactors are the 2 x 2 Gram determinants.  By hand, centres O_a = (0, 0) and
    O_b = (d, 0), contact (rho_a, 0): twists (0, 0, 1), (0, -d, 1), (0, -rho_a, 1); C_a = Gram(O_b, P) = (d - rho_a)^2
    = rho_b^2, C_b = Gram(O_a, P) = rho_a^2, C_P = Gram(O_a, O_b) = d^2.  A rack on a pinion at the origin, the contact
    (0, rho): twists (0, 0, 1), (+-1, 0, 0), (rho, 0, 1): C_pinion = 1, C_rack = rho^2, C_mesh = 1."""
    import sympy as sp
    assert main(["singularities", GEARS, "--symbolic", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)["gram_symbolic"][0]
    assert main(["equations", GEARS, "--json"]) == 0
    values = {n: s["value"] for n, s in json.loads(capsys.readouterr().out)["symbols"].items()}
    assert values["r1"] == pytest.approx(values["rho2"] + values["rho3"], abs=1e-12)  # the gears touch
    r1, rho2 = sp.symbols("r1 rho2", real=True)
    hand = {"input_joint": (r1 - rho2) ** 2, "idler_joint": rho2 ** 2, "mesh1": r1 ** 2}  # input: rho2, d = r1
    for joint, formula in hand.items():
        got = sp.sympify(first["cofactors"][joint], locals={"r1": r1, "rho2": rho2})
        assert sp.simplify(got - formula) == 0, (joint, first["cofactors"][joint])
        assert first["zero_when"][joint] == []
    assert main(["singularities", RACK, "--symbolic", "--json"]) == 0
    (loop,) = json.loads(capsys.readouterr().out)["gram_symbolic"]
    assert {j: sp.sympify(c) for j, c in loop["cofactors"].items()} == {
        "pinion_joint": 1, "rack_joint": sp.Symbol("rho2") ** 2, "mesh": 1}
