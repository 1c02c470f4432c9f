"""Mechanisms written the way students write them (tests/data/student/): every link along +x,
joint origins with rpy 0, loops left open in the file.  Every answer is checked against a
closed form computed here: circle intersections and Freudenstein's equation (four-bar), the
slider position (slider-crank), Bennett's relation, Sarrus's straight-line height, the
dead positions of a six-bar's dyad.  Each of these files failed with "cannot assemble"
before the assembly became a search.
"""

import json

import numpy as np
import pinocchio as pin
import pytest
from conftest import DATA, circles
from scipy.optimize import brentq

import screwkin
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import classify
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main

STUDENT = DATA / "student"
IN = 0.0254


def load(name):
    return screwkin.load(STUDENT / f"{name}.urdf")


def run_json(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def fmt(values):
    return " ".join(f"{float(x):.17g}" for x in np.atleast_1d(values))


def angle(v):
    return float(np.arctan2(v[1], v[0]))


def wrap(x):
    return float(np.mod(x + np.pi, 2 * np.pi) - np.pi)


# ------------------------------------------------------------------ four-bar 5-7-9-6 in
A_, B_, C_, D_ = 5 * IN, 7 * IN, 9 * IN, 6 * IN  # crank, coupler, rocker, ground


def fourbar_closed_form(theta2):
    """(theta3, theta4) of both assembly modes: B on circle (A, b) and circle (D, c)."""
    A = A_ * np.array([np.cos(theta2), np.sin(theta2)])
    D = np.array([D_, 0.0])
    return [(angle(B - A), angle(B - D)) for B in circles(A, B_, D, C_)]


def test_the_student_fourbar_assembles_and_says_from_where():
    mech = load("fourbar_5796")
    with pytest.raises(screwkin.AssemblyError):  # one descent from the straight drawing cannot close it
        mech.closure.solve(mech.neutral())
    r = mech.mobility()
    assert (r.mobility, r.topology.gruebler, r.redundant_constraints) == (1, 1, 0)
    assert "perturbation of the file's configuration" in r.assembly_start
    assert r.classification.startswith("constrained")


@pytest.mark.parametrize("theta2_deg", [45.0, 100.0, -70.0])
def test_student_fourbar_positions_against_circle_intersections_and_freudenstein(capsys, theta2_deg):
    theta2 = np.radians(theta2_deg)
    d = run_json(capsys, ["solve", str(STUDENT / "fourbar_5796.urdf"), "--set", f"crank_joint={theta2_deg}deg"])
    got = sorted((s["link_angles"]["coupler"], s["link_angles"]["rocker"]) for s in d["solutions"])
    want = sorted(fourbar_closed_form(theta2))
    assert len(got) == 2
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    # Freudenstein: K1 cos t4 - K2 cos t2 + K3 = cos(t2 - t4)
    K1, K2, K3 = D_ / A_, D_ / C_, (A_**2 - B_**2 + C_**2 + D_**2) / (2 * A_ * C_)
    for _, t4 in got:
        assert abs(K1 * np.cos(t4) - K2 * np.cos(theta2) + K3 - np.cos(theta2 - t4)) < 1e-9
    for s in d["solutions"]:
        assert s["link_angles"]["crank"] == pytest.approx(wrap(theta2), abs=1e-12)
        assert s["link_angles"]["ground"] == 0.0


def test_inputs_as_absolute_link_angles_match_joint_values(capsys):
    path = str(STUDENT / "fourbar_5796.urdf")
    by_angle = run_json(capsys, ["solve", path, "--set-angle", "crank=45deg", "--output", "rocker"])
    by_joint = run_json(capsys, ["solve", path, "--set", "crank_joint=45deg", "--output", "rocker"])
    assert by_angle["inputs"] == by_joint["inputs"]
    assert len(by_angle["solutions"]) == len(by_joint["solutions"]) >= 1
    for a, b in zip(by_angle["solutions"], by_joint["solutions"], strict=True):
        np.testing.assert_allclose(list(a["joints"].values()), list(b["joints"].values()), atol=1e-12)
        # the pose also as position and roll-pitch-yaw, beside the matrix
        T = np.array(a["output_pose"])
        np.testing.assert_allclose(a["output_position"], T[:3, 3], atol=1e-15)
        np.testing.assert_allclose(pin.rpy.rpyToMatrix(np.array(a["output_rpy"])), T[:3, :3], atol=1e-12)
    # a floating link's angle is an input too (tests/analysis/position/test_set_angle_floating.py); the ground's is not
    code = main(["solve", path, "--set-angle", "ground=10deg"])
    assert code == 2 and "is the ground" in capsys.readouterr().err


def test_limit_positions_located_from_both_sides_and_listed(capsys):
    """The 5-7-9-6 four-bar is non-Grashof: the crank stops where coupler and rocker fold,
    |BD| = c - b: cos t2 = (a^2 + d^2 - (c - b)^2) / (2 a d)."""
    exact = np.arccos((A_**2 + D_**2 - (C_ - B_) ** 2) / (2 * A_ * D_))
    mech = load("fourbar_5796")
    solver = PositionSolver(mech, ["crank_joint"])
    down = sweep(solver, "crank_joint", np.radians(45), 0.0, 9)
    up = sweep(solver, "crank_joint", np.radians(-45), 0.0, 9)
    assert down.stopped_at == pytest.approx(exact, abs=1e-9)
    assert up.stopped_at == pytest.approx(-exact, abs=1e-9)
    for res, x in ((down, exact), (up, -exact)):
        (lim,) = res.limits
        assert lim.kind == "actuator" and lim.limit and lim.input == pytest.approx(x, abs=1e-9)
        # and singularities, asked at that input, agrees
        q = solver.solve({"crank_joint": lim.input}).solutions[0].q
        assert classify(mech, q).actuator
    d = run_json(capsys, ["sweep", str(STUDENT / "fourbar_5796.urdf"), "--input", "crank_joint", "--from", "45deg",
                          "--to", "0", "--steps", "9"])
    assert d["singularities"][0]["input"] == pytest.approx(exact, abs=1e-9) and d["singularities"][0]["limit"]
    assert d["stopped_at"] == pytest.approx(exact, abs=1e-9)


def test_turn_traces_the_whole_circuit_of_a_non_grashof_fourbar():
    exact = np.arccos((A_**2 + D_**2 - (C_ - B_) ** 2) / (2 * A_ * D_))
    mech = load("fourbar_5796")
    res = sweep(PositionSolver(mech, ["crank_joint"]), "crank_joint", np.radians(45), 0.0, 45, turn=True)
    assert res.circuit_closed and res.stopped_at is None
    np.testing.assert_allclose(sorted(s.input for s in res.limits), [exact, 2 * np.pi - exact], atol=1e-9)
    # every configuration on the way is one of the closed-form solutions for its input
    assert len(res.values) == len(res.q)
    for x, q in zip(res.values[::7], res.q[::7], strict=True):
        angles = PositionSolver(mech, ["crank_joint"])._link_angles(q)
        want = fourbar_closed_form(x)
        assert min(abs(wrap(angles["rocker"] - t4)) for _, t4 in want) < 1e-8
    # both circuits of the rocker are visited: the crank comes back on the other branch
    rockers = [PositionSolver(mech, ["crank_joint"])._link_angles(q)["rocker"] for q in res.q]
    assert np.ptp(rockers) > np.radians(60)


def test_a_sweep_stop_of_a_sliding_input_is_in_metres(capsys):
    """The slider of the student slider-crank as input: it stops at the outer dead centre,
    x = crank + rod = 0.3 m."""
    out_code = main(["sweep", str(STUDENT / "slider_crank.urdf"), "--input", "slider_joint", "--from", "0.2",
                     "--to", "0.4", "--steps", "20"])
    text = capsys.readouterr().out
    assert out_code == 0
    line = next(line for line in text.splitlines() if line.startswith("stopped at"))
    assert "0.3 m" in line and "deg" not in line


# ------------------------------------------------------------------ slider-crank
def test_student_slider_crank_slider_position():
    a, b = 0.1, 0.2
    mech = load("slider_crank")
    res = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": np.radians(60)})
    xs = sorted(s.joints["slider_joint"] for s in res.solutions)
    t = np.radians(60)
    want = sorted(a * np.cos(t) + sgn * np.sqrt(b**2 - (a * np.sin(t)) ** 2) for sgn in (1, -1))
    np.testing.assert_allclose(xs, want, atol=1e-10)


@pytest.mark.parametrize("x", [0.3, 0.1])
def test_a_double_root_is_one_singular_solution(x):
    """Slider at a dead centre (crank and rod in line): the two modes meet.  One solution,
    flagged singular, crank at 0 (outer) or pi (inner)."""
    mech = load("slider_crank")
    res = PositionSolver(mech, ["slider_joint"]).solve({"slider_joint": x})
    (s,) = res.solutions
    assert s.singular and not s.continuum
    assert abs(wrap(s.joints["crank_joint"] - (0.0 if x > 0.2 else np.pi))) < 1e-4  # a double root: ~sqrt(tol)


def test_a_singular_input_with_a_continuum_is_one_solution():
    """R-R-P-R with crank = ground: at crank angle 0 the block's pin sits on the slotted link's
    pivot, which turns freely.  Solving there used to list 10 'modes'."""
    mech = load("rrpr")
    (s,) = PositionSolver(mech, ["A"]).solve({"A": 0.0}).solutions
    assert s.singular and s.continuum
    # elsewhere the slotted link points from D to B: a regular solution (two, the slot either way)
    t = np.radians(50)
    res = PositionSolver(mech, ["A"]).solve({"A": t})
    B = 0.1 * np.array([np.cos(t), np.sin(t)])
    slot = angle(B - np.array([0.1, 0.0]))
    assert not res.solutions[0].singular
    assert min(abs(wrap(s.joints["D"] - slot)) for s in res.solutions) < 1e-9


# ------------------------------------------------------------------ spatial overconstrained loops
@pytest.mark.slow  # about 1.4 s on 2 shared cores: out of the fast subset
def test_bennett_written_at_its_dh_zero():
    alpha, beta = np.radians(30), np.radians(50)
    k = np.sin((beta + alpha) / 2) / np.sin((beta - alpha) / 2)
    mech = load("bennett_dh")
    r = mech.mobility()
    assert (r.kutzbach, r.mobility, r.overconstraint) == (-2, 1, 3)
    for t1 in np.radians([40.0, 100.0, -25.0]):
        res = PositionSolver(mech).solve({"joint1": t1})
        s = res.solutions[0]
        t2 = s.joints["joint2"]
        assert abs(np.tan(t1 / 2) * np.tan(t2 / 2) - k) < 1e-9  # Bennett 1903
        assert abs(wrap(s.joints["joint3"] + t1)) < 1e-9  # theta3 = -theta1 in this DH convention


@pytest.mark.slow  # about 4.6 s on 2 shared cores: out of the fast subset
def test_sarrus_written_flat_moves_in_a_straight_line():
    """Top height 2 l sin(e) for limb A's elevation e, orientation unchanged (Sarrus 1853)."""
    mech = load("sarrus")
    r = mech.mobility(output="top")
    assert (r.mobility, r.kutzbach) == (1, 0) and r.output.label == "1T"
    for e in np.radians([30.0, 50.0]):
        res = PositionSolver(mech, output="top").solve({"A1": -e})  # rotation about +y by -e lifts +x
        regular = [s for s in res.solutions if not s.singular]
        assert regular
        for s in regular:
            T = s.output_pose
            assert T[2, 3] == pytest.approx(2 * 0.05 * np.sin(e), abs=1e-10)
            np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-9)
            np.testing.assert_allclose(T[:2, 3], [0.1, 0.0], atol=1e-10)


