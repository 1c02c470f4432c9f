"""A study's family path (screwkin.analysis.design.family, files.xacro_batch): a xacro family expanded
once for many designs, its four-bars' metrics in closed form over them.  Every row must be what the
design gives evaluated alone and what the single commands print for its --arg (sampled rows, to
1e-9: the lengths come from the file's placements instead of the assembled configuration, the same
to round-off); the same rows whatever the chunks; and where it cannot vouch for a design -- a
structure that depends on a parameter, a file the reader refuses, a closed form that disagrees with
the design's own evaluation -- the design (or the chunk) is evaluated alone, said in the notes."""

import json
import math

import numpy as np
import pytest
from conftest import ROBOTS

from screwkin.analysis.design.study import _GRASHOF, evaluate_design, design_args, metric_columns, study_task
from screwkin.cli import main
from screwkin.files.study import study_spec
from screwkin.files.xacro import expand
from screwkin.files.xacro_batch import Unbatchable, expand_batch
from screwkin.parallel.study import run_study

XACRO = ROBOTS / "fourbar.urdf.xacro"
METRICS = ["mobility", "grashof", "transmission_angle"]
LHS = {"file": str(XACRO), "args": {"ground": 0.1},
       "parameters": {"crank": {"min": 0.01, "max": 0.1}, "coupler": {"min": 0.05, "max": 0.2},
                      "rocker": {"min": 0.03, "max": 0.2}},
       "sampling": "lhs", "designs": 300, "seed": 7, "metrics": METRICS, "input": "crank_joint", "output": "rocker"}


def _close(a, b):
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    return a == b and type(a) is type(b)


@pytest.fixture(scope="module")
def lhs():
    return run_study(LHS, workers=0)


def test_rows_are_the_designs_own(lhs):
    """Every 5th row (60) and every failing one against the design evaluated alone (loaded, assembled,
    each metric computed on its mechanism), column by column."""
    assert lhs.extra["paths"]["family"] >= 290
    task = study_task(study_spec(LHS))
    columns = metric_columns(task.metrics)
    failed = 0
    for r in [r for r in lhs.rows if r["design"] % 5 == 0 or r["error"] is not None]:
        own = evaluate_design(task, r["design"], tuple(r[p] for p in task.parameters))
        for c in ("error", *columns):
            assert _close(r[c], own[c]), (r["design"], c, r[c], own[c])
        failed += r["error"] is not None
    assert failed >= 2  # loops that cannot close: the same sentence, proved from the lengths


def test_rows_are_the_single_commands(lhs, capsys):
    """Sampled rows against `mobility --json` and `sweep --json` given the row's --arg values: the
    mobility columns, the Grashof class, the located transmission range; a failing row's reason is
    the command's error line."""
    task = study_task(study_spec(LHS))
    checked = failed = 0
    for r in lhs.rows[::23]:
        argv = [str(XACRO)] + [x for n, v in design_args(task, tuple(r[p] for p in task.parameters)).items()
                               for x in ("--arg", f"{n}={v}")]
        if r["error"] is not None:
            assert main(["mobility", *argv, "--json"]) == 1
            err = capsys.readouterr().err
            assert r["error"] in err, (r["error"], err)
            failed += 1
            continue
        assert main(["mobility", *argv, "--output", "rocker", "--json"]) == 0
        m = json.loads(capsys.readouterr().out)
        assert (m["mobility"], m["motion_space"], m["overconstraint"], m["idle_dofs"], m["output_motion"]) == \
            (r["mobility"], r["motion_space"], r["overconstraint"], r["idle_dofs"], r["output_motion"])
        assert main(["sweep", *argv, "--input", "crank_joint", "--from", "0", "--to", "10deg", "--steps", "2",
                     "--json"]) == 0
        s = json.loads(capsys.readouterr().out)["linkage"]
        assert next(short for prefix, short in _GRASHOF if s["grashof"].startswith(prefix)) == r["grashof"]
        tr = s["transmission_range"]
        for key, col in (("min", "transmission_angle_min"), ("max", "transmission_angle_max"),
                         ("deviation", "transmission_deviation")):
            assert abs(tr[key] - r[col]) < 1e-9, (r["design"], key)
        assert (tr["turns"], tr["dead_points"]) == (r["input_turns"], r["dead_points"])
        checked += 1
    assert checked >= 8 and failed >= 1


@pytest.mark.slow  # about 2.7 s on 2 shared cores: out of the fast subset
def test_the_same_rows_whatever_the_chunks(lhs):
    """Every design the family path covers reports its closed-form row, whichever chunk it falls in (the
    reference and the spot-checked design too): the table is the same, to the last bit."""
    for chunk in (7, 64):
        assert run_study(dict(LHS, chunk=chunk), workers=0).rows == lhs.rows


def test_the_summary_says_which_path(lhs):
    from screwkin.present.study import study_dict, study_text

    text = study_text(lhs)
    assert "designs on the family path" in text
    assert study_dict(lhs)["paths"] == lhs.extra["paths"]
    spec = dict(LHS, designs=4, metrics=["grashof", "workspace_volume"], workspace={"resolution": 0.05})
    assert "each design evaluated alone" in study_text(run_study(spec, workers=0))


