"""Nothing silent (issue 23 item 4): a sweep with holes is not complete, and says where."""

from __future__ import annotations

import json

import pytest

from conftest import ROBOTS
from screwkin import load
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.sweep import sweep
from screwkin.present.report import sweep_dict, sweep_text


def test_a_sweep_with_holes_is_not_complete_and_says_where(monkeypatch):
    """A real sweep that skips: the tracker passes grid values where the loops cannot be closed with the
    input held there, as when Newton does not converge at a value, and goes on.  The crank-rocker's
    closure fails (AssemblyError, what the damped Newton raises) at crank = 0.3 and 0.4 rad exactly, with
    the crank held; everywhere else it is the real solver.  The tracker reaches the values around them by
    an arc step with a passive joint held, finds 0.3 and 0.4 on that arc (Brent on the arc) and cannot
    polish them: they are the sweep's holes (an AssemblyError escaped the arc's polish before, and the
    whole sweep failed).  Checked against the grid (20 steps of 0.05 rad) and the bar lengths of the
    file (crank 0.04, coupler 0.12, rocker 0.08 from the pivot at (0.10, 0, 0)) at every value reached."""
    import numpy as np
    import pinocchio as pin

    from screwkin.errors import AssemblyError

    mech = load(str(ROBOTS / "fourbar_crank_rocker.urdf"))
    ix = int(mech.velocity_indices(["crank_joint"])[0])
    iq = mech.coordinate("crank_joint").idx_q
    real = mech.closure.solve
    holes = (0.3, 0.4)

    def newton_fails_at_the_holes(q0, frozen=(), tolerances=None, trace=None):
        if ix in frozen and min(abs(q0[iq] - h) for h in holes) < 1e-9:
            raise AssemblyError(mech.path, 1e-3, mech.tolerances.max_iterations)
        return real(q0, frozen, tolerances, trace)

    monkeypatch.setattr(mech.closure, "solve", newton_fails_at_the_holes)
    res = sweep(PositionSolver(mech, ["crank_joint"]), "crank_joint", 0.0, 1.0, 20, closed_form=False, batch=False)
    grid = [0.05 * k for k in range(21)]
    assert res.stopped_at is None and not res.completed
    np.testing.assert_allclose(res.skipped, holes, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.values, [g for g in grid if min(abs(g - h) for h in holes) > 1e-9], rtol=0,
                               atol=1e-12)
    data = mech.model.createData()
    for x, q in zip(res.values, res.q):
        pin.framesForwardKinematics(mech.model, data, q)
        A = data.oMi[mech.model.getJointId("coupler_joint")].translation
        B = data.oMf[mech.closure.cuts[0].frame1].translation
        assert abs(np.arctan2(A[1], A[0]) - (x + np.radians(60))) < 1e-9  # drawn at 60 deg: the joint's zero
        assert abs(np.linalg.norm(A) - 0.04) < 1e-12 and abs(np.linalg.norm(B - A) - 0.12) < 1e-9
        assert abs(np.linalg.norm(B - np.array([0.10, 0, 0])) - 0.08) < 1e-9
    d = sweep_dict(res, mech)
    assert d["completed"] is False and d["skipped"] == pytest.approx(list(holes), abs=1e-12)
    assert "not solved at 2 input values the motion passed" in sweep_text(res)
    json.dumps(d, default=float)


def test_generic_configurations_are_cached_on_their_arguments():
    """Mechanism.mobility(seed=...) had no effect once topology() ran: the cache ignored hint and seed."""
    mech = load(str(ROBOTS / "fourbar_crank_rocker.urdf"))
    first = mech.generic_configurations()
    assert mech.generic_configurations() is not None and mech.generic_configurations()[1] is first[1]
    other = mech.generic_configurations(seed=7)
    assert len(other[1]) >= 1
    assert any(not (a.shape == b.shape and (a == b).all()) for a, b in zip(first[1], other[1])) or \
        len(first[1]) != len(other[1])  # another seed: another sample of configurations


def test_output_is_the_same_whatever_the_hash_seed():
    """The table order of info and mobility on the Delta and the Stewart platform changed with PYTHONHASHSEED
    (compound joints were read from sets)."""
    import os
    import subprocess
    import sys

    for robot in ("delta_parallelogram.urdf", "gough_stewart_6ups.urdf"):
        for command in ("info", "mobility"):
            outs = set()
            for seed in ("1", "2"):
                env = dict(os.environ, PYTHONHASHSEED=seed)
                p = subprocess.run([sys.executable, "-m", "screwkin", command, str(ROBOTS / robot), "--json"],
                                   capture_output=True, text=True, env=env, timeout=120)
                assert p.returncode == 0, p.stderr
                outs.add(p.stdout)
            assert len(outs) == 1, (robot, command)


