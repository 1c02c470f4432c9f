"""Hostile and huge inputs, round 2 (issue 22): work that doubles without a macro call, names
with dots, misspelt sidecar keys, XML comments holding ``--``.  Every case is either refused with
one line naming the file (exit 1) or gives the numbers the plain file gives.

Hostile inputs, round 3 (issue 33): names two XML readers read differently, physically impossible
inertias, unbounded coefficients and points, options ignored without a word, units of the wrong kind,
outputs that overwrite the model or each other.  Each is refused with one line (exit 1 for a file,
2 for a command line) or answered with a line saying what was done."""

from __future__ import annotations

import json
import os

import pytest
from conftest import ROBOTS, check_urdf, no_hang, screwkin_cli

from screwkin.cli import main
from screwkin.errors import MechanismFileError
from screwkin.files import xacro as xacro_module
from screwkin.files.description import LIMITS
from screwkin.files.xacro import XacroInternalError, expand
from screwkin.files.xacro_eval import MAX_STRING

HEAD = '<?xml version="1.0"?>\n<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


def doubling_blocks(levels: int) -> str:
    """b0 one link; bK two copies of bK-1; then b{levels} inserted: 2**levels links."""
    lines = [HEAD, '<xacro:property name="b0"><link name="l"/></xacro:property>\n']
    for k in range(1, levels + 1):
        lines.append(f'<xacro:property name="b{k}"><xacro:insert_block name="b{k - 1}"/>'
                     f'<xacro:insert_block name="b{k - 1}"/></xacro:property>\n')
    lines.append(f'<xacro:insert_block name="b{levels}"/>\n</robot>\n')
    return "".join(lines)


def doubling_text(levels: int) -> str:
    """s0 eight characters; sK is "${sK-1}${sK-1}": 8 * 2**levels characters."""
    lines = [HEAD, '<xacro:property name="s0" value="abcdefgh"/>\n']
    for k in range(1, levels + 1):
        lines.append(f'<xacro:property name="s{k}" value="${{s{k - 1}}}${{s{k - 1}}}"/>\n')
    lines.append(f'<link name="${{s{levels}}}"/>\n</robot>\n')
    return "".join(lines)


def test_a_small_doubling_of_blocks_expands(tmp_path):
    # 3 levels: 2**3 = 8 copies of the one link (the size check counts, it does not forbid)
    path = tmp_path / "d3.urdf.xacro"
    text = doubling_blocks(3)
    assert expand(path, text).count('<link name="l"/>') == 8


def test_insert_block_twice_still_expands(tmp_path):
    text = (HEAD + '<xacro:property name="part"><link name="a"/><link name="b"/></xacro:property>\n'
            '<xacro:macro name="two" params="*body"><xacro:insert_block name="body"/>'
            '<xacro:insert_block name="body"/></xacro:macro>\n'
            '<xacro:insert_block name="part"/><xacro:insert_block name="part"/>\n'
            '<xacro:two><link name="c"/></xacro:two>\n</robot>\n')
    out = expand(tmp_path / "twice.urdf.xacro", text)
    assert out.count('<link name="a"/>') == 2 and out.count('<link name="b"/>') == 2
    assert out.count('<link name="c"/>') == 2


@pytest.mark.parametrize("levels", [16, 30])
def test_doubling_blocks_are_refused_at_once(tmp_path, levels):
    # 2**16 links alone are 65,536 copies plus the blocks' own elements: past the 200,000-element bound.
    # Before the bound this ran for minutes (16 levels) and forever (30). The guard is against
    # that blow-up, not a speed measurement.
    path = tmp_path / f"d{levels}.urdf.xacro"
    text = doubling_blocks(levels)
    assert len(text) < 4000  # a small file
    with no_hang(5), pytest.raises(MechanismFileError) as info:
        expand(path, text)
    message = str(info.value)
    assert str(path) in message and f"{LIMITS.elements}" in message and "insert_block" in message
    assert "\n" not in message


def test_doubling_blocks_exit_1_on_the_command_line(tmp_path, capsys):
    path = tmp_path / "d30.urdf.xacro"
    path.write_text(doubling_blocks(30))
    with no_hang(5):
        code = main(["mobility", str(path)])
    err = capsys.readouterr().err.strip()
    assert code == 1 and len(err.splitlines()) == 1
    assert err.startswith("screwkin: error: ") and str(path) in err and "more than 200000 elements" in err


