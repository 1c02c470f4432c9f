"""Families of mechanisms as xacro files (robots/fourbar.urdf.xacro, robots/delta.urdf.xacro):
each expands to the same mechanism as the plain URDF it generalizes, arguments (with units)
change it, and hostile xacro files are one-line errors (exit 1), never code run, files read
outside the folder, or a hang."""

import json
import math

import numpy as np
import pytest
from conftest import ROBOTS, no_hang
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import screwkin
from screwkin.analysis.motion.planar import identify
from screwkin.cli import main
from screwkin.files.xacro import parse_args
from screwkin.files.xacro_eval import (
    XacroEvaluationError,
    check_expression,
    evaluate,
)
from screwkin.model.lengths import link_lengths

FOURBAR = ROBOTS / "fourbar.urdf.xacro"
DELTA = ROBOTS / "delta.urdf.xacro"
HEAD = '<?xml version="1.0"?>\n<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
LINK = ('<link name="{n}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link>')


def linkage(mech):
    q = mech.generic_configurations()[1][0]
    return identify(mech, mech.topology(q), q, "crank_joint")


def test_fourbar_family_default_is_the_plain_crank_rocker():
    plain = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    family = screwkin.load(FOURBAR)
    a, b = linkage(plain), linkage(family)
    assert a.grashof == b.grashof
    for k in a.lengths:
        assert b.lengths[k] == pytest.approx(a.lengths[k], abs=1e-12)
    ma, mb = plain.mobility(output="rocker"), family.mobility(output="rocker")
    assert (ma.mobility, ma.output.label, ma.gruebler) == (mb.mobility, mb.output.label, mb.gruebler) == (1, "1R", 1)
    # the file's configuration closes the loop
    assert np.abs(family.closure.residual(family.neutral())).max() < 1e-12


def test_fourbar_arguments_with_units_change_the_lengths():
    mech = screwkin.load(FOURBAR, args={"crank": "30mm", "coupler": 0.2, "rocker": "300 mm", "ground": "0.1"})
    info = linkage(mech)
    assert info.lengths == pytest.approx({"ground": 0.1, "input": 0.03, "coupler": 0.2, "output": 0.3}, abs=1e-12)
    assert info.grashof.startswith("non-Grashof")  # 0.03 + 0.3 > 0.1 + 0.2
    assert np.abs(mech.closure.residual(mech.neutral())).max() < 1e-12
    drawn = screwkin.load(FOURBAR, args={"theta": "60deg"})
    a = drawn.model.jointPlacements[drawn.model.getJointId("crank_joint")]
    assert math.atan2(a.rotation[1, 0], a.rotation[0, 0]) == pytest.approx(math.pi / 3)


def test_delta_family_default_is_the_plain_delta():
    plain = screwkin.load(ROBOTS / "delta_parallelogram.urdf")
    family = screwkin.load(DELTA)
    assert set(plain.model.names) == set(family.model.names)
    for j in range(1, plain.model.njoints):
        k = family.model.getJointId(plain.model.names[j])
        assert family.model.jointPlacements[k].isApprox(plain.model.jointPlacements[j], 1e-12)
        assert family.model.joints[k].shortname() == plain.model.joints[j].shortname()
    assert [c.name for c in family.cuts] == [c.name for c in plain.cuts]
    for c, d in zip(family.cuts, plain.cuts, strict=True):
        for f, g in ((c.frame1, d.frame1), (c.frame2, d.frame2)):
            assert family.model.frames[f].placement.isApprox(plain.model.frames[g].placement, 1e-12)
    assert sorted(link_lengths(family.model, family.cuts)) == pytest.approx(
        sorted(link_lengths(plain.model, plain.cuts)), abs=1e-12)
    r = family.mobility(output="platform")
    assert (r.mobility, r.idle_dofs, r.effective_mobility, r.output.label) == (9, 6, 3, "3T")
    assert family.actuated == plain.actuated == ["arm1", "arm2", "arm3"]


def test_delta_with_longer_rods_closes_its_loops():
    mech = screwkin.load(DELTA, args={"arm": "250mm", "rod": "0.5", "arm_angle": "20deg"})
    assert np.abs(mech.closure.residual(mech.neutral())).max() < 1e-12
    platform = mech.model.frames[mech.link_frame("platform")]
    data = mech.model.createData()
    import pinocchio as pin
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    z = data.oMf[mech.link_frame("platform")].translation[2]
    h = 0.15 + 0.25 * math.cos(math.radians(20)) - 0.04
    assert z == pytest.approx(-0.25 * math.sin(math.radians(20)) - math.sqrt(0.25 - h * h), abs=1e-12)
    assert platform is not None
    r = mech.mobility(output="platform")
    assert (r.effective_mobility, r.output.label) == (3, "3T")


