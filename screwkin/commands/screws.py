"""screwkin screws: product-of-exponentials structure equations and joint screws."""

from __future__ import annotations


from ..analysis.screws import loop_screws, structure
from ..errors import UsageError
from ..present.jsonout import json_of
from ..present.screws import (
    loops_dict,
    loops_text,
    screws_dict,
    screws_text,
)
from ._configuration import add_configuration_options, configuration, with_mode
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "screws"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("screws", help="product-of-exponentials structure equations and joint screws")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--output", help="also the chain to this link")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if not mech.cuts and not args.output:
        raise UsageError(f"{mech.path}: the mechanism has no loops: give --output LINK for the chain to a link")
    q = configuration(mech, args)
    st = structure(mech, q, args.output)
    topo = mech.topology(q)
    normal = None
    if topo.motion_space == "planar":
        normal = topo.normal
    loops = loop_screws(mech)
    if args.json:
        print(json_of(with_mode(args, {"motion_space": topo.motion_space, "chains": screws_dict(st, normal),
                                       "loops": loops_dict(loops, normal)})))
    else:
        print(screws_text(st, normal))
        if loops:
            print(loops_text(loops, normal))
    return 0
