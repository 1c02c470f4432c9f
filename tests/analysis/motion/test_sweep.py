"""Sweeps and the four-bar textbook extras, against closed forms and a second method."""

import numpy as np
import pytest

import screwkin
from conftest import A, B, C, G, fourbar, rocker_angles, world_angles
from screwkin.cli import main
from screwkin.analysis.motion.planar import identify
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep

STEPS = 360


@pytest.fixture
def mech(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    return screwkin.load(p)


def test_full_crank_turn_stays_on_one_circuit(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, STEPS)
    assert res.stopped_at is None and len(res.values) == STEPS + 1
    # the circuit of the file's configuration is the upper intersection throughout (closed form)
    circuit = None
    for q in res.q[::10]:
        sol = type("S", (), {"q": q})
        crank, rocker = world_angles(mech, sol)
        both = rocker_angles(crank)
        k = int(np.argmin(np.abs(np.asarray(both) - rocker)))
        assert abs(both[k] - rocker) < 1e-8  # closure tolerance 1e-10 m over an 0.08 m rocker
        circuit = k if circuit is None else circuit
        assert k == circuit
    # the motion closes on itself after a full turn
    np.testing.assert_allclose(res.joints[-1][1:], res.joints[0][1:], atol=1e-9)


def test_sweep_rates_match_finite_differences_of_positions(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 1.0, 1000)
    h = res.values[1] - res.values[0]
    fd = (res.joints[2:] - res.joints[:-2]) / (2 * h)
    np.testing.assert_allclose(res.rates[1:-1], fd, atol=1e-5)
    fd2 = (res.rates[2:] - res.rates[:-2]) / (2 * h)
    np.testing.assert_allclose(res.accelerations[1:-1], fd2, atol=1e-4)


def test_limit_positions_are_where_the_rocker_stops(mech):
    """At the crank angles reported as output limit positions (crank and coupler
    collinear) the rocker's rate vanishes: checked with the velocity analysis."""
    q = mech.assemble().q
    info = identify(mech, mech.topology(q), q, "crank_joint")
    assert info.grashof.startswith("Grashof crank-rocker") and info.input_range is None
    assert len(info.limit_inputs) == 2
    solver = PositionSolver(mech, ["crank_joint"])
    for x in info.limit_inputs:
        res = sweep(solver, "crank_joint", 0.0, x, 200)  # stay on the file's circuit
        assert res.stopped_at is None
        assert abs(res.rates[-1][res.names.index("rocker_joint")]) < 1e-9
        assert abs(res.rates[0][res.names.index("rocker_joint")]) > 0.1


def test_rocker_input_stops_at_its_range(mech):
    """Driving the rocker: the sweep stops where the closed-form input range ends."""
    q = mech.assemble().q
    info = identify(mech, mech.topology(q), q, "rocker_joint")
    assert info.grashof.startswith("Grashof rocker-crank")
    lo, hi = info.input_range
    # closed form: |AC| = a + b at the limit: cos(phi) = ((a + b)^2 - g^2 - c^2) / (2 g c) in world angles
    phi = np.arccos(((A + B) ** 2 - G**2 - C**2) / (2 * G * C))
    offset = world_angles(mech, type("S", (), {"q": mech.neutral()}))[1]
    assert min(abs(lo + offset - phi), abs(hi + offset - phi)) < 1e-9
    res = sweep(PositionSolver(mech, ["rocker_joint"]), "rocker_joint", 0.0, -1.5, 150)
    assert res.stopped_at is not None
    assert abs(res.stopped_at - lo) < 1e-4
    assert res.values[-1] >= lo


def test_transmission_angle_law_of_cosines(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 36)
    for q in res.q:
        info = identify(mech, mech.topology(q), q, "crank_joint")
        crank = world_angles(mech, type("S", (), {"q": q}))[0]
        Bp = A * np.array([np.cos(crank), np.sin(crank)])
        bd2 = np.sum((np.array([G, 0]) - Bp) ** 2)
        mu = np.arccos((B**2 + C**2 - bd2) / (2 * B * C))
        assert abs(info.transmission_angle - mu) < 1e-9


def test_cli_sweep_csv_and_json(mech, tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "9",
                 "--csv", str(out), "--json"]) == 0
    import json

    d = json.loads(capsys.readouterr().out)
    assert d["completed"] and len(d["values"]) == 10 and d["linkage"]["kind"] == "four-bar"
    lines = out.read_text().splitlines()
    assert len(lines) == 11 and lines[0].startswith("step,crank_joint_input")


