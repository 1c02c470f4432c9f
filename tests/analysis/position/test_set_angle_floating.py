"""--set-angle LINK=ANGLE of a floating link of a planar mechanism (issue 24, item 4): its absolute
angle held as one more loop equation.  Every value is checked against a closed form written here
from the files' own numbers (joint origins, loop-joint places): the link's far end from the crank tip
along its angle, the remaining dyad by circle intersection."""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from conftest import DATA, ROBOTS, circles

import screwkin
from screwkin.analysis.motion.link_inputs import holding_angles
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main

FIVE = ROBOTS / "five_bar.urdf"
FOUR = ROBOTS / "fourbar_crank_rocker.urdf"


def run(capsys, argv):
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


def run_json(capsys, argv):
    code, out, err = run(capsys, [*argv, "--json"])
    assert code == 0, err
    return json.loads(out)


def u(angle):
    return np.array([np.cos(angle), np.sin(angle)])


def k_cross(w, r):
    """w (about +z) x r in the plane."""
    return w * np.array([-r[1], r[0]])


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


def origins(path):
    """Joint origins (x, y) and the loop joint's two places (x, y) in their links' frames, as written
    (every rpy is 0 and every axis +z in these files, so the link frames are the world's at q = 0)."""
    root = ET.parse(path).getroot()
    for el in [*(j.find("origin") for j in root.findall("joint")), *root.find("loop_joint")]:
        assert el is None or [float(v) for v in el.get("rpy", "0 0 0").split()] == [0, 0, 0]
    for el in root.iter("axis"):
        assert el.get("xyz").split() == ["0", "0", "1"]

    def xy(el):
        return np.array([float(v) for v in el.get("xyz").split()][:2])

    joints = {j.get("name"): xy(j.find("origin")) for j in root.findall("joint") if j.find("origin") is not None}
    loop = root.find("loop_joint")
    return joints, xy(loop.find("link1")), xy(loop.find("link2"))


def five_bar():
    joints, p1, p2 = origins(FIVE)
    O1, O2 = joints["motor1"], joints["motor2"]
    return O1, O2, np.linalg.norm(joints["elbow1"]), np.linalg.norm(joints["elbow2"]), np.linalg.norm(p1), np.linalg.norm(p2)


def centres(sol):
    """The joint centres of a five-bar solution: (O1, A1, O2, A2, P) from the links' frame origins
    (each link's frame sits on the joint that carries it; tip's on the loop joint P)."""
    L = sol["links"]
    return [np.array(L[n]["position"][:2]) for n in ("proximal1", "distal1", "proximal2", "distal2", "tip")]


def match(found, expected, atol=1e-9):
    """Every solution's joint centres equal one closed-form assembly, each assembly met once."""
    assert len(found) == len(expected)
    left = list(expected)
    for pts in found:
        k = next((i for i, e in enumerate(left) if all(np.allclose(a, b, atol=atol) for a, b in zip(pts, e))), None)
        assert k is not None, (pts, left)
        left.pop(k)


@pytest.mark.parametrize("theta1,phi", [(110, -60), (95, -100), (130, -80)])
def test_five_bar_crank_and_the_floating_link_on_it(capsys, theta1, phi):
    """Crank 1 at theta1 and distal1 (on crank 1's tip) at phi: P = A1 + b1 u(phi); A2 on circles
    (O2, a2) and (P, b2)."""
    O1, O2, a1, a2, b1, b2 = five_bar()
    t1, ph = np.radians(theta1), np.radians(phi)
    A1 = O1 + a1 * u(t1)
    P = A1 + b1 * u(ph)
    expected = [[O1, A1, O2, A2, P] for A2 in circles(O2, a2, P, b2)]
    d = run_json(capsys, ["solve", str(FIVE), "--set-angle", f"proximal1={theta1}deg", "--set-angle",
                          f"distal1={phi}deg"])
    assert d["held_angles"] == {"distal1": pytest.approx(ph, abs=1e-12)}
    match([centres(s) for s in d["solutions"]], expected)
    for s in d["solutions"]:
        assert abs(wrap(s["link_angles"]["distal1"] - ph)) < 1e-9
        assert abs(wrap(s["link_angles"]["proximal1"] - t1)) < 1e-9


