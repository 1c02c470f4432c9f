"""The closed-form planar sweep (analysis/motion/dyads.py) against the tracker it stands in for, and
against circle intersections written here.

Both run with a tight closure tolerance (1e-13): the tracker's corrector then lands within
about 1e-12 of the curve, also next to limit positions where the default 1e-10 leaves it
1e-8 away (the curve is a square root of the input there), so the two can be compared to 1e-9.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS, ROBOTS
from screwkin.analysis.motion.dyads import planar_sweep
from screwkin.analysis.motion.links import Point, motion_along
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep
from screwkin.model.planar_graph import DyadPlan, plan
from screwkin.tolerances import Tolerances

TIGHT = Tolerances(closure=1e-13)


def load(name):
    return screwkin.load(ROBOTS / name, tolerances=TIGHT, warn=lambda *a, **k: None)


def assert_same(mech, fast, slow, points=()):
    """Every field of two SweepResults equal: values, q (on the manifold), rates and accelerations
    to 1e-9 (relative where they are large, next to a limit position), limits, the stop."""
    assert fast.values.shape == slow.values.shape, (len(fast.values), len(slow.values))
    np.testing.assert_allclose(fast.values, slow.values, rtol=0, atol=1e-12)
    dq = np.array([pin.difference(mech.model, a, b) for a, b in zip(fast.q, slow.q)])
    assert np.abs(dq).max() < 1e-9
    np.testing.assert_allclose(fast.joints, slow.joints, rtol=0, atol=1e-9)
    for a, b in ((fast.rates, slow.rates), (fast.accelerations, slow.accelerations)):
        assert np.all(np.abs(a - b) <= 1e-9 * (1 + np.abs(b))), np.abs(a - b).max()
    assert fast.names == slow.names and fast.unit == slow.unit and fast.rate == slow.rate
    assert fast.requested == slow.requested and fast.turn == slow.turn
    assert fast.circuit_closed == slow.circuit_closed and fast.skipped == slow.skipped == ()
    assert (fast.stopped_at is None) == (slow.stopped_at is None)
    assert fast.stop_reason == slow.stop_reason
    budget = fast.stop_reason is not None and "budget" in fast.stop_reason
    if budget:
        # the closed form stops at the last value it recorded; the tracker where its last (arc) step
        # ended, up to one grid step past it, and it may have met one more limit position there
        h = (slow.requested[1] - slow.requested[0]) / slow.requested[2]
        assert fast.stopped_at == fast.values[-1] or abs(fast.stopped_at - slow.stopped_at) < 1e-9
        assert abs(slow.stopped_at - slow.values[-1]) <= abs(h) + 1e-12
        assert len(slow.limits) - len(fast.limits) in (0, 1)
    else:
        assert len(fast.limits) == len(slow.limits)
        if fast.stopped_at is not None:
            assert abs(fast.stopped_at - slow.stopped_at) < 1e-9
    for a, b in zip(fast.limits, slow.limits):
        assert (a.kind, a.limit) == (b.kind, b.limit) == ("actuator", True)
        assert abs(a.input - b.input) < 1e-9
        assert np.abs(pin.difference(mech.model, a.q, b.q)).max() < 1e-6  # the tracker's Brent on a held joint
        assert a.sigma < 1e-6 and b.sigma < 1e-6
    if points:
        ma = motion_along(mech, fast.q, fast.rates, fast.accelerations, points)
        mb = motion_along(mech, slow.q, slow.rates, slow.accelerations, points)
        for p in points:
            for key in ("position", "velocity", "acceleration"):
                a, b = ma.points[p.name][key], mb.points[p.name][key]
                assert np.all(np.abs(a - b) <= 1e-9 * (1 + np.abs(b)))


def both(mech, inputs, name, start, stop, steps, **kw):
    solver = PositionSolver(mech, inputs)
    q0 = solver.solve({name: start, **kw.get("fixed", {})}, starts=8).solutions[0].q
    assert planar_sweep(solver, name, q0, start, stop, steps, kw.get("rate", 1.0), kw.get("turn", False),
                        kw.get("max_steps")) is not None, "the closed form does not apply"
    return sweep(solver, name, start, stop, steps, **kw), sweep(solver, name, start, stop, steps, closed_form=False, **kw)


CASES = [  # file, inputs, swept, from, to, steps, options
    ("fourbar_crank_rocker.urdf", ["crank_joint"], "crank_joint", 0.0, 2 * np.pi, 90, {"rate": 3.0}),
    ("fourbar_crank_rocker.urdf", ["crank_joint"], "crank_joint", 1.0, -1.0, 20, {}),
    ("fourbar_crank_rocker.urdf", ["rocker_joint"], "rocker_joint", 1.1, -1.0, 60, {}),  # a limit: stops there
    ("fourbar_crank_rocker.urdf", ["rocker_joint"], "rocker_joint", 1.1, -1.0, 30, {"turn": True, "max_steps": 150}),
    ("fourbar_non_grashof.urdf", ["input_joint"], "input_joint", 0.0, 2 * np.pi, 60, {"turn": True}),
    ("fourbar.urdf.xacro", ["crank_joint"], "crank_joint", 0.0, 2 * np.pi, 40, {}),
    ("slider_crank_offset.urdf", ["crank_joint"], "crank_joint", 0.0, 2 * np.pi, 72, {"rate": -2.0}),
    ("slider_crank_offset.urdf", ["slider_joint"], "slider_joint", 0.0, -0.1, 50, {}),  # the crank's dead centre
    ("slider_crank_offset.urdf", ["slider_joint"], "slider_joint", 0.0, -0.1, 25, {"turn": True, "max_steps": 120}),
    ("stephenson_sixbar.urdf", ["crank_joint"], "crank_joint", 0.0, 2 * np.pi, 45, {}),
    ("watt_sixbar.urdf", ["crank_joint"], "crank_joint", 0.0, 2 * np.pi, 45, {}),
    ("strider.urdf", ["crank_joint"], "crank_joint", 0.0, -2 * np.pi, 36, {}),
]


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}:{c[2]}:{c[5]}{'+turn' if c[6].get('turn') else ''}"
                                             for c in CASES])
def test_closed_form_is_the_tracker(case):
    name, inputs, swept, start, stop, steps, kw = case
    mech = load(name)
    fast, slow = both(mech, inputs, swept, start, stop, steps, **kw)
    assert_same(mech, fast, slow)
    assert len(fast.values) > 5


def test_closed_form_is_the_tracker_with_points_and_a_limit():
    mech = load("fourbar_crank_rocker.urdf")
    fast, slow = both(mech, ["rocker_joint"], "rocker_joint", 1.1, -1.0, 40)
    assert fast.stopped_at is not None and len(fast.limits) == 1
    assert_same(mech, fast, slow, points=(Point("tip", "coupler", (0.06, 0.02, 0.0)),))


def test_five_bar_with_its_other_motor_held():
    mech = load("five_bar.urdf")
    solver = PositionSolver(mech)
    m2 = solver.joint_values(mech.assemble().q)["motor2"]
    fast, slow = both(mech, ["motor1", "motor2"], "motor1", 0.0, 0.6, 30, fixed={"motor2": m2})
    assert_same(mech, fast, slow)


def test_four_bar_positions_are_the_circle_intersections():
    """fourbar_crank_rocker.urdf: ground pivots O1 = 0, O2 = (0.1, 0); crank 0.04 (at 60 deg when
    its joint is 0), coupler 0.12, rocker 0.08.  The coupler-rocker joint B is where the circles
    about the crank tip and about O2 meet; the rocker's joint value is B's angle about O2 less
    its angle at the file's configuration; rates from central differences of the same formula."""
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 360, rate=2.0)
    O2, a, b, c = np.array([0.1, 0.0]), 0.04, 0.12, 0.08
    B_file = np.array([0.03388096599604964, 0.07247123666099901])  # the loop joint on the rocker, rocker frame

    def rocker(q):
        A = a * np.stack([np.cos(np.pi / 3 + q), np.sin(np.pi / 3 + q)], -1)
        w = O2 - A
        d = np.linalg.norm(w, axis=-1, keepdims=True)
        along = (d ** 2 + b ** 2 - c ** 2) / (2 * d)
        h = np.sqrt(b ** 2 - along ** 2)
        perp = np.stack([-w[..., 1], w[..., 0]], -1) / d
        B = A + along * w / d + h * perp  # the branch the file is drawn on (B above AO2)
        ang = np.arctan2(B[..., 1] - O2[1], B[..., 0] - O2[0]) - np.arctan2(B_file[1], B_file[0])
        return np.mod(ang + np.pi, 2 * np.pi) - np.pi

    iv = mech.coordinate("rocker_joint").idx_v
    np.testing.assert_allclose(res.joints[:, iv], rocker(res.values), rtol=0, atol=1e-12)
    e = 1e-5
    fd = (rocker(res.values + e) - rocker(res.values - e)) / (2 * e)
    fdd = (rocker(res.values + e) - 2 * rocker(res.values) + rocker(res.values - e)) / e ** 2
    np.testing.assert_allclose(res.rates[:, iv], 2.0 * fd, rtol=0, atol=1e-8)
    np.testing.assert_allclose(res.accelerations[:, iv], 4.0 * fdd, rtol=0, atol=1e-4)
    residual = max(np.linalg.norm(mech.closure.residual(q)) for q in res.q)
    assert residual < 1e-13


