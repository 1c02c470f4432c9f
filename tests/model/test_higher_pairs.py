"""Higher pairs and couplings: rolling, gears, racks, cams, pins in slots, screws.  Against
textbook counts, closed forms written here, and finite differences on the manifold."""

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.singular_points import locate_singularities
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main


def load(name):
    return screwkin.load(ROBOTS / f"{name}.urdf")


def wrap(x):
    return float(np.mod(x + np.pi, 2 * np.pi) - np.pi)


def angle(v):
    return float(np.arctan2(v[1], v[0]))


@pytest.mark.parametrize("name, N, J1, J2, F", [
    ("friction_wheels", 4, 4, 0, 1),     # the course problem: L = 1, F = 1
    ("cam_followers", 4, 3, 2, 1),       # N = 4, J1 = 3, J2 = 2, F = 1
    ("quick_return_slot", 3, 2, 1, 1),
    ("rack_pinion", 3, 3, 0, 0),         # 3(2) - 2(3) = 0 (with the guides' redundant centre distance)
    ("gear_train_idler", 4, 5, 0, -1),
])
def test_planar_counts_as_the_textbooks_write_them(capsys, name, N, J1, J2, F):
    assert main(["mobility", str(ROBOTS / f"{name}.urdf"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert (d["links"], d["J1"], d["J2"]) == (N, J1, J2)
    assert 3 * (N - 1) - 2 * J1 - J2 == F == d["gruebler"]
    assert d["mobility"] == 1
    kinds = {j["name"]: (j["pair"], j["motion"], j["contact"]) for j in d["joints"]}
    for j in d["joints"]:
        if j["type"] in ("rolling", "gear", "contact"):
            assert j["pair"] == "higher" and j["contact"] in ("line", "point")
        else:
            assert j["pair"] == "lower" and j["contact"] == "surface"
    assert kinds.get("tip", ("higher", "rolling and sliding", "point"))[2] == "point"
    assert main(["mobility", str(ROBOTS / f"{name}.urdf")]) == 0
    text = capsys.readouterr().out
    assert "3(N-1) - 2 J1 - J2" in text and "pair (contact)" in text


def test_friction_wheels_at_45_deg_against_the_closed_form():
    """theta2 = 45 deg turns the centre (8, 8) to (0, 8 sqrt 2) mm; the slider puts disc 3's centre
    on the x axis 30 mm from it; no slip, rho2 (t2 - tk) = -rho3 (t3 - tk), followed from the drawing."""
    mech = load("friction_wheels")
    solver = PositionSolver(mech, ["wheel2_joint"])
    res = sweep(solver, "wheel2_joint", 0.0, np.radians(45), 45)
    assert res.stopped_at is None
    r2, r3 = 0.020, 0.010
    c2 = lambda t: np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]]) @ np.array([0.008, 0.008])
    x3 = lambda t: c2(t)[0] + np.sqrt(0.03 ** 2 - c2(t)[1] ** 2)
    t_end = np.radians(45)
    assert res.joints[-1][list(res.names).index("slide")] + x3(0.0) == pytest.approx(x3(t_end), abs=1e-12)
    assert x3(t_end) == pytest.approx(np.sqrt(0.03 ** 2 - 2 * 0.008 ** 2), abs=1e-15)
    tk = lambda t: angle(np.array([x3(t), 0.0]) - c2(t))  # line of centres
    # disc 3's turn, unwrapped along the motion: d t3 = d tk - (rho2 / rho3)(d t2 - d tk)
    turn = np.unwrap(res.joints[:, list(res.names).index("wheel3_joint")])
    want = (tk(t_end) - tk(0.0)) - (r2 / r3) * (t_end - (tk(t_end) - tk(0.0)))
    assert turn[-1] - turn[0] == pytest.approx(want, abs=1e-9)
    # and solved directly for 45 deg, the branch on this side: the same
    s = PositionSolver(mech, ["wheel2_joint"]).solve({"wheel2_joint": t_end}, near={"slide": 0.0})
    q = s.solutions[0].q
    pin.framesForwardKinematics(mech.model, mech.data, q)
    d = mech.data.oMf[mech.link_frame("wheel3")].translation - mech.data.oMf[mech.model.getFrameId("wheels@F1")].translation
    assert np.linalg.norm(d) == pytest.approx(r2 + r3, abs=1e-10)  # the closure tolerance