# ------------------------------------------------------------------ two-loop six-bar
def sixbar_dyad_gap(theta2, circuit):
    """|EF| of the student Watt six-bar for crank angle theta2 on a four-bar circuit (0 or 1)."""
    A = 0.04 * np.array([np.cos(theta2), np.sin(theta2)])
    O4 = np.array([0.12, 0.0])
    B = circles(A, 0.12, O4, 0.09)[circuit]
    t3, t4 = angle(B - A), angle(B - O4)

    def rot(t, v):
        return np.array([np.cos(t) * v[0] - np.sin(t) * v[1], np.sin(t) * v[0] + np.cos(t) * v[1]])

    return np.linalg.norm(A + rot(t3, (0.06, 0.03)) - (O4 + rot(t4, (0.05, -0.03))))


def test_six_bar_dyad_dead_positions_in_both_directions():
    mech = load("watt_sixbar")
    solver = PositionSolver(mech, ["O2"])
    q0 = solver.solve({"O2": 0.0}).solutions[0].q
    angles = solver._link_angles(q0)
    # which circuit of the four-bar the sweep is on: the closed form's rocker angle decides
    A = 0.04 * np.array([1.0, 0.0])
    circuit = int(np.argmin([abs(wrap(angle(B - np.array([0.12, 0.0])) - angles["rocker"]))
                             for B in circles(A, 0.12, np.array([0.12, 0.0]), 0.09)]))
    for stop in (2 * np.pi, -2 * np.pi):
        res = sweep(solver, "O2", 0.0, stop, 72)
        (lim,) = res.limits
        # the dyad E-G-F is straight there: |EF| = 0.065 + 0.040 or 0.065 - 0.040
        gap = sixbar_dyad_gap(lim.input, circuit)
        target = 0.105 if abs(gap - 0.105) < abs(gap - 0.025) else 0.025
        lo, hi = sorted((lim.input - 0.05, lim.input + 0.05))
        exact = brentq(lambda t: sixbar_dyad_gap(t, circuit) - target, lo, hi, xtol=1e-15)
        assert lim.input == pytest.approx(exact, abs=1e-9)
        assert res.stopped_at == lim.input and np.sign(lim.input) == np.sign(stop)