def test_plans_and_reasons():
    """What decomposes, and what the tracker keeps (a triad, a spatial loop, a higher pair)."""
    assert [d[0] for d in plan(load("slider_crank_offset.urdf"), ["crank_joint"], "crank_joint").dyads] == ["RRP"]
    assert [d[0] for d in plan(load("watt_sixbar.urdf"), ["crank_joint"], "crank_joint").dyads] == ["RRR", "RRR"]
    assert "class-II dyad" in plan(load("planar_3rrr.urdf"), ["motor1", "motor2", "motor3"], "motor1")
    assert "spherical" in plan(load("rssr.urdf"), ["crank_joint"], "crank_joint")
    assert "higher pairs" in plan(load("cam_followers.urdf"), ["cam_joint"], "cam_joint")
    five = screwkin.load(CORPUS / "5bar_linkage" / "robot.urdf", warn=lambda *a, **k: None)
    assert not isinstance(plan(five, ["mot1", "mot2"], "mot1"), DyadPlan)  # its pin link: a triad here


def test_spatial_loops_keep_the_tracker():
    """The Bennett linkage is an RRR 'dyad' by its graph, but its axes are not parallel: no closed form."""
    mech = load("bennett.urdf")
    solver = PositionSolver(mech, ["joint1"])
    q0 = solver.solve({"joint1": 0.3}, starts=8).solutions[0].q
    assert isinstance(plan(mech, ["joint1"], "joint1"), DyadPlan)
    assert planar_sweep(solver, "joint1", q0, 0.3, 0.5, 4) is None
    res = sweep(solver, "joint1", 0.3, 0.5, 4)
    assert res.completed and len(res.values) == 5


