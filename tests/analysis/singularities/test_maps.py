"""Singularity maps follow one assembly mode (issue 23 item 4: map never mixes modes).

A five-bar whose motors stand 0.3 m apart (proximal links 0.1 m, distal 0.15 m) cannot be
assembled where the elbows are more than 0.3 m apart, and its two modes (the tip left or right
of the line from elbow 1 to elbow 2) meet only there.  Every cell the map reports must lie on the
first cell's mode: the tip is the circle intersection of that side, computed here."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin

import screwkin
from screwkin.analysis.singularities.maps import singularity_map

from conftest import screwkin_cli

ROBOTS = Path(__file__).resolve().parents[3] / "robots"
R1, R2 = 0.1, 0.15  # proximal and distal lengths of robots/five_bar.urdf


def elbows(t1, t2):
    """Elbow centres in the plane: B1 = R(t1) (-0.05, 0.0866), B2 = (0.3, 0) + R(t2) (0.05, 0.0866)."""
    def rot(t, v):
        return np.array([np.cos(t) * v[0] - np.sin(t) * v[1], np.sin(t) * v[0] + np.cos(t) * v[1]])
    return rot(t1, (-0.05, np.sqrt(3) / 20)), np.array([0.3, 0.0]) + rot(t2, (0.05, np.sqrt(3) / 20))


def tip(B1, B2, side):
    """Intersection of the circles of radius R2 about B1 and B2 on ``side`` (+1: left of B1->B2)."""
    d = B2 - B1
    L = np.linalg.norm(d)
    a = L / 2
    h = np.sqrt(max(R2**2 - a**2, 0.0))
    n = np.array([-d[1], d[0]]) / L
    return B1 + d / 2 + side * h * n


def test_a_map_reports_only_cells_of_its_first_mode(wide_five_bar):
    mech = screwkin.load(wide_five_bar)
    solver = screwkin.PositionSolver(mech)
    xs = np.linspace(-np.pi, np.pi, 25)
    ys = np.linspace(-np.pi, np.pi, 25)
    res = singularity_map(solver, "motor1", xs, "motor2", ys)
    tip_frame = mech.model.getFrameId("tip")
    data = mech.model.createData()
    sides = []
    for j, i in zip(*np.nonzero(res.reached)):
        B1, B2 = elbows(xs[i], ys[j])
        assert np.linalg.norm(B2 - B1) <= 2 * R2 + 1e-9  # assembled cells only
        pin.framesForwardKinematics(mech.model, data, res.q[j, i])
        p = data.oMf[tip_frame].translation[:2]
        d = B2 - B1
        side = np.sign(d[0] * (p - B1)[1] - d[1] * (p - B1)[0])
        h = np.sqrt(max(R2**2 - (np.linalg.norm(d) / 2) ** 2, 0.0))
        if h > 1e-6:  # at the fold itself (the elbows 0.3 m apart) the two modes are one configuration
            sides.append(side)
        # the closure residual (1e-10) moves the tip by about residual / sin(angle of the distal
        # links): near the fold, where the two circles touch, the tip is less well determined
        np.testing.assert_allclose(p, tip(B1, B2, side), rtol=0, atol=1e-9 + 1e-9 * R2 / max(h, 1e-6))
    assert len(set(sides)) == 1, "the map mixed the two assembly modes"
    assert 0 < res.reached.sum() < res.reached.size
    off = [(j, i) for j in range(len(ys)) for i in range(len(xs)) if not res.reached[j, i]]
    assert all(np.isnan(res.log_sigma[j, i]) and res.kind[j, i] == "" for j, i in off)
    # the cells left out are those that do not assemble, or assemble only in the other mode: every
    # assemblable cell of the first mode that is connected to the first cell is reached
    assert res.notes and "not reached" in res.notes[0]


def test_the_map_command_says_what_it_left_out(wide_five_bar):
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=-180deg:180deg:13",
                     "--y", "motor2=-180deg:180deg:13", "--json")
    assert p.returncode == 0, p.stderr
    out = p.stdout
    d = json.loads(out)
    reached = np.array(d["reached"])
    logs = d["log10_sigma_min"]
    assert d["off_branch"] == int((~reached).sum()) > 0
    assert all((logs[j][i] is None) == (not reached[j][i]) for j in range(13) for i in range(13))
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=-180deg:180deg:13",
                     "--y", "motor2=-180deg:180deg:13")
    assert p.returncode == 0 and "not reached from the first one by continuation" in p.stdout


def test_json_writes_infinity_as_a_string_and_nan_as_null():
    from screwkin.present.jsonout import to_jsonable
    assert to_jsonable({"a": [1.0, float("inf"), -np.inf]}) == {"a": [1.0, "inf", "-inf"]}
    assert to_jsonable({"b": np.array([0.0, np.nan])}) == {"b": [0.0, None]}


def test_a_map_needs_two_different_inputs(wide_five_bar):
    """The same joint on both axes (it was an IndexError, exit 3) or also held by --set: usage errors."""
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=0:1:3", "--y", "motor1=0:1:3")
    assert p.returncode == 2 and "name the same input 'motor1'" in p.stderr
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--set", "motor2=0.1")
    assert p.returncode == 2 and "given by --x/--y and by --set" in p.stderr


def test_a_map_whose_first_corner_does_not_assemble_starts_where_the_box_does(wide_five_bar):
    """The first corner (motor1 = 0, motor2 = 0) has the elbows 0.4 m apart, more than the distal links reach
    (0.3 m): nothing assembles there.  The map starts at the box's centre (0.127 m apart), says so, and every
    cell it reports assembles (the closed form above); before, it stopped with an error."""
    p = screwkin_cli("map", str(wide_five_bar), "--x", "motor1=0deg:-180deg:13", "--y", "motor2=0deg:180deg:13",
                     "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert any("nothing assembles at the first corner" in n and "the map starts at" in n for n in d["notes"])
    reached = np.array(d["reached"])
    xs, ys = np.radians(np.linspace(0, -180, 13)), np.radians(np.linspace(0, 180, 13))
    B1, B2 = elbows(xs[0], ys[0])
    assert np.linalg.norm(B2 - B1) > 2 * R2 and not reached[0, 0] and reached[6, 6]
    for j, i in zip(*np.nonzero(reached)):
        B1, B2 = elbows(xs[i], ys[j])
        assert np.linalg.norm(B2 - B1) <= 2 * R2 + 1e-9
    # the Python API the same way
    solver = screwkin.PositionSolver(screwkin.load(wide_five_bar))
    res = singularity_map(solver, "motor1", xs, "motor2", ys)
    assert np.array_equal(res.reached, reached) and "nothing assembles at the first corner" in res.notes[0]