# ------------------------------------------------------------------ one answer everywhere
def test_planar_structures_are_judged_in_the_plane():
    r = load("triangle").mobility()
    assert (r.mobility, r.overconstraint, r.redundant_constraints) == (0, 3, 0)
    assert r.classification == "statically determinate structure in the plane"
    r = load("triangle_and_bar").mobility()
    assert (r.mobility, r.topology.gruebler, r.redundant_constraints) == (0, -1, 1)
    assert r.classification == "statically indeterminate structure in the plane (1 redundant constraint)"


def test_stationary_joints_do_not_depend_on_where_the_file_was_drawn(tmp_path):
    """The student slider-crank closes from its own drawing at the outer dead centre, where the
    slider is stationary; drawn elsewhere (crank at 60 deg) and set there, the answer is the same."""
    straight = load("slider_crank")
    assert straight.assemble().start == "the file's configuration"
    a, b, t = 0.1, 0.2, np.radians(60)
    x = a * np.cos(t) + np.sqrt(b**2 - (a * np.sin(t)) ** 2)
    rod = angle(np.array([x, 0.0]) - a * np.array([np.cos(t), np.sin(t)]))
    text = (STUDENT / "slider_crank.urdf").read_text()
    text = text.replace('<parent link="ground"/><child link="crank"/><origin xyz="0 0 0"/>',
                        f'<parent link="ground"/><child link="crank"/><origin xyz="0 0 0" rpy="0 0 {fmt(t)}"/>')
    text = text.replace('<parent link="crank"/><child link="rod"/><origin xyz="0.1 0 0"/>',
                        f'<parent link="crank"/><child link="rod"/><origin xyz="0.1 0 0" rpy="0 0 {fmt(rod - t)}"/>')
    text = text.replace('<link2 link="slider" xyz="0 0 0"/>', f'<link2 link="slider" xyz="{fmt(x)} 0 0" rpy="0 0 {fmt(rod)}"/>')
    p = tmp_path / "drawn_at_60.urdf"
    p.write_text(text)
    drawn = screwkin.load(p)
    assert drawn.assemble().iterations == 0  # closed as drawn
    for mech, crank in ((straight, 0.0), (drawn, -t)):
        q = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": crank}).solutions[0].q
        assert classify(mech, q, output="slider").stationary_joints == ("slider_joint",)
    # and at a generic crank angle no joint is stationary, in both
    for mech, crank in ((straight, 1.0), (drawn, 1.0 - t)):
        q = PositionSolver(mech, ["crank_joint"]).solve({"crank_joint": crank}).solutions[0].q
        assert classify(mech, q, output="slider").stationary_joints == ()