def test_strider_feet_are_pylinkages():
    """robots/strider.urdf against pylinkage's own Strider (its docs/examples/strider.py, built here
    with its components; one pylinkage unit = 0.1 m): both feet over a whole turn of the crank,
    turning clockwise by one degree a step as pylinkage's does."""
    pytest.importorskip("pylinkage", reason="pylinkage is not installed (the test extra has it)")
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage

    n = 360
    A, Y = Ground(0, 0, name="A"), Ground(0, 1, name="Y")
    B = FixedDyad(anchor1=A, anchor2=Y, distance=2, angle=-np.pi / 4, name="B")
    Bp = FixedDyad(anchor1=A, anchor2=Y, distance=2, angle=np.pi / 4, name="Bp")
    C = Crank(anchor=A, radius=1, angular_velocity=-2 * np.pi / n, name="C")
    D = RRRDyad(anchor1=Bp, anchor2=C.output, distance1=1.8, distance2=2.6, name="D")
    E = RRRDyad(anchor1=B, anchor2=C.output, distance1=1.8, distance2=2.6, name="E")
    F = FixedDyad(anchor1=C.output, anchor2=E, distance=1.4, angle=-(np.pi + 0.2), name="F")
    G = FixedDyad(anchor1=C.output, anchor2=D, distance=1.4, angle=np.pi + 0.2, name="G")
    H = RRRDyad(anchor1=D, anchor2=F, distance1=2.5, distance2=1.8, name="H")
    I_ = RRRDyad(anchor1=E, anchor2=G, distance1=2.5, distance2=1.8, name="I")
    strider = Linkage([A, Y, B, Bp, C, D, E, F, G, H, I_], name="Strider")
    strider.set_coords([(0, 0), (0, 1), (1.41, 1.41), (-1.41, 1.41), (0, -1), (-2.25, 0), (2.25, 0),
                        (-1.4, -1.2), (1.4, -1.2), (-2.7, -2.7), (2.7, -2.7)])
    theirs = 0.1 * np.array([[step[9], step[10]] for step in strider.step(iterations=n)])  # (n, 2 feet, 2)

    mech = screwkin.load(ROBOTS / "strider.urdf")
    res = sweep(PositionSolver(mech), "crank_joint", 0.0, -2 * np.pi, n)
    assert res.completed and len(res.values) == n + 1
    # the feet: the loop joints left_foot (H) and right_foot (I), on the tibiae
    cut = {c.name: c for c in mech.spec.cut_joints}
    feet = (Point("H", "left_tibia", tuple(cut["left_foot"].xyz1)), Point("I", "right_tibia", tuple(cut["right_foot"].xyz1)))
    m = motion_along(mech, res.q[1:], res.rates[1:], res.accelerations[1:], feet)
    ours = np.stack([m.points["H"]["position"][:, :2], m.points["I"]["position"][:, :2]], 1)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name,link", [("slider_crank_offset.urdf", "rod"), ("fourbar_crank_rocker.urdf", "coupler")])
