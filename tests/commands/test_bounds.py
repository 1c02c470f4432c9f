"""Issue 22, 'hangs' and 'silent acceptances': every count a person types has a bound, an empty
value is not the default, every output is checked before the work starts, an output link must
exist, lengths have a kind and a sane range.  Each case must answer in one line, exit 2, at once
(``no_hang`` guards against the work starting; the bounds are in commands/_options.BOUNDS)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROBOTS, no_hang
from screwkin.cli import main
from screwkin.commands._options import BOUNDS

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")
FIVEBAR = str(ROBOTS / "five_bar.urdf")
ARM = str(ROBOTS / "arm_6r.urdf")
SWEEP = ["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "4"]


def run(argv, capsys):
    """main(argv) in process: (exit code, stderr); argparse's own exits included."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    return code, err


def refused(argv, capsys, *words, seconds=20):
    with no_hang(seconds):
        code, err = run(argv, capsys)
    assert code == 2, (argv, code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("screwkin: error:"), err
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


HUGE = [
    (["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "100000000"], "100,000"),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--starts", "1000000"], "1,000"),
    (["ik", ARM, "--output", "flange", "--pose", "0.3 0 0.3 0 0 0", "--starts", "1000000"], "1,000"),
    (["draw", FOURBAR, "--png", "x.png", "--singular", "--steps", "100000000"], "20,000"),
    (["report", FOURBAR, "--md", "x.md", "--steps", "100000000"], "20,000"),
    (["scan", ARM, "--output", "flange", "--samples", "100000000000"], "10,000,000"),
    (["scan", ARM, "--output", "flange", "--threads", "1000000"], "256"),
    (["scan", ARM, "--output", "flange", "--seed", "-1"], "4,294,967,295"),
    (["map", FIVEBAR, "--x", "motor1=0:1:1000000", "--y", "motor2=0:1:10"], "2,000"),
    (["map", FIVEBAR, "--x", "motor1=0:1:1000", "--y", "motor2=0:1:1000"], "100,000"),
    (["view", FOURBAR, "--sweep", "crank_joint=0:1:100000000", "--html", "x.html"], "2,000"),
    (["synthesize", "path", "--points", "0,0; 1,0; 1,1; 0,1; 0.5,0.5", "--starts", "100000000"], "1,000"),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--start", "rocker=1", "--iterations", "100000000"], "1,000"),
]


@pytest.mark.parametrize("argv,bound", HUGE, ids=[" ".join(a[:1] + a[-2:]) for a, _ in HUGE])
def test_huge_counts_are_refused_with_their_bound(argv, bound, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    refused(argv, capsys, bound)


def test_bounds_are_whole_numbers():
    for what, (lo, hi) in BOUNDS.items():
        assert isinstance(lo, int) and isinstance(hi, int) and 0 <= lo < hi, what


@pytest.mark.parametrize("argv,option", [
    (["solve", FOURBAR, "--set", "crank_joint=1", "--length="], "--length"),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--length", "  "], "--length"),
    (["solve", FOURBAR, "--set="], "--set"),
    (SWEEP + ["--rate="], "--rate"),
    (["workspace", FIVEBAR, "--output", "tip", "--resolution", ""], "--resolution"),
    (["mobility", ""], "FILE"),
    (["mobility", FIVEBAR, "--output="], "--output"),
])
def test_empty_values_are_errors_not_defaults(argv, option, capsys):
    refused(argv, capsys, option, "empty value")


@pytest.mark.parametrize("extra", [["--csv"], ["--plot"]])
def test_sweep_outputs_checked_before_the_work(extra, capsys, tmp_path):
    missing = tmp_path / "missing" / "out.file"
    refused(SWEEP + extra + [missing], capsys, extra[0], "does not exist")
    refused(SWEEP + extra + [tmp_path], capsys, extra[0], "it is a folder")
    assert not (tmp_path / "missing").exists()


@pytest.mark.parametrize("argv,option", [
    (["draw", FOURBAR, "--svg"], "--svg"),
    (["draw", FOURBAR, "--png"], "--png"),
    (["report", FOURBAR, "--html"], "--html"),
    (["report", FOURBAR, "--md"], "--md"),
    (["map", FIVEBAR, "--x", "motor1=0:1:3", "--y", "motor2=0:1:3", "--csv"], "--csv"),
    (["scan", ARM, "--output", "flange", "--samples", "10", "--csv"], "--csv"),
    (["view", FOURBAR, "--html"], "--html"),
    (["workspace", FIVEBAR, "--output", "tip", "--csv"], "--csv"),
])
def test_every_output_is_checked_before_the_work(argv, option, capsys, tmp_path):
    refused(argv + [tmp_path / "no" / "such" / "file"], capsys, option, "does not exist")
    refused(argv + [tmp_path], capsys, option, "it is a folder")


def test_a_folder_output_is_checked_before_the_work(capsys, tmp_path):
    """synthesize chains writes into a folder: an existing one is used, a file or a missing parent refused."""
    argv = ["synthesize", "chains", "--links", "4", "--dof", "1", "-o"]
    refused(argv + [tmp_path / "no" / "such" / "folder"], capsys, "--output", "does not exist")
    (tmp_path / "f").write_text("")
    refused(argv + [tmp_path / "f"], capsys, "--output", "it is a file")


@pytest.mark.parametrize("argv", [
    SWEEP + ["--output", "no_such_link"],
    ["draw", FOURBAR, "--svg", "x.svg", "--output", "no_such_link"],
    ["solve", FOURBAR, "--set", "crank_joint=1", "--output", "no_such_link"],
])
def test_an_output_link_must_exist(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    line = refused(argv, capsys, "no link named 'no_such_link'")
    for link in ("ground", "crank", "coupler", "rocker"):  # the links that exist are listed
        assert link in line
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize("value,words", [
    ("5e-324", ["1e-09 m"]),        # a subnormal: the measures divided by it overflowed (SVD did not converge)
    ("0", ["1e-09 m"]),
    ("-1", ["1e-09 m"]),
    ("1e9", ["10000 m"]),
    ("90deg", ["unit of angle", "takes a length"]),
    ("1turn", ["unit of angle"]),
])
def test_lengths_have_a_kind_and_a_range(value, words, capsys):
    refused(["solve", FOURBAR, "--set", "crank_joint=1", "--length", value], capsys, "--length", *words)


def test_a_length_in_range_with_a_unit_is_taken_in_si(capsys):
    import json

    code = main(["solve", FOURBAR, "--set", "crank_joint=1", "--length", "90mm", "--json"])
    assert code == 0
    assert json.loads(capsys.readouterr().out)["characteristic_length"] == pytest.approx(0.09, abs=1e-15)


def test_counts_at_their_bounds_are_accepted(capsys, tmp_path):
    # the bound itself is a valid value: a two-point grid per axis (the smallest) maps
    code = main(["map", FIVEBAR, "--x", "motor1=0:1:2", "--y", "motor2=0:1:2", "--csv", str(tmp_path / "m.csv")])
    assert code == 0
    rows = (tmp_path / "m.csv").read_text().strip().splitlines()
    assert len(rows) == 1 + 4  # the header and 2 x 2 configurations


def test_negative_values_with_units_are_values_not_options(capsys):
    import json

    import numpy as np

    code = main(["sweep", FOURBAR, "--input", "crank_joint", "--from", "-90deg", "--to", "-1e-3", "--steps", "2",
                 "--json"])
    assert code == 0
    d = json.loads(capsys.readouterr().out)
    assert d["values"][0] == pytest.approx(-np.pi / 2, abs=1e-12) and d["values"][-1] == pytest.approx(-1e-3)


def test_version_and_bare_command_list(capsys):
    from importlib import metadata

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"screwkin {metadata.version('screwkin')}"
    assert main([]) == 0
    out = capsys.readouterr().out
    for command in ("mobility", "solve", "sweep", "singularities", "draw", "report", "workspace", "study"):
        assert f"\n    {command} " in out or f"\n    {command}\n" in out, command


# ---- joint values take their kind from the joint (issue 24 item 5, the part the bounds need)

SLIDER = str(ROBOTS / "slider_crank_offset.urdf")


@pytest.mark.parametrize("argv,words", [
    (["solve", FOURBAR, "--set", "crank_joint=30mm"], ["--set", "angle joint", "mm is a unit of length"]),
    (["solve", SLIDER, "--set", "crank_joint=1,slider_joint=30deg"], ["length joint", "deg is a unit of angle"]),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--rate", "crank_joint=2mm"], ["--rate", "angle joint"]),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--near", "rocker_joint=1in"], ["--near", "angle joint"]),
    (SWEEP[:7] + ["30mm"], ["--to", "angle joint"]),
    (["solve", FOURBAR, "--set-angle", "crank=3mm"], ["--set-angle", "unit of length"]),
])
def test_a_unit_of_the_wrong_kind_is_refused(argv, words, capsys):
    refused(argv, capsys, *words)


def test_a_bare_angle_beyond_a_turn_warns_and_is_radians(capsys):
    import json

    assert main(["solve", FOURBAR, "--set", "crank_joint=30", "--json"]) == 0
    captured = capsys.readouterr()
    assert "30 rad = 1718.87 deg" in captured.err and "write 30deg" in captured.err
    crank = json.loads(captured.out)["solutions"][0]["joints"]["crank_joint"]
    assert crank == pytest.approx(30.0, abs=1e-12)  # 30 rad, reported as typed
    assert main(["solve", FOURBAR, "--set", "crank_joint=6", "--json"]) == 0
    assert "warning" not in capsys.readouterr().err  # within a turn: no warning


@pytest.mark.parametrize("text,si", [
    ("60rpm", 2 * 3.141592653589793), ("1 rev/s", 2 * 3.141592653589793), ("90deg/s", 3.141592653589793 / 2),
    ("3rad/s", 3.0), ("20mm/s", 0.02), ("2m/s^2", 2.0), ("500mm/s2", 0.5), ("180deg/s^2", 3.141592653589793),
    ("2kN", 2000.0), ("3N*m", 3.0), ("3Nm", 3.0), ("1500Nmm", 1.5), ("5nm", 5e-9), ("2KN", 2000.0),
])
def test_units_of_rates_accelerations_forces_and_moments(text, si):
    from screwkin.units import parse_value

    assert parse_value(text) == pytest.approx(si, rel=1e-15)


def test_rates_take_rate_units_and_wrenches_force_and_moment_units(capsys):
    import json

    assert main(["solve", FOURBAR, "--set", "crank_joint=30deg", "--rate", "crank_joint=60rpm", "--json"]) == 0
    sol = json.loads(capsys.readouterr().out)["solutions"][0]
    assert sol["rates"]["crank_joint"] == pytest.approx(2 * np.pi, abs=1e-12)
    assert sol["links"]["crank"]["omega"] == pytest.approx(2 * np.pi, abs=1e-12)
    refused(["solve", FOURBAR, "--set", "crank_joint=10rpm"], capsys, "unit of angular rate", "takes angle")
    refused(["solve", FOURBAR, "--set", "crank_joint=1", "--accel", "crank_joint=2rpm"], capsys, "angular rate")
    refused(["solve", FOURBAR, "--set", "crank_joint=1", "--rate", "crank_joint=2mm/s"], capsys, "linear rate")
    refused(["statics", FOURBAR, "--output", "rocker", "--wrench", "0 0 0 0 0 2N"], capsys, "takes a moment")
    refused(["statics", FOURBAR, "--output", "rocker", "--wrench", "1Nm 0 0 0 0 2"], capsys, "takes a force")
    refused(SWEEP + ["--rate", "2mm/s"], capsys, "--rate", "linear rate")
    refused(["ik", ARM, "--output", "flange", "--pose", "0.3 0 0.3 0 0 5mm"], capsys, "takes an angle")


def test_a_unit_that_differs_by_case_only_is_not_guessed():
    from screwkin.errors import UsageError
    from screwkin.units import parse_value

    with pytest.raises(UsageError, match="ambiguous: write nm or Nm"):
        parse_value("5NM")