def test_cli_takes_arg(capsys):
    assert main(["mobility", str(FOURBAR), "--arg", "crank=30mm", "--arg", "coupler=0.11", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["mobility"] == 1
    assert main(["info", str(DELTA), "--arg", "rod=0.45"]) == 0
    assert "platform" in capsys.readouterr().out


def test_parse_args():
    assert parse_args(["a=30mm", "b=0.1", "c=left_", "n=3"]) == {"a": "0.03", "b": "0.1", "c": "left_", "n": "3"}
    with pytest.raises(screwkin.UsageError, match="NAME=VALUE"):
        parse_args(["a"])
    with pytest.raises(screwkin.UsageError, match="twice"):
        parse_args(["a=1", "a=2"])
    with pytest.raises(screwkin.UsageError, match="not a xacro argument name"):
        parse_args(["a-b=1"])


# ------------------------------------------------------------------ the expression subset
@pytest.mark.parametrize("expr, value", [
    ("1 + 2 * 3", 7), ("2 ** 10", 1024), ("sqrt(16)", 4.0), ("math.sin(math.pi / 2)", 1.0),
    ("atan2(1, 1) * 4", math.pi), ("max(1, 2.5, -3)", 2.5), ("abs(-2)", 2), ("pow(2, 3)", 8),
    ("'a' + 'b'", "ab"), ("1 if 2 > 1 else 0", 1), ("not 0 and 3", 3), ("radians(180)", math.pi),
    ("x * 2", 0.2), ("floor(2.5) + ceil(2.5)", 5), ("log(math.e)", 1.0), ("1 < 2 <= 2", True),
])
def test_expressions_in_the_subset(expr, value):
    check_expression(expr)
    assert evaluate(expr, {"x": 0.1}) == pytest.approx(value)


HOSTILE_EXPRESSIONS = [
    "__import__('os').system('echo hacked')", "().__class__", "().__class__.__bases__[0].__subclasses__()",
    "open('/etc/passwd').read()", "python.type(1)", "xacro.load_yaml('x.yaml')", "load_yaml('x.yaml')",
    "[1, 2]", "{'a': 1}", "(lambda: 1)()", "f'{x}'", "x[0]", "eval('1')", "exec('1')", "getattr(x, 'y')",
    "type(1)", "str(1)", "math.__dict__", "_secret", "(x := 1)", "1 in [1]", "[i for i in range(10)]",
    "sin(x=1)", "globals()", "vars()", "x.real",
]


@pytest.mark.parametrize("expr", HOSTILE_EXPRESSIONS)
def test_hostile_expressions_are_refused(expr):
    with pytest.raises(ValueError, match="only numbers"):
        check_expression(expr)
    with pytest.raises(XacroEvaluationError):
        evaluate(expr, {"x": 1.0, "python": {}, "xacro": {}})


@pytest.mark.parametrize("expr", ["9 ** 9 ** 9", "10 ** 400", "'a' * 1000000000", "'%999999999s' % 1",
                                  "exp(1000)", "2 ** 64 ** 2", "pow(10, 10 ** 10)"])
def test_expensive_expressions_fail_fast(expr):
    with no_hang(10):  # refused before it is computed: 9 ** 9 ** 9 would run for hours
        try:
            v = evaluate(expr, {})
            assert not isinstance(v, int) or abs(v) <= 2**63  # a float (inf), never a huge integer
        except XacroEvaluationError:
            pass


@given(st.text(max_size=200))
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_any_text_is_evaluated_or_refused(text):
    try:
        evaluate(text, {"a": 1.0, "b": "x"})
    except (XacroEvaluationError, NameError, ArithmeticError, ValueError, TypeError):
        pass


# ------------------------------------------------------------------ hostile files: one line, exit 1
def fourbar_with(extra_head="", body_extra="", prolog=""):
    """A small valid xacro four-bar (no loop joint: a serial chain is enough) with extras."""
    return (f'{prolog}{HEAD}{extra_head}<xacro:arg name="l" default="0.1"/>'
            + LINK.format(n="base") + LINK.format(n="arm")
            + '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
              '<origin xyz="$(arg l) 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
              f'</joint>{body_extra}</robot>')


HOSTILE_FILES = {
    "import": ('<link name="${__import__(\'os\').system(\'touch /tmp/screwkin_hacked\')}"/>', "__import__"),
    "class": ('<link name="${().__class__}"/>', "attribute access"),
    "subclasses": ('<link name="${().__class__.__bases__[0].__subclasses__()}"/>', "a call of"),
    "env": ('<link name="$(env HOME)"/>', "only $(arg NAME)"),
    "optenv": ('<link name="$(optenv HOME x)"/>', "only $(arg NAME)"),
    "find": ('<link name="$(find x)"/>', "only $(arg NAME)"),
    "eval": ('<link name="$(eval 1 + 1)"/>', "only $(arg NAME)"),
    "dirname": ('<link name="$(dirname)"/>', "only $(arg NAME)"),
    "cwd": ('<link name="$(cwd)"/>', "only $(arg NAME)"),
    "env_in_expression": ('<link name="${$(env HOME)}"/>', "only $(arg NAME)"),
    "load_yaml": ('<xacro:property name="p" value="${load_yaml(\'/etc/passwd\')}"/>', "load_yaml"),
    "xacro_load_yaml": ('<xacro:property name="p" value="${xacro.load_yaml(\'x.yaml\')}"/>', "load_yaml"),
    "include_passwd": ('<xacro:include filename="/etc/passwd"/>', "outside the folder"),
    "include_parent": ('<xacro:include filename="../../../../etc/hostname"/>', "outside the folder"),
    "include_glob": ('<xacro:include filename="*.xacro"/>', "wildcards"),
    "computed_include_outside": ('<xacro:include filename="${\'/etc/\' + \'passwd\'}"/>', "outside the folder"),
    "string_bomb": ('<xacro:property name="p" value="${\'a\' * 1000000000}"/><link name="${p}"/>', "on text"),
    "power_bomb": ('<origin xyz="${9 ** 9 ** 9}"/>', "overflow"),
    "undefined": ('<link name="${nothere}"/>', "nothere"),
    "bad_arg_use": ('<link name="$(arg missing)"/>', "'missing' has no value"),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_FILES))
def test_hostile_xacro_files(tmp_path, capsys, case):
    extra, word = HOSTILE_FILES[case]
    path = tmp_path / "m.urdf.xacro"
    path.write_text(fourbar_with(body_extra=extra))
    code = main(["info", str(path)])
    err = capsys.readouterr().err
    assert code == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"screwkin: error: {path}: "), lines[0]
    assert word in lines[0], lines[0]
    assert len(lines[0]) < 400 + len(str(path))
    assert not (tmp_path / "screwkin_hacked").exists()


