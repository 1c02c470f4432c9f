"""The options every command takes (FILE, --json, --debug, ...; --length and --point) and ``emit``,
its one way to print JSON or text."""

from __future__ import annotations

import argparse

from ..present.jsonout import json_of
from ._output_frame import add_point_option
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["add_common", "add_scaled", "emit", "EXPLAIN_HELP"]

#: --explain, the one option every command shares for the explanations its text leaves out by default.
EXPLAIN_HELP = ("also print the explanations: how each answer was decided, the redundant constraints by name and "
                "how to remove them, the worked numbers (the default text gives the answers, about a screen for a "
                "four-bar; --json and report always have everything)")


def add_common(sp: argparse.ArgumentParser, mechanism: bool = True, optional_file: bool = False) -> None:
    """The options every command takes (with mechanism=False: no FILE and no mechanism options)."""
    sp.add_argument("--explain", action="store_true", help=EXPLAIN_HELP)
    if not mechanism:
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
        return
    sp.add_argument("file", help="URDF (with <loop_joint> or a YAML sidecar), SDF, MJCF, or xacro file",
                    **({"nargs": "?"} if optional_file else {}))
    sp.add_argument("--arg", action="append", dest="xacro_args", metavar="NAME=VALUE",
                    help="xacro argument of a .xacro file (units allowed, e.g. crank=30mm: given in SI); repeatable")
    sp.add_argument("--yaml", help="Extended-URDF sidecar (default: FILE with .yaml suffix, if present)")
    sp.add_argument("--json", action="store_true", help="print one JSON object")
    # SUPPRESS: when absent after the command, the top-level --debug (before the command) is kept
    sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
    sp.add_argument("--actuated", help="actuated joints, comma separated (overrides the file)")
    sp.add_argument("--package-dir", action="append", dest="package_dirs", metavar="DIR",
                    help="folder holding ROS packages (or a package) for package:// meshes, searched before "
                         "ROS_PACKAGE_PATH; repeatable")


def add_scaled(sp: argparse.ArgumentParser, point: bool=True) -> None:
    """--length (the characteristic length of the dimensionless measures) and --point."""
    sp.add_argument("--length", help="characteristic length that makes the measures dimensionless "
                                     "(default: the mean link length; printed with every measure)")
    if point:
        add_point_option(sp, "--point alone: analyse the output link's origin as a point (3 translations) "
                             "instead of its full motion")


def emit(args: argparse.Namespace, data: Callable, text: Callable) -> int:
    """Print ``data`` as one JSON object (--json; written by present/jsonout.json_of, the one writer) or
    ``text`` (a string, or a callable making it, so that text-only work is skipped for --json); exit code 0."""
    if getattr(args, "json", False):
        print(json_of(data() if callable(data) else data))
    else:
        print(text() if callable(text) else text)
    return 0