def test_batched_motion_and_transmission_angles_are_the_per_state_ones(name, link):
    """What `screwkin sweep` reports along the motion, computed on the stacks (motion_along,
    transmission_angles), equals the one-configuration functions (KinematicState, identify) at
    every step."""
    from screwkin.analysis.motion.links import link_motions, point_motions
    from screwkin.analysis.motion.planar import LinkAngles, identify, transmission_angles
    from screwkin.model.state import KinematicState

    mech = screwkin.load(ROBOTS / name)
    res = sweep(PositionSolver(mech), "crank_joint", 0.0, 2 * np.pi, 24, rate=3.0)
    topo = mech.topology(res.q[0])
    angles = LinkAngles(mech, topo)
    pts = (Point("P", link, (0.03, 0.01, 0.0)),)
    m = motion_along(mech, res.q, res.rates, res.accelerations, pts, angles, angles.n)
    mus = transmission_angles(mech, identify(mech, topo, res.q[0], "crank_joint"), res.q)
    for k, (q, v, a) in enumerate(zip(res.q, res.rates, res.accelerations)):
        st = KinematicState(mech, q, v, a)
        for ln, d in link_motions(st, angles(q), angles.n, along=angles.along()).items():
            assert list(d) == list(m.links[ln])
            for key, val in d.items():
                if key == "angle_along":  # the two points the angle is measured along: names, once per sweep
                    assert m.links[ln][key] == val
                    continue
                np.testing.assert_allclose(m.links[ln][key][k], val, rtol=0, atol=1e-12)
        for key in ("position", "velocity", "acceleration"):
            np.testing.assert_allclose(m.points["P"][key][k], point_motions(st, pts)["P"][key], rtol=0, atol=1e-12)
        for c, val in st.loop_joints.items():
            assert abs(m.loop_joints[c][k] - val) < 1e-12
            assert abs(m.loop_rates[c][k] - st.loop_rates[c]) < 1e-12
            assert abs(m.loop_accelerations[c][k] - st.loop_accelerations[c]) < 1e-12
        assert abs(mus[k] - identify(mech, mech.topology(q), q, "crank_joint").transmission_angle) < 1e-12


def inverted_slider_crank(a=0.04, d=0.1, theta0=np.radians(60)):
    """Crank a about the origin; its tip B carries a block (revolute) that slides in the slot of a
    rocker pivoted at D = (d, 0): the block and the rocker are an RPR dyad."""
    from conftest import LINK, rev

    B = a * np.array([np.cos(theta0), np.sin(theta0)])
    u = B - np.array([d, 0.0])
    phi, L = np.arctan2(u[1], u[0]), np.linalg.norm(u)
    body = "".join(LINK.format(n=n) for n in ("ground", "crank", "block", "rocker"))
    body += rev("crank_joint", "ground", "crank", rpy=f"0 0 {theta0}", jtype="continuous")
    body += rev("block_joint", "crank", "block", xyz=f"{a} 0 0", rpy=f"0 0 {phi - theta0}")
    body += rev("rocker_joint", "ground", "rocker", xyz=f"{d} 0 0", rpy=f"0 0 {phi}")
    body += (f'<loop_joint name="slot" type="prismatic"><link1 link="rocker" xyz="{L} 0 0"/>'
             f'<link2 link="block"/><axis xyz="1 0 0"/></loop_joint>')
    return f'<robot name="inverted_slider_crank">{body}</robot>'