def test_friction_wheels_at_45_deg_has_both_assemblies(capsys):
    """The rolling-contact course problem at theta2 = 45 deg: disc 2's centre at (0, 8 sqrt 2) mm, disc 3's
    centre on the x axis 30 mm from it, so at x = +-sqrt(30^2 - 2 * 8^2) mm: the upper assembly (the
    drawing's side) and the lower one.  A release that kept only the solutions whose rolling angles
    continue the drawing's (as a thread or a tooth would) dropped the lower assembly; it is another
    mode, not another turn, and is reported (labelled: its slider lies outside the slide's limits)."""
    assert main(["solve", str(ROBOTS / "friction_wheels.urdf"), "--set", "wheel2_joint=45deg", "--all", "--json"]) == 0
    sols = json.loads(capsys.readouterr().out)["solutions"]
    x_drawn = 0.008 + np.sqrt(0.03 ** 2 - 0.008 ** 2)  # disc 3's centre at theta2 = 0 (the file's comment)
    x3 = np.sqrt(0.03 ** 2 - 2 * 0.008 ** 2)
    got = sorted(s["joints"]["slide"] + x_drawn for s in sols)
    np.testing.assert_allclose(got, [-x3, x3], rtol=0, atol=1e-9)
    assert [s["physical"] for s in sorted(sols, key=lambda s: -s["joints"]["slide"])] == [True, False]

@pytest.mark.parametrize("name", ["gear_train_idler", "gear_train_idler_mimic"])
def test_gear_train_output_speed_ratio(name):
    mech = load(name)
    res = PositionSolver(mech, ["input_joint"], output="output").solve({"input_joint": 0.3}, rates={"input_joint": 1.0})
    s = res.solutions[0]
    assert s.output_twist[5] == pytest.approx(0.05 / 0.08, abs=1e-12)  # (-r1/r2)(-r2/r3) = r1/r3


def test_rack_moves_two_pi_r_per_turn():
    mech = load("rack_pinion")
    res = sweep(PositionSolver(mech, ["pinion_joint"]), "pinion_joint", 0.0, 2 * np.pi, 24)
    x = res.joints[:, list(res.names).index("rack_joint")]
    assert abs(x[-1] - x[0]) == pytest.approx(2 * np.pi * 0.04, abs=1e-12)
    np.testing.assert_allclose(np.abs(x - x[0]), 0.04 * res.values, atol=1e-12)


@pytest.mark.parametrize("name, carriage", [("lead_screw_jack", "lift"), ("lead_screw_mimic", None)])
def test_lead_screw_moves_one_lead_per_turn(name, carriage):
    mech = load(name)
    inp = mech.actuated[0]
    res = sweep(PositionSolver(mech, [inp], output="carriage" if carriage else "nut"), inp, 0.0, 6 * np.pi, 30)
    if carriage:
        z = res.joints[:, list(res.names).index(carriage)]
    else:
        z = res.coupled["nut_advance"]
    assert abs(z[-1] - z[0]) == pytest.approx(3 * 0.005, abs=1e-12)  # three turns, three leads
    assert np.allclose(np.abs(np.diff(z)), 0.005 / (2 * np.pi) * np.diff(res.values), atol=1e-12)


def test_the_mimic_screw_is_one_screw_pair():
    r = load("lead_screw_mimic").mobility(output="nut")
    (j,) = r.topology.joints
    assert (j.type, j.dof, j.motion, j.pair) == ("helical", 1, "helical (screw)", "lower")
    assert r.topology.couplings == () and r.kutzbach == 1 == r.mobility
    assert r.output.label.startswith("1H") and "0.0007958" in r.output.label  # pitch lead / 2 pi [m/rad]


