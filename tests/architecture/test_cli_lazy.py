"""The command line imports only the command it runs (cli.COMMANDS lists the others by name and
help line): the table must say what each command's own module says, and the parser built
lazily must be the parser built from every module."""

import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROBOTS
from screwkin import cli
from screwkin.commands._common import add_common, add_scaled

ROOT = Path(__file__).resolve().parents[2]


def full_parser():
    """The parser as cli built it before: every command module's add_parser."""
    p = cli._Parser(prog="screwkin", description="Screw-theory analysis of spatial mechanisms described in URDF.")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    p.add_argument("--version", action="version", version=f"screwkin {cli.screwkin_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=cli._Parser, title="commands",
                           metavar="COMMAND")
    for name, _ in cli.COMMANDS:
        cli.command_module(name).add_parser(sub, add_common, add_scaled)
    return p, sub


def test_the_table_is_what_the_modules_say():
    _, sub = full_parser()
    own = [(a.dest, a.help) for a in sub._choices_actions]
    assert own == list(cli.COMMANDS)
    for name, _ in cli.COMMANDS:
        assert cli.command_module(name).NAME == name
    modules = sorted(p.stem for p in (ROOT / "screwkin" / "commands").glob("*.py") if not p.stem.startswith("_"))
    assert modules == sorted(name for name, _ in cli.COMMANDS)


def test_help_is_the_full_parsers():
    full, sub = full_parser()
    assert cli._parser([]).format_help() == full.format_help()
    assert cli._parser(["--debug", "sweep", "x"]).format_help() == full.format_help()
    for name, _ in cli.COMMANDS:
        lazy = cli._parser([name])._subparsers._group_actions[0].choices[name]
        assert lazy.format_help() == sub.choices[name].format_help(), name



def _last_line(code: str) -> str:
    """The last line a fresh Python prints running ``code`` with this checkout first on its path."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                         env={"PYTHONPATH": str(ROOT), "PATH": ""}, check=True)
    return out.stdout.strip().splitlines()[-1]

@pytest.mark.parametrize("argv", [[], ["--help"], ["--version"], ["nosuch"], ["--debug"]])
def test_nothing_but_the_top_level_is_imported(argv):
    code = ("import sys\nfrom screwkin import cli\ntry:\n    cli.main(%r)\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in sys.modules if m.startswith('screwkin.commands.') and "
            "not m.startswith('screwkin.commands._')))" % (argv,))
    assert _last_line(code) == "[]"


def test_a_command_imports_its_module_alone():
    fourbar = ROBOTS / "fourbar_crank_rocker.urdf"
    code = ("import sys\nfrom screwkin import cli\ncode = cli.main(['sweep', %r, '--input', 'crank_joint', "
            "'--from', '0', '--to', '1', '--steps', '3'])\n"
            "print(code, sorted(m for m in sys.modules if m.startswith('screwkin.commands.') and "
            "not m.startswith('screwkin.commands._')))" % str(fourbar))
    assert _last_line(code) == "0 ['screwkin.commands.sweep']"


def test_usage_errors_are_the_same():
    full, _ = full_parser()
    for argv in (["sweep"], ["sweep", "f.urdf", "--steps", "0"], ["nosuch"], ["mobility", "--nosuch", "f"]):
        with pytest.raises(SystemExit) as lazy:
            cli._parser(argv).parse_args(argv)
        with pytest.raises(SystemExit) as whole:
            full.parse_args(argv)
        assert lazy.value.code == whole.value.code == 2



def test_a_sweep_imports_no_other_analysis():
    """What `screwkin sweep` costs at start-up: not the analyses of other commands (the public API
    imports them when first used)."""
    fourbar = ROBOTS / "fourbar_crank_rocker.urdf"
    code = ("import sys\nfrom screwkin import cli\ncode = cli.main(['sweep', %r, '--input', 'crank_joint', "
            "'--from', '0', '--to', '1', '--steps', '3', '--json'])\n"
            "print(code, sorted(m for m in ('screwkin.analysis.forces.dynamics', 'screwkin.analysis.design.study', "
            "'screwkin.parallel.study', 'screwkin.analysis.position.ik') if m in sys.modules))" % str(fourbar))
    assert _last_line(code) == "0 []"


def test_a_urdf_imports_neither_yaml_nor_the_web():
    """Start-up on a URDF: no yaml (sidecars only), no xml.sax.saxutils with urllib, http, ssl (xacro only)."""
    fourbar = ROBOTS / "fourbar_crank_rocker.urdf"
    code = ("import sys\nfrom screwkin import cli\ncode = cli.main(['mobility', %r])\n"
            "print(code, sorted(m for m in ('yaml', 'xml.sax.saxutils', 'urllib.request', 'ssl', 'defusedxml.minidom') "
            "if m in sys.modules))" % str(fourbar))
    assert _last_line(code) == "0 []"


@pytest.mark.parametrize("text", ["", "a", 'say "hi"', "it's", "\"'", "a&b<c>d", "x\ny\rz\tw", "&amp;", "é"])
def test_quoteattr_is_saxutils(text):
    from xml.sax.saxutils import quoteattr as oracle

    from screwkin.files.writer import quoteattr

    assert quoteattr(text) == oracle(text)