def test_small_doubling_text_expands(tmp_path):
    out = expand(tmp_path / "t3.urdf.xacro", doubling_text(3))
    assert '<link name="' + "abcdefgh" * 8 + '"/>' in out


@pytest.mark.parametrize("levels", [12, 40])
def test_doubling_text_is_refused(tmp_path, levels):
    # 8 * 2**11 = 16,384 > 10,000 characters: refused at the eleventh level, long before 8 * 2**40
    path = tmp_path / "t.urdf.xacro"
    with no_hang(5), pytest.raises(MechanismFileError) as info:
        expand(path, doubling_text(levels))
    message = str(info.value)
    assert str(path) in message and f"more than {MAX_STRING} characters" in message and "\n" not in message


def test_a_bug_inside_xacro_is_an_internal_error_not_the_files(tmp_path, monkeypatch, capsys):
    import xacro

    def broken(*args, **kwargs):
        raise KeyError("boom")

    monkeypatch.setattr(xacro, "grab_property", broken)
    path = tmp_path / "ok.urdf.xacro"
    path.write_text(HEAD + '<xacro:property name="a" value="1"/><link name="l"/>\n</robot>\n')
    with pytest.raises(XacroInternalError, match="internal error in the xacro expansion"):
        expand(path, path.read_text())
    assert main(["mobility", str(path)]) == 3
    err = capsys.readouterr().err
    assert "internal error" in err and "xacro expansion" in err and "KeyError" in err


def test_the_files_mistake_inside_xacro_stays_exit_1(tmp_path, capsys):
    path = tmp_path / "bad.urdf.xacro"
    path.write_text(HEAD + '<xacro:insert_block name="nowhere"/><link name="l"/>\n</robot>\n')
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err
    assert "Undefined block" in err and str(path) in err and "internal error" not in err


def test_the_interpreter_lives_in_its_own_module():
    # the split of files/xacro.py keeps the public names where callers import them
    from screwkin.files import xacro_eval

    assert xacro_module.evaluate is xacro_eval.evaluate
    assert xacro_module.check_expression is xacro_eval.check_expression


# ------------------------------------------------------------------ names with dots
DOTTED = {  # file -> (its actuated joint, an input value, {loop joint: a name with dots})
    "rack_pinion.urdf": ("pinion_joint", 0.3, {"mesh": "mesh.2"}),
    # "a" and "a.x": the virtual joints of "a" (a.a1, a.a2) must not take those of "a.x" (a.x.a1, a.x.a2)
    "gear_train_idler.urdf": ("input_joint", 0.3, {"mesh1": "a", "mesh2": "a.x"}),
    "lead_screw_jack.urdf": ("screw_joint", 2.0, {"thread": "thread.x.turn"}),
    "friction_wheels.urdf": ("wheel2_joint", 0.4, {"wheels": "w.a1"}),
}
SCALARS = ("loops", "kutzbach", "gruebler", "coordinates", "constraint_rows", "constraint_rank", "mobility",
           "overconstraint", "effective_mobility", "classification", "redundant_constraints")


def cli_json(capsys, argv):
    import json

    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


@pytest.mark.parametrize("name", sorted(DOTTED))
def test_loop_joint_names_with_dots(tmp_path, capsys, name):
    from conftest import ROBOTS

    joint, value, renames = DOTTED[name]
    text = (ROBOTS / name).read_text()
    for old, new in renames.items():
        assert f'<loop_joint name="{old}"' in text
        text = text.replace(f'<loop_joint name="{old}"', f'<loop_joint name="{new}"')
    dotted = tmp_path / name
    dotted.write_text(text)
    plain = cli_json(capsys, ["mobility", str(ROBOTS / name), "--json"])
    renamed = cli_json(capsys, ["mobility", str(dotted), "--json"])
    assert {k: renamed[k] for k in SCALARS} == {k: plain[k] for k in SCALARS}
    assert plain["mobility"] == 1
    argv = ["solve", "--set", f"{joint}={value}", "--json"]
    plain = cli_json(capsys, [argv[0], str(ROBOTS / name), *argv[1:]])["solutions"]
    renamed = cli_json(capsys, [argv[0], str(dotted), *argv[1:]])["solutions"]
    assert len(plain) == len(renamed) >= 1
    for a, b in zip(plain, renamed, strict=True):
        expected = {}
        for k, v in a["joints"].items():  # the virtual joints carry the loop joint's new name
            loop, dot, role = k.partition(".")
            expected[f"{renames[loop]}.{role}" if dot and loop in renames else renames.get(k, k)] = v
        assert b["joints"].keys() == expected.keys()
        for k, v in expected.items():
            assert b["joints"][k] == pytest.approx(v, abs=1e-9)