@pytest.mark.parametrize("t", np.radians([0.0, 35.0, 100.0, 210.0, 300.0]))
def test_cam_followers_against_the_circle_and_line_distances(t):
    """The cam's circle (radius 0.03, centre C = 0.01 (cos t, sin t)): the plunger's tip on it,
    y = C_y + sqrt(R^2 - C_x^2); the rocker's face through P = (0.05, 0.04) at distance R from C,
    its angle atan2(C - P) - asin(R / |C - P|)."""
    mech = load("cam_followers")
    R = 0.03
    C = 0.01 * np.array([np.cos(t), np.sin(t)])
    P = np.array([0.05, 0.04])
    res = PositionSolver(mech, ["cam_joint"]).solve({"cam_joint": t})
    want_tip = C[1] + np.sqrt(R ** 2 - C[0] ** 2)
    tip0 = np.sqrt(R ** 2 - 0.01 ** 2)
    phi0 = angle(np.array([0.01, 0.0]) - P) - np.arcsin(R / np.linalg.norm(np.array([0.01, 0.0]) - P))
    want_phi = angle(C - P) - np.arcsin(R / np.linalg.norm(C - P))
    hits = [s for s in res.solutions
            if abs(s.joints["plunger_joint"] + tip0 - want_tip) < 1e-10
            and abs(wrap(s.joints["rocker_joint"] + phi0 - want_phi)) < 1e-9]
    assert hits, [(s.joints["plunger_joint"] + tip0, s.joints["rocker_joint"] + phi0) for s in res.solutions]


def test_quick_return_ratio_is_two():
    """The lever stops where the slot is tangent to the pin's circle: the crank turns
    180 + 2 asin(r / d) = 240 deg one way and 120 deg back."""
    mech = load("quick_return_slot")
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 180)
    stops = sorted(s.input for s in locate_singularities(solver, res, output="slotted") if s.kind == "serial")
    assert len(stops) == 2
    forward = stops[1] - stops[0]
    ratio = max(forward, 2 * np.pi - forward) / min(forward, 2 * np.pi - forward)
    assert ratio == pytest.approx(2.0, abs=1e-9)
    assert max(forward, 2 * np.pi - forward) == pytest.approx(np.radians(180 + 2 * 30), abs=1e-9)


# ------------------------------------------------------------------ Jacobians, rates, accelerations
HIGHER = ["friction_wheels", "gear_train_idler", "rack_pinion", "cam_followers", "quick_return_slot",
          "lead_screw_jack"]


@pytest.mark.parametrize("name", HIGHER)
def test_constraint_jacobian_matches_finite_differences_on_the_manifold(name):
    mech = load(name)
    rng = np.random.default_rng(3)
    q = mech.generic_configurations()[1][0]
    q = pin.integrate(mech.model, q, rng.normal(scale=0.2, size=mech.nv))  # also off the closed set
    K = mech.closure.jacobian(q)
    h = 1e-6
    for i in range(mech.nv):
        e = np.zeros(mech.nv)
        e[i] = h
        fd = (mech.closure.residual(pin.integrate(mech.model, q, e))
              - mech.closure.residual(pin.integrate(mech.model, q, -e))) / (2 * h)
        np.testing.assert_allclose(K[:, i], fd, atol=1e-7, rtol=0)


@pytest.mark.parametrize("name, inp", [("friction_wheels", "wheel2_joint"), ("cam_followers", "cam_joint"),
                                       ("quick_return_slot", "crank_joint"), ("rack_pinion", "pinion_joint")])
def test_rates_and_accelerations_match_finite_differences_along_a_motion(name, inp):
    mech = load(name)
    res = sweep(PositionSolver(mech, [inp]), inp, 0.2, 0.6, 400)
    h = res.values[1] - res.values[0]
    values = np.unwrap(res.joints, axis=0)
    fd = (values[2:] - values[:-2]) / (2 * h)
    np.testing.assert_allclose(res.rates[1:-1, :fd.shape[1]][:, :values.shape[1]], fd, atol=2e-5)
    fd2 = (res.rates[2:] - res.rates[:-2]) / (2 * h)
    np.testing.assert_allclose(res.accelerations[1:-1], fd2, atol=2e-4)


# ------------------------------------------------------------------ bad values
GOOD = (ROBOTS / "friction_wheels.urdf").read_text()
CAM = (ROBOTS / "cam_followers.urdf").read_text()
SCREW = (ROBOTS / "lead_screw_jack.urdf").read_text()


