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
from screwkin.analysis.position.position import PositionSolver
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
    assert set(sol["links"]["rod"]) == {"position", "velocity", "acceleration", "omega", "alpha", "angle",
                                        "angle_along"}
    assert sol["links"]["rod"]["angle_along"] == ["pin_A", "pin_B"]  # the line its angle is measured along
    assert main(["solve", str(path), "--set", "crank_joint=30deg", "--rate", "crank_joint=10"]) == 0
    out = capsys.readouterr().out
    assert "guide (loop)" in out and "absolute link motion" in out and "omega [rad/s]" in out


@pytest.mark.parametrize("crank_deg", [40.0, 160.0, 290.0])
def test_coupler_point_against_circle_intersections(crank_deg, capsys):
    """--point P=coupler:60mm,20mm: the file writes the coupler frame at B along the world x axis with
    C at (0.11388, 0.03783) in it, so the frame is turned by -atan2(0.03783, 0.11388) from B->C."""
    a, b, c, d, w2 = 0.04, 0.12, 0.08, 0.1, 2.0
    offset = -np.arctan2(0.03783022050962147, 0.1138809659960496)
    local = np.array([0.06, 0.02])
    t2 = np.radians(crank_deg)
    t0 = np.radians(60.0)  # the crank as written: B = (0.02, 0.034641)
    argv = ["solve", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", f"crank_joint={crank_deg - 60}deg",
            "--rate", f"crank_joint={w2}", "--point", "P=coupler:60mm,20mm", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    B, D = a * np.array([np.cos(t2), np.sin(t2)]), np.array([d, 0.0])
    assert np.isclose(t0, np.arctan2(0.03464101615137755, 0.02))
    for sol in out["solutions"]:
        p = sol["points"]["P"]
        assert p["link"] == "coupler"
        # which closed-form mode: the C that the reported coupler angle points at
        t3 = sol["links"]["coupler"]["angle"]
        C = min(circles(B, b, D, c), key=lambda X: np.linalg.norm(X - B - b * np.array([np.cos(t3), np.sin(t3)])))
        t3 = np.arctan2(*(C - B)[::-1])
        t4 = np.arctan2(*(C - D)[::-1])
        w3, w4, a3, a4 = _fourbar_rates(a, b, c, t2, t3, t4, w2)
        f = t3 + offset
        r = np.array([[np.cos(f), -np.sin(f)], [np.sin(f), np.cos(f)]]) @ local
        vB, aB = a * w2 * np.array([-np.sin(t2), np.cos(t2)]), -a * w2**2 * np.array([np.cos(t2), np.sin(t2)])
        perp = np.array([-r[1], r[0]])
        assert p["position"] == pytest.approx([*(B + r), 0.0], abs=1e-10)
        assert p["velocity"] == pytest.approx([*(vB + w3 * perp), 0.0], abs=1e-9)
        assert p["acceleration"] == pytest.approx([*(aB + a3 * perp - w3**2 * r), 0.0], abs=1e-8)


@pytest.mark.parametrize("spec,words", [
    ("P=nolink:1,2,3", "no link named 'nolink'"),
    ("P=coupler:1deg,2,3", "unit of angle"),
    ("P=coupler:1", "NAME=LINK:x,y,z"),
    ("coupler:1,2", "NAME=LINK:x,y,z"),
])
def test_bad_points_are_usage_errors(spec, words, capsys):
    argv = ["solve", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=1", "--point", spec]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1


def test_point_alone_keeps_its_old_meaning(capsys):
    """sweep --point (no value) still analyses the output link's origin as a point."""
    argv = ["sweep", str(ROBOTS / "five_bar.urdf"), "--input", "motor1", "--from", "0", "--to", "0.2",
            "--steps", "2", "--set", "motor2=1", "--output", "tip", "--point", "--singularities", "--json"]
    assert main(argv) == 0
    json.loads(capsys.readouterr().out)


def test_sweep_reports_the_slider_and_the_links_at_every_step(tmp_path, capsys):
    """sweep of the crank through 0..270 deg at 1 rad/s: the guide's x, x', x'' at every step are the closed
    form's at the crank's absolute angle; a coupler point's path is one entry per step."""
    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    argv = ["sweep", str(path), "--input", "crank_joint", "--from", "0", "--to", "270deg", "--steps", "27",
            "--point", "M=rod:60mm,0", "--json"]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    (x, xd, xdd), (phi, phid, _) = _slider_closed_form()
    theta0 = np.arctan2(A_Y, A_X)
    n = len(d["values"])
    assert n == 28 and len(d["points"]["M"]["position"]) == n and len(d["links"]["rod"]["omega"]) == n
    for k, v in enumerate(d["values"]):
        t = v + theta0
        assert d["loop_joints"]["guide"][k] == pytest.approx(x(t, 1.0), abs=1e-9)
        assert d["loop_rates"]["guide"][k] == pytest.approx(xd(t, 1.0), abs=1e-8)
        assert d["loop_accelerations"]["guide"][k] == pytest.approx(xdd(t, 1.0), abs=1e-7)
        assert d["links"]["rod"]["omega"][k] == pytest.approx(phid(t, 1.0), abs=1e-8)
        A = np.hypot(A_X, A_Y) * np.array([np.cos(t), np.sin(t)])
        f = phi(t, 1.0) - np.arctan2(B_REL[1], B_REL[0])  # the rod frame: B_REL in it points along A -> B
        M = A + 0.06 * np.array([np.cos(f), np.sin(f)])
        assert d["points"]["M"]["position"][k] == pytest.approx([*M, 0.0], abs=1e-9)


def test_sweep_plot_shows_absolute_link_motion_and_point_paths(tmp_path):
    """The planar sweep plot draws the links' absolute angle/omega/alpha (the vector-loop angle of the
    coupler, unwrapped) and the slider's loop coordinate, and a panel with the point's path in mm."""
    pytest.importorskip("matplotlib")
    from screwkin.analysis.motion.links import Point, motion_along
    from screwkin.analysis.motion.planar import LinkAngles
    from screwkin.analysis.motion.sweep import sweep
    from screwkin.present.plots import absolute_series, sweep_figure

    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    mech = load(str(path))
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 36)
    topo = mech.topology(res.q[0])
    angles = LinkAngles(mech, topo)
    motion = motion_along(mech, res.q, res.rates, res.accelerations, (Point("M", "rod", (0.06, 0.0, 0.0)),),
                          angles, angles.n)
    series, lengths = absolute_series(res, motion, mech.translational)
    assert series.names == ("crank (angle)", "rod (angle)", "guide (loop)")  # the slider block does not turn
    assert list(lengths) == [False, False, True]
    (x, xd, _), (phi, phid, _) = _slider_closed_form()
    t = np.asarray(res.values) + np.arctan2(A_Y, A_X)
    assert series.joints[:, 2] == pytest.approx([x(tk, 1.0) for tk in t], abs=1e-9)
    assert series.rates[:, 1] == pytest.approx([phid(tk, 1.0) for tk in t], abs=1e-8)
    xy = np.asarray(motion.points["M"]["position"])[:, :2]
    fig = sweep_figure(series, linear=lengths, paths={"M": xy}, absolute=True)
    line = next(ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == "M (path)")
    assert np.allclose(line.get_xdata(), 1000 * xy[:, 0]) and np.allclose(line.get_ydata(), 1000 * xy[:, 1])
    import matplotlib.pyplot as plt

    plt.close(fig)


@pytest.mark.parametrize("crank_deg", [30.0, 100.0, 215.0, 320.0])
def test_four_bar_diagonal_construction_by_the_law_of_cosines(crank_deg, capsys):
    """issue 25 item 1: z^2 = a^2 + d^2 - 2ad cos t2; cos beta = (z^2 + d^2 - a^2) / 2zd;
    cos alpha = (z^2 + c^2 - b^2) / 2zc; cos mu = (b^2 + c^2 - z^2) / 2bc; and theta4 = 180 - beta -+ alpha."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.1
    t2 = np.radians(crank_deg)
    argv = ["solve", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", f"crank_joint={crank_deg - 60}deg", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    z = np.sqrt(a * a + d * d - 2 * a * d * np.cos(t2))
    beta = np.arccos((z * z + d * d - a * a) / (2 * z * d))
    alpha = np.arccos((z * z + c * c - b * b) / (2 * z * c))
    mu = np.arccos((b * b + c * c - z * z) / (2 * b * c))
    for sol in out["solutions"]:
        fb = sol["four_bar"]
        assert fb["diagonal"] == pytest.approx(z, abs=1e-12)
        assert fb["beta"] == pytest.approx(beta, abs=1e-9) and fb["alpha"] == pytest.approx(alpha, abs=1e-9)
        assert fb["transmission_angle"] == pytest.approx(mu, abs=1e-9)
        t4 = sol["links"]["rocker"]["angle"]
        s = 1.0 if np.sin(t2) >= 0 else -1.0  # the crank tip above or below the ground line
        options = [s * (np.pi - beta) + alpha, s * (np.pi - beta) - alpha]
        assert min(abs(np.mod(t4 - o + np.pi, 2 * np.pi) - np.pi) for o in options) < 1e-8  # arccos near 0: 1e-9


def test_slider_crank_transmission_angle_per_solution(tmp_path, capsys):
    """mu is the angle between the rod and the normal of the slide: 90 deg - |phi|, phi the rod's angle."""
    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    assert main(["solve", str(path), "--set", "crank_joint=40deg", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for sol in out["solutions"]:
        phi = sol["links"]["rod"]["angle"]
        expected = np.pi / 2 - abs(np.arcsin(np.sin(phi)))
        assert sol["slider_crank"]["transmission_angle"] == pytest.approx(expected, abs=1e-9)


@pytest.mark.slow  # about 2.2 s on 2 shared cores: out of the fast subset
def test_stewart_leg_lengths_set_and_reported_between_u_and_s_centres(capsys):
    """issue 24 item 4: --set-length leg1,...,leg6=0.7; each leg k >= 2 ends at its base U centre (joint basek_a's
    origin) and its platform S centre (ballk's link2 point in the platform frame), read from the file here: the
    distance between them at the solved platform pose is 0.7 m, and each reported leg length is 0.7."""
    import xml.etree.ElementTree as ET

    path = ROBOTS / "gough_stewart_6ups.urdf"
    root = ET.parse(path).getroot()
    base = {j.get("name"): np.array(j.find("origin").get("xyz").split(), float) for j in root.iter("joint")
            if j.find("origin") is not None}
    spheres = {lj.get("name"): np.array(lj.find("link2").get("xyz").split(), float) for lj in root.iter("loop_joint")}
    argv = ["solve", str(path), "--set-length", "leg1,leg2,leg3,leg4,leg5,leg6=700mm", "--output", "platform",
            "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["solutions"]
    for sol in out["solutions"]:
        assert sol["leg_lengths"] == pytest.approx({f"leg{k}": 0.7 for k in range(1, 7)}, abs=1e-9)
        T = np.array(sol["output_pose"])
        for k in range(2, 7):
            s_world = T[:3, :3] @ spheres[f"ball{k}"] + T[:3, 3]
            assert np.linalg.norm(s_world - base[f"base{k}_a"]) == pytest.approx(0.7, abs=1e-9)


def test_leg_length_errors(capsys):
    path = str(ROBOTS / "gough_stewart_6ups.urdf")
    assert main(["solve", path, "--set-length", "leg1=30deg"]) == 2
    assert "a leg length is a length" in capsys.readouterr().err
    assert main(["solve", path, "--set-length", "base1_a=0.5"]) == 2
    assert "not a prismatic joint between two joint centres" in capsys.readouterr().err


def test_stroke_and_time_ratio_of_an_offset_slider_crank(tmp_path, capsys):
    """Stroke sqrt((a + b)^2 - e^2) - sqrt((b - a)^2 - e^2); the crank turns 180 deg -+ (asin(e / (b - a)) -
    asin(e / (a + b))) between the dead centres (the textbook's quick-return angle)."""
    path = tmp_path / "slider.urdf"
    path.write_text(SLIDER)
    a, b, e = np.hypot(A_X, A_Y), np.hypot(*B_REL), E
    stroke = np.sqrt((a + b) ** 2 - e * e) - np.sqrt((b - a) ** 2 - e * e)
    delta = np.arcsin(e / (b - a)) - np.arcsin(e / (a + b))
    for steps in ("12", "72"):  # the ends are located on the mechanism: a coarse grid gives them exactly too
        argv = ["sweep", str(path), "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", steps, "--json"]
        assert main(argv) == 0
        (st,) = json.loads(capsys.readouterr().out)["strokes"]
        assert st["coordinate"] == "guide"
        assert st["stroke"] == pytest.approx(stroke, abs=1e-10)
        assert sorted(st["crank_angles"]) == pytest.approx([np.pi - delta, np.pi + delta], abs=1e-9)
        assert st["time_ratio"] == pytest.approx((np.pi + delta) / (np.pi - delta), abs=1e-9)
    assert main(argv[:-1] + ["--rows", "all"]) == 0
    out = capsys.readouterr().out
    assert "joint values at 73 of the 73 configurations" in out and "time ratio" in out


@pytest.mark.slow  # about 1.9 s on 2 shared cores: out of the fast subset
def test_solve_says_a_leg_length_input_as_typed(capsys):
    """--set-length leg1=450mm: the inputs line gives the length typed beside the joint's displacement
    (it gave only the displacement, -0.2026 m, which the user never typed)."""
    assert main(["solve", str(ROBOTS / "gough_stewart_6ups.urdf"), "--set-length",
                 "leg1,leg2,leg3,leg4,leg5,leg6=450mm"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("inputs: leg1 = 0.45 m long (joint -0.20258") and first.count("0.45 m long") == 6