def test_a_joint_named_like_a_virtual_joint_is_refused(tmp_path, capsys):
    from conftest import ROBOTS

    text = (ROBOTS / "rack_pinion.urdf").read_text().replace('<joint name="rack_joint"', '<joint name="mesh.x"')
    text = text.replace('<joint name="rack_joint"/>', '<joint name="mesh.x"/>')
    path = tmp_path / "clash.urdf"
    path.write_text(text)
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err
    assert str(path) in err and "'mesh.x'" in err and "rename" in err and "internal error" not in err


# ------------------------------------------------------------------ misspelt sidecar keys
FIVE_BAR = "corpus/example-parallel-robots/5bar_linkage"


def five_bar_with(tmp_path, yaml_text):
    import shutil

    from conftest import ROBOTS

    folder = tmp_path / "fivebar"
    folder.mkdir()
    shutil.copy(ROBOTS / FIVE_BAR / "robot.urdf", folder / "robot.urdf")
    (folder / "robot.yaml").write_text(yaml_text)
    return folder / "robot.urdf"


def test_the_five_bar_sidecar_gives_mobility_3(tmp_path, capsys):
    # the collection's 5bar_linkage (tests/files/test_corpus.py): planar, Gruebler 3(6-1-6)+6 = 3 with its
    # loop; without the loop the open tree has its 6 joints free (M = 6)
    path = five_bar_with(tmp_path, "closed_loop: [['closedloop1_A', 'closedloop1_B']]\nname_mot: ['mot1', 'mot2']\n")
    result = cli_json(capsys, ["mobility", str(path), "--json"])
    assert result["loops"] == 1 and result["mobility"] == 3


def test_a_misspelt_sidecar_key_warns_with_the_right_one(tmp_path, capsys):
    path = five_bar_with(tmp_path, "closed_loops: [['closedloop1_A', 'closedloop1_B']]\nname_mot: ['mot1', 'mot2']\n")
    assert main(["mobility", str(path), "--json"]) == 0
    err = capsys.readouterr().err
    warning = [line for line in err.splitlines() if "closed_loops" in line]
    assert len(warning) == 1 and warning[0].startswith("warning: ")
    assert str(path.with_suffix(".yaml")) in warning[0] and "did you mean 'closed_loop'?" in warning[0]


def test_a_misspelt_key_is_named_first_when_the_sidecar_fails(tmp_path, capsys):
    path = five_bar_with(tmp_path, "closed_loops: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\n")
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"screwkin: error: {path.with_suffix('.yaml')}: unknown key 'closed_loops' (did you mean "
                          "'closed_loop'?)")
    assert "0 pairs but type has 1" in err and len(err.splitlines()) == 1


def test_an_unknown_key_far_from_any_lists_the_known_ones(tmp_path, capsys):
    path = five_bar_with(tmp_path, "closed_loop: [['closedloop1_A', 'closedloop1_B']]\nzzz: 1\n")
    assert main(["mobility", str(path)]) == 0
    err = capsys.readouterr().err
    assert "unknown key 'zzz'" in err and "known keys: closed_loop, type, name_mot, joint_name, joint_type" in err


# ------------------------------------------------------------------ XML comments holding "--"
GOOD_URDF = ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="base"/>\n  <link name="arm"/>\n'
             '  {comment}\n  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
             '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>\n')


@pytest.mark.parametrize("comment, line, opened", [
    ("<!-- the arm -- 40 mm -->", 5, 5),
    ("<!-- an arrow --->", 5, 5),
    ("<!--\n  several lines\n  a--b\n  -->", 7, 5),
])
def test_double_hyphen_in_a_comment_is_named(tmp_path, capsys, comment, line, opened):
    path = tmp_path / "r.urdf"
    path.write_text(GOOD_URDF.format(comment=comment))
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (f"screwkin: error: {path}: malformed XML: a comment cannot contain '--' (line {line}, in the "
                   f"comment opened at line {opened}): write it without the double hyphen")


