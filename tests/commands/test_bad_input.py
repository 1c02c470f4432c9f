"""Bad input: one line naming the file and the problem, exit 1 (file) or 2 (usage), no traceback."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ROBOTS, fourbar, no_hang
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
    # the rocker side 0.4 m against 0.26 m for the other three: the lengths prove it, no search is made
    assert "rocker 0.4 m > " in line and "cannot get below 0.14 (proved from the lengths: no assembly search)" in line


@pytest.mark.parametrize("argv, word", [
    (["--actuated", "no_such_joint"], "'no_such_joint'"),
    (["--output", "no_such_link"], "'no_such_link'"),
])
def test_usage_errors_naming_missing_things(tmp_path, capsys, argv, word):
    path = write(tmp_path, GOOD)
    check(capsys, ["mobility", path, *argv], 2, word, path=path)


def test_argparse_usage_errors_exit_2(tmp_path, capsys):
    for argv in (["frobnicate", "x"], ["mobility"]):
        assert main(argv) == 2  # main(argv) -> int: argparse's exit is its return value
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
    import screwkin.commands.mobility

    def broken(*args, **kwargs):
        raise ValueError("shapes do not match")

    monkeypatch.setattr(screwkin.commands.mobility, "analyze_mobility", broken)
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


# ---------------------------------------------------------------------------------------------
# Regressions of the fuzzing campaign (3,815 runs on 1,682 mutated files): one test per signature.

CORPUS_5BAR = Path(__file__).resolve().parents[2] / "robots" / "corpus" / "example-parallel-robots" / "5bar_linkage"
FOURBAR = Path(__file__).resolve().parents[2] / "robots" / "fourbar_crank_rocker.urdf"


def five_bar(tmp_path, sidecar: str | bytes):
    """The corpus 5-bar (closed by its YAML sidecar) with the sidecar replaced."""
    path = tmp_path / "robot.urdf"
    path.write_bytes((CORPUS_5BAR / "robot.urdf").read_bytes())
    y = tmp_path / "robot.yaml"
    y.write_bytes(sidecar if isinstance(sidecar, bytes) else sidecar.encode())
    return str(path), str(y)


LOOP = "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\n"


@pytest.mark.parametrize("sidecar, word", [
    (LOOP + "name_mot: [['mot1'], ['mot2']]\n", "name_mot entry 1 is ['mot1'], not a string"),
    (LOOP + "name_mot: {mot1: 1}\n", "name_mot must be a list"),
    (LOOP + "name_mot: [yes]\n", "name_mot entry 1 is True"),
    ("closed_loop: [[['a'], 'b']]\ntype: ['6d']\n", "not a pair of frame names"),
    ("closed_loop: {a: b}\n", "closed_loop must be a list"),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: [['6d']]\n", "closed_loop type ['6d'] is unknown"),
    (LOOP + "joint_name: [[1]]\njoint_type: ['SPHERICAL']\n", "joint_name entry 1"),
    (LOOP + "joint_name: ['mot1']\njoint_type: ['UJOINT_XX']\n", "joint_type 'UJOINT_XX' is unknown"),
    ("- just\n- a list\n", "expected a mapping"),
])
def test_yaml_fields_of_the_wrong_type(tmp_path, capsys, sidecar, word):
    path, y = five_bar(tmp_path, sidecar)
    check(capsys, ["mobility", path], 1, word, path=y)


def test_yaml_alias_bomb_is_refused_in_one_short_line(tmp_path, capsys):
    bomb = "a: &a [x,x,x,x,x,x,x,x,x]\n" + "".join(
        f"{n}: &{n} [{','.join([f'*{p}'] * 9)}]\n" for p, n in zip("abcdefgh", "bcdefghi")) + "name_mot: *i\n"
    assert len(bomb) < 400  # 9**9 = 387 million x's once expanded
    path, y = five_bar(tmp_path, bomb)
    line = check(capsys, ["mobility", path], 1, "aliases", "not allowed", path=y)
    assert len(line) < 300


def test_yaml_too_big_or_too_deep(tmp_path, capsys):
    path, y = five_bar(tmp_path, LOOP + "# " + "x" * 1_100_000 + "\n")
    check(capsys, ["mobility", path], 1, "at most 1 MB", path=y)
    path, y = five_bar(tmp_path, "name_mot: " + "[" * 5000 + "]" * 5000 + "\n")
    check(capsys, ["mobility", path], 1, "malformed YAML", "nested deeper", path=y)
    path, y = five_bar(tmp_path, "name_mot: [" + "9" * 5000 + "]\n")
    check(capsys, ["mobility", path], 1, "malformed YAML", path=y)


def test_yaml_not_utf8(tmp_path, capsys):
    path, y = five_bar(tmp_path, b"\xff\xfe" + LOOP.encode())
    check(capsys, ["mobility", path], 1, "not UTF-8", path=y)


def test_yaml_pair_of_a_frame_with_itself(tmp_path, capsys):
    path, y = five_bar(tmp_path, "closed_loop: [['closedloop1_A', 'closedloop1_A']]\ntype: ['6d']\n")
    check(capsys, ["mobility", path], 1, "pairs frame 'closedloop1_A' with itself", path=y)


def test_yaml_pair_of_frames_fixed_together(tmp_path, capsys):
    # end_rod and effector are joined by the fixed joint effector_frame
    path, y = five_bar(tmp_path, "closed_loop: [['end_rod', 'effector']]\ntype: ['6d']\n")
    check(capsys, ["mobility", path], 1, "'end_rod' and 'effector'", "fixed together", path=y)


@pytest.mark.parametrize("kind", ["CARDAN", "SPHERICAL", "UJOINT_XZ"])
def test_yaml_replacement_of_a_fixed_joint(tmp_path, capsys, kind):
    path, y = five_bar(tmp_path, LOOP + f"joint_name: ['effector_frame']\njoint_type: ['{kind}']\n")
    check(capsys, ["mobility", path], 1, "'effector_frame', which is fixed", "must name a moving joint", path=y)


def test_loop_joint_between_links_fixed_together(tmp_path, capsys):
    text = GOOD.replace('name="rocker_joint" type="revolute"', 'name="rocker_joint" type="fixed"')
    text = text.replace('<link1 link="coupler"', '<link1 link="ground"')
    path = write(tmp_path, text)
    check(capsys, ["mobility", path], 1, "loop joint 'C'", "fixed together", path=path)


def test_third_link_child_of_a_loop_joint(tmp_path, capsys):
    path = write(tmp_path, fourbar('<link1 link="coupler" xyz="0.12 0 0"/><link2 link="rocker" xyz="0.08 0 0"/>'
                                   '<link2 link="ground"/>'))
    check(capsys, ["mobility", path], 1, "1 <link1> and 2 <link2>", "exactly one", path=path)


@pytest.mark.parametrize("old, new, words", [
    ('<axis xyz="0 0 1"/><limit', '<axis xyz="0 0 1e308"/><limit', ("axis '0 0 1e+308'", "not a plausible value")),
    ('<axis xyz="0 0 1"/><limit', '<axis xyz="1e-200 0 0"/><limit', ("not a plausible value",)),
    ('<origin xyz="0.04 0 0"', '<origin xyz="1e5 0 0"', ("'1e5 0 0' is not a plausible value", "beyond 10000 m")),
    ('rpy="0 0 1.5707963267948966"', 'rpy="0 0 1e300"', ("not a plausible value", "rad")),
    ('<mass value="1"/>', '<mass value="-1"/>', ("<mass value>", "below 0 kg")),
    ('<mass value="1"/>', '<mass value="1e9"/>', ("<mass value>", "beyond 1e+06 kg")),
    ('ixx="1"', 'ixx="1e300"', ("<inertia 'ixx'>",)),
    ('<box size="0.01 0.01 0.01"/>', '<box size="1e308 1 1"/>', ("<box size>",)),
    ('<origin xyz="0.04 0 0"', '<origin xyz="\u0661 0 0"', ("is not 3 numbers",)),
    ('<origin xyz="0.04 0 0"', '<origin xyz="1_0 0 0"', ("is not 3 numbers",)),
])
def test_implausible_numbers(tmp_path, capsys, old, new, words):
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    check(capsys, ["mobility", path], 1, *words, path=path)


def test_axis_is_normalized_whatever_its_length(tmp_path):
    import screwkin

    p = write(tmp_path, GOOD.replace('<axis xyz="0 0 1"/><limit', '<axis xyz="0 0 1e5"/><limit', 1))
    assert screwkin.load(p).spec.joints[0].axis == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("lo, hi, code, word", [
    ("1e308", "-1e308", 1, "joint 'crank_joint' <limit>: lower 1e+308 > upper -1e+308"),
    ("0.5", "0.1", 1, "joint 'crank_joint' <limit>: lower 0.5 > upper 0.1"),
    ("nan", "1", 1, "NaN or infinite"),
    ("-1.79769e+308", "1.79769e+308", 0, None),  # ROS/Gazebo's "unlimited"
    ("-1e16", "1e16", 0, None),
])
def test_limits(tmp_path, capsys, lo, hi, code, word):
    text = GOOD.replace('<limit lower="-3" upper="3"', f'<limit lower="{lo}" upper="{hi}"', 1)
    path = write(tmp_path, text)
    argv = ["solve", path, "--set", "crank_joint=0.1", "--json"]
    if code:
        check(capsys, argv, code, word, path=path)
    else:
        got, err = run(capsys, argv)
        assert got == 0, err


def test_prismatic_limits_swapped(tmp_path, capsys):
    from conftest import slider_crank

    text = slider_crank().replace('jtype="prismatic"', "")
    text = text.replace('type="prismatic"><parent link="ground"/><child link="slider"/>',
                        'type="prismatic"><parent link="ground"/><child link="slider"/>')
    i = text.index('name="slider_joint"')
    j = text.index("<limit", i)
    text = text[:j] + text[j:].replace('lower="-3" upper="3"', 'lower="1e308" upper="-1e308"', 1)
    path = write(tmp_path, text)
    check(capsys, ["solve", path, "--set", "crank_joint=0.1"], 1, "joint 'slider_joint' <limit>: lower", path=path)


def test_mesh_file_name_too_long_is_a_missing_mesh(tmp_path, capsys):
    name = "m" * 304
    text = GOOD.replace('<box size="0.01 0.01 0.01"/>', f'<mesh filename="package://pkg/{name}.stl"/>', 1)
    code, err = run(capsys, ["mobility", write(tmp_path, text)])
    assert code == 0 and "mesh file(s) not found" in err and "..." in err
    assert max(len(line) for line in err.splitlines()) < 600


def test_joint_named_like_a_link_loads_and_gives_the_same_answer(tmp_path, capsys):
    """Pinocchio then has a JOINT and a BODY frame of that name: the loop joint binds
    to the link (BODY frame), and the answer equals the one of the renamed file."""
    a, b = write(tmp_path, GOOD, "a.urdf"), write(tmp_path, GOOD.replace("crank_joint", "coupler"), "b.urdf")
    renamed = _json(capsys, ["mobility", a, "--json"]).replace(a, "F")
    same = _json(capsys, ["mobility", b, "--json"]).replace(b, "F")
    assert json.loads(renamed)["mobility"] == 1
    # the same report, but for the joint's name ("coupler" is also the link's name: compare word by word)
    words = [w for w in renamed.split('"')]
    other = [w for w in same.split('"')]
    assert len(words) == len(other)
    assert all(x == y or (x, y) == ("crank_joint", "coupler") or x == y.replace("coupler", "crank_joint")
               for x, y in zip(words, other))  # the last: a sentence naming the joint (mobility's suggestion)
    # and every command that binds frames by name works on it
    path = write(tmp_path, GOOD.replace("crank_joint", "coupler"), "c.urdf")
    for argv in (["info", path], ["solve", path, "--set", "coupler=0.3"], ["screws", path]):
        code, err = run(capsys, argv)
        assert code == 0, err


def _json(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_hundred_duplicate_loop_joints_do_not_hang(tmp_path, capsys):
    loop = '<loop_joint name="D{k}" type="revolute"><link1 link="coupler" xyz="0.12 0 0"/>' \
           '<link2 link="rocker" xyz="0.08 0 0"/><axis xyz="0 0 1"/></loop_joint>'
    path = write(tmp_path, fourbar(extra="".join(loop.format(k=k) for k in range(100))))
    with no_hang(120):
        out = json.loads(_json(capsys, ["mobility", path, "--json"]))
    assert out["mobility"] == 1
    path = write(tmp_path, fourbar(extra="".join(loop.format(k=k) for k in range(250))), "many.urdf")
    check(capsys, ["mobility", path], 1, "251 loop joints", "at most 200", path=path)


def chain(n, name="l"):
    body = f'<robot name="chain"><link name="{name}0"/>'
    for k in range(1, n + 1):
        body += (f'<link name="{name}{k}"/><joint name="j{k}" type="revolute"><parent link="{name}{k - 1}"/>'
                 f'<child link="{name}{k}"/><origin xyz="0.1 0 0"/><axis xyz="0 0 1"/>'
                 '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return body + "</robot>"


@pytest.mark.parametrize("n, words", [(2000, ("2001 links", "at most 2000")), (5000, ("5001 links",)),
                                      (600, ("600 moving joint coordinates", "at most 500", "13.8 GB"))])
def test_huge_chains_are_refused_before_pinocchio(tmp_path, capsys, n, words):
    path = write(tmp_path, chain(n))
    check(capsys, ["info", path], 1, *words, path=path)


def test_file_too_big(tmp_path, capsys):
    path = tmp_path / "big.urdf"
    with open(path, "w") as f:
        f.write(GOOD.replace("</robot>", ""))
        f.write("<!--" + "x" * 21_000_000 + "--></robot>")
    check(capsys, ["info", str(path)], 1, "at most 20 MB", path=str(path))


def test_nested_xml_is_refused(tmp_path, capsys):
    path = write(tmp_path, GOOD.replace("</robot>", "<x>" * 1000 + "</x>" * 1000 + "</robot>"))
    check(capsys, ["info", path], 1, "nested deeper than 100", path=path)


def test_sdf_in_a_comment_does_not_make_an_sdf_file(tmp_path, capsys):
    path = write(tmp_path, "<!-- converted from an <sdf version='1.7'> model -->\n" + GOOD)
    out = json.loads(_json(capsys, ["mobility", path, "--json"]))
    assert out["mobility"] == 1
    path = write(tmp_path, GOOD, "m.sdf")  # a URDF named .sdf is read as what it is
    assert json.loads(_json(capsys, ["mobility", path, "--json"]))["mobility"] == 1


def test_numpy_warnings_stay_off_stderr(tmp_path, capsys, monkeypatch):
    import warnings

    import numpy as np

    import screwkin.commands.mobility

    original = screwkin.commands.mobility.analyze_mobility

    def noisy(*a, **k):
        np.float64(1.0) / np.zeros(1)  # divide by zero: RuntimeWarning unless silenced
        warnings.warn("Mean of empty slice", RuntimeWarning)
        return original(*a, **k)

    monkeypatch.setattr(screwkin.commands.mobility, "analyze_mobility", noisy)
    code, err = run(capsys, ["mobility", write(tmp_path, GOOD)])
    assert code == 0 and err == "", err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
def test_named_pipes_are_refused_not_waited_on(tmp_path, capsys):
    fifo = tmp_path / "pipe.urdf"
    os.mkfifo(fifo)
    check(capsys, ["info", str(fifo)], 1, "is not a regular file", path=str(fifo))
    path = write(tmp_path, GOOD)
    os.mkfifo(tmp_path / "m.yaml")  # the sidecar beside the file
    check(capsys, ["info", path], 1, "is not a regular file", path=str(tmp_path / "m.yaml"))
    os.remove(tmp_path / "m.yaml")
    os.mkfifo(tmp_path / "other.yaml")
    check(capsys, ["info", path, "--yaml", str(tmp_path / "other.yaml")], 1, "is not a regular file")


def test_debug_before_the_command(tmp_path, capsys):
    path = write(tmp_path, "<robot")
    for argv in (["--debug", "mobility", path], ["mobility", path, "--debug"]):
        code, err = run(capsys, argv)
        assert code == 1 and "Traceback" in err and err.strip().splitlines()[-1].startswith("screwkin: error:")
    code, err = run(capsys, ["mobility", path])
    assert code == 1 and "Traceback" not in err


def test_broken_pipe_is_quiet(tmp_path):
    """``screwkin info F | head -1``: the reader goes away; no message, exit 141 (as if SIGPIPE)."""
    p = subprocess.Popen([sys.executable, "-m", "screwkin", "info", str(FOURBAR)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    p.stdout.close()  # before screwkin writes anything
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 141, err
    assert err == ""


def test_hostile_text_in_messages_is_short_and_one_line(tmp_path, capsys):
    big = "r" * 200_000
    path = write(tmp_path, GOOD.replace('name="coupler_joint" type="revolute"', f'name="coupler_joint" type="{big}"'))
    line = check(capsys, ["mobility", path], 1, "unknown type 'rrrr", "...", path=path)
    assert len(line) < 300 + len(path)
    path = write(tmp_path, GOOD.replace('name="coupler_joint" type="revolute"',
                                        'name="coupler_joint" type="revolute&#10;revolute&#8238;x"'))
    check(capsys, ["mobility", path], 1, r"'revolute\nrevolute\u202ex'", path=path)


# ---------------------------------------------------------------------------------------------
# Forgiving where a user would expect it

def test_transmission_of_a_fixed_or_missing_joint_is_a_warning(tmp_path, capsys):
    tx = ('<transmission name="t_ghost"><joint name="ghost"/></transmission>'
          '<transmission name="t_crank"><joint name="crank_joint"/></transmission>')
    text = fourbar(extra=tx).replace(
        "</robot>", '<link name="tool"/><joint name="tool_joint" type="fixed"><parent link="rocker"/>'
                    '<child link="tool"/></joint><transmission name="t_tool"><joint name="tool_joint"/>'
                    "</transmission></robot>")
    path = write(tmp_path, text)
    code, err = run(capsys, ["info", path])
    assert code == 0, err
    assert f"warning: {path}: transmission 't_ghost' names joint 'ghost', which is not in the file: ignored" in err
    assert "transmission 't_tool' names joint 'tool_joint', which is fixed: ignored" in err
    import screwkin

    assert screwkin.load(path, warn=lambda m: None).actuated == ["crank_joint"]
    # a name on the command line that is not a moving joint stays a usage error
    code, err = run(capsys, ["mobility", path, "--actuated", "tool_joint"])
    assert code == 2 and "'tool_joint'" in err.strip().splitlines()[-1]


def test_missing_meshes_say_where_and_package_dir_finds_them(tmp_path, capsys):
    mesh = '<visual><geometry><mesh filename="package://my_robot/meshes/base.stl"/></geometry></visual>'
    text = GOOD.replace('<link name="ground">', f'<link name="ground">{mesh}')
    path = write(tmp_path, text)
    code, err = run(capsys, ["info", path])
    assert code == 0 and "package://my_robot/meshes/base.stl" in err
    assert "looked for packages in" in err and "ROS_PACKAGE_PATH" in err and "--package-dir DIR" in err
    pkgs = tmp_path / "somewhere" / "src"
    (pkgs / "my_robot" / "meshes").mkdir(parents=True)
    (pkgs / "my_robot" / "meshes" / "base.stl").write_text("solid x\nendsolid x\n")
    code, err = run(capsys, ["info", path, "--package-dir", str(pkgs)])
    assert code == 0 and "mesh" not in err, err
    code, err = run(capsys, ["info", path, "--package-dir", str(tmp_path / "nowhere")])
    assert code == 2 and "is not a folder" in err
    import screwkin
    from screwkin.present.view import _visual_urdf

    mech = screwkin.load(path, package_dirs=[pkgs], warn=lambda m: None)
    assert str((pkgs / "my_robot" / "meshes" / "base.stl").resolve()) in _visual_urdf(mech)


@pytest.mark.parametrize("text, value", [
    ("1in", 0.0254), ("2 inch", 0.0508), ("1ft", 0.3048), ("30 mm", 0.03), ("30MM", 0.03), ("3cm", 0.03),
    ("5um", 5e-6), ("2 m", 2.0), ("45deg", np.pi / 4), ("45 DEG", np.pi / 4), ("90°", np.pi / 2),
    ("0.5 rad", 0.5), ("500mrad", 0.5), ("0.25turn", np.pi / 2), ("-.5", -0.5), ("1e-3", 1e-3),
])
def test_units_users_type(text, value):
    from screwkin.units import parse_value

    assert abs(parse_value(text) - value) < 1e-12


@pytest.mark.parametrize("text, word", [("1km", "unknown unit 'km'"), ("nan", "not a number"),
                                        ("1e999", "not a finite"), ("12parsecs", "unknown unit"),
                                        ("\u0661", "not a number")])
def test_units_refused(text, word):
    from screwkin.errors import UsageError
    from screwkin.units import parse_value

    with pytest.raises(UsageError, match=word):
        parse_value(text)


def test_view_draws_bare_links_with_stand_ins(tmp_path):
    """Links with neither visual nor inertial still show: a ball at each joint centre and bars
    to the joint centres and loop-joint frames on them (only zero-length links inside compound
    joints are left out)."""
    import re

    import screwkin
    from screwkin.present.view import RecordingViewer, build_scene, show

    bare = re.sub(r'<link name="(\w+)">.*?</link>', r'<link name="\1"/>', GOOD)
    # a zero-length massless link between two joints at the same point: inside a compound joint
    bare = bare.replace('<child link="rocker"/>', '<child link="knuckle"/>').replace(
        "</robot>", '<link name="knuckle"/><joint name="k" type="revolute"><parent link="knuckle"/>'
                    '<child link="rocker"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" '
                    'velocity="1"/></joint></robot>')
    path = write(tmp_path, bare)
    mech = screwkin.load(path)
    scene = build_scene(mech, mech.assemble().q)
    balls = {n.split("/", 2)[2] for n in scene.roles if n.startswith("screwkin/standin/")}
    bars = {n.split("/", 2)[2] for n in scene.roles if n.startswith("screwkin/standin_bar/")}
    assert balls == {"crank", "coupler", "rocker"}
    assert {"crank/coupler_joint", "coupler/C", "rocker/C", "ground/rocker_joint"} <= bars
    assert not any(b.startswith("knuckle") for b in bars)
    viewer = RecordingViewer()
    show(mech, scene, viewer, mech.assemble().q)
    assert any("standin" in p for p in viewer.objects)


def test_mirrored_mesh_scale_is_fine(tmp_path, capsys):
    text = GOOD.replace('<box size="0.01 0.01 0.01"/>', '<mesh filename="m.stl" scale="-1 1 1"/>', 1)
    code, err = run(capsys, ["info", write(tmp_path, text)])
    assert code == 0 and "plausible" not in err, err


def test_too_many_elements_or_meshes(tmp_path, capsys):
    """A file of 250,000 visuals is refused while it is parsed; 3,000 distinct missing meshes are
    looked for only up to 2,000 (a load stays quick whatever the file)."""
    vis = '<visual><geometry><box size="1 1 1"/></geometry></visual>'
    path = write(tmp_path, GOOD.replace('<link name="crank">', '<link name="crank">' + vis * 70_000))
    check(capsys, ["info", path], 1, "more than 200000 XML elements", path=path)
    mesh = '<visual><geometry><mesh filename="package://p/m{k}.stl"/></geometry></visual>'
    text = GOOD.replace('<link name="crank">', '<link name="crank">' + "".join(mesh.format(k=k) for k in range(3000)))
    code, err = run(capsys, ["info", write(tmp_path, text, "meshes.urdf")])
    assert code == 0 and "2000 mesh file(s) not found" in err and "only the first 2000" in err


@pytest.mark.parametrize("command", [["solve"], ["report", "--md", "r.md", "--no-view"]])
def test_a_rate_of_a_joint_that_is_not_an_input_is_refused(command, capsys, tmp_path, monkeypatch):
    """--rate rocker_joint with the crank as input used to be dropped without a word (rates all 0)."""
    from screwkin.cli import main

    monkeypatch.chdir(tmp_path)
    argv = [command[0], str(ROBOTS / "fourbar_crank_rocker.urdf"), "--set", "crank_joint=30deg",
            "--rate", "rocker_joint=2", *command[1:]]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--rate rocker_joint: not an input (inputs: crank_joint)" in err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("argv,words", [
    (["--set", "crank_joint=0.1", "--set", "crank_joint=0.2"], "--set: 'crank_joint' is given twice"),
    (["--set", "crank_joint=0.1,crank_joint=0.2"], "--set: 'crank_joint' is given twice"),
    (["--set-angle", "crank=10deg", "--set-angle", "crank=20deg"], "--set-angle: 'crank' is given twice"),
    (["--set", "crank_joint=1e308"], "beyond 100000 rad an angle's place in its turn is lost"),
    (["--set-angle", "coupler=1e9deg"], "beyond 100000 rad an angle's place in its turn is lost"),
])
def test_a_value_given_twice_or_beyond_any_turn_is_refused(argv, words, capsys):
    """The last of two values won without a word; 1e308 rad was solved as if it meant an angle
    (nothing of its fraction of a turn survives rounding past 1e5 rad at the closure tolerance)."""
    from screwkin.cli import main

    assert main(["solve", str(ROBOTS / "fourbar_crank_rocker.urdf"), *argv]) == 2
    assert words in capsys.readouterr().err