def test_rigid_loop_solve_and_singularities_agree(tmp_path):
    """A 6R loop of general geometry is a structure (M = 0); solved with one joint held at its
    value, solve's singular flag is singularities' actuator/constraint verdict (both false)."""
    rng = np.random.default_rng(7)
    links = "".join(f'<link name="l{k}"/>' for k in range(6))
    joints, T = "", pin.SE3.Identity()
    for k in range(1, 6):
        xyz, rpy = rng.uniform(-0.1, 0.1, 3) + np.array([0.1, 0, 0]), rng.uniform(-1, 1, 3)
        joints += (f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
                   f'<origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/><axis xyz="0 0 1"/>'
                   f'<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
        T = T * pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz)
    xyz6, rpy6 = rng.uniform(-0.1, 0.1, 3) + np.array([0.1, 0, 0]), rng.uniform(-1, 1, 3)
    F = T * pin.SE3(pin.rpy.rpyToMatrix(rpy6), xyz6)  # the sixth joint's frame at all zeros: closed as drawn
    cut = (f'<loop_joint name="j6" type="revolute"><link1 link="l5" xyz="{fmt(xyz6)}" rpy="{fmt(rpy6)}"/>'
           f'<link2 link="l0" xyz="{fmt(F.translation)}" rpy="{fmt(pin.rpy.matrixToRpy(F.rotation))}"/>'
           '<axis xyz="0 0 1"/></loop_joint>')
    p = tmp_path / "six_r.urdf"
    p.write_text(f'<robot name="six_r">{links}{joints}{cut}</robot>')
    mech = screwkin.load(p)
    r = mech.mobility()
    assert r.mobility == 0 and r.classification.startswith("statically determinate structure")
    (s,) = PositionSolver(mech, ["j1"]).solve({"j1": 0.0}).solutions
    rep = classify(mech, s.q, inputs=["j1"])
    assert s.singular is False and not rep.actuator and not rep.constraint
    assert s.sigmas["actuator"] == pytest.approx(rep.sigmas["actuator"], rel=1e-12)