def test_double_hyphen_outside_comments_is_fine(tmp_path, capsys):
    # "--" in text and attributes is well-formed XML; a closed comment before another error is not blamed
    path = tmp_path / "r.urdf"
    path.write_text(GOOD_URDF.format(comment="<!-- fine --><!----><a_text>-- not a comment</a_text>"))
    assert main(["mobility", str(path)]) == 0
    capsys.readouterr()
    path.write_text(GOOD_URDF.format(comment="<!-- fine --><a></b>"))
    assert main(["mobility", str(path)]) == 1
    err = capsys.readouterr().err
    assert "mismatched tag" in err and "comment" not in err


def test_double_hyphen_in_a_xacro_comment(tmp_path, capsys):
    path = tmp_path / "r.urdf.xacro"
    path.write_text(HEAD + '<!-- width -- in metres -->\n<link name="l"/>\n</robot>\n')
    assert main(["mobility", str(path)]) == 1
    assert "a comment cannot contain '--' (line 3" in capsys.readouterr().err


@pytest.mark.parametrize("body, missing", [
    ('<xacro:attribute name="a"/>', "xacro:attribute: missing attribute 'value'"),
    ("<xacro:macro/>", "xacro:macro: missing attribute 'name'"),
    ("<xacro:unless/>", "xacro:unless: missing attribute 'value'"),
    ("<xacro:call/>", "xacro:call: missing attribute 'macro'"),
    ("<xacro:insert_block/>", "xacro:insert_block: missing attribute 'name'"),
])
def test_a_missing_xacro_attribute_is_the_files_mistake(tmp_path, capsys, body, missing):
    # xacro raises RuntimeError (not XacroException) for these: still the file's mistake, exit 1
    path = tmp_path / "m.urdf.xacro"
    path.write_text(HEAD + body + '<link name="l"/>\n</robot>\n')
    assert main(["mobility", str(path)]) == 1
    assert capsys.readouterr().err.strip() == f"screwkin: error: {path}: xacro: {missing}"


# ---------------------------------------------------------------- folded in from test_hostile_round3.py
FOURBAR = ROBOTS / "fourbar_crank_rocker.urdf"


def _one_line_error(err: str) -> str:
    """The one error line (the `note:` lines a command says as it goes -- the assembly mode it chose --
    may come before it, as tests/commands/test_fuzz.py's contract allows)."""
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("note: ")]
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
    assert "child(2):  rock\ter" in check_urdf(path)


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


# ------------------------------------------------------------------ inertias no body has
def _with_coupler_inertia(tmp_path, ixx, iyy, izz, ixy=0.0):
    text = FOURBAR.read_text()
    start = text.index('<link name="coupler"')
    a = text.index("<inertia ", start)
    b = text.index("/>", a) + 2
    path = tmp_path / "m.urdf"
    path.write_text(text[:a] + f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="{ixy}" ixz="0" iyz="0"/>'
                    + text[b:])
    return path


@pytest.mark.parametrize("inertia, says", [((0.0002, 0.0002, -1.0), "a negative principal moment"),
                                           ((0.0002, 0.0002, 0.0005), "A + B >= C (0.0004 < 0.0005)"),
                                           ((0.0002, 0.0002, 0.0002, 0.0003), "a negative principal moment")])
