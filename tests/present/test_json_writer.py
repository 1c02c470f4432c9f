"""One JSON writer (issue 37 item 5): every ``--json``, report's data.json and the Python API's
``to_dict`` are written by present/jsonout.py, by one rule that README states -- an infinite number
is the string "inf" or "-inf" (JSON has no Infinity), a value that does not exist (NaN inside
screwkin, None) is null.  CSV spells a missing value its own way, an empty cell.

The infinite and missing values come from the analyses themselves, each checked against what makes
it so: a stretched 2R arm's force ellipsoid (closed form), a prismatic joint's screw (a pure
translation), a map cell no continuation reaches (a linkage that cannot close there), a study's
design that fails."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import ARM, ROBOTS

from screwkin.cli import main

ROOT = Path(__file__).resolve().parents[2]
SLIDER = str(ROBOTS / "slider_crank_offset.urdf")


def _strict(text: str):
    """The JSON of ``text``, refusing the NaN and Infinity tokens Python's json would write and read."""
    return json.loads(text, parse_constant=lambda token: pytest.fail(f"{token} in the JSON"))


def _json(argv, capsys):
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return _strict(out)


def _leaves(obj):
    if isinstance(obj, dict):
        for v in obj.values():
            yield from _leaves(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _leaves(v)
    else:
        yield obj


def test_the_rule_in_values_arrays_and_numpy_scalars():
    from screwkin.present.jsonout import json_of, to_jsonable
    obj = {"x": np.array([np.inf, -np.inf, np.nan, 1.0]), "y": [float("nan")], "z": np.float32("inf"), "w": None}
    assert to_jsonable(obj) == {"x": ["inf", "-inf", None, 1.0], "y": [None], "z": "inf", "w": None}
    assert _strict(json_of(obj)) == to_jsonable(obj)


def test_infinity_is_inf_at_a_singular_configuration(tmp_path, capsys):
    """A 2R arm stretched (elbow 0): its point Jacobian (x, y, z rows) has rank 1, one singular value
    s = sqrt((l1 + l2)^2 + l2^2) / L (the columns ((l1 + l2) n, l2 n), n the unit normal to the arm),
    so the force ellipsoid's semi-axes are 1/s and two infinite ones; the singular twist -- the motion
    the hand cannot make, along the arm -- is a pure translation, of infinite pitch."""
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    d = _json(["singularities", str(path), "--set", "shoulder=0.3,elbow=0", "--output", "hand", "--point",
               "--ellipsoids", "--length", "0.5"], capsys)
    l1, l2, L = 0.4, 0.25, 0.5
    s = math.hypot(l1 + l2, l2) / L
    force = d["ellipsoids"]["force_semi_axes"]
    assert force.count("inf") == 2
    assert [f for f in force if f != "inf"] == pytest.approx([1 / s], rel=1e-9)
    assert d["singular_twists"] and all(t["screw"]["pitch"] == "inf" for t in d["singular_twists"])


def test_a_prismatic_joints_screw_has_pitch_inf(capsys):
    """A slider's joint screw is a pure translation (w = 0): pitch w.v / |w|^2 is infinite."""
    d = _json(["screws", SLIDER], capsys)
    pitches = {j["joint"]: j["xi0"]["pitch"] for ch in d["chains"] for j in ch["joints"]}
    assert pitches["slider_joint"] == "inf"
    assert all(isinstance(p, float) for n, p in pitches.items() if n != "slider_joint")


def test_a_value_that_does_not_exist_is_null(wide_five_bar, capsys):
    """The five-bar with its motors 0.3 m apart cannot close where its elbows are more than 0.3 m apart
    (conftest.wide_five_bar): the map's cells there hold no measure (NaN inside), null in the JSON,
    exactly the cells ``reached`` is false."""
    d = _json(["map", str(wide_five_bar), "--x", "motor1=-180deg:180deg:7", "--y", "motor2=-180deg:180deg:7"],
              capsys)
    logs, reached = d["log10_sigma_min"], d["reached"]
    missing = [(j, i) for j in range(7) for i in range(7) if logs[j][i] is None]
    assert missing and missing == [(j, i) for j in range(7) for i in range(7) if not reached[j][i]]


def test_a_failed_design_is_null_in_json_and_empty_in_csv(tmp_path, capsys):
    """A crank of 0 divides by zero in robots/fourbar.urdf.xacro: that design fails, its metrics do not
    exist -- null in --json, empty cells in the table."""
    spec = tmp_path / "study.yaml"
    spec.write_text(f"file: {ROBOTS / 'fourbar.urdf.xacro'}\nargs: {{ground: 0.1, coupler: 0.12, rocker: 0.08}}\n"
                    "parameters:\n  crank: {values: [0.0, 0.04]}\nmetrics: [mobility, grashof]\ninput: crank_joint\n")
    d = _json(["study", str(spec), "--workers", "0"], capsys)
    failed, ok = d["rows"]
    assert failed["error"] and all(failed[c] is None for c in d["columns"])
    assert ok["error"] is None and ok["mobility"] == 1
    table = tmp_path / "rows.csv"
    assert main(["study", str(spec), "--workers", "0", "-o", str(table)]) == 0
    capsys.readouterr()
    cells = next(csv.DictReader(io.StringIO(table.read_text())))
    assert cells["error"] and all(v == "" for k, v in cells.items() if k not in ("design", "crank", "error"))


def test_csv_writes_no_value_as_an_empty_cell_and_infinity_as_inf():
    from screwkin.present.tables import csv_text
    assert csv_text(["a", "b", "c"], [[float("nan"), float("inf"), 1.5], [None, np.float64("nan"), -np.inf]]) == \
        "a,b,c\n,inf,1.5\n,,-inf\n"


# Every command that prints JSON, on a small case: the text is strict JSON (no NaN or Infinity token).
COMMANDS = {
    "mobility": ["mobility", SLIDER],
    "info": ["info", SLIDER],
    "solve": ["solve", SLIDER, "--set", "crank_joint=30deg", "--rate", "60rpm"],
    "sweep": ["sweep", SLIDER, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "4"],
    "statics": ["statics", SLIDER, "--set", "crank_joint=30deg", "--output", "slider", "--wrench", "1,0,0,0,0,0"],
    "dynamics": ["dynamics", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--input", "crank_joint", "--speed", "60rpm",
                 "--steps", "4"],
    "equations": ["equations", SLIDER, "--set", "crank_joint=30deg"],
    "scan": ["scan", str(ROBOTS / "arm_6r.urdf"), "--samples", "50", "--output", "flange"],
    "ik": ["ik", str(ROBOTS / "arm_6r.urdf"), "--output", "flange", "--position", "0.3,0.1,0.4"],
    "workspace": ["workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--point", "--resolution", "20mm"],
    "grasp": ["grasp", str(ROOT / "examples" / "grasp_box.yaml")],
    "synthesize": ["synthesize", "chains", "--links", "4", "--dof", "1"],
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_writes_strict_json(name, capsys):
    d = _json(COMMANDS[name], capsys)
    assert all(not isinstance(v, float) or math.isfinite(v) for v in _leaves(d))


def test_commands_writing_files_say_so_in_strict_json(tmp_path, capsys):
    """draw, export and report (its data.json too: sorted keys, one space of indent, by the writer)."""
    _json(["draw", SLIDER, "--png", str(tmp_path / "d.png")], capsys)
    _json(["export", SLIDER, "--mjcf", str(tmp_path / "x.xml")], capsys)
    d = _json(["report", SLIDER, "--set", "crank_joint=30deg", "--md", str(tmp_path / "r.md"), "--no-view"], capsys)
    assert d["written"] == [str(tmp_path / "r.md")]
    text = (tmp_path / "r_files" / "data.json").read_text()
    data = _strict(text)
    assert text == json.dumps(data, indent=1, sort_keys=True) + "\n"


def test_readme_states_the_rule():
    readme = " ".join((ROOT / "docs" / "reference" / "options.md").read_text().split())  # was the README's
    assert 'an infinite number as the string `"inf"` or `"-inf"`' in readme
    assert "a value that does not exist" in readme and "`null`" in readme
