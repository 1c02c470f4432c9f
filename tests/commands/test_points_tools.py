"""Named points and tool frames as the output of ik, singularities, statics and workspace (issue 24
item 3): each against a value written here -- forward kinematics by hand, finite differences of
positions computed with Pinocchio, the four-bar's closed-form velocity ratios, a load moved to the
link's origin by hand, the area of an annulus."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import circles, fourbar, screwkin_cli

L1, L2 = 0.4, 0.25
ARM = """<robot name="arm2r">
  <link name="base"/><link name="upper"/><link name="fore"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/><limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>
</robot>"""


def rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def arm_tool(t1, t2, x, y, yaw=0.0):
    """Forward kinematics by hand: the tool at (x, y) in 'fore' turned by yaw: (position, heading)."""
    elbow = L1 * np.array([np.cos(t1), np.sin(t1)])
    return elbow + rot(t1 + t2) @ np.array([x, y]), t1 + t2 + yaw


def run_json(*args):
    r = screwkin_cli(*args, "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.fixture
def arm(tmp_path):
    path = tmp_path / "arm2r.urdf"
    path.write_text(ARM)
    return str(path)


@pytest.fixture
def four_bar(tmp_path):
    path = tmp_path / "fourbar.urdf"
    path.write_text(fourbar())
    return str(path)


@pytest.mark.slow  # about 1.6 s on 2 shared cores: out of the fast subset
def test_ik_places_the_tool_at_the_target_pose(arm):
    # a reachable target: the tool of joint values (0.3, 1.1), placed at (0.25, 0.05) turned 30 deg on 'fore'
    target, heading = arm_tool(0.3, 1.1, 0.25, 0.05, np.radians(30))
    d = run_json("ik", arm, "--output", "fore", "--tool", "250mm,50mm,0,0,0,30deg", "--pose",
                 f"{target[0]} {target[1]} 0 0 0 {heading}")
    assert d["output"] == "fore@tool" and d["output_frame"]["link"] == "fore"
    assert d["solutions"]
    for s in d["solutions"]:
        p, h = arm_tool(s["joints"]["shoulder"], s["joints"]["elbow"], 0.25, 0.05, np.radians(30))
        assert p == pytest.approx(target, abs=1e-8)
        assert np.cos(h - heading) == pytest.approx(1.0, abs=1e-10)
        assert s["output_position"][:2] == pytest.approx(target, abs=1e-8)
    # the link itself lands at target * tool^-1
    s = d["solutions"][0]
    elbow = L1 * np.array([np.cos(s["joints"]["shoulder"]), np.sin(s["joints"]["shoulder"])])
    tool = pin.SE3(pin.rpy.rpyToMatrix(0, 0, np.radians(30)), np.array([0.25, 0.05, 0]))
    link = pin.SE3(pin.rpy.rpyToMatrix(0, 0, heading), np.r_[target, 0]) * tool.inverse()
    assert link.translation[:2] == pytest.approx(elbow, abs=1e-8)


@pytest.mark.slow  # about 1.5 s on 2 shared cores: out of the fast subset
def test_ik_places_a_named_point_at_a_position(arm):
    d = run_json("ik", arm, "--point", "P=fore:0.25,0.05,0", "--position", "0.3,0.4,0")
    assert len(d["solutions"]) == 2  # elbow up and down
    for s in d["solutions"]:
        p, _ = arm_tool(s["joints"]["shoulder"], s["joints"]["elbow"], 0.25, 0.05)
        assert p == pytest.approx([0.3, 0.4], abs=1e-8)
    # the elbow angle from the law of cosines on the triangle base, elbow, P
    r2, l2 = 0.3**2 + 0.4**2, np.hypot(0.25, 0.05)
    c = (r2 - L1**2 - l2**2) / (2 * L1 * l2)
    found = sorted(np.cos(s["joints"]["elbow"] + np.arctan2(0.05, 0.25)) for s in d["solutions"])
    assert found == pytest.approx([c, c], abs=1e-9)


def test_singularities_of_a_coupler_point_use_its_jacobian(four_bar):
    local = np.array([0.06, 0.02, 0.0])
    d = run_json("singularities", four_bar, "--actuated", "crank_joint", "--point", "P=coupler:0.06,0.02,0")
    frame = d["output_frame"]
    assert d["output"] == "P" and d["point"] is True and frame["link"] == "coupler"
    # J_p by central differences of the point's position, computed with Pinocchio here
    model = screwkin.load(four_bar).model
    data = model.createData()
    fid = model.getFrameId("coupler", pin.FrameType.BODY)

    def p(q):
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[fid].act(local)

    q0, h = pin.neutral(model), 1e-6  # the file is written closed
    J = np.column_stack([(p(q0 + h * e) - p(q0 - h * e)) / (2 * h) for e in np.eye(model.nv)])
    assert frame["position"] == pytest.approx(p(q0), abs=1e-12)
    assert np.array(frame["jacobian"]) == pytest.approx(J, abs=1e-8)
    # the point's speed per unit motion: the four-bar's closed-form velocity ratios (A at the origin,
    # crank 0.04 at 90 deg, coupler 0.12, rocker 0.08 pivoted at D = (0.1, 0))
    B, D = np.array([0.0, 0.04]), np.array([0.1, 0.0])
    th3 = np.arctan2(frame["rotation"][1][0], frame["rotation"][0][0])
    C = B + 0.12 * np.array([np.cos(th3), np.sin(th3)])
    th4 = np.arctan2(*(C - D)[::-1])
    assert np.linalg.norm(C - D) == pytest.approx(0.08, abs=1e-9)
    th2 = np.pi / 2
    w3 = 0.04 * np.sin(th4 - th2) / (0.12 * np.sin(th3 - th4))
    w4 = 0.04 * np.sin(th2 - th3) / (0.08 * np.sin(th4 - th3))
    rates = np.array([1.0, w3 - 1.0, w4])  # relative joint rates per unit crank rate
    v = rates / np.linalg.norm(rates)
    assert d["manipulability"] == pytest.approx(np.linalg.norm(J @ v) / d["characteristic_length"], rel=1e-6)


def test_statics_of_a_load_at_a_point_is_the_load_moved_to_the_origin(four_bar):
    f, m = np.array([1.0, 2.0, 0.0]), np.array([0.0, 0.0, 0.1])
    at_p = run_json("statics", four_bar, "--actuated", "crank_joint", "--point", "P=coupler:60mm,20mm,0",
                    "--wrench", "1 2 0 0 0 0.1")
    # the coupler's origin is B = (0, 0.04); P is (0.06, 0.02) in its frame, turned by its angle th3
    rot3 = np.array(at_p["output_frame"]["rotation"])
    r = rot3 @ np.array([0.06, 0.02, 0.0])  # from the coupler's origin to P
    assert at_p["output_frame"]["position"] == pytest.approx(np.array([0.0, 0.04, 0.0]) + r, abs=1e-12)
    moved = np.r_[f, m + np.cross(r, f)]  # m_o = m + r x f
    assert at_p["output_frame"]["wrench_at_link_origin"] == pytest.approx(moved, abs=1e-12)
    at_o = run_json("statics", four_bar, "--actuated", "crank_joint", "--output", "coupler", "--wrench",
                    " ".join(repr(float(x)) for x in moved))
    assert at_p["efforts"]["crank_joint"] == pytest.approx(at_o["efforts"]["crank_joint"], rel=1e-9)
    assert at_p["efforts"]["crank_joint"] != pytest.approx(
        run_json("statics", four_bar, "--actuated", "crank_joint", "--output", "coupler", "--wrench",
                 "1 2 0 0 0 0.1")["efforts"]["crank_joint"], rel=1e-3)  # the point matters


def test_workspace_of_a_named_point_is_its_annulus(arm):
    d = run_json("workspace", arm, "--point", "P=fore:0.25,0,0", "--method", "grid", "--resolution", "0.01")
    assert d["output"] == "P" and d["output_frame"]["link"] == "fore"
    assert d["volume"] == pytest.approx(np.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2), rel=5e-3)


@pytest.mark.parametrize("args, message", [
    (["ik", "{arm}", "--tool", "0.1,0,0", "--position", "0.3,0.4,0"], "--tool needs --output"),
    (["ik", "{arm}", "--output", "fore", "--tool", "0.1,0", "--position", "0.3,0.4,0"], "--tool expects"),
    (["ik", "{arm}", "--output", "fore", "--tool", "0.1,0,30deg", "--position", "0.3,0.4,0"], "--tool"),
    (["ik", "{arm}", "--point", "P=fore:0.1,0,0", "--pose", "0.3 0.4 0 0 0 0"], "give --position"),
    (["ik", "{arm}", "--output", "fore"], "give one target"),
    (["ik", "{arm}", "--output", "fore", "--tool", "0.1,0,0", "--point", "P=fore:0.1,0,0", "--position", "0,0.3,0"],
     "give one of them"),
    (["ik", "{arm}", "--output", "upper", "--point", "P=fore:0.1,0,0", "--position", "0,0.3,0"], "not on the --output"),
    (["ik", "{arm}", "--point", "upper=fore:0.1,0,0", "--position", "0,0.3,0"], "a link's name"),
    (["workspace", "{arm}", "--point", "P=fore:0.1,0,0", "--point", "Q=fore:0.2,0,0"], "one named point"),
    (["statics", "{arm}", "--wrench", "1 0 0 0 0 0"], "--wrench needs --output"),
])
def test_bad_points_and_tools_are_usage_errors(arm, args, message):
    r = screwkin_cli(*[a.format(arm=arm) for a in args])
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert message in r.stderr and "Traceback" not in r.stderr


def test_report_lists_the_points_of_its_solutions(four_bar, tmp_path):
    md = tmp_path / "r.md"
    r = screwkin_cli("report", four_bar, "--actuated", "crank_joint", "--set-angle", "crank=100deg", "--rate",
                     "crank_joint=10", "--point", "P=coupler:60mm,20mm,0", "--md", str(md), "--no-view")
    assert r.returncode == 0, r.stderr
    rows = [line for line in md.read_text().splitlines() if line.startswith("| P | coupler |")]
    assert len(rows) == 2  # one per assembly mode

    def numbers(cell):
        return np.array([float(x) for x in cell.strip().strip("()").replace(",", " ").split()])  # solve's "x y z"

    # closed form: B on the crank at 100 deg, C where the coupler (0.12) meets the rocker (0.08) about D
    th2, w2 = np.radians(100), 10.0
    B, D = 0.04 * np.array([np.cos(th2), np.sin(th2)]), np.array([0.1, 0.0])
    expected = []
    for C in circles(B, 0.12, D, 0.08):
        th3, th4 = np.arctan2(*(C - B)[::-1]), np.arctan2(*(C - D)[::-1])
        P = B + rot(th3) @ np.array([0.06, 0.02])
        w3 = w2 * 0.04 * np.sin(th4 - th2) / (0.12 * np.sin(th3 - th4))
        k_cross = np.array([[0, -1], [1, 0]])
        expected.append((P, w2 * k_cross @ B + w3 * k_cross @ (P - B)))
    for row in rows:
        cells = row.strip("|").split("|")
        p, v = numbers(cells[2])[:2], numbers(cells[3])[:2]
        P, V = min(expected, key=lambda e: np.linalg.norm(e[0] - p))
        assert p == pytest.approx(P, rel=1e-5, abs=1e-9)
        assert v == pytest.approx(V, rel=1e-5, abs=1e-9)


def test_serial_singularity_of_a_point_is_where_its_jacobian_drops_rank(arm):
    # the arm stretched along x (the file's configuration): J_p = [[-y, -y], [x, x - 0.4]] for P = (x, y)
    off = run_json("singularities", arm, "--point", "P=fore:0.25,0.05,0")  # det = -0.05 * (0.65 - 0.4) + 0.05 * 0.65
    assert off["serial"] is False
    assert off["manipulability"] == pytest.approx(abs(-0.05 * 0.25 + 0.05 * 0.65) / off["characteristic_length"] ** 2)
    on = run_json("singularities", arm, "--point", "P=fore:0.25,0,0")  # on the line of the arm: it cannot move along it
    assert on["serial"] is True
    (lost,) = [t for t in on["singular_twists"] if t["kind"] == "serial"]
    assert np.abs(lost["screw"]["direction"]) == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)


def test_scan_of_a_named_point_finds_where_it_lines_up_with_the_shoulder(arm):
    # det J_p = 0.4 |p| sin(elbow + phi) for P at |p|, angle phi on 'fore': singular at elbow = -phi (or pi - phi)
    d = run_json("scan", arm, "--point", "P=fore:0.25,0.05,0", "--samples", "5000")
    assert d["output"] == "P" and d["point"] is True
    elbow = d["min_configuration"]["elbow"]
    assert abs(np.sin(elbow + np.arctan2(0.05, 0.25))) < 0.01
    assert d["min"] < 1e-3


def test_map_takes_a_named_point_as_its_output(tmp_path):
    from conftest import ROBOTS

    d = run_json("map", str(ROBOTS / "five_bar.urdf"), "--x", "motor1=-1:1:3", "--y", "motor2=-1:1:3", "--point",
                 "P=distal1:0.05,0,0")
    plain = run_json("map", str(ROBOTS / "five_bar.urdf"), "--x", "motor1=-1:1:3", "--y", "motor2=-1:1:3")
    assert np.array(d["reached"]).shape == (3, 3)
    assert d["kind"] != plain["kind"] or d["log10_sigma_min"] != plain["log10_sigma_min"]  # the point's serial measure counts


def test_the_tool_jacobian_is_the_link_jacobian_shifted_to_the_tool(four_bar):
    from screwkin.model.state import KinematicState, place_tool

    mech = screwkin.load(four_bar)
    q = mech.generic_configurations()[0].q
    before = KinematicState(mech, q)
    J, M = before.link_jacobian("coupler"), before.frame_placement(mech.link_frame("coupler"))
    tool = pin.SE3(pin.rpy.rpyToMatrix(0.1, 0.2, 0.3), np.array([0.06, 0.02, 0.01]))
    name = place_tool(mech, "tip", "coupler", tool)
    after = KinematicState(mech, q)
    r = M.rotation @ tool.translation  # link origin -> tool origin, world axes
    skew = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    expected = np.vstack([J[:3] - skew @ J[3:], J[3:]])  # v_tool = v_o + w x r
    assert after.link_jacobian(name) == pytest.approx(expected, abs=1e-12)
    placed = after.frame_placement(mech.link_frame(name))
    assert placed.homogeneous == pytest.approx((M * tool).homogeneous, abs=1e-12)