def test_dynamics_refuses_an_inertia_no_body_has_and_loading_warns(tmp_path, capsys, inertia, says):
    """izz="-1" gave a kinetic energy of -29.9 J.  Refused by dynamics (exit 1, naming the link), warned
    of by every command (the file still loads for kinematics: real robots' files break it too)."""
    path = _with_coupler_inertia(tmp_path, *inertia)
    code = main(["dynamics", str(path), "--input", "crank_joint", "--speed", "100rpm", "--steps", "4"])
    line = _one_line_error(capsys.readouterr().err.split("\n", 1)[1])
    assert code == 1 and "link 'coupler' moves and has" in line and says in line, line
    assert main(["info", str(path)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"warning: {path}: link 'coupler' has") and says in err[0]


def test_the_check_agrees_with_mujoco():
    """files/inertia.inertia_problem against MuJoCo's compiler (an independent implementation: it refuses
    "inertia must have positive eigenvalues" and "A + B >= C"), on random tensors R diag(A, B, C) R^T
    whose principal moments are each way of the boundaries by at least 1 %."""
    mujoco = pytest.importorskip("mujoco")
    import numpy as np

    from screwkin.files.inertia import inertia_problem

    rng = np.random.default_rng(33)
    agree, seen = 0, set()
    while agree < 60:
        moments = rng.uniform(-0.5, 2.0, 3)
        a, b, c = np.sort(moments)
        if min(abs(a), abs(a + b - c)) < 0.01 * c:
            continue
        q = rng.normal(size=4)
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
        R = R.reshape(3, 3)
        T = R @ np.diag(moments) @ R.T
        full = " ".join(f"{x:.17g}" for x in (T[0, 0], T[1, 1], T[2, 2], T[0, 1], T[0, 2], T[1, 2]))
        xml = (f'<mujoco><worldbody><body><joint type="hinge"/><inertial pos="0 0 0" mass="1" '
               f'fullinertia="{full}"/></body></worldbody></mujoco>')
        try:
            mujoco.MjModel.from_xml_string(xml)
            refused = False
        except ValueError:
            refused = True
        ours = inertia_problem(1.0, T[0, 0], T[1, 1], T[2, 2], T[0, 1], T[0, 2], T[1, 2])
        assert refused == (ours is not None), (moments, ours)
        agree += 1
        seen.add(ours and ("negative" if "negative" in ours else "A + B"))
    assert seen == {None, "negative", "A + B"}, seen


def test_rounding_in_the_last_digits_is_taken_as_written():
    """A + B = C to 7 digits (a flat plate written by a CAD export), and zeros written as 1e-35."""
    from screwkin.files.inertia import inertia_problem

    assert inertia_problem(1.0, 0.1234567, 0.2345678, 0.3580246) is None  # A + B = 0.3580245
    assert inertia_problem(1.0, -2.4e-35, 0.0, 2.4e-35) is None
    assert inertia_problem(-1.0, 1, 1, 1) == "a negative mass (-1 kg)"


# ------------------------------------------------------------------ bounded numbers
@pytest.mark.parametrize("cs", ["1e-320", "0", "0.00009", "0.51", "nan", "inf"])
def test_the_coefficient_of_speed_fluctuation_is_bounded(capsys, cs):
    """--cs 1e-320 gave an infinite flywheel (I = dE / (Cs omega^2)): 0.0001 to 0.5, said."""
    line = _usage(capsys, ["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "100rpm", "--steps", "4",
                           "--cs", cs])
    assert "--cs must lie between 0.0001 and 0.5" in line


def test_the_bounds_of_the_coefficient_are_taken(capsys):
    """At both ends the flywheel is dE / (Cs omega^2), omega = 100 rpm = 10.472 rad/s: the two figures are in
    the ratio of the ends (5,000)."""
    inertias = []
    for cs in ("0.0001", "0.5"):
        assert main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "100rpm", "--steps", "8",
                     "--cs", cs, "--json"]) == 0
        fly = json.loads(capsys.readouterr().out)["flywheel"]
        omega = 100 * 2 * 3.141592653589793 / 60
        assert fly["inertia"] == pytest.approx(fly["energy_fluctuation"] / (float(cs) * omega**2), rel=1e-12)
        inertias.append(fly["inertia"])
    assert inertias[0] / inertias[1] == pytest.approx(5000, rel=1e-12)


@pytest.mark.parametrize("command", [["solve", "--set", "crank_joint=0.5"], ["draw", "--png", "{o}.png"],
                                     ["dynamics", "--input", "crank_joint", "--speed", "1rpm", "--steps", "3"],
                                     ["view", "--html", "{o}.html"]])
@pytest.mark.parametrize("point, says", [("P=coupler:1e308,0,0", "is beyond the 10000 m a length may have"),
                                         ("P=coupler:0,-10001,0", "is beyond the 10000 m a length may have"),
                                         ("P=nolink:0,0,0", "no link named 'nolink'"),
                                         ("P=coupler:nan,0,0", "'nan' is not a number"),
                                         ("P=coupler:0,0", None)])
def test_every_point_is_checked_by_one_parser(tmp_path, capsys, command, point, says):
    """--point 1e308 m gave inf and NaN answers (exit 0), and draw did not look at --point at all (an
    unknown link, NaN).  One parser (commands/_output_frame.named_points, called for every command) bounds the
    coordinates as a file's positions are (10 km)."""
    argv = [a.replace("{o}", str(tmp_path / "out")) for a in command]
    code = main([argv[0], str(FOURBAR), *argv[1:], "--point", point])
    err = capsys.readouterr().err
    if says is None and argv[0] == "view":  # a checked point, which a static view does not show: said
        assert code == 2 and "--point goes with --interactive" in _one_line_error(err)
        return
    if says is None:
        assert code == 0, err
        return
    line = _one_line_error(err)
    assert code == 2 and says in line, line


