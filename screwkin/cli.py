"""Command line: ``screwkin COMMAND FILE ...``.

A thin edge over the Python API: it builds the parser from the command modules of
``screwkin/commands/`` (one module per command: ``NAME``, ``NEEDS_MECHANISM``,
``add_parser(sub, common, scaled)``, ``run(mech, args) -> exit code``; only the invoked
command's module is imported, the others are listed from the table COMMANDS), loads the
mechanism, checks what every command shares and dispatches.  Exit codes: 0 success, 1 invalid or
unanalysable file, 2 usage error, 3 internal error (a bug).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import traceback
import warnings

import numpy as np

from .commands._common import add_common, add_scaled
from .commands._output_frame import named_points
from .commands._values import names_list
from .commands._options import check_not_read, check_parsed, screwkin_version
from .errors import MESSAGE_LIMIT, ScrewkinError, UsageError, one_line
from .files.xacro import parse_args as parse_xacro_args
from .model.loader import load
from .units import parse_length
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["main", "COMMANDS", "command_module"]

#: The commands, in the order `screwkin` lists them, each with its one-line help (the same text as
#: its module's ``add_parser`` gives: tests/architecture/test_cli_lazy.py).  A command's module
#: (screwkin/commands/NAME.py, with the analysis and presentation it imports) is imported only
#: when that command runs or shows its own --help: ``screwkin`` and ``screwkin --help`` list them
#: from this table, and ``screwkin sweep ...`` imports sweep's module alone.
COMMANDS = (
    ("mobility", "degrees of freedom: counts and screw-theory mobility"),
    ("info", "topology table: links, joints, loops (--joint-types: the joint vocabulary)"),
    ("solve", "position, velocity and acceleration for given input values"),
    ("screws", "product-of-exponentials structure equations and joint screws"),
    ("singularities", "classify the singularities of a configuration"),
    ("map", "map of the smallest singular value over two inputs"),
    ("scan", "singularity scan of a serial chain over random configurations"),
    ("view", "show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)"),
    ("ik", "inverse kinematics: joint values that place an output link at a pose"),
    ("sweep", "track one assembly mode along an input motion"),
    ("statics", "actuator efforts and joint reactions holding a load; legs' wrenches"),
    ("dynamics", "input efforts, joint reactions, shaking forces and flywheel at constant input speed"),
    ("study", "design-space study of a family of mechanisms (a xacro file) on Dask"),
    ("synthesize", "synthesize a planar linkage (motion, function, path) or enumerate kinematic chains; "
                   "writes URDF checked with screwkin"),
    ("grasp", "grasp analysis: grasp map, form and force closure, internal forces, quality"),
    ("workspace", "workspace of an output link: volume, singularity-free part, conditioning"),
    ("equations", "the loop equations in symbols: vector loops, velocity and acceleration matrices, det A and "
                  "its singular conditions"),
    ("draw", "skeleton diagram (PNG/SVG), kinematic chain graph, singular configurations"),
    ("report", "one self-contained document (HTML and/or Markdown): topology, counts, equations, Newton "
               "iterations, motion, singular configurations with drawings, sweep, view"),
    ("export", "write the mechanism as MJCF (MuJoCo) or URDF, assembled (loops closed in the file)"),
)


def command_module(name: str):
    """The module of command ``name`` (screwkin/commands/NAME.py), imported now."""
    return importlib.import_module(f"{__package__}.commands.{name}")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # a value that starts with a minus and a digit is a value, units and all: --to -90deg, --from -1e-3
        self._negative_number_matcher = re.compile(r"^-\.?[0-9]")

    def error(self, message: str) -> None:  # one line (the arguments quoted in it are bounded and escaped), exit code 2
        self.exit(2, f"screwkin: error: {one_line(message, MESSAGE_LIMIT)}\n")

    def parse_known_args(self, args: argparse.Namespace | None = None, namespace=None) -> tuple:
        # every (sub)parser checks its own options: no empty values, outputs writable (commands/_options.py)
        ns, rest = super().parse_known_args(args, namespace)
        try:
            check_parsed(self, ns)
        except UsageError as exc:
            self.error(str(exc))
        return ns, rest


def _invoked(argv: list) -> str | None:
    """The command named on the command line: its first word that is not an option (the top-level
    options, --debug, --version and --help, take no value); None when there is none."""
    names = {name for name, _ in COMMANDS}
    for word in argv:
        if isinstance(word, str) and not word.startswith("-"):
            return word if word in names else None
    return None


def _parser(argv: list=()) -> _Parser:
    """The parser: every command listed with its help line; the one ``argv`` invokes built in full
    (its module imported), the others as names only."""
    p = _Parser(prog="screwkin", description="Screw-theory analysis of spatial mechanisms described in URDF.")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    p.add_argument("--version", action="version", version=f"screwkin {screwkin_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser, title="commands",
                           metavar="COMMAND")
    wanted = _invoked(argv)
    for name, help in COMMANDS:
        if name == wanted:
            command_module(name).add_parser(sub, add_common, add_scaled)
        else:
            sub.add_parser(name, help=help)
    return p


def _run(args: argparse.Namespace) -> int:
    command = command_module(args.command)
    if not command.NEEDS_MECHANISM or (command.NEEDS_MECHANISM == "optional" and args.file is None):
        return command.run(None, args)
    if args.file is None:
        raise UsageError(f"{args.command} needs a FILE")
    mech = load(args.file, yaml=args.yaml, actuated=names_list(getattr(args, "actuated", None)),
                package_dirs=args.package_dirs, args=parse_xacro_args(args.xacro_args))
    check_not_read(args, mech.spec.files_read)  # an output onto an included file, a mesh: only reading finds them
    if getattr(args, "length", None):
        mech.length = parse_length(args.length, "--length")
    if isinstance(getattr(args, "output", None), str):  # every command's output link exists (sweep, draw...)
        mech.link_frame(args.output)
    if getattr(args, "points", None):  # every --point NAME=LINK:x,y,z checked, whatever the command does with it
        named_points(mech, args)
    return command.run(mech, args)


def main(argv: list | None=None) -> int:
    """The command line.  Exit codes: 0 success, 1 invalid or unanalysable file, 2 usage
    error, 3 internal error (a bug: never caused by input), 141 when the reader of the
    output went away (``screwkin info F | head -1``): the shell's code for a process ended
    by SIGPIPE, as ``cat`` or ``grep`` report it, so ``set -o pipefail`` scripts see screwkin
    like any other tool; nothing is printed then.

    Errors are one line on stderr, ``screwkin: error: FILE: PROBLEM``, at most about
    MESSAGE_LIMIT characters after the path, control characters escaped; ``--debug``
    (before or after the command) prints the traceback first, with the same exit code.
    """

    def say(line) -> None:
        try:
            print(line, file=sys.stderr)
        except (OSError, ValueError):  # stderr closed: nowhere to say it
            pass

    words = sys.argv[1:] if argv is None else list(argv)
    parser = _parser(words)
    if not words:  # bare `screwkin`: what it can do, a line a command
        print(parser.format_help())
        return 0
    try:
        args = parser.parse_args(words)
    except SystemExit as exc:  # usage errors (2), --help and --version (0): main(argv) returns its code
        return exc.code if isinstance(exc.code, int) else 2
    debug = bool(getattr(args, "debug", False))
    paths = [str(p) for p in (getattr(args, "file", None), getattr(args, "yaml", None)) if p]
    limit = MESSAGE_LIMIT + 40 + max((len(p) for p in paths), default=0)  # the problem, "(and N more)", the path
    try:
        # numpy's floating-point RuntimeWarnings (overflow in a singular configuration...) are not messages for
        # the user: screwkin reports what matters itself, as "warning: FILE: ..." lines or in the results
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            code = _run(args)
        sys.stdout.flush()
        return code
    except BrokenPipeError:  # https://docs.python.org/3/library/signal.html#note-on-sigpipe
        try:  # stdout to /dev/null, so that the interpreter's last flush does not fail again
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError, AttributeError):  # no real stdout (captured in process): nothing to redirect
            pass
        return 141
    except ScrewkinError as exc:
        if debug:
            traceback.print_exc()
        say(f"screwkin: error: {one_line(str(exc), limit)}")
        return exc.exit_code
    except KeyboardInterrupt:  # pragma: no cover
        return 130
    except Exception as exc:  # noqa: BLE001 - a bug in screwkin, not a problem of the input: still one line, exit 3
        if debug:
            traceback.print_exc()
        where = f" on {one_line(paths[0], 200)}" if paths else ""
        say(f"screwkin: internal error{where}: {type(exc).__name__}: {one_line(str(exc), 200)} "
            "(a bug in screwkin: run again with --debug for the traceback and report it)")
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