def test_five_bar_floating_link_across_the_loop(capsys):
    """Crank 1 at theta1 and distal2 (on the other crank) at phi: A2 on circles (O2, a2) and
    (A1 - b2 u(phi), b1), P = A2 + b2 u(phi)."""
    O1, O2, a1, a2, b1, b2 = five_bar()
    t1, ph = np.radians(110), np.radians(-120)
    A1 = O1 + a1 * u(t1)
    expected = [[O1, A1, O2, A2, A2 + b2 * u(ph)] for A2 in circles(O2, a2, A1 - b2 * u(ph), b1)]
    d = run_json(capsys, ["solve", str(FIVE), "--set-angle", "proximal1=110deg", "--set-angle", "distal2=-120deg"])
    match([centres(s) for s in d["solutions"]], expected)
    for s in d["solutions"]:
        assert abs(wrap(s["link_angles"]["distal2"] - ph)) < 1e-9


def test_five_bar_rates_of_a_floating_input(capsys):
    """--rate/--accel of the crank and of the floating link: P's velocity and acceleration are the two
    rotations' (about O1, then about A1), and each link turns at the rate given."""
    O1, O2, a1, a2, b1, b2 = five_bar()
    t1, ph = np.radians(110), np.radians(-60)
    w1, w, al1, al = 1.5, -2.0, 0.7, 3.0
    r1, r2 = a1 * u(t1), b1 * u(ph)
    v = k_cross(w1, r1) + k_cross(w, r2)
    a = k_cross(al1, r1) - w1**2 * r1 + k_cross(al, r2) - w**2 * r2
    d = run_json(capsys, ["solve", str(FIVE), "--set-angle", "proximal1=110deg", "--set-angle", "distal1=-60deg",
                          "--rate", f"proximal1={w1},distal1={w}", "--accel", f"proximal1={al1},distal1={al}"])
    assert len(d["solutions"]) == 2
    for s in d["solutions"]:
        L = s["links"]
        assert L["proximal1"]["omega"] == pytest.approx(w1, abs=1e-12)
        assert L["distal1"]["omega"] == pytest.approx(w, abs=1e-9)
        assert L["distal1"]["alpha"] == pytest.approx(al, abs=1e-9)
        np.testing.assert_allclose(L["tip"]["velocity"][:2], v, atol=1e-9)
        np.testing.assert_allclose(L["tip"]["acceleration"][:2], a, atol=1e-9)
        # the crank's rate is its joint's (motor1 turns +z)
        assert s["rates"]["motor1"] == pytest.approx(w1, abs=1e-12)


def test_five_bar_rates_need_no_rate_flag(capsys):
    """Without --rate or --accel no rates are reported (as for joint inputs)."""
    d = run_json(capsys, ["solve", str(FIVE), "--set", "motor1=-10deg", "--set-angle", "distal1=-60deg"])
    assert all("rates" not in s for s in d["solutions"])


@pytest.mark.parametrize("path,phis", [(FOUR, (20, 25)), (DATA / "student" / "fourbar_5796.urdf", (120, -150))])
def test_four_bar_coupler_angle_as_the_only_input(capsys, path, phis):
    """The coupler's angle phi instead of the crank's: A = O1 + a u(theta2) and |A + b u(phi) - O2| = c,
    so A lies on circles (O1, a) and (O2 - b u(phi), c): two crank angles.  The student's file turns on
    continuous joints (a coordinate pair cos, sin each)."""
    joints, p1, p2 = origins(path)
    O1, O2 = joints["crank_joint"], joints["rocker_joint"]
    a, b, c = np.linalg.norm(joints["coupler_joint"]), np.linalg.norm(p1), np.linalg.norm(p2)
    for phi in phis:
        ph = np.radians(phi)
        cranks = sorted(np.arctan2(*(A - O1)[::-1]) for A in circles(O1, a, O2 - b * u(ph), c))
        d = run_json(capsys, ["solve", str(path), "--set-angle", f"coupler={phi}deg"])
        got = sorted(s["link_angles"]["crank"] for s in d["solutions"])
        np.testing.assert_allclose(got, cranks, atol=1e-9)
        assert d["input_joints"] == [] and d["free_dofs"] == 0
        for s in d["solutions"]:
            assert abs(wrap(s["link_angles"]["coupler"] - ph)) < 1e-9
        # the text says which angle is the input
        code, out, _ = run(capsys, ["solve", str(path), "--set-angle", f"coupler={phi}deg"])
        assert code == 0 and f"angle of coupler = {ph:.9g} rad" in out


