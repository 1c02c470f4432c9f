"""Wrong words (issue 33 item 5): what a report says must be what the mechanism is."""

from __future__ import annotations

import json
import math

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import classify, lost_direction
from screwkin.cli import main
from screwkin.model._pin import joint_axis
from screwkin.model.state import KinematicState

BALL = """<mujoco model="ball"><worldbody><body name="arm" pos="0 0 0.1"><joint name="ball" type="ball"/>
<inertial pos="0 0 0.1" mass="1" diaginertia="0.1 0.1 0.1"/></body></worldbody></mujoco>"""


def _out(argv, capsys, code=0):
    got = main(argv)
    out, err = capsys.readouterr()
    assert got == code, err
    return out, err


# ------------------------------------------------------------------ (a) a ball joint's axes are concurrent
def test_a_single_ball_joint_moves_spherically(tmp_path, capsys):
    p = tmp_path / "ball.xml"
    p.write_text(BALL)
    out, _ = _out(["mobility", str(p), "--json"], capsys)
    d = json.loads(out)
    assert d["motion_space"] == "spherical"
    out, _ = _out(["mobility", str(p)], capsys)
    assert "motion space: spherical (every joint axis passes through (0, 0, 0.1))" in out
    assert "neither all parallel" not in out
    # a mechanism whose balls are not concurrent stays spatial; the spherical four-bar stays spherical
    assert screwkin.load(ROBOTS / "delta_parallelogram.urdf").topology().motion_space == "spatial"
    assert screwkin.load(ROBOTS / "spherical_fourbar.urdf").topology().motion_space == "spherical"


# ------------------------------------------------------------------ (b) never a zero twist as a screw
def test_the_lost_direction_of_a_planar_output_stays_in_its_plane():
    """The output's motion map of a planar point: it moves along x only (a serial singularity: y is lost);
    round-off out of the plane (1e-17 in z) is larger than the vanishing in-plane singular value (0), so the
    plain SVD's second left singular vector is z -- the zero twist once projected onto the plane."""
    JV = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-17, 0.0]])
    naive = np.linalg.svd(JV)[0][:, 1]
    assert abs(naive[2]) == pytest.approx(1.0)  # the trap: out of the plane
    lost = lost_direction(JV, 2, normal=(0.0, 0.0, 1.0))
    assert np.allclose(np.abs(lost), [0, 1, 0, 0, 0, 0], atol=1e-12)
    lost = lost_direction(np.vstack([JV, np.zeros((3, 3))]), 2, normal=(0.0, 0.0, 1.0))  # (v, w) rows
    assert np.linalg.norm(lost) == pytest.approx(1.0)  # a unit twist in the plane: (vx, vy, wz) only
    assert np.abs(lost[[2, 3, 4]]).max() < 1e-12


def test_3rpr_serial_direction_at_a_zero_length_leg_is_a_translation_across_it(capsys):
    """Leg 1 of zero length: the platform's joint with it sits on its base pivot, and moves only along the leg;
    the platform loses the translation across the leg (its frame is at that joint: the lost twist is that
    translation, a screw of infinite pitch perpendicular to the leg's axis)."""
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    q0 = mech.generic_configurations()[0].q
    st = KinematicState(mech, q0)
    w1 = st.joint_placement(mech.model.getJointId("wrist1")).translation[:2]
    frame2 = {c.name: st.frame_placement(c.frame1).translation[:2] for c in mech.cuts}
    anchors = {1: np.zeros(2), 2: frame2["wrist2"] - w1, 3: frame2["wrist3"] - w1}
    base = {1: np.array([0, 0.25]), 2: np.array([-0.2165063509461096, -0.125]),
            3: np.array([0.2165063509461096, -0.125])}
    values = {f"leg{i}": float(np.linalg.norm(base[1] + anchors[i] - base[i])) - st.leg_lengths[f"leg{i}"]
              for i in (1, 2, 3)}
    res = PositionSolver(mech, ["leg1", "leg2", "leg3"], output="platform").solve(values)
    for sol in res.solutions:
        rep = classify(mech, sol.q, ["leg1", "leg2", "leg3"], "platform")
        (serial,) = [t for t in rep.singular_twists if t.kind == "serial"]
        assert rep.serial and np.linalg.norm(serial.screw.direction) == pytest.approx(1.0)
        assert math.isinf(serial.screw.pitch)
        j = mech.model.getJointId("leg1")
        axis = KinematicState(mech, sol.q).joint_placement(j).rotation @ joint_axis(mech.model.joints[j])
        assert abs(np.dot(serial.screw.direction, axis)) < 1e-6
    text, _ = _out(["singularities", str(ROBOTS / "planar_3rpr.urdf"), "--output", "platform", "--set",
                    ",".join(f"{k}={v!r}" for k, v in values.items())], capsys)
    assert "serial singular direction" in text and "axis direction 0 0 0" not in text


