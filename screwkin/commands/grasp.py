"""``screwkin grasp GRASP.yaml``: grasp map, form and force closure with a certificate,
internal forces and the Ferrari-Canny quality of contacts on one object."""

from __future__ import annotations


from ..analysis.forces.grasp import GRASP_TOLERANCES, analyze_grasp
from ..errors import UsageError
from ..files.grasp import read_grasp
from ..present.jsonout import json_of
from ..present.grasp import grasp_dict, grasp_text
from ..units import parse_length
from ._options import whole
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

NAME = "grasp"
NEEDS_MECHANISM = False


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="grasp analysis: grasp map, form and force closure, internal forces, quality")
    sp.add_argument("file", metavar="GRASP.yaml", help="contacts on one object (docs/format.md, 'Grasps')")
    common(sp, mechanism=False)
    sp.add_argument("--facets", type=whole, default=8,
                    help="facets of the pyramids that stand for circular friction cones (default 8; refined up to "
                         f"{GRASP_TOLERANCES.max_facets} when the answer is ambiguous)")
    sp.add_argument("--length", help="characteristic length L dividing the moments (default: the mean distance "
                                     "of the contacts from their centroid; printed with the quality)")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if not 3 <= args.facets <= GRASP_TOLERANCES.max_facets:
        raise UsageError(f"--facets {args.facets}: give 3 to {GRASP_TOLERANCES.max_facets}")
    length = None
    if args.length is not None:
        length = parse_length(args.length, "--length")
    spec = read_grasp(args.file)
    result = analyze_grasp(spec, facets=args.facets, length=length)
    if args.json:
        print(json_of(grasp_dict(result)))
    else:
        print(grasp_text(result))
    return 0