def test_configuration_commands_take_a_floating_angle(capsys, tmp_path):
    """statics, singularities, export and draw analyse the configuration the angle gives (the same
    joint values as solve's first mode)."""
    args = ["--set-angle", "proximal1=110deg", "--set-angle", "distal1=-60deg"]
    first = run_json(capsys, ["solve", str(FIVE), *args])["solutions"][0]["joints"]
    sing = run_json(capsys, ["singularities", str(FIVE), *args])
    assert sing["mode"] == {"index": 1, "of": 2}
    code, out, err = run(capsys, ["export", str(FIVE), *args, "--urdf", str(tmp_path / "x.urdf")])
    assert code == 0
    for name in ("motor1", "elbow1", "motor2", "elbow2"):  # the tree's joints (the loop joint is not written)
        assert f"{name} = {first[name]:.6g}" in out
    code, _, err = run(capsys, ["draw", str(FIVE), *args, "--png", str(tmp_path / "x.png")])
    assert code == 0 and (tmp_path / "x.png").stat().st_size > 0
    assert run_json(capsys, ["statics", str(FIVE), *args])["mode"] == {"index": 1, "of": 2}


@pytest.mark.parametrize("argv,code,words", [
    ([str(FIVE), "--set-angle", "ground=10deg"], 2, ["'ground' is the ground"]),
    ([str(FIVE), "--set-angle", "nolink=10deg"], 2, ["no moving link named 'nolink'"]),
    ([str(FIVE), "--set-angle", "tip=10deg"], 2, ["'tip' is fixed to 'distal1'"]),
    ([str(FIVE), "--set-angle", "distal1=3mm"], 2, ["unit of length"]),
    ([str(FOUR), "--set", "crank_joint=30deg", "--set-angle", "coupler=20deg"], 2,
     ["angle of 'coupler' is fixed by the other inputs (crank_joint)"]),
    ([str(FIVE), "--set-angle", "proximal1=110deg", "--set-angle", "distal1=10deg", "--set-angle",
      "distal2=10deg"], 2, ["angle of 'distal2' is fixed by the other inputs (motor1, distal1)"]),
    ([str(ROBOTS / "rssr.urdf"), "--set-angle", "crank=10deg"], 2, ["planar"]),
    ([str(FOUR), "--set-angle", "coupler=10deg"], 1, ["the angle of coupler cannot be reached"]),
    ([str(FIVE), "--set-angle", "proximal1=110deg", "--set-angle", "distal1=-60deg", "--rate", "distal2=1"], 2,
     ["--rate distal2: not an input"]),
    ([str(FIVE), "--set-angle", "distal1=-60deg", "--set", "motor1=10deg", "--rate", "distal1=3mm/s"], 2,
     ["'distal1' is a link given by its angle, mm/s is a unit of linear rate"]),
])
def test_errors(capsys, argv, code, words):
    got, out, err = run(capsys, ["solve", *argv])
    assert got == code
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    for w in words:
        assert w in err