def test_one_characteristic_length_everywhere(capsys):
    """The length is the mean link length (the student four-bar: (5 + 7 + 9 + 6) / 4 in); the
    same sigma comes out of scan, singularities and the Python API, and --length overrides
    it in each."""
    assert load("fourbar_5796").length == pytest.approx(27 / 4 * IN, abs=1e-15)
    arm = screwkin.load(DATA.parent.parent / "robots" / "arm_6r.urdf")
    path = str(arm.path)
    scan = run_json(capsys, ["scan", path, "--output", "flange", "--samples", "2000"])
    values = [scan["min_configuration"][f"joint{k}"] for k in range(1, 7)]
    q = arm.neutral()
    for k, v in enumerate(values, 1):
        q[arm.coordinate(f"joint{k}").idx_q] = v
    from screwkin.analysis.singularities.batch import SerialJacobians

    api = SerialJacobians(arm, "flange").measures(q[None], "sigma_ratio")[0]
    sing = classify(arm, q, output="flange", inputs=[])
    assert scan["length"] == arm.length == sing.length
    np.testing.assert_allclose([scan["min"], sing.sigmas["serial"]], [api, api], rtol=1e-9)
    set_args = [f"--set=joint{k}={v!r}" for k, v in enumerate(values, 1)]
    cli = run_json(capsys, ["singularities", path, "--output", "flange", "--actuated",
                            ",".join(f"joint{k}" for k in range(1, 7)), *set_args])
    assert cli["sigmas"]["serial"] == pytest.approx(api, rel=1e-9)
    other = run_json(capsys, ["scan", path, "--output", "flange", "--samples", "10", "--length", "0.5"])
    assert other["length"] == 0.5
    other = run_json(capsys, ["singularities", path, "--output", "flange", "--length", "0.5"])
    assert other["characteristic_length"] == 0.5