# ------------------------------------------------------------------ (c) one lettering
def test_synthesize_letters_the_joints_as_its_drawing(tmp_path, capsys):
    out_file = tmp_path / "m.urdf"
    out, _ = _out(["synthesize", "motion", "--poses", "0,0,0; 0.05,0.02,20deg; 0.1,0.0,40deg", "--pivots",
                   "0,-0.1; 0.15,-0.1", "-o", str(out_file), "--json"], capsys)
    d = json.loads(out)
    drawn, _ = _out(["draw", str(out_file), "--png", str(tmp_path / "m.png"), "--json"], capsys)
    letters = {j["name"]: j["letter"] for j in json.loads(drawn)["joints"]}
    for role, pj in d["pivot_joints"].items():
        assert pj["letter"] == letters[pj["joint"]]
        x, y = d["pivots"][role]
        point = next(j["point"] for j in json.loads(drawn)["joints"] if j["name"] == pj["joint"])
        assert (x, y) == pytest.approx(tuple(point), abs=1e-9)  # the same joint, at the same place
    text, _ = _out(["synthesize", "motion", "--poses", "0,0,0; 0.05,0.02,20deg; 0.1,0.0,40deg", "--pivots",
                    "0,-0.1; 0.15,-0.1", "-o", str(out_file)], capsys)
    line = next(ln for ln in text.splitlines() if ln.startswith("joints [m]"))
    for name, letter in letters.items():
        assert f"{letter} {name} (" in line
    assert "A0" not in text and "B0" not in text


# ------------------------------------------------------------------ (d) compound joints named as mobility does
def test_reactions_name_compound_joints_as_mobility(capsys):
    delta = str(ROBOTS / "delta_parallelogram.urdf")
    mob, _ = _out(["mobility", delta, "--json"], capsys)
    compound = {j["name"] for j in json.loads(mob)["joints"] if "[" in j["name"]}
    assert "rod1a_top[S]" in compound
    out, _ = _out(["dynamics", delta, "--input", "arm1", "--speed", "60rpm", "--steps", "2", "--set", "arm2=0,arm3=0",
                   "--from", "0", "--to", "10deg", "--json"], capsys)
    reactions = json.loads(out)["reactions"]
    assert not any(n.endswith(("_x", "_y", "_z")) for n in reactions)
    assert "rod1a_top[S]" in reactions
    out, _ = _out(["statics", delta, "--output", "platform", "--wrench", "0 0 -10 0 0 0", "--gravity", "--json"],
                  capsys)
    d = json.loads(out)
    by_name = {r["joint"]: r for r in d["reactions"]}
    assert "rod1a_top[S]" in by_name and "rod1a_top_x" not in by_name
    assert all(not n.endswith(("_x", "_y", "_z")) for leg in d["legs"] for n in leg["joints"])
    # the compound's row is the wrench its first member passes on; the massless links inside pass it on to the
    # rod unchanged: Pinocchio's RNEA of the last member (into the rod) gives the same force
    mech = screwkin.load(delta)
    q = mech.generic_configurations()[0].q
    data = mech.model.createData()
    pin.rnea(mech.model, data, q, np.zeros(mech.nv), np.zeros(mech.nv))
    last = mech.model.getJointId("rod1a_top_z")
    f_last = data.oMi[last].rotation @ data.f[last].linear
    first = mech.model.getJointId("rod1a_top_x")
    f_first = data.oMi[first].rotation @ data.f[first].linear
    assert f_first == pytest.approx(f_last, abs=1e-6 * max(1.0, np.abs(f_last).max()))


# ------------------------------------------------------------------ (e) said once
def test_delta_singularities_say_adj_g_once(capsys):
    out, _ = _out(["singularities", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform"], capsys)
    assert out.count("adj(G) = 0") == 1
    for loop in ("rod1b_bottom", "rod2a_bottom", "rod2b_bottom", "rod3a_bottom", "rod3b_bottom"):
        assert loop in out


# ------------------------------------------------------------------ (f) legs only where there are legs
def test_statics_of_a_slider_crank_prints_no_legs(capsys):
    slider = str(ROBOTS / "slider_crank_offset.urdf")
    out, _ = _out(["statics", slider, "--output", "slider", "--wrench", "10 0 0 0 0 0", "--set", "crank_joint=30deg"],
                  capsys)
    assert "leg 1:" not in out and "no legs' wrenches: 'slider' is joined to the ground by the single joint " \
                                   "slider_joint" in out
    out, _ = _out(["statics", slider, "--output", "slider", "--wrench", "10 0 0 0 0 0", "--set", "crank_joint=30deg",
                   "--json"], capsys)
    d = json.loads(out)
    assert d["legs"] == [] and d["legs_note"].startswith("no legs: ")
    out, _ = _out(["statics", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform", "--wrench",
                   "0 0 -10 0 0 0"], capsys)
    assert out.count("\nleg ") == 3  # a Delta's three legs