@pytest.mark.slow  # about 1.5 s on 2 shared cores: out of the fast subset
def test_report_takes_a_held_angle_for_its_positions_equations_and_newton(capsys, tmp_path):
    """report with a floating link's angle: its positions are solve's (the same numbers), its equations
    hold that link's theta as an input, Newton converges to the solved values, and its sweep moves the
    joint input with the angle held (the limit positions where the other dyad stretches or folds)."""
    argv = [str(FIVE), "--set", "motor1=-10deg", "--set-angle", "distal1=-60deg", "--rate", "motor1=1.5,distal1=-2"]
    sol = run_json(capsys, ["solve", *argv, "--json"])["solutions"][0]
    md = tmp_path / "r.md"
    got, _, err = run(capsys, ["report", *argv, "--md", str(md), "--no-view"])
    assert got == 0, err
    text = md.read_text()
    assert "angle of distal1 = -60 deg" in text
    data = json.loads((tmp_path / "r_files" / "data.json").read_text())
    rep = data["solve"]["solutions"][0]
    assert rep["links"].keys() == sol["links"].keys()
    for link, m in sol["links"].items():
        for key in ("angle", "omega", "alpha"):
            assert rep["links"][link].get(key) == pytest.approx(m.get(key), abs=1e-12)
    assert sol["links"]["distal1"]["angle"] == pytest.approx(np.radians(-60), abs=1e-9)
    assert data["newton"]["closes"] and "inputs held: θ2 = 110 deg, θ3 = -60 deg" in text
    # motor1 moved with distal1 held: its limit positions are where the dyad O2-A2-P stretches or folds,
    # |O1 + a1 u(theta1) + b1 u(phi) - O2| = a2 + b2 or |a2 - b2| (theta1 = motor1 + the crank's offset)
    O1, O2, a1, a2, b1, b2 = five_bar()
    offset = sol["links"]["proximal1"]["angle"] - sol["joints"]["motor1"]
    limits = [f["input"] for f in data["singular_configurations"]["found"] if f["limit"]]
    assert limits and "Sweep of the input" in text
    for x in limits:
        reach = np.linalg.norm(O1 + a1 * u(x + offset) + b1 * u(np.radians(-60)) - O2)
        assert min(abs(reach - (a2 + b2)), abs(reach - abs(a2 - b2))) < 1e-9


def test_draw_animate_holds_a_floating_link_angle(capsys, tmp_path):
    """draw --animate moves motor1 with distal1's angle held (the motion sweep --set-angle follows): one
    frame a value, as for joint inputs."""
    gif = tmp_path / "a.gif"
    d = run_json(capsys, ["draw", str(FIVE), "--animate", str(gif), "--input", "motor1", "--from", "-10deg",
                          "--to", "10deg", "--steps", "4", "--set-angle", "distal1=-60deg"])
    assert d["frames"] == 5 and d["stopped_at"] is None and gif.stat().st_size > 0
    assert d["values"] == pytest.approx(np.radians([-10, -5, 0, 5, 10]))


@pytest.mark.parametrize("argv", [["view", "--interactive"]])
def test_commands_moving_joint_inputs_refuse_a_held_angle(capsys, tmp_path, argv):
    """view --interactive moves joint inputs with sliders: a held angle is refused in one line, not dropped."""
    argv = [str(tmp_path / a) if a.endswith((".gif", ".md")) else a for a in argv]
    got, _, err = run(capsys, [argv[0], str(FIVE), *argv[1:], "--set-angle", "distal1=-60deg"])
    assert got == 2 and "held by its angle" in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_four_bar_rates_from_the_coupler_in_solve_and_in_the_equations(capsys):
    """The coupler turning at w3: a w2 u'(theta2) + b w3 u'(phi) - c w4 u'(theta4) = 0 (u' = d u / d angle),
    two equations for w2, w4 at the closed-form assembly; solve --rate coupler=1 and the vector-loop
    equations (theta3 known, A^-1 B) give them."""
    joints, p1, p2 = origins(FOUR)
    O1, O2 = joints["crank_joint"], joints["rocker_joint"]
    a, b, c = np.linalg.norm(joints["coupler_joint"]), np.linalg.norm(p1), np.linalg.norm(p2)
    ph = np.radians(20)

    def du(t):
        return np.array([-np.sin(t), np.cos(t)])

    expected = {}
    for A in circles(O1, a, O2 - b * u(ph), c):
        t2 = np.arctan2(*(A - O1)[::-1])
        B = A + b * u(ph)
        t4 = np.arctan2(*(B - O2)[::-1])
        w2, w4 = np.linalg.solve(np.column_stack([a * du(t2), -c * du(t4)]), -b * du(ph))
        expected[round(float(t2), 6)] = (w2, w4)
    d = run_json(capsys, ["solve", str(FOUR), "--set-angle", "coupler=20deg", "--rate", "coupler=1"])
    for s in d["solutions"]:
        w2, w4 = expected[round(s["link_angles"]["crank"], 6)]
        # (relative 1e-7: the positions close to 1e-11 m on 0.04 m links, near a limit position sigma ~ 0.02)
        assert s["links"]["crank"]["omega"] == pytest.approx(w2, rel=1e-7)
        assert s["links"]["rocker"]["omega"] == pytest.approx(w4, rel=1e-7)
        assert s["links"]["coupler"]["omega"] == pytest.approx(1.0, abs=1e-12)
    for mode in (1, 2):
        eq = run_json(capsys, ["equations", str(FOUR), "--set-angle", "coupler=20deg", "--mode", str(mode)])
        assert eq["inputs"] == {"theta3": "coupler"} and eq["unknowns"] == ["theta2", "theta4"]
        w2, w4 = expected[round(eq["symbols"]["theta2"]["value"], 6)]
        assert eq["symbols"]["theta3"]["role"] == "input"
        np.testing.assert_allclose(np.ravel(eq["at_configuration"]["unknown_rates_per_input_rate"]), [w2, w4],
                                   rtol=1e-7)


