"""Bad input: one line naming the file and the problem, exit 1 (file) or 2 (usage), no traceback."""

import subprocess
import sys

import pytest

from conftest import fourbar
from screwkin.cli import main

GOOD = fourbar()


def run(capsys, argv):
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.err


def write(tmp_path, text, name="m.urdf"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def check(capsys, argv, code, *words, path=None):
    got, err = run(capsys, argv)
    assert got == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    if path:
        assert path in lines[0]
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


def test_the_base_file_is_fine(tmp_path, capsys):
    assert main(["mobility", write(tmp_path, GOOD)]) == 0


FILE_CASES = {
    "empty": ("", "empty"),
    "blank": ("   \n\t\n", "empty"),
    "malformed": ("<robot name='x'><link name='a'></robot>", "malformed XML"),
    "not_urdf": ("<model/>", "not a URDF"),
    "loop_missing_link": (GOOD.replace('<link2 link="rocker"', '<link2 link="nowhere"'), "'nowhere'"),
    "unknown_joint_type": (GOOD.replace('name="coupler_joint" type="revolute"', 'name="coupler_joint" type="hinge"'),
                           "unknown type 'hinge'"),
    "unknown_loop_type": (GOOD.replace('<loop_joint name="C" type="revolute">', '<loop_joint name="C" type="ball">'),
                          "unknown type 'ball'"),
    "zero_axis": (GOOD.replace('<axis xyz="0 0 1"/><limit', '<axis xyz="0 0 0"/><limit', 1), "zero axis"),
    "zero_loop_axis": (GOOD.replace('<axis xyz="0 0 1"/></loop_joint>', '<axis xyz="0 0 0"/></loop_joint>'), "zero axis"),
    "nan": (GOOD.replace('<origin xyz="0.04 0 0"', '<origin xyz="nan 0 0"'), "NaN or infinite"),
    "inf": (GOOD.replace('<origin xyz="0.1 0 0"', '<origin xyz="0.1 inf 0"'), "NaN or infinite"),
    "two_parents": (GOOD.replace('<parent link="ground"/><child link="rocker"/>', '<parent link="crank"/><child link="coupler"/>'),
                    "two parents"),
    "two_roots": (GOOD.replace("</robot>", '<link name="floating_piece"/></robot>'), "do not form one tree"),
    "universal_without_axis2": (GOOD.replace('type="revolute"><link1', 'type="universal"><link1'), "axis2"),
    "not_words": (GOOD.replace('<origin xyz="0.04 0 0"', '<origin xyz="0.04 zero 0"'), "not 3 numbers"),
}


@pytest.mark.parametrize("case", sorted(FILE_CASES))
def test_invalid_files(tmp_path, capsys, case):
    text, word = FILE_CASES[case]
    path = write(tmp_path, text)
    check(capsys, ["mobility", path], 1, word, path=path)


def test_missing_file(tmp_path, capsys):
    path = str(tmp_path / "absent.urdf")
    check(capsys, ["mobility", path], 1, "no such file", path=path)


def test_directory(tmp_path, capsys):
    check(capsys, ["info", str(tmp_path)], 1, "directory", path=str(tmp_path))


def test_yaml_naming_a_missing_frame(tmp_path, capsys):
    path = write(tmp_path, GOOD.replace('<loop_joint name="C"', '<!-- no loop joint --><x name="C"').replace(
        "</loop_joint>", "</x>"))
    y = tmp_path / "m.yaml"
    y.write_text("closed_loop: [['coupler', 'ghost_frame']]\ntype: ['3d']\nname_mot: ['crank_joint']\n")
    check(capsys, ["mobility", path], 1, "'ghost_frame'", path=str(y))


def test_yaml_naming_a_missing_motor(tmp_path, capsys):
    path = write(tmp_path, GOOD)
    y = write(tmp_path, "name_mot: ['no_motor']\n", "other.yaml")
    check(capsys, ["mobility", path, "--yaml", y], 1, "'no_motor'", path=y)


def test_malformed_yaml(tmp_path, capsys):
    path = write(tmp_path, GOOD)
    (tmp_path / "m.yaml").write_text("closed_loop: [[unclosed\n")
    check(capsys, ["mobility", path], 1, "malformed YAML")


def test_unassemblable_mechanism_says_how_close_it_got(tmp_path, capsys):
    # the coupler-rocker loop joint placed 0.2 m away on the rocker: no configuration closes it
    path = write(tmp_path, GOOD.replace('<link2 link="rocker" xyz="0.08 0 0"/>', '<link2 link="rocker" xyz="0.4 0 0"/>'))
    line = check(capsys, ["mobility", path], 1, "cannot assemble", "residual", path=path)
    assert "got down to" in line


@pytest.mark.parametrize("argv, word", [
    (["--actuated", "no_such_joint"], "'no_such_joint'"),
    (["--output", "no_such_link"], "'no_such_link'"),
])
def test_usage_errors_naming_missing_things(tmp_path, capsys, argv, word):
    path = write(tmp_path, GOOD)
    check(capsys, ["mobility", path, *argv], 2, word, path=path)


def test_argparse_usage_errors_exit_2(tmp_path, capsys):
    for argv in (["frobnicate", "x"], ["mobility"]):
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    path = write(tmp_path, GOOD)
    check(capsys, ["solve", path, "--set", "crank_joint=12parsecs"], 2, "unknown unit")


def test_external_entity_is_never_resolved(tmp_path, capsys):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET-CONTENT")
    text = (f'<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY x SYSTEM "file://{secret}">]>\n'
            '<robot name="r"><link name="a"><visual><geometry><mesh filename="&x;"/></geometry></visual></link></robot>')
    path = write(tmp_path, text)
    got, err = run(capsys, ["info", path])
    assert got == 1 and "not allowed" in err and "TOP-SECRET" not in err


def test_entity_expansion_bomb_is_refused(tmp_path, capsys):
    lol = '<!ENTITY lol "lol">' + "".join(
        f'<!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">' for i in range(1, 10))
    text = f'<?xml version="1.0"?>\n<!DOCTYPE robot [{lol}]>\n<robot name="&lol9;"><link name="a"/></robot>'
    path = write(tmp_path, text)
    check(capsys, ["info", path], 1, "entity", path=path)


def test_warnings_do_not_fail(tmp_path, capsys):
    mesh = '<visual><geometry><mesh filename="package://nowhere/m.stl"/></geometry></visual>'
    text = GOOD.replace('<link name="ground">', f'<link name="ground">{mesh}')
    text = text.replace('<link2 link="rocker"', '<link1 link="rocker"')
    code, err = run(capsys, ["mobility", write(tmp_path, text)])
    assert code == 0
    assert "mesh" in err and "second is read as <link2>" in err


def test_no_traceback_reaches_the_terminal_and_debug_shows_one(tmp_path):
    path = write(tmp_path, "<robot")
    p = subprocess.run([sys.executable, "-m", "screwkin", "mobility", path], capture_output=True, text=True)
    assert p.returncode == 1 and "Traceback" not in p.stderr and len(p.stderr.strip().splitlines()) == 1
    p = subprocess.run([sys.executable, "-m", "screwkin", "mobility", path, "--debug"], capture_output=True, text=True)
    assert p.returncode != 0 and "Traceback" in p.stderr


ONE_JOINT = ('<robot name="one"><link name="a"/><link name="b"><inertial><mass value="1"/>'
             '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
             '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.1"/>'
             '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')


@pytest.mark.parametrize("argv", [["mobility", "--output", "b"], ["screws", "--output", "b"],
                                  ["singularities", "--output", "b"], ["scan", "--output", "b", "--samples", "5"],
                                  ["solve", "--set", "j=0.1", "--output", "b", "--rate", "j=1"],
                                  ["ik", "--output", "b", "--pose", "0 0 0.1 0 0 0.2"]])
def test_one_joint_arm(tmp_path, capsys, argv):
    """Pinocchio returns the frame Jacobian of a one-coordinate model as a 6-vector:
    every command still works on a single revolute joint."""
    path = write(tmp_path, ONE_JOINT)
    code, err = run(capsys, [argv[0], path, *argv[1:]])
    assert code == 0, err


def test_internal_error_is_one_line_not_a_traceback(tmp_path, capsys, monkeypatch):
    import screwkin.mechanism

    def broken(self, output=None):
        raise ValueError("shapes do not match")

    monkeypatch.setattr(screwkin.mechanism.Mechanism, "mobility", broken)
    path = write(tmp_path, GOOD)
    check(capsys, ["mobility", path], 3, "internal error", "ValueError", "--debug", path=path)
    # --debug (after or before the command): the traceback, then the same line, and still exit 3
    for argv in (["mobility", path, "--debug"], ["--debug", "mobility", path]):
        code, err = run(capsys, argv)
        assert code == 3 and "Traceback" in err and "shapes do not match" in err
        assert err.strip().splitlines()[-1].startswith("screwkin: internal error")


def test_urdf_parser_complaints_become_the_one_line(tmp_path, capfd):
    """urdfdom (inside Pinocchio) prints its reasons on the process's stderr; they are kept
    out of the output and the first one names the problem in screwkin's line."""
    path = write(tmp_path, '<robot name="s"><link name="a"/><link name="b"/><joint name="j" type="prismatic">'
                           '<parent link="a"/><child link="b"/><axis xyz="1 0 0"/></joint></robot>')
    assert main(["mobility", path]) == 1
    err = capfd.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert path in lines[0] and "PRISMATIC without limits" in lines[0]
