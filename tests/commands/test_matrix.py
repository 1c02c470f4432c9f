"""Every command on every bundled mechanism (issue 41, section 5): at the file's configuration, with every joint
given (the values of the file's assembled configuration), and at ``--mode 2``.  Whatever the command answers,
it answers as a tool: exit 0, or a clear one-line error with exit 1 (the file or the values cannot be analysed)
or 2 (usage) -- never exit 3 (a bug), never a traceback.  Where a certificate is printed, its counts do not
contradict it: the modes found (real and complex) are no more than the bound it cites.

The fast part (singularities and solve, every mechanism) guards issue 41's first two regressions: every
joint given exited 3 on every mechanism with loops; a default solve ran the whole homotopy.  The rest runs
in the slow tier.  ``study``, ``synthesize`` and ``grasp`` take no mechanism file (a family's spec, a
synthesis task, a grasp) and are not part of the matrix."""

from __future__ import annotations

import functools
import itertools
import json
import re

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS, robots_table
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main

#: The bundled mechanisms (robots/, not the corpus): their output link from robots/README.md's table; the
#: two xacro families have the outputs of the files they write with their defaults.
TABLE = robots_table()
OUTPUT = {**{name: row["out"] for name, row in TABLE.items()}, "fourbar.urdf.xacro": TABLE["fourbar_crank_rocker.urdf"]["out"],
          "delta.urdf.xacro": TABLE["delta_parallelogram.urdf"]["out"]}
MECHANISMS = sorted(OUTPUT)


@dataclass(frozen=True)
class Facts:
    """What the matrix needs of a mechanism: its inputs (solve's: the actuated joints, and the joints no loop
    passes through) at the file's assembled values, ``slides`` those that are lengths, every one-coordinate
    joint's value there, the output link's position there (a target ik reaches: Pinocchio's forward
    kinematics) and the characteristic length."""

    inputs: dict
    slides: set
    every: dict
    position: np.ndarray
    length: float


@functools.cache
def facts(name) -> Facts:
    mech = screwkin.load(ROBOTS / name)
    q = mech.generic_configurations()[0].q
    values = mech.joint_values(q)
    solver = PositionSolver(mech)
    inputs = {n: float(values[n]) for n in (*solver.inputs, *solver.unset)}
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return Facts(inputs, {n for n in inputs if mech.translational[mech.coordinate(n).idx_v]},
                 {c.joint: float(values[c.joint]) for c in mech.coordinates if c.nv == 1},
                 data.oMf[mech.link_frame(OUTPUT[name])].translation.copy(), mech.length)


def sets(values: dict) -> list:
    """--set NAME=VALUE for each value, written to round-trip (repr)."""
    return [w for n, v in values.items() for w in ("--set", f"{n}={float(v)!r}")]


