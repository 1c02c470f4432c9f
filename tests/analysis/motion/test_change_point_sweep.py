"""A motion through a change point (issue 41, section 4): a parallelogram four-bar (ground = coupler, crank =
rocker) folds flat where its links are collinear, and the parallelogram and antiparallelogram branches cross
there; a kite (crank = coupler, ground = rocker) folds with the coupler's end on the crank's pivot, where its
moving branch crosses the branch that keeps that point there.  Whatever the grid, the sweep passes the
change point on the branch whose tangent continues the incoming one, names it at the input value where the
links are collinear, never calls it a limit position; ``branch="other"`` (--branch other) takes the other.

Every value is checked against the closed forms of the two branches, written out here (angles from the
ground line, pivots A = (0, 0) and D = (g, 0), crank angle t, rocker angle p):
- parallelogram: p = t; antiparallelogram: tan(p / 2) = -(g + a) / (g - a) tan(t / 2) (from
  |C - B| = g: sin((p - t) / 2) (g sin((p + t) / 2) - a sin((p - t) / 2)) = 0); they cross at t = 0, 180 deg;
- kite: C is A mirrored in the line B D (the moving branch), or C = A (p = 180 deg, any t); they cross at
  t = 0, 180 deg.
"""

import json
import math

import numpy as np
import pytest

import screwkin
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main

G, A = 0.1, 0.04  # ground (= coupler), crank (= rocker) of the parallelogram; the kite: ground = rocker, crank = coupler
STEPS = (36, 72, 73, 100, 360)  # grid values on the change point (36, 72, 360) and off it (73, 100)
ANGLE = 1e-6  # rad: the closure tolerance 1e-10 m, near a fold where the closure converges as a square root


def _bar(name, length):
    return (f'  <link name="{name}"><visual><origin xyz="{length / 2} 0 0" rpy="0 1.5707963 0"/><geometry>'
            f'<cylinder radius="0.004" length="{length}"/></geometry></visual><inertial><origin xyz="{length / 2} 0 0"/>'
            '<mass value="0.2"/><inertia ixx="0.0002" iyy="0.0002" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial>'
            '</link>\n')


def four_bar(g, a, b, c, t, p_coupler, p_rocker, name="four_bar"):
    """A planar four-bar drawn with the crank at t, the coupler at p_coupler, the rocker at p_rocker (rad,
    absolute): every joint 0 as drawn."""
    return (f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "".join(_bar(n, x) for n, x in (
        ("ground", g), ("crank", a), ("coupler", b), ("rocker", c))) +
        f'  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/>'
        f'<origin xyz="0 0 0" rpy="0 0 {t!r}"/><axis xyz="0 0 1"/></joint>\n'
        f'  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>'
        f'<origin xyz="{a} 0 0" rpy="0 0 {p_coupler - t!r}"/><axis xyz="0 0 1"/></joint>\n'
        f'  <joint name="rocker_joint" type="continuous"><parent link="ground"/><child link="rocker"/>'
        f'<origin xyz="{g} 0 0" rpy="0 0 {p_rocker!r}"/><axis xyz="0 0 1"/></joint>\n'
        f'  <loop_joint name="coupler_rocker" type="revolute"><link1 link="coupler" xyz="{b} 0 0"/>'
        f'<link2 link="rocker" xyz="{c} 0 0"/><axis xyz="0 0 1"/></loop_joint>\n'
        '  <transmission name="t"><type>transmission_interface/SimpleTransmission</type><joint name="crank_joint">'
        '<hardwareInterface>EffortJointInterface</hardwareInterface></joint><actuator name="m">'
        '<mechanicalReduction>1</mechanicalReduction></actuator></transmission>\n</robot>\n')


def parallelogram(t):
    return t


def antiparallelogram(t):
    return 2 * np.arctan2(-(G + A) * np.sin(t / 2), (G - A) * np.cos(t / 2))


def kite(t):
    """The kite's moving branch: C = A mirrored in the line B D."""
    B, D = np.array([A * np.cos(t), A * np.sin(t)]), np.array([G, 0.0])
    u = (D - B) / np.linalg.norm(D - B)
    C = 2 * (B - (B @ u) * u)
    return math.atan2(C[1], C[0] - G)


def kite_folded(t):
    return math.pi


DRAWN = {  # name: (crank angle drawn, rocker angle drawn, the file)
    "parallelogram": (math.pi / 3, math.pi / 3, lambda t, p: four_bar(G, A, G, A, t, 0.0, p, "parallelogram")),
    "flat": (0.0, 0.0, lambda t, p: four_bar(G, A, G, A, t, 0.0, p, "parallelogram_flat")),
    "kite": (math.pi / 2, kite(math.pi / 2), lambda t, p: four_bar(G, A, A, G, t, _kite_coupler(t), p, "kite")),
}


