"""``screwkin equations``: the course-solution equations in symbols (vector loops, velocity and
acceleration matrices, det A and where it vanishes).  Newton on those equations from a person's
estimates is ``solve --start`` (commands/solve.py)."""

from __future__ import annotations

from ..analysis.course.equations import equations
from ..present.equations import equations_dict, equations_text
from ..present.jsonout import json_of
from ._configuration import add_configuration_options, configuration, with_mode
from ._values import split_inputs
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

NAME = "equations"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="the loop equations in symbols: vector loops, velocity and acceleration "
                                   "matrices, det A and its singular conditions")
    common(sp)
    sp.add_argument("--input", action="append", metavar="NAME",
                    help="input joint (repeat or comma-separate; default: the --set joints, else the actuated ones)")
    add_configuration_options(sp)
    sp.add_argument("--output", help="spatial mechanisms: also the chain to this link")


def _input_names(mech: Mechanism, args: argparse.Namespace, values: dict, held: dict) -> list:
    """The input joints: --input, else those set (``values``: --set, --set-angle of a link pinned to the
    ground), else -- unless a floating link's angle is given (``held``: an input of its own) -- the
    actuated ones."""
    names = [n.strip() for item in (args.input or []) for n in item.split(",") if n.strip()]
    if names:
        return names
    return list(values) or ([] if held else list(mech.actuated))


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    values, held, _ = split_inputs(mech, args)
    names = _input_names(mech, args, values, held)
    q = configuration(mech, args)
    res = equations(mech, q, names, output=args.output, links=list(held))
    if args.json:
        print(json_of(with_mode(args, equations_dict(res))))
    else:
        print(equations_text(res, args.explain))
    return 0