# ------------------------------------------------------------------ modes a user can read
def test_delta_modes_that_keep_the_platform_orientation_come_first(capsys):
    path = str(DATA.parent.parent / "robots" / "delta_parallelogram.urdf")
    # every mode: --all (issue 41: the default answers the mode asked for, at once)
    d = run_json(capsys, ["solve", path, "--set", "arm1=0.1,arm2=0,arm3=-0.1", "--output", "platform", "--all"])
    phys = [s for s in d["solutions"] if s["physical"]]
    assert phys and d["solutions"][:len(phys)] == phys
    for s in phys:
        np.testing.assert_allclose(np.array(s["output_pose"])[:3, :3], np.eye(3), atol=1e-9)
    for s in d["solutions"][len(phys):]:
        assert s["labels"]
    assert main(["solve", path, "--set", "arm1=0.1,arm2=0,arm3=-0.1", "--output", "platform", "--all"]) == 0
    text = capsys.readouterr().out
    n = len(d["solutions"])  # the count reads as the total; --all shows every mode, each one's label with it
    assert f"{n} assembly modes found" in text
    assert text.count("\nsolution ") == n
    assert all(text.split("\nsolution ")[k + 1].count("\n  not reached by moving: ") == len(s["labels"])
               for k, s in enumerate(d["solutions"]))
    # the default: the mode Newton reaches from the drawn configuration, the platform level, and how to get every one
    d1 = run_json(capsys, ["solve", path, "--set", "arm1=0.1,arm2=0,arm3=-0.1", "--output", "platform"])
    assert len(d1["solutions"]) == 1 and d1["solutions"][0]["physical"] and not d1["complete"]
    assert d1["method"] == "newton from the file's configuration" and "--all" in d1["modes"]["reason"]
    np.testing.assert_allclose(d1["solutions"][0]["output_pose"], phys[0]["output_pose"], atol=1e-9)


@pytest.mark.slow  # about 2.9 s on 2 shared cores: out of the fast subset
def test_3rpr_inverse_kinematics_labels_reversed_legs():
    mech = screwkin.load(DATA.parent.parent / "robots" / "planar_3rpr.urdf")
    home = mech.model.createData()
    pin.framesForwardKinematics(mech.model, home, mech.neutral())
    from screwkin.analysis.position.ik import inverse_kinematics

    res = inverse_kinematics(mech, "platform", home.oMf[mech.link_frame("platform")])
    first = res.solutions[0]
    assert first.physical and np.allclose([first.joints[f"leg{k}"] for k in (1, 2, 3)], 0, atol=1e-9)
    reversed_ = [s for s in res.solutions if any(lab.startswith("legs reversed") for lab in s.labels)]
    assert len(reversed_) == len(res.solutions) - 1


# ------------------------------------------------------------------ output as a point
def leg_urdf():
    """A Solo-like leg: hip abduction about x, hip and knee flexion about y, thigh and shank
    0.16 m down; the foot is the shank's tip."""
    def j(name, parent, child, xyz, axis):
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{xyz}"/><axis xyz="{axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/>'
                '</joint>')
    body = "".join(f'<link name="{n}"/>' for n in ("base", "hip", "thigh", "shank", "foot"))
    body += j("haa", "base", "hip", "0 0 0", "1 0 0") + j("hfe", "hip", "thigh", "0 0.05 0", "0 1 0")
    body += j("kfe", "thigh", "shank", "0 0 -0.16", "0 1 0")
    body += '<joint name="tip" type="fixed"><parent link="shank"/><child link="foot"/><origin xyz="0 0 -0.16"/></joint>'
    return f'<robot name="leg">{body}</robot>'