def test_draw_says_a_point_it_does_not_draw(tmp_path, capsys):
    assert main(["draw", str(FOURBAR), "--png", str(tmp_path / "d.png"), "--point", "P=coupler:60mm,0,0"]) == 0
    assert "note: --point 'P': a point is drawn as its path, with --trace NAME" in capsys.readouterr().err
    assert main(["draw", str(FOURBAR), "--png", str(tmp_path / "d.png"), "--point", "P=coupler:60mm,0,0",
                 "--trace", "P"]) == 0
    assert "note: --point" not in capsys.readouterr().err


# ------------------------------------------------------------------ options that were ignored without a word
@pytest.mark.parametrize("command", [["draw", "--png", "{o}.png"], ["export", "--mjcf", "{o}.xml"],
                                     ["view", "--html", "{o}.html"], ["solve"],
                                     ["sweep", "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3"],
                                     ["dynamics", "--input", "crank_joint", "--speed", "1rpm", "--steps", "3"]])
def test_near_names_joints_that_exist_for_every_command(tmp_path, capsys, command):
    """--near no_such=1 was refused by solve and ignored by draw, export and view: one check
    (commands/_configuration.near_values)."""
    argv = [a.replace("{o}", str(tmp_path / "out")) for a in command]
    given = [] if "--input" in argv else ["--set", "crank_joint=0.5"]  # (a moved input takes no --set value)
    line = _usage(capsys, [argv[0], FOURBAR, *argv[1:], *given, "--near", "no_such=1"])
    assert "no moving joint named 'no_such'" in line, line
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("command", [["draw", "--png", "{o}.png"], ["export", "--urdf", "{o}.urdf"]])
def test_near_without_set_is_refused_as_mode_is(tmp_path, capsys, command):
    """Without --set the file's own configuration is analysed: --near chose nothing, and said nothing."""
    argv = [a.replace("{o}", str(tmp_path / "out")) for a in command]
    line = _usage(capsys, [argv[0], FOURBAR, *argv[1:], "--near", "crank_joint=1"])
    assert "--near: the file's own configuration is one mode; give --set values" in line