def test_entities_depth_and_size(tmp_path, capsys):
    cases = {
        "entity": (fourbar_with(prolog='<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">]>\n').replace(
            '<?xml version="1.0"?>\n', ""), "entity"),
        "deep": (fourbar_with(body_extra="<a>" * 200 + "</a>" * 200), "nested deeper"),
    }
    for name, (text, word) in cases.items():
        path = tmp_path / f"{name}.urdf.xacro"
        path.write_text(text)
        assert main(["info", str(path)]) == 1, name
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and word in err, err
    huge = tmp_path / "huge.urdf.xacro"
    with open(huge, "wb") as f:
        f.truncate(25_000_000)
    assert main(["info", str(huge)]) == 1
    assert "MB" in capsys.readouterr().err


def test_macro_bomb_and_recursion_are_bounded(tmp_path, capsys):
    # each macro calls the one before twice: 2**30 copies if unbounded
    macros = '<xacro:macro name="m0"><link name="x"/></xacro:macro>' + "".join(
        f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>' for k in range(1, 31))
    cases = {"bomb": (macros + "<xacro:m30/>", "more than 5000 macro calls"),
             "recursive": ('<xacro:macro name="r"><xacro:r/></xacro:macro><xacro:r/>', "nested too deeply"),
             "self_include": ('<xacro:include filename="self.urdf.xacro"/>', "files included")}
    for name, (extra, word) in cases.items():
        path = tmp_path / "self.urdf.xacro"
        path.write_text(fourbar_with(body_extra=extra))
        with no_hang(60):  # 2**30 macro copies if unbounded
            assert main(["info", str(path)]) == 1, name
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and word in err, (name, err)


def test_includes_beside_the_file_work(tmp_path, capsys):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "arm.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="arm" params="n">'
        + LINK.format(n="${n}") + "</xacro:macro></robot>")
    path = tmp_path / "m.urdf.xacro"
    path.write_text(f'{HEAD}<xacro:include filename="parts/arm.xacro"/>' + LINK.format(n="base")
                    + '<xacro:arm n="arm"/><joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                      '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    assert main(["info", str(path)]) == 0, capsys.readouterr().err
    assert "arm" in capsys.readouterr().out
    (tmp_path / "parts" / "arm.xacro").write_text('<!DOCTYPE r [<!ENTITY a "b">]><robot/>')
    assert main(["info", str(path)]) == 1
    assert "entity" in capsys.readouterr().err


def test_arguments_errors(tmp_path, capsys):
    path = tmp_path / "m.urdf.xacro"
    path.write_text(fourbar_with(extra_head='<xacro:arg name="needed"/>'))
    assert main(["info", str(path)]) == 1
    assert "'needed' has no default" in capsys.readouterr().err
    assert main(["info", str(path), "--arg", "needed=1"]) == 0
    capsys.readouterr()
    assert main(["info", str(path), "--arg", "needed=1", "--arg", "typo=2"]) == 2
    assert "declares no xacro argument 'typo'" in capsys.readouterr().err
    assert main(["info", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--arg", "a=1"]) == 2
    assert "not a xacro file" in capsys.readouterr().err


def test_a_design_that_does_not_close_is_an_assembly_error():
    mech = screwkin.load(FOURBAR, args={"ground": 0.5})  # 0.5 > 0.04 + 0.12 + 0.08
    with pytest.raises(screwkin.AssemblyError):
        mech.assemble()


def _doubling_blocks(levels: int) -> str:
    """issue 22 item 1: each block property inserts the previous one twice; no macro is called."""
    blocks = ['<xacro:property name="b0"><link name="x"/></xacro:property>']
    blocks += [f'<xacro:property name="b{k}"><xacro:insert_block name="b{k - 1}"/>'
               f'<xacro:insert_block name="b{k - 1}"/></xacro:property>' for k in range(1, levels + 1)]
    return ('<?xml version="1.0"?><robot name="bomb" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            + "".join(blocks) + f'<xacro:insert_block name="b{levels}"/></robot>')


def _doubling_strings(levels: int) -> str:
    props = ['<xacro:property name="s0" value="aaaaaaaaaaaaaaaa"/>']
    props += [f'<xacro:property name="s{k}" value="${{s{k - 1}}}${{s{k - 1}}}"/>' for k in range(1, levels + 1)]
    return ('<?xml version="1.0"?><robot name="s" xmlns:xacro="http://www.ros.org/wiki/xacro">' + "".join(props)
            + f'<link name="${{s{levels}}}"/></robot>')


@pytest.mark.parametrize("levels", [16, 30])
def test_property_blocks_that_double_are_refused_at_once(levels, tmp_path, capsys):
    path = tmp_path / "bomb.urdf.xacro"
    path.write_text(_doubling_blocks(levels))
    assert len(path.read_bytes()) < 4000
    with no_hang(10):  # minutes (16 levels) or forever (30) when only the final size was checked
        assert main(["info", str(path)]) == 1
    err = capsys.readouterr().err
    assert "copies expand to more than 200000 elements" in err and len(err.strip().splitlines()) == 1


def test_properties_whose_text_doubles_are_refused_at_once(tmp_path, capsys):
    path = tmp_path / "strings.urdf.xacro"
    path.write_text(_doubling_strings(40))  # 16 * 2**40 characters if concatenated
    with no_hang(10):
        assert main(["info", str(path)]) == 1
    err = capsys.readouterr().err
    assert "a text of more than 10000 characters" in err and len(err.strip().splitlines()) == 1


def test_blocks_inserted_a_few_times_still_expand(tmp_path, capsys):
    """The bound is on copies, not on insert_block: a block property inserted twice (4 links) expands."""
    path = tmp_path / "ok.urdf.xacro"
    text = _doubling_blocks(2).replace('<link name="x"/>', '<link name="x${n}"/>')
    text = text.replace('<robot name="bomb" xmlns:xacro="http://www.ros.org/wiki/xacro">',
                        '<robot name="ok" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="n" '
                        'value="0"/>')
    path.write_text(text)
    from screwkin.files.xacro import expand

    out = expand(path, path.read_text())
    assert out.count('<link name="x0"/>') == 4


# ---- the contract with the xacro internals that screwkin/files/xacro.py replaces and calls
# (xacro keeps them as module globals; a release that renames one, changes its parameters or
# stops looking it up as a global would leave a hole in the checks: these tests name the version)

def _xacro():
    import importlib.metadata

    import xacro

    return xacro, importlib.metadata.version("xacro")


def _positional(fn):
    import inspect

    params = [p for p in inspect.signature(fn).parameters.values()
              if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len([p for p in params if p.default is p.empty]), len(params)


def _global_names(module):
    """Every name the module's functions and methods look up as a global (nested code included)."""
    import inspect
    import types

    names, stack = set(), [obj.__code__ for obj in vars(module).values() if inspect.isfunction(obj)]
    stack += [f.__code__ for cls in vars(module).values() if inspect.isclass(cls)
              for f in vars(cls).values() if inspect.isfunction(f)]
    while stack:
        code = stack.pop()
        names |= set(code.co_names)
        stack += [c for c in code.co_consts if isinstance(c, types.CodeType)]
    return names


def test_xacro_internals_that_screwkin_replaces_keep_their_shape():
    """Each function screwkin swaps in (files/xacro.py: _patched) exists in the xacro module,
    takes the same positional parameters as xacro's own (xacro's calls must bind to the
    replacement, and the replacement forwards to the original), and is looked up by xacro's own
    code as a module global (so that the swap takes effect)."""
    from screwkin.files.xacro import _patched, _prepare

    xacro, version = _xacro()
    text = FOURBAR.read_text()
    original, replaced = _patched(xacro, _prepare(FOURBAR, text), FOURBAR)
    assert set(original) == set(replaced) == {"safe_eval", "eval_extension", "get_include_files", "parse",
                                              "handle_macro_call", "eval_all", "eval_text", "reqd_attrs"}
    used = _global_names(xacro)
    for name, fn in replaced.items():
        theirs = getattr(xacro, name, None)
        assert callable(theirs), f"xacro {version} has no function {name}: screwkin/files/xacro.py replaces it"
        assert _positional(fn) == _positional(theirs), (
            f"xacro {version}: {name} takes {_positional(theirs)} (required, all) positional parameters, "
            f"screwkin's replacement {_positional(fn)}")
        assert name in used, f"xacro {version} no longer calls {name} as a module global: replacing it does nothing"


def test_xacro_internals_that_screwkin_calls_keep_their_shape():
    """The state, functions and classes files/xacro.py reads or calls, as it uses them."""
    import inspect

    xacro, version = _xacro()
    where = f"xacro {version} (screwkin/files/xacro.py relies on it)"
    assert issubclass(xacro.XacroException, Exception), where
    assert isinstance(xacro.substitution_args_context, dict), where
    assert isinstance(xacro.all_includes, list) and isinstance(xacro.verbosity, int), where
    assert hasattr(xacro, "filestack"), where
    inspect.signature(xacro.init_stacks).bind("file.xacro")
    inspect.signature(xacro.process_doc).bind(None, mappings={}, verbosity=0)
    assert _positional(xacro.resolve_macro) == (3, 3), where


def test_xacro_resolve_macro_returns_the_macro_with_its_body(monkeypatch):
    """screwkin counts a macro's elements from ``xacro.resolve_macro(name, macros,
    symbols)[2].body`` (and takes an error there as "no body": the count would then be skipped
    silently), so the shape is checked here on a real expansion."""
    xacro, version = _xacro()
    seen = []
    real = xacro.resolve_macro

    def spy(*args):
        result = real(*args)
        seen.append(result)
        return result

    monkeypatch.setattr(xacro, "resolve_macro", spy)
    screwkin.load(DELTA)  # three legs from one macro
    assert seen, f"xacro {version} expanded the Delta's macro without resolve_macro"
    for result in seen:
        assert isinstance(result, tuple) and len(result) == 3, f"xacro {version}: resolve_macro returns {result!r}"
        assert hasattr(result[2].body, "getElementsByTagName"), f"xacro {version}: the macro's body is not a DOM node"


@pytest.mark.parametrize("text", ["a ${x} b", "$${x} $$(arg a) ${1+2}$(arg a)", "${'}'} x", "$(arg a) ${a}} $", "$$$${y}",
                                  "plain", "${a}${b}", "$ {a} $(a b c) ${ x }"])
def test_xacro_lexer_splits_as_screwkin_checks(text):
    """Before xacro sees a file, screwkin checks every ${...} and $(...) it finds with its own
    regular expression (files/xacro.py: _TOKENS); xacro's lexer (xacro.LEXER) must find the same ones."""
    from screwkin.files.xacro import _TOKENS

    xacro, version = _xacro()
    lex = xacro.QuickLexer(xacro.LEXER)
    lex.lex(text)
    theirs = []
    while lex.peek():
        kind, token = lex.next()
        if kind != lex.TEXT:
            theirs.append(token)
    assert theirs == [m.group(0) for m in _TOKENS.finditer(text)], f"xacro {version}'s lexer on {text!r}"