def swapped_slider_crank():
    """conftest's slider-crank with its loop joint written from the slider's side: a PRR dyad."""
    from conftest import slider_crank

    text = slider_crank()
    start = text.index('<loop_joint name="pin"')
    end = text.index("</loop_joint>") + len("</loop_joint>")
    loop = text[start:end]
    link1 = loop[loop.index("<link1"):loop.index("/>", loop.index("<link1")) + 2]
    link2 = loop[loop.index("<link2"):loop.index("/>", loop.index("<link2")) + 2]
    swapped = loop.replace(link1, "@1").replace(link2, link1.replace("link1", "link2")).replace(
        "@1", link2.replace("link2", "link1"))
    return text[:start] + swapped + text[end:]


@pytest.mark.parametrize("make,kind,swept,span,kw", [
    (inverted_slider_crank, "RPR", "crank_joint", 2 * np.pi, {}),
    (swapped_slider_crank, "PRR", "crank_joint", 2 * np.pi, {}),
    (inverted_slider_crank, "RRP", "rocker_joint", 1.5, {}),  # its slide on the moving rocker; a limit
    (inverted_slider_crank, "RRP", "rocker_joint", 1.5, {"turn": True, "max_steps": 100})])
def test_slider_dyads_are_the_tracker(tmp_path, make, kind, swept, span, kw):
    path = tmp_path / "m.urdf"
    path.write_text(make())
    mech = screwkin.load(path, tolerances=TIGHT, warn=lambda *a, **k: None)
    p = plan(mech, [swept], swept)
    assert [d[0] for d in p.dyads] == [kind]
    solver = PositionSolver(mech, [swept])
    x0 = solver.joint_values(mech.assemble().q)[swept]
    fast, slow = both(mech, [swept], swept, x0, x0 + span, 40, **kw)
    assert_same(mech, fast, slow)
    assert len(fast.values) > 10


def test_json_text_is_json_dumps_with_indent():
    """The sweep's JSON writer gives json.dumps(..., indent=2) character for character."""
    import json

    from screwkin.present.jsonout import json_text, to_jsonable

    mech = load("slider_crank_offset.urdf")
    res = sweep(PositionSolver(mech), "crank_joint", 0.0, 2 * np.pi, 12)
    sample = to_jsonable({
        "values": res.values, "q": res.q, "rows": res.q.tolist(), "empty": [], "none": {}, "mixed": [1, 2.5, None],
        "ints": [1, 2], "flags": [True, False], "text": 'a "quoted"\nline', "inf": [float("inf"), 1.0],
        "nested": {"deep": [[1.0, 2.0], [3.0]], "ragged": [[1.0], []], 3: "int key"}, "tiny": [1e-300, -0.0, 1e20]})
    for obj in (sample, [], {}, 1.5, "x", [[1.0, 2.0]], {"a": [{"b": [1.0]}]}):
        assert json_text(obj) == json.dumps(obj, indent=2)


def test_a_grid_too_coarse_to_follow_the_turns_is_left_to_the_tracker():
    """Three grid values over 4 rad of a Watt six-bar's rocker, turning at its limit positions: between
    two samples a joint turns by more than a quarter turn, so which turn (2 pi k) it is on cannot be
    told from the samples; the closed form declines (the tracker follows the turns step by step),
    while the same motion on a fine grid is the closed form's."""
    mech = load("watt_sixbar.urdf")
    solver = PositionSolver(mech, ["rocker_joint"])
    x0 = solver.joint_values(mech.assemble().q)["rocker_joint"]
    q0 = solver.solve({"rocker_joint": x0}, starts=8).solutions[0].q
    assert planar_sweep(solver, "rocker_joint", q0, x0, x0 - 4.15, 3, 1.0, True, 40) is None
    fine = planar_sweep(solver, "rocker_joint", q0, x0, x0 - 4.15, 300, 1.0, True, 400)
    assert fine is not None and len(fine.limits) >= 2


