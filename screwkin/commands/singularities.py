"""screwkin singularities: classify the singularities of a configuration."""

from __future__ import annotations


from ..analysis.singularities.ellipsoids import ellipsoids, with_input_output_condition
from ..analysis.singularities.gram_symbolic import symbolic_gram
from ..analysis.local import local_analysis
from ..analysis.singular import classify, named_types
from ..errors import UsageError
from ..present.jsonout import json_of
from ..present.ellipsoids import ellipsoids_dict, ellipsoids_text
from ..present.local import local_dict, local_lines, types_lines
from ..present.singular import singularity_dict, singularity_text
from ..present.screws import gram_symbolic_dict, gram_symbolic_text
from ._configuration import add_configuration_options, configuration, with_mode
from ._output_frame import add_tool_option, output_frame, output_frame_dict, output_frame_line
from ._values import inputs
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "singularities"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("singularities", help="classify the singularities of a configuration")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--output", help="output link (for serial singularities and the output twist)")
    sp.add_argument("--ellipsoids", action="store_true",
                   help="the output's velocity and force ellipsoids for the inputs (needs --output)")
    sp.add_argument("--symbolic", action="store_true",
                   help="planar loops: each joint's Gram cofactor as a formula in the symbols of screwkin equations, "
                        "and where it vanishes (the joint is stationary)")
    add_tool_option(sp)
    scaled(sp)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    output, point = output_frame(mech, args)
    if point and not output:
        raise UsageError("--point needs --output LINK")
    if args.ellipsoids and not output:
        raise UsageError("--ellipsoids needs --output LINK")
    q = configuration(mech, args)
    rep = with_input_output_condition(mech, q, classify(mech, q, output=output, point=point))
    local = local_analysis(mech, q, generic_rank=None)
    types = named_types(rep, local, mech.tolerances)
    ell = ellipsoids(mech, q, output, point=point) if args.ellipsoids else None
    frame = output_frame_dict(mech, q, jacobian=True, point=point)
    gram = symbolic_gram(mech, q, list(inputs(mech, args)) or None) if args.symbolic else None
    if args.json:
        d = singularity_dict(rep)
        d["local"] = local_dict(local, mech.joint_values(q))
        d["types"] = [{"vocabulary": v, "name": n, "meaning": w} for v, n, w in types]
        if frame is not None:  # the named point or tool frame analysed as the output
            d["output_frame"] = frame
        if ell is not None:
            d["ellipsoids"] = ellipsoids_dict(ell)
        if gram is not None:
            d["gram_symbolic"] = gram_symbolic_dict(gram)
        print(json_of(with_mode(args, d)))
    else:
        if frame is not None:
            print(output_frame_line(frame, point))
        print(singularity_text(rep))
        print("\n".join(["", *types_lines(types), *local_lines(local, "this configuration", args.explain)]))
        if ell is not None:
            print()
            print(ellipsoids_text(ell))
        if gram is not None:
            print()
            print(gram_symbolic_text(gram))
    return 0