@pytest.mark.parametrize("text, word", [
    (GOOD.replace('radius1="0.02"', 'radius1="0"'), "radius1 must be positive"),
    (GOOD.replace('radius2="0.01"', 'radius2="-0.01"'), "radius2 must be positive"),
    (GOOD.replace('radius2="0.01" contact="external"', 'radius2="0.03" contact="internal"'), "radius2 < radius1"),
    (GOOD.replace('contact="external"', 'contact="sideways"'), "'sideways'"),
    (GOOD.replace('<rolling radius1="0.02" radius2="0.01" contact="external"/>', ''), "needs a <rolling"),
    (CAM.replace('shape="line"', 'shape="ellipse"'), "unknown shape 'ellipse'"),
    (CAM.replace('<profile1 shape="circle" radius="0.03"/><profile2 shape="line"/>',
                 '<profile1 shape="line"/><profile2 shape="line"/>'), "no sliding contact"),
    (SCREW.replace('<pitch lead="0.005"/>', ''), "needs a <pitch lead"),
    (SCREW.replace('lead="0.005"', 'lead="0"'), "no lead is a revolute"),
])
def test_bad_higher_pair_values_are_one_line_errors(tmp_path, capsys, text, word):
    p = tmp_path / "m.urdf"
    p.write_text(text)
    assert main(["info", str(p)]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and word in err and str(p) in err, err


@pytest.mark.parametrize("typed,theta", [("720deg", 4 * np.pi), ("90deg", np.pi / 2), ("-1.5turn", -3 * np.pi),
                                         ("1000deg", np.radians(1000))])
def test_a_screw_counts_turns(typed, theta, capsys):
    """issue 25 item 13: robots/lead_screw_jack.urdf, lead 5 mm: |lift| = lead * |theta| / 2 pi over any number
    of turns (the file's convention: lift = -lead theta / 2 pi, as at 90 deg), one solution, the input as typed."""
    import json

    from screwkin.cli import main

    assert main(["solve", str(ROBOTS / "lead_screw_jack.urdf"), "--set", f"screw_joint={typed}", "--all",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["inputs"]["screw_joint"] == pytest.approx(theta, abs=1e-12)  # the header's input, as typed
    (sol,) = out["solutions"]
    assert sol["joints"]["lift"] == pytest.approx(-0.005 * theta / (2 * np.pi), abs=1e-9)
    assert sol["joints"]["screw_joint"] == pytest.approx(theta, abs=1e-12)


@pytest.mark.parametrize("deg", [30.0, 390.0, 750.0, -500.0])
def test_a_gear_train_counts_turns(deg, capsys):
    """robots/gear_train_idler.urdf: input 0.05, idler 0.03, output 0.08 m pitch radii: the output turns
    deg * 0.05 / 0.08 the same way (two external meshes), modulo a turn as the joint is reported."""
    import json

    from screwkin.cli import main

    assert main(["solve", str(ROBOTS / "gear_train_idler.urdf"), "--set", f"input_joint={deg}deg", "--json"]) == 0
    sols = json.loads(capsys.readouterr().out)["solutions"]
    assert len(sols) == 1
    out = np.degrees(sols[0]["joints"]["output_joint"])
    at_zero = 0.0  # the file's output at input 0 (the gears are drawn at zero)
    expected = at_zero + deg * 0.05 / 0.08
    assert np.mod(out - expected + 180, 360) - 180 == pytest.approx(0, abs=1e-7)


@pytest.mark.parametrize("deg", [100, 160, -160, 200, 390, -150, -400, 720])
def test_gear_train_output_is_the_ratio_times_the_input(deg):
    """Input 0.05 m, idler 0.03 m, output 0.08 m: output = (r1 / r3) input = 0.625 input, the idler reversing
    twice, whatever the input (within a turn or beyond).  At 160 deg solve gave 35 deg (the idler's two meshes
    counted its turn differently: no start reached the counted angles of the motion from the file's drawing)."""
    import math

    m = screwkin.load(Path(__file__).resolve().parents[2] / "robots" / "gear_train_idler.urdf")
    res = screwkin.PositionSolver(m).solve({"input_joint": math.radians(deg)})
    (sol,) = res.solutions
    out = math.degrees(sol.joints["output_joint"])
    want = 0.625 * deg
    assert abs((out - want + 180.0) % 360.0 - 180.0) < 1e-6
    assert math.degrees(sol.joints["mesh2.a2"]) == pytest.approx(want, abs=1e-6)  # the counted angle: every turn
