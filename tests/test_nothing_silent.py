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
