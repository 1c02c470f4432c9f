"""Hostile inputs, round 3 (issue 33): names two XML readers read differently, physically impossible
inertias, unbounded coefficients and points, options ignored without a word, units of the wrong kind,
outputs that overwrite the model or each other.  Each is refused with one line (exit 1 for a file,
2 for a command line) or answered with a line saying what was done."""

from __future__ import annotations

import json
import os
import shutil
import subprocess

import pytest

from conftest import ROBOTS, screwkin_cli
from screwkin.cli import main

FOURBAR = ROBOTS / "fourbar_crank_rocker.urdf"


def _one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("screwkin: error: ") and "Traceback" not in err, err
    return lines[0]


# ------------------------------------------------------------------ names the readers disagree on
@pytest.mark.parametrize("char", ["\t", "\n", "\r"])
@pytest.mark.parametrize("what", ["coupler_joint", "rocker"])
def test_a_literal_tab_or_line_break_in_a_name_is_refused_naming_it(tmp_path, capsys, char, what):
    """Every command exited 3 (TypeError on None): screwkin's reader normalises the character to a space
    (XML 1.0 section 3.3.3), Pinocchio's urdfdom keeps it, and the two models disagreed.  Refused, exit 1,
    naming the file and the name as urdfdom reads it (a carriage return becomes a newline there)."""
    path = tmp_path / "m.urdf"
    path.write_text(FOURBAR.read_text().replace(f'"{what}"', f'"{what[:4]}{char}{what[4:]}"'), newline="")
    kind = "joint" if what.endswith("joint") else "link"
    shown = what[:4] + ("\\t" if char == "\t" else "\\n") + what[4:]
    for command in (["info"], ["mobility"], ["solve", "--set", "crank_joint=10deg"]):
        code = main([command[0], str(path), *command[1:]])
        err = capsys.readouterr().err
        line = _one_line_error(err)
        assert code == 1 and str(path) in line and f"{kind} '{shown}'" in line, line


def test_what_the_readers_do_with_such_a_name(tmp_path):
    """Why refused, not read one way: ROS's own tools disagree.  urdfdom's check_urdf prints the link
    with its tab; xacro (minidom, the XML standard) gives the joint a space."""
    import xacro

    path = tmp_path / "m.urdf"
    path.write_text(FOURBAR.read_text().replace('"rocker"', '"rock\ter"').replace('"coupler_joint"',
                                                                                  '"coupler\tjoint"'))
    names = [j.getAttribute("name") for j in xacro.process_file(str(path)).getElementsByTagName("joint")]
    assert "coupler joint" in names and "coupler\tjoint" not in names
    tool = shutil.which("check_urdf")
    if tool is None:
        pytest.skip("urdfdom's check_urdf is not installed")
    done = subprocess.run([tool, str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "child(2):  rock\ter" in done.stdout


def test_a_character_reference_is_read_alike_and_kept(tmp_path):
    """&#9; is not normalised by the standard: every reader keeps the tab, and the name is accepted."""
    path = tmp_path / "m.urdf"
    path.write_text(FOURBAR.read_text().replace('"coupler_joint"', '"coupler&#9;joint"'))
    done = screwkin_cli("info", str(path), "--json")
    assert done.returncode == 0, done.stderr
    assert "coupler\tjoint" in [j["name"] for j in json.loads(done.stdout)["joints"]]


# ------------------------------------------------------------------ outputs that overwrite what is read
@pytest.fixture
def model(tmp_path):
    path = tmp_path / "x.urdf"
    path.write_text(FOURBAR.read_text())
    return path


def _usage(capsys, argv) -> str:
    code = main([str(a) for a in argv])
    line = _one_line_error(capsys.readouterr().err)
    assert code == 2, line
    return line


def test_an_output_that_is_the_model_or_another_output_is_refused_before_the_work(model, tmp_path, capsys):
    """export --mjcf o.xml --urdf o.xml wrote one over the other; sweep --csv robots/x.urdf overwrote the
    model it had read.  Compared as resolved paths: through '..', a symbolic link, a hard link."""
    sweep = ["sweep", model, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3"]
    before = model.read_bytes()
    line = _usage(capsys, ["export", model, "--mjcf", tmp_path / "o.xml", "--urdf", tmp_path / "o.xml"])
    assert "--urdf" in line and "the same file as --mjcf" in line and not (tmp_path / "o.xml").exists()
    assert "is the file read" in _usage(capsys, [*sweep, "--csv", model])
    assert "is the file read" in _usage(capsys, [*sweep, "--csv", tmp_path / ".." / tmp_path.name / "x.urdf"])
    (tmp_path / "link.csv").symlink_to(model)
    assert "is the file read" in _usage(capsys, [*sweep, "--csv", tmp_path / "link.csv"])
    os.link(model, tmp_path / "hard.csv")
    assert "is the file read" in _usage(capsys, [*sweep, "--plot", tmp_path / "hard.csv"])
    assert "the same file as --csv" in _usage(capsys, [*sweep, "--csv", tmp_path / "a.csv", "--plot",
                                                      tmp_path / "a.csv"])
    assert model.read_bytes() == before


def test_the_sidecar_found_beside_the_model_is_not_overwritten_either(model, capsys):
    side = model.with_suffix(".yaml")
    side.write_text("actuated: [crank_joint]\n")
    line = _usage(capsys, ["draw", model, "--png", side])
    assert "the sidecar read beside it" in line and side.read_text() == "actuated: [crank_joint]\n"


def test_devices_take_several_outputs(model, capsys):
    assert main(["export", str(model), "--mjcf", "/dev/null", "--urdf", "/dev/null"]) == 0
