"""Nothing silent (issue 23 item 4): a sweep with holes is not complete, and says where."""

from __future__ import annotations

import dataclasses

from conftest import ROBOTS
from screwkin import load
from screwkin.analysis.position import PositionSolver
from screwkin.analysis.sweep import sweep
from screwkin.present.report import sweep_dict, sweep_text


def test_a_sweep_with_holes_is_not_complete_and_says_where():
    mech = load(str(ROBOTS / "fourbar_crank_rocker.urdf"))
    res = sweep(PositionSolver(mech, ["crank_joint"]), "crank_joint", 0.0, 1.0, 10)
    assert res.completed and sweep_dict(res, mech)["completed"] is True and sweep_dict(res, mech)["skipped"] == []
    holed = dataclasses.replace(res, skipped=(0.3, 0.4))
    d = sweep_dict(holed, mech)
    assert d["completed"] is False and d["skipped"] == [0.3, 0.4]
    assert "not solved at 2 input values the motion passed" in sweep_text(holed)


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