def _kite_coupler(t):
    B = np.array([A * np.cos(t), A * np.sin(t)])
    C = np.array([G, 0.0]) + G * np.array([np.cos(kite(t)), np.sin(kite(t))])
    return math.atan2(C[1] - B[1], C[0] - B[0])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("change_points")
    out = {}
    for name, (t, p, text) in DRAWN.items():
        path = folder / f"{name}.urdf"
        path.write_text(text(t, p))
        out[name] = path
    return out


@pytest.fixture(scope="module")
def solvers(files):
    return {name: PositionSolver(screwkin.load(path), ["crank_joint"]) for name, path in files.items()}


def angles(res, name):
    """(crank, rocker) angles from the ground line along the sweep [rad]."""
    t0, p0, _ = DRAWN[name]
    ic, ir = res.names.index("crank_joint"), res.names.index("rocker_joint")
    return t0 + res.joints[:, ic], p0 + res.joints[:, ir]


def off(p, expected) -> np.ndarray:
    """|p - expected| up to whole turns [rad]."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(p) - np.asarray(expected)))))


def check_through(res, name, branch_before, branch_after, change_at, steps, switched=False):
    """The sweep is complete, lists no limit position, follows branch_before up to the change point and
    branch_after from it, and names the change point at change_at (the crank's joint value) once."""
    assert res.stopped_at is None and res.stop_reason is None and res.completed
    assert len(res.values) == steps + 1 and not res.limits
    t, p = angles(res, name)
    x = res.values
    before, after = x <= change_at + ANGLE, x >= change_at - ANGLE
    assert np.max(off(p[before], [branch_before(v) for v in t[before]])) < ANGLE
    assert np.max(off(p[after], [branch_after(v) for v in t[after]])) < ANGLE
    named = [c for c in res.change_points if abs(c.input - change_at) < ANGLE]
    assert len(named) == 1 and named[0].local.kind == "bifurcation" and len(named[0].local.branches) == 2
    assert named[0].switched == switched
    line = next(n for n in res.change_point_notes if f"({math.degrees(change_at):.6g} deg)" in n)
    assert "two branches cross" in line
    assert ("as --branch other asks" in line) == switched
    assert "limit position" not in " ".join(res.notes)


@pytest.mark.parametrize("turn", [False, True])
@pytest.mark.parametrize("steps", STEPS)
def test_the_parallelogram_stays_a_parallelogram_through_its_change_point(solvers, steps, turn):
    """Drawn at 60 deg, swept 180 deg: the links are collinear at crank 180 deg, the joint's 120 deg (on the
    grid of 36, 72 and 360 steps, off it for 73 and 100); with and without --turn."""
    res = sweep(solvers["parallelogram"], "crank_joint", 0.0, math.pi, steps, turn=turn)
    check_through(res, "parallelogram", parallelogram, parallelogram, 2 * math.pi / 3, steps)


@pytest.mark.parametrize("steps", STEPS)
def test_the_other_branch_is_the_antiparallelogram(solvers, steps):
    res = sweep(solvers["parallelogram"], "crank_joint", 0.0, math.pi, steps, branch="other")
    check_through(res, "parallelogram", parallelogram, antiparallelogram, 2 * math.pi / 3, steps, switched=True)


@pytest.mark.parametrize("steps", STEPS)
def test_the_parallelogram_drawn_folded_flat_turns_a_whole_turn_as_a_parallelogram(solvers, steps):
    """Drawn folded flat (every joint 0 is the change point): the motion starts on it on the branch nearest
    the input's own direction, the parallelogram, and passes the other fold at 180 deg."""
    res = sweep(solvers["flat"], "crank_joint", 0.0, 2 * math.pi, steps)
    check_through(res, "flat", parallelogram, parallelogram, math.pi, steps)
    first = res.change_points[0]
    assert abs(first.input) < ANGLE and first.came is None
    assert "the motion starts on it" in res.change_point_notes[0]


@pytest.mark.parametrize("turn", [False, True])
@pytest.mark.parametrize("steps", STEPS)
def test_the_kite_passes_its_fold_on_its_moving_branch(solvers, steps, turn):
    """Before: a grid value on the fold (crank 180 deg, the joint's 90 deg) stopped there as a "limit
    position" (with --turn the motion bounced between the folds, 1,439 configurations for 36 steps), and
    off the grid the motion slipped onto the branch with the coupler's end held on the crank's pivot."""
    res = sweep(solvers["kite"], "crank_joint", 0.0, math.pi, steps, turn=turn)
    check_through(res, "kite", kite, kite, math.pi / 2, steps)


@pytest.mark.parametrize("steps", (36, 73))
def test_the_kite_s_other_branch_holds_the_coupler_s_end_on_the_crank_s_pivot(solvers, steps):
    res = sweep(solvers["kite"], "crank_joint", 0.0, math.pi, steps, branch="other")
    check_through(res, "kite", kite, kite_folded, math.pi / 2, steps, switched=True)


def test_the_kite_started_on_its_fold_takes_the_branch_it_is_drawn_on(solvers):
    """Swept from the fold at crank 0 (joint -90 deg): the file is drawn on the moving branch, so the motion
    starts on it (said so), and passes the other fold at crank 180 deg (joint 90 deg)."""
    res = sweep(solvers["kite"], "crank_joint", -math.pi / 2, 3 * math.pi / 2, 36)
    check_through(res, "kite", kite, kite, math.pi / 2, 36)
    assert "the branch the file's configuration lies on" in res.change_point_notes[0]


def test_sweep_names_the_change_point_and_takes_the_other_branch_on_request(files, capsys):
    args = ["sweep", str(files["kite"]), "--input", "crank_joint", "--from", "0", "--to", "180deg", "--steps", "36"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert ("note: change point at crank_joint = 1.570796 rad (90 deg): two branches cross; continuing on the "
            "branch whose tangent continues the motion (the other: --branch other)") in out
    assert "limit position at" not in out and "stopped" not in out and ": 37 configurations" in out
    assert main([*args, "--turn"]) == 0
    assert ": 37 configurations" in capsys.readouterr().out  # (it bounced over 1,439 before)
    assert main([*args, "--branch", "other", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["completed"] and d["stopped_at"] is None and len(d["values"]) == 37
    (cp,) = d["change_points"]
    assert cp["branch"] == "other" and abs(cp["input"] - math.pi / 2) < ANGLE
    assert cp["local"]["kind"] == "bifurcation" and "as --branch other asks" in cp["note"]
    assert abs(d["joints"][-1][2] + DRAWN["kite"][1] - math.pi) < ANGLE  # the rocker stays at 180 deg
    assert main([*args, "--branch", "sideways"]) == 2


def test_dynamics_shares_the_sweep(files, capsys):
    """The same motion in dynamics: its notes name the change point."""
    assert main(["dynamics", str(files["kite"]), "--input", "crank_joint", "--from", "0", "--to", "180deg",
                 "--steps", "36", "--speed", "60rpm", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["completed"] and any(n.startswith("change point at crank_joint = 1.570796 rad (90 deg)") for n in d["notes"])
    assert not any("limit position" in n for n in d["notes"])


@pytest.mark.slow
def test_draw_animate_shares_the_sweep(files, capsys, tmp_path):
    """The same motion in draw --animate: its frames, its JSON."""
    pytest.importorskip("matplotlib")
    gif = tmp_path / "kite.gif"
    assert main(["draw", str(files["kite"]), "--animate", str(gif), "--from", "0", "--to", "180deg", "--steps", "12",
                 "--branch", "other", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["frames"] == 13 and d["stopped_at"] is None
    assert len(d["change_points"]) == 1 and "as --branch other asks" in d["change_points"][0]


@pytest.mark.parametrize("chunk", [18, 5])
def test_a_sweep_in_chunks_passes_the_change_point_as_the_whole_sweep(solvers, chunk):
    """sweep --chunk: a chunk that starts on the change point (18: the fold at the 18th of 36 steps) goes on
    along the branch the motion came in on, as the sweep in one piece does."""
    from screwkin.analysis.motion.stream import sweep_chunks

    pieces = list(sweep_chunks(solvers["kite"], "crank_joint", 0.0, math.pi, 36, chunk=chunk))
    t = DRAWN["kite"][0] + np.concatenate([p.joints[:, 0] for p in pieces])
    p = DRAWN["kite"][1] + np.concatenate([p.joints[:, 2] for p in pieces])
    assert len(t) == 37 and np.max(off(p, [kite(v) for v in t])) < ANGLE
    assert sum(len(p.change_points) for p in pieces) == 1


def test_a_chunk_that_starts_on_the_change_point_continues_the_motion_before_it(solvers):
    """The parallelogram drawn folded flat, a whole turn in chunks of 18 of 36 steps: the second chunk starts
    on the fold at 180 deg, where the drawing (on the other fold, on both branches) cannot choose; the
    motion before it (the chunk's prior configuration) does: the parallelogram."""
    from screwkin.analysis.motion.stream import sweep_chunks

    pieces = list(sweep_chunks(solvers["flat"], "crank_joint", 0.0, 2 * math.pi, 36, chunk=18))
    t = np.concatenate([p.joints[:, 0] for p in pieces])
    p = np.concatenate([p.joints[:, 2] for p in pieces])
    assert len(t) == 37 and np.max(off(p, t)) < ANGLE