def test_holding_an_angle_leaves_the_mechanism_as_it_was():
    """The angle row lives on a copy (Mechanism.with_rows): the mechanism's own closure, rows and solves
    are the same after."""
    mech = screwkin.load(str(FIVE))
    values = {"motor1": np.radians(-10), "motor2": np.radians(20)}
    before = [s.q for s in PositionSolver(mech, list(values)).solve(values).solutions]
    rows, closure = mech.closure.nrows, mech.closure
    held = holding_angles(mech, ["motor1"], {"distal1": np.radians(-60)})
    assert held.closure.nrows == rows + 1 and held.closure.row_inputs == ("distal1",)
    PositionSolver(held, ["motor1"]).solve({"motor1": np.radians(-10)})
    assert mech.closure is closure and mech.closure.nrows == rows and mech.extra_rows == []
    after = [s.q for s in PositionSolver(mech, list(values)).solve(values).solutions]
    np.testing.assert_allclose(np.array(after), np.array(before), atol=1e-12)


def test_the_angle_row_against_forward_kinematics():
    """The row's residual is distal1's angle (A1 -> P, from Pinocchio's placements here) minus the value
    held, modulo a turn, and its Jacobian row is that angle's finite difference (on the manifold)."""
    mech = screwkin.load(str(FIVE))
    phi = np.radians(-60)
    held = holding_angles(mech, ["motor1"], {"distal1": phi})
    model, data = mech.model, mech.model.createData()
    elbow, end = model.getJointId("elbow1"), next(c.frame1 for c in mech.cuts if c.name == "end_joint")

    def angle(q):
        pin.framesForwardKinematics(model, data, q)
        d = data.oMf[end].translation - data.oMi[elbow].translation
        return np.arctan2(d[1], d[0])

    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-3, 3, model.nq)
        r = held.closure.residual(q)[-1]
        assert r == pytest.approx(wrap(angle(q) - phi), abs=1e-12)
        turned = pin.integrate(model, q, 2 * np.pi * np.eye(model.nv)[1])  # elbow1 a whole turn on
        assert held.closure.residual(turned)[-1] == pytest.approx(r, abs=1e-9)
        J = held.closure.jacobian(q)[-1]
        h = 1e-6
        fd = [wrap(angle(pin.integrate(model, q, h * e)) - angle(pin.integrate(model, q, -h * e))) / (2 * h)
              for e in np.eye(model.nv)]
        np.testing.assert_allclose(J, fd, atol=1e-7)