def test_closed_form_up_to_a_range_end_next_to_a_limit_position():
    """A non-Grashof four-bar swept to just inside its limit (as a study's transmission metric does): the
    slope of the coupler grows without bound there, and the trapezoid predictor of the angle unwrapping
    overshot by whole turns, so the closed form gave the motion up to the tracker (9x slower in a study).
    Now it keeps the closed form, and agrees with the tracker (whose passive joints converge only to about
    the square root of the closure tolerance at the last, nearly singular, value)."""
    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    mech = screwkin.load(ROBOTS / "fourbar.urdf.xacro",
                         args={"ground": "0.1", "crank": "0.095", "coupler": "0.06", "rocker": "0.075"})
    solver = PositionSolver(mech, ["crank_joint"])
    q0 = mech.generic_configurations()[1][0]
    end = 0.7406765579590034  # 2 % of the crank's range inside its limit position
    fast = sweep(solver, "crank_joint", 0.0, end, 96, q_start=q0)
    slow = sweep(solver, "crank_joint", 0.0, end, 96, q_start=q0, closed_form=False, batch=False)
    assert fast.method == "closed form" and fast.completed and slow.completed
    np.testing.assert_allclose(fast.values, slow.values, atol=1e-12)
    np.testing.assert_allclose(fast.joints[:-1], slow.joints[:-1], atol=1e-8)
    np.testing.assert_allclose(fast.joints[-1], slow.joints[-1], atol=1e-4)
    assert np.ptp(np.unwrap(fast.joints[:, 1])) < np.pi  # no spurious turn of the coupler joint


def test_a_grid_too_coarse_to_unwrap_is_read_from_a_finer_closed_form():
    """Three steps over a crank's turn (120 deg each: which turn each joint is on cannot be told from the
    samples) are computed on a grid 8 times finer and read at the three values: still the closed form,
    and the tracker's answer (which takes steps of at most Tolerances.max_step between the values)."""
    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    solver = PositionSolver(mech, ["crank_joint"])
    fast = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 3)
    slow = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 3, closed_form=False, batch=False)
    assert fast.method == "closed form" and len(fast.values) == len(slow.values) == 4
    np.testing.assert_allclose(fast.values, slow.values, atol=1e-12)
    np.testing.assert_allclose(fast.q, slow.q, atol=1e-8)
    np.testing.assert_allclose(fast.rates, slow.rates, atol=1e-7)


def test_a_regular_drawing_starts_the_sweep_without_the_generic_search():
    """sweep's start from the file's drawing (sweep._drawn_regular): for mechanisms the dyad plan covers,
    drawn closed at the start value, it is the configuration solve(values, starts=8) puts first, found
    without the generic configurations' search; a drawing at a limit position (an actuator
    singularity: the four-bar's output dyad folded, z = |b - c|) is not taken."""
    import math

    from screwkin.analysis.motion.sweep import _drawn_regular

    for name in ("strider.urdf", "fourbar_crank_rocker.urdf", "watt_sixbar.urdf", "stephenson_sixbar.urdf",
                 "slider_crank_offset.urdf", "five_bar.urdf"):
        mech = screwkin.load(ROBOTS / name)
        solver = PositionSolver(mech)
        values = {n: 0.0 for n in solver.inputs}
        q = _drawn_regular(solver, values)
        assert q is not None and not mech.generic_known, name
        first = PositionSolver(screwkin.load(ROBOTS / name)).solve(values, starts=8).solutions[0].q
        np.testing.assert_allclose(q, first, rtol=0, atol=1e-12, err_msg=name)
        assert _drawn_regular(solver, {n: 0.3 for n in solver.inputs}) is None  # not drawn there
    g, a, b, c = 0.1, 0.02, 0.16, 0.075  # a triple rocker drawn at its input's limit position
    theta = math.acos((a * a + g * g - (b - c) ** 2) / (2 * a * g))
    mech = screwkin.load(ROBOTS / "fourbar.urdf.xacro", args={"ground": g, "crank": a, "coupler": b, "rocker": c,
                                                                 "theta": theta})
    solver = PositionSolver(mech)
    assert _drawn_regular(solver, {"crank_joint": 0.0}) is None
