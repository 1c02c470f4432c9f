"""``screwkin statics``: actuator efforts and joint reactions that hold a load; the constraint
and transmission wrenches of a parallel mechanism's legs."""

from __future__ import annotations

import json

from ..analysis.forces.statics import legs, statics
from ..errors import UsageError
from ..present.report import to_jsonable
from ..present.statics import statics_dict, statics_text
from ..units import parse_value
from ._common import add_configuration_options, configuration, with_mode

NAME = "statics"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser(NAME, help="actuator efforts and joint reactions holding a load; legs' wrenches")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--output", help="the link the wrench is applied to (at its frame's origin, world axes)")
    sp.add_argument("--wrench", help='"fx fy fz mx my mz": force [N] and moment [N m]')
    sp.add_argument("--gravity", action="store_true", help="also the links' weights (from the file's inertials)")
    sp.add_argument("--length", help="characteristic length for the amplification (default: mean link length)")


def run(mech, args) -> int:
    wrench = None
    if args.wrench is not None:
        parts = args.wrench.replace(",", " ").split()
        if len(parts) != 6:
            raise UsageError(f'--wrench expects "fx fy fz mx my mz", got {len(parts)} numbers')
        wrench = [parse_value(p, "force" if k < 3 else "moment", "--wrench") for k, p in enumerate(parts)]
        if args.output is None:
            raise UsageError("--wrench needs --output LINK (the link it is applied to)")
    q = configuration(mech, args)
    result = statics(mech, q, output=args.output, wrench=wrench, gravity=args.gravity)
    leg_list = legs(mech, q, args.output) if args.output is not None and mech.cuts else None
    if args.json:
        print(json.dumps(to_jsonable(with_mode(args, statics_dict(result, leg_list))), indent=2))
    else:
        print(statics_text(result, leg_list))
    return 0