def run(capsys, argv):
    """main(argv) in this process: (exit code, stdout, stderr), asserted to be an answer or a clear error."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    shown = " ".join(map(str, argv))
    assert code in (0, 1, 2), f"{shown}: exit {code}\n{err[-2000:]}"
    assert "Traceback" not in err + out, f"{shown}: a traceback\n{err[-2000:]}"
    if code:
        last = [line for line in err.splitlines() if line.strip()][-1]
        assert last.startswith("screwkin: error: "), f"{shown}: exit {code} without a one-line error\n{err[-2000:]}"
    return code, out, err


def counts_hold(modes: dict, where: str):
    """A ModeCount's JSON does not contradict itself: real <= found, real + complex = found where both are
    known, and found no more than the bound its certificate (or its reason) cites."""
    found, real, cplx = modes["found"], modes["real"], modes["complex"]
    assert real <= found, (where, modes)
    if cplx is not None:
        assert real + cplx == found, (where, modes)
    if modes["complete"]:
        assert modes["certificate"], (where, modes)
    for text in (modes["certificate"] or "", modes["reason"] or ""):
        for bound in re.findall(r"(?:at most|^)\s*(\d+) (?:poses|solutions|angle sets|joint solutions)", text):
            unit = re.search(rf"{bound} (\w+)", text)[1]
            # a bound on poses (placements) counts modes; on angle sets, the search's angle sets
            reached = found if unit != "angle" else modes["search"].get("angle_sets", 0)
            assert reached <= int(bound), f"{where}: {reached} found, more than the {bound} {unit} cited: {modes}"


def certificates(d, where):
    """counts_hold on every ModeCount in a JSON answer."""
    if isinstance(d, dict):
        if {"found", "complete", "certificate", "real"} <= set(d):
            counts_hold(d, where)
        for v in d.values():
            certificates(v, where)
    elif isinstance(d, list):
        for v in d:
            certificates(v, where)


# ------------------------------------------------------------------ fast: the two regressions of issue 41
@pytest.mark.parametrize("name", MECHANISMS)
def test_singularities_with_every_joint_given_answer_there_without_a_search(name, capsys):
    every = facts(name).every
    code, out, err = run(capsys, ["singularities", ROBOTS / name, *sets(every), "--json"])
    assert code == 0, err
    # the values are the file's assembled configuration's: the loops close there, and nothing is searched
    assert "every joint given: the loops close (residual" in err and "no search" in err
    d = json.loads(out)
    assert "mode" not in d  # one configuration, not one of several modes


@pytest.mark.parametrize("name", MECHANISMS)
def test_solve_with_every_joint_given_is_that_configuration(name, capsys):
    every = facts(name).every
    code, out, err = run(capsys, ["solve", ROBOTS / name, *sets(every), "--json"])
    assert code == 0, err
    d = json.loads(out)
    assert d["method"] == "every joint given" and d["complete"] and len(d["solutions"]) == 1
    joints = d["solutions"][0]["joints"]
    for n, v in every.items():  # the values given, unchanged (an angle up to whole turns)
        assert abs(np.angle(np.exp(1j * (joints[n] - v)))) < 1e-12, (n, joints[n], v)


@pytest.mark.parametrize("name", MECHANISMS)
def test_default_solve_at_the_file_inputs(name, capsys):
    inputs = facts(name).inputs
    assert inputs  # every bundled mechanism has one (robots/README.md's table)
    code, out, err = run(capsys, ["solve", ROBOTS / name, *sets(inputs), "--json"])
    assert code == 0, err
    d = json.loads(out)
    certificates(d, name)
    assert d["method"] in ("newton from the file's configuration", "closed form (dyads)", "random starts",
                           "homotopy search", "every joint given", "no loops")
    if d["method"] == "newton from the file's configuration":  # one mode, said not to be every one
        assert len(d["solutions"]) == 1 and not d["complete"] and "--all" in d["modes"]["reason"]


@pytest.mark.parametrize("name", ["gough_stewart_6ups.urdf", "planar_3rpr.urdf", "planar_3rrr.urdf", "tsai_3upu.urdf"])
def test_default_solve_of_a_platform_is_the_drawn_mode_at_once(name, capsys):
    """At the file's own input values the mode nearest the drawn configuration is the drawn one: every file's
    zero configuration closes its loops (robots/README.md), so Newton from it answers every joint 0 -- the
    whole homotopy is not run (it is --all's), and the answer says so."""
    inputs, every = facts(name).inputs, facts(name).every
    assert all(abs(v) < 1e-12 for v in every.values())  # (the file's assembled configuration is its zero one)
    _, out, _ = run(capsys, ["solve", ROBOTS / name, *sets(inputs), "--json"])
    d = json.loads(out)
    assert d["method"] == "newton from the file's configuration" and not d["complete"]
    assert d["modes"]["found"] == 1 and d["modes"]["certificate"] is None and "--all" in d["modes"]["reason"]
    (s,) = d["solutions"]
    assert max(abs(v) for v in s["joints"].values()) < 1e-9 and s["residual"] < 1e-10
    _, out, _ = run(capsys, ["solve", ROBOTS / name, *sets(inputs)])
    assert "1 assembly mode: the one Newton reaches from the file's configuration (no search; --all" in out


def test_default_solve_falls_back_to_the_search_where_newton_fails(monkeypatch):
    """Newton from the file's configuration made to fail (rssr: a polynomial closure, no dyads): solve says
    so in a note and searches every mode, as --all does."""
    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.errors import AssemblyError

    mech = screwkin.load(ROBOTS / "rssr.urdf")
    solver = PositionSolver(mech)
    drawn = solver.set_inputs(solver.reference(), {"crank_joint": 0.3})
    real = mech.closure.solve

    def fails_from_the_drawn(q0, frozen=(), tolerances=None, trace=None):
        if np.array_equal(q0, drawn):
            raise AssemblyError(mech.path, 1e-3, mech.tolerances.max_iterations)
        return real(q0, frozen, tolerances, trace)

    monkeypatch.setattr(mech.closure, "solve", fails_from_the_drawn)
    res = solver.solve({"crank_joint": 0.3}, method="nearest")
    every = PositionSolver(mech).solve({"crank_joint": 0.3})
    assert any("Newton from the file's configuration did not converge" in n and "every mode searched" in n
               for n in res.notes)
    assert res.method != "newton from the file's configuration" and res.method == every.method
    assert len(res.solutions) == len(every.solutions) >= 1


def test_every_joint_given_that_does_not_close_names_the_gap(capsys):
    """planar_3rpr with leg 1 given 0.01 m longer than the file's closed configuration: the platform rides on
    leg 1 (its wrist is in the tree), so the loops through legs 2 and 3 open at their wrists."""
    every = facts("planar_3rpr.urdf").every
    code, _, err = run(capsys, ["singularities", ROBOTS / "planar_3rpr.urdf", *sets({**every, "leg1": every["leg1"]
                                                                                      + 0.01})])
    assert code == 1
    assert "every joint is given" in err and "wrist2" in err and "wrist3" in err and "apart" in err


# ------------------------------------------------------------------ slow: every command, three ways
def commands(name, tmp_path):
    """(command, its arguments after the file) for every command that takes a mechanism file, with the least
    each needs: inputs at the file's values where a command needs them, a load for statics, a target for ik,
    coarse grids for the maps, sweeps and workspaces, files written under tmp_path."""
    f = facts(name)
    inputs, position, length = f.inputs, f.position, f.length
    out = OUTPUT[name]
    first = next(iter(inputs), None)
    step = {n: 0.01 * length if n in f.slides else 0.1 for n in inputs}
    rest = {n: v for n, v in inputs.items() if n != first}
    second = next(iter(rest), None)
    table = [("mobility", []), ("info", []), ("screws", []), ("singularities", []), ("equations", []),
             ("statics", ["--gravity"]), ("export", ["--urdf", tmp_path / "out.urdf", "--mjcf", tmp_path / "out.xml"]),
             ("draw", ["--png", tmp_path / "draw.png"]), ("view", ["--html", tmp_path / "view.html"]),
             ("report", ["--md", tmp_path / "report.md"]), ("scan", ["--output", out, "--samples", "8"]),
             ("ik", ["--output", out, "--position", ",".join(f"{float(x)!r}" for x in position)]),
             ("workspace", ["--output", out, "--resolution", f"{length / 3!r}", "--timeout", "5"])]
    if inputs:
        table.append(("solve", sets(inputs)))
    if first is not None:
        v = inputs[first]
        span = ["--from", f"{v!r}", "--to", f"{v + step[first]!r}"]
        table += [("sweep", ["--input", first, *span, "--steps", "3", *sets(rest)]),
                  ("dynamics", ["--input", first, "--speed", "1", "--steps", "4",
                                *(span if first in f.slides else []), *sets(rest)])]
    if second is not None:
        a, b = inputs[first], inputs[second]
        table.append(("map", ["--x", f"{first}={a!r}:{a + step[first]!r}:3", "--y", f"{second}={b!r}:{b + step[second]!r}:3",
                              *sets({n: v for n, v in rest.items() if n != second})]))
    return table


@pytest.mark.slow
@pytest.mark.parametrize("name", MECHANISMS)
def test_ik_reaches_the_output_where_the_file_puts_it(name, capsys):
    """The output link's position in the file's assembled configuration is reachable: that configuration
    reaches it (a position computed by Pinocchio's forward kinematics, not by the ik under test)."""
    position = facts(name).position
    code, out, err = run(capsys, ["ik", ROBOTS / name, "--output", OUTPUT[name], "--position",
                                  ",".join(f"{float(x)!r}" for x in position), "--json"])
    assert code == 0, err
    d = json.loads(out)
    certificates(d, f"{name} ik")
    assert d["solutions"]


#: Commands whose --set is the configuration analysed (every joint given, --mode 2).
CONFIGURED = {"mobility", "screws", "singularities", "equations", "statics", "export", "draw", "view", "report",
              "solve", "sweep", "dynamics", "map"}
MODED = CONFIGURED - {"solve"} | {"workspace"}
#: The commands run at --mode 2 where the modes come from a search: one per way of taking a mode.
SEARCHED = {"singularities", "sweep", "dynamics", "map", "workspace"}


@pytest.mark.slow
@pytest.mark.parametrize("name", MECHANISMS)
def test_every_command_at_the_file_configuration(name, tmp_path, capsys):
    for command, args in commands(name, tmp_path):
        run(capsys, [command, ROBOTS / name, *args])


@pytest.mark.slow
@pytest.mark.parametrize("name", MECHANISMS)
def test_every_command_with_every_joint_given(name, tmp_path, capsys):
    every = facts(name).every
    for command, args in commands(name, tmp_path):
        if command not in CONFIGURED:
            continue
        # every joint's value in place of the command's own --set values; a swept or mapped input is left out
        moved = {str(b).split("=")[0] for a, b in itertools.pairwise(args) if a in ("--input", "--x", "--y")}
        run(capsys, [command, ROBOTS / name, *own(args), *sets({n: v for n, v in every.items() if n not in moved})])


def own(args):
    """A command's arguments without its --set values (the matrix gives its own)."""
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a == "--set":
            skip = True
            continue
        out.append(a)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", MECHANISMS)
def test_every_command_at_mode_2(name, tmp_path, capsys):
    inputs = facts(name).inputs
    assert inputs  # every bundled mechanism has one (robots/README.md's table)
    code, out, err = run(capsys, ["solve", ROBOTS / name, *sets(inputs), "--all", "--json"])
    assert code == 0, err
    d = json.loads(out)
    certificates(d, f"{name} solve --all")
    if len(d["solutions"]) < 2:
        return  # one mode: --mode 2 is a usage error, checked below on one command
    # where the modes come from the homotopy, each command's --mode 2 runs the whole search again (about
    # 6 s each on 2 cores): one command per way of taking a mode -- the configuration's (singularities;
    # mobility, screws, statics, equations, export, draw, view and report take it the same way, and are
    # run at mode 2 on every mechanism whose modes are in closed form) and the motions' own
    closed = d["modes"]["method"] == "closed form (dyads)"
    for command, args in commands(name, tmp_path):
        if command not in MODED or not (closed or command in SEARCHED):
            continue
        # (sweep, dynamics and map give the inputs they do not move already; workspace takes the file's)
        extra = [] if command in ("sweep", "dynamics", "map", "workspace") else sets(inputs)
        run(capsys, [command, ROBOTS / name, *args, *extra, "--mode", "2"])
