"""The assembly mode is never chosen silently (issue 33 item 2): sweep, dynamics, map, workspace and study take
``--mode K`` with the grammar of the other commands, say "assembly mode K of N (others: ...)" on stderr and put
``mode`` {index, of} in their JSON (a study: the rule once, ``mode`` and ``modes`` in every row)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from conftest import ROBOTS, readme_fourbar
from screwkin.cli import main

# The README's first four-bar, every link along +x and the loop open at B: ground O2-O4 d = 0.10 m, crank O2-A
# a = 0.04, coupler A-B b = 0.12, rocker O4-B c = 0.08.  Written along +x, each joint's value is its link's
# absolute angle for the crank (theta2) and the rocker (theta4).
FOURBAR = readme_fourbar()


def rocker_angles(theta2, a=0.04, b=0.12, c=0.08, d=0.10):
    """Both closures of the four-bar at crank angle theta2, in closed form: A = a (cos, sin) theta2 and O4 = (d, 0);
    B lies on the circle of radius b about A and the circle of radius c about O4.  With e = |O4 - A| and u the
    unit vector from A to O4, B = A + p u +- h n (n = u turned +90 deg), p = (b^2 - c^2 + e^2) / (2 e),
    h = sqrt(b^2 - p^2); theta4 = atan2(By, Bx - d).  Returns (theta4 with +h, theta4 with -h)."""
    A = a * np.array([math.cos(theta2), math.sin(theta2)])
    O4 = np.array([d, 0.0])
    e = np.linalg.norm(O4 - A)
    u = (O4 - A) / e
    n = np.array([-u[1], u[0]])
    p = (b * b - c * c + e * e) / (2 * e)
    h = math.sqrt(b * b - p * p)
    return tuple(math.atan2(B[1], B[0] - d) for B in (A + p * u + h * n, A + p * u - h * n))


def _wrapped(x):
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi


def _run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out, err


def test_sweep_mode_2_follows_the_other_circuit(tmp_path, capsys):
    path = tmp_path / "fourbar.urdf"
    path.write_text(FOURBAR)
    circuits = {}
    for k in (1, 2):
        out, err = _run(["sweep", str(path), "--input", "O2", "--from", "0", "--to", "360deg", "--steps", "36",
                         "--mode", str(k), "--json"], capsys)
        d = json.loads(out)
        assert d["mode"] == {"index": k, "of": 2} and d["completed"]
        names = d["coordinates"]
        theta2 = np.array([row[names.index("O2")] for row in d["joints"]])
        theta4 = np.array([row[names.index("O4")] for row in d["joints"]])
        closed = np.array([rocker_angles(t) for t in theta2])  # (steps, 2): the +h and -h closures
        err_plus = np.abs(_wrapped(theta4 - closed[:, 0])).max()
        err_minus = np.abs(_wrapped(theta4 - closed[:, 1])).max()
        assert min(err_plus, err_minus) < 1e-9, (k, err_plus, err_minus)  # one closure, the whole turn
        circuits[k] = 0 if err_plus < err_minus else 1
    assert circuits[1] != circuits[2]  # mode 2 is the other circuit
    # the text says which mode it follows, in the words of the configuration commands
    _, err = _run(["sweep", str(path), "--input", "O2", "--from", "30deg", "--to", "60deg", "--steps", "2",
                   "--mode", "2"], capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1, or --near)" in err
    _, err = _run(["statics", str(path), "--set", "O2=30deg", "--mode", "2"], capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1, or --near)" in err


def test_a_mode_beyond_the_modes_is_a_usage_error(tmp_path, capsys):
    path = tmp_path / "fourbar.urdf"
    path.write_text(FOURBAR)
    for argv in (["sweep", str(path), "--input", "O2", "--from", "0", "--to", "1"],
                 ["statics", str(path), "--set", "O2=0"]):
        assert main([*argv, "--mode", "3"]) == 2
        assert "--mode 3: these inputs give 2 assembly modes" in capsys.readouterr().err


def test_dynamics_torques_differ_between_modes_and_each_balances_the_energy(capsys):
    """Each mode's input torque is the one that drives its own motion: with no gravity and no load, the input
    power tau omega is the rate of change of the kinetic energy (central differences over the steps), and the
    two circuits need different torques."""
    torques = {}
    for k in (1, 2):
        out, err = _run(["dynamics", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--input", "crank_joint",
                         "--speed", "60rpm", "--steps", "240", "--mode", str(k), "--json"], capsys)
        d = json.loads(out)
        assert d["mode"] == {"index": k, "of": 2}
        tau = np.array(d["efforts"]["crank_joint"])
        T = np.array(d["kinetic_energy"])
        omega = 2 * np.pi
        dt = (2 * np.pi / 240) / omega
        dTdt = (T[2:] - T[:-2]) / (2 * dt)
        assert np.abs(tau[1:-1] * omega - dTdt).max() < 5e-3 * np.abs(dTdt).max()  # O(h^2), h = 1.5 deg
        torques[k] = tau
    assert np.abs(torques[1] - torques[2]).max() > 0.1 * np.abs(torques[1]).max()


@pytest.mark.slow  # about 1.7 s on 2 shared cores: out of the fast subset
def test_map_workspace_and_study_say_the_mode(tmp_path, capsys):
    _, err = _run(["map", str(ROBOTS / "five_bar.urdf"), "--x", "motor1=0:90deg:3", "--y", "motor2=0:90deg:3",
                   "--mode", "2"], capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1)" in err
    out, _ = _run(["map", str(ROBOTS / "five_bar.urdf"), "--x", "motor1=0:90deg:3", "--y", "motor2=0:90deg:3",
                   "--json"], capsys)
    assert json.loads(out)["mode"] == {"index": 1, "of": 2}
    out, err = _run(["workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--point", "--resolution",
                     "20mm", "--json", "--mode", "2"], capsys)
    assert json.loads(out)["mode"] == {"index": 2, "of": 2}
    assert main(["workspace", str(ROBOTS / "arm_6r.urdf"), "--output", "flange", "--mode", "2"]) == 2
    assert "has no loops" in capsys.readouterr().err
    spec = tmp_path / "study.yaml"
    spec.write_text(f"file: {ROBOTS / 'fourbar.urdf.xacro'}\nargs: {{ground: 0.1}}\n"
                    "parameters: {crank: {values: [0.02, 0.03]}, coupler: {values: [0.12]}, rocker: {values: [0.08]}}\n"
                    "metrics: [transmission_angle]\ninput: crank_joint\n")
    # the transmission angle is the same on both circuits (mu from the law of cosines in the diagonal from the
    # crank tip to the output pivot, which the crank angle alone sets): --mode is said not to apply, no mode columns
    out, _ = _run(["study", str(spec), "--workers", "0", "--mode", "2"], capsys)
    assert "--mode 2 does not apply: the transmission angle is the same on every assembly mode" in out
    out, _ = _run(["study", str(spec), "--workers", "0", "--json"], capsys)
    assert all("mode" not in r for r in json.loads(out)["rows"])
    # a metric that follows one mode: the five-bar's conditioning over its tip's workspace (a family of one
    # design: the five-bar written as a xacro file with an argument that changes nothing)
    five = tmp_path / "five_bar.urdf.xacro"
    five.write_text((ROBOTS / "five_bar.urdf").read_text().replace(
        '<robot name="five_bar">',
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="five_bar"><xacro:arg name="unused" default="0"/>', 1))
    spec.write_text(f"file: {five}\nparameters: {{unused: {{values: [0]}}}}\nmetrics: [conditioning]\noutput: tip\n"
                    "point: true\nworkspace: {resolution: 20mm}\n")
    out, _ = _run(["study", str(spec), "--workers", "0", "--json", "--mode", "2"], capsys)
    d = json.loads(out)
    assert d["mode"] == 2 and "each design follows mode 2 of its actuated joints" in d["mode_rule"]
    assert [(r["mode"], r["modes"]) for r in d["rows"]] == [(2, 2)]


@pytest.mark.parametrize("command", ["sweep", "dynamics", "map", "workspace", "study", "statics", "draw", "export",
                                     "screws", "singularities", "equations", "view", "report"])
def test_every_motion_and_configuration_command_takes_mode_k(command, capsys):
    """One grammar: --mode K, a count from 1 (--mode 0 refused by the same bound everywhere)."""
    assert main([command, "x", "--mode", "0"]) == 2
    assert "--mode: must be between 1 and 1,000, got 0" in capsys.readouterr().err


def test_draw_animate_and_view_sweep_follow_the_mode_asked(tmp_path, capsys):
    """draw --animate and view --sweep took --mode and followed the drawn mode without a word."""
    path = tmp_path / "fourbar.urdf"
    path.write_text(FOURBAR)
    out, err = _run(["draw", str(path), "--animate", str(tmp_path / "a.gif"), "--from", "0", "--to", "30deg",
                     "--steps", "2", "--mode", "2"], capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1, or --near)" in err
    _, err = _run(["view", str(path), "--sweep", "O2=0:30deg:3", "--html", str(tmp_path / "v.html"), "--mode", "2"],
                  capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1, or --near)" in err


def test_report_analyses_the_mode_asked(tmp_path, capsys):
    """report took --mode and analysed solution 1 whatever K was: its document now says which it analyses and
    its skeleton's rocker is the one of that mode (the data's rocker angle is solve's for that mode)."""
    path = str(ROBOTS / "fourbar_crank_rocker.urdf")
    md = tmp_path / "r.md"
    _, err = _run(["report", path, "--set", "crank_joint=30deg", "--mode", "2", "--md", str(md), "--no-view",
                   "--steps", "8"], capsys)
    assert "note: assembly mode 2 of 2 (others: --mode 1, or --near)" in err
    assert "solution 2 is the configuration this report analyses" in md.read_text()
    data = json.loads((tmp_path / "r_files" / "data.json").read_text())
    assert data["mode"] == {"index": 2, "of": 2}
    solved, _ = _run(["solve", path, "--set", "crank_joint=30deg", "--json"], capsys)
    rockers = [s["joints"]["rocker_joint"] for s in json.loads(solved)["solutions"]]
    sweep = data["sweep"]  # the report's sweep starts at the configuration it analyses
    start = sweep["joints"][0][sweep["coordinates"].index("rocker_joint")]
    assert abs(_wrapped(start - rockers[1])) < 1e-7 and abs(_wrapped(start - rockers[0])) > 0.1