def test_mode_k_is_chosen_and_said(tmp_path, capsys):
    """--mode K on the commands that analyse one configuration; with several modes the text says which one
    (stderr) and the JSON has mode {index, of}. The crank-rocker at a 90 deg crank: the rocker's absolute angle
    in each mode by the law of cosines (crank 0.04, coupler 0.12, rocker 0.08, ground 0.1)."""
    import json

    import numpy as np

    from screwkin.cli import main

    a, b, c, d = 0.04, 0.12, 0.08, 0.1
    A, D = np.array([0.0, a]), np.array([d, 0.0])  # crank at 90 deg (the file draws it at 60 deg)
    z = np.linalg.norm(A - D)
    towards = np.arctan2(*(A - D)[::-1])
    gamma = np.arccos((c * c + z * z - b * b) / (2 * c * z))
    expected = {round(float(np.degrees(np.mod(t + np.pi, 2 * np.pi) - np.pi)), 6) for t in (towards - gamma,
                                                                                           towards + gamma)}
    seen = set()
    for k in (1, 2):
        argv = ["draw", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=30deg", "--mode", str(k),
                "--svg", str(tmp_path / f"m{k}.svg"), "--json"]
        assert main(argv) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["mode"] == {"index": k, "of": 2}
        seen.add(round(float(np.degrees(out["link_angles"]["4"])), 6))  # link 4: the rocker (ground 1)
    assert seen == expected
    assert main(["singularities", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=30deg"]) == 0
    assert "note: assembly mode 1 of 2 (others: --mode 2, or --near)" in capsys.readouterr().err
    assert main(["singularities", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=30deg",
                 "--mode", "3"]) == 2
    assert "give 2 assembly modes" in capsys.readouterr().err


def test_a_near_value_the_mode_misses_is_said(tmp_path, capsys):
    """issue 23 item 3: --near names only the rocker, at 170 deg; with the crank at 30 deg the four-bar's modes put
    the rocker at 55.27 or -89.30 deg (law of cosines), so the mode found is far from the value given: said, in the
    text and in JSON, with the value it has."""
    import math

    from screwkin.cli import main

    path = tmp_path / "fourbar.urdf"
    path.write_text(QUICK_FOURBAR)
    g, a, b, c, t2 = 0.10, 0.04, 0.12, 0.08, math.radians(30)
    A = (a * math.cos(t2), a * math.sin(t2))
    d = math.hypot(g - A[0], A[1])
    gamma = math.acos((c * c + d * d - b * b) / (2 * c * d))  # at O4 between O4->A and O4->B
    phi = math.atan2(A[1], A[0] - g)
    rockers = sorted(math.degrees(phi + s * gamma) for s in (1, -1))
    assert main(["solve", str(path), "--set", "O2=30deg", "--near", "O4=170deg", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (note,) = d["notes"]
    got = math.degrees(d["solutions"][0]["joints"]["O4"])
    assert min(abs(got - r) for r in rockers) < 1e-6 and "--near O4=170 deg" in note and f"{got:.4g} deg" in note
    assert main(["solve", str(path), "--set", "O2=30deg", "--near", "O4=60deg", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["notes"] == []  # 55.27 deg is near 60 deg: nothing to say
    assert main(["singularities", str(path), "--set", "O2=30deg", "--near", "O4=170deg"]) == 0
    assert "--near O4=170 deg: the assembly mode found has O4" in capsys.readouterr().err


QUICK_FOURBAR = """<?xml version="1.0"?>
<robot name="my_fourbar">
  <link name="ground"/> <link name="crank"/> <link name="coupler"/> <link name="rocker"/>
  <joint name="O2" type="continuous"><parent link="ground"/> <child link="crank"/> <origin xyz="0 0 0"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="A" type="continuous"><parent link="crank"/> <child link="coupler"/> <origin xyz="0.04 0 0"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="O4" type="continuous"><parent link="ground"/> <child link="rocker"/> <origin xyz="0.10 0 0"/>
    <axis xyz="0 0 1"/></joint>
  <loop_joint name="B" type="revolute"><link1 link="coupler" xyz="0.12 0 0"/> <link2 link="rocker" xyz="0.08 0 0"/>
    <axis xyz="0 0 1"/></loop_joint>
  <transmission name="motor"><joint name="O2"/></transmission>
</robot>
"""


def test_solve_without_inputs_names_them_with_a_command_that_works(capsys):
    """solve with no input value said only "solve needs input values"; a newcomer then had to read the
    file for the names.  The error names the inputs (the actuated joints leg1..leg6 of the Stewart
    platform, motor1 and motor2 of the five-bar: as the files' <transmission> elements say) in a --set
    at the file's values, and that option, typed as printed, solves."""
    from screwkin.cli import main

    for name, want in (("gough_stewart_6ups.urdf", "--set leg1,leg2,leg3,leg4,leg5,leg6=0"),
                       ("five_bar.urdf", "--set motor1,motor2=0")):
        assert main(["solve", str(ROBOTS / name)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"screwkin: error: {ROBOTS / name}: solve needs input values") and want in err, err
    assert main(["solve", str(ROBOTS / "five_bar.urdf"), *"--set motor1,motor2=0".split()]) == 0
    assert "all 2 assembly modes (certified" in capsys.readouterr().out