def test_plot_and_map_pictures(mech, tmp_path):
    from conftest import ROBOTS

    png = tmp_path / "s.png"
    assert main(["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "20",
                 "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    png2, csv = tmp_path / "m.png", tmp_path / "m.csv"
    assert main(["map", str(ROBOTS / "five_bar.urdf"), "--x", "motor1=0:0.5:6", "--y", "motor2=0:0.5:5",
                 "--png", str(png2), "--csv", str(csv)]) == 0
    assert png2.read_bytes()[:4] == b"\x89PNG" and csv.read_text().count("\n") == 31


def test_slider_crank_closed_form_and_extras(tmp_path):
    """Offset slider-crank: slider x = a cos(t) + sqrt(b^2 - (e - a sin t)^2); dead centres at
    atan2(e, sqrt((a + b)^2 - e^2)) and atan2(e, sqrt((b - a)^2 - e^2)) + pi; a + e <= b: full turn."""
    from conftest import slider_crank

    a, b, e, t0 = 0.05, 0.15, 0.02, np.radians(60)
    p = tmp_path / "sc.urdf"
    p.write_text(slider_crank(a, b, e, t0))
    mech = screwkin.load(p)
    solver = PositionSolver(mech, ["crank_joint"])
    res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 72)
    x0 = a * np.cos(t0) + np.sqrt(b**2 - (e - a * np.sin(t0)) ** 2)
    for x_in, joints in zip(res.values, res.joints, strict=True):
        t = t0 + x_in
        x = a * np.cos(t) + np.sqrt(b**2 - (e - a * np.sin(t)) ** 2)
        assert abs(joints[res.names.index("slider_joint")] - (x - x0)) < 1e-9
    q = mech.assemble().q
    info = identify(mech, mech.topology(q), q, "crank_joint")
    assert info.kind == "slider-crank" and info.grashof.startswith("crank turns fully")
    assert info.input_range is None
    dead = sorted(np.mod(np.array([np.arctan2(e, np.sqrt((a + b) ** 2 - e**2)),
                                   np.arctan2(e, np.sqrt((b - a) ** 2 - e**2)) + np.pi]) - t0 + np.pi, 2 * np.pi) - np.pi)
    np.testing.assert_allclose(sorted(info.limit_inputs), dead, atol=1e-12)
    # transmission angle: between the rod and the normal of the slide, 90 deg when the rod lies along the slide
    B = a * np.array([np.cos(t0), np.sin(t0)])
    rod = np.array([x0, e]) - B
    assert abs(info.transmission_angle - np.arccos(abs(rod[1]) / b)) < 1e-12


def test_grid_values_next_to_a_limit_position_are_reached(tmp_path):
    """A triple rocker (ground 0.10, crank 0.04, coupler 0.12, rocker 0.19: non-Grashof) driven to
    within 1e-8 rad of its limit position.  There the tangent predictor overshoots the bend of the
    curve; the value is found on the arc step's own parametrization instead of being skipped.
    Checked in lengths: at the limit the crank tip A is rocker - coupler = 0.07 m from the rocker
    pivot (the law of cosines' bound); at the last value every bar keeps its length."""
    import pinocchio as pin
    from pathlib import Path
    robots = Path(__file__).resolve().parents[3] / "robots"
    m = screwkin.load(robots / "fourbar.urdf.xacro", args={"crank": "0.04", "coupler": "0.12", "rocker": "0.19"})
    solver = PositionSolver(m, ["crank_joint"])
    first = sweep(solver, "crank_joint", 0.0, 6.0, 60)
    assert first.stopped_at is not None and len(first.limits) == 1
    data = m.model.createData()

    def pins(q):
        pin.framesForwardKinematics(m.model, data, q)
        A = data.oMi[m.model.getJointId("coupler_joint")].translation
        B = data.oMf[m.closure.cuts[0].frame1].translation
        return A, B

    A, _ = pins(first.limits[0].q)
    assert np.linalg.norm(A - np.array([0.10, 0, 0])) == pytest.approx(0.07, abs=1e-7)
    end = first.stopped_at - 1e-8
    res = sweep(solver, "crank_joint", 0.0, end, 300)
    assert res.completed and not res.skipped and len(res.values) == 301
    assert res.values[-1] == pytest.approx(end, abs=1e-12)
    A, B = pins(res.q[-1])
    assert np.linalg.norm(A) == pytest.approx(0.04, abs=1e-12)
    assert np.linalg.norm(B - A) == pytest.approx(0.12, abs=1e-9)
    assert np.linalg.norm(B - np.array([0.10, 0, 0])) == pytest.approx(0.19, abs=1e-9)


def test_a_coarse_grid_follows_the_same_branch_and_ends():
    """A non-Grashof four-bar driven from its output link, 3 grid steps over 4.2 rad (a step of 80 deg):
    the tracker ran on without end here (its step budget counted only recorded values), and a coarse
    step could jump across the curve's bend to the other branch.  Now it steps at most
    Tolerances.max_step between grid values: the same limit positions and circuits as a grid 40 times
    finer, found within a bounded amount of work."""
    from pathlib import Path

    from conftest import no_hang

    m = screwkin.load(Path(__file__).resolve().parents[3] / "robots" / "fourbar_non_grashof.urdf")
    solver = PositionSolver(m, ["output_joint"])
    for a, b, turn in ((-2.1, 2.1, False), (-4.2, 0.0, False), (1.0, 5.2, False), (2.0, 6.2, True)):
        with no_hang(30):
            coarse = sweep(solver, "output_joint", a, b, 3, turn=turn, closed_form=False)
        fine = sweep(solver, "output_joint", a, b, 120, turn=turn, closed_form=False)
        assert (coarse.stopped_at is None) == (fine.stopped_at is None)
        if fine.stopped_at is not None:
            assert coarse.stopped_at == pytest.approx(fine.stopped_at, abs=1e-8)
        assert coarse.circuit_closed == fine.circuit_closed
        for x, q in zip(coarse.values, coarse.q):  # every coarse configuration is one the fine grid passes
            same = [qf for xf, qf in zip(fine.values, fine.q) if abs(xf - x) < 1e-12]
            assert not same or min(np.abs(qf - q).max() for qf in same) < 1e-6