def test_a_refused_file_and_a_failing_expansion_are_evaluated_alone():
    """A negative coupler gives a cylinder of negative length, which the reader refuses; the design is
    evaluated alone and its row has the reader's message, the others stay on the family path."""
    spec = dict(LHS, sampling="grid", designs=None,
                parameters={"crank": {"values": [0.03, 0.04]}, "coupler": {"values": [0.12, -0.12, 0.11]},
                            "rocker": {"values": [0.08, 0.09]}})
    res = run_study(spec, workers=0)
    bad = [r for r in res.rows if r["coupler"] < 0]
    assert bad and all("below 0" in r["error"] or "cannot" in r["error"] for r in bad), [r["error"] for r in bad]
    task = study_task(study_spec(spec))
    for r in bad:
        assert r["error"] == evaluate_design(task, r["design"], (r["crank"], r["coupler"], r["rocker"]))["error"]
    assert res.extra["paths"]["family"] == 8 and res.extra["paths"]["design"] == 4
    assert any("refused" in n for n in res.extra["path_notes"])


def test_a_closed_form_that_disagrees_sends_the_chunk_design_by_design(monkeypatch):
    """Were the closed form wrong (here: the transmission angles moved by 1e-6 rad), the spot check
    catches it and the chunk is evaluated one design at a time, with the note saying where."""
    import screwkin.analysis.design.family as fam

    real = fam.four_bar_transmission

    def off(*a, **k):
        lo, hi, turns, dead = real(*a, **k)
        return lo + 1e-6, hi, turns, dead

    monkeypatch.setattr(fam, "four_bar_transmission", off)
    spec = dict(LHS, designs=20)
    res = run_study(spec, workers=0)
    assert res.extra["paths"] == {"design": 20}
    assert "transmission_angle_min" in res.extra["path_notes"][0] and "one by one" in res.extra["path_notes"][0]
    task = study_task(study_spec(spec))
    r = dict(res.rows[3])
    r.pop("meets_requirements")
    assert r == evaluate_design(task, r["design"], (r["crank"], r["coupler"], r["rocker"]))


# ------------------------------------------------------------------ the expansion for many designs at once
FAMILY_TEXT = """<?xml version="1.0"?>
<robot name="f" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="a" default="0.1"/>
  <xacro:arg name="b" default="0.2"/>
  <xacro:property name="a" value="$(arg a)"/>
  <xacro:property name="h" value="${sqrt(a * a - 0.01) if a > 0.1 else min(a, $(arg b)) ** 2}"/>
  <link name="base"/><link name="l1"/>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="${h} ${a or 3} ${floor(a * 10) / 7}" rpy="0 0 ${atan2(a, $(arg b))}"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _numbers(text):
    """The text with every number written as a float (xacro writes an integer result as 3, the template 3.0)."""
    import re

    return re.sub(r"(?<![\w.])-?[0-9]+(?:\.[0-9]*)?(?:e-?[0-9]+)?(?![\w.])", lambda m: repr(float(m.group(0))), text)


def test_the_template_is_each_designs_expansion(tmp_path):
    """Each design's text from the template is xacro's expansion of the file with that design's
    arguments, number for number: a if c else b and min, floor, atan2, sqrt, ** and or taken
    design by design."""
    path = tmp_path / "f.urdf.xacro"
    path.write_text(FAMILY_TEXT)
    a = np.array([0.05, 0.1, 0.15, 0.3, 0.0])
    b = np.array([0.2, 0.01, 0.3, 0.4, 0.5])
    be = expand_batch(path, FAMILY_TEXT, {}, {"a": a, "b": b})
    assert not be.bad.any()
    for k in range(len(a)):
        mine, xacros = be.design(k), expand(path, FAMILY_TEXT, {"a": repr(float(a[k])), "b": repr(float(b[k]))})
        assert _numbers(mine) == _numbers(xacros), k
        assert mine == xacros or k == 4  # (design 4: a = 0 makes "a or 3" the integer 3)


def test_designs_whose_expansion_fails_are_marked(tmp_path):
    """sqrt of a negative number (a math domain error for that design alone) marks it bad; the others
    expand."""
    text = FAMILY_TEXT.replace("sqrt(a * a - 0.01) if a > 0.1 else", "sqrt(a - 0.1) if a > 0 else")
    path = tmp_path / "f.urdf.xacro"
    path.write_text(text)
    be = expand_batch(path, text, {}, {"a": np.array([0.2, 0.05, 0.3]), "b": np.array([0.1, 0.1, 0.1])})
    assert be.bad.tolist() == [False, True, False]
    with pytest.raises(Exception, match="math domain error"):
        expand(path, text, {"a": "0.05", "b": "0.1"})


@pytest.mark.parametrize("change, why", [
    ('<joint name="j" type="revolute">', "condition on a parameter"),
    ("${h} ${a or 3}", "inside quotes"),
    ('<child link="l1"/>', "reaches"),
])
def test_a_structure_that_depends_on_a_parameter_is_refused(tmp_path, change, why):
    """A xacro:if some designs take and others not, a parameter compared as text, a parameter in a
    name or a limit: Unbatchable (the study then evaluates the designs one by one)."""
    edits = {
        '<joint name="j" type="revolute">': '<xacro:if value="${a > 0.1}"><link name="extra"/></xacro:if>\n'
                                            '  <joint name="j" type="revolute">',
        "${h} ${a or 3}": "${h} ${1 if '$(arg a)' == '0.1' else 2}",
        '<child link="l1"/>': '<child link="l1"/><dynamics damping="${a}"/>',
    }
    text = FAMILY_TEXT.replace(change, edits[change])
    path = tmp_path / "f.urdf.xacro"
    path.write_text(text)
    with pytest.raises(Unbatchable, match=why):
        expand_batch(path, text, {}, {"a": np.array([0.05, 0.2]), "b": np.array([0.2, 0.2])})
    # the same condition met by every design is no obstacle
    if change == '<joint name="j" type="revolute">':
        expand_batch(path, text, {}, {"a": np.array([0.15, 0.2]), "b": np.array([0.2, 0.2])})
        assert not math.isnan(0.0)