@pytest.mark.parametrize("command, says", [
    (["sweep", "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3"], "sweep moves it"),
    (["dynamics", "--input", "crank_joint", "--speed", "10rpm", "--steps", "3"], "dynamics drives it"),
    (["draw", "--animate", "{o}.gif", "--from", "0", "--to", "1", "--steps", "3"], "--animate moves it"),
    (["draw", "--animate", "{o}.gif", "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "3"],
     "--animate moves it"),
    (["view", "--html", "{o}.html", "--sweep", "crank_joint=0:30deg:5"], "view --sweep moves it"),
])
def test_a_set_value_of_the_input_moved_is_a_usage_error(tmp_path, capsys, command, says):
    """sweep --input X --set X=..., dynamics and draw --animate dropped the value without a word (draw
    --animate even took the first --set joint as the input to move); view --sweep too."""
    argv = [a.replace("{o}", str(tmp_path / "out")) for a in command]
    line = _usage(capsys, [argv[0], FOURBAR, *argv[1:], "--set", "crank_joint=0.3"])
    assert "--set 'crank_joint' (or --set-angle of its link): " + says in line, line
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("command", [["view", "--html", "{o}.html", "--sweep", "crank_joint=0:30mm:5"],
                                     ["map", "--x", "crank_joint=0:1cm:3", "--y", "rocker_joint=0:1:3"]])
def test_a_range_in_a_unit_of_the_wrong_kind_is_refused(tmp_path, capsys, command):
    """view --sweep crank=0:30mm:5 labelled an angle in mm: a range's ends are the joint's values, checked
    as --set checks them."""
    argv = [a.replace("{o}", str(tmp_path / "out")) for a in command]
    line = _usage(capsys, [argv[0], FOURBAR, *argv[1:]])
    assert "'crank_joint' is an angle joint" in line and "is a unit of length" in line, line


@pytest.mark.parametrize("argv, says", [
    (["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "1e308rpm"], "beyond the 100000 rad/s an angular rate"),
    (["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "10rpm", "--gravity", "1e300,0,0"],
     "beyond the 1e+07 m/s^2 a linear acceleration"),
    (["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "10rpm", "--load", "coupler:1e308,0,0,0,0,0"],
     "beyond the 1e+10 N a force"),
    (["statics", FOURBAR, "--set", "crank_joint=1", "--output", "rocker", "--wrench", "0 0 0 0 0 1e11"],
     "beyond the 1e+10 N m a moment"),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--rate", "crank_joint=1e300"], "an angular rate"),
    (["solve", FOURBAR, "--set", "crank_joint=1", "--accel", "crank_joint=1e9"], "an angular acceleration"),
    (["solve", ROBOTS / "slider_crank_offset.urdf", "--set", "slider_joint=1e308"], "beyond the 10000 m a length"),
])
def test_typed_magnitudes_are_bounded_by_their_kind(capsys, argv, says):
    """--speed 1e308rpm gave NaN efforts, --gravity 1e300 and --load 1e308 inf reactions, and statics
    --wrench 1e308 an effort of 0, all with exit 0: a value beyond any machine is a usage error naming
    its kind's bound (units.MAGNITUDES)."""
    assert says in _usage(capsys, argv)


def test_the_length_bound_is_the_files_one():
    from screwkin.files.description import LIMITS
    from screwkin.units import MAGNITUDES

    assert MAGNITUDES["length"] == LIMITS.length


def test_a_speed_whose_square_underflows_has_no_flywheel(capsys):
    """--speed 1e-300rpm: omega^2 is 0 in double precision, and dE / (Cs omega^2) was a ZeroDivisionError."""
    assert main(["dynamics", str(FOURBAR), "--input", "crank_joint", "--speed", "1e-300rpm", "--steps", "8"]) == 0
    assert "flywheel: not given (at zero speed" in capsys.readouterr().out


def test_synthesize_draw_is_an_output_checked_like_the_others(tmp_path, capsys):
    """synthesize -o F --draw F wrote the drawing over the URDF (exit 0): --draw was not among the outputs
    the up-front check knows."""
    line = _usage(capsys, ["synthesize", "path", "--points", "0,0; 0.05,0.02; 0.1,0.05; 0.12,0.1; 0.08,0.12",
                           "--starts", "2", "-o", tmp_path / "d.png", "--draw", tmp_path / "d.png"])
    assert "--draw" in line and "the same file as --output" in line and not (tmp_path / "d.png").exists()


@pytest.mark.parametrize("argv", [
    ["view", FOURBAR, "--html", "{o}.html", "--sweep", "crank_joint=0:1e5rad:2000"],
    ["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "1rpm", "--from", "0", "--to", "1e5rad", "--steps", "10000"],
    ["sweep", FOURBAR, "--input", "crank_joint", "--from", "-1e5rad", "--to", "1e5rad", "--steps", "3"],
])
def test_a_range_the_tracker_would_take_hours_over_is_refused_at_once(tmp_path, capsys, argv):
    """view --sweep crank=0:1e5rad:2000 and dynamics --to 1e5rad ran past 5 minutes (found by the directed
    probes): a grid coarser than the tracker's longest step (0.1 rad) makes it walk the whole range,
    here a million steps.  More than 100,000 (sweep.MAX_TRACKED) is a usage error naming the count:
    1e5 rad / 0.1 rad = 1,000,000 steps."""
    with no_hang(30):
        line = _usage(capsys, [a.replace("{o}", str(tmp_path / "o")) if isinstance(a, str) else a for a in argv])
    assert "continuation steps" in line and "more than the 100,000 a sweep tracks" in line
    assert ("1,000,000" in line) or ("2,000,000" in line)


@pytest.mark.parametrize("argv, says", [
    (["workspace", ROBOTS / "five_bar.urdf", "--output", "tip", "--bounds", "0:30deg,-1:1"], "--bounds takes a length"),
    (["synthesize", "path", "--points", "0,0; 0.05,0.02; 0.1,0.05; 0.12,0.1; 0.08,0.12", "--tolerance", "1e308",
      "-o", "x.urdf"], "beyond the 10000 m a length"),
])
def test_lengths_of_other_options_take_their_kind(tmp_path, monkeypatch, capsys, argv, says):
    """workspace --bounds 0:30deg and synthesize --tolerance 1e308 were taken as they came (exit 0)."""
    monkeypatch.chdir(tmp_path)
    assert says in _usage(capsys, argv)