def test_a_straight_knee_is_a_singularity_of_the_foot_position(tmp_path, capsys):
    p = tmp_path / "leg.urdf"
    p.write_text(leg_urdf())
    mech = screwkin.load(p)
    assert mech.mobility(output="foot", point=True).output.label == "3T"
    q = mech.neutral()
    q[mech.coordinate("hfe").idx_q] = 0.4  # knee straight (kfe = 0), thigh swung forward
    rep = classify(mech, q, output="foot", inputs=[], point=True)
    assert rep.serial and rep.sigmas["serial"] < 1e-12
    assert not classify(mech, q, output="foot", inputs=[]).serial  # its 6-D motion keeps 3 directions
    q[mech.coordinate("kfe").idx_q] = 0.8
    assert not classify(mech, q, output="foot", inputs=[], point=True).serial
    d = run_json(capsys, ["scan", str(p), "--output", "foot", "--point", "--samples", "20000"])
    assert d["point"] and d["min"] < 0.02 and abs(d["min_configuration"]["kfe"]) < 0.05


JOINT_STYLE_LOOP = """<robot name="student_fourbar">
  <link name="ground"/><link name="crank"/><link name="coupler"/><link name="rocker"/><link name="rocker_tip"/>
  <joint name="A" type="revolute"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/>
    <limit lower="-6.3" upper="6.3" effort="1" velocity="1"/></joint>
  <joint name="B" type="revolute"><parent link="crank"/><child link="coupler"/><origin xyz="0.05 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-6.3" upper="6.3" effort="1" velocity="1"/></joint>
  <joint name="C" type="revolute"><parent link="coupler"/><child link="rocker"/><origin xyz="0.07 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-6.3" upper="6.3" effort="1" velocity="1"/></joint>
  <joint name="rt" type="fixed"><parent link="rocker"/><child link="rocker_tip"/><origin xyz="0.09 0 0"/></joint>
  <loop_joint name="D" type="revolute"><parent link="ground"/><child link="rocker_tip"/>
    <origin xyz="0.06 0 0"/><axis xyz="0 0 1"/></loop_joint>
  <transmission name="t"><joint name="A"/></transmission>
</robot>"""


def test_loop_joint_written_like_a_joint(tmp_path):
    """A newcomer writes the loop joint as a <joint> (parent, child, origin in the parent): read
    as link1 = parent at the origin, link2 = the child's own frame.  Four-bar 0.05/0.07/0.09,
    ground 0.06, crank at 45 deg: the rocker's direction from D by the law of cosines."""
    import numpy as np

    import screwkin
    from screwkin.analysis.position.position import PositionSolver

    path = tmp_path / "fourbar.urdf"
    path.write_text(JOINT_STYLE_LOOP)
    m = screwkin.load(path)
    assert len(m.cuts) == 1
    res = PositionSolver(m).solve({"A": np.radians(45)})
    B = 0.05 * np.array([np.cos(np.radians(45)), np.sin(np.radians(45))])
    D = np.array([0.06, 0.0])
    BD = np.linalg.norm(B - D)
    base = np.arctan2(*(B - D)[::-1])
    alpha = np.arccos((0.09**2 + BD**2 - 0.07**2) / (2 * 0.09 * BD))
    # the rocker's x axis points from C to D: its angle is that of D -> C turned by pi
    expected = sorted(np.degrees(np.angle(np.exp(1j * (base + s * alpha + np.pi)))) for s in (1, -1))
    got = sorted(np.degrees(np.angle(np.exp(1j * s.link_angles["rocker"]))) for s in res.solutions)
    assert np.allclose(got, expected, atol=1e-6)