def test_newton_from_estimates_with_the_coupler_angle_known(capsys):
    """solve --start with the coupler's angle given: one step of Newton on the loop equations
    F = (-d + a cos t2 + b cos phi - c cos t4, a sin t2 + b sin phi - c sin t4), written here, and the
    converged crank angle is the closed form's."""
    joints, p1, p2 = origins(FOUR)
    O1, O2 = joints["crank_joint"], joints["rocker_joint"]
    a, b, c, d = (np.linalg.norm(joints["coupler_joint"]), np.linalg.norm(p1), np.linalg.norm(p2),
                  np.linalg.norm(O2 - O1))
    ph, t2, t4 = np.radians([20, 40, 60])
    F = np.array([-d + a * np.cos(t2) + b * np.cos(ph) - c * np.cos(t4), a * np.sin(t2) + b * np.sin(ph) - c * np.sin(t4)])
    A = np.array([[-a * np.sin(t2), c * np.sin(t4)], [a * np.cos(t2), -c * np.cos(t4)]])
    step = np.linalg.solve(A, -F)
    args = ["solve", str(FOUR), "--set-angle", "coupler=20deg", "--start", "theta2=40deg,theta4=60deg"]
    one = run_json(capsys, [*args, "--iterations", "1"])
    assert one["inputs"] == {"theta3": pytest.approx(ph, abs=1e-15)}
    np.testing.assert_allclose([one["values"]["theta2"], one["values"]["theta4"]], [t2, t4] + step, atol=1e-12)
    done = run_json(capsys, args)
    crank = done["solutions"][0]["link_angles"]["crank"]
    closed = [np.arctan2(*(X - O1)[::-1]) for X in circles(O1, a, O2 - b * u(ph), c)]
    assert min(abs(wrap(crank - x)) for x in closed) < 1e-9
    assert done["held_angles"] == {"coupler": pytest.approx(ph, abs=1e-12)}


def test_a_bare_angle_beyond_a_turn_warns(capsys):
    """--set-angle distal1=30 is 30 rad: read so (the same row as 30 - 10 pi rad), with a warning."""
    code, out, err = run(capsys, ["solve", str(FIVE), "--set-angle", "proximal1=110deg", "--set-angle", "distal1=30"])
    assert "distal1=30 is read as 30 rad = 1718.87 deg" in err
    assert code == 0 and f"angle of distal1 = {wrap(30.0):.9g} rad" in out


def test_sweep_holds_a_floating_link_angle_along_the_motion(capsys):
    """sweep motor1 with distal1's absolute angle held (--set-angle): at every step distal1 stays at -60 deg
    and every joint centre is the closed form's (the far end of distal1 from the crank tip along phi, then
    the dyad to motor2 by circle intersection, on the branch of the first step)."""
    O1, O2, a1, a2, b1, b2 = five_bar()
    phi = np.radians(-60)
    d = run_json(capsys, ["sweep", str(FIVE), "--input", "motor1", "--from", "-10deg", "--to", "10deg",
                          "--steps", "8", "--set-angle", "distal1=-60deg"])
    assert d["held_angles"] == {"distal1": pytest.approx(phi)}
    links = d["links"]
    assert np.allclose(links["distal1"]["angle"], phi, atol=1e-9)
    th1 = np.array(links["proximal1"]["angle"])
    A1 = O1 + a1 * np.stack([np.cos(th1), np.sin(th1)], axis=1)
    P = A1 + b1 * u(phi)
    assert np.allclose(np.array(links["tip"]["position"])[:, :2], P, atol=1e-9)
    A2 = np.array(links["distal2"]["position"])[:, :2]  # the elbow of the second arm
    assert np.allclose(np.linalg.norm(A2 - O2, axis=1), a2, atol=1e-9)
    assert np.allclose(np.linalg.norm(P - A2, axis=1), b2, atol=1e-9)
    k0 = np.argmin([np.linalg.norm(A2[0] - c) for c in circles(O2, a2, P[0], b2)])
    for k in range(len(P)):  # the branch of the first step, followed
        expected = circles(O2, a2, P[k], b2)
        assert np.linalg.norm(A2[k] - expected[k0]) < 1e-9
