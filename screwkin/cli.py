"""Command line: ``screwkin COMMAND FILE ...``.

A thin edge over the Python API: it builds the parser from the command modules of
``screwkin/commands/`` (one module per command: ``NAME``, ``NEEDS_MECHANISM``,
``add_parser(sub, common, scaled)``, ``run(mech, args) -> exit code``), loads the mechanism,
checks what every command shares and dispatches.  Exit codes: 0 success, 1 invalid or
unanalysable file, 2 usage error, 3 internal error (a bug).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import traceback
import warnings

import numpy as np

from .commands import (
    draw,
    dynamics,
    equations,
    export,
    grasp,
    ik,
    info,
    map,
    mobility,
    report,
    scan,
    screws,
    singularities,
    solve,
    statics,
    study,
    sweep,
    synthesize,
    view,
    workspace,
)
from .commands._common import add_common, add_scaled, names_list
from .commands._options import check_parsed, screwkin_version
from .errors import MESSAGE_LIMIT, ScrewkinError, UsageError, one_line
from .files.xacro import parse_args as parse_xacro_args
from .model.loader import load
from .units import parse_length

__all__ = ["main", "COMMANDS"]

#: The commands, in the order `screwkin` lists them.
COMMANDS = (mobility, info, solve, screws, singularities, map, scan, view, ik, sweep, statics, dynamics, study,
            synthesize, grasp, workspace, equations, draw, report, export)
_COMMAND_MODULES = {m.NAME: m for m in COMMANDS}


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # a value that starts with a minus and a digit is a value, units and all: --to -90deg, --from -1e-3
        self._negative_number_matcher = re.compile(r"^-\.?[0-9]")

    def error(self, message):  # one line (the arguments quoted in it are bounded and escaped), exit code 2
        self.exit(2, f"screwkin: error: {one_line(message, MESSAGE_LIMIT)}\n")

    def parse_known_args(self, args=None, namespace=None):
        # every (sub)parser checks its own options: no empty values, outputs writable (commands/_options.py)
        ns, rest = super().parse_known_args(args, namespace)
        try:
            check_parsed(self, ns)
        except UsageError as exc:
            self.error(str(exc))
        return ns, rest


def _parser():
    p = _Parser(prog="screwkin", description="Screw-theory analysis of spatial mechanisms described in URDF.")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    p.add_argument("--version", action="version", version=f"screwkin {screwkin_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser, title="commands",
                           metavar="COMMAND")
    for command in COMMANDS:
        command.add_parser(sub, add_common, add_scaled)
    return p


def _run(args):
    command = _COMMAND_MODULES[args.command]
    if not command.NEEDS_MECHANISM or (command.NEEDS_MECHANISM == "optional" and args.file is None):
        return command.run(None, args)
    if args.file is None:
        raise UsageError(f"{args.command} needs a FILE")
    mech = load(args.file, yaml=args.yaml, actuated=names_list(getattr(args, "actuated", None)),
                package_dirs=args.package_dirs, args=parse_xacro_args(args.xacro_args))
    if getattr(args, "length", None):
        mech.length = parse_length(args.length, "--length")
    if isinstance(getattr(args, "output", None), str):  # every command's output link exists (sweep, draw...)
        mech.link_frame(args.output)
    return command.run(mech, args)


def main(argv=None) -> int:
    """The command line.  Exit codes: 0 success, 1 invalid or unanalysable file, 2 usage
    error, 3 internal error (a bug: never caused by input), 141 when the reader of the
    output went away (``screwkin info F | head -1``): the shell's code for a process ended
    by SIGPIPE, as ``cat`` or ``grep`` report it, so ``set -o pipefail`` scripts see screwkin
    like any other tool; nothing is printed then.

    Errors are one line on stderr, ``screwkin: error: FILE: PROBLEM``, at most about
    MESSAGE_LIMIT characters after the path, control characters escaped; ``--debug``
    (before or after the command) prints the traceback first, with the same exit code.
    """

    def say(line):
        try:
            print(line, file=sys.stderr)
        except (OSError, ValueError):  # stderr closed: nowhere to say it
            pass

    parser = _parser()
    if not (sys.argv[1:] if argv is None else argv):  # bare `screwkin`: what it can do, a line a command
        print(parser.format_help())
        return 0
    try:
        args = parser.parse_args(argv)
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
    except Exception as exc:  # a bug in screwkin, not a problem of the input: still one line, exit 3
        if debug:
            traceback.print_exc()
        where = f" on {one_line(paths[0], 200)}" if paths else ""
        say(f"screwkin: internal error{where}: {type(exc).__name__}: {one_line(str(exc), 200)} "
            "(a bug in screwkin: run again with --debug for the traceback and report it)")
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
