"""Hostile and huge inputs, round 2 (issue 22): work that doubles without a macro call, names
with dots, misspelt sidecar keys, XML comments holding ``--``.  Every case is either refused with
one line naming the file (exit 1) or gives the numbers the plain file gives."""

import pytest
from conftest import no_hang

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
    # the collection's 5bar_linkage (tests/test_corpus.py): planar, Gruebler 3(6-1-6)+6 = 3 with its
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
