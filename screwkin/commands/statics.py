"""``screwkin statics``: actuator efforts and joint reactions that hold a load; the constraint
and transmission wrenches of a parallel mechanism's legs."""

from __future__ import annotations


import numpy as np

from ..analysis.forces.statics import legs, no_legs_reason, statics
from ..analysis.redundancy import redundancy
from ..errors import UsageError
from ..model.state import KinematicState
from ..present.jsonout import json_of
from ..present.local import redundancy_dict, redundancy_lines
from ..present.statics import statics_dict, statics_text
from ..units import parse_value
from ._configuration import add_configuration_options, configuration, with_mode
from ._output_frame import add_point_option, add_tool_option, output_frame, output_frame_dict, output_frame_line
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

NAME = "statics"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="actuator efforts and joint reactions holding a load; legs' wrenches")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--output", help="the link the wrench is applied to (at its frame's origin, world axes; at the "
                                     "--tool's origin or the named --point with those)")
    add_tool_option(sp)
    add_point_option(sp)
    sp.add_argument("--wrench", help='"fx fy fz mx my mz": force [N] and moment [N m]')
    sp.add_argument("--gravity", action="store_true", help="also the links' weights (from the file's inertials)")
    sp.add_argument("--length", help="characteristic length for the amplification (default: mean link length)")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    wrench = None
    if args.wrench is not None:
        parts = args.wrench.replace(",", " ").split()
        if len(parts) != 6:
            raise UsageError(f'--wrench expects "fx fy fz mx my mz", got {len(parts)} numbers')
        wrench = [parse_value(p, "force" if k < 3 else "moment", "--wrench") for k, p in enumerate(parts)]
        if args.output is None and not args.points:
            raise UsageError("--wrench needs --output LINK (the link it is applied to) or a named --point")
    output, _ = output_frame(mech, args)
    q = configuration(mech, args)
    result = statics(mech, q, output=output, wrench=wrench, gravity=args.gravity)
    leg_list = legs(mech, q, output) if output is not None and mech.cuts else None
    # the indeterminate reactions by name: the redundant constraint wrenches (analysis.redundancy)
    red = redundancy(mech, q) if result.indeterminate else None
    why_not = no_legs_reason(leg_list, output) if leg_list is not None else None
    if why_not:  # a slider-crank's slider, a four-bar's coupler: no parallel-robot legs to speak of
        leg_list = None
    frame = output_frame_dict(mech, q)
    if frame is not None:  # the load at the point (tool origin) is, at the link frame's origin, m_o = m + r x f
        o = KinematicState(mech, q).link_motion(frame["link"])["position"]
        f, m = np.asarray(result.wrench[:3]), np.asarray(result.wrench[3:])
        frame["wrench_at_link_origin"] = [*f.tolist(), *(m + np.cross(np.asarray(frame["position"]) - o, f)).tolist()]
    if args.json:
        d = statics_dict(result, leg_list)
        if red is not None:
            d.update({k: v for k, v in redundancy_dict(red).items() if k != "exactly_constrained_by"})
        if why_not:
            d["legs"], d["legs_note"] = [], f"no legs: {why_not}"
        if frame is not None:
            d["output_frame"] = frame
        print(json_of(with_mode(args, d)))
    else:
        if frame is not None:
            moved = " ".join(f"{v:.6g}" for v in frame["wrench_at_link_origin"])
            print(output_frame_line(frame, args.tool is None) + f"; the load there is, at {frame['link']}'s "
                  f"origin, (fx fy fz mx my mz) = {moved} (N, N m)")
        print(statics_text(result, leg_list))
        if why_not:
            print(f"\nno legs' wrenches: {why_not} (the joint reactions above give what each joint carries)")
        if red is not None and red.count:
            print("\n".join(redundancy_lines(red, "the reactions statics cannot give, by joint", args.explain)))
    return 0
